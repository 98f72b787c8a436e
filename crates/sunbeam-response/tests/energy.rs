//! PHYSICS.md 5, target 12 (energy): the directional albedo
//!
//! ```text
//! a(wr) = integral f_r cos(theta_i) dw_i,   f_r cos(theta_i) = G R_U A / lambda^2
//! ```
//!
//! (diffraction: `G` absolute, n = 1.5; `R_U` = `Pack::shading_reflectance`,
//! PHYSICS.md 2b's exact term for the window model, `R` for the tiled model;
//! `A` the coherent area: window `(sum g)^2 / sum g^2 dx dy`, tiled
//! `1 / (2 pi sigma_f^2) = 2 pi (coherence / 4)^2`, from Parseval
//! `integral R d^2f = 1 / A`, computed here and checked against the
//! manifest's), optionally with Smith masking from the pack's rms slopes,
//! plus a diffuse base of albedo `BASE` = 0.5 under the skin
//! (`base / pi cos(theta_i) (1 - F(theta_i))`, PHYSICS.md 2).
//!
//! Quadrature over the incident hemisphere (`dw_i = du dv / cos theta_i` with
//! `(u, v) = -(wi + wr)_xy`, or `d(cos theta_i) d phi_i`; the cosine weights
//! of `f_r cos theta_i` and of `dw_i` do not cancel in `(u, v)`: the
//! integrand there is `G R_U A / (lambda^2 cos theta_i)`, bounded in
//! `(cos theta_i, phi_i)`). A smooth partition of unity in `rho = sin
//! theta_i`: a Cartesian midpoint grid in `(u, v)` over `rho < 0.85`
//! (weight `delta^2 / cos theta_i` times a cosine taper from 1 at 0.6 to 0 at
//! 0.85), and rings in `cos theta_i` over `rho > 0.6` down to the horizon
//! (midpoints, uniform `phi`, weight `d(cos) d phi` times one minus the
//! taper). Points at most `delta` apart in `(u, v)`: 0.5 of the lobes' rms
//! width in `u` for the window model (`lambda / (2 sqrt 2 pi sigma)`), 0.9 for
//! the tiled model's Gaussians (`lambda sigma_f`); near the horizon the ring
//! steps are also at most 0.15 `(cos theta_i + cos theta_r)`, the scale on
//! which `G` and `R_U` change there. Halving `delta` changes the flat
//! patches' albedos by < 0.1 % (window) and < 0.4 % (tiled); a flat patch
//! gives the furnace values `F(0)` and `F(60 deg)` within 1 % (asserted).

//! The diffuse base's share depends on how it is counted, and PHYSICS.md's
//! form is not reciprocal:
//! - `literal`: PHYSICS.md's `base/pi cos_i (1 - F(theta_i))` integrated over
//!   the light at a fixed view: `base (1 - F_avg)` = 0.454 whatever the
//!   view. With a flat patch's specular `F(theta_r)` (a narrow lobe) that
//!   exceeds 1 once `F(theta_r) > 0.546` (theta_r > 84 deg), masked or not,
//!   both models: not an energy balance.
//! - `energy`: light arriving from `w` is reflected by the diffraction term
//!   (reciprocal: the same integral with `w` as the view) or enters the
//!   skin (`1 - F(theta_w)`) and the base returns `base` of it:
//!   `a_diffraction(w) + base (1 - F(theta_w))`. This is the energy balance,
//!   and what is asserted.
//!
//! Measured (printed as a table; `HOLDS_UP_TO` below), PHYSICS.md 5 item
//! 12 does not hold as written:
//! - unmasked, every case exceeds 1 at grazing views, the tiled model too
//!   (from 85-89.2 deg on; 5-20 at 89.9 deg): `G`'s `1 / cos(theta_r)` meets
//!   lobes at `cos(theta_i) >> cos(theta_r)` (the flat patch's: the lobe's
//!   width; the ridges': their orders), with the window's exact term (2b) or
//!   Beckmann's factor alike. docs/LIGHTING.md's flat figures are reproduced:
//!   1.316 at `cos(theta_r)` 0.01 and 11.93 at 1e-3 (sigma 3 um, 500 nm);
//! - masked, the ridge packs hold to 89.9 deg except the 20 um
//!   Xenopeltis-like window pack seen along its ridges (rms slope 0.019
//!   along y: masking does little), 1.26 at 89.9 deg; a flat patch has no
//!   slopes, so Smith is off and its masked albedo is the unmasked one;
//! - the literal diffuse form adds 0.454 at every view and crosses 1 earlier
//!   (from 80 deg on unmasked).

