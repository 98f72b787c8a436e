//! The irradiance of an environment at every normal, tabulated: the diffuse
//! part of the reference's quadrature estimator (`base / pi` times this), so
//! that a Lambertian term adds no Monte Carlo noise.
//!
//! `E(n) = int L(d) max(n . d, 0) dw` of the radiance without the sun by a
//! midpoint rule over 512 x 256 directions equal in solid angle (rows uniform
//! in `d_y`), at the normals of a 96 x 48 equirectangular table read
//! bilinearly (`E` is the radiance convolved with a clamped cosine, smooth at
//! that spacing); the sun's disc adds `Omega L_sun max(n . s, 0)` exactly (a
//! disc of 0.5 degrees as a point: within 1e-5 away from its terminator).

use crate::Environment;
use rayon::prelude::*;
use std::f64::consts::PI;
use sunbeam_optics::colour;

/// Directions of the quadrature (width; height is half).
const DIRS_W: usize = 512;
/// Normals of the table (width; height is half).
const NORMALS_W: usize = 96;

/// Intervals of a weight other than the clamped cosine, tabulated over `c`
/// in [0, 1] and read linearly ([`Irradiance::transmitted`]: error below 1e-7).
const WEIGHT_TABLE: usize = 4096;

/// Irradiance (linear sRGB) per normal of one environment.
#[derive(Debug, Clone)]
pub struct Irradiance {
    /// The weight `w(c)` of `c = n . d` tabulated (none: `c` itself).
    weight: Option<Vec<f64>>,
    /// Rows from `n_y = 1` to `-1` (angle `theta` from +y at row centres
    /// `pi (j + 0.5) / H`), columns `phi = atan2(z, x)` at `2 pi (i + 0.5) / W`.
    table: Vec<[f64; 3]>,
    /// The sun's direction and `Omega L_sun` (linear sRGB), when it is up.
    sun: Option<([f64; 3], [f64; 3])>,
}

impl Irradiance {
    pub fn new(env: &Environment) -> Irradiance {
        Self::build(env, None)
    }

    /// The irradiance a diffuse base under a dielectric skin of index `ior`
    /// receives: `int L(d) max(n . d, 0) (1 - F(n . d)) dw` (PHYSICS.md 2: the
    /// base gets what the interface does not reflect; `F` the exact Fresnel
    /// reflectance, `sunbeam_optics::gain::fresnel`), the same tabulation with
    /// the weight `c (1 - F(c))` in place of `c`.
    pub fn transmitted(env: &Environment, ior: f64) -> Irradiance {
        let w = (0..=WEIGHT_TABLE + 1)
            .map(|i| {
                let c = (i as f64 / WEIGHT_TABLE as f64).min(1.0);
                c * (1.0 - sunbeam_optics::gain::fresnel(c, ior))
            })
            .collect();
        Self::build(env, Some(w))
    }

    /// The weight at `c` in (0, 1].
    fn weight_at(weight: &Option<Vec<f64>>, c: f64) -> f64 {
        match weight {
            None => c,
            Some(w) => {
                let x = c.min(1.0) * WEIGHT_TABLE as f64;
                let i = (x as usize).min(WEIGHT_TABLE - 1);
                let f = x - i as f64;
                w[i] * (1.0 - f) + w[i + 1] * f
            }
        }
    }

    fn build(env: &Environment, weight: Option<Vec<f64>>) -> Irradiance {
        let sun = env.sun();
        // The radiance without the sun, on directions of equal solid angle.
        let (dw, dh) = (DIRS_W, DIRS_W / 2);
        let dirs: Vec<([f64; 3], [f64; 3])> = (0..dw * dh)
            .map(|k| {
                let (i, j) = (k % dw, k / dw);
                let y = 1.0 - 2.0 * (j as f64 + 0.5) / dh as f64;
                let phi = 2.0 * PI * (i as f64 + 0.5) / dw as f64;
                let d = crate::direction(y, phi);
                let rgb = match sun {
                    Some(s) if s.in_sun(d) => {
                        let c = s.coefficients(d);
                        let b = crate::daylight::basis_xyz();
                        colour::xyz_to_linear_srgb(std::array::from_fn(|a| {
                            (0..3).map(|k| c[k] * b[k][a]).sum()
                        }))
                    }
                    _ => env.rgb(d),
                };
                (d, rgb)
            })
            .collect();
        let d_omega = 4.0 * PI / (dw * dh) as f64;
        let (nw, nh) = (NORMALS_W, NORMALS_W / 2);
        let table = (0..nw * nh)
            .into_par_iter()
            .map(|k| {
                let (i, j) = (k % nw, k / nw);
                let theta = PI * (j as f64 + 0.5) / nh as f64;
                let phi = 2.0 * PI * (i as f64 + 0.5) / nw as f64;
                let n = crate::direction(theta.cos(), phi);
                let mut e = [0.0; 3];
                for (d, rgb) in &dirs {
                    let c = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
                    if c > 0.0 {
                        let wc = Self::weight_at(&weight, c);
                        for a in 0..3 {
                            e[a] += rgb[a] * wc;
                        }
                    }
                }
                e.map(|v| v * d_omega)
            })
            .collect();
        let sun = sun.map(|s| {
            let rgb = colour::xyz_to_linear_srgb(s.sun_xyz());
            (s.sun_direction(), rgb.map(|v| v * s.sun_solid_angle()))
        });
        Irradiance { weight, table, sun }
    }

