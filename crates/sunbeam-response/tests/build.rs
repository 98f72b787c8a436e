//! The response map against the pack's own CPU evaluator (`Pack::reflectance`,
//! a different code path: per-point coefficients, taps and sums in float64):
//! at texel centres the map must equal the colour sum to f16 rounding; the KTX2
//! file must round-trip; bad files must be refused.

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

fn check_centres(pack: &Pack, grid: Grid) {
    let o = Options {
        lambda_samples: 24,
        grid: Some(grid),
        ..Default::default()
    };
    let map = build(pack, &o);
    let lw = sunbeam_response::build::wavelength_weights(24);
    let mut worst: f64 = 0.0;
    let mut peak: f64 = 0.0;
    for k in [0, grid.n_s / 2, grid.n_s - 1] {
        for j in [0, 3, grid.n_rho / 3, grid.n_rho / 2, grid.n_rho - 2] {
            for i in [0, 7, grid.n_theta / 4 + 1, grid.n_theta - 1] {
                let (th, r, s) = (grid.theta_at(i), grid.r_at(j), grid.s_at(k));
                let w = -s * (4.0 - r * r).max(0.0).sqrt();
                let (u, v) = (r * th.cos(), r * th.sin());
                let mut want = [0.0; 3];
                for (l, wt) in &lw {
                    let rr = pack.reflectance(u, v, w, *l);
                    for c in 0..3 {
                        want[c] += rr * wt[c];
                    }
                }
                let got = map.lookup(u, v, w);
                for c in 0..3 {
                    worst = worst.max((got[c] - want[c]).abs() / want[c].abs().max(1e-3));
                    peak = peak.max(want[c]);
                }
            }
        }
    }
    assert!(peak > 1e-3, "the sampled points see no light (peak {peak})");
    // f16 storage: 2^-11 relative; f32 sums: ~1e-6.
    assert!(
        worst < 2e-3,
        "map vs Pack::reflectance: relative error {worst}"
    );
}

#[test]
fn window_map_equals_the_pack_at_texel_centres() {
    let pack = ridge_pack(Model::Window, 64, 40e-9);
    // Even: angles half a turn apart share their work (Hermitian terms); odd: each alone.
    for n_theta in [64, 63] {
        let grid = Grid {
            n_theta,
            n_rho: 24,
            n_s: 6,
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
            n_s: 5,
            r0: 0.02,
        };
        check_centres(&pack, grid);
    }
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
