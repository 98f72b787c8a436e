//! The ground truth against closed forms, Parseval, symmetry and an
//! independent naive implementation of PHYSICS.md 2.
use std::f64::consts::PI;
use sunbeam_field::HeightField;
use sunbeam_optics::truth::{Model, Params, Truth};
use sunbeam_optics::{cie, colour};

fn field(w: usize, h: usize, dx: f64, dy: f64, f: impl Fn(usize, usize) -> f64) -> HeightField {
    let data = (0..h)
        .flat_map(|r| (0..w).map(move |c| (r, c)))
        .map(|(r, c)| f(r, c))
        .collect();
    HeightField::new(w, h, dx, dy, data).unwrap()
}

/// A deterministic pseudo-random rough surface (the project's seeded
/// `SplitMix64`), heights in [0, amp].
fn rough(w: usize, h: usize, dx: f64, dy: f64, amp: f64, seed: u64) -> HeightField {
    let mut rng = sunbeam_common::rng::SplitMix64::new(seed);
    let data: Vec<f64> = (0..w * h).map(|_| amp * rng.unit()).collect();
    HeightField::new(w, h, dx, dy, data).unwrap()
}

fn params(model: Model) -> Params {
    Params {
        model,
        coherence_m: 65e-6,
    }
}

#[test]
fn flat_patch_specular_is_one_at_any_offset() {
    for model in [Model::Window, Model::Tiled] {
        for offset in [0.0, 1e-7, -3.3e-6, 1.0] {
            let f = field(17, 9, 50e-9, 70e-9, |_, _| offset);
            let t = Truth::new(&f, &params(model)).unwrap();
            for (w, l) in [(-2.0, 380e-9), (-1.3, 555e-9), (-0.2, 780e-9)] {
                let r = t.reflectance(0.0, 0.0, w, l);
                assert!((r - 1.0).abs() < 1e-12, "{model}: R = {r}");
            }
        }
    }
}

#[test]
fn flat_mirror_normal_incidence_is_d65_white() {
    for model in [Model::Window, Model::Tiled] {
        let f = field(8, 8, 40e-9, 40e-9, |_, _| 2e-7);
        let t = Truth::new(&f, &params(model)).unwrap();
        let xyz = t.colour_xyz([0.0, 0.0, 1.0], [0.0, 0.0, 1.0]);
        let white = cie::d65_white_xyz(cie::DEFAULT_RANGE_NM);
        assert!((xyz[1] - 1.0).abs() < 1e-12, "Y = {}", xyz[1]);
        for i in 0..3 {
            assert!((xyz[i] - white[i]).abs() < 1e-12);
        }
        // ... which is the D65 white of CIELAB to within table rounding.
        let de = colour::ciede2000_xyz(xyz, colour::D65_WHITE);
        assert!(de < 0.05, "dE00 = {de}");
        let rgb = colour::xyz_to_linear_srgb(xyz);
        for c in rgb {
            assert!((c - 1.0).abs() < 2e-3, "{rgb:?}");
        }
    }
}

#[test]
fn parseval_window_model() {
    // Over the full DFT (f = b/L for every bin), sum R = M sum g^2 / (sum g)^2, M = Mx My.
    let (mx, my, dx, dy) = (12, 10, 60e-9, 45e-9);
    let f = rough(mx, my, dx, dy, 400e-9, 7);
    let t = Truth::new(&f, &params(Model::Window)).unwrap();
    let (lx, ly) = (mx as f64 * dx, my as f64 * dy);
    let sigma = t.window_sigma_m();
    let g = |c: usize, r: usize| {
        let x = (c as f64 - 0.5 * (mx as f64 - 1.0)) * dx;
        let y = (r as f64 - 0.5 * (my as f64 - 1.0)) * dy;
        (-(x * x + y * y) / (2.0 * sigma * sigma)).exp()
    };
    let (mut sg, mut sg2) = (0.0, 0.0);
    for r in 0..my {
        for c in 0..mx {
            sg += g(c, r);
            sg2 += g(c, r).powi(2);
        }
    }
    let want = (mx * my) as f64 * sg2 / (sg * sg);
    for kw in [0.0, 1.7e7, -3.1e7] {
        let mut sum = 0.0;
        for by in 0..my {
            for bx in 0..mx {
                sum += t.reflectance_at_frequency(bx as f64 / lx, by as f64 / ly, kw);
            }
        }
        assert!(
            (sum - want).abs() < 1e-10 * want,
            "kw {kw}: {sum} vs {want}"
        );
    }
}

