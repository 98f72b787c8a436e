//! EXR and GSF files: round trips, byte-identical output, bad input refused,
//! and the EXR opened by an independent reader (OpenImageIO's oiiotool).

use sunbeam_common::testdata;
use sunbeam_field::io::{self, Kind};
use sunbeam_field::{HeightField, Provenance};

fn sample() -> HeightField {
    let (w, h) = (37, 23);
    let data = (0..w * h)
        .map(|p| ((p % w) as f64 * 0.37).sin() * 12e-9 + (p / w) as f64 * 0.5e-9)
        .collect();
    let mut f = HeightField::new(w, h, 6.5e-9, 7.25e-9, data).unwrap();
    f.provenance = Provenance {
        source_file: "scan.spm".into(),
        source_format: "nanoscope".into(),
        channel: "Height".into(),
        processing: vec!["level plane".into(), "align-rows median".into()],
    };
    f
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("sunbeam-field-io-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn assert_f32_equal(a: &HeightField, b: &HeightField) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    for (x, y) in a.data.iter().zip(&b.data) {
        assert_eq!(*x as f32, *y as f32);
    }
}

#[test]
fn exr_round_trip_and_determinism() {
    let f = sample();
    let p = tmp("rt.exr");
    io::write(&p, &f).unwrap();
    let g = io::read(&p).unwrap();
    assert_f32_equal(&f, &g);
    assert_eq!(
        (g.dx, g.dy),
        (f.dx, f.dy),
        "pixel size is stored as f64, exactly"
    );
    assert_eq!(g.provenance, f.provenance);
    assert_eq!(
        io::encode(Kind::Exr, &f).unwrap(),
        std::fs::read(&p).unwrap()
    );
    assert_eq!(
        io::encode(Kind::Exr, &f).unwrap(),
        io::encode(Kind::Exr, &f.clone()).unwrap()
    );
}

#[test]
fn gsf_round_trip_and_determinism() {
    let f = sample();
    let p = tmp("rt.gsf");
    io::write(&p, &f).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    assert!(bytes.starts_with(b"Gwyddion Simple Field 1.0\nXRes = 37\nYRes = 23\n"));
    let hdr = bytes.iter().position(|&b| b == 0).unwrap();
    assert_eq!((hdr / 4 + 1) * 4 + 37 * 23 * 4, bytes.len());
    let g = io::read(&p).unwrap();
    assert_f32_equal(&f, &g);
    assert!(((g.dx - f.dx) / f.dx).abs() < 1e-15 && ((g.dy - f.dy) / f.dy).abs() < 1e-15);
    assert_eq!(g.provenance, f.provenance);
    assert_eq!(io::encode(Kind::Gsf, &f).unwrap(), bytes);
}

#[test]
fn reads_gwyddions_own_gsf() {
    // A GSF written by Gwyddion 2.62 from the Veeco scan, against Gwyddion's values.
    let Some(p) =
        testdata::shared_file("afm/samples/derived_by_gwyddion/Veeco_20160622.003.height.gsf")
    else {
        return;
    };
    let Some(r) = testdata::shared_file("afm/reference/Veeco_20160622.003.height.gsf.0.f64") else {
        return;
    };
    let f = io::read(&p).unwrap();
    assert_eq!((f.width, f.height), (512, 512));
    assert!((f.size_x() - 1.76908e-06).abs() < 1e-17);
    let want: Vec<f64> = std::fs::read(r)
        .unwrap()
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    for (a, b) in f.data.iter().zip(&want) {
        assert_eq!(*a as f32, *b as f32);
    }
}

