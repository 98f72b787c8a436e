//! The first-frame estimator's cells: the extended-light maps' mass
//! clustered once per pack into a few cells in `(u, v)`, so that a shading
//! point sums a few dozen terms instead of drawing samples (docs/LIGHTING.md
//! "The first frame").
//!
//! Why this works: the maps `E_k(u, v, w)` do not depend on the view; a view
//! `wr` only shifts the disc of propagating directions (`wi_xy = -(u, v) -
//! wr_xy`) and picks the layer `s` of each point. So the integral
//!
//! `XYZ(wr) = int d(u, v) [G / cos(theta_i)] sum_k c_k(wi) E_k(u, v, w)`
//!
//! is, cell by cell, the cell's mass `M_k(s) = int_cell E_k d(u, v)` (per
//! layer, exact sums of the maps' texels) times the smooth factors at the
//! cell's centroid: `G / cos(theta_i)` and the environment's coefficients
//! averaged over the cell's footprint (`c_k` read from the prefiltered
//! environment at the cell's solid angle, `sunbeam_light::prefilter`). The
//! error is that of a midpoint rule per cell: the factors' curvature over the
//! cell and the environment's correlation with the colour inside it.
//!
//! Clustering: the texels of the reference's quadrature (centres and areas
//! of `EnvQuadrature`'s rows; a texel's mass is its area times its |Y|
//! summed over the maps, averaged over the layers) are split top-down, at
//! each step the cell with the largest `mass x spread^2` (mass-weighted
//! variance of its position) at its mass median along its longer axis, until
//! `n` cells: a median-cut quadtree in the mass, not the grid. The specular
//! peak (much mass, no spread) stays one cell; the orders' rainbow streaks
//! are cut along their length.
//!
//! Cells near the view's horizon: a cell is split further, per view, into the
//! two children the clustering made (kept as a binary tree), while its spread
//! reaches the horizon (`|dist| < REFINE * spread`), so that the `1 / cos`
//! peak there is followed; a cell further outside is one leaf, its share
//! inside (its Gaussian's tail) about 0, as its children's would be
//! (refining those too made a view visit 4.7 times the nodes at 20 um for
//! the same image: docs/LIGHTING.md "Where a walk's time goes"); leaves straddling it count the share of their spread
//! inside the disc (a Gaussian's, along the normal to the horizon), each
//! channel from its own centroid ([`Cell::offsets`]): on a pack of real size
//! the diffraction orders are narrow, a cell on one holds a rainbow along
//! it, and the horizon keeps one end of it (docs/LIGHTING.md "Why 20 um is
//! harder").

use crate::grid::Grid;
use crate::Response;
use rayon::prelude::*;
use std::collections::BinaryHeap;
use sunbeam_optics::gain;
use sunbeam_optics::masking::Masking;

/// A local frame `(t, b, n)` (world vectors).
pub type Frame = ([f64; 3], [f64; 3], [f64; 3]);

/// Cells refine near the horizon while their spread (rms radius) times this
/// reaches it.
pub const REFINE: f64 = 3.0;

/// Cells every view visits (the top cut) in the player.
pub const DEFAULT_TOP: usize = 256;
/// Levels below the top cut kept for views whose horizon a cell reaches.
pub const DEFAULT_DEPTH: usize = 4;
/// The top cut of the player's first frame and the engines' export
/// (`--env-cells`), and what `sunbeam-pack --response` clusters by default,
/// for a patch smaller than [`LARGE_PATCH_M`] ([`first_frame_top`]).
pub const FIRST_FRAME_TOP: usize = 512;
/// The same for a patch of [`LARGE_PATCH_M`] or more.
pub const FIRST_FRAME_TOP_LARGE: usize = 1024;
/// The patch size (its longer side) from which [`first_frame_top`] is
/// [`FIRST_FRAME_TOP_LARGE`].
pub const LARGE_PATCH_M: f64 = 10e-6;

/// The top cut for a pack whose patch's longer side is `patch_m` metres:
/// [`FIRST_FRAME_TOP`] below [`LARGE_PATCH_M`], [`FIRST_FRAME_TOP_LARGE`]
/// from it. Measured against the quadrature at single shading points
/// (benches/cells.rs, sky, CIEDE2000 p99, 2026-12-01): the thesis' 5 um
/// patch 0.35 at 512 cells, 0.27 at 768 (1.44x the nodes: not worth it);
/// a 20 um scan 4.85 at 512, 4.24 at 640, 1.78 at 768, 0.99 at 1024; its
/// sky-lit sphere (40 x 40, 4 x 4 supersampled, against a converged
/// reference) inside p99 1.25 in the first frame at 768, 0.85 at 1024, and
/// over every lit pixel after 16 frames 1.27 and 0.85, for 1.19x the frame
/// (docs/LIGHTING.md "How many cells").
pub fn first_frame_top(patch_m: f64) -> usize {
    if patch_m >= LARGE_PATCH_M {
        FIRST_FRAME_TOP_LARGE
    } else {
        FIRST_FRAME_TOP
    }
}

