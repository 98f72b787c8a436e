//! An environment's hot spots pulled out as small lights (docs/LIGHTING.md
//! "The first frame": a real HDR image keeps most of its energy in a few
//! hundred texels, its lamps and softboxes, which one centroid per cell
//! cannot follow through a rainbow streak; a small light through the
//! extended-light maps can).
//!
//! A texel is hot when its brightness (the sum of its three basis
//! coefficients) exceeds `threshold` times the map's mean over the sphere.
//! Hot texels are grouped into 8-connected regions (the azimuth wraps); the
//! brightest regions become lights, each taking the part of its texels above
//! the threshold, `c (1 - tau / y)`, with the texel's own chromaticity. What
//! stays is the residual table, `min(y, tau)` in brightness: smooth enough
//! for the cells. Energy is conserved texel by texel: residual plus lights is
//! the table.
//!
//! Hand-written: a flood fill over an equirectangular grid with a wrapping
//! azimuth is a few lines, and no image crate of the workspace offers
//! connected components on a wrapping grid.

use std::f64::consts::{PI, TAU};

/// Lights by default (see [`SplitOptions::default`]).
pub const DEFAULT_MAX_LIGHTS: usize = 32;
/// A texel is hot above this many times the map's mean by default (see
/// [`SplitOptions::default`]).
pub const DEFAULT_THRESHOLD: f64 = 8.0;

/// How hot spots are chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitOptions {
    /// A texel is hot above this many times the table's mean brightness.
    pub threshold: f64,
    /// At most this many lights (the brightest regions); the other regions
    /// stay in the residual.
    pub max_lights: usize,
}

impl Default for SplitOptions {
    fn default() -> Self {
        // The studio map (../shared/data/hdri/studio.exr, 256 cells below):
        // per shading point CIEDE2000 p99 24.1 without lights, 9.7 / 7.8 /
        // 6.4 with 16 / 32 / 64 (`cargo bench -p sunbeam-response --bench
        // cells`); thresholds 2 to 30 change little.
        SplitOptions {
            threshold: DEFAULT_THRESHOLD,
            max_lights: DEFAULT_MAX_LIGHTS,
        }
    }
}

/// One hot spot as a light.
#[derive(Debug, Clone, PartialEq)]
pub struct HotSpot {
    /// Unit direction towards the light (world), the power-weighted mean of
    /// its texels' directions.
    pub dir: [f64; 3],
    /// `int c_k d(omega)` over the light's texels (its part above the
    /// threshold): the basis coefficients' power, per steradian summed.
    pub power: [f64; 3],
    /// The solid angle of its texels (sr).
    pub solid_angle: f64,
    /// Power-weighted rms angle of its texels from `dir` (radians).
    pub spread: f64,
    /// Its extent along its two principal axes: tangent vectors at `dir`
    /// (world), each `sqrt(2 lambda)` long for the eigenvalue `lambda` of the
    /// power-weighted covariance of its texels' directions projected on the
    /// tangent plane, so that four taps at `dir +- axes[i]` with weight 1/4
    /// have the light's second moments. Zero for a single texel.
    pub axes: [[f64; 3]; 2],
}

/// A coefficient table split into lights and a residual table.
#[derive(Debug, Clone)]
pub struct Split {
    pub lights: Vec<HotSpot>,
    /// The table without the lights (same layout: RGBA f32, `w x h`).
    pub residual: Vec<f32>,
    /// Share of the table's energy (brightness times solid angle) the lights took.
    pub share: f64,
}

/// Solid angle of a texel in row `j` of a `w x h` equirectangular table.
pub fn texel_solid_angle(w: usize, h: usize, j: usize) -> f64 {
    ((PI * j as f64 / h as f64).cos() - (PI * (j + 1) as f64 / h as f64).cos()) * TAU / w as f64
}

/// Direction of texel `(i, j)`'s centre (crate::direction's convention).
fn texel_dir(w: usize, h: usize, i: usize, j: usize) -> [f64; 3] {
    let theta = (j as f64 + 0.5) / h as f64 * PI;
    let phi = (i as f64 + 0.5) / w as f64 * TAU;
    crate::direction(theta.cos(), phi)
}

