//! Building a pack from a height field (PHYSICS.md 3, docs/PACK_FORMAT.md).
//!
//! Per term n (streamed: only the current basis term, one row-transform buffer
//! and the stored crop are held):
//! 1. `B_n(s)` with `s = (h - hc) / H` (Chebyshev recurrence or powers), rows
//!    flipped so the row index runs up the image (y up);
//! 2. times the separable weight `q = wx[c] wy[r]`: window model
//!    `g / phihat / sum g` (Gaussian window divided by the Kaiser-Bessel
//!    transform = deapodisation), tiled model `1 / (Mx My)`;
//! 3. zero-padded real FFT of each row (length Nx = Z Mx), keeping bins 0..=Kx;
//! 4. complex FFT of each kept column (length Ny = Z My), keeping bins -Ky..=Ky;
//! 5. phase centring `exp(2 pi i (kx cx / Nx + ky cy / Ny))` with (cx, cy) the
//!    patch centre in pixels, and the negative kx half from Hermitian symmetry.

use crate::kernel;
use crate::manifest::{
    Basis, Crop, ErrorInfo, Kernel, Manifest, Model, Patch, Precision, Source, FORMAT_NAME,
    FORMAT_VERSION,
};
use crate::pack::Pack;
use crate::series;
use rayon::prelude::*;
use realfft::RealFftPlanner;
use rustfft::num_complex::Complex64;
use rustfft::FftPlanner;
use sunbeam_common::{Error, Result};

/// Largest crop side accepted (GPU texture limits are 8192-16384).
pub const MAX_CROP_SIDE: usize = 16384;

/// A borrowed height field (metres, row 0 at the top).
#[derive(Debug, Clone, Copy)]
pub struct FieldRef<'a> {
    pub width: usize,
    pub height: usize,
    pub dx: f64,
    pub dy: f64,
    pub data: &'a [f64],
}

/// What to build.
#[derive(Debug, Clone)]
pub struct BuildOptions {
    pub basis: Basis,
    pub model: Model,
    pub coherence_m: f64,
    pub lambda_min_m: f64,
    pub lambda_max_m: f64,
    /// Bound on max |dR| that picks the term count (ignored when `terms` is set).
    pub max_error: f64,
    pub terms: Option<usize>,
    pub precision: Precision,
    /// Largest |w| (2 reaches grazing light and view).
    pub max_w: f64,
    /// Largest |fx|, |fy| to store, cycles per metre; None: 2 / lambda_min on both axes.
    pub freq_limit_per_m: Option<[f64; 2]>,
    /// Kaiser-Bessel taps per axis (window model), even.
    pub taps: usize,
    /// Worker threads (results do not depend on it).
    pub threads: usize,
    /// Written into the manifest's `generator` (tool name and version).
    pub generator: String,
    pub source: Source,
    pub notes: Vec<String>,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            basis: Basis::Chebyshev,
            model: Model::Window,
            coherence_m: 65e-6,
            lambda_min_m: 380e-9,
            lambda_max_m: 780e-9,
            max_error: 1e-4,
            terms: None,
            precision: Precision::F32,
            max_w: 2.0,
            freq_limit_per_m: None,
            taps: 6,
            threads: std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1)
                .min(8),
            generator: format!("sunbeam-pack {}", env!("CARGO_PKG_VERSION")),
            source: Source::default(),
            notes: vec![],
        }
    }
}

/// Warnings about the input (coarse sampling, tilt), for the tool to print.
pub fn check_field(f: FieldRef, lambda_min_m: f64) -> Vec<String> {
    let mut w = vec![];
    let coarse = 30e-9 * lambda_min_m / 380e-9;
    if f.dx > coarse * 1.0001 || f.dy > coarse * 1.0001 {
        w.push(format!(
            "pixel size {:.1} x {:.1} nm is coarser than ~{:.0} nm for lambda_min {:.0} nm: expect aliasing errors \
             (PHYSICS.md 3); resample finer with sunbeam-import --pixel-size",
            f.dx * 1e9,
            f.dy * 1e9,
            coarse * 1e9,
            lambda_min_m * 1e9
        ));
    }
    if let Some((a, b, range)) = plane_fit(f) {
        let span = a.abs() * f.width as f64 + b.abs() * f.height as f64;
        if range > 0.0 && span > 0.5 * range && f.width > 2 && f.height > 2 {
            w.push(format!(
                "the height field looks tilted (a fitted plane spans {:.1} nm of the {:.1} nm range): \
                 level it with sunbeam-import (plane levelling) unless the tilt is real",
                span * 1e9,
                range * 1e9
            ));
        }
    }
    w
}

