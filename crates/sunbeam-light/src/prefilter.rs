//! The environment prefiltered by solid angle: a mip chain of the
//! equirectangular coefficient table ([`crate::Environment::coefficient_table`]),
//! read at the solid angle a shading estimate covers (filtered importance
//! sampling, Krivanek and Colbert 2008: a direction that stands for a region
//! of `Omega` steradians reads the environment averaged over about
//! `Omega`). The player's first-frame estimator reads it once per response
//! cell (docs/LIGHTING.md "The first frame"); its texture is this chain.
//!
//! Why an equirectangular chain and not a cube or octahedral pyramid: it is
//! the table the player already binds (sb_env_texel, the background pass),
//! a 2x2 box is exact in solid angle when weighted by each row's `sin(theta)`
//! band, and the hardware's trilinear filter reads it with one sample. Its
//! one flaw, texels narrow in azimuth near the poles, only blurs more there
//! (the level is picked from the texel's polar extent, the larger one).
//!
//! Level `m` has `w / 2^m x h / 2^m` texels (down to 2 x 1); texel `(i, j)`
//! of level `m` is the solid-angle-weighted mean of its four children. Cost:
//! one pass over the table, rows in parallel (a 4096 x 2048 map: see
//! crates/sunbeam-light/benches/env_tables.rs and docs/bench/hdri.md).

use rayon::prelude::*;

/// The chain: level 0 is the table itself, `[c0, c1, c2, 0]` per texel.
#[derive(Debug, Clone)]
pub struct Prefiltered {
    /// `(width, height, rgba)` per level, level 0 first.
    pub levels: Vec<(usize, usize, Vec<f32>)>,
    /// Where the table's columns start, in turns after `phi = 0`
    /// ([`crate::Environment::table_phase`]; 0 unless set by
    /// [`Prefiltered::with_phase`]).
    pub phase: f64,
}

impl Prefiltered {
    /// The chain of an equirectangular table of `w x h` (`w = 2 h`, a power
    /// of two or not: odd sides are rounded down, the last row or column of
    /// the finer level folded into its neighbour).
    pub fn new(w: usize, h: usize, rgba: Vec<f32>) -> Prefiltered {
        assert_eq!(rgba.len(), w * h * 4, "one rgba texel per table texel");
        let mut levels = vec![(w, h, rgba)];
        loop {
            let (pw, ph, prev) = levels.last().expect("level 0");
            let (pw, ph) = (*pw, *ph);
            if ph < 2 || pw < 4 {
                break;
            }
            let (nw, nh) = (pw / 2, ph / 2);
            let weight = |j: usize| {
                // solid angle of a texel of row j (up to the azimuth step)
                let t0 = std::f64::consts::PI * j as f64 / ph as f64;
                let t1 = std::f64::consts::PI * (j + 1) as f64 / ph as f64;
                t0.cos() - t1.cos()
            };
            let weights: Vec<f64> = (0..ph).map(weight).collect();
            let mut out = vec![0.0f32; nw * nh * 4];
            // Output rows in parallel (each texel is its own mean, summed in a
            // fixed order: the chain does not depend on the thread count).
            out.par_chunks_mut(nw * 4).enumerate().for_each(|(y, row)| {
                let rows = 2 * y..if y + 1 == nh { ph } else { 2 * y + 2 };
                for x in 0..nw {
                    let cols = 2 * x..if x + 1 == nw { pw } else { 2 * x + 2 };
                    let mut acc = [0.0f64; 4];
                    let mut wsum = 0.0;
                    for j in rows.clone() {
                        let wj = weights[j];
                        for i in cols.clone() {
                            let o = 4 * (j * pw + i);
                            for (a, v) in acc.iter_mut().zip(&prev[o..o + 4]) {
                                *a += wj * *v as f64;
                            }
                            wsum += wj;
                        }
                    }
                    for c in 0..4 {
                        row[4 * x + c] = (acc[c] / wsum) as f32;
                    }
                }
            });
            levels.push((nw, nh, out));
        }
        Prefiltered { levels, phase: 0.0 }
    }

    /// The same chain for a table whose columns start `phase` turns after
    /// `phi = 0` ([`crate::Environment::table_phase`]).
    pub fn with_phase(mut self, phase: f64) -> Prefiltered {
        self.phase = phase;
        self
    }

    /// The level (fractional, clamped to the chain) at which one texel's
    /// polar extent `pi / h_m` squared is `solid_angle`: what both the
    /// shader (`textureSampleLevel`) and [`Prefiltered::lookup`] read.
    pub fn level(&self, solid_angle: f64) -> f64 {
        let h0 = self.levels[0].1 as f64;
        let texel = (std::f64::consts::PI / h0).powi(2);
        let m = 0.5 * (solid_angle / texel).max(1e-30).log2();
        m.clamp(0.0, (self.levels.len() - 1) as f64)
    }

    /// The coefficients at world direction `d` (unit) averaged over about
    /// `solid_angle` steradians: bilinear within a level (azimuth wraps,
    /// polar angle clamps), linear between levels, as a GPU's trilinear
    /// filter with repeat / clamp addressing.
    pub fn lookup(&self, d: [f64; 3], solid_angle: f64) -> [f64; 3] {
        let m = self.level(solid_angle);
        let m0 = m.floor() as usize;
        let m1 = (m0 + 1).min(self.levels.len() - 1);
        let t = m - m0 as f64;
        let a = self.bilinear(m0, d);
        if t == 0.0 {
            return a;
        }
        let b = self.bilinear(m1, d);
        [0, 1, 2].map(|c| a[c] + t * (b[c] - a[c]))
    }

