//! Headless GPU frames against the CPU reference (sunbeam-raster, float64, 1 nm):
//! mean CIEDE2000 < 0.5 and 99th percentile < 2 (issue 6). Runs on Mesa lavapipe
//! in CI; without an adapter the tests skip, or fail under SUNBEAM_REQUIRE_ALL=1.

mod gpu;

use gpu::gpu;
use std::path::PathBuf;
use std::sync::Arc;
use sunbeam_frame::{fixtures, Image, Prepared};
use sunbeam_raster::Options;
use sunbeam_render::{Gpu, Mode, Settings};

const SIZE: [u32; 2] = [128, 128];

fn data_dir() -> Option<PathBuf> {
    sunbeam_common::testdata::shared_file("snake/BlazingBump.bmp")
        .map(|p| p.parent().unwrap().to_path_buf())
}

fn out_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("play-frames");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Point-sampled against point-sampled: the reference shades pixel centres, so
/// the player does too here (no MSAA, no footprint filter); the anti-aliased
/// comparison is `response_map_*` below.
fn point() -> Settings {
    Settings {
        msaa: 1,
        footprint: false,
        ..Default::default()
    }
}

fn check(name: &str, gpu: &Gpu, p: &Prepared, mean_max: f64, p99_max: f64) {
    check_with(name, gpu, p, &point(), mean_max, p99_max)
}

fn check_with(name: &str, gpu: &Gpu, p: &Prepared, st: &Settings, mean_max: f64, p99_max: f64) {
    let t = std::time::Instant::now();
    let reference = sunbeam_raster::render_prepared(p, &Options::default());
    let t_cpu = t.elapsed();
    let t = std::time::Instant::now();
    let frame = sunbeam_render::render_headless(gpu, p, st, None, 1).unwrap();
    let t_gpu = t.elapsed();
    let dir = out_dir();
    reference
        .write_png(&dir.join(format!("{name}-cpu.png")))
        .unwrap();
    frame
        .write_png(&dir.join(format!("{name}-gpu.png")))
        .unwrap();
    let d = sunbeam_frame::compare(&frame, &reference).unwrap();
    let (mean, sd) = reference.mean_sd();
    eprintln!("{name}: {d} (cpu {t_cpu:.2?}, gpu {t_gpu:.2?}; reference mean {mean:.3} sd {sd:.3}; frames in {})", dir.display());
    assert!(
        sd > 0.02,
        "{name}: the reference image is nearly uniform: the scene shows nothing"
    );
    assert!(
        d.mean < mean_max && d.p99 < p99_max,
        "{name}: GPU frame differs from the CPU reference: {d}"
    );
}

/// Stops added to the fixtures' exposure: they were set for the relative
/// normalisation (a flat patch head-on reflects 1); the default absolute
/// reflectance is `F(0)` = 0.04 of that head-on (PHYSICS.md 2), so
/// `log2(1 / F(0))` = 4.64 stops keeps the frames about as bright, and the
/// CIEDE2000 comparisons as sensitive, as they were.
fn absolute_exposure() -> f64 {
    use sunbeam_optics::gain;
    -gain::f0(gain::DEFAULT_IOR).log2()
}

fn with_pack(
    patch: &fixtures::Patch,
    mut scene: (sunbeam_scene::Scene, sunbeam_frame::Mesh),
) -> Option<Prepared> {
    let dir = data_dir()?;
    scene.0.exposure += absolute_exposure();
    let pack = fixtures::pack(patch, &dir, &Default::default()).unwrap();
    eprintln!(
        "{}: {} terms, crop {}x{}",
        patch.file, pack.manifest.terms, pack.manifest.crop.width, pack.manifest.crop.height
    );
    Some(fixtures::prepared(scene.0, scene.1, Some(Arc::new(pack))))
}

#[test]
fn blazed_grating_quad_matches_reference() {
    let Some(p) = with_pack(&fixtures::BLAZED, fixtures::quad_scene(SIZE)) else {
        return;
    };
    let Some(gpu) = gpu() else { return };
    check("quad-blazed", &gpu, &p, 0.5, 2.0);
}

/// The per-fragment path (`--mode direct`, shared with the thesis mode) against the
/// same reference: a regression test for a pack-unit slip (bin scale in um) that
/// sent every fragment to the specular bin and rendered the mesh white.
#[test]
fn direct_mode_quad_matches_reference() {
    let Some(p) = with_pack(&fixtures::BLAZED, fixtures::quad_scene(SIZE)) else {
        return;
    };
    let Some(gpu) = gpu() else { return };
    let st = Settings {
        mode: Mode::Direct,
        ..point()
    };
    check_with("quad-blazed-direct", &gpu, &p, &st, 0.5, 2.0);
}

