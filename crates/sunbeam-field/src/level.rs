//! Levelling: mean-plane subtraction (Gwyddion's Plane Level), 2D polynomial
//! background subtraction, zero mean. Non-finite values are ignored by the fits
//! and left as they are.

use crate::HeightField;
use sunbeam_common::{Error, Result};

/// Least-squares plane `z = a + bx*j + by*i` over the finite values, in pixel
/// index units (`j` column, `i` row from the top), as Gwyddion's
/// `gwy_data_field_fit_plane` returns it. None when fewer than 3 finite values.
pub fn fit_plane(f: &HeightField) -> Option<(f64, f64, f64)> {
    let (w, h) = (f.width, f.height);
    let (xc, yc) = ((w as f64 - 1.0) / 2.0, (h as f64 - 1.0) / 2.0);
    // Centred coordinates for conditioning.
    let (mut n, mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut sz, mut sxz, mut syz) = (0.0, 0.0, 0.0);
    for i in 0..h {
        let y = i as f64 - yc;
        let row = &f.data[i * w..(i + 1) * w];
        let (mut rn, mut rx, mut rxx, mut rz, mut rxz) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (j, &z) in row.iter().enumerate() {
            if z.is_finite() {
                let x = j as f64 - xc;
                rn += 1.0;
                rx += x;
                rxx += x * x;
                rz += z;
                rxz += x * z;
            }
        }
        n += rn;
        sx += rx;
        sxx += rxx;
        sy += rn * y;
        syy += rn * y * y;
        sxy += rx * y;
        sz += rz;
        sxz += rxz;
        syz += rz * y;
    }
    if n < 3.0 {
        return None;
    }
    let m = [[n, sx, sy], [sx, sxx, sxy], [sy, sxy, syy]];
    let r = [sz, sxz, syz];
    let s = solve(&m.iter().map(|r| r.to_vec()).collect::<Vec<_>>(), &r)?;
    let (a0, bx, by) = (s[0], s[1], s[2]);
    Some((a0 - bx * xc - by * yc, bx, by))
}

/// Gwyddion's Plane Level: fit the mean plane and subtract it so that the
/// plane's value at the pixel position (W/2, H/2) stays (the mean is kept to
/// within half a pixel of slope), i.e. `z -= bx*(j - W/2) + by*(i - H/2)`.
pub fn level_plane(f: &mut HeightField) -> Result<()> {
    let (_, bx, by) = fit_plane(f).ok_or_else(|| {
        Error::input("plane level needs at least 3 finite values that are not collinear")
    })?;
    let (w, h) = (f.width, f.height);
    let (xc, yc) = (w as f64 / 2.0, h as f64 / 2.0);
    for i in 0..h {
        let off = by * (i as f64 - yc);
        for (j, z) in f.data[i * w..(i + 1) * w].iter_mut().enumerate() {
            *z -= bx * (j as f64 - xc) + off;
        }
    }
    Ok(())
}

/// Legendre polynomials P_0..P_n at x.
fn legendre(n: usize, x: f64, out: &mut [f64]) {
    out[0] = 1.0;
    if n >= 1 {
        out[1] = x;
    }
    for k in 2..=n {
        let kf = k as f64;
        out[k] = ((2.0 * kf - 1.0) * x * out[k - 1] - (kf - 1.0) * out[k - 2]) / kf;
    }
}

fn unit_coord(k: usize, n: usize) -> f64 {
    if n <= 1 {
        0.0
    } else {
        2.0 * k as f64 / (n - 1) as f64 - 1.0
    }
}

/// Largest polynomial degree accepted by [`level_poly`].
pub const MAX_POLY_DEGREE: usize = 12;

/// Fit and subtract a 2D polynomial of total degree `degree` (all terms
/// x^p y^q with p+q <= degree) by least squares over the finite values. The
/// whole fit is subtracted, so the result has (close to) zero mean. Uses a
/// Legendre basis on [-1, 1] for a well-conditioned fit.
pub fn level_poly(f: &mut HeightField, degree: usize) -> Result<()> {
    if degree > MAX_POLY_DEGREE {
        return Err(Error::usage(format!(
            "polynomial degree {degree} is above {MAX_POLY_DEGREE}"
        )));
    }
    let (w, h) = (f.width, f.height);
    let n1 = degree + 1;
    let terms: Vec<(usize, usize)> = (0..=degree)
        .flat_map(|q| (0..=degree - q).map(move |p| (p, q)))
        .collect();
    let k = terms.len();
    let mut px = vec![0.0; w * n1];
    for j in 0..w {
        legendre(degree, unit_coord(j, w), &mut px[j * n1..(j + 1) * n1]);
    }
    let mut py = vec![0.0; h * n1];
    for i in 0..h {
        legendre(degree, unit_coord(i, h), &mut py[i * n1..(i + 1) * n1]);
    }
    // Normal matrix of the full grid is separable; remove non-finite pixels.
    let mut gx = vec![0.0; n1 * n1];
    let mut gy = vec![0.0; n1 * n1];
    for a in 0..n1 {
        for b in 0..n1 {
            gx[a * n1 + b] = (0..w).map(|j| px[j * n1 + a] * px[j * n1 + b]).sum();
            gy[a * n1 + b] = (0..h).map(|i| py[i * n1 + a] * py[i * n1 + b]).sum();
        }
    }
    let mut m = vec![vec![0.0; k]; k];
    for (r, &(p, q)) in terms.iter().enumerate() {
        for (c, &(p2, q2)) in terms.iter().enumerate() {
            m[r][c] = gx[p * n1 + p2] * gy[q * n1 + q2];
        }
    }
    let mut rhs = vec![0.0; k];
    let mut rowm = vec![0.0; n1];
    let mut nfinite = 0usize;
    for i in 0..h {
        rowm.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..w {
            let z = f.data[i * w + j];
            if z.is_finite() {
                nfinite += 1;
                for p in 0..n1 {
                    rowm[p] += px[j * n1 + p] * z;
                }
            } else {
                for (r, &(p, q)) in terms.iter().enumerate() {
                    let br = px[j * n1 + p] * py[i * n1 + q];
                    for (c, &(p2, q2)) in terms.iter().enumerate() {
                        m[r][c] -= br * px[j * n1 + p2] * py[i * n1 + q2];
                    }
                }
            }
        }
        for (r, &(p, q)) in terms.iter().enumerate() {
            rhs[r] += py[i * n1 + q] * rowm[p];
        }
    }
    if nfinite < k {
        return Err(Error::input(format!(
            "poly:{degree} level needs at least {k} finite values, the field has {nfinite}"
        )));
    }
    let c = solve(&m, &rhs).ok_or_else(|| {
        Error::input(format!(
            "poly:{degree} level: the fit is singular (too few or degenerate finite values)"
        ))
    })?;
    // Subtract: per row, collapse the y factor first.
    let mut cx = vec![0.0; n1];
    for i in 0..h {
        cx.iter_mut().for_each(|v| *v = 0.0);
        for (r, &(p, q)) in terms.iter().enumerate() {
            cx[p] += c[r] * py[i * n1 + q];
        }
        for j in 0..w {
            let bg: f64 = (0..n1).map(|p| cx[p] * px[j * n1 + p]).sum();
            f.data[i * w + j] -= bg;
        }
    }
    Ok(())
}

