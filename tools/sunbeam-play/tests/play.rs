//! sunbeam-play end to end: headless frames against `--cpu` (the reference),
//! the no-adapter message, and a real window under Xvfb whose swapchain image is
//! not blank.

use std::path::{Path, PathBuf};
use std::process::Command;
use sunbeam_frame::{fixtures, Image};

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-play");

fn tmp(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("play-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A scene file with the blazed grating on the built-in quad; None when the data is missing.
fn blazed_scene(dir: &Path, size: u32) -> Option<PathBuf> {
    let data = sunbeam_common::testdata::shared_file("snake/BlazingBump.bmp")?;
    let pack = fixtures::pack(
        &fixtures::BLAZED,
        data.parent().unwrap(),
        &Default::default(),
    )
    .unwrap();
    sunbeam_pack::io::write_pack(
        &pack,
        &dir.join("blazed.ktx2"),
        sunbeam_pack::io::OutputKind::Ktx2,
    )
    .unwrap();
    let (mut scene, _) = fixtures::quad_scene([size, size]);
    scene.meshes[0].pack = Some("blazed.ktx2".into());
    let text = serde_json::to_string_pretty(&scene).unwrap();
    let p = dir.join("scene.json");
    std::fs::write(&p, text).unwrap();
    Some(p)
}

fn have_gpu() -> bool {
    let ok = sunbeam_render::Gpu::headless(Default::default()).is_ok();
    if !ok {
        if sunbeam_common::testdata::require_all() {
            panic!("no GPU adapter and SUNBEAM_REQUIRE_ALL=1 (install mesa-vulkan-drivers)");
        }
        eprintln!("SKIP: no GPU adapter");
    }
    ok
}

#[test]
fn headless_frame_matches_cpu_reference_and_is_deterministic() {
    let dir = tmp("headless");
    let Some(scene) = blazed_scene(&dir, 64) else {
        return;
    };
    if !have_gpu() {
        return;
    }
    let run = |args: &[&str]| {
        let o = Command::new(BIN).arg(&scene).args(args).output().unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8_lossy(&o.stdout).to_string()
    };
    let gpu = dir.join("gpu.png");
    let cpu = dir.join("cpu.png");
    run(&["--cpu", "-o", cpu.to_str().unwrap()]);
    let out = run(&[
        "--headless",
        "-o",
        gpu.to_str().unwrap(),
        "--compare",
        cpu.to_str().unwrap(),
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    let mean = report["ciede2000"]["mean"].as_f64().unwrap();
    let p99 = report["ciede2000"]["p99"].as_f64().unwrap();
    assert!(mean < 0.5 && p99 < 2.0, "{report}");
    let a = std::fs::read(&gpu).unwrap();
    let gpu2 = dir.join("gpu2.png");
    run(&["--headless", "-o", gpu2.to_str().unwrap(), "--frames", "2"]);
    assert_eq!(
        a,
        std::fs::read(&gpu2).unwrap(),
        "headless frames are not deterministic"
    );
    let img = Image::read_png(&gpu).unwrap();
    assert!(img.mean_sd().1 > 0.02, "blank frame");
}

#[test]
fn usage_and_input_errors_have_their_exit_codes() {
    let o = Command::new(BIN).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let o = Command::new(BIN)
        .args(["/nonexistent/scene.json", "--headless", "-o", "x.png"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("/nonexistent/scene.json"));
    let o = Command::new(BIN)
        .args(["--mesh", "builtin:cube", "--headless", "-o", "x.png"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    // --supersample is 1..8: outside, a usage error naming the flag, no frame.
    for k in ["0", "9"] {
        let f = std::env::temp_dir().join(format!("sunbeam-play-ss{k}-{}.png", std::process::id()));
        let o = Command::new(BIN)
            .args([
                "--mesh",
                "builtin:quad",
                "--headless",
                "--supersample",
                k,
                "-o",
            ])
            .arg(&f)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "--supersample {k}: {err}");
        assert!(err.contains("--supersample must be 1..8"), "{err}");
        assert!(!f.exists());
    }
    // Edge refinement's levels: an odd first level, or a last level past 64
    // positions a side, is a usage error naming the flags, no frame.
    for (args, says) in [
        (
            ["--edge-supersample", "5", "--edge-levels", "2"],
            "even --edge-supersample",
        ),
        (
            ["--edge-supersample", "32", "--edge-levels", "3"],
            "reaches 128",
        ),
    ] {
        let f =
            std::env::temp_dir().join(format!("sunbeam-play-levels-{}.png", std::process::id()));
        let o = Command::new(BIN)
            .args(["--mesh", "builtin:quad", "--headless", "-o"])
            .arg(&f)
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("--edge-levels") && err.contains(says), "{err}");
        assert!(!f.exists());
    }
}

#[test]
fn no_adapter_says_what_to_install() {
    let dir = tmp("noadapter");
    let o = Command::new(BIN)
        .args([
            "--mesh",
            "builtin:quad",
            "--headless",
            "--backend",
            "vulkan",
            "-o",
        ])
        .arg(dir.join("x.png"))
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("mesa-vulkan-drivers"), "{err}");
    assert!(!dir.join("x.png").exists());
}

/// A real window under Xvfb (xvfb-run -a): the player's own copy of its swapchain
/// image after 3 frames must not be blank.
#[test]
fn window_opens_under_xvfb_and_is_not_blank() {
    if !sunbeam_common::testdata::have_command("xvfb-run", &["--help"]) {
        return;
    }
    let dir = tmp("window");
    let Some(scene) = blazed_scene(&dir, 160) else {
        return;
    };
    if !have_gpu() {
        return;
    }
    let shot = dir.join("window.png");
    let o = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 640x480x24", BIN])
        .arg(&scene)
        .args(["--frames", "3", "--hold-secs", "0.5", "-o"])
        .arg(&shot)
        .output()
        .unwrap();
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "window run failed: {log}");
    assert!(log.contains("window frames: n=3"), "{log}");
    let img = Image::read_png(&shot).unwrap_or_else(|e| panic!("no screenshot ({e}): {log}"));
    let (mean, sd) = img.mean_sd();
    eprintln!(
        "window screenshot {}x{} mean {mean:.3} sd {sd:.3}",
        img.width, img.height
    );
    assert!(
        img.width == 160 && img.height == 160,
        "{}x{}",
        img.width,
        img.height
    );
    assert!(
        mean > 0.02 && sd > 0.02,
        "screenshot looks blank: mean {mean} sd {sd}"
    );
}
