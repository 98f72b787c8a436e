#![allow(dead_code)] // each test binary uses a part
//! Shared by the integration tests: the window model's shading reflectance
//! by a direct float64 sum (no pack code).

use std::f64::consts::PI;

/// The window model's `R` and `R_U` (PHYSICS.md 2, 2b) by a direct float64
/// sum over the height field: the amplitude `P = sum g e^{i k (u x + v y +
/// w (h - hc))} / sum g` and its derivatives along `u`, `v` (`x`, `y` from
/// the patch's centre, row 0 at the top, `g` the Gaussian window of
/// PHYSICS.md 2 cut at the patch, `hc` the height range's centre), `R_U`
/// from them by `sunbeam_optics::grazing::window_reflectance`. No pack code;
/// `R = |P|^2` is the float64 truth's (a test checks it).
pub struct Kirchhoff {
    w: usize,
    xs: Vec<f64>,
    ys: Vec<f64>,
    g: Vec<f64>,
    h: Vec<f64>,
    gsum: f64,
    pub sigma: f64,
}

impl Kirchhoff {
    /// The field `data` (`w x h`, row-major, row 0 at the top, metres) of
    /// pixels `dx x dy`, the window of coherence length `coherence_m`.
    pub fn new(w: usize, h: usize, dx: f64, dy: f64, data: &[f64], coherence_m: f64) -> Kirchhoff {
        let (lo, hi) = data
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let hc = 0.5 * (lo + hi);
        let xs: Vec<f64> = (0..w)
            .map(|c| (c as f64 - 0.5 * (w as f64 - 1.0)) * dx)
            .collect();
        let ys: Vec<f64> = (0..h)
            .map(|r| ((h - 1 - r) as f64 - 0.5 * (h as f64 - 1.0)) * dy)
            .collect();
        let lmin = (w as f64 * dx).min(h as f64 * dy);
        let sigma = (coherence_m / (4.0 * std::f64::consts::SQRT_2)).min(lmin / 6.0);
        let gauss = |d: f64| (-(d * d) / (2.0 * sigma * sigma)).exp();
        let g: Vec<f64> = (0..w * h)
            .map(|k| gauss(xs[k % w]) * gauss(ys[k / w]))
            .collect();
        Kirchhoff {
            w,
            gsum: g.iter().sum(),
            xs,
            ys,
            g,
            h: data.iter().map(|v| v - hc).collect(),
            sigma,
        }
    }

    /// `g e^{i k w (h - hc)}` per sample, for one `(w, lambda)`.
    pub fn phasors(&self, w: f64, lambda: f64) -> Vec<(f64, f64)> {
        let k = 2.0 * PI / lambda;
        self.h
            .iter()
            .zip(&self.g)
            .map(|(&h, &g)| {
                let (s, c) = (k * w * h).sin_cos();
                (g * c, g * s)
            })
            .collect()
    }

    /// `(R, R_U)` at `(u, v)` for the phasors `p` of `(w, lambda)`.
    pub fn r_u(&self, p: &[(f64, f64)], u: f64, v: f64, w: f64, lambda: f64) -> (f64, f64) {
        let k = 2.0 * PI / lambda;
        let n = self.w;
        let a: Vec<(f64, f64)> = self.xs.iter().map(|&x| (k * u * x).sin_cos()).collect();
        let (mut pp, mut px, mut py) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        for (r, &y) in self.ys.iter().enumerate() {
            let (mut s0, mut s1) = ([0.0; 2], [0.0; 2]);
            for c in 0..n {
                let (sa, ca) = a[c];
                let (pr, pi) = p[r * n + c];
                let (re, im) = (ca * pr - sa * pi, ca * pi + sa * pr);
                s0[0] += re;
                s0[1] += im;
                s1[0] += self.xs[c] * re;
                s1[1] += self.xs[c] * im;
            }
            let (sb, cb) = (k * v * y).sin_cos();
            let mul = |z: [f64; 2]| [cb * z[0] - sb * z[1], cb * z[1] + sb * z[0]];
            let (b0, b1) = (mul(s0), mul(s1));
            for i in 0..2 {
                pp[i] += b0[i];
                px[i] += b1[i];
                py[i] += y * b0[i];
            }
        }
        // d/du of e^{i k u x} is i k x: (re, im) -> (-k im, k re).
        let d = |z: [f64; 2]| [-k * z[1] / self.gsum, k * z[0] / self.gsum];
        let p0 = pp.map(|z| z / self.gsum);
        let ru = sunbeam_optics::grazing::window_reflectance(
            [u, v, w],
            p0,
            d(px),
            d(py),
            k,
            [self.sigma, self.sigma],
        );
        (p0[0] * p0[0] + p0[1] * p0[1], ru)
    }
}

