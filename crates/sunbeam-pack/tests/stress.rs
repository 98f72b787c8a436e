//! Stress: extreme |t|, degenerate and odd-shaped fields, hostile files.

mod common;
use common::*;
use sunbeam_optics::truth::{Params, Truth};
use sunbeam_pack::build::{BuildOptions, FieldRef};
use sunbeam_pack::{ktx2, Basis, Pack};

fn check_vs_truth(f: &sunbeam_field::HeightField, p: &Pack, n: usize, seed: u64) -> f64 {
    let t = Truth::new(f, &Params::default()).unwrap();
    let mut rng = Rng(seed);
    let mut worst = 0.0f64;
    for _ in 0..n {
        let (u, v, w, l) = random_query(&mut rng, 85.0);
        let a = p.reflectance(u, v, w, l);
        assert!(a.is_finite() && a >= 0.0);
        worst = worst.max((a - t.reflectance(u, v, w, l)).abs());
    }
    worst
}

#[test]
fn t_from_0_1_to_60() {
    // t_max = 4 pi H / 380 nm: H from ~3 nm to ~1.8 um.
    for &t_max in &[0.1, 3.0, 20.0, 60.0] {
        let h = t_max * 380e-9 / (4.0 * std::f64::consts::PI);
        let f = rough(20, 18, 25e-9, 25e-9, 2.0 * h, 3);
        let p = build(&f, &BuildOptions::default());
        assert!((p.manifest.t_max - t_max).abs() < 1e-6 * t_max.max(1.0));
        assert!(p.terms.iter().all(|v| v.is_finite()));
        let worst = check_vs_truth(&f, &p, 60, 5);
        assert!(
            worst <= 1e-3,
            "|t| = {t_max}: N = {}, max|dR| = {worst:e}",
            p.manifest.terms
        );
    }
}

#[test]
fn constant_field_and_single_pixel() {
    let f = field(17, 9, 20e-9, 20e-9, |_, _| 123e-9);
    let p = build(&f, &BuildOptions::default());
    assert_eq!(p.manifest.terms, 1);
    assert_eq!(p.manifest.height_half_range_m, 0.0);
    assert!((p.reflectance(0.0, 0.0, -2.0, 400e-9) - 1.0).abs() < 5e-5);
    assert!(check_vs_truth(&f, &p, 40, 1) <= 1e-3);

    let one = field(1, 1, 30e-9, 30e-9, |_, _| 5e-9);
    let p = build(&one, &BuildOptions::default());
    // A single sample scatters evenly: R = 1 in every direction.
    let mut rng = Rng(8);
    for _ in 0..50 {
        let (u, v, w, l) = random_query(&mut rng, 89.0);
        let r = p.reflectance(u, v, w, l);
        assert!((r - 1.0).abs() < 5e-5, "1x1: R = {r}");
    }
}

#[test]
fn thin_fields_3x1000_and_1000x3() {
    for (w, h) in [(3usize, 1000usize), (1000, 3)] {
        let f = rough(w, h, 25e-9, 25e-9, 200e-9, 13);
        let p = build(&f, &BuildOptions::default());
        let worst = check_vs_truth(&f, &p, 40, 9);
        assert!(worst <= 1e-3, "{w}x{h}: {worst:e}");
    }
}

#[test]
fn non_square_pixels_both_bases() {
    let f = rough(30, 24, 15e-9, 27e-9, 300e-9, 31);
    for basis in [Basis::Chebyshev, Basis::Taylor] {
        let p = build(
            &f,
            &BuildOptions {
                basis,
                ..BuildOptions::default()
            },
        );
        let worst = check_vs_truth(&f, &p, 80, 2);
        assert!(worst <= 1e-3, "{basis:?}: {worst:e}");
    }
}

#[test]
fn nan_heights_are_refused_with_a_fix() {
    let mut f = rough(8, 8, 25e-9, 25e-9, 100e-9, 1);
    f.data[10] = f64::NAN;
    let fr = FieldRef {
        width: 8,
        height: 8,
        dx: f.dx,
        dy: f.dy,
        data: &f.data,
    };
    let e = sunbeam_pack::build(fr, &BuildOptions::default(), &mut |_, _| {}).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(e.message.contains("--fill-nonfinite"), "{}", e.message);
}

