//! Nanosurf .nid, PicoView .mi, WSxM .top/.stp, NT-MDT .mdt.
//!
//! - Layout variants (sample types, units, frame types, missing keys) in small
//!   synthetic files, `tests/data/gwyddion_variants` (make_variants.py), against
//!   Gwyddion 2.62's reading of the same files (`gwyddion/`, dump.sh): title,
//!   size, physical size, units and every value. Runs without ../shared.
//! - The real samples (../shared/data/afm): channel listing, heights, and bad
//!   input: wrong sizes in headers, garbled blocks, truncation -> Input errors
//!   naming the field. (Their values against Gwyddion: reference.rs.)

use std::path::{Path, PathBuf};

use sunbeam_afm::{detect, list_channels, read_bytes, read_file, Channel, Format, ReadOptions};
use sunbeam_common::{testdata, ExitCode};

fn variants() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gwyddion_variants")
}

fn load_f64(p: &Path) -> Vec<f64> {
    std::fs::read(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

/// One channel as Gwyddion read it: (id, its .txt key=value lines, values).
type GwyChannel = (usize, Vec<(String, String)>, Vec<f64>);

/// Gwyddion's channels of a variant file.
fn gwyddion_channels(file: &str) -> Vec<GwyChannel> {
    let dir = variants().join("gwyddion");
    let mut ids: Vec<usize> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let n = e.unwrap().file_name().to_string_lossy().into_owned();
            n.strip_prefix(&format!("{file}."))?
                .strip_suffix(".txt")?
                .parse()
                .ok()
        })
        .collect();
    ids.sort();
    ids.into_iter()
        .map(|id| {
            let txt = std::fs::read_to_string(dir.join(format!("{file}.{id}.txt"))).unwrap();
            let kv = txt
                .lines()
                .filter_map(|l| l.split_once('='))
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect();
            (id, kv, load_f64(&dir.join(format!("{file}.{id}.f64"))))
        })
        .collect()
}

fn get<'a>(kv: &'a [(String, String)], k: &str) -> &'a str {
    kv.iter()
        .find(|(a, _)| a == k)
        .map(|(_, v)| v.as_str())
        .unwrap_or_else(|| panic!("no {k}"))
}

fn unit(u: &str) -> &str {
    if u == "(none)" {
        ""
    } else {
        u
    }
}

/// One channel against Gwyddion's; `lateral` false skips xreal/yreal/xy unit.
fn compare(ctx: &str, c: &Channel, kv: &[(String, String)], want: &[f64], lateral: bool) {
    assert_eq!(c.name, get(kv, "title"), "{ctx}: title");
    assert_eq!(c.z_unit, unit(get(kv, "unit_z")), "{ctx}: z unit");
    assert_eq!(c.field.width.to_string(), get(kv, "xres"), "{ctx}: xres");
    assert_eq!(c.field.height.to_string(), get(kv, "yres"), "{ctx}: yres");
    if lateral {
        assert_eq!(c.xy_unit, unit(get(kv, "unit_xy")), "{ctx}: xy unit");
        for (ours, k) in [(c.field.size_x(), "xreal"), (c.field.size_y(), "yreal")] {
            let g: f64 = get(kv, k).parse().unwrap();
            assert!(
                (ours - g).abs() <= 1e-9 * g.abs(),
                "{ctx}: {k} {ours} vs {g}"
            );
        }
    }
    assert_eq!(c.field.data.len(), want.len(), "{ctx}: value count");
    let lo = want.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = want.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let range = (hi - lo).max(hi.abs().max(lo.abs()) * 1e-12);
    for (i, (a, b)) in c.field.data.iter().zip(want).enumerate() {
        assert!(
            (a - b).abs() <= 1e-6 * range,
            "{ctx}: value {i} (row {}, col {}) is {a}, Gwyddion says {b}",
            i / c.field.width,
            i % c.field.width
        );
    }
}

/// Files Gwyddion reads but we refuse (or Gwyddion crashes on), with a word
/// the message must contain.
const REFUSED: &[(&str, &str)] = &[
    ("n_1d.nid", "no 2-D image"),
    ("n_motorola.nid", "SaveOrder"),
    ("n_unsigned.nid", "SaveSign"),
    ("m_ascii.mi", "ASCII"),         // Gwyddion: all zeros
    ("m_nolen.mi", "xLength"),       // Gwyddion: 1 nm wide
    ("w_uchar.top", "Data Type"),    // Gwyddion refuses too
    ("w_flat.top", "flat"),          // Gwyddion: inf everywhere
    ("w_nozamp.top", "Z Amplitude"), // Gwyddion 2.62 crashes
    ("w_noxamp.top", "X Amplitude"), // Gwyddion: 1 um, no unit
];