/// The pack of an `n x n` height field of `dx` (metres) under `model`, the
/// other build options at their defaults.
pub fn pack_of(
    n: usize,
    dx: f64,
    data: &[f64],
    model: sunbeam_pack::Model,
) -> std::sync::Arc<sunbeam_pack::Pack> {
    let f = sunbeam_pack::FieldRef {
        width: n,
        height: n,
        dx,
        dy: dx,
        data,
    };
    let opts = sunbeam_pack::build::BuildOptions {
        model,
        ..sunbeam_pack::build::BuildOptions::default()
    };
    std::sync::Arc::new(sunbeam_pack::build(f, &opts, &mut |_, _| {}).unwrap())
}

/// A flat patch whose lobe is narrow (`sigma_u` about 0.0015 at 550 nm): the
/// furnace's `F(theta)` is the narrow-lobe limit of `int G R A / l^2 dw`;
/// a lobe `sigma_u` wide adds about `(G / cos(theta_i))'' sigma_u^2 / 2`,
/// which at 80 degrees is large (+1.2 / +2.8 / +3.3 % for `sigma_u` 0.004 /
/// 0.0054 / 0.007, a Gaussian average of `G / cos(theta_i)`): a 6.4 um
/// tiled patch at the default coherence (65 um) gives 0.3983 there.
/// Window: 256 um at 1 um (a flat field needs no finer sampling), coherence
/// 400 um (`sigma` = 42.7 um), frequencies stored up to 0.1 / 380 nm; tiled:
/// 6.4 um, coherence 400 um.
pub fn narrow_flat_pack(model: sunbeam_pack::Model) -> std::sync::Arc<sunbeam_pack::Pack> {
    let (n, dx) = match model {
        sunbeam_pack::Model::Window => (256usize, 1e-6),
        sunbeam_pack::Model::Tiled => (64, 100e-9),
    };
    let data = vec![0.0; n * n];
    let f = sunbeam_pack::FieldRef {
        width: n,
        height: n,
        dx,
        dy: dx,
        data: &data,
    };
    let opts = sunbeam_pack::build::BuildOptions {
        model,
        coherence_m: 400e-6,
        freq_limit_per_m: (model == sunbeam_pack::Model::Window).then_some([0.1 / 380e-9; 2]),
        ..sunbeam_pack::build::BuildOptions::default()
    };
    std::sync::Arc::new(sunbeam_pack::build(f, &opts, &mut |_, _| {}).unwrap())
}

/// Sum over samples `ks` of the reference estimator's XYZ at one shading
/// point (frame `f`, world view `wr`; no diffuse part), each divided by `m`:
/// sample k draws from its own stream `EnvShader::rng(seed, 0, k)` and takes
/// wavelength stratum k of `m`, so a range of a larger sum is a part of it.
pub fn estimator_xyz_sum(
    es: &sunbeam_raster::environment::EnvShader,
    f: sunbeam_raster::environment::Frame,
    wr: [f64; 3],
    seed: u64,
    ks: std::ops::Range<u64>,
    m: u64,
) -> [f64; 3] {
    use sunbeam_raster::environment::{EnvShader, Uniforms};
    let mut mc = [0.0; 3];
    for k in ks {
        let mut rng = EnvShader::rng(seed, 0, k);
        let lu = (k as f64 + rng.unit()) / m as f64;
        let u = Uniforms {
            lambda: lu,
            ..Uniforms::random(&mut rng)
        };
        let xyz =
            sunbeam_optics::colour::linear_srgb_to_xyz(es.sample(0, f, wr, [0.0; 3], 0.0, &u));
        for i in 0..3 {
            mc[i] += xyz[i] / m as f64;
        }
    }
    mc
}