/// Least-squares plane h = a c + b r + c0 (per pixel); returns (a, b, peak-to-peak range).
fn plane_fit(f: FieldRef) -> Option<(f64, f64, f64)> {
    let (mx, my) = (f.width as f64, f.height as f64);
    let (cx, cy) = ((mx - 1.0) / 2.0, (my - 1.0) / 2.0);
    let (mut sxh, mut syh, mut sxx, mut syy, mut mean) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for r in 0..f.height {
        for c in 0..f.width {
            let h = f.data[r * f.width + c];
            mean += h;
            lo = lo.min(h);
            hi = hi.max(h);
        }
    }
    mean /= mx * my;
    for r in 0..f.height {
        for c in 0..f.width {
            let h = f.data[r * f.width + c] - mean;
            let (x, y) = (c as f64 - cx, r as f64 - cy);
            sxh += x * h;
            syh += y * h;
            sxx += x * x;
            syy += y * y;
        }
    }
    if sxx == 0.0 || syy == 0.0 {
        return None;
    }
    Some((sxh / sxx, syh / syy, hi - lo))
}

/// Everything derived before the FFTs (also what `--json` reports).
#[derive(Debug, Clone)]
pub struct Plan {
    pub manifest: Manifest,
    /// Row weights wx[c] and column weights wy[r_up] (r_up = My-1-r).
    wx: Vec<f64>,
    wy: Vec<f64>,
}

