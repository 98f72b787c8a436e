//! Environment scenes (sky or map) in the player, end to end on the GPU
//! (lavapipe in CI): the settled frame (`--headless --frames N`, the average of
//! N progressive frames) against the reference (`sunbeam-eval render`, here
//! `sunbeam_raster::render_linear` in-process: the same code), unmasked and
//! with Smith masking (docs/LIGHTING.md "Grazing views: masking"),
//! a white furnace, and bad inputs.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, OnceLock};
use sunbeam_frame::LinearImage;
use sunbeam_pack::{build::BuildOptions, FieldRef, Model, Pack};

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-play");

fn tmp(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("play-env-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
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

/// A small synthetic pack like snake skin scaled down (as
/// crates/sunbeam-raster/tests/environment.rs): sinusoidal ridges of 1.3 um,
/// 420 nm peak to peak, on 64 x 64 samples of 50 nm; copied into `dir` as
/// `ridge.ktx2` with its point map `ridge.response.ktx2` (what `sunbeam-pack
/// --response` writes: the energy bound's tables, which every player run
/// would otherwise build, 11 s each). Built once per test binary.
fn ridge_pack(dir: &Path) -> Arc<Pack> {
    static BUILT: OnceLock<(PathBuf, Arc<Pack>)> = OnceLock::new();
    copy_pack(
        BUILT.get_or_init(|| build_ridge_pack("ridge-pack", 64, 50e-9)),
        dir,
    )
}

/// The same ridges on a patch four times as wide, 12.8 um (128 x 128
/// samples of 100 nm): lobes about 2.5 degrees wide, narrow enough that the
/// mirrored sky's horizon stays sharp across a grid's block of 4 pixels
/// (as a 20 um pack's do; docs/LIGHTING.md "Cells at a lower rate").
fn wide_ridge_pack(dir: &Path) -> Arc<Pack> {
    static BUILT: OnceLock<(PathBuf, Arc<Pack>)> = OnceLock::new();
    copy_pack(
        BUILT.get_or_init(|| build_ridge_pack("wide-ridge-pack", 128, 100e-9)),
        dir,
    )
}

fn copy_pack((src, pack): &(PathBuf, Arc<Pack>), dir: &Path) -> Arc<Pack> {
    for f in ["ridge.ktx2", "ridge.response.ktx2"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    pack.clone()
}

/// The ridges on `n` x `n` samples of `dx` metres, built into the folder
/// `name` as `ridge.ktx2` with its point map.
fn build_ridge_pack(name: &str, n: usize, dx: f64) -> (PathBuf, Arc<Pack>) {
    let src = tmp(name);
    let (period, amp) = (1.3e-6, 420e-9);
    let data: Vec<f64> = (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            0.5 * amp
                * (1.0
                    + (2.0 * std::f64::consts::PI * (i * dx) / period
                        + 0.3 * (0.7 * j * (dx / 50e-9)).sin())
                    .sin())
        })
        .collect();
    let f = FieldRef {
        width: n,
        height: n,
        dx,
        dy: dx,
        data: &data,
    };
    let opts = BuildOptions {
        model: Model::Window,
        ..BuildOptions::default()
    };
    let pack = sunbeam_pack::build(f, &opts, &mut |_, _| {}).unwrap();
    let path = src.join("ridge.ktx2");
    sunbeam_pack::io::write_pack(&pack, &path, sunbeam_pack::io::OutputKind::Ktx2).unwrap();
    let response = sunbeam_response::build(&pack, &Default::default());
    std::fs::write(
        sunbeam_response::sidecar_path(&path),
        sunbeam_response::ktx2::encode(&response),
    )
    .unwrap();
    (src, Arc::new(pack))
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The reference (`sunbeam-eval render --samples S --seed K -o ref.exr`), averaged over seeds.
fn reference(scene: &Path, samples: u32, seeds: &[u64], out: &Path) -> LinearImage {
    let s = sunbeam_scene::Scene::load(scene).unwrap();
    let frames: Vec<LinearImage> = seeds
        .iter()
        .map(|&seed| {
            sunbeam_raster::render_linear(
                &s,
                &sunbeam_raster::Options {
                    samples,
                    seed,
                    ..Default::default()
                },
            )
            .unwrap()
        })
        .collect();
    let a = sunbeam_frame::linear::mean_of(&frames).unwrap();
    a.write_exr(out).unwrap();
    a
}

/// The player's settled frame of `frames` frames, compared with `reference`:
/// the JSON report.
fn play(scene: &Path, frames: u32, out: &Path, reference: &Path) -> serde_json::Value {
    play_with(
        scene,
        frames,
        out,
        reference,
        &["--env-estimator", "monte-carlo"],
    )
}

/// [`play`] with other options.
fn play_with(
    scene: &Path,
    frames: u32,
    out: &Path,
    reference: &Path,
    extra: &[&str],
) -> serde_json::Value {
    let o = Command::new(BIN)
        .arg(scene)
        .args(["--headless", "--supersample", "1", "--json", "--frames"])
        .arg(frames.to_string())
        .arg("-o")
        .arg(out)
        .arg("--compare")
        .arg(reference)
        .args(extra)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("built the environment's response maps"),
        "start-up says it built the maps: {err}"
    );
    serde_json::from_slice(&o.stdout).unwrap()
}

fn p99(report: &serde_json::Value) -> f64 {
    report["ciede2000"]["p99"].as_f64().unwrap()
}

/// A sky-lit sphere with the ridge pack, filling the frame: the settled frame
/// (256 frames) against the reference at 64 samples per pixel (two seeds
/// agree to p99 0.54; 256 samples took 2.4x as long and moved no figure below
/// by more than 0.05), CIEDE2000 p99 over the lit pixels in linear light, and
/// over 4 x 4 blocks (a bias). Unmasked (PHYSICS.md's model) here, with the pack's Smith masking in
/// [`sky_lit_sphere_with_masking_settles_to_the_reference`] (two tests, so the
/// harness runs them side by side).
#[test]
fn sky_lit_sphere_settles_to_the_reference() {
    sky_lit_sphere("off");
}

/// [`sky_lit_sphere_settles_to_the_reference`] with the pack's Smith masking,
/// over 64 frames (a quarter of the time; the masking's bias would show
/// as it does unmasked, the bounds are those of 64 frames' noise).
#[test]
fn sky_lit_sphere_with_masking_settles_to_the_reference() {
    sky_lit_sphere("smith");
}

/// Frames, bound on p99 per pixel and on p99 over 4 x 4 blocks of
/// [`sky_lit_sphere`] by masking. Measured on lavapipe (2026-12-02):
/// unmasked, 256 frames, p99 6.1, blocks 1.89; masked, 64 frames, p99 12.1,
/// blocks 3.33 (1.65 at 256 frames); the masked bounds are those plus 25 %.
fn settle_bounds(masking: &str) -> (u32, f64, f64) {
    match masking {
        "off" => (256, 11.0, BLOCKS_P99),
        _ => (64, 15.2, 4.2),
    }
}

fn sky_lit_sphere(masking: &str) {
    let (frames, p99_bound, blocks_bound) = settle_bounds(masking);
    let dir = tmp(&format!("sky-{masking}"));
    ridge_pack(&dir);
    // log2(1 / F(0)) = 4.64 stops: the bounds below were measured in the
    // relative normalisation, which the default absolute reflectance is F(0)
    // times (PHYSICS.md 2); the exposure keeps the frame as bright and the
    // comparison as sensitive.
    let exposure = -sunbeam_optics::gain::f0(sunbeam_optics::gain::DEFAULT_IOR).log2();
    let scene = write(
        &dir,
        "sky.json",
        &format!(
            r#"{{ "camera": {{ "eye": [0, 0.25, 1.2], "target": [0, 0, 0] }},
  "meshes": [ {{ "mesh": "builtin:sphere", "pack": "ridge.ktx2", "masking": "{masking}" }} ],
  "lights": [],
  "environment": {{ "sky": {{ "sun_elevation_deg": 35, "sun_azimuth_deg": 60 }} }},
  "exposure": {exposure},
  "size": [64, 64] }}"#
        ),
    );
    if !have_gpu() {
        return;
    }
    eprintln!("masking {masking}:");
    let t = std::time::Instant::now();
    let refp = dir.join("ref.exr");
    reference(&scene, 64, &[1], &refp);
    eprintln!("reference: {:.1} s", t.elapsed().as_secs_f64());
    let t = std::time::Instant::now();
    let r = play(&scene, frames, &dir.join("f.exr"), &refp);
    eprintln!("player: {:.1} s, {r}", t.elapsed().as_secs_f64());
    assert_eq!(r["accumulated_frames"].as_u64(), Some(u64::from(frames)));
    let d = p99(&r);
    // Measured on lavapipe: p99 9.1 at 256 frames unmasked, 8.3 masked
    // (one sample per pixel and frame, --msaa 1 by default; deterministic: both
    // renderers are seeded), the player's own noise (the reference, the
    // quadrature, is at p99 ~0.2 between seeds); it falls with the frames to
    // p99 1.6 at 4096 on the demo pack's sphere (docs/bench/play.md
    // "Environment mode"). Bound: the measurement plus 25 %. With exact
    // Fresnel once, absolute reflectance (the exposure compensating it) and the
    // base's 1 - F: p99 6.1 unmasked, 6.2 masked (bounds kept).
    assert!(d < p99_bound, "CIEDE2000 p99 {d} (report {r})");
    // A bias survives averaging over 4 x 4 pixel blocks, the noise does not:
    // shading at llvmpipe's centroid (a covered sample, 0.4 px off the centre
    // of every pixel a triangle edge crosses) shifted sharp features and gave
    // blocks p99 2.6 on the demo pack's sphere at any number of frames.
    let frame = LinearImage::read_exr(&dir.join("f.exr")).unwrap();
    let reference = LinearImage::read_exr(&refp).unwrap();
    let blocks =
        sunbeam_frame::compare_linear(&frame.downsample(4), &reference.downsample(4)).unwrap();
    eprintln!("4 x 4 blocks: {blocks}");
    assert!(blocks.p99 < blocks_bound, "{blocks}");
    // The first-frame estimator (--env-estimator cells): its first frame (no
    // accumulation; MSAA 4 by default for one headless frame). Unmasked only.
    if masking != "off" {
        return;
    }
    let t = std::time::Instant::now();
    let c = play_with(
        &scene,
        1,
        &dir.join("c.exr"),
        &refp,
        &["--env-estimator", "cells"],
    );
    eprintln!(
        "player, cells, first frame: {:.1} s, {c}",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(c["accumulated_frames"].as_u64(), Some(1));
    let dc = p99(&c);
    // Measured on lavapipe: see CELLS_P99.
    assert!(dc < CELLS_P99, "cells: CIEDE2000 p99 {dc} (report {c})");
}

/// Bound of the cells' first frame in [`sky_lit_sphere_settles_to_the_reference`]
/// (docs/LIGHTING.md "The first frame"): measured p99 1.51 (mean 0.38, max
/// 4.5; lavapipe, 2026-11-29) against the Monte Carlo's 6.15 at 256 frames;
/// the bound is 1.66 (before the rim's integral, "Accuracy per view") plus
/// 25 %; 3.04 before the frame sat at the pixel centre and its partly
/// covered pixels shaded their covered samples.
const CELLS_P99: f64 = 2.1;

/// Bound of [`sky_lit_sphere_settles_to_the_reference`]'s 4 x 4 blocks:
/// measured 2.27 unmasked and 2.16 masked at 256 frames (2026-11-25; mostly
/// the noise, 8-9 per pixel, over 4), plus 25 %; 1.71 and 1.58 with exact
/// Fresnel once and absolute reflectance (exposure compensated).
const BLOCKS_P99: f64 = 2.8;

/// A white furnace: a constant white map (radiance 1) on the ridge quad seen
/// head-on; the frame's centre (512 frames) equals the reference's.
#[test]
fn white_furnace_on_the_quad_matches_the_reference_at_the_centre() {
    let dir = tmp("furnace");
    ridge_pack(&dir);
    LinearImage {
        width: 8,
        height: 4,
        rgb: vec![[1.0; 3]; 32],
    }
    .write_exr(&dir.join("white.exr"))
    .unwrap();
    let scene = write(
        &dir,
        "furnace.json",
        r#"{ "camera": { "eye": [0, 0, 1.5], "target": [0, 0, 0] },
  "meshes": [ { "mesh": "builtin:quad", "pack": "ridge.ktx2" } ],
  "lights": [],
  "environment": { "map": "white.exr" },
  "size": [64, 64] }"#,
    );
    if !have_gpu() {
        return;
    }
    let refp = dir.join("ref.exr");
    let reference = reference(&scene, 64, &[1], &refp);
    let out = dir.join("f.exr");
    let r = play(&scene, 512, &out, &refp);
    let frame = LinearImage::read_exr(&out).unwrap();
    let centre = |img: &LinearImage| {
        let mut s = [0.0f64; 3];
        let mut n = 0.0;
        for y in 24..40 {
            for x in 24..40 {
                let p = img.rgb[(y * img.width + x) as usize];
                for c in 0..3 {
                    s[c] += p[c] as f64;
                }
                n += 1.0;
            }
        }
        s.map(|v| v / n)
    };
    let (a, b) = (centre(&frame), centre(&reference));
    // Measured on lavapipe (512 frames) against the quadrature reference:
    // within 0.02-0.12 % per channel (the player's standard error 0.3-0.5 %).
    // Clamping each frame at 0 had made red +2.4 %.
    eprintln!("furnace centre: player {a:?} reference {b:?} ({r})");
    for c in 0..3 {
        assert!(
            (a[c] / b[c] - 1.0).abs() < 0.015,
            "channel {c}: player {} vs reference {}",
            a[c],
            b[c]
        );
    }
}

