//! The built-in sky: Preetham, Shirley and Smits, "A practical analytic model
//! for daylight" (SIGGRAPH 1999), with its sun.
//!
//! - Sky: the Perez distribution of luminance `Y` and chromaticity `x, y`
//!   with the paper's turbidity fits (its appendix A.2), the zenith values
//!   of its equations for `Y_z`, `x_z`, `y_z`; the spectrum per direction from
//!   the CIE daylight basis at that chromaticity ([`crate::daylight`]), as the
//!   paper does. Directions at and below the horizon see a grey ground of
//!   albedo [`GROUND_ALBEDO`] lit by sun and sky (a Lambertian disc: constant
//!   radiance): the daylight spectrum at D65's chromaticity ([`D65_XY`]) with
//!   the luminance of `ground * D65`. Within 1 % of D65's shape, and it keeps
//!   the whole radiance without the sun exactly in the span of `S0, S1, S2`
//!   ([`Sky::coefficients`]), which the extended-light response maps need.
//! - Sun: a disc of angular radius [`SUN_RADIUS_RAD`], the extraterrestrial
//!   spectrum approximated by a 5778 K black body scaled to 128 klux at
//!   normal incidence, attenuated along the air mass (Kasten and Young 1989)
//!   by Rayleigh scattering and by aerosols (Angstrom exponent 1.3, `beta`
//!   from the turbidity as in the paper). Ozone and water vapour absorption
//!   are left out (a few % in the red); no limb darkening.
//! - Units: the sun and sky together give a horizontal white Lambertian
//!   surface the radiance `intensity` (scene units, `Y = 1` is the white of
//!   the point lights): radiance = luminance (cd/m^2) * `intensity * pi / E_h`,
//!   with `E_h` the horizontal illuminance of sun and sky (integrated here,
//!   sun by its disc).
//!
//! Sampling: with probability [`SUN_PROB`] (when the sun is up) uniformly over
//! the sun's cone, else from a 256 x 128 luminance table of sky and ground
//! ([`crate::EnvMap`]'s sampler); `pdf` is the mixture's exact density.
//! World frame: +y up, azimuth from +x towards +z.

use crate::{daylight, EnvMap};
use std::f64::consts::PI;
use sunbeam_optics::cie;

/// Angular radius of the sun's disc (0.533 degrees across).
pub const SUN_RADIUS_RAD: f64 = 0.004_65;
/// Reflectance of the grey ground seen below the horizon.
pub const GROUND_ALBEDO: f64 = 0.2;
/// D65's chromaticity (CIE 1931 x, y): the ground's colour.
pub const D65_XY: [f64; 2] = [0.3127, 0.3290];
/// Probability of sampling the sun's cone when the sun is up.
pub const SUN_PROB: f64 = 0.5;
/// Sampling table size (width; height is half).
const TABLE_W: usize = 256;

/// Perez coefficients A..E.
type Perez = [f64; 5];

fn perez(c: &Perez, cos_theta: f64, gamma: f64) -> f64 {
    let ct = cos_theta.max(0.01);
    (1.0 + c[0] * (c[1] / ct).exp())
        * (1.0 + c[2] * (c[3] * gamma).exp() + c[4] * gamma.cos().powi(2))
}

/// The sky and sun of one scene.
#[derive(Debug, Clone)]
pub struct Sky {
    sun_dir: [f64; 3],
    sun_up: bool,
    theta_s: f64,
    coef: [Perez; 3],
    zenith: [f64; 3],
    /// `F(0, theta_s)` per quantity.
    norm: [f64; 3],
    /// Luminance (cd/m^2) to scene radiance.
    scale: f64,
    /// XYZ (scene units per unit weight) of S0, S1, S2.
    basis_xyz: [[f64; 3]; 3],
    /// Sun: scene radiance = `sun_scale * spectrum(lambda)`.
    sun_scale: f64,
    turbidity: f64,
    sun_cos_max: f64,
    /// XYZ of the sun's disc radiance.
    sun_xyz: [f64; 3],
    ground: f64,
    /// Daylight weights of the ground: the spectrum at D65's chromaticity with
    /// luminance `ground` (so sky and ground are both in the span of S0, S1, S2).
    ground_weights: [f64; 3],
    table: EnvMap,
}

