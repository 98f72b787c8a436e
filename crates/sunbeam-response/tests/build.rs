//! The response map against the pack's own CPU evaluator
//! (`Pack::shading_reflectance`, a different code path: per-point
//! coefficients, taps and sums in float64, the window's grazing term from
//! its own kernel-derivative taps): at texel centres the map must equal the
//! colour sum to f16 rounding, at grazing texels too; the KTX2 file must
//! round-trip; bad files must be refused.

use sunbeam_optics::cie;
use sunbeam_pack::build::{BuildOptions, FieldRef};
use sunbeam_pack::{Model, Pack};
use sunbeam_response::{build, ktx2, Grid, Options};

fn ridge_pack(model: Model, size: usize, pixel: f64) -> Pack {
    let f = sunbeam_synth::preset("xenopeltis", size, pixel).unwrap();
    let opts = BuildOptions {
        model,
        ..Default::default()
    };
    let r = FieldRef {
        width: f.width,
        height: f.height,
        dx: f.dx,
        dy: f.dy,
        data: &f.data,
    };
    sunbeam_pack::build::build(r, &opts, &mut |_, _| {}).unwrap()
}

/// The map's wavelength samples at 1 nm: 400 midpoints, 380.5 .. 779.5 nm.
const ONE_NM: usize = 400;

/// XYZ of `R_shading(l)` summed at the 1 nm midpoints with D65 and the CIE
/// 1931 observer, normalised by the same sum of `D65 ybar`: written out here,
/// not through `build::wavelength_weights`.
fn colour_1nm(r: impl Fn(f64) -> f64) -> [f64; 3] {
    let (mut xyz, mut norm) = ([0.0; 3], 0.0);
    for n in 0..ONE_NM {
        let l = (380.5 + n as f64) * 1e-9;
        let (s, c) = (cie::d65_at(l), cie::cmf_at(l));
        let rr = r(l);
        for a in 0..3 {
            xyz[a] += rr * s * c[a];
        }
        norm += s * c[1];
    }
    xyz.map(|v| v / norm)
}

/// The texel `(i, j, k)`'s direction from the grid's definition (lib docs:
/// `theta = 2 pi i / n_theta`, `r = r0 sinh(rho asinh(2 / r0))` with `rho =
/// j / (n_rho - 1)`, `w = -s sqrt(4 - r^2)` with `s = k / (n_s - 1)`),
/// computed here, not by the grid's own `theta_at`/`r_at`/`s_at`.
fn texel_uvw(g: &Grid, i: usize, j: usize, k: usize) -> [f64; 3] {
    let th = 2.0 * std::f64::consts::PI * i as f64 / g.n_theta as f64;
    let rho = j as f64 / (g.n_rho - 1) as f64;
    let r = (g.r0 * (rho * (2.0 / g.r0).asinh()).sinh()).min(2.0);
    let s = k as f64 / (g.n_s - 1) as f64;
    [
        r * th.cos(),
        r * th.sin(),
        -s * (4.0 - r * r).max(0.0).sqrt(),
    ]
}

