//! Environment lighting in the reference: the integral over incoming
//! directions (docs/LIGHTING.md "The reference's estimator"), by one of two
//! estimators ([`EnvEstimator`]):
//!
//! - **quadrature** (the default): per sub-pixel sample, the sum over the
//!   texels of the pack's extended-light maps
//!   ([`sunbeam_response::quadrature`]), interleaved over the pixel's samples
//!   ([`EnvShader::shade_pixel`]), the sun at a point of its disc, the diffuse
//!   part from the environment's tabulated irradiance at the normal, with
//!   the skin's transmission `1 - F(theta_i)` inside the integral
//!   ([`Irradiance::transmitted`]; [`sunbeam_light::irradiance`] for a mesh
//!   without a pack): no noise but the sub-pixel positions';
//! - **Monte Carlo** ([`EnvShader::sample`]), which evaluates the pack's `R`
//!   per wavelength and direction and shares no code with the maps: the check
//!   of the quadrature. Per sub-pixel sample, [`HERO`] wavelengths and up to
//!   three directions:
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
//! - the diffraction term is `XYZ += L(wi, lambda) G G2 R_U(u, v, w, lambda)
//!   (A / lambda^2) cmf(lambda) / (p_lambda sum D65 ybar)`, `A` the pack's
//!   coherent area (window: `(sum g)^2 / sum g^2 dx dy`, tiled:
//!   `1 / (2 pi sigma_f^2)`), `G G2` the mesh's skin's gain times its masking
//!   (`Masking::gain`), `R_U` `Pack::shading_reflectance` (the window's
//!   grazing term, PHYSICS.md 2b), the BRDF of docs/LIGHTING.md; the diffuse
//!   part is `base / pi cos(theta_i) (1 - F(theta_i))` per direction (the
//!   skin's transmission, PHYSICS.md 2; no `1 - F` for a mesh without a
//!   pack), estimated with the environment's sample only (a white Lambertian
//!   without a skin under a white furnace of radiance 1 has radiance 1).
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
use sunbeam_light::irradiance::Irradiance;
use sunbeam_light::Environment;
use sunbeam_optics::masking::Masking;
use sunbeam_optics::{cie, colour, gain};
use sunbeam_pack::Pack;
use sunbeam_response::quadrature::{EnvQuadrature, Query};

/// How the reference integrates an environment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EnvEstimator {
    /// The sum over the extended-light maps' texels (no direction noise).
    #[default]
    Quadrature,
    /// Monte Carlo with the pack's `R` per wavelength (the independent check).
    MonteCarlo,
}

/// Largest number of interleaved classes a pixel's samples share ([`EnvShader::shade_pixel`]).
pub const MAX_PARTS: usize = 4096;

/// One covered sub-pixel sample of a pixel for [`EnvShader::shade_pixel`].
#[derive(Debug, Clone, Copy)]
pub struct Fragment {
    pub mesh: usize,
    pub frame: Frame,
    /// View direction (world, unit).
    pub wr: [f64; 3],
    pub base: [f64; 3],
    /// Diffuse weight.
    pub dw: f64,
    /// Two uniforms for the point of the sun's disc.
    pub sun_u: [f64; 2],
}

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
    /// Per mesh: its pack's extended-light maps (quadrature only).
    quads: Vec<Option<Arc<EnvQuadrature>>>,
    irradiance: Option<Irradiance>,
    /// The irradiance a diffuse base under a skin receives, per refractive
    /// index of the meshes' skins (quadrature only).
    /// Per skin index, the base's irradiance through the interface.
    transmitted: Vec<(f64, Arc<Irradiance>)>,
    /// Per mesh: whether it has a pack (a skin over its base).
    has_pack: Vec<bool>,
    /// Per mesh: the masking on its `G` (none: off for every mesh).
    masking: Vec<Masking>,
    /// Per mesh: the skin's material (none: the default for every mesh).
    skins: Vec<gain::Material>,
    norm: f64,
}

/// A local frame: tangent, bitangent, normal.
pub type Frame = ([f64; 3], [f64; 3], [f64; 3]);

impl EnvShader {
    pub fn new(env: Arc<Environment>, packs: &[Option<Arc<Pack>>]) -> EnvShader {
        Self::with_estimator(env, packs, EnvEstimator::MonteCarlo)
    }