/// [`first_frame_top`] for `manifest`'s pack.
pub fn first_frame_top_for(manifest: &sunbeam_pack::Manifest) -> usize {
    first_frame_top(manifest.patch.lx_m.max(manifest.patch.ly_m))
}
/// Floats per node in [`Cells::gpu_data`] before its layers' masses: `[u,
/// v, spread, first]`, `[next, uu, uv, vv]`, per basis its 3 offsets in 8.
pub const GPU_HEADER: usize = 4 + 4 + 3 * 8;
/// Floats per layer of a node's masses in [`Cells::gpu_data`]: per basis
/// XYZ and a 0.
pub const GPU_LAYER: usize = 3 * 4;

/// Floats per node in [`Cells::gpu_data`] for maps of `n_s` layers.
pub fn gpu_stride(n_s: usize) -> usize {
    GPU_HEADER + GPU_LAYER * n_s
}
/// Leaves whose centroid lies within this many of their widths of the view's
/// horizon take [`rim_point`]'s integral of `G / cos` across them.
pub const RIM_WIDTHS: f64 = 5.0;
/// Leaves whose centroid lies outside the disc by less than this still count
/// (through [`rim_point`]): the maps' interpolation spreads their texels
/// across the horizon, where `1 / cos` is largest.
pub const RIM_OUTSIDE: f64 = 0.05;
/// Half-width of [`rim_moments`]' box in units of the cell's rms width
/// (`sqrt 3`: the box of the same variance).
pub const RIM_BOX: f64 = 1.732_050_807_568_877_2;
/// "No node" in [`Cells::gpu_data`]'s links.
pub const GPU_NONE: u32 = u32::MAX;

/// One node of the cells' tree.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// Mass-weighted centroid in `(u, v)`.
    pub uv: [f64; 2],
    /// Mass-weighted rms distance of the cell's texels from the centroid.
    pub spread: f64,
    /// Children (indices into `Cells::nodes`), or none for a leaf.
    pub children: Option<[u32; 2]>,
    /// Per layer `k` (the maps' `s` texels): `int_cell E_b d(u, v)`, XYZ of
    /// `b = 0, 1, 2` (9 values).
    pub mass: Vec<[f64; 9]>,
    /// Per value of `mass`: its own centroid less `uv`, over all layers
    /// (`int E (uv - centroid) / int E`), at most `2 spread` long.
    pub offsets: [[f64; 2]; 9],
    /// The cell's extent for the horizon ([`rim_point`]): the mass-weighted
    /// covariance of its texels' centres in `(u, v)` (uu, uv, vv) plus, on
    /// the diagonal, the maps' texel extents at the centroid, `(dr^2 +
    /// (r dtheta)^2) / 12`, over which their interpolation spreads a texel
    /// (a cell of one texel has that width).
    pub width: [f64; 3],
}

impl Cell {
    /// Value `q` of the mass between layers `k0` and `k0 + 1`, `f` the
    /// weight of the latter.
    fn mass_at(&self, k0: usize, f: f64, q: usize) -> f64 {
        self.mass[k0][q] * (1.0 - f) + self.mass[k0 + 1][q] * f
    }
}

/// The cells of one pack's maps.
#[derive(Debug, Clone, PartialEq)]
pub struct Cells {
    pub grid: Grid,
    /// Every node of the tree; the first `n_top` are the top cut (the cells
    /// every view visits), the rest their descendants.
    pub nodes: Vec<Cell>,
    pub n_top: usize,
}

/// The cells as the shaders read them ([`Cells::gpu_data`]) with their
/// counts: what the player uploads and the pipeline's cells file
/// (`NAME.env-cells.ktx2`) holds.
#[derive(Debug, Clone, PartialEq)]
pub struct GpuCells {
    /// Cells of the top cut.
    pub n_top: usize,
    /// Nodes in all: what one walk of them may visit.
    pub nodes: usize,
    pub data: Vec<f32>,
}

struct Texel {
    uv: [f64; 2],
    m: f64,
    t: u32,
}

struct Pending {
    cost: f64,
    members: Vec<u32>,
}

impl PartialEq for Pending {
    fn eq(&self, o: &Self) -> bool {
        self.cost == o.cost
    }
}
impl Eq for Pending {}
impl PartialOrd for Pending {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Pending {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.cost.total_cmp(&o.cost)
    }
}

