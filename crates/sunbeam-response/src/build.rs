//! Building a response map from a term pack: for every texel and wavelength
//! sample, the reflectance that shading uses exactly as
//! `sunbeam_pack::Pack::shading_reflectance` defines it (same coefficients,
//! kernel taps and model), summed with the colour weights: for the window
//! model `R_U` (PHYSICS.md 2b, `sunbeam_optics::grazing::window_reflectance`:
//! the amplitude plus its derivatives along the frequency, through the
//! derivative of the same Kaiser-Bessel kernel), for the tiled model `R`.
//!
//! Arranged so that each (texel column, wavelength) interpolates the N terms
//! once (Kaiser-Bessel or Gaussian taps, PACK_FORMAT.md), for the column half
//! a turn away too (the terms are Hermitian, see [`build`]), and then evaluates
//! every `w` of the column from those N complex values: `t` changes with `w`
//! but the frequency does not. The coefficients `c_n(t)` depend only on the
//! radius row, the wavelength and `s`, so they are tabulated per row. Rows run
//! in parallel (rayon); each texel's sum runs in a fixed order, so the map does
//! not depend on the thread count.
//!
//! One file of about 900 lines on purpose: the tap tables, the terms' layout
//! and the two sweeps (`window_by_rays`, `tiled_by_rows`) share private
//! fields inside the build's inner loops; split into modules they would have
//! to be made visible to the whole crate.

use crate::grid::Grid;
use crate::{Info, Response, FORMAT, VERSION};
use rayon::prelude::*;
use sunbeam_optics::cie;
use sunbeam_pack::{kernel, series, Model, Pack};

/// How to build a map.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Wavelength samples (midpoints over 380..780 nm).
    pub lambda_samples: usize,
    /// Upper bound on the map's size in bytes (RGBA16F texels).
    pub budget_bytes: usize,
    /// Fixed grid (None: chosen from the pack, [`auto_grid`]).
    pub grid: Option<Grid>,
}

/// Default wavelength samples (docs/PACK_FORMAT.md "Response map": chosen by measurement).
pub const DEFAULT_LAMBDA_SAMPLES: usize = 96;
/// Default size bound: 64 MiB.
pub const DEFAULT_BUDGET: usize = 64 << 20;

impl Default for Options {
    fn default() -> Self {
        Options {
            lambda_samples: DEFAULT_LAMBDA_SAMPLES,
            budget_bytes: DEFAULT_BUDGET,
            grid: None,
        }
    }
}

/// Shortest wavelength of the colour integral, metres.
const LAMBDA_MIN: f64 = cie::DEFAULT_RANGE_NM.0 as f64 * 1e-9;

/// Width (sigma, in |(u, v)|) of the narrowest lobe the pack can make: the
/// coherence window's transform, squared, at the shortest wavelength.
pub fn lobe_width(pack: &Pack) -> f64 {
    let m = &pack.manifest;
    let w = match m.model {
        Model::Window if m.window_sigma_m > 0.0 => {
            LAMBDA_MIN / (2.0 * std::f64::consts::SQRT_2 * std::f64::consts::PI * m.window_sigma_m)
        }
        Model::Tiled if m.sigma_f_per_m > 0.0 => LAMBDA_MIN * m.sigma_f_per_m,
        _ => 0.02,
    };
    w.clamp(1e-4, 0.05)
}

/// Radial texels per unit of `asinh(r / r0)`: steps of 2 % in `r` beyond the
/// knee. The colour changes along a ray about as fast as the wavelength (a
/// lobe of order m sits at `r = m lambda / period`), so this step is what holds
/// the hue; measured on a 5 um ridge patch (docs/bench/play.md), 25 per unit
/// gave CIEDE2000 p99 1.03 and 50 gave 0.50 (twice the angle or `s`: no gain).
const RHO_PER_UNIT: f64 = 50.0;
/// The radial density below which the budget takes angle texels first.
const RHO_PER_UNIT_MIN: f64 = 25.0;

/// Fewest `s` layers of a window pack's map (its grazing term): `R_U` of the
/// window's own lobe falls to 0 as `w -> 0` (a flat patch's is `(w^2 /
/// |q|^2)^2 R`, a notch `|w| ~ r` wide), and every pack is flat there (`t ->
/// 0`), so the layer `s = 0` holds about 0 under the specular lobe and
/// linear interpolation towards it dims every direction pair with `s` below
/// the next layer. Measured on a flat 40 um patch under a white furnace at a
/// view of 80 degrees (the quadrature over the maps against Monte Carlo on
/// the pack): -3 % with 8 layers, -0.2 % with 16
/// (`furnace_maps_follow_the_grazing_term` in crates/sunbeam-raster/tests/environment.rs).
pub const MIN_S_GRAZING: usize = 16;