use rayon::prelude::*;
use std::f64::consts::PI;
use sunbeam_field::HeightField;
use sunbeam_optics::gain::{self, Material};
use sunbeam_optics::masking::Masking;
use sunbeam_pack::build::BuildOptions;
use sunbeam_pack::{Model, Pack};
use sunbeam_response::energy;

/// A height field of `w x h` samples from `f(x, y)` (x along columns, y up the image).
fn field(w: usize, h: usize, dx: f64, dy: f64, f: impl Fn(f64, f64) -> f64) -> HeightField {
    let d = (0..h)
        .flat_map(|r| (0..w).map(move |c| (c, r)))
        .map(|(c, r)| f(c as f64 * dx, (h - 1 - r) as f64 * dy))
        .collect();
    HeightField::new(w, h, dx, dy, d).unwrap()
}

fn build(f: &HeightField, o: &BuildOptions) -> Pack {
    let r = sunbeam_pack::FieldRef {
        width: f.width,
        height: f.height,
        dx: f.dx,
        dy: f.dy,
        data: &f.data,
    };
    sunbeam_pack::build(r, o, &mut |_, _| {}).unwrap()
}

const LAMBDA: f64 = 500e-9;
const BASE: f64 = 0.5;
const COHERENCE: f64 = 65e-6;
/// View angles (degrees from the normal); 89.427 is cos = 0.01.
const VIEWS: [f64; 17] = [
    0.0, 30.0, 60.0, 75.0, 80.0, 85.0, 87.0, 88.0, 88.5, 89.0, 89.2, 89.427, 89.5, 89.6, 89.7,
    89.8, 89.9,
];

struct Case {
    name: &'static str,
    pack: Pack,
    /// Coherent area A (m^2).
    area: f64,
    /// Quadrature spacing in (u, v).
    delta: f64,
    /// View azimuths (degrees).
    azimuths: Vec<f64>,
}

fn make_case(
    name: &'static str,
    f: &sunbeam_field::HeightField,
    model: Model,
    azimuths: Vec<f64>,
) -> Case {
    let o = BuildOptions {
        model,
        coherence_m: COHERENCE,
        lambda_min_m: LAMBDA,
        lambda_max_m: LAMBDA,
        threads: 2,
        ..BuildOptions::default()
    };
    let pack = build(f, &o);
    let (area, sigma_u) = match model {
        Model::Window => {
            // PHYSICS.md 2's window, computed here.
            let sigma = (COHERENCE / (4.0 * 2f64.sqrt()))
                .min((f.width as f64 * f.dx).min(f.height as f64 * f.dy) / 6.0);
            let axis = |m: usize, d: f64| {
                let c = (m as f64 - 1.0) / 2.0;
                let g: Vec<f64> = (0..m)
                    .map(|i| (-((i as f64 - c) * d).powi(2) / (2.0 * sigma * sigma)).exp())
                    .collect();
                let s1: f64 = g.iter().sum();
                let s2: f64 = g.iter().map(|v| v * v).sum();
                s1 * s1 / s2 * d
            };
            // |FT g|^2 has rms width 1 / (2 sqrt 2 pi sigma) in f.
            (
                axis(f.width, f.dx) * axis(f.height, f.dy),
                LAMBDA / (2.0 * 2f64.sqrt() * PI * sigma),
            )
        }
        Model::Tiled => {
            let sigma_f = 1.0 / (2.0 * PI * COHERENCE / 4.0);
            (1.0 / (2.0 * PI * sigma_f * sigma_f), LAMBDA * sigma_f)
        }
    };
    let a_m = pack.manifest.coherent_area_m2();
    assert!(
        (a_m / area - 1.0).abs() < 1e-9,
        "{name}: A {area} vs manifest {a_m}"
    );
    let delta = match model {
        Model::Window => 0.5 * sigma_u,
        Model::Tiled => 0.9 * sigma_u,
    };
    Case {
        name,
        pack,
        area,
        delta,
        azimuths,
    }
}

