//! `sunbeam-eval grating`: the thesis' chapter 4 evaluation (PHYSICS.md 4,
//! last item). Light at `theta_i` in the plane of incidence (the x-z plane of
//! the patch, or rotated by `--azimuth`), the viewer swept over signed angles
//! `theta_r` in the same plane (positive on the light's side):
//!
//! ```text
//! wi = (sin th_i cos a, sin th_i sin a, cos th_i),  wr = (sin th_r cos a, sin th_r sin a, cos th_r)
//! f  = (wi + wr)_xy / lambda,  |f| = (sin th_i + sin th_r) / lambda along the plane
//! ```
//!
//! For each wavelength, every local maximum of `R(theta_r)` beyond the specular
//! peak that is at least 1 % of the brightest one is refined by golden-section
//! search on the continuous `R`. Its spatial frequency `f = (sin th_i + sin th_r)
//! / lambda` is `m / d` for its order `m`, so the orders are found together
//! (`find_orders`): the fundamental `f0` is the largest `|f_b| / n` (`f_b` the
//! brightest peak of a wavelength, n = 1, 2, ...) of which the strong peaks are
//! integer multiples, refitted to every peak it explains; each peak takes the
//! nearest order (one peak per order and wavelength). The period is the least
//! squares fit of the grating equation `sin th_r = m lambda / d - sin th_i` over
//! all peaks with an order, each weighted by its brightness relative to the
//! brightest peak of its wavelength (`w`), leaving out those on the specular
//! lobe's tail: `d = sum w (m lambda)^2 / sum w m lambda (sin th_i + sin th_r)`.
//! With one order visible it cannot be told from the others: the brightest
//! peaks are taken as order `--order` (the thesis' method), and the report says so.

use crate::source::{par_map, Source};
use sunbeam_common::{Error, Result};

#[derive(Debug, Clone)]
pub struct Options {
    pub theta_i: f64,
    pub azimuth: f64,
    pub lambda_min: f64,
    pub lambda_max: f64,
    pub lambda_step: f64,
    pub angle_step: f64,
    pub order: i32,
    /// Peaks with |f| below this (cycles per metre) count as specular.
    pub min_frequency: Option<f64>,
}

#[derive(Debug, Clone)]
pub struct Peak {
    pub lambda_m: f64,
    pub theta_r_deg: f64,
    pub r: f64,
    /// Spatial frequency along the plane, cycles per metre.
    pub f: f64,
    /// Diffraction order (signed); 0 when the peak is no multiple of the
    /// fundamental frequency (left out of the fit).
    pub order: i32,
    /// The brightest peak of its wavelength.
    pub brightest: bool,
    /// R relative to the brightest peak of its wavelength (the weight in the fit).
    pub weight: f64,
    /// Used in the period's fit (has an order, clear of the specular lobe).
    pub in_fit: bool,
}

#[derive(Debug, Clone)]
pub struct Outcome {
    pub lambdas: Vec<f64>,
    pub angles_deg: Vec<f64>,
    /// R[lambda][angle].
    pub response: Vec<Vec<f64>>,
    pub peaks: Vec<Peak>,
    pub period_m: f64,
    pub period_mean_m: f64,
    pub period_std_m: f64,
    pub min_frequency: f64,
    pub orders: Orders,
}

fn r_at(src: &Source, o: &Options, lambda: f64, theta_r: f64) -> f64 {
    let (ca, sa) = (o.azimuth.cos(), o.azimuth.sin());
    let (si, ci) = o.theta_i.sin_cos();
    let (sr, cr) = theta_r.sin_cos();
    let wi = [si * ca, si * sa, ci];
    let wr = [sr * ca, sr * sa, cr];
    src.reflectance(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2], lambda)
}

