//! The response table of `--mode table`: the spectral integral of a pack,
//! `T(u, v, w) = sum_l R_s(u, v, w, l) S(l) cmf(l) / sum_l S(l) ybar(l)` (XYZ,
//! without `G`), on a regular grid over `u, v` in [-2, 2] and `w` in [-2, 0],
//! built once when a pack loads. A fragment then reads 8 cells and interpolates
//! trilinearly instead of summing terms, taps and wavelengths (docs/PLAY.md
//! "Response table").
//!
//! `R_s` is the reflectance that shading uses, exactly as
//! `Pack::shading_reflectance` defines it (same coefficients, taps, kernel and
//! model; the term count per |t| from `terms_at`), in float64: for the window
//! model with a window (`window_sigma_m > 0`) `R_U` of PHYSICS.md 2b
//! (`sunbeam_optics::grazing::window_reflectance`, from the amplitude and its
//! derivatives along `u` and `v` through the derivative of the same
//! Kaiser-Bessel kernel, `kernel::kb_derivative`), otherwise `R` (the tiled
//! model keeps Beckmann's factor). tests/response_table.rs checks the grid
//! nodes against the pack's evaluator; the trilinear lookup's error against
//! the direct path is in docs/bench/play.md.
//!
//! Arranged so that each (w, wavelength) pair costs one pass over the crop
//! plus separable interpolations (the taps, which depend on the wavelength
//! only, are computed once per wavelength): `A = sum_n c_n D_n` on the crop;
//! then the x taps for every table column (for `R_U` also the x derivative
//! taps: `dA/dkappa_x`); then the y taps for every table row (for `R_U` also
//! the y taps of `dA/dkappa_x` and the y derivative taps of `A`: three
//! interpolations of the one crop sum, where `R` needs one).

use rayon::prelude::*;

use sunbeam_frame::spectral::Samples;
use sunbeam_pack::{kernel, series, Manifest, Model, Pack};

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

/// A complex value (re, im), as `window_reflectance` takes it.
type C = [f64; 2];

/// One axis' taps for every table column (x) or row (y) at one wavelength:
/// the first crop index, the weights (0 outside the crop) and, for `R_U`, the
/// weights' derivatives along `kappa`; `ok` is false where no tap falls
/// inside the crop.
struct AxisTaps {
    k0: Vec<i64>,
    w: Vec<f64>,
    dw: Vec<f64>,
    ok: Vec<bool>,
}

impl AxisTaps {
    /// The taps at the `count` coordinates `U_MIN + i d` of `axis` (0: u, 1:
    /// v) and wavelength `lam`; with `deriv` their derivatives too.
    fn new(m: &Manifest, lam: f64, count: usize, d: f64, axis: usize, deriv: bool) -> AxisTaps {
        let n = m.kernel.taps;
        let mut t = AxisTaps {
            k0: vec![0; count],
            w: vec![0.0; count * n],
            dw: vec![0.0; count * n],
            ok: vec![false; count],
        };
        let k_half = if axis == 0 { m.crop.kx } else { m.crop.ky };
        for (i, ok) in t.ok.iter_mut().enumerate() {
            let kappa = -(U_MIN + i as f64 * d) / lam * m.bin_scale_m[axis];
            if kappa.abs() > k_half as f64 + n as f64 {
                continue;
            }
            let k0 = kernel::first_tap(kappa, n);
            let (w, dw) = (&mut t.w[i * n..(i + 1) * n], &mut t.dw[i * n..(i + 1) * n]);
            for j in 0..n {
                let k = k0 + j as i64;
                (w[j], dw[j]) = if k < -k_half || k > k_half {
                    (0.0, 0.0)
                } else {
                    *ok = true;
                    let x = kappa - k as f64;
                    match m.model {
                        Model::Window => (
                            kernel::kb(x, n, m.kernel.beta),
                            if deriv {
                                kernel::kb_derivative(x, n, m.kernel.beta)
                            } else {
                                0.0
                            },
                        ),
                        Model::Tiled => (kernel::gauss(x, m.kernel.sigma_bins[axis]), 0.0),
                    }
                };
            }
            t.k0[i] = k0 + k_half;
        }
        t
    }
}

