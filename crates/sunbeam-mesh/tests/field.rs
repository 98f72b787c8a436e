//! The orientation field: unit and tangent, samples reproduced, axial symmetry,
//! convergence on an analytic field, and the awkward inputs.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use serde_json::json;
use std::f64::consts::PI;
use sunbeam_mesh::bake::{bake, compute, BakeOptions, Work};
use sunbeam_mesh::geom::{cross, dot, norm};
use sunbeam_mesh::orient::{Curve, Interp, Sample, SampleAt, Samples, Source, UvAxis};
use sunbeam_mesh::snake::{self, SnakeParams};

/// Baked angle of vertex i from +u, counter-clockwise about n.
fn angle(w: &Work, i: usize) -> f64 {
    let d = w.dir[i].unwrap();
    let u = w.u_world.as_ref().unwrap()[i].unwrap();
    let n = w.n_world[i];
    dot(d, cross(n, u)).atan2(dot(d, u))
}

fn uv_samples(items: Vec<([f64; 2], f64)>) -> Source {
    Source::Samples(Samples {
        path: "test.csv".into(),
        items: items
            .into_iter()
            .enumerate()
            .map(|(k, (uv, a))| Sample {
                line: k + 2,
                at: SampleAt::Uv { uv, angle: a },
            })
            .collect(),
    })
}

fn small_snake() -> sunbeam_mesh::gltf::Document {
    snake::generate(&SnakeParams {
        rings: 80,
        segments: 16,
        ..Default::default()
    })
}

/// Every output vector, as stored (f32) in the GLB: unit, orthogonal to the stored normal, w = +-1.
fn check_stored(doc: &mut sunbeam_mesh::gltf::Document) {
    let glb = doc.to_glb();
    let back =
        sunbeam_mesh::gltf::Document::from_bytes(&glb, std::path::Path::new("out.glb")).unwrap();
    for (m, mesh) in back.array("meshes").iter().enumerate() {
        for (k, _) in mesh["primitives"].as_array().unwrap().iter().enumerate() {
            let p = sunbeam_mesh::nodes::read_primitive(&back, m, k, 0)
                .unwrap()
                .unwrap();
            let n = p.normals.unwrap();
            let t = p.tangents.unwrap();
            let o = p.orientation.unwrap();
            for i in 0..n.len() {
                let tt = [t[i][0], t[i][1], t[i][2]];
                assert!(
                    (norm(tt) - 1.0).abs() < 1e-5 && (norm(o[i]) - 1.0).abs() < 1e-5,
                    "not unit at {i}"
                );
                assert!(
                    dot(tt, n[i]).abs() < 1e-5 && dot(o[i], n[i]).abs() < 1e-5,
                    "not orthogonal at {i}: {}",
                    dot(o[i], n[i])
                );
                assert!(t[i][3] == 1.0 || t[i][3] == -1.0);
                assert!((norm(n[i]) - 1.0).abs() < 1e-5);
            }
        }
    }
}

#[test]
fn every_source_gives_unit_tangent_directions() {
    let sp = snake::spine(&SnakeParams {
        rings: 80,
        segments: 16,
        ..Default::default()
    });
    let curve = Curve::from_points(std::path::Path::new("spine"), sp).unwrap();
    let mut rng = Lcg(7);
    let samples: Vec<([f64; 2], f64)> = (0..200)
        .map(|_| ([rng.next(), rng.next()], rng.next() * 2.0 * PI))
        .collect();
    for (name, src) in [
        ("axis", Source::Axis([0.0, 0.0, 1.0])),
        ("curve", Source::Curve(curve)),
        ("uv-u", Source::UvDirection(UvAxis::U)),
        ("uv-v", Source::UvDirection(UvAxis::V)),
        ("samples", uv_samples(samples)),
    ] {
        let mut o = BakeOptions::new(src);
        o.rotate_deg = 30.0;
        let mut b = bake(small_snake(), &o).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_stored(&mut b.doc);
    }
}

