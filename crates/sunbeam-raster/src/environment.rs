//! Environment lighting in the reference: the integral over incoming directions
//! by Monte Carlo (docs/LIGHTING.md "The reference's estimator"). Per sub-pixel
//! sample, [`HERO`] wavelengths and up to three directions:
//!
//! - a hero wavelength uniform over 380..780 nm, stratified over the pixel's
//!   samples by the caller, and its rotations by `1 / HERO` of the range (hero
//!   wavelength sampling, Wilkie et al. 2014): every direction is evaluated at
//!   all of them;
//! - one direction from the environment's sampler (sky/sun mixture or the
//!   map's luminance), one from the sun's disc (sky only) and one from the
//!   diffraction lobes ([`LobeSampler`]), combined by multiple importance
//!   sampling with the balance heuristic: each adds
//!   `f L / (p_env + p_sun + p_lobe)`, the lobe density being the mean over
//!   the hero wavelengths; the sun's disc belongs to the sun technique alone
//!   (the other two skip directions in it);
//! - the diffraction term is `XYZ += L(wi, lambda) G R(u, v, w, lambda)
//!   (A / lambda^2) cmf(lambda) / (p_lambda sum D65 ybar)`, `A` the pack's
//!   coherent area (window: `(sum g)^2 / sum g^2 dx dy`, tiled:
//!   `1 / (2 pi sigma_f^2)`), the BRDF of docs/LIGHTING.md; the diffuse part
//!   is `base / pi` times the irradiance, estimated with the environment's
//!   sample only (a white Lambertian under a white furnace of radiance 1 has
//!   radiance 1).
//!
//! Random numbers come from SplitMix64 seeded by (seed, pixel, sample), so a
//! frame depends on `--seed` and `--samples` only, not on the thread count.
//! Besides the wavelengths, the lobe sampler's descent and the environment
//! sampler's first coordinate are stratified over a pixel's samples
//! ([`pixel_uniforms`]); the rest are independent.

pub use crate::lobe_sampler::{LobeQuery, LobeSampler};
use crate::shade::dot;
use std::f64::consts::PI;
use std::sync::Arc;
use sunbeam_common::rng::SplitMix64;
use sunbeam_light::Environment;
use sunbeam_optics::{cie, colour};
use sunbeam_pack::Pack;

/// Wavelength range of the integral (nm).
const RANGE_NM: (u32, u32) = cie::DEFAULT_RANGE_NM;
/// Wavelengths evaluated per direction (hero wavelength sampling, Wilkie et al. 2014).
pub const HERO: usize = 8;
/// The uniform numbers of one sample: the hero wavelength's position, the
/// environment's three, the sun disc's two, the lobe sampler's three (bin, then
/// the offset inside it).
#[derive(Debug, Clone, Copy)]
pub struct Uniforms {
    pub lambda: f64,
    pub env: [f64; 3],
    pub sun: [f64; 2],
    pub lobe: [f64; 3],
}

impl Uniforms {
    /// Independent uniform numbers.
    pub fn random(rng: &mut SplitMix64) -> Uniforms {
        Uniforms {
            lambda: rng.unit(),
            env: [rng.unit(), rng.unit(), rng.unit()],
            sun: [rng.unit(), rng.unit()],
            lobe: [rng.unit(), rng.unit(), rng.unit()],
        }
    }
}

/// The uniform numbers of a pixel's `n` samples under `seed`: the wavelengths
/// stratified (sample `k` in stratum `k` of `n`, shifted per pixel), the
/// lobe sampler's descent (`lobe[0]`) and the environment sampler's first
/// coordinate (`env[1]`) stratified too, each in its own random permutation of the
/// strata (Latin hypercube: each dimension's strata are all hit once,
/// independently of the others); the rest independent, each sample from its own
/// generator ([`EnvShader::rng`]). One uniform drives the whole descent of the
/// lobe sampler, so its strata are strata of the proposal's leaves.
pub fn pixel_uniforms(seed: u64, pixel: u64, n: u64) -> Vec<Uniforms> {
    let mut g = EnvShader::rng(seed, pixel, u64::MAX);
    let offset = g.unit();
    let mut perm = || {
        let mut p: Vec<u64> = (0..n).collect();
        for i in (1..p.len()).rev() {
            let j = ((g.unit() * (i + 1) as f64) as usize).min(i);
            p.swap(i, j);
        }
        p
    };
    let (pl, pe) = (perm(), perm());
    (0..n)
        .map(|k| {
            let mut rng = EnvShader::rng(seed, pixel, k);
            let lambda = (offset + (k as f64 + rng.unit()) / n as f64).fract();
            let mut u = Uniforms {
                lambda,
                ..Uniforms::random(&mut rng)
            };
            u.lobe[0] = (pl[k as usize] as f64 + u.lobe[0]) / n as f64;
            u.env[1] = (pe[k as usize] as f64 + u.env[1]) / n as f64;
            u
        })
        .collect()
}

/// The environment and the lobe samplers of a prepared scene's packs.
pub struct EnvShader {
    pub env: Arc<Environment>,
    /// Per mesh of the scene: its pack's sampler (None without a pack).
    lobes: Vec<Option<LobeSampler>>,
    norm: f64,
}

/// A local frame: tangent, bitangent, normal.
pub type Frame = ([f64; 3], [f64; 3], [f64; 3]);

impl EnvShader {
    pub fn new(env: Arc<Environment>, packs: &[Option<Arc<Pack>>]) -> EnvShader {
        EnvShader {
            env,
            lobes: packs
                .iter()
                .map(|p| {
                    p.as_ref()
                        .filter(|p| p.has_terms())
                        .map(|p| LobeSampler::new(p.clone()))
                })
                .collect(),
            norm: cie::d65_y_norm(RANGE_NM),
        }
    }