/// Peaks dimmer than this fraction of the brightest non-specular peak of their
/// wavelength are not taken as orders (speckle, the tiled model's minor bins).
pub const MIN_RELATIVE_R: f64 = 0.01;
/// Peaks at least this fraction of the brightest of their wavelength decide the
/// fundamental frequency (the weaker ones only follow it).
pub const STRONG_RELATIVE_R: f64 = 0.2;
/// A peak belongs to order m when `|f / f0 - m| <= ORDER_TOLERANCE`.
pub const ORDER_TOLERANCE: f64 = 0.2;
/// Share of the strong peaks that the fundamental frequency must explain.
const EXPLAINED_SHARE: f64 = 0.9;
/// Largest divisor of a peak's frequency tried as the fundamental.
const MAX_DIVISOR: usize = 12;

/// Golden-section search for the maximum of R within one scan step of `theta0`.
fn refine(src: &Source, o: &Options, l: f64, theta0: f64, r0: f64, lim: f64) -> (f64, f64) {
    let (mut a, mut b) = (theta0 - o.angle_step, theta0 + o.angle_step);
    a = a.max(-lim);
    b = b.min(lim);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (r_at(src, o, l, c), r_at(src, o, l, d));
    for _ in 0..60 {
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = r_at(src, o, l, c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = r_at(src, o, l, d);
        }
        if (b - a) < 1e-10 {
            break;
        }
    }
    let th = 0.5 * (a + b);
    let r = r_at(src, o, l, th);
    if r >= r0 {
        (th, r)
    } else {
        (theta0, r0)
    }
}

/// The orders of the peaks: the largest fundamental frequency `f0` of which
/// (nearly) every strong peak's frequency is an integer multiple.
#[derive(Debug, Clone)]
pub struct Orders {
    /// Fundamental frequency (cycles per metre), 1/period as the orders say.
    pub f0: f64,
    /// Whether the orders were found from the peaks (at least two different
    /// orders seen); false: a single order is visible, so it cannot be told
    /// from the others and `--order` is assumed.
    pub found: bool,
    pub note: String,
}

