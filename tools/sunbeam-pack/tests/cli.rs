//! End-to-end tests of the sunbeam-pack binary.

use std::path::{Path, PathBuf};
use std::process::Command;
use sunbeam_common::testdata;
use sunbeam_field::HeightField;
use sunbeam_pack::Pack;

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-pack");

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sb-pack-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(BIN).args(args).output().unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into(),
        String::from_utf8_lossy(&o.stderr).into(),
    )
}

/// A small height field EXR written with sunbeam-field's own writer.
fn height_exr(dir: &Path, nan: bool) -> PathBuf {
    let (w, h) = (24usize, 20usize);
    let mut d: Vec<f64> = (0..w * h)
        .map(|i| {
            let (c, r) = ((i % w) as f64, (i / w) as f64);
            100e-9 * ((c * 0.7).sin() + (r * 0.4 + c * 0.1).cos())
        })
        .collect();
    if nan {
        d[5] = f64::NAN;
    }
    let f = HeightField::new(w, h, 25e-9, 25e-9, d).unwrap();
    let p = dir.join(if nan { "nan.exr" } else { "h.exr" });
    sunbeam_field::io::write(&p, &f).unwrap();
    p
}

#[test]
fn snake_png_to_ktx2_with_json_report_depfile_and_manifest() {
    let Some(png) = testdata::shared_file("snake/Elaph100x100.png") else {
        return;
    };
    let d = tmpdir("png");
    let out = d.join("elaph.ktx2");
    let dep = d.join("elaph.d");
    let man = d.join("elaph.json");
    let (code, stdout, stderr) = run(&[
        png.to_str().unwrap(),
        "--pixel-size",
        "65nm",
        "--z-range",
        "375nm",
        "-o",
        out.to_str().unwrap(),
        "--json",
        "--depfile",
        dep.to_str().unwrap(),
        "--manifest",
        man.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("coarser than"),
        "coarse-sampling warning expected: {stderr}"
    );
    let r: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    for k in [
        "terms",
        "basis",
        "model",
        "crop",
        "padding",
        "t_max",
        "error_bound",
        "bytes_written",
        "time_s",
    ] {
        assert!(r.get(k).is_some(), "report lacks {k}");
    }
    assert_eq!(r["basis"], "chebyshev");
    let p = Pack::read(&out).unwrap();
    assert_eq!(r["terms"].as_u64().unwrap() as usize, p.manifest.terms);
    assert_eq!(p.manifest.source.file, "Elaph100x100.png");
    // 8-bit grey scaled to 375 nm: H is at most half of it.
    assert!(
        p.manifest.height_half_range_m > 50e-9
            && p.manifest.height_half_range_m <= 187.5e-9 + 1e-15
    );
    let side: Pack = Pack {
        manifest: sunbeam_pack::Manifest::from_json(&std::fs::read_to_string(&man).unwrap())
            .unwrap(),
        terms: p.terms.clone(),
    };
    assert!(side.manifest == p.manifest);
    let dep_text = std::fs::read_to_string(&dep).unwrap();
    assert!(
        dep_text.contains("elaph.ktx2:") && dep_text.contains("Elaph100x100.png"),
        "{dep_text}"
    );
    // Flat-ish sanity: R at specular is finite and at most 1.
    let r0 = p.reflectance(0.0, 0.0, -2.0, 550e-9);
    assert!(r0.is_finite() && r0 <= 1.0 + 1e-4);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn same_input_gives_byte_identical_files_whatever_the_threads() {
    let d = tmpdir("ident");
    let h = height_exr(&d, false);
    let (a, b) = (d.join("a.ktx2"), d.join("b.ktx2"));
    assert_eq!(
        run(&[
            h.to_str().unwrap(),
            "-o",
            a.to_str().unwrap(),
            "--threads",
            "1",
            "-q"
        ])
        .0,
        0
    );
    assert_eq!(
        run(&[
            h.to_str().unwrap(),
            "-o",
            b.to_str().unwrap(),
            "--threads",
            "2",
            "-q"
        ])
        .0,
        0
    );
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let (c, e) = (d.join("c.exr"), d.join("e.exr"));
    assert_eq!(
        run(&[h.to_str().unwrap(), "-o", c.to_str().unwrap(), "-q"]).0,
        0
    );
    assert_eq!(
        run(&[h.to_str().unwrap(), "-o", e.to_str().unwrap(), "-q"]).0,
        0
    );
    assert_eq!(std::fs::read(&c).unwrap(), std::fs::read(&e).unwrap());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn exr_split_and_atlas_outputs() {
    let d = tmpdir("exr");
    let h = height_exr(&d, false);
    let s = d.join("s.exr");
    let (code, _, err) = run(&[
        h.to_str().unwrap(),
        "-o",
        s.to_str().unwrap(),
        "--split",
        "--terms",
        "5",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    for n in 0..5 {
        assert!(d.join(format!("s.n{n:02}.exr")).exists());
    }
    let p = Pack::read(&d.join("s.n00.exr")).unwrap();
    assert_eq!(p.manifest.terms, 5);
    assert!(p.manifest.error.terms_fixed);
    let a = d.join("a.exr");
    assert_eq!(
        run(&[
            h.to_str().unwrap(),
            "-o",
            a.to_str().unwrap(),
            "--atlas",
            "--terms",
            "5",
            "-q"
        ])
        .0,
        0
    );
    assert!(Pack::read(&a).unwrap() == p);
    if testdata::have_command("oiiotool", &["--help"]) {
        for f in [d.join("s.n03.exr"), a.clone()] {
            let st = Command::new("oiiotool")
                .args(["-q", "-a"])
                .arg(&f)
                .arg("--printstats")
                .output()
                .unwrap();
            assert!(st.status.success(), "oiiotool rejects {}", f.display());
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn bad_inputs_and_usage_get_their_exit_codes() {
    let d = tmpdir("bad");
    let h = height_exr(&d, true);
    let out = d.join("x.ktx2");
    let (code, _, err) = run(&[h.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--fill-nonfinite"), "{err}");
    assert!(!out.exists(), "no output on failure");
    let good = height_exr(&d, false);
    assert_eq!(
        run(&[
            good.to_str().unwrap(),
            "-o",
            d.join("x.png").to_str().unwrap()
        ])
        .0,
        1
    );
    assert_eq!(
        run(&[
            good.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--coherence",
            "65"
        ])
        .0,
        1
    );
    assert_eq!(
        run(&[
            good.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--split"
        ])
        .0,
        1
    );
    assert_eq!(
        run(&[
            d.join("missing.exr").to_str().unwrap(),
            "-o",
            out.to_str().unwrap()
        ])
        .0,
        2
    );
    std::fs::write(d.join("junk.exr"), b"v/1\x01garbage").unwrap();
    assert_eq!(
        run(&[
            d.join("junk.exr").to_str().unwrap(),
            "-o",
            out.to_str().unwrap()
        ])
        .0,
        2
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn scene_bounds_shrink_the_pack_and_are_reported() {
    let d = tmpdir("scene");
    let h = height_exr(&d, false);
    // Light from the side (90 deg from the view direction): |wi + wr| <= ~sqrt(2).
    let scene = r#"{"camera":{"eye":[0,0,3],"target":[0,0,0]},
        "lights":[{"direction":[1,0,0.05]}],
        "meshes":[{"mesh":"builtin:quad"}]}"#;
    std::fs::write(d.join("scene.json"), scene).unwrap();
    let (full, bounded) = (d.join("full.ktx2"), d.join("bounded.ktx2"));
    assert_eq!(
        run(&[h.to_str().unwrap(), "-o", full.to_str().unwrap(), "-q"]).0,
        0
    );
    let (code, out, err) = run(&[
        h.to_str().unwrap(),
        "-o",
        bounded.to_str().unwrap(),
        "--scene",
        d.join("scene.json").to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(
        r["notes"]
            .as_array()
            .unwrap()
            .iter()
            .any(|n| n.as_str().unwrap().contains("skipped")),
        "{out}"
    );
    let (pf, pb) = (Pack::read(&full).unwrap(), Pack::read(&bounded).unwrap());
    assert!(pb.manifest.crop.width < pf.manifest.crop.width);
    assert!(pb.manifest.max_w < 2.0);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn three_js_ktx2_loader_reads_the_pack() {
    let modules = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/node/node_modules");
    if !modules.join("three").is_dir() {
        assert!(
            !testdata::require_all(),
            "tests/node/node_modules/three missing (npm ci in tests/node)"
        );
        eprintln!("SKIP: three.js not installed in tests/node");
        return;
    }
    if !testdata::have_command("node", &[]) {
        return;
    }
    let d = tmpdir("three");
    let h = height_exr(&d, false);
    for (prec, vk, ty) in [("f32", 103, "float"), ("f16", 83, "half")] {
        let out = d.join(format!("p{prec}.ktx2"));
        assert_eq!(
            run(&[
                h.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--precision",
                prec,
                "-q"
            ])
            .0,
            0
        );
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/three_ktx2.mjs");
        let o = Command::new("node")
            .arg(&script)
            .arg(&modules)
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "node: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let p = Pack::read(&out).unwrap();
        let m = &p.manifest;
        assert_eq!(r["vkFormat"], vk);
        assert_eq!(r["type"], ty);
        assert_eq!(r["format"], "RG");
        assert_eq!(r["width"].as_u64().unwrap() as usize, m.crop.width);
        assert_eq!(r["height"].as_u64().unwrap() as usize, m.crop.height);
        assert_eq!(r["layers"].as_u64().unwrap() as usize, m.terms);
        assert_eq!(r["terms"].as_u64().unwrap() as usize, m.terms);
        assert_eq!(
            r["dataLength"].as_u64().unwrap() as usize,
            2 * m.crop.width * m.crop.height * m.terms
        );
        assert!(r["writer"].as_str().unwrap().starts_with("sunbeam-pack "));
        if prec == "f32" {
            let first: Vec<f64> = r["first"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            for (i, v) in first.iter().enumerate() {
                assert_eq!(*v as f32, p.terms[i]);
            }
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}
