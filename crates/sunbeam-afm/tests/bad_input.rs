//! Bad input: every failure is an `Error` with code Input and a message that
//! names what is wrong; nothing panics.

use std::path::{Path, PathBuf};

use sunbeam_afm::{list_channels, read_bytes, read_file, ReadOptions};
use sunbeam_common::{testdata, ExitCode};

fn samples() -> Option<PathBuf> {
    testdata::shared_file("afm/samples")
}

fn all_samples(dir: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    for sub in ["", "derived_by_gwyddion", "header_only"] {
        for e in std::fs::read_dir(dir.join(sub)).unwrap() {
            let p = e.unwrap().path();
            if p.is_file() {
                v.push(p);
            }
        }
    }
    v.sort();
    v
}

fn uncal() -> ReadOptions {
    ReadOptions {
        pixel_size: Some((1e-9, 1e-9)),
        z_range: Some(1e-6),
        ..Default::default()
    }
}

#[track_caller]
fn assert_input_err(r: sunbeam_common::Result<Vec<sunbeam_afm::Channel>>, ctx: &str) -> String {
    match r {
        Ok(c) => panic!("{ctx}: expected an error, got {} channels", c.len()),
        Err(e) => {
            assert_eq!(e.code, ExitCode::Input, "{ctx}: {e}");
            assert!(e.message.len() > 10, "{ctx}: message too short: {e}");
            e.message
        }
    }
}

#[test]
fn empty_file() {
    let m = assert_input_err(read_bytes(&[], &ReadOptions::default()), "empty");
    assert!(m.contains("empty"), "{m}");
    let dir = std::env::temp_dir().join(format!("sunbeam-afm-empty-{}", std::process::id()));
    std::fs::write(&dir, b"").unwrap();
    let m = assert_input_err(read_file(&dir, &ReadOptions::default()), "empty file");
    assert!(
        m.starts_with(&dir.display().to_string()),
        "message names the file: {m}"
    );
    std::fs::remove_file(&dir).ok();
}

#[test]
fn unknown_content() {
    let m = assert_input_err(
        read_bytes(b"\x00\x01\x02\x03garbage\xff\xfe", &ReadOptions::default()),
        "garbage",
    );
    assert!(m.contains("unknown file format"), "{m}");
}

#[test]
fn force_curve_ibw_is_refused() {
    let Some(d) = samples() else { return };
    let p = d.join("scifireaders_force_ibw.ibw");
    let m = assert_input_err(read_file(&p, &ReadOptions::default()), "force curve");
    assert!(m.contains("not an image") && m.contains("1261x3"), "{m}");
    assert!(m.contains("scifireaders_force_ibw.ibw"), "{m}");
}