/// Inner disc (Cartesian in `(u, v)`) weight `w(rho)`: 1 up to `RHO_IN`, 0
/// from `RHO_OUT`, a cosine taper between; the rings take `1 - w`.
const RHO_IN: f64 = 0.6;
const RHO_OUT: f64 = 0.85;
fn inner_weight(rho: f64) -> f64 {
    if rho <= RHO_IN {
        1.0
    } else if rho >= RHO_OUT {
        0.0
    } else {
        let t = (rho - RHO_IN) / (RHO_OUT - RHO_IN);
        0.5 + 0.5 * (PI * t).cos()
    }
}

/// Quadrature nodes `(wi, weight in solid angle)` for view cosine `cos_r`
/// (module doc): a Cartesian midpoint grid of spacing `delta` in
/// `wi_xy` over the inner disc (weight `delta^2 / cos theta_i` times the
/// taper), and rings in `cos theta_i` over the rest, down to the horizon.
fn nodes(delta: f64, cos_r: f64, az0: f64) -> Vec<Vec<([f64; 3], f64)>> {
    let mut out = vec![];
    let n = (RHO_OUT / delta).ceil() as i64;
    for iy in -n..n {
        let y = (iy as f64 + 0.5) * delta;
        let mut row = vec![];
        for ix in -n..n {
            let x = (ix as f64 + 0.5) * delta;
            let r2 = x * x + y * y;
            let w = inner_weight(r2.sqrt());
            if w > 0.0 {
                let c = (1.0 - r2).sqrt();
                row.push(([x, y, c], w * delta * delta / c));
            }
        }
        out.push(row);
    }
    // Rings over cos theta in [0, cos(asin RHO_IN)]: steps <= delta rho / c
    // (radial spacing in (u, v)) and 0.15 (c + cos_r).
    let mut c = (1.0 - RHO_IN * RHO_IN).sqrt();
    while c > 0.0 {
        let rho = (1.0 - c * c).sqrt();
        let dc = (delta * rho / c).min(0.15 * (c + cos_r));
        let lo = if dc >= 0.9 * c { 0.0 } else { c - dc };
        let cm = 0.5 * (lo + c);
        let rm = (1.0 - cm * cm).sqrt();
        let w = 1.0 - inner_weight(rm);
        let np = ((2.0 * PI * rm / delta).ceil() as usize).max(8);
        let wt = w * (c - lo) * 2.0 * PI / np as f64;
        if wt > 0.0 {
            out.push(
                (0..np)
                    .map(|j| {
                        let ph = az0 + (j as f64 + 0.5) * 2.0 * PI / np as f64;
                        ([rm * ph.cos(), rm * ph.sin(), cm], wt)
                    })
                    .collect(),
            );
        }
        c = lo;
    }
    out
}

/// Diffraction albedo for view `wr` (local, unit): (unmasked, masked).
fn diffraction_albedo(case: &Case, wr: [f64; 3]) -> (f64, f64) {
    let mat = Material::default();
    let smith = Masking::smith(case.pack.manifest.rms_slope.unwrap_or([0.0, 0.0]));
    let k = case.area / (LAMBDA * LAMBDA);
    let az0 = wr[1].atan2(wr[0]);
    let sums: Vec<(f64, f64)> = nodes(case.delta, wr[2], az0)
        .par_iter()
        .map(|group| {
            let (mut s, mut sm) = (0.0, 0.0);
            for &(wi, wt) in group {
                let r = case.pack.shading_reflectance(
                    -wi[0] - wr[0],
                    -wi[1] - wr[1],
                    -wi[2] - wr[2],
                    LAMBDA,
                );
                if r == 0.0 {
                    continue;
                }
                let g = gain::g(wi, wr, mat) * r * wt;
                s += g;
                sm += g * smith.factor(wi, wr);
            }
            (s * k, sm * k)
        })
        .collect();
    sums.iter().fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1))
}

fn view(theta_deg: f64, az_deg: f64) -> [f64; 3] {
    let (t, a) = (theta_deg.to_radians(), az_deg.to_radians());
    [t.sin() * a.cos(), t.sin() * a.sin(), t.cos()]
}

/// `2 integral_0^1 (1 - F(c)) c dc`: the base's share of light from a uniform sky.
fn one_minus_f_avg() -> f64 {
    let n = 200_000;
    let mut s = 0.0;
    for i in 0..n {
        let c = (i as f64 + 0.5) / n as f64;
        s += Material::default().transmission(c) * c;
    }
    2.0 * s / n as f64
}

// ----------------------------------------------------------------- surfaces

