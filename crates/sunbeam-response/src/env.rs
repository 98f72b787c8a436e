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
//! response map's polar grid (`R` is what shading uses: `R_U` with the
//! window's grazing term for the window model, PHYSICS.md 2b; `G` the mesh's
//! skin's, times its masking, per direction). The integral over `(u, v)` is left to Monte
//! Carlo with a proposal that follows the maps' energy ([`Proposal`]). The sun
//! (sky only) is outside the basis: a fourth map `E_sun` with `B = sun_spectral`
//! and a sample on its disc per estimate.

use crate::build::{self, Options};
use crate::grid::Grid;
use crate::Response;
use sunbeam_light::sky::Sky;
use sunbeam_light::Environment;
use sunbeam_optics::masking::Masking;
use sunbeam_optics::{cie, colour, gain};
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
    /// `Omega_sun E_sun` for a sky with the sun up: the map of the sun's
    /// spectrum times the disc's solid angle (the sun's radiance, ~1e5 scene
    /// units, would overflow f16; times `Omega` it is an irradiance, ~1). A
    /// sun sample adds `G(wi, wr) * texel` at a point of the disc.
    pub sun: Option<Response>,
    /// The proposal over `(u, v)` built from the maps' luminance.
    pub proposal: Proposal,
}

/// Build the extended-light maps of `pack` under `env` in one pass over the
/// pack's `R` (the expensive part, shared by all the weight sets), on the grid
/// `opts.grid` or the one [`build::auto_grid`] picks under `opts.budget_bytes`
/// (the same grid as the point map's).
pub fn build_env(pack: &Pack, env: &Environment, opts: &Options) -> EnvResponse {
    let g = opts
        .grid
        .unwrap_or_else(|| build::auto_grid(pack, opts.budget_bytes));
    let ws = env_weights(pack, env, opts.lambda_samples);
    let nl = ws.lambdas.len();
    let mut xyz = build::build_sets(pack, &g, &ws);
    let sun = env.sun().map(|_| {
        let e = xyz.pop().expect("the sun's set");
        build::to_response(
            pack,
            g,
            nl,
            &e,
            false,
            &quantity(pack, "the sun's spectral radiance times its solid angle"),
        )
    });
    let names = match env {
        Environment::Sky(_) => ["S0", "S1", "S2"],
        Environment::Map(_) => ["D65 b_r", "D65 b_g", "D65 b_b"],
    };
    let basis: Vec<Response> = xyz
        .iter()
        .zip(names)
        .map(|(e, n)| build::to_response(pack, g, nl, e, false, &quantity(pack, n)))
        .collect();
    let proposal = Proposal::from_maps(g, proposal_maps(env, &basis));
    EnvResponse {
        grid: g,
        basis,
        sun,
        proposal,
    }
}

/// `Info::quantity` of an extended-light map of `pack` for basis spectrum `b`.
pub(crate) fn quantity(pack: &Pack, b: &str) -> String {
    format!(
        "XYZ without G: sum_l {}(u, v, w, l) (A / l^2) B(l) cmf(l) / sum_l D65(l) ybar(l), B = {b}",
        build::reflectance_name(pack)
    )
}

/// The maps whose luminance the proposal follows: `E_0` for the sky (`S0` is
/// close to the mean daylight), `E_0 + E_1 + E_2` for a map (D65).
pub(crate) fn proposal_maps<'a>(env: &Environment, basis: &'a [Response]) -> Vec<&'a Response> {
    match env {
        Environment::Sky(_) => vec![&basis[0]],
        Environment::Map(_) => basis.iter().collect(),
    }
}

/// The pack's coherent area `A` (m^2), as the reference's
/// `LobeSampler::area_m2`: window `(sum g)^2 / sum g^2 dx dy`, tiled
/// `1 / (2 pi sigma_f^2)` (docs/LIGHTING.md "The factor").
pub fn coherent_area_m2(pack: &Pack) -> f64 {
    pack.manifest.coherent_area_m2()
}

