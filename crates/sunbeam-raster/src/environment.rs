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
//!   the hero wavelengths;
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
//! Stratifying the directions too (per-pixel permuted grids) was measured and
//! gained nothing under the sky (docs/LIGHTING.md "Noise"), so they are
//! independent.

use crate::shade::dot;
use std::f64::consts::PI;
use std::sync::Arc;
use sunbeam_common::rng::SplitMix64;
use sunbeam_light::Environment;
use sunbeam_optics::{cie, colour, gain};
use sunbeam_pack::{manifest::Model, series, Pack};

/// Wavelength range of the integral (nm).
const RANGE_NM: (u32, u32) = cie::DEFAULT_RANGE_NM;
/// Wavelengths evaluated per direction (hero wavelength sampling, Wilkie et al. 2014).
pub const HERO: usize = 8;
/// Bins summed on each side for the tiled model's density, in sigmas.
const TILED_REACH: f64 = 5.0;

/// Draws incoming directions near the diffraction lobes of a pack: a bin of the
/// pack's stored spectrum with probability proportional to `|sum c_n(t) T_n|^2`
/// at one of up to eight phase depths `t` spanning the pack's range (a table
/// per depth), then a point in the bin. Bins are fixed in spatial frequency, so
/// the tables serve every wavelength and view; for a view `wr` and wavelength
/// the directions can only reach `|t|` in `2 pi H / lambda [cos(theta_r),
/// 1 + cos(theta_r)]`, so the draw mixes, with equal weights, only the tables
/// of the depths in that range (the orders' strengths change with `t`).
pub struct LobeSampler {
    pack: Arc<Pack>,
    /// One CDF over the bins per phase depth `t_j = -t_max (j + 1/2) / depths`.
    cdfs: Vec<Vec<f64>>,
    width: usize,
    height: usize,
    /// Coherent area (m^2).
    pub area_m2: f64,
}

impl LobeSampler {
    pub fn new(pack: Arc<Pack>) -> LobeSampler {
        use rayon::prelude::*;
        let m = &pack.manifest;
        let (w, h) = (m.crop.width, m.crop.height);
        let layer = m.layer_texels();
        // Up to 8 depths, fewer for very large crops (memory: 8 bytes per bin per depth).
        let depths = (16_000_000 / (w * h).max(1)).clamp(1, 8);
        let cdfs: Vec<Vec<f64>> = (0..depths)
            .map(|j| {
                let t = -m.t_max * (j as f64 + 0.5) / depths as f64;
                let c = series::coefficients_f64(m.basis, t, m.terms);
                let p: Vec<f64> = (0..w * h)
                    .into_par_iter()
                    .map(|b| {
                        let mut a = [0.0f64; 2];
                        for (n, cn) in c.iter().enumerate() {
                            let i = 2 * (n * layer + b);
                            let (re, im) = (pack.terms[i] as f64, pack.terms[i + 1] as f64);
                            a[0] += cn[0] * re - cn[1] * im;
                            a[1] += cn[0] * im + cn[1] * re;
                        }
                        a[0] * a[0] + a[1] * a[1]
                    })
                    .collect();
                let s: f64 = p.iter().sum();
                let mut cdf = Vec::with_capacity(w * h + 1);
                let mut acc = 0.0;
                cdf.push(0.0);
                for v in &p {
                    acc += if s > 0.0 { v / s } else { 1.0 / (w * h) as f64 };
                    cdf.push(acc);
                }
                cdf
            })
            .collect();
        let area_m2 = match m.model {
            Model::Window => sunbeam_optics::truth::window_coherent_area_m2(
                m.patch.width,
                m.patch.height,
                m.patch.dx_m,
                m.patch.dy_m,
                m.window_sigma_m,
            ),
            Model::Tiled => sunbeam_optics::truth::tiled_coherent_area_m2(m.sigma_f_per_m),
        };
        LobeSampler {
            pack,
            cdfs,
            width: w,
            height: h,
            area_m2,
        }
    }

    /// The depth tables a view and wavelength mix: `[lo, hi]` (inclusive).
    fn levels(&self, wr_z: f64, lambda_m: f64) -> (usize, usize) {
        let m = &self.pack.manifest;
        let d = self.cdfs.len();
        if m.t_max.is_nan() || m.t_max <= 0.0 {
            return (0, d - 1);
        }
        let k = 2.0 * std::f64::consts::PI * m.height_half_range_m / lambda_m;
        let level =
            |t_abs: f64| ((t_abs / m.t_max * d as f64).floor().max(0.0) as usize).min(d - 1);
        (level(k * wr_z.max(0.0)), level(k * (1.0 + wr_z.max(0.0))))
    }