    fn bilinear(&self, m: usize, d: [f64; 3]) -> [f64; 3] {
        let (w, h, data) = &self.levels[m];
        let (w, h) = (*w, *h);
        let theta = d[1].clamp(-1.0, 1.0).acos();
        let phi = d[2].atan2(d[0]).rem_euclid(std::f64::consts::TAU);
        let x = (phi / std::f64::consts::TAU - self.phase) * w as f64 - 0.5;
        let y = (theta / std::f64::consts::PI * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
        let (x0, y0) = (x.floor(), y.floor());
        let (tx, ty) = (x - x0, y - y0);
        let i0 = (x0 as i64).rem_euclid(w as i64) as usize;
        let i1 = (i0 + 1) % w;
        let j0 = y0 as usize;
        let j1 = (j0 + 1).min(h - 1);
        let at = |i: usize, j: usize, c: usize| data[4 * (j * w + i) + c] as f64;
        [0, 1, 2].map(|c| {
            let top = at(i0, j0, c) * (1.0 - tx) + at(i1, j0, c) * tx;
            let bot = at(i0, j1, c) * (1.0 - tx) + at(i1, j1, c) * tx;
            top * (1.0 - ty) + bot * ty
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A table whose value is a known function of direction.
    fn table(w: usize, h: usize, f: impl Fn([f64; 3]) -> f64) -> Vec<f32> {
        let mut out = Vec::new();
        for j in 0..h {
            let theta = (j as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            for i in 0..w {
                let phi = (i as f64 + 0.5) / w as f64 * std::f64::consts::TAU;
                let v = f(crate::direction(theta.cos(), phi)) as f32;
                out.extend([v, 2.0 * v, 0.5, 0.0]);
            }
        }
        out
    }

    #[test]
    fn every_level_keeps_the_mean_over_the_sphere() {
        // The solid-angle weighted mean is what a box filter must conserve:
        // the integral of y^2 + x over the sphere is 4 pi / 3.
        let (w, h) = (256, 128);
        let p = Prefiltered::new(w, h, table(w, h, |d| d[1] * d[1] + d[0]));
        assert_eq!(p.levels.len(), 8); // 256 x 128 down to 2 x 1
        for (lw, lh, data) in &p.levels {
            let mut sum = 0.0;
            for j in 0..*lh {
                let t0 = std::f64::consts::PI * j as f64 / *lh as f64;
                let t1 = std::f64::consts::PI * (j + 1) as f64 / *lh as f64;
                let omega = (t0.cos() - t1.cos()) * std::f64::consts::TAU / *lw as f64;
                for i in 0..*lw {
                    sum += omega * data[4 * (j * lw + i)] as f64;
                }
            }
            // the table's own midpoint rule: 1e-4 of the exact integral
            let want = 4.0 * std::f64::consts::PI / 3.0;
            assert!(
                (sum - want).abs() < 2e-4 * want,
                "level {lw} x {lh}: {sum} vs {want}"
            );
        }
    }

    #[test]
    fn a_wide_footprint_reads_the_local_mean() {
        // y^2 averaged over a cap of half-angle a about the pole is
        // (1 + cos a + cos^2 a) / 3; a footprint of the cap's solid angle at
        // the pole reads a value between the cap's mean and the pole's 1.
        let (w, h) = (512, 256);
        let p = Prefiltered::new(w, h, table(w, h, |d| d[1] * d[1]));
        let small = p.lookup([0.0, 1.0, 0.0], 1e-6);
        assert!((small[0] - 1.0).abs() < 1e-3, "{small:?}");
        assert!((small[2] - 0.5).abs() < 1e-6, "{small:?}");
        // at the equator y^2 ~ 0 in a small footprint, and grows with it
        let eq0 = p.lookup([1.0, 0.0, 0.0], 1e-6)[0];
        let eq1 = p.lookup([1.0, 0.0, 0.0], 0.1)[0];
        let eq2 = p.lookup([1.0, 0.0, 0.0], 1.0)[0];
        assert!(
            eq0 < 1e-3 && eq0 < eq1 && eq1 < eq2 && eq2 < 0.4,
            "{eq0} {eq1} {eq2}"
        );
        assert_eq!(p.level(1e-9), 0.0);
        assert_eq!(p.level(100.0), (p.levels.len() - 1) as f64);
    }

    /// A table whose columns start 0.3 column after phi = 0 (a map turned
    /// by a fraction of a texel): read with its phase, the centre of each
    /// texel gives that texel; read without, a mix with its neighbour.
    #[test]
    fn a_phased_table_is_read_at_its_own_columns() {
        let (w, h) = (16, 8);
        let phase = 0.3 / w as f64;
        let rgba: Vec<f32> = (0..w * h)
            .flat_map(|t| [(t % w) as f32 + 10.0 * (t / w) as f32, 0.0, 0.0, 0.0])
            .collect();
        let phased = Prefiltered::new(w, h, rgba.clone()).with_phase(phase);
        let plain = Prefiltered::new(w, h, rgba);
        for (i, j) in [(0, 3), (5, 4), (15, 7)] {
            let theta = (j as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            let phi = ((i as f64 + 0.5) / w as f64 + phase) * std::f64::consts::TAU;
            let d = crate::direction(theta.cos(), phi);
            let want = i as f64 + 10.0 * j as f64;
            assert!((phased.lookup(d, 1e-9)[0] - want).abs() < 1e-9);
            assert!((plain.lookup(d, 1e-9)[0] - want).abs() > 0.2);
        }
    }
}
