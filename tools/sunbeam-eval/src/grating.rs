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
//! For each wavelength the brightest non-specular peak of `R(theta_r)` (beyond
//! the specular lobe, or beyond `--max-period`) is refined by golden-section
//! search on the continuous `R`, and the period follows from the first-order
//! (`--order m`) grating equation `sin th_r = m lambda / d - sin th_i`:
//! `d = m sum(lambda^2) / sum(lambda (sin th_i + sin th_r))` (least squares).

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
}

fn r_at(src: &Source, o: &Options, lambda: f64, theta_r: f64) -> f64 {
    let (ca, sa) = (o.azimuth.cos(), o.azimuth.sin());
    let (si, ci) = o.theta_i.sin_cos();
    let (sr, cr) = theta_r.sin_cos();
    let wi = [si * ca, si * sa, ci];
    let wr = [sr * ca, sr * sa, cr];
    src.reflectance(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2], lambda)
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
    let fmin = o.min_frequency.unwrap_or_else(|| src.specular_halfwidth());
    let si = o.theta_i.sin();

    let peaks: Vec<Option<Peak>> = par_map(nl, |li| {
        let l = lambdas[li];
        let row = &response[li];
        let mut best: Option<usize> = None;
        for (j, &r) in row.iter().enumerate() {
            let f = (si + angles[j].sin()) / l;
            if f.abs() < fmin || !r.is_finite() {
                continue;
            }
            if best.is_none_or(|b| r > row[b]) {
                best = Some(j);
            }
        }
        let j = best?;
        if row[j] <= 0.0 {
            return None;
        }
        // Golden-section refinement on the continuous R within one step each side.
        let (mut a, mut b) = (angles[j] - o.angle_step, angles[j] + o.angle_step);
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
        let (th, r) = if r >= row[j] {
            (th, r)
        } else {
            (angles[j], row[j])
        };
        Some(Peak {
            lambda_m: l,
            theta_r_deg: th.to_degrees(),
            r,
            f: (si + th.sin()) / l,
        })
    });
    let peaks: Vec<Peak> = peaks.into_iter().flatten().collect();
    if peaks.is_empty() {
        return Err(Error::input(
            "no diffraction peak beyond the specular lobe at any wavelength (patch too small for its period? try --tile or --max-period)",
        ));
    }
    let m = o.order as f64;
    let (mut sll, mut sls) = (0.0, 0.0);
    let mut ds = Vec::new();
    for p in &peaks {
        let s = si + p.theta_r_deg.to_radians().sin();
        sll += p.lambda_m * p.lambda_m;
        sls += p.lambda_m * s;
        ds.push(m * p.lambda_m / s);
    }
    let period = (m * sll / sls).abs();
    let mean = ds.iter().sum::<f64>() / ds.len() as f64;
    let sd = (ds.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / ds.len() as f64).sqrt();
    Ok(Outcome {
        lambdas,
        angles_deg: angles.iter().map(|a| a.to_degrees()).collect(),
        response,
        peaks,
        period_m: period,
        period_mean_m: mean.abs(),
        period_std_m: sd,
        min_frequency: fmin,
    })
}

/// The viewing angle (degrees) the grating equation predicts, if visible.
pub fn grating_angle_deg(theta_i: f64, order: i32, lambda: f64, d: f64) -> Option<f64> {
    let s = order as f64 * lambda / d - theta_i.sin();
    (s.abs() < 1.0).then(|| s.asin().to_degrees())
}
