//! A converged reference under an environment (`sunbeam-eval render
//! --converge DE`): each pixel gets finer sub-pixel grids and more seeds
//! until its estimated error is below a CIEDE2000 target (docs/EVAL.md "A
//! converged reference").
//!
//! Why per pixel: a frame's noise sits in few pixels. Inside a silhouette the
//! quadrature leaves only the sub-pixel positions' noise, which is small. At
//! a silhouette a pixel's value is which of its sub-pixel samples fall on the
//! mesh: on the baked snake at 96 x 48 an edge pixel with 12 of 256 samples
//! covered (a sliver) varies by 10-20 % from seed to seed, in its covered
//! count and in which positions of a limb's sheen it hits. Seeds for every
//! pixel pay for the few.
//!
//! Why finer grids before more seeds: a stratified grid's error at an edge
//! falls about as `N^(-3/4)` with its `N` samples (only the strata the edge
//! crosses are uncertain), the mean of `k` seeds' only as `k^(-1/2)`. So an
//! open pixel goes up a level, `4^L` times `opts.samples` per pixel (twice the
//! grid's side), until `max_samples`; at the top level it takes more seeds,
//! up to `max_seeds`.
//!
//! Each level renders `seeds` rounds (distinct seeds, [`round_seed`]) at the
//! pixels still open; a pixel's value is the mean of its rounds at its last
//! level. Its error is the standard error of that mean carried into
//! CIEDE2000: with `m` the mean and `se_c` the standard error of channel `c`
//! (linear sRGB; the rounds' sample variance over their count),
//! `sqrt(sum_c dE(m, m + se_c e_c)^2)`, the root-mean-square error of the mean
//! for independent channels to first order. A pixel closes when that is at
//! most the target, or when it is unlit (`Y < LIT_Y`) with three standard
//! errors to spare. Each round is an unbiased frame; stopping on the estimate
//! leaves a bias far below the target.

use crate::{render_environment_at, LinearImage, Options, Prepared};
use sunbeam_common::rng::SplitMix64;
use sunbeam_common::{Error, Result};
use sunbeam_frame::linear::{luminance, LIT_Y};
use sunbeam_optics::colour::{ciede2000_xyz, linear_srgb_to_xyz};

/// When [`render_converged`] stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Converge {
    /// Target: a pixel closes when its estimated CIEDE2000 error is at most this.
    pub de: f64,
    /// Rounds (seeds) per level before a pixel's error is estimated (at least 2).
    pub seeds: u32,
    /// The finest grid: samples per pixel (a square, at least the frame's).
    pub max_samples: u32,
    /// The most rounds a pixel gets at the finest grid.
    pub max_seeds: u32,
}

impl Default for Converge {
    fn default() -> Self {
        Converge {
            de: 0.15,
            seeds: 3,
            max_samples: 16384,
            max_seeds: 12,
        }
    }
}

/// What [`render_converged`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct Converged {
    /// Each pixel's value (linear light, exposure applied).
    pub image: LinearImage,
    /// Frames rendered (each at the open pixels only).
    pub rounds: u32,
    /// Sub-pixel samples per pixel, mean over the lit pixels and largest.
    pub samples_mean: f64,
    pub samples_max: u64,
    /// Pixels still above the target at the end.
    pub open: usize,
    /// The estimated error (CIEDE2000) over the lit pixels: 99th percentile and largest.
    pub estimate_p99: f64,
    pub estimate_max: f64,
}

/// Seed of round `r` of `seed` (round 0: `seed` itself; rounds of different
/// seeds are distinct streams).
pub fn round_seed(seed: u64, r: u32) -> u64 {
    if r == 0 {
        return seed;
    }
    let mut g = SplitMix64::new(
        seed ^ 0xC0DE_5EED_0000_0000 ^ u64::from(r).wrapping_mul(0x9E37_79B9_7F4A_7C15),
    );
    g.next_u64()
}

/// Per pixel: its rounds' sums of linear values and of their squares.
#[derive(Clone, Copy, Default)]
struct Moments {
    k: u32,
    sum: [f64; 3],
    sq: [f64; 3],
}

