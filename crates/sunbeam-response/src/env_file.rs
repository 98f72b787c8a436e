//! The environment's maps of a pack on disk (docs/PACK_FORMAT.md "Environment
//! maps file"): what `sunbeam-pack --response` writes beside the point map as
//! `NAME.env-response.ktx2`, so that the player opens an environment scene
//! without building [`crate::env::build_env`]'s maps (seconds) at start.
//!
//! The maps of the basis spectra are the same for every sky (`S0, S1, S2`) and
//! for every map (`D65 b_k`), so the file holds both sets, built in one pass
//! over the pack. The sun's map depends on the sky (its spectrum and disc):
//! the file holds it for one sky (`sunbeam-pack --response-sky SCENE.json`),
//! keyed by the bits of `Omega_sun sun(lambda)` at the map's wavelengths, and
//! the player rebuilds the maps in memory (and says so) for another sun.
//!
//! Layout: one KTX2 3D texture, `VK_FORMAT_R16G16B16A16_SFLOAT`, `n_theta x
//! n_rho x (n_s * maps)`: map `m` is depth layers `m n_s .. (m + 1) n_s`, each
//! laid out as a [`Response`]; the [`EnvInfo`] JSON under the key
//! `sunbeam.env-response`.

use crate::build::{self, Options};
use crate::env::{self, EnvResponse};
use crate::grid::Grid;
use crate::{ktx2, Info, Response};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};
use sunbeam_light::environment::{map_basis_at, sky_basis_at};
use sunbeam_light::sky::Sky;
use sunbeam_light::Environment;
use sunbeam_pack::{Manifest, Pack};

/// `EnvInfo::format`.
pub const FORMAT: &str = "sunbeam-env-response";
/// Format version.
pub const VERSION: u32 = 1;
/// Key of the info JSON in the KTX2 key/value data.
pub const INFO_KEY: &str = "sunbeam.env-response";

/// Names (`Info::quantity`'s `B = ...`) of the sky's and a map's basis maps.
const SKY_NAMES: [&str; 3] = ["S0", "S1", "S2"];
const MAP_NAMES: [&str; 3] = ["D65 b_r", "D65 b_g", "D65 b_b"];
/// `Info::quantity`'s `B = ...` of the sun's map.
const SUN_NAME: &str = "the sun's spectral radiance times its solid angle";

/// What the file holds (JSON in the file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnvInfo {
    /// Always "sunbeam-env-response".
    pub format: String,
    pub version: u32,
    pub generator: String,
    /// The grid of every map (the point map's).
    pub grid: Grid,
    pub lambda_samples: usize,
    /// The maps in texture order: `"sky"` (3), `"map"` (3), then `"sun"` (0 or 1).
    pub maps: Vec<MapEntry>,
    /// The sun's key: `(Omega_sun sun(lambda)).to_bits()` at the map's
    /// wavelengths, for the sky the sun's map was built for (None: no sun map).
    pub sun_key: Option<Vec<u64>>,
    /// The manifest of the pack it was built from.
    pub pack: Manifest,
}

/// One map of the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapEntry {
    /// "sky", "map" or "sun".
    pub basis: String,
    /// What the texels are (`Info::quantity` of the map).
    pub quantity: String,
}

/// The file in memory: its description and one [`Response`] per map.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvFile {
    pub info: EnvInfo,
    pub maps: Vec<Response>,
}

/// Where the environment's maps of a pack live: `dir/NAME.env-response.ktx2`
/// for `dir/NAME.ext`.
pub fn sidecar_path(pack: &Path) -> PathBuf {
    crate::beside(pack, "env-response.ktx2")
}

/// The sun's key of `sky` at `lambdas` (None when its sun is down).
fn sun_key(sky: &Sky, lambdas: &[f64]) -> Option<Vec<u64>> {
    sky.sun_is_up().then(|| {
        lambdas
            .iter()
            .map(|&l| (sky.sun_solid_angle() * sky.sun_spectral(l)).to_bits())
            .collect()
    })
}