impl Sky {
    /// Sun elevation and azimuth in degrees (elevation in [0, 90]), turbidity
    /// in [1.7, 10], intensity >= 0 (checked by the scene).
    pub fn new(
        sun_elevation_deg: f64,
        sun_azimuth_deg: f64,
        turbidity: f64,
        intensity: f64,
    ) -> Sky {
        let el = sun_elevation_deg.to_radians();
        let az = sun_azimuth_deg.to_radians();
        let sun_dir = [el.cos() * az.cos(), el.sin(), el.cos() * az.sin()];
        let theta_s = PI / 2.0 - el;
        let t = turbidity;
        let coef = [
            [
                0.1787 * t - 1.4630,
                -0.3554 * t + 0.4275,
                -0.0227 * t + 5.3251,
                0.1206 * t - 2.5771,
                -0.0670 * t + 0.3703,
            ],
            [
                -0.0193 * t - 0.2592,
                -0.0665 * t + 0.0008,
                -0.0004 * t + 0.2125,
                -0.0641 * t - 0.8989,
                -0.0033 * t + 0.0452,
            ],
            [
                -0.0167 * t - 0.2608,
                -0.0950 * t + 0.0092,
                -0.0079 * t + 0.2102,
                -0.0441 * t - 1.6537,
                -0.0109 * t + 0.0529,
            ],
        ];
        let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta_s);
        let y_z = ((4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192) * 1000.0;
        let th = theta_s;
        let (th2, th3) = (th * th, th * th * th);
        let x_z = t * t * (0.00166 * th3 - 0.00375 * th2 + 0.00209 * th)
            + t * (-0.02903 * th3 + 0.06377 * th2 - 0.03202 * th + 0.00394)
            + (0.11693 * th3 - 0.21196 * th2 + 0.06052 * th + 0.25886);
        let yy_z = t * t * (0.00275 * th3 - 0.00610 * th2 + 0.00317 * th)
            + t * (-0.04214 * th3 + 0.08970 * th2 - 0.04153 * th + 0.00516)
            + (0.15346 * th3 - 0.26756 * th2 + 0.06670 * th + 0.26688);
        let norm = [0, 1, 2].map(|k| perez(&coef[k], 1.0, theta_s));
        let mut sky = Sky {
            sun_dir,
            sun_up: el > 0.0,
            theta_s,
            coef,
            zenith: [y_z.max(0.0), x_z, yy_z],
            norm,
            scale: 1.0,
            basis_xyz: daylight::basis_xyz(),
            sun_scale: 0.0,
            turbidity: t,
            sun_cos_max: SUN_RADIUS_RAD.cos(),
            sun_xyz: [0.0; 3],
            ground: 0.0,
            ground_weights: [0.0; 3],
            table: EnvMap::constant([0.0; 3]),
        };
        // Sun: luminance (cd/m^2) of its disc and the scale of its spectrum.
        let omega_sun = 2.0 * PI * (1.0 - sky.sun_cos_max);
        let (mut e_bb, mut e_att) = (0.0, 0.0);
        for nm in cie::DEFAULT_RANGE_NM.0..=cie::DEFAULT_RANGE_NM.1 {
            let l = nm as f64 * 1e-9;
            let yb = cie::cmf_nm(nm)[1];
            e_bb += planck(l) * yb;
            e_att += sky.sun_spectrum_shape(l) * yb;
        }
        // 683 lm/W * k * e_bb = 128 klux: k scales the black body to the sun's irradiance.
        let k = 128_000.0 / (683.0 * e_bb);
        let sun_lum = if sky.sun_up {
            683.0 * k * e_att / omega_sun
        } else {
            0.0
        };
        // Horizontal illuminance: sky by midpoint quadrature, sun by its disc.
        let (nt, np) = (64, 128);
        let mut e_sky = 0.0;
        for j in 0..nt {
            let theta = (j as f64 + 0.5) / nt as f64 * PI / 2.0;
            let d_omega = (PI / 2.0 / nt as f64) * (2.0 * PI / np as f64) * theta.sin();
            for i in 0..np {
                let phi = (i as f64 + 0.5) / np as f64 * 2.0 * PI;
                let d = crate::direction(theta.cos(), phi);
                e_sky += sky.sky_yxy(d)[0] * theta.cos() * d_omega;
            }
        }
        let e_h = e_sky + sun_lum * omega_sun * el.sin().max(0.0);
        let scale = if e_h > 0.0 { intensity * PI / e_h } else { 0.0 };
        sky.scale = scale;
        sky.ground = GROUND_ALBEDO * e_h / PI * scale;
        sky.ground_weights = sky.daylight_of_luminance(D65_XY, sky.ground);
        // Scene radiance of the sun at lambda = sun_scale * shape(lambda), with
        // Y (scene units) = sun_lum * scale.
        let y_shape: f64 = (cie::DEFAULT_RANGE_NM.0..=cie::DEFAULT_RANGE_NM.1)
            .map(|nm| sky.sun_spectrum_shape(nm as f64 * 1e-9) * cie::cmf_nm(nm)[1])
            .sum::<f64>()
            / cie::d65_y_norm(cie::DEFAULT_RANGE_NM);
        sky.sun_scale = if y_shape > 0.0 {
            sun_lum * scale / y_shape
        } else {
            0.0
        };
        sky.sun_xyz = sky.sun_xyz_sum();
        // Sampling table of sky and ground luminance (the sun is sampled by its cone).
        let h = TABLE_W / 2;
        let mut px = Vec::with_capacity(TABLE_W * h);
        for j in 0..h {
            let theta = (j as f64 + 0.5) / h as f64 * PI;
            for i in 0..TABLE_W {
                let phi = (i as f64 + 0.5) / TABLE_W as f64 * 2.0 * PI;
                let d = crate::direction(theta.cos(), phi);
                let y = sky.sky_luminance(d) as f32;
                px.push([y, y, y]);
            }
        }
        sky.table =
            EnvMap::new(TABLE_W, h, px, 0.0, 1.0).unwrap_or_else(|_| EnvMap::constant([0.0; 3]));
        sky
    }