/// Snake-like ridges (after sunbeam-synth's presets, written here: the pack's
/// tests do not depend on sunbeam-synth): crests along y repeating along x
/// with period `period`, an asymmetric profile rising over `rise` of the
/// period, sideways waviness, finger breaks, and a little smooth roughness.
#[allow(clippy::too_many_arguments)]
fn ridges(
    n: usize,
    px: f64,
    period: f64,
    height: f64,
    rise: f64,
    wave: (f64, f64),
    finger: f64,
    rough: f64,
    seed: u64,
) -> sunbeam_field::HeightField {
    let mut rng = sunbeam_common::rng::SplitMix64(seed);
    let mut range = |a: f64, b: f64| a + (b - a) * rng.unit();
    let bumps: Vec<(f64, f64, f64)> = (0..(n * n / 400).max(8))
        .map(|_| {
            (
                range(0.0, n as f64 * px),
                range(0.0, n as f64 * px),
                range(-1.0, 1.0),
            )
        })
        .collect();
    let phases: Vec<f64> = (0..64).map(|_| rng.unit()).collect();
    let bump_s = 0.15e-6;
    field(n, n, px, px, |x0, y| {
        let x = x0 + wave.0 * (2.0 * PI * y / wave.1).sin();
        let ph = x / period;
        let ridge = ph.floor();
        let fr = ph - ridge;
        let mut z = if fr < rise {
            0.5 - 0.5 * (PI * fr / rise).cos()
        } else {
            0.5 + 0.5 * (PI * (fr - rise) / (1.0 - rise)).cos()
        };
        if finger > 0.0 {
            let p = y / finger + phases[(ridge.rem_euclid(64.0)) as usize];
            let q = p - p.floor();
            let ss = |a: f64, b: f64, v: f64| {
                let t = ((v - a) / (b - a)).clamp(0.0, 1.0);
                t * t * (3.0 - 2.0 * t)
            };
            z *= 0.35 + 0.65 * ss(0.0, 0.15, q) * ss(1.0, 0.85, q);
        }
        let mut b = 0.0;
        for &(bx, by, a) in &bumps {
            let d2 = (x0 - bx).powi(2) + (y - by).powi(2);
            if d2 < 25.0 * bump_s * bump_s {
                b += a * (-d2 / (2.0 * bump_s * bump_s)).exp();
            }
        }
        (z + rough * b) * height
    })
}

/// Elaphe-like: period 1.144 um, 375 nm, rise 0.35, waviness 60 nm / 5 um,
/// fingers 3 um, roughness 3 %.
fn elaphe(n: usize, px: f64) -> sunbeam_field::HeightField {
    ridges(n, px, 1.144e-6, 375e-9, 0.35, (60e-9, 5e-6), 3e-6, 0.03, 1)
}

/// Xenopeltis-like: period 1.552 um, 443 nm, rise 0.45, waviness 40 nm / 7 um,
/// continuous ridges, roughness 2 %.
fn xenopeltis(n: usize, px: f64) -> sunbeam_field::HeightField {
    ridges(
        n,
        px,
        1.552e-6,
        443.45e-9,
        0.45,
        (40e-9, 7e-6),
        0.0,
        0.02,
        2,
    )
}

// -------------------------------------------------------------------- test

/// Per view: (theta, azimuth, diffraction unmasked, diffraction masked).
fn measure(case: &Case) -> Vec<(f64, f64, f64, f64)> {
    let mut out = vec![];
    for &az in &case.azimuths {
        for &th in &VIEWS {
            let (a, m) = diffraction_albedo(case, view(th, az));
            out.push((th, az, a, m));
        }
    }
    out
}

/// The largest view in `VIEWS` up to which (inclusive, every azimuth) `a` is
/// at most 1; 0 when even the first is not (-1 never happens: VIEWS[0] = 0).
fn holds_up_to(rows: &[(f64, f64, f64)]) -> f64 {
    let mut last = -1.0;
    for &th in &VIEWS {
        if rows.iter().filter(|r| r.0 == th).all(|r| r.2 <= 1.0) {
            last = th;
        } else {
            break;
        }
    }
    last
}

/// Largest value and its (theta, azimuth).
fn max_of(rows: &[(f64, f64, f64)]) -> (f64, f64, f64) {
    rows.iter().fold((f64::MIN, 0.0, 0.0), |m, r| {
        if r.2 > m.0 {
            (r.2, r.0, r.1)
        } else {
            m
        }
    })
}

