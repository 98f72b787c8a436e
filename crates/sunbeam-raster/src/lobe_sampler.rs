//! Importance sampling of the diffraction lobes by hierarchical sample warping
//! (docs/LIGHTING.md "The reference's estimator").
//!
//! The integrand of the environment integral in spatial frequency is
//! `L G R A / lambda^2 dw = L R (G / cos(theta_i)) A d^2f`: the pack's `R`
//! (`R_U` with the window's grazing term, PHYSICS.md 2b), whose
//! orders change strength with the phase depth `t = 2 pi H w / lambda`
//! (`w = -(cos(theta_i) + cos(theta_r))` changes with the direction), times a
//! factor that grows without bound towards the horizon (`1 / cos(theta_i)`) and
//! with Fresnel at grazing forward scattering (`F / F(0)` up to 25). A
//! proposal that follows `R` at fixed depths only leaves both to the weights,
//! which then have heavy tails.
//!
//! So the proposal is a quadtree over the pack's bins (a pyramid of sums of
//! `|sum_n c_n(t_j) T_n|^2` per depth table `t_j`, with each node's first
//! moments). For a view and wavelength a [`LobeQuery`] holds the weights of a
//! flat top level (nodes about `TOP_NODE_COS` wide in direction cosines, so
//! that one point per node represents it well enough); the descent starts
//! there and at each node chooses one of its four children with probability
//! proportional to
//!
//! - the child's stored energy interpolated linearly in `|t|` between the depth
//!   tables at the actual `t` of the direction of its energy centroid (for this
//!   view and wavelength), times
//! - `F(theta_d) (1 + wi.wr)^2 / (cos(theta_i) + cos(theta_r))^2` at the
//!   centroid (`F` the skin's, by `gain::fresnel` at `gain::cos_half`),
//!   times the mean of `1 / cos(theta_i)` over the child's radial
//!   extent (near the horizon `(asin rho_1 - asin rho_0) / (2 ext)`, the part
//!   beyond the horizon counting 0), i.e. `G / cos(theta_i)` up to the view's
//!   constant (and without the masking, a shape), times
//! - zero when the child lies wholly outside the disc of propagating
//!   directions (`|wi_xy| < 1`), so no sample is spent on evanescent frequencies.
//!
//! At the leaf (one bin) the point is uniform in the bin, or near the horizon
//! half the time drawn towards it (`horizon_mode`) (window model), or the
//! tiled model's Gaussian around the bin. The density of any frequency is the
//! product of the choices along its leaf's path times the leaf's density,
//! computed by the same code as the draw, so the estimator's multiple importance
//! sampling stays exact. A draw consumes one uniform for the whole descent
//! (rescaled at each choice), so stratifying that uniform over a pixel's
//! samples stratifies the leaves. Measured choices and the variants not kept:
//! docs/LIGHTING.md "Noise".

use std::f64::consts::PI;
use std::sync::Arc;
use sunbeam_optics::gain;
use sunbeam_optics::masking::Masking;
use sunbeam_pack::{manifest::Model, series, Pack};

/// Bins summed on each side for the tiled model's density, in sigmas.
const TILED_REACH: f64 = 5.0;
/// Leaves per bin along each axis for the window model (R at the leaves'
/// centres by `Pack::shading_reflectance` when above 1). R varies inside a bin (one
/// sample's relative spread 0.3 with one leaf per bin), but 2 leaves per bin
/// measured no better on frames at 4 times the preparation, so 1.
const SUB_BINS: usize = 1;
/// Most depth tables (more follow the orders' strengths more closely in `t`).
const MAX_DEPTHS: usize = 16;
/// Memory budget of the pyramids, in f32 values.
const BUDGET_VALUES: usize = 24_000_000;
/// Leaves within this many leaf widths of the horizon sample towards it.
const HORIZON_LEAVES: f64 = 6.0;
/// Width of the descent's top-level nodes in direction cosines (at most).
const TOP_NODE_COS: f64 = 1.0;

