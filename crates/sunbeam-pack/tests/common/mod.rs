//! Shared helpers for the pack tests: synthetic height fields and a tiny RNG.
#![allow(dead_code)]

use sunbeam_field::HeightField;
use sunbeam_pack::build::{BuildOptions, FieldRef};
use sunbeam_pack::Pack;

/// Deterministic random numbers in [0, 1): the project's seeded
/// `SplitMix64` (`sunbeam_common::rng`), state in `.0`.
pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> f64 {
        let mut g = sunbeam_common::rng::SplitMix64(self.0);
        let v = g.unit();
        self.0 = g.0;
        v
    }
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

pub fn field(w: usize, h: usize, dx: f64, dy: f64, f: impl Fn(f64, f64) -> f64) -> HeightField {
    let mut d = Vec::with_capacity(w * h);
    for r in 0..h {
        for c in 0..w {
            // x along columns, y up the image.
            d.push(f(c as f64 * dx, (h - 1 - r) as f64 * dy));
        }
    }
    HeightField::new(w, h, dx, dy, d).unwrap()
}

/// A rough, asymmetric "snake-like" surface: ridges plus smooth bumps, peak-to-peak about `amp`.
pub fn rough(w: usize, h: usize, dx: f64, dy: f64, amp: f64, seed: u64) -> HeightField {
    let mut rng = Rng(seed);
    let bumps: Vec<(f64, f64, f64, f64)> = (0..12)
        .map(|_| {
            (
                rng.range(0.0, w as f64 * dx),
                rng.range(0.0, h as f64 * dy),
                rng.range(0.1e-6, 0.5e-6),
                rng.range(-1.0, 1.0),
            )
        })
        .collect();
    let period = 1.1e-6;
    let mut f = field(w, h, dx, dy, |x, y| {
        let ridge = ((x / period).fract() - 0.5).abs() * 2.0; // triangle ridges along x
        let saw = (x / period + 0.3 * (y / 2.0e-6).sin()).fract(); // asymmetric
        let mut b = 0.0;
        for &(bx, by, s, a) in &bumps {
            b += a * (-((x - bx).powi(2) + (y - by).powi(2)) / (2.0 * s * s)).exp();
        }
        0.4 * ridge + 0.4 * saw + 0.3 * b
    });
    let (lo, hi) = f.finite_range().unwrap();
    for v in &mut f.data {
        *v = (*v - lo) / (hi - lo) * amp + 50e-9; // offset: heights need not start at 0
    }
    f
}

pub fn fref(f: &HeightField) -> FieldRef<'_> {
    FieldRef {
        width: f.width,
        height: f.height,
        dx: f.dx,
        dy: f.dy,
        data: &f.data,
    }
}

pub fn build(f: &HeightField, o: &BuildOptions) -> Pack {
    sunbeam_pack::build(fref(f), o, &mut |_, _| {}).unwrap()
}

/// Random (u, v, w, lambda) from random light and view directions in the upper hemisphere.
pub fn random_query(rng: &mut Rng, max_theta_deg: f64) -> (f64, f64, f64, f64) {
    let dir = |rng: &mut Rng| {
        let th = rng.range(0.0, max_theta_deg).to_radians();
        let ph = rng.range(0.0, 2.0 * std::f64::consts::PI);
        [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()]
    };
    let wi = dir(rng);
    let wr = dir(rng);
    let l = rng.range(380e-9, 780e-9);
    (-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2], l)
}