    /// Direction towards the sun (unit, world).
    pub fn sun_direction(&self) -> [f64; 3] {
        self.sun_dir
    }

    /// Preetham's `[Y (cd/m^2), x, y]` of the sky (no sun) in direction `d` (y > 0).
    fn sky_yxy(&self, d: [f64; 3]) -> [f64; 3] {
        let cos_g = dot(d, self.sun_dir).clamp(-1.0, 1.0);
        let gamma = cos_g.acos();
        let ct = d[1];
        [0, 1, 2].map(|k| self.zenith[k] * perez(&self.coef[k], ct, gamma) / self.norm[k])
    }

    /// Scene luminance of sky or ground (no sun) in direction `d`.
    fn sky_luminance(&self, d: [f64; 3]) -> f64 {
        if d[1] > 0.0 {
            self.sky_yxy(d)[0] * self.scale
        } else {
            self.ground
        }
    }

    /// Weights `w` of S0, S1, S2 such that the sky's spectral radiance in `d`
    /// (above the horizon) is `sum_k w_k S_k(lambda)` (scene units).
    fn sky_weights(&self, d: [f64; 3]) -> [f64; 3] {
        let [y, x, yy] = self.sky_yxy(d);
        self.daylight_of_luminance([x, yy], y * self.scale)
    }