/// One view and wavelength, prepared for drawing and for densities: the
/// constants of the weights and the flat top level of the descent (the
/// weights of every node there that can reach propagating directions, in a
/// cumulative table). Prepare once, use for any number of draws and densities.
pub struct LobeQuery {
    wr: [f64; 3],
    /// The skin's refractive index (the proposal's Fresnel factor).
    ior: f64,
    /// `lambda / bin_scale`: direction cosines per bin, per axis.
    du: [f64; 2],
    /// `2 pi H / lambda`.
    k_h: f64,
    /// The top level and its nodes with weight, `(x, y)`, and their cumulative weights.
    top: usize,
    nodes: Vec<(u32, u32)>,
    cdf: Vec<f64>,
}

impl LobeQuery {
    fn total(&self) -> f64 {
        self.cdf.last().copied().unwrap_or(0.0)
    }
}

/// Draws incoming directions near the diffraction lobes of a pack for a view
/// and wavelength (module doc); [`LobeSampler::pdf`] is the exact density of
/// [`LobeSampler::sample`].
pub struct LobeSampler {
    pack: Arc<Pack>,
    /// `pyramids[level][depth * n_level^2 + node]`: energy sums, level 0 the
    /// root, the last level the bins (`side x side`, zero outside the crop).
    pyramids: Vec<Vec<f32>>,
    /// `|t|` of the depth tables: `t_max j / (depths - 1)`.
    depths: usize,
    side: usize,
    /// Leaves per bin along each axis ([`SUB_BINS`] for the window model, 1
    /// for the tiled model, whose leaves are its bins).
    sub: usize,
    /// Leaf coordinates: leaf `(ix, iy)` is centred at `kappa sub = (ix, iy) - origin`.
    origin: [f64; 2],
    /// Coherent area (m^2).
    pub area_m2: f64,
}