impl Moments {
    fn add(&mut self, v: [f32; 3]) {
        self.k += 1;
        for ((s, q), x) in self.sum.iter_mut().zip(self.sq.iter_mut()).zip(v) {
            let x = f64::from(x);
            *s += x;
            *q += x * x;
        }
    }

    fn mean(&self) -> [f64; 3] {
        self.sum.map(|s| s / f64::from(self.k.max(1)))
    }

    /// Standard error of the mean per channel (0 with fewer than two rounds).
    fn se(&self) -> [f64; 3] {
        if self.k < 2 {
            return [0.0; 3];
        }
        let k = f64::from(self.k);
        let m = self.mean();
        [0, 1, 2].map(|c| ((self.sq[c] - k * m[c] * m[c]).max(0.0) / (k - 1.0) / k).sqrt())
    }

    /// Estimated CIEDE2000 error of the mean, or None for an unlit pixel.
    fn estimate(&self) -> Option<f64> {
        let m = self.mean();
        let se = self.se();
        let far = [0, 1, 2].map(|c| (m[c] + 3.0 * se[c]) as f32);
        if luminance(far) < LIT_Y {
            return None;
        }
        let xyz = |v: [f64; 3]| linear_srgb_to_xyz(v.map(|x| x.max(0.0)));
        let at = xyz(m);
        let sq: f64 = (0..3)
            .map(|c| {
                let mut v = m;
                v[c] += se[c];
                ciede2000_xyz(at, xyz(v)).powi(2)
            })
            .sum();
        Some(sq.sqrt())
    }
}

/// The frame of `p` (which must have an environment) refined per pixel until
/// every pixel's estimated error is at most `c.de` (module doc).
pub fn render_converged(p: &Prepared, opts: &Options, c: Converge) -> Result<Converged> {
    if p.environment.is_none() {
        return Err(Error::usage(
            "--converge: the scene has no environment (without one the frame has no noise; raise --samples)",
        ));
    }
    let base = opts.samples.max(1);
    crate::samples_side(c.max_samples)?;
    if !(c.de.is_finite() && c.de > 0.0)
        || c.seeds < 2
        || c.max_seeds < c.seeds
        || c.max_samples < base
    {
        return Err(Error::usage(format!(
            "--converge {}: give a positive target, --max-samples ({}) at least --samples ({base}), at least two seeds",
            c.de, c.max_samples
        )));
    }
    let p = &crate::bounded(p);
    let [w, h] = opts.size.unwrap_or(p.scene.size);
    let n = (w as usize) * (h as usize);
    let mut acc = vec![Moments::default(); n];
    let mut samples = vec![0u64; n];
    let mut open = vec![true; n];
    let mut rounds = 0u32;
    let mut level_samples = base;
    loop {
        let top = level_samples.saturating_mul(4) > c.max_samples;
        let level_rounds = if top { c.max_seeds } else { c.seeds };
        // A pixel still open starts this level afresh.
        let level_open = open.clone();
        for (m, &o) in acc.iter_mut().zip(&open) {
            if o {
                *m = Moments::default();
            }
        }
        for k in 0..level_rounds {
            if k >= c.seeds {
                close(&mut open, &acc, c.de);
            }
            if !open.contains(&true) {
                break;
            }
            let o = Options {
                samples: level_samples,
                seed: round_seed(opts.seed, rounds),
                subpixel_seed: opts.subpixel_seed.map(|s| round_seed(s, rounds)),
                ..opts.clone()
            };
            let env = p.environment.clone().expect("checked above");
            let frame = render_environment_at(p, env, &o, Some(&open))?;
            for (((m, &v), &o), s) in acc
                .iter_mut()
                .zip(&frame.rgb)
                .zip(&open)
                .zip(samples.iter_mut())
            {
                if o {
                    m.add(v);
                    *s += u64::from(level_samples);
                }
            }
            rounds += 1;
        }
        close(&mut open, &acc, c.de);
        if !top {
            keep_beside_open(&mut open, &level_open, w as usize);
        }
        if top || !open.contains(&true) {
            break;
        }
        level_samples *= 4;
    }
    // Each lit pixel's (samples, estimate).
    let lit: Vec<(u64, f64)> = (0..n)
        .filter_map(|i| acc[i].estimate().map(|e| (samples[i], e)))
        .collect();
    let mut est: Vec<f64> = lit.iter().map(|&(_, e)| e).collect();
    let stats = crate::diff::stats(&mut est);
    let mut image = LinearImage::new(w, h);
    for (px, m) in image.rgb.iter_mut().zip(&acc) {
        *px = m.mean().map(|v| v as f32);
    }
    Ok(Converged {
        image,
        rounds,
        samples_mean: lit.iter().map(|&(k, _)| k as f64).sum::<f64>() / lit.len().max(1) as f64,
        samples_max: samples.iter().copied().max().unwrap_or(0),
        open: open.iter().filter(|&&o| o).count(),
        estimate_p99: if stats.pixels > 0 { stats.p99 } else { 0.0 },
        estimate_max: if stats.pixels > 0 { stats.max } else { 0.0 },
    })
}