impl Cells {
    /// Cluster the three maps `basis` (on one grid) into `n_top` cells, each
    /// split further down to `depth` levels for views that need it.
    pub fn build(basis: &[Response], n_top: usize, depth: usize) -> Cells {
        assert_eq!(basis.len(), 3, "three basis maps");
        let g = basis[0].info.grid;
        let (nt, nr, ns) = (g.n_theta, g.n_rho, g.n_s);
        // Texels as the quadrature's: centre, area. The maps' Y summed over
        // the layers and maps, in memory order (layer-major), rows in parallel.
        let areas: Vec<f64> = (0..nr).map(|j| g.texel_extent(j).2).collect();
        let y_sum: Vec<f64> = (0..nr)
            .into_par_iter()
            .flat_map_iter(|j| {
                let mut row = vec![0.0; nt];
                for k in 0..ns {
                    for m in basis {
                        for (i, y) in row.iter_mut().enumerate() {
                            *y += m.texel_channel(i, j, k, 1).abs();
                        }
                    }
                }
                row
            })
            .collect();
        let mut texels = Vec::new();
        for (j, area) in areas.iter().enumerate() {
            let r = g.r_at(j);
            for i in 0..nt {
                let m = *area * y_sum[j * nt + i] / ns as f64;
                if m > 0.0 {
                    let th = g.theta_at(i);
                    texels.push(Texel {
                        uv: [r * th.cos(), r * th.sin()],
                        m,
                        t: (j * nt + i) as u32,
                    });
                }
            }
        }
        if texels.is_empty() {
            return Cells {
                grid: g,
                nodes: Vec::new(),
                n_top: 0,
            };
        }
        let stats = |members: &[u32]| -> ([f64; 2], f64, f64) {
            let (mut m, mut su, mut sv) = (0.0, 0.0, 0.0);
            for &t in members {
                let x = &texels[t as usize];
                m += x.m;
                su += x.m * x.uv[0];
                sv += x.m * x.uv[1];
            }
            let c = [su / m, sv / m];
            let mut var = 0.0;
            for &t in members {
                let x = &texels[t as usize];
                var += x.m * ((x.uv[0] - c[0]).powi(2) + (x.uv[1] - c[1]).powi(2));
            }
            (c, m, (var / m).max(0.0))
        };
        let texel_var = |c: [f64; 2]| {
            let r = c[0].hypot(c[1]);
            let dr = (r * r + g.r0 * g.r0).sqrt() * g.rho_scale() / (nr - 1) as f64;
            let da = r * std::f64::consts::TAU / nt as f64;
            (dr * dr + da * da) / 12.0
        };
        let width_of = |members: &[u32], c: [f64; 2], m: f64| -> [f64; 3] {
            let mut w = [0.0; 3];
            for &t in members {
                let x = &texels[t as usize];
                let (du, dv) = (x.uv[0] - c[0], x.uv[1] - c[1]);
                w[0] += x.m * du * du;
                w[1] += x.m * du * dv;
                w[2] += x.m * dv * dv;
            }
            let t = texel_var(c);
            [w[0] / m + t, w[1] / m, w[2] / m + t]
        };
        let all: Vec<u32> = (0..texels.len() as u32).collect();
        let split = |members: &[u32]| -> Option<(Vec<u32>, Vec<u32>)> {
            if members.len() < 2 {
                return None;
            }
            let (c, _, _) = stats(members);
            let (mut vu, mut vv) = (0.0, 0.0);
            for &t in members {
                let x = &texels[t as usize];
                vu += x.m * (x.uv[0] - c[0]).powi(2);
                vv += x.m * (x.uv[1] - c[1]).powi(2);
            }
            let axis = usize::from(vv > vu);
            let mut s = members.to_vec();
            s.sort_by(|a, b| texels[*a as usize].uv[axis].total_cmp(&texels[*b as usize].uv[axis]));
            let total: f64 = s.iter().map(|&t| texels[t as usize].m).sum();
            let mut acc = 0.0;
            let mut cut = 1;
            for (q, &t) in s.iter().enumerate() {
                acc += texels[t as usize].m;
                if acc >= 0.5 * total {
                    cut = (q + 1).clamp(1, s.len() - 1);
                    break;
                }
            }
            let b = s.split_off(cut);
            Some((s, b))
        };
        // The top cut: repeatedly split the costliest cell.
        let cost = |members: &[u32]| {
            let (_, m, var) = stats(members);
            m * var
        };
        let mut heap = BinaryHeap::new();
        heap.push(Pending {
            cost: cost(&all),
            members: all,
        });
        let mut top: Vec<Vec<u32>> = Vec::new();
        while top.len() + heap.len() < n_top.max(1) {
            let Some(p) = heap.pop() else { break };
            match (p.cost > 0.0).then(|| split(&p.members)).flatten() {
                Some((a, b)) => {
                    for half in [a, b] {
                        heap.push(Pending {
                            cost: cost(&half),
                            members: half,
                        });
                    }
                }
                None => top.push(p.members),
            }
        }
        top.extend(heap.into_iter().map(|p| p.members));
        // Rebuild as a tree whose first n_top nodes are the top cut.
        let mut out: Vec<Cell> = Vec::new();
        let mut queue: Vec<(usize, Vec<u32>, usize)> = Vec::new();
        for m in top {
            out.push(Cell {
                uv: [0.0; 2],
                spread: 0.0,
                children: None,
                mass: Vec::new(),
                offsets: [[0.0; 2]; 9],
                width: [0.0; 3],
            });
            queue.push((out.len() - 1, m, 0));
        }
        let n_top = out.len();
        // The leaves partition the texels: `owner` maps a texel to its leaf.
        let mut owner = vec![u32::MAX; nt * nr];
        let mut q = 0;
        while q < queue.len() {
            let (id, members, d) = std::mem::take(&mut queue[q]);
            q += 1;
            let (c, m, var) = stats(&members);
            out[id].uv = c;
            out[id].spread = var.sqrt();
            out[id].width = width_of(&members, c, m);
            let halves = if d < depth && var > 0.0 {
                split(&members)
            } else {
                None
            };
            match halves {
                Some((a, b)) => {
                    let ia = out.len();
                    out.push(out[id].clone());
                    out.push(out[id].clone());
                    out[id].children = Some([ia as u32, ia as u32 + 1]);
                    queue.push((ia, a, d + 1));
                    queue.push((ia + 1, b, d + 1));
                }
                None => {
                    for &t in &members {
                        owner[texels[t as usize].t as usize] = id as u32;
                    }
                }
            }
        }
        // Masses: each leaf's by one pass over the maps in memory order (a
        // layer per task), then each parent's as the sum of its children's
        // (children come after their parent). One pass instead of one per
        // tree level, and no strided reads: most of the player's start-up
        // under an environment before (docs/bench/play.md "Start-up").
        // The same pass takes each value's first moment (raw, about the
        // origin), summed over the layers below, for the values' own
        // centroids. Per layer: each node's 9 masses and their moments.
        let cols: Vec<(f64, f64)> = (0..nt).map(|i| g.theta_at(i).sin_cos()).collect();
        type Layer = (Vec<[f64; 9]>, Vec<[[f64; 2]; 9]>);
        let per_layer: Vec<Layer> = (0..ns)
            .into_par_iter()
            .map(|k| {
                let mut acc = vec![[0.0; 9]; out.len()];
                let mut mom = vec![[[0.0; 2]; 9]; out.len()];
                for j in 0..nr {
                    let a = areas[j];
                    let r = g.r_at(j);
                    for i in 0..nt {
                        let leaf = owner[j * nt + i];
                        if leaf == u32::MAX {
                            continue;
                        }
                        let (sn, cs) = cols[i];
                        let (o, q) = (&mut acc[leaf as usize], &mut mom[leaf as usize]);
                        for (b, map) in basis.iter().enumerate() {
                            let e = map.texel(i, j, k);
                            for c in 0..3 {
                                let m = a * e[c];
                                o[3 * b + c] += m;
                                q[3 * b + c][0] += m * r * cs;
                                q[3 * b + c][1] += m * r * sn;
                            }
                        }
                    }
                }
                (acc, mom)
            })
            .collect();
        let mut moment = vec![[[0.0; 2]; 9]; out.len()];
        for (id, cell) in out.iter_mut().enumerate() {
            cell.mass = per_layer.iter().map(|l| l.0[id]).collect();
            for l in &per_layer {
                for (x, y) in moment[id].iter_mut().zip(&l.1[id]) {
                    x[0] += y[0];
                    x[1] += y[1];
                }
            }
        }
        for id in (0..out.len()).rev() {
            if let Some([a, b]) = out[id].children {
                let (ma, mb) = (&out[a as usize].mass, &out[b as usize].mass);
                let sum: Vec<[f64; 9]> = ma
                    .iter()
                    .zip(mb)
                    .map(|(x, y)| std::array::from_fn(|c| x[c] + y[c]))
                    .collect();
                out[id].mass = sum;
                let (qa, qb) = (moment[a as usize], moment[b as usize]);
                moment[id] = std::array::from_fn(|c| [qa[c][0] + qb[c][0], qa[c][1] + qb[c][1]]);
            }
        }
        for (cell, q) in out.iter_mut().zip(&moment) {
            let total: [f64; 9] = std::array::from_fn(|c| cell.mass.iter().map(|l| l[c]).sum());
            let scale: f64 = total.iter().map(|m| m.abs()).sum();
            let longest = 2.0 * cell.spread;
            cell.offsets = std::array::from_fn(|c| {
                // a value whose mass nearly cancels over the cell (the basis
                // maps are signed) has no centroid to speak of
                if total[c].abs() <= 1e-6 * scale {
                    return [0.0; 2];
                }
                let d = [
                    q[c][0] / total[c] - cell.uv[0],
                    q[c][1] / total[c] - cell.uv[1],
                ];
                let l = d[0].hypot(d[1]);
                if l > longest {
                    let k = longest / l;
                    [d[0] * k, d[1] * k]
                } else {
                    d
                }
            });
        }
        Cells {
            grid: g,
            nodes: out,
            n_top,
        }
    }

