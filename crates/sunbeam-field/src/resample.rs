//! Resampling to a pixel size or a grid, with square pixels out.
//!
//! Kernel: a Kaiser-windowed sinc (beta = [`KAISER_BETA`], [`LOBES`] zero
//! crossings each side), applied separably along x then y. The pixel grid is
//! the pixel-area convention (pixel k covers [k, k+1) x pixel size), and the
//! output grid is centred on the input area.
//!
//! - Shrinking (output pixel larger than input): the sinc is stretched to the
//!   output rate and its cutoff is lowered to [`DOWN_CUTOFF`] of the output
//!   Nyquist frequency, so the stopband (response < 1e-3, < 1e-4 from 1.005 x)
//!   starts at the output Nyquist: nothing aliases. The passband is flat to
//!   1e-4 up to 0.75 and to 1e-3 up to 0.79 of the output Nyquist.
//! - Enlarging: the sinc runs at the input rate with its cutoff at the input
//!   Nyquist; flat to 1e-4 up to 0.75 and to 1e-3 up to 0.88 of the input
//!   Nyquist, images suppressed below 1e-3 beyond 1.12 of it.
//! - Same grid: the field is returned unchanged (and the kernel would reduce
//!   to the identity anyway: sinc at integer offsets).
//!
//! Edges: half-sample mirror extension. Weights are normalised to sum to 1
//! (flat fields stay exactly flat). Work is split over threads by rows; each
//! output value is computed by the same arithmetic whatever the thread count.

use rayon::prelude::*;

use crate::{HeightField, MAX_SIDE};
use sunbeam_common::{Error, Result};

/// Kaiser window shape parameter.
pub const KAISER_BETA: f64 = 8.0;
/// Zero crossings of the sinc on each side of the kernel centre.
pub const LOBES: f64 = 20.0;
/// Cutoff when shrinking, as a fraction of the output Nyquist frequency, chosen
/// so that the kernel's stopband (< 1e-3) begins at the output Nyquist.
pub const DOWN_CUTOFF: f64 = 0.891;
/// Cutoff when enlarging, as a fraction of the input Nyquist frequency.
pub const UP_CUTOFF: f64 = 1.0;

/// What to resample to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// Square pixels of this size (metres); the grid is round(L / p) pixels per side.
    PixelSize(f64),
    /// This many pixels; square pixels of min(Lx/W, Ly/H), so when the aspect
    /// ratio differs from the input's the longer side is cropped symmetrically.
    Size(usize, usize),
}

/// The output grid for a target: (width, height, pixel size).
pub fn target_grid(f: &HeightField, t: Target) -> Result<(usize, usize, f64)> {
    let (lx, ly) = (f.size_x(), f.size_y());
    let (w, h, p) = match t {
        Target::PixelSize(p) => {
            if !(p.is_finite() && p > 0.0) {
                return Err(Error::usage(format!("pixel size {p} must be positive")));
            }
            let n = |l: f64| (l / p).round().max(1.0);
            let (w, h) = (n(lx), n(ly));
            if w > MAX_SIDE as f64 || h > MAX_SIDE as f64 {
                return Err(Error::usage(format!(
                    "resampling to {p:e} m pixels gives {w}x{h} pixels, above the {MAX_SIDE} limit per side"
                )));
            }
            (w as usize, h as usize, p)
        }
        Target::Size(w, h) => {
            if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
                return Err(Error::usage(format!(
                    "size {w}x{h} must be 1..{MAX_SIDE} per side"
                )));
            }
            (w, h, (lx / w as f64).min(ly / h as f64))
        }
    };
    Ok((w, h, p))
}

/// Resample to a target (square pixels out).
pub fn resample(f: &HeightField, t: Target) -> Result<HeightField> {
    let (w, h, p) = target_grid(f, t)?;
    resample_grid(f, w, h, p, p)
}

fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        let a = std::f64::consts::PI * x;
        a.sin() / a
    }
}