/// Validate the field and options and derive the manifest (no FFT yet).
pub fn plan(f: FieldRef, o: &BuildOptions) -> Result<Plan> {
    if f.width == 0 || f.height == 0 || f.data.len() != f.width * f.height {
        return Err(Error::input(format!(
            "height field {}x{} with {} values",
            f.width,
            f.height,
            f.data.len()
        )));
    }
    if !(f.dx.is_finite() && f.dx > 0.0 && f.dy.is_finite() && f.dy > 0.0) {
        return Err(Error::input("pixel size must be finite and positive"));
    }
    let bad = f.data.iter().filter(|v| !v.is_finite()).count();
    if bad > 0 {
        return Err(Error::input(format!(
            "height field has {bad} NaN/Inf heights: fill them first (sunbeam-import --fill-nonfinite)"
        )));
    }
    let pos = |v: f64| v.is_finite() && v > 0.0;
    if !(pos(o.lambda_min_m) && pos(o.lambda_max_m) && o.lambda_max_m >= o.lambda_min_m) {
        return Err(Error::usage(
            "wavelength range must be positive with min <= max",
        ));
    }
    if !pos(o.coherence_m) {
        return Err(Error::usage("coherence length must be positive"));
    }
    if !(o.max_w.is_finite() && o.max_w >= 0.0 && o.max_w <= 2.0) {
        return Err(Error::usage("--max-w must be in [0, 2]"));
    }
    if o.terms.is_none() && !(o.max_error.is_finite() && o.max_error > 0.0) {
        return Err(Error::usage("--max-error must be positive"));
    }
    if let Some(n) = o.terms {
        if n == 0 || n > 1024 {
            return Err(Error::usage("--terms must be 1..1024"));
        }
    }
    if o.taps < 2 || o.taps & 1 == 1 || o.taps > 32 {
        return Err(Error::usage("taps must be even, 2..32"));
    }
    let (mx, my) = (f.width, f.height);
    let (lx, ly) = (mx as f64 * f.dx, my as f64 * f.dy);
    let (lo, hi) = f
        .data
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let hc = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    let t_max = 2.0 * std::f64::consts::PI / o.lambda_min_m * o.max_w * half;

    let (terms, tolerance) = match o.terms {
        Some(n) => (n, None),
        None => (
            series::terms_for_tolerance(o.basis, t_max, o.max_error),
            Some(o.max_error),
        ),
    };
    if terms > 1024 {
        return Err(Error::input(format!(
            "{terms} terms needed for |t| = {t_max:.1} with the {:?} basis: the field is too tall for this wavelength range",
            o.basis
        )));
    }

    let flim = o.freq_limit_per_m.unwrap_or([2.0 / o.lambda_min_m; 2]);
    if !(flim.iter().all(|v| v.is_finite() && *v >= 0.0)) {
        return Err(Error::usage("frequency limit must be finite"));
    }
    let sigma_s = o.coherence_m / 4.0;
    let (z, kern, bin_scale) = match o.model {
        Model::Window => {
            let beta = kernel::kb_beta(o.taps);
            (
                2usize,
                Kernel {
                    kind: "kaiser-bessel".into(),
                    taps: o.taps,
                    beta,
                    sigma_bins: [0.0, 0.0],
                },
                [2.0 * lx, 2.0 * ly],
            )
        }
        Model::Tiled => {
            let sigma_f = 1.0 / (2.0 * std::f64::consts::PI * sigma_s);
            let sb = [sigma_f * lx, sigma_f * ly];
            let taps = kernel::gauss_taps(sb[0].max(sb[1]));
            (
                1usize,
                Kernel {
                    kind: "gaussian".into(),
                    taps,
                    beta: 0.0,
                    sigma_bins: sb,
                },
                [lx, ly],
            )
        }
    };
    let half_taps = (kern.taps / 2) as i64;
    let kx = (flim[0] * bin_scale[0]).ceil() as i64 + half_taps;
    let ky = (flim[1] * bin_scale[1]).ceil() as i64 + half_taps;
    let (cw, ch) = (2 * kx as usize + 1, 2 * ky as usize + 1);
    if cw > MAX_CROP_SIDE || ch > MAX_CROP_SIDE {
        return Err(Error::input(format!(
            "the stored spectrum would be {cw}x{ch} texels (over {MAX_CROP_SIDE}): the patch is too large for \
             lambda_min; crop the height field or bound the directions with --scene"
        )));
    }
    let (nx, ny) = (z * mx, z * my);
    let (cx, cy) = ((mx as f64 - 1.0) / 2.0, (my as f64 - 1.0) / 2.0);

    let (wx, wy, window_sigma, norm_name, norm_value) = match o.model {
        Model::Window => {
            // The window acts on the amplitude: sqrt 2 narrower than the
            // tiled model's Gaussian on the power, so that a flat patch's lobe
            // |FT g|^2 is exactly the tiled model's phi (PHYSICS.md 2).
            let sigma = (sigma_s / std::f64::consts::SQRT_2).min(lx.min(ly) / 6.0);
            let gx: Vec<f64> = (0..mx)
                .map(|c| (-((c as f64 - cx) * f.dx).powi(2) / (2.0 * sigma * sigma)).exp())
                .collect();
            let gy: Vec<f64> = (0..my)
                .map(|r| (-((r as f64 - cy) * f.dy).powi(2) / (2.0 * sigma * sigma)).exp())
                .collect();
            let sum_g = gx.iter().sum::<f64>() * gy.iter().sum::<f64>();
            let wx: Vec<f64> = (0..mx)
                .map(|c| gx[c] / kernel::kb_hat((c as f64 - cx) / nx as f64, kern.taps, kern.beta))
                .collect();
            let wy: Vec<f64> = (0..my)
                .map(|r| {
                    gy[r]
                        / kernel::kb_hat((r as f64 - cy) / ny as f64, kern.taps, kern.beta)
                        / sum_g
                })
                .collect();
            (wx, wy, sigma, "sum_g", sum_g)
        }
        Model::Tiled => {
            let n = (mx * my) as f64;
            (vec![1.0; mx], vec![1.0 / n; my], 0.0, "mx_my", n)
        }
    };

    let mut series_bound = series::tail_bound_upto(o.basis, t_max, terms);
    if o.model == Model::Tiled {
        // R sums |.|^2 over bins weighted by phi: the bound scales with the largest sum of weights.
        let s: f64 = kern
            .sigma_bins
            .iter()
            .map(|sb| (2.0 * std::f64::consts::PI).sqrt() * sb.max(1.0 / 2.5))
            .product();
        series_bound *= s.max(1.0);
    }
    let manifest = Manifest {
        format: FORMAT_NAME.into(),
        version: FORMAT_VERSION,
        generator: o.generator.clone(),
        model: o.model,
        basis: o.basis,
        terms,
        precision: o.precision,
        patch: Patch {
            width: mx,
            height: my,
            dx_m: f.dx,
            dy_m: f.dy,
            lx_m: lx,
            ly_m: ly,
        },
        height_centre_m: hc,
        height_half_range_m: half,
        lambda_min_m: o.lambda_min_m,
        lambda_max_m: o.lambda_max_m,
        max_w: o.max_w,
        t_max,
        coherence_m: o.coherence_m,
        window_sigma_m: window_sigma,
        sigma_f_per_m: if o.model == Model::Tiled {
            1.0 / (2.0 * std::f64::consts::PI * sigma_s)
        } else {
            0.0
        },
        padding: z,
        grid: [nx, ny],
        bin_scale_m: bin_scale,
        freq_limit_per_m: flim,
        crop: Crop {
            kx,
            ky,
            width: cw,
            height: ch,
        },
        kernel: kern,
        normalisation: norm_name.into(),
        normalisation_value: norm_value,
        error: ErrorInfo {
            tolerance,
            series_bound,
            f32_rounding_estimate: series::f32_rounding_estimate(o.basis, t_max, terms),
            terms_fixed: o.terms.is_some(),
        },
        source: o.source.clone(),
        notes: o.notes.clone(),
        rms_slope: Some(rms_slope(f, window_sigma)),
    };
    manifest
        .validate()
        .map_err(|e| Error::internal(e.message))?;
    Ok(Plan { manifest, wx, wy })
}