    /// [`Cells::gpu_data`] with the counts.
    pub fn gpu(&self) -> GpuCells {
        GpuCells {
            n_top: self.n_top,
            nodes: self.nodes.len(),
            data: self.gpu_data(),
        }
    }

    /// The nodes for the shader (shaders/env_cells.wgsl `env_cells`), in
    /// fours of floats: per node `[u, v, spread, first child]`, `[next, uu,
    /// uv, vv]` (links as u32 bits, [`GPU_NONE`] for none; `width`), per
    /// basis `b` its 3 `offsets` (u, v each) and two 0s, then `n_s` layers of
    /// `[X, Y, Z, 0]` of `E_0, E_1, E_2`; the second child follows the first.
    /// A four is one load in the shader: read one float at a time, a leaf's
    /// reads were about 40 % of a walk on llvmpipe (docs/LIGHTING.md "Where a
    /// walk's time goes").
    ///
    /// `next` threads the tree: the node a depth-first walk visits after this
    /// one and its subtree (the next top cell, or the sibling, or the
    /// parent's `next`). With it the shader walks the tree with one index and
    /// no stack: a dynamically indexed private array costs a GPU local memory
    /// round trip per access (on an NVIDIA H200 it made a 1080p frame 7x
    /// slower, docs/bench/play.md "Real GPU").
    pub fn gpu_data(&self) -> Vec<f32> {
        let ns = self.grid.n_s;
        let mut next = vec![GPU_NONE; self.nodes.len()];
        for (i, n) in next.iter_mut().enumerate().take(self.n_top) {
            if i + 1 < self.n_top {
                *n = i as u32 + 1;
            }
        }
        // children come after their parent, so a parent's next is known first
        for (i, c) in self.nodes.iter().enumerate() {
            if let Some([a, b]) = c.children {
                next[a as usize] = b;
                next[b as usize] = next[i];
            }
        }
        let mut out = Vec::with_capacity(self.nodes.len() * gpu_stride(ns));
        for (c, &nx) in self.nodes.iter().zip(&next) {
            let first = c.children.map_or(GPU_NONE, |ch| ch[0]);
            out.extend([
                c.uv[0] as f32,
                c.uv[1] as f32,
                c.spread as f32,
                f32::from_bits(first),
                f32::from_bits(nx),
            ]);
            out.extend(c.width.map(|x| x as f32));
            for o in c.offsets.chunks(3) {
                out.extend(o.iter().flat_map(|o| o.map(|x| x as f32)));
                out.extend([0.0; 2]);
            }
            for layer in &c.mass {
                for m in layer.chunks(3) {
                    out.extend(m.iter().map(|&m| m as f32));
                    out.push(0.0);
                }
            }
        }
        out
    }

