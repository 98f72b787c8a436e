//! Shadowing and masking by the surface's own relief (PHYSICS.md 2 lists it as
//! an option of the model; docs/LIGHTING.md "Grazing views: masking").
//!
//! The gain `G` has `1 / cos(theta_r)`: a patch seen edge-on reflects its light
//! into a vanishing projected area. On a curved body that makes a pixel at the
//! limb a finite integral with an infinite-variance estimator (and on a mesh
//! with interpolated normals, whose `cos(theta_r)` crosses zero linearly inside
//! a triangle, an integral that diverges logarithmically). A real ridged
//! surface hides part of itself at grazing angles: Smith's height-correlated
//! masking-shadowing function for a Gaussian (Beckmann) slope distribution,
//! anisotropic with the relief's own rms slopes along the patch's x and y,
//!
//! ```text
//! G2 = 1 / (1 + Lambda(wi) + Lambda(wr))
//! Lambda(w) = (erf(a) - 1)/2 + exp(-a^2) / (2 a sqrt(pi)),  a = 1 / (alpha_w tan theta)
//! alpha_w^2 = (w_x^2 alpha_x^2 + w_y^2 alpha_y^2) / (w_x^2 + w_y^2),  alpha_x = sqrt(2) rms(dh/dx)
//! ```
//!
//! (Walter et al. 2007; Heitz 2014 for the height-correlated form and the
//! anisotropic projected roughness). `Lambda ~ 1/(2 a sqrt(pi))` as the
//! direction grazes, so `G2 ~ cos(theta_r)` and `G * G2` stays bounded for
//! each light direction. At normal incidence and view `G2 = 1`. Where the
//! light grazes too, the window's own diffraction is bounded by the exact
//! Kirchhoff term (PHYSICS.md 2b, [`crate::grazing`]), not by masking: masking
//! is a mesh's option, never what keeps the albedo below 1.

/// Which masking the shading applies on top of `G`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Masking {
    /// None: PHYSICS.md's reference model.
    #[default]
    Off,
    /// Smith, height-correlated, Beckmann slopes with these rms slopes of the
    /// height field along the local x (`t`) and y (`b`) axes (`rms(dh/dx)`,
    /// `rms(dh/dy)`, dimensionless).
    Smith { rms_slope: [f64; 2] },
}

impl Masking {
    /// Smith masking for rms slopes `[sx, sy]`; `Off` when both are zero.
    pub fn smith(rms_slope: [f64; 2]) -> Masking {
        if rms_slope[0] <= 0.0 && rms_slope[1] <= 0.0 {
            Masking::Off
        } else {
            Masking::Smith { rms_slope }
        }
    }

    /// The factor on `G` for local unit directions `wi` (to the light) and
    /// `wr` (to the viewer): `G2`; 1 when off, 0 when either is at or below
    /// the horizon.
    pub fn factor(self, wi: [f64; 3], wr: [f64; 3]) -> f64 {
        match self {
            Masking::Off => 1.0,
            Masking::Smith { rms_slope } => {
                if !(wi[2] > 0.0 && wr[2] > 0.0) {
                    return 0.0;
                }
                1.0 / (1.0 + lambda(wi, rms_slope) + lambda(wr, rms_slope))
            }
        }
    }

    /// The model's gain with this masking: `G(wi, wr) G2(wi, wr)` for the
    /// skin `mat`, what every light direction is shaded with.
    pub fn gain(self, wi: [f64; 3], wr: [f64; 3], mat: crate::gain::Material) -> f64 {
        let g = crate::gain::g(wi, wr, mat);
        match self {
            Masking::Off => g,
            Masking::Smith { .. } => g * self.factor(wi, wr),
        }
    }

    /// The rms slopes (zeros when off): what the player's shader gets.
    pub fn rms_slope(self) -> [f64; 2] {
        match self {
            Masking::Off => [0.0, 0.0],
            Masking::Smith { rms_slope } => rms_slope,
        }
    }
}

