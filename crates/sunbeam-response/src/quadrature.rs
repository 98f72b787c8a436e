//! The direction integral of extended light by quadrature: what the reference
//! (`sunbeam-eval render`, `sunbeam_raster::environment`) computes per
//! sub-pixel sample under a sky or a map (docs/LIGHTING.md "The reference's
//! estimator").
//!
//! The integral over incoming directions,
//!
//! `XYZ(wr) = int d(u, v) [G / cos(theta_i)] sum_k c_k(wi) E_k(u, v, w)  +  (sun)`,
//!
//! is a sum over the texels of the extended-light maps `E_k` ([`crate::env`],
//! kept here in `f32` and built with more wavelengths than the player's):
//! each texel inside the view's disc of propagating directions adds its area
//! in `(u, v)` times `E_k` at its centre (linear in `s`) times the smooth
//! factors `c_k G / cos(theta_i)` there. Why a sum and not Monte Carlo: the
//! integrand's lobes and its `1 / cos` at the horizon gave Monte Carlo a
//! per-pixel noise of 2-5 % (80 % at silhouettes) at 256 samples; the sum has
//! none, and its error is the maps' (measured against the per-wavelength
//! Monte Carlo estimator, which evaluates `R` from the pack directly).
//!
//! Texels within [`BAND`] of their widths of the horizon (`|wi_xy| = 1`),
//! where `1 / cos(theta_i)` and `G` change within a texel, are integrated
//! across their extent: `d = |wi_xy|` over the texel is a trapezoid
//! distribution (the centre's `d` plus the radial and angular half extents
//! projected on `wi_xy`), and each linear piece of it, cut at `d = 1`, by
//! 3-point Gauss-Legendre in `tau = -1 / (cos(theta_i) + cos(theta_r))`, in
//! which the integrand is smooth (`G (ci + cr)^2` is): the peak at the
//! horizon, `cos(theta_r)^2` wide in `d` at grazing views, is followed
//! whatever the view. A midpoint rule there lost the integrable
//! `1 / sqrt(1 - d)` peak (1.8 % of a head-on ridge patch under a white map,
//! tens of per cent at grazing views).
//! The sun (a disc of 0.5 degrees, outside the basis) is a point of its disc
//! per call, with `Omega E_sun` interpolated trilinearly, as in the player.
//!
//! A map is split texel by texel ([`LAMP_THRESHOLD`]): its lamps, the part of
//! each texel above 8x the map's mean, are point lights through the same
//! trilinear lookup of the three basis maps, one per map texel; the residual
//! is read averaged over each sum texel's footprint of directions (a mip
//! chain, `sunbeam_light::prefilter`), not at its centre (docs/LIGHTING.md
//! "Lamps in a map").
//!
//! Cost: only texels that matter are visited. Texels are ranked by their
//! largest `|E|` times area over the layers, and the smallest, together at
//! most [`SKIP_SHARE`] of the total, are left out. The rest can be split into
//! `parts` interleaved classes (texel `(i, j)` in class `(i mod q) + q (j mod
//! q)`, `parts = q^2`), so that the sub-pixel samples of a pixel share the
//! work: each sums one class times `parts`, and over a pixel whose samples
//! cover the classes evenly the sum is the whole (Keller and Heidrich 2001,
//! interleaved sampling; the caller balances the classes).

use crate::build::{self, Options};
use crate::env::env_weights;
use crate::grid::Grid;
use rayon::prelude::*;
use sunbeam_light::prefilter::Prefiltered;
use sunbeam_light::Environment;
use sunbeam_optics::gain;
use sunbeam_optics::masking::Masking;
use sunbeam_pack::Pack;

/// Wavelength samples of the reference's maps (the player's: 96).
pub const REFERENCE_LAMBDA_SAMPLES: usize = 160;

/// A local frame `(t, b, n)` (world vectors).
pub type Frame = ([f64; 3], [f64; 3], [f64; 3]);

/// Texels within this many of their extents of the horizon get the closed
/// form of `G / cos(theta_i)` across it.
pub const BAND: f64 = 2.0;

/// Largest share of `sum |E| area` left out with the smallest texels.
pub const SKIP_SHARE: f64 = 1e-4;

/// Per radial row of the grid.
#[derive(Debug, Clone)]
struct Row {
    r: f64,
    /// `1 / sqrt(4 - r^2)`: the layer's scale at this radius ([`View::add`]),
    /// once per row rather than per texel and view.
    inv_chord: f64,
    /// Radii of the texel's inner and outer edges.
    r_lo: f64,
    r_hi: f64,
    /// `(u, v)` area of one texel of the row.
    area: f64,
    /// Largest extent of a texel of the row (angle or radius).
    extent: f64,
    /// Per column: whether the texel is summed.
    kept: Vec<bool>,
}

