//! Extended light (sky, sun, environment maps) for the player: per pack and
//! environment, three **extended-light response maps** `E_k` and a
//! **proposal** for sampling `(u, v)`, plus the CPU twin of the player's
//! estimator (docs/PACK_FORMAT.md "Extended-light maps", docs/LIGHTING.md).
//!
//! Why maps per basis: the radiance of the environment without the sun is
//! exactly `L(wi, l) = sum_k c_k(wi) B_k(l)` (3 basis spectra,
//! `sunbeam_light::Environment::basis_at`), so the spectral integral of the
//! reference,
//!
//! `XYZ(wr) = int d(u,v) [G / cos(theta_i)] sum_l L(wi, l) R(u, v, w, l) (A / l^2) cmf(l) dl / sum_l D65 ybar dl`,
//!
//! becomes `int d(u,v) [G / cos(theta_i)] sum_k c_k(wi) E_k(u, v, w)` with
//! `E_k = sum_l R (A / l^2) B_k cmf dl / sum_l D65 ybar dl` precomputed on the
//! response map's polar grid. The integral over `(u, v)` is left to Monte
//! Carlo with a proposal that follows the maps' energy ([`Proposal`]). The sun
//! (sky only) is outside the basis: a fourth map `E_sun` with `B = sun_spectral`
//! and a sample on its disc per estimate.

use crate::build::{self, Options};
use crate::grid::Grid;
use crate::Response;
use sunbeam_light::Environment;
use sunbeam_pack::Pack;

pub use crate::proposal::Proposal;

/// A local frame `(t, b, n)` (world vectors), as `sunbeam_raster::environment::Frame`.
pub type Frame = ([f64; 3], [f64; 3], [f64; 3]);

/// The maps and the proposal for one pack under one environment.
#[derive(Debug, Clone)]
pub struct EnvResponse {
    /// The grid of every map (the point map's grid for the same options).
    pub grid: Grid,
    /// `E_0..E_2`, one per basis spectrum (`Info::quantity` says which). Same
    /// texel layout as the point-light map; XYZ in RGB, A = 0.
    pub basis: Vec<Response>,
    /// `E_sun` for a sky with the sun up.
    pub sun: Option<Response>,
    /// The proposal over `(u, v)` built from the maps' luminance.
    pub proposal: Proposal,
}

/// Build the extended-light maps of `pack` under `env` in one pass over the
/// pack's `R` (the expensive part, shared by all the weight sets), on the grid
/// `opts.grid` or the one [`build::auto_grid`] picks under `opts.budget_bytes`
/// (the same grid as the point map's).
pub fn build_env(pack: &Pack, env: &Environment, opts: &Options) -> EnvResponse {
    let _ = (pack, env, opts, build::DEFAULT_LAMBDA_SAMPLES);
    unimplemented!("build_env: step 3")
}

impl EnvResponse {
    /// CPU twin of the player's estimator: one sample of the diffraction part
    /// (linear sRGB) at local view `wr_l` (unit, z > 0), with `frame` turning
    /// local `wi` to world for the coefficients. Uniforms: `u[0..3]` the
    /// proposal's descent and position, `u[3..5]` the sun's disc. Its
    /// expectation is the reference's (`sunbeam_raster::environment`) specular
    /// part for the same pack and environment.
    pub fn sample(&self, env: &Environment, frame: Frame, wr_l: [f64; 3], u: [f64; 5]) -> [f64; 3] {
        let _ = (env, frame, wr_l, u);
        unimplemented!("EnvResponse::sample: step 5")
    }
}