/// Build every basis map of `pack` (sky and map) and, when `sky`'s sun is up,
/// its sun's map, in one pass over the pack's `R`; on the grid of
/// [`crate::point::build`] for the same options.
pub fn build(pack: &Pack, sky: Option<&Sky>, opts: &Options) -> EnvFile {
    let g = opts
        .grid
        .unwrap_or_else(|| build::auto_grid(pack, opts.budget_bytes));
    let sun = sky.filter(|s| s.sun_is_up());
    let ws = env::weight_sets(
        pack,
        opts.lambda_samples,
        &[&sky_basis_at, &map_basis_at],
        sun,
    );
    let nl = ws.lambdas.len();
    let xyz = build::build_sets(pack, &g, &ws);
    let names = SKY_NAMES
        .iter()
        .map(|n| ("sky", *n))
        .chain(MAP_NAMES.iter().map(|n| ("map", *n)))
        .chain(sun.map(|_| ("sun", SUN_NAME)));
    let mut entries = Vec::new();
    let mut maps = Vec::new();
    for (e, (basis, name)) in xyz.iter().zip(names) {
        let q = env::quantity(pack, name);
        maps.push(build::to_response(pack, g, nl, e, false, &q));
        entries.push(MapEntry {
            basis: basis.to_string(),
            quantity: q,
        });
    }
    EnvFile {
        info: EnvInfo {
            format: FORMAT.to_string(),
            version: VERSION,
            generator: format!("sunbeam-response {}", env!("CARGO_PKG_VERSION")),
            grid: g,
            lambda_samples: nl,
            maps: entries,
            sun_key: sun.and_then(|s| sun_key(s, &ws.lambdas)),
            pack: pack.manifest.clone(),
        },
        maps,
    }
}

impl EnvInfo {
    /// Which maps serve `env` (three basis maps, then the sun's when its sun
    /// is up), or why this file does not: another pack, other wavelength
    /// samples or grid, another sun.
    pub fn select(
        &self,
        manifest: &Manifest,
        env: &Environment,
        opts: &Options,
    ) -> std::result::Result<Vec<usize>, String> {
        if self.pack != *manifest {
            return Err("was built from another pack".into());
        }
        if self.lambda_samples != opts.lambda_samples {
            return Err(format!(
                "has {} wavelength samples, not {}",
                self.lambda_samples, opts.lambda_samples
            ));
        }
        if opts.grid.is_some_and(|g| g != self.grid) {
            return Err("has another grid".into());
        }
        let want = match env {
            Environment::Sky(_) => "sky",
            Environment::Map(_) => "map",
        };
        let maps = &self.maps;
        let of = |b: &'static str| (0..maps.len()).filter(move |&m| maps[m].basis == b);
        let mut picked: Vec<usize> = of(want).collect();
        if picked.len() != 3 {
            return Err(format!("holds no {want} maps"));
        }
        if let Some(sky) = env.sun() {
            let lambdas: Vec<f64> = build::wavelength_weights(opts.lambda_samples)
                .iter()
                .map(|l| l.0)
                .collect();
            if self.sun_key.is_none() || self.sun_key != sun_key(sky, &lambdas) {
                return Err("holds the sun's map of another sky (or none)".into());
            }
            picked.extend(of("sun"));
        }
        Ok(picked)
    }

    /// The [`EnvResponse`] of `env` from the maps [`EnvInfo::select`] picked
    /// (the basis maps only where `needs` asks for them).
    fn assemble(&self, env: &Environment, mut maps: Vec<Response>, needs: Needs) -> EnvResponse {
        let sun = if needs.basis {
            (maps.len() > 3).then(|| maps.remove(3))
        } else {
            maps.pop()
        };
        let proposal = if needs.proposal {
            crate::Proposal::from_maps(self.grid, env::proposal_maps(env, &maps))
        } else {
            crate::Proposal::none(self.grid)
        };
        EnvResponse {
            grid: self.grid,
            basis: maps,
            sun,
            proposal,
        }
    }
}