impl LobeSampler {
    pub fn new(pack: Arc<Pack>) -> LobeSampler {
        use rayon::prelude::*;
        let m = &pack.manifest;
        let sub = match m.model {
            Model::Window => SUB_BINS,
            Model::Tiled => 1,
        };
        let (w, h) = (m.crop.width * sub, m.crop.height * sub);
        let side = w.max(h).max(1).next_power_of_two();
        let levels = side.trailing_zeros() as usize + 1;
        let t_max = if m.t_max.is_finite() && m.t_max > 0.0 {
            m.t_max
        } else {
            0.0
        };
        let depths = if t_max > 0.0 {
            (BUDGET_VALUES / (3 * side * side * 4 / 3).max(1)).clamp(2, MAX_DEPTHS)
        } else {
            1
        };
        let layer = m.layer_texels();
        // The leaves' energy per depth table: the window model's R at the leaf
        // centres (the pack's own interpolation between bins), the tiled
        // model's bin powers.
        let leaves: Vec<Vec<f32>> = (0..depths)
            .into_par_iter()
            .map(|j| {
                let t = if depths > 1 {
                    -t_max * j as f64 / (depths - 1) as f64
                } else {
                    0.0
                };
                let mut e = vec![0.0f32; side * side];
                if sub > 1 {
                    // Pack::reflectance at phase depth t: any wavelength will do.
                    let l = m.lambda_min_m;
                    let wz = if m.height_half_range_m > 0.0 {
                        t * l / (2.0 * PI * m.height_half_range_m)
                    } else {
                        -1.0
                    };
                    for iy in 0..h {
                        for ix in 0..w {
                            let kx = (ix as f64 + 0.5) / sub as f64 - 0.5 - m.crop.kx as f64;
                            let ky = (iy as f64 + 0.5) / sub as f64 - 0.5 - m.crop.ky as f64;
                            let u = -kx * l / m.bin_scale_m[0];
                            let v = -ky * l / m.bin_scale_m[1];
                            e[iy * side + ix] = pack.shading_reflectance(u, v, wz, l) as f32;
                        }
                    }
                } else {
                    let c = series::coefficients_f64(m.basis, t, m.terms);
                    for iy in 0..h {
                        for ix in 0..w {
                            let b = iy * w + ix;
                            let mut a = [0.0f64; 2];
                            for (n, cn) in c.iter().enumerate() {
                                let i = 2 * (n * layer + b);
                                let (re, im) = (pack.terms[i] as f64, pack.terms[i + 1] as f64);
                                a[0] += cn[0] * re - cn[1] * im;
                                a[1] += cn[0] * im + cn[1] * re;
                            }
                            e[iy * side + ix] = (a[0] * a[0] + a[1] * a[1]) as f32;
                        }
                    }
                }
                e
            })
            .collect();
        // Per node and depth: the energy and its first moments about the
        // node's centre (bins), so a node's weight is taken at its centroid.
        let mut pyramids = vec![Vec::new(); levels];
        pyramids[levels - 1] = leaves
            .iter()
            .flat_map(|e| e.iter().flat_map(|&v| [v, 0.0, 0.0]))
            .collect();
        for l in (0..levels - 1).rev() {
            let (n, nf) = (1usize << l, 1usize << (l + 1));
            // Children's centres lie a quarter of the parent's width from its centre.
            let off = 0.25 * (side / n) as f64;
            let fine = &pyramids[l + 1];
            let mut coarse = vec![0.0f32; 3 * depths * n * n];
            for d in 0..depths {
                for y in 0..n {
                    for x in 0..n {
                        let mut acc = [0.0f64; 3];
                        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                            let i = 3 * (d * nf * nf + (2 * y + dy) * nf + 2 * x + dx);
                            let e = fine[i] as f64;
                            let (sx, sy) = (dx as f64 * 2.0 - 1.0, dy as f64 * 2.0 - 1.0);
                            acc[0] += e;
                            acc[1] += fine[i + 1] as f64 + e * sx * off;
                            acc[2] += fine[i + 2] as f64 + e * sy * off;
                        }
                        let o = 3 * (d * n * n + y * n + x);
                        coarse[o..o + 3].copy_from_slice(&acc.map(|v| v as f32));
                    }
                }
            }
            pyramids[l] = coarse;
        }
        let area_m2 = m.coherent_area_m2();
        let origin = [
            sub as f64 * (m.crop.kx as f64 + 0.5) - 0.5,
            sub as f64 * (m.crop.ky as f64 + 0.5) - 0.5,
        ];
        LobeSampler {
            pack,
            pyramids,
            depths,
            side,
            sub,
            origin,
            area_m2,
        }
    }

    /// Prepare view `wr` (local, unit) at `lambda_m` for a mesh with skin
    /// `skin` ([`LobeQuery`]). The top
    /// level's nodes are about `TOP_NODE_COS` wide in direction cosines, so
    /// that the weights, taken at one point per node, are accurate where the
    /// descent starts (a few hundred nodes over the disc of directions).
    pub fn query(&self, wr: [f64; 3], lambda_m: f64, skin: gain::Material) -> LobeQuery {
        let m = &self.pack.manifest;
        // Direction cosines per leaf.
        let sub = self.sub as f64;
        let du = [
            lambda_m / (m.bin_scale_m[0] * sub),
            lambda_m / (m.bin_scale_m[1] * sub),
        ];
        let levels = self.pyramids.len();
        let bins = (TOP_NODE_COS / du[0].max(du[1])).max(1.0);
        // Node width 2^(levels - 1 - top) <= bins.
        let shift = (bins.log2().floor() as usize).min(levels - 1);
        let top = levels - 1 - shift;
        let mut q = LobeQuery {
            wr,
            ior: skin.ior,
            du,
            k_h: 2.0 * PI * m.height_half_range_m / lambda_m,
            top,
            nodes: Vec::new(),
            cdf: Vec::new(),
        };
        if !positive(wr[2]) {
            return q;
        }
        let [(x0, x1), (y0, y1)] = self.top_range(&q);
        let mut acc = 0.0;
        for y in y0..=y1 {
            for x in x0..=x1 {
                let w = self.weight(&q, top, x as usize, y as usize);
                if w > 0.0 {
                    acc += w;
                    q.nodes.push((x as u32, y as u32));
                    q.cdf.push(acc);
                }
            }
        }
        q
    }

    /// The top level's nodes (inclusive ranges of x and y) that meet the crop
    /// and the bounding box of the disc of propagating directions
    /// (`wi_xy = kappa du - wr_xy`, `|wi_xy| < 1`).
    fn top_range(&self, q: &LobeQuery) -> [(i64, i64); 2] {
        let m = &self.pack.manifest;
        let shift = self.pyramids.len() - 1 - q.top;
        let n = 1i64 << q.top;
        let range = |axis: usize, len: usize| {
            let o = self.origin[axis];
            let lo = ((-1.0 + q.wr[axis]) / q.du[axis] + o).floor() as i64 - 1;
            let hi = ((1.0 + q.wr[axis]) / q.du[axis] + o).ceil() as i64 + 1;
            let (lo, hi) = (lo.max(0), hi.min(len as i64 - 1));
            ((lo >> shift).clamp(0, n - 1), (hi >> shift).clamp(0, n - 1))
        };
        [
            range(0, m.crop.width * self.sub),
            range(1, m.crop.height * self.sub),
        ]
    }

    /// The proposal's weight of node `(x, y)` of `level` (module doc).
    fn weight(&self, q: &LobeQuery, level: usize, x: usize, y: usize) -> f64 {
        let m = &self.pack.manifest;
        let n = 1usize << level;
        let size = (self.side / n) as f64;
        // The node's centre and half width in direction cosines of wi.
        let kc = [
            x as f64 * size + 0.5 * size - 0.5 - self.origin[0],
            y as f64 * size + 0.5 * size - 0.5 - self.origin[1],
        ];
        // f = (wi + wr)_xy / lambda, kappa = f bin_scale: wi_xy = kappa du - wr_xy.
        let c = [kc[0] * q.du[0] - q.wr[0], kc[1] * q.du[1] - q.wr[1]];
        let half = [0.5 * size * q.du[0], 0.5 * size * q.du[1]];
        // Wholly outside the unit disc: evanescent everywhere.
        let gap = [
            (c[0].abs() - half[0]).max(0.0),
            (c[1].abs() - half[1]).max(0.0),
        ];
        if gap[0] * gap[0] + gap[1] * gap[1] >= 1.0 {
            return 0.0;
        }
        // The energy and its centroid at the centre's phase depth, then the
        // energy at the centroid's depth, and the factor at the centroid.
        let v = &self.pyramids[level];
        let node = y * n + x;
        let at = |d: usize, k: usize| v[3 * (d * n * n + node) + k] as f64;
        let interp = |wi_z: f64, k: usize| {
            if self.depths == 1 {
                return at(0, k);
            }
            let s = ((wi_z + q.wr[2]) * q.k_h / m.t_max * (self.depths - 1) as f64)
                .clamp(0.0, (self.depths - 1) as f64);
            let j = (s.floor() as usize).min(self.depths - 2);
            let a = s - j as f64;
            at(j, k) + a * (at(j + 1, k) - at(j, k))
        };
        // Leaves have no moments; a node's centroid from the table nearest to
        // its centre's depth (cheap; the energy is then interpolated).
        let wi = if level + 1 < self.pyramids.len() {
            let s = ((direction_of(c)[2] + q.wr[2]) * q.k_h / m.t_max * (self.depths - 1) as f64)
                .clamp(0.0, (self.depths - 1) as f64);
            let j = s.round() as usize;
            let e0 = at(j, 0);
            if e0 > 0.0 {
                direction_of([
                    c[0] + at(j, 1) / e0 * q.du[0],
                    c[1] + at(j, 2) / e0 * q.du[1],
                ])
            } else {
                direction_of(c)
            }
        } else {
            direction_of(c)
        };
        let e = interp(wi[2], 0);
        if e <= 0.0 {
            return 0.0;
        }
        // 1 / cos(theta_i) averaged over the node's radial extent, the part
        // beyond the horizon (evanescent) counting 0: with rho the distance from
        // the disc's centre, the mean of 1 / sqrt(1 - rho^2) over
        // [r - ext, r + ext] is (asin(rho_1) - asin(rho_0)) / (2 ext), finite
        // for a node at the horizon, where the integrand's 1 / cos is integrable.
        let r = (c[0] * c[0] + c[1] * c[1]).sqrt();
        let nr = if r > 0.0 {
            [c[0] / r, c[1] / r]
        } else {
            [1.0, 0.0]
        };
        let ext = (half[0] * nr[0].abs() + half[1] * nr[1].abs()).max(1e-9);
        let mean_inv_cos = if r + ext < 0.8 {
            // Far from the horizon 1 / cos varies slowly: its value at the centre.
            1.0 / (1.0 - r * r).sqrt()
        } else {
            let (r0, r1) = ((r - ext).clamp(0.0, 1.0), (r + ext).min(1.0));
            (r1.asin() - r0.asin()) / (2.0 * ext)
        };
        e * mean_inv_cos * gain_over_cos(wi, q.wr, q.ior, 1.0)
    }

    /// Probability of bin `(ix, iy)` (crop texel indices; 0 outside): the
    /// product of the descent's choices along its path.
    fn bin_prob(&self, q: &LobeQuery, ix: i64, iy: i64) -> f64 {
        let m = &self.pack.manifest;
        let (w, h) = (m.crop.width * self.sub, m.crop.height * self.sub);
        if ix < 0 || iy < 0 || ix >= w as i64 || iy >= h as i64 {
            return 0.0;
        }
        let (ix, iy) = (ix as usize, iy as usize);
        let levels = self.pyramids.len();
        let total = q.total();
        if !positive(total) {
            return 0.0;
        }
        let shift = levels - 1 - q.top;
        let (tx, ty) = (ix >> shift, iy >> shift);
        let [(x0, x1), (y0, y1)] = self.top_range(q);
        if !((x0..=x1).contains(&(tx as i64)) && (y0..=y1).contains(&(ty as i64))) {
            return 0.0;
        }
        let mut p = self.weight(q, q.top, tx, ty) / total;
        if !positive(p) {
            return 0.0;
        }
        for l in q.top + 1..levels {
            let shift = levels - 1 - l;
            let (x, y) = (ix >> shift, iy >> shift);
            let (px, py) = (x & !1, y & !1);
            let ws = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .map(|(dx, dy)| self.weight(q, l, px + dx, py + dy));
            let total: f64 = ws.iter().sum();
            let own = ws[(y - py) * 2 + (x - px)];
            if !positive(total) || own <= 0.0 {
                return 0.0;
            }
            p *= own / total;
        }
        p
    }

    /// Density per unit bin area at bin coordinates `kappa`. Window model: the
    /// bin's probability spread uniformly over it. Tiled model: each bin's
    /// probability spread as the model's Gaussian of `sigma_bins` around it
    /// (the tiled response is exactly such a sum), summed over the bins within
    /// [`TILED_REACH`] sigma.
    fn pdf_kappa(&self, q: &LobeQuery, kx: f64, ky: f64) -> f64 {
        let m = &self.pack.manifest;
        match self.tiled_sigma() {
            None => {
                let [ox, oy] = self.origin;
                let (ix, iy) = ((kx + ox).round(), (ky + oy).round());
                let p = self.bin_prob(q, ix as i64, iy as i64);
                if p > 0.0 {
                    let c = [ix - ox, iy - oy];
                    p * leaf_density(q, c, [kx - c[0] + 0.5, ky - c[1] + 0.5])
                } else {
                    0.0
                }
            }
            Some([sx, sy]) => {
                let (rx, ry) = (
                    (TILED_REACH * sx).ceil() as i64,
                    (TILED_REACH * sy).ceil() as i64,
                );
                let (cx, cy) = (kx.round() as i64, ky.round() as i64);
                let gauss =
                    |d: f64, s: f64| (-0.5 * d * d / (s * s)).exp() / (s * (2.0 * PI).sqrt());
                let mut p = 0.0;
                for by in cy - ry..=cy + ry {
                    let gy = gauss(ky - by as f64, sy);
                    for bx in cx - rx..=cx + rx {
                        let q = self.bin_prob(q, bx + m.crop.kx, by + m.crop.ky);
                        if q > 0.0 {
                            p += q * gy * gauss(kx - bx as f64, sx);
                        }
                    }
                }
                p
            }
        }
    }

    /// The tiled model's Gaussian width in bins (None for the window model).
    fn tiled_sigma(&self) -> Option<[f64; 2]> {
        let m = &self.pack.manifest;
        (m.model == Model::Tiled).then(|| m.kernel.sigma_bins.map(|s| s.clamp(1e-3, 8.0)))
    }

    /// Solid-angle density (1/sr) of drawing local `wi` for view `wr` at
    /// `lambda_m` and skin `skin`.
    pub fn pdf(&self, wi: [f64; 3], wr: [f64; 3], lambda_m: f64, skin: gain::Material) -> f64 {
        self.pdf_in(&self.query(wr, lambda_m, skin), wi)
    }

    /// [`LobeSampler::pdf`] for a prepared view and wavelength.
    pub fn pdf_in(&self, q: &LobeQuery, wi: [f64; 3]) -> f64 {
        if wi[2] <= 0.0 || q.wr[2] <= 0.0 {
            return 0.0;
        }
        // kappa = (wi + wr)_xy / du.
        let (kx, ky) = ((wi[0] + q.wr[0]) / q.du[0], (wi[1] + q.wr[1]) / q.du[1]);
        // d(kappa_x, kappa_y) = d(u, v) / (du_x du_y), d(u, v) = cos(theta_i) dw.
        self.pdf_kappa(q, kx, ky) / (q.du[0] * q.du[1]) * wi[2]
    }

    /// A local incoming direction for view `wr` at `lambda_m` and skin
    /// `skin` (its density is [`LobeSampler::pdf`]); None when the drawn
    /// frequency is evanescent. `u[0]` drives the descent, `u[1]` and `u[2]`
    /// the point in the bin.
    pub fn sample(
        &self,
        u: [f64; 3],
        wr: [f64; 3],
        lambda_m: f64,
        skin: gain::Material,
    ) -> Option<[f64; 3]> {
        self.sample_in(&self.query(wr, lambda_m, skin), u)
            .map(|(wi, _)| wi)
    }

    /// [`LobeSampler::sample`] for a prepared view and wavelength, with the
    /// direction's density ([`LobeSampler::pdf_in`]; for the window model the
    /// product of the descent's choices, no second descent).
    pub fn sample_in(&self, q: &LobeQuery, u: [f64; 3]) -> Option<([f64; 3], f64)> {
        let total = q.total();
        if !positive(total) {
            return None;
        }
        let levels = self.pyramids.len();
        // The top node: the first whose cumulative weight exceeds u total.
        let target = u[0] * total;
        let i = q.cdf.partition_point(|&c| c <= target).min(q.cdf.len() - 1);
        let below = if i > 0 { q.cdf[i - 1] } else { 0.0 };
        let mut r = ((target - below) / (q.cdf[i] - below)).clamp(0.0, 1.0 - f64::EPSILON);
        let mut p = (q.cdf[i] - below) / total;
        let (mut x, mut y) = (q.nodes[i].0 as usize, q.nodes[i].1 as usize);
        for l in q.top + 1..levels {
            let (px, py) = (2 * x, 2 * y);
            let kids = [(0, 0), (1, 0), (0, 1), (1, 1)];
            let ws = kids.map(|(dx, dy)| self.weight(q, l, px + dx, py + dy));
            let total: f64 = ws.iter().sum();
            if !positive(total) {
                return None;
            }
            let mut target = r * total;
            let mut pick = 3;
            for (i, &w) in ws.iter().enumerate() {
                if w > 0.0 && (target < w || i == 3) {
                    pick = i;
                    break;
                }
                target -= w;
            }
            // The last child with weight, when rounding ran past the end.
            while ws[pick] <= 0.0 {
                pick -= 1;
            }
            r = (target / ws[pick]).clamp(0.0, 1.0 - f64::EPSILON);
            p *= ws[pick] / total;
            x = px + kids[pick].0;
            y = py + kids[pick].1;
        }
        let kc = [x as f64 - self.origin[0], y as f64 - self.origin[1]];
        let (ox, oy) = match self.tiled_sigma() {
            None => {
                let s = leaf_point(q, kc, [u[1], u[2]]);
                p *= leaf_density(q, kc, s);
                (s[0] - 0.5, s[1] - 0.5)
            }
            Some([sx, sy]) => {
                // Box-Muller: a Gaussian offset of the model's width.
                let r = (-2.0 * (1.0 - u[1]).ln()).sqrt();
                let (s, c) = (2.0 * PI * u[2]).sin_cos();
                (r * c * sx, r * s * sy)
            }
        };
        let (kx, ky) = (kc[0] + ox, kc[1] + oy);
        let (wx, wy) = (kx * q.du[0] - q.wr[0], ky * q.du[1] - q.wr[1]);
        let r2 = wx * wx + wy * wy;
        if r2 >= 1.0 {
            return None;
        }
        let wi = [wx, wy, (1.0 - r2).sqrt()];
        let pdf = match self.tiled_sigma() {
            None => p / (q.du[0] * q.du[1]) * wi[2],
            Some(_) => self.pdf_in(q, wi),
        };
        Some((wi, pdf))
    }

    /// `f_r cos(theta_i) = G G2 R_U A / lambda^2` (1/sr) for local directions
    /// on a mesh with skin `skin` and `masking` (`G G2 = masking.gain(wi, wr,
    /// skin)`, [`LobeSampler::response`]).
    pub fn brdf_cos(
        &self,
        wi: [f64; 3],
        wr: [f64; 3],
        lambda_m: f64,
        masking: Masking,
        skin: gain::Material,
    ) -> f64 {
        if !(wi[2] > 0.0 && wr[2] > 0.0) {
            return 0.0;
        }
        masking.gain(wi, wr, skin) * self.response(wi, wr, lambda_m)
    }

    /// `R A / lambda^2` (1/sr) for local directions, `R` the reflectance
    /// shading uses (`Pack::shading_reflectance`: `R_U` for the window model):
    /// [`LobeSampler::brdf_cos`] without the gain, which does not depend on
    /// the wavelength.
    pub fn response(&self, wi: [f64; 3], wr: [f64; 3], lambda_m: f64) -> f64 {
        let r =
            self.pack
                .shading_reflectance(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2], lambda_m);
        r * self.area_m2 / (lambda_m * lambda_m)
    }
}

