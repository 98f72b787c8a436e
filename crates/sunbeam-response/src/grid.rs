//! Where the response map puts its texels: a polar grid over `(u, v)` with an
//! `asinh` radius, and `w` relative to its largest possible magnitude.
//!
//! Why polar: after the spectral integral, `T(u, v, w)` is smooth along the
//! radial direction of `(u, v)` (each wavelength samples `f = -(u, v) / lambda`
//! along one ray from the specular direction, so the colour integral smears
//! every lobe along that ray) and sharp across it (lobes are `lambda / (2 pi sigma)`
//! wide). Angle gets the many texels, radius few. The radius is
//! `rho = asinh(r / r0) / asinh(2 / r0)`: linear near the specular peak (steps
//! of about `r0`, the width of a lobe) and logarithmic beyond, where the
//! smearing is proportional to `r`. The third axis is
//! `s = -w / sqrt(4 - r^2)` in [0, 1] (`|(u, v, w)| <= 2`), so no texel is spent
//! on directions no pair of unit vectors has.
//!
//! Texture coordinates (what the WGSL and the CPU lookup compute, texel centres
//! at `(i + 0.5) / n`): `x = theta / 2 pi + 0.5 / n_theta` (repeats),
//! `y = (rho (n_rho - 1) + 0.5) / n_rho`, `z = (s (n_s - 1) + 0.5) / n_s`
//! (clamped), so texel `(i, j, k)` holds `theta = 2 pi i / n_theta`,
//! `rho = j / (n_rho - 1)`, `s = k / (n_s - 1)`.

use serde::{Deserialize, Serialize};

/// Grid of a response map.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Grid {
    pub n_theta: usize,
    pub n_rho: usize,
    pub n_s: usize,
    /// Knee of the radial warp (in units of |(u, v)|).
    pub r0: f64,
}

impl Grid {
    /// `asinh(2 / r0)`.
    pub fn rho_scale(&self) -> f64 {
        (2.0 / self.r0).asinh()
    }

    /// `(u, v)` radius of radial texel `j`.
    pub fn r_at(&self, j: usize) -> f64 {
        let rho = j as f64 / (self.n_rho - 1) as f64;
        (self.r0 * (rho * self.rho_scale()).sinh()).min(2.0)
    }

    /// Radii of the inner and outer edges of a texel of radial row `j`
    /// (halfway to its neighbours' centres) and its area in `(u, v)`: the
    /// texels the reference's quadrature sums and the cells cluster.
    pub fn texel_extent(&self, j: usize) -> (f64, f64, f64) {
        let last = (self.n_rho - 1) as f64;
        let r = |rho: f64| (self.r0 * (rho * self.rho_scale()).sinh()).clamp(0.0, 2.0);
        let r_lo = r((j as f64 - 0.5).max(0.0) / last);
        let r_hi = r((j as f64 + 0.5).min(last) / last);
        let dt = std::f64::consts::TAU / self.n_theta as f64;
        (r_lo, r_hi, dt * (r_hi * r_hi - r_lo * r_lo) / 2.0)
    }

    /// `s` of texel `k`.
    pub fn s_at(&self, k: usize) -> f64 {
        k as f64 / (self.n_s - 1) as f64
    }

    /// Angle of texel `i`.
    pub fn theta_at(&self, i: usize) -> f64 {
        std::f64::consts::TAU * i as f64 / self.n_theta as f64
    }

    /// Continuous texel coordinates `(i, j, k)` (texel units, centres at integers)
    /// of a direction, before wrapping/clamping. `None` outside the domain (w > 0).
    pub fn coords(&self, u: f64, v: f64, w: f64) -> Option<[f64; 3]> {
        if !(u.is_finite() && v.is_finite() && w.is_finite()) || w > 0.0 {
            return None;
        }
        let r = (u * u + v * v).sqrt();
        let theta = v.atan2(u).rem_euclid(std::f64::consts::TAU);
        let rho = ((r / self.r0).asinh() / self.rho_scale()).clamp(0.0, 1.0);
        let s = (-w / (4.0 - r * r).max(1e-12).sqrt()).clamp(0.0, 1.0);
        Some([
            theta / std::f64::consts::TAU * self.n_theta as f64,
            rho * (self.n_rho - 1) as f64,
            s * (self.n_s - 1) as f64,
        ])
    }

    /// Trilinear interpolation at continuous texel coordinates `c` (see
    /// [`Grid::coords`]): the angle wraps, radius and `s` are clamped; `texel`
    /// reads texel `(i, j, k)`. What a shader's single texture sample returns.
    pub fn trilinear(
        &self,
        c: [f64; 3],
        texel: impl Fn(usize, usize, usize) -> [f64; 3],
    ) -> [f64; 3] {
        let fi = c[0].floor();
        let (ti, i0) = (
            c[0] - fi,
            (fi as i64).rem_euclid(self.n_theta as i64) as usize,
        );
        let i1 = (i0 + 1) % self.n_theta;
        let split = |x: f64, n: usize| {
            let x = x.clamp(0.0, (n - 1) as f64);
            let j = (x.floor() as usize).min(n - 2);
            (j, x - j as f64)
        };
        let (j0, tj) = split(c[1], self.n_rho);
        let (k0, tk) = split(c[2], self.n_s);
        let mut out = [0.0; 3];
        for (k, wk) in [(k0, 1.0 - tk), (k0 + 1, tk)] {
            for (j, wj) in [(j0, 1.0 - tj), (j0 + 1, tj)] {
                for (i, wi) in [(i0, 1.0 - ti), (i1, ti)] {
                    let wgt = wk * wj * wi;
                    if wgt == 0.0 {
                        continue;
                    }
                    let t = texel(i, j, k);
                    for (o, v) in out.iter_mut().zip(t) {
                        *o += wgt * v;
                    }
                }
            }
        }
        out
    }

    pub fn texels(&self) -> usize {
        self.n_theta * self.n_rho * self.n_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_centres_map_back_to_their_indices() {
        let g = Grid {
            n_theta: 64,
            n_rho: 40,
            n_s: 12,
            r0: 0.01,
        };
        for (i, j, k) in [(0, 0, 0), (5, 7, 3), (63, 39, 11), (32, 20, 6)] {
            let (th, r, s) = (g.theta_at(i), g.r_at(j), g.s_at(k));
            let w = -s * (4.0 - r * r).max(0.0).sqrt();
            let c = g.coords(r * th.cos(), r * th.sin(), w).unwrap();
            let want = [i as f64, j as f64, k as f64];
            for a in 0..3 {
                // theta is undefined at r = 0, s at r = 2 (there w must be 0)
                if (a == 0 && j == 0) || (a == 2 && j == g.n_rho - 1) {
                    continue;
                }
                assert!((c[a] - want[a]).abs() < 1e-6, "{c:?} vs {want:?}");
            }
        }
        assert!(g.coords(0.1, 0.0, 0.1).is_none());
        assert!((g.r_at(39) - 2.0).abs() < 1e-9);
    }
}
