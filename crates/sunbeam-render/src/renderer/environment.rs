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
use sunbeam_response::cells::{Cells, GpuCells};
use sunbeam_response::{cells_file, env_file};

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

/// Iterations after which Mesa's llvmpipe (lavapipe's rasteriser) ends every
/// loop of a shader invocation (LP_MAX_TGSI_LOOP_ITERATIONS, one count for
/// all of its loops): a walk of the cells longer than this is cut short and
/// its view darkens.
pub(crate) const CPU_LOOP_LIMIT: usize = 65_535;

/// Cells' nodes above which a CPU rasteriser may cut a walk: a grazing view
/// refines most of the tree, a walk counts up to two iterations per node
/// (each leaf's and each step of the descent to it: shaders/env_cells.wgsl
/// `env_cells`, docs/LIGHTING.md "What a branch costs on llvmpipe"), and the
/// invocation's other loops (lights, MSAA samples, hot spots) take their
/// share of [`CPU_LOOP_LIMIT`].
pub(crate) const CPU_CELL_NODES: usize = 30_000;

/// The extended-light maps of `pack` (meshes[`mi`], read from `path`) under
/// `env` on the GPU, once per pack (`built`; [`response`] reads or builds
/// them). On a CPU rasteriser whose loops a walk of these cells may outrun,
/// a warning naming the count to use (`warnings`, with `estimator` cells).
#[allow(clippy::too_many_arguments)]
pub(super) fn maps(
    gpu: &crate::gpu::Gpu,
    env: &Environment,
    pack: &Arc<Pack>,
    path: Option<&Path>,
    mi: usize,
    opts: &sunbeam_response::Options,
    cells: (Option<usize>, usize),
    estimator: crate::env::EnvEstimator,
    built: &mut BuiltMaps,
    notes: &mut Vec<String>,
    warnings: &mut Vec<String>,
) -> Result<Arc<crate::env::EnvMaps>> {
    let key = Arc::as_ptr(pack);
    if let Some((_, m)) = built.iter().find(|(k, _)| *k == key) {
        return Ok(m.clone());
    }
    let cells = crate::env::pack_cells(cells, pack);
    // The first frame with the pipeline's cells: under the sky it needs no
    // basis map (its sun has its own map, the sky no hot spots) and never the
    // proposal, so only the sun's map is read (docs/bench/play.md "Start-up").
    let cells_first = estimator == crate::env::EnvEstimator::Cells;
    let from_file = match path.map(env_file::sidecar_path).filter(|p| p.is_file()) {
        // a head that cannot be read is reported by `response` below
        Some(side) if cells_first => match env_file::read_info(&side) {
            Ok(head) => cells_from_file(env, pack, path, &head.grid, head.lambda_samples, cells)?
                .ok()
                .map(|c| (head.grid, c)),
            Err(_) => None,
        },
        _ => None,
    };
    let needs = env_file::Needs {
        basis: from_file.is_none() || !cells_first || matches!(env, Environment::Map(_)),
        proposal: !cells_first,
    };
    let er = response(env, pack, path, mi, opts, needs, notes)?;
    // Monte Carlo draws from the maps' pyramid and never walks the cells.
    let gc = match (estimator, from_file) {
        (crate::env::EnvEstimator::Cells, Some((grid, c))) if grid == er.grid => Some(c),
        (crate::env::EnvEstimator::Cells, _) => {
            Some(first_frame_cells(&er, env, pack, path, mi, cells, notes)?)
        }
        (crate::env::EnvEstimator::MonteCarlo, _) => None,
    };
    let m = Arc::new(crate::env::EnvMaps::new(gpu, &er, gc.as_ref())?);
    if estimator == crate::env::EnvEstimator::Cells && gpu.is_cpu() && m.nodes > CPU_CELL_NODES {
        // nodes grow about as the cells: the power of two that fits
        let fit = (cells.0 * CPU_CELL_NODES / m.nodes).max(1);
        let fewer = 1usize << fit.ilog2();
        warnings.push(format!(
            "meshes[{mi}].pack: {} cells make {} nodes, more than a CPU rasteriser's shader loops \
             may run ({CPU_LOOP_LIMIT} iterations in all): grazing views may darken; use \
             --env-cells {fewer} or fewer here (docs/LIGHTING.md \"One walk per fragment\")",
            cells.0, m.nodes
        ));
    }
    built.push((key, m.clone()));
    Ok(m)
}