/// How a leaf near the horizon is sampled: along `axis`, towards the horizon
/// when `toward_plus` (else towards minus), the horizon crossing `d` leaf widths
/// from the leaf's near edge on the line through its centre. None: uniform.
///
/// Uniform in frequency (`kappa`) means a solid-angle density proportional to
/// `cos(theta_i)`, zero at the horizon, where the integrand `G R A / lambda^2`
/// is not: weights without bound (a variance that diverges logarithmically).
/// Half of a near-horizon leaf's draws therefore follow `1 / sqrt(d - s)` along
/// the axis closest to the radial direction (`s` the position in the leaf),
/// the shape of `1 / cos(theta_i)` there, which keeps the density in solid
/// angle bounded below.
fn horizon_mode(q: &LobeQuery, kc: [f64; 2]) -> Option<(usize, bool, f64)> {
    let c = [kc[0] * q.du[0] - q.wr[0], kc[1] * q.du[1] - q.wr[1]];
    let axis = if c[0].abs() >= c[1].abs() { 0 } else { 1 };
    let plus = c[axis] >= 0.0;
    let other = c[1 - axis];
    if other.abs() >= 1.0 {
        return None;
    }
    // |c_axis + t| = sqrt(1 - other^2) in direction cosines, t >= 0 outwards.
    let edge = (1.0 - other * other).sqrt();
    let t = (edge - c[axis].abs()) / q.du[axis];
    let d = t + 0.5;
    (d > 0.0 && d < HORIZON_LEAVES).then_some((axis, plus, d))
}

