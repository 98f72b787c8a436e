//! `sunbeam-import synthetic:NAME`: the built-in fields the demo falls back to
//! when ../shared/data is missing. Checked through the files the tool writes:
//! size and pixel, the ridge period by a direct DFT (independent of the
//! generator), byte-identical reruns, a depfile without prerequisites, errors.

use std::path::PathBuf;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-import");

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "sunbeam-import-synth-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

/// Index of the strongest DFT bin (1..n/2) of the column-averaged profile.
fn dominant_bin(f: &sunbeam_field::HeightField) -> usize {
    let (w, h) = (f.width, f.height);
    let prof: Vec<f64> = (0..w)
        .map(|c| (0..h).map(|r| f.data[r * w + c]).sum::<f64>() / h as f64)
        .collect();
    let mut best = (0, 0.0);
    for k in 1..w / 2 {
        let (mut re, mut im) = (0.0, 0.0);
        for (c, v) in prof.iter().enumerate() {
            let a = -2.0 * std::f64::consts::PI * (k * c) as f64 / w as f64;
            re += v * a.cos();
            im += v * a.sin();
        }
        if re * re + im * im > best.1 {
            best = (k, re * re + im * im);
        }
    }
    best.0
}

#[test]
fn presets_have_their_period_size_and_pixel() {
    let d = tmpdir("period");
    // (preset, period in metres): the thesis' estimates (sunbeam-synth docs).
    for (name, period) in [
        ("elaphe", 1.144e-6),
        ("xenopeltis", 1.552e-6),
        ("sine", 2.5e-6_f64),
    ] {
        let out = d.join(format!("{name}.exr"));
        let o = run(&[
            &format!("synthetic:{name}"),
            "-o",
            out.to_str().unwrap(),
            "--synthetic-size",
            "320",
            "--synthetic-pixel",
            "25nm",
            "-q",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let f = sunbeam_field::io::read(&out).unwrap();
        assert_eq!((f.width, f.height), (320, 320));
        assert!((f.dx - 25e-9).abs() < 1e-18 && (f.dy - 25e-9).abs() < 1e-18);
        assert_eq!(f.provenance.source_format, "synthetic");
        let k_want = (320.0 * 25e-9 / period).round() as usize;
        assert_eq!(dominant_bin(&f), k_want, "{name}");
        let (lo, hi) = f
            .data
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(
            hi - lo > 100e-9 && hi - lo < 700e-9,
            "{name}: z span {}",
            hi - lo
        );
    }
}

#[test]
fn synthetic_is_deterministic_and_depends_on_no_file() {
    let d = tmpdir("det");
    let (a, b, dep) = (d.join("a.exr"), d.join("b.exr"), d.join("a.d"));
    for (out, extra) in [(&a, Some(&dep)), (&b, None)] {
        let mut args = vec![
            "synthetic:elaphe",
            "-o",
            out.to_str().unwrap(),
            "--synthetic-size",
            "64",
            "-q",
        ];
        if let Some(dep) = extra {
            args.extend(["--depfile", dep.to_str().unwrap()]);
        }
        let o = run(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let dep = std::fs::read_to_string(&dep).unwrap();
    assert_eq!(dep.trim_end(), format!("{}:", a.display()), "{dep}");
    // Processing applies to synthetic fields like to scans.
    let c = d.join("c.exr");
    let o = run(&[
        "synthetic:sine",
        "-o",
        c.to_str().unwrap(),
        "--synthetic-size",
        "64",
        "--resample-to",
        "50nm",
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["source_format"], "synthetic");
    assert_eq!(v["width"], 32);
}

#[test]
fn bad_synthetic_requests_are_usage_errors() {
    let d = tmpdir("bad");
    let out = d.join("x.exr");
    for args in [
        vec!["synthetic:python", "-o", out.to_str().unwrap()],
        vec![
            "synthetic:elaphe",
            "-o",
            out.to_str().unwrap(),
            "--synthetic-size",
            "0",
        ],
        vec![
            "synthetic:elaphe",
            "-o",
            out.to_str().unwrap(),
            "--synthetic-pixel",
            "-3nm",
        ],
        vec![
            "synthetic:elaphe",
            "-o",
            out.to_str().unwrap(),
            "--z-range",
            "3nm",
        ],
    ] {
        let o = run(&args);
        assert_eq!(
            o.status.code(),
            Some(1),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!out.exists());
    }
    let o = run(&["synthetic:python", "-o", out.to_str().unwrap()]);
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("elaphe"),
        "names the presets"
    );
}
