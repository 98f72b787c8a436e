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

use crate::cells::{gpu_stride, Cells, GpuCells, GPU_HEADER, GPU_NONE};
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
/// Format version: 2 added each node's `width`, 3 laid each node out in
/// fours of floats ([`GPU_HEADER`] 32, [`GPU_LAYER`](crate::cells::GPU_LAYER) 12). A file of an
/// earlier version does not serve (the player clusters instead and says
/// so), it is not damaged.
pub const VERSION: u32 = 3;
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

impl CellsInfo {
    /// The set of `basis` for `(cells, depth)` if the file was built from
    /// `manifest` on `grid` with `lambda_samples`, or why it does not serve
    /// them.
    pub fn select(
        &self,
        manifest: &Manifest,
        grid: &Grid,
        lambda_samples: usize,
        basis: &str,
        (cells, depth): (usize, usize),
    ) -> std::result::Result<&CellSet, String> {
        if self.pack != *manifest {
            return Err("was built from another pack".into());
        }
        if self.lambda_samples != lambda_samples || self.grid != *grid {
            return Err("was built for other environment maps (grid or wavelength samples)".into());
        }
        self.sets
            .iter()
            .find(|s| s.basis == basis && s.cells == cells && s.depth == depth)
            .ok_or_else(|| {
                let held: Vec<String> = self
                    .sets
                    .iter()
                    .filter(|s| s.basis == basis)
                    .map(|s| s.cells.to_string())
                    .collect();
                format!(
                    "holds {basis} cells for --env-cells {} only, not {cells} (write them with \
                     sunbeam-pack --response-cells {cells})",
                    if held.is_empty() {
                        "none".to_string()
                    } else {
                        held.join(", ")
                    }
                )
            })
    }

    /// Floats per node.
    fn stride(&self) -> usize {
        gpu_stride(self.grid.n_s)
    }

    /// Check the description against a texture of `texels`: every set
    /// inside it, its length that of its nodes.
    fn check(&self, texels: usize) -> Result<()> {
        if self.format != FORMAT || self.version != VERSION {
            return Err(Error::input(format!(
                "not a {FORMAT} v{VERSION} file (format '{}', version {})",
                self.format, self.version
            )));
        }
        if self.header != GPU_HEADER {
            return Err(Error::input(format!(
                "{INFO_KEY}: header {} is not {GPU_HEADER}",
                self.header
            )));
        }
        let stride = self.stride();
        for (n, s) in self.sets.iter().enumerate() {
            let bad = |why: String| Err(Error::input(format!("{INFO_KEY}: sets[{n}] {why}")));
            if s.basis != "sky" && s.basis != "map" {
                return bad("basis must be 'sky' or 'map'".into());
            }
            if s.n_top > s.nodes || s.nodes.checked_mul(stride) != Some(s.len) {
                return bad(format!(
                    "has {} floats for {} nodes of {stride} ({} top cells)",
                    s.len, s.nodes, s.n_top
                ));
            }
            let end = s.row.checked_mul(WIDTH).and_then(|a| a.checked_add(s.len));
            if end.is_none_or(|e| e > texels) {
                return bad("lies outside the texture".into());
            }
        }
        Ok(())
    }
}

impl CellSet {
    /// The set's floats from its texels (`stride` floats per node), every
    /// link to a node of its own.
    fn cells(&self, stride: usize, texels: &[u32]) -> Result<GpuCells> {
        for node in texels.chunks_exact(stride) {
            for link in [node[3], node[4]] {
                if link != GPU_NONE && link as usize >= self.nodes {
                    return Err(Error::input(format!(
                        "{INFO_KEY}: a {} set's node links to node {link} of {}",
                        self.basis, self.nodes
                    )));
                }
            }
        }
        Ok(GpuCells {
            n_top: self.n_top,
            nodes: self.nodes,
            data: texels.iter().map(|&b| f32::from_bits(b)).collect(),
        })
    }
}

impl CellsFile {
    /// The cells of `basis` for `(cells, depth)` if the file serves them
    /// ([`CellsInfo::select`]), or why not.
    pub fn get(
        &self,
        manifest: &Manifest,
        grid: &Grid,
        lambda_samples: usize,
        basis: &str,
        cells: (usize, usize),
    ) -> std::result::Result<GpuCells, String> {
        let s = self
            .info
            .select(manifest, grid, lambda_samples, basis, cells)?;
        let at = s.row * WIDTH;
        s.cells(self.info.stride(), &self.bits[at..at + s.len])
            .map_err(|e| e.to_string())
    }

    /// Check the description against the texels (after reading a file).
    fn validate(&self) -> Result<()> {
        self.info.check(self.bits.len())?;
        for s in &self.info.sets {
            let at = s.row * WIDTH;
            s.cells(self.info.stride(), &self.bits[at..at + s.len])?;
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

/// The cells of `basis` for `cells` = (top cut, levels) from the file at
/// `path` for maps of `manifest`'s pack on `grid` with `lambda_samples`,
/// reading its head and that set's texels only, or why the file does not
/// serve them (the outer error: the file cannot be read or is not a valid
/// file; its message names it).
pub fn read_set(
    path: &Path,
    manifest: &Manifest,
    grid: &Grid,
    lambda_samples: usize,
    basis: &str,
    cells: (usize, usize),
) -> Result<std::result::Result<GpuCells, String>> {
    use std::io::{Read, Seek, SeekFrom};
    let ctx = |e: Error| e.context(path.display().to_string());
    let (text, [w, h, _], lv_off) = ktx2::read_head_as(path, INFO_KEY, ktx2::VK_R32_UINT, 4)?;
    let info: CellsInfo = serde_json::from_str(&text)
        .map_err(|e| ctx(Error::input(format!("{INFO_KEY} JSON is invalid: {e}"))))?;
    if w != WIDTH {
        return Err(ctx(Error::input(format!(
            "{INFO_KEY}: the texture is {w} x {h}, not {WIDTH} wide"
        ))));
    }
    if info.format == FORMAT && info.version < VERSION {
        return Ok(Err(format!(
            "holds cells of an earlier layout (version {}, this reader's {VERSION}: rewrite it with sunbeam-pack --response)",
            info.version
        )));
    }
    info.check(w * h.max(1)).map_err(ctx)?;
    let s = match info.select(manifest, grid, lambda_samples, basis, cells) {
        Ok(s) => s,
        Err(why) => return Ok(Err(why)),
    };
    let err = |e: std::io::Error| Error::input_file(path, format!("cannot read: {e}"));
    let mut f = std::fs::File::open(path).map_err(err)?;
    f.seek(SeekFrom::Start(lv_off + (s.row * WIDTH * 4) as u64))
        .map_err(err)?;
    let mut raw = vec![0u8; s.len * 4];
    f.read_exact(&mut raw).map_err(err)?;
    let texels: Vec<u32> = raw
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    Ok(Ok(s.cells(info.stride(), &texels).map_err(ctx)?))
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
