//! Synthetic height fields, deterministic (a seeded SplitMix64, no system RNG),
//! so that `make demo` works on a fresh machine without `../shared/data` and so
//! that benchmarks and tests have surfaces with known periods.
//!
//! The snake-like presets imitate the thesis' AFM patches (see
//! `../shared/data/snake/README.md`): parallel micro-ridges whose crests run
//! along y, repeating along x with the period the thesis estimates for each
//! species (Elaphe ~1144 nm, Xenopeltis ~1552 nm), with an asymmetric
//! (finger-like) profile, gentle waviness, finger breaks along the ridge, and
//! a little band-limited roughness. They are stand-ins, not measurements.

use sunbeam_common::rng::SplitMix64;
use sunbeam_common::{Error, Result};
use sunbeam_field::{HeightField, Provenance};

/// Parameters of a ridge field.
#[derive(Debug, Clone, PartialEq)]
pub struct Ridges {
    /// Ridge period along x, metres.
    pub period: f64,
    /// Peak-to-valley height, metres.
    pub height: f64,
    /// Fraction of a period spent rising (0.5 = symmetric; small = blazed).
    pub rise: f64,
    /// Amplitude of the ridges' sideways waviness, metres.
    pub wave_amplitude: f64,
    /// Wavelength of the waviness along y, metres.
    pub wave_length: f64,
    /// Length of a "finger" along y before it breaks (0 = continuous ridges), metres.
    pub finger_length: f64,
    /// RMS of the added roughness as a fraction of `height`.
    pub roughness: f64,
    pub seed: u64,
}

/// Named presets, as accepted by `sunbeam-import synthetic:NAME`.
pub const PRESETS: &[&str] = &["elaphe", "xenopeltis", "sine", "blazed"];

impl Ridges {
    pub fn preset(name: &str) -> Result<Self> {
        let base = Ridges {
            period: 1.144e-6,
            height: 375e-9,
            rise: 0.35,
            wave_amplitude: 60e-9,
            wave_length: 5.0e-6,
            finger_length: 3.0e-6,
            roughness: 0.03,
            seed: 1,
        };
        Ok(match name {
            "elaphe" => base,
            "xenopeltis" => Ridges {
                period: 1.552e-6,
                height: 443.45e-9,
                rise: 0.45,
                wave_amplitude: 40e-9,
                wave_length: 7.0e-6,
                finger_length: 0.0,
                roughness: 0.02,
                seed: 2,
            },
            "sine" => Ridges {
                period: 2.5e-6,
                height: 246.23e-9,
                rise: 0.5,
                wave_amplitude: 0.0,
                wave_length: 1.0,
                finger_length: 0.0,
                roughness: 0.0,
                seed: 0,
            },
            "blazed" => Ridges {
                period: 2.5e-6,
                height: 246.23e-9,
                rise: 1.0,
                wave_amplitude: 0.0,
                wave_length: 1.0,
                finger_length: 0.0,
                roughness: 0.0,
                seed: 0,
            },
            other => {
                return Err(Error::usage(format!(
                    "unknown synthetic preset '{other}' (one of: {})",
                    PRESETS.join(", ")
                )))
            }
        })
    }

    /// Sample the field on `width x height` pixels of size `pixel` (metres).
    pub fn generate(
        &self,
        name: &str,
        width: usize,
        height: usize,
        pixel: f64,
    ) -> Result<HeightField> {
        if !(self.period > 0.0 && self.height >= 0.0 && (0.0..=1.0).contains(&self.rise)) {
            return Err(Error::usage(
                "synthetic ridges: need period > 0, height >= 0, rise in [0, 1]",
            ));
        }
        let mut rng = SplitMix64(self.seed);
        let noise = if self.roughness > 0.0 {
            smooth_noise(width, height, 3, &mut rng)
        } else {
            vec![0.0; width * height]
        };
        // Per-ridge random phase of the finger breaks, so fingers are staggered.
        let n_ridges = ((width as f64 * pixel) / self.period).ceil() as usize + 2;
        let finger_phase: Vec<f64> = (0..n_ridges).map(|_| rng.unit()).collect();
        let mut data = Vec::with_capacity(width * height);
        for r in 0..height {
            // y runs up the image (PHYSICS.md 1): row 0 is the top.
            let y = (height - 1 - r) as f64 * pixel;
            let shift =
                self.wave_amplitude * (2.0 * std::f64::consts::PI * y / self.wave_length).sin();
            for c in 0..width {
                let x = c as f64 * pixel + shift;
                let phase = x / self.period;
                let ridge = phase.floor();
                let frac = phase - ridge;
                let mut z = profile(frac, self.rise);
                if self.finger_length > 0.0 {
                    let idx = (ridge.rem_euclid(n_ridges as f64)) as usize;
                    let p = y / self.finger_length + finger_phase[idx];
                    // Each finger tapers to zero at its ends over ~15 % of its length.
                    let q = p - p.floor();
                    let taper = smoothstep(0.0, 0.15, q) * smoothstep(1.0, 0.85, q);
                    z *= 0.35 + 0.65 * taper;
                }
                z += self.roughness * noise[r * width + c];
                data.push(z * self.height);
            }
        }
        let mut f = HeightField::new(width, height, pixel, pixel, data)?;
        f.provenance = Provenance {
            source_file: format!("synthetic:{name}"),
            source_format: "synthetic".into(),
            channel: "Height".into(),
            processing: vec![],
        };
        Ok(f)
    }
}