/// Subtract the mean of the finite values.
pub fn zero_mean(f: &mut HeightField) -> Result<()> {
    let (s, n) = f
        .data
        .iter()
        .filter(|v| v.is_finite())
        .fold((0.0, 0usize), |(s, n), &v| (s + v, n + 1));
    if n == 0 {
        return Err(Error::input("zero mean: the field has no finite values"));
    }
    let m = s / n as f64;
    f.data.iter_mut().for_each(|v| *v -= m);
    Ok(())
}

/// Solve a small dense system by Gaussian elimination with partial pivoting.
/// None when (numerically) singular.
pub(crate) fn solve(m: &[Vec<f64>], r: &[f64]) -> Option<Vec<f64>> {
    let n = r.len();
    let mut a: Vec<Vec<f64>> = m
        .iter()
        .zip(r)
        .map(|(row, &b)| {
            let mut v = row.clone();
            v.push(b);
            v
        })
        .collect();
    let scale = a
        .iter()
        .flat_map(|r| r[..n].iter())
        .fold(0.0f64, |s, v| s.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    for col in 0..n {
        let piv = (col..n).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))?;
        if a[piv][col].abs() <= scale * 1e-13 {
            return None;
        }
        a.swap(col, piv);
        for row in col + 1..n {
            let fct = a[row][col] / a[col][col];
            if fct != 0.0 {
                let (top, bottom) = a.split_at_mut(row);
                for (x, &p) in bottom[0][col..=n].iter_mut().zip(&top[col][col..=n]) {
                    *x -= fct * p;
                }
            }
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|c| a[row][c] * x[c]).sum();
        x[row] = (a[row][n] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(w: usize, h: usize, f: impl Fn(f64, f64) -> f64) -> HeightField {
        let data = (0..h)
            .flat_map(|i| (0..w).map(move |j| (j, i)))
            .map(|(j, i)| f(j as f64, i as f64))
            .collect();
        HeightField::new(w, h, 1e-9, 1e-9, data).unwrap()
    }

    #[test]
    fn plane_removes_tilt_keeps_centre() {
        let mut f = field(8, 6, |x, y| 5.0 + 0.5 * x - 0.25 * y);
        let (a, bx, by) = fit_plane(&f).unwrap();
        assert!((a - 5.0).abs() < 1e-12 && (bx - 0.5).abs() < 1e-12 && (by + 0.25).abs() < 1e-12);
        level_plane(&mut f).unwrap();
        let c = 5.0 + 0.5 * 4.0 - 0.25 * 3.0;
        assert!(f.data.iter().all(|v| (v - c).abs() < 1e-12), "{:?}", f.data);
    }

    #[test]
    fn poly_removes_quadratic_with_holes() {
        let mut f = field(20, 15, |x, y| {
            1.0 + 0.1 * x * x - 0.05 * x * y + 0.2 * y + 3e-3 * y * y
        });
        f.data[7] = f64::NAN;
        f.data[100] = f64::NAN;
        level_poly(&mut f, 2).unwrap();
        for v in f.data.iter().filter(|v| v.is_finite()) {
            assert!(v.abs() < 1e-9, "{v}");
        }
        assert_eq!(f.count_nonfinite(), 2);
        assert!(level_poly(&mut field(2, 2, |_, _| 0.0), 3).is_err());
    }

    #[test]
    fn solver() {
        let m = vec![vec![2.0, 1.0], vec![1.0, 3.0]];
        let x = solve(&m, &[3.0, 5.0]).unwrap();
        assert!((x[0] - 0.8).abs() < 1e-12 && (x[1] - 1.4).abs() < 1e-12);
        assert!(solve(&[vec![1.0, 2.0], vec![2.0, 4.0]], &[1.0, 2.0]).is_none());
    }
}