/// (name, unmasked, masked): the largest view angle (degrees) up to which the
/// albedo (diffraction + base, the energy form) is measured at most 1 at
/// every azimuth; the test asserts at least these. Measured at 500 nm
/// (largest albedo, at 89.9 deg, unmasked / masked; then the literal form's
/// limits, unmasked / masked):
/// - flat 18 um (sigma 3 um), window: 89.0 / 89.0 (6.90 / 6.90: no slopes,
///   Smith is off; 1.023 at 89.2); literal 88.0 / 88.0
/// - flat 18 um, tiled: 89.2 / 89.2 (4.70 / 4.70; 1.013 at 89.427); literal 88.5 / 88.5
/// - Elaphe-like 5 um, window: 87.0 / 89.9 (18.3 / max 0.52; 1.072 at 88);
///   literal 85.0 / 89.9
/// - Elaphe-like 5 um, tiled: 87.0 / 89.9 (16.7 / max 0.55; 1.179 at 88);
///   literal 80.0 / 89.9
/// - Xenopeltis-like 20 um, window: 87.0 / 89.6 (19.6 / 1.26, along the
///   ridges, whose rms slope along y is 0.019: masking does little; 1.065 at
///   89.7); literal 80.0 / 88.5
/// - Xenopeltis-like 20 um, tiled: 85.0 / 89.9 (18.2 / max 0.71; 1.027 at
///   87); literal 80.0 / 89.0
const HOLDS_UP_TO: [(&str, f64, f64); 6] = [
    ("flat 18 um (sigma 3 um), window", 89.0, 89.0),
    ("flat 18 um, tiled", 89.2, 89.2),
    ("Elaphe-like 5 um, window", 87.0, 89.9),
    ("Elaphe-like 5 um, tiled", 87.0, 89.9),
    ("Xenopeltis-like 20 um, window", 87.0, 89.6),
    ("Xenopeltis-like 20 um, tiled", 85.0, 89.9),
];