/// WSxM files whose Z Amplitude unit differs from X/Y Amplitude's: Gwyddion
/// 2.62 takes the lateral unit and prefix from Z Amplitude (a bug: 600 nm
/// becomes 600 pm, or 600 V); we use X/Y Amplitude's own (as make_variants.py
/// writes them): expected (xreal, yreal, xy unit).
const WSXM_LATERAL: &[(&str, f64, f64, &str)] = &[
    ("w_au.top", 600e-9, 300e-9, "m"),
    ("w_chan.top", 600e-9, 300e-9, "m"),
    ("w_phase.top", 600e-9, 300e-9, "m"),
    ("w_um.top", 2e-6, 3e-10, "m"),
    ("u_0.top", 600e-9, 300e-9, "m"),
    ("u_1.top", 600e-9, 300e-9, "m"),
    ("u_2.top", 600e-9, 300e-9, "m"),
    ("u_3.top", 600e-9, 300e-9, "m"),
    ("u_4.top", 600e-9, 300e-9, "m"),
    ("u_5.top", 600e-9, 300e-9, "m"),
    ("u_6.top", 600e-9, 300e-9, "m"),
    ("u_7.top", 600e-9, 300e-9, "m"),
];

#[test]
fn variants_match_gwyddion() {
    let mut files: Vec<String> = std::fs::read_dir(variants())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| {
            [".nid", ".mi", ".top", ".mdt"]
                .iter()
                .any(|x| n.ends_with(x))
        })
        .collect();
    files.sort();
    assert!(files.len() >= 55, "variant files missing: {files:?}");
    let (mut compared, mut refused) = (0, 0);
    for f in &files {
        let b = std::fs::read(variants().join(f)).unwrap();
        let fmt = detect(&b);
        let want_fmt = match f.rsplit('.').next().unwrap() {
            "nid" => Format::Nid,
            "mi" => Format::Mi,
            "top" => Format::Wsxm,
            _ => Format::Mdt,
        };
        assert_eq!(fmt, Some(want_fmt), "{f}: detected as {fmt:?}");
        let r = read_bytes(&b, &ReadOptions::default());
        if let Some((_, word)) = REFUSED.iter().find(|(n, _)| n == f) {
            let e = r.expect_err(f);
            assert_eq!(e.code, ExitCode::Input, "{f}: {e}");
            assert!(e.message.contains(word), "{f}: {e}");
            refused += 1;
            continue;
        }
        let chans = r.unwrap_or_else(|e| panic!("{f}: {e}"));
        // Gwyddion refuses CR LF line ends in .mi headers; we read them: same as m_16.mi.
        let gw = gwyddion_channels(if f == "m_crlf.mi" { "m_16.mi" } else { f });
        assert_eq!(chans.len(), gw.len(), "{f}: channel count");
        let lateral = WSXM_LATERAL.iter().find(|(n, ..)| n == f);
        for (c, (id, kv, want)) in chans.iter().zip(&gw) {
            compare(&format!("{f} channel {id}"), c, kv, want, lateral.is_none());
            if let Some((_, xr, yr, u)) = lateral {
                assert!(
                    (c.field.size_x() - xr).abs() < 1e-9 * xr,
                    "{f}: xreal {}",
                    c.field.size_x()
                );
                assert!(
                    (c.field.size_y() - yr).abs() < 1e-9 * yr,
                    "{f}: yreal {}",
                    c.field.size_y()
                );
                assert_eq!(c.xy_unit, *u, "{f}");
            }
            compared += 1;
        }
    }
    eprintln!("{compared} channels equal to Gwyddion's, {refused} files refused");
    assert!(compared >= 50 && refused == REFUSED.len());
}

/// MDT frames with spectra before an image: Gwyddion numbers the image after
/// the spectrum as channel 3 (ids 0, 1, 3); ours are consecutive (0, 1, 2).
#[test]
fn mdt_skips_spectroscopy_frames() {
    let b = std::fs::read(variants().join("t_mix.mdt")).unwrap();
    let c = read_bytes(&b, &ReadOptions::default()).unwrap();
    let names: Vec<&str> = c.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["A (1)", "B (2)", "C (4)"]);
    assert!(c.iter().all(|c| c.z_unit == "m" && c.field.width == 4));
}

