//! One interface over the two kinds of environment a scene can name: the
//! built-in sky ([`crate::sky::Sky`]) and an equirectangular map
//! ([`crate::EnvMap`], its RGB made spectral by [`crate::rgb_spectrum`]).
//! Radiance is in scene units: a D65 spectrum of luminance 1 is `D65(lambda)`.

use crate::rgb_spectrum::RgbBasis;
use crate::sky::Sky;
use crate::{daylight, EnvMap};
use rayon::prelude::*;
use sunbeam_optics::{cie, colour};

/// The basis spectra of every sky (CIE daylight `S0, S1, S2`), as
/// [`Environment::basis_at`] for a sky: the same for every sky, so a pack's
/// maps in this basis can be built before the scene is known.
pub fn sky_basis_at(lambda_m: f64) -> [f64; 3] {
    daylight::basis_at(lambda_m)
}

/// The basis spectra of every map (`D65(lambda) b_k(lambda)`), as
/// [`Environment::basis_at`] for a map (the same for every map).
pub fn map_basis_at(lambda_m: f64) -> [f64; 3] {
    let d65 = cie::d65_at(lambda_m);
    RgbBasis::get().at(lambda_m).map(|b| d65 * b)
}

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
            Environment::Sky(_) => sky_basis_at(lambda_m),
            Environment::Map(_) => map_basis_at(lambda_m),
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
    /// the table has the map's own size with the rotation baked in: its
    /// columns start [`Environment::table_phase`] of a turn after `phi = 0`
    /// (column `i` covers `phi / 2 pi` in `[i / W + phase, (i + 1) / W +
    /// phase)`), so that each column is exactly one column of the rotated map
    /// and the table equals `coefficients` everywhere, whatever the rotation.
    /// Readers subtract the phase from `phi / 2 pi` (shaders/env_table.wgsl).
    pub fn coefficient_table(&self, height: usize) -> (usize, usize, Vec<f32>) {
        let h = match self {
            Environment::Sky(_) => height.max(1),
            Environment::Map(m) => m.height(),
        };
        let w = 2 * h;
        let phase = self.table_phase();
        let mut out = vec![0.0f32; w * h * 4];
        // Rows in parallel (each texel is its own; the table does not depend
        // on the thread count): 0.52 s serially for a 4096 x 2048 map
        // (crates/sunbeam-light/benches/env_tables.rs).
        out.par_chunks_mut(w * 4).enumerate().for_each(|(j, row)| {
            let theta = (j as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            for (i, t) in row.chunks_exact_mut(4).enumerate() {
                let phi = ((i as f64 + 0.5) / w as f64 + phase) * std::f64::consts::TAU;
                let c = self.coefficients(crate::direction(theta.cos(), phi));
                t.copy_from_slice(&[c[0] as f32, c[1] as f32, c[2] as f32, 0.0]);
            }
        });
        (w, h, out)
    }

    /// Where [`Environment::coefficient_table`]'s columns start, in turns
    /// after `phi = 0`, in `[0, 1 / W)`: 0 for a sky, and for a map the
    /// fraction of a column by which its rotation turns the map's column
    /// edges off the table's grid (0 when the rotation is a multiple of
    /// `360 / W` degrees). Without it, a table at the map's size could only
    /// hold the nearest texel of the rotated map at its centres, which moved
    /// every edge of the map by up to half a texel: under studio.exr turned
    /// 30 degrees (85.33 columns of 1024) the first frame's sharp diffraction
    /// orders sat 0.1 sub-pixel off the reference's, CIEDE2000 p99 2.0
    /// against 1.3 at 29.88 degrees (85 columns).
    pub fn table_phase(&self) -> f64 {
        match self {
            Environment::Sky(_) => 0.0,
            Environment::Map(m) => {
                let w = 2 * m.height();
                // the map's column coordinate of world phi = 0
                let l = m.local([1.0, 0.0, 0.0]);
                let u0 = l[2].atan2(l[0]).rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU
                    * w as f64;
                let p = (-u0).rem_euclid(1.0);
                // (a whole number of columns, up to rounding: no phase)
                if (1e-9..=1.0 - 1e-9).contains(&p) {
                    p / w as f64
                } else {
                    0.0
                }
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::Sky;
    use sunbeam_common::rng::SplitMix64;

    fn test_map(rot: f64) -> EnvMap {
        let (w, h) = (16, 8);
        let rgb = (0..w * h)
            .map(|k| [(k % 7) as f32 * 0.3, (k % 3) as f32 + 0.1, (k % 5) as f32])
            .collect();
        EnvMap::new(w, h, rgb, rot, 1.5).unwrap()
    }

    /// A map's radiance, `D65 sum_k rgb_k b_k`, from the texel the test
    /// finds itself (no rotation): `basis_at . coefficients` and `spectral`
    /// reproduce it to 1e-9 at random directions and wavelengths.
    #[test]
    fn map_coefficients_reproduce_the_spectrum() {
        let m = test_map(0.0);
        let raw: Vec<[f32; 3]> = (0..16 * 8)
            .map(|k| [(k % 7) as f32 * 0.3, (k % 3) as f32 + 0.1, (k % 5) as f32])
            .collect();
        let env = Environment::Map(m);
        let mut r = SplitMix64::new(4);
        for _ in 0..2000 {
            let (ct, phi) = (2.0 * r.unit() - 1.0, std::f64::consts::TAU * r.unit());
            let d = crate::direction(ct, phi);
            let (i, j) = (
                (phi / std::f64::consts::TAU * 16.0) as usize,
                (ct.acos() / std::f64::consts::PI * 8.0) as usize,
            );
            // The map stores texels times intensity as f32.
            let rgb = raw[j * 16 + i].map(|v| (v as f64 * 1.5) as f32 as f64);
            let l = (380.0 + 400.0 * r.unit()) * 1e-9;
            let b = RgbBasis::get().at(l);
            let want = cie::d65_at(l) * (rgb[0] * b[0] + rgb[1] * b[1] + rgb[2] * b[2]);
            let (c, bk) = (env.coefficients(d), env.basis_at(l));
            let got = c[0] * bk[0] + c[1] * bk[1] + c[2] * bk[2];
            let s = env.spectral(d, l);
            for v in [got, s] {
                assert!(
                    (v - want).abs() <= 1e-9 * want.abs().max(1e-12),
                    "{v} vs {want}"
                );
            }
        }
    }

    /// The table holds the coefficients of its texels: a sky's at the
    /// centres; a map's, rotated by any angle and read with its phase,
    /// everywhere in the texel. The sun is absent from it and reported by `sun`.
    #[test]
    fn coefficient_table_matches_coefficients() {
        let sky = Environment::Sky(Box::new(Sky::new(30.0, 10.0, 3.0, 1.0)));
        assert!(sky.sun().is_some());
        let night = Environment::Sky(Box::new(Sky::new(0.0, 10.0, 3.0, 1.0)));
        assert!(night.sun().is_none());
        let (w, h, t) = sky.coefficient_table(16);
        assert_eq!((w, h, t.len()), (32, 16, 32 * 16 * 4));
        for (i, j) in [(0, 0), (5, 3), (31, 15), (12, 8), (7, 7)] {
            let theta = (j as f64 + 0.5) / 16.0 * std::f64::consts::PI;
            let phi = (i as f64 + 0.5) / 32.0 * std::f64::consts::TAU;
            let c = sky.coefficients(crate::direction(theta.cos(), phi));
            let o = 4 * (j * w + i);
            for k in 0..3 {
                assert!((t[o + k] as f64 - c[k]).abs() <= 1e-6 * c[k].abs().max(1e-9));
            }
            assert_eq!(t[o + 3], 0.0);
        }
        // Whole and fractional numbers of texels, either way: read with the
        // table's phase, the table is the rotated map everywhere.
        for texels in [3.0, 3.37, -5.71, 0.5] {
            let map = Environment::Map(test_map(texels * 360.0 / 16.0));
            let phase = map.table_phase();
            assert!((0.0..1.0 / 16.0).contains(&phase), "{phase}");
            if texels == 3.0 {
                assert_eq!(phase, 0.0);
            }
            let (w, h, t) = map.coefficient_table(99);
            assert_eq!((w, h), (16, 8));
            let mut r = SplitMix64::new(8);
            for _ in 0..2000 {
                let (ct, phi) = (2.0 * r.unit() - 1.0, std::f64::consts::TAU * r.unit());
                let fi = (phi / std::f64::consts::TAU - phase) * 16.0;
                let (i, j) = (
                    (fi.rem_euclid(16.0) as usize).min(15),
                    ((ct.acos() / std::f64::consts::PI * 8.0) as usize).min(7),
                );
                let c = map.coefficients(crate::direction(ct, phi));
                let o = 4 * (j * w + i);
                // Texel borders are where rounding may pick the neighbour.
                if (fi - fi.round()).abs() < 1e-9 {
                    continue;
                }
                assert_eq!(
                    [t[o], t[o + 1], t[o + 2]],
                    c.map(|v| v as f32),
                    "{texels} texels"
                );
            }
        }
    }
}