    /// The table without the sun (the player's texture, read bilinearly as
    /// [`Irradiance::at`]; the sun's disc is added in the shader):
    /// `(width, height, rgba)` over normals, rows from `n_y = 1` down,
    /// columns `phi = atan2(z, x)`, texel centres at `(i + 0.5) / W`.
    pub fn table_rgba(&self) -> (usize, usize, Vec<f32>) {
        let (nw, nh) = (NORMALS_W, NORMALS_W / 2);
        let data = self
            .table
            .iter()
            .flat_map(|e| [e[0] as f32, e[1] as f32, e[2] as f32, 0.0])
            .collect();
        (nw, nh, data)
    }

    /// Irradiance at world normal `n` (unit).
    pub fn at(&self, n: [f64; 3]) -> [f64; 3] {
        let (nw, nh) = (NORMALS_W, NORMALS_W / 2);
        let theta = n[1].clamp(-1.0, 1.0).acos();
        let phi = n[2].atan2(n[0]).rem_euclid(2.0 * PI);
        let fx = phi / (2.0 * PI) * nw as f64 - 0.5;
        let fy = (theta / PI * nh as f64 - 0.5).clamp(0.0, (nh - 1) as f64);
        let x0 = fx.floor();
        let tx = fx - x0;
        let i0 = (x0 as i64).rem_euclid(nw as i64) as usize;
        let i1 = (i0 + 1) % nw;
        let j0 = (fy as usize).min(nh - 2);
        let ty = fy - j0 as f64;
        let at = |i: usize, j: usize| self.table[j * nw + i];
        let mut e: [f64; 3] = std::array::from_fn(|a| {
            let top = at(i0, j0)[a] * (1.0 - tx) + at(i1, j0)[a] * tx;
            let bot = at(i0, j0 + 1)[a] * (1.0 - tx) + at(i1, j0 + 1)[a] * tx;
            top * (1.0 - ty) + bot * ty
        });
        if let Some((s, rgb)) = self.sun {
            let c = n[0] * s[0] + n[1] * s[1] + n[2] * s[2];
            if c > 0.0 {
                let wc = Self::weight_at(&self.weight, c);
                for a in 0..3 {
                    e[a] += rgb[a] * wc;
                }
            }
        }
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{sky::Sky, EnvMap};

    /// A constant white environment of radiance 1 gives pi at every normal;
    /// the sky's horizontal irradiance is its `intensity` times pi (the sky's
    /// units: a white Lambertian surface facing up has radiance `intensity`).
    #[test]
    fn furnace_and_sky_units() {
        let white = Irradiance::new(&Environment::Map(EnvMap::constant([1.0; 3])));
        for n in [
            [0.0f64, 1.0, 0.0],
            [0.6, 0.0, 0.8],
            [0.0, -1.0, 0.0],
            [0.3, -0.5, 0.81],
        ] {
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let e = white.at(n.map(|v| v / l));
            for v in e {
                assert!((v / PI - 1.0).abs() < 1e-3, "{e:?} at {n:?}");
            }
        }
        let sky = Environment::Sky(Box::new(Sky::new(35.0, 70.0, 3.0, 1.0)));
        let e = Irradiance::new(&sky).at([0.0, 1.0, 0.0]);
        let y = colour::linear_srgb_to_xyz(e)[1];
        assert!(
            (y / PI - 1.0).abs() < 0.01,
            "horizontal irradiance {y} vs pi"
        );
    }

    /// Under a white furnace of radiance 1, the transmitted irradiance is
    /// `2 pi int_0^1 c (1 - F(c)) dc` at every normal (a fine midpoint rule
    /// here): about 0.908 pi for n = 1.5 (a dielectric's hemispherical
    /// transmission).
    #[test]
    fn furnace_transmission() {
        let white = Environment::Map(EnvMap::constant([1.0; 3]));
        for ior in [1.5, 1.33] {
            let t = Irradiance::transmitted(&white, ior);
            let m = 200_000;
            let want: f64 = (0..m)
                .map(|i| {
                    let c = (i as f64 + 0.5) / m as f64;
                    c * (1.0 - sunbeam_optics::gain::fresnel(c, ior)) / m as f64
                })
                .sum::<f64>()
                * 2.0
                * PI;
            for n in [[0.0, 1.0, 0.0], [0.6, 0.0, 0.8], [0.3f64, -0.5, 0.81]] {
                let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                let e = t.at(n.map(|v| v / l));
                for v in e {
                    assert!((v / want - 1.0).abs() < 1e-3, "{ior}: {e:?} vs {want}");
                }
            }
        }
    }
}
