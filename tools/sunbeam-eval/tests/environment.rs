//! `sunbeam-eval render` under a scene `environment` (docs/SCENE.md,
//! docs/LIGHTING.md): a sky-lit scene renders (deterministic for a seed,
//! the two estimators agree);
//! bad environments exit 2 naming the file and field, with no output.

use std::path::Path;
use std::process::{Command, Output};

fn render(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sunbeam-eval"))
        .arg("render")
        .arg(scene)
        .arg("-o")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

/// The seed mechanics are tested on the Monte Carlo estimator (under the
/// quadrature a diffuse sphere's frame does not depend on the seed).
const MC: &str = "--env-estimator";
const MC_NAME: &str = "monte-carlo";

fn scene(env: &str) -> String {
    format!(
        r#"{{ "camera": {{ "eye": [0, 0.5, 2.5], "target": [0, 0, 0] }},
  "meshes": [ {{ "mesh": "builtin:sphere", "base_color": [0.8, 0.8, 0.8] }} ],
  "environment": {env},
  "size": [12, 12] }}"#
    )
}

/// A scratch folder `sb-eval-TAG-PID` holding `sky.json`: [`scene`] under
/// the sky (sun at 35 degrees): the folder and the scene file.
fn sky_scene_in(tag: &str) -> (std::path::PathBuf, std::path::PathBuf) {
    let d = std::env::temp_dir().join(format!("sb-eval-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let s = d.join("sky.json");
    std::fs::write(
        &s,
        scene(r#"{ "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 120, "turbidity": 3 }, "intensity": 1 }"#),
    )
    .unwrap();
    (d, s)
}

#[test]
fn sky_scene_renders_and_bad_environments_are_refused() {
    let (d, s) = sky_scene_in("env");
    let (a, b) = (d.join("a.exr"), d.join("b.exr"));
    for out in [&a, &b] {
        let o = render(&s, out, &[MC, MC_NAME, "--samples", "4", "--seed", "7"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(
        std::fs::read(&a).unwrap(),
        std::fs::read(&b).unwrap(),
        "same seed, other frame"
    );
    // --compare: the same seed gives the same frame (CIEDE2000 0), another seed not.
    let compare = |seed: &str| {
        let args = [
            MC,
            MC_NAME,
            "--samples",
            "4",
            "--seed",
            seed,
            "--compare",
            a.to_str().unwrap(),
        ];
        let o = render(&s, &d.join("c.exr"), &args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let same = compare("7");
    assert!(same.contains("CIEDE2000 mean 0.000 p99 0.000"), "{same}");
    let other = compare("8");
    assert!(
        other.contains("CIEDE2000") && !other.contains("max 0.000"),
        "{other}"
    );
    // --seed 7 --seed 8: the mean of the two frames (read back and averaged here).
    let b8 = d.join("b8.exr");
    let o = render(&s, &b8, &[MC, MC_NAME, "--samples", "4", "--seed", "8"]);
    assert!(o.status.success());
    let both = d.join("both.exr");
    let o = render(
        &s,
        &both,
        &[MC, MC_NAME, "--samples", "4", "--seed", "7", "--seed", "8"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (p7, p8, pm) = (
        sunbeam_raster::LinearImage::read_exr(&a).unwrap(),
        sunbeam_raster::LinearImage::read_exr(&b8).unwrap(),
        sunbeam_raster::LinearImage::read_exr(&both).unwrap(),
    );
    let mut differs = false;
    for ((x, y), m) in p7.rgb.iter().zip(&p8.rgb).zip(&pm.rgb) {
        for c in 0..3 {
            let want = (x[c] + y[c]) / 2.0;
            assert!(
                (m[c] - want).abs() <= 1e-6 * want.abs().max(1e-3),
                "{m:?} vs {x:?} {y:?}"
            );
            differs |= x[c] != y[c];
        }
    }
    assert!(differs, "two seeds gave the same frame");
    // A white diffuse sphere under the sky is lit (no point light is added).
    let img = sunbeam_raster_probe(&a);
    assert!(img > 0.05, "mean value {img}");
    // The default estimator (the quadrature; here the diffuse part from the
    // tabulated irradiance) agrees with Monte Carlo's mean of two seeds.
    let q = d.join("q.exr");
    let o = render(&s, &q, &["--samples", "16"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (vq, vm) = (sunbeam_raster_probe(&q), sunbeam_raster_probe(&both));
    assert!(
        (vq / vm - 1.0).abs() < 0.05,
        "quadrature {vq} vs Monte Carlo {vm}"
    );
    // An unknown estimator is a usage error (exit 1, DESIGN.md).
    let o = render(&s, &q, &["--env-estimator", "guess"]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );

    let bad_map = d.join("bad.hdr");
    std::fs::write(&bad_map, b"not an image").unwrap();
    let wide = d.join("wide.hdr");
    std::fs::write(&wide, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 3\n").unwrap();
    for (env, field, file) in [
        (
            r#"{ "map": "missing.exr" }"#,
            "environment.map",
            "missing.exr",
        ),
        (r#"{ "map": "bad.hdr" }"#, "environment.map", "bad.hdr"),
        (r#"{ "map": "wide.hdr" }"#, "environment.map", "wide.hdr"),
        (
            r#"{ "sky": { "sun_elevation_deg": 30 }, "intensity": -1 }"#,
            "environment.intensity",
            "",
        ),
        (
            r#"{ "sky": { "sun_elevation_deg": 30, "turbidity": 40 } }"#,
            "turbidity",
            "",
        ),
    ] {
        let sc = d.join("bad.json");
        std::fs::write(&sc, scene(env)).unwrap();
        let out = d.join("bad.png");
        let o = render(&sc, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{env}: {err}");
        assert!(err.contains(field) && err.contains(file), "{env}: {err}");
        assert!(!out.exists(), "{env}: output written");
    }
    std::fs::remove_dir_all(&d).ok();
}

/// A mesh's `masking` and `rms_slope` (docs/SCENE.md): bad values exit 2
/// naming the scene file and the field, with no output.
#[test]
fn bad_masking_is_refused() {
    let d = std::env::temp_dir().join(format!("sb-eval-mask-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    for (mesh_extra, field) in [
        (r#""masking": "beckmann""#, "masking"),
        (
            r#""masking": "smith", "rms_slope": -0.5"#,
            "meshes[0].rms_slope",
        ),
        (r#""masking": "smith", "rms_slope": [0.2]"#, "rms_slope"),
    ] {
        let sc = d.join("mask.json");
        std::fs::write(
            &sc,
            format!(
                r#"{{ "camera": {{ "eye": [0, 0.5, 2.5], "target": [0, 0, 0] }},
  "meshes": [ {{ "mesh": "builtin:sphere", {mesh_extra} }} ], "size": [8, 8] }}"#
            ),
        )
        .unwrap();
        let out = d.join("mask.png");
        let o = render(&sc, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{mesh_extra}: {err}");
        assert!(
            err.contains(field) && err.contains("mask.json"),
            "{mesh_extra}: {err}"
        );
        assert!(!out.exists(), "{mesh_extra}: output written");
    }
    std::fs::remove_dir_all(&d).ok();
}

/// Mean of the EXR's values (a crude "is it lit" probe, read with `exr`).
fn sunbeam_raster_probe(path: &Path) -> f64 {
    let img = sunbeam_raster::LinearImage::read_exr(path).unwrap();
    img.rgb
        .iter()
        .map(|p| (p[0] + p[1] + p[2]) as f64 / 3.0)
        .sum::<f64>()
        / img.rgb.len() as f64
}

/// `--turntable N`: an animated PNG of N frames (acTL says N), the first frame
/// equal to the plain render, the others different (the camera moves, the
/// light stays); `--frames-dir` writes them; bad values are usage errors
/// (exit 1) with no output.
#[test]
fn turntable_writes_an_animated_png() {
    let d = std::env::temp_dir().join(format!("sb-eval-tt-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let s = d.join("lit.json");
    std::fs::write(
        &s,
        r#"{ "camera": { "eye": [0, 0.5, 2.5], "target": [0, 0, 0] },
  "lights": [ { "direction": [1, 1, 0.3] } ],
  "meshes": [ { "mesh": "builtin:sphere", "base_color": [0.8, 0.5, 0.2] } ],
  "size": [16, 12] }"#,
    )
    .unwrap();
    let (anim, plain, frames) = (d.join("tt.png"), d.join("plain.png"), d.join("frames"));
    let o = render(&s, &plain, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = render(
        &s,
        &anim,
        &["--turntable", "4", "--frames-dir", frames.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&anim).unwrap();
    let at = bytes
        .windows(4)
        .position(|w| w == b"acTL")
        .expect("an acTL chunk");
    let n = u32::from_be_bytes(bytes[at + 4..at + 8].try_into().unwrap());
    assert_eq!(n, 4);
    assert_eq!(bytes.windows(4).filter(|w| *w == b"fcTL").count(), 4);
    let f: Vec<Vec<u8>> = (0..4)
        .map(|k| std::fs::read(frames.join(format!("frame-{k:03}.png"))).unwrap())
        .collect();
    assert_eq!(
        f[0],
        std::fs::read(&plain).unwrap(),
        "frame 0 is the scene's own view"
    );
    assert_ne!(f[0], f[1]);
    for bad in [
        vec!["--turntable", "0"],
        vec!["--turntable", "3", "--axis", "0,0,0"],
        vec!["--frames-dir", "x"],
    ] {
        let out = d.join("bad.png");
        let o = render(&s, &out, &bad);
        assert_eq!(
            o.status.code(),
            Some(1),
            "{bad:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!out.exists(), "{bad:?}");
    }
    let o = render(&s, &d.join("tt.exr"), &["--turntable", "3"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("FILE.png"));
    std::fs::remove_dir_all(&d).ok();
}

/// A real HDRI with lossy-compression negatives (../shared/data/hdri/night.exr:
/// 829 values in 596 texels, from the data's README): counted in the `--json`
/// report, reported in exactly one warning line, none with `-q`.
#[test]
fn real_hdri_negatives_are_counted_and_warned_once() {
    let Some(night) = sunbeam_common::testdata::shared_file("hdri/night.exr") else {
        return;
    };
    let d = std::env::temp_dir().join(format!("sb-eval-hdri-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let s = d.join("night.json");
    let env = format!(r#"{{ "map": "{}" }}"#, night.display());
    std::fs::write(&s, scene(&env)).unwrap();
    let o = render(&s, &d.join("n.png"), &["--samples", "1", "--json"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let z = &r["environment_negatives_zeroed"];
    assert_eq!(
        (z["values"].as_u64(), z["texels"].as_u64()),
        (Some(829), Some(596)),
        "{r}"
    );
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains("night.exr") && warnings[0].contains("829"),
        "{err}"
    );
    let o = render(&s, &d.join("q.png"), &["--samples", "1", "-q"]);
    assert!(o.status.success());
    assert!(!String::from_utf8_lossy(&o.stderr).contains("warning"));
    let _ = std::fs::remove_dir_all(&d);
}

/// `--lambda-step NM` (docs/EVAL.md "Wavelength step"): the `--json` report
/// names the step (null: the adaptive one); 0 and 11 are usage errors (exit
/// 1, DESIGN.md's codes) naming the flag, with no output.
#[test]
fn lambda_step_is_reported_and_checked() {
    let (d, s) = sky_scene_in("step");
    for (extra, want) in [
        (vec!["--lambda-step", "2"], serde_json::json!(2)),
        (vec![], serde_json::Value::Null),
    ] {
        let mut args = vec!["--samples", "1", "--json"];
        args.extend(extra);
        let o = render(&s, &d.join("ok.png"), &args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(r["lambda_step_nm"], want, "{r}");
    }
    for bad in ["0", "11"] {
        let out = d.join(format!("bad-{bad}.png"));
        let o = render(&s, &out, &["--lambda-step", bad]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "--lambda-step {bad}: {err}");
        assert!(err.contains("--lambda-step"), "{err}");
        assert!(!out.exists(), "--lambda-step {bad} wrote {}", out.display());
    }
}

/// `--converge DE` (docs/EVAL.md "A converged reference"): the report says
/// what it did; the frame is the plain frame where one round's estimate
/// suffices; bad combinations are usage errors (exit 1) with no output.
#[test]
fn converge_reports_and_refuses_bad_combinations() {
    let (d, s) = sky_scene_in("converge");
    let out = d.join("c.exr");
    // The quadrature on the diffuse sphere: inside, the seeds give the same
    // value (the pixels close after the first level); at the silhouette the
    // sub-pixel positions differ (those go up).
    let o = render(
        &s,
        &out,
        &[
            "--samples",
            "4",
            "--converge",
            "0.5",
            "--max-samples",
            "64",
            "--max-seeds",
            "4",
            "--json",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let c = &report["converge"];
    eprintln!("{c}");
    let (mean, max) = (
        c["samples_mean"].as_f64().unwrap(),
        c["samples_max"].as_u64().unwrap(),
    );
    // Every pixel took at least the first level's 3 rounds of 4 samples, the
    // open ones 3 rounds of 16 and then up to 4 of 64: 12 + 48 + 256.
    assert!(
        mean >= 12.0 && max > 12 && max <= 316 && mean < max as f64,
        "{c}"
    );
    assert!(c["rounds"].as_u64().unwrap() >= 4, "{c}");
    assert!(c["estimate_p99"].as_f64().unwrap() > 0.0, "{c}");
    let open = c["open"].as_u64().unwrap();
    let warned = String::from_utf8_lossy(&o.stderr).contains("still above --converge");
    assert_eq!(
        open > 0,
        warned,
        "{c}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.is_file());

    let none = d.join("none.exr");
    let plain = d.join("plain.json");
    std::fs::write(
        &plain,
        r#"{ "camera": { "eye": [0, 0.5, 2.5], "target": [0, 0, 0] },
  "meshes": [ { "mesh": "builtin:sphere" } ], "size": [12, 12] }"#,
    )
    .unwrap();
    for (scene, extra, says) in [
        (
            &s,
            vec!["--converge", "0.5", "--seed", "1", "--seed", "2"],
            "one --seed",
        ),
        (
            &s,
            vec!["--converge", "0.5", "--samples", "16", "--max-samples", "4"],
            "--max-samples",
        ),
        (
            &s,
            vec!["--converge", "0.5", "--max-samples", "99"],
            "square",
        ),
        (&s, vec!["--converge", "0"], "positive"),
        (&s, vec!["--max-samples", "64"], "--converge"),
        (&plain, vec!["--converge", "0.5"], "no environment"),
    ] {
        let o = render(scene, &none, &extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{extra:?}: {err}");
        assert!(err.contains(says), "{extra:?}: {err}");
        assert!(!none.exists(), "{extra:?} wrote output");
    }
    std::fs::remove_dir_all(&d).ok();
}
