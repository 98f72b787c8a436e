//! The response table of the default mode: the spectral integral of a pack,
//! `T(u, v, w) = sum_l R(u, v, w, l) S(l) cmf(l) / sum_l S(l) ybar(l)` (XYZ, without
//! `G`), on a regular grid over `u, v` in [-2, 2] and `w` in [-2, 0], built once when
//! a pack loads. A fragment then reads 8 cells and interpolates trilinearly
//! instead of summing terms, taps and wavelengths (docs/PLAY.md "Response table";
//! its error against the direct path is measured in the tests and docs/bench/play.md).
//!
//! Built on the CPU in float64 with exactly the pack's evaluation
//! (`Pack::reflectance`: same coefficients, taps, kernel and model) but arranged so
//! that each (w, wavelength) pair costs one pass over the crop plus a separable
//! interpolation: `A = sum_n c_n D_n` on the crop, then the x taps for every
//! table column, then the y taps for every table row.

use rayon::prelude::*;

use sunbeam_frame::spectral::Samples;
use sunbeam_pack::{kernel, series, Model, Pack};

/// Table resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dims {
    pub nu: usize,
    pub nv: usize,
    pub nw: usize,
}

impl Default for Dims {
    fn default() -> Self {
        Dims {
            nu: 256,
            nv: 256,
            nw: 32,
        }
    }
}

/// The table: `data[(iw * nv + iv) * nu + iu]` = XYZ (w unused) at
/// `u = -2 + iu du`, `v = -2 + iv dv`, `w = -2 + iw dw`.
#[derive(Debug, Clone)]
pub struct ResponseTable {
    pub dims: Dims,
    pub du: f64,
    pub dv: f64,
    pub dw: f64,
    pub data: Vec<[f32; 4]>,
}

pub const U_MIN: f64 = -2.0;
pub const W_MIN: f64 = -2.0;

#[derive(Clone, Copy, Default)]
struct C {
    re: f64,
    im: f64,
}

/// Taps of one axis at `kappa`: first texel index and weights (0 outside the crop).
fn taps(
    m: &sunbeam_pack::Manifest,
    kappa: f64,
    k_half: i64,
    axis: usize,
    w: &mut [f64],
) -> (i64, bool) {
    let n = m.kernel.taps;
    let k0 = kernel::first_tap(kappa, n);
    let mut any = false;
    for (j, wj) in w.iter_mut().enumerate().take(n) {
        let k = k0 + j as i64;
        *wj = if k < -k_half || k > k_half {
            0.0
        } else {
            any = true;
            let d = kappa - k as f64;
            match m.model {
                Model::Window => kernel::kb(d, n, m.kernel.beta),
                Model::Tiled => kernel::gauss(d, m.kernel.sigma_bins[axis]),
            }
        };
    }
    (k0 + k_half, any)
}