fn sample(name: &str) -> Option<(PathBuf, Vec<u8>)> {
    let p = testdata::shared_file(&format!("afm/samples/{name}"))?;
    let b = std::fs::read(&p).unwrap();
    Some((p, b))
}

#[test]
fn samples_list_with_units_and_pick_a_height() {
    // (file, format, channels, first height channel, some (index, name, z unit))
    type Case<'a> = (
        &'a str,
        Format,
        usize,
        Option<&'a str>,
        &'a [(usize, &'a str, &'a str)],
    );
    let cases: &[Case] = &[
        (
            "surfacetopography_nid-1.nid",
            Format::Nid,
            8,
            Some("Z-Axis forward"),
            &[
                (0, "Deflection forward", "N"),
                (2, "Friction force forward", "V"),
                (7, "Z-AxisSensor backward", "m"),
            ],
        ),
        (
            "nsfopen_grid1.nid",
            Format::Nid,
            6,
            Some("Z-Axis forward"),
            &[(1, "Amplitude forward", "V"), (2, "Phase forward", "deg")],
        ),
        (
            "nsfopen_circles.nid",
            Format::Nid,
            4,
            Some("Topography forward"),
            &[(3, "Amplitude backward", "V")],
        ),
        (
            "surfacetopography_mi-1.mi",
            Format::Mi,
            4,
            Some("Topography"),
            &[(1, "Deflection", "V"), (3, "Friction", "V")],
        ),
        (
            "surfacetopography_top-1.top",
            Format::Wsxm,
            1,
            Some("Topography"),
            &[],
        ),
        (
            "surfacetopography_stp-1.stp",
            Format::Wsxm,
            1,
            Some("Topography"),
            &[],
        ),
        (
            "scifidatasets_test_mdt.mdt",
            Format::Mdt,
            1,
            None,
            &[(0, "1F:Iprobe (2)", "A")],
        ),
    ];
    for (file, fmt, n, height, some) in cases {
        let Some((p, b)) = sample(file) else { return };
        assert_eq!(detect(&b), Some(*fmt), "{file}");
        let info = list_channels(&p, &ReadOptions::default()).unwrap();
        assert_eq!(info.len(), *n, "{file}");
        for (i, name, u) in *some {
            assert_eq!(
                (info[*i].name.as_str(), info[*i].z_unit.as_str()),
                (*name, *u),
                "{file}"
            );
            assert!(!info[*i].is_height || *u == "m", "{file}: {:?}", info[*i]);
            assert_eq!(info[*i].format, *fmt);
        }
        let chans = read_file(&p, &ReadOptions::default()).unwrap();
        let first = sunbeam_afm::select_channel(&chans, None).unwrap();
        match height {
            Some(h) => assert!(
                first.is_height && first.name == *h,
                "{file}: {}",
                first.name
            ),
            None => assert!(chans.iter().all(|c| !c.is_height), "{file}"),
        }
        assert_eq!(first.field.provenance.source_format, fmt.name());
    }
}

fn replace(b: &[u8], from: &str, to: &str) -> Vec<u8> {
    let f = from.as_bytes();
    let pos = b
        .windows(f.len())
        .position(|w| w == f)
        .unwrap_or_else(|| panic!("{from:?} not found"));
    let mut v = b[..pos].to_vec();
    v.extend_from_slice(to.as_bytes());
    v.extend_from_slice(&b[pos + f.len()..]);
    v
}

/// Replace `from` at its first place after `after`.
fn replace_after(b: &[u8], after: &str, from: &str, to: &str) -> Vec<u8> {
    let a = b
        .windows(after.len())
        .position(|w| w == after.as_bytes())
        .unwrap_or_else(|| panic!("{after:?} not found"));
    let mut v = b[..a].to_vec();
    v.extend_from_slice(&replace(&b[a..], from, to));
    v
}

#[track_caller]
fn refused(b: &[u8], ctx: &str, words: &[&str]) {
    match read_bytes(b, &ReadOptions::default()) {
        Ok(c) => panic!("{ctx}: read {} channels", c.len()),
        Err(e) => {
            assert_eq!(e.code, ExitCode::Input, "{ctx}: {e}");
            assert!(
                words.iter().any(|w| e.message.contains(w)),
                "{ctx}: message should name one of {words:?}: {e}"
            );
        }
    }
}

