//! `grating`: periods of synthetic and shared gratings (PHYSICS.md 4, 5.7).
mod common;
use common::*;
use std::f64::consts::PI;

fn report(out: &str) -> serde_json::Value {
    let v: serde_json::Value = serde_json::from_str(out.trim()).expect("json report");
    assert!(v["peaks"].as_array().is_some_and(|p| !p.is_empty()));
    v
}

fn period(out: &str) -> f64 {
    report(out)["period_m"].as_f64().unwrap()
}

/// The orders of the brightest peak of each wavelength.
fn brightest_orders(v: &serde_json::Value) -> Vec<i64> {
    let orders = v["peak_order"]
        .as_array()
        .expect("peak_order in the report");
    let bright = v["peak_brightest"].as_array().expect("peak_brightest");
    orders
        .iter()
        .zip(bright)
        .filter(|(_, b)| b.as_bool() == Some(true))
        .map(|(m, _)| m.as_i64().unwrap())
        .collect()
}

/// A grating constant along y: `rows` copies of one row of `n` heights, as an
/// ASCII matrix in metres to 1e-12 m. Every number takes 16 bytes: the format
/// sniffer reads the first 4096 bytes and refuses a file whose first line is
/// cut there in the middle of a number (sunbeam-afm `ascii::detect`).
fn write_grating(path: &std::path::Path, n: usize, rows: usize, h: impl Fn(usize) -> f64) {
    let row: Vec<String> = (0..n).map(|c| format!("{:>15.12}", h(c))).collect();
    let line = row.join(" ") + "\n";
    std::fs::write(path, line.repeat(rows)).unwrap();
}

