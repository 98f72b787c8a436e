//! Row alignment (Gwyddion's Correct Data > Align Rows), for scan lines offset
//! from each other. Non-finite values are skipped and kept.

use crate::HeightField;
use sunbeam_common::{Error, Result};

/// Row alignment methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AlignRows {
    None,
    /// Subtract each row's median; the shifts are made zero-mean (Gwyddion "Median").
    Median,
    /// Shift each row by the median of its differences to the row above,
    /// accumulated down the image, minus a least-squares line through the
    /// shifts (Gwyddion "Median of differences").
    MedianDiff,
}

impl std::str::FromStr for AlignRows {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "none" => Ok(Self::None),
            "median" => Ok(Self::Median),
            "median-diff" | "median-of-differences" => Ok(Self::MedianDiff),
            _ => Err(Error::usage(format!(
                "'{s}': unknown row alignment (median, median-diff, none)"
            ))),
        }
    }
}

impl AlignRows {
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Median => "median",
            Self::MedianDiff => "median-diff",
        }
    }
}

/// The value of rank `len/2` (upper median for even counts, as Gwyddion's
/// `gwy_math_median`). `buf` is reordered. None for an empty slice.
pub fn median(buf: &mut [f64]) -> Option<f64> {
    if buf.is_empty() {
        return None;
    }
    let k = buf.len() / 2;
    let (_, m, _) = buf.select_nth_unstable_by(k, |a, b| a.total_cmp(b));
    Some(*m)
}

/// Gwyddion's minimum count of values for a per-row statistic: round(ln(W) + 1).
fn min_count(w: usize) -> usize {
    ((w as f64).ln() + 1.0).round() as usize
}

/// Per-row shifts that [`align_rows`] subtracts.
pub fn row_shifts(f: &HeightField, method: AlignRows) -> Result<Vec<f64>> {
    let (w, h) = (f.width, f.height);
    let mincount = min_count(w);
    let mut buf = Vec::with_capacity(w);
    let mut shifts = vec![0.0; h];
    match method {
        AlignRows::None => {}
        AlignRows::Median => {
            let mut all: Vec<f64> = f.data.iter().copied().filter(|v| v.is_finite()).collect();
            let total = median(&mut all)
                .ok_or_else(|| Error::input("align rows: the field has no finite values"))?;
            drop(all);
            for (i, s) in shifts.iter_mut().enumerate() {
                buf.clear();
                buf.extend(
                    f.data[i * w..(i + 1) * w]
                        .iter()
                        .copied()
                        .filter(|v| v.is_finite()),
                );
                *s = if buf.len() >= mincount {
                    median(&mut buf).unwrap_or(total)
                } else {
                    total
                };
            }
            let mean = shifts.iter().sum::<f64>() / h as f64;
            shifts.iter_mut().for_each(|s| *s -= mean);
        }
        AlignRows::MedianDiff => {
            for i in 1..h {
                buf.clear();
                let (a, b) = (&f.data[(i - 1) * w..i * w], &f.data[i * w..(i + 1) * w]);
                buf.extend(
                    a.iter()
                        .zip(b)
                        .filter(|(x, y)| x.is_finite() && y.is_finite())
                        .map(|(x, y)| y - x),
                );
                let d = if buf.len() >= mincount {
                    median(&mut buf).unwrap_or(0.0)
                } else {
                    0.0
                };
                shifts[i] = shifts[i - 1] + d;
            }
            // Subtract the least-squares line through the shifts (index units).
            if h >= 2 {
                let n = h as f64;
                let xm = (n - 1.0) / 2.0;
                let ym = shifts.iter().sum::<f64>() / n;
                let (mut sxy, mut sxx) = (0.0, 0.0);
                for (i, &s) in shifts.iter().enumerate() {
                    let x = i as f64 - xm;
                    sxy += x * (s - ym);
                    sxx += x * x;
                }
                let b = sxy / sxx;
                for (i, s) in shifts.iter_mut().enumerate() {
                    *s -= ym + b * (i as f64 - xm);
                }
            } else {
                shifts[0] = 0.0;
            }
        }
    }
    Ok(shifts)
}

/// Align rows in place.
pub fn align_rows(f: &mut HeightField, method: AlignRows) -> Result<()> {
    if method == AlignRows::None {
        return Ok(());
    }
    let shifts = row_shifts(f, method)?;
    let w = f.width;
    for (i, s) in shifts.iter().enumerate() {
        f.data[i * w..(i + 1) * w].iter_mut().for_each(|v| *v -= s);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_rank() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0, 4.0]), Some(3.0));
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&mut []), None);
    }

    #[test]
    fn removes_row_offsets() {
        let (w, h) = (32, 16);
        let offs: Vec<f64> = (0..h).map(|i| ((i * 7) % 5) as f64).collect();
        let data: Vec<f64> = (0..h)
            .flat_map(|i| (0..w).map(move |j| (i, j)))
            .map(|(i, j)| ((j * 3) % 7) as f64 * 0.1 + offs[i])
            .collect();
        for m in [AlignRows::Median, AlignRows::MedianDiff] {
            let mut f = HeightField::new(w, h, 1.0, 1.0, data.clone()).unwrap();
            align_rows(&mut f, m).unwrap();
            for i in 1..h {
                for j in 0..w {
                    assert!((f.at(i, j) - f.at(0, j)).abs() < 1e-12, "{m:?}");
                }
            }
        }
    }
}