/// The grid for a pack: two texels per lobe width across `(u, v)` at radius 1
/// (angle), [`RHO_PER_UNIT`] steps per unit of `asinh(r / r0)` along the
/// radius, about three per unit of `|t|` along `w` (at least 8, or
/// [`MIN_S_GRAZING`] for a window pack); then shrunk to the budget:
/// `s` to 16, the radius to [`RHO_PER_UNIT_MIN`], the angle to 128, the radius
/// to 64, in that order.
pub fn auto_grid(pack: &Pack, budget_bytes: usize) -> Grid {
    let m = &pack.manifest;
    let lobe = lobe_width(pack);
    let n_theta = ((std::f64::consts::TAU * 2.0 / lobe) / 64.0).ceil() as usize * 64;
    let mut g = Grid {
        n_theta: n_theta.clamp(128, 2048),
        n_rho: 0,
        n_s: 0,
        r0: lobe,
    };
    let scale = g.rho_scale();
    let rho_at = |per_unit: f64| ((scale * per_unit).ceil() as usize + 1).clamp(32, 400);
    g.n_rho = rho_at(RHO_PER_UNIT);
    let rho_floor = rho_at(RHO_PER_UNIT_MIN);
    let t_max = 4.0 * std::f64::consts::PI * m.height_half_range_m / LAMBDA_MIN;
    let min_s = if grazing_sigma(pack).is_some() {
        MIN_S_GRAZING
    } else {
        8
    };
    g.n_s = ((3.0 * t_max).ceil() as usize + 2).clamp(min_s, 40);
    let max_texels = (budget_bytes / 8).max(128 * 32 * 8);
    while g.texels() > max_texels {
        if g.n_s > 16 {
            g.n_s = (g.n_s * 7 / 8).max(16);
        } else if g.n_rho > rho_floor {
            g.n_rho = (g.n_rho * 7 / 8).max(rho_floor);
        } else if g.n_theta > 128 {
            g.n_theta = (g.n_theta / 2).max(128);
        } else if g.n_rho > 64 {
            g.n_rho = (g.n_rho * 7 / 8).max(64);
        } else {
            break;
        }
    }
    g
}

/// Wavelengths (metres) and XYZ weights `S cmf / sum S ybar` of `n` midpoint samples.
pub fn wavelength_weights(n: usize) -> Vec<(f64, [f64; 3])> {
    let n = n.max(1);
    let (lo, hi) = (
        cie::DEFAULT_RANGE_NM.0 as f64,
        cie::DEFAULT_RANGE_NM.1 as f64,
    );
    let step = (hi - lo) / n as f64;
    let raw: Vec<(f64, [f64; 3])> = (0..n)
        .map(|j| {
            let l = (lo + (j as f64 + 0.5) * step) * 1e-9;
            let s = cie::d65_at(l);
            let c = cie::cmf_at(l);
            (l, [s * c[0], s * c[1], s * c[2]])
        })
        .collect();
    let norm: f64 = raw.iter().map(|r| r.1[1]).sum();
    raw.into_iter()
        .map(|(l, w)| (l, w.map(|v| v / norm)))
        .collect()
}

/// The Kaiser-Bessel kernel and its derivative tabulated over `|d| in [0,
/// taps / 2]` (linear interpolation; the kernel's second and third
/// derivatives are O(1), so the tables' error is about 1e-8): `kernel::kb` and
/// `kernel::kb_derivative` sum a Bessel series per call, which dominated the
/// build.
struct KbTable {
    step: f64,
    v: Vec<f64>,
    /// `kernel::kb_derivative` at `|d|` (the derivative is odd in `d`).
    dv: Vec<f64>,
}

const KB_TABLE: usize = 8192;

impl KbTable {
    fn new(taps: usize, beta: f64) -> KbTable {
        let half = taps as f64 / 2.0;
        let step = half / KB_TABLE as f64;
        let v = (0..=KB_TABLE + 1)
            .map(|i| kernel::kb(i as f64 * step, taps, beta))
            .collect();
        let dv = (0..=KB_TABLE + 1)
            .map(|i| kernel::kb_derivative(i as f64 * step, taps, beta))
            .collect();
        KbTable { step, v, dv }
    }
    fn lerp(&self, t: &[f64], d: f64) -> f64 {
        let x = d.abs() / self.step;
        let i = x.floor() as usize;
        if i >= KB_TABLE {
            return 0.0;
        }
        let f = x - i as f64;
        t[i] * (1.0 - f) + t[i + 1] * f
    }
    fn at(&self, d: f64) -> f64 {
        self.lerp(&self.v, d)
    }
    /// `d kb / dd` at `d`.
    fn deriv(&self, d: f64) -> f64 {
        let v = self.lerp(&self.dv, d);
        if d < 0.0 {
            -v
        } else {
            v
        }
    }
}

