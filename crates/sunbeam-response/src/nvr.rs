//! The `n = v = r` prefilter approximation (Toisoul and Ghosh, "Practical
//! acquisition and rendering of diffraction effects in surface reflectance",
//! TOG 2017), as a CPU estimator with the same maps, proposal and uniforms as
//! the player's twin [`EnvResponse::sample`], so that what it costs can be
//! measured against that twin and nothing else (issue #13; figures in
//! docs/bench/prefilter.md, docs/LIGHTING.md "The player against n = v = r").
//!
//! Why it exists: real-time diffraction renderers prefilter the environment
//! with the diffraction lobe of *one* view, the one along the normal
//! (`n = v = r`), and look the result up by the mirror direction `r` of the
//! actual view, rotating the head-on lobe rigidly onto `r`. That drops
//! everything the lobe does when the view tilts: the orders' positions in
//! `(u, v)` are offset by `wr_xy` (dispersion is not a rigid rotation), the
//! phase depth `w = -(wi_z + wr_z)` and with it the orders' strengths change,
//! `G` grows towards grazing views, and the lobe's part below the surface's
//! horizon is kept. The player does not use this approximation; this module
//! is a yardstick (and a regression test keeps it from quietly becoming the
//! exact estimator, tests/nvr.rs).
//!
//! One sample, with `n = (0, 0, 1)`, the mirror direction `r = (-wr_x, -wr_y,
//! wr_z)` (local) and `Q` the minimal rotation taking `n` to `r`:
//!
//! - sky and map: `(u, v)` from [`EnvResponse::draw`] at the view `n` (the
//!   same mixture of proposal and defensive hemisphere, the same density),
//!   `wi' = (-u, -v, sqrt(1 - u^2 - v^2))`, weight
//!   `G(wi', n) / cos(theta_i') sum_k c_k(frame(Q wi')) E_k(u, v, -wi'_z - 1) / pdf`;
//! - the sun: its local direction `d` taken back to the head-on lobe,
//!   `wi' = Q^T d`, adds `G(wi', n) (Omega E_sun)(-wi'_x, -wi'_y, -wi'_z - 1)`
//!
//! (`G` the mesh's skin's gain times its masking, `masking.gain(wi', n, skin)`,
//! as in the twin)
//!   when `wi'_z > 0` (the hemisphere the prefilter integrates over, not the
//!   surface's: a prefiltered map indexed by `r` alone cannot know where the
//!   surface's horizon is, so neither does this estimator's sky part).
//!
//! At a head-on view (`wr = n`, so `Q = I`) it is [`EnvResponse::sample`]
//! term for term.

use crate::env::{EnvResponse, Frame};
use sunbeam_light::Environment;
use sunbeam_optics::masking::Masking;
use sunbeam_optics::{colour, gain};

/// The normal, which is also the view and the mirror direction of the
/// prefilter's lobe.
const N: [f64; 3] = [0.0, 0.0, 1.0];

/// `Q v`, `Q` the minimal rotation (about `n x r`) taking `n = (0, 0, 1)` to
/// the unit `r` with `r_z > -1`; with `inverse`, `Q^T v`. Rodrigues' formula
/// in the form `v c + k x v + k (k . v) / (1 + c)`, `k = n x r`, `c = r_z`,
/// which is exactly `v` when `r = n` (so the head-on case reproduces the
/// exact twin bit for bit).
pub fn rotate_from_normal(r: [f64; 3], v: [f64; 3], inverse: bool) -> [f64; 3] {
    let c = r[2];
    let s = if inverse { -1.0 } else { 1.0 };
    let k = [-r[1], r[0], 0.0];
    let kxv = [
        k[1] * v[2] - k[2] * v[1],
        k[2] * v[0] - k[0] * v[2],
        k[0] * v[1] - k[1] * v[0],
    ];
    let kv = (k[0] * v[0] + k[1] * v[1] + k[2] * v[2]) / (1.0 + c);
    [0, 1, 2].map(|a| v[a] * c + s * kxv[a] + k[a] * kv)
}

/// One sample of the `n = v = r` prefilter approximation (linear sRGB) at
/// local view `wr_l` (unit, z > 0), with the same arguments and uniforms as
/// [`EnvResponse::sample`] (the skin and masking of the mesh, `u[0..3]` the
/// draw at the head-on view, `u[3..5]` the sun's disc). Its expectation is
/// what a renderer that prefilters the environment with the head-on lobe and
/// looks it up by the mirror direction shows, computed from the same maps
/// (module docs).
pub fn prefilter_nvr_sample(
    e: &EnvResponse,
    env: &Environment,
    frame: Frame,
    wr_l: [f64; 3],
    masking: Masking,
    skin: gain::Material,
    u: [f64; 5],
) -> [f64; 3] {
    let (t, b, n) = frame;
    let world = |d: [f64; 3]| [0, 1, 2].map(|k| d[0] * t[k] + d[1] * b[k] + d[2] * n[k]);
    let mut xyz = [0.0; 3];
    if wr_l[2].is_nan() || wr_l[2] <= 0.0 {
        return xyz;
    }
    let r = [-wr_l[0], -wr_l[1], wr_l[2]];
    // The sky and the map: the head-on lobe, rotated onto r for the lookup.
    if let Some((uv, pdf)) = e.draw(N, skin, [u[0], u[1], u[2]]) {
        let (wx, wy) = (-uv[0] - N[0], -uv[1] - N[1]);
        let r2 = wx * wx + wy * wy;
        if r2 < 1.0 && pdf > 0.0 {
            let wi = [wx, wy, (1.0 - r2).sqrt()];
            let w = -(wi[2] + N[2]);
            let c = env.coefficients(world(rotate_from_normal(r, wi, false)));
            let f = masking.gain(wi, N, skin) / (wi[2] * pdf);
            for (ck, ek) in c.iter().zip(&e.basis) {
                let v = ek.lookup(uv[0], uv[1], w);
                for a in 0..3 {
                    xyz[a] += f * ck * v[a];
                }
            }
        }
    }
    // The sun: its direction taken back into the head-on lobe's frame.
    if let (Some(sky), Some(e_sun)) = (env.sun(), &e.sun) {
        if let Some((d, _)) = sky.sample_sun(u[3], u[4]) {
            let dot = |a: [f64; 3]| a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
            let wi = rotate_from_normal(r, [dot(t), dot(b), dot(n)], true);
            if wi[2] > 0.0 {
                let (uu, vv, w) = (-wi[0] - N[0], -wi[1] - N[1], -wi[2] - N[2]);
                let f = masking.gain(wi, N, skin);
                let v = e_sun.lookup(uu, vv, w);
                for a in 0..3 {
                    xyz[a] += f * v[a];
                }
            }
        }
    }
    colour::xyz_to_linear_srgb(xyz)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(v: [f64; 3]) -> [f64; 3] {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / l)
    }

    /// `Q n = r`, `Q^T r = n`, `Q^T Q v = v`, lengths kept, and the axis
    /// `n x r` is fixed (the rotation is the minimal one).
    #[test]
    fn rotation_takes_n_to_r() {
        let r = unit([0.3, -0.5, 0.4]);
        let v = unit([-0.2, 0.7, 0.1]);
        let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-12);
        assert!(close(rotate_from_normal(r, N, false), r));
        assert!(close(rotate_from_normal(r, r, true), N));
        let back = rotate_from_normal(r, rotate_from_normal(r, v, false), true);
        assert!(close(back, v));
        let axis = [-r[1], r[0], 0.0];
        assert!(close(rotate_from_normal(r, axis, false), axis));
        assert_eq!(rotate_from_normal(N, v, false), v);
    }
}