    /// The generator of sample `k` of pixel `pixel` under `seed`.
    pub fn rng(seed: u64, pixel: u64, k: u64) -> SplitMix64 {
        let mut h = SplitMix64::new(seed ^ 0x5EED_0000_0000_0000);
        let a = h.next_u64() ^ pixel.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let mut h = SplitMix64::new(a);
        SplitMix64::new(h.next_u64() ^ k.wrapping_mul(0xD1B5_4A32_D192_ED03))
    }

    /// One sample's linear sRGB radiance towards the viewer for mesh `mi` at a
    /// point with frame `f`, view `wr` (world, unit), base colour and diffuse
    /// weight `dw`, from the uniform numbers `u`.
    pub fn sample(
        &self,
        mi: usize,
        f: Frame,
        wr: [f64; 3],
        base: [f64; 3],
        dw: f64,
        u: &Uniforms,
    ) -> [f64; 3] {
        let lambda_u = u.lambda;
        let (t, b, n) = f;
        let local = |d: [f64; 3]| [dot(d, t), dot(d, b), dot(d, n)];
        let world = |d: [f64; 3]| [0, 1, 2].map(|k| d[0] * t[k] + d[1] * b[k] + d[2] * n[k]);
        let wr_l = local(wr);
        let (lo, hi) = (RANGE_NM.0 as f64 * 1e-9, RANGE_NM.1 as f64 * 1e-9);
        // HERO wavelengths per direction: lambda_u and its rotations by 1/HERO
        // of the range (each uniform, together stratified).
        let lambdas: [f64; HERO] =
            std::array::from_fn(|j| lo + (lambda_u + j as f64 / HERO as f64).fract() * (hi - lo));
        // The integral over nm of a uniform wavelength: span / HERO per wavelength.
        let span_nm = (RANGE_NM.1 - RANGE_NM.0) as f64 / HERO as f64;
        let lobe = self
            .lobes
            .get(mi)
            .and_then(|l| l.as_ref())
            .filter(|_| dw < 1.0);
        let mut rgb = [0.0; 3];
        let mut xyz = [0.0; 3];
        // Each wavelength's lobe proposal, prepared once for the draw and the
        // densities. The lobe technique draws at the hero wavelength, which is
        // any of the HERO with equal probability, so its density is the mean
        // over them (one direction serves all wavelengths: measured on frames,
        // a direction per wavelength, each evaluated at its own, was noisier).
        let queries: Vec<LobeQuery> = match lobe {
            Some(l) if wr_l[2] > 0.0 => lambdas.iter().map(|&x| l.query(wr_l, x)).collect(),
            _ => Vec::new(),
        };
        let lobe = lobe.filter(|_| !queries.is_empty());
        let lobe_pdf = |lobe: &LobeSampler, wi: [f64; 3]| {
            queries.iter().map(|q| lobe.pdf_in(q, wi)).sum::<f64>() / HERO as f64
        };
        let mut add = |lobe: &LobeSampler, d: [f64; 3], wi: [f64; 3], p_sum: f64| {
            let radiance = self.env.spectrum(d);
            for &l in &lambdas {
                let fc = lobe.brdf_cos(wi, wr_l, l);
                if fc > 0.0 {
                    let s = radiance.at(l) * fc * span_nm / (self.norm * p_sum);
                    if s.is_finite() {
                        let cmf = cie::cmf_at(l);
                        for c in 0..3 {
                            xyz[c] += s * cmf[c];
                        }
                    }
                }
            }
        };
        // A third technique for the sky's sun: its disc sampled at every sample
        // (so the wavelengths stay stratified over the pixel where the sun's
        // diffraction is). The disc is its alone: the other two techniques
        // skip directions in it (a partition of the sphere, so none of their
        // densities is needed there; the disc's density, 1 / its solid angle,
        // would take nearly all of the balance heuristic's weight anyway).
        let sun = match &*self.env {
            Environment::Sky(s) => Some(s),
            Environment::Map(_) => None,
        };
        let sun_drawn = sun.is_some_and(|s| s.sample_sun(0.5, 0.5).is_some());
        let in_sun = |d: [f64; 3]| sun_drawn && sun.is_some_and(|s| s.in_sun(d));
        if let Some((d, p_env)) = self.env.sample(u.env[0], u.env[1], u.env[2]) {
            let wi = local(d);
            if wi[2] > 0.0 && wr_l[2] > 0.0 {
                if dw > 0.0 {
                    let e = self.env.rgb(d);
                    for c in 0..3 {
                        rgb[c] += dw * base[c] * e[c] * wi[2] / (PI * p_env);
                    }
                }
                if let (Some(lobe), false) = (lobe, in_sun(d)) {
                    add(lobe, d, wi, p_env + lobe_pdf(lobe, wi));
                }
            }
        }
        if let (Some(lobe), Some(sky)) = (lobe, sun) {
            if let Some((d, p_sun)) = sky.sample_sun(u.sun[0], u.sun[1]) {
                let wi = local(d);
                if wi[2] > 0.0 {
                    add(lobe, d, wi, p_sun);
                }
            }
        }
        if let Some(lobe) = lobe {
            if let Some((wi, _)) = lobe.sample_in(&queries[0], u.lobe) {
                let d = world(wi);
                if !in_sun(d) {
                    add(lobe, d, wi, self.env.pdf(d) + lobe_pdf(lobe, wi));
                }
            }
        }
        let spec = colour::xyz_to_linear_srgb(xyz);
        for c in 0..3 {
            rgb[c] += (1.0 - dw) * spec[c];
        }
        rgb
    }
}