/// One axis' taps at `kappa`: crop indices and weights (weights 0 outside the
/// crop), and with `dw` the weights' derivatives along `kappa` (window model).
fn taps(
    pack: &Pack,
    kb: &KbTable,
    kappa: f64,
    axis: usize,
    idx: &mut [usize],
    w: &mut [f32],
    mut dw: Option<&mut [f32]>,
) -> bool {
    let m = &pack.manifest;
    let (half, n) = (if axis == 0 { m.crop.kx } else { m.crop.ky }, m.kernel.taps);
    let k0 = kernel::first_tap(kappa, n);
    let mut any = false;
    for j in 0..n {
        let k = k0 + j as i64;
        if k < -half || k > half {
            w[j] = 0.0;
            idx[j] = 0;
            if let Some(dw) = dw.as_deref_mut() {
                dw[j] = 0.0;
            }
            continue;
        }
        let d = kappa - k as f64;
        w[j] = match m.model {
            Model::Window => kb.at(d),
            Model::Tiled => kernel::gauss(d, m.kernel.sigma_bins[axis]),
        } as f32;
        if let Some(dw) = dw.as_deref_mut() {
            dw[j] = kb.deriv(d) as f32;
            any |= dw[j] != 0.0;
        }
        idx[j] = (k + half) as usize;
        any |= w[j] != 0.0;
    }
    any
}

/// `y += a x`.
#[inline]
fn axpy(y: &mut [f32], a: f32, x: &[f32]) {
    for (yv, xv) in y.iter_mut().zip(x) {
        *yv += a * xv;
    }
}

/// `|A(f)|^2` (into `p`) and `|A(-f)|^2` (into `q`) for every `s` of a
/// column at once: `cl` holds the coefficients term-major (`cl[n ns + k]`),
/// so each term is one `axpy` over the column, which vectorises. The four
/// half sums are explained at [`build`]. With the window's grazing term, the
/// same four sums of the amplitude's derivative along the ray (`d*`) give
/// `A_U = A + beta D` per `s` ([`Powers::at_u`]).
struct Powers {
    ge: Vec<f32>,
    go: Vec<f32>,
    he: Vec<f32>,
    ho: Vec<f32>,
    dge: Vec<f32>,
    dgo: Vec<f32>,
    dhe: Vec<f32>,
    dho: Vec<f32>,
}

impl Powers {
    fn new(ns: usize) -> Powers {
        Powers {
            ge: vec![0.0; ns],
            go: vec![0.0; ns],
            he: vec![0.0; ns],
            ho: vec![0.0; ns],
            dge: vec![0.0; ns],
            dgo: vec![0.0; ns],
            dhe: vec![0.0; ns],
            dho: vec![0.0; ns],
        }
    }

    fn eval(&mut self, cl: &[f32], g: &[f32], h: &[f32], ne: usize) {
        half_sums(
            [&mut self.ge, &mut self.go, &mut self.he, &mut self.ho],
            cl,
            g,
            h,
            ne,
        );
    }

    /// The half sums of the derivative terms `dg`, `dh` (as [`Powers::eval`]).
    fn eval_d(&mut self, cl: &[f32], dg: &[f32], dh: &[f32], ne: usize) {
        half_sums(
            [&mut self.dge, &mut self.dgo, &mut self.dhe, &mut self.dho],
            cl,
            dg,
            dh,
            ne,
        );
    }

    /// `(|A(f)|^2, |A(-f)|^2)` of row `k` after [`Powers::eval`].
    #[inline]
    fn at(&self, k: usize) -> (f32, f32) {
        let (ge, go, he, ho) = (self.ge[k], self.go[k], self.he[k], self.ho[k]);
        let (a, b) = (ge + go, he + ho);
        let (am, bm) = (ge - go, ho - he);
        (a * a + b * b, am * am + bm * bm)
    }

    /// `(|A(f) + beta D(f)|^2, |A(-f) + beta D(-f)|^2)` of row `k` after
    /// [`Powers::eval`] and [`Powers::eval_d`]: the derivative terms along
    /// the mirrored ray are the conjugates of those along the ray (module
    /// [`build`]), so the same half sums give both.
    #[inline]
    fn at_u(&self, k: usize, beta: f32) -> (f32, f32) {
        let ge = self.ge[k] + beta * self.dge[k];
        let go = self.go[k] + beta * self.dgo[k];
        let he = self.he[k] + beta * self.dhe[k];
        let ho = self.ho[k] + beta * self.dho[k];
        let (a, b) = (ge + go, he + ho);
        let (am, bm) = (ge - go, ho - he);
        (a * a + b * b, am * am + bm * bm)
    }
}

/// The four half sums `[G_e, G_o, H_e, H_o]` of coefficients `cl` (term-major)
/// with the terms `g`, `h` (even terms first, `ne` of them).
fn half_sums(out: [&mut Vec<f32>; 4], cl: &[f32], g: &[f32], h: &[f32], ne: usize) {
    let [ge, go, he, ho] = out;
    let ns = ge.len();
    for v in [&mut *ge, &mut *go, &mut *he, &mut *ho] {
        v.iter_mut().for_each(|x| *x = 0.0);
    }
    for (n, c) in cl.chunks_exact(ns).enumerate() {
        let (gs, hs) = if n < ne {
            (&mut *ge, &mut *he)
        } else {
            (&mut *go, &mut *ho)
        };
        axpy(gs, g[n], c);
        axpy(hs, h[n], c);
    }
}

