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
//! light grazes too, `G`'s Kirchhoff obliquity (a facet facing the half
//! vector) still grows without bound; `tilt_cap` holds the half vector's tilt
//! at the steepest facet the slopes allow, so the factor is
//! `G2 min(1, cos^2(theta_h) / cos^2(theta_T))`.

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
    /// `wr` (to the viewer): `G2` times the tilt cap; 1 when off, 0 when either
    /// is at or below the horizon.
    pub fn factor(self, wi: [f64; 3], wr: [f64; 3]) -> f64 {
        match self {
            Masking::Off => 1.0,
            Masking::Smith { rms_slope } => {
                if !(wi[2] > 0.0 && wr[2] > 0.0) {
                    return 0.0;
                }
                tilt_cap(wi, wr, rms_slope) / (1.0 + lambda(wi, rms_slope) + lambda(wr, rms_slope))
            }
        }
    }

    /// The model's gain with this masking: `G(wi, wr) G2(wi, wr)` (index 1.5,
    /// [`crate::gain::DEFAULT_IOR`]), what every light direction is shaded with.
    pub fn gain(self, wi: [f64; 3], wr: [f64; 3]) -> f64 {
        let g = crate::gain::g(wi, wr, crate::gain::DEFAULT_IOR);
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

/// Facets steeper than this many Beckmann roughnesses (`alpha = sqrt(2) s`)
/// are taken to be absent: `exp(-9)`, about 1e-4, of the slopes lie beyond.
pub const MAX_TILT_ALPHAS: f64 = 3.0;

/// The cap on `G`'s Kirchhoff obliquity, `min(1, cos^2(theta_h) / cos^2(theta_T))`:
/// `G` with the half vector's tilt `theta_h` held at most `theta_T`,
/// `tan(theta_T) = 3 alpha_h` (the roughness along the half vector's azimuth).
/// Why: `(1 + wi.wr)^2 / (ci + cr)^2 = |wi + wr|^4 / (4 (ci + cr)^2)` is the
/// stationary-phase obliquity of a facet facing the half vector; where no facet
/// is that steep the light there is the patch's own diffraction (the coherence
/// window's blur of the specular lobe, which at grazing reaches tilts near
/// 90 degrees), whose exact Kirchhoff obliquity is that of the mean surface
/// (docs/LIGHTING.md "Grazing views: masking"). Without the cap a limb's light
/// grows like `1 / cos(theta_r)` even with Smith's masking.
fn tilt_cap(wi: [f64; 3], wr: [f64; 3], rms_slope: [f64; 2]) -> f64 {
    let q = [wi[0] + wr[0], wi[1] + wr[1], wi[2] + wr[2]];
    let qxy2 = q[0] * q[0] + q[1] * q[1];
    if qxy2 <= 0.0 {
        return 1.0;
    }
    // tan^2(theta_T) = 9 alpha_h^2 = 9 * 2 (qx^2 sx^2 + qy^2 sy^2) / |q_xy|^2
    let t2 = MAX_TILT_ALPHAS
        * MAX_TILT_ALPHAS
        * 2.0
        * (q[0] * q[0] * rms_slope[0] * rms_slope[0] + q[1] * q[1] * rms_slope[1] * rms_slope[1])
        / qxy2;
    // cos^2(theta_h) / cos^2(theta_T) = (1 + tan^2 theta_T) qz^2 / |q|^2
    ((1.0 + t2) * q[2] * q[2] / (qxy2 + q[2] * q[2])).min(1.0)
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
/// same few operations as the shader's, which has no `erf` (shaders/response_map.wgsl).
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
            let gm = crate::gain::g(wi, wr, 1.5) * m.factor(wi, wr);
            assert!(gm.is_finite() && gm < 200.0, "cos {cr}: {gm}");
            last = gm;
        }
        let wr = [(1.0f64 - 1e-12).sqrt(), 0.0, 1e-6];
        assert!(crate::gain::g(wi, wr, 1.5) > 1e5 * last);
    }

    /// Where a facet faces the half vector the cap is 1: moderate angles keep
    /// G G2 exactly.
    #[test]
    fn tilt_cap_leaves_facet_geometry_alone() {
        let s = [0.21, 0.43];
        for (wi, wr) in [
            (dir(0.0, 0.0), dir(30.0, 90.0)),
            (dir(45.0, 0.0), dir(45.0, 180.0)),
            (dir(60.0, 90.0), dir(20.0, 250.0)),
        ] {
            assert_eq!(tilt_cap(wi, wr, s), 1.0, "{wi:?} {wr:?}");
        }
        // Both grazing, 10 degrees off the forward direction: a half vector
        // tilted 85 degrees, far past 3 alphas (about 61 degrees here).
        let c = tilt_cap(dir(89.9, 0.0), dir(89.9, 190.0), s);
        assert!(c > 0.0 && c < 0.05, "{c}");
    }

    /// The light a grazing view gets from the band where the light grazes
    /// too: the integral over `wi` of `G G2` times a specular lobe of the
    /// width a few-micrometre window gives (`exp(-|u|^2 / (2 0.05^2))`)
    /// settles as `cos(theta_r)` goes to 0 with the cap, and grows like
    /// `1 / cos(theta_r)` without it.
    #[test]
    fn grazing_band_light_is_bounded() {
        let s = [0.21, 0.43];
        let m = Masking::smith(s);
        let band = |cr: f64, capped: bool| {
            let wr = [(1.0 - cr * cr).sqrt(), 0.0, cr];
            let (nc, np) = (400, 1200);
            let mut sum = 0.0;
            for ic in 0..nc {
                let (t0, t1) = (ic as f64 / nc as f64, (ic + 1) as f64 / nc as f64);
                let (c0, c1) = (t0 * t0 * t0, t1 * t1 * t1);
                let ci = 0.5 * (c0 + c1);
                let si = (1.0 - ci * ci).sqrt();
                for ip in 0..np {
                    // azimuths within 30 degrees of the forward direction
                    let p = std::f64::consts::PI + ((ip as f64 + 0.5) / np as f64 - 0.5) * 1.05;
                    let wi = [si * p.cos(), si * p.sin(), ci];
                    let u2 = (wi[0] + wr[0]).powi(2) + (wi[1] + wr[1]).powi(2);
                    let g = crate::gain::g(wi, wr, 1.5);
                    let g2 = if capped {
                        m.factor(wi, wr)
                    } else {
                        1.0 / (1.0 + lambda(wi, s) + lambda(wr, s))
                    };
                    sum += g * g2 * (-u2 / (2.0 * 0.05 * 0.05)).exp() * (c1 - c0);
                }
            }
            sum * 1.05 / np as f64
        };
        let (a, b) = (band(1e-2, true), band(1e-4, true));
        assert!(b < 1.3 * a, "capped: {a} at cos 1e-2, {b} at 1e-4");
        let (a, b) = (band(1e-2, false), band(1e-4, false));
        assert!(b > 10.0 * a, "uncapped: {a} at cos 1e-2, {b} at 1e-4");
    }
}
