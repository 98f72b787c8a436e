//! The scaled snake under the sky (issue 27: the player and three.js
//! against the reference under an environment): a 16 x 16 crop of the
//! whole scaled snake of tests/scales_player.rs (`sunbeam-bake
//! --generate-snake --scales`, defaults; the same camera and pixel size as
//! its 128 x 64 frame, so a scale is about 1.5 pixels long and half the lit
//! pixels touch the silhouette), the tests' 5 um ridge pack, the default
//! sky with the sun at 35 deg and the sky drawn behind. The player's first
//! frame (`--env-estimator cells --supersample 8`, 4x MSAA) and render.mjs
//! (`--supersample 16`: at the silhouette three.js shades one point per
//! sub-pixel, where the player shades each covered sample) against
//! `sunbeam-eval render --samples 256 --converge 0.15` (seed 1), over the
//! snake's pixels (a mask: the snake lit from the eye, nothing behind),
//! anti-aliased, in linear light.
//!
//! What it checks: the sun's disc points read with the frame the scale maps
//! give at each point's own place in the pixel (the player's
//! env_sun_disc_carried, three.js through `sunbeam_shade_sun_sample_point`;
//! docs/LIGHTING.md "Scale borders"). Before, with the footprint's linear
//! model inside a scale and a point across a border, the same crop read
//! p99 5.04 (player) and 12.5 (three.js), both at 4 x 4. Both are held to
//! the issue's p99 < 2 with the silhouette at the sub-pixel counts that
//! meet it on the whole snake (docs/BENCHMARKS.md): the player at 8 x 8
//! (the crop's ring reads 2.32 at 4 x 4, 1.59 at 8 x 8), three.js at 16 x
//! 16 (its ring 5.96 / 2.32 / 0.67 at 4 x 4 / 8 x 8 / 16 x 16).

mod common;

use common::player_works;
use common::threejs::{example, ridges, threejs_frame_at};
use std::path::Path;
use std::process::Command;
use sunbeam::{run_ok, scratch, tool};
use sunbeam_frame::linear::{compare_regions_within, RegionDiff};
use sunbeam_frame::LinearImage;

/// The crop: the whole-snake camera turned to a stretch of the body, the
/// field of view cut to keep its 0.547 deg per pixel.
fn scene(mesh: &str, material: &str, lighting: &str) -> String {
    format!(
        r#"{{ "camera": {{ "eye": [0, 0.3, 1.0], "target": [-0.1, 0, 0], "fov_y_deg": 8.75 }},
  "meshes": [ {{ "mesh": "{mesh}", {material} }} ],
  {lighting}, "size": [16, 16] }}"#
    )
}

fn write(d: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = d.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn the_scaled_snake_under_the_sky_in_the_player_and_three_js() {
    let d = scratch("scales_sky");
    if !player_works(&d) {
        return;
    }
    let render = example(&d);
    ridges(&d);
    run_ok(
        Command::new(tool("sunbeam-bake"))
            .args(["--generate-snake", "--scales", "-q", "-o"])
            .arg(d.join("snake.glb")),
    );
    let sky = write(
        &d,
        "sky.json",
        &scene(
            "snake.glb",
            r#""pack": "ridges.ktx2", "base_color": [0.05, 0.05, 0.05], "diffuse_weight": 0.2"#,
            r#""environment": { "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 60 } }, "background": "environment", "exposure": 4.64"#,
        ),
    );
    // The mask: the snake alone, lit from the eye, black behind.
    let mask_scene = write(
        &d,
        "mask.json",
        &scene(
            "snake.glb",
            r#""base_color": [0.5, 0.5, 0.5], "diffuse_weight": 1"#,
            r#""lights": [ { "direction": [0, 0.3, 1.0], "intensity": 1 } ], "exposure": 0"#,
        ),
    );
    let play = |scene: &Path, out: &Path, extra: &[&str]| {
        run_ok(
            Command::new(tool("sunbeam-play"))
                .arg(scene)
                .args(["--headless", "-q"])
                .args(extra)
                .arg("-o")
                .arg(out),
        );
        LinearImage::read_exr(out).unwrap()
    };
    let mask = play(&mask_scene, &d.join("mask.exr"), &[]);
    let t = std::time::Instant::now();
    run_ok(
        Command::new(tool("sunbeam-eval"))
            .arg("render")
            .arg(&sky)
            .args([
                "--samples",
                "256",
                "--converge",
                "0.15",
                "--seed",
                "1",
                "-q",
                "-o",
            ])
            .arg(d.join("reference.exr")),
    );
    let reference = LinearImage::read_exr(&d.join("reference.exr")).unwrap();
    let t_ref = t.elapsed();
    let judge = |a: &LinearImage| -> RegionDiff {
        compare_regions_within(a, &reference, Some(&mask)).unwrap()
    };

    let t = std::time::Instant::now();
    let out = run_ok(
        Command::new(tool("sunbeam-play"))
            .arg(&sky)
            .args(["--headless", "-q", "--json"])
            .args(["--env-estimator", "cells", "--supersample", "8", "-o"])
            .arg(d.join("player.exr")),
    );
    let t_player = t.elapsed();
    let player = LinearImage::read_exr(&d.join("player.exr")).unwrap();
    // Every diffracting mesh has scale maps and the frame is multisampled:
    // no fragment reads the cells' pre-passes, so there are none
    // (docs/LIGHTING.md "One walk per pixel").
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["env_cells_rate"], 0, "{report}");
    let p = judge(&player);
    eprintln!(
        "scaled snake crop under the sky, player 8 x 8: all {}, interior {}, ring {} (reference {t_ref:.1?}, player {t_player:.1?})",
        p.all, p.interior, p.edge
    );
    assert!(p.all.pixels > 100, "the crop shows little snake: {}", p.all);
    assert!(
        p.edge.pixels > 40,
        "the crop shows little silhouette: {}",
        p.edge
    );
    assert!(p.all.p99 < PLAYER_P99, "player: {}", p.all);
    assert!(p.edge.p99 < 2.0, "player, ring: {}", p.edge);

    // three.js needs node and chromium (`example`: under SUNBEAM_REQUIRE_ALL=1
    // their absence fails, as in tests/threejs_scales.rs).
    let Some(render) = render else { return };
    let js = threejs_frame_at(&render, &d, &sky, "threejs", 16);
    let j = judge(&js);
    eprintln!(
        "scaled snake crop under the sky, three.js 16 x 16: all {}, interior {}, ring {}",
        j.all, j.interior, j.edge
    );
    assert!(j.edge.p99 < THREEJS_P99, "three.js, ring: {}", j.edge);
    assert!(j.all.p99 < THREEJS_P99, "three.js: {}", j.all);
}

/// Bound of the player's first frame at 8 x 8 over the crop's snake pixels
/// (the ring alone: the issue's 2): measured p99 0.90 (mean 0.28, 124 px;
/// the ring 1.59, the interior 0.57), lavapipe, 2026-12-04; plus 33 %. At 4
/// x 4 2.50 (the ring 2.32); before the carried disc points 5.04.
const PLAYER_P99: f64 = 1.2;

/// Bound of three.js at 16 x 16 over all the snake's pixels and over its
/// ring alone: measured p99 0.61 (ring 0.67, interior 0.44; SwiftShader,
/// 2026-12-04), plus 60 % and within the issue's 2; at 8 x 8 2.07 (ring
/// 2.32), at 4 x 4 4.26 (ring 5.96).
const THREEJS_P99: f64 = 1.0;
