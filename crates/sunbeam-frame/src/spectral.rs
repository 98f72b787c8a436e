//! Wavelength sampling of the colour integral (PHYSICS.md 2), shared with the player.
//!
//! The reference sums at every integer nanometre of 380..=780 nm
//! (`sunbeam_optics::cie::integrate_xyz_1nm`). The player uses `n` samples at
//! the midpoints of `n` equal intervals of [380, 780] nm with weights
//! `S(l) [xbar, ybar, zbar](l) / sum_j S(l_j) ybar(l_j)` (so `R = 1` still gives
//! `Y = 1` exactly), `S` = D65, the CIE 1931 2-degree observer, both linearly
//! interpolated between the 1 nm table values.

use sunbeam_optics::cie;

/// One wavelength sample: wavelength in metres and its XYZ weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub lambda_m: f64,
    pub weight: [f64; 3],
}

/// A set of wavelength samples.
#[derive(Debug, Clone, PartialEq)]
pub struct Samples(pub Vec<Sample>);

impl Samples {
    /// `n` midpoint samples over `range_nm`.
    pub fn uniform(n: usize, range_nm: (u32, u32)) -> Samples {
        let n = n.max(1);
        let (lo, hi) = (range_nm.0 as f64, range_nm.1 as f64);
        let step = (hi - lo) / n as f64;
        Self::from_nm((0..n).map(|j| lo + (j as f64 + 0.5) * step))
    }

    /// Samples at the integer nanometres `lo..=hi` (the reference; step 1 nm) or any
    /// step (the thesis' 5 nm: `stepped(380, 780, 5)`), endpoints included.
    pub fn stepped(lo: u32, hi: u32, step: u32) -> Samples {
        let step = step.max(1);
        Self::from_nm((lo..=hi).step_by(step as usize).map(|nm| nm as f64))
    }

    fn from_nm(nms: impl Iterator<Item = f64>) -> Samples {
        let raw: Vec<(f64, [f64; 3])> = nms
            .map(|nm| {
                let l = nm * 1e-9;
                let s = cie::d65_at(l);
                let c = cie::cmf_at(l);
                (l, [s * c[0], s * c[1], s * c[2]])
            })
            .collect();
        let norm: f64 = raw.iter().map(|r| r.1[1]).sum();
        let inv = if norm > 0.0 { 1.0 / norm } else { 0.0 };
        Samples(
            raw.into_iter()
                .map(|(l, w)| Sample {
                    lambda_m: l,
                    weight: w.map(|v| v * inv),
                })
                .collect(),
        )
    }

    /// `sum_j R(l_j) weight_j`.
    pub fn integrate(&self, mut r: impl FnMut(f64) -> f64) -> [f64; 3] {
        let mut acc = [0.0; 3];
        for s in &self.0 {
            let v = r(s.lambda_m);
            if v != 0.0 {
                for (a, w) in acc.iter_mut().zip(&s.weight) {
                    *a += v * w;
                }
            }
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_reflectance_is_the_white_with_y_one() {
        let white = cie::d65_white_xyz(cie::DEFAULT_RANGE_NM);
        for n in [16usize, 40, 64] {
            let x = Samples::uniform(n, cie::DEFAULT_RANGE_NM).integrate(|_| 1.0);
            assert!((x[1] - 1.0).abs() < 1e-12);
            for k in 0..3 {
                assert!((x[k] - white[k]).abs() < 5e-3, "n={n}: {x:?} vs {white:?}");
            }
        }
        let s1 = Samples::stepped(380, 780, 1).integrate(|_| 1.0);
        for k in 0..3 {
            assert!((s1[k] - white[k]).abs() < 1e-12);
        }
    }
}