#[test]
fn parseval_tiled_model() {
    // With phi = 1 exactly at the bins, sum over the bins of R = 1 (unitary DFT).
    let (mx, my, dx, dy) = (9, 6, 80e-9, 50e-9);
    let f = rough(mx, my, dx, dy, 300e-9, 11);
    let t = Truth::new(&f, &params(Model::Tiled)).unwrap();
    let (lx, ly) = (mx as f64 * dx, my as f64 * dy);
    let mut sum = 0.0;
    for by in -(my as i64 / 2)..(my as i64 - my as i64 / 2) {
        for bx in -(mx as i64 / 2)..(mx as i64 - mx as i64 / 2) {
            sum += t.reflectance_at_frequency(bx as f64 / lx, by as f64 / ly, 2.3e7);
        }
    }
    assert!((sum - 1.0).abs() < 1e-12, "{sum}");
}

#[test]
fn symmetry_f_minus_t() {
    let f = rough(11, 7, 55e-9, 65e-9, 500e-9, 3);
    for model in [Model::Window, Model::Tiled] {
        let t = Truth::new(&f, &params(model)).unwrap();
        let (lx, ly) = (11.0 * 55e-9, 7.0 * 65e-9);
        for (fx, fy, kw) in [
            (0.37e6, -1.1e6, 2.0e7),
            (1.0 / lx, 2.0 / ly, -1.3e7),
            (-2.5e6, 0.3e6, 4.4e7),
        ] {
            let a = t.reflectance_at_frequency(fx, fy, -kw);
            let b = t.reflectance_at_frequency(-fx, -fy, kw);
            assert!(
                (a - b).abs() < 1e-12 * (1.0 + a.abs()),
                "{model}: {a} vs {b}"
            );
        }
    }
}

/// The independent reference: PHYSICS.md 2 written out naively, pixel by pixel,
/// with its own window and its own coordinate conventions, complex numbers as pairs.
fn naive(
    f: &HeightField,
    model: Model,
    coherence: f64,
    u: f64,
    v: f64,
    w: f64,
    lambda: f64,
) -> f64 {
    let (mx, my) = (f.width, f.height);
    let k = 2.0 * PI / lambda;
    let fx = -u / lambda;
    let fy = -v / lambda;
    match model {
        Model::Window => {
            let lmin = (mx as f64 * f.dx).min(my as f64 * f.dy);
            let sigma = (coherence / (4.0 * std::f64::consts::SQRT_2)).min(lmin / 6.0);
            let xc = (mx as f64 - 1.0) * f.dx / 2.0;
            let yc = (my as f64 - 1.0) * f.dy / 2.0;
            let (mut re, mut im, mut gs) = (0.0, 0.0, 0.0);
            for r in 0..my {
                for c in 0..mx {
                    let x = c as f64 * f.dx - xc;
                    let y = (my - 1 - r) as f64 * f.dy - yc;
                    let g = (-(x * x + y * y) / (2.0 * sigma * sigma)).exp();
                    let ph = k * w * f.data[r * mx + c] - 2.0 * PI * (fx * x + fy * y);
                    re += g * ph.cos();
                    im += g * ph.sin();
                    gs += g;
                }
            }
            (re * re + im * im) / (gs * gs)
        }
        Model::Tiled => {
            let sigma_f = 1.0 / (2.0 * PI * coherence / 4.0);
            let (lx, ly) = (mx as f64 * f.dx, my as f64 * f.dy);
            let mut total = 0.0;
            for by in 0..my as i64 {
                let by = if by >= my as i64 - my as i64 / 2 {
                    by - my as i64
                } else {
                    by
                };
                for bx in 0..mx as i64 {
                    let bx = if bx >= mx as i64 - mx as i64 / 2 {
                        bx - mx as i64
                    } else {
                        bx
                    };
                    let (mut re, mut im) = (0.0, 0.0);
                    for r in 0..my {
                        for c in 0..mx {
                            let jy = (my - 1 - r) as f64;
                            let ph = k * w * f.data[r * mx + c]
                                - 2.0
                                    * PI
                                    * (bx as f64 * c as f64 / mx as f64
                                        + by as f64 * jy / my as f64);
                            re += ph.cos();
                            im += ph.sin();
                        }
                    }
                    let d2 = (fx - bx as f64 / lx).powi(2) + (fy - by as f64 / ly).powi(2);
                    total += (re * re + im * im) * (-d2 / (2.0 * sigma_f * sigma_f)).exp();
                }
            }
            total / ((mx * my) as f64).powi(2)
        }
    }
}

