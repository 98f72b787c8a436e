//! An environment's hot spots (sunbeam_light::hotspots) through the
//! extended-light maps: the float64 twin of shaders/env_hotspots.wgsl
//! (docs/LIGHTING.md "The first frame").
//!
//! A light of basis power `P_k = int c_k d(omega)` over a small solid angle
//! adds `G(wi, wr) sum_k P_k E_k(-wi - wr)`: the maps integrate over `(u,
//! v)`, and `d(u, v) = cos(theta_i) d(omega)` cancels their `1 / cos`. Its
//! extent is four taps on its principal axes (`HotSpot::axes`: they have the
//! light's second moments; one tap for a single texel).

use crate::cells::Frame;
use crate::Response;
use sunbeam_light::hotspots::HotSpot;
use sunbeam_optics::gain;
use sunbeam_optics::masking::Masking;

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = dot(v, v).sqrt();
    v.map(|x| x / l)
}

/// The taps of a light: (world direction, weight).
pub fn taps(l: &HotSpot) -> Vec<([f64; 3], f64)> {
    if l.spread.is_nan() || l.spread <= 0.0 {
        return vec![(l.dir, 1.0)];
    }
    let [a1, a2] = l.axes;
    [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
        .map(|(p, q)| {
            let d = [0, 1, 2].map(|k| l.dir[k] + p * a1[k] + q * a2[k]);
            (unit(d), 0.25)
        })
        .to_vec()
}

/// XYZ towards local view `wr` from `lights` through the basis maps `basis`
/// (`EnvResponse::basis`), frame `(t, b, n)`.
pub fn estimate(
    lights: &[HotSpot],
    basis: &[Response],
    frame: Frame,
    wr: [f64; 3],
    masking: Masking,
    skin: gain::Material,
) -> [f64; 3] {
    let (t, b, n) = frame;
    let mut x = [0.0; 3];
    if wr[2].is_nan() || wr[2] <= 0.0 {
        return x;
    }
    for l in lights {
        for (d, wt) in taps(l) {
            let wi = [dot(t, d), dot(b, d), dot(n, d)];
            if wi[2] <= 0.0 {
                continue;
            }
            let g = masking.gain(wi, wr, skin);
            let (u, v, w) = (-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]);
            for (k, m) in basis.iter().enumerate() {
                let e = m.lookup(u, v, w);
                for a in 0..3 {
                    x[a] += wt * g * l.power[k] * e[a];
                }
            }
        }
    }
    x
}
