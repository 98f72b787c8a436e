//! Issue 14 item 3: heights no instrument can measure are refused (exit 2,
//! naming the file and the channel, no output) by the one height-field reader
//! (`sunbeam_afm::height`), unless `--allow-implausible` forces them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use sunbeam_common::testdata;

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "sunbeam-import-implausible-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A real .gwy with 4 KiB of random bytes (SplitMix64, seed 14) written over
/// its data block, 8 KiB into the heights.
fn damaged_gwy(dir: &Path) -> Option<PathBuf> {
    let src = testdata::shared_file("afm/samples/derived_by_gwyddion/Park_20210916_034.gwy")?;
    let mut b = std::fs::read(src).unwrap();
    let at = b
        .windows(6)
        .position(|w| w == b"data\0D")
        .expect("a GwyDataField data array");
    let start = at + 6 + 4 + 8192;
    let noise = sunbeam_common::rng::SplitMix64::new(14).bytes(4096);
    b[start..start + 4096].copy_from_slice(&noise);
    let p = dir.join("damaged.gwy");
    std::fs::write(&p, b).unwrap();
    Some(p)
}

fn import(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sunbeam-import"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn damaged_gwy_is_refused_and_can_be_forced() {
    let d = tmpdir("gwy");
    let Some(gwy) = damaged_gwy(&d) else {
        return;
    };
    let out = d.join("h.exr");
    let o = import(&[gwy.as_os_str(), "-o".as_ref(), out.as_os_str()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("damaged.gwy"), "names the file: {err}");
    assert!(err.contains("'Topography'"), "names the channel: {err}");
    assert!(
        err.contains("1 mm") && err.contains("--allow-implausible"),
        "{err}"
    );
    assert!(!out.exists(), "no output on refusal");
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name() != "damaged.gwy")
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    let o = import(&[
        gwy.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--allow-implausible".as_ref(),
        "-q".as_ref(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.exists());
}

#[test]
fn the_intact_gwy_still_imports() {
    let Some(gwy) = testdata::shared_file("afm/samples/derived_by_gwyddion/Park_20210916_034.gwy")
    else {
        return;
    };
    let d = tmpdir("ok");
    let out = d.join("h.exr");
    let o = import(&[
        gwy.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "-q".as_ref(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
