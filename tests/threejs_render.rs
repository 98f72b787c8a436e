//! examples/threejs/render.mjs (three.js in headless Chromium, WebGL2 on
//! SwiftShader) against the CPU reference: the same scene file rendered by
//! `sunbeam-eval render --samples 16` (a different code path: per-pixel spectral
//! evaluation of the pack, no response map, no GPU), both anti-aliased and
//! compared in linear light, CIEDE2000 over lit pixels p99 < 2 (issue 12). The
//! page must load with no WebGL or console errors (render.mjs fails on any).
//! Scenes: a front-lit sphere and the baked snake, each with a ridge pack
//! (absolute reflectance, the default; their exposures were raised by
//! log2(1 / F(0)) = 4.64 stops from those of the relative normalisation, so
//! the frames are as bright and the comparisons as sensitive as they were),
//! and the sphere lit from the side with another skin: Smith masking with the
//! pack's slopes, an index of 1.4, relative reflectance.

#[path = "gpu/mod.rs"]
mod gpu;

mod common;

use common::threejs::{
    example, measure, measure_at, reference_frame_at, ridge_pack, ridges, threejs_frame_at,
    threejs_frame_with,
};
use std::path::Path;
use std::process::Command;
use sunbeam::{run_ok, scratch, tool, workspace_root};
use sunbeam_common::testdata;
use sunbeam_frame::linear::compare_regions_within;
use sunbeam_frame::{compare_linear, LinearImage};

/// render.mjs on `scene` against the reference of `ref_scene` (the same
/// scene unless the material comes from the GLB's extension instead of `pack`).
fn compare(render: &Path, d: &Path, scene: &str, name: &str) {
    compare_with(render, d, scene, scene, name)
}

fn compare_with(render: &Path, d: &Path, scene: &str, ref_scene: &str, name: &str) {
    let c = measure(render, d, scene, ref_scene, name);
    assert!(c.p99 < 2.0, "{name}: three.js vs reference {c}");
}

#[test]
fn threejs_renders_the_sphere_and_the_snake_like_the_reference() {
    let d = scratch("threejs-render");
    let Some(render) = example(&d) else { return };
    ridges(&d);
    let sphere = r#"{ "camera": { "eye": [0, 0, 1.6], "target": [0, 0, 0], "fov_y_deg": 35 },
  "lights": [ { "direction": [0.15, 0.1, 1], "intensity": 1 } ],
  "meshes": [ { "mesh": "builtin:sphere", "pack": "ridges.ktx2", "base_color": [0.03, 0.03, 0.03], "diffuse_weight": 0.1 } ],
  "exposure": 4.64, "size": [48, 48] }"#;
    compare(&render, &d, sphere, "sphere");

    // The skin's uniforms: Smith masking with the pack's rms slopes (from the
    // map's copy of the manifest), another index, the relative normalisation;
    // the sphere lit from the side, where the masking shows: the reference
    // must differ visibly from the unmasked one, or the comparison would not
    // show that three.js applies it.
    let skin = r#"{ "camera": { "eye": [0, 0, 1.6], "target": [0, 0, 0], "fov_y_deg": 35 },
  "lights": [ { "direction": [1, 0.3, 0.25], "intensity": 1 } ],
  "meshes": [ { "mesh": "builtin:sphere", "pack": "ridges.ktx2", "base_color": [0.03, 0.03, 0.03], "diffuse_weight": 0.1,
                "masking": "smith", "ior": 1.4, "reflectance": "relative" } ],
  "exposure": 0, "size": [48, 48] }"#;
    compare(&render, &d, skin, "sphere-skin");
    let unmasked = d.join("sphere-skin-unmasked.json");
    std::fs::write(&unmasked, skin.replace("\"masking\": \"smith\", ", "")).unwrap();
    let unmasked_ref = d.join("sphere-skin-unmasked.exr");
    run_ok(
        Command::new(tool("sunbeam-eval"))
            .arg("render")
            .arg(&unmasked)
            .args(["--samples", "16", "-q", "-o"])
            .arg(&unmasked_ref),
    );
    let c = compare_linear(
        &LinearImage::read_exr(&d.join("sphere-skin-ref.exr")).unwrap(),
        &LinearImage::read_exr(&unmasked_ref).unwrap(),
    )
    .unwrap();
    eprintln!("masked vs unmasked reference: {c}");
    assert!(c.p99 > 5.0, "the masking changed nothing visible: {c}");

    let glb = d.join("snake.glb");
    run_ok(
        Command::new(tool("sunbeam-bake"))
            .arg("--generate-snake")
            .arg("-o")
            .arg(&glb)
            .arg("-q"),
    );
    let snake = r#"{ "camera": { "eye": [0, 0.3, 1.0], "target": [0, 0, 0], "fov_y_deg": 35 },
  "lights": [ { "direction": [0.2, 0.5, 1], "intensity": 1 }, { "direction": [-0.5, 0.3, 0.6], "intensity": 0.5 } ],
  "meshes": [ { "mesh": "snake.glb", "pack": "ridges.ktx2", "base_color": [0.05, 0.05, 0.05], "diffuse_weight": 0.2 } ],
  "exposure": 5.64, "size": [96, 48] }"#;
    compare(&render, &d, snake, "snake");

    // The material from the GLB alone (sunbeam-bake --pack writes
    // SUNBEAM_materials_diffraction): the same frame as with the scene's pack.
    run_ok(
        Command::new(tool("sunbeam-bake"))
            .args(["--generate-snake", "--pack"])
            .arg(d.join("ridges.ktx2"))
            .arg("-o")
            .arg(d.join("snake-ext.glb"))
            .arg("-q"),
    );
    let alone = snake.replace(
        "\"mesh\": \"snake.glb\", \"pack\": \"ridges.ktx2\", ",
        "\"mesh\": \"snake-ext.glb\", ",
    );
    assert!(!alone.contains("pack"));
    compare_with(&render, &d, &alone, snake, "snake-ext");
}

