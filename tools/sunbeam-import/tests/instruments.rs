//! sunbeam-import on Nanosurf .nid, PicoView .mi, WSxM .top/.stp and NT-MDT
//! .mdt scans (../shared/data/afm/samples): `--list` as Gwyddion numbers and
//! names the channels, `--channel N` writes that channel (values checked
//! against Gwyddion's dump), non-height channels refused naming their unit,
//! damaged files exit 2 naming the file with nothing written.

use std::path::PathBuf;
use std::process::{Command, Output};
use sunbeam_common::testdata;

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-import");

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "sunbeam-import-instr-{name}-{}",
        std::process::id()
    ));
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

fn sample(name: &str) -> Option<PathBuf> {
    testdata::shared_file(&format!("afm/samples/{name}"))
}

fn reference() -> Option<(PathBuf, serde_json::Value)> {
    let p = testdata::shared_file("afm/reference/gwyddion_reference.json")?;
    let j = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    Some((p.parent().unwrap().to_path_buf(), j))
}

const FILES: [&str; 7] = [
    "surfacetopography_nid-1.nid",
    "nsfopen_grid1.nid",
    "nsfopen_circles.nid",
    "surfacetopography_mi-1.mi",
    "surfacetopography_top-1.top",
    "surfacetopography_stp-1.stp",
    "scifidatasets_test_mdt.mdt",
];