/// Modified Bessel function of the first kind, order 0 (power series).
fn bessel_i0(x: f64) -> f64 {
    let (mut sum, mut term, q) = (1.0, 1.0, x * x / 4.0);
    for k in 1..200 {
        term *= q / (k as f64 * k as f64);
        sum += term;
        if term < sum * 1e-17 {
            break;
        }
    }
    sum
}

/// Sparse resampling matrix for one axis: for output k, `taps` (index, weight) pairs.
struct Axis {
    taps: usize,
    idx: Vec<usize>,
    w: Vec<f64>,
    /// First input index of output k's taps when they are contiguous (no mirroring).
    contiguous: Vec<Option<usize>>,
}

fn mirror(j: i64, n: usize) -> usize {
    let n2 = 2 * n as i64;
    let m = j.rem_euclid(n2);
    (if m >= n as i64 { n2 - 1 - m } else { m }) as usize
}

/// Weights from `n_in` samples of spacing `d_in` to `n_out` of spacing `d_out`,
/// output grid centred on the input extent.
fn axis(n_in: usize, d_in: f64, n_out: usize, d_out: f64) -> Axis {
    let scale = d_out / d_in;
    // Cutoff in cycles per input sample, then the sinc's zero spacing (input samples).
    let fc = if scale > 1.0 {
        0.5 * DOWN_CUTOFF / scale
    } else {
        0.5 * UP_CUTOFF
    };
    let spacing = 1.0 / (2.0 * fc);
    let radius = LOBES * spacing;
    let taps = 2 * radius.ceil() as usize + 1;
    let x0 = 0.5 * (n_in as f64 * d_in - n_out as f64 * d_out);
    let i0b = bessel_i0(KAISER_BETA);
    let mut idx = Vec::with_capacity(n_out * taps);
    let mut w = Vec::with_capacity(n_out * taps);
    let mut contiguous = Vec::with_capacity(n_out);
    for k in 0..n_out {
        let t = (x0 + (k as f64 + 0.5) * d_out) / d_in - 0.5;
        let first = (t - radius).ceil() as i64;
        contiguous.push((first >= 0 && first as usize + taps <= n_in).then_some(first as usize));
        let mut sum = 0.0;
        let start = w.len();
        for m in 0..taps as i64 {
            let j = first + m;
            let u = j as f64 - t;
            let r = u / radius;
            let wt = if r.abs() < 1.0 {
                sinc(u / spacing) * bessel_i0(KAISER_BETA * (1.0 - r * r).sqrt()) / i0b
            } else {
                0.0
            };
            idx.push(mirror(j, n_in));
            w.push(wt);
            sum += wt;
        }
        for v in &mut w[start..] {
            *v /= sum;
        }
    }
    Axis {
        taps,
        idx,
        w,
        contiguous,
    }
}

/// Dot product with four accumulators (vectorises; fixed order, so the result
/// does not depend on the thread count).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let (mut s0, mut s1, mut s2, mut s3) = (0.0, 0.0, 0.0, 0.0);
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        s0 += x[0] * y[0];
        s1 += x[1] * y[1];
        s2 += x[2] * y[2];
        s3 += x[3] * y[3];
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (s0 + s1) + (s2 + s3) + tail
}

/// Apply `axis` along rows: `rows` rows of `n_in` values -> rows of `n_out`
/// (rows in parallel on rayon; each output value is one fixed-order sum).
fn apply_rows(src: &[f64], n_in: usize, ax: &Axis, n_out: usize) -> Vec<f64> {
    let rows = src.len() / n_in;
    let mut out = vec![0.0; rows * n_out];
    out.par_chunks_mut(n_out)
        .zip(src.par_chunks(n_in))
        .for_each(|(orow, irow)| {
            for (k, o) in orow.iter_mut().enumerate() {
                let wt = &ax.w[k * ax.taps..(k + 1) * ax.taps];
                *o = match ax.contiguous[k] {
                    Some(first) => dot(&irow[first..first + ax.taps], wt),
                    None => {
                        let ix = &ax.idx[k * ax.taps..(k + 1) * ax.taps];
                        ix.iter().zip(wt).map(|(&j, &w)| irow[j] * w).sum()
                    }
                };
            }
        });
    out
}

