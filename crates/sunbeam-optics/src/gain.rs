//! The gain `G(wi, wr)` of PHYSICS.md 2 (thesis eqs. 2.15, 2.29):
//!
//! ```text
//! G = F(wi,wr)^2 (1 + wi.wr)^2 / ( F0^2 (cos th_i + cos th_r)^2 cos th_r )
//! ```
//!
//! with Schlick's Fresnel `F = F0 + (1 - F0)(1 - cos th_h)^5`,
//! `F0 = ((n - 1)/(n + 1))^2`, `cos th_h = wi.h` and `h = (wi + wr)/|wi + wr|`
//! the half vector. A flat mirror at normal incidence gets `G = 1`; at
//! oblique specular `G = (F/F0)^2 cos th`. Directions are local unit vectors
//! `(d.t, d.b, d.n)`; `wi` to the light, `wr` to the viewer.

/// Default index of refraction (PHYSICS.md 2).
pub const DEFAULT_IOR: f64 = 1.5;

/// Schlick's `F0 = ((n - 1)/(n + 1))^2`.
pub fn f0(n_ior: f64) -> f64 {
    let r = (n_ior - 1.0) / (n_ior + 1.0);
    r * r
}

/// Schlick's Fresnel for `cos_theta` (clamped to [0, 1]).
pub fn schlick(cos_theta: f64, n_ior: f64) -> f64 {
    let f0 = f0(n_ior);
    let m = 1.0 - cos_theta.clamp(0.0, 1.0);
    f0 + (1.0 - f0) * m.powi(5)
}

/// `G(wi, wr)`. Zero when either direction is at or below the horizon (`d.n <= 0`).
pub fn g(wi: [f64; 3], wr: [f64; 3], n_ior: f64) -> f64 {
    let ci = wi[2];
    let cr = wr[2];
    if !(ci > 0.0 && cr > 0.0) {
        return 0.0;
    }
    let s = [wi[0] + wr[0], wi[1] + wr[1], wi[2] + wr[2]];
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let cos_h = if len > 0.0 {
        (wi[0] * s[0] + wi[1] * s[1] + wi[2] * s[2]) / len
    } else {
        0.0
    };
    let f = schlick(cos_h, n_ior);
    let f0 = f0(n_ior);
    let dot = wi[0] * wr[0] + wi[1] * wr[1] + wi[2] * wr[2];
    let num = f * f * (1.0 + dot) * (1.0 + dot);
    let den = f0 * f0 * (ci + cr) * (ci + cr) * cr;
    num / den
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_is_one() {
        assert!((g([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], DEFAULT_IOR) - 1.0).abs() < 1e-15);
        assert!((f0(1.5) - 0.04).abs() < 1e-15);
    }

    #[test]
    fn oblique_specular_closed_form() {
        for deg in [10.0f64, 40.0, 75.0, 85.0] {
            let th = deg.to_radians();
            let wi = [th.sin(), 0.0, th.cos()];
            let wr = [-th.sin(), 0.0, th.cos()];
            let f = schlick(th.cos(), 1.5);
            let want = (f / 0.04).powi(2) * th.cos();
            let got = g(wi, wr, 1.5);
            assert!((got - want).abs() < 1e-12 * want, "{deg}: {got} vs {want}");
        }
    }

    #[test]
    fn below_horizon_is_zero() {
        assert_eq!(g([0.0, 0.0, -1.0], [0.0, 0.0, 1.0], 1.5), 0.0);
    }
}
