//! Helpers of the three.js tests (tests/threejs_render.rs,
//! tests/threejs_scales.rs): examples/threejs/render.mjs set up as a user
//! runs it, ridge packs, and a scene rendered by render.mjs and by the
//! reference (`sunbeam-eval render --samples 16`), compared in linear light.

use std::path::{Path, PathBuf};
use std::process::Command;
use sunbeam::{run_ok, tool, workspace_root};
use sunbeam_common::testdata;
use sunbeam_frame::{compare_linear, ColourDiff, LinearImage};

/// The example next to a node_modules with three and playwright-core, as a
/// user runs it (in `d`/js); None (the test skips) without node, chromium or
/// the modules.
pub fn example(d: &Path) -> Option<PathBuf> {
    if !testdata::have_command("node", &[]) || !testdata::have_command("chromium", &["--version"]) {
        return None;
    }
    let modules = workspace_root().join("tests/node/node_modules");
    if !modules.join("playwright-core/package.json").exists() {
        if testdata::require_all() {
            panic!("tests/node/node_modules/playwright-core missing and SUNBEAM_REQUIRE_ALL=1 (run scripts/ensure-deps.sh)");
        }
        eprintln!("SKIP: playwright-core not installed in tests/node/node_modules");
        return None;
    }
    let js = d.join("js");
    std::fs::create_dir_all(&js).unwrap();
    for f in ["render.mjs", "render-page.mjs", "sunbeam-three.mjs"] {
        std::fs::copy(
            workspace_root().join("examples/threejs").join(f),
            js.join(f),
        )
        .unwrap();
    }
    std::os::unix::fs::symlink(&modules, js.join("node_modules")).unwrap();
    Some(js.join("render.mjs"))
}

/// A pack of the synthetic Xenopeltis-like ridges (`size`^2 samples of
/// `pixel`) with its response map, `d`/NAME.ktx2, by the tools.
pub fn ridge_pack(d: &Path, name: &str, size: &str, pixel: &str) -> PathBuf {
    let h = d.join(format!("{name}.exr"));
    let p = d.join(format!("{name}.ktx2"));
    run_ok(
        Command::new(tool("sunbeam-import"))
            .args([
                "synthetic:xenopeltis",
                "--synthetic-size",
                size,
                "--synthetic-pixel",
                pixel,
                "-q",
                "-o",
            ])
            .arg(&h),
    );
    run_ok(
        Command::new(tool("sunbeam-pack"))
            .arg(&h)
            .arg("-o")
            .arg(&p)
            .args(["--response", "-q"]),
    );
    p
}

/// render.mjs on the scene file `scene`: the linear frame (also written as
/// `d`/NAME.exr and NAME.png).
pub fn threejs_frame(render: &Path, d: &Path, scene: &Path, name: &str) -> LinearImage {
    let (png, exr) = (d.join(format!("{name}.png")), d.join(format!("{name}.exr")));
    run_ok(
        Command::new("node")
            .arg(render)
            .arg(scene)
            .arg("-o")
            .arg(&png)
            .arg("--exr")
            .arg(&exr)
            .env("SUNBEAM_PLAY", tool("sunbeam-play")),
    );
    assert!(png.is_file());
    LinearImage::read_exr(&exr).unwrap()
}

/// The reference of the scene file `scene` (`sunbeam-eval render --samples
/// 16`), written as `out` (EXR).
pub fn reference_frame(scene: &Path, out: &Path) -> LinearImage {
    run_ok(
        Command::new(tool("sunbeam-eval"))
            .arg("render")
            .arg(scene)
            .args(["--samples", "16", "-q", "-o"])
            .arg(out),
    );
    LinearImage::read_exr(out).unwrap()
}

/// render.mjs on `scene` and `sunbeam-eval render --samples 16` on
/// `ref_scene` (written into `d` as NAME.json and NAME-ref.json): the
/// difference over lit pixels.
pub fn measure(render: &Path, d: &Path, scene: &str, ref_scene: &str, name: &str) -> ColourDiff {
    let s = d.join(format!("{name}.json"));
    std::fs::write(&s, scene).unwrap();
    let rs = d.join(format!("{name}-ref.json"));
    std::fs::write(&rs, ref_scene).unwrap();
    let a = threejs_frame(render, d, &s, name);
    let r = reference_frame(&rs, &d.join(format!("{name}-ref.exr")));
    let c = compare_linear(&a, &r).unwrap();
    eprintln!("three.js {name}: {c}");
    assert!(c.pixels > 200, "{name}: only {} lit pixels", c.pixels);
    c
}
