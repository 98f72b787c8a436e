//! The window model's exact Kirchhoff amplitude at grazing directions
//! (PHYSICS.md 2b): the one float64 implementation; the pack's evaluator and
//! the response-map builder feed it their amplitudes and derivatives.
//!
//! With the window `g` (a Gaussian of widths `sigma_x`, `sigma_y`) integrated
//! by parts, the amplitude is
//!
//! ```text
//! U(q) = (|q|^2 / q_z) P + 1 / (k^2 q_z) (q_x / sigma_x^2 dP/dq_x + q_y / sigma_y^2 dP/dq_y)
//! ```
//!
//! and `|U|^2 / 4` takes the place of `|q|^4 / (4 q_z^2) |P|^2` in `G R`.
//! Written as an effective reflectance that multiplies the unchanged gain `G`:
//!
//! ```text
//! R_U = |U|^2 q_z^2 / |q|^4 = | P + (u/sigma_x^2 dP/du + v/sigma_y^2 dP/dv) / (k^2 |q|^2) |^2
//! ```
//!
//! in the pack's convention (`P(u, v, w) = sum g exp(i k (u x + v y + w h)) / sum g`,
//! `(u, v, w) = -q`, derivatives at fixed `w`: `q_x d/dq_x = u d/du`, and the
//! conjugation between the two conventions leaves the modulus alone). For a
//! flat patch `dP/du = -k^2 sigma_x^2 u P`, so `R_U = (w^2/|q|^2)^2 |P|^2`:
//! `G R_U` is bounded at grazing. For a diffracted order centred at `q0` the
//! correction vanishes at the order's centre: Beckmann's factor holds there.

/// `R_U` from the amplitude `p` (re, im), its derivatives `dp_du`, `dp_dv` at
/// fixed `w`, the wavenumber `k = 2 pi / lambda` and the window's widths
/// `sigma` (metres). `uvw` is `-wi - wr`.
pub fn window_reflectance(
    uvw: [f64; 3],
    p: [f64; 2],
    dp_du: [f64; 2],
    dp_dv: [f64; 2],
    k: f64,
    sigma: [f64; 2],
) -> f64 {
    let q2 = uvw[0] * uvw[0] + uvw[1] * uvw[1] + uvw[2] * uvw[2];
    if !(q2 > 0.0 && k > 0.0 && sigma[0] > 0.0 && sigma[1] > 0.0) {
        return p[0] * p[0] + p[1] * p[1];
    }
    let a = uvw[0] / (sigma[0] * sigma[0] * k * k * q2);
    let b = uvw[1] / (sigma[1] * sigma[1] * k * k * q2);
    let re = p[0] + a * dp_du[0] + b * dp_dv[0];
    let im = p[1] + a * dp_du[1] + b * dp_dv[1];
    re * re + im * im
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat patch's Gaussian lobe: `R_U = (w^2 / |q|^2)^2 |P|^2` exactly.
    #[test]
    fn flat_patch_closed_form() {
        let (sx, sy, k) = (3e-6, 5e-6, 2.0 * std::f64::consts::PI / 500e-9);
        for uvw in [[0.01, 0.0, -1.99], [0.9, 0.3, -0.2], [1.7, -0.9, -0.01]] {
            let (u, v) = (uvw[0], uvw[1]);
            let pa = (-(k * k) * (u * u * sx * sx + v * v * sy * sy) / 2.0).exp();
            let p = [0.6 * pa, 0.8 * pa];
            let du = p.map(|c| -k * k * sx * sx * u * c);
            let dv = p.map(|c| -k * k * sy * sy * v * c);
            let q2 = u * u + v * v + uvw[2] * uvw[2];
            let want = (uvw[2] * uvw[2] / q2).powi(2) * pa * pa;
            let got = window_reflectance(uvw, p, du, dv, k, [sx, sy]);
            assert!(
                (got - want).abs() <= 1e-12 * want.max(1e-300),
                "{uvw:?}: {got} vs {want}"
            );
        }
    }

    /// With no derivative (an order's centre) `R_U = |P|^2`.
    #[test]
    fn stationary_point_is_beckmann() {
        let got = window_reflectance(
            [0.3, 0.1, -1.0],
            [0.3, 0.4],
            [0.0; 2],
            [0.0; 2],
            1e7,
            [1e-6; 2],
        );
        assert!((got - 0.25).abs() < 1e-15);
    }
}
