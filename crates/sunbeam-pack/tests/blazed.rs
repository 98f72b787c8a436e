//! PHYSICS.md 5, target 14: energy per order of a blazed (sawtooth) grating
//! against scalar theory's closed form
//!
//! ```text
//! E_m = sinc^2(m - a_m),  a_m = (cos th_i + cos th_m) d tan th_B / lambda,  sinc x = sin(pi x)/(pi x)
//! ```
//!
//! 300 lines/mm (`d` = 3.333 um), blaze 4.3 deg (`lambda_B = 2 d sin th_B` =
//! 500 nm). `E_m` is `Pack::reflectance` (`R`, not the grazing term: the
//! energy per order is about `R`) integrated over order `m`'s lobe, divided
//! by a flat patch's specular lobe integrated the same way. The integral is
//! in `(u, v)` at **fixed `w`**, the order centre's `w_m = -(cos th_i + cos
//! th_m)`: at fixed `w` the phase depth, and so the order's efficiency, is
//! constant across the lobe, which is what the closed form describes, and
//! the flat patch's `R` does not depend on `w`. The box is the order's
//! centre `u_m = -m lambda / d` plus or minus half the order spacing in `u`,
//! times `|v| <= 6` lobe widths; midpoint rule at a third of the lobe's rms
//! width. Orders on the side the facets face have `m > 0` (`h` falls along
//! +x: the facets face +x).
//!
//! The field: 12 periods along x at 340 samples per period (dx = 9.80 nm),
//! constant along y with 16 rows of 2.5 um (the window is isotropic,
//! `sigma = min(Lx, Ly) / 6`, so the patch is as long in y as in x; the
//! coarse rows cost nothing because the field does not change along y).
//! Both models; for the window model the orders' lobes are 8.9 of their rms
//! widths from the midpoint between orders.

mod common;
use common::*;
use std::f64::consts::PI;
use sunbeam_pack::build::BuildOptions;
use sunbeam_pack::{Model, Pack};

const D: f64 = 1e-3 / 300.0;
const PERIODS: usize = 12;
const PER_PERIOD: usize = 340;
const ROWS: usize = 16;
const DY: f64 = 2.5e-6;

fn blaze() -> f64 {
    4.3f64.to_radians()
}

fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-12 {
        1.0
    } else {
        (PI * x).sin() / (PI * x)
    }
}

/// `h = -frac(x / d) d tan th_B` (`flat`: 0).
fn surface(flat: bool) -> sunbeam_field::HeightField {
    let dx = D / PER_PERIOD as f64;
    let h = D * blaze().tan();
    let mut data = Vec::with_capacity(PERIODS * PER_PERIOD * ROWS);
    for _ in 0..ROWS {
        for c in 0..PERIODS * PER_PERIOD {
            let j = c % PER_PERIOD; // exact: no rounding of x / d
            data.push(if flat {
                0.0
            } else {
                -(j as f64) / PER_PERIOD as f64 * h
            });
        }
    }
    sunbeam_field::HeightField::new(PERIODS * PER_PERIOD, ROWS, dx, DY, data).unwrap()
}

fn pack(flat: bool, model: Model) -> Pack {
    let o = BuildOptions {
        model,
        lambda_min_m: 400e-9,
        lambda_max_m: 700e-9,
        // |v| <= 6 lobe widths at 700 nm is f_y < 2e5 / m.
        freq_limit_per_m: Some([2.0 / 400e-9, 3e5]),
        threads: 2,
        ..BuildOptions::default()
    };
    build(&surface(flat), &o)
}

/// The lobe's rms width in `u` (and `v`) at `lambda`.
fn lobe_width(p: &Pack, lambda: f64) -> f64 {
    let m = &p.manifest;
    match m.model {
        Model::Window => lambda / (2.0 * 2f64.sqrt() * PI * m.window_sigma_m),
        Model::Tiled => lambda * m.sigma_f_per_m,
    }
}

