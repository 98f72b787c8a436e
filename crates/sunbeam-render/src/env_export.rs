//! `sunbeam-play SCENE.json --export-environment DIR`: the files an engine
//! binds to light the exported material with the scene's environment
//! (shaders/export_env.wgsl, docs/ENGINES.md "Environment"): the same data
//! the player's first-frame cells read (crate::env), written once instead of
//! rebuilt in every engine:
//!
//! - `chain.ktx2`: the prefiltered coefficient table (sunbeam_light::prefilter),
//!   2D RGBA16F, every level of the chain (level m: `w / 2^m x h / 2^m`, down
//!   to 2 x 1);
//! - `irradiance-skin.ktx2`, `irradiance.ktx2`: the irradiance per normal
//!   without the sun (sunbeam_light::irradiance), transmitted through the
//!   skin of the first mesh with a pack and plain, 2D RGBA16F;
//! - `cells-I.ktx2` for each mesh I with a pack (one per distinct pack, the
//!   others naming the same file): Cells::gpu_data as 2D R32G32B32A32_UINT
//!   (the floats' bits, one of its fours a texel), [`CELLS_WIDTH`] texels
//!   wide; with the sky's sun up, `sun-I.ktx2`: the
//!   pack's `Omega_sun E_sun` map (a response map, RGBA16F 3D);
//! - a map's hot spots as lights (sunbeam_light::hotspots, as the player's
//!   `--env-hot-spots`): their taps in `environment.json` (`hot_spots`), the
//!   chain then made from the rest of the map, and for each mesh I the pack's
//!   extended-light maps they are read through, `basis-I-K.ktx2` (K = 0, 1,
//!   2; response maps, RGBA16F 3D);
//! - with hot spots, `table.ktx2`: the whole coefficient table (level 0 of
//!   the chain without them), for a background;
//! - `environment.json`: what the uniforms need (docs/ENGINES.md).
//!
//! f16, as the player uploads them, so an engine reads the player's numbers.
//! Deterministic (the same scene gives the same bytes) and atomic per file.

use crate::renderer::environment;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use sunbeam_common::{Error, Result};
use sunbeam_frame::Prepared;
use sunbeam_optics::colour;
use sunbeam_response::ktx2::{encode_2d, Texture2d};

/// Width of the cells' texture in texels of four words (WebGL2 guarantees
/// 2048).
pub const CELLS_WIDTH: usize = 2048;
/// The KTX2 key of each file's JSON.
pub const KEY: &str = "sunbeam.environment";

fn f16_levels(levels: &[(usize, usize, Vec<f32>)]) -> Vec<(usize, usize, Vec<u16>)> {
    levels
        .iter()
        .map(|(w, h, d)| {
            let bits = d
                .iter()
                .map(|&v| half::f16::from_f32(v.clamp(-65504.0, 65504.0)).to_bits())
                .collect();
            (*w, *h, bits)
        })
        .collect()
}