#[test]
fn directional_albedo_at_most_one() {
    let t0 = std::time::Instant::now();
    let fbar = one_minus_f_avg();
    let mat = Material::default();
    let flat = field(180, 180, 100e-9, 100e-9, |_, _| 2e-7); // 18 um: window sigma 3 um
    let small = elaphe(200, 25e-9); // 5 um
    let big = xenopeltis(640, 31.25e-9); // 20 um
    let cases = [
        make_case(HOLDS_UP_TO[0].0, &flat, Model::Window, vec![0.0]),
        make_case(HOLDS_UP_TO[1].0, &flat, Model::Tiled, vec![0.0]),
        make_case(HOLDS_UP_TO[2].0, &small, Model::Window, vec![0.0, 90.0]),
        make_case(HOLDS_UP_TO[3].0, &small, Model::Tiled, vec![0.0, 90.0]),
        make_case(HOLDS_UP_TO[4].0, &big, Model::Window, vec![0.0, 90.0]),
        make_case(HOLDS_UP_TO[5].0, &big, Model::Tiled, vec![0.0, 90.0]),
    ];
    println!("built in {:.1} s", t0.elapsed().as_secs_f64());
    println!(
        "directional albedo at {:.0} nm, n = 1.5 absolute, base {BASE}: \
         energy = diffraction + base (1 - F(theta_r)); literal = diffraction + base (1 - F_avg) = + {:.4}",
        LAMBDA * 1e9,
        BASE * fbar
    );
    let mut summary = vec![];
    let mut failures = vec![];
    for (case, &(name, want_u, want_m)) in cases.iter().zip(&HOLDS_UP_TO) {
        let t = std::time::Instant::now();
        let rows = measure(case);
        println!(
            "\n{} (rms slopes {:?}; {} views in {:.1} s)",
            case.name,
            case.pack.manifest.rms_slope,
            rows.len(),
            t.elapsed().as_secs_f64()
        );
        println!("  theta_r    az  diffraction   masked | energy  masked | literal masked");
        let (mut eu, mut em, mut lu, mut lm) = (vec![], vec![], vec![], vec![]);
        for &(th, az, a, m) in &rows {
            let base_e = BASE * mat.transmission(th.to_radians().cos());
            println!(
                "  {th:7.3} {az:5.0}  {a:10.4} {m:8.4} | {:6.3} {:6.3} | {:6.3} {:6.3}",
                a + base_e,
                m + base_e,
                a + BASE * fbar,
                m + BASE * fbar
            );
            eu.push((th, az, a + base_e));
            em.push((th, az, m + base_e));
            lu.push((th, az, a + BASE * fbar));
            lm.push((th, az, m + BASE * fbar));
        }
        if name.starts_with("flat") {
            // The furnace (PHYSICS.md 5 item 11): F(0) = 0.0400, F(60 deg) = 0.0892.
            for &(th, _, a, _) in rows.iter().filter(|r| r.0 == 0.0 || r.0 == 60.0) {
                let f = mat.fresnel(th.to_radians().cos());
                assert!(
                    (a / f - 1.0).abs() < 0.01,
                    "{name} at {th} deg: {a} vs F {f}"
                );
            }
        }
        if case.name == HOLDS_UP_TO[0].0 {
            // docs/LIGHTING.md "Energy: Kirchhoff's limit": 1.31 at cos 0.01, 11.9 at 1e-3.
            let at = |c: f64| diffraction_albedo(case, [(1.0 - c * c).sqrt(), 0.0, c]).0;
            println!(
                "  diffraction at cos(theta_r) 0.01: {:.3}, 1e-3: {:.2} (docs/LIGHTING.md: 1.31, 11.9)",
                at(0.01),
                at(1e-3)
            );
        }
        let (hu, hm) = (holds_up_to(&eu), holds_up_to(&em));
        let (mu, mm) = (max_of(&eu), max_of(&em));
        summary.push(format!(
            "{name:34} {:7.3} ({:6.3} {:3.0}) {:7.3} ({:6.3} {:3.0}) | {:6.3} {:6.3} | {:6.3} {:6.3}",
            mu.0,
            mu.1,
            mu.2,
            mm.0,
            mm.1,
            mm.2,
            hu,
            hm,
            holds_up_to(&lu),
            holds_up_to(&lm)
        ));
        if hu < want_u || hm < want_m {
            failures.push(format!(
                "{name}: albedo <= 1 up to {hu} deg unmasked (want {want_u}), {hm} deg masked (want {want_m})"
            ));
        }
    }
    println!("\nmaxima over views 0..89.9 deg (energy form; at theta, azimuth) and the largest view up to which albedo <= 1:");
    println!(
        "{:34} {:>23} {:>23} | {:>13} | {:>13}",
        "case", "max unmasked", "max masked", "<=1 up to u/m", "literal u/m"
    );
    for s in &summary {
        println!("{s}");
    }
    println!("total {:.1} s", t0.elapsed().as_secs_f64());
    assert!(failures.is_empty(), "{failures:#?}");
}

// ------------------------------------------------------ the energy bound

/// Wavelengths of the spectral check (midpoints over 380..780 nm).
const SPECTRAL: usize = 12;
/// Views of the spectral check (degrees): where the bound acts.
const BOUND_VIEWS: [f64; 3] = [88.0, 89.5, 89.9];

/// The diffraction term's albedo towards `wr` in linear sRGB under a white
/// furnace (D65 of luminance 1), (unmasked, masked), from the pack's `R_U`
/// per wavelength ([`SPECTRAL`] of them), not from the maps the bound's
/// tables come from: `XYZ = sum_l sum_nodes G R_U (A / l^2) D65 cmf wt /
/// sum_l D65 ybar`.
fn spectral_albedo(case: &Case, wr: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    use sunbeam_optics::{cie, colour};
    let mat = Material::default();
    let smith = Masking::smith(case.pack.manifest.rms_slope.unwrap_or([0.0, 0.0]));
    let dl = 400e-9 / SPECTRAL as f64;
    let lambdas: Vec<f64> = (0..SPECTRAL)
        .map(|i| 380e-9 + (i as f64 + 0.5) * dl)
        .collect();
    let norm: f64 = lambdas
        .iter()
        .map(|&l| cie::d65_at(l) * cie::cmf_at(l)[1])
        .sum();
    let weights: Vec<[f64; 3]> = lambdas
        .iter()
        .map(|&l| cie::cmf_at(l).map(|c| c * cie::d65_at(l) * case.area / (l * l) / norm))
        .collect();
    // Lobes are narrower at the shortest wavelength than at LAMBDA.
    let delta = case.delta * 380.0 / 500.0;
    let az0 = wr[1].atan2(wr[0]);
    let sums: Vec<[f64; 6]> = nodes(delta, wr[2], az0)
        .par_iter()
        .map(|group| {
            let mut s = [0.0; 6];
            for &(wi, wt) in group {
                let g = gain::g(wi, wr, mat) * wt;
                if g == 0.0 {
                    continue;
                }
                let m = smith.factor(wi, wr);
                for (&l, w) in lambdas.iter().zip(&weights) {
                    let r = case.pack.shading_reflectance(
                        -wi[0] - wr[0],
                        -wi[1] - wr[1],
                        -wi[2] - wr[2],
                        l,
                    );
                    for c in 0..3 {
                        s[c] += g * r * w[c];
                        s[3 + c] += g * m * r * w[c];
                    }
                }
            }
            s
        })
        .collect();
    let t = sums.iter().fold([0.0; 6], |mut a, b| {
        for i in 0..6 {
            a[i] += b[i];
        }
        a
    });
    (
        colour::xyz_to_linear_srgb([t[0], t[1], t[2]]),
        colour::xyz_to_linear_srgb([t[3], t[4], t[5]]),
    )
}

