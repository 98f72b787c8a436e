//! The energy bound's tables (`sunbeam_optics::energy`, docs/LIGHTING.md
//! "Energy bound") of a pack: the directional albedo of the diffraction term
//! under a white furnace (a constant environment of radiance 1, D65 white),
//! its largest linear-sRGB channel, the largest over the view's azimuth, at
//! the table's [`KNOTS`] view cosines.
//!
//! How: the white furnace's map `E_w(u, v, w) = sum_l R (A / l^2) D65 cmf /
//! sum_l D65 ybar` (the extended-light maps' weights for the spectrum D65,
//! [`crate::env::weight_sets`]) on the point map's grid, built in the same
//! pass over the pack as the point map (by `sunbeam_response::build`), and the reference's
//! quadrature over it ([`EnvQuadrature::from_xyz`]: the sum over the texels
//! with the closed form of `G / cos(theta_i)` at the horizon) at
//! [`AZIMUTHS`] azimuths over half a turn (the pack's axes among them) (a real height field's `|FT|^2` is
//! point-symmetric, and so is the map in `(u, v)`).
//!
//! What the bound is tabulated for, and so what every renderer uses (the
//! player, the exports and three.js read the tables from the map's info,
//! [`crate::Info::energy`]; the reference builds the same tables from the
//! pack, [`EnergyInfo::from_pack`]): the default skin (index 1.5, absolute
//! reflectance), without masking and with Smith masking at the pack's rms
//! slopes. A mesh with masking on uses the masked table when the pack has
//! slopes (whatever slopes the scene gives), else the unmasked one; other
//! indices use the tables of 1.5 (at the grazing views where the bound acts,
//! `F(theta_d)` is near 1 for every index). Relative reflectance (divided by
//! `F(0)`, for comparisons with the thesis and plots of `R`) is not bounded:
//! it is by design not an energy balance (a flat patch reflects 1 head-on
//! and `F / F(0) > 1` beyond).

use crate::build::{self, Options, WeightSets};
use crate::grid::Grid;
use crate::quadrature::{EnvQuadrature, Query};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sunbeam_light::{EnvMap, Environment};
use sunbeam_optics::colour;
use sunbeam_optics::energy::{EnergyBound, KNOTS};
use sunbeam_optics::gain::{self, Reflectance};
use sunbeam_optics::masking::Masking;
use sunbeam_pack::Pack;

/// View azimuths per knot, over half a turn.
pub const AZIMUTHS: usize = 8;

/// `cos(theta_r)` at which the first knot (`cos = 0`, where the view is
/// gone) is evaluated: `b = c a(c)` is smooth there.
const GRAZING_COS: f64 = 1e-4;

/// The bound's tables of a pack (in the response map's info).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnergyInfo {
    /// The skin's refractive index the tables were built with.
    pub ior: f64,
    /// `b = cos(theta_r) a` at the knots `t = sqrt(cos(theta_r)) = k / 15`, no masking.
    pub off: Vec<f32>,
    /// The same with Smith masking at the pack's `rms_slope` (None: the pack has none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smith: Option<Vec<f32>>,
}

/// The white furnace's weight set at `n` wavelengths (those of the point map).
pub fn white_weights(pack: &Pack, n: usize) -> Vec<[f64; 3]> {
    let d65 = |l: f64| [sunbeam_optics::cie::d65_at(l), 0.0, 0.0];
    crate::env::weight_sets(pack, n, &[&d65], None)
        .sets
        .swap_remove(0)
}

impl EnergyInfo {
    /// The tables of `pack`, built as `sunbeam-pack --response` builds them
    /// with options `o` (its grid and wavelengths): what the reference uses.
    pub fn from_pack(pack: &Pack, o: &Options) -> EnergyInfo {
        let g = o
            .grid
            .unwrap_or_else(|| build::auto_grid(pack, o.budget_bytes));
        let lambdas = build::wavelength_weights(o.lambda_samples)
            .iter()
            .map(|l| l.0)
            .collect();
        let ws = WeightSets {
            lambdas,
            sets: vec![white_weights(pack, o.lambda_samples)],
        };
        let white = build::build_sets(pack, &g, &ws).swap_remove(0);
        Self::from_white(g, &white, pack.manifest.rms_slope)
    }

    /// The tables from the white furnace's map `white` on grid `g`.
    pub fn from_white(g: Grid, white: &[f32], rms_slope: Option<[f64; 2]>) -> EnergyInfo {
        let (g, white) = coarsen_angle(g, white);
        let q = EnvQuadrature::from_xyz(g, &white);
        let skin = gain::Material::default();
        EnergyInfo {
            ior: skin.ior,
            off: table(&q, skin, Masking::Off).b.to_vec(),
            smith: rms_slope.map(|s| table(&q, skin, Masking::smith(s)).b.to_vec()),
        }
    }