/// Smith's `Lambda` for the Beckmann distribution, direction `w` (local, `w.z > 0`).
fn lambda(w: [f64; 3], rms_slope: [f64; 2]) -> f64 {
    let s2 = w[0] * w[0] + w[1] * w[1];
    if s2 <= 0.0 {
        return 0.0;
    }
    // alpha_w^2 tan^2 = 2 (wx^2 sx^2 + wy^2 sy^2) / wz^2
    let at2 = 2.0
        * (w[0] * w[0] * rms_slope[0] * rms_slope[0] + w[1] * w[1] * rms_slope[1] * rms_slope[1]);
    if at2 <= 0.0 {
        return 0.0;
    }
    let a = w[2] / at2.sqrt();
    if a > 8.0 {
        // erf(8) = 1 and exp(-64) ~ 1e-28: no masking.
        return 0.0;
    }
    (erf(a) - 1.0) / 2.0 + (-a * a).exp() / (2.0 * a * std::f64::consts::PI.sqrt())
}

/// The error function (Abramowitz & Stegun 7.1.26, |error| < 1.5e-7): the
/// same few operations as the shader's, which has no `erf` (`sb_masking` in shaders/material.wgsl).
pub fn erf(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let p = ((((1.061_405_429 * t - 1.453_152_027) * t + 1.421_413_741) * t - 0.284_496_736) * t
        + 0.254_829_592)
        * t;
    let y = 1.0 - p * (-x * x).exp();
    if x < 0.0 {
        -y
    } else {
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(theta_deg: f64, phi_deg: f64) -> [f64; 3] {
        let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
        [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]
    }

    #[test]
    fn erf_matches_known_values() {
        // erf(0.5), erf(1), erf(2) to 10 digits (Abramowitz & Stegun table 7.1).
        for (x, want) in [
            (0.5, 0.520_499_877_8),
            (1.0, 0.842_700_792_9),
            (2.0, 0.995_322_265_0),
        ] {
            assert!((erf(x) - want).abs() < 2e-7, "erf({x})");
            assert!((erf(-x) + want).abs() < 2e-7);
        }
    }

    #[test]
    fn off_is_one_and_normal_is_one() {
        let m = Masking::smith([0.4, 0.2]);
        assert_eq!(Masking::Off.factor(dir(80.0, 0.0), dir(89.0, 30.0)), 1.0);
        assert!((m.factor(dir(0.0, 0.0), dir(0.0, 0.0)) - 1.0).abs() < 1e-15);
        assert_eq!(Masking::smith([0.0, 0.0]), Masking::Off);
    }

    /// Lambda against a direct numerical integral of its definition:
    /// Lambda = (1/mu) * integral over slopes q > mu of (q - mu) p(q) dq, with
    /// p the 1D Gaussian of the slope along the direction's azimuth (variance
    /// cos^2 sx^2 + sin^2 sy^2) and mu = cot(theta) (Smith 1967).
    #[test]
    fn lambda_matches_its_integral_definition() {
        for (theta, phi, s) in [
            (60.0, 0.0, [0.3, 0.3]),
            (85.0, 30.0, [0.5, 0.15]),
            (89.0, 90.0, [0.4, 0.1]),
        ] {
            let w = dir(theta, phi);
            let (c, sn) = (
                f64::cos(phi * std::f64::consts::PI / 180.0),
                f64::sin(phi * std::f64::consts::PI / 180.0),
            );
            let var = c * c * s[0] * s[0] + sn * sn * s[1] * s[1];
            let mu = 1.0 / f64::tan(theta * std::f64::consts::PI / 180.0);
            let n = 200_000;
            let hi = mu + 12.0 * var.sqrt();
            let h = (hi - mu) / n as f64;
            let mut sum = 0.0;
            for k in 0..n {
                let q = mu + (k as f64 + 0.5) * h;
                sum += (q - mu) * (-q * q / (2.0 * var)).exp()
                    / (2.0 * std::f64::consts::PI * var).sqrt()
                    * h;
            }
            let want = sum / mu;
            let got = lambda(w, s);
            // erf to 1.5e-7 absolute (A&S 7.1.26)
            assert!(
                (got - want).abs() < 1e-5 * want + 2e-7,
                "{theta} {phi}: {got} vs {want}"
            );
        }
    }

    /// G * G2 stays bounded as the view grazes (what makes a limb pixel's
    /// estimator settle); G alone grows like 1 / cos(theta_r).
    #[test]
    fn masked_gain_is_bounded_at_grazing_views() {
        let m = Masking::smith([0.4, 0.4]);
        let wi = dir(40.0, 180.0);
        let mut last = 0.0;
        for k in 1..=6 {
            let cr = 10f64.powi(-k);
            let wr = [(1.0 - cr * cr).sqrt(), 0.0, cr];
            let gm = crate::gain::g(wi, wr, crate::gain::Material::RELATIVE) * m.factor(wi, wr);
            assert!(gm.is_finite() && gm < 200.0, "cos {cr}: {gm}");
            last = gm;
        }
        let wr = [(1.0f64 - 1e-12).sqrt(), 0.0, 1e-6];
        assert!(crate::gain::g(wi, wr, crate::gain::Material::RELATIVE) > 1e5 * last);
    }

    /// The light a grazing view gets from the band where the light grazes
    /// too, from a flat window patch's specular lobe (`sigma` 3 um at 500 nm),
    /// with the exact window term (PHYSICS.md 2b): bounded as `cos(theta_r)`
    /// goes to 0 with Smith masking; without it, it still grows like
    /// `1 / cos(theta_r)` (the lobe reaches light with `cos(theta_i)` far above
    /// `cos(theta_r)`, where `q_z^2 / (4 cos_r cos_i)` is large): the amplitude
    /// window's Kirchhoff model is not energy-conserving at grazing views
    /// (docs/LIGHTING.md "Grazing views").
    #[test]
    fn grazing_band_light_is_bounded_when_masked() {
        let s = [0.21, 0.43];
        let m = Masking::smith(s);
        let (k, sg) = (2.0 * std::f64::consts::PI / 500e-9, 3e-6);
        let band = |cr: f64, exact: bool, mask: Masking| {
            let wr = [(1.0 - cr * cr).sqrt(), 0.0, cr];
            let (nc, np) = (400, 1200);
            let mut sum = 0.0;
            for ic in 0..nc {
                let (t0, t1) = (ic as f64 / nc as f64, (ic + 1) as f64 / nc as f64);
                let (c0, c1) = (t0 * t0 * t0, t1 * t1 * t1);
                let ci = 0.5 * (c0 + c1);
                let si = (1.0 - ci * ci).sqrt();
                for ip in 0..np {
                    let p = std::f64::consts::PI + ((ip as f64 + 0.5) / np as f64 - 0.5) * 0.2;
                    let wi = [si * p.cos(), si * p.sin(), ci];
                    let uvw = [-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]];
                    let pa = (-(k * k) * sg * sg * (uvw[0].powi(2) + uvw[1].powi(2)) / 2.0).exp();
                    let r = if exact {
                        let du = -k * k * sg * sg * uvw[0] * pa;
                        let dv = -k * k * sg * sg * uvw[1] * pa;
                        crate::grazing::window_reflectance(
                            uvw,
                            [pa, 0.0],
                            [du, 0.0],
                            [dv, 0.0],
                            k,
                            [sg, sg],
                        )
                    } else {
                        pa * pa
                    };
                    sum += mask.gain(wi, wr, crate::gain::Material::default()) * r * (c1 - c0);
                }
            }
            sum * 0.2 / np as f64
        };
        let (a, b) = (band(1e-2, true, m), band(1e-4, true, m));
        assert!(b < 1.3 * a, "masked: {a} at cos 1e-2, {b} at 1e-4");
        let (a, b) = (
            band(1e-2, true, Masking::Off),
            band(1e-4, true, Masking::Off),
        );
        assert!(
            b > 10.0 * a,
            "unmasked, exact term: {a} at cos 1e-2, {b} at 1e-4"
        );
        // The exact term is below Beckmann's obliquity everywhere in the band.
        assert!(band(1e-3, true, Masking::Off) < band(1e-3, false, Masking::Off));
    }
}