/// Build the response map of `pack`.
///
/// Angles come in pairs: `theta + pi` samples `-f` where `theta` samples `f`,
/// and the terms of a real height field are Hermitian, `F_n(-f) = conj F_n(f)`
/// (the crop and the kernel are symmetric, so the taps mirror too). With the
/// sums split by the parity of `n` (`G_e, G_o, H_e, H_o` below), `A(f) =
/// (G_e + G_o) + i (H_e + H_o)` and `A(-f) = (G_e - G_o) + i (H_o - H_e)`: one
/// interpolation and one set of dot products give both texels, half the work.
///
/// The window model's grazing term (PHYSICS.md 2b) needs the amplitude's
/// derivatives along `u` and `v`. On the ray of angle `theta`, `kappa = a q`
/// with `a = -(cos theta bin_scale_x, sin theta bin_scale_y)` and `q = r /
/// lambda`, and `window_reflectance`'s correction is exactly
/// `beta D` with `D = a . grad_kappa A = dA/dq` (the derivative along the
/// ray) and `beta = r lambda / (4 pi^2 sigma^2 (r^2 + w^2))`: one derivative
/// per ray, not two. The kernel's derivative is odd, so the interpolated
/// terms' gradient at `-kappa` is `-conj` of that at `kappa`; along the
/// mirrored ray (`a -> -a`) the two signs cancel and `D_n(-f) = conj D_n(f)`,
/// the same symmetry as the terms': the half sums above serve `D` too.
/// With `extra` weight sets (at the point map's wavelengths) built in the
/// same pass: their texels are returned beside the map (the energy bound's
/// white furnace, in the point module).
pub fn build_with(
    pack: &Pack,
    o: &Options,
    extra: Vec<Vec<[f64; 3]>>,
) -> (Response, Vec<Vec<f32>>) {
    let g = o.grid.unwrap_or_else(|| auto_grid(pack, o.budget_bytes));
    let lw = wavelength_weights(o.lambda_samples);
    let mut sets = vec![lw.iter().map(|l| l.1).collect()];
    sets.extend(extra);
    let ws = WeightSets {
        lambdas: lw.iter().map(|l| l.0).collect(),
        sets,
    };
    let mut out = build_sets(pack, &g, &ws);
    let xyz = out.remove(0);
    let quantity = format!(
        "XYZ without G: sum_l {}(u, v, w, l) S(l) cmf(l) / sum_l S(l) ybar(l)",
        reflectance_name(pack)
    );
    (to_response(pack, g, lw.len(), &xyz, true, &quantity), out)
}

/// What the maps of `pack` hold per wavelength: `R_U` (the window model with
/// its grazing term, PHYSICS.md 2b) or `R` (the tiled model).
pub fn reflectance_name(pack: &Pack) -> &'static str {
    if grazing_sigma(pack).is_some() {
        "R_U"
    } else {
        "R"
    }
}

/// The window's `sigma` (metres) when the maps carry its grazing term.
fn grazing_sigma(pack: &Pack) -> Option<f64> {
    let m = &pack.manifest;
    (m.model == Model::Window && m.window_sigma_m > 0.0).then_some(m.window_sigma_m)
}

/// Several colour integrals of the same `R`: wavelengths (metres) and, per
/// set, one XYZ weight per wavelength (`texel_s = sum_l R(.., l) set_s[l]`).
#[derive(Debug, Clone, PartialEq)]
pub struct WeightSets {
    pub lambdas: Vec<f64>,
    pub sets: Vec<Vec<[f64; 3]>>,
}

/// The texels (XYZ, `f32`, response-map order) of every weight set of `ws` on
/// grid `g`, in one pass over the pack's reflectance (`R_U` for the window
/// model, `R` for the tiled model: [`reflectance_name`]): the interpolation
/// of the terms and the powers, the expensive part, are shared; each set only
/// adds its own multiply-add per (texel, wavelength). Set `s`'s texels do not
/// depend on the other sets (same operations in the same order), so
/// [`build`] through here gives the same bytes as a set of its own.
pub fn build_sets(pack: &Pack, g: &Grid, ws: &WeightSets) -> Vec<Vec<f32>> {
    sets_of(pack, g, ws, grazing_sigma(pack))
}

/// [`build_sets`] with `R` (Beckmann's obliquity, no grazing term) for the
/// window model too: the maps before PHYSICS.md 2b, for plots of `R` itself
/// and for measuring what the grazing term costs (benches/build.rs).
pub fn build_sets_r(pack: &Pack, g: &Grid, ws: &WeightSets) -> Vec<Vec<f32>> {
    sets_of(pack, g, ws, None)
}