/// Write the environment's files for `p` into `dir` (created if missing);
/// `cells`: the top cut's cells (none: each pack's own) and the levels below
/// it (as the player's `--env-cells`); `hot_spots`: how a map's hot spots become lights (as the
/// player's `--env-hot-spots`, `--env-hot-threshold`; the chain is then the
/// rest).
/// Returns the files written and notes (maps built).
pub fn export(
    p: &Prepared,
    opts: &sunbeam_response::Options,
    cells: (Option<usize>, usize),
    hot_spots: sunbeam_light::hotspots::SplitOptions,
    dir: &Path,
) -> Result<(Vec<PathBuf>, Vec<String>)> {
    let env = p.environment.clone().ok_or_else(|| {
        Error::usage("--export-environment: the scene has no \"environment\" (docs/SCENE.md)")
    })?;
    std::fs::create_dir_all(dir).map_err(|e| Error::output_file(dir, e))?;
    let mut files = Vec::new();
    let mut notes = Vec::new();
    let mut put = |name: &str, bytes: Vec<u8>| -> Result<String> {
        let path = dir.join(name);
        sunbeam_common::output::write_atomic(&path, &bytes)?;
        files.push(path);
        Ok(name.to_string())
    };
    let (tw, th, table) = env.coefficient_table(crate::env::SKY_TABLE_HEIGHT);
    let phase = env.table_phase();
    let hot = crate::env::HotSpots::split(tw, th, &table, phase, hot_spots);
    // With hot spots the chain is the rest of the map: the whole map (for a
    // background) is then a file of its own.
    let table_file = if hot.taps.is_empty() {
        None
    } else {
        let json = serde_json::json!({"width": tw, "height": th, "phase": phase});
        Some(put(
            "table.ktx2",
            encode_2d(
                KEY,
                &json.to_string(),
                &Texture2d::Rgba16f(&f16_levels(&[(tw, th, table)])),
            ),
        )?)
    };
    let chain = sunbeam_light::prefilter::Prefiltered::new(tw, th, hot.residual).levels;
    let chain_json =
        serde_json::json!({"width": tw, "height": th, "levels": chain.len(), "phase": phase});
    let chain_file = put(
        "chain.ktx2",
        encode_2d(
            KEY,
            &chain_json.to_string(),
            &Texture2d::Rgba16f(&f16_levels(&chain)),
        ),
    )?;
    // The transmitted table for the first skin's index, as the player's.
    let ior = p
        .meshes
        .iter()
        .find(|(_, m)| m.pack.is_some())
        .map_or(sunbeam_optics::gain::Material::default().ior, |(_, m)| {
            m.skin.ior
        });
    let (plain, skin) = sunbeam_light::irradiance::Irradiance::pair(&env, ior);
    let (plain, skin) = (plain.table_rgba(), skin.table_rgba());
    let irr_json = serde_json::json!({"width": skin.0, "height": skin.1, "ior": ior});
    let skin_file = put(
        "irradiance-skin.ktx2",
        encode_2d(
            KEY,
            &irr_json.to_string(),
            &Texture2d::Rgba16f(&f16_levels(&[skin])),
        ),
    )?;
    let plain_file = put(
        "irradiance.ktx2",
        encode_2d(
            KEY,
            &irr_json.to_string(),
            &Texture2d::Rgba16f(&f16_levels(&[plain])),
        ),
    )?;
    // The cells, once per distinct pack.
    let mut meshes = Vec::new();
    let mut done: Vec<(*const sunbeam_pack::Pack, serde_json::Value)> = Vec::new();
    for (mi, (_, m)) in p.meshes.iter().enumerate() {
        let Some(pack) = &m.pack else { continue };
        let key = Arc::as_ptr(pack);
        if let Some((_, v)) = done.iter().find(|(k, _)| *k == key) {
            let mut v = v.clone();
            v["mesh"] = mi.into();
            meshes.push(v);
            continue;
        }
        let path = p.scene.meshes.get(mi).and_then(|s| s.pack.as_deref());
        let er = environment::response(
            &env,
            pack,
            path,
            mi,
            opts,
            sunbeam_response::env_file::Needs::ALL,
            &mut notes,
        )?;
        let cells = crate::env::pack_cells(cells, pack);
        let c = environment::first_frame_cells(&er, &env, pack, path, mi, cells, &mut notes)?;
        let mut bits: Vec<u32> = c.data.iter().map(|v| v.to_bits()).collect();
        // one four a texel, one fetch in the shader (shaders/export_env.wgsl
        // `env_cell_v4`): SwiftShader's frame took 0.77-0.83x the time of
        // four R32_UINT fetches (docs/ENGINES.md "Environment")
        let fours = bits.len().div_ceil(4);
        let w = CELLS_WIDTH.min(fours.max(1));
        let h = fours.div_ceil(w).max(1);
        bits.resize(4 * w * h, 0);
        let info = serde_json::json!({
            "n_top": c.n_top, "n_s": er.grid.n_s, "nodes": c.nodes,
            "header": sunbeam_response::cells::GPU_HEADER, "layer": sunbeam_response::cells::GPU_LAYER,
            "width": w, "height": h,
        });
        let file = put(
            &format!("cells-{mi}.ktx2"),
            encode_2d(KEY, &info.to_string(), &Texture2d::Rgba32u(w, h, &bits)),
        )?;
        let mut v = info;
        v["file"] = file.into();
        // The sky's sun through its own map (the sun's spectrum), as the player's.
        if let Some(sun) = &er.sun {
            let g = &sun.info.grid;
            v["sun"] = put(
                &format!("sun-{mi}.ktx2"),
                sunbeam_response::ktx2::encode(sun),
            )?
            .into();
            v["sun_grid"] = serde_json::json!([g.n_theta, g.n_rho, g.n_s, g.r0]);
        }
        // The basis maps E_k, which the hot spots are read through.
        if !hot.taps.is_empty() {
            let g = &er.basis[0].info.grid;
            let mut names = Vec::new();
            for (k, m) in er.basis.iter().enumerate() {
                names.push(put(
                    &format!("basis-{mi}-{k}.ktx2"),
                    sunbeam_response::ktx2::encode(m),
                )?);
            }
            v["basis"] = names.into();
            v["basis_grid"] = serde_json::json!([g.n_theta, g.n_rho, g.n_s, g.r0]);
        }
        done.push((key, v.clone()));
        v["mesh"] = mi.into();
        meshes.push(v);
    }
    let m = crate::env::basis_to_rgb(&env);
    let sun = env.sun().map(|sky| {
        let omega = sky.sun_solid_angle();
        let rgb = colour::xyz_to_linear_srgb(crate::env::spectrum_xyz(|l| sky.sun_spectral(l)));
        serde_json::json!({
            "direction": sky.sun_direction(),
            "rgb": rgb.map(|c| c * omega),
            "solid_angle": omega,
        })
    });
    let json = serde_json::json!({
        "format": "sunbeam-environment",
        "version": 1,
        "kind": if matches!(*env, sunbeam_light::Environment::Sky(_)) { "sky" } else { "map" },
        "chain": {"file": chain_file, "width": tw, "height": th, "levels": chain.len(), "phase": phase},
        "irradiance": {"skin": skin_file, "plain": plain_file, "ior": ior},
        "basis_to_rgb": m,
        "sun": sun,
        "table": table_file,
        "hot_spots": hot.taps.iter().map(|[d, p]| [d[0], d[1], d[2], p[0], p[1], p[2]]).collect::<Vec<_>>(),
        "meshes": meshes,
    });
    let text = serde_json::to_string_pretty(&json).expect("JSON serialises") + "\n";
    put("environment.json", text.into_bytes())?;
    Ok((files, notes))
}
