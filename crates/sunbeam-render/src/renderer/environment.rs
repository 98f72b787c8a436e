//! Sky and map lighting in the player (docs/PLAY.md "Environment"): which
//! modes shade a scene's environment, and the extended-light maps of each
//! pack under it (read from the pack's `NAME.env-response.ktx2` or built by
//! sunbeam-response's `build_env`, uploaded by
//! [`crate::env::EnvMaps`]). The progressive estimator itself is
//! [`crate::env`] and shaders/environment.wgsl.

use super::Mode;
use std::path::Path;
use std::sync::Arc;
use sunbeam_common::{Error, Result};
use sunbeam_frame::Prepared;
use sunbeam_light::Environment;
use sunbeam_pack::Pack;
use sunbeam_response::env_file;

/// The environment a mode shades: the scene's in the default mode, none for
/// the Lambert baseline; the other baselines refuse a scene with one.
pub(super) fn of_scene(p: &Prepared, mode: Mode) -> Result<Option<Arc<Environment>>> {
    Ok(match mode {
        Mode::Default => p.environment.clone(),
        Mode::Lambert => None,
        m => {
            if p.environment.is_some() {
                return Err(Error::usage(format!(
                    "environment: the player shades sky and map lighting in the default mode only (not --mode {})",
                    format!("{m:?}").to_lowercase()
                )));
            }
            None
        }
    })
}

/// The environment's maps already built, per pack (the same `Arc`).
pub(super) type BuiltMaps = Vec<(*const Pack, Arc<crate::env::EnvMaps>)>;

/// The extended-light maps of `pack` (meshes[`mi`], read from `path`) under
/// `env` on the GPU, once per pack (`built`; [`response`] reads or builds them).
#[allow(clippy::too_many_arguments)]
pub(super) fn maps(
    gpu: &crate::gpu::Gpu,
    env: &Environment,
    pack: &Arc<Pack>,
    path: Option<&Path>,
    mi: usize,
    opts: &sunbeam_response::Options,
    cells: (usize, usize),
    built: &mut BuiltMaps,
    notes: &mut Vec<String>,
) -> Result<Arc<crate::env::EnvMaps>> {
    let key = Arc::as_ptr(pack);
    if let Some((_, m)) = built.iter().find(|(k, _)| *k == key) {
        return Ok(m.clone());
    }
    let er = response(env, pack, path, mi, opts, notes)?;
    let m = Arc::new(crate::env::EnvMaps::new(gpu, &er, cells)?);
    built.push((key, m.clone()));
    Ok(m)
}

/// The extended-light maps of `pack` (meshes[`mi`], read from `path`) under
/// `env`: read from the pack's `NAME.env-response.ktx2` (`sunbeam-pack
/// --response`) when it serves this pack and environment, else built (what
/// the build took, and why, goes to `notes`). A file that cannot be read is
/// an input error naming it. Also what `--export-environment` writes from.
pub(crate) fn response(
    env: &Environment,
    pack: &Arc<Pack>,
    path: Option<&Path>,
    mi: usize,
    opts: &sunbeam_response::Options,
    notes: &mut Vec<String>,
) -> Result<sunbeam_response::env::EnvResponse> {
    let t0 = std::time::Instant::now();
    let side = path.map(env_file::sidecar_path).filter(|p| p.is_file());
    let mut stale = None;
    if let Some(side) = &side {
        match env_file::read_for(side, &pack.manifest, env, opts)? {
            Ok(er) => {
                log::info!(
                    "read the environment's response maps of meshes[{mi}].pack from {} in {:.2?}",
                    side.display(),
                    t0.elapsed()
                );
                return Ok(er);
            }
            Err(why) => stale = Some(format!("{} {why}; ", side.display())),
        }
    }
    // A manifest-only pack (read so because its maps looked current) has no
    // terms to build from: read it whole.
    let full;
    let pack_terms = if pack.has_terms() {
        pack
    } else {
        match path {
            Some(p) => {
                full =
                    Arc::new(Pack::read(p).map_err(|e| e.context(format!("meshes[{mi}].pack")))?);
                &full
            }
            None => {
                return Err(Error::internal(format!(
                "meshes[{mi}].pack: the environment's maps need the pack's terms (read it whole)"
            )))
            }
        }
    };
    let t0 = std::time::Instant::now();
    let er = sunbeam_response::env::build_env(pack_terms, env, opts);
    let hint = if side.is_some() {
        " (rebuild it: sunbeam-pack --response)"
    } else {
        " (write them once with `sunbeam-pack --response` to open instantly)"
    };
    notes.push(format!(
        "{}built the environment's response maps for meshes[{mi}].pack ({} x {} x {} texels, {} maps, \
         {} pyramid levels) in {:.2} s{hint}",
        stale.unwrap_or_default(),
        er.grid.n_theta,
        er.grid.n_rho,
        er.grid.n_s,
        er.basis.len() + usize::from(er.sun.is_some()),
        er.proposal.offsets.len(),
        t0.elapsed().as_secs_f64()
    ));
    Ok(er)
}
