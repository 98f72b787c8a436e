//! Linear sRGB radiance to a spectrum: `L(lambda) = D65(lambda) sum_k c_k b_k(lambda)`
//! for the colour `c = (r, g, b)`.
//!
//! The three curves `b_k` are the smoothest (least summed squared first
//! difference on a 5 nm grid over 380..780 nm, linear in between) whose spectra
//! `D65 b_k` have exactly the XYZ of the sRGB primaries under the CIE 1931
//! observer (1 nm sums, the scene's units: `sum D65 ybar = 1`). Consequences:
//! - linear in `c`, so an environment map's spectral radiance is a texel's
//!   colour times three fixed curves (cheap, and the same in any renderer);
//! - the round trip RGB -> spectrum -> XYZ -> RGB is the identity, so the
//!   luminance (the energy a camera sees) is conserved exactly;
//! - `b_r + b_g + b_b = 1` at every wavelength (the constant is the smoothest
//!   curve with white's XYZ), so white stays D65. The primaries' targets are
//!   scaled per XYZ channel by the ratio of the 1 nm D65 white to the sRGB
//!   white point (a 1e-4 correction) so that both statements hold together.
//!
//! Saturated colours give curves that dip below zero at some wavelengths (a
//! linear map cannot keep every sRGB colour physical); sky and daylight maps
//! are far from that edge. The solve is an 84 x 84 linear system done once by
//! Gaussian elimination: hand-written because it is small and runs once.

// Index loops read as the linear algebra they implement.
#![allow(clippy::needless_range_loop)]

use std::sync::OnceLock;
use sunbeam_optics::{cie, colour};

/// Grid nodes: 380, 385, ..., 780 nm.
const NODES: usize = 81;
const FIRST_NM: f64 = 380.0;
const STEP_NM: f64 = 5.0;

/// The three curves at the grid nodes.
pub struct RgbBasis {
    nodes: Vec<[f64; 3]>,
}

impl RgbBasis {
    /// The basis (computed once per process).
    pub fn get() -> &'static RgbBasis {
        static B: OnceLock<RgbBasis> = OnceLock::new();
        B.get_or_init(solve)
    }

    /// `[b_r, b_g, b_b]` at `lambda_m`; zero outside 380..780 nm.
    pub fn at(&self, lambda_m: f64) -> [f64; 3] {
        let x = (lambda_m * 1e9 - FIRST_NM) / STEP_NM;
        if !(x >= 0.0 && x <= (NODES - 1) as f64) {
            return [0.0; 3];
        }
        let i = (x.floor() as usize).min(NODES - 2);
        let t = x - i as f64;
        let (a, b) = (self.nodes[i], self.nodes[i + 1]);
        [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]))
    }

    /// Spectral radiance of linear sRGB `rgb` at `lambda_m` (scene units).
    pub fn radiance(&self, rgb: [f64; 3], lambda_m: f64) -> f64 {
        let b = self.at(lambda_m);
        cie::d65_at(lambda_m) * (rgb[0] * b[0] + rgb[1] * b[1] + rgb[2] * b[2])
    }
}

/// Hat function of node `i` at `nm`.
fn hat(i: usize, nm: f64) -> f64 {
    let x = (nm - FIRST_NM) / STEP_NM - i as f64;
    (1.0 - x.abs()).max(0.0)
}

fn solve() -> RgbBasis {
    let (lo, hi) = cie::DEFAULT_RANGE_NM;
    let norm = cie::d65_y_norm(cie::DEFAULT_RANGE_NM);
    // A[c][i]: XYZ channel c of D65 times hat i (1 nm sums, scene units).
    let mut a = vec![[0.0f64; NODES]; 3];
    let mut white = [0.0f64; 3];
    for nm in lo..=hi {
        let s = cie::d65_nm(nm);
        let c = cie::cmf_nm(nm);
        let i0 = ((nm as f64 - FIRST_NM) / STEP_NM).floor() as usize;
        for i in i0.saturating_sub(1)..=(i0 + 1).min(NODES - 1) {
            let h = hat(i, nm as f64);
            for ch in 0..3 {
                a[ch][i] += s * c[ch] * h / norm;
            }
        }
        for ch in 0..3 {
            white[ch] += s * c[ch] / norm;
        }
    }
    let m = colour::SRGB_TO_XYZ;
    let m_white: [f64; 3] = [0, 1, 2].map(|r| m[r][0] + m[r][1] + m[r][2]);
    let n = NODES + 3;
    let mut nodes = vec![[0.0; 3]; NODES];
    for k in 0..3 {
        // KKT system of: minimise sum (b[i+1] - b[i])^2 subject to A b = y.
        let mut kkt = vec![vec![0.0f64; n + 1]; n];
        for i in 0..NODES - 1 {
            kkt[i][i] += 2.0;
            kkt[i + 1][i + 1] += 2.0;
            kkt[i][i + 1] -= 2.0;
            kkt[i + 1][i] -= 2.0;
        }
        for ch in 0..3 {
            for i in 0..NODES {
                kkt[NODES + ch][i] = a[ch][i];
                kkt[i][NODES + ch] = a[ch][i];
            }
            kkt[NODES + ch][n] = m[ch][k] * white[ch] / m_white[ch];
        }
        let x = gauss(kkt);
        for i in 0..NODES {
            nodes[i][k] = x[i];
        }
    }
    RgbBasis { nodes }
}

/// Gaussian elimination with partial pivoting on an augmented `n x (n + 1)` matrix.
fn gauss(mut m: Vec<Vec<f64>>) -> Vec<f64> {
    let n = m.len();
    for col in 0..n {
        let p = (col..n)
            .max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))
            .unwrap_or(col);
        m.swap(col, p);
        let d = m[col][col];
        for r in 0..n {
            if r != col && m[r][col] != 0.0 {
                let f = m[r][col] / d;
                for c in col..=n {
                    m[r][c] -= f * m[col][c];
                }
            }
        }
    }
    (0..n).map(|i| m[i][n] / m[i][i]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn xyz_of(rgb: [f64; 3]) -> [f64; 3] {
        let b = RgbBasis::get();
        cie::integrate_xyz_1nm(cie::DEFAULT_RANGE_NM, |l| {
            b.radiance(rgb, l) / cie::d65_at(l).max(1e-300)
        })
    }

    /// Truth: the sRGB matrix (IEC 61966-2-1) and the CIE observer, not this solve.
    #[test]
    fn round_trip_is_the_identity() {
        for rgb in [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.2, 0.5, 0.9],
            [3.0, 1.0, 0.25],
        ] {
            let xyz = xyz_of(rgb);
            let want = colour::linear_srgb_to_xyz(rgb);
            for c in 0..3 {
                assert!(
                    (xyz[c] - want[c]).abs() < 2e-4 * (1.0 + want[c]),
                    "{rgb:?}: {xyz:?} vs {want:?}"
                );
            }
        }
    }

    #[test]
    fn white_stays_d65() {
        let b = RgbBasis::get();
        for nm in (380..=780).step_by(7) {
            let l = nm as f64 * 1e-9;
            let s = b.at(l);
            assert!((s[0] + s[1] + s[2] - 1.0).abs() < 1e-9, "{nm}: {s:?}");
            assert!((b.radiance([1.0; 3], l) - cie::d65_at(l)).abs() < 1e-9 * cie::d65_at(l));
        }
    }
}