/// rms slopes `[rms dh/dx, rms dh/dy]` of the field (sunbeam_optics::masking),
/// weighted like the terms: by the coherence window `sigma` (the window model;
/// the part of the relief the response sees) or uniformly (`sigma` 0, the tiled
/// model). Central differences, one-sided at the edges, periodic for the tiled
/// model (its patch repeats).
fn rms_slope(f: FieldRef, sigma: f64) -> [f64; 2] {
    let (mx, my) = (f.width, f.height);
    let tiled = sigma <= 0.0;
    let weights = |n: usize, d: f64| -> Vec<f64> {
        let c = (n as f64 - 1.0) / 2.0;
        (0..n)
            .map(|i| {
                if tiled {
                    1.0
                } else {
                    (-((i as f64 - c) * d).powi(2) / (2.0 * sigma * sigma)).exp()
                }
            })
            .collect()
    };
    let (gx, gy) = (weights(mx, f.dx), weights(my, f.dy));
    // (lower index, upper index, their distance in samples) of the difference at i
    let stencil = |i: usize, n: usize| -> (usize, usize, f64) {
        if tiled {
            ((i + n - 1) % n, (i + 1) % n, 2.0)
        } else if i == 0 {
            (0, 1, 1.0)
        } else if i == n - 1 {
            (n - 2, n - 1, 1.0)
        } else {
            (i - 1, i + 1, 2.0)
        }
    };
    if mx < 2 || my < 2 {
        return [0.0, 0.0];
    }
    let h = |c: usize, r: usize| f.data[r * mx + c];
    let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
    for (r, wy) in gy.iter().enumerate() {
        let (r0, r1, nr) = stencil(r, my);
        for (c, wx) in gx.iter().enumerate() {
            let (c0, c1, nc) = stencil(c, mx);
            let w = wx * wy;
            let dx = (h(c1, r) - h(c0, r)) / (nc * f.dx);
            let dy = (h(c, r1) - h(c, r0)) / (nr * f.dy);
            sx += w * dx * dx;
            sy += w * dy * dy;
            sw += w;
        }
    }
    [(sx / sw).sqrt(), (sy / sw).sqrt()]
}

/// Run `job` on `pool` (a fixed thread count), or on rayon's global pool.
fn in_pool<R: Send>(pool: &Option<rayon::ThreadPool>, job: impl FnOnce() -> R + Send) -> R {
    match pool {
        Some(p) => p.install(job),
        None => job(),
    }
}