/// The map's texels at a spread of angles (both of a mirrored pair), radii
/// and `s` (the three smallest `|w|` of the grid among them, `w = 0` the
/// horizon pair) against the pack's `shading_reflectance` summed at 1 nm:
/// relative error (to `max(|want|, 1e-3)`) below 2e-3. Measured: 4.6e-4 /
/// 7.9e-4 (window, 64 / 63 angles; the worst at `w = 0`, where `R_U` is 1e-3
/// of `R`), 4.2e-4 (tiled).
fn check_centres(pack: &Pack, grid: Grid) {
    let o = Options {
        lambda_samples: ONE_NM,
        grid: Some(grid),
        ..Default::default()
    };
    let map = build(pack, &o);
    let (mut worst, mut worst_grazing, mut peak, mut peak_grazing) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let nt = grid.n_theta;
    for k in [0, 1, 2, grid.n_s / 2, grid.n_s - 1] {
        for j in [0, 3, grid.n_rho / 3, grid.n_rho / 2, grid.n_rho - 2] {
            for i in [0, 7, nt / 2 + 7, nt / 4 + 1, nt - 1] {
                let [u, v, w] = texel_uvw(&grid, i, j, k);
                let want = colour_1nm(|l| pack.shading_reflectance(u, v, w, l));
                let got = map.texel(i, j, k);
                for c in 0..3 {
                    let e = (got[c] - want[c]).abs() / want[c].abs().max(1e-3);
                    worst = worst.max(e);
                    peak = peak.max(want[c]);
                    if w.abs() < 0.2 {
                        worst_grazing = worst_grazing.max(e);
                        peak_grazing = peak_grazing.max(want[c]);
                    }
                }
            }
        }
    }
    eprintln!(
        "{:?} n_theta {nt}: worst {worst:.2e} (|w| < 0.2: {worst_grazing:.2e}), peak {peak:.3} (|w| < 0.2: {peak_grazing:.3})",
        pack.manifest.model
    );
    assert!(peak > 1e-3, "the sampled points see no light (peak {peak})");
    assert!(
        peak_grazing > 1e-3,
        "the grazing points see no light (peak {peak_grazing})"
    );
    // f16 storage: 2^-11 relative; f32 sums: ~1e-6.
    assert!(
        worst < 2e-3,
        "map vs Pack::shading_reflectance: relative error {worst}"
    );
}

#[test]
fn window_map_equals_the_pack_at_texel_centres() {
    let pack = ridge_pack(Model::Window, 64, 40e-9);
    // Even: angles half a turn apart share their work (Hermitian terms); odd: each alone.
    // n_s 41: |w| of the three smallest layers 0, 0.05 and 0.1 at r = 0.
    for n_theta in [64, 63] {
        let grid = Grid {
            n_theta,
            n_rho: 24,
            n_s: 41,
            r0: 0.02,
        };
        check_centres(&pack, grid);
    }
}

#[test]
fn tiled_map_equals_the_pack_at_texel_centres() {
    let pack = ridge_pack(Model::Tiled, 48, 40e-9);
    for n_theta in [32, 31] {
        let grid = Grid {
            n_theta,
            n_rho: 16,
            n_s: 21,
            r0: 0.02,
        };
        check_centres(&pack, grid);
    }
}

/// The window map holds `R_U`, not `R`: at a grazing texel of the ridge
/// pack's specular lobe the two differ by far more than the map's precision
/// (so the comparison above could not pass with `R`).
#[test]
fn window_map_holds_the_grazing_term() {
    let pack = ridge_pack(Model::Window, 64, 40e-9);
    let grid = Grid {
        n_theta: 64,
        n_rho: 24,
        n_s: 41,
        r0: 0.02,
    };
    let map = build(
        &pack,
        &Options {
            lambda_samples: ONE_NM,
            grid: Some(grid),
            ..Default::default()
        },
    );
    assert!(map.info.quantity.contains("R_U"), "{}", map.info.quantity);
    let (i, j, k) = (0, 3, 1);
    let [u, v, w] = texel_uvw(&grid, i, j, k);
    let ru = colour_1nm(|l| pack.shading_reflectance(u, v, w, l))[1];
    let r = colour_1nm(|l| pack.reflectance(u, v, w, l))[1];
    let got = map.texel(i, j, k)[1];
    eprintln!("texel ({i}, {j}, {k}) at w = {w:.3}: map {got:.5}, R_U {ru:.5}, R {r:.5}");
    assert!((got / ru - 1.0).abs() < 2e-3 && (r / ru - 1.0).abs() > 0.05);
}

/// The same map whatever the thread count (rows and rays are independent
/// tasks, each texel's sum in a fixed order).
#[test]
fn map_does_not_depend_on_the_thread_count() {
    let pack = ridge_pack(Model::Window, 32, 40e-9);
    let o = Options {
        lambda_samples: 16,
        grid: Some(Grid {
            n_theta: 32,
            n_rho: 12,
            n_s: 6,
            r0: 0.02,
        }),
        ..Default::default()
    };
    let with = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| build(&pack, &o))
    };
    assert_eq!(with(1), with(3));
}

