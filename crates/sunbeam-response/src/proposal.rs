//! Hierarchical sample warping over the response map's polar grid: the
//! proposal with which the player (WGSL) and its CPU twin draw `(u, v)` for
//! extended light. Identical in both (docs/PACK_FORMAT.md "Extended-light
//! maps", the contract in the env module's docs).
//!
//! Cells are the grid's **dual cells**: cell `(i, j)` spans angle texels
//! `i .. i+1` (mod `n_theta`) and radius texels `j .. j+1`, inside which the
//! trilinear lookup is bilinear in its four corner texels. Level 0 stores per
//! `s` layer the cell's area times the mean luminance of its corners (plus a
//! small floor so that no reachable cell has probability 0), padded to
//! power-of-two sides; each coarser level sums its children. A descent for a
//! view weighs each child by its stored value (interpolated in `s`) times the
//! view's gain factor `G / max(cos(theta_i), 0.05)` at the child's sub-points
//! (`sunbeam_optics::gain::g` with the mesh's skin, so its Fresnel factor is
//! the skin's; masking is left out of this shape), so the proposal follows
//! the integrand's energy, not just the map's.

use crate::grid::Grid;
use crate::Response;
use sunbeam_optics::gain;

/// The proposal pyramid for one grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Proposal {
    /// The response maps' grid (`n_theta`, `n_rho`, `n_s`, `r0`).
    pub grid: Grid,
    /// Padded level-0 sides: `next_pow2(n_theta)`, `next_pow2(n_rho - 1)`.
    pub pw: usize,
    pub ph: usize,
    /// Layers (one per `s` texel): `grid.n_s`.
    pub n_s: usize,
    /// `W_l`, `H_l` and the start of level `l` in `data`, for `l = 0..=L`
    /// (level `L` is 1 x 1).
    pub widths: Vec<usize>,
    pub heights: Vec<usize>,
    pub offsets: Vec<usize>,
    /// All levels: cell `(x, y)` of layer `k` at level `l` is
    /// `data[offsets[l] + (k * H_l + y) * W_l + x]`.
    pub data: Vec<f32>,
}

impl Proposal {
    /// No proposal (no levels): what a reader that draws no samples holds
    /// (the first-frame estimator: the environment maps file read without
    /// its proposal).
    pub fn none(grid: Grid) -> Proposal {
        Proposal {
            grid,
            pw: 0,
            ph: 0,
            n_s: grid.n_s,
            widths: Vec::new(),
            heights: Vec::new(),
            offsets: Vec::new(),
            data: Vec::new(),
        }
    }

    /// Build from the luminance `y` of the proposal map at every texel (the
    /// response-map layout, `(k * n_rho + j) * n_theta + i`).
    pub fn new(grid: Grid, y: &[f32]) -> Proposal {
        let (nt, nr, ns) = (grid.n_theta, grid.n_rho, grid.n_s);
        assert_eq!(y.len(), grid.texels(), "one luminance per texel");
        let (pw, ph) = (nt.next_power_of_two(), (nr - 1).next_power_of_two());
        let top = pw.trailing_zeros().max(ph.trailing_zeros()) as usize;
        let widths: Vec<usize> = (0..=top).map(|l| (pw >> l).max(1)).collect();
        let heights: Vec<usize> = (0..=top).map(|l| (ph >> l).max(1)).collect();
        let mut offsets = Vec::with_capacity(top + 1);
        let mut len = 0;
        for l in 0..=top {
            offsets.push(len);
            len += ns * widths[l] * heights[l];
        }
        let mut data = vec![0.0f32; len];
        // Level 0: area times the mean of the 4 corners, then the floor.
        let tex = |i: usize, j: usize, k: usize| y[(k * nr + j) * nt + i] as f64;
        for k in 0..ns {
            let mut cells = vec![0.0f64; nt * (nr - 1)];
            for j in 0..nr - 1 {
                let a = cell_area(&grid, j);
                for i in 0..nt {
                    let i1 = (i + 1) % nt;
                    let mean =
                        (tex(i, j, k) + tex(i1, j, k) + tex(i, j + 1, k) + tex(i1, j + 1, k)) / 4.0;
                    cells[j * nt + i] = a * mean.max(0.0);
                }
            }
            let total: f64 = cells.iter().sum();
            let floor = FLOOR * total / (nt * (nr - 1)) as f64;
            for j in 0..nr - 1 {
                for i in 0..nt {
                    data[(k * ph + j) * pw + i] = (cells[j * nt + i] + floor) as f32;
                }
            }
        }
        // Coarser levels: each cell the sum of its children.
        for l in 1..=top {
            let (w, h, cw, ch) = (widths[l], heights[l], widths[l - 1], heights[l - 1]);
            for k in 0..ns {
                for yy in 0..h {
                    for xx in 0..w {
                        let mut sum = 0.0f32;
                        for cy in children(yy, h, ch) {
                            for cx in children(xx, w, cw) {
                                sum += data[offsets[l - 1] + (k * ch + cy) * cw + cx];
                            }
                        }
                        data[offsets[l] + (k * h + yy) * w + xx] = sum;
                    }
                }
            }
        }
        Proposal {
            grid,
            pw,
            ph,
            n_s: ns,
            widths,
            heights,
            offsets,
            data,
        }
    }

