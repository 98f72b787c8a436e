//! The ground truth of PHYSICS.md 2 and 4: `R(u, v, w, lambda)` computed
//! directly in float64 for both models, and the colour integral at 1 nm.
//!
//! This module shares no code with `sunbeam-pack` (no FFT, no basis expansion,
//! no interpolation): every query is an O(M^2) direct sum over the pixels.
//!
//! Conventions (PHYSICS.md 1): pixel `(r, c)` sits at `x = c dx`,
//! `y = (My - 1 - r) dy` (row 0 at the top, y up); `(u, v, w) = -wi - wr`;
//! `f = -(u, v) / lambda`; `k = 2 pi / lambda`.
//!
//! **Window model**: `R(f) = |sum_j g_j e^{i k w h_j} e^{-2 pi i f.(x_j - x_c)}|^2 / (sum_j g_j)^2`
//! with `x_c` the patch centre, taken as the mean of the pixel positions
//! `((Mx-1) dx / 2, (My-1) dy / 2)`, and `g` the Gaussian centred there with
//! `sigma = min(coherence/(4 sqrt 2), Lmin/6)`, `Lmin = min(Mx dx, My dy)`.
//!
//! **Tiled model**: `R(f) = sum_b |Pd[b]|^2 phi(f - b/L) / (Mx My)^2` with
//! `Pd` the DFT of `exp(i k w h)` over the pixel indices `(c, My-1-r)`, the
//! signed bins `b_x in [-floor(Mx/2), Mx-1-floor(Mx/2)]` (each DFT bin once),
//! and `phi(df) = exp(-|df|^2 / (2 sigma_f^2))`, `sigma_f = 1/(2 pi sigma_s)`,
//! `sigma_s = coherence/4`. Bins where `phi < 1e-18` are skipped (their
//! contribution is below 1e-18 each, since `|Pd|^2 <= (Mx My)^2`). `Pd` is
//! computed by a direct (separable) DFT at just the bins needed.
//!
//! Heights enter only through `e^{i k w (h - hc)}` with `hc` the centre of the
//! height range (a constant phase, which `|.|^2` ignores) for accuracy.

use crate::{cie, gain};
use std::f64::consts::PI;
use sunbeam_common::{Error, Result};
use sunbeam_field::HeightField;

/// What lies beyond the measured patch (PHYSICS.md 2): the one enum for it
/// where the crates meet (the ground truth, the pack manifest as
/// `sunbeam_pack::Model`, the tools' `--model window|tiled`; serialised
/// `"window"` / `"tiled"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Model {
    /// A Gaussian coherence window over one patch, amplitudes interpolated in
    /// the pack (NUFFT). The default.
    #[default]
    Window,
    /// The patch repeated periodically (the thesis): power per DFT bin,
    /// broadened by a Gaussian.
    Tiled,
}

impl Model {
    /// The names `--model` accepts, in `Model` order.
    pub const NAMES: [&'static str; 2] = ["window", "tiled"];
}

impl Model {
    pub fn name(&self) -> &'static str {
        match self {
            Model::Window => "window",
            Model::Tiled => "tiled",
        }
    }
}

impl std::str::FromStr for Model {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "window" => Ok(Model::Window),
            "tiled" => Ok(Model::Tiled),
            _ => Err(Error::usage(format!("unknown model '{s}' (window, tiled)"))),
        }
    }
}