/// Build the table of `pack` with the wavelength `samples` and a per-|t| term
/// count `terms_at` (the same rule as the shader's direct path).
pub fn build(
    pack: &Pack,
    samples: &Samples,
    dims: Dims,
    terms_at: &(dyn Fn(f64) -> usize + Sync),
) -> ResponseTable {
    let m = &pack.manifest;
    let (nu, nv, nw) = (dims.nu.max(2), dims.nv.max(2), dims.nw.max(2));
    let du = 4.0 / (nu - 1) as f64;
    let dv = 4.0 / (nv - 1) as f64;
    let dw = 2.0 / (nw - 1) as f64;
    let (cw, ch) = (m.crop.width, m.crop.height);
    let layer = cw * ch;
    let ntaps = m.kernel.taps;
    let mut data = vec![[0.0f32; 4]; nu * nv * nw];
    data.par_chunks_mut(nu * nv).enumerate().for_each_init(
        || {
            (
                vec![C::default(); layer],
                vec![C::default(); ch * nu], // x-interpolated rows
                vec![[0.0f64; 3]; nu * nv],
                vec![0.0; nu * ntaps],
                vec![0i64; nu],
                vec![false; nu],
                vec![0.0; ntaps],
            )
        },
        |(a, b, acc, wx, kx0, xok, wy), (iw, out)| {
            let w = W_MIN + iw as f64 * dw;
            acc.iter_mut().for_each(|v| *v = [0.0; 3]);
            for s in &samples.0 {
                let lam = s.lambda_m;
                let t = pack.t(w, lam);
                let n = terms_at(t.abs()).clamp(1, m.terms);
                let c = series::coefficients_f64(m.basis, t, n);
                // A = sum_n c_n D_n over the crop (|A|^2 for the tiled model, in re).
                for (i, ai) in a.iter_mut().enumerate() {
                    let mut re = 0.0;
                    let mut im = 0.0;
                    for (q, cn) in c.iter().enumerate() {
                        let j = 2 * (q * layer + i);
                        let (dr, di) = (pack.terms[j] as f64, pack.terms[j + 1] as f64);
                        re += cn[0] * dr - cn[1] * di;
                        im += cn[0] * di + cn[1] * dr;
                    }
                    *ai = match m.model {
                        Model::Window => C { re, im },
                        Model::Tiled => C {
                            re: re * re + im * im,
                            im: 0.0,
                        },
                    };
                }
                // x pass
                for iu in 0..nu {
                    let u = U_MIN + iu as f64 * du;
                    let kappa = -u / lam * m.bin_scale_m[0];
                    if kappa.abs() > m.crop.kx as f64 + ntaps as f64 {
                        xok[iu] = false;
                        continue;
                    }
                    let (k0, any) = taps(
                        m,
                        kappa,
                        m.crop.kx,
                        0,
                        &mut wx[iu * ntaps..(iu + 1) * ntaps],
                    );
                    kx0[iu] = k0;
                    xok[iu] = any;
                }
                for ty in 0..ch {
                    let row = &a[ty * cw..(ty + 1) * cw];
                    for iu in 0..nu {
                        if !xok[iu] {
                            continue;
                        }
                        let mut sre = 0.0;
                        let mut sim = 0.0;
                        for j in 0..ntaps {
                            let wt = wx[iu * ntaps + j];
                            if wt != 0.0 {
                                let v = row[(kx0[iu] + j as i64) as usize];
                                sre += wt * v.re;
                                sim += wt * v.im;
                            }
                        }
                        b[ty * nu + iu] = C { re: sre, im: sim };
                    }
                }
                // y pass
                for iv in 0..nv {
                    let v = U_MIN + iv as f64 * dv;
                    let kappa = -v / lam * m.bin_scale_m[1];
                    if kappa.abs() > m.crop.ky as f64 + ntaps as f64 {
                        continue;
                    }
                    let (k0, any) = taps(m, kappa, m.crop.ky, 1, wy);
                    if !any {
                        continue;
                    }
                    for iu in 0..nu {
                        if !xok[iu] {
                            continue;
                        }
                        let mut sre = 0.0;
                        let mut sim = 0.0;
                        for (j, &wt) in wy.iter().enumerate().take(ntaps) {
                            if wt != 0.0 {
                                let q = b[(k0 + j as i64) as usize * nu + iu];
                                sre += wt * q.re;
                                sim += wt * q.im;
                            }
                        }
                        let r = match m.model {
                            Model::Window => sre * sre + sim * sim,
                            Model::Tiled => sre,
                        };
                        let cell = &mut acc[iv * nu + iu];
                        for (c, w) in cell.iter_mut().zip(&s.weight) {
                            *c += r * w;
                        }
                    }
                }
            }
            for (o, v) in out.iter_mut().zip(acc.iter()) {
                *o = [v[0] as f32, v[1] as f32, v[2] as f32, 0.0];
            }
        },
    );
    ResponseTable {
        dims: Dims { nu, nv, nw },
        du,
        dv,
        dw,
        data,
    }
}

impl ResponseTable {
    /// Trilinear lookup (what the shader does), for tests.
    pub fn lookup(&self, u: f64, v: f64, w: f64) -> [f64; 3] {
        let Dims { nu, nv, nw } = self.dims;
        let f = |x: f64, d: f64, lo: f64, n: usize| {
            let p = ((x - lo) / d).clamp(0.0, (n - 1) as f64);
            let i = (p.floor() as usize).min(n - 2);
            (i, p - i as f64)
        };
        let (iu, fu) = f(u, self.du, U_MIN, nu);
        let (iv, fv) = f(v, self.dv, U_MIN, nv);
        let (iw, fw) = f(w, self.dw, W_MIN, nw);
        let mut out = [0.0; 3];
        for (dz, wz) in [(0, 1.0 - fw), (1, fw)] {
            for (dy, wy) in [(0, 1.0 - fv), (1, fv)] {
                for (dx, wx) in [(0, 1.0 - fu), (1, fu)] {
                    let c = self.data[((iw + dz) * nv + iv + dy) * nu + iu + dx];
                    for k in 0..3 {
                        out[k] += wz * wy * wx * c[k] as f64;
                    }
                }
            }
        }
        out
    }
}