    /// The shader for `estimator`: under [`EnvEstimator::Quadrature`] each
    /// distinct pack's maps are built once (1-3 s for the demo's packs).
    pub fn with_estimator(
        env: Arc<Environment>,
        packs: &[Option<Arc<Pack>>],
        estimator: EnvEstimator,
    ) -> EnvShader {
        let mut quads: Vec<Option<Arc<EnvQuadrature>>> = Vec::with_capacity(packs.len());
        let mut irradiance = None;
        let mut transmitted = Vec::new();
        if estimator == EnvEstimator::Quadrature {
            for (i, p) in packs.iter().enumerate() {
                let q = p.as_ref().filter(|p| p.has_terms()).map(|p| {
                    // Meshes that share a pack share its maps.
                    let same = packs[..i]
                        .iter()
                        .position(|o| o.as_ref().is_some_and(|o| Arc::ptr_eq(o, p)));
                    match same.and_then(|k| quads[k].clone()) {
                        Some(q) => q,
                        None => Arc::new(EnvQuadrature::build(
                            p,
                            &env,
                            &EnvQuadrature::reference_options(),
                        )),
                    }
                });
                quads.push(q);
            }
            let ior = gain::Material::default().ior;
            let (plain, skin) = Irradiance::pair(&env, ior);
            irradiance = Some(plain);
            transmitted = vec![(ior, Arc::new(skin))];
        }
        EnvShader {
            quads,
            irradiance,
            transmitted,
            has_pack: packs.iter().map(Option::is_some).collect(),
            env,
            lobes: packs
                .iter()
                .map(|p| {
                    p.as_ref()
                        .filter(|p| p.has_terms())
                        .map(|p| LobeSampler::new(p.clone()))
                })
                .collect(),
            masking: Vec::new(),
            skins: Vec::new(),
            norm: cie::d65_y_norm(RANGE_NM),
        }
    }

    /// The same shader with per-mesh masking (`masking[mi]`; meshes past its
    /// end unmasked).
    pub fn with_masking(mut self, masking: &[Masking]) -> EnvShader {
        self.masking = masking.to_vec();
        self
    }

    /// The same shader with per-mesh skins (`skins[mi]`, the scene's `ior`
    /// and `reflectance`; meshes past its end get the default): the gain of
    /// every light direction and the base's transmission. Under the
    /// quadrature, the transmitted irradiance of each index not yet
    /// tabulated is built here.
    pub fn with_skin(mut self, skins: &[gain::Material]) -> EnvShader {
        self.skins = skins.to_vec();
        if self.irradiance.is_some() {
            for s in skins {
                if !self.transmitted.iter().any(|t| t.0 == s.ior) {
                    self.transmitted
                        .push((s.ior, Arc::new(Irradiance::transmitted(&self.env, s.ior))));
                }
            }
        }
        self
    }

    fn masking(&self, mi: usize) -> Masking {
        self.masking.get(mi).copied().unwrap_or_default()
    }

    fn skin(&self, mi: usize) -> gain::Material {
        self.skins.get(mi).copied().unwrap_or_default()
    }

    fn has_pack(&self, mi: usize) -> bool {
        self.has_pack.get(mi).copied().unwrap_or(false)
    }

    /// True when the shader runs the quadrature ([`EnvShader::shade_pixel`]).
    pub fn is_quadrature(&self) -> bool {
        self.irradiance.is_some()
    }

