//! Resampling against closed forms: band-limited surfaces made of cosines that
//! are symmetric about the field's edges (so the mirror extension at the edges
//! is exact) are resampled down and up; their values (hence their spectra)
//! below the band limit must survive to 1e-3 of the surface's amplitude, and
//! a tone above the new Nyquist frequency must not alias into the result.

use sunbeam_field::resample::{resample, resample_grid, Target};
use sunbeam_field::HeightField;

/// Deterministic pseudo-random numbers in [-1, 1): the project's seeded
/// `SplitMix64` (`sunbeam_common::rng`), state in `.0`.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        let mut g = sunbeam_common::rng::SplitMix64(self.0);
        let v = g.unit();
        self.0 = g.0;
        v * 2.0 - 1.0
    }
}

/// sum a_kl cos(pi k x / Lx) cos(pi l y / Ly) over k, l below the limits.
struct Surface {
    lx: f64,
    ly: f64,
    terms: Vec<(usize, usize, f64)>,
}

impl Surface {
    fn new(lx: f64, ly: f64, kmax: usize, lmax: usize, seed: u64) -> Self {
        let mut r = Lcg(seed);
        let mut terms = Vec::new();
        for k in 0..=kmax {
            for l in 0..=lmax {
                terms.push((k, l, r.next() * 1e-9));
            }
        }
        Surface { lx, ly, terms }
    }
    /// Sample at pixel centres of a w x h grid of dx x dy centred on the surface's area.
    fn sample(&self, w: usize, h: usize, dx: f64, dy: f64) -> HeightField {
        let x0 = 0.5 * (self.lx - w as f64 * dx);
        let y0 = 0.5 * (self.ly - h as f64 * dy);
        let kmax = self.terms.iter().map(|t| t.0).max().unwrap();
        let lmax = self.terms.iter().map(|t| t.1).max().unwrap();
        let cx: Vec<Vec<f64>> = (0..=kmax)
            .map(|k| {
                (0..w)
                    .map(|j| {
                        (std::f64::consts::PI * k as f64 * (x0 + (j as f64 + 0.5) * dx) / self.lx)
                            .cos()
                    })
                    .collect()
            })
            .collect();
        let cy: Vec<Vec<f64>> = (0..=lmax)
            .map(|l| {
                (0..h)
                    .map(|i| {
                        (std::f64::consts::PI * l as f64 * (y0 + (i as f64 + 0.5) * dy) / self.ly)
                            .cos()
                    })
                    .collect()
            })
            .collect();
        // Separable: first collapse k for each (l, j).
        let mut bl = vec![vec![0.0; w]; lmax + 1];
        for &(k, l, a) in &self.terms {
            for j in 0..w {
                bl[l][j] += a * cx[k][j];
            }
        }
        let mut data = vec![0.0; w * h];
        for i in 0..h {
            for l in 0..=lmax {
                let c = cy[l][i];
                for j in 0..w {
                    data[i * w + j] += c * bl[l][j];
                }
            }
        }
        HeightField::new(w, h, dx, dy, data).unwrap()
    }
    fn amplitude(&self) -> f64 {
        self.terms.iter().map(|t| t.2.abs()).sum()
    }
}

/// DCT-II coefficients a_kl of a field sampled at pixel centres over its whole
/// area (the inverse of `Surface::sample` for k < width, l < height).
fn dct(f: &HeightField) -> Vec<Vec<f64>> {
    let (w, h) = (f.width, f.height);
    let basis = |n: usize| -> Vec<Vec<f64>> {
        (0..n)
            .map(|k| {
                let c = if k == 0 { 1.0 } else { 2.0 } / n as f64;
                (0..n)
                    .map(|j| {
                        c * (std::f64::consts::PI * k as f64 * (j as f64 + 0.5) / n as f64).cos()
                    })
                    .collect()
            })
            .collect()
    };
    let (bx, by) = (basis(w), basis(h));
    // rows: r[i][k] = sum_j f[i][j] bx[k][j]
    let r: Vec<Vec<f64>> = (0..h)
        .map(|i| {
            (0..w)
                .map(|k| (0..w).map(|j| f.data[i * w + j] * bx[k][j]).sum())
                .collect()
        })
        .collect();
    (0..w)
        .map(|k| {
            (0..h)
                .map(|l| (0..h).map(|i| r[i][k] * by[l][i]).sum())
                .collect()
        })
        .collect()
}

fn max_diff(a: &HeightField, b: &HeightField) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.data
        .iter()
        .zip(&b.data)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Root-mean-square amplitude of a field.
fn rms(f: &HeightField) -> f64 {
    (f.data.iter().map(|v| v * v).sum::<f64>() / f.data.len() as f64).sqrt()
}