/// The extended-light maps of `pack` (meshes[`mi`], read from `path`) under
/// `env`: read from the pack's `NAME.env-response.ktx2` (`sunbeam-pack
/// --response`) when it serves this pack and environment, only what `needs`
/// asks for, else built, all of them (what the build took, and why, goes to
/// `notes`). A file that cannot be read is
/// an input error naming it. Also what `--export-environment` writes from.
pub(crate) fn response(
    env: &Environment,
    pack: &Arc<Pack>,
    path: Option<&Path>,
    mi: usize,
    opts: &sunbeam_response::Options,
    needs: env_file::Needs,
    notes: &mut Vec<String>,
) -> Result<sunbeam_response::env::EnvResponse> {
    let t0 = std::time::Instant::now();
    let side = path.map(env_file::sidecar_path).filter(|p| p.is_file());
    let mut stale = None;
    if let Some(side) = &side {
        match env_file::read_needed(side, &pack.manifest, env, opts, needs)? {
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

/// The first-frame cells of `env`'s basis for maps on `grid` with `lambdas`
/// wavelength samples (the mesh's pack `pack`, read from `path`), `cells` =
/// (top cut, levels below), from the pack's `NAME.env-cells.ktx2`
/// (`sunbeam-pack --response`), or why not (None: no file). A file that
/// cannot be read is an input error naming it.
fn cells_from_file(
    env: &Environment,
    pack: &Pack,
    path: Option<&Path>,
    grid: &sunbeam_response::Grid,
    lambdas: usize,
    cells: (usize, usize),
) -> Result<std::result::Result<GpuCells, Option<String>>> {
    let Some(side) = path.map(cells_file::sidecar_path).filter(|p| p.is_file()) else {
        return Ok(Err(None));
    };
    let basis = cells_file::basis_of(env);
    Ok(
        cells_file::read_set(&side, &pack.manifest, grid, lambdas, basis, cells)?
            .map_err(|why| Some(format!("{} {why}", side.display()))),
    )
}

/// The first-frame cells of `er` (`env`'s basis maps; meshes[`mi`]'s pack,
/// read from `path`), `cells` = (top cut, levels below): read from the
/// pack's `NAME.env-cells.ktx2` (`sunbeam-pack --response`) when it holds
/// them, else clustered here; where the pipeline's maps stand beside the
/// pack but its cells do not serve, a note says what the clustering took
/// and why. A cells file that cannot be read is an input error naming it.
pub(crate) fn first_frame_cells(
    er: &sunbeam_response::env::EnvResponse,
    env: &Environment,
    pack: &Pack,
    path: Option<&Path>,
    mi: usize,
    cells: (usize, usize),
    notes: &mut Vec<String>,
) -> Result<GpuCells> {
    let lambdas = er.basis.first().map_or(0, |m| m.info.lambda_samples);
    let why = match cells_from_file(env, pack, path, &er.grid, lambdas, cells)? {
        Ok(g) => return Ok(g),
        Err(Some(why)) => Some(why),
        Err(None) => path
            .filter(|p| env_file::sidecar_path(p).is_file())
            .map(|p| {
                format!(
                    "no cells beside the pack ({}; write them once with `sunbeam-pack --response`)",
                    cells_file::sidecar_path(p).display()
                )
            }),
    };
    let t0 = std::time::Instant::now();
    let g = Cells::build(&er.basis, cells.0, cells.1).gpu();
    if let Some(why) = why {
        notes.push(format!(
            "clustered the environment's maps of meshes[{mi}].pack into {} cells ({} nodes) in {:.2} s: {why}",
            g.n_top,
            g.nodes,
            t0.elapsed().as_secs_f64()
        ));
    }
    Ok(g)
}

#[cfg(test)]
mod cells_wgsl_tests {
    //! shaders/env_cells.wgsl mirrors sunbeam_response::cells' constants by
    //! hand (the layout of `Cells::gpu_data` in fours, the walk's
    //! thresholds); naga's parse of the player's shader reads them back, so
    //! the two cannot drift (a wrong layout would show only as a wrong image).
    use super::super::SHADER;
    use sunbeam_response::cells;

    fn constant(module: &naga::Module, name: &str) -> f64 {
        let (_, c) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("{name} is not a constant of the WGSL"));
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::F32(x)) => f64::from(x),
            naga::Expression::Literal(naga::Literal::U32(x)) => f64::from(x),
            ref e => panic!("{name}: not a literal: {e:?}"),
        }
    }

    #[test]
    fn the_cells_constants_match_the_wgsl() {
        let module = naga::front::wgsl::parse_str(SHADER).expect("the shader parses");
        let c = |name| constant(&module, name);
        assert_eq!(
            c("ENV_CELL_HEADER") * 4.0,
            cells::GPU_HEADER as f64,
            "header in fours"
        );
        assert_eq!(
            c("ENV_CELL_LAYER") * 4.0,
            cells::GPU_LAYER as f64,
            "layer in fours"
        );
        assert_eq!(c("ENV_CELL_NONE"), f64::from(cells::GPU_NONE));
        for (name, rust) in [
            ("ENV_REFINE", cells::REFINE),
            ("ENV_RIM_WIDTHS", cells::RIM_WIDTHS),
            ("ENV_RIM_OUTSIDE", cells::RIM_OUTSIDE),
            ("ENV_RIM_BOX", cells::RIM_BOX),
            ("ENV_CELL_STRADDLE", cells::STRADDLE),
        ] {
            assert_eq!(c(name), f64::from(rust as f32), "{name}");
        }
    }
}