/// Bad environments are input errors (exit 2) through the player too: an
/// unreadable or missing map, a negative or NaN intensity.
#[test]
fn bad_environments_exit_2() {
    let dir = tmp("bad");
    std::fs::write(dir.join("broken.hdr"), b"not an image").unwrap();
    let cases = [
        (
            "unreadable.json",
            r#"{ "camera": { "eye": [0, 0, 3], "target": [0, 0, 0] }, "meshes": [ { "mesh": "builtin:sphere" } ], "environment": { "map": "broken.hdr" }, "size": [8, 8] }"#,
            "broken.hdr",
        ),
        (
            "missing.json",
            r#"{ "camera": { "eye": [0, 0, 3], "target": [0, 0, 0] }, "meshes": [ { "mesh": "builtin:sphere" } ], "environment": { "map": "nowhere.exr" }, "size": [8, 8] }"#,
            "nowhere.exr",
        ),
        (
            "negative.json",
            r#"{ "camera": { "eye": [0, 0, 3], "target": [0, 0, 0] }, "meshes": [ { "mesh": "builtin:sphere" } ], "environment": { "sky": { "sun_elevation_deg": 35 }, "intensity": -1 }, "size": [8, 8] }"#,
            "intensity",
        ),
        // JSON has no NaN: the literal is refused as unreadable JSON (the scene
        // crate refuses a NaN set from code, crates/sunbeam-scene).
        (
            "nan.json",
            r#"{ "camera": { "eye": [0, 0, 3], "target": [0, 0, 0] }, "meshes": [ { "mesh": "builtin:sphere" } ], "environment": { "sky": { "sun_elevation_deg": 35 }, "intensity": NaN }, "size": [8, 8] }"#,
            "nan.json",
        ),
    ];
    for (name, text, needle) in cases {
        let s = write(&dir, name, text);
        let out = dir.join("f.png");
        let o = Command::new(BIN)
            .arg(&s)
            .args(["--headless", "-o"])
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(needle), "{name}: {err}");
        assert!(!out.exists(), "{name}");
    }
    // A hot-spot threshold outside 1..=1000 is a usage error naming the flag.
    let s = write(
        &dir,
        "sky.json",
        &cases[2].1.replace("\"intensity\": -1", "\"intensity\": 1"),
    );
    for bad in ["0.5", "nan", "inf", "2000", "x"] {
        let out = dir.join("f.png");
        let o = Command::new(BIN)
            .arg(&s)
            .args(["--headless", "--env-hot-threshold", bad, "-o"])
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{bad}: {err}");
        assert!(err.contains("--env-hot-threshold"), "{bad}: {err}");
        assert!(!out.exists(), "{bad}");
    }
}