impl EnvFile {
    /// The maps and proposal of `env` (what [`env::build_env`] builds for the
    /// same pack and options, bit for bit), or why this file does not serve
    /// it ([`EnvInfo::select`]).
    pub fn response_for(
        self,
        manifest: &Manifest,
        env: &Environment,
        opts: &Options,
    ) -> std::result::Result<EnvResponse, String> {
        let picked = self.info.select(manifest, env, opts)?;
        let mut all: Vec<Option<Response>> = self.maps.into_iter().map(Some).collect();
        let maps = picked.iter().filter_map(|&m| all[m].take()).collect();
        Ok(self.info.assemble(env, maps, Needs::ALL))
    }

    /// Check the description against the texels (after reading a file).
    fn validate(&self) -> Result<()> {
        let i = &self.info;
        if i.format != FORMAT || i.version != VERSION {
            return Err(Error::input(format!(
                "not a {FORMAT} v{VERSION} file (format '{}', version {})",
                i.format, i.version
            )));
        }
        let suns = i.maps.iter().filter(|m| m.basis == "sun").count();
        if suns != usize::from(i.sun_key.is_some())
            || i.maps
                .iter()
                .any(|m| !["sky", "map", "sun"].contains(&m.basis.as_str()))
        {
            return Err(Error::input(format!(
                "{INFO_KEY}: maps must be 'sky', 'map' or one 'sun' with a sun key"
            )));
        }
        for m in &self.maps {
            m.validate()?;
        }
        Ok(())
    }
}

/// The [`Info`] of map `e` of a file.
fn map_info(i: &EnvInfo, e: &MapEntry) -> Info {
    Info {
        format: crate::FORMAT.to_string(),
        version: crate::VERSION,
        generator: i.generator.clone(),
        grid: i.grid,
        lambda_samples: i.lambda_samples,
        lambda_range_nm: [
            sunbeam_optics::cie::DEFAULT_RANGE_NM.0,
            sunbeam_optics::cie::DEFAULT_RANGE_NM.1,
        ],
        quantity: e.quantity.clone(),
        energy: None,
        pack: i.pack.clone(),
    }
}

/// Encode as KTX2 bytes (deterministic).
pub fn encode(f: &EnvFile) -> Vec<u8> {
    let g = &f.info.grid;
    let info = serde_json::to_string(&f.info).expect("info serialises");
    let data: Vec<u16> = f.maps.iter().flat_map(|m| m.data.iter().copied()).collect();
    ktx2::encode_texture(
        INFO_KEY,
        &info,
        [g.n_theta, g.n_rho, g.n_s * f.maps.len()],
        &data,
    )
}

/// Decode KTX2 bytes (every size checked before use).
pub fn decode(bytes: &[u8]) -> Result<EnvFile> {
    let (text, [w, h, d], raw) = ktx2::decode_texture(bytes, INFO_KEY)?;
    let info: EnvInfo = serde_json::from_str(&text)
        .map_err(|e| Error::input(format!("{INFO_KEY} JSON is invalid: {e}")))?;
    check_layout(&info, [w, h, d])?;
    let n = info.maps.len();
    let per = raw.len() / n;
    let maps = info
        .maps
        .iter()
        .enumerate()
        .map(|(m, e)| Response {
            info: map_info(&info, e),
            data: ktx2::halves(&raw[m * per..(m + 1) * per]),
        })
        .collect();
    let f = EnvFile { info, maps };
    f.validate()?;
    Ok(f)
}

/// Only the description, from the file's head (the texels are not read).
pub fn read_info(path: &Path) -> Result<EnvInfo> {
    let text = ktx2::read_entry(path, INFO_KEY)?;
    serde_json::from_str(&text).map_err(|e| {
        Error::input(format!("{INFO_KEY} JSON is invalid: {e}")).context(path.display().to_string())
    })
}

