//! sunbeam-import end to end: the binary against Gwyddion's processing of a
//! real scan, bad inputs (exit 2, message naming the file, no output), usage
//! errors (exit 1), determinism, reports, depfiles, resampling and calibration.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use sunbeam_common::testdata;

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-import");

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sunbeam-import-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

macro_rules! args {
    ($($a:expr),* $(,)?) => { &[$(std::ffi::OsStr::new($a)),*] };
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn veeco() -> Option<PathBuf> {
    testdata::shared_file("afm/samples/nanoscopeAFM_Veeco_20160622.003")
}

#[test]
fn level_plane_align_rows_median_agrees_with_gwyddion() {
    let Some(scan) = veeco() else { return };
    let d = tmpdir("gwy");
    let out = d.join("v.exr");
    let o = run(args!(
        &scan,
        "-o",
        &out,
        "--level",
        "plane",
        "--align-rows",
        "median",
        "-q"
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let f = sunbeam_field::io::read(&out).unwrap();
    assert_eq!((f.width, f.height), (512, 512));
    assert!((f.size_x() - 1.76908e-06).abs() < 1e-15);
    // Gwyddion 2.62: Plane Level + Align Rows (median), see crates/sunbeam-field/tests/data.
    let gz = Path::new(env!("CARGO_MANIFEST_DIR")).join(
        "../../crates/sunbeam-field/tests/data/veeco_20160622_003_height.level_align_median.f32.gz",
    );
    let mut b = Vec::new();
    flate2::read::GzDecoder::new(std::fs::File::open(gz).unwrap())
        .read_to_end(&mut b)
        .unwrap();
    let want: Vec<f64> = b
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()) as f64)
        .collect();
    let lo = want.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = want.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let err = f
        .data
        .iter()
        .zip(&want)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "tool vs Gwyddion: max difference {err:e} m = {:.2e} of the z range",
        err / (hi - lo)
    );
    assert!(err < 0.01 * (hi - lo), "{err:e} m");
}

#[test]
fn bad_inputs_exit_2_name_the_file_and_write_nothing() {
    let d = tmpdir("bad");
    let mut inputs: Vec<(String, PathBuf)> = Vec::new();
    let mut make = |name: &str, bytes: &[u8]| {
        let p = d.join(name);
        std::fs::write(&p, bytes).unwrap();
        inputs.push((name.to_string(), p));
    };
    make("empty.spm", b"");
    make(
        "magic.spm",
        &[0xde, 0xad, 0xbe, 0xef, 0, 1, 2, 3, 0xff, 0xfe],
    );
    make(
        "absurd.gsf",
        b"Gwyddion Simple Field 1.0\nXRes = 99999999\nYRes = 99999999\n\0\0\0\0",
    );
    let mut exr = sunbeam_field::io::encode(
        sunbeam_field::io::Kind::Exr,
        &sunbeam_field::HeightField::new(8, 8, 1e-9, 1e-9, vec![0.0; 64]).unwrap(),
    )
    .unwrap();
    exr.truncate(exr.len() - 50);
    make("truncated.exr", &exr);
    if let Some(v) = veeco() {
        let b = std::fs::read(v).unwrap();
        make("truncated_nanoscope.003", &b[..b.len() / 2]);
        make("header_cut.003", &b[..10000]);
    }
    for rel in [
        "afm/samples/scifireaders_force_ibw.ibw",
        "afm/samples/header_only/pySPM_bruker_data_header.000",
        "afm/samples/header_only/pySPM_bruker_data_header.002",
        "afm/samples/header_only/pySPM_bruker_data_header.003",
    ] {
        if let Some(p) = testdata::shared_file(rel) {
            inputs.push((rel.to_string(), p));
        }
    }
    inputs.push(("missing".into(), d.join("does-not-exist.spm")));
    let outdir = tmpdir("bad-out");
    for (what, p) in &inputs {
        for ext in ["exr", "gsf"] {
            let out = outdir.join(format!("out.{ext}"));
            let prev = outdir.join("prev.png");
            let o = run(args!(p, "-o", &out, "--preview", &prev, "--level", "plane"));
            let msg = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{what}: {msg}");
            assert!(
                msg.contains(&p.display().to_string()),
                "{what}: message does not name the file: {msg}"
            );
            assert!(!msg.contains("panicked"), "{what}: {msg}");
            assert_eq!(
                std::fs::read_dir(&outdir).unwrap().count(),
                0,
                "{what}: left a file behind"
            );
        }
    }
    // A channel that is not a height (Amplitude, in volts).
    if let Some(v) = veeco() {
        let a = outdir.join("a.exr");
        let o = run(args!(&v, "-o", &a, "--channel", "Amplitude"));
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains("Amplitude"));
        assert_eq!(std::fs::read_dir(&outdir).unwrap().count(), 0);
    }
}

