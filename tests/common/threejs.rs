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

/// The tests' common pack, `ridges.ktx2` in `d` (with its response maps):
/// [`ridge_pack`] of 256^2 samples of 20 nm, built once per test binary and
/// linked into `d` (each build takes about 4 s).
pub fn ridges(d: &Path) {
    static BUILT: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    let dir = BUILT.get_or_init(|| {
        let dir = sunbeam::scratch("threejs-ridges");
        ridge_pack(&dir, "ridges", "256", "20nm");
        dir
    });
    for f in [
        "ridges.ktx2",
        "ridges.response.ktx2",
        "ridges.env-response.ktx2",
        "ridges.env-cells.ktx2",
    ] {
        assert!(dir.join(f).is_file(), "{f} not built");
        std::os::unix::fs::symlink(dir.join(f), d.join(f)).unwrap();
    }
}

/// render.mjs on the scene file `scene`: the linear frame (also written as
/// `d`/NAME.exr and NAME.png), 4 x 4 supersampled (render.mjs's default).
pub fn threejs_frame(render: &Path, d: &Path, scene: &Path, name: &str) -> LinearImage {
    threejs_frame_at(render, d, scene, name, 4)
}

/// [`threejs_frame`] at `--supersample K`.
pub fn threejs_frame_at(
    render: &Path,
    d: &Path,
    scene: &Path,
    name: &str,
    supersample: u32,
) -> LinearImage {
    threejs_frame_with(render, d, scene, name, supersample, &[])
}

/// [`threejs_frame_at`] with more render.mjs options (`--tile T`, `--msaa N`).
pub fn threejs_frame_with(
    render: &Path,
    d: &Path,
    scene: &Path,
    name: &str,
    supersample: u32,
    extra: &[&str],
) -> LinearImage {
    let (png, exr) = (d.join(format!("{name}.png")), d.join(format!("{name}.exr")));
    run_ok(
        Command::new("node")
            .arg(render)
            .arg(scene)
            .arg("-o")
            .arg(&png)
            .arg("--exr")
            .arg(&exr)
            .args(["--supersample", &supersample.to_string()])
            .args(extra)
            .env("SUNBEAM_PLAY", tool("sunbeam-play")),
    );
    assert!(png.is_file());
    LinearImage::read_exr(&exr).unwrap()
}

/// The reference of the scene file `scene` (`sunbeam-eval render --samples
/// 16`), written as `out` (EXR).
pub fn reference_frame(scene: &Path, out: &Path) -> LinearImage {
    reference_frame_at(scene, out, 16)
}

/// [`reference_frame`] at `samples` per pixel. Under an environment the
/// quadrature's cost per pixel hardly grows with the samples (a pixel's
/// samples share the maps' texels: docs/LIGHTING.md "Quadrature"), and
/// thin meshes need many: the baked snake under the sky at 96 x 48, two
/// seeds differ by CIEDE2000 p99 25.9 / 14.2 / 5.4 at 16 / 64 / 256 samples
/// (10.9 s / 13.0 s / 13.3 s, 2026-11-27).
pub fn reference_frame_at(scene: &Path, out: &Path, samples: u32) -> LinearImage {
    run_ok(
        Command::new(tool("sunbeam-eval"))
            .arg("render")
            .arg(scene)
            .args(["--samples", &samples.to_string(), "-q", "-o"])
            .arg(out),
    );
    LinearImage::read_exr(out).unwrap()
}

/// render.mjs on `scene` and `sunbeam-eval render --samples 16` on
/// `ref_scene` (written into `d` as NAME.json and NAME-ref.json): the
/// difference over lit pixels.
pub fn measure(render: &Path, d: &Path, scene: &str, ref_scene: &str, name: &str) -> ColourDiff {
    measure_at(render, d, scene, ref_scene, name, 16, 4)
}

/// [`measure`] with the reference at `samples` per pixel and render.mjs at
/// `--supersample supersample`.
pub fn measure_at(
    render: &Path,
    d: &Path,
    scene: &str,
    ref_scene: &str,
    name: &str,
    samples: u32,
    supersample: u32,
) -> ColourDiff {
    let s = d.join(format!("{name}.json"));
    std::fs::write(&s, scene).unwrap();
    let rs = d.join(format!("{name}-ref.json"));
    std::fs::write(&rs, ref_scene).unwrap();
    let a = threejs_frame_at(render, d, &s, name, supersample);
    let r = reference_frame_at(&rs, &d.join(format!("{name}-ref.exr")), samples);
    let c = compare_linear(&a, &r).unwrap();
    eprintln!("three.js {name}: {c}");
    assert!(c.pixels > 200, "{name}: only {} lit pixels", c.pixels);
    c
}