/// The extended-light maps of one pack under one environment, laid out for
/// the sum.
#[derive(Debug, Clone)]
pub struct EnvQuadrature {
    grid: Grid,
    /// Per texel `(j, i)` (index `j * n_theta + i`), its `n_s` layers of the
    /// XYZ of `E_0, E_1, E_2` (9 values each), contiguous.
    basis: Vec<f32>,
    /// `Omega_sun E_sun`, XYZ per texel in the response-map order
    /// `(k * n_rho + j) * n_theta + i` (empty without the sun).
    sun: Vec<f32>,
    cols: Vec<(f64, f64)>,
    rows: Vec<Row>,
    /// The sky's coefficients tabulated (None: ask the environment).
    table: Option<OctTable>,
    /// A white furnace's map ([`EnvQuadrature::from_xyz`]): the
    /// coefficients are `(1, 0, 0)` without asking the environment.
    white: bool,
    /// A map's residual (its texels capped at [`LAMP_THRESHOLD`] times its
    /// mean) prefiltered by solid angle: each texel of the sum reads it
    /// averaged over its own footprint of directions.
    chain: Option<Prefiltered>,
    /// A map's lamps: each texel's part above the cap as a point light at
    /// its centre (world direction, `int c_k d(omega)` over the texel).
    lamps: Vec<Lamp>,
}

impl EnvQuadrature {
    /// Build the maps of `pack` under `env` on the grid of `opts` (or the
    /// point map's automatic grid) with `opts.lambda_samples` wavelengths.
    pub fn build(pack: &Pack, env: &Environment, opts: &Options) -> EnvQuadrature {
        let g = opts
            .grid
            .unwrap_or_else(|| build::auto_grid(pack, opts.budget_bytes));
        let ws = env_weights(pack, env, opts.lambda_samples);
        let mut sets = build::build_sets(pack, &g, &ws);
        let sun = if env.sun().is_some() {
            sets.pop().expect("the sun's set")
        } else {
            Vec::new()
        };
        let basis = interleave(
            g,
            &sets.iter().take(3).map(Vec::as_slice).collect::<Vec<_>>(),
        );
        let mut q = Self::from_parts(g, basis, sun);
        match env {
            Environment::Sky(_) => q.table = Some(OctTable::new(env, OCT_SIDE)),
            Environment::Map(m) => {
                let (chain, lamps) = split_map(m);
                q.chain = Some(chain);
                q.lamps = lamps;
            }
        }
        q
    }

    /// The quadrature of one map `xyz` (XYZ per texel, response-map order,
    /// on `grid`) under an environment whose first coefficient is 1
    /// everywhere (a constant white map): the map is put in the first basis
    /// slot. What the energy bound's tables integrate the directional albedo with.
    pub fn from_xyz(grid: Grid, xyz: &[f32]) -> EnvQuadrature {
        assert_eq!(xyz.len(), grid.texels() * 3, "map size");
        EnvQuadrature {
            white: true,
            ..Self::from_parts(grid, interleave(grid, &[xyz]), Vec::new())
        }
    }

    /// The reference's options: the point map's automatic grid,
    /// [`REFERENCE_LAMBDA_SAMPLES`] wavelengths.
    pub fn reference_options() -> Options {
        Options {
            lambda_samples: REFERENCE_LAMBDA_SAMPLES,
            ..Options::default()
        }
    }

    fn from_parts(grid: Grid, basis: Vec<f32>, sun: Vec<f32>) -> EnvQuadrature {
        let (nt, ns) = (grid.n_theta, grid.n_s);
        let dt = std::f64::consts::TAU / nt as f64;
        let cols = (0..nt)
            .map(|i| {
                let (s, c) = grid.theta_at(i).sin_cos();
                (c, s)
            })
            .collect();
        let mut rows: Vec<Row> = (0..grid.n_rho)
            .map(|j| {
                let (r_lo, r_hi, area) = grid.texel_extent(j);
                let r = grid.r_at(j);
                Row {
                    r,
                    inv_chord: 1.0 / (4.0 - r * r).max(1e-12).sqrt(),
                    r_lo,
                    r_hi,
                    area,
                    extent: (r_hi * dt).max(r_hi - r_lo),
                    kept: vec![false; nt],
                }
            })
            .collect();
        // Rank the texels by their largest |E| times area; leave out the
        // smallest, SKIP_SHARE of the total at most.
        let mut mass: Vec<(f64, u32)> = (0..grid.n_rho * nt)
            .map(|t| {
                let m = basis[t * ns * 9..(t + 1) * ns * 9]
                    .iter()
                    .fold(0.0f64, |a, &v| a.max((v as f64).abs()));
                (m * rows[t / nt].area, t as u32)
            })
            .collect();
        let total: f64 = mass.iter().map(|m| m.0).sum();
        mass.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut dropped = 0.0;
        for &(m, t) in &mass {
            if dropped + m <= SKIP_SHARE * total {
                dropped += m;
                continue;
            }
            let t = t as usize;
            rows[t / nt].kept[t % nt] = true;
        }
        EnvQuadrature {
            grid,
            basis,
            sun,
            cols,
            rows,
            table: None,
            white: false,
            chain: None,
            lamps: Vec::new(),
        }
    }