#[test]
fn flat_patch_is_white_at_specular() {
    let f = vec![1e-7; 32 * 32];
    let r = FieldRef {
        width: 32,
        height: 32,
        dx: 30e-9,
        dy: 30e-9,
        data: &f,
    };
    let pack = sunbeam_pack::build::build(r, &BuildOptions::default(), &mut |_, _| {}).unwrap();
    let map = build(&pack, &Options::default());
    let xyz = map.lookup(0.0, 0.0, -2.0);
    // D65 white with Y = 1 (PHYSICS.md 5.1), to f16 and interpolation floor.
    assert!((xyz[1] - 1.0).abs() < 2e-3, "Y at specular {}", xyz[1]);
    let white = sunbeam_optics::cie::d65_white_xyz(sunbeam_optics::cie::DEFAULT_RANGE_NM);
    for c in [0, 2] {
        assert!(
            (xyz[c] / xyz[1] - white[c] / white[1]).abs() < 5e-3,
            "chromaticity {xyz:?} vs D65 {white:?}"
        );
    }
}

#[test]
fn ktx2_round_trip_and_bad_files() {
    let pack = ridge_pack(Model::Window, 32, 40e-9);
    let o = Options {
        lambda_samples: 8,
        grid: Some(Grid {
            n_theta: 16,
            n_rho: 8,
            n_s: 4,
            r0: 0.02,
        }),
        ..Default::default()
    };
    let map = build(&pack, &o);
    let bytes = ktx2::encode(&map);
    assert_eq!(bytes, ktx2::encode(&build(&pack, &o)), "deterministic");
    let back = ktx2::decode(&bytes).unwrap();
    assert_eq!(back, map);
    // Truncated, wrong identifier, garbled sizes: errors, no panic.
    for cut in [0, 11, 50, 100, bytes.len() - 1] {
        assert!(ktx2::decode(&bytes[..cut]).is_err(), "cut at {cut}");
    }
    let mut b = bytes.clone();
    b[0] = 0;
    assert!(ktx2::decode(&b).is_err());
    let mut b = bytes.clone();
    b[20..24].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(ktx2::decode(&b).is_err());
    // A NaN texel is refused.
    let mut b = bytes.clone();
    let n = b.len();
    b[n - 8..n - 6].copy_from_slice(&half::f16::NAN.to_bits().to_le_bytes());
    assert!(ktx2::decode(&b).is_err());
}

#[test]
fn exr_atlas_holds_the_same_texels() {
    use exr::prelude::*;
    let pack = ridge_pack(Model::Window, 32, 40e-9);
    let o = Options {
        lambda_samples: 8,
        grid: Some(Grid {
            n_theta: 16,
            n_rho: 8,
            n_s: 4,
            r0: 0.02,
        }),
        ..Default::default()
    };
    let map = build(&pack, &o);
    let bytes = sunbeam_response::exr::encode(&map).unwrap();
    assert_eq!(bytes, sunbeam_response::exr::encode(&map).unwrap());
    // Read with the exr crate's generic reader (not our writer's code).
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .unwrap();
    let layer = &img.layer_data;
    assert_eq!(layer.size, Vec2(16, 8 * 4));
    assert!(layer
        .attributes
        .other
        .contains_key(&Text::new_or_panic("sunbeam.response")));
    let chan = |name: &str| -> Vec<f32> {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name == Text::new_or_panic(name))
            .unwrap();
        c.sample_data.values_as_f32().collect()
    };
    let (r, g, b) = (chan("R"), chan("G"), chan("B"));
    for k in 0..4 {
        for j in 0..8 {
            for i in 0..16 {
                let t = map.texel(i, j, k);
                let p = (k * 8 + j) * 16 + i;
                assert_eq!(
                    [r[p] as f64, g[p] as f64, b[p] as f64],
                    t,
                    "texel {i} {j} {k}"
                );
            }
        }
    }
}
