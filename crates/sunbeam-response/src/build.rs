//! Building a response map from a term pack: for every texel and wavelength
//! sample, `R` exactly as `sunbeam_pack::Pack::reflectance` defines it (same
//! coefficients, kernel taps and model), summed with the colour weights.
//!
//! Arranged so that each (texel column, wavelength) interpolates the N terms
//! once (Kaiser-Bessel or Gaussian taps, PACK_FORMAT.md) and then evaluates
//! every `w` of the column from those N complex values: `t` changes with `w`
//! but the frequency does not. The coefficients `c_n(t)` depend only on the
//! radius row, the wavelength and `s`, so they are tabulated per row. Rows run
//! in parallel (rayon); each texel's sum runs in a fixed order, so the map does
//! not depend on the thread count.

use crate::grid::Grid;
use crate::{Info, Response, FORMAT, VERSION};
use rayon::prelude::*;
use sunbeam_optics::cie;
use sunbeam_pack::{kernel, series, Model, Pack};

/// How to build a map.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Wavelength samples (midpoints over 380..780 nm).
    pub lambda_samples: usize,
    /// Upper bound on the map's size in bytes (RGBA16F texels).
    pub budget_bytes: usize,
    /// Fixed grid (None: chosen from the pack, [`auto_grid`]).
    pub grid: Option<Grid>,
}

/// Default wavelength samples (docs/PACK_FORMAT.md "Response map": chosen by measurement).
pub const DEFAULT_LAMBDA_SAMPLES: usize = 96;
/// Default size bound: 64 MiB.
pub const DEFAULT_BUDGET: usize = 64 << 20;

impl Default for Options {
    fn default() -> Self {
        Options {
            lambda_samples: DEFAULT_LAMBDA_SAMPLES,
            budget_bytes: DEFAULT_BUDGET,
            grid: None,
        }
    }
}

/// Shortest wavelength of the colour integral, metres.
const LAMBDA_MIN: f64 = cie::DEFAULT_RANGE_NM.0 as f64 * 1e-9;

/// Width (sigma, in |(u, v)|) of the narrowest lobe the pack can make: the
/// coherence window's transform, squared, at the shortest wavelength.
pub fn lobe_width(pack: &Pack) -> f64 {
    let m = &pack.manifest;
    let w = match m.model {
        Model::Window if m.window_sigma_m > 0.0 => {
            LAMBDA_MIN / (2.0 * std::f64::consts::SQRT_2 * std::f64::consts::PI * m.window_sigma_m)
        }
        Model::Tiled if m.sigma_f_per_m > 0.0 => LAMBDA_MIN * m.sigma_f_per_m,
        _ => 0.02,
    };
    w.clamp(1e-4, 0.05)
}

/// The grid for a pack: two texels per lobe width across `(u, v)` at radius 1
/// (angle), steps of 1/25 in `asinh(r / r0)` along the radius, about three per
/// unit of `|t|` along `w`; then shrunk to the budget (angle last).
pub fn auto_grid(pack: &Pack, budget_bytes: usize) -> Grid {
    let m = &pack.manifest;
    let lobe = lobe_width(pack);
    let n_theta = ((std::f64::consts::TAU * 2.0 / lobe) / 64.0).ceil() as usize * 64;
    let mut g = Grid {
        n_theta: n_theta.clamp(128, 2048),
        n_rho: 0,
        n_s: 0,
        r0: lobe,
    };
    g.n_rho = ((g.rho_scale() * 25.0).ceil() as usize + 1).clamp(32, 192);
    let t_max = 4.0 * std::f64::consts::PI * m.height_half_range_m / LAMBDA_MIN;
    g.n_s = ((3.0 * t_max).ceil() as usize + 2).clamp(8, 40);
    let max_texels = (budget_bytes / 8).max(128 * 32 * 8);
    while g.texels() > max_texels {
        if g.n_s > 16 {
            g.n_s = (g.n_s * 7 / 8).max(16);
        } else if g.n_rho > 64 {
            g.n_rho = (g.n_rho * 7 / 8).max(64);
        } else if g.n_theta > 128 {
            g.n_theta = (g.n_theta / 2).max(128);
        } else {
            break;
        }
    }
    g
}

/// Wavelengths (metres) and XYZ weights `S cmf / sum S ybar` of `n` midpoint samples.
pub fn wavelength_weights(n: usize) -> Vec<(f64, [f64; 3])> {
    let n = n.max(1);
    let (lo, hi) = (
        cie::DEFAULT_RANGE_NM.0 as f64,
        cie::DEFAULT_RANGE_NM.1 as f64,
    );
    let step = (hi - lo) / n as f64;
    let raw: Vec<(f64, [f64; 3])> = (0..n)
        .map(|j| {
            let l = (lo + (j as f64 + 0.5) * step) * 1e-9;
            let s = cie::d65_at(l);
            let c = cie::cmf_at(l);
            (l, [s * c[0], s * c[1], s * c[2]])
        })
        .collect();
    let norm: f64 = raw.iter().map(|r| r.1[1]).sum();
    raw.into_iter()
        .map(|(l, w)| (l, w.map(|v| v / norm)))
        .collect()
}

