//! `sunbeam_analysis::brdf` on a flat patch: its only lobe is the mirror
//! direction (the law of reflection, PHYSICS.md 5 target 1), so the brightest
//! hemisphere pixel and the brightest plane-of-incidence column of every
//! wavelength must sit there, and the disk must hold exactly the pixel centres
//! inside it.

use sunbeam_analysis::brdf;
use sunbeam_pack::{BuildOptions, FieldRef, Pack};

fn flat_pack() -> Pack {
    let n = 64;
    let z = vec![0.0; n * n];
    let o = BuildOptions {
        threads: 1,
        ..BuildOptions::default()
    };
    sunbeam_pack::build(
        FieldRef {
            width: n,
            height: n,
            dx: 100e-9,
            dy: 100e-9,
            data: &z,
        },
        &o,
        &mut |_, _| {},
    )
    .expect("a flat patch builds")
}

#[test]
fn hemisphere_peaks_at_the_mirror_direction() {
    let pack = flat_pack();
    let theta = 30f64.to_radians();
    let light = [theta.sin(), 0.0, theta.cos()];
    let n = 33; // odd: y = 0 is a row of pixel centres
    let h = brdf::hemisphere(&pack, light, n, 16);
    assert_eq!(h.xyz.len(), n * n);

    // The disk: pixel centres with x^2 + y^2 < 0.999, counted here directly.
    let mut inside = 0;
    for j in 0..n {
        for i in 0..n {
            let x = -1.0 + (2 * i + 1) as f64 / n as f64;
            let y = 1.0 - (2 * j + 1) as f64 / n as f64;
            let is_in = x * x + y * y < 0.999;
            inside += is_in as usize;
            assert_eq!(h.xyz[j * n + i].is_some(), is_in, "pixel ({i}, {j})");
        }
    }
    assert!(inside > 0);

    // Brightest pixel: the mirror direction wr = (-sin 30, 0, cos 30).
    let (k, y) = h
        .xyz
        .iter()
        .enumerate()
        .filter_map(|(k, c)| c.map(|c| (k, c[1])))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    assert_eq!(y, h.max_y);
    let (i, j) = (k % n, k / n);
    let (ie, je) = (((1.0 - theta.sin()) / 2.0 * n as f64) as usize, n / 2);
    assert!(
        i.abs_diff(ie) <= 1 && j == je,
        "brightest pixel ({i}, {j}), mirror direction in ({ie}, {je})"
    );
    // A flat mirror reflects everything there: the peak is near Y = G = 1 ...
    assert!(y > 0.2, "peak Y {y}");
    // ... and far from it there is next to nothing.
    let far = h.xyz[(n / 2) * n + n - 4].expect("inside the disk")[1];
    assert!(far < 1e-3 * y, "Y {far} far from the lobe against {y}");
    // The auto exposure maps the 95th percentile of Y to 1: finite.
    assert!(h.auto_exposure_ev().is_finite());
}

#[test]
fn plane_of_incidence_peaks_at_the_mirror_angle() {
    let pack = flat_pack();
    let theta = 40f64.to_radians();
    let light = [theta.sin(), 0.0, theta.cos()];
    let (nl, na) = (12, 179);
    let g = brdf::plane_of_incidence(&pack, light, nl, na);
    assert_eq!((g.lambdas, g.angles, g.r.len()), (nl, na, nl * na));
    let (a0, a1) = brdf::PlaneGrid::ANGLE_RANGE_DEG;
    let da = (a1 - a0) / na as f64;
    for li in 0..nl {
        let row = &g.r[li * na..(li + 1) * na];
        let ai = (0..na).max_by(|&a, &b| row[a].total_cmp(&row[b])).unwrap();
        let centre = a0 + (ai as f64 + 0.5) * da;
        // Mirror direction: theta_r = -40 deg (negative: away from the light).
        assert!(
            (centre + 40.0).abs() <= da,
            "row {li}: peak at {centre} deg, mirror at -40 deg"
        );
        // Retro-reflection (theta_r = +40 deg) is dark.
        let back = ((40.0 - a0) / da) as usize;
        assert!(
            row[back] < 1e-3 * row[ai],
            "row {li}: R {} at +40 deg",
            row[back]
        );
    }
}