/// Apply `axis` along columns: `n_in` rows of `width` -> `n_out` rows (output
/// rows in parallel on rayon).
fn apply_cols(src: &[f64], width: usize, ax: &Axis, n_out: usize) -> Vec<f64> {
    let mut out = vec![0.0; n_out * width];
    out.par_chunks_mut(width).enumerate().for_each(|(k, orow)| {
        let (ix, wt) = (
            &ax.idx[k * ax.taps..(k + 1) * ax.taps],
            &ax.w[k * ax.taps..(k + 1) * ax.taps],
        );
        for (&j, &w) in ix.iter().zip(wt) {
            if w == 0.0 {
                continue;
            }
            let irow = &src[j * width..(j + 1) * width];
            for (o, &v) in orow.iter_mut().zip(irow) {
                *o += w * v;
            }
        }
    });
    out
}

/// Resample to exactly `w` x `h` pixels of `dx` x `dy`, centred on the input area.
/// The field must be finite (fill non-finite values first).
pub fn resample_grid(f: &HeightField, w: usize, h: usize, dx: f64, dy: f64) -> Result<HeightField> {
    if w == f.width && h == f.height && dx == f.dx && dy == f.dy {
        return Ok(f.clone());
    }
    if w == 0
        || h == 0
        || w > MAX_SIDE
        || h > MAX_SIDE
        || !(dx > 0.0 && dy > 0.0 && dx.is_finite() && dy.is_finite())
    {
        return Err(Error::usage(format!(
            "cannot resample to {w}x{h} pixels of {dx:e} x {dy:e} m"
        )));
    }
    let bad = f.count_nonfinite();
    if bad > 0 {
        return Err(Error::input(format!(
            "cannot resample a field with {bad} non-finite values (use --fill-nonfinite first)"
        )));
    }
    let same_x = w == f.width && dx == f.dx;
    let same_y = h == f.height && dy == f.dy;
    let tmp = if same_x {
        f.data.clone()
    } else {
        apply_rows(&f.data, f.width, &axis(f.width, f.dx, w, dx), w)
    };
    let data = if same_y {
        tmp
    } else {
        apply_cols(&tmp, w, &axis(f.height, f.dy, h, dy), h)
    };
    let mut out = HeightField::new(w, h, dx, dy, data)?;
    out.provenance = f.provenance.clone();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identity_and_flat() {
        let f = HeightField::new(
            5,
            4,
            2e-9,
            2e-9,
            (0..20).map(|v| (v as f64).sin()).collect(),
        )
        .unwrap();
        assert_eq!(resample(&f, Target::PixelSize(2e-9)).unwrap(), f);
        assert_eq!(resample(&f, Target::Size(5, 4)).unwrap(), f);
        let flat = HeightField::new(30, 20, 1e-9, 1e-9, vec![3.5; 600]).unwrap();
        for t in [
            Target::PixelSize(1.7e-9),
            Target::PixelSize(0.3e-9),
            Target::Size(7, 11),
        ] {
            let g = resample(&flat, t).unwrap();
            assert!(g.data.iter().all(|v| (v - 3.5).abs() < 1e-12));
            assert_eq!(g.dx, g.dy);
        }
    }

    #[test]
    fn grids() {
        // 100 x 50 pixels of 2 x 4 nm = 200 x 200 nm.
        let f = HeightField::new(100, 50, 2e-9, 4e-9, vec![0.0; 5000]).unwrap();
        assert_eq!(
            target_grid(&f, Target::PixelSize(2e-9)).unwrap(),
            (100, 100, 2e-9)
        );
        let (w, h, p) = target_grid(&f, Target::Size(64, 32)).unwrap();
        assert_eq!((w, h), (64, 32));
        assert!((p - 200e-9 / 64.0).abs() < 1e-20);
        assert!(target_grid(&f, Target::PixelSize(1e-15)).is_err());
    }

    #[test]
    fn non_finite_refused() {
        let f = HeightField::new(
            3,
            3,
            1.0,
            1.0,
            vec![0.0, 1.0, f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        )
        .unwrap();
        assert!(resample(&f, Target::Size(5, 5)).is_err());
    }
}