    /// Weights of the daylight spectrum of chromaticity `xy` and luminance `y`
    /// (scene units).
    fn daylight_of_luminance(&self, xy: [f64; 2], y: f64) -> [f64; 3] {
        let m = daylight::weights(xy[0], xy[1]);
        let y_basis: f64 = (0..3).map(|k| m[k] * self.basis_xyz[k][1]).sum();
        let s = if y_basis > 0.0 { y / y_basis } else { 0.0 };
        m.map(|v| v * s)
    }

    /// Weights `c` of S0, S1, S2 ([`daylight::basis_at`]) such that the
    /// radiance from `d` without the sun is exactly `sum_k c_k S_k(lambda)`:
    /// the sky's above the horizon, the ground's (D65's chromaticity) at and
    /// below it. The extended-light response maps rely on this being exact.
    pub fn coefficients(&self, d: [f64; 3]) -> [f64; 3] {
        if d[1] > 0.0 {
            self.sky_weights(d)
        } else {
            self.ground_weights
        }
    }

    /// True when the sun is above the horizon (and so shines).
    pub fn sun_is_up(&self) -> bool {
        self.sun_up && self.sun_scale > 0.0
    }

    /// Relative spectral shape of the sun at the ground (before scaling).
    fn sun_spectrum_shape(&self, lambda_m: f64) -> f64 {
        let el_deg = 90.0 - self.theta_s.to_degrees();
        // Kasten and Young (1989) relative air mass.
        let m =
            1.0 / (el_deg.to_radians().sin() + 0.50572 * (el_deg + 6.07995).max(0.1).powf(-1.6364));
        let um = lambda_m * 1e6;
        let beta = 0.04608 * self.turbidity - 0.04586;
        let tau_r = (-0.008735 * um.powf(-4.08) * m).exp();
        let tau_a = (-beta * um.powf(-1.3) * m).exp();
        planck(lambda_m) * tau_r * tau_a
    }

    /// Spectral radiance of the sun's disc at `lambda_m` (0 when the sun is down).
    pub fn sun_spectral(&self, lambda_m: f64) -> f64 {
        if self.sun_up {
            self.sun_scale * self.sun_spectrum_shape(lambda_m)
        } else {
            0.0
        }
    }

    /// A direction uniformly over the sun's disc from two uniform numbers, with
    /// its density `1 / solid angle` (None when the sun is down).
    pub fn sample_sun(&self, u1: f64, u2: f64) -> Option<([f64; 3], f64)> {
        if !(self.sun_up && self.sun_scale > 0.0) {
            return None;
        }
        let cos_t = 1.0 - u1 * (1.0 - self.sun_cos_max);
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let (t, b) = basis(self.sun_dir);
        let (s, c) = (2.0 * PI * u2).sin_cos();
        let d = [0, 1, 2].map(|k| sin_t * (c * t[k] + s * b[k]) + cos_t * self.sun_dir[k]);
        Some((d, 1.0 / self.sun_solid_angle()))
    }

    /// XYZ of the sun disc's radiance (scene units; zero when the sun is down).
    pub fn sun_xyz(&self) -> [f64; 3] {
        if self.sun_is_up() {
            self.sun_xyz
        } else {
            [0.0; 3]
        }
    }

    /// Solid angle of the sun's disc (sr).
    pub fn sun_solid_angle(&self) -> f64 {
        2.0 * PI * (1.0 - self.sun_cos_max)
    }

    /// True when `d` lies in the sun's disc.
    pub fn in_sun(&self, d: [f64; 3]) -> bool {
        self.sun_up && dot(d, self.sun_dir) >= self.sun_cos_max
    }

    /// Spectral radiance arriving from direction `d` at `lambda_m` (scene units).
    pub fn spectral(&self, d: [f64; 3], lambda_m: f64) -> f64 {
        self.spectrum(d).at(self, lambda_m)
    }

