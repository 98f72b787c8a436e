//! The radiometric factor of docs/LIGHTING.md, checked as a furnace test on
//! the float64 truth: under a constant environment of radiance 1, a flat patch
//! seen head-on reflects `integral G R (A / lambda^2) cos(theta_i) dw_i =
//! integral G R A d^2f`, which must equal the specular gain at normal incidence
//! (1, PHYSICS.md 2) within 1 %, for small and large patches and both models.
//! The integral is a plain quadrature over `f = wi_xy / lambda` (independent of
//! Parseval, which the factor itself comes from), with `G` at each `wi`.

use sunbeam_field::HeightField;
use sunbeam_optics::gain;
use sunbeam_optics::truth::{Model, Params, Truth};

/// `integral G R A d^2f` over a square of +-`half` around f = 0, `n` x `n` midpoints.
fn furnace(t: &Truth, lambda: f64, half: f64, n: usize) -> f64 {
    let a = t.coherent_area_m2();
    let h = 2.0 * half / n as f64;
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let fx = -half + (i as f64 + 0.5) * h;
            let fy = -half + (j as f64 + 0.5) * h;
            // wr = (0, 0, 1); f = (wi + wr)_xy / lambda = wi_xy / lambda.
            let (sx, sy) = (fx * lambda, fy * lambda);
            let s2 = sx * sx + sy * sy;
            if s2 >= 1.0 {
                continue;
            }
            let wi = [sx, sy, (1.0 - s2).sqrt()];
            let wr = [0.0, 0.0, 1.0];
            let (u, v, w) = (-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]);
            let r = t.reflectance(u, v, w, lambda);
            sum += gain::g(wi, wr, gain::Material::RELATIVE) * r * h * h;
        }
    }
    sum * a
}

fn flat(n: usize, dx: f64) -> HeightField {
    HeightField::new(n, n, dx, dx, vec![0.0; n * n]).unwrap()
}

#[test]
fn window_model_furnace_small_and_large_patches() {
    // 4 um (sigma = L/6 = 0.67 um: a wide lobe) and 40 um (sigma = 6.7 um).
    for (n, dx) in [(160, 25e-9), (200, 200e-9)] {
        let t = Truth::new(
            &flat(n, dx),
            &Params {
                model: Model::Window,
                coherence_m: 65e-6,
            },
        )
        .unwrap();
        // The lobe |G_x|^2 is a Gaussian of sigma_f = 1 / (2 sqrt 2 pi sigma): cover 7 of them.
        let sf = 1.0 / (2.0 * std::f64::consts::SQRT_2 * std::f64::consts::PI * t.window_sigma_m());
        for lambda in [400e-9, 700e-9] {
            let y = furnace(&t, lambda, 7.0 * sf, 60);
            eprintln!(
                "furnace {:?} {:.1} um {:.0} nm: {y:.5}",
                t.params().model,
                n_or_zero(&t),
                lambda * 1e9
            );
            assert!(
                (y - 1.0).abs() < 0.01,
                "window, {} um patch, {} nm: furnace {y}",
                n as f64 * dx * 1e6,
                lambda * 1e9
            );
        }
    }
}

#[test]
fn tiled_model_furnace() {
    for coherence in [20e-6, 65e-6] {
        let t = Truth::new(
            &flat(32, 50e-9),
            &Params {
                model: Model::Tiled,
                coherence_m: coherence,
            },
        )
        .unwrap();
        let sf = t.tiled_sigma_f();
        for lambda in [450e-9, 650e-9] {
            let y = furnace(&t, lambda, 7.0 * sf, 60);
            eprintln!(
                "furnace {:?} {:.1} um {:.0} nm: {y:.5}",
                t.params().model,
                n_or_zero(&t),
                lambda * 1e9
            );
            assert!(
                (y - 1.0).abs() < 0.01,
                "tiled, coherence {coherence}: furnace {y}"
            );
        }
    }
}

#[test]
fn the_factor_follows_parseval() {
    // A = (sum g)^2 / sum g^2 dx dy for a Gaussian window of sigma = L/6 cut
    // at +-3 sigma: per axis (sigma sqrt(2 pi) erf(3/sqrt 2))^2 / (sigma sqrt(pi) erf(3)),
    // so A = 4 pi sigma^2 (erf(3/sqrt 2)^2 / erf(3))^2 (erf(3/sqrt 2) = 0.9973002,
    // erf(3) = 0.9999779), less than the patch's area.
    let t = Truth::new(
        &flat(400, 100e-9),
        &Params {
            model: Model::Window,
            coherence_m: 65e-6,
        },
    )
    .unwrap();
    let s = t.window_sigma_m();
    let a = t.coherent_area_m2();
    let k = 0.997_300_2f64.powi(2) / 0.999_977_9;
    let want = 4.0 * std::f64::consts::PI * s * s * k * k;
    assert!((a / want - 1.0).abs() < 2e-3, "A {a} vs {want}");
    assert!(a < 40e-6 * 40e-6);
    // The manifest-only form (what renderers use) agrees with the truth's.
    let (mx, my, dx, dy) = t.grid();
    let from_manifest = sunbeam_optics::truth::window_coherent_area_m2(mx, my, dx, dy, s);
    assert!(
        (from_manifest / a - 1.0).abs() < 1e-12,
        "{from_manifest} vs {a}"
    );
    // Tiled: A = 2 pi (coherence / 4)^2.
    let t = Truth::new(
        &flat(32, 50e-9),
        &Params {
            model: Model::Tiled,
            coherence_m: 20e-6,
        },
    )
    .unwrap();
    let want = 2.0 * std::f64::consts::PI * 5e-6 * 5e-6;
    assert!((t.coherent_area_m2() / want - 1.0).abs() < 1e-9);
    let sigma_f = 1.0 / (2.0 * std::f64::consts::PI * 5e-6);
    let from_manifest = sunbeam_optics::truth::tiled_coherent_area_m2(sigma_f);
    assert!(
        (from_manifest / want - 1.0).abs() < 1e-9,
        "{from_manifest} vs {want}"
    );
}

/// Patch width in micrometres (for the log lines).
fn n_or_zero(t: &Truth) -> f64 {
    let (mx, _, dx, _) = t.grid();
    mx as f64 * dx * 1e6
}