/// `sum_j w_j v(k0 + j)` for the weights `w` (zero weights skipped).
#[inline]
fn dot(w: &[f64], k0: i64, v: impl Fn(usize) -> C) -> C {
    let mut s = [0.0; 2];
    for (j, &wt) in w.iter().enumerate() {
        if wt != 0.0 {
            let q = v((k0 + j as i64) as usize);
            s[0] += wt * q[0];
            s[1] += wt * q[1];
        }
    }
    s
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
    // The window's sigma when the table holds R_U (PHYSICS.md 2b), as in
    // `Pack::shading_reflectance`.
    let sigma = (m.model == Model::Window && m.window_sigma_m > 0.0).then_some(m.window_sigma_m);
    let deriv = sigma.is_some();
    let (nu, nv, nw) = (dims.nu.max(2), dims.nv.max(2), dims.nw.max(2));
    let du = 4.0 / (nu - 1) as f64;
    let dv = 4.0 / (nv - 1) as f64;
    let dw = 2.0 / (nw - 1) as f64;
    let (cw, ch) = (m.crop.width, m.crop.height);
    let layer = cw * ch;
    let ntaps = m.kernel.taps;
    // The taps depend on the wavelength, not on w: once per sample.
    let axes: Vec<[AxisTaps; 2]> = samples
        .0
        .par_iter()
        .map(|s| {
            let lam = s.lambda_m;
            [
                AxisTaps::new(m, lam, nu, du, 0, deriv),
                AxisTaps::new(m, lam, nv, dv, 1, deriv),
            ]
        })
        .collect();
    let mut data = vec![[0.0f32; 4]; nu * nv * nw];
    data.par_chunks_mut(nu * nv).enumerate().for_each_init(
        || {
            (
                vec![[0.0; 2]; layer],
                // x-interpolated rows: A, and dA/dkappa_x for R_U
                vec![[0.0; 2]; ch * nu],
                vec![[0.0; 2]; if deriv { ch * nu } else { 0 }],
                vec![[0.0f64; 3]; nu * nv],
                vec![[[0.0; 2]; 3]; nu],
            )
        },
        |(a, b, bx, acc, ys), (iw, out)| {
            let w = W_MIN + iw as f64 * dw;
            acc.iter_mut().for_each(|v| *v = [0.0; 3]);
            for (s, [tx, ty]) in samples.0.iter().zip(&axes) {
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
                        Model::Window => [re, im],
                        Model::Tiled => [re * re + im * im, 0.0],
                    };
                }
                // x pass (with the derivative taps for R_U)
                for yy in 0..ch {
                    let row = &a[yy * cw..(yy + 1) * cw];
                    for iu in (0..nu).filter(|&iu| tx.ok[iu]) {
                        let taps = iu * ntaps..(iu + 1) * ntaps;
                        let k0 = tx.k0[iu];
                        b[yy * nu + iu] = dot(&tx.w[taps.clone()], k0, |k| row[k]);
                        if deriv {
                            bx[yy * nu + iu] = dot(&tx.dw[taps], k0, |k| row[k]);
                        }
                    }
                }
                // y pass: A, dA/du, dA/dv (d/du = -(bin_scale_x / lambda) d/dkappa_x)
                let (su, sv) = (-m.bin_scale_m[0] / lam, -m.bin_scale_m[1] / lam);
                let k = 2.0 * std::f64::consts::PI / lam;
                // The columns with taps in the crop (an interval of u).
                let lo = tx.ok.iter().position(|&ok| ok).unwrap_or(nu);
                let hi = tx.ok.iter().rposition(|&ok| ok).map_or(lo, |i| i + 1);
                for iv in (0..nv).filter(|&iv| ty.ok[iv]) {
                    let v = U_MIN + iv as f64 * dv;
                    let taps = iv * ntaps..(iv + 1) * ntaps;
                    // Row-wise over the taps (contiguous in u): per column
                    // A, dA/dkappa_x, dA/dkappa_y, each summed in tap order.
                    ys[lo..hi].iter_mut().for_each(|y| *y = [[0.0; 2]; 3]);
                    for (j, (&wt, &dwt)) in ty.w[taps.clone()].iter().zip(&ty.dw[taps]).enumerate()
                    {
                        if wt == 0.0 && dwt == 0.0 {
                            continue; // outside the crop
                        }
                        let row = (ty.k0[iv] + j as i64) as usize * nu + lo;
                        let (br, yr) = (&b[row..row + hi - lo], &mut ys[lo..hi]);
                        if !deriv {
                            for (y, q) in yr.iter_mut().zip(br) {
                                y[0][0] += wt * q[0];
                                y[0][1] += wt * q[1];
                            }
                            continue;
                        }
                        // One pass for the three (a zero weight adds exact zeros).
                        let bxr = &bx[row..row + hi - lo];
                        for ((y, q), qx) in yr.iter_mut().zip(br).zip(bxr) {
                            y[0][0] += wt * q[0];
                            y[0][1] += wt * q[1];
                            y[1][0] += wt * qx[0];
                            y[1][1] += wt * qx[1];
                            y[2][0] += dwt * q[0];
                            y[2][1] += dwt * q[1];
                        }
                    }
                    for iu in (lo..hi).filter(|&iu| tx.ok[iu]) {
                        let [amp, d_x, d_y] = ys[iu];
                        let r = match (m.model, sigma) {
                            (Model::Tiled, _) => amp[0],
                            (Model::Window, None) => amp[0] * amp[0] + amp[1] * amp[1],
                            (Model::Window, Some(sg)) => {
                                sunbeam_optics::grazing::window_reflectance(
                                    [U_MIN + iu as f64 * du, v, w],
                                    amp,
                                    d_x.map(|d| d * su),
                                    d_y.map(|d| d * sv),
                                    k,
                                    [sg, sg],
                                )
                            }
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
