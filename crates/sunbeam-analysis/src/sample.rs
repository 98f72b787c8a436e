//! Deterministic direction and point sampling shared by compare, brdf and bench.

use sunbeam_common::rng::SplitMix64;

/// The project's seeded generator (`sunbeam_common::rng::SplitMix64`, the
/// same sequence everywhere) with the sampling this crate needs.
pub struct Rng(SplitMix64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(SplitMix64::new(seed))
    }
    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        self.0.unit()
    }
    /// A direction uniform in solid angle on the upper hemisphere with d.n >= min_cos.
    pub fn hemisphere(&mut self, min_cos: f64) -> [f64; 3] {
        let z = min_cos + (1.0 - min_cos) * self.next_f64();
        let phi = 2.0 * std::f64::consts::PI * self.next_f64();
        let s = (1.0 - z * z).max(0.0).sqrt();
        [s * phi.cos(), s * phi.sin(), z]
    }
}

/// `n` random points `(u, v, w, lambda)` of `R`: `wi` and `wr` uniform in
/// solid angle with `d.n >= min_cos` (`u, v, w = -(wi + wr)`), kept when
/// `|w| <= max_w`, then `lambda` uniform in `lambda_range` (metres). The same
/// seed gives the same points.
pub fn scatter_points(
    n: usize,
    seed: u64,
    min_cos: f64,
    max_w: f64,
    lambda_range: (f64, f64),
) -> Vec<[f64; 4]> {
    let mut rng = Rng::new(seed);
    let mut pts = Vec::with_capacity(n);
    while pts.len() < n {
        let wi = rng.hemisphere(min_cos);
        let wr = rng.hemisphere(min_cos);
        let w = -wi[2] - wr[2];
        if w.abs() > max_w {
            continue;
        }
        let (l0, l1) = lambda_range;
        let l = l0 + (l1 - l0) * rng.next_f64();
        pts.push([-wi[0] - wr[0], -wi[1] - wr[1], w, l]);
    }
    pts
}

/// `n` directions on the upper hemisphere (Fibonacci lattice, uniform in solid
/// angle), with d.n in [min_cos, 1].
pub fn fibonacci_hemisphere(n: usize, min_cos: f64) -> Vec<[f64; 3]> {
    let ga = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (1.0 - min_cos) * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let phi = ga * i as f64;
            [s * phi.cos(), s * phi.sin(), z]
        })
        .collect()
}

/// A light direction from polar angle and azimuth (radians).
pub fn dir(theta: f64, phi: f64) -> [f64; 3] {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

/// Percentile (0..100) of a slice (nearest rank on a sorted copy).
pub fn percentile(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return f64::NAN;
    }
    s.sort_by(|a, b| a.total_cmp(b));
    let rank = ((p / 100.0) * s.len() as f64).ceil() as usize;
    s[rank.clamp(1, s.len()) - 1]
}