#[test]
fn sinusoidal_grating_period_both_models() {
    let dir = tmpdir("sine");
    // d = 1 um, 20 periods of 20 px at 50 nm along x; constant along y (4 rows of
    // 5 um so the window model's window is as wide as the patch).
    let (per, n, rows) = (20usize, 400usize, 4usize);
    let a = 60e-9;
    let z: Vec<f64> = (0..rows * n)
        .map(|i| a * (2.0 * PI * (i % n) as f64 / per as f64).sin())
        .collect();
    let f = dir.join("sine.txt");
    write_ascii(&f, n, rows, &z);
    for model in ["tiled", "window"] {
        let out = ok(&[
            "grating",
            f.to_str().unwrap(),
            "--pixel-size",
            "50nm,5um",
            "--model",
            model,
            "--json",
            "--lambda-step",
            "20nm",
            "--angle-step",
            "0.2deg",
        ]);
        let v = report(&out);
        let d = v["period_m"].as_f64().unwrap();
        let rel = (d - 1e-6).abs() / 1e-6;
        eprintln!("sine {model}: d = {d:e} ({:.4} %)", rel * 100.0);
        assert!(rel < 0.005, "{model}: period {d} vs 1 um");
        // Its first order is the brightest: the estimate is the one from before the
        // orders were found (issue 14: 999.970 nm tiled, 999.821 nm window, the
        // brightest peak per wavelength as order 1), orders 1 and 2 seen.
        let before = if model == "tiled" {
            999.970e-9
        } else {
            999.821e-9
        };
        assert!(
            (d - before).abs() / before < 2e-4,
            "{model}: {d} moved from {before}"
        );
        assert!(brightest_orders(&v).iter().all(|&m| m == 1), "{v}");
        assert_eq!(v["orders_found"], true, "{v}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 14, item 1: a blazed grating (2.5 um, 246 nm, facets 85/15, 25 nm
/// pixels) on a 512 x 256 patch. The short side sets the window (sigma 1.07 um):
/// lobes are broad and order 1 (0.4 /um) lies inside the old specular cut
/// (0.6/sigma), so the brightest peak beyond it was order 2, taken as order 1:
/// 1239.9 nm. The orders are now found from the spacing of all the peaks.
#[test]
fn blazed_grating_on_a_short_patch_finds_its_orders() {
    let dir = tmpdir("blazed-512x256");
    let f = dir.join("blazed.txt");
    let (px, d, h) = (25e-9, 2.5e-6, 246.23e-9);
    write_grating(&f, 512, 256, |c| {
        let q = (c as f64 * px / d).fract();
        h * if q < 0.85 { q / 0.85 } else { (1.0 - q) / 0.15 }
    });
    let out = ok(&[
        "grating",
        f.to_str().unwrap(),
        "--pixel-size",
        "25nm",
        "--json",
        "--lambda-step",
        "20nm",
        "--angle-step",
        "0.2deg",
    ]);
    let v = report(&out);
    let p = v["period_m"].as_f64().unwrap();
    eprintln!("blazed 85/15 on 512 x 256: d = {p:e}; {}", v["orders_note"]);
    assert!((p - d).abs() / d < 0.005, "period {p} vs {d}");
    assert_eq!(v["orders_found"], true, "{v}");
    // Every peak with an order sits on it: |f d - m| small (PHYSICS.md 5.7, loosely:
    // broad lobes pull the low orders).
    let orders = v["peak_order"].as_array().unwrap();
    let fs = v["peak_f_per_m"].as_array().unwrap();
    let mut seen = std::collections::BTreeSet::new();
    for (m, f) in orders.iter().zip(fs) {
        let (m, f) = (m.as_i64().unwrap(), f.as_f64().unwrap());
        if m != 0 {
            seen.insert(m);
            assert!(
                (f * d - m as f64).abs() < 0.1,
                "order {m} at f d = {}",
                f * d
            );
        }
    }
    assert!(
        seen.contains(&1) && seen.contains(&2) && seen.contains(&3),
        "{seen:?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// One order visible (a shallow sine: order 2 is below 1 % of order 1): the
/// orders cannot be told apart, the report says so, and `--order` decides.
#[test]
fn single_order_cannot_be_told_apart() {
    let dir = tmpdir("shallow-sine");
    let f = dir.join("sine.txt");
    write_grating(&f, 400, 4, |c| 5e-9 * (2.0 * PI * c as f64 / 20.0).sin());
    let run_with = |order: &str| {
        report(&ok(&[
            "grating",
            f.to_str().unwrap(),
            "--pixel-size",
            "50nm,5um",
            "--model",
            "tiled",
            "--json",
            "--lambda-step",
            "40nm",
            "--angle-step",
            "0.2deg",
            "--order",
            order,
        ]))
    };
    let v = run_with("1");
    assert_eq!(v["orders_found"], false, "{v}");
    assert!(
        v["orders_note"]
            .as_str()
            .unwrap()
            .contains("cannot be told apart"),
        "{v}"
    );
    let d1 = v["period_m"].as_f64().unwrap();
    assert!((d1 - 1e-6).abs() / 1e-6 < 0.005, "{d1}");
    assert!(brightest_orders(&v).iter().all(|&m| m == 1));
    let d2 = run_with("2")["period_m"].as_f64().unwrap();
    assert!((d2 / d1 - 2.0).abs() < 1e-9, "--order 2: {d2} vs {d1}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn blazed_grating_period() {
    let Some(bmp) = sunbeam_common::testdata::shared_file("snake/BlazingBump.bmp") else {
        return;
    };
    let b = bmp.to_str().unwrap();
    // Tiled model (the thesis): one period per 100 px patch of 2.5 um.
    let out = ok(&[
        "grating",
        b,
        "--pixel-size",
        "25nm",
        "--z-range",
        "246.23nm",
        "--model",
        "tiled",
        "--json",
        "--lambda-step",
        "20nm",
        "--angle-step",
        "0.2deg",
    ]);
    let d = period(&out);
    eprintln!("blazed tiled: {d:e}");
    assert!((d - 2.5e-6).abs() / 2.5e-6 < 0.005, "tiled: {d}");
    // Window model: 8 periods side by side under the window (rows are identical, so a
    // 200 nm row pitch only widens the window).
    let out = ok(&[
        "grating",
        b,
        "--pixel-size",
        "25nm,200nm",
        "--z-range",
        "246.23nm",
        "--model",
        "window",
        "--tile",
        "8x1",
        "--json",
        "--lambda-step",
        "20nm",
        "--angle-step",
        "0.2deg",
    ]);
    let d = period(&out);
    eprintln!("blazed window: {d:e}");
    assert!((d - 2.5e-6).abs() / 2.5e-6 < 0.005, "window: {d}");
}

#[test]
fn thesis_table_snake_patches() {
    // Thesis chapter 4: Elaphe 1144.26 nm, Xenopeltis 1552.27 nm, assuming 65 nm pixels.
    let Some(el) = sunbeam_common::testdata::shared_file("snake/Elaph100x100.png") else {
        return;
    };
    let Some(xe) = sunbeam_common::testdata::shared_file("snake/Xeno100x100.png") else {
        return;
    };
    let case = |f: &std::path::Path, z: &str, az: &str, model: &str| {
        period(&ok(&[
            "grating",
            f.to_str().unwrap(),
            "--pixel-size",
            "65nm",
            "--z-range",
            z,
            "--azimuth",
            az,
            "--model",
            model,
            "--json",
            "--lambda-step",
            "20nm",
            "--angle-step",
            "0.2deg",
        ]))
    };
    let e_w = case(&el, "375nm", "90deg", "window");
    let x_w = case(&xe, "443.45nm", "0deg", "window");
    let e_t = case(&el, "375nm", "90deg", "tiled");
    let x_t = case(&xe, "443.45nm", "0deg", "tiled");
    eprintln!("elaphe window {e_w:e} tiled {e_t:e}; xeno window {x_w:e} tiled {x_t:e}");
    // Window model: within 2 % of the thesis' numbers.
    assert!(
        (e_w - 1144.26e-9).abs() / 1144.26e-9 < 0.02,
        "elaphe window {e_w}"
    );
    assert!(
        (x_w - 1552.27e-9).abs() / 1552.27e-9 < 0.02,
        "xeno window {x_w}"
    );
    // Tiled model: the orders sit on the patch's bins: Lpatch/6 and Lpatch/4.
    assert!(
        (e_t - 6.5e-6 / 6.0).abs() / (6.5e-6 / 6.0) < 0.005,
        "elaphe tiled {e_t}"
    );
    assert!(
        (x_t - 6.5e-6 / 4.0).abs() / (6.5e-6 / 4.0) < 0.005,
        "xeno tiled {x_t}"
    );
}
