//! The gain `G(wi, wr)` of PHYSICS.md 2 and the Fresnel reflectance it carries:
//!
//! ```text
//! G = F(theta_d) (1 + wi.wr)^2 / ( (cos th_i + cos th_r)^2 cos th_r )      absolute (default)
//! G / F(0)                                                                relative (the thesis')
//! ```
//!
//! `F` is the exact unpolarised Fresnel **power** reflectance `(r_s^2 + r_p^2) / 2`
//! of a dielectric of index `n` (from air), taken once, at the angle `theta_d`
//! between `wi` and the half vector `h = (wi + wr)/|wi + wr|`. A flat patch
//! seen in its specular direction gets `G = F(theta) cos theta` (absolute;
//! `F(0) = 0.04` for `n = 1.5`) or `F(theta)/F(0) cos theta` (relative: 1
//! head-on). Directions are local unit vectors `(d.t, d.b, d.n)`; `wi` to the
//! light, `wr` to the viewer.
//!
//! This module is the only float64 implementation of `F` and `G`: the
//! reference, the response maps' environment paths and the tests call it; the
//! GPU's is `shaders/material.wgsl` (`sb_fresnel`, `sb_gain`), checked against this one.

use crate::energy::EnergyBound;

/// Default index of refraction (PHYSICS.md 2).
pub const DEFAULT_IOR: f64 = 1.5;

/// What `G` is normalised to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reflectance {
    /// Physical reflectance: a dielectric reflects `F(0)` (4 % for n = 1.5)
    /// head-on. What rendered scenes use.
    #[default]
    Absolute,
    /// Divided by `F(0)`: a flat patch seen head-on reflects 1 (the thesis'
    /// normalisation; for comparisons with it and plots of `R`).
    Relative,
}

impl Reflectance {
    /// The scene/CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Reflectance::Absolute => "absolute",
            Reflectance::Relative => "relative",
        }
    }

    /// From the scene/CLI name.
    pub fn from_name(s: &str) -> Option<Reflectance> {
        match s {
            "absolute" => Some(Reflectance::Absolute),
            "relative" => Some(Reflectance::Relative),
            _ => None,
        }
    }
}

/// The skin's interface: its refractive index and the normalisation of `G`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Refractive index of the skin (from air); > 1 for the default 1.5.
    pub ior: f64,
    pub reflectance: Reflectance,
    /// The energy bound on `G` of this skin on its pack (OFF: none; built by
    /// `sunbeam_response::energy`).
    pub energy: EnergyBound,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            ior: DEFAULT_IOR,
            reflectance: Reflectance::Absolute,
            energy: EnergyBound::OFF,
        }
    }
}

impl Material {
    /// The thesis' normalisation at the default index.
    pub const RELATIVE: Material = Material {
        ior: DEFAULT_IOR,
        reflectance: Reflectance::Relative,
        energy: EnergyBound::OFF,
    };

    /// The factor `G` is divided by: 1 (absolute) or `F(0)` (relative).
    pub fn norm(self) -> f64 {
        match self.reflectance {
            Reflectance::Absolute => 1.0,
            Reflectance::Relative => f0(self.ior),
        }
    }

    /// `F(theta)` for this index.
    pub fn fresnel(self, cos_theta: f64) -> f64 {
        fresnel(cos_theta, self.ior)
    }

    /// What a diffuse base under the skin gets at incidence `cos_i`: `1 - F(th_i)`
    /// (PHYSICS.md 2; not divided by `F(0)` in either normalisation).
    pub fn transmission(self, cos_i: f64) -> f64 {
        1.0 - fresnel(cos_i, self.ior)
    }
}

/// Fresnel reflectance at normal incidence, `((n - 1)/(n + 1))^2`.
pub fn f0(n_ior: f64) -> f64 {
    let r = (n_ior - 1.0) / (n_ior + 1.0);
    r * r
}