    /// Probability of bin `(ix, iy)` (crop indices; 0 outside) in the mixture
    /// of the depth tables `lv`.
    fn bin_prob(&self, lv: (usize, usize), ix: i64, iy: i64) -> f64 {
        if ix < 0 || iy < 0 || ix >= self.width as i64 || iy >= self.height as i64 {
            return 0.0;
        }
        let b = iy as usize * self.width + ix as usize;
        let sum: f64 = self.cdfs[lv.0..=lv.1].iter().map(|c| c[b + 1] - c[b]).sum();
        sum / (lv.1 - lv.0 + 1) as f64
    }

    /// Density per unit bin area at bin coordinates `kappa`. Window model: the
    /// bin's probability spread uniformly over it. Tiled model: each bin's
    /// probability spread as the model's Gaussian of `sigma_bins` around it
    /// (the tiled response is exactly such a sum), summed over the bins within
    /// [`TILED_REACH`] sigma.
    fn pdf_kappa(&self, lv: (usize, usize), kx: f64, ky: f64) -> f64 {
        let m = &self.pack.manifest;
        match self.tiled_sigma() {
            None => self.bin_prob(
                lv,
                kx.round() as i64 + m.crop.kx,
                ky.round() as i64 + m.crop.ky,
            ),
            Some([sx, sy]) => {
                let (rx, ry) = (
                    (TILED_REACH * sx).ceil() as i64,
                    (TILED_REACH * sy).ceil() as i64,
                );
                let (cx, cy) = (kx.round() as i64, ky.round() as i64);
                let gauss =
                    |d: f64, s: f64| (-0.5 * d * d / (s * s)).exp() / (s * (2.0 * PI).sqrt());
                let mut p = 0.0;
                for by in cy - ry..=cy + ry {
                    let gy = gauss(ky - by as f64, sy);
                    for bx in cx - rx..=cx + rx {
                        let q = self.bin_prob(lv, bx + m.crop.kx, by + m.crop.ky);
                        if q > 0.0 {
                            p += q * gy * gauss(kx - bx as f64, sx);
                        }
                    }
                }
                p
            }
        }
    }

    /// The tiled model's Gaussian width in bins (None for the window model).
    fn tiled_sigma(&self) -> Option<[f64; 2]> {
        let m = &self.pack.manifest;
        (m.model == Model::Tiled).then(|| m.kernel.sigma_bins.map(|s| s.clamp(1e-3, 8.0)))
    }

    /// Bin coordinates of local directions at `lambda_m` (as `Pack::reflectance`).
    fn kappa(&self, wi: [f64; 3], wr: [f64; 3], lambda_m: f64) -> (f64, f64) {
        let m = &self.pack.manifest;
        let (u, v) = (-wi[0] - wr[0], -wi[1] - wr[1]);
        (
            -u / lambda_m * m.bin_scale_m[0],
            -v / lambda_m * m.bin_scale_m[1],
        )
    }

    /// Solid-angle density (1/sr) of drawing local `wi` for view `wr` at `lambda_m`.
    pub fn pdf(&self, wi: [f64; 3], wr: [f64; 3], lambda_m: f64) -> f64 {
        if wi[2] <= 0.0 {
            return 0.0;
        }
        let m = &self.pack.manifest;
        let (kx, ky) = self.kappa(wi, wr, lambda_m);
        let lv = self.levels(wr[2], lambda_m);
        // d(kappa_x, kappa_y) = bin_scale^2 / lambda^2 d(u, v), d(u, v) = cos(theta_i) dw.
        self.pdf_kappa(lv, kx, ky) * m.bin_scale_m[0] * m.bin_scale_m[1] / (lambda_m * lambda_m)
            * wi[2]
    }