/// The weight sets of the extended-light maps at `n` midpoint wavelengths:
/// `A / l^2 B_k(l) cmf(l) / sum_l D65(l) ybar(l)` for the three basis spectra,
/// then the sun's spectrum times its disc's solid angle when the sun is up. The normalisation is the same
/// discrete sum as the point map's, so `B = D65` integrates to `Y = 1` exactly
/// (Parseval) over the same samples.
pub fn env_weights(pack: &Pack, env: &Environment, n: usize) -> build::WeightSets {
    weight_sets(pack, n, &[&|l| env.basis_at(l)], env.sun())
}

/// The weight sets of [`env_weights`] for several bases at once (three sets
/// each, in order), then the sun's set when `sun` is given: what
/// `sunbeam-pack --response` builds in one pass for every sky and every map
/// (written and read by the `env_file` module).
pub fn weight_sets(
    pack: &Pack,
    n: usize,
    bases: &[&dyn Fn(f64) -> [f64; 3]],
    sun: Option<&Sky>,
) -> build::WeightSets {
    let a = coherent_area_m2(pack);
    let lw = build::wavelength_weights(n);
    let lambdas: Vec<f64> = lw.iter().map(|l| l.0).collect();
    let norm: f64 = lambdas
        .iter()
        .map(|&l| cie::d65_at(l) * cie::cmf_at(l)[1])
        .sum();
    let weight = |l: f64, b: f64| {
        let f = a / (l * l) * b / norm;
        cie::cmf_at(l).map(|c| c * f)
    };
    let mut sets: Vec<Vec<[f64; 3]>> = bases
        .iter()
        .flat_map(|basis| {
            let lambdas = &lambdas;
            (0..3).map(move |k| lambdas.iter().map(|&l| weight(l, basis(l)[k])).collect())
        })
        .collect();
    if let Some(sky) = sun {
        sets.push(sun_weights(&lambdas, sky, &weight));
    }
    build::WeightSets { lambdas, sets }
}

/// The sun's weight set: `weight(l, Omega_sun sun(l))` at every wavelength.
fn sun_weights(lambdas: &[f64], sky: &Sky, weight: &dyn Fn(f64, f64) -> [f64; 3]) -> Vec<[f64; 3]> {
    lambdas
        .iter()
        .map(|&l| weight(l, sky.sun_solid_angle() * sky.sun_spectral(l)))
        .collect()
}

impl EnvResponse {
    /// CPU twin of the player's estimator: one sample of the diffraction part
    /// (linear sRGB) at local view `wr_l` (unit, z > 0), with `frame` turning
    /// local `wi` to world for the coefficients, for a mesh whose skin is
    /// `skin` with `masking` on its `G` (every direction's gain is
    /// `masking.gain(wi, wr, skin)`, as the shader's). Uniforms: `u[0..3]` the
    /// proposal's descent and position, `u[3..5]` the sun's disc. Its
    /// expectation is the reference's (`sunbeam_raster::environment`) specular
    /// part for the same pack, environment, skin and masking.
    pub fn sample(
        &self,
        env: &Environment,
        frame: Frame,
        wr_l: [f64; 3],
        masking: Masking,
        skin: gain::Material,
        u: [f64; 5],
    ) -> [f64; 3] {
        let (t, b, n) = frame;
        let world = |d: [f64; 3]| [0, 1, 2].map(|k| d[0] * t[k] + d[1] * b[k] + d[2] * n[k]);
        let mut xyz = [0.0; 3];
        if wr_l[2].is_nan() || wr_l[2] <= 0.0 {
            return xyz;
        }
        // The sky and the map (everything but the sun): one sample, from the
        // proposal or (with probability DEFENSIVE) uniform over the
        // hemisphere, weighed by the mixture's density (one-sample MIS).
        if let Some((uv, pdf)) = self.draw(wr_l, skin, [u[0], u[1], u[2]]) {
            let (wx, wy) = (-uv[0] - wr_l[0], -uv[1] - wr_l[1]);
            let r2 = wx * wx + wy * wy;
            if r2 < 1.0 && pdf > 0.0 {
                let wi = [wx, wy, (1.0 - r2).sqrt()];
                let w = -(wi[2] + wr_l[2]);
                let c = env.coefficients(world(wi));
                let f = masking.gain(wi, wr_l, skin) / (wi[2] * pdf);
                for (ck, ek) in c.iter().zip(&self.basis) {
                    let e = ek.lookup(uv[0], uv[1], w);
                    for a in 0..3 {
                        xyz[a] += f * ck * e[a];
                    }
                }
            }
        }
        // The sun: a point of its disc; d(u, v) = cos(theta_i) dw cancels 1 / cos.
        if let (Some(sky), Some(e_sun)) = (env.sun(), &self.sun) {
            if let Some((d, _)) = sky.sample_sun(u[3], u[4]) {
                let dot = |a: [f64; 3]| a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
                let wi = [dot(t), dot(b), dot(n)];
                if wi[2] > 0.0 {
                    let (uu, vv, w) = (-wi[0] - wr_l[0], -wi[1] - wr_l[1], -wi[2] - wr_l[2]);
                    // The map holds Omega_sun E_sun.
                    let f = masking.gain(wi, wr_l, skin);
                    let e = e_sun.lookup(uu, vv, w);
                    for a in 0..3 {
                        xyz[a] += f * e[a];
                    }
                }
            }
        }
        colour::xyz_to_linear_srgb(xyz)
    }
}