/// The exact unpolarised Fresnel power reflectance `(r_s^2 + r_p^2) / 2` from
/// air into index `n_ior` at incidence `cos_theta` (clamped to [0, 1]); 1 at
/// grazing and under total internal reflection (`n_ior < 1`).
pub fn fresnel(cos_theta: f64, n_ior: f64) -> f64 {
    let c = cos_theta.clamp(0.0, 1.0);
    let s2t = (1.0 - c * c) / (n_ior * n_ior);
    if s2t >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - s2t).sqrt();
    let rs = (c - n_ior * ct) / (c + n_ior * ct);
    let rp = (n_ior * c - ct) / (n_ior * c + ct);
    0.5 * (rs * rs + rp * rp)
}

/// `cos theta_d = wi.h`, the angle at which `F` is taken (0 when `wi + wr = 0`).
pub fn cos_half(wi: [f64; 3], wr: [f64; 3]) -> f64 {
    let s = [wi[0] + wr[0], wi[1] + wr[1], wi[2] + wr[2]];
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    if len > 0.0 {
        (wi[0] * s[0] + wi[1] * s[1] + wi[2] * s[2]) / len
    } else {
        0.0
    }
}

/// `G(wi, wr)` for `mat`, times its energy bound at `wr` ([`EnergyBound`]; 1
/// without one). Zero when either direction is at or below the horizon (`d.n <= 0`).
pub fn g(wi: [f64; 3], wr: [f64; 3], mat: Material) -> f64 {
    let ci = wi[2];
    let cr = wr[2];
    if !(ci > 0.0 && cr > 0.0) {
        return 0.0;
    }
    let f = mat.fresnel(cos_half(wi, wr));
    let dot = wi[0] * wr[0] + wi[1] * wr[1] + wi[2] * wr[2];
    let num = f * (1.0 + dot) * (1.0 + dot);
    let den = mat.norm() * (ci + cr) * (ci + cr) * cr;
    num / den * mat.energy.factor(cr)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// PHYSICS.md 2's values for n = 1.5, and the closed forms at the ends.
    #[test]
    fn fresnel_known_values() {
        for (deg, want) in [(0.0f64, 0.04), (60.0, 0.0892), (80.0, 0.3877)] {
            let got = fresnel(deg.to_radians().cos(), 1.5);
            assert!((got - want).abs() < 5e-5, "{deg}: {got}");
        }
        assert!((fresnel(0.0, 1.5) - 1.0).abs() < 1e-15);
        assert!((fresnel(1.0, 1.33) - f0(1.33)).abs() < 1e-15);
        // Brewster: r_p vanishes, F = r_s^2 / 2.
        let tb = 1.5f64.atan();
        let ct = (1.0 - tb.sin().powi(2) / 2.25).sqrt();
        let rs = (tb.cos() - 1.5 * ct) / (tb.cos() + 1.5 * ct);
        assert!((fresnel(tb.cos(), 1.5) - rs * rs / 2.0).abs() < 1e-15);
    }

    #[test]
    fn normal_incidence() {
        let n = [0.0, 0.0, 1.0];
        assert!((g(n, n, Material::default()) - 0.04).abs() < 1e-15);
        assert!((g(n, n, Material::RELATIVE) - 1.0).abs() < 1e-14);
        assert!((f0(1.5) - 0.04).abs() < 1e-15);
    }

    /// Oblique specular: `G = F(theta) cos theta` (absolute), Fresnel once.
    #[test]
    fn oblique_specular_closed_form() {
        for deg in [10.0f64, 40.0, 75.0, 85.0] {
            let th = deg.to_radians();
            let wi = [th.sin(), 0.0, th.cos()];
            let wr = [-th.sin(), 0.0, th.cos()];
            let want = fresnel(th.cos(), 1.5) * th.cos();
            let got = g(wi, wr, Material::default());
            assert!((got - want).abs() < 1e-12 * want, "{deg}: {got} vs {want}");
            let rel = g(wi, wr, Material::RELATIVE);
            assert!((rel - want / 0.04).abs() < 1e-11 * rel);
        }
    }

    #[test]
    fn below_horizon_is_zero() {
        assert_eq!(
            g([0.0, 0.0, -1.0], [0.0, 0.0, 1.0], Material::default()),
            0.0
        );
    }

    #[test]
    fn names_round_trip() {
        for r in [Reflectance::Absolute, Reflectance::Relative] {
            assert_eq!(Reflectance::from_name(r.name()), Some(r));
        }
        assert_eq!(Reflectance::from_name("mirror"), None);
    }
}
