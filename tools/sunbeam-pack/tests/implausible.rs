//! The height-field reader's plausibility rule (docs/IMPORT.md) holds in
//! sunbeam-pack too: one reader, one rule set.

use std::process::Command;
use sunbeam_field::HeightField;

#[test]
fn a_range_beyond_1mm_is_refused_unless_forced() {
    let d = std::env::temp_dir().join(format!("sb-pack-implausible-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let (w, h) = (16usize, 16usize);
    let mut z: Vec<f64> = (0..w * h).map(|i| 1e-7 * (i as f64 * 0.3).sin()).collect();
    z[17] = 2e-3;
    let f = HeightField::new(w, h, 25e-9, 25e-9, z).unwrap();
    let input = d.join("tall.exr");
    sunbeam_field::io::write(&input, &f).unwrap();
    let out = d.join("p.ktx2");
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_sunbeam-pack"))
            .arg(&input)
            .arg("-o")
            .arg(&out)
            .args(["--terms", "2", "-q"])
            .args(extra)
            .output()
            .unwrap()
    };
    let o = run(&[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("tall.exr") && err.contains("channel"), "{err}");
    assert!(!out.exists());
    let o = run(&["--allow-implausible"]);
    assert!(
        o.status.code() != Some(2) || !String::from_utf8_lossy(&o.stderr).contains("1 mm"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