    /// The spectrum arriving from `d`, for evaluating at several wavelengths
    /// (the sky model runs once per direction, not once per wavelength).
    pub fn spectrum(&self, d: [f64; 3]) -> SkySpectrum {
        SkySpectrum {
            daylight: self.coefficients(d),
            sun: self.in_sun(d),
        }
    }

    /// XYZ of the radiance from `d` (scene units), consistent with [`Sky::spectral`].
    pub fn xyz(&self, d: [f64; 3]) -> [f64; 3] {
        let w = self.coefficients(d);
        let mut xyz: [f64; 3] =
            [0, 1, 2].map(|c| (0..3).map(|k| w[k] * self.basis_xyz[k][c]).sum());
        if self.in_sun(d) {
            let s = self.sun_xyz;
            for c in 0..3 {
                xyz[c] += s[c];
            }
        }
        xyz
    }

    fn sun_xyz_sum(&self) -> [f64; 3] {
        let norm = cie::d65_y_norm(cie::DEFAULT_RANGE_NM);
        let mut xyz = [0.0; 3];
        for nm in cie::DEFAULT_RANGE_NM.0..=cie::DEFAULT_RANGE_NM.1 {
            let s = self.sun_scale * self.sun_spectrum_shape(nm as f64 * 1e-9) / norm;
            let c = cie::cmf_nm(nm);
            for k in 0..3 {
                xyz[k] += s * c[k];
            }
        }
        xyz
    }

    fn sun_prob(&self) -> f64 {
        if self.sun_up && self.sun_scale > 0.0 {
            SUN_PROB
        } else {
            0.0
        }
    }

    /// Density (1/sr) with which [`Sky::sample`] draws `d`.
    pub fn pdf(&self, d: [f64; 3]) -> f64 {
        let ps = self.sun_prob();
        let cone = if self.in_sun(d) {
            1.0 / (2.0 * PI * (1.0 - self.sun_cos_max))
        } else {
            0.0
        };
        ps * cone + (1.0 - ps) * self.table.pdf(d)
    }

    /// A direction drawn from three uniform numbers, with its density.
    pub fn sample(&self, u0: f64, u1: f64, u2: f64) -> Option<([f64; 3], f64)> {
        let d = if u0 < self.sun_prob() {
            let cos_t = 1.0 - u1 * (1.0 - self.sun_cos_max);
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let phi = 2.0 * PI * u2;
            let (t, b) = basis(self.sun_dir);
            let (s, c) = phi.sin_cos();
            [0, 1, 2].map(|k| sin_t * (c * t[k] + s * b[k]) + cos_t * self.sun_dir[k])
        } else {
            self.table.sample(u1, u2)?.0
        };
        let p = self.pdf(d);
        (p > 0.0).then_some((d, p))
    }
}

/// The radiance from one direction of a [`Sky`] ([`Sky::spectrum`]).
#[derive(Debug, Clone, Copy)]
pub struct SkySpectrum {
    /// Weights of the CIE daylight basis (sky or ground, [`Sky::coefficients`]).
    daylight: [f64; 3],
    /// The direction lies in the sun's disc.
    sun: bool,
}

impl SkySpectrum {
    /// Spectral radiance at `lambda_m` (scene units); `sky` is the one it came from.
    pub fn at(&self, sky: &Sky, lambda_m: f64) -> f64 {
        let (w, b) = (self.daylight, daylight::basis_at(lambda_m));
        let mut l = w[0] * b[0] + w[1] * b[1] + w[2] * b[2];
        if self.sun {
            l += sky.sun_scale * sky.sun_spectrum_shape(lambda_m);
        }
        l
    }
}