/// The Kaiser-Bessel kernel tabulated over `|d| in [0, taps / 2]` (linear
/// interpolation; the kernel's second derivative is O(1), so the table's error
/// is about 1e-8): `kernel::kb` sums a Bessel series per call, which dominated
/// the build.
struct KbTable {
    step: f64,
    v: Vec<f64>,
}

const KB_TABLE: usize = 8192;

impl KbTable {
    fn new(taps: usize, beta: f64) -> KbTable {
        let half = taps as f64 / 2.0;
        let step = half / KB_TABLE as f64;
        let v = (0..=KB_TABLE + 1)
            .map(|i| kernel::kb(i as f64 * step, taps, beta))
            .collect();
        KbTable { step, v }
    }
    fn at(&self, d: f64) -> f64 {
        let x = d.abs() / self.step;
        let i = x.floor() as usize;
        if i >= KB_TABLE {
            return 0.0;
        }
        let f = x - i as f64;
        self.v[i] * (1.0 - f) + self.v[i + 1] * f
    }
}

/// One axis' taps at `kappa`: crop indices and weights (weights 0 outside the crop).
fn taps(
    pack: &Pack,
    kb: &KbTable,
    kappa: f64,
    axis: usize,
    idx: &mut [usize],
    w: &mut [f32],
) -> bool {
    let m = &pack.manifest;
    let (half, n) = (if axis == 0 { m.crop.kx } else { m.crop.ky }, m.kernel.taps);
    let k0 = kernel::first_tap(kappa, n);
    let mut any = false;
    for j in 0..n {
        let k = k0 + j as i64;
        if k < -half || k > half {
            w[j] = 0.0;
            idx[j] = 0;
            continue;
        }
        let d = kappa - k as f64;
        w[j] = match m.model {
            Model::Window => kb.at(d),
            Model::Tiled => kernel::gauss(d, m.kernel.sigma_bins[axis]),
        } as f32;
        idx[j] = (k + half) as usize;
        any |= w[j] != 0.0;
    }
    any
}

/// `y += a x`.
#[inline]
fn axpy(y: &mut [f32], a: f32, x: &[f32]) {
    for (yv, xv) in y.iter_mut().zip(x) {
        *yv += a * xv;
    }
}

/// Dot product with eight partial sums (so that it vectorises; fixed order, so
/// the result does not depend on the machine's thread count).
#[inline]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0.0f32; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut s = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    acc.iter().sum::<f32>() + s
}

