//! Every sample in ../shared/data/afm that Gwyddion reads: dimensions,
//! physical size, units and every value against Gwyddion 2.62's own arrays
//! (reference/*.f64), to float32 precision, row 0 at the top.

use std::path::Path;

use sunbeam_afm::{read_file, Channel, ReadOptions};
use sunbeam_common::testdata;

fn load_f64(p: &Path) -> Vec<f64> {
    let b = std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    b.chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

fn unit(u: &str) -> &str {
    if u == "(none)" {
        ""
    } else {
        u
    }
}

/// Compare one channel with Gwyddion's reference; returns the max error / range.
fn compare(
    file: &str,
    ch: &Channel,
    r: &serde_json::Value,
    refdir: &Path,
    check_units: bool,
) -> f64 {
    let id = r["id"].as_u64().unwrap();
    let ctx = format!("{file} channel {id} '{}'", ch.name);
    assert_eq!(
        ch.field.width as u64,
        r["xres"].as_u64().unwrap(),
        "{ctx}: xres"
    );
    assert_eq!(
        ch.field.height as u64,
        r["yres"].as_u64().unwrap(),
        "{ctx}: yres"
    );
    let (xr, yr) = (r["xreal"].as_f64().unwrap(), r["yreal"].as_f64().unwrap());
    assert!(
        (ch.field.size_x() - xr).abs() <= 1e-9 * xr,
        "{ctx}: xreal {} vs {xr}",
        ch.field.size_x()
    );
    assert!(
        (ch.field.size_y() - yr).abs() <= 1e-9 * yr,
        "{ctx}: yreal {} vs {yr}",
        ch.field.size_y()
    );
    if check_units {
        assert_eq!(
            ch.z_unit,
            unit(r["unit_z"].as_str().unwrap()),
            "{ctx}: z unit"
        );
        assert_eq!(
            ch.xy_unit,
            unit(r["unit_xy"].as_str().unwrap()),
            "{ctx}: xy unit"
        );
    }
    let base = Path::new(file)
        .file_name()
        .unwrap()
        .to_string_lossy()
        .into_owned();
    let txt = std::fs::read_to_string(refdir.join(format!("{base}.{id}.txt"))).unwrap();
    let title = txt.lines().find_map(|l| l.strip_prefix("title=")).unwrap();
    if check_units {
        assert_eq!(ch.name, title, "{ctx}: title");
    }
    let want = load_f64(&refdir.join(format!("{base}.{id}.f64")));
    assert_eq!(want.len(), ch.field.data.len(), "{ctx}: value count");
    let (lo, hi) = (r["min"].as_f64().unwrap(), r["max"].as_f64().unwrap());
    let range = (hi - lo).abs().max(hi.abs().max(lo.abs()) * 1e-12);
    let mut worst: f64 = 0.0;
    for (i, (a, b)) in ch.field.data.iter().zip(&want).enumerate() {
        if b.is_nan() {
            assert!(a.is_nan(), "{ctx}: value {i} should be NaN");
            continue;
        }
        let e = (a - b).abs() / range;
        assert!(
            e <= 1e-6,
            "{ctx}: value {i} (row {}, col {}) is {a}, Gwyddion says {b} (error {e:.2e} of the range)",
            i / ch.field.width,
            i % ch.field.width
        );
        worst = worst.max(e);
    }
    worst
}

#[test]
fn every_sample_matches_gwyddion() {
    let Some(afm) = testdata::shared_file("afm/reference/gwyddion_reference.json") else {
        return;
    };
    let refdir = afm.parent().unwrap().to_path_buf();
    let samples = refdir.parent().unwrap().join("samples");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&afm).unwrap()).unwrap();
    let mut checked = 0;
    for (file, entry) in json.as_object().unwrap() {
        let chans_ref = entry["channels"].as_array().unwrap();
        if chans_ref.is_empty() || entry.get("load_failed").is_some() {
            continue; // refused by Gwyddion: see bad_input.rs
        }
        let path = samples.join(file);
        // Gwyddion's 16-bit TIFF export keeps no scale; Gwyddion shows it as 0..1 over 1x1 (no units).
        let uncal = entry["gwyddion_module"] == "tiff";
        let opts = if uncal {
            let r = &chans_ref[0];
            let (w, h) = (r["xres"].as_f64().unwrap(), r["yres"].as_f64().unwrap());
            ReadOptions {
                pixel_size: Some((1.0 / w, 1.0 / h)),
                z_range: Some(1.0),
                ..Default::default()
            }
        } else {
            ReadOptions::default()
        };
        let chans = read_file(&path, &opts).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(chans.len(), chans_ref.len(), "{file}: channel count");
        if uncal {
            check_grey16_tiff(file, &chans[0], &chans_ref[0], &refdir, &json);
            checked += 1;
            continue;
        }
        for (ch, r) in chans.iter().zip(chans_ref) {
            let worst = compare(file, ch, r, &refdir, !uncal);
            eprintln!(
                "{file} [{}] {}x{}: max error {worst:.2e} of the range",
                ch.name, ch.field.width, ch.field.height
            );
            checked += 1;
        }
    }
    assert!(checked >= 25, "only {checked} channels compared");
}