/// Black body spectral radiance shape at 5778 K (unnormalised).
fn planck(lambda_m: f64) -> f64 {
    const C2: f64 = 1.438_776_9e-2; // h c / k, m K
    1.0 / (lambda_m.powi(5) * ((C2 / (lambda_m * 5778.0)).exp() - 1.0))
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Two unit vectors perpendicular to `n` and each other.
pub(crate) fn basis(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let d = dot(a, n);
    let t = [a[0] - d * n[0], a[1] - d * n[1], a[2] - d * n[2]];
    let l = dot(t, t).sqrt();
    let t = t.map(|v| v / l);
    let b = [
        n[1] * t[2] - n[2] * t[1],
        n[2] * t[0] - n[0] * t[2],
        n[0] * t[1] - n[1] * t[0],
    ];
    (t, b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sunbeam_common::rng::SplitMix64;

    /// The zenith of a clear sky is bluer than D65 (x, y below 0.3127, 0.3290;
    /// the fit gives about (0.238, 0.242) at turbidity 2, sun 30 degrees up);
    /// a hazier sky is whiter; the sky is brighter near the sun than opposite.
    #[test]
    fn zenith_colour_is_sky_blue_and_hazier_is_whiter() {
        let clear = Sky::new(30.0, 0.0, 2.0, 1.0);
        let hazy = Sky::new(30.0, 0.0, 10.0, 1.0);
        let z = [0.0, 1.0, 0.0];
        let c = clear.sky_yxy(z);
        assert!(
            (c[1] - 0.238).abs() < 0.003 && (c[2] - 0.242).abs() < 0.003,
            "{c:?}"
        );
        let near = clear.sky_yxy([0.8, 0.6, 0.0]);
        let far = clear.sky_yxy([-0.8, 0.6, 0.0]);
        assert!(near[0] > 2.0 * far[0], "{near:?} {far:?}");
        let h = hazy.sky_yxy(z);
        assert!(h[1] > c[1] && h[2] > c[2], "{h:?} vs {c:?}");
    }

    /// The normalisation: a horizontal white Lambertian surface has radiance
    /// `intensity`, estimated here by Monte Carlo with the sampler (an
    /// independent path from the quadrature that set the scale).
    #[test]
    fn horizontal_white_surface_has_radiance_intensity() {
        for (el, t) in [(10.0, 2.5), (45.0, 3.0), (80.0, 6.0)] {
            let sky = Sky::new(el, 30.0, t, 2.0);
            let mut r = SplitMix64::new(5);
            let n = 400_000;
            let mut e = 0.0;
            for _ in 0..n {
                if let Some((d, p)) = sky.sample(r.unit(), r.unit(), r.unit()) {
                    if d[1] > 0.0 {
                        e += sky.xyz(d)[1] * d[1] / p;
                    }
                }
            }
            let radiance = e / n as f64 / PI;
            assert!((radiance / 2.0 - 1.0).abs() < 0.01, "el {el}: {radiance}");
        }
    }

    /// `pdf` is the density of `sample`: the estimate of the sphere's solid
    /// angle, `E[1 / pdf]`, is 4 pi.
    #[test]
    fn pdf_is_the_sampler_density() {
        let sky = Sky::new(35.0, 120.0, 3.0, 1.0);
        let mut r = SplitMix64::new(9);
        let n = 400_000;
        // E over the sampler of f / pdf with f = 1 on the sky and ground, but
        // the sun's cone is sampled too: use a smooth f that the cone cannot
        // dominate, the indicator of y > 0.3.
        let mut est = 0.0;
        for _ in 0..n {
            if let Some((d, p)) = sky.sample(r.unit(), r.unit(), r.unit()) {
                if d[1] > 0.3 && !sky.in_sun(d) {
                    est += 1.0 / p;
                }
            }
        }
        let want = 2.0 * PI * (1.0 - 0.3) - 2.0 * PI * (1.0 - sky.sun_cos_max);
        assert!(
            (est / n as f64 / want - 1.0).abs() < 0.01,
            "{} vs {want}",
            est / n as f64
        );
    }

    /// Independent recomputation of the radiance without the sun: above the
    /// horizon Preetham's `(Y, x, y)` turned into `S0 + M1 S1 + M2 S2` scaled
    /// to `Y` by a 1 nm sum of its own; at and below it the daylight spectrum
    /// at D65's chromaticity scaled to `Y = albedo * intensity` (the ground of
    /// a horizontal white surface of radiance `intensity`). `basis_at .
    /// coefficients` and `spectral` must both equal it to 1e-9.
    #[test]
    fn coefficients_reproduce_the_spectrum() {
        use crate::Environment;
        let intensity = 1.7;
        let sky = Sky::new(35.0, 200.0, 3.5, intensity);
        let env = Environment::Sky(Box::new(sky.clone()));
        let norm = cie::d65_y_norm(cie::DEFAULT_RANGE_NM);
        let luminance_of = |m: [f64; 3]| {
            (380..=780u32)
                .map(|nm| {
                    let b = daylight::basis_at(nm as f64 * 1e-9);
                    (m[0] * b[0] + m[1] * b[1] + m[2] * b[2]) * cie::cmf_nm(nm)[1]
                })
                .sum::<f64>()
                / norm
        };
        let mut r = SplitMix64::new(21);
        let mut n_ground = 0;
        for _ in 0..400 {
            let d = crate::direction(2.0 * r.unit() - 1.0, 2.0 * PI * r.unit());
            if sky.in_sun(d) {
                continue;
            }
            let (m, y) = if d[1] > 0.0 {
                let [y, x, yy] = sky.sky_yxy(d);
                (daylight::weights(x, yy), y * sky.scale)
            } else {
                n_ground += 1;
                (daylight::weights(0.3127, 0.3290), GROUND_ALBEDO * intensity)
            };
            let k = y / luminance_of(m);
            for _ in 0..5 {
                let l = (380.0 + 400.0 * r.unit()) * 1e-9;
                let b = daylight::basis_at(l);
                let want = k * (m[0] * b[0] + m[1] * b[1] + m[2] * b[2]);
                let c = env.coefficients(d);
                let bk = env.basis_at(l);
                let got = c[0] * bk[0] + c[1] * bk[1] + c[2] * bk[2];
                assert!(
                    (got / want - 1.0).abs() < 1e-9,
                    "{d:?} {l}: {got} vs {want}"
                );
                let s = env.spectral(d, l);
                assert!((s / want - 1.0).abs() < 1e-9, "{d:?} {l}: {s} vs {want}");
            }
        }
        assert!(n_ground > 100);
        // The ground is D65's colour with D65's luminance.
        let g = sky.xyz([0.0, -1.0, 0.0]);
        let sum = g[0] + g[1] + g[2];
        assert!((g[0] / sum - 0.3127).abs() < 1e-3 && (g[1] / sum - 0.3290).abs() < 1e-3);
        assert!(
            (g[1] / (GROUND_ALBEDO * intensity) - 1.0).abs() < 2e-3,
            "{g:?}"
        );
    }

    /// `xyz` is the colour of `spectral` (1 nm sums).
    #[test]
    fn xyz_matches_spectrum() {
        let sky = Sky::new(40.0, 60.0, 4.0, 1.0);
        for d in [
            [0.0, 1.0, 0.0],
            [0.6, 0.3, 0.74],
            [0.0, -1.0, 0.0],
            sky.sun_direction(),
        ] {
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let d = d.map(|v| v / l);
            let norm = cie::d65_y_norm(cie::DEFAULT_RANGE_NM);
            let mut xyz = [0.0; 3];
            for nm in 380..=780u32 {
                let s = sky.spectral(d, nm as f64 * 1e-9) / norm;
                let c = cie::cmf_nm(nm);
                for k in 0..3 {
                    xyz[k] += s * c[k];
                }
            }
            let want = sky.xyz(d);
            for k in 0..3 {
                assert!(
                    (xyz[k] / want[k] - 1.0).abs() < 1e-3,
                    "{d:?}: {xyz:?} vs {want:?}"
                );
            }
        }
    }
}