/// Keep open, for the next level, the pixels of this level (`level_open`)
/// beside a pixel still open (8-neighbours). A glint a fraction of a pixel
/// wide that none of a level's few rounds hit leaves a pixel's rounds alike
/// and its estimate 0; its neighbour that did hit it stays open, so the
/// pixel is looked at again. On the 24 x 24 sky-lit sphere of
/// crates/sunbeam-raster/tests/environment.rs, from 16 samples: two seeds'
/// converged frames differed by CIEDE2000 p99 2.27 without this (two plain
/// 256-sample frames: 1.47), 0.31 with it.
fn keep_beside_open(open: &mut [bool], level_open: &[bool], w: usize) {
    let h = open.len() / w.max(1);
    let was = open.to_vec();
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if was[i] || !level_open[i] {
                continue;
            }
            let near = (y.saturating_sub(1)..(y + 2).min(h))
                .any(|yy| (x.saturating_sub(1)..(x + 2).min(w)).any(|xx| was[yy * w + xx]));
            open[i] = near;
        }
    }
}

/// Close the open pixels whose estimate is at most `de` (or that are unlit).
fn close(open: &mut [bool], acc: &[Moments], de: f64) {
    for (o, m) in open.iter_mut().zip(acc) {
        *o = *o && m.estimate().is_some_and(|e| e > de);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_zero_is_the_seed_and_rounds_differ() {
        assert_eq!(round_seed(7, 0), 7);
        let s: std::collections::BTreeSet<u64> = (0..64)
            .flat_map(|r| [round_seed(1, r), round_seed(2, r)])
            .collect();
        assert_eq!(s.len(), 128);
    }

    #[test]
    fn the_estimate_is_the_error_of_the_mean() {
        // Rounds alternating 0.2 +- 0.01 in red: se = 0.01 / sqrt(k) (sample
        // variance with k - 1), the estimate is dE of that step in red.
        let mut m = Moments::default();
        for i in 0..16 {
            let d = if i % 2 == 0 { 0.01 } else { -0.01 };
            m.add([0.2 + d, 0.2, 0.2]);
        }
        let se = m.se();
        let want = 0.01 * (16.0f64 / 15.0).sqrt() / 4.0;
        assert!((se[0] / want - 1.0).abs() < 1e-4, "{se:?} vs {want}");
        assert!(se[1] < 1e-9 && se[2] < 1e-9, "{se:?}");
        let xyz = |v: [f64; 3]| linear_srgb_to_xyz(v);
        let de = ciede2000_xyz(xyz([0.2, 0.2, 0.2]), xyz([0.2 + want, 0.2, 0.2]));
        let e = m.estimate().unwrap();
        assert!((e / de - 1.0).abs() < 1e-3, "{e} vs {de}");
        // Unlit with margin: no estimate.
        let mut dark = Moments::default();
        dark.add([1e-5, 1e-5, 1e-5]);
        dark.add([2e-5, 1e-5, 1e-5]);
        assert!(dark.estimate().is_none());
    }
}