    /// The diffraction part (XYZ) towards local view `wr` (unit, `z > 0`),
    /// `coeffs(d, omega)` the environment's coefficients at world direction
    /// `d` averaged over `omega` steradians.
    pub fn estimate(
        &self,
        frame: Frame,
        wr: [f64; 3],
        masking: Masking,
        skin: gain::Material,
        coeffs: &dyn Fn([f64; 3], f64) -> [f64; 3],
    ) -> [f64; 3] {
        let top: Vec<u32> = (0..self.n_top as u32).collect();
        self.estimate_from(&top, frame, wr, masking, skin, coeffs).0
    }

    /// [`Cells::estimate`] from the nodes `start` instead of the top cut
    /// (a cut chosen per view, for measurements: benches/cells.rs `CUT`),
    /// with the number of nodes visited.
    pub fn estimate_from(
        &self,
        start: &[u32],
        frame: Frame,
        wr: [f64; 3],
        masking: Masking,
        skin: gain::Material,
        coeffs: &dyn Fn([f64; 3], f64) -> [f64; 3],
    ) -> ([f64; 3], usize) {
        let mut xyz = [0.0; 3];
        let mut visits = 0;
        if wr[2].is_nan() || wr[2] <= 0.0 {
            return (xyz, visits);
        }
        let (t, b, n) = frame;
        let world = |d: [f64; 3]| [0, 1, 2].map(|k| d[0] * t[k] + d[1] * b[k] + d[2] * n[k]);
        let mut stack: Vec<u32> = start.iter().rev().copied().collect();
        while let Some(id) = stack.pop() {
            visits += 1;
            let c = &self.nodes[id as usize];
            let wxy = [-c.uv[0] - wr[0], -c.uv[1] - wr[1]];
            let dist = 1.0 - (wxy[0] * wxy[0] + wxy[1] * wxy[1]).sqrt();
            if let Some(ch) = c.children {
                if dist.abs() < REFINE * c.spread {
                    stack.extend(ch);
                    continue;
                }
            }
            let inside = if c.spread > 0.0 {
                gaussian_inside(dist, c.spread)
            } else {
                f64::from(dist > 0.0)
            };
            // near the horizon: the cell's width towards it
            let l = 1.0 - dist;
            let dir = [wxy[0] / l.max(1e-12), wxy[1] / l.max(1e-12)];
            let sigma = (dir[0] * dir[0] * c.width[0]
                + 2.0 * dir[0] * dir[1] * c.width[1]
                + dir[1] * dir[1] * c.width[2])
                .max(0.0)
                .sqrt();
            let rim = l > 1e-9 && sigma > 0.0 && dist < RIM_WIDTHS * sigma && dist > -RIM_OUTSIDE;
            if !rim && (inside <= 0.0 || dist <= -0.5) {
                continue;
            }
            // the centroid, pulled inside the disc when it is not
            let k = if l > 0.999 { 0.999 / l } else { 1.0 };
            let (wx, wy) = (wxy[0] * k, wxy[1] * k);
            let wi = [wx, wy, (1.0 - wx * wx - wy * wy).max(0.0).sqrt()];
            let r = c.uv[0].hypot(c.uv[1]);
            // the layer (k0 and the weight of k0 + 1) at cos(theta_i) = wz
            let layer = |wz: f64| {
                let s = ((wz + wr[2]) / (4.0 - r * r).max(1e-12).sqrt()).clamp(0.0, 1.0);
                let sc = s * (self.grid.n_s - 1) as f64;
                let k0 = (sc.floor() as usize).min(self.grid.n_s - 2);
                (k0, sc - k0 as f64)
            };
            // the environment averaged over the cell's footprint: a disc of
            // the same area as its extent's ellipse (an isotropic filter; the
            // spread's circle would blur a streak across its length's width)
            let area = (c.width[0] * c.width[2] - c.width[1] * c.width[1])
                .max(0.0)
                .sqrt();
            let omega = (std::f64::consts::TAU * area / wi[2]).max(1e-9);
            let ck = coeffs(world(wi), omega);
            let straddles = inside < STRADDLE && c.spread > 0.0;
            if rim {
                // G / cos integrated across the cell ([`rim_point`]), G and the
                // layer read where that integral puts its weight; a cell that
                // straddles it integrates each value about its own centroid
                // (as [`channel_inside`] shares it), G on a line ([`rim_slope`])
                if let Some(p) = rim_point(dist, sigma) {
                    let wg = [dir[0] * (1.0 - p.x), dir[1] * (1.0 - p.x), p.wz];
                    let g0 = masking.gain(wg, wr, skin);
                    let slope = if straddles {
                        rim_slope(&p, sigma, dir, wr, masking, skin, g0)
                    } else {
                        0.0
                    };
                    let (k0, f) = layer(p.wz);
                    for (bb, cb) in ck.iter().enumerate() {
                        for (a, x) in xyz.iter_mut().enumerate() {
                            let q = 3 * bb + a;
                            let g = if straddles {
                                mass_rim_gain(dist, sigma, dir, c.offsets[q], &p, g0, slope)
                            } else {
                                g0 * p.factor
                            };
                            *x += g * cb * c.mass_at(k0, f, q);
                        }
                    }
                }
                continue;
            }
            let (k0, f) = layer(wi[2]);
            let g = masking.gain(wi, wr, skin) / wi[2];
            for (bb, cb) in ck.iter().enumerate() {
                for (a, x) in xyz.iter_mut().enumerate() {
                    let q = 3 * bb + a;
                    let share = if straddles {
                        channel_inside(c, q, wr)
                    } else {
                        inside
                    };
                    *x += g * share * cb * c.mass_at(k0, f, q);
                }
            }
        }
        (xyz, visits)
    }
}

