//! Shared helpers for the player's tests (tests/match_reference.rs,
//! tests/material_wgsl.rs, tests/silhouette.rs, tests/scales_player.rs): the headless adapter
//! (`SUNBEAM_TEST_BACKEND`; None to skip, a failure under
//! SUNBEAM_REQUIRE_ALL=1) and the synthetic ridge packs of the real-scale
//! comparisons on a point-lit sphere.
#![allow(dead_code)]

use sunbeam_render::Gpu;

/// The headless adapter (`SUNBEAM_TEST_BACKEND` picks the backend); without
/// one the test skips with a message, or fails under SUNBEAM_REQUIRE_ALL=1.
pub fn gpu() -> Option<Gpu> {
    let backend = std::env::var("SUNBEAM_TEST_BACKEND")
        .ok()
        .and_then(|b| b.parse().ok())
        .unwrap_or_default();
    match Gpu::headless(backend) {
        Ok(g) => {
            eprintln!("adapter: {}", g.describe());
            Some(g)
        }
        Err(e) => {
            if sunbeam_common::testdata::require_all() {
                panic!("{e} (SUNBEAM_REQUIRE_ALL=1: CI needs a GPU adapter; scripts/ensure-deps.sh installs lavapipe)");
            }
            eprintln!("SKIP: {e}");
            None
        }
    }
}

/// A window-model pack of the synthetic Xenopeltis-like ridge field
/// (`sunbeam_synth::preset`: 443 nm tall, 1.55 um period, rough) of `n^2`
/// samples of `pixel` metres, default build options.
pub fn ridge_pack(n: usize, pixel: f64) -> sunbeam_pack::Pack {
    let f = sunbeam_synth::preset("xenopeltis", n, pixel).unwrap();
    let fr = sunbeam_pack::build::FieldRef {
        width: f.width,
        height: f.height,
        dx: f.dx,
        dy: f.dy,
        data: &f.data,
    };
    sunbeam_pack::build::build(fr, &Default::default(), &mut |_, _| {}).unwrap()
}

/// A unit-diameter sphere (`Mesh::uv_sphere(96, 48)`) with `pack`, seen from
/// `eye_z` on +z (35 deg field of view) in a `size` x `size` frame, lit from
/// (0.15, 0.1, 1), diffuse weight 0.1, in absolute reflectance at +4.64 EV
/// (`log2(1 / F(0))`) with the base times F(0): the frame as the response-map
/// tests had it in the relative normalisation (the diffraction as bright, the
/// grey base as faint beside it).
pub fn ridge_sphere(pack: sunbeam_pack::Pack, eye_z: f64, size: u32) -> sunbeam_frame::Prepared {
    let mesh = sunbeam_frame::Mesh::uv_sphere(96, 48);
    let mut scene = sunbeam_scene::Scene::default_lit(
        "builtin:sphere".into(),
        Some("pack".into()),
        mesh.bounds(),
        sunbeam_scene::DefaultLighting::Point,
    );
    scene.camera.eye = [0.0, 0.0, eye_z];
    scene.camera.target = [0.0, 0.0, 0.0];
    scene.camera.fov_y_deg = 35.0;
    scene.lights[0].direction = [0.15, 0.1, 1.0];
    scene.meshes[0].diffuse_weight = 0.1;
    scene.size = [size, size];
    let f0 = sunbeam_optics::gain::f0(sunbeam_optics::gain::DEFAULT_IOR);
    scene.exposure -= f0.log2();
    scene.meshes[0].base_color = scene.meshes[0].base_color.map(|c| c * f0);
    sunbeam_frame::fixtures::prepared(scene, mesh, Some(std::sync::Arc::new(pack)))
}
