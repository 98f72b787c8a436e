//! `grating`: periods of synthetic and shared gratings (PHYSICS.md 4, 5.7).
mod common;
use common::*;
use std::f64::consts::PI;

fn period(out: &str) -> f64 {
    let v: serde_json::Value = serde_json::from_str(out.trim()).expect("json report");
    assert!(v["peaks"].as_array().is_some_and(|p| !p.is_empty()));
    v["period_m"].as_f64().unwrap()
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
        let d = period(&out);
        let rel = (d - 1e-6).abs() / 1e-6;
        eprintln!("sine {model}: d = {d:e} ({:.4} %)", rel * 100.0);
        assert!(rel < 0.005, "{model}: period {d} vs 1 um");
    }
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