#[test]
fn nid_bad_headers() {
    let Some((_, b)) = sample("surfacetopography_nid-1.nid") else {
        return;
    };
    let sec = "[DataSet-0:1]";
    for v in ["999999999", "-5", "0", "x", "40000"] {
        let bb = replace_after(&b, sec, "Points=256", &format!("Points={v}"));
        refused(&bb, &format!("Points={v}"), &["Points x Lines"]);
    }
    let bb = replace_after(&b, sec, "Lines=256", "Lines=4096");
    refused(
        &bb,
        "Lines larger than the data",
        &["truncated", "needs bytes"],
    );
    let bb = replace_after(&b, sec, "SaveBits=32", "SaveBits=12");
    refused(&bb, "SaveBits=12", &["SaveBits"]);
    let bb = replace_after(&b, sec, "SaveSign=Signed", "SaveSign=Unsigned");
    refused(&bb, "SaveSign", &["SaveSign"]);
    let bb = replace_after(&b, sec, "Dim0Range=2e-05", "Dim0Range=0");
    refused(&bb, "Dim0Range=0", &["physical size"]);
    for v in ["0", "-1", "many"] {
        let bb = replace(&b, "GroupCount=2", &format!("GroupCount={v}"));
        refused(&bb, &format!("GroupCount={v}"), &["GroupCount"]);
    }
    let bb = replace(&b, "Gr0-Ch1=DataSet-0:1", "Gr0-Ch1=DataSet-9:9");
    refused(&bb, "dangling GrI-ChJ", &["Gr0-Ch1"]);
    let bb = replace(&b, "Version=2\r\nGroupCount", "Version 2\r\nGroupCount");
    refused(&bb, "line without =", &["key=value"]);
    let bb = replace(&b, "#!", "##");
    // (the binary part then reads as header lines)
    refused(&bb, "no #!", &["#!", "key=value"]);
    // A huge GroupCount costs nothing: the channels are found from the keys.
    let bb = replace(&b, "GroupCount=2", "GroupCount=2000000000");
    assert_eq!(read_bytes(&bb, &ReadOptions::default()).unwrap().len(), 8);
}

#[test]
fn mi_bad_headers() {
    let Some((_, b)) = sample("surfacetopography_mi-1.mi") else {
        return;
    };
    for v in ["99999999", "0", "-3", "x"] {
        let bb = replace(&b, "xPixels       256", &format!("xPixels       {v}"));
        refused(&bb, &format!("xPixels {v}"), &["xPixels"]);
    }
    let bb = replace(&b, "yPixels       256", "yPixels       4096");
    refused(
        &bb,
        "yPixels larger than the data",
        &["truncated", "needs bytes"],
    );
    let bb = replace(&b, "data          BINARY_32", "data          ASCII");
    refused(&bb, "ASCII", &["ASCII"]);
    let bb = replace(&b, "data          BINARY_32", "data          FLOAT");
    refused(&bb, "FLOAT", &["FLOAT"]);
    let bb = replace(&b, "\ndata          BINARY_32", "\nDATA          BINARY_32");
    refused(&bb, "no data line", &["data"]);
    let bb = replace(&b, "xLength       2.0", "xLength       x.0");
    refused(&bb, "xLength", &["xLength"]);
    let bb = replace(&b, "fileType      Image", "fileType      Spectroscopy");
    refused(&bb, "spectroscopy", &["spectroscopy"]);
}

#[test]
fn wsxm_bad_headers() {
    let Some((_, b)) = sample("surfacetopography_top-1.top") else {
        return;
    };
    for v in ["99999999", "0", "-1", "x"] {
        let bb = replace(
            &b,
            "Image header size: 2245",
            &format!("Image header size: {v}"),
        );
        refused(
            &bb,
            &format!("header size {v}"),
            &["header size", "Header end"],
        );
    }
    for v in ["70000", "0", "-256"] {
        let bb = replace(
            &b,
            "Number of columns: 256",
            &format!("Number of columns: {v}"),
        );
        refused(&bb, &format!("columns {v}"), &["Number of columns"]);
    }
    // (same length: the header size stays right)
    let bb = replace(&b, "Number of rows: 256", "Number of rows: 999");
    refused(&bb, "rows beyond the data", &["truncated", "needs bytes"]);
    let bb = replace(&b, "Image Data Type: short", "Image Data Type: long!");
    refused(&bb, "data type", &["Data Type"]);
    let bb = replace(&b, "[Header end]", "[Header and]");
    refused(&bb, "no header end", &["Header end"]);
    let bb = replace(&b, "Z Amplitude: 18.8851 nm", "Z Amplitude: -8.8851 nm");
    refused(&bb, "negative Z Amplitude", &["Z Amplitude"]);
    let bb = replace(&b, "X Amplitude: 600 nm", "X Amplitude: abc nm");
    refused(&bb, "X Amplitude", &["X Amplitude"]);
}