#[test]
fn usage_errors_exit_1() {
    let d = tmpdir("usage");
    let gsf = d.join("in.gsf");
    sunbeam_field::io::write(
        &gsf,
        &sunbeam_field::HeightField::new(4, 4, 1e-9, 1e-9, vec![0.0; 16]).unwrap(),
    )
    .unwrap();
    let out = d.join("o.exr");
    for a in [
        vec!["-o", "x.tif"],
        vec!["-o", "o.exr", "--level", "cubic"],
        vec!["-o", "o.exr", "--rotate", "45"],
        vec!["-o", "o.exr", "--align-rows", "mean"],
        vec!["-o", "o.exr", "--crop", "1,2,3"],
        vec!["-o", "o.exr", "--pixel-size", "20"],
        vec!["-o", "o.exr", "--size", "0x5"],
        vec!["-o", "o.exr", "--resample-to", "2nm", "--size", "5x5"],
        vec!["-o", "o.exr", "--crop", "2,2,4,4"],
        vec!["-o", "o.exr", "--pixel-size", "2nm", "--size", "5x5"],
        vec!["--no-such-flag"],
        vec![],
    ] {
        let mut cmd = Command::new(BIN);
        cmd.current_dir(&d).arg(&gsf).args(&a);
        let o = cmd.output().unwrap();
        assert_eq!(o.status.code(), Some(1), "{a:?}: {}", stderr(&o));
        assert!(!out.exists(), "{a:?}");
    }
}

#[test]
fn outputs_are_deterministic_with_report_and_depfile() {
    let Some(scan) = veeco() else { return };
    let d = tmpdir("det");
    let mut bytes = Vec::new();
    for k in 0..2 {
        for ext in ["exr", "gsf"] {
            let out = d.join(format!("o{k}.{ext}"));
            let prev = d.join(format!("o{k}.png"));
            let dep = d.join(format!("o{k}.d"));
            let o = run(args!(
                &scan,
                "-o",
                &out,
                "--level",
                "poly:2",
                "--align-rows",
                "median-diff",
                "--resample-to",
                "10nm",
                "--preview",
                &prev,
                "--depfile",
                &dep,
                "--json"
            ));
            assert!(o.status.success(), "{}", stderr(&o));
            let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            assert_eq!(rep["width"], 177);
            assert_eq!(rep["dx_m"], 1e-8);
            assert_eq!(rep["source_format"], "nanoscope");
            assert_eq!(rep["channel"], "Height");
            assert_eq!(rep["processing"].as_array().unwrap().len(), 3);
            for k in [
                "z_min_m", "z_max_m", "z_mean_m", "z_rms_m", "dy_m", "height",
            ] {
                assert!(rep[k].is_number(), "{k}");
            }
            let dep = std::fs::read_to_string(&dep).unwrap();
            assert!(
                dep.contains(&*scan.to_string_lossy()) && dep.contains(&*out.to_string_lossy()),
                "{dep}"
            );
            bytes.push((std::fs::read(&out).unwrap(), std::fs::read(&prev).unwrap()));
        }
    }
    assert!(
        bytes[0] == bytes[2] && bytes[1] == bytes[3],
        "outputs differ between identical runs"
    );
}