    /// Build from the sum of the luminance (Y) of `maps` (all on `grid`).
    pub fn from_maps(grid: Grid, maps: Vec<&Response>) -> Proposal {
        let y: Vec<f32> = (0..grid.texels())
            .map(|t| {
                maps.iter()
                    .map(|m| half::f16::from_bits(m.data[4 * t + 1]).to_f32())
                    .sum()
            })
            .collect();
        Proposal::new(grid, &y)
    }

    /// Number of levels (`L + 1`).
    pub fn levels(&self) -> usize {
        self.offsets.len()
    }

    /// The weight of cell `(x, y)` at level `l` for view `wr` and the skin
    /// `skin`: 0 when the
    /// cell does not meet the view's disc ([`Proposal::reaches_disc`]) or holds
    /// no real cell; else the mean, over the [`SUB_POINTS`] of the cell that
    /// lie inside the disc, of the stored value interpolated in `s` at that
    /// point times `G / max(cos(theta_i), 0.05)` there ([`OUTSIDE`] when none
    /// does). Sub-points rather than the centre: at coarse levels `G / cos`,
    /// `s` and the disc's rim change across a cell, and the centre alone
    /// starved cells by factors of 30-400 (docs/PACK_FORMAT.md).
    pub fn weight(&self, wr: [f64; 3], skin: gain::Material, l: usize, x: usize, y: usize) -> f64 {
        let g = &self.grid;
        let Some([x0, x1, y0, y1]) = self.extent(l, x, y) else {
            return 0.0;
        };
        if !self.reaches_disc(wr, l, x, y) {
            return 0.0;
        }
        let (w, h) = (self.widths[l], self.heights[l]);
        let at = |k: usize| self.data[self.offsets[l] + (k * h + y) * w + x] as f64;
        let n1 = (g.n_rho - 1) as f64;
        // The mean over the sub-points inside the disc (the cell's energy is
        // where the light can come from); outside points only set a fallback.
        let (mut sum, mut n_in, mut fallback) = (0.0, 0usize, 0.0f64);
        for &(fx, fy) in &SUB_POINTS {
            let theta = std::f64::consts::TAU * (x0 + fx * (x1 - x0)) / g.n_theta as f64;
            let r = r_at(g, (y0 + fy * (y1 - y0)) / n1);
            let (wi, w_, inside) = incoming(wr, [r * theta.cos(), r * theta.sin()]);
            let s = (-w_ / (4.0 - r * r).max(1e-12).sqrt()).clamp(0.0, 1.0);
            let sc = s * (self.n_s - 1) as f64;
            let k0 = (sc.floor() as usize).min(self.n_s.saturating_sub(2));
            let t = sc - k0 as f64;
            let v = if self.n_s > 1 {
                (1.0 - t) * at(k0) + t * at(k0 + 1)
            } else {
                at(0)
            };
            let gain = gain::g(wi, wr, skin);
            if inside {
                sum += v * gain / wi[2].max(0.05);
                n_in += 1;
            } else {
                fallback = fallback.max(v * gain);
            }
        }
        if n_in > 0 {
            sum / n_in as f64
        } else {
            fallback * OUTSIDE
        }
    }

    /// The real (unpadded) extent of cell `(x, y)` of level `l` in level-0
    /// cell units, `[x0, x1, y0, y1]`; None when it holds no real cell.
    fn extent(&self, l: usize, x: usize, y: usize) -> Option<[f64; 4]> {
        let g = &self.grid;
        let (sx, sy) = (self.pw / self.widths[l], self.ph / self.heights[l]);
        let (x0, x1) = (x * sx, ((x + 1) * sx).min(g.n_theta));
        let (y0, y1) = (y * sy, ((y + 1) * sy).min(g.n_rho - 1));
        (x0 < x1 && y0 < y1).then_some([x0 as f64, x1 as f64, y0 as f64, y1 as f64])
    }