#[test]
fn no_nan_or_inf_reaches_a_pack() {
    let f = rough(8, 8, 25e-9, 25e-9, 100e-9, 1);
    let mut p = build(&f, &BuildOptions::default());
    p.terms[3] = f32::INFINITY;
    assert!(Pack::new(p.manifest.clone(), p.terms.clone()).is_err());
    // A file carrying NaN is refused on reading.
    p.terms[3] = f32::NAN;
    let bytes = ktx2::encode(&p, "test");
    assert!(Pack::from_bytes(&bytes).is_err());
}

#[test]
fn hostile_headers_are_refused_without_allocating() {
    let f = rough(8, 8, 25e-9, 25e-9, 100e-9, 1);
    let p = build(&f, &BuildOptions::default());
    let good = ktx2::encode(&p, "test");
    assert!(Pack::from_bytes(&good).is_ok());
    // Huge width/height/layers in the header.
    for off in [20usize, 24, 32] {
        let mut b = good.clone();
        b[off..off + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(Pack::from_bytes(&b).is_err(), "offset {off}");
    }
    // Level byteLength / key-value length pointing far past the end.
    for off in [88usize, 60] {
        let mut b = good.clone();
        b[off..off + 4].copy_from_slice(&0x7fff_fff0u32.to_le_bytes());
        assert!(Pack::from_bytes(&b).is_err(), "offset {off}");
    }
    // Truncations anywhere.
    for cut in [0usize, 11, 50, 100, good.len() / 2, good.len() - 1] {
        assert!(Pack::from_bytes(&good[..cut]).is_err(), "cut {cut}");
    }
    // A manifest claiming absurd sizes.
    let mut m = p.manifest.clone();
    m.crop.kx = 1 << 40;
    assert!(m.validate().is_err());
    // EXR: garbage after the magic number.
    let mut e = vec![0x76, 0x2f, 0x31, 0x01];
    e.extend(std::iter::repeat_n(0xffu8, 64));
    assert!(Pack::from_bytes(&e).is_err());
}

#[test]
fn tiled_model_on_a_large_patch_with_a_wide_gaussian() {
    // L = 61 um: sigma_f L ~ 0.6 bins, so the Gaussian spans several bins (more taps).
    let f = rough(244, 244, 250e-9, 250e-9, 150e-9, 77);
    let o = BuildOptions {
        model: sunbeam_pack::Model::Tiled,
        ..BuildOptions::default()
    };
    let p = build(&f, &o);
    assert!(
        p.manifest.kernel.taps >= 8,
        "taps {}",
        p.manifest.kernel.taps
    );
    let t = Truth::new(
        &f,
        &Params {
            model: sunbeam_optics::truth::Model::Tiled,
            coherence_m: 65e-6,
        },
    )
    .unwrap();
    let mut rng = Rng(12);
    let mut worst = 0.0f64;
    for i in 0..60 {
        let (u, v, w, l) = if i < 20 {
            // near specular, where the strong low orders are
            (
                rng.range(-0.02, 0.02),
                rng.range(-0.02, 0.02),
                -1.8,
                rng.range(380e-9, 780e-9),
            )
        } else {
            random_query(&mut rng, 80.0)
        };
        worst = worst.max((p.reflectance(u, v, w, l) - t.reflectance(u, v, w, l)).abs());
    }
    assert!(worst <= 1e-3, "tiled large patch: {worst:e}");
}

#[test]
fn float32_evaluator_matches_the_float64_one() {
    // The shader-style f32 path (docs/PACK_FORMAT.md step by step) against the f64 reference.
    for model in [sunbeam_pack::Model::Window, sunbeam_pack::Model::Tiled] {
        let f = rough(40, 36, 25e-9, 25e-9, 800e-9, 5);
        let p = build(
            &f,
            &BuildOptions {
                model,
                ..BuildOptions::default()
            },
        );
        let mut rng = Rng(31);
        let mut worst = 0.0f64;
        for _ in 0..300 {
            let (u, v, w, l) = random_query(&mut rng, 85.0);
            let a = p.reflectance(u, v, w, l);
            let b = p.reflectance_f32(u as f32, v as f32, w as f32, l as f32) as f64;
            worst = worst.max((a - b).abs());
        }
        assert!(
            worst < 1e-5,
            "{model:?}: f32 evaluator differs by {worst:e}"
        );
    }
}