/// Build the pack. `progress(done, total)` is called after each term.
pub fn build(
    f: FieldRef,
    o: &BuildOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Pack> {
    let p = plan(f, o)?;
    run(f, &p, o.threads, progress)
}

/// Run a plan: the FFTs, term by term.
pub fn run(
    f: FieldRef,
    p: &Plan,
    threads: usize,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Pack> {
    let m = &p.manifest;
    let (mx, my) = (f.width, f.height);
    let [nx, ny] = m.grid;
    let (kx, ky) = (m.crop.kx, m.crop.ky);
    let (cw, chh) = (m.crop.width, m.crop.height);
    let ncols = kx as usize + 1;
    let inv_h = if m.height_half_range_m > 0.0 {
        1.0 / m.height_half_range_m
    } else {
        0.0
    };
    let hc = m.height_centre_m;
    let (cx, cy) = ((mx as f64 - 1.0) / 2.0, (my as f64 - 1.0) / 2.0);

    let r2c = RealFftPlanner::<f64>::new().plan_fft_forward(nx);
    let cfft = FftPlanner::<f64>::new().plan_fft_forward(ny);

    // Phase factors per kept bin.
    let two_pi = 2.0 * std::f64::consts::PI;
    let phx: Vec<Complex64> = (0..=kx)
        .map(|k| Complex64::from_polar(1.0, two_pi * ((k as f64 * cx) / nx as f64).fract()))
        .collect();
    let phy: Vec<Complex64> = (-ky..=ky)
        .map(|k| Complex64::from_polar(1.0, two_pi * ((k as f64 * cy) / ny as f64).fract()))
        .collect();

    // Basis state in y-up row order: prev = B_{n-2}, cur = B_{n-1}.
    let s_at = |ru: usize, c: usize| (f.data[(my - 1 - ru) * mx + c] - hc) * inv_h;
    let mut prev = vec![0.0f64; mx * my];
    let mut cur = vec![0.0f64; mx * my];
    let mut rowbuf = vec![Complex64::new(0.0, 0.0); my * ncols];
    let lt = cw * chh;
    let mut terms = vec![0.0f32; 2 * lt * m.terms];
    // `threads` workers (0: all cores); the output does not depend on it: every
    // row and column is one task with its own fixed-order arithmetic.
    let pool = match threads {
        0 => None,
        n => rayon::ThreadPoolBuilder::new().num_threads(n).build().ok(),
    };

    for n in 0..m.terms {
        // 1+2+3: basis term and row FFTs, one task per row.
        {
            let basis = m.basis;
            let (wx, wy) = (&p.wx, &p.wy);
            let (prev, cur, rowbuf, r2c, s_at) = (&mut prev, &mut cur, &mut rowbuf, &r2c, &s_at);
            in_pool(&pool, move || {
                let rows = prev
                    .par_chunks_mut(mx)
                    .zip(cur.par_chunks_mut(mx))
                    .zip(rowbuf.par_chunks_mut(ncols))
                    .enumerate();
                rows.for_each_init(
                    || {
                        (
                            r2c.make_input_vec(),
                            r2c.make_output_vec(),
                            r2c.make_scratch_vec(),
                        )
                    },
                    |(input, output, scratch), (ru, ((pv, cv), out_row))| {
                        for c in 0..mx {
                            let b = match (basis, n) {
                                (_, 0) => 1.0,
                                (_, 1) => s_at(ru, c),
                                (Basis::Chebyshev, _) => 2.0 * s_at(ru, c) * cv[c] - pv[c],
                                (Basis::Taylor, _) => s_at(ru, c) * cv[c],
                            };
                            pv[c] = cv[c];
                            cv[c] = b;
                            input[c] = b * wx[c] * wy[ru];
                        }
                        input[mx..].iter_mut().for_each(|v| *v = 0.0);
                        r2c.process_with_scratch(input, output, scratch)
                            .expect("fft sizes");
                        for (k, o) in out_row.iter_mut().enumerate() {
                            let kk = k % nx;
                            *o = if kk <= nx / 2 {
                                output[kk]
                            } else {
                                output[nx - kk].conj()
                            };
                        }
                    },
                );
            });
        }
        // 4+5: column FFTs, one task per column (results in column order); scatter serially.
        let rowbuf = &rowbuf;
        let results: Vec<Vec<Complex64>> = in_pool(&pool, || {
            (0..ncols)
                .into_par_iter()
                .map_init(
                    || {
                        (
                            vec![Complex64::new(0.0, 0.0); ny],
                            vec![Complex64::new(0.0, 0.0); cfft.get_inplace_scratch_len()],
                        )
                    },
                    |(buf, scratch), k| {
                        for (ru, b) in buf.iter_mut().enumerate().take(my) {
                            *b = rowbuf[ru * ncols + k];
                        }
                        buf[my..]
                            .iter_mut()
                            .for_each(|v| *v = Complex64::new(0.0, 0.0));
                        cfft.process_with_scratch(buf, scratch);
                        (-ky..=ky)
                            .enumerate()
                            .map(|(j, kyv)| {
                                let kk = kyv.rem_euclid(ny as i64) as usize;
                                buf[kk] * phx[k] * phy[j]
                            })
                            .collect()
                    },
                )
                .collect()
        });
        let layer = &mut terms[2 * n * lt..2 * (n + 1) * lt];
        // Tiled model: each DFT bin once, b in [-floor(M/2), M-1-floor(M/2)] per axis (no periodic images).
        let tiled = m.model == Model::Tiled;
        let in_range = |k: i64, mm: usize| {
            let lo = -((mm / 2) as i64);
            !tiled || (k >= lo && k < lo + mm as i64)
        };
        for (k, res) in results.iter().enumerate() {
            {
                for (j, &v) in res.iter().enumerate().take(chh) {
                    let kys = j as i64 - ky;
                    let (tx, ty) = (kx as usize + k, j);
                    let (txn, tyn) = (kx as usize - k, chh - 1 - j);
                    let a = 2 * (ty * cw + tx);
                    let ok = in_range(k as i64, mx) && in_range(kys, my);
                    layer[a] = if ok { v.re as f32 } else { 0.0 };
                    layer[a + 1] = if ok { v.im as f32 } else { 0.0 };
                    if k != 0 {
                        let b = 2 * (tyn * cw + txn);
                        let ok = in_range(-(k as i64), mx) && in_range(-kys, my);
                        layer[b] = if ok { v.re as f32 } else { 0.0 };
                        layer[b + 1] = if ok { -v.im as f32 } else { 0.0 };
                    }
                }
            }
        }
        if m.precision == Precision::F16 {
            for v in layer.iter_mut() {
                *v = half::f16::from_f32(*v).to_f32();
            }
        }
        if layer.iter().any(|v| !v.is_finite()) {
            return Err(Error::internal(format!(
                "term {n} holds NaN/Inf (a bug; please report)"
            )));
        }
        progress(n + 1, m.terms);
    }
    Pack::new(m.clone(), terms).map_err(|e| Error::internal(e.message))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_pixels(width: usize, height: usize, d: f64, data: &[f64]) -> FieldRef<'_> {
        FieldRef {
            width,
            height,
            dx: d,
            dy: d,
            data,
        }
    }

    /// A tilted plane has the same slope everywhere: the rms is the slope,
    /// whatever the window (central and one-sided differences are exact on it).
    #[test]
    fn rms_slope_of_a_plane_is_its_slope() {
        let (mx, my, d) = (40, 30, 20e-9);
        let data: Vec<f64> = (0..mx * my)
            .map(|i| 0.3 * (i % mx) as f64 * d - 0.1 * (i / mx) as f64 * d)
            .collect();
        let f = square_pixels(mx, my, d, &data);
        for sigma in [0.2e-6, 1.0] {
            let s = rms_slope(f, sigma);
            assert!(
                (s[0] - 0.3).abs() < 1e-12 && (s[1] - 0.1).abs() < 1e-12,
                "{sigma}: {s:?}"
            );
        }
    }

    /// Tiled: a sinusoid of amplitude A along x, one period per patch: rms of
    /// the derivative A k / sqrt(2) (k = 2 pi / L), times the central
    /// difference's sinc(k dx) (sin(k dx) / (k dx)); none along y.
    #[test]
    fn rms_slope_of_a_tiled_sinusoid() {
        let (mx, my, d, a) = (64, 8, 25e-9, 100e-9);
        let k = 2.0 * std::f64::consts::PI / (mx as f64 * d);
        let data: Vec<f64> = (0..mx * my)
            .map(|i| a * (k * (i % mx) as f64 * d).sin())
            .collect();
        let f = square_pixels(mx, my, d, &data);
        let s = rms_slope(f, 0.0);
        let want = a * k / 2f64.sqrt() * (k * d).sin() / (k * d);
        assert!(
            (s[0] - want).abs() < 1e-12 * want && s[1] < 1e-15,
            "{s:?} vs {want}"
        );
        // and the plan writes it into the manifest
        let o = BuildOptions {
            model: Model::Tiled,
            ..BuildOptions::default()
        };
        let p = plan(f, &o).unwrap();
        assert_eq!(p.manifest.rms_slope, Some(s));
    }
}