/// `integral R du dv` over order `m`'s box at fixed `w`.
fn lobe_integral(p: &Pack, m: i32, w: f64, lambda: f64) -> f64 {
    let s = lobe_width(p, lambda);
    let half = 0.5 * lambda / D;
    let uc = -(m as f64) * lambda / D;
    let vmax = 6.0 * s;
    let h = s / 3.0;
    let (nu, nv) = (
        (2.0 * half / h).ceil() as usize,
        (2.0 * vmax / h).ceil() as usize,
    );
    let (du, dv) = (2.0 * half / nu as f64, 2.0 * vmax / nv as f64);
    let mut sum = 0.0;
    for j in 0..nv {
        let v = -vmax + (j as f64 + 0.5) * dv;
        for i in 0..nu {
            let u = uc - half + (i as f64 + 0.5) * du;
            sum += p.reflectance(u, v, w, lambda);
        }
    }
    sum * du * dv
}

/// (measured, closed form) for order `m` lit from `wi_x` (the light's
/// tangential component along x; `wi_y` = 0) at `lambda`; None if evanescent.
fn order(grating: &Pack, flat: &Pack, m: i32, wi_x: f64, lambda: f64) -> Option<(f64, f64)> {
    let wr_x = m as f64 * lambda / D - wi_x;
    if wr_x.abs() >= 1.0 {
        return None;
    }
    let (ci, cm) = ((1.0 - wi_x * wi_x).sqrt(), (1.0 - wr_x * wr_x).sqrt());
    let w = -(ci + cm);
    let a = (ci + cm) * D * blaze().tan() / lambda;
    let e = lobe_integral(grating, m, w, lambda) / lobe_integral(flat, 0, w, lambda);
    Some((e, sinc(m as f64 - a).powi(2)))
}

#[test]
fn blazed_grating_energy_per_order() {
    let mut worst = 0.0f64;
    for model in [Model::Window, Model::Tiled] {
        let (g, f) = (pack(false, model), pack(true, model));
        println!(
            "{model:?}: {} terms, window sigma {:.2} um, lobe width in u at 500 nm {:.2e} (orders {:.3e} apart)",
            g.manifest.terms,
            g.manifest.window_sigma_m * 1e6,
            lobe_width(&g, 500e-9),
            500e-9 / D
        );
        for th_i in [0.0f64, 30.0] {
            // Light from the -x side: wi_x = -sin th_i.
            let wi_x = -th_i.to_radians().sin();
            for lambda in [400e-9, 500e-9, 600e-9, 700e-9] {
                let mut line = format!("  th_i {th_i:4.1} lambda {:.0} nm:", lambda * 1e9);
                for m in [-1, 0, 1, 2] {
                    if let Some((e, want)) = order(&g, &f, m, wi_x, lambda) {
                        line += &format!("  m={m:+}: {e:.4} ({want:.4})");
                        if m >= 0 {
                            worst = worst.max((e - want).abs());
                            assert!(
                                (e - want).abs() < 0.02,
                                "{model:?} th_i {th_i} lambda {lambda}: order {m} {e} vs {want}"
                            );
                        }
                    }
                }
                println!("{line}");
            }
        }
        // Littrow: order 1 back along the light, wi_x = lambda / (2 d).
        let table = [
            (400e-9, 0.81),
            (450e-9, 0.96),
            (500e-9, 1.00),
            (550e-9, 0.97),
            (600e-9, 0.91),
            (700e-9, 0.76),
        ];
        let mut line = "  Littrow order 1:".to_string();
        for (lambda, listed) in table {
            let (e, want) = order(&g, &f, 1, lambda / (2.0 * D), lambda).unwrap();
            line += &format!(
                " {:.0} nm {e:.4} ({want:.4}, listed {listed:.2})",
                lambda * 1e9
            );
            assert!(
                (want - listed).abs() < 0.006,
                "closed form {want} vs PHYSICS.md {listed}"
            );
            assert!(
                (e - listed).abs() < 0.02,
                "{model:?} Littrow {lambda}: {e} vs {listed}"
            );
            worst = worst.max((e - want).abs());
        }
        println!("{line}");
    }
    println!("worst |E - closed form| over m = 0, 1, 2 and Littrow: {worst:.2e}");
}