/// `h(a) = int_0^inf p(y - a) y^(-1/2) dy` and `h1(a)`, the same with
/// `y^(1/2)`, for `p` the uniform density of unit variance (on `[-RIM_BOX,
/// RIM_BOX]`, `RIM_BOX = sqrt 3`): closed forms, `(sqrt(a + c) - sqrt(lo)) /
/// c` and `((a + c)^(3/2) - lo^(3/2)) / (3 c)` with `lo = max(a - c, 0)`.
/// Why a box and not a Gaussian of the same variance: the reference's
/// quadrature spreads each texel over its extent (a trapezoid in `x`), with
/// no tails, and a Gaussian's tails put weight into the `1 / sqrt` peak that
/// the texels do not have. On the 20 um synthetic pack under a white map
/// (views 53-78 degrees from the normal, against the quadrature) the Gaussian
/// was CIEDE2000 p99 4.33 (max 5.66; Z 11-15 % low at the worst points), the
/// box 3.15 (max 4.36); luminance alone over all views p99 0.42 → 0.31;
/// the ridge patch's 32 views -2.0 % / +1.5 % → -1.45 % / +1.1 %
/// (docs/LIGHTING.md "Accuracy per view"). The shader
/// (shaders/env_cells.wgsl `env_rim_moments`) computes the same.
fn rim_moments(a: f64) -> (f64, f64) {
    if a.is_nan() || a + RIM_BOX <= 0.0 {
        return (0.0, 0.0);
    }
    let (c, lo) = (RIM_BOX, (a - RIM_BOX).max(0.0));
    (
        ((a + c).sqrt() - lo.sqrt()) / c,
        ((a + c).powf(1.5) - lo.powf(1.5)) / (3.0 * c),
    )
}