    /// True when cell `(x, y)` of level `l` meets the disc of `(u, v)` that
    /// view `wr` can receive light from, `|(u, v) + wr_xy| < 1`: elsewhere the
    /// integrand is 0, and weighing such cells by their centre would spend
    /// most samples there (head-on, the map's energy at `1 < r < 2` took
    /// about 80 % of them). Exact distance from the disc's centre to the
    /// cell's annular sector, so no cell that meets the disc gets weight 0.
    pub fn reaches_disc(&self, wr: [f64; 3], l: usize, x: usize, y: usize) -> bool {
        let g = &self.grid;
        let (sx, sy) = (self.pw / self.widths[l], self.ph / self.heights[l]);
        let (x0, x1) = (x * sx, ((x + 1) * sx).min(g.n_theta));
        let (y0, y1) = (y * sy, ((y + 1) * sy).min(g.n_rho - 1));
        if x0 >= x1 || y0 >= y1 {
            return false;
        }
        let n1 = (g.n_rho - 1) as f64;
        let (ra, rb) = (r_at(g, y0 as f64 / n1), r_at(g, y1 as f64 / n1));
        let tau = std::f64::consts::TAU;
        let (ta, tb) = (
            tau * x0 as f64 / g.n_theta as f64,
            tau * x1 as f64 / g.n_theta as f64,
        );
        // The disc's centre, in (u, v).
        let p = [-wr[0], -wr[1]];
        let rp = p[0].hypot(p[1]);
        let tp = p[1].atan2(p[0]).rem_euclid(tau);
        let d = if rp == 0.0 || (tp >= ta && tp <= tb) {
            (ra - rp).max(rp - rb).max(0.0)
        } else {
            let edge = |t: f64| {
                let e = [t.cos(), t.sin()];
                let s = (p[0] * e[0] + p[1] * e[1]).clamp(ra, rb);
                (p[0] - s * e[0]).hypot(p[1] - s * e[1])
            };
            edge(ta).min(edge(tb))
        };
        d < 1.0
    }

    /// The descent: from the top, at each level the children of the current
    /// cell (in the order y outer, x inner), one picked by `pick(level,
    /// children, weights)`; returns the level-0 cell and the product of the
    /// picked children's probabilities (0 when a pick weighs 0).
    fn descend(
        &self,
        wr: [f64; 3],
        skin: gain::Material,
        mut pick: impl FnMut(usize, &[(usize, usize)], &[f64]) -> Option<usize>,
    ) -> Option<(usize, usize, f64)> {
        let top = self.levels() - 1;
        let (mut x, mut y, mut prob) = (0usize, 0usize, 1.0f64);
        let mut cells = Vec::with_capacity(4);
        let mut wts = Vec::with_capacity(4);
        for l in (0..top).rev() {
            cells.clear();
            wts.clear();
            let (w, h) = (self.widths[l], self.heights[l]);
            for cy in children(y, self.heights[l + 1], h) {
                for cx in children(x, self.widths[l + 1], w) {
                    cells.push((cx, cy));
                    wts.push(self.weight(wr, skin, l, cx, cy));
                }
            }
            let sum: f64 = wts.iter().sum();
            if sum.is_nan() || sum <= 0.0 {
                return None;
            }
            let c = pick(l, &cells, &wts)?;
            if wts[c].is_nan() || wts[c] <= 0.0 {
                return None;
            }
            prob *= wts[c] / sum;
            (x, y) = cells[c];
        }
        Some((x, y, prob))
    }

    /// Draw `(u, v)` for local view `wr` (unit, z > 0) and skin `skin` from three uniforms in
    /// [0, 1): `u[0]` the descent (rescaled within the chosen interval at
    /// each level), `u[1]`, `u[2]` the position in the level-0 cell (uniform
    /// in angle and in `r^2`). Returns the point and its density per unit
    /// `(u, v)` area (equal to [`Proposal::pdf`] there); None when every cell
    /// weighs 0.
    pub fn sample(
        &self,
        wr: [f64; 3],
        skin: gain::Material,
        u: [f64; 3],
    ) -> Option<([f64; 2], f64)> {
        let mut u0 = u[0];
        let (i, j, prob) = self.descend(wr, skin, |_, _, wts| {
            let sum: f64 = wts.iter().sum();
            let target = u0 * sum;
            let mut acc = 0.0;
            let mut c = wts.len() - 1;
            for (n, &wt) in wts.iter().enumerate() {
                if target < acc + wt {
                    c = n;
                    break;
                }
                acc += wt;
            }
            // The last non-empty child if rounding ran past the end.
            while wts[c] <= 0.0 && c > 0 {
                c -= 1;
            }
            u0 = ((target - acc) / wts[c]).clamp(0.0, 1.0 - f64::EPSILON);
            Some(c)
        })?;
        let g = &self.grid;
        let theta = std::f64::consts::TAU * (i as f64 + u[1]) / g.n_theta as f64;
        let (r0, r1) = (g.r_at(j), g.r_at(j + 1));
        let r = (r0 * r0 + u[2] * (r1 * r1 - r0 * r0)).sqrt();
        Some(([r * theta.cos(), r * theta.sin()], prob / cell_area(g, j)))
    }