/// Build the response map of `pack`.
pub fn build(pack: &Pack, o: &Options) -> Response {
    let m = &pack.manifest;
    let g = o.grid.unwrap_or_else(|| auto_grid(pack, o.budget_bytes));
    let nt = m.terms;
    let (cw, ch) = (m.crop.width, m.crop.height);
    // Terms tap-major (the N values of one texel contiguous), rearranged so that
    // c_n F_n = i^n a_n F_n becomes two real dot products: A = a.G + i a.H with
    // G_n = Re F_n, H_n = Im F_n for even n and G_n = -Im F_n, H_n = Re F_n for odd n.
    let mut tg = vec![0.0f32; cw * ch * nt];
    let mut th_ = vec![0.0f32; cw * ch * nt];
    for n in 0..nt {
        for ty in 0..ch {
            for tx in 0..cw {
                let [re, im] = pack.texel(n, tx, ty);
                let o = (ty * cw + tx) * nt + n;
                (tg[o], th_[o]) = if n % 2 == 0 { (re, im) } else { (-im, re) };
            }
        }
    }
    let lw = wavelength_weights(o.lambda_samples);
    let h = m.height_half_range_m;
    let ntaps = m.kernel.taps;
    let kb = KbTable::new(ntaps, m.kernel.beta);
    let rows: Vec<Vec<f32>> = (0..g.n_rho)
        .into_par_iter()
        .map(|j| {
            let r = g.r_at(j);
            let wmax = (4.0 - r * r).max(0.0).sqrt();
            // c_n(t) = i^n a_n with a_n real (both bases), for every (wavelength, s).
            let mut coef = vec![0.0f32; lw.len() * g.n_s * nt];
            for (l, (lambda, _)) in lw.iter().enumerate() {
                for k in 0..g.n_s {
                    let w = -g.s_at(k) * wmax;
                    let t = std::f64::consts::TAU / lambda * w * h;
                    let c = series::coefficients_f64(m.basis, t, nt);
                    let base = (l * g.n_s + k) * nt;
                    for (n, cn) in c.iter().enumerate() {
                        coef[base + n] = if n % 2 == 0 { cn[0] } else { cn[1] } as f32;
                    }
                }
            }
            let mut out = vec![0.0f32; g.n_theta * g.n_s * 3];
            let (mut ix, mut iy) = (vec![0usize; ntaps], vec![0usize; ntaps]);
            let (mut wx, mut wy) = (vec![0.0f32; ntaps], vec![0.0f32; ntaps]);
            let (mut gr, mut hi) = (vec![0.0f32; nt], vec![0.0f32; nt]);
            let mut rs = vec![0.0f32; g.n_s];
            for i in 0..g.n_theta {
                let th = g.theta_at(i);
                let (cu, su) = (r * th.cos(), r * th.sin());
                for (l, (lambda, wt)) in lw.iter().enumerate() {
                    let kx = -cu / lambda * m.bin_scale_m[0];
                    let ky = -su / lambda * m.bin_scale_m[1];
                    if !taps(pack, &kb, kx, 0, &mut ix, &mut wx)
                        || !taps(pack, &kb, ky, 1, &mut iy, &mut wy)
                    {
                        continue;
                    }
                    let cl = &coef[l * g.n_s * nt..(l + 1) * g.n_s * nt];
                    match m.model {
                        Model::Window => {
                            gr.iter_mut().for_each(|v| *v = 0.0);
                            hi.iter_mut().for_each(|v| *v = 0.0);
                            for (a, &yy) in iy.iter().enumerate() {
                                if wy[a] == 0.0 {
                                    continue;
                                }
                                for (b, &xx) in ix.iter().enumerate() {
                                    let wgt = wy[a] * wx[b];
                                    if wgt == 0.0 {
                                        continue;
                                    }
                                    let o = (yy * cw + xx) * nt;
                                    axpy(&mut gr, wgt, &tg[o..o + nt]);
                                    axpy(&mut hi, wgt, &th_[o..o + nt]);
                                }
                            }
                            for (k, rk) in rs.iter_mut().enumerate() {
                                let c = &cl[k * nt..(k + 1) * nt];
                                let (are, aim) = (dot(c, &gr), dot(c, &hi));
                                *rk = are * are + aim * aim;
                            }
                        }
                        Model::Tiled => {
                            rs.iter_mut().for_each(|v| *v = 0.0);
                            for (a, &yy) in iy.iter().enumerate() {
                                for (b, &xx) in ix.iter().enumerate() {
                                    let wgt = wy[a] * wx[b];
                                    if wgt == 0.0 {
                                        continue;
                                    }
                                    let o = (yy * cw + xx) * nt;
                                    let (sg, sh) = (&tg[o..o + nt], &th_[o..o + nt]);
                                    for (k, rk) in rs.iter_mut().enumerate() {
                                        let c = &cl[k * nt..(k + 1) * nt];
                                        let (are, aim) = (dot(c, sg), dot(c, sh));
                                        *rk += wgt * (are * are + aim * aim);
                                    }
                                }
                            }
                        }
                    }
                    let wt = wt.map(|v| v as f32);
                    for (k, rk) in rs.iter().enumerate() {
                        let o = (k * g.n_theta + i) * 3;
                        out[o] += rk * wt[0];
                        out[o + 1] += rk * wt[1];
                        out[o + 2] += rk * wt[2];
                    }
                }
            }
            out
        })
        .collect();
    let mut data = vec![0u16; g.texels() * 4];
    for (j, row) in rows.iter().enumerate() {
        for k in 0..g.n_s {
            for i in 0..g.n_theta {
                let src = (k * g.n_theta + i) * 3;
                let dst = ((k * g.n_rho + j) * g.n_theta + i) * 4;
                for c in 0..3 {
                    data[dst + c] = half::f16::from_f32(row[src + c].max(0.0)).to_bits();
                }
                data[dst + 3] = half::f16::ONE.to_bits();
            }
        }
    }
    Response {
        info: Info {
            format: FORMAT.to_string(),
            version: VERSION,
            generator: format!("sunbeam-response {}", env!("CARGO_PKG_VERSION")),
            grid: g,
            lambda_samples: lw.len(),
            lambda_range_nm: [cie::DEFAULT_RANGE_NM.0, cie::DEFAULT_RANGE_NM.1],
            quantity: "XYZ without G: sum_l R(u, v, w, l) S(l) cmf(l) / sum_l S(l) ybar(l)"
                .to_string(),
            pack: m.clone(),
        },
        data,
    }
}
