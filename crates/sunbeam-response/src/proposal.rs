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
        let _ = (grid, y);
        unimplemented!("Proposal::new: step 4")
    }

    /// Number of levels (`L + 1`).
    pub fn levels(&self) -> usize {
        self.offsets.len()
    }

    /// Draw `(u, v)` for local view `wr` (unit, z > 0) from three uniforms in
    /// [0, 1): `u[0]` the descent, `u[1]`, `u[2]` the position in the level-0
    /// cell. Returns the point and its density per unit `(u, v)` area (equal to
    /// [`Proposal::pdf`] there); None when every cell weighs 0.
    pub fn sample(&self, wr: [f64; 3], u: [f64; 3]) -> Option<([f64; 2], f64)> {
        let _ = (wr, u);
        unimplemented!("Proposal::sample: step 4")
    }

    /// Density per unit `(u, v)` area with which [`Proposal::sample`] draws
    /// `uv` for view `wr` (repeats the descent along the point's cell).
    pub fn pdf(&self, wr: [f64; 3], uv: [f64; 2]) -> f64 {
        let _ = (wr, uv);
        unimplemented!("Proposal::pdf: step 4")
    }
}
