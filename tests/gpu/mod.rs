//! The GPU of the player's tests (tests/match_reference.rs,
//! tests/material_wgsl.rs): a headless adapter (`SUNBEAM_TEST_BACKEND`),
//! or None to skip, a failure under SUNBEAM_REQUIRE_ALL=1.

use sunbeam_render::Gpu;

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