/// A coloured light (`lights[].color`) through a shifted lens
/// (`camera.shift`) on a non-square frame: three.js against the reference
/// (the colour tints the light's RGB in both, the shift moves the projection).
#[test]
fn threejs_renders_a_coloured_light_through_a_shifted_lens() {
    let d = scratch("threejs-render-colour-shift");
    let Some(render) = example(&d) else { return };
    ridges(&d);
    let scene = r#"{ "camera": { "eye": [0, 0, 1.6], "target": [0, 0, 0], "fov_y_deg": 35, "shift": [0.12, -0.08] },
  "lights": [ { "direction": [0.15, 0.1, 1], "intensity": 1, "color": [1, 0.35, 0.15] }, { "direction": [-0.6, 0.3, 0.8], "intensity": 0.7, "color": [0.2, 0.5, 1] } ],
  "meshes": [ { "mesh": "builtin:sphere", "pack": "ridges.ktx2", "base_color": [0.03, 0.03, 0.03], "diffuse_weight": 0.1 } ],
  "exposure": 4.64, "size": [64, 40] }"#;
    compare(&render, &d, scene, "sphere-colour-shift");
    // Drawn in 24 tiles of 50 texels (render.mjs --tile), each a view offset
    // inside the lens shift's own: the frame of one pass (measured: p99
    // 0.000, max 0.05 on limb texels).
    same_in_tiles(&render, &d, "sphere-colour-shift");
}

/// render.mjs `--tile 50` against its one-pass frame `d`/NAME.exr (NAME.json):
/// the tiles' frame equals it but for a few limb texels' coverage.
fn same_in_tiles(render: &Path, d: &Path, name: &str) {
    let one = LinearImage::read_exr(&d.join(format!("{name}.exr"))).unwrap();
    let scene = d.join(format!("{name}.json"));
    let tiled = threejs_frame_with(
        render,
        d,
        &scene,
        &format!("{name}-tiled"),
        4,
        &["--tile", "50"],
    );
    let c = compare_linear(&tiled, &one).unwrap();
    eprintln!("three.js {name} in tiles against one pass: {c}");
    assert!(c.p99 < 0.05 && c.max < 0.5, "{name} in tiles: {c}");
}