    /// The quadrature estimator's radiance (linear sRGB) of the covered
    /// samples `frags` of one pixel, in their order.
    ///
    /// Interleaved sampling (Keller and Heidrich 2001): the samples of each
    /// mesh share the texels of its maps. With `m` samples of a mesh, the
    /// texels are split into `K` classes (`K` the largest of 4096, 1024, 256,
    /// 64, 16, 4, 1 not above `m` nor above `max(64, m / 4)`: at most 64 up to 256
    /// samples, then `m / 4`, so that a pixel sums its texels four times
    /// whatever `m` and more sub-pixel positions cost little more than their
    /// rasterisation), the samples are dealt the classes in turn after a random
    /// permutation from `rng` (so every class has `m / K` samples, give or
    /// take one), and a sample of class `c` with `m_c` members sums its class
    /// with weight `m / m_c` (times `K` inside the sum over one class): the
    /// pixel gets every texel once per mesh, each class's share from the mean
    /// over its samples. Unbiased over the permutation; where the integrand
    /// does not change over the pixel, exact.
    pub fn shade_pixel(&self, frags: &[Fragment], rng: &mut SplitMix64) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; frags.len()];
        let Some(irr) = &self.irradiance else {
            return out;
        };
        let local = |f: &Fragment| {
            let (t, b, n) = f.frame;
            [dot(f.wr, t), dot(f.wr, b), dot(f.wr, n)]
        };
        // Diffuse: base / pi times the irradiance at the normal, with the
        // skin's transmission 1 - F(theta_i) inside the integral (none
        // without a pack).
        for (f, o) in frags.iter().zip(out.iter_mut()) {
            if f.dw > 0.0 && local(f)[2] > 0.0 {
                let ior = self.skin(f.mesh).ior;
                let e = match self.transmitted.iter().find(|t| t.0 == ior) {
                    Some(t) if self.has_pack(f.mesh) => t.1.at(f.frame.2),
                    _ => irr.at(f.frame.2),
                };
                for c in 0..3 {
                    o[c] += f.dw * f.base[c] * e[c] / PI;
                }
            }
        }
        let mut meshes: Vec<usize> = frags.iter().map(|f| f.mesh).collect();
        meshes.sort_unstable();
        meshes.dedup();
        for mi in meshes {
            let Some(quad) = self.quads.get(mi).and_then(|q| q.as_ref()) else {
                continue;
            };
            let members: Vec<usize> = (0..frags.len())
                .filter(|&k| frags[k].mesh == mi && frags[k].dw < 1.0)
                .collect();
            let m = members.len();
            if m == 0 {
                continue;
            }
            let parts = [MAX_PARTS, 1024, 256, 64, 16, 4, 1]
                .into_iter()
                .find(|&k| k <= m && k <= (m / 4).max(64))
                .unwrap_or(1);
            let mut perm: Vec<usize> = (0..parts).collect();
            for i in (1..parts).rev() {
                let j = ((rng.unit() * (i + 1) as f64) as usize).min(i);
                perm.swap(i, j);
            }
            let mut classes: Vec<Vec<usize>> = vec![Vec::new(); parts];
            for (r, &k) in members.iter().enumerate() {
                classes[perm[r % parts]].push(k);
            }
            for (c, ks) in classes.iter().enumerate() {
                if ks.is_empty() {
                    continue;
                }
                let queries: Vec<Query> = ks
                    .iter()
                    .map(|&k| Query {
                        frame: frags[k].frame,
                        wr: local(&frags[k]),
                        sun_u: frags[k].sun_u,
                        masking: self.masking(mi),
                        skin: self.skin(mi),
                    })
                    .collect();
                let weight = m as f64 / (parts * ks.len()) as f64;
                for (&k, xyz) in ks
                    .iter()
                    .zip(quad.integrate_many(&self.env, &queries, (c, parts)))
                {
                    let rgb = colour::xyz_to_linear_srgb(xyz);
                    let f = &frags[k];
                    for a in 0..3 {
                        out[k][a] += (1.0 - f.dw) * weight * rgb[a];
                    }
                }
            }
        }
        out
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
        let masking = self.masking(mi);
        let skin = self.skin(mi);
        let queries: Vec<LobeQuery> = match lobe {
            Some(l) if wr_l[2] > 0.0 => lambdas.iter().map(|&x| l.query(wr_l, x, skin)).collect(),
            _ => Vec::new(),
        };
        let lobe = lobe.filter(|_| !queries.is_empty());
        let lobe_pdf = |lobe: &LobeSampler, wi: [f64; 3]| {
            queries.iter().map(|q| lobe.pdf_in(q, wi)).sum::<f64>() / HERO as f64
        };
        let mut add = |lobe: &LobeSampler, d: [f64; 3], wi: [f64; 3], p_sum: f64| {
            let radiance = self.env.spectrum(d);
            // G G2: the same for every wavelength (LobeSampler::brdf_cos split).
            let g = masking.gain(wi, wr_l, skin);
            if g.is_nan() || g <= 0.0 {
                return;
            }
            for &l in &lambdas {
                let fc = g * lobe.response(wi, wr_l, l);
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
                    // The base gets what the skin does not reflect (PHYSICS.md 2).
                    let t = if self.has_pack(mi) {
                        skin.transmission(wi[2])
                    } else {
                        1.0
                    };
                    let e = self.env.rgb(d);
                    for c in 0..3 {
                        rgb[c] += dw * base[c] * e[c] * wi[2] * t / (PI * p_env);
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