#[test]
fn uv_direction_follows_u_and_rotation_turns_it() {
    let (pos, uv, idx) = grid(11, |x, y| 0.2 * x * y);
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    let mut o = BakeOptions::new(Source::UvDirection(UvAxis::U));
    o.rotate_deg = 40.0;
    let (w, _) = compute(&d, &o).unwrap();
    for i in 0..pos.len() {
        assert!((angle(&w[0], i) - 40f64.to_radians()).abs() < 1e-9);
    }
}

#[test]
fn samples_are_reproduced_at_their_own_positions() {
    // UV samples on a curved grid, at vertex positions: natural neighbour is exact there.
    let (pos, uv, idx) = grid(41, |x, y| 0.3 * (3.0 * x).sin() + 0.2 * y * y);
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    let mut rng = Lcg(11);
    let picks: Vec<usize> = (0..150)
        .map(|_| (rng.next() * pos.len() as f64) as usize)
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let angles: Vec<f64> = picks.iter().map(|_| (rng.next() - 0.5) * PI).collect();
    for interp in [Interp::Natural, Interp::Linear] {
        let mut o = BakeOptions::new(uv_samples(
            picks
                .iter()
                .zip(&angles)
                .map(|(&i, &a)| (uv[i], a))
                .collect(),
        ));
        o.interp = interp;
        let (w, r) = compute(&d, &o).unwrap();
        assert_eq!(r.samples.as_ref().unwrap().used, picks.len());
        for (&i, &a) in picks.iter().zip(&angles) {
            let e = axial_diff(angle(&w[0], i), a);
            assert!(e < 1e-4, "{interp:?}: vertex {i}: error {e} rad");
        }
    }
    // 3D samples placed on vertices of the snake (snapped with zero distance).
    let doc = small_snake();
    let (w0, _) = compute(&doc, &BakeOptions::new(Source::Axis([1.0, 0.0, 0.0]))).unwrap();
    let wk = &w0[0];
    let mut items = Vec::new();
    let mut want = Vec::new();
    for (k, i) in (0..wk.p_world.len()).step_by(37).enumerate() {
        let n = wk.n_world[i];
        let u = wk.u_world.as_ref().unwrap()[i].unwrap();
        let a = (k as f64 * 0.7).sin() * 1.4;
        let d = [
            u[0] * a.cos() + cross(n, u)[0] * a.sin() + 0.3 * n[0],
            u[1] * a.cos() + cross(n, u)[1] * a.sin() + 0.3 * n[1],
            u[2] * a.cos() + cross(n, u)[2] * a.sin() + 0.3 * n[2],
        ];
        items.push(Sample {
            line: k + 2,
            at: SampleAt::Xyz {
                p: wk.p_world[i],
                d,
            },
        });
        want.push((i, a));
    }
    let src = Source::Samples(Samples {
        path: "s.csv".into(),
        items,
    });
    let (w, r) = compute(&doc, &BakeOptions::new(src)).unwrap();
    let sr = r.samples.unwrap();
    assert!(sr.rejected.is_empty(), "{:?}", sr.rejected);
    for (i, a) in want {
        // The tips and the seam share positions between several vertices: skip those.
        let e = axial_diff(angle(&w[0], i), a);
        let shared = wk.p_world.iter().filter(|p| **p == wk.p_world[i]).count() > 1;
        if !shared {
            assert!(e < 1e-4, "vertex {i}: error {e} rad");
        }
    }
}

#[test]
fn opposite_directions_give_the_same_field() {
    let (pos, uv, idx) = grid(21, |_, _| 0.0);
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    let mut rng = Lcg(3);
    let s: Vec<([f64; 2], f64)> = (0..60)
        .map(|_| ([rng.next(), rng.next()], rng.next() * PI))
        .collect();
    let flipped: Vec<([f64; 2], f64)> = s
        .iter()
        .enumerate()
        .map(|(k, &(p, a))| (p, if k % 2 == 0 { a + PI } else { a - 3.0 * PI }))
        .collect();
    let (a, _) = compute(&d, &BakeOptions::new(uv_samples(s))).unwrap();
    let (b, _) = compute(&d, &BakeOptions::new(uv_samples(flipped))).unwrap();
    for i in 0..pos.len() {
        assert!(axial_diff(angle(&a[0], i), angle(&b[0], i)) < 1e-9);
    }
    // Raw vector averaging would cancel here; the doubled angle does not: two samples
    // at +x and -x give +x everywhere between them.
    let (c, _) = compute(
        &d,
        &BakeOptions::new(uv_samples(vec![
            ([0.0, 0.5], 0.0),
            ([1.0, 0.5], PI),
            ([0.5, 0.0], PI),
            ([0.5, 1.0], 0.0),
        ])),
    )
    .unwrap();
    for i in 0..pos.len() {
        assert!(axial_diff(angle(&c[0], i), 0.0) < 1e-9);
    }
}