/// The default scene of `--mesh --pack` is sky-lit (issue #13), with the sky
/// drawn behind the mesh: the player builds the environment's maps and
/// accumulates over `--frames` 3 with Monte Carlo; one frame (no `--frames`)
/// takes the first-frame estimator (`--env-estimator auto`: cells);
/// `--lighting point` keeps the point-lit scene (no environment, nothing
/// accumulated); a bad value is a usage error naming the flag.
#[test]
fn default_scene_is_sky_lit() {
    if !have_gpu() {
        return;
    }
    let dir = tmp("default");
    ridge_pack(&dir);
    let run = |extra: &[&str]| {
        Command::new(BIN)
            .args(["--mesh", "builtin:sphere", "--pack"])
            .arg(dir.join("ridge.ktx2"))
            .args(["--headless", "--size", "32x32", "--json"])
            .args(extra)
            .output()
            .unwrap()
    };
    let f = dir.join("f.png");
    let o = run(&["--frames", "3", "-o", f.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("built the environment's response maps"),
        "{err}"
    );
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(r["accumulated_frames"].as_u64(), Some(3), "{r}");
    assert_eq!(r["env_estimator"], "monte-carlo", "{r}");
    // One frame, the product itself: the estimator that is right in it.
    let one = dir.join("one.exr");
    let o = run(&["-o", one.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(r["accumulated_frames"].as_u64(), Some(1), "{r}");
    assert_eq!(r["env_estimator"], "cells", "{r}");
    assert_eq!(r["env_cells"], 512, "{r}");
    // Where the time went: each phase's milliseconds, the frame's not zero.
    for k in ["prepare_ms", "setup_ms", "render_ms"] {
        assert!(r[k].as_f64().is_some_and(|t| t >= 0.0), "{k}: {r}");
    }
    assert!(r["render_ms"].as_f64().unwrap() > 0.0, "{r}");
    // The sky behind the sphere: the top corner sees it, lit and blue
    // (the sky's zenith is bluer than its horizon and the ground grey).
    let img = LinearImage::read_exr(&one).unwrap();
    let [cr, _, cb] = img.rgb[0];
    assert!(cb > 0.0 && cb > cr, "top-left corner {:?}", img.rgb[0]);
    let o = run(&[
        "--env-estimator",
        "monte-carlo",
        "-o",
        one.to_str().unwrap(),
    ]);
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(r["env_estimator"], "monte-carlo", "{r}");
    let o = run(&["--lighting", "point", "-o", f.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        r["accumulated_frames"].as_u64().unwrap_or(0) == 0,
        "point-lit frames do not accumulate: {r}"
    );
    let o = run(&["--lighting", "moon", "-o", f.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--lighting"));
}

/// The environment mode in a real window under Xvfb (`xvfb-run -a`): the
/// sky-lit default scene accumulates in the window too, and the player's copy
/// of its swapchain image after 4 frames is lit, not blank.
#[test]
fn window_shades_the_sky() {
    if !sunbeam_common::testdata::have_command("xvfb-run", &["--help"]) {
        return;
    }
    if !have_gpu() {
        return;
    }
    let dir = tmp("window");
    ridge_pack(&dir);
    let shot = dir.join("window.png");
    let o = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 640x480x24", BIN])
        .args(["--mesh", "builtin:sphere", "--pack"])
        .arg(dir.join("ridge.ktx2"))
        .args([
            "--size",
            "96x96",
            "--frames",
            "4",
            "--hold-secs",
            "0.3",
            "-o",
        ])
        .arg(&shot)
        .output()
        .unwrap();
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "window run failed: {log}");
    assert!(log.contains("window frames: n=4"), "{log}");
    assert!(
        log.contains("built the environment's response maps"),
        "{log}"
    );
    let img = sunbeam_frame::Image::read_png(&shot)
        .unwrap_or_else(|e| panic!("no screenshot ({e}): {log}"));
    let (mean, sd) = img.mean_sd();
    eprintln!(
        "sky window {}x{} mean {mean:.3} sd {sd:.3}",
        img.width, img.height
    );
    assert!(
        mean > 0.02 && sd > 0.02,
        "screenshot looks blank: mean {mean} sd {sd}"
    );
}

/// The first frame (`--env-estimator cells`) under a real HDR image: the map
/// rotated by R about +y lights the sphere as the unrotated map lights the
/// scene rotated by -R (docs/SCENE.md `rotation_deg`: from +x towards +z).
/// builtin:sphere and its orientation field repeat every 3.75 degrees about
/// +y, so rotating the scene by 90 degrees is rotating the camera. Both the
/// camera's rotation and the comparison are written here from the convention,
/// not from the renderer's code.
#[test]
fn rotating_the_map_equals_rotating_the_scene_back_in_the_first_frame() {
    let Some(studio) = sunbeam_common::testdata::shared_file("hdri/studio.exr") else {
        return;
    };
    let dir = tmp("rotation");
    ridge_pack(&dir);
    let (r, eye) = (90.0f64, [0.35f64, 0.5, 1.2]);
    // rot_y(a): +x towards +z
    let rot_y = |v: [f64; 3], deg: f64| {
        let (s, c) = deg.to_radians().sin_cos();
        [v[0] * c - v[2] * s, v[1], v[0] * s + v[2] * c]
    };
    let scene = |name: &str, rotation: f64, eye: [f64; 3]| {
        write(
            &dir,
            name,
            &format!(
                r#"{{ "camera": {{ "eye": [{}, {}, {}], "target": [0, 0, 0] }},
  "meshes": [ {{ "mesh": "builtin:sphere", "pack": "ridge.ktx2", "base_color": [0.02, 0.02, 0.02], "diffuse_weight": 0.2 }} ],
  "lights": [],
  "environment": {{ "map": "{}", "rotation_deg": {rotation} }},
  "exposure": 4,
  "size": [48, 48] }}"#,
                eye[0],
                eye[1],
                eye[2],
                studio.display()
            ),
        )
    };
    let a = scene("rotated-map.json", r, eye);
    let b = scene("rotated-scene.json", 0.0, rot_y(eye, -r));
    if !have_gpu() {
        return;
    }
    let first = |s: &Path, out: &Path, compare: Option<&Path>| {
        let mut c = Command::new(BIN);
        c.arg(s)
            .args(["--headless", "--json", "-q", "--frames", "1", "--msaa", "1"])
            .args(["--env-estimator", "cells", "--env-cells", "128", "-o"])
            .arg(out);
        if let Some(p) = compare {
            c.arg("--compare").arg(p);
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()
    };
    let fa = dir.join("a.exr");
    first(&a, &fa, None);
    let rep = first(&b, &dir.join("b.exr"), Some(&fa));
    assert_eq!(rep["env_cells"], 128, "{rep}");
    eprintln!(
        "rotated map vs rotated scene, first frame: {}",
        rep["ciede2000"]
    );
    let lit = LinearImage::read_exr(&fa).unwrap();
    let y: f64 = lit.rgb.iter().map(|p| f64::from(p[1])).sum::<f64>() / lit.rgb.len() as f64;
    assert!(y > 1e-3, "the map lights the sphere: mean G {y}");
    let c = &rep["ciede2000"];
    let (mean, p99) = (c["mean"].as_f64().unwrap(), c["p99"].as_f64().unwrap());
    // Measured on lavapipe: see ROTATION_BOUNDS.
    assert!(
        mean < ROTATION_BOUNDS.0 && p99 < ROTATION_BOUNDS.1,
        "CIEDE2000 {c}"
    );
}

/// Bounds (mean, p99) of [`rotating_the_map_equals_rotating_the_scene_back_in_the_first_frame`]:
/// measured on lavapipe with `--msaa 1` mean 0.016, p99 0.064, max 0.073
/// at 512 cells (2026-11-27, half the time) and the same at the 128 cells
/// the test uses for speed (2026-12-02; the rotation's exactness does not
/// depend on the count; with 4x MSAA 0.039 / 0.29 / 0.58: the
/// silhouette's coverage, the rotated vertices rounded differently); the map rotated the wrong way (-90) gives mean 19.8, p99 61.6.
const ROTATION_BOUNDS: (f64, f64) = (0.05, 0.3);

/// The cells at a lower rate (`--env-cells-rate`, docs/LIGHTING.md "Cells at
/// a lower rate"): the first frame of a sky-lit sphere whose normal turns
/// about half a degree per pixel, its cells shaded on the default grid of 4 x
/// 4 pixels and interpolated, against every pixel walking them
/// (`--env-cells-rate 1`). They differ (the grid is in use: a rate that
/// reached no pixel would give the same image) by little: bilinear
/// interpolation of a term smooth over a few degrees. The frame is a 128 x
/// 128 window onto the 256 x 256 view of the sphere (half the field of view,
/// aimed at the right limb): the same degrees per pixel, interior and
/// silhouette, at a quarter of the cost. 128 cells keep it quick; the
/// comparison does not depend on the count (LOWER_RATE_P99).
#[test]
fn cells_at_a_lower_rate_match_every_pixel() {
    let Some((dir, scene)) = sky_lit_ridge_sphere(
        "cells-rate",
        r#"{ "eye": [0, 0, 2.4], "target": [0.3, 0.1, 0], "fov_y_deg": 13 }"#,
        128,
    ) else {
        return;
    };
    // Measured on lavapipe: see LOWER_RATE_P99.
    grid_against_every_pixel(&dir, &scene, LOWER_RATE_P99);
}

/// The grid of 4 against every pixel (`--env-cells-rate 1`) on `scene`,
/// single-sampled, 128 cells: the frames must differ (the grid is in use)
/// and agree within `p99`.
fn grid_against_every_pixel(dir: &Path, scene: &Path, p99: f64) {
    let (grid, every) = grid_and_every_pixel(dir, scene);
    let d = sunbeam_frame::compare_linear(&grid, &every).unwrap();
    eprintln!("{}: grid of 4 against every pixel: {d}", scene.display());
    assert!(d.max > 0.0, "the grid changed nothing: {d}");
    assert!(d.p99 < p99, "{d}");
}

/// A smooth surface can see a sharp edge of the environment: the sky's
/// horizon mirrored across the middle of a sphere, through lobes about 2.5
/// degrees wide (the 12.8 um ridge pack), where a grid's block of 4 pixels
/// turns the view by about 1 degree. Mixed bilinearly over the blocks, the
/// edge became a band a few rows high (the 20 um pack at 40 x 40, 4 x 4
/// supersampled: the row above the horizon 3.6 % too dark, the row below
/// 6.2 % too bright, against a converged reference); blocks whose values
/// curve more than the mix can follow now walk every pixel
/// (shaders/environment.wgsl `env_block_linear`). The grid of 4 against
/// every pixel, 128 x 128 over 13 degrees of view, single-sampled, 128
/// cells: each row's luminance, and the grid in use elsewhere.
#[test]
fn a_sharp_edge_of_the_environment_is_not_spread_by_the_grid() {
    let Some((dir, scene)) = sky_lit_sphere_with(
        wide_ridge_pack,
        "cells-edge",
        r#"{ "eye": [0, 0, 2.4], "target": [0, 0, 0], "fov_y_deg": 13 }"#,
        128,
    ) else {
        return;
    };
    let (grid, every) = grid_and_every_pixel(&dir, &scene);
    let d = sunbeam_frame::compare_linear(&grid, &every).unwrap();
    let rows = |im: &LinearImage| -> Vec<f64> {
        im.rgb
            .chunks(im.width as usize)
            .map(|row| {
                row.iter()
                    .map(|p| sunbeam_frame::linear::luminance(*p))
                    .sum()
            })
            .collect()
    };
    let (worst_row, worst) = rows(&grid)
        .iter()
        .zip(rows(&every))
        .map(|(g, e)| (g / e - 1.0).abs())
        .enumerate()
        .fold((0, 0.0), |w, (i, r)| if r > w.1 { (i, r) } else { w });
    eprintln!(
        "the horizon mirrored: grid of 4 against every pixel {d}; worst row {worst_row} {:+.3} %",
        100.0 * worst
    );
    assert!(d.max > 0.0, "the grid changed nothing: {d}");
    assert!(
        worst < EDGE_ROW_BOUND,
        "row {worst_row}: {:.3} %",
        100.0 * worst
    );
}

/// Bound of [`a_sharp_edge_of_the_environment_is_not_spread_by_the_grid`],
/// the largest relative change of a row's luminance: measured 0.08 % (row
/// 54; lavapipe, 2026-12-06), 0.21 % (row 59) since the refused blocks'
/// pixels are mixed from their even neighbours where those pass the test
/// (the centre's half, 2026-12-07: mean 0.093 → 0.122, p99 0.872 → 0.873
/// against every pixel); mixing every smooth block, as before
/// `env_block_linear`, 4.06 % (row 65, the row below the horizon).
const EDGE_ROW_BOUND: f64 = 0.005;

/// `scene`'s cells frames, single-sampled, 128 cells, on the grid of 4 and
/// with every pixel walking (`--env-cells-rate 1`), in `dir`.
fn grid_and_every_pixel(dir: &Path, scene: &Path) -> (LinearImage, LinearImage) {
    let render = |rate: &str, out: &str| {
        cells_frame(
            scene,
            &["--msaa", "1", "--env-cells", "128"],
            rate,
            &dir.join(out),
        )
    };
    (render("4", "grid.exr"), render("1", "every.exr"))
}

/// Each mesh's points walk with its own material and pack: the grid's and
/// the centre pass's walks are one full-screen pass per mesh over the points
/// the raster pass marked with the mesh (shaders/default.wgsl
/// `fs_cells_walk`). A sphere in front of a quad whose corners show around
/// it, the sphere's skin `"relative"` (its diffraction 25 times the quad's),
/// both lit by the sky, single-sampled: the centre pass alone
/// (`--env-cells-rate 1`) and the grid of 4 against every fragment walking
/// in the frame's own pass with its own material (`--env-cells-rate 0`, no
/// pre-pass). Had the quad's pass walked the sphere's points, or the other
/// way, they would be 25 times too dark or too bright.
#[test]
fn each_mesh_walks_its_own_points() {
    let dir = tmp("cells-two-meshes");
    ridge_pack(&dir);
    let scene = write(
        &dir,
        "two.json",
        r#"{ "camera": { "eye": [0, 0, 2.4], "target": [0, 0, 0], "fov_y_deg": 28 },
  "meshes": [
    { "mesh": "builtin:quad", "pack": "ridge.ktx2", "masking": "smith" },
    { "mesh": "builtin:sphere", "pack": "ridge.ktx2", "masking": "smith", "reflectance": "relative" } ],
  "lights": [],
  "environment": { "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 60 } },
  "exposure": 4.64,
  "size": [64, 64] }"#,
    );
    if !have_gpu() {
        return;
    }
    let render = |rate: &str, out: &str| {
        cells_frame(
            &scene,
            &["--msaa", "1", "--env-cells", "128"],
            rate,
            &dir.join(out),
        )
    };
    let every = render("0", "every-fragment.exr");
    for (rate, bound) in [("1", CENTRE_TWO_MESHES_P99), ("4", TWO_MESHES_P99)] {
        let frame = render(rate, &format!("rate-{rate}.exr"));
        let d = sunbeam_frame::compare_linear(&frame, &every).unwrap();
        eprintln!("two meshes, --env-cells-rate {rate} against every fragment: {d}");
        assert!(d.p99 < bound, "--env-cells-rate {rate}: {d}");
    }
}

/// Bound of [`each_mesh_walks_its_own_points`] for the grid of 4: measured
/// p99 0.052 (mean 0.001, max 0.147 over 2916 lit pixels; lavapipe,
/// 2026-12-05); the bound is the one-mesh grid's ([`LOWER_RATE_P99`]),
/// which two meshes must not exceed. With every mesh's pass walking every
/// marked point (no mesh check) p99 54.3.
const TWO_MESHES_P99: f64 = LOWER_RATE_P99;

/// Bound of [`each_mesh_walks_its_own_points`] for the centre pass alone:
/// single-sampled, its walk is the frame's own at the pixel centre, so the
/// same up to floating-point rounding (measured max 0 over 2916 lit pixels;
/// lavapipe, 2026-12-05).
const CENTRE_TWO_MESHES_P99: f64 = 0.05;

/// The centre pass (`--env-cells-rate 1`: one walk per pixel, read by every
/// fragment of the pixel that sees the same surface) against every fragment
/// walking the cells itself (`--env-cells-rate 0`), multisampled, on a sphere
/// small enough that its triangles are a few pixels wide: several fragments
/// per pixel along every edge between triangles. The frames must differ (the
/// pass is in use) and agree within CENTRE_P99 (a fragment off the centre
/// takes the centre's value, a deferred renderer's approximation). 128
/// cells keep it quick; the comparison does not depend on the count.
#[test]
fn one_walk_per_pixel_matches_every_fragment() {
    let Some((dir, scene)) = sky_lit_ridge_sphere(
        "cells-centre",
        r#"{ "eye": [0, 0.3, 6], "target": [0, 0, 0], "fov_y_deg": 20 }"#,
        64,
    ) else {
        return;
    };
    let render = |rate: &str, out: &str| {
        cells_frame(
            &scene,
            &["--msaa", "4", "--env-cells", "128"],
            rate,
            &dir.join(out),
        )
    };
    let every = render("0", "every-fragment.exr");
    let centre = render("1", "centre.exr");
    let d = sunbeam_frame::compare_linear(&centre, &every).unwrap();
    eprintln!("one walk per pixel against every fragment: {d}");
    assert!(d.max > 0.0, "the centre pass changed nothing: {d}");
    assert!(d.p99 < CENTRE_P99, "{d}");
}

/// Bound of [`one_walk_per_pixel_matches_every_fragment`]: measured p99 0.942
/// at 128 cells (mean 0.059, max 1.78 over 749 lit pixels; 0.912 at 512;
/// lavapipe, 2026-11-27), plus 25 %. Against a 64-sample reference both
/// frames are alike (at 512 cells mean 3.085 after, 3.095 before: the frame
/// is not anti-aliased).
const CENTRE_P99: f64 = 1.18;

/// The ridge pack on a masked `builtin:sphere` under the built-in sky (sun
/// 35 deg up), seen by `camera` (JSON) at `size` x `size`, in a fresh folder
/// `name`: the folder and the scene, or none without a GPU adapter.
fn sky_lit_ridge_sphere(name: &str, camera: &str, size: u32) -> Option<(PathBuf, PathBuf)> {
    sky_lit_sphere_with(ridge_pack, name, camera, size)
}

/// [`sky_lit_ridge_sphere`] with the pack that `pack` copies in.
fn sky_lit_sphere_with(
    pack: fn(&Path) -> Arc<Pack>,
    name: &str,
    camera: &str,
    size: u32,
) -> Option<(PathBuf, PathBuf)> {
    let dir = tmp(name);
    pack(&dir);
    let scene = write(
        &dir,
        "sky.json",
        &format!(
            r#"{{ "camera": {camera},
  "meshes": [ {{ "mesh": "builtin:sphere", "pack": "ridge.ktx2", "masking": "smith" }} ],
  "lights": [],
  "environment": {{ "sky": {{ "sun_elevation_deg": 35, "sun_azimuth_deg": 60 }} }},
  "exposure": 4.64,
  "size": [{size}, {size}] }}"#
        ),
    );
    have_gpu().then_some((dir, scene))
}

/// Every cell is walked at a grazing view: Mesa's llvmpipe ends all the
/// loops of a shader invocation after 65,535 iterations in all, and a
/// partly covered pixel used to walk the cells once per covered sample
/// (with this pack 2048 cells are 31,434 nodes: three walks were cut short
/// and darkened the pixel, p99 20.2 here); a walk now counts up to two
/// iterations per node (the leaf's and the descent's), so the player warns
/// above 30,000 nodes (`CPU_CELL_NODES`). A close-up of the sphere's limb,
/// where every view grazes and the edges between triangles and the
/// silhouette leave many pixels partly covered, with 4x MSAA: 1024 cells
/// against 256, which more cells change by little.
#[test]
fn grazing_pixels_walk_every_cell() {
    let Some((dir, scene)) = sky_lit_ridge_sphere(
        "cells-limb",
        r#"{ "eye": [0, 0, 2.4], "target": [0, 0.49, 0], "fov_y_deg": 3 }"#,
        32,
    ) else {
        return;
    };
    let render = |cells: &str, out: &str| {
        cells_frame(
            &scene,
            &["--msaa", "4", "--env-cells", cells],
            "1",
            &dir.join(out),
        )
    };
    let few = render("256", "cells-256.exr");
    let many = render("1024", "cells-1024.exr");
    let d = sunbeam_frame::compare_linear(&many, &few).unwrap();
    eprintln!("1024 cells against 256 at the limb: {d}");
    assert!(d.p99 < LIMB_CELLS_P99, "{d}");
}

/// Bound of [`grazing_pixels_walk_every_cell`]: measured p99 0.689 (mean
/// 0.27, max 0.88 over 672 lit pixels; lavapipe, 2026-12-06), plus 25 %.
/// A walk that counts four iterations a node (the leaf's bases in a loop)
/// is cut short at 1024 cells: p99 3.25; at 2048 cells with a walk per
/// covered sample it was 20.2.
const LIMB_CELLS_P99: f64 = 0.86;

/// One headless cells frame of `scene` at `--env-cells-rate rate` with
/// `args`, written to and read back from `out`. The report names the rate
/// the frame used: these scenes' meshes have no scale maps, so every
/// fragment may read the pre-passes and the rate is the one asked for.
fn cells_frame(scene: &Path, args: &[&str], rate: &str, out: &Path) -> LinearImage {
    let o = Command::new(BIN)
        .arg(scene)
        .args(["--headless", "--frames", "1", "--json"])
        .args(args)
        .args(["--env-estimator", "cells", "--env-cells-rate", rate, "-o"])
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        report["env_cells_rate"].as_u64(),
        rate.parse::<u64>().ok(),
        "{report}"
    );
    if let Some(i) = args.iter().position(|a| *a == "--env-cells-half") {
        let grid = rate.parse::<u32>().unwrap() > 1;
        assert_eq!(
            report["env_cells_half"].as_bool(),
            Some(grid && args[i + 1] == "true"),
            "{report}"
        );
    }
    LinearImage::read_exr(out).unwrap()
}

/// The half grid (`--env-cells-half`): the grid's own points mixed from
/// every other grid point where those blocks of 8 pixels pass the cone. A
/// narrow window onto the sky-lit ridge sphere (3 degrees of view: its
/// normals turn about 0.2 degrees a pixel, so blocks of 8 pixels pass the
/// 2-degree cone; on the whole sphere at 128 x 128 none does), 64 x 64,
/// single-sampled, the grid of 4 with and without the half grid against
/// every pixel: the half grid is in use (the frames differ, the report says
/// so) and within [`HALF_GRID_P99`] of every pixel.
#[test]
fn the_half_grid_matches_every_pixel() {
    let Some((dir, scene)) = sky_lit_ridge_sphere(
        "cells-half",
        r#"{ "eye": [0, 0, 2.4], "target": [0.2, 0.1, 0], "fov_y_deg": 3 }"#,
        64,
    ) else {
        return;
    };
    let render = |rate: &str, half: &str, out: &str| {
        cells_frame(
            &scene,
            &[
                "--msaa",
                "1",
                "--env-cells",
                "128",
                "--env-cells-half",
                half,
            ],
            rate,
            &dir.join(out),
        )
    };
    let every = render("1", "true", "every.exr");
    let grid = render("4", "false", "grid.exr");
    let half = render("4", "true", "half.exr");
    let d_grid = sunbeam_frame::compare_linear(&grid, &every).unwrap();
    let d_half = sunbeam_frame::compare_linear(&half, &every).unwrap();
    let apart = sunbeam_frame::compare_linear(&half, &grid).unwrap();
    eprintln!("window: grid of 4 against every pixel {d_grid}; with the half grid {d_half}; apart {apart}");
    assert!(apart.max > 0.0, "the half grid changed nothing: {apart}");
    assert!(d_half.p99 < HALF_GRID_P99, "{d_half}");
}

/// Bound of [`the_half_grid_matches_every_pixel`]: measured p99 0.174
/// (mean 0.052, max 0.241; the grid of 4 alone 0.115; lavapipe,
/// 2026-12-05), plus a third, as [`LOWER_RATE_P99`]; 0.166 (mean 0.051,
/// max 0.212) since blocks that curve walk (2026-12-06).
const HALF_GRID_P99: f64 = 0.23;

/// Bound of [`cells_at_a_lower_rate_match_every_pixel`]: measured p99 0.179
/// (mean 0.046, max 0.35; lavapipe, 2026-11-27; the whole sphere at 256 x 256
/// gave p99 0.250 in 7x the time), plus 25 %; 0.198 (mean 0.051, max 0.52)
/// since the centre pass mixes the grid; at the 128 cells the test uses
/// (2026-12-02, a third of the time) 0.199 (mean 0.050, max 0.41), at 512
/// the same day 0.197; 0.187 (mean 0.043, max 0.35) since blocks that curve
/// walk (`env_block_linear`, 2026-12-06).
const LOWER_RATE_P99: f64 = 0.23;

/// Accumulated first-frame estimates are the pixel's mean: 16 cells frames
/// at `--msaa 1` (a headless run knows its length, so its frames take the
/// 4 x 4 grid of sub-pixel centres, renderer::lattice_jitter) against one
/// frame 8 x 8 supersampled (the mean of 64 point samples per pixel, a box
/// filter that owes nothing to the jitter), interior pixels. The sun's
/// orders on the sphere are sharp at the scale of a pixel, so offsets that
/// stray from a midpoint rule leave the pixel's mean (docs/LIGHTING.md
/// "Accumulated frames"); the first frame alone (the centre) must be
/// farther off, or the test could not tell. The 16 frames' offsets are
/// the sample positions of 4 x 4 supersampling, so they must also give that
/// frame (up to the half floats of the sum), each walking the cells at
/// every pixel. With `--msaa 4` each frame is
/// read at one sample, jittered onto the same offsets
/// (renderer::targets::frame_sample), with the cells' pre-passes drawn at
/// that sample's points, so the 16 frames must be as close; read resolved,
/// each frame's samples would sit off its offset and widen the pixel's
/// filter.
#[test]
fn accumulated_cells_frames_are_the_pixels_mean() {
    let Some((_, scene)) = sky_lit_ridge_sphere(
        "cells-frames",
        r#"{ "eye": [0, 0, 2.4], "target": [0, 0, 0], "fov_y_deg": 26 }"#,
        24,
    ) else {
        return;
    };
    let render_msaa =
        |frames: &str, ss: &str, msaa: &str, out: &str| cells_frames(&scene, frames, ss, msaa, out);
    let render = |frames: &str, ss: &str, out: &str| render_msaa(frames, ss, "1", out);
    let boxed = render("1", "8", "box.exr");
    let interior = interior_against(&boxed);
    let one = interior(&render("1", "1", "one.exr"), &boxed);
    let sixteen = render("16", "1", "sixteen.exr");
    let sum = interior(&sixteen, &boxed);
    // the offsets against the 4 x 4 positions with every pixel walking
    // (`--env-cells-rate 1`): with a grid, the 4 x 4 frame's pixels are a
    // quarter as wide, and more of them are mixed from their neighbours
    // (docs/LIGHTING.md "The centre's half")
    let every = |frames: &str, ss: &str, out: &str| {
        cells_frames_at(&scene, frames, ss, "1", Some("1"), out)
    };
    let grid = interior(
        &every("16", "1", "sixteen-every.exr"),
        &every("1", "4", "grid-every.exr"),
    );
    let msaa = interior(&render_msaa("16", "1", "4", "sixteen-msaa.exr"), &boxed);
    eprintln!(
        "interior against the 8 x 8 box: 1 frame {one}; 16 frames {sum}; \
         16 frames against the 4 x 4 box, every pixel walking, {grid}; 16 frames at --msaa 4 {msaa}"
    );
    assert!(sum.pixels > 200, "{sum}");
    assert!(
        one.p99 > 2.0 * ACCUMULATED_P99,
        "the first frame is as close: {one}"
    );
    assert!(sum.p99 < ACCUMULATED_P99, "{sum}");
    assert!(msaa.p99 < ACCUMULATED_P99, "--msaa 4: {msaa}");
    assert!(grid.p99 < LATTICE_IS_GRID_P99, "{grid}");
}

/// `frames` cells frames of `scene` (128 cells) at `--supersample ss` and
/// `--msaa msaa`, written beside it as `out`.
fn cells_frames(scene: &Path, frames: &str, ss: &str, msaa: &str, out: &str) -> LinearImage {
    cells_frames_at(scene, frames, ss, msaa, None, out)
}

/// [`cells_frames`] at `--env-cells-rate rate` (None: the default).
fn cells_frames_at(
    scene: &Path,
    frames: &str,
    ss: &str,
    msaa: &str,
    rate: Option<&str>,
    out: &str,
) -> LinearImage {
    let out = scene.with_file_name(out);
    let rate = rate.map(|r| ["--env-cells-rate", r]);
    let o = Command::new(BIN)
        .arg(scene)
        .args([
            "--headless",
            "-q",
            "--env-estimator",
            "cells",
            "--msaa",
            msaa,
        ])
        .args([
            "--env-cells",
            "128",
            "--frames",
            frames,
            "--supersample",
            ss,
            "-o",
        ])
        .arg(&out)
        .args(rate.iter().flatten())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    LinearImage::read_exr(&out).unwrap()
}

/// CIEDE2000 of a frame against `truth` over `truth`'s interior pixels.
fn interior_against(
    truth: &LinearImage,
) -> impl Fn(&LinearImage, &LinearImage) -> sunbeam_frame::diff::ColourDiff {
    let inside = sunbeam_frame::linear::interior_pixels(&[truth]);
    move |f: &LinearImage, t: &LinearImage| {
        let de = sunbeam_frame::linear::per_pixel_de(f, t).unwrap();
        let mut v: Vec<f64> = inside.iter().filter_map(|&i| de[i]).collect();
        sunbeam_frame::diff::stats(&mut v)
    }
}

/// A point light beside the sky, accumulated: 16 cells frames at `--msaa 1`
/// against one frame 8 x 8 supersampled, interior pixels. Each frame reads
/// the point light's map over its own share of the pixel
/// (EnvGlobals::frame_share, as the environment's hot spots), the frames'
/// jitter spreading them over the pixel: the whole pixel's footprint in
/// every frame widened the sum's filter (p99 0.338 against 0.179).
#[test]
fn accumulated_frames_with_a_point_light_are_the_pixels_mean() {
    let Some((dir, sky)) = sky_lit_ridge_sphere(
        "cells-frames-light",
        r#"{ "eye": [0, 0, 2.4], "target": [0, 0, 0], "fov_y_deg": 26 }"#,
        24,
    ) else {
        return;
    };
    let text = std::fs::read_to_string(&sky).unwrap().replace(
        r#""lights": []"#,
        r#""lights": [ { "direction": [0.3, 0.4, 0.866], "intensity": 1, "spectrum": "D65" } ]"#,
    );
    assert!(text.contains("D65"), "{text}");
    let scene = write(&dir, "lit.json", &text);
    let boxed = cells_frames(&scene, "1", "8", "1", "box.exr");
    let interior = interior_against(&boxed);
    let sum = interior(&cells_frames(&scene, "16", "1", "1", "sixteen.exr"), &boxed);
    let msaa = interior(
        &cells_frames(&scene, "16", "1", "4", "sixteen-msaa.exr"),
        &boxed,
    );
    eprintln!("interior against the 8 x 8 box: 16 frames {sum}; at --msaa 4 {msaa}");
    assert!(sum.pixels > 200, "{sum}");
    assert!(sum.p99 < POINT_ACCUMULATED_P99, "{sum}");
    assert!(msaa.p99 < POINT_ACCUMULATED_P99, "--msaa 4: {msaa}");
}

/// Bound of [`accumulated_frames_with_a_point_light_are_the_pixels_mean`]:
/// measured p99 0.179 at `--msaa 1` (mean 0.054, max 0.27), 0.223 at
/// `--msaa 4` (lavapipe, 2026-12-06); each frame with the whole pixel's
/// footprint 0.338.
const POINT_ACCUMULATED_P99: f64 = 0.27;

/// Bound of [`accumulated_cells_frames_are_the_pixels_mean`]: measured p99
/// 0.220 (mean 0.064, max 0.35 over 332 pixels; lavapipe, 2026-12-03, the
/// sun's disc points spread over each frame's share of the pixel), 0.356
/// before that spread, kept as the bound; the open-ended sequence of a
/// window's sum (antithetic Halton pairs, renderer::subpixel_jitter) 0.484,
/// and 0.776 against the 4 x 4 box; the first frame alone 3.08 (7.20
/// without the spread).
/// At `--msaa 4` the same (2026-12-06): p99 0.232 (mean 0.076, max 0.83);
/// read resolved 5.33, with the centre pass at the pixel centres instead of
/// the sample's points 0.567.
const ACCUMULATED_P99: f64 = 0.45;

/// Bound of the 16 frames against the 4 x 4 supersampled frame in
/// [`accumulated_cells_frames_are_the_pixels_mean`]: measured p99 0.072
/// (max 0.18; 0.022 before the sun's disc points were spread over the
/// pixel: each frame's quarter of the pixel is taken from derivatives over
/// 2 x 2 pixels, each sub-pixel's over 2 x 2 sub-pixels), 0.036 (max 0.054)
/// since each frame takes differences across its own share (2026-12-06),
/// with a margin;
/// frames at other offsets than the grid's are tenths off (0.776). Both at
/// `--env-cells-rate 1` since the centre's half (2026-12-07): at the
/// default rate the 4 x 4 frame's pixels are mixed from their even
/// neighbours where the 24 x 24 frames' walk, p99 0.114.
const LATTICE_IS_GRID_P99: f64 = 0.1;

/// The baked snake (`sunbeam-bake --generate-snake`) with the ridge pack
/// under the sky, 96 x 48: the first frame (cells, 4 x 4 supersampled, 4x
/// MSAA) against a 64-sample reference, CIEDE2000 p99 over the interior
/// pixels (all nine lit in the reference, `interior_pixels`). Along the
/// tapering tail the triangles are smaller than a sub-pixel and turn fast:
/// a partly covered pixel shaded at its centre (its attributes extrapolated
/// past the triangle) or at one picked sample was far off there, so the
/// first-frame estimator shades every covered sample (shaders/diffraction.wgsl
/// `shade`; docs/LIGHTING.md "The first frame").
#[test]
fn snake_first_frame_matches_the_reference_inside() {
    let Some((dir, scene)) = sky_lit_snake("snake-first") else {
        return;
    };
    let r = reference(&scene, 64, &[1], &dir.join("ref.exr"));
    let o = Command::new(BIN)
        .arg(&scene)
        .args("--headless --env-estimator cells --supersample 4 -q -o".split(' '))
        .arg(dir.join("first.exr"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let f = LinearImage::read_exr(&dir.join("first.exr")).unwrap();
    let s = interior_against(&r)(&f, &r);
    eprintln!("snake, first frame against 64 samples, interior: {s}");
    assert!(s.pixels > 50, "{s}");
    assert!(s.p99 < SNAKE_INTERIOR_P99, "{s}");
}

/// Accumulated frames on a surface that turns tens of degrees across a
/// pixel: the baked snake of [`snake_first_frame_matches_the_reference_inside`],
/// 16 cells frames at `--msaa 1` (the 4 x 4 lattice of sub-pixel centres)
/// against one frame 4 x 4 supersampled at `--msaa 1` (the same 16 points),
/// interior pixels. Each frame reads the sun's orders over its share of the
/// pixel's footprint; taken as the whole pixel's differences scaled by the
/// share, that footprint was far off where the frame turns fast (p99 4.3 on
/// the 256^2 x 20 nm ridge pack's snake, docs/LIGHTING.md "The sun over
/// the pixel"); the differences across
/// the share itself (shaders/diffraction.wgsl `shade`) follow the sub-pixels'.
#[test]
fn accumulated_frames_on_the_snake_are_its_supersampled_frame() {
    let Some((dir, scene)) = sky_lit_snake("snake-frames") else {
        return;
    };
    let render = |args: &str, out: &str| {
        let o = Command::new(BIN)
            .arg(&scene)
            .args(args.split(' '))
            .args([
                "--headless",
                "--env-estimator",
                "cells",
                "--msaa",
                "1",
                "-q",
                "-o",
            ])
            .arg(dir.join(out))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        LinearImage::read_exr(&dir.join(out)).unwrap()
    };
    let frames = render("--frames 16", "frames.exr");
    let grid = render("--supersample 4", "grid.exr");
    let s = interior_against(&grid)(&frames, &grid);
    eprintln!("snake, 16 frames against the 4 x 4 supersampled frame, interior: {s}");
    assert!(s.pixels > 50, "{s}");
    assert!(s.p99 < SNAKE_FRAMES_P99, "{s}");
}

/// Bound of [`accumulated_frames_on_the_snake_are_its_supersampled_frame`]:
/// measured p99 0.803 (mean 0.051, max 1.09 over 147 pixels; lavapipe,
/// 2026-12-06), plus 25 %; the whole pixel's differences scaled 1.51.
const SNAKE_FRAMES_P99: f64 = 1.0;

/// The baked snake (`sunbeam-bake --generate-snake`) with the ridge pack
/// under the sky (sun 35 degrees up), 96 x 48, in a fresh folder `name`:
/// the folder and the scene, or none without a GPU adapter.
fn sky_lit_snake(name: &str) -> Option<(PathBuf, PathBuf)> {
    if !have_gpu() {
        return None;
    }
    let dir = tmp(name);
    ridge_pack(&dir);
    let glb = dir.join("snake.glb");
    let o = Command::new(PathBuf::from(BIN).with_file_name("sunbeam-bake"))
        .arg("--generate-snake")
        .arg("-o")
        .arg(&glb)
        .arg("-q")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let scene = write(
        &dir,
        "snake.json",
        r#"{ "camera": { "eye": [0, 0.3, 1.0], "target": [0, 0, 0], "fov_y_deg": 35 },
  "meshes": [ { "mesh": "snake.glb", "pack": "ridge.ktx2", "base_color": [0.05, 0.05, 0.05], "diffuse_weight": 0.2 } ],
  "lights": [],
  "environment": { "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 60 } },
  "exposure": 4.64,
  "size": [96, 48] }"#,
    );
    Some((dir, scene))
}

/// Bound of [`snake_first_frame_matches_the_reference_inside`]: measured p99
/// 1.815 (mean 0.617, max 2.12 over 159 pixels; lavapipe, 2026-11-28), plus
/// 25 %; every pixel shaded at its centre instead: 3.27.
const SNAKE_INTERIOR_P99: f64 = 2.3;

/// Without 32-bit float render targets (an OpenGL adapter: llvmpipe when no
/// Vulkan driver is installed, forced here with `WGPU_BACKEND=gl`) the
/// first-frame cells fail saying what to do instead (install Vulkan, or use
/// Monte Carlo) and write nothing; where the adapter renders them, the frame
/// is written.
#[test]
fn an_adapter_without_float_targets_says_what_to_do() {
    let Some((dir, scene)) =
        sky_lit_ridge_sphere("gl", r#"{ "eye": [0, 0, 3], "target": [0, 0, 0] }"#, 8)
    else {
        return;
    };
    let out = dir.join("f.exr");
    let o = Command::new(BIN)
        .arg(&scene)
        .args(["--headless", "--env-estimator", "cells", "-o"])
        .arg(&out)
        .env("WGPU_BACKEND", "gl")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    if o.status.success() {
        assert!(out.exists(), "{err}");
    } else {
        assert!(
            err.contains("mesa-vulkan-drivers") && err.contains("--env-estimator monte-carlo"),
            "{err}"
        );
        assert!(!out.exists());
    }
}

/// The edge refinement's scene: [`sky_lit_ridge_sphere`] 32 x 32 on black,
/// filling half the frame (a long, steep outline).
fn edge_sphere(name: &str) -> Option<(PathBuf, PathBuf)> {
    sky_lit_ridge_sphere(name, r#"{ "eye": [0, 0, 2.6], "target": [0, 0, 0] }"#, 32)
}

/// The player's cells frame of `scene` with `args` (the edge refinement's),
/// written to `out`, and its `--json` report.
fn edge_frame(scene: &Path, out: &Path, args: &[&str]) -> (LinearImage, serde_json::Value) {
    let o = Command::new(BIN)
        .arg(scene)
        .args(["--headless", "--json", "--env-estimator", "cells", "-o"])
        .arg(out)
        .args(args)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    (LinearImage::read_exr(out).unwrap(), report)
}

/// Edge refinement (`--edge-supersample M`, docs/LIGHTING.md "Edge
/// refinement"): the pixels it replaces are what the whole frame
/// supersampled at M x M gives there (the same positions through the full
/// camera, no tiles), the rest of the frame is untouched, and it replaced
/// the silhouette. The sky-lit ridge sphere, 32 x 32 on black (a steep
/// outline), 2 x 2 then 8 x 8 at the flagged pixels, against
/// `--supersample 8`.
#[test]
fn edge_refinement_is_the_supersampled_frame_at_its_pixels() {
    let Some((dir, scene)) = edge_sphere("edge-refine") else {
        return;
    };
    let run = |args: &[&str], out: &str| edge_frame(&scene, &dir.join(out), args);
    let (refined, report) = run(
        &["--supersample", "2", "--edge-supersample", "8"],
        "refined.exr",
    );
    let (plain, _) = run(&["--supersample", "2"], "plain.exr");
    let (truth, _) = run(&["--supersample", "8"], "truth.exr");
    let changed: Vec<usize> = (0..plain.rgb.len())
        .filter(|&i| refined.rgb[i] != plain.rgb[i])
        .collect();
    let pixels = report["edge_refine"]["pixels"].as_u64().unwrap() as usize;
    // a replaced pixel comes back equal where both are exact (black)
    assert!(
        changed.len() <= pixels && changed.len() * 4 >= pixels * 3,
        "{} pixels changed, {report}",
        changed.len()
    );
    // every silhouette pixel (partly covered at 8 x 8: neither black nor
    // like all its lit neighbours) is among them: each lit pixel with an
    // unlit neighbour
    let w = truth.width as usize;
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
    assert!(outline > 40, "{outline}");
    let de = |a: &LinearImage| {
        let d = sunbeam_frame::linear::per_pixel_de(a, &truth).unwrap();
        let mut v: Vec<f64> = changed.iter().filter_map(|&i| d[i]).collect();
        sunbeam_frame::diff::stats(&mut v)
    };
    let (after, before) = (de(&refined), de(&plain));
    eprintln!("refined pixels against --supersample 8: {after}; unrefined {before}");
    assert!(after.p99 < EDGE_REFINED_P99, "{after}");
    assert!(
        before.p99 > 4.0 * EDGE_REFINED_P99,
        "the refinement changed little: {before}"
    );
}

/// Bound of [`edge_refinement_is_the_supersampled_frame_at_its_pixels`]:
/// measured p99 0.22 over the 302 refined pixels (0.17 in the levels'
/// test), the 2 x 2 frame 7.67 there; lavapipe, 2026-12-07. The two are
/// the same positions by two ways: a tile's cells' grid serves its grazing
/// views (a tile's texel is an eighth of the pixel), where the whole frame
/// walks the cells at each grazing pixel (0.042 when both walked at each
/// fragment), besides half floats. Tiles a twentieth of a pixel off (the
/// window's centre moved by 0.05 pixels) read p99 5.5 and an outline pixel
/// unchanged.
const EDGE_REFINED_P99: f64 = 0.3;

/// Levels of edge refinement (`--edge-levels`): the second level takes the
/// refined pixels whose quarter-lattices still disagree to twice the
/// positions. The sky-lit ridge sphere of
/// [`edge_refinement_is_the_supersampled_frame_at_its_pixels`], 2 x 2, then
/// 4 x 4 at the flagged pixels and 8 x 8 at the unsettled ones: each
/// replaced pixel is the whole frame's at `--supersample 4` or `8` there,
/// some (no more than the second level reports) only at 8, and fewer than
/// the first level's.
#[test]
fn edge_refinement_levels_take_the_unsettled_pixels_further() {
    let Some((dir, scene)) = edge_sphere("edge-levels") else {
        return;
    };
    let run = |args: &[&str], out: &str| edge_frame(&scene, &dir.join(out), args);
    let (refined, report) = run(
        &[
            "--supersample",
            "2",
            "--edge-supersample",
            "4",
            "--edge-levels",
            "2",
        ],
        "refined.exr",
    );
    let (plain, _) = run(&["--supersample", "2"], "plain.exr");
    let (four, _) = run(&["--supersample", "4"], "four.exr");
    let (eight, _) = run(&["--supersample", "8"], "eight.exr");
    let levels = report["edge_refine"]["levels"].as_array().unwrap();
    let count = |l: usize| levels[l]["pixels"].as_u64().unwrap() as usize;
    assert!(
        levels.len() == 2 && count(1) > 0 && count(1) < count(0),
        "{report}"
    );
    let d4 = sunbeam_frame::linear::per_pixel_de(&refined, &four).unwrap();
    let d8 = sunbeam_frame::linear::per_pixel_de(&refined, &eight).unwrap();
    let (mut off, mut only_eight, mut changed) = (vec![], 0, 0);
    for i in 0..plain.rgb.len() {
        if refined.rgb[i] == plain.rgb[i] {
            continue;
        }
        changed += 1;
        let (a, b) = (d4[i].unwrap_or(0.0), d8[i].unwrap_or(0.0));
        off.push(a.min(b));
        if b < EDGE_REFINED_P99 && a >= EDGE_REFINED_P99 {
            only_eight += 1;
        }
    }
    let off = sunbeam_frame::diff::stats(&mut off);
    eprintln!(
        "{changed} pixels changed, {only_eight} the 8 x 8 frame's only; against the nearer of 4 x 4 and 8 x 8: {off}; {report}"
    );
    assert!(changed <= count(0) && off.p99 < EDGE_REFINED_P99, "{off}");
    assert!(only_eight > 0 && only_eight <= count(1), "{only_eight}");
}