    /// The same sum under coefficients `f(d)` at world direction `d` over
    /// the whole sphere (tabulated like the sky's, the ground included), with
    /// no sun and no lamps: what one part of an environment contributes (for
    /// measurements: benches/cells.rs `QUAD`, a polynomial fit of the sky).
    pub fn with_coefficients(&self, f: &(dyn Fn([f64; 3]) -> [f64; 3] + Sync)) -> EnvQuadrature {
        EnvQuadrature {
            sun: Vec::new(),
            table: Some(OctTable::sphere(f, OCT_SIDE)),
            white: false,
            chain: None,
            lamps: Vec::new(),
            ..self.clone()
        }
    }

    /// The grid of the maps.
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// Texels visited by a whole sum (after leaving out the smallest).
    pub fn kept_texels(&self) -> usize {
        self.rows
            .iter()
            .map(|r| r.kept.iter().filter(|&&k| k).count())
            .sum()
    }

    /// The diffraction part (XYZ) towards local view `wr` (unit, `z > 0`) of
    /// an unmasked surface with skin `skin` and frame `frame`, lit by `env`:
    /// the sum over class `part.0` of `part.1` (1, 4, 16, .. a square) times
    /// `part.1`, plus the sun at the point `sun_u` of its disc.
    pub fn integrate(
        &self,
        env: &Environment,
        frame: Frame,
        wr: [f64; 3],
        sun_u: [f64; 2],
        skin: gain::Material,
        part: (usize, usize),
    ) -> [f64; 3] {
        self.integrate_many(
            env,
            &[Query {
                frame,
                wr,
                sun_u,
                masking: Masking::Off,
                skin,
            }],
            part,
        )[0]
    }

    /// [`EnvQuadrature::integrate`] for several shading points at once (the
    /// sub-pixel samples of a pixel that share a class): each texel's layers
    /// are read once for all of them.
    pub fn integrate_many(
        &self,
        env: &Environment,
        queries: &[Query],
        part: (usize, usize),
    ) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; queries.len()];
        let g = &self.grid;
        let (nt, ns) = (g.n_theta, g.n_s);
        let q = (part.1 as f64).sqrt().round().max(1.0) as usize;
        assert_eq!(q * q, part.1.max(1), "parts must be a square");
        let (pi_, pj) = (part.0 % q, (part.0 / q) % q);
        let scale = (q * q) as f64;
        let dt = std::f64::consts::TAU / nt as f64;
        let views: Vec<Option<View>> = queries.iter().map(|q| View::new(q, self, env)).collect();
        for (j, row) in self.rows.iter().enumerate().skip(pj).step_by(q) {
            if row.area <= 0.0 {
                continue;
            }
            // The columns that any view's disc can reach, as a range.
            let mut range: Option<(i64, i64)> = None;
            for v in views.iter().flatten() {
                let Some((lo, len)) = v.columns(row, nt, dt) else {
                    continue;
                };
                let hi = lo + len as i64;
                range = Some(match range {
                    None => (lo, hi),
                    Some((a, b)) => {
                        // Unwrap this range next to the first one.
                        let shift = ((a - lo) as f64 / nt as f64).round() as i64 * nt as i64;
                        (a.min(lo + shift), b.max(hi + shift))
                    }
                });
            }
            let Some((lo, hi)) = range else {
                continue;
            };
            let len = ((hi - lo) as usize).min(nt);
            // Columns lo .. lo + len (wrapping) of this part's class.
            let start = lo.rem_euclid(nt as i64) as usize;
            let mut off = (pi_ + q - start % q) % q;
            while off < len {
                let mut i = start + off;
                off += q;
                if i >= nt {
                    i -= nt;
                }
                if !row.kept[i] {
                    continue;
                }
                let texel = j * nt + i;
                let e = &self.basis[texel * ns * 9..(texel + 1) * ns * 9];
                let (cs, sn) = self.cols[i];
                for (v, o) in views.iter().zip(out.iter_mut()) {
                    if let Some(v) = v {
                        v.texel(self, row, cs, sn, dt, row.area * scale, e, o);
                    }
                }
            }
        }
        // The sun: a point of its disc per query.
        for ((qy, v), o) in queries.iter().zip(&views).zip(out.iter_mut()) {
            if v.is_some() {
                let s = self.sun_term(env, qy);
                for a in 0..3 {
                    o[a] += s[a];
                }
            }
        }
        // A map's lamps: every `kl`-th of them (in raster order, so each
        // class spans every lamp's extent) times `kl`.
        let kl = lamp_parts(self.lamps.len(), part.1.max(1));
        for (dir, power) in self.lamps.iter().skip(part.0 % kl).step_by(kl) {
            for ((qy, v), o) in queries.iter().zip(&views).zip(out.iter_mut()) {
                if v.is_some() {
                    let s = self.point_light(qy, *dir, *power);
                    for a in 0..3 {
                        o[a] += kl as f64 * s[a];
                    }
                }
            }
        }
        out
    }

    /// A point light of basis power `power` from world direction `dir`:
    /// `G sum_k P_k E_k(-wi - wr)` (`d(u, v) = cos(theta_i) d(omega)`
    /// cancels `1 / cos`, as for the sun).
    fn point_light(&self, q: &Query, dir: [f64; 3], power: [f64; 3]) -> [f64; 3] {
        let Some((wi, gain)) = incoming(q, dir) else {
            return [0.0; 3];
        };
        let wr = q.wr;
        let g = &self.grid;
        let Some(c) = g.coords(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]) else {
            return [0.0; 3];
        };
        let ns = g.n_s;
        let e = g.trilinear(c, |i, j, k| {
            let o = (j * g.n_theta + i) * ns * 9 + k * 9;
            let l = &self.basis[o..o + 9];
            [0, 1, 2].map(|a| {
                (0..3)
                    .map(|kk| power[kk] * f64::from(l[3 * kk + a]))
                    .sum::<f64>()
            })
        });
        e.map(|x| gain * x)
    }

    /// The sun's part at a point of its disc (`d(u, v) = cos(theta_i) dw`
    /// cancels `1 / cos`).
    fn sun_term(&self, env: &Environment, q: &Query) -> [f64; 3] {
        let mut xyz = [0.0; 3];
        if let (Some(sky), false) = (env.sun(), self.sun.is_empty()) {
            if let Some((d, _)) = sky.sample_sun(q.sun_u[0], q.sun_u[1]) {
                let wr = q.wr;
                if let Some((wi, gain)) = incoming(q, d) {
                    let e = self.lookup_sun(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]);
                    for a in 0..3 {
                        xyz[a] += gain * e[a];
                    }
                }
            }
        }
        xyz
    }

    /// `Omega E_sun` at `(u, v, w)` by trilinear interpolation (as
    /// `Response::lookup`).
    fn lookup_sun(&self, u: f64, v: f64, w: f64) -> [f64; 3] {
        let g = &self.grid;
        let Some(c) = g.coords(u, v, w) else {
            return [0.0; 3];
        };
        g.trilinear(c, |i, j, k| {
            let o = 3 * ((k * g.n_rho + j) * g.n_theta + i);
            [0, 1, 2].map(|a| f64::from(self.sun[o + a]))
        })
    }
}

