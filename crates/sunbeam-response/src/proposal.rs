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
//! view's gain factor `G / max(cos(theta_i), 0.05)` at the child's centre, so
//! the proposal follows the integrand's energy, not just the map's.

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

    /// The weight of cell `(x, y)` at level `l` for view `wr`: the stored
    /// value interpolated in `s` times `G / max(cos(theta_i), 0.05)`, both at
    /// the cell's centre; 0 for a level-0 cell outside the grid.
    pub fn weight(&self, wr: [f64; 3], l: usize, x: usize, y: usize) -> f64 {
        let g = &self.grid;
        let (w, h) = (self.widths[l], self.heights[l]);
        let xf = (x as f64 + 0.5) * self.pw as f64 / w as f64;
        let yf = (y as f64 + 0.5) * self.ph as f64 / h as f64;
        if l == 0 && (xf >= g.n_theta as f64 || yf >= (g.n_rho - 1) as f64) {
            return 0.0;
        }
        let theta = std::f64::consts::TAU * xf / g.n_theta as f64;
        let r = r_at(g, yf / (g.n_rho - 1) as f64);
        let (wi, w_) = incoming(wr, [r * theta.cos(), r * theta.sin()]);
        let s = (-w_ / (4.0 - r * r).max(1e-12).sqrt()).clamp(0.0, 1.0);
        let sc = s * (self.n_s - 1) as f64;
        let k0 = (sc.floor() as usize).min(self.n_s.saturating_sub(2));
        let t = sc - k0 as f64;
        let at = |k: usize| self.data[self.offsets[l] + (k * h + y) * w + x] as f64;
        let v = if self.n_s > 1 {
            (1.0 - t) * at(k0) + t * at(k0 + 1)
        } else {
            at(0)
        };
        v * gain::g(wi, wr, gain::DEFAULT_IOR) / wi[2].max(0.05)
    }

    /// The descent: from the top, at each level the children of the current
    /// cell (in the order y outer, x inner), one picked by `pick(level,
    /// children, weights)`; returns the level-0 cell and the product of the
    /// picked children's probabilities (0 when a pick weighs 0).
    fn descend(
        &self,
        wr: [f64; 3],
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
                    wts.push(self.weight(wr, l, cx, cy));
                }
            }
            let sum: f64 = wts.iter().sum();
            if !(sum > 0.0) {
                return None;
            }
            let c = pick(l, &cells, &wts)?;
            if !(wts[c] > 0.0) {
                return None;
            }
            prob *= wts[c] / sum;
            (x, y) = cells[c];
        }
        Some((x, y, prob))
    }

    /// Draw `(u, v)` for local view `wr` (unit, z > 0) from three uniforms in
    /// [0, 1): `u[0]` the descent (rescaled within the chosen interval at
    /// each level), `u[1]`, `u[2]` the position in the level-0 cell (uniform
    /// in angle and in `r^2`). Returns the point and its density per unit
    /// `(u, v)` area (equal to [`Proposal::pdf`] there); None when every cell
    /// weighs 0.
    pub fn sample(&self, wr: [f64; 3], u: [f64; 3]) -> Option<([f64; 2], f64)> {
        let mut u0 = u[0];
        let (i, j, prob) = self.descend(wr, |_, _, wts| {
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
    /// `uv` for view `wr` (repeats the descent along the point's cell).
    pub fn pdf(&self, wr: [f64; 3], uv: [f64; 2]) -> f64 {
        let Some((i, j)) = self.cell_of(uv) else {
            return 0.0;
        };
        let found = self.descend(wr, |l, cells, _| {
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
        if !(r < 2.0) {
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
fn incoming(wr: [f64; 3], uv: [f64; 2]) -> ([f64; 3], f64) {
    let (mut x, mut y) = (-uv[0] - wr[0], -uv[1] - wr[1]);
    let len = x.hypot(y);
    if len > 0.999 {
        x *= 0.999 / len;
        y *= 0.999 / len;
    }
    let z = (1.0 - x * x - y * y).sqrt();
    ([x, y, z], -(z + wr[2]))
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