#[test]
fn elaphe_sphere_matches_reference() {
    let Some(p) = with_pack(&fixtures::ELAPHE, fixtures::sphere_scene(SIZE)) else {
        return;
    };
    let Some(gpu) = gpu() else { return };
    check("sphere-elaphe", &gpu, &p, 0.5, 2.0);
}

#[test]
fn xenopeltis_snake_matches_reference() {
    let Some(p) = with_pack(&fixtures::XENO, fixtures::snake_scene(SIZE).unwrap()) else {
        return;
    };
    let Some(gpu) = gpu() else { return };
    check("snake-xeno", &gpu, &p, 0.5, 2.0);
}

/// Smith masking (scene `"masking": "smith"`, sunbeam_optics::masking) in the
/// player's shader against the reference's (two implementations), on the
/// snake, whose limbs it darkens (the point-lit sphere hardly has grazing
/// light); the masked reference must differ from the unmasked one or the
/// comparison would not show that either renderer applies it.
#[test]
fn masked_snake_matches_reference() {
    let Some(mut p) = with_pack(&fixtures::XENO, fixtures::snake_scene(SIZE).unwrap()) else {
        return;
    };
    let Some(gpu) = gpu() else { return };
    // Steep, anisotropic slopes show the shape of the function (an axis
    // swapped in one renderer would not match).
    let own = p.meshes[0]
        .1
        .pack
        .as_ref()
        .and_then(|k| k.manifest.rms_slope);
    assert!(
        own.is_some_and(|s| s[0] > 0.0 && s[1] > 0.0),
        "the pack records its slopes: {own:?}"
    );
    let slope = [0.9, 0.3];
    let unmasked = sunbeam_raster::render_prepared(&p, &Options::default());
    p.meshes[0].1.masking = sunbeam_optics::masking::Masking::smith(slope);
    let masked = sunbeam_raster::render_prepared(&p, &Options::default());
    let d = sunbeam_frame::compare(&masked, &unmasked).unwrap();
    eprintln!("masked vs unmasked reference: {d}");
    // Where masking acts, the energy bound (docs/LIGHTING.md "Energy bound")
    // already darkens the unmasked limb: 7.3 here (above 8 without the bound).
    assert!(d.max > 4.0, "masking changed nothing visible: {d}");
    check("snake-xeno-masked", &gpu, &p, 0.5, 2.0);
}

/// The skin's uniforms (sunbeam_optics::gain::Material: scene `ior` and
/// `reflectance`): another index in the relative normalisation, in the
/// player's shader against the reference, on the sphere, whose limbs show the
/// Fresnel curve; the reference must differ from the default skin's.
#[test]
fn relative_reflectance_and_index_match_reference() {
    let Some(mut p) = with_pack(&fixtures::ELAPHE, fixtures::sphere_scene(SIZE)) else {
        return;
    };
    let Some(gpu) = gpu() else { return };
    let default = sunbeam_raster::render_prepared(&p, &Options::default());
    p.meshes[0].1.skin = sunbeam_optics::gain::Material {
        ior: 1.33,
        reflectance: sunbeam_optics::gain::Reflectance::Relative,
        ..Default::default()
    };
    // relative: back to the fixture's own exposure
    p.scene.exposure -= absolute_exposure();
    let other = sunbeam_raster::render_prepared(&p, &Options::default());
    let d = sunbeam_frame::compare(&other, &default).unwrap();
    eprintln!("ior 1.33 relative vs the default skin (reference): {d}");
    assert!(d.max > 2.0, "the skin changed nothing visible: {d}");
    check("sphere-elaphe-relative", &gpu, &p, 0.5, 2.0);
}

#[test]
fn lambert_mode_is_the_closed_form() {
    let Some(gpu) = gpu() else { return };
    let (mut scene, mesh) = fixtures::quad_scene([32, 32]);
    scene.meshes[0].base_color = [0.5, 0.25, 0.125];
    let p = fixtures::prepared(scene, mesh, None);
    let st = Settings {
        mode: Mode::Lambert,
        ..Default::default()
    };
    let frame: Image = sunbeam_render::render_headless(&gpu, &p, &st, None, 1).unwrap();
    let reference = sunbeam_raster::render_prepared(&p, &Options::default());
    let d = sunbeam_frame::compare(&frame, &reference).unwrap();
    assert!(d.max < 0.05, "{d}");
}