    /// The bound of a mesh with this pack: OFF for relative reflectance, the
    /// masked table when `masked` and the pack has slopes, else the unmasked.
    pub fn bound(&self, skin: gain::Material, masked: bool) -> EnergyBound {
        if skin.reflectance != Reflectance::Absolute {
            return EnergyBound::OFF;
        }
        let b = match (&self.smith, masked) {
            (Some(s), true) => s,
            _ => &self.off,
        };
        let mut e = EnergyBound::OFF;
        if b.len() == KNOTS && b.iter().all(|v| v.is_finite() && *v >= 0.0) {
            e.b.copy_from_slice(b);
        }
        e
    }
}

/// Fewest angle texels of the map the tables integrate.
const MIN_ANGLE_TEXELS: usize = 192;

/// The map with its angle texels merged by the largest power of two that
/// leaves at least [`MIN_ANGLE_TEXELS`]: the tables need the map's integral,
/// not its lobes' shapes, and the quadrature's cost is its texel count
/// (256 views of the 1024 x 289 x 26 map of a 20 um ridge pack: 0.5 s on 2 cores merged to 256 angles).
/// The merge is a tent of the factor's width centred on the coarse texel's
/// angle (weights 1/2 at its ends), so that every fine texel's mass is kept
/// whole and lands on the coarse texels nearest it.
fn coarsen_angle(g: Grid, xyz: &[f32]) -> (Grid, Vec<f32>) {
    let mut f = 1;
    while g.n_theta.is_multiple_of(2 * f) && g.n_theta / (2 * f) >= MIN_ANGLE_TEXELS {
        f *= 2;
    }
    if f == 1 {
        return (g, xyz.to_vec());
    }
    let (nt, nr, ns) = (g.n_theta, g.n_rho, g.n_s);
    let ct = nt / f;
    let mut out = vec![0.0f32; ct * nr * ns * 3];
    let h = f / 2;
    for k in 0..ns {
        for j in 0..nr {
            let row = (k * nr + j) * nt;
            let orow = (k * nr + j) * ct;
            for i in 0..ct {
                let mut acc = [0.0f64; 3];
                for d in 0..=f {
                    let w = if d == 0 || d == f { 0.5 } else { 1.0 };
                    let src = (i * f + nt + d - h) % nt;
                    for c in 0..3 {
                        acc[c] += w * xyz[3 * (row + src) + c] as f64;
                    }
                }
                for c in 0..3 {
                    out[3 * (orow + i) + c] = (acc[c] / f as f64) as f32;
                }
            }
        }
    }
    (Grid { n_theta: ct, ..g }, out)
}

/// The table of `skin` with `masking` over quadrature `q` of a white map.
fn table(q: &EnvQuadrature, skin: gain::Material, masking: Masking) -> EnergyBound {
    let white = white_furnace();
    let b: Vec<f32> = (0..KNOTS)
        .into_par_iter()
        .map(|k| {
            let c = EnergyBound::knot_cos(k).max(GRAZING_COS);
            // Azimuths j pi / AZIMUTHS: the pack's axes (ridges along one
            // of them, seen along it, are the strongest view) among them.
            let queries: Vec<Query> = (0..AZIMUTHS)
                .map(|j| {
                    let phi = std::f64::consts::PI * j as f64 / AZIMUTHS as f64;
                    query(view(c, phi), skin, masking)
                })
                .collect();
            let a = q
                .integrate_many(&white, &queries, (0, 1))
                .into_iter()
                .map(|xyz| max_channel(colour::xyz_to_linear_srgb(xyz)))
                .fold(0.0f64, f64::max);
            (c * a) as f32
        })
        .collect();
    let mut e = EnergyBound::OFF;
    e.b.copy_from_slice(&b);
    e
}

fn max_channel(v: [f64; 3]) -> f64 {
    v[0].max(v[1]).max(v[2])
}

fn white_furnace() -> Environment {
    Environment::Map(EnvMap::constant([1.0; 3]))
}

fn query(wr: [f64; 3], skin: gain::Material, masking: Masking) -> Query {
    Query {
        frame: ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        wr,
        sun_u: [0.5, 0.5],
        masking,
        skin,
    }
}

/// The local view at cosine `c` and azimuth `phi`.
pub fn view(c: f64, phi: f64) -> [f64; 3] {
    let s = (1.0 - c * c).max(0.0).sqrt();
    [s * phi.cos(), s * phi.sin(), c]
}

/// The diffraction term's directional albedo towards local view `wr`,
/// linear sRGB, over quadrature `q` of a white map (
/// [`EnvQuadrature::from_xyz`]), with `skin`'s `G` (its bound applied) and
/// `masking`.
pub fn albedo(q: &EnvQuadrature, wr: [f64; 3], skin: gain::Material, masking: Masking) -> [f64; 3] {
    let xyz = q.integrate_many(&white_furnace(), &[query(wr, skin, masking)], (0, 1))[0];
    colour::xyz_to_linear_srgb(xyz)
}
