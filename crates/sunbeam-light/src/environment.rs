//! One interface over the two kinds of environment a scene can name: the
//! built-in sky ([`crate::sky::Sky`]) and an equirectangular map
//! ([`crate::EnvMap`], its RGB made spectral by [`crate::rgb_spectrum`]).
//! Radiance is in scene units: a D65 spectrum of luminance 1 is `D65(lambda)`.

use crate::rgb_spectrum::RgbBasis;
use crate::sky::Sky;
use crate::{daylight, EnvMap};
use sunbeam_optics::{cie, colour};

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

    /// Basis spectra `B_k(lambda)` of the radiance without the sun (scene
    /// units): the sky's `[S0, S1, S2]` (CIE daylight basis), a map's
    /// `D65(lambda) b_k(lambda)` ([`RgbBasis`]). With [`Environment::coefficients`],
    /// `L(d, lambda) = sum_k c_k(d) B_k(lambda)` exactly (the sun aside), which
    /// is what lets a pack's extended-light response be three precomputed maps
    /// (docs/LIGHTING.md "Basis spectra").
    pub fn basis_at(&self, lambda_m: f64) -> [f64; 3] {
        match self {
            Environment::Sky(_) => daylight::basis_at(lambda_m),
            Environment::Map(_) => {
                let d65 = cie::d65_at(lambda_m);
                RgbBasis::get().at(lambda_m).map(|b| d65 * b)
            }
        }
    }

    /// Coefficients `c_k(d)` of the radiance from world direction `d` (unit)
    /// without the sun, in the basis of [`Environment::basis_at`]: the sky's
    /// (or ground's) daylight weights, a map's linear RGB (intensity and
    /// rotation applied, as [`EnvMap::lookup`]).
    pub fn coefficients(&self, d: [f64; 3]) -> [f64; 3] {
        match self {
            Environment::Sky(s) => s.coefficients(d),
            Environment::Map(m) => m.lookup(d).map(f64::from),
        }
    }

    /// The sky when its sun is up (the one part of the radiance outside the
    /// basis: shaded as a disc of its own), else None.
    pub fn sun(&self) -> Option<&Sky> {
        match self {
            Environment::Sky(s) if s.sun_is_up() => Some(s),
            _ => None,
        }
    }

    /// An equirectangular table of [`Environment::coefficients`] for the
    /// player's texture: `(width, height, rgba)` with `width = 2 height`, the
    /// [`EnvMap`] convention (column `i` covers `phi` in `2 pi [i, i + 1) / W`,
    /// row `j` covers `theta` in `pi [j, j + 1) / H`, `theta` from +y, `phi =
    /// atan2(z, x)`), texels `[c_0, c_1, c_2, 0]` row-major from the top.
    ///
    /// Sky: `height` rows, each texel the coefficients at its centre (the sky
    /// is smooth; the ground's texels are exact). Map: `height` is ignored and
    /// the table has the map's own size, each texel the map's value at the
    /// texel's centre direction, so the rotation is baked in: exact (equal to
    /// `coefficients` everywhere) when the rotation is a multiple of `360 / W`
    /// degrees, otherwise the nearest texel of the rotated map at the centres.
    pub fn coefficient_table(&self, height: usize) -> (usize, usize, Vec<f32>) {
        let h = match self {
            Environment::Sky(_) => height.max(1),
            Environment::Map(m) => m.height(),
        };
        let w = 2 * h;
        let mut out = Vec::with_capacity(w * h * 4);
        for j in 0..h {
            let theta = (j as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            for i in 0..w {
                let phi = (i as f64 + 0.5) / w as f64 * std::f64::consts::TAU;
                let c = self.coefficients(crate::direction(theta.cos(), phi));
                out.extend([c[0] as f32, c[1] as f32, c[2] as f32, 0.0]);
            }
        }
        (w, h, out)
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
