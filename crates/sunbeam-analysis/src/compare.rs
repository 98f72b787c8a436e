//! `sunbeam-eval compare PACK HEIGHT`: spectral and colour errors of a pack
//! against the ground truth of the height field it was built from
//! (PHYSICS.md 4).

use crate::sample::{fibonacci_hemisphere, percentile, scatter_points};
use crate::source::par_map;
use sunbeam_optics::colour::{self, ToneCurve, ToneMap};
use sunbeam_optics::truth::Truth;
use sunbeam_pack::Pack;

#[derive(Debug, Clone)]
pub struct SpectralError {
    pub points: usize,
    pub max_abs: f64,
    /// max |dR| / R_truth over points with R_truth >= 1e-3.
    pub peak_relative: f64,
    /// max |dR| / R_truth over strong lobes (R_truth >= 1e-2).
    pub strong_relative: f64,
    pub worst: [f64; 4],
}

/// Spectral error over `n` random (wi, wr, lambda) inside what the pack supports
/// (|w| <= max_w, lambda in its range).
pub fn spectral(pack: &Pack, truth: &Truth, n: usize, seed: u64) -> SpectralError {
    let m = &pack.manifest;
    let pts = scatter_points(n, seed, 0.05, m.max_w, (m.lambda_min_m, m.lambda_max_m));
    spectral_at(pack, truth, &pts)
}

pub fn spectral_at(pack: &Pack, truth: &Truth, pts: &[[f64; 4]]) -> SpectralError {
    let res = par_map(pts.len(), |i| {
        let p = pts[i];
        (
            pack.reflectance(p[0], p[1], p[2], p[3]),
            truth.reflectance(p[0], p[1], p[2], p[3]),
        )
    });
    let mut e = SpectralError {
        points: pts.len(),
        max_abs: 0.0,
        peak_relative: 0.0,
        strong_relative: 0.0,
        worst: [0.0; 4],
    };
    for (p, (a, t)) in pts.iter().zip(res) {
        let d = (a - t).abs();
        if d > e.max_abs || !d.is_finite() {
            e.max_abs = if d.is_finite() { d } else { f64::INFINITY };
            e.worst = *p;
        }
        if t >= 1e-3 {
            e.peak_relative = e.peak_relative.max(d / t);
        }
        if t >= 1e-2 {
            e.strong_relative = e.strong_relative.max(d / t);
        }
    }
    e
}

#[derive(Debug, Clone)]
#[allow(dead_code)]
pub struct ColourError {
    pub light: [f64; 3],
    pub views: usize,
    pub exposure_scale: f64,
    pub mean: f64,
    pub p99: f64,
    pub max: f64,
}

/// What a viewer sees: XYZ scaled by the exposure, through the display
/// transform's clamp (linear sRGB clipped to [0, 1]), back to XYZ.
pub fn displayed_xyz(xyz: [f64; 3], scale: f64) -> [f64; 3] {
    let tm = ToneMap {
        exposure_ev: 0.0,
        curve: ToneCurve::Clamp,
    };
    let rgb = colour::xyz_to_linear_srgb(xyz.map(|c| c * scale)).map(|c| tm.apply(c));
    colour::linear_srgb_to_xyz(rgb)
}

/// The true colours (1 nm, with G) for `views` view directions and one light.
pub fn truth_colours(truth: &Truth, pack: &Pack, light: [f64; 3], views: usize) -> Vec<[f64; 3]> {
    let dirs = fibonacci_hemisphere(views, 0.05);
    let range = (
        (pack.manifest.lambda_min_m * 1e9).round() as u32,
        (pack.manifest.lambda_max_m * 1e9).round() as u32,
    );
    par_map(dirs.len(), |i| {
        truth.colour_xyz_with(
            light,
            dirs[i],
            range,
            sunbeam_optics::gain::Material::RELATIVE,
        )
    })
}

/// CIEDE2000 between the pack's colour (`lambda_samples` samples) and the 1 nm
/// truth over `views` view directions for one light. The exposure puts the
/// 95th percentile of the true Y at 1 (the same for both), unless given.
pub fn colour(
    pack: &Pack,
    truth: &Truth,
    light: [f64; 3],
    views: usize,
    lambda_samples: usize,
    exposure_scale: Option<f64>,
) -> ColourError {
    let t = truth_colours(truth, pack, light, views);
    colour_vs(pack, &t, light, lambda_samples, exposure_scale)
}

/// [`colour`] against precomputed true colours (from [`truth_colours`], same light and view count).
pub fn colour_vs(
    pack: &Pack,
    truth_xyz: &[[f64; 3]],
    light: [f64; 3],
    lambda_samples: usize,
    exposure_scale: Option<f64>,
) -> ColourError {
    let views = truth_xyz.len();
    let dirs = fibonacci_hemisphere(views, 0.05);
    let approx = par_map(dirs.len(), |i| {
        pack.colour_xyz(light, dirs[i], lambda_samples)
    });
    let ys: Vec<f64> = truth_xyz.iter().map(|c| c[1]).collect();
    let scale = exposure_scale.unwrap_or_else(|| {
        let p = percentile(&ys, 95.0);
        if p > 0.0 && p.is_finite() {
            1.0 / p
        } else {
            1.0
        }
    });
    let des: Vec<f64> = approx
        .iter()
        .zip(truth_xyz)
        .map(|(a, t)| colour::ciede2000_xyz(displayed_xyz(*a, scale), displayed_xyz(*t, scale)))
        .collect();
    ColourError {
        light,
        views,
        exposure_scale: scale,
        mean: des.iter().sum::<f64>() / des.len().max(1) as f64,
        p99: percentile(&des, 99.0),
        max: des.iter().copied().fold(0.0, f64::max),
    }
}