#[test]
fn header_only_nanoscope() {
    let Some(d) = samples() else { return };
    let d = d.join("header_only");
    let info = list_channels(
        &d.join("pySPM_bruker_data_header.002"),
        &ReadOptions::default(),
    )
    .unwrap();
    let h = &info[0];
    assert_eq!((h.width, h.height), (512, 358));
    assert!((h.size.0 - 300e-9).abs() < 1e-15, "xreal {}", h.size.0);
    assert!(
        (h.size.1 - 300e-9 * 358.0 / 512.0).abs() < 1e-15 && (h.size.1 - 209.77e-9).abs() < 0.01e-9,
        "yreal {}",
        h.size.1
    );
    assert_eq!(h.z_unit, "m");
    assert!(h.is_height, "{h:?}");
    for f in [
        "pySPM_bruker_data_header.000",
        "pySPM_bruker_data_header.002",
        "pySPM_bruker_data_header.003",
    ] {
        let p = d.join(f);
        let info = list_channels(&p, &ReadOptions::default())
            .unwrap_or_else(|e| panic!("{f}: header: {e}"));
        assert!(!info.is_empty(), "{f}");
        let m = assert_input_err(read_file(&p, &ReadOptions::default()), f);
        assert!(
            m.contains("line endings") || m.contains("truncated"),
            "{f}: {m}"
        );
    }
    let info = list_channels(
        &d.join("pySPM_bruker_data_header.000"),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!((info[0].width, info[0].height), (512, 512));
    assert!((info[0].size.0 - 93e-6).abs() < 1e-12);
}

/// Cut every sample at several lengths: Input errors or (beyond the data) a
/// clean read; never a panic. Cut in the middle, every reader must fail.
#[test]
fn truncations_of_every_sample() {
    let Some(d) = samples() else { return };
    let mut n = 0;
    for p in all_samples(&d) {
        let b = std::fs::read(&p).unwrap();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let cuts = [
            1,
            2,
            4,
            8,
            16,
            64,
            100,
            383,
            384,
            1000,
            4096,
            b.len() / 4,
            b.len() / 2,
            b.len() * 3 / 4,
            b.len() - 64,
            b.len() - 1,
        ];
        for &c in cuts.iter().filter(|&&c| c < b.len()) {
            let r = read_bytes(&b[..c], &uncal());
            if let Err(e) = &r {
                assert_eq!(e.code, ExitCode::Input, "{name} cut at {c}: {e}");
            }
            if c <= b.len() / 2 {
                assert_input_err(r, &format!("{name} cut at {c}"));
            }
            n += 1;
        }
    }
    assert!(n > 150);
}

#[test]
fn wrong_magic() {
    let Some(d) = samples() else { return };
    for p in all_samples(&d) {
        let mut b = std::fs::read(&p).unwrap();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        b[0] ^= 0x5a;
        b[1] ^= 0x33;
        assert_input_err(
            read_bytes(&b, &uncal()),
            &format!("{name} with a wrong magic"),
        );
    }
}

fn replace(b: &[u8], from: &str, to: &str) -> Vec<u8> {
    let f = from.as_bytes();
    let pos = b
        .windows(f.len())
        .position(|w| w == f)
        .unwrap_or_else(|| panic!("{from} not found"));
    let mut v = b[..pos].to_vec();
    v.extend_from_slice(to.as_bytes());
    v.extend_from_slice(&b[pos + f.len()..]);
    v
}

#[test]
fn absurd_header_dimensions() {
    let Some(d) = samples() else { return };
    let o = ReadOptions::default();
    // Nanoscope: the image list's Samps/line.
    let b = std::fs::read(d.join("topostats_old_bruker.002")).unwrap();
    for v in ["999999999", "-5", "0", "1e300", "nan"] {
        let bb = replace(
            &b,
            "Samps/line: 256\r\n\\Number",
            &format!("Samps/line: {v}\r\n\\Number"),
        );
        assert_input_err(read_bytes(&bb, &o), &format!("nanoscope Samps/line {v}"));
    }
    let bb = replace(&b, "Data length: 131072", "Data length: 999999999");
    assert_input_err(read_bytes(&bb, &o), "nanoscope Data length");
    // GSF
    let b = std::fs::read(d.join("derived_by_gwyddion/Veeco_20160622.003.height.gsf")).unwrap();
    for v in ["XRes = 4000000000", "XRes = 30000", "XRes = -1", "XRes = x"] {
        let bb = replace(&b, "XRes = 512", v);
        let m = assert_input_err(read_bytes(&bb, &o), v);
        assert!(m.contains("XRes") || m.contains("GSF"), "{m}");
    }
    // Nanonis
    let b = std::fs::read(d.join("pySPM_test.sxm")).unwrap();
    let bb = replace(&b, "       256       256", "  99999999  99999999");
    assert_input_err(read_bytes(&bb, &o), "sxm pixels");
    let bb = replace(&b, "       256       256", "      4096      4096");
    let m = assert_input_err(read_bytes(&bb, &o), "sxm pixels larger than the data");
    assert!(m.contains("truncated") || m.contains("needs"), "{m}");
    // Igor: nDim[0] at 64 + 68.
    let b = std::fs::read(d.join("nanoAFMr_AR_20211011.ibw")).unwrap();
    for v in [i32::MAX, -1, 1 << 20] {
        let mut bb = b.clone();
        bb[132..136].copy_from_slice(&v.to_le_bytes());
        assert_input_err(read_bytes(&bb, &o), &format!("ibw nDim {v}"));
    }
    // Gwyddion: xres of the data field.
    let b = std::fs::read(d.join("gwyfile_test.gwy")).unwrap();
    let pos = b.windows(6).position(|w| w == b"xres\0i").unwrap() + 6;
    let mut bb = b.clone();
    bb[pos..pos + 4].copy_from_slice(&(1i32 << 30).to_le_bytes());
    assert_input_err(read_bytes(&bb, &o), "gwy xres");
    // Park: xres in the header tag.
    let b = std::fs::read(d.join("nanoAFMr_Park_20210916_034.tiff")).unwrap();
    let mut bb = b.clone();
    bb[264185 + 100..264185 + 104].copy_from_slice(&(1i32 << 16).to_le_bytes());
    assert_input_err(read_bytes(&bb, &o), "park xres");
}

#[test]
fn uncalibrated_images_name_the_missing_flags() {
    let Some(d) = samples() else { return };
    let p = d.join("derived_by_gwyddion/Veeco_20160622.003.height.grey16.tiff");
    let m = assert_input_err(read_file(&p, &ReadOptions::default()), "tiff");
    assert!(m.contains("--pixel-size") && m.contains("--z-range"), "{m}");
    let o = ReadOptions {
        pixel_size: Some((1e-9, 1e-9)),
        ..Default::default()
    };
    let m = assert_input_err(read_file(&p, &o), "tiff");
    assert!(
        !m.contains("--pixel-size") && m.contains("--z-range"),
        "{m}"
    );
}

/// Inputs the fuzzer found (fuzz/, docs/bench/fuzz.md), kept as regressions.
#[test]
fn fuzzer_findings() {
    use sunbeam_afm::Format;
    let cases: &[(&str, Format, &[u8])] = &[
        // xyz: extreme aspect ratio -> grid size overflowed i64 (add overflow)
        // (with the fuzz targets' --pixel-size 1nm)
        (
            "xyz grid overflow",
            Format::Xyz,
            b"0 0 0\n333333333333330 2 0\n0 20 62 \n\n",
        ),
    ];
    for (what, f, b) in cases {
        let o = ReadOptions {
            format: Some(*f),
            ..uncal()
        };
        if let Err(e) = read_bytes(b, &o) {
            assert_eq!(e.code, ExitCode::Input, "{what}: {e}");
        }
    }
}