#[test]
fn down_and_up_keeps_the_band_below_the_new_nyquist() {
    // 256 x 192 pixels of 2 nm -> 160 x 120 pixels of 3.2 nm (factor 1.6), and back.
    let (w, h, d) = (256usize, 192usize, 2e-9);
    let (lx, ly) = (w as f64 * d, h as f64 * d);
    let coarse = 3.2e-9;
    // New Nyquist: 1/(2*3.2 nm); cos(pi k x / L) has frequency k / (2 L).
    // Fill the band up to 0.75 of the new Nyquist.
    let kmax = (0.75 * lx / coarse) as usize;
    let lmax = (0.75 * ly / coarse) as usize;
    let s = Surface::new(lx, ly, kmax, lmax, 7);
    let fine = s.sample(w, h, d, d);
    let amp = s.amplitude().max(rms(&fine));

    let down = resample(&fine, Target::PixelSize(coarse)).unwrap();
    assert_eq!(
        (down.width, down.height, down.dx, down.dy),
        (160, 120, coarse, coarse)
    );
    let e_down = max_diff(&down, &s.sample(160, 120, coarse, coarse)) / rms(&fine);
    let up = resample_grid(&down, w, h, d, d).unwrap();
    let e_up = max_diff(&up, &fine) / rms(&fine);
    eprintln!("band to 0.75 Nyquist: down max error {e_down:.2e}, down+up {e_up:.2e} of the RMS height (sum |a| = {amp:e})");
    assert!(e_down < 1e-3, "down: {e_down:e}");
    assert!(e_up < 1e-3, "down+up: {e_up:e}");
    // The spectrum: every coefficient below the band limit survives to 1e-3 of
    // its own value (plus 1e-4 of the largest), and nothing appears above it.
    let a = dct(&up);
    let amax = s.terms.iter().map(|t| t.2.abs()).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for &(k, l, v) in &s.terms {
        let e = (a[k][l] - v).abs() / (v.abs() + 0.1 * amax);
        worst = worst.max(e);
    }
    let mut above = 0.0f64;
    for (k, col) in a.iter().enumerate() {
        for (l, &v) in col.iter().enumerate() {
            if k > kmax || l > lmax {
                above = above.max(v.abs() / amax);
            }
        }
    }
    eprintln!("spectrum after down+up: worst relative coefficient error {worst:.2e}, largest spurious {above:.2e}");
    assert!(worst < 1e-3, "spectrum: {worst:e}");
    assert!(above < 1e-3, "spurious spectrum: {above:e}");
}

#[test]
fn a_tone_above_the_new_nyquist_does_not_alias() {
    let (w, h, d) = (240usize, 64usize, 1e-9);
    let (lx, ly) = (w as f64 * d, h as f64 * d);
    let coarse = 2e-9; // new Nyquist: 1/(4 nm); cos(pi k x/L) at k = 1.05 * L / 2 nm ...
    let k = (1.05 * lx / coarse).round() as usize;
    let s = Surface {
        lx,
        ly,
        terms: vec![(k, 0, 1e-9)],
    };
    let fine = s.sample(w, h, d, d);
    let down = resample(&fine, Target::PixelSize(coarse)).unwrap();
    let leak = rms(&down) / rms(&fine);
    eprintln!("tone at 1.05 x new Nyquist: {leak:.2e} of its RMS left after shrinking");
    assert!(leak < 1e-3, "aliasing: {leak:e}");
}

#[test]
fn non_square_pixels_become_square() {
    // 200 x 50 pixels of 1 x 4 nm (200 x 200 nm) -> 100 x 100 pixels of 2 nm.
    let (lx, ly) = (200e-9, 200e-9);
    let s = Surface::new(lx, ly, 30, 14, 11);
    let f = s.sample(200, 50, 1e-9, 4e-9);
    let g = resample(&f, Target::Size(100, 100)).unwrap();
    assert_eq!((g.width, g.height, g.dx, g.dy), (100, 100, 2e-9, 2e-9));
    let e = max_diff(&g, &s.sample(100, 100, 2e-9, 2e-9)) / rms(&f);
    eprintln!("non-square 1x4 nm -> 2 nm: max error {e:.2e} of RMS");
    assert!(e < 1e-3, "{e:e}");
}

#[test]
fn same_grid_is_the_identity() {
    let s = Surface::new(64e-9, 48e-9, 10, 10, 3);
    let f = s.sample(64, 48, 1e-9, 1e-9);
    assert_eq!(resample(&f, Target::PixelSize(1e-9)).unwrap(), f);
    assert_eq!(resample(&f, Target::Size(64, 48)).unwrap(), f);
    assert_eq!(resample_grid(&f, 64, 48, 1e-9, 1e-9).unwrap(), f);
}