fn sets_of(pack: &Pack, g: &Grid, ws: &WeightSets, sigma: Option<f64>) -> Vec<Vec<f32>> {
    let terms = Terms::new(pack);
    let coef = coefficients(pack, g, &ws.lambdas, &terms);
    let wt: Vec<Vec<[f32; 3]>> = ws
        .sets
        .iter()
        .map(|s| s.iter().map(|w| w.map(|v| v as f32)).collect())
        .collect();
    match pack.manifest.model {
        Model::Window => window_by_rays(pack, g, &ws.lambdas, &wt, &terms, &coef, sigma),
        Model::Tiled => tiled_by_rows(pack, g, &ws.lambdas, &wt, &terms, &coef),
    }
}

/// A response map of XYZ texels. The point map (`point`: alpha 1) clamps
/// negative values (rounding) to 0; the extended-light maps (alpha 0) keep
/// them: a basis spectrum that dips below zero (`S1`, `S2`, a map's `D65
/// b_k`) has texels of either sign, and only the combination `sum_k c_k E_k`
/// is a colour.
pub fn to_response(
    pack: &Pack,
    g: Grid,
    lambda_samples: usize,
    xyz: &[f32],
    point: bool,
    quantity: &str,
) -> Response {
    let (a, lo) = if point {
        (half::f16::ONE.to_bits(), 0.0)
    } else {
        (half::f16::ZERO.to_bits(), f32::NEG_INFINITY)
    };
    let data = xyz
        .chunks_exact(3)
        .flat_map(|c| {
            let h = |v: f32| half::f16::from_f32(v.max(lo)).to_bits();
            [h(c[0]), h(c[1]), h(c[2]), a]
        })
        .collect();
    Response {
        info: Info {
            format: FORMAT.to_string(),
            version: VERSION,
            generator: format!("sunbeam-response {}", env!("CARGO_PKG_VERSION")),
            grid: g,
            lambda_samples,
            lambda_range_nm: [cie::DEFAULT_RANGE_NM.0, cie::DEFAULT_RANGE_NM.1],
            quantity: quantity.to_string(),
            pack: pack.manifest.clone(),
            energy: None,
        },
        data,
    }
}

/// The pack's terms tap-major (the N values of one texel contiguous, even `n`
/// first), rearranged so that `c_n F_n = i^n a_n F_n` becomes two real dot
/// products: `A = a.G + i a.H` with `G_n = Re F_n, H_n = Im F_n` for even `n`
/// and `G_n = -Im F_n, H_n = Re F_n` for odd `n`.
struct Terms {
    g: Vec<f32>,
    h: Vec<f32>,
    /// Number of terms, and of even ones.
    nt: usize,
    ne: usize,
}

impl Terms {
    fn new(pack: &Pack) -> Terms {
        let m = &pack.manifest;
        let (nt, cw, ch) = (m.terms, m.crop.width, m.crop.height);
        let ne = nt.div_ceil(2);
        let (mut g, mut h) = (vec![0.0f32; cw * ch * nt], vec![0.0f32; cw * ch * nt]);
        for n in 0..nt {
            for ty in 0..ch {
                for tx in 0..cw {
                    let [re, im] = pack.texel(n, tx, ty);
                    let o = (ty * cw + tx) * nt + Self::slot(n, ne);
                    (g[o], h[o]) = if n % 2 == 0 { (re, im) } else { (-im, re) };
                }
            }
        }
        Terms { g, h, nt, ne }
    }

    fn slot(n: usize, ne: usize) -> usize {
        if n.is_multiple_of(2) {
            n / 2
        } else {
            ne + n / 2
        }
    }

    /// `G` and `H` interpolated at bin coordinates `(kx, ky)` (zero outside
    /// the crop), and with `deriv = Some((a, dg, dh))` their derivative along
    /// the direction `a` in bin coordinates, `a . grad_kappa`, from the
    /// kernel's derivative (window model).
    #[allow(clippy::too_many_arguments)]
    fn interpolate(
        &self,
        pack: &Pack,
        kb: &KbTable,
        (kx, ky): (f64, f64),
        t: &mut TapBuf,
        gr: &mut [f32],
        hi: &mut [f32],
        mut deriv: Option<RayDerivative>,
    ) {
        gr.iter_mut().for_each(|v| *v = 0.0);
        hi.iter_mut().for_each(|v| *v = 0.0);
        if let Some((_, dg, dh)) = deriv.as_mut() {
            dg.iter_mut().for_each(|v| *v = 0.0);
            dh.iter_mut().for_each(|v| *v = 0.0);
        }
        let with_d = deriv.is_some();
        if !taps(
            pack,
            kb,
            kx,
            0,
            &mut t.ix,
            &mut t.wx,
            with_d.then_some(&mut t.dx[..]),
        ) || !taps(
            pack,
            kb,
            ky,
            1,
            &mut t.iy,
            &mut t.wy,
            with_d.then_some(&mut t.dy[..]),
        ) {
            return;
        }
        let (nt, cw) = (self.nt, pack.manifest.crop.width);
        for (a, &yy) in t.iy.iter().enumerate() {
            for (b, &xx) in t.ix.iter().enumerate() {
                let wgt = t.wy[a] * t.wx[b];
                let o = (yy * cw + xx) * nt;
                if let Some(((ax, ay), dg, dh)) = deriv.as_mut() {
                    let dw = *ax * t.dx[b] * t.wy[a] + *ay * t.wx[b] * t.dy[a];
                    if dw != 0.0 {
                        axpy(dg, dw, &self.g[o..o + nt]);
                        axpy(dh, dw, &self.h[o..o + nt]);
                    }
                }
                if wgt == 0.0 {
                    continue;
                }
                axpy(gr, wgt, &self.g[o..o + nt]);
                axpy(hi, wgt, &self.h[o..o + nt]);
            }
        }
    }
}

