//! Scale maps in the reference (`sunbeam-bake --scales`, docs/BAKE.md
//! "Scales"): a flat quad whose scales are all tilted by the same angle
//! (no dome, no jitter). The reference's diffraction orders of a sinusoidal
//! grating must leave in the directions the grating equation gives for the
//! tilted normal, an independent geometric prediction, within 0.5 deg.

use std::path::Path;
use std::sync::Arc;
use sunbeam_mesh::bake::{bake, BakeOptions};
use sunbeam_mesh::orient::{Source, UvAxis};
use sunbeam_mesh::scales::{self, ScaleParams};
use sunbeam_raster::{fixtures, raster, shade};

/// Period of the test grating: a sinusoid of 50 px of 50 nm, 5 periods per
/// patch (the coherence window then resolves the orders).
const PERIOD_M: f64 = 2.5e-6;
const PX: usize = 250;
const DX_M: f64 = 50e-9;
const LAMBDA_M: f64 = 550e-9;

/// The quad of `builtin:quad` (u along +x) as a GLB with scales tilted by `tilt_deg`.
fn tilted_quad(dir: &Path, tilt_deg: f64) -> std::path::PathBuf {
    let obj = dir.join("quad.obj");
    std::fs::write(
        &obj,
        "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n",
    )
    .unwrap();
    let doc = sunbeam_mesh::load_document(&obj).unwrap();
    let mut opts = BakeOptions::new(Source::UvDirection(UvAxis::U));
    opts.uv_tangents = true;
    let mut b = bake(doc, &opts).unwrap();
    let p = ScaleParams {
        rows: 3,
        length: 1.0,
        overlap: 0.3,
        dome: 0.0,
        keel: 0.0,
        tilt_deg,
        tilt_jitter_deg: 0.0,
        ridge_jitter_deg: 0.0,
        texels_per_scale: 16,
        seed: 1,
    };
    scales::attach(&mut b.doc, &b.work, &p, 0, None).unwrap();
    let out = dir.join(format!("quad-{tilt_deg}.glb"));
    std::fs::write(&out, b.doc.to_glb()).unwrap();
    out
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// World view angles (deg from +z toward +x, in the x-z plane) of the local
/// maxima of the reference's R at 550 nm, and the frame it shaded with.
fn measured_orders(p: &sunbeam_raster::Prepared, wi: [f64; 3]) -> (Vec<(f64, f64)>, [f64; 3]) {
    let g = raster::rasterise(p, 40, 40);
    let f = &g[20 * 40 + 20];
    assert!(f.mesh.is_some());
    let (t, b, n) = shade::frame(f.normal, f.tangent).unwrap();
    let pack = p.meshes[0].1.pack.as_ref().unwrap();
    let loc = |d: [f64; 3]| [dot(d, t), dot(d, b), dot(d, n)];
    let wi_l = loc(wi);
    let r = |phi: f64| {
        let wr = [phi.to_radians().sin(), 0.0, phi.to_radians().cos()];
        let wr_l = loc(wr);
        if wr_l[2] <= 0.0 || wi_l[2] <= 0.0 {
            return 0.0;
        }
        pack.shading_reflectance(
            -wi_l[0] - wr_l[0],
            -wi_l[1] - wr_l[1],
            -wi_l[2] - wr_l[2],
            LAMBDA_M,
        )
    };
    let step = 0.01;
    let phis: Vec<f64> = (0..=16000).map(|k| -80.0 + k as f64 * step).collect();
    let rs: Vec<f64> = phis.iter().map(|&a| r(a)).collect();
    let top = rs.iter().cloned().fold(0.0, f64::max);
    let mut peaks = Vec::new();
    for k in 1..rs.len() - 1 {
        if rs[k] > rs[k - 1] && rs[k] >= rs[k + 1] && rs[k] > 0.02 * top {
            peaks.push((phis[k], rs[k]));
        }
    }
    (peaks, n)
}

/// The grating equation on a surface tilted by `tilt` about +y (normal toward
/// +x): the world angle of order m, or None when it is evanescent.
fn predicted(wi: [f64; 3], tilt_deg: f64, m: i32) -> Option<f64> {
    let th = tilt_deg.to_radians();
    let (n, t) = ([th.sin(), 0.0, th.cos()], [th.cos(), 0.0, -th.sin()]);
    let x = -dot(wi, t) - m as f64 * LAMBDA_M / PERIOD_M;
    if x.abs() >= 1.0 {
        return None;
    }
    let z = (1.0 - x * x).sqrt();
    let wr = [0, 1, 2].map(|k| x * t[k] + z * n[k]);
    (wr[2] > 0.0).then(|| wr[0].atan2(wr[2]).to_degrees())
}

#[test]
fn a_tilted_scale_moves_the_diffraction_orders_as_the_grating_equation_says() {
    let dir = std::env::temp_dir().join(format!("sunbeam-raster-scales-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let opts = sunbeam_pack::build::BuildOptions::default();
    let heights: Vec<f64> = (0..PX * PX)
        .map(|i| 60e-9 * (std::f64::consts::TAU * (i % PX) as f64 * DX_M / PERIOD_M).sin())
        .collect();
    let field = sunbeam_pack::build::FieldRef {
        width: PX,
        height: PX,
        dx: DX_M,
        dy: DX_M,
        data: &heights,
    };
    let pack = Arc::new(sunbeam_pack::build::build(field, &opts, &mut |_, _| {}).unwrap());
    let (scene, _) = fixtures::quad_scene([40, 40]);
    let l = scene.lights[0].direction;
    let wi = {
        let n = dot(l, l).sqrt();
        l.map(|v| v / n)
    };
    let mut all = Vec::new();
    for tilt in [0.0, 10.0] {
        let glb = tilted_quad(&dir, tilt);
        let (mesh, sc) = sunbeam_raster::load_mesh_with_scales(&glb).unwrap();
        let mut p = fixtures::prepared(scene.clone(), mesh, Some(pack.clone()));
        p.meshes[0].1.scales = Some(Arc::new(sc.expect("scale maps")));
        let (peaks, n) = measured_orders(&p, wi);
        // The shading normal is the tilted one (8-bit normal map: ~0.3 deg).
        let want_n = [tilt.to_radians().sin(), 0.0, tilt.to_radians().cos()];
        let err_n = dot(n, want_n).clamp(-1.0, 1.0).acos().to_degrees();
        assert!(err_n < 0.35, "tilt {tilt}: normal {n:?} off by {err_n} deg");
        eprintln!("tilt {tilt}: peaks {peaks:?}");
        let mut matched = Vec::new();
        for m in -3..=3 {
            let Some(want) = predicted(wi, tilt, m) else {
                continue;
            };
            if want.abs() > 79.0 {
                continue;
            }
            let Some(&(got, _)) = peaks
                .iter()
                .min_by(|a, b| (a.0 - want).abs().total_cmp(&(b.0 - want).abs()))
            else {
                continue;
            };
            if (got - want).abs() < 3.0 {
                assert!(
                    (got - want).abs() <= 0.5,
                    "tilt {tilt} order {m}: lobe at {got:.3} deg, the grating equation says {want:.3}"
                );
                matched.push((m, got, want));
            }
        }
        eprintln!("tilt {tilt}: (order, reference, prediction) {matched:?}");
        assert!(
            matched.iter().filter(|(m, _, _)| *m != 0).count() >= 1 && matched.len() >= 2,
            "tilt {tilt}: too few orders found: {matched:?} among {peaks:?}"
        );
        all.push(matched);
    }
    // The same order moved by more than the tolerance (a tilt ignored fails above).
    let moved = all[1].iter().any(|(m, got, _)| {
        all[0]
            .iter()
            .any(|(m0, got0, _)| m0 == m && (got - got0).abs() > 10.0)
    });
    assert!(moved, "{all:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