#[test]
fn bad_files_are_input_errors() {
    let f = sample();
    let exr = io::encode(Kind::Exr, &f).unwrap();
    let gsf = io::encode(Kind::Gsf, &f).unwrap();
    let mut cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty", vec![]),
        ("wrong magic", b"hello world".to_vec()),
        ("truncated exr", exr[..exr.len() / 2].to_vec()),
        ("exr header only", exr[..200].to_vec()),
        ("truncated gsf", gsf[..gsf.len() - 10].to_vec()),
        (
            "gsf without NUL",
            b"Gwyddion Simple Field 1.0\nXRes = 2\nYRes = 2\n".to_vec(),
        ),
    ];
    let huge = b"Gwyddion Simple Field 1.0\nXRes = 30000\nYRes = 30000\n\0\0\0\0".to_vec();
    cases.push(("gsf size beyond the file", huge));
    let absurd = b"Gwyddion Simple Field 1.0\nXRes = 99999999\nYRes = 3\n\0\0\0".to_vec();
    cases.push(("absurd gsf size", absurd));
    let mut neg = b"Gwyddion Simple Field 1.0\nXRes = 1\nYRes = 1\nXReal = -1\n".to_vec();
    neg.resize(64, 0);
    cases.push(("negative XReal", neg));
    let mut big_exr = exr.clone();
    // dataWindow xMax -> 2^30: refused before decoding pixels.
    let pos = big_exr
        .windows(10)
        .position(|w| w == b"dataWindow")
        .unwrap()
        + 10
        + 1
        + 6
        + 4
        + 8;
    big_exr[pos..pos + 4].copy_from_slice(&(1i32 << 30).to_le_bytes());
    cases.push(("absurd exr size", big_exr));
    for (what, bytes) in cases {
        let e = io::decode(&bytes).expect_err(what);
        assert_eq!(e.exit_code(), 2, "{what}: {e}");
        eprintln!("{what}: {e}");
    }
    let e = io::read(std::path::Path::new("/nonexistent/x.exr")).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(e.message.contains("/nonexistent/x.exr"));
}

#[test]
fn oiiotool_reads_our_exr() {
    if !testdata::have_command("oiiotool", &["--help"]) {
        return;
    }
    let f = sample();
    let p = tmp("oiio.exr");
    io::write(&p, &f).unwrap();
    let out = std::process::Command::new("oiiotool")
        .arg("--info")
        .arg("-v")
        .arg(&p)
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "oiiotool failed: {text}");
    let words: Vec<&str> = text.split_whitespace().collect();
    assert!(words.windows(3).any(|w| w == ["37", "x", "23,"]), "{text}");
    assert!(
        text.contains("sunbeam_dx_m") && text.contains("sunbeam_source_file"),
        "{text}"
    );
    assert!(text.contains("float") && text.contains('Z'), "{text}");
    // Values: oiiotool's statistics of the channel (in nm) against ours.
    let out = std::process::Command::new("oiiotool")
        .arg(&p)
        .args(["--mulc", "1e9", "--printstats"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(out.status.success(), "{text}");
    let st = sunbeam_field::stats::Stats::of(&f);
    let stat = |name: &str| -> f64 {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(name))
            .unwrap_or_else(|| panic!("{text}"));
        line.split(':')
            .nth(1)
            .unwrap()
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    for (name, ours) in [
        ("Stats Min:", st.min),
        ("Stats Max:", st.max),
        ("Stats Avg:", st.mean),
    ] {
        let theirs = stat(name);
        assert!(
            (theirs - ours * 1e9).abs() < 1e-5,
            "oiiotool {name} {theirs} nm vs ours {} nm",
            ours * 1e9
        );
    }
    std::fs::remove_file(&p).ok();
}

#[test]
fn mutated_files_never_panic() {
    // A small deterministic mutation fuzzer over both decoders.
    let f = HeightField::new(
        9,
        7,
        1e-9,
        2e-9,
        (0..63).map(|v| v as f64 * 1e-10).collect(),
    )
    .unwrap();
    let mut rng = sunbeam_common::rng::SplitMix64::new(0x1234_5678_9abc_def0);
    let mut next = move || (rng.next_u64() >> 33) as usize;
    for kind in [Kind::Exr, Kind::Gsf] {
        let good = io::encode(kind, &f).unwrap();
        for _ in 0..3000 {
            let mut b = good.clone();
            match next() % 4 {
                0 => b.truncate(next() % good.len()),
                1 => {
                    for _ in 0..1 + next() % 4 {
                        let i = next() % b.len();
                        b[i] = next() as u8;
                    }
                }
                2 => {
                    let i = next() % (b.len() - 4);
                    b[i..i + 4].copy_from_slice(&[0xff, 0xff, 0xff, 0x7f]);
                }
                _ => {
                    let i = next() % b.len();
                    b.insert(i, next() as u8);
                }
            }
            if let Ok(g) = io::decode(&b) {
                assert_eq!(g.data.len(), g.width * g.height);
            }
        }
    }
}
