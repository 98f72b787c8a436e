//! The three.js material applies the scale maps (`sunbeam-bake --scales`,
//! docs/BAKE.md "Scales"; issue 27) as the reference does: the close-up of
//! tests/scales_player.rs (the procedural snake baked with scales at low
//! detail, `--snake-detail 0.25 --scale-texels 8`, a 5 um synthetic ridge
//! pack, one point light, 48 x 48, absolute reflectance) rendered by
//! examples/threejs/render.mjs (4 x 4 supersampled, box-filtered) and by
//! `sunbeam-eval render --samples 16`, compared in linear light (CIEDE2000
//! over the reference's lit pixels). The material's frame is the player's
//! own WGSL (shaders/scales.wgsl `sb_scale_frame`, carried by
//! `--export-shader` through shaders/export_scales.wgsl), the maps read
//! texel by texel from the GLB's embedded PNGs.
//!
//! - with the maps: p99 < 2 (the issue's goal);
//! - the same frame by three.js from the mesh baked without `--scales` must
//!   be far off, or the comparison would pass with the maps ignored;
//! - the GLB alone (the material from its SUNBEAM_materials_diffraction,
//!   the path of a GLB without a scene pack) draws the same frame as with the
//!   scene's pack and the extension's numbers: the maps reach the material on
//!   both paths.
//!
//! Measured (2026-11-26, SwiftShader, 2 cores): with the maps mean 0.013,
//! p99 0.17, max 0.45 over 2226 lit px; without them mean 2.8, p99 33.5,
//! max 40.3. The run: 88 s on 2 cores shared with other work (load 6; 54 s
//! of CPU), the reference about 40 s of it, each render.mjs frame 4 s.

mod common;

use common::threejs::{
    example, reference_frame, reference_frame_at, ridge_pack, threejs_frame, threejs_frame_at,
};
use std::path::{Path, PathBuf};
use std::process::Command;
use sunbeam::{run_ok, scratch, tool};
use sunbeam_frame::compare_linear;
use sunbeam_frame::linear::compare_regions;

/// The procedural snake baked with the pack (and with scales when `scales`).
fn snake(d: &Path, name: &str, scales: bool) -> PathBuf {
    let out = d.join(format!("{name}.glb"));
    let mut c = Command::new(tool("sunbeam-bake"));
    c.args(["--generate-snake", "--snake-detail", "0.25", "--pack"])
        .arg(d.join("ridges.ktx2"))
        .args(["--diffuse-weight", "0.1"]);
    if scales {
        c.args(["--scales", "--scale-texels", "8"]);
    }
    run_ok(c.args(["-q", "-o"]).arg(&out));
    out
}

/// tests/scales_player.rs's close-up as a scene file: the camera close
/// above the snake's back (a few scales across), lit from the upper left,
/// the base times F(0) = 0.04 and the exposure raised by log2(1 / F(0)).
/// `pack`: the scene's `"pack"` and `"base_color"` entries, or "" for the
/// material from the GLB's extension.
fn scene(d: &Path, name: &str, mesh: &str, pack: &str) -> PathBuf {
    let s = format!(
        r#"{{ "camera": {{ "eye": [0, -0.104, 0.077], "target": [0, -0.085, 0.02], "fov_y_deg": 30 }},
  "lights": [ {{ "direction": [-0.35, -0.45, 0.82], "intensity": 1 }} ],
  "meshes": [ {{ "mesh": "{mesh}", {pack}"diffuse_weight": 0.1 }} ],
  "exposure": 4.643856, "size": [48, 48] }}"#
    );
    let p = d.join(format!("{name}.json"));
    std::fs::write(&p, s).unwrap();
    p
}

const PACK: &str = r#""pack": "ridges.ktx2", "base_color": [0.002, 0.002, 0.002], "#;