#[test]
fn exr_and_gsf_outputs_read_back_through_the_tool() {
    let Some(scan) = veeco() else { return };
    let d = tmpdir("rt");
    let a = d.join("a.exr");
    assert!(run(args!(
        &scan,
        "-o",
        &a,
        "--crop",
        "10,20,300,200",
        "--rotate",
        "90",
        "-q"
    ))
    .status
    .success());
    let f = sunbeam_field::io::read(&a).unwrap();
    assert_eq!((f.width, f.height), (200, 300));
    for (input, out) in [
        (a.clone(), d.join("b.gsf")),
        (d.join("b.gsf"), d.join("c.exr")),
    ] {
        let o = run(args!(&input, "-o", &out, "--json"));
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let c = sunbeam_field::io::read(&d.join("c.exr")).unwrap();
    assert_eq!((c.width, c.height), (200, 300));
    assert_eq!(c.data, f.data, "EXR -> GSF -> EXR changes values");
    assert!((c.dx - f.dx).abs() < 1e-15 * f.dx);
    // --list --json on our own file.
    let o = run(args!(&a, "--list", "--json"));
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["channels"][0]["width"], 200);
    assert_eq!(v["channels"][0]["z_unit"], "m");
}

#[test]
fn pixel_size_calibrates_uncalibrated_images_and_resamples_calibrated_ones() {
    let Some(png) = testdata::shared_file("snake/Xeno100x100.png") else {
        return;
    };
    let d = tmpdir("cal");
    let out = d.join("x.exr");
    let o = run(args!(&png, "-o", &out));
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--pixel-size"), "{}", stderr(&o));
    let o = run(args!(
        &png,
        "-o",
        &out,
        "--pixel-size",
        "65nm",
        "--z-range",
        "375nm",
        "--json"
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(rep["pixel_size_role"], "calibration");
    assert_eq!(
        (rep["width"].as_u64(), rep["dx_m"].as_f64()),
        (Some(100), Some(65e-9))
    );
    assert!(rep["z_max_m"].as_f64().unwrap() <= 375e-9);
    let Some(scan) = veeco() else { return };
    let o = run(args!(&scan, "-o", &out, "--pixel-size", "20nm", "--json"));
    assert!(o.status.success(), "{}", stderr(&o));
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(rep["pixel_size_role"], "resample");
    assert_eq!(
        (
            rep["width"].as_u64(),
            rep["height"].as_u64(),
            rep["dx_m"].as_f64()
        ),
        (Some(88), Some(88), Some(20e-9))
    );
    let o = run(args!(&scan, "-o", &out, "--size", "256x128", "--json"));
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (rep["width"].as_u64(), rep["height"].as_u64()),
        (Some(256), Some(128))
    );
    assert_eq!(rep["dx_m"], rep["dy_m"]);
}

#[test]
fn list_reads_headers_even_when_the_data_are_damaged() {
    let Some(p) = testdata::shared_file("afm/samples/header_only/pySPM_bruker_data_header.002")
    else {
        return;
    };
    let o = run(args!(&p, "--list", "--json"));
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let ch = v["channels"].as_array().unwrap();
    assert_eq!(ch.len(), 8);
    assert_eq!(ch[0]["name"], "Height Sensor");
    assert_eq!(
        (ch[0]["width"].as_u64(), ch[0]["height"].as_u64()),
        (Some(512), Some(358))
    );
    // 300 x 300 nm declared, 358 of 512 lines: yreal = 209.77 nm (Gwyddion's reading).
    assert!((ch[0]["size_y"].as_f64().unwrap() - 209.765625e-9).abs() < 1e-15);
    // Importing it is still an input error.
    let d = tmpdir("list");
    let out = d.join("x.exr");
    let o = run(args!(&p, "-o", &out));
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
}