/// World direction `d` of a point light in `q`'s frame and its gain
/// (`G` times the masking), or None below the horizon or without gain: what
/// the sun and a map's lamps share.
fn incoming(q: &Query, d: [f64; 3]) -> Option<([f64; 3], f64)> {
    let (t, b, n) = q.frame;
    let dot = |a: [f64; 3]| a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
    let wi = [dot(t), dot(b), dot(n)];
    if wi[2] <= 0.0 {
        return None;
    }
    let gain = q.masking.gain(wi, q.wr, q.skin);
    (gain > 0.0 && gain.is_finite()).then_some((wi, gain))
}

/// A map texel brighter than this many times the map's mean brightness (the
/// sum of its coefficients, over the sphere) is a lamp: its part above the
/// cap is summed as a point light per texel, not through the maps' texels.
/// Why: a lamp smaller than the maps' texel spacing lands in a few texels of
/// one interleaved class, so one sub-pixel sample of 16 carried it (two seeds
/// of a 40 x 40 frame under ../shared/data/hdri/studio.exr differed by
/// CIEDE2000 p99 31; with the residual prefiltered per texel footprint but
/// no lamps, 16); every class sees a lamp through its own share of the
/// lamp's texels.
pub const LAMP_THRESHOLD: f64 = 8.0;

/// Interleaved classes of the lamps for `parts` classes of the maps' texels:
/// the largest power of four dividing `parts` that leaves each class
/// [`LAMPS_PER_CLASS`] lamps or more (1 for a few lamps: every sample sums
/// them all).
fn lamp_parts(lamps: usize, parts: usize) -> usize {
    let mut k = 1;
    while parts.is_multiple_of(4 * k) && lamps / (4 * k) >= LAMPS_PER_CLASS {
        k *= 4;
    }
    k
}

/// A lamp texel: world direction and basis power.
type Lamp = ([f64; 3], [f64; 3]);

/// Fewest lamp texels one class sums.
const LAMPS_PER_CLASS: usize = 64;