impl std::fmt::Display for Model {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Default coherence length of the light, metres (PHYSICS.md 2).
pub const DEFAULT_COHERENCE_M: f64 = 65e-6;

/// Parameters of the ground truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    pub model: Model,
    /// Spatial coherence length of the light, metres (65 um by default).
    pub coherence_m: f64,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            model: Model::Window,
            coherence_m: DEFAULT_COHERENCE_M,
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct C64 {
    re: f64,
    im: f64,
}

impl C64 {
    const ZERO: C64 = C64 { re: 0.0, im: 0.0 };
    #[inline]
    fn cis(a: f64) -> C64 {
        let (s, c) = a.sin_cos();
        C64 { re: c, im: s }
    }
    #[inline]
    fn mul(self, o: C64) -> C64 {
        C64 {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    #[inline]
    fn scale(self, s: f64) -> C64 {
        C64 {
            re: self.re * s,
            im: self.im * s,
        }
    }
    #[inline]
    fn add(self, o: C64) -> C64 {
        C64 {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
    #[inline]
    fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
}

/// Heights as a small table of distinct levels plus an index per pixel (8-bit
/// height maps have at most 256 levels), or one value per pixel.
#[derive(Debug, Clone)]
enum Heights {
    Levels { values: Vec<f64>, index: Vec<u16> },
    Direct(Vec<f64>),
}

/// The ground truth for one height field (see the module docs).
#[derive(Debug, Clone)]
pub struct Truth {
    params: Params,
    mx: usize,
    my: usize,
    dx: f64,
    dy: f64,
    /// h - hc, row-major, row 0 at the top.
    heights: Heights,
    /// Window model: x_c - centre per column, y - centre per row.
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// Window model: separable Gaussian factors and their sums.
    gx: Vec<f64>,
    gy: Vec<f64>,
    gsum: f64,
    sigma_window_m: f64,
    /// Tiled model: twiddles e^{-2 pi i m / M} for m = 0..M.
    twx: Vec<C64>,
    twy: Vec<C64>,
    sigma_f: f64,
    height_centre_m: f64,
    height_half_range_m: f64,
}

/// `phi < 1e-18` beyond this many sigma_f: sqrt(2 ln 1e18).
const PHI_CUTOFF_SIGMAS: f64 = 9.1;

impl Truth {
    /// Prepare the ground truth of `field`. Fails (input error) on non-finite
    /// heights or a non-positive coherence length.
    pub fn new(field: &HeightField, p: &Params) -> Result<Truth> {
        let (mx, my) = (field.width, field.height);
        if mx == 0 || my == 0 || field.data.len() != mx * my {
            return Err(Error::input(format!(
                "height field has {} values for {mx}x{my} pixels",
                field.data.len()
            )));
        }
        if !(field.dx.is_finite() && field.dx > 0.0 && field.dy.is_finite() && field.dy > 0.0) {
            return Err(Error::input(format!(
                "pixel size must be finite and positive (dx={}, dy={})",
                field.dx, field.dy
            )));
        }
        let bad = field.count_nonfinite();
        if bad > 0 {
            return Err(Error::input(format!(
                "height field has {bad} non-finite heights (NaN/Inf): fill them before computing the ground truth"
            )));
        }
        if !(p.coherence_m.is_finite() && p.coherence_m > 0.0) {
            return Err(Error::usage(format!(
                "coherence length must be finite and positive (got {})",
                p.coherence_m
            )));
        }
        let (lo, hi) = field.finite_range().unwrap_or((0.0, 0.0));
        let hc = 0.5 * (lo + hi);
        let centred: Vec<f64> = field.data.iter().map(|h| h - hc).collect();
        let heights = levels_of(&centred).unwrap_or(Heights::Direct(centred));

        let (dx, dy) = (field.dx, field.dy);
        let xs: Vec<f64> = (0..mx)
            .map(|c| (c as f64 - 0.5 * (mx as f64 - 1.0)) * dx)
            .collect();
        let ys: Vec<f64> = (0..my)
            .map(|r| ((my - 1 - r) as f64 - 0.5 * (my as f64 - 1.0)) * dy)
            .collect();
        let lmin = (mx as f64 * dx).min(my as f64 * dy);
        let sigma = (p.coherence_m / (4.0 * std::f64::consts::SQRT_2)).min(lmin / 6.0);
        let gauss = |d: f64| (-(d * d) / (2.0 * sigma * sigma)).exp();
        let gx: Vec<f64> = xs.iter().map(|&x| gauss(x)).collect();
        let gy: Vec<f64> = ys.iter().map(|&y| gauss(y)).collect();
        let gsum = gx.iter().sum::<f64>() * gy.iter().sum::<f64>();

        let tw = |m: usize| -> Vec<C64> {
            (0..m)
                .map(|j| C64::cis(-2.0 * PI * j as f64 / m as f64))
                .collect()
        };
        let sigma_s = p.coherence_m / 4.0;
        Ok(Truth {
            params: *p,
            mx,
            my,
            dx,
            dy,
            heights,
            xs,
            ys,
            gx,
            gy,
            gsum,
            sigma_window_m: sigma,
            twx: tw(mx),
            twy: tw(my),
            sigma_f: 1.0 / (2.0 * PI * sigma_s),
            height_centre_m: hc,
            height_half_range_m: 0.5 * (hi - lo),
        })
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Grid size (Mx, My) and pixel size (dx, dy).
    pub fn grid(&self) -> (usize, usize, f64, f64) {
        (self.mx, self.my, self.dx, self.dy)
    }

    /// The window model's Gaussian sigma in metres: `min(coherence/(4 sqrt 2), Lmin/6)`.
    pub fn window_sigma_m(&self) -> f64 {
        self.sigma_window_m
    }

    /// The tiled model's broadening `sigma_f` in cycles per metre.
    pub fn tiled_sigma_f(&self) -> f64 {
        self.sigma_f
    }

    /// The effective coherent area `A` (square metres) that turns `R` into a
    /// BRDF for extended light: `f_r cos(theta_i) = G R A / lambda^2`, so that
    /// `L_o = integral L(wi) G R (A / lambda^2) cos(theta_i) dw_i`
    /// (docs/LIGHTING.md). By Parseval, `integral R d^2f = 1 / A` for every
    /// surface: window model `A = (sum g)^2 / sum g^2 * dx dy`; tiled model
    /// `A = 1 / (2 pi sigma_f^2) = 2 pi (coherence / 4)^2`.
    pub fn coherent_area_m2(&self) -> f64 {
        match self.params.model {
            Model::Window => {
                let s2 = |g: &[f64]| g.iter().map(|v| v * v).sum::<f64>();
                self.gsum * self.gsum / (s2(&self.gx) * s2(&self.gy)) * self.dx * self.dy
            }
            Model::Tiled => 1.0 / (2.0 * PI * self.sigma_f * self.sigma_f),
        }
    }

    /// Centre and half range of the heights, metres.
    pub fn height_centre_and_half_range(&self) -> (f64, f64) {
        (self.height_centre_m, self.height_half_range_m)
    }

    /// `R(u, v, w, lambda)` (PHYSICS.md 2), relative to a perfect flat mirror.
    /// NaN when an argument is not finite or `lambda_m <= 0`.
    pub fn reflectance(&self, u: f64, v: f64, w: f64, lambda_m: f64) -> f64 {
        if !(u.is_finite()
            && v.is_finite()
            && w.is_finite()
            && lambda_m.is_finite()
            && lambda_m > 0.0)
        {
            return f64::NAN;
        }
        let fx = -u / lambda_m;
        let fy = -v / lambda_m;
        let kw = 2.0 * PI / lambda_m * w;
        match self.params.model {
            Model::Window => self.window(fx, fy, kw),
            Model::Tiled => self.tiled(fx, fy, kw),
        }
    }

    /// `R` at a spatial frequency `f = (fx, fy)` (cycles per metre) and phase
    /// factor `t' = k w` (radians per metre of height).
    pub fn reflectance_at_frequency(&self, fx: f64, fy: f64, kw: f64) -> f64 {
        match self.params.model {
            Model::Window => self.window(fx, fy, kw),
            Model::Tiled => self.tiled(fx, fy, kw),
        }
    }

    /// Per-pixel phasors `e^{i kw (h - hc)}`, row-major, built by `f(r, c, phasor)`.
    fn phasor_rows(&self, kw: f64, mut per_row: impl FnMut(usize, &mut dyn Iterator<Item = C64>)) {
        match &self.heights {
            Heights::Levels { values, index } => {
                let table: Vec<C64> = values.iter().map(|&h| C64::cis(kw * h)).collect();
                for r in 0..self.my {
                    let row = &index[r * self.mx..(r + 1) * self.mx];
                    per_row(r, &mut row.iter().map(|&i| table[i as usize]));
                }
            }
            Heights::Direct(h) => {
                for r in 0..self.my {
                    let row = &h[r * self.mx..(r + 1) * self.mx];
                    per_row(r, &mut row.iter().map(|&h| C64::cis(kw * h)));
                }
            }
        }
    }

    fn window(&self, fx: f64, fy: f64, kw: f64) -> f64 {
        let ex: Vec<C64> = self
            .xs
            .iter()
            .zip(&self.gx)
            .map(|(&x, &g)| C64::cis(-2.0 * PI * fx * x).scale(g))
            .collect();
        let mut total = C64::ZERO;
        self.phasor_rows(kw, |r, row| {
            let mut acc = C64::ZERO;
            for (p, e) in row.zip(&ex) {
                acc = acc.add(p.mul(*e));
            }
            let ey = C64::cis(-2.0 * PI * fy * self.ys[r]).scale(self.gy[r]);
            total = total.add(acc.mul(ey));
        });
        total.norm2() / (self.gsum * self.gsum)
    }

    fn bin_range(f: f64, l: f64, m: usize, rc: f64) -> (i64, i64) {
        let lo_signed = -((m / 2) as i64);
        let hi_signed = m as i64 - 1 - (m / 2) as i64;
        let lo = ((f - rc) * l).ceil();
        let hi = ((f + rc) * l).floor();
        let lo = if lo.is_finite() {
            (lo.max(lo_signed as f64)) as i64
        } else {
            lo_signed
        };
        let hi = if hi.is_finite() {
            (hi.min(hi_signed as f64)) as i64
        } else {
            hi_signed
        };
        (lo, hi)
    }

    fn tiled(&self, fx: f64, fy: f64, kw: f64) -> f64 {
        let (lx, ly) = (self.mx as f64 * self.dx, self.my as f64 * self.dy);
        let rc = PHI_CUTOFF_SIGMAS * self.sigma_f;
        let (bx0, bx1) = Self::bin_range(fx, lx, self.mx, rc);
        let (by0, by1) = Self::bin_range(fy, ly, self.my, rc);
        if bx0 > bx1 || by0 > by1 {
            return 0.0;
        }
        let two_s2 = 2.0 * self.sigma_f * self.sigma_f;
        let phi_x: Vec<f64> = (bx0..=bx1)
            .map(|b| (-(fx - b as f64 / lx).powi(2) / two_s2).exp())
            .collect();
        let phi_y: Vec<f64> = (by0..=by1)
            .map(|b| (-(fy - b as f64 / ly).powi(2) / two_s2).exp())
            .collect();
        let nbx = phi_x.len();
        // Row transforms at the needed bx: q[r][i] = sum_c p[r][c] e^{-2 pi i bx c / Mx}.
        let mut q = vec![C64::ZERO; self.my * nbx];
        let mx = self.mx as i64;
        self.phasor_rows(kw, |r, row| {
            let row: Vec<C64> = row.collect();
            for (i, b) in (bx0..=bx1).enumerate() {
                let mut acc = C64::ZERO;
                for (c, p) in row.iter().enumerate() {
                    let m = (b * c as i64).rem_euclid(mx) as usize;
                    acc = acc.add(p.mul(self.twx[m]));
                }
                q[r * nbx + i] = acc;
            }
        });
        let my = self.my as i64;
        let mut sum = 0.0;
        for (j, b) in (by0..=by1).enumerate() {
            for (i, px) in phi_x.iter().enumerate() {
                let phi = px * phi_y[j];
                if phi < 1e-18 {
                    continue;
                }
                let mut acc = C64::ZERO;
                for r in 0..self.my {
                    let jy = (self.my - 1 - r) as i64;
                    let m = (b * jy).rem_euclid(my) as usize;
                    acc = acc.add(q[r * nbx + i].mul(self.twy[m]));
                }
                sum += acc.norm2() * phi;
            }
        }
        let n = (self.mx * self.my) as f64;
        sum / (n * n)
    }

    /// XYZ of the reflected light for local directions `wi` (to the light) and
    /// `wr` (to the viewer), PHYSICS.md 2: the 1 nm integral over 380..780 nm
    /// of `R S cmf / sum S ybar`, times `G` (the thesis' relative
    /// normalisation: a flat patch head-on gives Y = 1, so `R` reads directly).
    pub fn colour_xyz(&self, wi_local: [f64; 3], wr_local: [f64; 3]) -> [f64; 3] {
        self.colour_xyz_with(
            wi_local,
            wr_local,
            cie::DEFAULT_RANGE_NM,
            gain::Material::RELATIVE,
        )
    }

    /// [`Truth::colour_xyz`] with an explicit wavelength range (nm, inclusive, 1 nm
    /// steps) and skin material (index, normalisation).
    pub fn colour_xyz_with(
        &self,
        wi: [f64; 3],
        wr: [f64; 3],
        range_nm: (u32, u32),
        mat: gain::Material,
    ) -> [f64; 3] {
        let g = gain::g(wi, wr, mat);
        if g == 0.0 {
            return [0.0; 3];
        }
        let (u, v, w) = (-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]);
        let xyz = cie::integrate_xyz_1nm(range_nm, |l| self.reflectance(u, v, w, l));
        xyz.map(|c| c * g)
    }
}

/// Distinct levels of `h` when there are at most 4096 of them.
fn levels_of(h: &[f64]) -> Option<Heights> {
    let mut vals: Vec<f64> = h.to_vec();
    vals.sort_by(|a, b| a.total_cmp(b));
    vals.dedup();
    if vals.len() > 4096 {
        return None;
    }
    let index = h
        .iter()
        .map(|x| vals.binary_search_by(|v| v.total_cmp(x)).map(|i| i as u16))
        .collect::<std::result::Result<Vec<u16>, usize>>()
        .ok()?;
    Some(Heights::Levels {
        values: vals,
        index,
    })
}

/// The window model's coherent area `A = (sum g)^2 / sum g^2 dx dy` (docs/LIGHTING.md)
/// of an `mx x my` patch of pixel `dx x dy` under the Gaussian window of `sigma_m`
/// centred on the patch: what [`Truth::coherent_area_m2`] gives, from a pack's
/// manifest alone.
pub fn window_coherent_area_m2(mx: usize, my: usize, dx: f64, dy: f64, sigma_m: f64) -> f64 {
    let axis = |m: usize, d: f64| {
        let (mut s1, mut s2) = (0.0, 0.0);
        for c in 0..m {
            let x = (c as f64 - 0.5 * (m as f64 - 1.0)) * d;
            let g = (-(x * x) / (2.0 * sigma_m * sigma_m)).exp();
            s1 += g;
            s2 += g * g;
        }
        s1 * s1 / s2
    };
    axis(mx, dx) * axis(my, dy) * dx * dy
}

/// The tiled model's coherent area `1 / (2 pi sigma_f^2)` (docs/LIGHTING.md).
pub fn tiled_coherent_area_m2(sigma_f_per_m: f64) -> f64 {
    1.0 / (2.0 * PI * sigma_f_per_m * sigma_f_per_m)
}