#[test]
fn bad_scenes_exit_non_zero_with_the_field_named() {
    let d = scratch("threejs-render-bad");
    let Some(render) = example(&d) else { return };
    let s = d.join("bad.json");
    // render.mjs on `text`: exit 2 naming `field`, no frame.
    let refused = |text: &str, field: &str| {
        std::fs::write(&s, text).unwrap();
        let o = Command::new("node")
            .arg(&render)
            .arg(&s)
            .arg("-o")
            .arg(d.join("x.png"))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{text}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(field), "{text}: {err}");
        assert!(!d.join("x.png").exists());
    };
    refused(
        r#"{ "camera": { "eye": [0, 0, 2], "target": [0, 0, 0] }, "meshes": [ { "mesh": "builtin:sphere", "pack": "missing.ktx2" } ] }"#,
        "meshes[0].pack",
    );
    let o = Command::new("node").arg(&render).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    // --msaa takes 1 or 4 (a usage error otherwise, before the scene is read).
    let o = Command::new("node")
        .arg(&render)
        .arg(&s)
        .args(["-o", "x.png", "--msaa", "2"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--msaa"));
    // (the arguments, the flag the error names)
    let levels = "--edge-levels";
    for (bad, flag) in [
        (&["--tile", "0"][..], "--tile"),
        (&["--supersample", "17"], "--supersample"),
        (&["--edge-supersample", "65"], "--edge-supersample"),
        (&["--edge-threshold", "-1"], "--edge-threshold"),
        (&["--edge-supersample", "8", levels, "5"], levels),
        (&["--edge-supersample", "3", levels, "2"], levels),
        (&["--edge-supersample", "32", levels, "3"], levels),
        (&[levels, "2"], levels),
    ] {
        let o = Command::new("node")
            .arg(&render)
            .arg(&s)
            .args(["-o", "x.png"])
            .args(bad)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{bad:?}");
        assert!(String::from_utf8_lossy(&o.stderr).contains(flag), "{bad:?}");
    }
    // A light's colour and the lens shift are checked, naming the field.
    for (bad, field) in [
        (
            r#""lights": [ { "direction": [0, 0, 1], "color": [1, -1, 0] } ]"#,
            "lights[0].color",
        ),
        (
            r#""lights": [ { "direction": [0, 0, 1], "color": [1, 1] } ]"#,
            "lights[0].color",
        ),
        (
            r#""camera": { "eye": [0, 0, 2], "target": [0, 0, 0], "shift": [0.1] }"#,
            "camera.shift",
        ),
    ] {
        let mut text = format!(
            r#"{{ "camera": {{ "eye": [0, 0, 2], "target": [0, 0, 0] }}, "meshes": [ {{ "mesh": "builtin:sphere" }} ], {bad} }}"#
        );
        if bad.starts_with(r#""camera""#) {
            text = format!(r#"{{ "meshes": [ {{ "mesh": "builtin:sphere" }} ], {bad} }}"#);
        }
        refused(&text, field);
    }
    // An environment whose map is missing: exit 2 naming it (sunbeam-play
    // --export-environment checks it), no frame.
    std::fs::write(&s, r#"{ "camera": { "eye": [0, 0, 2], "target": [0, 0, 0] }, "meshes": [ { "mesh": "builtin:sphere" } ], "environment": { "map": "sky.exr" } }"#).unwrap();
    let o = Command::new("node")
        .arg(&render)
        .arg(&s)
        .arg("-o")
        .arg(d.join("x.png"))
        .env("SUNBEAM_PLAY", tool("sunbeam-play"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("environment") && err.contains("sky.exr"),
        "{err}"
    );
    assert!(!d.join("x.png").exists());
    // An output that cannot be written: exit 3.
    ridge_pack(&d, "ok", "64", "25nm");
    let s = d.join("ok.json");
    std::fs::write(&s, r#"{ "camera": { "eye": [0, 0, 2], "target": [0, 0, 0] }, "meshes": [ { "mesh": "builtin:quad", "pack": "ok.ktx2" } ], "size": [8, 8] }"#).unwrap();
    let o = Command::new("node")
        .arg(&render)
        .arg(&s)
        .arg("-o")
        .arg(d.join("no/such/dir/x.png"))
        .env("SUNBEAM_PLAY", tool("sunbeam-play"))
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// examples/threejs/index.html (the viewer a user opens after `make demo`) loads
/// the snake with its material from the GLB's extension and its scale maps
/// (baked with `--scales`, as `make demo` does) and draws a frame with no
/// WebGL, console or page error (page-check.mjs fails on any), with the head
/// lamp (`?env=none`) and lit by the demo's sky (`?env=sky`, the files of
/// `sunbeam-play SKY-SCENE --export-environment`, as `make demo` writes them;
/// the background off so that the snake alone is measured): the snake is lit
/// under the sky (no lamp) and its frame differs from the lamp's.
#[test]
fn the_viewer_page_loads_without_errors() {
    let d = scratch("threejs-page");
    let Some(render) = example(&d) else { return };
    let js = render.parent().unwrap().to_path_buf();
    let root = d.join("site");
    let (web, out) = (root.join("threejs"), root.join("out"));
    std::fs::create_dir_all(&web).unwrap();
    std::fs::create_dir_all(&out).unwrap();
    for f in [
        "index.html",
        "sunbeam-three.mjs",
        "serve.mjs",
        "page-check.mjs",
    ] {
        std::fs::copy(
            workspace_root().join("examples/threejs").join(f),
            web.join(f),
        )
        .unwrap();
    }
    std::os::unix::fs::symlink(
        std::fs::read_link(js.join("node_modules")).unwrap(),
        web.join("node_modules"),
    )
    .unwrap();
    let pack = ridge_pack(&out, "xeno", "128", "25nm");
    run_ok(
        Command::new(tool("sunbeam-bake"))
            .args(["--generate-snake", "--snake-detail", "0.5", "--pack"])
            .arg(&pack)
            .args(["--scales", "--scale-texels", "8", "-o"])
            .arg(out.join("snake-xeno.glb"))
            .arg("-q"),
    );
    run_ok(
        Command::new(tool("sunbeam-play"))
            .args(["--export-shader", "glsl-es", "-q", "-o"])
            .arg(out.join("sunbeam-es.frag")),
    );
    // The demo's sky (examples/Makefile: NAME-sky.json, env-sky-NAME/, environments.json).
    let sky = std::fs::read_to_string(workspace_root().join("examples/sky-scene.json.in"))
        .unwrap()
        .replace("@PACK@", "xeno.ktx2")
        .replace("@MESH@", "snake-xeno.glb");
    std::fs::write(out.join("xeno-sky.json"), sky).unwrap();
    run_ok(
        Command::new(tool("sunbeam-play"))
            .arg(out.join("xeno-sky.json"))
            .arg("--export-environment")
            .arg(out.join("env-sky-xeno"))
            // 64 cells, not the default 512: the page must load and light the
            // snake, and SwiftShader walks the cells on the CPU (the sky page
            // took 55 s at 512 cells, 12 s at 64; lit fraction 0.063 both).
            .args(["--env-cells", "64", "-q"]),
    );
    std::fs::write(
        out.join("environments.json"),
        "{ \"environments\": [\"sky\"] }\n",
    )
    .unwrap();
    let page = |query: &str| {
        let o = Command::new("node")
            .arg(web.join("page-check.mjs"))
            .arg(&root)
            .arg(format!("threejs/index.html{query}"))
            .args(["--frame", "--size", "160x120"])
            .output()
            .unwrap();
        let report = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(
            o.status.success(),
            "{query}: {report}\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let v: serde_json::Value = serde_json::from_str(report.trim()).unwrap();
        let run = v["runs"][0].clone();
        assert!(run["loadMs"].as_f64().unwrap() > 0.0, "{report}");
        assert!(run["mapBytes"].as_u64().unwrap() > 1000, "{report}");
        assert_eq!(run["material"], "xeno");
        assert_eq!(
            run["scaledMeshes"], 1,
            "the scale maps were not applied: {report}"
        );
        run
    };
    let lamp = page("?env=none");
    assert_eq!(lamp["env"], "none");
    assert_eq!(lamp["lamp"], true);
    let sky = page("?env=sky&background=0");
    assert_eq!(sky["env"], "sky");
    assert_eq!(sky["lamp"], false, "{sky}");
    let f = |r: &serde_json::Value, k: &str| r["frame"][k].clone();
    let lit = |r: &serde_json::Value| f(r, "lit").as_f64().unwrap();
    let grid = |r: &serde_json::Value| -> Vec<f64> {
        f(r, "grid")
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let (a, b) = (grid(&lamp), grid(&sky));
    let diff = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).sum::<f64>() / a.len() as f64;
    eprintln!(
        "viewer: lit fraction {:.4} (head lamp) {:.4} (sky), means {} {}, blocks' mean |difference| {diff:.3}",
        lit(&lamp),
        lit(&sky),
        f(&lamp, "mean"),
        f(&sky, "mean")
    );
    // The snake covers a few per cent of the frame: lit under either.
    assert!(lit(&lamp) > 0.02, "head lamp: {lamp}");
    assert!(lit(&sky) > 0.02, "sky: the snake is not lit: {sky}");
    assert!(
        diff > VIEWER_SKY_DIFF,
        "sky and head lamp frames alike: {diff}"
    );
}

/// The mean absolute difference (display values, 0..255) over the viewer's 8 x
/// 6 blocks between the sky-lit and the lamp-lit snake must exceed this:
/// measured 3.54 (2026-11-26, SwiftShader; the snake 6.1 % of the frame
/// under the lamp, 6.3 % under the sky, mean display value 7.2 and 3.6).
/// Under the sky with the lamp off and no background a broken environment
/// leaves the snake black (lit fraction near 0).
const VIEWER_SKY_DIFF: f64 = 1.5;

/// An environment (issue 26, "Engines"): render.mjs lights a sky-lit sphere
/// through the exported sunbeam_shade_environment (the player's first-frame
/// cells, from the files of `sunbeam-play --export-environment`) and the
/// sun through sunbeam_shade_sun, one frame, 2 x 2 supersampled, against
/// `sunbeam-eval render --samples 64` of the same scene (the player's cells
/// frame of this scene is sunbeam-play's tests/environment.rs; three.js
/// against the player is checked under studio.exr below). The environment
/// must matter: the frame without it (the sun as the only light) is far
/// from the reference.
#[test]
fn threejs_renders_a_sky_lit_sphere_like_the_reference() {
    let d = scratch("threejs-env");
    let Some(render) = example(&d) else { return };
    ridges(&d);
    let sky = r#"{ "camera": { "eye": [0, 0.25, 1.2], "target": [0, 0, 0], "fov_y_deg": 35 },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "ridges.ktx2", "base_color": [0.03, 0.03, 0.03], "diffuse_weight": 0.1 } ],
  "environment": { "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 60 } },
  "exposure": 4.64, "size": [40, 40] }"#;
    let c = measure_at(&render, &d, sky, sky, "sky", 64, 2);
    assert!(c.p99 < SKY_P99, "three.js sky: {c}");
    // Without the environment's own light (the sun alone, as a point light)
    // the frame is far from the reference: the comparison can fail.
    let sun_only = r#"{ "camera": { "eye": [0, 0.25, 1.2], "target": [0, 0, 0], "fov_y_deg": 35 },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "ridges.ktx2", "base_color": [0.03, 0.03, 0.03], "diffuse_weight": 0.1 } ],
  "lights": [ { "direction": [0.4096, 0.5736, 0.7094], "intensity": 1 } ],
  "exposure": 4.64, "size": [40, 40] }"#;
    let r = d.join("sky-ref.exr");
    std::fs::write(d.join("sun-only.json"), sun_only).unwrap();
    run_ok(
        Command::new("node")
            .arg(&render)
            .arg(d.join("sun-only.json"))
            .arg("-o")
            .arg(d.join("sun-only.png"))
            .arg("--exr")
            .arg(d.join("sun-only.exr"))
            .env("SUNBEAM_PLAY", tool("sunbeam-play")),
    );
    let c = compare_linear(
        &LinearImage::read_exr(&d.join("sun-only.exr")).unwrap(),
        &LinearImage::read_exr(&r).unwrap(),
    )
    .unwrap();
    eprintln!("sun only vs the sky's reference: {c}");
    assert!(c.p99 > 3.0 * SKY_P99, "{c}");
}

/// Bound of [`threejs_renders_a_sky_lit_sphere_like_the_reference`]
/// (docs/ENGINES.md "Environment"): measured on SwiftShader and lavapipe
/// (2026-11-30, 512 cells, against a 64-sample reference) three.js p99 1.10
/// (mean 0.34, max 1.9) 4 x 4 supersampled, 1.21 (mean 0.37, max 1.84) 2 x 2
/// (2026-12-02, a third of the time; the studio scene 2 x 2: 1.54 against
/// 1.35, so it stays at 4 x 4; the snake takes 8 x 8), the player's
/// cells first frame 1.17 (mean 0.41), three.js against the player 0.57;
/// plus 25 %. With the cells refined at 2
/// spreads and the environment read over the spread's circle (2026-11-27)
/// 1.57, 1.94 and 1.65; at 256 cells 2.27 and 2.50.
const SKY_P99: f64 = 1.5;

/// A real HDR image (../shared/data/hdri/studio.exr): render.mjs against the
/// reference and against the player's cells frame (the same functions and
/// data: they must agree, whatever the cells' own error under this map), and
/// `"background": "environment"`: a far, small sphere in front of the map,
/// so that the background decides the p99.
#[test]
fn threejs_renders_an_hdr_image_and_its_background() {
    let d = scratch("threejs-hdri");
    let Some(render) = example(&d) else { return };
    let Some(map) = testdata::shared_file("hdri/studio.exr") else {
        return;
    };
    ridges(&d);
    let scene = |eye: &str, background: &str| {
        format!(
            r#"{{ "camera": {{ "eye": {eye}, "target": [0, 0, 0], "fov_y_deg": 35 }},
  "meshes": [ {{ "mesh": "builtin:sphere", "pack": "ridges.ktx2", "base_color": [0.03, 0.03, 0.03], "diffuse_weight": 0.1 }} ],
  "environment": {{ "map": "{}", "rotation_deg": 30 }},{background}
  "exposure": 4.64, "size": [40, 40] }}"#,
            map.display()
        )
    };
    let studio = scene("[0, 0.25, 1.2]", "");
    // 64 samples: seeds agree to p99 1.25 against 2.34 at 16, at the same
    // cost (docs/LIGHTING.md "Lamps in a map").
    let c = measure_at(&render, &d, &studio, &studio, "studio", 64, 4);
    assert!(c.p99 < STUDIO_P99, "three.js under studio.exr: {c}");
    let far = scene("[0, 0.25, 20]", "\n  \"background\": \"environment\",");
    let c = measure_at(&render, &d, &far, &far, "background", 256, 4);
    assert!(c.p99 < BACKGROUND_P99, "background: {c}");
    // The player's cells frame of the studio scene: the same functions and
    // data, the map's hot spots as lights included (the export's default, as
    // the player's). The background's player frame is tests/background.rs's.
    if gpu::gpu().is_some() {
        let o = run_ok(
            Command::new(tool("sunbeam-play"))
                .arg(d.join("studio.json"))
                .args(["--headless", "--env-estimator", "cells"])
                .args(["--supersample", "4", "--json", "-q", "-o"])
                .arg(d.join("studio-player.exr"))
                .arg("--compare")
                .arg(d.join("studio-ref.exr")),
        );
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        eprintln!("player cells, studio, first frame: {}", r["ciede2000"]);
        let p99 = r["ciede2000"]["p99"].as_f64().unwrap();
        assert!(p99 < STUDIO_P99, "player cells under studio.exr: {r}");
        let p = LinearImage::read_exr(&d.join("studio-player.exr")).unwrap();
        let t = LinearImage::read_exr(&d.join("studio.exr")).unwrap();
        let pt = compare_linear(&t, &p).unwrap();
        eprintln!("three.js vs player, studio: {pt}");
        assert!(pt.p99 < SKY_P99, "three.js vs player cells, studio: {pt}");
        // Without its hot spots as lights the player is further from the
        // reference. Both frames one sample per pixel (the sampling's own
        // error alike in both; without hot spots every pixel walks the
        // cells, 4 x 4 of it was this test's dearest run).
        let mean_error = |hot_spots: &str, out: &str| {
            let o = run_ok(
                Command::new(tool("sunbeam-play"))
                    .arg(d.join("studio.json"))
                    .args(["--headless", "--env-estimator", "cells"])
                    .args(["--env-hot-spots", hot_spots])
                    .args(["--supersample", "1", "--json", "-q", "-o"])
                    .arg(d.join(out))
                    .arg("--compare")
                    .arg(d.join("studio-ref.exr")),
            );
            let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            r["ciede2000"]["mean"].as_f64().unwrap()
        };
        let with = mean_error("32", "studio-hot-32.exr");
        let without = mean_error("0", "studio-hot-0.exr");
        eprintln!(
            "player cells under studio.exr, one sample per pixel: mean {without:.2} without hot spots, {with:.2} with"
        );
        assert!(
            with < 0.7 * without,
            "hot spots: mean {with} against {without}"
        );
    }
}

/// Bounds of [`threejs_renders_an_hdr_image_and_its_background`], measured
/// plus 25 % (docs/ENGINES.md "Environment", 2026-11-30): under studio.exr,
/// the map's hot spots as lights in both and the default 512 cells,
/// against the reference at 64 samples (its two seeds: p99 1.25), three.js
/// p99 1.35 (mean 0.30), the player's first frame 1.34 (mean 0.33). The
/// bound is the larger plus 25 %, for both. With the cells refined at 2
/// spreads and the environment read over the spread's circle (2026-11-27):
/// 1.99 and 2.25 (at 256 cells 4.02 and 4.38). With one sample per pixel
/// the player's mean is 0.35 with the hot spots and 2.78 without
/// (2026-12-03; 3.73 without at 4 x 4).
const STUDIO_P99: f64 = 1.7;
/// The background scene (a far sphere before the map) against a 256-sample
/// reference: three.js p99 1.09 (mean 0.148) with 16 rays per pixel (4 x 4
/// supersampled: 256 per output pixel), 7.65 (mean 0.77) with one ray per
/// pixel (the pass before; 2026-12-02, SwiftShader); plus 25 %.
const BACKGROUND_P99: f64 = 1.4;

/// `"background": "environment"` under the sky with its sun in view (8
/// degrees above the view direction; a far sphere): three.js draws the sky
/// and the sun's disc as the reference does. The disc is smaller than a
/// pixel, so its light is checked as the sum over the 5 x 5 pixels around
/// the reference's brightest. Measured (2026-12-02, SwiftShader): the sum
/// 0.99999 of the reference's, p99 0.10, max 2.02; without the sun in the
/// background (the pass before) the sum 0.0086 and max 115 (p99 still 0.10:
/// the disc lies in two pixels). Exposure -3 keeps the disc's radiance
/// within half floats (the player's offscreen target saturates near 65,504).
#[test]
fn threejs_draws_the_sky_and_its_sun_behind() {
    let d = scratch("threejs-sun-behind");
    let Some(render) = example(&d) else { return };
    ridges(&d);
    let scene = r#"{ "camera": { "eye": [0, 0, 20], "target": [0, 0, 0], "fov_y_deg": 35 },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "ridges.ktx2", "base_color": [0.03, 0.03, 0.03], "diffuse_weight": 0.1 } ],
  "environment": { "sky": { "sun_elevation_deg": 8, "sun_azimuth_deg": 270 } },
  "background": "environment", "exposure": -3, "size": [40, 40] }"#;
    let c = measure_at(&render, &d, scene, scene, "sun-behind", 256, 4);
    assert!(
        c.p99 < 0.5 && c.max < 5.0,
        "three.js sky and sun behind: {c}"
    );
    // In 16 tiles the background's rays follow each tile's view offset
    // (measured max 0.003; with the whole frame's rays in every tile p99 100).
    same_in_tiles(&render, &d, "sun-behind");
    let t = LinearImage::read_exr(&d.join("sun-behind.exr")).unwrap();
    let r = LinearImage::read_exr(&d.join("sun-behind-ref.exr")).unwrap();
    let y = sunbeam_frame::linear::luminance;
    let w = r.width as usize;
    let brightest = (0..r.rgb.len())
        .max_by(|&a, &b| y(r.rgb[a]).total_cmp(&y(r.rgb[b])))
        .unwrap();
    let (bx, by) = (brightest % w, brightest / w);
    let block = |im: &LinearImage| -> f64 {
        let mut s = 0.0;
        for j in by.saturating_sub(2)..(by + 3).min(im.height as usize) {
            for i in bx.saturating_sub(2)..(bx + 3).min(w) {
                s += y(im.rgb[j * w + i]);
            }
        }
        s
    };
    let ratio = block(&t) / block(&r);
    eprintln!(
        "the sun's 5 x 5 pixels: three.js / reference {ratio:.5} (brightest at {bx}, {by}: {:.1})",
        y(r.rgb[brightest])
    );
    assert!(y(r.rgb[brightest]) > 100.0, "the sun's disc is not in view");
    assert!(
        (ratio - 1.0).abs() < 0.02,
        "the sun's light behind: {ratio}"
    );
}

/// The baked snake under the sky with the sky behind it (issue 26: three.js
/// on the snake, sky; what a camera sees), render.mjs at `--supersample 8`
/// against a converged reference (`sunbeam-eval render --samples 256
/// --converge 0.15`) over the snake's pixels (those lit in the frame without
/// the background), silhouette included: the issue's p99 < 2. About 5
/// minutes on 2 cores (the reference 2.5, SwiftShader's 64 samples a pixel
/// 2); the snake is the issue's second scene, so CI runs it.
#[test]
fn threejs_renders_the_snake_under_the_sky() {
    let d = scratch("threejs-snake-sky");
    let Some(render) = example(&d) else { return };
    ridges(&d);
    run_ok(
        Command::new(tool("sunbeam-bake"))
            .arg("--generate-snake")
            .arg("-o")
            .arg(d.join("snake.glb"))
            .arg("-q"),
    );
    let scene = |background: &str| {
        format!(
            r#"{{ "camera": {{ "eye": [0, 0.3, 1.0], "target": [0, 0, 0], "fov_y_deg": 35 }},
  "meshes": [ {{ "mesh": "snake.glb", "pack": "ridges.ktx2", "base_color": [0.05, 0.05, 0.05], "diffuse_weight": 0.2 }} ],
  "environment": {{ "sky": {{ "sun_elevation_deg": 35, "sun_azimuth_deg": 60 }} }},{background}
  "exposure": 4.64, "size": [96, 48] }}"#
        )
    };
    let (behind, alone) = (d.join("snake-sky.json"), d.join("snake-alone.json"));
    std::fs::write(&behind, scene(r#" "background": "environment","#)).unwrap();
    std::fs::write(&alone, scene("")).unwrap();
    let frame = threejs_frame_at(&render, &d, &behind, "snake-sky", 8);
    let reference = d.join("snake-sky-ref.exr");
    run_ok(
        Command::new(tool("sunbeam-eval"))
            .arg("render")
            .arg(&behind)
            .args(["--samples", "256", "--converge", "0.15", "-q", "-o"])
            .arg(&reference),
    );
    let reference = LinearImage::read_exr(&reference).unwrap();
    // the snake's pixels: lit with the background off
    let mask = reference_frame_at(&alone, &d.join("snake-alone-ref.exr"), 256);
    let r = compare_regions_within(&frame, &reference, Some(&mask)).unwrap();
    eprintln!(
        "three.js snake under the sky, sky behind, the snake's pixels: all {}, interior {}, edge {}",
        r.all, r.interior, r.edge
    );
    assert!(r.all.pixels > 300 && r.interior.pixels > 100, "{}", r.all);
    assert!(
        r.all.p99 < SNAKE_SKY_P99,
        "three.js snake under the sky: {}",
        r.all
    );
    assert!(
        r.interior.p99 < SNAKE_SKY_INTERIOR_P99,
        "three.js snake under the sky, interior: {}",
        r.interior
    );
}

/// Bound of [`threejs_renders_the_snake_under_the_sky`] over the snake's
/// pixels: issue 26's p99 < 2. Measured p99 1.65-1.69 (mean 0.31; edge
/// 1.70-1.71) against two converged seeds and one at `--converge 0.3`
/// (SwiftShader, 2026-12-06). At `--supersample 4` it is 4.65 (edge 4.67):
/// at the silhouette the count of positions decides, not the material
/// (docs/ENGINES.md "The baked snake under the sky").
const SNAKE_SKY_P99: f64 = 2.0;

/// Bound of [`threejs_renders_the_snake_under_the_sky`] inside the
/// silhouette: measured p99 0.51-0.55 (0.96-1.00 at `--supersample 4`; 9.97
/// before the sun's disc points were read over the footprint, one point per
/// sub-pixel), plus 25 %.
const SNAKE_SKY_INTERIOR_P99: f64 = 0.7;

/// Edge refinement in three.js (`render.mjs --edge-supersample M`: the
/// player's criterion, docs/LIGHTING.md "Edge refinement", the tiles drawn
/// through `camera.setViewOffset`): the pixels it replaces are what the
/// whole frame supersampled at M x M gives there (the same positions in
/// one pass, no tiles), the others are the plain frame's, and every pixel
/// of the silhouette is replaced. The sky-lit ridge sphere 24 x 24 on
/// black (a steep outline), 2 x 2 then 8 x 8 at the flagged pixels, against
/// `--supersample 8`; and with `--edge-levels 2` from 4 x 4, against
/// `--supersample 4` and `8`.
#[test]
fn threejs_edge_refinement_is_the_supersampled_frame_at_its_pixels() {
    let d = scratch("threejs-edge");
    let Some(render) = example(&d) else { return };
    ridges(&d);
    let scene = d.join("sphere.json");
    std::fs::write(
        &scene,
        r#"{ "camera": { "eye": [0, 0, 2.6], "target": [0, 0, 0], "fov_y_deg": 35 },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "ridges.ktx2", "base_color": [0.03, 0.03, 0.03], "diffuse_weight": 0.1 } ],
  "environment": { "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 60 } },
  "exposure": 4.64, "size": [24, 24] }"#,
    )
    .unwrap();
    let refined = threejs_frame_with(
        &render,
        &d,
        &scene,
        "refined",
        2,
        &["--edge-supersample", "8"],
    );
    let plain = threejs_frame_at(&render, &d, &scene, "plain", 2);
    let truth = threejs_frame_at(&render, &d, &scene, "truth", 8);
    let (w, h) = (truth.width as usize, truth.height as usize);
    let changed: Vec<usize> = (0..w * h)
        .filter(|&i| refined.rgb[i] != plain.rgb[i])
        .collect();
    // every silhouette pixel (lit at 8 x 8, with an unlit neighbour) is replaced
    let outline = sunbeam_frame::linear::outline_pixels(&truth);
    for &i in &outline {
        assert!(
            refined.rgb[i] != plain.rgb[i],
            "outline pixel ({}, {}) not refined",
            i % w,
            i / w
        );
    }
    let outline = outline.len();
    assert!(outline > 30, "{outline}");
    // the flags take the outline and its neighbours, not the whole sphere
    assert!(
        changed.len() > outline && changed.len() < w * h / 2,
        "{} pixels changed, {outline} on the outline",
        changed.len()
    );
    let de = |a: &LinearImage| {
        let d = sunbeam_frame::linear::per_pixel_de(a, &truth).unwrap();
        let mut v: Vec<f64> = changed.iter().filter_map(|&i| d[i]).collect();
        sunbeam_frame::diff::stats(&mut v)
    };
    let (after, before) = (de(&refined), de(&plain));
    eprintln!(
        "three.js: {} refined pixels against --supersample 8: {after}; unrefined {before}",
        changed.len()
    );
    assert!(after.p99 < EDGE_REFINED_P99, "{after}");
    assert!(
        before.p99 > 4.0 * EDGE_REFINED_P99,
        "the refinement changed little: {before}"
    );
    // Levels (`--edge-levels 2`): 4 x 4 at the flagged pixels, then 8 x 8
    // at those whose quarter-lattices still disagree: each replaced pixel
    // is the whole frame's at 4 x 4 or at 8 x 8, some only at 8 x 8, not
    // all of them.
    let levels = threejs_frame_with(
        &render,
        &d,
        &scene,
        "levels",
        2,
        &["--edge-supersample", "4", "--edge-levels", "2"],
    );
    let four = threejs_frame_at(&render, &d, &scene, "four", 4);
    let d4 = sunbeam_frame::linear::per_pixel_de(&levels, &four).unwrap();
    let d8 = sunbeam_frame::linear::per_pixel_de(&levels, &truth).unwrap();
    let (mut off, mut only_eight, mut replaced) = (vec![], 0, 0);
    for i in (0..w * h).filter(|&i| levels.rgb[i] != plain.rgb[i]) {
        replaced += 1;
        let (a, b) = (d4[i].unwrap_or(0.0), d8[i].unwrap_or(0.0));
        off.push(a.min(b));
        if b < EDGE_REFINED_P99 && a >= EDGE_REFINED_P99 {
            only_eight += 1;
        }
    }
    let off = sunbeam_frame::diff::stats(&mut off);
    eprintln!("three.js levels: {replaced} pixels replaced, {only_eight} the 8 x 8 frame's only; against the nearer of 4 x 4 and 8 x 8: {off}");
    assert!(off.p99 < EDGE_REFINED_P99, "{off}");
    assert!(
        only_eight > 0 && only_eight < replaced,
        "{only_eight} of {replaced}"
    );
}

/// Bound of [`threejs_edge_refinement_is_the_supersampled_frame_at_its_pixels`]
/// (the player's for its own refinement, tools/sunbeam-play/tests/environment.rs):
/// measured p99 0.000 over the 206 refined pixels (SwiftShader, 2026-12-07:
/// the same positions through the same shader, to the bit), the 2 x 2 frame
/// 32.8 there; tiles a twentieth of a pixel off read 55 at the outline (at
/// 32 x 32, 2026-12-06).
const EDGE_REFINED_P99: f64 = 0.1;