/// A map split into its residual's prefiltered chain and its lamps
/// ([`LAMP_THRESHOLD`]): texel by texel, residual plus lamp is the map.
fn split_map(m: &sunbeam_light::EnvMap) -> (Prefiltered, Vec<Lamp>) {
    use std::f64::consts::{PI, TAU};
    let (w, h) = (m.width(), m.height());
    let texels = m.texels();
    let omega = |j: usize| sunbeam_light::hotspots::texel_solid_angle(w, h, j);
    let y = |c: [f32; 3]| f64::from(c[0]) + f64::from(c[1]) + f64::from(c[2]);
    let total: f64 = texels
        .iter()
        .enumerate()
        .map(|(t, c)| y(*c) * omega(t / w))
        .sum();
    let cap = LAMP_THRESHOLD * total / (4.0 * PI);
    let mut lamps = Vec::new();
    let mut rgba = Vec::with_capacity(w * h * 4);
    for (t, c) in texels.iter().enumerate() {
        let yt = y(*c);
        if cap > 0.0 && yt > cap {
            let (i, j) = (t % w, t / w);
            let keep = cap / yt;
            let theta = (j as f64 + 0.5) / h as f64 * PI;
            let phi = (i as f64 + 0.5) / w as f64 * TAU;
            let dir = m.world(sunbeam_light::direction(theta.cos(), phi));
            let p = c.map(|v| f64::from(v) * (1.0 - keep) * omega(j));
            lamps.push((dir, p));
            rgba.extend(c.map(|v| (f64::from(v) * keep) as f32));
        } else {
            rgba.extend(*c);
        }
        rgba.push(0.0);
    }
    (Prefiltered::new(w, h, rgba), lamps)
}

/// 3-point Gauss-Legendre nodes and weights on [-1, 1].
const GAUSS3: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// Side of the sky's coefficient table.
const OCT_SIDE: usize = 512;

/// The sky's coefficients `c_k` on an octahedral map of the upper
/// hemisphere (+y the pole, the horizon the map's diamond `|x| + |z| = 1`),
/// read bilinearly, and the ground's below the horizon: the Perez model per
/// texel of the sum is dearer than the rest of the texel. Texels are about
/// 0.35 degrees; those across the horizon hold the sky's continuation, so the
/// step between sky and ground stays sharp. A map environment is read
/// directly (its texels are constant, `EnvMap::lookup`).
#[derive(Debug, Clone)]
struct OctTable {
    side: usize,
    c: Vec<[f32; 3]>,
    /// The coefficients at and below the horizon (the ground's, constant).
    ground: [f64; 3],
    /// The table covers the whole sphere (octahedral, folded below the
    /// horizon) instead of the upper hemisphere and the ground.
    sphere: bool,
}

impl OctTable {
    fn new(env: &Environment, side: usize) -> OctTable {
        let mut c = Vec::with_capacity(side * side);
        for j in 0..side {
            for i in 0..side {
                // Texels below the horizon hold the sky's continuation
                // (the ground is read exactly, not from here).
                let k = env.coefficients(oct_direction(i, j, side, true));
                c.push(k.map(|v| v as f32));
            }
        }
        OctTable {
            side,
            c,
            ground: env.coefficients([0.0, -1.0, 0.0]),
            sphere: false,
        }
    }

    /// `f` over the whole sphere.
    fn sphere(f: &(dyn Fn([f64; 3]) -> [f64; 3] + Sync), side: usize) -> OctTable {
        let c = (0..side * side)
            .into_par_iter()
            .map(|t| f(oct_direction(t % side, t / side, side, false)).map(|v| v as f32))
            .collect();
        OctTable {
            side,
            c,
            ground: [0.0; 3],
            sphere: true,
        }
    }

    fn at(&self, d: [f64; 3]) -> [f64; 3] {
        if d[1] <= 0.0 && !self.sphere {
            return self.ground;
        }
        let s = d[0].abs() + d[1].abs() + d[2].abs();
        if s.is_nan() || s <= 0.0 {
            return [0.0; 3];
        }
        let (mut u, mut v) = (d[0] / s, d[2] / s);
        if d[1] < 0.0 {
            (u, v) = oct_fold(u, v);
        }
        let n = self.side as f64;
        let fx = ((u + 1.0) * 0.5 * n - 0.5).clamp(0.0, n - 1.0);
        let fy = ((v + 1.0) * 0.5 * n - 0.5).clamp(0.0, n - 1.0);
        let (i0, j0) = (
            (fx as usize).min(self.side - 2),
            (fy as usize).min(self.side - 2),
        );
        let (tx, ty) = (fx - i0 as f64, fy - j0 as f64);
        let at = |i: usize, j: usize| self.c[j * self.side + i];
        let (a, b, c, e) = (
            at(i0, j0),
            at(i0 + 1, j0),
            at(i0, j0 + 1),
            at(i0 + 1, j0 + 1),
        );
        std::array::from_fn(|k| {
            let top = a[k] as f64 * (1.0 - tx) + b[k] as f64 * tx;
            let bot = c[k] as f64 * (1.0 - tx) + e[k] as f64 * tx;
            top * (1.0 - ty) + bot * ty
        })
    }
}