    /// A local incoming direction for view `wr` at `lambda_m` (its density is
    /// [`LobeSampler::pdf`]); None when the drawn frequency is evanescent.
    pub fn sample(&self, u: [f64; 3], wr: [f64; 3], lambda_m: f64) -> Option<[f64; 3]> {
        let m = &self.pack.manifest;
        // The depth table, then the bin (u[0] split between the two choices).
        let lv = self.levels(wr[2], lambda_m);
        let k = lv.1 - lv.0 + 1;
        let uk = u[0] * k as f64;
        let li = (lv.0 + uk.floor() as usize).min(lv.1);
        let cdf = &self.cdfs[li];
        let x = (uk - uk.floor()) * cdf[cdf.len() - 1];
        let b = cdf
            .partition_point(|&c| c <= x)
            .saturating_sub(1)
            .min(cdf.len() - 2);
        let (ix, iy) = ((b % self.width) as i64, (b / self.width) as i64);
        let (ox, oy) = match self.tiled_sigma() {
            None => (u[1] - 0.5, u[2] - 0.5),
            Some([sx, sy]) => {
                // Box-Muller: a Gaussian offset of the model's width.
                let r = (-2.0 * (1.0 - u[1]).ln()).sqrt();
                let (s, c) = (2.0 * PI * u[2]).sin_cos();
                (r * c * sx, r * s * sy)
            }
        };
        let kx = (ix - m.crop.kx) as f64 + ox;
        let ky = (iy - m.crop.ky) as f64 + oy;
        let uu = -kx * lambda_m / m.bin_scale_m[0];
        let vv = -ky * lambda_m / m.bin_scale_m[1];
        let (wx, wy) = (-uu - wr[0], -vv - wr[1]);
        let r2 = wx * wx + wy * wy;
        if r2 >= 1.0 {
            return None;
        }
        Some([wx, wy, (1.0 - r2).sqrt()])
    }

    /// `f_r cos(theta_i) = G R A / lambda^2` (1/sr) for local directions.
    pub fn brdf_cos(&self, wi: [f64; 3], wr: [f64; 3], lambda_m: f64) -> f64 {
        if !(wi[2] > 0.0 && wr[2] > 0.0) {
            return 0.0;
        }
        let r = self
            .pack
            .reflectance(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2], lambda_m);
        gain::g(wi, wr, gain::DEFAULT_IOR) * r * self.area_m2 / (lambda_m * lambda_m)
    }
}

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
/// stratified (sample `k` in stratum `k` of `n`, shifted per pixel), the rest
/// independent, each sample from its own generator ([`EnvShader::rng`]).
pub fn pixel_uniforms(seed: u64, pixel: u64, n: u64) -> Vec<Uniforms> {
    let offset = EnvShader::rng(seed, pixel, u64::MAX).unit();
    (0..n)
        .map(|k| {
            let mut rng = EnvShader::rng(seed, pixel, k);
            let lambda = (offset + (k as f64 + rng.unit()) / n as f64).fract();
            Uniforms {
                lambda,
                ..Uniforms::random(&mut rng)
            }
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
        // The lobe technique's density: the hero is any of the HERO wavelengths
        // with equal probability, so its density is the mean over them.
        let lobe_pdf = |lobe: &LobeSampler, wi: [f64; 3]| {
            lambdas.iter().map(|&l| lobe.pdf(wi, wr_l, l)).sum::<f64>() / HERO as f64
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
        // diffraction is); its density joins the balance heuristic.
        let sun = match &*self.env {
            Environment::Sky(s) => Some(s),
            Environment::Map(_) => None,
        };
        let sun_pdf = |d: [f64; 3]| match sun {
            Some(s) if s.in_sun(d) => 1.0 / s.sun_solid_angle(),
            _ => 0.0,
        };
        if let Some((d, p_env)) = self.env.sample(u.env[0], u.env[1], u.env[2]) {
            let wi = local(d);
            if wi[2] > 0.0 && wr_l[2] > 0.0 {
                if dw > 0.0 {
                    let e = self.env.rgb(d);
                    for c in 0..3 {
                        rgb[c] += dw * base[c] * e[c] * wi[2] / (PI * p_env);
                    }
                }
                if let Some(lobe) = lobe {
                    add(lobe, d, wi, p_env + sun_pdf(d) + lobe_pdf(lobe, wi));
                }
            }
        }
        if let (Some(lobe), Some(sky)) = (lobe, sun) {
            if let Some((d, p_sun)) = sky.sample_sun(u.sun[0], u.sun[1]) {
                let wi = local(d);
                if wi[2] > 0.0 && wr_l[2] > 0.0 {
                    add(lobe, d, wi, self.env.pdf(d) + p_sun + lobe_pdf(lobe, wi));
                }
            }
        }
        if let Some(lobe) = lobe {
            if let Some(wi) = lobe.sample(u.lobe, wr_l, lambdas[0]) {
                if wr_l[2] > 0.0 {
                    let d = world(wi);
                    add(
                        lobe,
                        d,
                        wi,
                        self.env.pdf(d) + sun_pdf(d) + lobe_pdf(lobe, wi),
                    );
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