/// Density (per unit leaf area) of the point `s` (in `[0, 1]^2`, leaf units,
/// increasing with kappa) in the leaf centred at bin `kc` (`horizon_mode`).
fn leaf_density(q: &LobeQuery, kc: [f64; 2], s: [f64; 2]) -> f64 {
    match horizon_mode(q, kc) {
        None => 1.0,
        Some((axis, plus, d)) => {
            let x = if plus { s[axis] } else { 1.0 - s[axis] };
            let e = d.min(1.0);
            let z = 2.0 * (d.sqrt() - (d - e).sqrt());
            let ph = if x < e {
                1.0 / (z * (d - x).sqrt())
            } else {
                0.0
            };
            0.5 + 0.5 * ph
        }
    }
}

/// A point in the leaf centred at bin `kc` from two uniforms, with density
/// [`leaf_density`].
fn leaf_point(q: &LobeQuery, kc: [f64; 2], u: [f64; 2]) -> [f64; 2] {
    match horizon_mode(q, kc) {
        None => u,
        Some((axis, plus, d)) => {
            if u[0] < 0.5 {
                return [2.0 * u[0], u[1]];
            }
            let v = 2.0 * u[0] - 1.0;
            let e = d.min(1.0);
            let z = 2.0 * (d.sqrt() - (d - e).sqrt());
            // CDF 2 (sqrt(d) - sqrt(d - x)) / z = v.
            let r = d.sqrt() - 0.5 * v * z;
            let x = (d - r * r).clamp(0.0, e);
            let a = if plus { x } else { 1.0 - x };
            let mut p = [0.0; 2];
            p[axis] = a;
            p[1 - axis] = u[1];
            p
        }
    }
}