/// Where `G / cos(theta_i)` integrated across a cell near the view's horizon
/// puts its weight, times its share inside: the cell's mass along `dir`
/// (the unit direction of its centroid's `wi_xy`) as a box of rms `sigma` in
/// `x = 1 - |wi_xy|` about `dist` ([`rim_moments`]), cut at `x = 0`. Near
/// the horizon `1 / cos = 1 / sqrt(x (2 - x))`; with `1 / sqrt(2 x)` the
/// integral is `h(dist / sigma) / sqrt(2 sigma)` ([`rim_moments`]), and `G`,
/// the rest of `1 / cos` and the caller's layer are read once at the
/// weighted mean `x = sigma h1 / h`. A midpoint rule at the centroid misses
/// the integrable peak (-4 % to +2 % of a view's Y on the 5 um pack;
/// docs/LIGHTING.md "Accuracy per view"). None when nothing is inside. As
/// shaders/env_cells.wgsl `env_rim_point`.
fn rim_point(dist: f64, sigma: f64) -> Option<RimPoint> {
    let (h, h1) = rim_moments(dist / sigma);
    // zero (or NaN from a NaN width) means nothing of the cell is inside
    if h.is_nan() || h <= 0.0 {
        return None;
    }
    let x = (sigma * h1 / h).min(1.0);
    Some(RimPoint {
        factor: h / (2.0 * sigma).sqrt() * (2.0 / (2.0 - x)).sqrt(),
        x,
        wz: rim_cos(x),
    })
}

/// [`rim_point`]'s result: `G / cos` integrated is `G(x) factor`.
struct RimPoint {
    /// What multiplies `G` read at `x`.
    factor: f64,
    /// The weighted mean of `x = 1 - |wi_xy|`.
    x: f64,
    /// `cos(theta_i)` there.
    wz: f64,
}

/// `cos(theta_i)` at `x = 1 - |wi_xy|`, at least 1e-6.
fn rim_cos(x: f64) -> f64 {
    let d = 1.0 - x;
    (1.0 - d * d).max(0.0).sqrt().max(1e-6)
}

/// The slope in `cos(theta_i)` of the line on which the values of a rim
/// cell that straddles the horizon read `G` ([`mass_rim_gain`]): through
/// `G` at the cell's weighted mean `p` (`g0`) and at a second point along
/// `dir`, at a quarter of the mean's `x` (towards the horizon, where a
/// straddling cell's values mostly lie and the masking takes `G` down), or,
/// where the mean is within a quarter width of the horizon, a width further
/// in. Two reads of `G` per cell instead of one per value: on llvmpipe every
/// leaf the walk reads pays for all of them (docs/LIGHTING.md "What a
/// branch costs on llvmpipe"). The 20 um synthetic pack, Smith masking, views
/// 0.02-0.6 from grazing, white map, per point against the quadrature
/// (benches/cells.rs): CIEDE2000 p99 2.40 against 2.73 with each value's own
/// `G` (a secant half a width further in: 3.18); the thesis patch 0.32
/// against 0.26. As shaders/env_cells.wgsl `env_rim_slope`.
fn rim_slope(
    p: &RimPoint,
    sigma: f64,
    dir: [f64; 2],
    wr: [f64; 3],
    masking: Masking,
    skin: gain::Material,
    g0: f64,
) -> f64 {
    let x2 = if p.x > 0.25 * sigma {
        0.25 * p.x
    } else {
        (p.x + sigma).min(1.0)
    };
    let d2 = 1.0 - x2;
    let wz2 = rim_cos(x2);
    let dz = wz2 - p.wz;
    if dz.is_nan() || dz.abs() <= 1e-7 {
        return 0.0;
    }
    let g2 = masking.gain([dir[0] * d2, dir[1] * d2, wz2], wr, skin);
    (g2 - g0) / dz
}