#[test]
fn first_height_channel_is_picked() {
    let Some(p) = testdata::shared_file("afm/samples/nanoscopeAFM_Veeco_20160622.003") else {
        return;
    };
    let chans = read_file(&p, &ReadOptions::default()).unwrap();
    assert!(chans[0].is_height && !chans[1].is_height);
    let c = sunbeam_afm::select_channel(&chans, None).unwrap();
    assert_eq!(c.name, "Height");
    assert_eq!(
        sunbeam_afm::select_channel(&chans, Some("amplitude"))
            .unwrap()
            .name,
        "Amplitude"
    );
    assert_eq!(
        sunbeam_afm::select_channel(&chans, Some("1")).unwrap().name,
        "Amplitude"
    );
    assert!(sunbeam_afm::select_channel(&chans, Some("Phase")).is_err());
    assert_eq!(
        c.field.provenance.source_file,
        "nanoscopeAFM_Veeco_20160622.003"
    );
    assert_eq!(c.field.provenance.source_format, "nanoscope");
}

/// Gwyddion 2.62 reads 16-bit TIFF through an 8-bit path (its values are the
/// high byte / 255), so the full-precision check is against the 16-bit PNG
/// export of the same channel (same quantisation, with its scale).
fn check_grey16_tiff(
    file: &str,
    ch: &Channel,
    r: &serde_json::Value,
    refdir: &Path,
    json: &serde_json::Value,
) {
    let gw = load_f64(&refdir.join(format!(
        "{}.0.f64",
        Path::new(file).file_name().unwrap().to_string_lossy()
    )));
    assert_eq!(ch.field.width as u64, r["xres"].as_u64().unwrap());
    assert_eq!(ch.field.height as u64, r["yres"].as_u64().unwrap());
    assert_eq!(gw.len(), ch.field.data.len());
    for (i, (&v, &g)) in ch.field.data.iter().zip(&gw).enumerate() {
        let raw = (v * 65535.0).round();
        assert!(
            (raw - v * 65535.0).abs() < 1e-6,
            "{file}: value {i} is not k/65535"
        );
        let hb = (raw as u32 >> 8) as f64 / 255.0;
        assert!(
            (hb - g).abs() < 1e-9,
            "{file}: value {i}: high byte {hb} differs from Gwyddion's {g}"
        );
    }
    let png = "derived_by_gwyddion/Veeco_20160622.003.height.grey16.png";
    let pr = &json[png]["channels"][0];
    let want = load_f64(&refdir.join("Veeco_20160622.003.height.grey16.png.0.f64"));
    let (lo, hi) = (pr["min"].as_f64().unwrap(), pr["max"].as_f64().unwrap());
    for (i, (&v, &w)) in ch.field.data.iter().zip(&want).enumerate() {
        let z = lo + v * (hi - lo);
        assert!(
            (z - w).abs() <= 1e-6 * (hi - lo),
            "{file}: value {i} scaled {z} vs the PNG's {w}"
        );
    }
}