/// Assign orders to `peaks` (their `order` field): candidates `f0 = |f_b| / n`
/// from each wavelength's brightest peak `f_b` (n = 1..MAX_DIVISOR), each
/// refitted (least squares of `f = m f0` over the peaks within ORDER_TOLERANCE
/// of an order, so the high orders, whose relative error is smallest, weigh
/// most); the largest that explains 90 % of the strong peaks wins. Each peak
/// takes the nearest order, one peak (the brightest) per order and wavelength.
/// If all have the same order (one order visible), the orders cannot be told
/// apart: the brightest peaks are taken as order `assumed`, the others dropped.
pub fn find_orders(peaks: &mut [Peak], assumed: i32) -> Orders {
    let order_of = |p: &Peak, g: f64| {
        let q = p.f / g;
        let m = q.round();
        (m != 0.0 && (q - m).abs() <= ORDER_TOLERANCE).then_some(m)
    };
    let refit = |mut g: f64| {
        for _ in 0..5 {
            let (smf, smm) = peaks
                .iter()
                .filter_map(|p| order_of(p, g).map(|m| (m * p.f, m * m)))
                .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
            if smm == 0.0 {
                break;
            }
            g = smf / smm;
        }
        g
    };
    let strong: Vec<&Peak> = peaks
        .iter()
        .filter(|p| p.weight >= STRONG_RELATIVE_R)
        .collect();
    let need = (EXPLAINED_SHARE * strong.len() as f64).ceil() as usize;
    let mut cands: Vec<f64> = Vec::new();
    for p in peaks.iter().filter(|p| p.brightest) {
        for n in 1..=MAX_DIVISOR {
            cands.push(p.f.abs() / n as f64);
        }
    }
    cands.sort_by(|a, b| b.total_cmp(a));
    cands.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * *b);
    let g = cands
        .iter()
        .filter(|&&g| g > 0.0)
        .map(|&g| refit(g))
        .find(|&g| strong.iter().filter(|p| order_of(p, g).is_some()).count() >= need);
    // Nearest order, the brightest peak of each (wavelength, order) only.
    let mut orders: Vec<i32> = Vec::new();
    if let Some(g) = g {
        for k in 0..peaks.len() {
            let m = order_of(&peaks[k], g).map_or(0, |m| m as i32);
            let beaten = m != 0
                && peaks.iter().any(|q| {
                    q.lambda_m == peaks[k].lambda_m
                        && order_of(q, g) == Some(m as f64)
                        && (q.r > peaks[k].r || (q.r == peaks[k].r && q.f < peaks[k].f))
                });
            peaks[k].order = if beaten { 0 } else { m };
            if peaks[k].order != 0 {
                orders.push(m);
            }
        }
    }
    orders.sort();
    orders.dedup();
    if let (Some(g), true) = (g, orders.len() >= 2) {
        return Orders {
            f0: g,
            found: true,
            note: format!(
                "orders {} found from the spacing of the peaks",
                orders
                    .iter()
                    .map(|m| m.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
    }
    // One order visible (or no common spacing): the brightest peaks are order `assumed`.
    let mut fb: Vec<f64> = Vec::new();
    for p in peaks.iter_mut() {
        p.order = if p.brightest {
            fb.push(p.f.abs());
            assumed * p.f.signum() as i32
        } else {
            0
        };
    }
    fb.sort_by(f64::total_cmp);
    let why = if g.is_some() {
        "only one order is visible"
    } else {
        "no common spacing explains the peaks"
    };
    Orders {
        f0: fb[fb.len() / 2] / assumed.unsigned_abs() as f64,
        found: false,
        note: format!(
            "orders cannot be told apart ({why}): the brightest peaks are taken as order {assumed} (--order)"
        ),
    }
}

pub fn run(src: &Source, o: &Options) -> Result<Outcome> {
    if o.theta_i.is_nan() || o.theta_i.abs() >= 89.9f64.to_radians() {
        return Err(Error::usage(
            "--theta-i must be within (-89.9, 89.9) degrees",
        ));
    }
    if !(o.lambda_step > 0.0 && o.angle_step > 0.0 && o.angle_step <= 5f64.to_radians()) {
        return Err(Error::usage(
            "--lambda-step must be positive and --angle-step in (0, 5] degrees",
        ));
    }
    if o.order == 0 {
        return Err(Error::usage(
            "--order must not be 0 (the specular order has no period)",
        ));
    }
    let nl = ((o.lambda_max - o.lambda_min) / o.lambda_step + 1e-9).floor() as usize + 1;
    if nl > 100_000 {
        return Err(Error::usage("too many wavelengths (check --lambda-step)"));
    }
    let lambdas: Vec<f64> = (0..nl)
        .map(|i| o.lambda_min + i as f64 * o.lambda_step)
        .collect();
    let lim = 89.5f64.to_radians();
    let na = ((2.0 * lim) / o.angle_step).floor() as usize + 1;
    let angles: Vec<f64> = (0..na).map(|j| -lim + j as f64 * o.angle_step).collect();
    let flat = par_map(nl * na, |k| r_at(src, o, lambdas[k / na], angles[k % na]));
    let response: Vec<Vec<f64>> = flat.chunks(na).map(|c| c.to_vec()).collect();
    // Beyond the specular peak: half the lobe's half width (a quarter bin, tiled; the
    // larger of 0.25/L and 0.3/sigma, window), where its tail is down to ~3 %; a
    // nearer order is still seen when it is a maximum of its own.
    let fmin = o
        .min_frequency
        .unwrap_or_else(|| 0.5 * src.specular_halfwidth());
    let si = o.theta_i.sin();

    // Per wavelength: the local maxima of R beyond the specular lobe that are at
    // least MIN_RELATIVE_R of the brightest one, each refined on the continuous R.
    let mut found: Vec<(usize, usize)> = Vec::new(); // (wavelength, angle index)
    for (li, row) in response.iter().enumerate() {
        let l = lambdas[li];
        let is_max = |j: usize| {
            let r = row[j];
            r.is_finite()
                && r > 0.0
                && j > 0
                && j + 1 < na
                && r > row[j - 1]
                && r >= row[j + 1]
                && ((si + angles[j].sin()) / l).abs() >= fmin
        };
        let maxima: Vec<usize> = (0..na).filter(|&j| is_max(j)).collect();
        let top = maxima.iter().map(|&j| row[j]).fold(0.0, f64::max);
        found.extend(
            maxima
                .into_iter()
                .filter(|&j| row[j] >= MIN_RELATIVE_R * top)
                .map(|j| (li, j)),
        );
    }
    // No lobe resolved at all (a patch of one or two periods under the window):
    // the brightest R beyond the specular lobe per wavelength, as before; the
    // orders then cannot be told apart.
    let unresolved = found.is_empty();
    if unresolved {
        let cut = o.min_frequency.unwrap_or_else(|| src.specular_halfwidth());
        for (li, row) in response.iter().enumerate() {
            let best = (0..na)
                .filter(|&j| {
                    row[j].is_finite()
                        && row[j] > 0.0
                        && ((si + angles[j].sin()) / lambdas[li]).abs() >= cut
                })
                .max_by(|&a, &b| row[a].total_cmp(&row[b]));
            found.extend(best.map(|j| (li, j)));
        }
    }
    let mut peaks: Vec<Peak> = par_map(found.len(), |k| {
        let (li, j) = found[k];
        let l = lambdas[li];
        let (th, r) = refine(src, o, l, angles[j], response[li][j], lim);
        Peak {
            lambda_m: l,
            theta_r_deg: th.to_degrees(),
            r,
            f: (si + th.sin()) / l,
            order: 0,
            brightest: false,
            weight: 0.0,
            in_fit: false,
        }
    });
    if peaks.is_empty() {
        return Err(Error::input(
            "no diffraction peak beyond the specular lobe at any wavelength (patch too small for its period? try --tile or --max-period)",
        ));
    }
    // Brightness relative to the brightest peak of the same wavelength.
    for li in 0..nl {
        let idx: Vec<usize> = (0..peaks.len()).filter(|&k| found[k].0 == li).collect();
        let top = idx.iter().map(|&k| peaks[k].r).fold(0.0, f64::max);
        if let Some(&b) = idx.iter().find(|&&k| peaks[k].r == top) {
            peaks[b].brightest = true;
        }
        for &k in &idx {
            peaks[k].weight = peaks[k].r / top;
        }
    }
    let mut orders = find_orders(&mut peaks, o.order);
    if unresolved {
        orders.found = false;
        orders.note = format!(
            "orders cannot be told apart (no lobe resolved beyond the specular one: the brightest R beyond it is taken as order {}, --order; try --tile or --max-period)",
            o.order
        );
    }
    // The fit: every peak with an order, weighted by its relative brightness;
    // not those on the specular lobe's tail (|f| below its half width, where it
    // pulls them outward) unless nothing else is left.
    let clear = |p: &Peak| o.min_frequency.is_some() || p.f.abs() >= src.specular_halfwidth();
    let any_clear = peaks.iter().any(|p| p.order != 0 && clear(p));
    for p in peaks.iter_mut() {
        p.in_fit = p.order != 0 && (clear(p) || !any_clear);
    }
    let (mut sll, mut sls, mut sw) = (0.0, 0.0, 0.0);
    let mut ds = Vec::new();
    for p in peaks.iter().filter(|p| p.in_fit) {
        let ml = p.order as f64 * p.lambda_m;
        let s = si + p.theta_r_deg.to_radians().sin();
        sll += p.weight * ml * ml;
        sls += p.weight * ml * s;
        sw += p.weight;
        ds.push((p.weight, ml / s));
    }
    let period = (sll / sls).abs();
    let mean = ds.iter().map(|(w, d)| w * d).sum::<f64>() / sw;
    let sd = (ds.iter().map(|(w, d)| w * (d - mean).powi(2)).sum::<f64>() / sw).sqrt();
    Ok(Outcome {
        lambdas,
        angles_deg: angles.iter().map(|a| a.to_degrees()).collect(),
        response,
        peaks,
        period_m: period,
        period_mean_m: mean.abs(),
        period_std_m: sd,
        min_frequency: fmin,
        orders,
    })
}

/// The viewing angle (degrees) the grating equation predicts, if visible.
pub fn grating_angle_deg(theta_i: f64, order: i32, lambda: f64, d: f64) -> Option<f64> {
    let s = order as f64 * lambda / d - theta_i.sin();
    (s.abs() < 1.0).then(|| s.asin().to_degrees())
}