/// Where [`Terms::interpolate`] puts the terms' derivative along a direction:
/// the direction in bin coordinates and the `G`, `H` outputs.
type RayDerivative<'a> = ((f32, f32), &'a mut [f32], &'a mut [f32]);

/// Scratch for one point's taps.
struct TapBuf {
    ix: Vec<usize>,
    iy: Vec<usize>,
    wx: Vec<f32>,
    wy: Vec<f32>,
    /// The weights' derivatives (window model's grazing term).
    dx: Vec<f32>,
    dy: Vec<f32>,
}

impl TapBuf {
    fn new(n: usize) -> TapBuf {
        TapBuf {
            ix: vec![0; n],
            iy: vec![0; n],
            wx: vec![0.0; n],
            wy: vec![0.0; n],
            dx: vec![0.0; n],
            dy: vec![0.0; n],
        }
    }
}

/// `c_n(t) = i^n a_n` (`a_n` real in both bases) for every (radius row,
/// wavelength, `s`), terms in [`Terms`]' order: `[j][l][n][k]`.
fn coefficients(pack: &Pack, g: &Grid, lambdas: &[f64], terms: &Terms) -> Vec<f32> {
    let m = &pack.manifest;
    let (nt, ne) = (terms.nt, terms.ne);
    (0..g.n_rho)
        .into_par_iter()
        .flat_map_iter(|j| {
            let r = g.r_at(j);
            let wmax = (4.0 - r * r).max(0.0).sqrt();
            let mut coef = vec![0.0f32; lambdas.len() * g.n_s * nt];
            for (l, lambda) in lambdas.iter().enumerate() {
                for k in 0..g.n_s {
                    let w = -g.s_at(k) * wmax;
                    let t = std::f64::consts::TAU / lambda * w * m.height_half_range_m;
                    let c = series::coefficients_f64(m.basis, t, nt);
                    for (n, cn) in c.iter().enumerate() {
                        coef[(l * nt + Terms::slot(n, ne)) * g.n_s + k] =
                            if n % 2 == 0 { cn[0] } else { cn[1] } as f32;
                    }
                }
            }
            coef
        })
        .collect()
}

/// Ray samples per bin along a ray: the window's lobes are about a bin wide, and
/// four-point Lagrange interpolation at 1/8 bin keeps the ray's error below
/// the map's f16 rounding (tests/build.rs checks the map against the pack's
/// own evaluator at texel centres).
const RAY_SAMPLES_PER_BIN: f64 = 8.0;
/// The same with the window's grazing term: where `R_U` is the small
/// difference of the amplitude and its correction (a lobe seen with both
/// directions at the horizon: `R_U ~ 1e-3 R`), the ray's interpolation error
/// is amplified by `|A| / |A_U|`; at 1/8 bin the map was 4e-3 off there
/// (relative to 1e-3), at 1/16 bin 8e-4 (tests/build.rs).
const RAY_SAMPLES_PER_BIN_GRAZING: f64 = 16.0;

