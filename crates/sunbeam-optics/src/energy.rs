//! The energy bound (PHYSICS.md 2b: "the directional albedo must stay <= 1
//! at every view"; docs/LIGHTING.md "Energy bound"): a factor on `G` that
//! depends on the view alone,
//!
//! ```text
//! E(wr) = 1 / max(1, a(wr)) = min(1, cos(theta_r) / b(cos(theta_r)))
//! ```
//!
//! with `a` the diffraction term's directional albedo, `b(c) = c a(c)`.
//! Why: `G`'s `1 / cos(theta_r)` meets lobes at `cos(theta_i) >>
//! cos(theta_r)` at grazing views, so without masking the albedo grows like
//! `1 / cos(theta_r)` (5-20 at 89.9 deg, crates/sunbeam-response/tests/energy.rs),
//! and on a mesh with interpolated normals the mean of that over a
//! silhouette pixel diverges: no sample count converged the reference there
//! (docs/EVAL.md "diff"). Dividing by the albedo where it exceeds 1 is the
//! least change that bounds the energy: views whose albedo is <= 1 (all but
//! the last degrees, for absolute reflectance) are untouched.
//!
//! `a` is tabulated per pack and skin (index, normalisation, masking) by
//! `sunbeam_response::energy` from the pack's response map, as the largest
//! linear-sRGB channel of the albedo under a white furnace, the largest over
//! the view's azimuth: one table of [`KNOTS`] values of `b` at `t =
//! sqrt(cos(theta_r))` uniform in [0, 1], linear in `t` between them (`b` is
//! smooth where `a` is not: `a ~ b(0) / cos(theta_r)` at grazing), so that
//! it fits the material's uniforms in every renderer (a `mat4x4` in WGSL and
//! GLSL; `sb_energy` in shaders/material.wgsl is the same function).
//! Taking the largest over the azimuth keeps the bound at every azimuth and
//! darkens the weaker azimuths of a ridge pack a little more than needed,
//! only where the strongest one exceeds 1.

/// Knots of the table, at `t = sqrt(cos(theta_r)) = k / (KNOTS - 1)`.
pub const KNOTS: usize = 16;

/// The bound of one skin on one pack: `b` at the knots. All zero: no bound
/// (the factor is 1), what a material without a table gets.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyBound {
    pub b: [f32; KNOTS],
}

impl EnergyBound {
    /// No bound: the factor is 1 at every view.
    pub const OFF: EnergyBound = EnergyBound { b: [0.0; KNOTS] };

    /// `cos(theta_r)` of knot `k` (`t^2`).
    pub fn knot_cos(k: usize) -> f64 {
        let t = k as f64 / (KNOTS - 1) as f64;
        t * t
    }

    /// `b(cos_r)`, linear in `t = sqrt(cos_r)` between the knots.
    pub fn b_at(&self, cos_r: f64) -> f64 {
        let t = cos_r.clamp(0.0, 1.0).sqrt() * (KNOTS - 1) as f64;
        let k = (t as usize).min(KNOTS - 2);
        let f = t - k as f64;
        self.b[k] as f64 * (1.0 - f) + self.b[k + 1] as f64 * f
    }

    /// The factor `E = min(1, cos_r / b(cos_r))` on `G` at view `cos_r`.
    pub fn factor(&self, cos_r: f64) -> f64 {
        let b = self.b_at(cos_r);
        if b <= cos_r {
            1.0
        } else {
            cos_r.max(0.0) / b
        }
    }

    /// Whether any view is bounded.
    pub fn is_off(&self) -> bool {
        self.b.iter().all(|&b| b <= 0.0)
    }

    /// The table as the GPU's `mat4x4<f32>` (column `k / 4`, row `k % 4`).
    pub fn columns(&self) -> [[f32; 4]; 4] {
        let mut m = [[0.0; 4]; 4];
        for (k, &b) in self.b.iter().enumerate() {
            m[k / 4][k % 4] = b;
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn off_is_one_and_bound_caps_albedo() {
        for c in [0.0, 1e-4, 0.3, 1.0] {
            assert_eq!(EnergyBound::OFF.factor(c), 1.0);
        }
        // a = 0.04 + 0.02 / c: b = 0.04 c + 0.02 (linear in c, so not in t:
        // the knots are exact, in between within the interpolation).
        let mut e = EnergyBound::OFF;
        for k in 0..KNOTS {
            let c = EnergyBound::knot_cos(k);
            e.b[k] = (0.04 * c + 0.02) as f32;
        }
        assert_eq!(e.factor(1.0), 1.0);
        assert_eq!(e.factor(0.5), 1.0);
        assert_eq!(e.factor(0.0), 0.0);
        for c in [1e-4, 1e-3, 0.01, 0.019] {
            let a = 0.04 + 0.02 / c;
            let bounded = a * e.factor(c);
            assert!((bounded - 1.0).abs() < 5e-3, "{c}: {bounded}");
        }
        let m = e.columns();
        assert_eq!(m[3][3], e.b[15]);
        assert_eq!(m[1][2], e.b[6]);
    }
}