/// A front-lit sphere filling the frame, shaded with a synthetic snake-skin ridge
/// field (443 nm tall, 1.55 um period, rough) of `n^2` pixels of `pixel` metres:
/// the player (response map, MSAA, footprint filter) against the anti-aliased
/// CPU reference (`--samples 16`, the 1 nm tables every 1-5 nm), both in linear light,
/// CIEDE2000 over lit pixels (issue 11: anti-aliased p99 < 1, max < 5; the
/// player's own 1x frame p99 < 2).
fn response_map_at_scale(name: &str, n: usize, pixel: f64) {
    let Some(gpu) = gpu() else { return };
    // The frame as this test had it in the relative normalisation: the
    // diffraction as bright (the exposure) and the grey base as faint beside
    // it (its colour times F(0)). Brightened 25 times, the base's silhouette
    // alone (4x MSAA coverage against 16 samples per pixel) gave the 1x frame
    // p99 2.35, with p99 0.25 inside the silhouette.
    let p = gpu::ridge_sphere(gpu::ridge_pack(n, pixel), 1.6, 48);
    let t = std::time::Instant::now();
    let reference = sunbeam_raster::render_prepared_linear(
        &p,
        &Options {
            samples: 16,
            ..Default::default()
        },
    )
    .unwrap();
    let t_cpu = t.elapsed();
    let st = Settings::default();
    let aa = sunbeam_render::render_headless_linear(&gpu, &p, &st, None, 1, 2).unwrap();
    let one = sunbeam_render::render_headless_linear(&gpu, &p, &st, None, 1, 1).unwrap();
    let dir = out_dir();
    reference
        .write_exr(&dir.join(format!("{name}-ref.exr")))
        .unwrap();
    aa.write_exr(&dir.join(format!("{name}-aa.exr"))).unwrap();
    let d_aa = sunbeam_frame::compare_linear(&aa, &reference).unwrap();
    let d_one = sunbeam_frame::compare_linear(&one, &reference).unwrap();
    eprintln!("{name}: anti-aliased {d_aa}; 1x {d_one} (reference {t_cpu:.2?})");
    assert!(
        d_aa.pixels > 48 * 48 / 2,
        "{name}: only {} lit pixels: the scene shows little",
        d_aa.pixels
    );
    assert!(
        d_aa.p99 < 1.0 && d_aa.max < 5.0,
        "{name}: anti-aliased {d_aa}"
    );
    assert!(d_one.p99 < 2.0, "{name}: 1x {d_one}");
}

#[test]
fn response_map_5um_patch_matches_antialiased_reference() {
    response_map_at_scale("map-5um", 160, 31e-9);
}

#[test]
fn response_map_20um_patch_matches_antialiased_reference() {
    response_map_at_scale("map-20um", 640, 31e-9);
}

/// The background goes through the display transform once: a mesh-free frame
/// of a grey background equals the CPU reference (regression: the offscreen
/// target is linear, and its clear colour was display-encoded twice).
#[test]
fn background_matches_reference() {
    let Some(gpu) = gpu() else { return };
    let (mut scene, mesh) = fixtures::quad_scene([16, 16]);
    scene.background = sunbeam_scene::Background::Colour([0.004, 0.004, 0.005]);
    scene.exposure = 1.5;
    scene.camera.eye = [0.0, 0.0, -5.0]; // behind the quad: back face culled, background only
    let p = fixtures::prepared(scene, mesh, None);
    let frame: Image =
        sunbeam_render::render_headless(&gpu, &p, &Settings::default(), None, 1).unwrap();
    let reference = sunbeam_raster::render_prepared(&p, &Options::default());
    let d = sunbeam_frame::compare(&frame, &reference).unwrap();
    assert!(d.max < 0.5, "background: {d}");
}

/// A coloured light (scene `lights[].color`, tinting its RGB contribution)
/// seen through a shifted lens (`camera.shift`) on a non-square frame: the
/// reference under a red light differs from the white one (and is red), and
/// the player's frame matches the reference, so both renderers carry the
/// colour and the off-axis projection alike.
#[test]
fn coloured_light_and_lens_shift_match_reference() {
    let Some(mut p) = with_pack(&fixtures::ELAPHE, fixtures::sphere_scene([96, 64])) else {
        return;
    };
    p.scene.camera.shift = [0.12, -0.08];
    let white = sunbeam_raster::render_prepared(&p, &Options::default());
    p.scene.lights[0].color = [1.0, 0.35, 0.15];
    let red = sunbeam_raster::render_prepared(&p, &Options::default());
    let d = sunbeam_frame::compare(&red, &white).unwrap();
    eprintln!("red vs white light (reference): {d}");
    assert!(d.p99 > 10.0, "the light's colour changed little: {d}");
    let sum = |img: &Image, k: usize| -> f64 {
        (0..img.height)
            .flat_map(|j| (0..img.width).map(move |i| (i, j)))
            .map(|(i, j)| img.pixel(i, j)[k] as f64)
            .sum()
    };
    // the red channel keeps more than green and blue lose
    let ratio = |k: usize| sum(&red, k) / sum(&white, k);
    eprintln!(
        "channel sums red / white: {:.3} {:.3} {:.3}",
        ratio(0),
        ratio(1),
        ratio(2)
    );
    assert!(ratio(0) > ratio(1) && ratio(1) > ratio(2), "not red");
    let Some(gpu) = gpu() else { return };
    check("sphere-elaphe-red-shifted", &gpu, &p, 0.5, 2.0);
}
