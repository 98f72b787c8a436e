//! One interface over the two kinds of environment a scene can name: the
//! built-in sky ([`crate::sky::Sky`]) and an equirectangular map
//! ([`crate::EnvMap`], its RGB made spectral by [`crate::rgb_spectrum`]).
//! Radiance is in scene units: a D65 spectrum of luminance 1 is `D65(lambda)`.

use crate::rgb_spectrum::RgbBasis;
use crate::sky::Sky;
use crate::EnvMap;
use sunbeam_optics::colour;

/// Extended light around a scene.
#[derive(Debug, Clone)]
pub enum Environment {
    Sky(Box<Sky>),
    Map(EnvMap),
}

impl Environment {
    /// Spectral radiance arriving from world direction `d` (unit) at `lambda_m`.
    pub fn spectral(&self, d: [f64; 3], lambda_m: f64) -> f64 {
        self.spectrum(d).at(lambda_m)
    }

    /// The spectrum arriving from `d`, for evaluating at several wavelengths
    /// ([`DirSpectrum::at`] equals [`Environment::spectral`]; the sky model or
    /// the map lookup runs once).
    pub fn spectrum(&self, d: [f64; 3]) -> DirSpectrum<'_> {
        match self {
            Environment::Sky(s) => DirSpectrum::Sky(s, s.spectrum(d)),
            Environment::Map(m) => DirSpectrum::Rgb(m.lookup(d).map(f64::from)),
        }
    }

    /// XYZ of the radiance from `d`, consistent with [`Environment::spectral`].
    pub fn xyz(&self, d: [f64; 3]) -> [f64; 3] {
        match self {
            Environment::Sky(s) => s.xyz(d),
            Environment::Map(m) => colour::linear_srgb_to_xyz(m.lookup(d).map(f64::from)),
        }
    }

    /// Linear sRGB of the radiance from `d`.
    pub fn rgb(&self, d: [f64; 3]) -> [f64; 3] {
        match self {
            Environment::Sky(s) => colour::xyz_to_linear_srgb(s.xyz(d)),
            Environment::Map(m) => m.lookup(d).map(f64::from),
        }
    }

    /// A direction drawn from three uniform numbers in [0, 1), with its density (1/sr).
    pub fn sample(&self, u0: f64, u1: f64, u2: f64) -> Option<([f64; 3], f64)> {
        match self {
            Environment::Sky(s) => s.sample(u0, u1, u2),
            Environment::Map(m) => m.sample(u1, u2),
        }
    }

    /// Density (1/sr) with which [`Environment::sample`] draws `d`.
    pub fn pdf(&self, d: [f64; 3]) -> f64 {
        match self {
            Environment::Sky(s) => s.pdf(d),
            Environment::Map(m) => m.pdf(d),
        }
    }
}

/// The radiance from one direction of an [`Environment`].
#[derive(Debug, Clone, Copy)]
pub enum DirSpectrum<'a> {
    Sky(&'a Sky, crate::sky::SkySpectrum),
    /// A map texel's linear sRGB, made spectral by [`RgbBasis`].
    Rgb([f64; 3]),
}

impl DirSpectrum<'_> {
    /// Spectral radiance at `lambda_m` (scene units).
    pub fn at(&self, lambda_m: f64) -> f64 {
        match self {
            DirSpectrum::Sky(s, sp) => sp.at(s, lambda_m),
            DirSpectrum::Rgb(c) => RgbBasis::get().radiance(*c, lambda_m),
        }
    }
}