/// Split the coefficient table `rgba` (`w x h`, RGBA f32, as
/// `Environment::coefficient_table`) into hot spots and a residual.
pub fn split(w: usize, h: usize, rgba: &[f32], opts: SplitOptions) -> Split {
    assert_eq!(rgba.len(), w * h * 4, "coefficient table size");
    let y = |t: usize| f64::from(rgba[4 * t] + rgba[4 * t + 1] + rgba[4 * t + 2]);
    let omega: Vec<f64> = (0..h).map(|j| texel_solid_angle(w, h, j)).collect();
    let total: f64 = (0..w * h).map(|t| y(t).max(0.0) * omega[t / w]).sum();
    let mut residual = rgba.to_vec();
    let tau = opts.threshold * total / (4.0 * PI);
    if total.is_nan() || total <= 0.0 || opts.max_lights == 0 {
        return Split {
            lights: Vec::new(),
            residual,
            share: 0.0,
        };
    }
    // 8-connected regions of hot texels
    let hot = |t: usize| y(t) > tau;
    let mut region = vec![u32::MAX; w * h];
    let mut regions: Vec<Vec<usize>> = Vec::new();
    for start in 0..w * h {
        if region[start] != u32::MAX || !hot(start) {
            continue;
        }
        let id = regions.len() as u32;
        let mut members = vec![start];
        region[start] = id;
        let mut q = 0;
        while q < members.len() {
            let t = members[q];
            q += 1;
            let (i, j) = ((t % w) as isize, (t / w) as isize);
            for dj in -1..=1isize {
                for di in -1..=1isize {
                    let jj = j + dj;
                    if (di, dj) == (0, 0) || jj < 0 || jj >= h as isize {
                        continue;
                    }
                    let ii = (i + di).rem_euclid(w as isize);
                    let n = jj as usize * w + ii as usize;
                    if region[n] == u32::MAX && hot(n) {
                        region[n] = id;
                        members.push(n);
                    }
                }
            }
        }
        regions.push(members);
    }
    let excess = |t: usize| (y(t) - tau) * omega[t / w];
    let mut order: Vec<(f64, usize)> = regions
        .iter()
        .enumerate()
        .map(|(r, m)| (m.iter().map(|&t| excess(t)).sum(), r))
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    // The brightest regions, then the widest pieces split at their power's
    // median along their widest axis until the lights run out: a softbox many
    // degrees across becomes several lights, each small enough for its map.
    let mut pieces: Vec<Vec<usize>> = order
        .iter()
        .take(opts.max_lights)
        .map(|&(_, r)| std::mem::take(&mut regions[r]))
        .collect();
    let stats = |m: &[usize]| {
        let mut sw = 0.0;
        let mut mean = [0.0; 3];
        for &t in m {
            let (wt, d) = (excess(t), texel_dir(w, h, t % w, t / w));
            sw += wt;
            for k in 0..3 {
                mean[k] += wt * d[k];
            }
        }
        let mean = mean.map(|x| x / sw);
        let mut var = [0.0; 3];
        for &t in m {
            let (wt, d) = (excess(t), texel_dir(w, h, t % w, t / w));
            for k in 0..3 {
                var[k] += wt * (d[k] - mean[k]).powi(2);
            }
        }
        (sw, var)
    };
    // power times spread squared (var is power-weighted: power^2 x spread^2),
    // kept per piece: only the two halves of a split piece change (recomputed
    // for every piece at every split, a 4096 x 2048 map's split took 0.3 s).
    let cost = |m: &[usize]| {
        let (_, var) = stats(m);
        var[0] + var[1] + var[2]
    };
    let mut costs: Vec<f64> = pieces.iter().map(|m| cost(m)).collect();
    while pieces.len() < opts.max_lights {
        let Some((at, _)) = costs
            .iter()
            .enumerate()
            .filter(|&(i, _)| pieces[i].len() > 1)
            .max_by(|a, b| a.1.total_cmp(b.1))
        else {
            break;
        };
        let m = std::mem::take(&mut pieces[at]);
        let (sw, var) = stats(&m);
        let axis = (0..3).max_by(|&a, &b| var[a].total_cmp(&var[b])).unwrap();
        // A stable sort on the axis' coordinate, each texel's direction made once.
        let mut keyed: Vec<(f64, usize)> = m
            .iter()
            .map(|&t| (texel_dir(w, h, t % w, t / w)[axis], t))
            .collect();
        keyed.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut m: Vec<usize> = keyed.into_iter().map(|(_, t)| t).collect();
        let mut acc = 0.0;
        let mut cut = m.len() - 1;
        for (q, &t) in m.iter().enumerate() {
            acc += excess(t);
            if acc >= 0.5 * sw {
                cut = (q + 1).min(m.len() - 1);
                break;
            }
        }
        let rest = m.split_off(cut.max(1));
        costs[at] = cost(&m);
        costs.push(cost(&rest));
        pieces[at] = m;
        pieces.push(rest);
    }
    let mut lights = Vec::new();
    let mut taken = 0.0;
    for members in &pieces {
        let e: f64 = members.iter().map(|&t| excess(t)).sum();
        let mut power = [0.0; 3];
        let mut d = [0.0; 3];
        let mut solid_angle = 0.0;
        for &t in members {
            let (yt, om) = (y(t), omega[t / w]);
            let keep = tau / yt;
            let td = texel_dir(w, h, t % w, t / w);
            let wgt = (yt - tau) * om;
            for k in 0..3 {
                power[k] += f64::from(rgba[4 * t + k]) * (1.0 - keep) * om;
                residual[4 * t + k] = (f64::from(rgba[4 * t + k]) * keep) as f32;
                d[k] += td[k] * wgt;
            }
            solid_angle += om;
        }
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let dir = d.map(|x| x / l);
        let mut s2 = 0.0;
        for &t in members {
            let td = texel_dir(w, h, t % w, t / w);
            let c = (td[0] * dir[0] + td[1] * dir[1] + td[2] * dir[2]).clamp(-1.0, 1.0);
            s2 += c.acos().powi(2) * (y(t) - tau) * omega[t / w];
        }
        taken += e;
        let axes = principal_axes(
            dir,
            members
                .iter()
                .map(|&t| (texel_dir(w, h, t % w, t / w), (y(t) - tau) * omega[t / w])),
        );
        lights.push(HotSpot {
            dir,
            power,
            solid_angle,
            spread: (s2 / e).sqrt(),
            axes,
        });
    }
    Split {
        lights,
        residual,
        share: taken / total,
    }
}