    /// Density per unit `(u, v)` area with which [`Proposal::sample`] draws
    /// `uv` for view `wr` and skin `skin` (repeats the descent along the point's cell).
    pub fn pdf(&self, wr: [f64; 3], skin: gain::Material, uv: [f64; 2]) -> f64 {
        let Some((i, j)) = self.cell_of(uv) else {
            return 0.0;
        };
        let found = self.descend(wr, skin, |l, cells, _| {
            let want = (
                i / (self.pw / self.widths[l]),
                j / (self.ph / self.heights[l]),
            );
            cells.iter().position(|&c| c == want)
        });
        match found {
            Some((_, _, prob)) => prob / cell_area(&self.grid, j),
            None => 0.0,
        }
    }

    /// The level-0 cell `(i, j)` holding `uv` (None beyond radius 2).
    pub fn cell_of(&self, uv: [f64; 2]) -> Option<(usize, usize)> {
        let g = &self.grid;
        let r = uv[0].hypot(uv[1]);
        if r.is_nan() || r >= 2.0 {
            return None;
        }
        let theta = uv[1].atan2(uv[0]).rem_euclid(std::f64::consts::TAU);
        let i = ((theta / std::f64::consts::TAU * g.n_theta as f64) as usize).min(g.n_theta - 1);
        let rho = (r / g.r0).asinh() / g.rho_scale();
        let mut j = ((rho * (g.n_rho - 1) as f64) as usize).min(g.n_rho - 2);
        // The cell's radii are r_at(j), r_at(j + 1): settle rounding at the edges.
        while j > 0 && r < g.r_at(j) {
            j -= 1;
        }
        while j + 2 < g.n_rho && r >= g.r_at(j + 1) {
            j += 1;
        }
        Some((i, j))
    }
}

/// Where a cell's weight is evaluated, as fractions of its extent: the mean
/// over these points of `stored(s) G / cos` follows the view's gain and the
/// disc's rim across a coarse cell far better than its centre alone.
const SUB_POINTS: [(f64, f64); 4] = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)];

/// A cell that meets the disc but none of whose [`SUB_POINTS`] lies in it
/// weighs `OUTSIDE` times the largest `stored(s) G` at them (no `1 / cos`):
/// positive, so the thin part inside the disc can still be drawn, but small,
/// so the rim does not take the samples.
pub const OUTSIDE: f64 = 0.05;

/// Share of every real level-0 cell added to its layer's mean, so that no
/// cell the lookup can reach has probability 0.
pub const FLOOR: f64 = 1e-4;

/// `(u, v)` area of the dual cells of radial row `j`:
/// `(2 pi / n_theta) (r_{j+1}^2 - r_j^2) / 2`.
pub fn cell_area(g: &Grid, j: usize) -> f64 {
    let (r0, r1) = (g.r_at(j), g.r_at(j + 1));
    std::f64::consts::TAU / g.n_theta as f64 * (r1 * r1 - r0 * r0) / 2.0
}

/// The radius at continuous `rho` (as [`Grid::r_at`] at texels).
fn r_at(g: &Grid, rho: f64) -> f64 {
    (g.r0 * (rho * g.rho_scale()).sinh()).min(2.0)
}

/// The incoming direction of `(u, v)` for view `wr` (its `xy` clamped to
/// length 0.999) and `w = -(wi_z + wr_z)`.
fn incoming(wr: [f64; 3], uv: [f64; 2]) -> ([f64; 3], f64, bool) {
    let (mut x, mut y) = (-uv[0] - wr[0], -uv[1] - wr[1]);
    let len = x.hypot(y);
    let inside = len < 1.0;
    if len > 0.999 {
        x *= 0.999 / len;
        y *= 0.999 / len;
    }
    let z = (1.0 - x * x - y * y).sqrt();
    ([x, y, z], -(z + wr[2]), inside)
}

/// The children at the finer level (side `fine`) of index `p` at the coarser
/// level (side `coarse`): `2p, 2p + 1` when the side halved, else `p`.
fn children(p: usize, coarse: usize, fine: usize) -> std::ops::Range<usize> {
    if fine > coarse {
        2 * p..2 * p + 2
    } else {
        p..p + 1
    }
}