/// `G / cos` integrated across one value of a straddling rim cell, about the
/// value's own centroid (the cell's plus `off`) with the cell's width less
/// the offset, at least a quarter of it; `G` on the line through `g0` at
/// `p` ([`rim_slope`]). As shaders/env_cells.wgsl `env_cell_rim_gain`.
fn mass_rim_gain(
    dist: f64,
    sigma: f64,
    dir: [f64; 2],
    off: [f64; 2],
    p: &RimPoint,
    g0: f64,
    slope: f64,
) -> f64 {
    let po = dir[0] * off[0] + dir[1] * off[1];
    let sq = (sigma * sigma - po * po).max(sigma * sigma / 16.0).sqrt();
    rim_point(dist + po, sq).map_or(0.0, |m| (g0 + slope * (m.wz - p.wz)).max(0.0) * m.factor)
}

/// A cell whose share inside the disc is below this straddles the horizon:
/// each channel counts its own share ([`channel_inside`]).
pub const STRADDLE: f64 = 0.999;

/// The share of value `q`'s mass inside the disc for view `wr`: a Gaussian
/// about the value's own centroid, with the cell's spread less the offset
/// (at least a quarter of it). As shaders/env_cells.wgsl `env_cell_inside`.
fn channel_inside(c: &Cell, q: usize, wr: [f64; 3]) -> f64 {
    let off = c.offsets[q];
    let o2 = off[0] * off[0] + off[1] * off[1];
    let sq = (c.spread * c.spread - o2)
        .max(0.0625 * c.spread * c.spread)
        .sqrt();
    let wxy = [-c.uv[0] - off[0] - wr[0], -c.uv[1] - off[1] - wr[1]];
    gaussian_inside(1.0 - wxy[0].hypot(wxy[1]), sq)
}

/// The share inside the disc of a Gaussian of rms `sigma` whose centre lies
/// `dist` inside the horizon (negative: outside), along the horizon's normal.
fn gaussian_inside(dist: f64, sigma: f64) -> f64 {
    0.5 * (1.0 + sunbeam_optics::masking::erf(dist / (std::f64::consts::SQRT_2 * sigma)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(children: Option<[u32; 2]>) -> Cell {
        Cell {
            uv: [0.0; 2],
            spread: 0.0,
            children,
            mass: vec![[0.0; 9]; 2],
            offsets: [[0.0; 2]; 9],
            width: [0.0; 3],
        }
    }

    /// Walk `gpu_data` as the shader does: descend where `descend(id)`, else
    /// take `next`.
    fn walk(data: &[f32], stride: usize, descend: &dyn Fn(u32) -> bool) -> Vec<u32> {
        let mut seen = Vec::new();
        let mut id = 0u32;
        while id != GPU_NONE {
            let o = id as usize * stride;
            let first = data[o + 3].to_bits();
            if first != GPU_NONE && descend(id) {
                id = first;
                continue;
            }
            seen.push(id);
            id = data[o + 4].to_bits();
        }
        seen
    }

    #[test]
    fn the_threaded_walk_visits_what_the_stack_walk_visits() {
        // tops 0, 1, 2; 0 -> (3, 4), 2 -> (5, 6), 4 -> (7, 8), 6 -> (9, 10)
        let mut nodes: Vec<Cell> = (0..11).map(|_| node(None)).collect();
        nodes[0].children = Some([3, 4]);
        nodes[2].children = Some([5, 6]);
        nodes[4].children = Some([7, 8]);
        nodes[6].children = Some([9, 10]);
        let cells = Cells {
            grid: Grid {
                n_theta: 4,
                n_rho: 4,
                n_s: 2,
                r0: 0.1,
            },
            nodes,
            n_top: 3,
        };
        let data = cells.gpu_data();
        let stride = gpu_stride(2);
        assert_eq!(data.len(), 11 * stride);
        assert_eq!(walk(&data, stride, &|_| false), vec![0, 1, 2]);
        assert_eq!(walk(&data, stride, &|_| true), vec![3, 7, 8, 1, 5, 9, 10]);
        assert_eq!(walk(&data, stride, &|id| id != 2), vec![3, 7, 8, 1, 2]);
        assert_eq!(walk(&data, stride, &|id| id == 6), vec![0, 1, 2]);
    }
}