#[test]
fn mdt_bad_frames() {
    let Some((_, b)) = sample("scifidatasets_test_mdt.mdt") else {
        return;
    };
    let put32 = |b: &[u8], at: usize, v: u32| {
        let mut c = b.to_vec();
        c[at..at + 4].copy_from_slice(&v.to_le_bytes());
        c
    };
    let size = u32::from_le_bytes(b[4..8].try_into().unwrap());
    refused(&put32(&b, 4, size + 1), "file size", &["file header"]);
    refused(&put32(&b, 4, u32::MAX), "file size", &["file header"]);
    let mut bb = b.clone();
    bb[12..14].copy_from_slice(&500u16.to_le_bytes());
    refused(&bb, "frame count", &["frame 4"]);
    // frame 2 (the MDA image) starts at 737
    refused(&put32(&b, 737, u32::MAX), "frame size", &["frame 2"]);
    refused(&put32(&b, 737, 10), "frame size", &["frame 2"]);
    // MDA header size, title size, calibrations
    refused(
        &put32(&b, 737 + 22, 0x7fff_ffff),
        "MDA head size",
        &["frame 2"],
    );
    refused(
        &put32(&b, 737 + 22 + 44, 0x7fff_ffff),
        "MDA title size",
        &["frame 2 title"],
    );
    // the value calibration: max index (x axis) absurd, data type unknown
    let cal0 = 737 + 22 + 76 + 9 + 43068 + 1104 + 8 + 33;
    refused(
        &put32(&b, cal0 + 8 + 60, 0xffff_ff00),
        "MDA x size",
        &["MDA image size"],
    );
    let cal2 = cal0 + 2 * 124;
    refused(
        &put32(&b, cal2 + 8 + 68, 12345),
        "MDA data type",
        &["data type"],
    );
    refused(
        &put32(&b, cal2, 0),
        "MDA calibration size",
        &["calibration size"],
    );
    refused(
        &put32(&b, cal2 + 4, 0x7fff_0000),
        "MDA struct size",
        &["calibration"],
    );
    // only non-image frames left: frame 2 becomes a palette
    let mut bb = b.clone();
    bb[737 + 4..737 + 6].copy_from_slice(&107u16.to_le_bytes());
    refused(&bb, "no image frame", &["no image frame"]);
}

/// Every byte of the first 2 KiB of each new sample (and each variant file)
/// mutated in turn, plus cuts at every 97th length: Input errors or channels,
/// never a panic.
#[test]
fn mutations_never_panic() {
    let mut files: Vec<Vec<u8>> = std::fs::read_dir(variants())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.extension()
                .is_some_and(|x| ["nid", "mi", "top", "mdt"].contains(&x.to_str().unwrap()))
        })
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    for s in [
        "nsfopen_circles.nid",
        "surfacetopography_top-1.top",
        "scifidatasets_test_mdt.mdt",
        "surfacetopography_mi-1.mi",
    ] {
        if let Some((_, b)) = sample(s) {
            files.push(b);
        }
    }
    let mut n = 0;
    for b in &files {
        let top = b.len().min(2048);
        for i in (0..top).step_by(if b.len() > 4096 { 13 } else { 1 }) {
            for x in [0xffu8, 0x80, 0x01] {
                let mut m = b.clone();
                m[i] ^= x;
                if let Err(e) = read_bytes(&m, &ReadOptions::default()) {
                    assert_eq!(e.code, ExitCode::Input, "{e}");
                }
                n += 1;
            }
        }
        for c in (0..b.len()).step_by(97.max(b.len() / 200)) {
            if let Err(e) = read_bytes(&b[..c], &ReadOptions::default()) {
                assert_eq!(e.code, ExitCode::Input, "{e}");
            }
        }
    }
    assert!(n > 10_000, "{n}");
}