/// [`HotSpot::axes`] of weighted directions `pts` about unit `dir`.
fn principal_axes(dir: [f64; 3], pts: impl Iterator<Item = ([f64; 3], f64)>) -> [[f64; 3]; 2] {
    // any tangent basis: the axes do not depend on it
    let (e1, e2) = crate::sky::basis(dir);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (mut sw, mut m) = (0.0, [0.0f64; 3]);
    for (d, wt) in pts {
        let (x, y) = (dot(d, e1), dot(d, e2));
        sw += wt;
        m[0] += wt * x * x;
        m[1] += wt * x * y;
        m[2] += wt * y * y;
    }
    if sw <= 0.0 {
        return [[0.0; 3]; 2];
    }
    let (a, b, c) = (m[0] / sw, m[1] / sw, m[2] / sw);
    let half = 0.5 * (a - c);
    let r = (half * half + b * b).sqrt();
    let l1 = (0.5 * (a + c) + r).max(0.0);
    let l2 = (0.5 * (a + c) - r).max(0.0);
    // eigenvector of l1: (cos t, sin t) with tan 2t = 2b / (a - c)
    let t = 0.5 * (2.0 * b).atan2(a - c);
    let (s, co) = t.sin_cos();
    let v1 = [0, 1, 2].map(|k| co * e1[k] + s * e2[k]);
    let v2 = [0, 1, 2].map(|k| -s * e1[k] + co * e2[k]);
    let (s1, s2) = ((2.0 * l1).sqrt(), (2.0 * l2).sqrt());
    [v1.map(|x| x * s1), v2.map(|x| x * s2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A uniform table with two bright patches, one across the azimuth's seam:
    /// two lights, the residual at the threshold there, the energy conserved.
    #[test]
    fn two_patches_become_two_lights_and_nothing_is_lost() {
        let (w, h) = (64, 32);
        let mut t = vec![0.0f32; w * h * 4];
        for p in 0..w * h {
            t[4 * p..4 * p + 3].copy_from_slice(&[1.0, 1.0, 1.0]);
        }
        let mut put = |i: usize, j: usize, v: f32| {
            let p = j * w + i;
            t[4 * p..4 * p + 3].copy_from_slice(&[v, 2.0 * v, v]);
        };
        for j in 10..13 {
            for i in 20..23 {
                put(i, j, 200.0);
            }
            put(63, j, 500.0);
            put(0, j, 500.0);
        }
        let energy = |tab: &[f32]| -> [f64; 3] {
            let mut e = [0.0; 3];
            for p in 0..w * h {
                for k in 0..3 {
                    e[k] += f64::from(tab[4 * p + k]) * texel_solid_angle(w, h, p / w);
                }
            }
            e
        };
        let two = SplitOptions {
            max_lights: 2,
            ..SplitOptions::default()
        };
        let s = split(w, h, &t, two);
        assert_eq!(s.lights.len(), 2, "{:?}", s.lights);
        // with more lights to spend, the patches are cut into pieces, and the
        // pieces hold what the two lights held
        let many = split(w, h, &t, SplitOptions::default());
        assert_eq!(
            many.lights.len(),
            15,
            "one light per hot texel (32 allowed)"
        );
        for k in 0..3 {
            let a: f64 = s.lights.iter().map(|l| l.power[k]).sum();
            let b: f64 = many.lights.iter().map(|l| l.power[k]).sum();
            assert!((a / b - 1.0).abs() < 1e-9, "{a} vs {b}");
        }
        assert!(many.lights.iter().all(|l| l.spread < s.lights[1].spread));
        let before = energy(&t);
        let after = energy(&s.residual);
        for k in 0..3 {
            let lit: f64 = s.lights.iter().map(|l| l.power[k]).sum();
            assert!(
                ((after[k] + lit) / before[k] - 1.0).abs() < 1e-5,
                "channel {k}: {} + {lit} vs {}",
                after[k],
                before[k]
            );
        }
        // the seam's patch: centred on phi = 0, theta near rows 10..13's middle
        // (the power-weighted mean leans towards the equator's larger texels)
        let seam = &s.lights[0];
        let theta = 11.5 / h as f64 * PI;
        assert!((seam.dir[1] - theta.cos()).abs() < 5e-3, "{seam:?}");
        assert!(seam.dir[2].abs() < 1e-3 && seam.dir[0] > 0.0, "{seam:?}");
        assert!(s.share > 0.5 && s.share < 1.0, "{}", s.share);
        let sphere: f64 = (0..h).map(|j| texel_solid_angle(w, h, j)).sum::<f64>() * w as f64;
        assert!((sphere / (4.0 * PI) - 1.0).abs() < 1e-12);
    }

    /// A strip of nine equal texels along the equator is one light long in
    /// azimuth and without extent in polar angle: its first axis is
    /// horizontal, `sqrt(2 mean(sin^2 delta))` long for the texels' azimuth
    /// offsets `delta` from its centre (their tangent-plane offsets), its
    /// second nearly zero (the row's curvature: second order in `delta`).
    #[test]
    fn a_strips_axes_follow_its_length() {
        let (w, h) = (256, 128);
        let mut t = vec![0.0f32; w * h * 4];
        for p in 0..w * h {
            t[4 * p..4 * p + 3].copy_from_slice(&[0.01; 3]);
        }
        // rows 63 and 64 straddle the equator: take row 64's centre
        for i in 100..109 {
            let p = 64 * w + i;
            t[4 * p..4 * p + 3].copy_from_slice(&[100.0; 3]);
        }
        // one light (more would cut the strip into pieces)
        let one = SplitOptions {
            max_lights: 1,
            ..SplitOptions::default()
        };
        let s = split(w, h, &t, one);
        assert_eq!(s.lights.len(), 1);
        let [a1, a2] = s.lights[0].axes;
        let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let dphi = TAU / w as f64;
        let theta = 64.5 / h as f64 * PI;
        // the tangent-plane offset of a texel delta away in azimuth at polar
        // angle theta, from the light's direction (on the same row)
        let ms: f64 = (-4..=4)
            .map(|k| (theta.sin() * (k as f64 * dphi).sin()).powi(2))
            .sum::<f64>()
            / 9.0;
        let want = (2.0 * ms).sqrt();
        assert!((len(a1) / want - 1.0).abs() < 0.01, "{} vs {want}", len(a1));
        assert!(a1[1].abs() < 1e-9 * len(a1), "horizontal: {a1:?}");
        assert!(len(a2) < 0.01 * len(a1), "little polar extent: {a2:?}");
    }
}