/// The analytic field the convergence test samples.
fn field(u: f64, v: f64) -> f64 {
    0.8 * (2.5 * u).sin() + 0.6 * (2.0 * v + 0.3).cos() * u
}

/// (max, rms) axial error on the interior [0.1, 0.9]^2 for `n` random samples.
pub fn convergence_error(n: usize, interp: Interp) -> (f64, f64) {
    let (pos, uv, idx) = grid(101, |_, _| 0.0);
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    let mut rng = Lcg(1234);
    let s: Vec<([f64; 2], f64)> = (0..n)
        .map(|_| {
            let p = [rng.next(), rng.next()];
            (p, field(p[0], p[1]))
        })
        .collect();
    let mut o = BakeOptions::new(uv_samples(s));
    o.interp = interp;
    let (w, _) = compute(&d, &o).unwrap();
    let (mut mx, mut ss, mut cnt) = (0.0f64, 0.0, 0);
    for i in 0..pos.len() {
        let [u, v] = uv[i];
        if !(0.1..=0.9).contains(&u) || !(0.1..=0.9).contains(&v) {
            continue;
        }
        let e = axial_diff(angle(&w[0], i), field(u, v));
        mx = mx.max(e);
        ss += e * e;
        cnt += 1;
    }
    (mx, (ss / cnt as f64).sqrt())
}

#[test]
fn analytic_field_error_falls_with_sample_density() {
    for interp in [Interp::Natural, Interp::SibsonC1, Interp::Linear] {
        let mut prev = (f64::INFINITY, f64::INFINITY);
        for n in [100, 400, 1600, 6400] {
            let (mx, rms) = convergence_error(n, interp);
            println!("{interp:?} samples {n}: max {mx:.3e} rad, rms {rms:.3e} rad");
            assert!(
                rms < prev.1 * 0.6,
                "{interp:?}: rms {rms} did not fall enough from {}",
                prev.1
            );
            assert!(
                mx < prev.0,
                "{interp:?}: max {mx} did not fall from {}",
                prev.0
            );
            prev = (mx, rms);
        }
        if interp == Interp::SibsonC1 {
            // The C1 interpolant must beat plain natural neighbour on a smooth field.
            let (_, rms_nn) = convergence_error(6400, Interp::Natural);
            assert!(
                prev.1 < 0.5 * rms_nn,
                "Sibson C1 rms {} vs natural {rms_nn}",
                prev.1
            );
        }
        // Stated bound (docs/BAKE.md): with 6400 samples on the unit square, max error < 2e-3 rad.
        assert!(
            prev.0 < 2e-3,
            "{interp:?}: max error {} at 6400 samples",
            prev.0
        );
    }
}

