//! Scar removal: short horizontal streaks (the tip jumping for part of a scan
//! line) are marked and Laplace-interpolated, after Gwyddion's "Remove Scars"
//! (Correct Data > Remove Scars, default parameters).
//!
//! A pixel run of 1..=`max_width` rows is a scar candidate where every pixel is
//! above both the row just above and the row just below the run (or below
//! both) by more than `threshold_low` x sigma, with at least one pixel beyond
//! `threshold_high` x sigma, sigma being the RMS of the differences between
//! neighbouring rows. Runs shorter than `min_len` pixels along the row are
//! dropped.

use crate::fill::fill_masked;
use crate::HeightField;
use sunbeam_common::Result;

/// Parameters of scar detection (defaults as Gwyddion's).
#[derive(Debug, Clone, Copy)]
pub struct ScarParams {
    pub threshold_high: f64,
    pub threshold_low: f64,
    pub min_len: usize,
    pub max_width: usize,
}

impl Default for ScarParams {
    fn default() -> Self {
        Self {
            threshold_high: 0.666,
            threshold_low: 0.25,
            min_len: 16,
            max_width: 4,
        }
    }
}

/// Mark scars (true = scar pixel).
pub fn mark_scars(f: &HeightField, p: &ScarParams) -> Vec<bool> {
    let (w, h) = (f.width, f.height);
    let mut mask = vec![false; w * h];
    if h < 3 || w < p.min_len.max(1) {
        return mask;
    }
    let (mut s2, mut n) = (0.0, 0usize);
    for i in 1..h {
        for j in 0..w {
            let d = f.data[i * w + j] - f.data[(i - 1) * w + j];
            if d.is_finite() {
                s2 += d * d;
                n += 1;
            }
        }
    }
    if n == 0 {
        return mask;
    }
    let sigma = (s2 / n as f64).sqrt();
    if sigma == 0.0 {
        return mask;
    }
    let (lo, hi) = (p.threshold_low * sigma, p.threshold_high * sigma);
    for sign in [1.0, -1.0] {
        for width in 1..=p.max_width.min(h - 2) {
            for top in 1..h - width {
                // Rows top..top+width are the candidate; top-1 and top+width bound it.
                let (above, below) = (top - 1, top + width);
                let mut j = 0;
                while j < w {
                    // Excess of the run over its bounds at column j (min over the run's rows).
                    let excess = |j: usize| -> f64 {
                        let bound = if sign > 0.0 {
                            f.data[above * w + j].max(f.data[below * w + j])
                        } else {
                            f.data[above * w + j].min(f.data[below * w + j])
                        };
                        (top..top + width)
                            .map(|r| sign * (f.data[r * w + j] - bound))
                            .fold(f64::INFINITY, f64::min)
                    };
                    if excess(j).is_nan() || excess(j) <= lo {
                        j += 1;
                        continue;
                    }
                    let start = j;
                    let mut peak = 0.0f64;
                    while j < w {
                        let e = excess(j);
                        if e.is_nan() || e <= lo {
                            break;
                        }
                        peak = peak.max(e);
                        j += 1;
                    }
                    if j - start >= p.min_len && peak > hi {
                        for r in top..top + width {
                            for c in start..j {
                                mask[r * w + c] = true;
                            }
                        }
                    }
                }
            }
        }
    }
    mask
}

/// Mark scars and Laplace-interpolate them. Returns the number of pixels replaced.
pub fn remove_scars(f: &mut HeightField, p: &ScarParams) -> Result<usize> {
    let mask = mark_scars(f, p);
    if !mask.iter().any(|&m| m) {
        return Ok(0);
    }
    fill_masked(f, &mask)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn removes_a_streak() {
        let (w, h) = (64, 32);
        let truth: Vec<f64> = (0..w * h)
            .map(|p| ((p % w) as f64 * 0.3).sin() + ((p / w) as f64 * 0.2).cos())
            .collect();
        let mut data = truth.clone();
        for j in 10..40 {
            data[12 * w + j] += 5.0;
        }
        let mut f = HeightField::new(w, h, 1.0, 1.0, data).unwrap();
        let n = remove_scars(&mut f, &ScarParams::default()).unwrap();
        assert!(n >= 30, "{n}");
        let err = (10..40)
            .map(|j| (f.data[12 * w + j] - truth[12 * w + j]).abs())
            .fold(0.0, f64::max);
        assert!(err < 0.2, "{err}");
        // A clean field is untouched.
        let mut g = HeightField::new(w, h, 1.0, 1.0, truth.clone()).unwrap();
        assert_eq!(remove_scars(&mut g, &ScarParams::default()).unwrap(), 0);
    }
}