#[test]
fn threejs_applies_the_scale_maps_as_the_reference() {
    let t = std::time::Instant::now();
    let d = scratch("threejs-scales");
    let Some(render) = example(&d) else { return };
    ridge_pack(&d, "ridges", "160", "31nm");
    snake(&d, "scaled", true);
    snake(&d, "plain", false);

    let with = scene(&d, "scales", "scaled.glb", PACK);
    let reference = reference_frame(&with, &d.join("scales-ref.exr"));
    let three = threejs_frame(&render, &d, &with, "scales");
    let c = compare_linear(&three, &reference).unwrap();
    let plain = scene(&d, "no-scales", "plain.glb", PACK);
    let c0 = compare_linear(&threejs_frame(&render, &d, &plain, "no-scales"), &reference).unwrap();
    eprintln!("three.js with the scale maps: {c}; without: {c0}");
    assert!(c.pixels > 48 * 48 / 2, "the snake shows little: {c}");
    assert!(
        c.p99 < 2.0,
        "three.js with the scale maps against the reference: {c}"
    );
    // The maps matter here: ignoring them is far off (the check above can fail).
    assert!(
        c0.p99 > 10.0 && c0.mean > 10.0 * c.mean,
        "without the maps {c0}, with {c}: the scene does not show the scales"
    );

    // The material from the GLB's extension (its base colour 0.05 and
    // diffuse weight), with the maps: as with the scene's pack and the
    // same numbers.
    let ext = scene(&d, "ext", "scaled.glb", "");
    let same = scene(
        &d,
        "ext-pack",
        "scaled.glb",
        r#""pack": "ridges.ktx2", "base_color": [0.05, 0.05, 0.05], "#,
    );
    let e = compare_linear(
        &threejs_frame(&render, &d, &ext, "ext"),
        &threejs_frame(&render, &d, &same, "ext-pack"),
    )
    .unwrap();
    eprintln!("three.js, the GLB's extension against the scene's pack: {e}");
    assert!(e.max < 0.01, "the extension's material differs: {e}");
    eprintln!("threejs_scales: {:.1?}", t.elapsed());
}

/// The whole scaled snake as the demo bakes it (`sunbeam-bake
/// --generate-snake --scales`, default detail and scale parameters), seen as
/// tests/threejs_render.rs' snake scene, under one point light, 128 x 64:
/// issue 27's three.js "p99 < 2, silhouettes included". Nearly half the lit
/// pixels touch the silhouette; the scales are about 1.5 pixels long.
/// render.mjs at 8 x 8 against `sunbeam-eval render --samples 256`; the
/// silhouette ring (the lit pixels outside `interior_pixels`) is held to
/// the same bound. Measured in [`WHOLE_P99`].
#[test]
fn threejs_shades_the_whole_scaled_snake_silhouettes_included() {
    let d = scratch("threejs-scales-whole");
    let Some(render) = example(&d) else { return };
    ridge_pack(&d, "ridges", "160", "31nm");
    run_ok(
        Command::new(tool("sunbeam-bake"))
            .args(["--generate-snake", "--scales", "-q", "-o"])
            .arg(d.join("whole.glb")),
    );
    let s = d.join("whole.json");
    std::fs::write(
        &s,
        r#"{ "camera": { "eye": [0, 0.3, 1.0], "target": [0, 0, 0], "fov_y_deg": 35 },
  "lights": [ { "direction": [-0.35, 0.6, 0.72], "intensity": 1 } ],
  "meshes": [ { "mesh": "whole.glb", "pack": "ridges.ktx2", "base_color": [0.05, 0.05, 0.05], "diffuse_weight": 0.2 } ],
  "exposure": 4.64, "size": [128, 64] }"#,
    )
    .unwrap();
    let reference = reference_frame_at(&s, &d.join("whole-ref.exr"), 256);
    let eight = threejs_frame_at(&render, &d, &s, "whole-8", 8);
    let four = threejs_frame_at(&render, &d, &s, "whole-4", 4);
    let c = compare_regions(&eight, &reference).unwrap();
    let c4 = compare_regions(&four, &reference).unwrap();
    eprintln!(
        "three.js, whole scaled snake (128 x 64, point light): 8 x 8 all {}, ring {}; 4 x 4 all {}, ring {}",
        c.all, c.edge, c4.all, c4.edge
    );
    assert!(
        c.edge.pixels > 150 && c.all.pixels > 400,
        "the frame shows little silhouette: {c:?}"
    );
    assert!(c.all.p99 < WHOLE_P99, "three.js, all lit pixels: {}", c.all);
    assert!(
        c.edge.p99 < WHOLE_P99,
        "three.js, the silhouette ring: {}",
        c.edge
    );
}

/// Bound of [`threejs_shades_the_whole_scaled_snake_silhouettes_included`]:
/// the issue's 2 for three.js. Measured (SwiftShader, 2026-12-02, against a
/// 1024-sample reference): 8 x 8 all p99 1.03 (max 1.91), ring 1.15; 4 x 4
/// 2.32 (ring 2.50, max 7.6), which is why the test renders 8 x 8 (3 s).
const WHOLE_P99: f64 = 2.0;