/// The octahedron's fold between the upper and the lower hemisphere (its own
/// inverse): `(u, v)` of the square to `(x, z)` below the horizon and back.
fn oct_fold(u: f64, v: f64) -> (f64, f64) {
    ((1.0 - v.abs()) * u.signum(), (1.0 - u.abs()) * v.signum())
}

/// The world direction at the centre of texel `(i, j)` of an octahedral
/// table of `side` texels (`y` up); `upper`: below the horizon, the upper
/// hemisphere's continuation (`y` floored at 0).
fn oct_direction(i: usize, j: usize, side: usize, upper: bool) -> [f64; 3] {
    let u = 2.0 * (i as f64 + 0.5) / side as f64 - 1.0;
    let v = 2.0 * (j as f64 + 0.5) / side as f64 - 1.0;
    let y = 1.0 - u.abs() - v.abs();
    let (x, z) = if y < 0.0 { oct_fold(u, v) } else { (u, v) };
    let y = if upper { y.max(1e-9) } else { y };
    let l = (x * x + y * y + z * z).sqrt();
    [x / l, y / l, z / l]
}

/// Up to three maps (XYZ per texel, response-map order `(k * n_rho + j) *
/// n_theta + i`) laid out for the sum: per texel `(j, i)` its `n_s` layers of
/// 9 values (the maps' XYZ in order; missing maps 0).
fn interleave(g: Grid, maps: &[&[f32]]) -> Vec<f32> {
    let (nt, nr, ns) = (g.n_theta, g.n_rho, g.n_s);
    let mut basis = vec![0.0f32; nt * nr * ns * 9];
    for k in 0..ns {
        for j in 0..nr {
            for i in 0..nt {
                let src = 3 * ((k * nr + j) * nt + i);
                let dst = ((j * nt + i) * ns + k) * 9;
                for (b, m) in maps.iter().enumerate() {
                    basis[dst + 3 * b..dst + 3 * b + 3].copy_from_slice(&m[src..src + 3]);
                }
            }
        }
    }
    basis
}

/// One shading point of [`EnvQuadrature::integrate_many`].
#[derive(Debug, Clone, Copy)]
pub struct Query {
    /// Local frame `(t, b, n)` (world vectors).
    pub frame: Frame,
    /// Local view (unit, `z > 0`).
    pub wr: [f64; 3],
    /// The point of the sun's disc (two uniforms).
    pub sun_u: [f64; 2],
    /// Shadowing-masking on `G` (sunbeam_optics::masking).
    pub masking: Masking,
    /// The skin's interface: index and normalisation of `G` (sunbeam_optics::gain).
    pub skin: gain::Material,
}

/// A texel's footprint of incoming directions: its `(u, v)` area over
/// `cos(theta_i)` steradians (`d(u, v) = cos(theta_i) d(omega)`), the cosine
/// floored at the texel's reach from the horizon (`sqrt(2 extent)`: the
/// cosine at `|wi_xy| = 1 - extent`).
#[derive(Debug, Clone, Copy)]
struct Footprint {
    area: f64,
    min_cos: f64,
}

impl Footprint {
    fn solid_angle(self, ci: f64) -> f64 {
        self.area / ci.max(self.min_cos)
    }
}

/// A query prepared for the sum.
struct View<'a> {
    frame: Frame,
    wr: [f64; 3],
    masking: Masking,
    skin: gain::Material,
    rho_v: f64,
    phi_v: f64,
    table: Option<&'a OctTable>,
    white: bool,
    chain: Option<&'a Prefiltered>,
    env: &'a Environment,
}

