//! Summary statistics of a height field (finite values only).

use crate::HeightField;

/// min, max, mean and RMS roughness (root mean square deviation from the mean,
/// Gwyddion's "RMS (Sq)") of the finite values, and the non-finite count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
    pub rms: f64,
    pub finite: usize,
    pub nonfinite: usize,
}

impl Stats {
    pub fn of(f: &HeightField) -> Stats {
        let (mut min, mut max, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
        for &v in f.data.iter().filter(|v| v.is_finite()) {
            min = min.min(v);
            max = max.max(v);
            sum += v;
            n += 1;
        }
        if n == 0 {
            return Stats {
                min: f64::NAN,
                max: f64::NAN,
                mean: f64::NAN,
                rms: f64::NAN,
                finite: 0,
                nonfinite: f.data.len(),
            };
        }
        let mean = sum / n as f64;
        let ss: f64 = f
            .data
            .iter()
            .filter(|v| v.is_finite())
            .map(|v| (v - mean) * (v - mean))
            .sum();
        Stats {
            min,
            max,
            mean,
            rms: (ss / n as f64).sqrt(),
            finite: n,
            nonfinite: f.data.len() - n,
        }
    }
}
