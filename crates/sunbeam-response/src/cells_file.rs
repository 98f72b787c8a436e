//! The first-frame cells of a pack on disk (docs/PACK_FORMAT.md "Cells
//! file"): what `sunbeam-pack --response` writes beside the environment's
//! maps as `NAME.env-cells.ktx2`, so that the player's first frame under an
//! environment (and `--export-environment`) does not cluster the maps at
//! every start ([`Cells::build`]: 0.6 s for a 20 um pack on 2 cores, most
//! of an environment scene's start-up before).
//!
//! The cells depend on the basis maps only: the sky's (`S0, S1, S2`) or a
//! map's (`D65 b_k`), never on the sun or the image. So the file holds, for
//! each count the pipeline asked for (`--response-cells`, the player's
//! `--env-cells`), the cells of both bases, and serves every sky and every
//! map. They are [`Cells::gpu_data`] exactly (the bits), so a frame from the
//! file is the frame from a fresh build.
//!
//! Layout: one KTX2 2D texture, `VK_FORMAT_R32_UINT`, [`WIDTH`] texels wide
//! (the engines' `cells-I.ktx2`, docs/ENGINES.md): the sets' floats as bits,
//! one after another, each from the start of a row; the [`CellsInfo`] JSON
//! under the key `sunbeam.env-cells` says where each set lies.

use crate::cells::{Cells, GpuCells, GPU_HEADER, GPU_NONE};
use crate::env_file::EnvFile;
use crate::grid::Grid;
use crate::ktx2;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};
use sunbeam_light::Environment;
use sunbeam_pack::Manifest;

/// `CellsInfo::format`.
pub const FORMAT: &str = "sunbeam-env-cells";
/// Format version.
pub const VERSION: u32 = 1;
/// Key of the info JSON in the KTX2 key/value data.
pub const INFO_KEY: &str = "sunbeam.env-cells";
/// Width of the texture (texels; WebGL2 guarantees 2048).
pub const WIDTH: usize = 2048;

/// What the file holds (JSON in the file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CellsInfo {
    /// Always "sunbeam-env-cells".
    pub format: String,
    pub version: u32,
    pub generator: String,
    /// The grid of the maps the cells were clustered from.
    pub grid: Grid,
    /// Their wavelength samples.
    pub lambda_samples: usize,
    /// Floats per node before its masses ([`GPU_HEADER`]).
    pub header: usize,
    pub sets: Vec<CellSet>,
    /// The manifest of the pack they were built from.
    pub pack: Manifest,
}

/// One set of cells in the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CellSet {
    /// "sky" or "map": the basis maps clustered.
    pub basis: String,
    /// The cells asked for (`--env-cells`) and the levels kept below them.
    pub cells: usize,
    pub depth: usize,
    /// What the clustering made: cells of the top cut (at most `cells`) and
    /// nodes in all.
    pub n_top: usize,
    pub nodes: usize,
    /// The first row of the texture and the floats of the set.
    pub row: usize,
    pub len: usize,
}

/// The file in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct CellsFile {
    pub info: CellsInfo,
    /// The texture's texels (row-major, `WIDTH` per row).
    pub bits: Vec<u32>,
}

/// Where the cells of a pack live: `dir/NAME.env-cells.ktx2` for
/// `dir/NAME.ext`.
pub fn sidecar_path(pack: &Path) -> PathBuf {
    crate::beside(pack, "env-cells.ktx2")
}

/// The basis ("sky" or "map") whose cells shade `env`.
pub fn basis_of(env: &Environment) -> &'static str {
    match env {
        Environment::Sky(_) => "sky",
        Environment::Map(_) => "map",
    }
}

/// Cluster the sky's and the map's basis maps of `env` into cells, for each
/// `(cells, depth)` of `counts` (the player's `--env-cells` and its levels;
/// in any order, repeats once: the file is the same).
pub fn build(env: &EnvFile, counts: &[(usize, usize)]) -> CellsFile {
    let mut counts = counts.to_vec();
    counts.sort_unstable();
    counts.dedup();
    let mut sets = Vec::new();
    let mut bits: Vec<u32> = Vec::new();
    for (cells, depth) in counts {
        for basis in ["sky", "map"] {
            let maps: Vec<crate::Response> = env
                .info
                .maps
                .iter()
                .zip(&env.maps)
                .filter(|(e, _)| e.basis == basis)
                .map(|(_, m)| m.clone())
                .collect();
            if maps.len() != 3 {
                continue;
            }
            let g = Cells::build(&maps, cells, depth).gpu();
            let row = bits.len() / WIDTH;
            sets.push(CellSet {
                basis: basis.to_string(),
                cells,
                depth,
                n_top: g.n_top,
                nodes: g.nodes,
                row,
                len: g.data.len(),
            });
            bits.extend(g.data.iter().map(|v| v.to_bits()));
            bits.resize(bits.len().div_ceil(WIDTH) * WIDTH, 0);
        }
    }
    if bits.is_empty() {
        bits.resize(WIDTH, 0);
    }
    CellsFile {
        info: CellsInfo {
            format: FORMAT.to_string(),
            version: VERSION,
            generator: format!("sunbeam-response {}", env!("CARGO_PKG_VERSION")),
            grid: env.info.grid,
            lambda_samples: env.info.lambda_samples,
            header: GPU_HEADER,
            sets,
            pack: env.info.pack.clone(),
        },
        bits,
    }
}