#[test]
fn duplicate_collinear_and_single_samples() {
    let (pos, uv, idx) = grid(11, |_, _| 0.0);
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    // Duplicates: same position twice with d and -d merge into one sample; perpendicular
    // duplicates cancel and are dropped with a reason.
    let (w, r) = compute(
        &d,
        &BakeOptions::new(uv_samples(vec![
            ([0.2, 0.2], 0.3),
            ([0.2, 0.2], 0.3 + PI),
            ([0.8, 0.2], 0.3),
            ([0.5, 0.9], 0.3),
            ([0.5, 0.5], 0.0),
            ([0.5, 0.5], PI / 2.0),
        ])),
    )
    .unwrap();
    let sr = r.samples.unwrap();
    assert_eq!(sr.merged_duplicates, 2);
    assert_eq!(sr.used, 3);
    assert_eq!(sr.rejected.len(), 1, "{:?}", sr.rejected);
    for i in 0..pos.len() {
        assert!(axial_diff(angle(&w[0], i), 0.3) < 1e-9);
    }
    // Collinear: linear along the line, constant across it.
    let (w, r) = compute(
        &d,
        &BakeOptions::new(uv_samples(vec![
            ([0.0, 0.5], 0.0),
            ([0.5, 0.5], 0.4),
            ([1.0, 0.5], 0.8),
        ])),
    )
    .unwrap();
    assert!(!r.samples.unwrap().layout_notes.is_empty());
    for i in 0..pos.len() {
        let want = 0.8 * uv[i][0];
        assert!(
            axial_diff(angle(&w[0], i), want) < 0.02,
            "collinear: {} vs {want}",
            angle(&w[0], i)
        );
    }
    // Single sample: constant.
    let (w, _) = compute(&d, &BakeOptions::new(uv_samples(vec![([0.3, 0.3], 1.0)]))).unwrap();
    for i in 0..pos.len() {
        assert!(axial_diff(angle(&w[0], i), 1.0) < 1e-9);
    }
}

#[test]
fn off_surface_nan_and_missing_uvs() {
    let (pos, uv, idx) = grid(11, |_, _| 0.0);
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    let items = vec![
        Sample {
            line: 2,
            at: SampleAt::Xyz {
                p: [0.5, 0.5, 0.001],
                d: [1.0, 0.0, 0.0],
            },
        },
        Sample {
            line: 3,
            at: SampleAt::Xyz {
                p: [0.5, 0.5, 5.0],
                d: [1.0, 0.0, 0.0],
            },
        },
        Sample {
            line: 4,
            at: SampleAt::Xyz {
                p: [0.2, 0.5, 0.0],
                d: [0.0, 0.0, 1.0],
            },
        },
    ];
    let (_, r) = compute(
        &d,
        &BakeOptions::new(Source::Samples(Samples {
            path: "s.csv".into(),
            items,
        })),
    )
    .unwrap();
    let sr = r.samples.unwrap();
    let rows: Vec<usize> = sr.rejected.iter().map(|x| x.row).collect();
    assert_eq!(rows, vec![3, 4], "{:?}", sr.rejected);
    // All off the surface: an input error naming the samples file.
    let items = vec![Sample {
        line: 2,
        at: SampleAt::Xyz {
            p: [9.0, 9.0, 9.0],
            d: [1.0, 0.0, 0.0],
        },
    }];
    let e = compute(
        &d,
        &BakeOptions::new(Source::Samples(Samples {
            path: "far.csv".into(),
            items,
        })),
    )
    .err()
    .unwrap();
    assert_eq!(e.exit_code(), 2);
    assert!(e.message.contains("far.csv"));
    // NaN in a samples file: error naming file and row.
    let dir = tmpdir("nan");
    let f = dir.join("s.csv");
    std::fs::write(&f, "u,v,angle_deg\n0.1,0.2,30\n0.3,nan,10\n").unwrap();
    let e = Samples::load(&f).unwrap_err();
    assert!(
        e.message.contains("s.csv") && e.message.contains("row 3"),
        "{}",
        e.message
    );
    std::fs::write(&f, "a,b\n1,2\n").unwrap();
    assert_eq!(Samples::load(&f).unwrap_err().exit_code(), 2);
    std::fs::write(
        &f,
        "{\"samples\": [{\"x\": 0, \"y\": 0, \"z\": 0, \"dx\": 1, \"dy\": 0, \"dz\": 0}]}",
    )
    .unwrap();
    assert_eq!(Samples::load(&f).unwrap().items.len(), 1);
    // No UVs with a UV mode: input error naming the mesh file.
    let d2 = doc_from(&pos, None, None, &idx, json!({}));
    for src in [
        Source::UvDirection(UvAxis::U),
        uv_samples(vec![([0.5, 0.5], 0.0)]),
    ] {
        let e = compute(&d2, &BakeOptions::new(src)).err().unwrap();
        assert_eq!(e.exit_code(), 2);
        assert!(
            e.message.contains("test.glb") && e.message.contains("TEXCOORD_0"),
            "{}",
            e.message
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn degenerate_triangles_and_axis_along_the_normal() {
    // A grid with collapsed triangles, an unused vertex, and the axis along the normal.
    let (mut pos, mut uv, mut idx) = grid(5, |_, _| 0.0);
    pos.push([0.5, 0.5, 0.0]);
    uv.push([0.5, 0.5]);
    idx.extend_from_slice(&[0, 0, 1, 2, 2, 2, 3, 4, 3]);
    pos.push([7.0, 7.0, 7.0]); // used by no triangle
    uv.push([0.0, 0.0]);
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    let mut b = bake(d, &BakeOptions::new(Source::Axis([0.0, 0.0, 1.0]))).unwrap();
    assert!(b.report.degenerate_triangles >= 3);
    assert_eq!(
        b.report.without_direction.values().sum::<usize>(),
        pos.len()
    );
    assert_eq!(b.report.arbitrary, pos.len());
    check_stored(&mut b.doc);
    // A tilted axis: every vertex, the unused one included, gets the projection.
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    let b = bake(d, &BakeOptions::new(Source::Axis([1.0, 0.0, 1.0]))).unwrap();
    assert_eq!(b.report.arbitrary, 0);
}

#[test]
fn curve_nearest_point_matches_brute_force_and_is_projected() {
    let sp = snake::spine(&SnakeParams::default());
    let c = Curve::from_points(std::path::Path::new("spine"), sp).unwrap();
    let mut rng = Lcg(5);
    for _ in 0..2000 {
        let p = [
            rng.next() - 0.5,
            (rng.next() - 0.5) * 0.4,
            (rng.next() - 0.5) * 0.1,
        ];
        let (a, b) = (c.tangent_at(p), c.tangent_at_brute_force(p));
        assert!(
            norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]]) < 1e-9,
            "{a:?} vs {b:?}"
        );
    }
    // On the snake baked with its own spine, the direction runs along the body (+u) up to
    // the spine's curvature: within a few degrees of +u away from the tips.
    let (w, _) = compute(
        &small_snake(),
        &BakeOptions::new(Source::Curve(
            Curve::from_points(
                std::path::Path::new("s"),
                snake::spine(&SnakeParams {
                    rings: 80,
                    segments: 16,
                    ..Default::default()
                }),
            )
            .unwrap(),
        )),
    )
    .unwrap();
    let uv = w[0].local.uvs.as_ref().unwrap();
    for i in 0..uv.len() {
        if (0.1..0.9).contains(&uv[i][0]) {
            assert!(
                axial_diff(angle(&w[0], i), 0.0) < 0.1,
                "vertex {i} at u={}: {}",
                uv[i][0],
                angle(&w[0], i)
            );
        }
    }
}