impl<'a> View<'a> {
    fn new(q: &Query, quad: &'a EnvQuadrature, env: &'a Environment) -> Option<View<'a>> {
        let wr = q.wr;
        if wr[2].is_nan() || wr[2] <= 0.0 {
            return None;
        }
        Some(View {
            frame: q.frame,
            wr,
            masking: q.masking,
            skin: q.skin,
            rho_v: wr[0].hypot(wr[1]),
            phi_v: wr[1].atan2(wr[0]),
            table: quad.table.as_ref(),
            white: quad.white,
            chain: quad.chain.as_ref(),
            env,
        })
    }

    /// The columns `lo .. lo + len` (wrapping) of `row` whose texels can meet
    /// the disc `|(u, v) + wr_xy| < 1`, or None:
    /// `|p + wr|^2 = r^2 + rho_v^2 + 2 r rho_v cos(theta - phi_v)`.
    fn columns(&self, row: &Row, nt: usize, dt: f64) -> Option<(i64, usize)> {
        let reach = 1.0 + row.extent;
        if self.rho_v * row.r < 1e-12 {
            return (row.r.max(self.rho_v) <= reach).then_some((0, nt));
        }
        let c =
            (reach * reach - row.r * row.r - self.rho_v * self.rho_v) / (2.0 * row.r * self.rho_v);
        if c >= 1.0 {
            Some((0, nt))
        } else if c < -1.0 {
            None
        } else {
            // theta - phi_v in [acos c, 2 pi - acos c], about phi_v + pi.
            let half = std::f64::consts::PI - c.acos() + dt;
            let centre = (self.phi_v + std::f64::consts::PI) / dt;
            let lo = (centre - half / dt).floor() as i64;
            let hi = (centre + half / dt).ceil() as i64;
            Some((lo, ((hi - lo + 1) as usize).min(nt)))
        }
    }

    /// The coefficients from local direction `d`, averaged over `omega`
    /// steradians around it where the environment is a map: a texel of the
    /// sum stands for its footprint of directions, and a point lookup there
    /// aliases a lamp smaller than the texels' spacing (under
    /// ../shared/data/hdri/studio.exr two seeds of a 40 x 40 frame differed
    /// by CIEDE2000 p99 31 with point lookups).
    fn coefficients(&self, d: [f64; 3], omega: f64) -> [f64; 3] {
        if self.white {
            return [1.0, 0.0, 0.0];
        }
        let (t, b, n) = self.frame;
        let w = [0, 1, 2].map(|k| d[0] * t[k] + d[1] * b[k] + d[2] * n[k]);
        match (self.table, self.chain, self.env) {
            (Some(tab), _, _) => tab.at(w),
            (None, Some(chain), Environment::Map(m)) => chain.lookup(m.local(w), omega),
            _ => self.env.coefficients(w),
        }
    }

    /// Adds texel `(row, column at cos/sin (cs, sn))` with layers `e`,
    /// weighed by `area`, to `xyz`.
    #[allow(clippy::too_many_arguments)]
    fn texel(
        &self,
        quad: &EnvQuadrature,
        row: &Row,
        cs: f64,
        sn: f64,
        dt: f64,
        area: f64,
        e: &[f32],
        xyz: &mut [f64; 3],
    ) {
        let wr = self.wr;
        let (u, v) = (row.r * cs, row.r * sn);
        let (x, y) = (u + wr[0], v + wr[1]);
        let d2 = x * x + y * y;
        let reach = 1.0 + BAND * row.extent;
        if d2 >= reach * reach {
            return;
        }
        let d = d2.sqrt();
        let foot = Footprint {
            area: row.area,
            min_cos: (2.0 * row.extent).sqrt(),
        };
        if (1.0 - d).abs() > BAND * row.extent {
            self.plain(quad, -x, -y, row.inv_chord, area, foot, e, xyz);
            return;
        }
        // Near the horizon: the texel's radial and angular half extents
        // projected on wi_xy's direction.
        let dl = d.max(1e-12);
        let hr = ((x * cs + y * sn) / dl).abs() * (row.r_hi - row.r_lo) / 2.0;
        let ha = ((-x * sn + y * cs) / dl).abs() * row.r * dt / 2.0;
        self.band(
            quad,
            -x,
            -y,
            row.inv_chord,
            hr.max(1e-9),
            ha.max(1e-9),
            area,
            foot,
            e,
            xyz,
        );
    }

    /// Adds `weight * sum_k c_k E_k(s)` of texel layers `e` for an incoming
    /// direction with `cos(theta_i) = ci` at a `(u, v)` radius `r` whose row
    /// has `inv_chord = 1 / sqrt(4 - r^2)`.
    #[allow(clippy::too_many_arguments)]
    fn add(
        &self,
        quad: &EnvQuadrature,
        ci: f64,
        inv_chord: f64,
        weight: f64,
        c: [f64; 3],
        e: &[f32],
        xyz: &mut [f64; 3],
    ) {
        let ns = quad.grid.n_s;
        let s = (ci + self.wr[2]) * inv_chord;
        let ks = s.clamp(0.0, 1.0) * (ns - 1) as f64;
        let k0 = (ks.floor() as usize).min(ns.saturating_sub(2));
        let k1 = (k0 + 1).min(ns - 1);
        let f = (ks - k0 as f64) as f32;
        let (e0, e1) = (&e[k0 * 9..k0 * 9 + 9], &e[k1 * 9..k1 * 9 + 9]);
        for (a, x) in xyz.iter_mut().enumerate() {
            let acc: f64 = (0..3)
                .map(|k| {
                    let i = 3 * k + a;
                    c[k] * (e0[i] + f * (e1[i] - e0[i])) as f64
                })
                .sum();
            *x += weight * acc;
        }
    }

    /// A texel away from the horizon: its centre, `wi_xy = (x, y)`.
    #[allow(clippy::too_many_arguments)]
    fn plain(
        &self,
        quad: &EnvQuadrature,
        x: f64,
        y: f64,
        inv_chord: f64,
        area: f64,
        foot: Footprint,
        e: &[f32],
        xyz: &mut [f64; 3],
    ) {
        let d2 = x * x + y * y;
        if d2 >= 1.0 {
            return;
        }
        let ci = (1.0 - d2).sqrt();
        let wi = [x, y, ci];
        let gain = self.masking.gain(wi, self.wr, self.skin) / ci;
        if gain > 0.0 && gain.is_finite() {
            let c = self.coefficients([x, y, ci], foot.solid_angle(ci));
            self.add(quad, ci, inv_chord, area * gain, c, e, xyz);
        }
    }

    /// A texel near the horizon (centre `wi_xy = (x, y)`): `d = |wi_xy|`
    /// over it is its centre's plus two uniform offsets of half widths `hr`,
    /// `ha` (its radial and angular extents projected on wi_xy), a trapezoid;
    /// each linear piece of it (cut at d = 1) by 3-point Gauss-Legendre in
    /// `tau = -1 / (ci + cr)`, in which `G / cos(theta_i) dd = Gs |d tau| / d`
    /// with `Gs = G (ci + cr)^2` smooth: the peak at the horizon, `cr^2` wide
    /// in `d` at grazing views, is followed whatever `cr`. The coefficients
    /// `c_k` are the centre's.
    #[allow(clippy::too_many_arguments)]
    fn band(
        &self,
        quad: &EnvQuadrature,
        x: f64,
        y: f64,
        inv_chord: f64,
        hr: f64,
        ha: f64,
        area: f64,
        foot: Footprint,
        e: &[f32],
        xyz: &mut [f64; 3],
    ) {
        let cr = self.wr[2];
        let d = x.hypot(y).max(1e-12);
        let h = hr + ha;
        if d - h >= 1.0 {
            return;
        }
        let (w0, w1) = (hr.min(ha), hr.max(ha));
        let dc = d.min(1.0 - 1e-9);
        let cc = (1.0 - dc * dc).sqrt();
        let c = self.coefficients([x * dc / d, y * dc / d, cc], foot.solid_angle(cc));
        let tau = |d: f64| -1.0 / ((1.0 - d * d).max(0.0).sqrt() + cr);
        // Pieces (start, end, density at start, density at end) of the
        // trapezoid, whose integral is 1.
        let top = 1.0 / (2.0 * w1);
        let pieces = [
            (d - h, d - h + 2.0 * w0, 0.0, top),
            (d - h + 2.0 * w0, d + h - 2.0 * w0, top, top),
            (d + h - 2.0 * w0, d + h, top, 0.0),
        ];
        for (p0, p1, q0, q1) in pieces {
            let (a, b) = (p0.max(0.0), p1.min(1.0));
            if b <= a {
                continue;
            }
            let density = |dm: f64| q0 + (q1 - q0) * (dm - p0) / (p1 - p0);
            let (t0, t1) = (tau(a), tau(b));
            let half = 0.5 * (t1 - t0);
            for (node, wgt) in GAUSS3 {
                let tm = t0 + half * (1.0 + node);
                let ci = -1.0 / tm - cr;
                if ci <= 0.0 {
                    continue;
                }
                let dm = (1.0 - ci * ci).max(0.0).sqrt().max(1e-9);
                let wi = [x * dm / d, y * dm / d, ci];
                let gs = self.masking.gain(wi, self.wr, self.skin) * (ci + cr) * (ci + cr);
                let f = wgt * half.abs() * density(dm) / dm * gs;
                if f > 0.0 && f.is_finite() {
                    self.add(quad, ci, inv_chord, area * f, c, e, xyz);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::OctTable;

    // The whole-sphere table (EnvQuadrature::with_coefficients) reads back a
    // smooth function everywhere, below the horizon too (the fold), against
    // the function itself.
    #[test]
    fn the_sphere_table_reads_back_a_smooth_function_below_the_horizon_too() {
        let f = |d: [f64; 3]| [d[0], d[1] + 2.0, d[2] * d[0] - d[1] * d[1]];
        let t = OctTable::sphere(&f, 256);
        let mut worst = 0.0f64;
        for k in 0..2000 {
            let z = -1.0 + 2.0 * (k as f64 + 0.5) / 2000.0;
            let ph = k as f64 * 2.399_963_229_728_653;
            let d = sunbeam_light::direction(z, ph);
            let (a, b) = (t.at(d), f(d));
            for c in 0..3 {
                worst = worst.max((a[c] - b[c]).abs());
            }
        }
        // bilinear within half a texel of the octahedron's seams (about 0.7
        // degrees at 256, where f's gradient is at most about 2); a wrong
        // fold would be off by O(1)
        assert!(worst < 1e-2, "worst {worst}");
    }
}