/// Share of the samples drawn uniformly over the hemisphere instead of from
/// the proposal. The integrand carries `1 / cos(theta_i)` (from `d(u, v) =
/// cos(theta_i) dw`), which the proposal only follows at its cells' sample
/// points; near the horizon a sample's weight was unbounded. With this share
/// of uniform directions, whose density per `(u, v)` is `1 / (2 pi
/// cos(theta_i))`, the weight is at most `2 pi G E / DEFENSIVE`: the relative
/// standard deviation of one sample fell from 1.3-5 to 0.8-0.9 on the ridge
/// patch of the tests (docs/PACK_FORMAT.md "Extended-light maps").
pub const DEFENSIVE: f64 = 0.25;

impl EnvResponse {
    /// One `(u, v)` for local view `wr` from three uniforms, with the density
    /// per unit `(u, v)` of the mixture (`DEFENSIVE` uniform over the
    /// hemisphere, the rest from the proposal weighed with `skin`'s gain):
    /// `u[0] < DEFENSIVE` picks the
    /// hemisphere (`cos(theta_i) = u[1]`, azimuth `2 pi u[2]`), else the
    /// proposal with `u[0]` rescaled.
    pub fn draw(&self, wr: [f64; 3], skin: gain::Material, u: [f64; 3]) -> Option<([f64; 2], f64)> {
        let (uv, p) = if u[0] < DEFENSIVE {
            let z = u[1];
            let (s, c) = (2.0 * std::f64::consts::PI * u[2]).sin_cos();
            let sr = (1.0 - z * z).max(0.0).sqrt();
            let uv = [-sr * c - wr[0], -sr * s - wr[1]];
            (uv, self.density(wr, skin, uv))
        } else {
            // The proposal's density comes with its draw: no second descent.
            let u0 = ((u[0] - DEFENSIVE) / (1.0 - DEFENSIVE)).min(1.0 - f64::EPSILON);
            let (uv, p) = self.proposal.sample(wr, skin, [u0, u[1], u[2]])?;
            (
                uv,
                DEFENSIVE * hemisphere_density(wr, uv) + (1.0 - DEFENSIVE) * p,
            )
        };
        (p > 0.0).then_some((uv, p))
    }

    /// Density per unit `(u, v)` with which [`EnvResponse::draw`] draws `uv`.
    pub fn density(&self, wr: [f64; 3], skin: gain::Material, uv: [f64; 2]) -> f64 {
        DEFENSIVE * hemisphere_density(wr, uv) + (1.0 - DEFENSIVE) * self.proposal.pdf(wr, skin, uv)
    }
}

/// Density per unit `(u, v)` of a direction uniform over the hemisphere:
/// `1 / (2 pi cos(theta_i))` inside the view's disc, 0 outside.
fn hemisphere_density(wr: [f64; 3], uv: [f64; 2]) -> f64 {
    let (wx, wy) = (-uv[0] - wr[0], -uv[1] - wr[1]);
    let r2 = wx * wx + wy * wy;
    if r2 < 1.0 {
        1.0 / (2.0 * std::f64::consts::PI * (1.0 - r2).sqrt())
    } else {
        0.0
    }
}
