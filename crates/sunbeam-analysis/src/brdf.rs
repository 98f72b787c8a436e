//! What `sunbeam-eval brdf` pictures: the colour a pack reflects over the
//! hemisphere of view directions (an orthographic disk of `wr`) for one light,
//! with the automatic exposure, and `R` over (viewing angle, wavelength) in the
//! plane of incidence. The tool draws them (plots stay in the tool).

use crate::sample::percentile;
use crate::source::par_map;
use sunbeam_pack::Pack;

/// The colour over view directions: `size x size` pixels, row 0 at the top,
/// `+x` right, `+y` up (orthographic projection of `wr`); `None` outside the
/// unit disk (`x^2 + y^2 >= 0.999`).
pub struct Hemisphere {
    pub size: usize,
    /// CIE XYZ per pixel, row-major.
    pub xyz: Vec<Option<[f64; 3]>>,
    /// The largest `Y` over the disk.
    pub max_y: f64,
}

impl Hemisphere {
    /// The exposure that maps the 95th percentile of `Y` over the disk to 1
    /// (0 EV when that percentile is not a positive number).
    pub fn auto_exposure_ev(&self) -> f64 {
        let ys: Vec<f64> = self.xyz.iter().flatten().map(|c| c[1]).collect();
        let p = percentile(&ys, 95.0);
        if p > 0.0 && p.is_finite() {
            -p.log2()
        } else {
            0.0
        }
    }
}

/// The colour (`Pack::colour_xyz` with `lambda_samples`) for the light
/// direction `light` over the view hemisphere, `size x size` pixels.
pub fn hemisphere(pack: &Pack, light: [f64; 3], size: usize, lambda_samples: usize) -> Hemisphere {
    let n = size;
    let xyz = par_map(n * n, |k| {
        let (i, j) = (k % n, k / n);
        let x = (i as f64 + 0.5) / n as f64 * 2.0 - 1.0;
        let y = 1.0 - (j as f64 + 0.5) / n as f64 * 2.0;
        let r2 = x * x + y * y;
        if r2 >= 0.999 {
            return None;
        }
        let wr = [x, y, (1.0 - r2).sqrt()];
        Some(pack.colour_xyz(light, wr, lambda_samples))
    });
    let max_y = xyz.iter().flatten().map(|c| c[1]).fold(0.0, f64::max);
    Hemisphere { size, xyz, max_y }
}

/// `R` in the plane of incidence: `lambdas` rows (wavelength cell centres over
/// the pack's range, shortest first) by `angles` columns (signed viewing angle
/// cell centres over -89.5..89.5 degrees, positive on the light's side).
pub struct PlaneGrid {
    pub lambdas: usize,
    pub angles: usize,
    /// Row-major: `r[li * angles + ai]`.
    pub r: Vec<f64>,
}

impl PlaneGrid {
    /// The angle range the columns cover, in degrees.
    pub const ANGLE_RANGE_DEG: (f64, f64) = (-89.5, 89.5);
}

/// `R(wi, wr, lambda)` of `pack` on the plane of incidence of `light`.
pub fn plane_of_incidence(
    pack: &Pack,
    light: [f64; 3],
    lambdas: usize,
    angles: usize,
) -> PlaneGrid {
    let (lt, lp) = (light[2].acos(), light[1].atan2(light[0]));
    let (ca, sa) = (lp.cos(), lp.sin());
    let m = &pack.manifest;
    let (nl, na) = (lambdas, angles);
    let (a0, a1) = PlaneGrid::ANGLE_RANGE_DEG;
    let r = par_map(nl * na, |k| {
        let (li, ai) = (k / na, k % na);
        let l = m.lambda_min_m + (m.lambda_max_m - m.lambda_min_m) * (li as f64 + 0.5) / nl as f64;
        let th = (a0 + (a1 - a0) * (ai as f64 + 0.5) / na as f64).to_radians();
        let wi = [lt.sin() * ca, lt.sin() * sa, lt.cos()];
        let wr = [th.sin() * ca, th.sin() * sa, th.cos()];
        pack.reflectance(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2], l)
    });
    PlaneGrid {
        lambdas: nl,
        angles: na,
        r,
    }
}