/// Convenience: a named preset on a `size x size` grid with pixel `pixel`.
pub fn preset(name: &str, size: usize, pixel: f64) -> Result<HeightField> {
    Ridges::preset(name)?.generate(name, size, size, pixel)
}

/// Ridge profile over one period, 0..1: rises over `rise` of the period, falls over the rest.
/// `rise = 0.5` gives a raised cosine (the sine grating), `rise = 1` a sawtooth.
fn profile(frac: f64, rise: f64) -> f64 {
    use std::f64::consts::PI;
    if (rise - 0.5).abs() < 1e-12 {
        return 0.5 - 0.5 * (2.0 * PI * frac).cos();
    }
    if rise >= 1.0 {
        return frac;
    }
    if rise <= 0.0 {
        return 1.0 - frac;
    }
    if frac < rise {
        0.5 - 0.5 * (PI * frac / rise).cos()
    } else {
        0.5 + 0.5 * (PI * (frac - rise) / (1.0 - rise)).cos()
    }
}

fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Unit-RMS noise low-passed by `passes` box blurs of radius 2 (periodic edges).
fn smooth_noise(w: usize, h: usize, passes: usize, rng: &mut SplitMix64) -> Vec<f64> {
    let mut a: Vec<f64> = (0..w * h).map(|_| rng.unit() - 0.5).collect();
    let mut b = vec![0.0; w * h];
    for _ in 0..passes {
        for r in 0..h {
            for c in 0..w {
                let mut s = 0.0;
                for k in -2i64..=2 {
                    s += a[r * w + (c as i64 + k).rem_euclid(w as i64) as usize];
                }
                b[r * w + c] = s / 5.0;
            }
        }
        for r in 0..h {
            for c in 0..w {
                let mut s = 0.0;
                for k in -2i64..=2 {
                    s += b[(r as i64 + k).rem_euclid(h as i64) as usize * w + c];
                }
                a[r * w + c] = s / 5.0;
            }
        }
    }
    let rms = (a.iter().map(|v| v * v).sum::<f64>() / a.len() as f64).sqrt();
    if rms > 0.0 {
        a.iter_mut().for_each(|v| *v /= rms);
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dominant spatial frequency along x must be the preset's period:
    /// checked with a direct DFT of the row-averaged profile (independent of the generator).
    #[test]
    fn dominant_period_matches_preset() {
        for name in ["elaphe", "xenopeltis", "sine"] {
            let px = 20e-9;
            let n = 400; // 8 um
            let f = preset(name, n, px).unwrap();
            let mean_row: Vec<f64> = (0..n)
                .map(|c| (0..n).map(|r| f.at(r, c)).sum::<f64>() / n as f64)
                .collect();
            let mut best = (0, 0.0);
            for k in 1..n / 2 {
                let (mut re, mut im) = (0.0, 0.0);
                for (c, v) in mean_row.iter().enumerate() {
                    let a = -2.0 * std::f64::consts::PI * (k * c) as f64 / n as f64;
                    re += v * a.cos();
                    im += v * a.sin();
                }
                let p = re * re + im * im;
                if p > best.1 {
                    best = (k, p);
                }
            }
            let period = n as f64 * px / best.0 as f64;
            let want = Ridges::preset(name).unwrap().period;
            // One DFT bin at k ~ 5..7 is ~15 % wide: check the nearest bin.
            let k_want = (n as f64 * px / want).round() as usize;
            assert_eq!(best.0, k_want, "{name}: dominant period {period} vs {want}");
        }
    }

    #[test]
    fn deterministic_and_in_range() {
        let a = preset("elaphe", 64, 25e-9).unwrap();
        let b = preset("elaphe", 64, 25e-9).unwrap();
        assert_eq!(a, b);
        let (lo, hi) = a.finite_range().unwrap();
        assert!(lo > -0.2 * 375e-9 && hi < 1.2 * 375e-9, "{lo} {hi}");
        assert!(Ridges::preset("nope").is_err());
    }

    #[test]
    fn blazed_is_a_sawtooth() {
        let f = preset("blazed", 100, 25e-9).unwrap();
        // Rises linearly over one 2.5 um period = 100 px.
        assert!((f.at(0, 50) - 0.5 * 246.23e-9).abs() < 1e-12);
        assert!(f.at(0, 99) > f.at(0, 98));
    }
}