/// `--list --json`: every channel Gwyddion shows, in its order, with its title,
/// size, physical size and units; detected from the content (copied to a
/// neutral name).
#[test]
fn list_matches_gwyddion_channels() {
    let Some((_, refj)) = reference() else { return };
    let d = tmpdir("list");
    for f in FILES {
        let Some(p) = sample(f) else { return };
        let neutral = d.join("scan.dat");
        std::fs::copy(&p, &neutral).unwrap();
        let o = run(args!(&neutral, "--list", "--json"));
        assert!(o.status.success(), "{f}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let ours = v["channels"].as_array().unwrap();
        let gw = refj[f]["channels"].as_array().unwrap();
        assert_eq!(ours.len(), gw.len(), "{f}: channel count");
        for (i, (c, g)) in ours.iter().zip(gw).enumerate() {
            assert_eq!(c["index"], i, "{f}");
            assert_eq!(
                g["id"], i,
                "{f}: Gwyddion numbers channel {i} as {}",
                g["id"]
            );
            assert_eq!(c["name"], g["title"], "{f} channel {i}");
            assert_eq!(c["width"], g["xres"], "{f} channel {i}");
            assert_eq!(c["height"], g["yres"], "{f} channel {i}");
            let gz = g["unit_z"].as_str().unwrap();
            assert_eq!(c["z_unit"], if gz == "(none)" { "" } else { gz }, "{f} {i}");
            assert_eq!(c["xy_unit"], g["unit_xy"], "{f} channel {i}");
            for (a, b) in [("size_x", "xreal"), ("size_y", "yreal")] {
                let (x, y) = (c[a].as_f64().unwrap(), g[b].as_f64().unwrap());
                assert!((x - y).abs() <= 1e-9 * y, "{f} {i}: {a} {x} vs {y}");
            }
            assert_eq!(c["is_height"].as_bool().unwrap(), gz == "m", "{f} {i}: {c}");
        }
        // the plain listing names the format and every unit
        let o = run(args!(&neutral, "--list"));
        let s = String::from_utf8_lossy(&o.stdout);
        let fmt = ours[0]["format"].as_str().unwrap();
        assert!(s.contains(&format!("({fmt})")), "{f}: {s}");
        assert_eq!(s.lines().count(), gw.len() + 1, "{f}: {s}");
    }
}

/// `--channel N` writes Gwyddion's channel N (values to float32 precision).
#[test]
fn channel_n_is_gwyddions_channel_n() {
    let Some((refdir, _)) = reference() else {
        return;
    };
    let d = tmpdir("chan");
    for (f, n) in [
        ("surfacetopography_nid-1.nid", 1),
        ("surfacetopography_nid-1.nid", 7),
        ("nsfopen_grid1.nid", 3),
        ("nsfopen_circles.nid", 2),
        ("surfacetopography_mi-1.mi", 0),
        ("surfacetopography_top-1.top", 0),
        ("surfacetopography_stp-1.stp", 0),
    ] {
        let Some(p) = sample(f) else { return };
        let out = d.join("h.gsf");
        let o = run(args!(
            &p,
            "-o",
            &out,
            "--channel",
            &n.to_string(),
            "--json",
            "-q"
        ));
        assert!(o.status.success(), "{f} {n}: {}", stderr(&o));
        let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let f64s: Vec<f64> = std::fs::read(refdir.join(format!("{f}.{n}.f64")))
            .unwrap()
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let txt = std::fs::read_to_string(refdir.join(format!("{f}.{n}.txt"))).unwrap();
        let title = txt.lines().find_map(|l| l.strip_prefix("title=")).unwrap();
        assert_eq!(rep["channel"], title, "{f} {n}");
        let field = sunbeam_field::io::read(&out).unwrap();
        assert_eq!(field.data.len(), f64s.len());
        let lo = f64s.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = f64s.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let worst = field
            .data
            .iter()
            .zip(&f64s)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // written as float32: relative precision 6e-8 of the largest magnitude
        let tol = 1e-6 * (hi - lo) + 1.2e-7 * hi.abs().max(lo.abs());
        assert!(worst <= tol, "{f} channel {n}: {worst:e} vs tol {tol:e}");
        std::fs::remove_file(&out).unwrap();
    }
    // Without --channel: the first height channel (Z-Axis forward, index 1).
    if let Some(p) = sample("surfacetopography_nid-1.nid") {
        let out = d.join("z.exr");
        let o = run(args!(&p, "-o", &out, "--json", "-q"));
        assert!(o.status.success(), "{}", stderr(&o));
        let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(rep["channel"], "Z-Axis forward");
        assert_eq!(rep["source_format"], "nid");
    }
}

/// Channels in N, V, deg, A are listed but refused as height fields, naming the unit.
#[test]
fn non_height_channels_are_refused_naming_the_unit() {
    let d = tmpdir("nonheight");
    for (f, ch, unit) in [
        ("surfacetopography_nid-1.nid", Some("0"), "N"),
        ("surfacetopography_nid-1.nid", Some("2"), "V"),
        ("nsfopen_grid1.nid", Some("Phase forward"), "deg"),
        ("surfacetopography_mi-1.mi", Some("Friction"), "V"),
        ("scifidatasets_test_mdt.mdt", None, "A"),
    ] {
        let Some(p) = sample(f) else { return };
        let out = d.join("x.exr");
        let o = match ch {
            Some(c) => run(args!(&p, "-o", &out, "--channel", c)),
            None => run(args!(&p, "-o", &out)),
        };
        let m = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{f} {ch:?}: {m}");
        assert!(m.contains(&format!("'{unit}'")), "{f} {ch:?}: {m}");
        assert!(m.contains(&p.display().to_string()), "{f}: {m}");
        assert!(m.contains("not metres"), "{f}: {m}");
        assert_eq!(
            std::fs::read_dir(&d).unwrap().count(),
            0,
            "{f}: left output"
        );
    }
}

/// Truncated and damaged copies: exit 2, the file named, no output, no panic.
#[test]
fn damaged_files_exit_2_and_write_nothing() {
    let d = tmpdir("damaged");
    let outdir = tmpdir("damaged-out");
    let mut n = 0;
    for f in FILES {
        let Some(p) = sample(f) else { return };
        let b = std::fs::read(&p).unwrap();
        let mut cases: Vec<(String, Vec<u8>)> = vec![
            ("half".into(), b[..b.len() / 2].to_vec()),
            ("header".into(), b[..600.min(b.len())].to_vec()),
            ("short".into(), b[..b.len() - 1].to_vec()),
        ];
        let mut m = b.clone();
        m[0] ^= 0x20;
        m[1] ^= 0x11;
        cases.push(("magic".into(), m));
        for (what, bytes) in cases {
            let q = d.join(format!("{what}_{f}"));
            std::fs::write(&q, &bytes).unwrap();
            let out = outdir.join("o.exr");
            let o = run(args!(&q, "-o", &out, "--channel", "0", "--z-scale", "1nm"));
            let msg = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{what} {f}: {msg}");
            assert!(msg.contains(&q.display().to_string()), "{what} {f}: {msg}");
            assert!(!msg.contains("panicked"), "{what} {f}: {msg}");
            assert_eq!(std::fs::read_dir(&outdir).unwrap().count(), 0, "{what} {f}");
            n += 1;
        }
    }
    assert_eq!(n, 28);
}
