//! Laplace interpolation of non-finite values: the missing pixels are the
//! solution of the discrete Laplace equation (each equals the mean of its
//! 4-neighbours inside the grid) with the finite pixels as boundary values,
//! as Gwyddion's "Interpolate data under mask" (Laplace). Solved by
//! Jacobi-preconditioned conjugate gradients to a relative residual of 1e-12.

use crate::HeightField;
use sunbeam_common::{Error, Result};

/// Replace every non-finite value by Laplace interpolation. Returns how many
/// values were filled.
pub fn fill_nonfinite(f: &mut HeightField) -> Result<usize> {
    let mask: Vec<bool> = f.data.iter().map(|v| !v.is_finite()).collect();
    fill_masked(f, &mask)
}

/// Laplace-interpolate the pixels where `mask` is true (their values are ignored).
pub fn fill_masked(f: &mut HeightField, mask: &[bool]) -> Result<usize> {
    let (w, h) = (f.width, f.height);
    assert_eq!(mask.len(), w * h);
    let unknown: Vec<usize> = (0..w * h).filter(|&p| mask[p]).collect();
    let n = unknown.len();
    if n == 0 {
        return Ok(0);
    }
    if n == w * h {
        return Err(Error::input(
            "cannot fill non-finite values: the field has no finite values at all",
        ));
    }
    let mut index = vec![usize::MAX; w * h];
    for (k, &p) in unknown.iter().enumerate() {
        index[p] = k;
    }
    // A u = b with A = degree on the diagonal, -1 for unknown neighbours.
    let mut diag = vec![0.0; n];
    let mut b = vec![0.0; n];
    let mut nbrs: Vec<[usize; 4]> = vec![[usize::MAX; 4]; n];
    for (k, &p) in unknown.iter().enumerate() {
        let (i, j) = (p / w, p % w);
        let cand = [
            (i > 0).then(|| p - w),
            (i + 1 < h).then(|| p + w),
            (j > 0).then(|| p - 1),
            (j + 1 < w).then(|| p + 1),
        ];
        for (s, q) in cand.into_iter().flatten().enumerate() {
            diag[k] += 1.0;
            if mask[q] {
                nbrs[k][s] = index[q];
            } else {
                b[k] += f.data[q];
            }
        }
    }
    // Initial guess: mean of the known values.
    let (s, c) = (0..w * h)
        .filter(|&p| !mask[p])
        .fold((0.0, 0usize), |(s, c), p| (s + f.data[p], c + 1));
    let mean = s / c as f64;
    let mut x = vec![mean; n];
    let apply = |x: &[f64], out: &mut [f64]| {
        for k in 0..x.len() {
            let mut v = diag[k] * x[k];
            for &q in &nbrs[k] {
                if q != usize::MAX {
                    v -= x[q];
                }
            }
            out[k] = v;
        }
    };
    let mut ax = vec![0.0; n];
    apply(&x, &mut ax);
    let mut r: Vec<f64> = (0..n).map(|k| b[k] - ax[k]).collect();
    let mut z: Vec<f64> = (0..n).map(|k| r[k] / diag[k]).collect();
    let mut p = z.clone();
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
    let bnorm = b
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
        .max(mean.abs() * (n as f64).sqrt())
        .max(1e-300);
    let max_iter = 20 * (w + h) + 1000;
    let mut ap = vec![0.0; n];
    for _ in 0..max_iter {
        let rnorm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        if rnorm <= 1e-12 * bnorm {
            break;
        }
        apply(&p, &mut ap);
        let pap: f64 = p.iter().zip(&ap).map(|(a, b)| a * b).sum();
        if pap <= 0.0 || !pap.is_finite() {
            break;
        }
        let alpha = rz / pap;
        for k in 0..n {
            x[k] += alpha * p[k];
            r[k] -= alpha * ap[k];
            z[k] = r[k] / diag[k];
        }
        let rz_new: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
        let beta = rz_new / rz;
        rz = rz_new;
        for k in 0..n {
            p[k] = z[k] + beta * p[k];
        }
    }
    for (k, &pix) in unknown.iter().enumerate() {
        f.data[pix] = x[k];
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_harmonic_exactly() {
        // A linear function is harmonic: Laplace interpolation restores it.
        let (w, h) = (24, 20);
        let truth: Vec<f64> = (0..w * h)
            .map(|p| 0.3 * (p % w) as f64 - 0.7 * (p / w) as f64 + 2.0)
            .collect();
        let mut data = truth.clone();
        for i in 5..12 {
            for j in 3..15 {
                data[i * w + j] = f64::NAN;
            }
        }
        data[0] = f64::INFINITY; // corner
        let mut f = HeightField::new(w, h, 1.0, 1.0, data).unwrap();
        assert_eq!(fill_nonfinite(&mut f).unwrap(), 7 * 12 + 1);
        // At the corner the discrete Laplace equation (Neumann at the edge)
        // gives the mean of its two neighbours.
        assert!((f.data[0] - 0.5 * (truth[1] + truth[w])).abs() < 1e-8);
        for (a, b) in f.data.iter().zip(&truth).skip(1) {
            assert!((a - b).abs() < 1e-8, "{a} vs {b}");
        }
        let mut all_nan = HeightField::new(2, 2, 1.0, 1.0, vec![f64::NAN; 4]).unwrap();
        assert!(fill_nonfinite(&mut all_nan).is_err());
    }
}