#[test]
fn direction_map_png_and_exr() {
    use sunbeam_mesh::texture::{render, TextureOptions};
    // A grid covering UV [0.25, 0.75]^2, direction 30 degrees from +u everywhere.
    let (pos, uv, idx) = grid(6, |x, y| 0.1 * x * y);
    let uv: Vec<[f64; 2]> = uv
        .iter()
        .map(|q| [0.25 + 0.5 * q[0], 0.25 + 0.5 * q[1]])
        .collect();
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    let mut o = BakeOptions::new(Source::UvDirection(UvAxis::U));
    o.rotate_deg = 30.0;
    let (w, _) = compute(&d, &o).unwrap();
    let (c30, s30) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    // PNG
    let (bytes, rep) = render(
        &w,
        &TextureOptions {
            size: 64,
            dilate: 2,
            path: "d.png".into(),
        },
    )
    .unwrap();
    assert_eq!(rep["covered_texels"], 32 * 32);
    assert!(rep["dilated_texels"].as_u64().unwrap() > 0);
    let dec = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0u8; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.bit_depth), (64, png::BitDepth::Sixteen));
    let px = |x: usize, y: usize, c: usize| {
        u16::from_be_bytes([
            buf[(y * 64 + x) * 6 + 2 * c],
            buf[(y * 64 + x) * 6 + 2 * c + 1],
        ]) as f64
            / 65535.0
    };
    for (x, y) in [(32, 32), (17, 40), (46, 17)] {
        assert!(
            (px(x, y, 0) - (0.5 + 0.5 * c30)).abs() < 1e-4
                && (px(x, y, 1) - (0.5 + 0.5 * s30)).abs() < 1e-4
        );
        assert_eq!(px(x, y, 2), 1.0);
    }
    assert_eq!(px(2, 2, 2), 0.0, "far outside: empty");
    assert!(
        (px(15, 32, 2) - 0.5).abs() < 1e-4,
        "the first ring outside the island is dilated"
    );
    assert!(
        (px(15, 32, 0) - (0.5 + 0.5 * c30)).abs() < 1e-4,
        "with the island's direction"
    );
    // EXR
    let (bytes, _) = render(
        &w,
        &TextureOptions {
            size: 32,
            dilate: 0,
            path: "d.exr".into(),
        },
    )
    .unwrap();
    let img = exr::prelude::read_first_rgba_layer_from_file(
        {
            let f = std::env::temp_dir().join(format!("sb-dir-{}.exr", std::process::id()));
            std::fs::write(&f, &bytes).unwrap();
            f
        },
        |res, _| vec![vec![(0f32, 0f32, 0f32, 0f32); res.width()]; res.height()],
        |px: &mut Vec<Vec<(f32, f32, f32, f32)>>, p, (r, g, b, a): (f32, f32, f32, f32)| {
            px[p.y()][p.x()] = (r, g, b, a)
        },
    )
    .unwrap();
    let p = img.layer_data.channel_data.pixels[16][16];
    assert!(
        (p.0 as f64 - c30).abs() < 1e-6 && (p.1 as f64 - s30).abs() < 1e-6 && p.3 == 1.0,
        "{p:?}"
    );
    assert!((p.2 as f64 - 60f64.to_radians().cos()).abs() < 1e-6);
    let _ = std::fs::remove_file(
        std::env::temp_dir().join(format!("sb-dir-{}.exr", std::process::id())),
    );
}