/// What a reader of the file draws with: the basis maps (Monte Carlo, the
/// hot spots, clustering the cells) and the proposal built from them (Monte
/// Carlo only). The sun's map, when the sky has one, is always read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Needs {
    pub basis: bool,
    pub proposal: bool,
}

impl Needs {
    /// Everything: what [`env::build_env`] builds.
    pub const ALL: Needs = Needs {
        basis: true,
        proposal: true,
    };
}

/// The maps of `env` from the file at `path`, reading only the maps it needs
/// (the head first, then those maps' texels), or why the file does not serve
/// `env` (the outer error: the file cannot be read, or is not a valid file;
/// its message names it).
pub fn read_for(
    path: &Path,
    manifest: &Manifest,
    env: &Environment,
    opts: &Options,
) -> Result<std::result::Result<EnvResponse, String>> {
    read_needed(path, manifest, env, opts, Needs::ALL)
}

/// [`read_for`] reading only what `needs` asks for: without the basis maps,
/// the sun's map alone (an [`EnvResponse`] with no `basis`); without the
/// proposal, [`crate::Proposal::none`].
pub fn read_needed(
    path: &Path,
    manifest: &Manifest,
    env: &Environment,
    opts: &Options,
    needs: Needs,
) -> Result<std::result::Result<EnvResponse, String>> {
    use std::io::{Read, Seek, SeekFrom};
    let ctx = |e: Error| e.context(path.display().to_string());
    let (text, [w, h, d], lv_off) = ktx2::read_head_layout(path, INFO_KEY)?;
    let info: EnvInfo = serde_json::from_str(&text)
        .map_err(|e| ctx(Error::input(format!("{INFO_KEY} JSON is invalid: {e}"))))?;
    check_layout(&info, [w, h, d]).map_err(ctx)?;
    let mut picked = match info.select(manifest, env, opts) {
        Ok(p) => p,
        Err(why) => return Ok(Err(why)),
    };
    if !needs.basis {
        picked.drain(..3);
    }
    let needs = Needs {
        proposal: needs.proposal && needs.basis,
        ..needs
    };
    let per = info.grid.texels() * 8;
    let err = |e: std::io::Error| Error::input_file(path, format!("cannot read: {e}"));
    let mut f = std::fs::File::open(path).map_err(err)?;
    let mut raw = vec![0u8; per];
    let mut maps = Vec::with_capacity(picked.len());
    for &m in &picked {
        f.seek(SeekFrom::Start(lv_off + (m * per) as u64))
            .map_err(err)?;
        f.read_exact(&mut raw).map_err(err)?;
        let r = Response {
            info: map_info(&info, &info.maps[m]),
            data: ktx2::halves(&raw),
        };
        r.validate().map_err(ctx)?;
        maps.push(r);
    }
    Ok(Ok(info.assemble(env, maps, needs)))
}

/// The texture `[w, h, d]` holds `info.maps` on `info.grid`.
fn check_layout(info: &EnvInfo, [w, h, d]: [usize; 3]) -> Result<()> {
    let g = &info.grid;
    let n = info.maps.len();
    if n == 0 || (g.n_theta, g.n_rho, g.n_s.checked_mul(n)) != (w, h, Some(d)) {
        return Err(Error::input(format!(
            "{INFO_KEY}: {n} maps on a {}x{}x{} grid do not fill the texture {w}x{h}x{d}",
            g.n_theta, g.n_rho, g.n_s
        )));
    }
    Ok(())
}

/// Read a file (errors name it).
pub fn read(path: &Path) -> Result<EnvFile> {
    let bytes = std::fs::read(path).map_err(|e| Error::input_file(path, e))?;
    decode(&bytes).map_err(|e| e.context(path.display().to_string()))
}

/// Write atomically.
pub fn write(f: &EnvFile, path: &Path) -> Result<()> {
    sunbeam_common::output::write_atomic(path, &encode(f))
}