impl CellsFile {
    /// The cells of `basis` for `(cells, depth)` if the file was built from
    /// `manifest` on `grid` with `lambda_samples`, or why it does not serve
    /// them.
    pub fn get(
        &self,
        manifest: &Manifest,
        grid: &Grid,
        lambda_samples: usize,
        basis: &str,
        (cells, depth): (usize, usize),
    ) -> std::result::Result<GpuCells, String> {
        let i = &self.info;
        if i.pack != *manifest {
            return Err("was built from another pack".into());
        }
        if i.lambda_samples != lambda_samples || i.grid != *grid {
            return Err("was built for other environment maps (grid or wavelength samples)".into());
        }
        let Some(s) = i
            .sets
            .iter()
            .find(|s| s.basis == basis && s.cells == cells && s.depth == depth)
        else {
            let held: Vec<String> = i
                .sets
                .iter()
                .filter(|s| s.basis == basis)
                .map(|s| s.cells.to_string())
                .collect();
            return Err(format!(
                "holds {basis} cells for --env-cells {} only, not {cells} (write them with \
                 sunbeam-pack --response-cells {cells})",
                if held.is_empty() {
                    "none".to_string()
                } else {
                    held.join(", ")
                }
            ));
        };
        let at = s.row * WIDTH;
        Ok(GpuCells {
            n_top: s.n_top,
            nodes: s.nodes,
            data: self.bits[at..at + s.len]
                .iter()
                .map(|&b| f32::from_bits(b))
                .collect(),
        })
    }

    /// Check the description against the texels: every set inside the
    /// texture, its length that of its nodes, its links to nodes of its own.
    fn validate(&self) -> Result<()> {
        let i = &self.info;
        if i.format != FORMAT || i.version != VERSION {
            return Err(Error::input(format!(
                "not a {FORMAT} v{VERSION} file (format '{}', version {})",
                i.format, i.version
            )));
        }
        if i.header != GPU_HEADER {
            return Err(Error::input(format!(
                "{INFO_KEY}: header {} is not {GPU_HEADER}",
                i.header
            )));
        }
        let stride = GPU_HEADER + 9 * i.grid.n_s;
        for (n, s) in i.sets.iter().enumerate() {
            let bad = |why: &str| Err(Error::input(format!("{INFO_KEY}: sets[{n}] {why}")));
            if s.basis != "sky" && s.basis != "map" {
                return bad("basis must be 'sky' or 'map'");
            }
            if s.n_top > s.nodes || s.nodes.checked_mul(stride) != Some(s.len) {
                return bad(&format!(
                    "has {} floats for {} nodes of {stride} ({} top cells)",
                    s.len, s.nodes, s.n_top
                ));
            }
            let at = s.row.checked_mul(WIDTH);
            let Some(data) = at.and_then(|a| self.bits.get(a..a.checked_add(s.len)?)) else {
                return bad("lies outside the texture");
            };
            for node in data.chunks_exact(stride) {
                for link in [node[3], node[4]] {
                    if link != GPU_NONE && link as usize >= s.nodes {
                        return bad(&format!("links to node {link} of {}", s.nodes));
                    }
                }
            }
        }
        Ok(())
    }
}

/// Encode as KTX2 bytes (deterministic).
pub fn encode(f: &CellsFile) -> Vec<u8> {
    let info = serde_json::to_string(&f.info).expect("info serialises");
    ktx2::encode_2d(
        INFO_KEY,
        &info,
        &ktx2::Texture2d::R32u(WIDTH, f.bits.len() / WIDTH, &f.bits),
    )
}

/// Decode KTX2 bytes (every size checked before use).
pub fn decode(bytes: &[u8]) -> Result<CellsFile> {
    let (text, [w, h, _], raw) = ktx2::decode_r32u(bytes, INFO_KEY)?;
    let info: CellsInfo = serde_json::from_str(&text)
        .map_err(|e| Error::input(format!("{INFO_KEY} JSON is invalid: {e}")))?;
    if w != WIDTH || h == 0 {
        return Err(Error::input(format!(
            "{INFO_KEY}: the texture is {w} x {h}, not {WIDTH} wide"
        )));
    }
    let bits = raw
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let f = CellsFile { info, bits };
    f.validate()?;
    Ok(f)
}

/// Read a file (errors name it).
pub fn read(path: &Path) -> Result<CellsFile> {
    let bytes = std::fs::read(path).map_err(|e| Error::input_file(path, e))?;
    decode(&bytes).map_err(|e| e.context(path.display().to_string()))
}

/// Write atomically.
pub fn write(f: &CellsFile, path: &Path) -> Result<()> {
    sunbeam_common::output::write_atomic(path, &encode(f))
}