#[test]
fn samples_3d_are_interpolated_per_uv_island() {
    // Three copies of a grid in one primitive, all with UVs over [0,1]^2 (overlapping
    // islands): A at x in [0,1], B at [2,3], C at [10,11]. Samples on A point along +x,
    // on B along +y; C has none and takes its nearest sample (on B).
    let (p0, uv0, i0) = grid(9, |_, _| 0.0);
    let (mut pos, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for dx in [0.0, 2.0, 10.0] {
        let b = pos.len() as u32;
        pos.extend(p0.iter().map(|p| [p[0] + dx, p[1], p[2]]));
        uv.extend_from_slice(&uv0);
        idx.extend(i0.iter().map(|i| i + b));
    }
    let d = doc_from(&pos, None, Some(&uv), &idx, json!({}));
    let mut rng = Lcg(21);
    let mut items = Vec::new();
    for k in 0..40 {
        let (x, y) = (rng.next(), rng.next());
        let (off, dir) = if k % 2 == 0 {
            (0.0, [1.0, 0.0, 0.0])
        } else {
            (2.0, [0.0, -1.0, 0.0])
        };
        items.push(Sample {
            line: k + 2,
            at: SampleAt::Xyz {
                p: [x + off, y, 0.001],
                d: dir,
            },
        });
    }
    let mut o = BakeOptions::new(Source::Samples(Samples {
        path: "s.csv".into(),
        items,
    }));
    o.max_snap = Some(0.01);
    let (w, r) = compute(&d, &o).unwrap();
    let sr = r.samples.unwrap();
    assert_eq!(sr.used, 40);
    assert_eq!(sr.nearest_sample_vertices, 81);
    for i in 0..pos.len() {
        let want = if i < 81 { 0.0 } else { PI / 2.0 };
        assert!(
            axial_diff(angle(&w[0], i), want) < 1e-9,
            "vertex {i}: {}",
            angle(&w[0], i)
        );
    }
}
