//! The response map: the real-time representation of a term pack that the
//! player (`sunbeam-play`) and engines read (docs/PACK_FORMAT.md "Response map").
//!
//! It stores, after the spectral integral,
//! `T(u, v, w) = sum_l R(u, v, w, l) S(l) cmf(l) / sum_l S(l) ybar(l)` (XYZ,
//! without the gain `G`, which a shader computes per light; `R` the
//! reflectance shading uses, `sunbeam_pack::Pack::shading_reflectance`: for
//! the window model `R_U`, with the window's exact grazing term of
//! PHYSICS.md 2b) on the polar grid of
//! [`grid`], as one RGBA16F 3D texture (XYZ in RGB). A shader then reads it with
//! one trilinear sample per light (more when a pixel's footprint spans several
//! texels), times `G`. It is built once, offline, by `sunbeam-pack --response`
//! ([`point::build`]); the player only loads it.
//!
//! Files: KTX2 (a 3D texture, `VK_FORMAT_R16G16B16A16_SFLOAT`, the [`Info`] JSON
//! under the key `sunbeam.response`), see [`ktx2`]; an OpenEXR atlas of the same
//! texels for DCC tools, see [`exr`].

pub mod build;
pub mod cells;
pub mod cells_file;
pub mod energy;
pub mod env;
pub mod env_file;
pub mod exr;
pub mod grid;
pub mod hotspots;
pub mod ktx2;
pub mod nvr;
pub mod point;
pub mod proposal;
pub mod quadrature;

pub use build::Options;
pub use env::{build_env, EnvResponse};
pub use grid::Grid;
pub use point::build;
pub use proposal::Proposal;

use serde::{Deserialize, Serialize};
use sunbeam_common::{Error, Result};
use sunbeam_pack::Manifest;

/// `Info::format` of every response map.
pub const FORMAT: &str = "sunbeam-response";
/// Format version.
pub const VERSION: u32 = 1;
/// Key of the info JSON in the KTX2 key/value data.
pub const INFO_KEY: &str = "sunbeam.response";

/// What a response map holds (JSON in the file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Info {
    /// Always "sunbeam-response".
    pub format: String,
    pub version: u32,
    pub generator: String,
    pub grid: Grid,
    /// Wavelength samples of the colour integral (midpoints of equal intervals).
    pub lambda_samples: usize,
    pub lambda_range_nm: [u32; 2],
    /// What the texels are (a sentence).
    pub quantity: String,
    /// The manifest of the pack it was built from.
    pub pack: Manifest,
    /// The energy bound's tables for the default skin ([`energy`]; written
    /// by `sunbeam-pack --response`; maps without it build theirs on load).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub energy: Option<energy::EnergyInfo>,
}

/// Where the map of a pack lives: `dir/NAME.response.ktx2` for `dir/NAME.ext`
/// (what `sunbeam-pack --response` writes and the player looks for).
pub fn sidecar_path(pack: &std::path::Path) -> std::path::PathBuf {
    beside(pack, "response.ktx2")
}

/// `dir/NAME.SUFFIX` for a pack `dir/NAME.ext`: the files `sunbeam-pack
/// --response` writes beside a pack.
pub(crate) fn beside(pack: &std::path::Path, suffix: &str) -> std::path::PathBuf {
    let stem = pack
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    pack.with_file_name(format!("{stem}.{suffix}"))
}

/// A response map in memory: `data` holds f16 bits, RGBA, texel
/// `(i, j, k)` (angle, radius, s) at `4 * ((k * n_rho + j) * n_theta + i)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Response {
    pub info: Info,
    pub data: Vec<u16>,
}

impl Response {
    /// Check sizes and values (after reading a file).
    pub fn validate(&self) -> Result<()> {
        let g = &self.info.grid;
        if self.info.format != FORMAT || self.info.version != VERSION {
            return Err(Error::input(format!(
                "not a {FORMAT} v{VERSION} map (format '{}', version {})",
                self.info.format, self.info.version
            )));
        }
        let sides_ok = [g.n_theta, g.n_rho, g.n_s]
            .iter()
            .all(|n| (2..=4096).contains(n));
        if !(sides_ok && g.r0.is_finite() && g.r0 > 0.0) {
            return Err(Error::input(format!("response grid out of range: {g:?}")));
        }
        if self.data.len() != g.texels() * 4 {
            return Err(Error::input(format!(
                "response data holds {} values, the grid needs {}",
                self.data.len(),
                g.texels() * 4
            )));
        }
        if self
            .data
            .iter()
            .any(|&b| !half::f16::from_bits(b).is_finite())
        {
            return Err(Error::input("response data holds NaN or Inf values"));
        }
        Ok(())
    }

    /// XYZ of texel `(i, j, k)`.
    pub fn texel(&self, i: usize, j: usize, k: usize) -> [f64; 3] {
        [0, 1, 2].map(|c| self.texel_channel(i, j, k, c))
    }

    /// Channel `c` (0, 1, 2: X, Y, Z) of texel `(i, j, k)`.
    pub fn texel_channel(&self, i: usize, j: usize, k: usize, c: usize) -> f64 {
        let g = &self.info.grid;
        half::f16::from_bits(self.data[4 * ((k * g.n_rho + j) * g.n_theta + i) + c]).to_f64()
    }

    /// `T(u, v, w)` (XYZ without `G`) by trilinear interpolation, angle wrapping,
    /// radius and `s` clamped: what a shader's single texture sample returns.
    pub fn lookup(&self, u: f64, v: f64, w: f64) -> [f64; 3] {
        let g = &self.info.grid;
        let Some(c) = g.coords(u, v, w) else {
            return [0.0; 3];
        };
        self.lookup_texel(c)
    }

    /// Trilinear interpolation at continuous texel coordinates (see [`Grid::coords`]).
    pub fn lookup_texel(&self, c: [f64; 3]) -> [f64; 3] {
        self.info.grid.trilinear(c, |i, j, k| self.texel(i, j, k))
    }

    /// Size in bytes of the texel data.
    pub fn byte_len(&self) -> usize {
        self.data.len() * 2
    }
}