/// `x > 0`, false for NaN (a weight or density that can be drawn from).
fn positive(x: f64) -> bool {
    x > 0.0
}

/// The direction whose tangential part is `c` (on the horizon when `|c| >= 1`).
fn direction_of(c: [f64; 2]) -> [f64; 3] {
    let r2 = c[0] * c[0] + c[1] * c[1];
    if r2 < 1.0 {
        [c[0], c[1], (1.0 - r2).sqrt()]
    } else {
        let r = r2.sqrt();
        [c[0] / r, c[1] / r, 0.0]
    }
}

/// `G(wi, wr) cos(theta_r) / max(cos(theta_i), min_cos)` for a skin of index
/// `ior`: the factor of the integrand in frequency space that does not
/// depend on the pack, up to the view's constant `1 / cos(theta_r)`, the
/// normalisation (absolute here) and the masking (a shape for the proposal:
/// the factors it drops are constant or smooth); `G` itself from `gain::g`
/// (its Fresnel factor at `gain::cos_half`, its obliquity), with `wi` lifted
/// to `cos(theta_i) >= 1e-6` so that the shape is finite and positive at the
/// horizon, where `g` is 0.
fn gain_over_cos(wi: [f64; 3], wr: [f64; 3], ior: f64, min_cos: f64) -> f64 {
    const LIFT: f64 = 1e-6;
    let wi_g = if wi[2] >= LIFT {
        wi
    } else {
        let s = ((1.0 - LIFT * LIFT) / (wi[0] * wi[0] + wi[1] * wi[1]).max(1e-300)).sqrt();
        [wi[0] * s, wi[1] * s, LIFT]
    };
    let skin = gain::Material {
        ior,
        reflectance: gain::Reflectance::Absolute,
        ..Default::default()
    };
    gain::g(wi_g, wr, skin) * wr[2] / wi[2].max(min_cos)
}