/// The window model, one angle pair at a time. Every texel of angle `theta`
/// samples the terms at `f = -q (cos theta, sin theta)` with `q = r / lambda`:
/// one ray of the frequency plane. So the terms are interpolated (Kaiser-Bessel,
/// as the pack defines them) once at fine steps along the ray, and every
/// (radius, wavelength) pair reads that ray with a four-point Lagrange
/// interpolation: 36 taps per point become 4. With the grazing term (`sigma`,
/// the window's width), the terms' derivative along the ray is interpolated
/// alongside (the kernel's derivative taps) and read the same way ([`build`]).
fn window_by_rays(
    pack: &Pack,
    g: &Grid,
    lambdas: &[f64],
    wts: &[Vec<[f32; 3]>],
    terms: &Terms,
    coef: &[f32],
    sigma: Option<f64>,
) -> Vec<Vec<f32>> {
    let m = &pack.manifest;
    let (nt, ne, ns, nl) = (terms.nt, terms.ne, g.n_s, lambdas.len());
    // Per set, a column of n_rho * ns XYZ texels.
    let (nsets, stride) = (wts.len(), g.n_rho * ns * 3);
    let kb = KbTable::new(m.kernel.taps, m.kernel.beta);
    let paired = g.n_theta.is_multiple_of(2);
    let n_direct = if paired { g.n_theta / 2 } else { g.n_theta };
    let lambda_min = lambdas.iter().copied().fold(f64::INFINITY, f64::min);
    let grazing = sigma.is_some();
    // beta = r lambda / (4 pi^2 sigma^2 (r^2 + w^2)) = kr / (r^2 + w^2).
    let beta_scale = sigma.map_or(0.0, |sg| {
        1.0 / (4.0 * std::f64::consts::PI * std::f64::consts::PI * sg * sg)
    });
    let cols: Vec<(Vec<f32>, Vec<f32>)> = (0..n_direct)
        .into_par_iter()
        .map(|i| {
            let th = g.theta_at(i);
            // Bin coordinates per unit of q along this ray.
            let a = (-th.cos() * m.bin_scale_m[0], -th.sin() * m.bin_scale_m[1]);
            let len = a.0.hypot(a.1).max(1e-30);
            let per_bin = if grazing {
                RAY_SAMPLES_PER_BIN_GRAZING
            } else {
                RAY_SAMPLES_PER_BIN
            };
            let dq = 1.0 / (per_bin * len);
            let n_q = (2.0 / lambda_min / dq).ceil() as usize + 4;
            // Samples at q = (p - 1) dq, p = 0..n_q (one before zero for the stencil).
            let mut ray_g = vec![0.0f32; n_q * nt];
            let mut ray_h = vec![0.0f32; n_q * nt];
            // The derivative along the ray, dA/dq = a . grad_kappa A (grazing term only).
            let nd = if grazing { n_q * nt } else { 0 };
            let (mut ray_dg, mut ray_dh) = (vec![0.0f32; nd], vec![0.0f32; nd]);
            let mut tb = TapBuf::new(m.kernel.taps);
            let a32 = (a.0 as f32, a.1 as f32);
            for p in 0..n_q {
                let q = (p as f64 - 1.0) * dq;
                let (gs, hs) = (
                    &mut ray_g[p * nt..(p + 1) * nt],
                    &mut ray_h[p * nt..(p + 1) * nt],
                );
                let deriv = grazing.then(|| {
                    (
                        a32,
                        &mut ray_dg[p * nt..(p + 1) * nt],
                        &mut ray_dh[p * nt..(p + 1) * nt],
                    )
                });
                terms.interpolate(pack, &kb, (a.0 * q, a.1 * q), &mut tb, gs, hs, deriv);
            }
            let mut col = vec![0.0f32; nsets * stride];
            let mut col_m = vec![0.0f32; if paired { nsets * stride } else { 0 }];
            let (mut gr, mut hi) = (vec![0.0f32; nt], vec![0.0f32; nt]);
            let (mut dgr, mut dhi) = (vec![0.0f32; nt], vec![0.0f32; nt]);
            let mut beta = vec![0.0f32; ns];
            let mut pw = Powers::new(ns);
            for j in 0..g.n_rho {
                let r = g.r_at(j);
                let wmax = (4.0 - r * r).max(0.0).sqrt();
                for (l, lambda) in lambdas.iter().enumerate() {
                    let x = r / lambda / dq + 1.0;
                    let p0 = (x.floor() as usize).max(1);
                    if p0 + 2 >= n_q {
                        continue;
                    }
                    let f = (x - p0 as f64) as f32;
                    let lag = [
                        -f * (f - 1.0) * (f - 2.0) / 6.0,
                        (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0,
                        -(f + 1.0) * f * (f - 2.0) / 2.0,
                        (f + 1.0) * f * (f - 1.0) / 6.0,
                    ];
                    gr.iter_mut().for_each(|v| *v = 0.0);
                    hi.iter_mut().for_each(|v| *v = 0.0);
                    for (d, &wv) in lag.iter().enumerate() {
                        let o = (p0 - 1 + d) * nt;
                        axpy(&mut gr, wv, &ray_g[o..o + nt]);
                        axpy(&mut hi, wv, &ray_h[o..o + nt]);
                    }
                    let cl = &coef[(j * nl + l) * ns * nt..(j * nl + l + 1) * ns * nt];
                    pw.eval(cl, &gr, &hi, ne);
                    if grazing {
                        dgr.iter_mut().for_each(|v| *v = 0.0);
                        dhi.iter_mut().for_each(|v| *v = 0.0);
                        for (d, &wv) in lag.iter().enumerate() {
                            let o = (p0 - 1 + d) * nt;
                            axpy(&mut dgr, wv, &ray_dg[o..o + nt]);
                            axpy(&mut dhi, wv, &ray_dh[o..o + nt]);
                        }
                        pw.eval_d(cl, &dgr, &dhi, ne);
                        let kr = r * lambda * beta_scale;
                        for (k, b) in beta.iter_mut().enumerate() {
                            let w = g.s_at(k) * wmax;
                            let q2 = r * r + w * w;
                            *b = if q2 > 0.0 { (kr / q2) as f32 } else { 0.0 };
                        }
                    }
                    for (k, &bk) in beta.iter().enumerate() {
                        let (p, q) = if grazing { pw.at_u(k, bk) } else { pw.at(k) };
                        for (si, wt) in wts.iter().enumerate() {
                            let (wt, o) = (wt[l], si * stride + (j * ns + k) * 3);
                            for c in 0..3 {
                                col[o + c] += p * wt[c];
                            }
                            if paired {
                                for c in 0..3 {
                                    col_m[o + c] += q * wt[c];
                                }
                            }
                        }
                    }
                }
            }
            (col, col_m)
        })
        .collect();
    let mut out = vec![vec![0.0f32; g.texels() * 3]; nsets];
    for (si, xyz) in out.iter_mut().enumerate() {
        for (i, (col, col_m)) in cols.iter().enumerate() {
            for j in 0..g.n_rho {
                for k in 0..ns {
                    let src = si * stride + (j * ns + k) * 3;
                    let at = |i: usize| ((k * g.n_rho + j) * g.n_theta + i) * 3;
                    xyz[at(i)..at(i) + 3].copy_from_slice(&col[src..src + 3]);
                    if paired {
                        xyz[at(i + n_direct)..at(i + n_direct) + 3]
                            .copy_from_slice(&col_m[src..src + 3]);
                    }
                }
            }
        }
    }
    out
}

/// The tiled model (a Gaussian-weighted sum of per-bin powers, not an
/// interpolated amplitude), one radius row at a time, each (texel, wavelength)
/// from its own taps.
fn tiled_by_rows(
    pack: &Pack,
    g: &Grid,
    lambdas: &[f64],
    wts: &[Vec<[f32; 3]>],
    terms: &Terms,
    coef: &[f32],
) -> Vec<Vec<f32>> {
    let m = &pack.manifest;
    let (nt, ne, ns, nl) = (terms.nt, terms.ne, g.n_s, lambdas.len());
    // Per set, a row of n_theta * ns XYZ texels.
    let (nsets, stride) = (wts.len(), g.n_theta * ns * 3);
    let cw = m.crop.width;
    let kb = KbTable::new(m.kernel.taps, m.kernel.beta);
    let paired = g.n_theta.is_multiple_of(2);
    let n_direct = if paired { g.n_theta / 2 } else { g.n_theta };
    let rows: Vec<Vec<f32>> = (0..g.n_rho)
        .into_par_iter()
        .map(|j| {
            let r = g.r_at(j);
            let mut out = vec![0.0f32; nsets * stride];
            let mut tb = TapBuf::new(m.kernel.taps);
            let (mut rs, mut rm) = (vec![0.0f32; ns], vec![0.0f32; ns]);
            let mut pw = Powers::new(ns);
            for i in 0..n_direct {
                let th = g.theta_at(i);
                let (cu, su) = (r * th.cos(), r * th.sin());
                for (l, lambda) in lambdas.iter().enumerate() {
                    let kx = -cu / lambda * m.bin_scale_m[0];
                    let ky = -su / lambda * m.bin_scale_m[1];
                    if !taps(pack, &kb, kx, 0, &mut tb.ix, &mut tb.wx, None)
                        || !taps(pack, &kb, ky, 1, &mut tb.iy, &mut tb.wy, None)
                    {
                        continue;
                    }
                    let cl = &coef[(j * nl + l) * ns * nt..(j * nl + l + 1) * ns * nt];
                    rs.iter_mut().for_each(|v| *v = 0.0);
                    rm.iter_mut().for_each(|v| *v = 0.0);
                    for (a, &yy) in tb.iy.iter().enumerate() {
                        for (b, &xx) in tb.ix.iter().enumerate() {
                            let wgt = tb.wy[a] * tb.wx[b];
                            if wgt == 0.0 {
                                continue;
                            }
                            let o = (yy * cw + xx) * nt;
                            let (sg, sh) = (&terms.g[o..o + nt], &terms.h[o..o + nt]);
                            pw.eval(cl, sg, sh, ne);
                            for k in 0..ns {
                                let (p, q) = pw.at(k);
                                rs[k] += wgt * p;
                                rm[k] += wgt * q;
                            }
                        }
                    }
                    let mut add = |i: usize, rr: &[f32]| {
                        for (si, wt) in wts.iter().enumerate() {
                            let wt = wt[l];
                            for (k, rk) in rr.iter().enumerate() {
                                let o = si * stride + (k * g.n_theta + i) * 3;
                                for c in 0..3 {
                                    out[o + c] += rk * wt[c];
                                }
                            }
                        }
                    };
                    add(i, &rs);
                    if paired {
                        add(i + n_direct, &rm);
                    }
                }
            }
            out
        })
        .collect();
    let mut out = vec![vec![0.0f32; g.texels() * 3]; nsets];
    for (si, xyz) in out.iter_mut().enumerate() {
        for (j, row) in rows.iter().enumerate() {
            for k in 0..ns {
                for i in 0..g.n_theta {
                    let (src, dst) = (
                        si * stride + (k * g.n_theta + i) * 3,
                        ((k * g.n_rho + j) * g.n_theta + i) * 3,
                    );
                    xyz[dst..dst + 3].copy_from_slice(&row[src..src + 3]);
                }
            }
        }
    }
    out
}