#[test]
fn agrees_with_naive_independent_sum() {
    // Tiny fields, non-square pixels and patches, continuous heights (no level table)
    // and 8-bit-like heights (level table); a short coherence so the tiled model's
    // broadening spans several bins.
    let fields = [
        rough(7, 5, 60e-9, 85e-9, 450e-9, 5),
        field(6, 4, 100e-9, 100e-9, |r, c| {
            ((r * 7 + c * 3) % 5) as f64 * 50e-9
        }),
    ];
    let mut worst: f64 = 0.0;
    for f in &fields {
        for coherence in [65e-6, 2e-6] {
            for model in [Model::Window, Model::Tiled] {
                let t = Truth::new(
                    f,
                    &Params {
                        model,
                        coherence_m: coherence,
                    },
                )
                .unwrap();
                for (i, (u, v, w, l)) in [
                    (0.0, 0.0, -2.0, 380e-9),
                    (0.3, -0.1, -1.2, 500e-9),
                    (-0.9, 0.4, -0.6, 650e-9),
                    (1.2, 0.9, -1.7, 780e-9),
                    (0.05, -1.3, -0.9, 420e-9),
                ]
                .into_iter()
                .enumerate()
                {
                    let a = t.reflectance(u, v, w, l);
                    let b = naive(f, model, coherence, u, v, w, l);
                    worst = worst.max((a - b).abs());
                    assert!(
                        (a - b).abs() < 1e-9,
                        "{model} coh {coherence} point {i}: {a} vs {b}"
                    );
                }
            }
        }
    }
    eprintln!("worst |dR| vs naive: {worst:e}");
}

#[test]
fn bad_input_is_refused() {
    let mut f = field(3, 3, 1e-8, 1e-8, |_, _| 0.0);
    f.data[4] = f64::NAN;
    let e = Truth::new(&f, &Params::default()).unwrap_err();
    assert!(e.message.contains("non-finite"), "{}", e.message);
    let f = field(3, 3, 1e-8, 1e-8, |_, _| 0.0);
    assert!(Truth::new(
        &f,
        &Params {
            model: Model::Window,
            coherence_m: 0.0
        }
    )
    .is_err());
    let t = Truth::new(&f, &Params::default()).unwrap();
    assert!(t.reflectance(0.0, 0.0, -1.0, 0.0).is_nan());
    assert!(t.reflectance(f64::NAN, 0.0, -1.0, 5e-7).is_nan());
}

#[test]
fn sinusoidal_grating_orders() {
    // A sinusoidal grating h = a sin(2 pi x / d) puts |J_m(k w a)|^2 into order m
    // (exact for a whole number of periods in the tiled model at the bins).
    let (n, per) = (96usize, 24usize);
    let dx = 50e-9;
    let d = per as f64 * dx;
    let a = 120e-9;
    let f = field(n, 4, dx, dx, |_, c| {
        a * (2.0 * PI * c as f64 / per as f64).sin()
    });
    let t = Truth::new(&f, &params(Model::Tiled)).unwrap();
    let kw = -2.0 * PI / 500e-9 * 1.5;
    let j = |m: i32, x: f64| {
        // Bessel J_m by its integral, midpoint rule (exact to ~1e-15 for smooth periodic integrands).
        let nq = 2000;
        (0..nq)
            .map(|i| {
                let th = (i as f64 + 0.5) * 2.0 * PI / nq as f64;
                (m as f64 * th - x * th.sin()).cos()
            })
            .sum::<f64>()
            / nq as f64
    };
    for m in -3..=3 {
        let r = t.reflectance_at_frequency(m as f64 / d, 0.0, kw);
        let want = j(m, kw * a).powi(2);
        assert!((r - want).abs() < 1e-9, "order {m}: {r} vs {want}");
    }
}
