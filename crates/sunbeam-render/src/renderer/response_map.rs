//! The default mode (PHYSICS.md 2 through the pack's response map,
//! sunbeam-response): the point-light map of a pack, loaded from beside the
//! pack or built ([`crate::response`]), and its grid in the material's
//! uniforms. Its shading is shaders/response_map.wgsl's (through
//! shaders/default.wgsl, composed with shaders/diffraction.wgsl).

use super::uniforms::MaterialU;
use super::Settings;
use std::path::Path;
use std::sync::Arc;
use sunbeam_common::Result;
use sunbeam_pack::Pack;
use sunbeam_response::Response;

/// The point-light response map of `pack` (the file `path` names, if any),
/// its grid and the footprint switch set in `mu`; notes go to `warnings`.
pub(super) fn point_map(
    pack: &Arc<Pack>,
    path: Option<&Path>,
    settings: &Settings,
    mu: &mut MaterialU,
    warnings: &mut Vec<String>,
) -> Result<Arc<Response>> {
    let t0 = std::time::Instant::now();
    let (resp, note) = crate::response::load_or_build(pack, path, &settings.response)?;
    log::info!(
        "response map {:?} ready in {:.2?}",
        resp.info.grid,
        t0.elapsed()
    );
    warnings.extend(note);
    let gr = resp.info.grid;
    mu.resp_on = 1;
    mu.resp_n_theta = gr.n_theta as f32;
    mu.resp_n_rho = gr.n_rho as f32;
    mu.resp_n_s = gr.n_s as f32;
    mu.resp_r0 = gr.r0 as f32;
    mu.resp_rho_scale = gr.rho_scale() as f32;
    mu.resp_footprint = u32::from(settings.footprint);
    Ok(resp)
}