fn max3(v: [f64; 3]) -> f64 {
    v[0].max(v[1]).max(v[2])
}

/// The energy bound (sunbeam_optics::energy, sunbeam_response::energy): its
/// tables, built from the pack's white-furnace map as the pipeline builds
/// them, keep the diffraction term's albedo (largest linear-sRGB channel,
/// from the pack's `R_U` per wavelength, not the maps) at most 1 at the
/// grazing views where the unbounded term exceeds it, masked or not, both
/// models; and the tables' albedo is not below the truth's there.
#[test]
fn energy_bound_keeps_albedo_at_most_one() {
    let t0 = std::time::Instant::now();
    let flat = field(180, 180, 100e-9, 100e-9, |_, _| 2e-7);
    let small = elaphe(200, 25e-9);
    let big = xenopeltis(640, 31.25e-9);
    let cases = [
        make_case(HOLDS_UP_TO[0].0, &flat, Model::Window, vec![0.0]),
        make_case(HOLDS_UP_TO[3].0, &small, Model::Tiled, vec![0.0, 90.0]),
        make_case(HOLDS_UP_TO[4].0, &big, Model::Window, vec![0.0, 90.0]),
    ];
    let mut failures = vec![];
    for case in &cases {
        let t = std::time::Instant::now();
        let info = energy::EnergyInfo::from_pack(&case.pack, &sunbeam_response::Options::default());
        println!(
            "\n{}: tables (white map and quadrature) in {:.2} s; b unmasked {:?}",
            case.name,
            t.elapsed().as_secs_f64(),
            info.off
        );
        let mat = Material::default();
        for masked in [false, true] {
            let bound = info.bound(mat, masked);
            for &az in &case.azimuths {
                for &th in &BOUND_VIEWS {
                    let wr = view(th, az);
                    let (u, m) = spectral_albedo(case, wr);
                    let a = max3(if masked { m } else { u });
                    let f = bound.factor(wr[2]);
                    let table = bound.b_at(wr[2]) / wr[2];
                    println!(
                        "  {} {th:6.2} {az:4.0}: albedo {a:8.4}, table {table:8.4}, factor {f:.4}, bounded {:.4}",
                        if masked { "masked  " } else { "unmasked" },
                        a * f
                    );
                    if a * f > 1.03 {
                        failures.push(format!(
                            "{} {} at {th} deg, az {az}: bounded albedo {:.4}",
                            case.name,
                            if masked { "masked" } else { "unmasked" },
                            a * f
                        ));
                    }
                    if a > 1.0 && table < 0.97 * a {
                        failures.push(format!(
                            "{} at {th} deg, az {az}: the table's albedo {table:.4} is below the truth's {a:.4}",
                            case.name
                        ));
                    }
                }
            }
        }
        // Without the bound the term exceeds 1 at 89.9 deg (what the bound is for).
        let (u, _) = spectral_albedo(case, view(89.9, case.azimuths[0]));
        assert!(
            max3(u) > 1.5,
            "{}: unbounded albedo at 89.9 deg {u:?}",
            case.name
        );
    }
    println!("total {:.1} s", t0.elapsed().as_secs_f64());
    assert!(failures.is_empty(), "{failures:#?}");
}
