//! CIE 1931 2-degree colour matching functions and CIE standard illuminant D65,
//! tabulated at 1 nm from 360 to 830 nm (sources named in `cie_data.rs`:
//! the CIE's own data sets), and the colour integral of PHYSICS.md 2:
//!
//! ```text
//! XYZ = integral R S [xbar, ybar, zbar] dlambda / integral S ybar dlambda
//! ```
//!
//! evaluated as a sum over the 1 nm rows (the reference; every `step`-th row
//! where R is smooth enough: [`integrate_xyz_nm_step`]) so that `R = 1` gives
//! the D65 white with `Y = 1` exactly.

use crate::cie_data;

pub use crate::cie_data::{FIRST_NM, LAST_NM};

/// Default integration range of PHYSICS.md 2, nm (inclusive).
pub const DEFAULT_RANGE_NM: (u32, u32) = (380, 780);

/// `[xbar, ybar, zbar]` at an integer wavelength in nm; zero outside 360..=830.
pub fn cmf_nm(nm: u32) -> [f64; 3] {
    if (FIRST_NM..=LAST_NM).contains(&nm) {
        cie_data::CMF_1931_2DEG[(nm - FIRST_NM) as usize]
    } else {
        [0.0; 3]
    }
}

/// D65 relative spectral power (100 at 560 nm) at an integer wavelength in nm; zero outside 360..=830.
pub fn d65_nm(nm: u32) -> f64 {
    if (FIRST_NM..=LAST_NM).contains(&nm) {
        cie_data::D65[(nm - FIRST_NM) as usize]
    } else {
        0.0
    }
}

fn interp_index(lambda_m: f64) -> Option<(usize, f64)> {
    let nm = lambda_m * 1e9;
    if !(nm >= FIRST_NM as f64 && nm <= LAST_NM as f64) {
        return None;
    }
    let x = nm - FIRST_NM as f64;
    let i = (x.floor() as usize).min((LAST_NM - FIRST_NM - 1) as usize);
    Some((i, x - i as f64))
}

/// `[xbar, ybar, zbar]` at any wavelength (metres), linearly interpolated between the
/// 1 nm samples; zero outside 360..830 nm.
pub fn cmf_at(lambda_m: f64) -> [f64; 3] {
    match interp_index(lambda_m) {
        None => [0.0; 3],
        Some((i, t)) => {
            let a = cie_data::CMF_1931_2DEG[i];
            let b = cie_data::CMF_1931_2DEG[i + 1];
            [
                a[0] + t * (b[0] - a[0]),
                a[1] + t * (b[1] - a[1]),
                a[2] + t * (b[2] - a[2]),
            ]
        }
    }
}

/// D65 at any wavelength (metres), linearly interpolated; zero outside 360..830 nm.
pub fn d65_at(lambda_m: f64) -> f64 {
    match interp_index(lambda_m) {
        None => 0.0,
        Some((i, t)) => cie_data::D65[i] + t * (cie_data::D65[i + 1] - cie_data::D65[i]),
    }
}

/// `sum S(l) ybar(l)` over `lo..=hi` nm at 1 nm: the normaliser of PHYSICS.md 2.
pub fn d65_y_norm(range_nm: (u32, u32)) -> f64 {
    (range_nm.0..=range_nm.1)
        .map(|nm| d65_nm(nm) * cmf_nm(nm)[1])
        .sum()
}

/// The colour integral at 1 nm: `sum R(l) S(l) cmf(l) / sum S(l) ybar(l)` over
/// `range_nm` (inclusive), `r` called with the wavelength in metres. `R = 1`
/// gives the D65 white point of that range with `Y = 1` exactly.
pub fn integrate_xyz_1nm(range_nm: (u32, u32), r: impl FnMut(f64) -> f64) -> [f64; 3] {
    integrate_xyz_nm_step(range_nm, 1, r)
}

/// [`integrate_xyz_1nm`] over every `step_nm`-th row of the 1 nm tables
/// (`lo, lo + step, ...` up to `hi`; step 1 is [`integrate_xyz_1nm`]): the
/// normaliser sums the same rows, so `R = 1` still gives `Y = 1` exactly. For a
/// reflectance smooth at the step's scale (the reference's adaptive step,
/// docs/EVAL.md "Wavelength step").
pub fn integrate_xyz_nm_step(
    range_nm: (u32, u32),
    step_nm: u32,
    mut r: impl FnMut(f64) -> f64,
) -> [f64; 3] {
    let mut acc = [0.0f64; 3];
    let mut norm = 0.0;
    for nm in (range_nm.0..=range_nm.1).step_by(step_nm.max(1) as usize) {
        let s = d65_nm(nm);
        let c = cmf_nm(nm);
        norm += s * c[1];
        let rv = r(nm as f64 * 1e-9) * s;
        acc[0] += rv * c[0];
        acc[1] += rv * c[1];
        acc[2] += rv * c[2];
    }
    if norm > 0.0 {
        acc.map(|a| a / norm)
    } else {
        [0.0; 3]
    }
}

/// XYZ of D65 over `range_nm` normalised to `Y = 1` (the colour of a perfect
/// mirror seen at normal incidence).
pub fn d65_white_xyz(range_nm: (u32, u32)) -> [f64; 3] {
    integrate_xyz_1nm(range_nm, |_| 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_match_published_values() {
        // Spot values from the CIE 1931 2-degree table and the D65 table.
        assert_eq!(cmf_nm(555), [0.5120501, 1.0, 0.005749999]);
        assert_eq!(cmf_nm(600), [1.0622, 0.631, 0.0008]);
        assert_eq!(d65_nm(560), 100.0);
        assert_eq!(d65_nm(380), 49.9755);
        assert_eq!(d65_nm(830), 60.3125);
        assert_eq!(cmf_nm(359), [0.0; 3]);
    }

    #[test]
    fn d65_white_point() {
        // Chromaticity of D65 for the 1931 observer: x = 0.31272, y = 0.32903 (CIE 15).
        let w = d65_white_xyz((360, 830));
        let s = w[0] + w[1] + w[2];
        assert!((w[1] - 1.0).abs() < 1e-15);
        assert!((w[0] / s - 0.31272).abs() < 5e-5, "x = {}", w[0] / s);
        assert!((w[1] / s - 0.32903).abs() < 5e-5, "y = {}", w[1] / s);
        // 380..780 barely differs.
        let w2 = d65_white_xyz(DEFAULT_RANGE_NM);
        assert!((w2[0] - w[0]).abs() < 1e-3 && (w2[2] - w[2]).abs() < 1e-3);
    }

    #[test]
    fn interpolation_hits_samples() {
        assert_eq!(cmf_at(555e-9), cmf_nm(555));
        assert!((d65_at(380.5e-9) - 0.5 * (d65_nm(380) + d65_nm(381))).abs() < 1e-12);
        assert_eq!(d65_at(200e-9), 0.0);
        assert_eq!(cmf_at(f64::NAN), [0.0; 3]);
    }
}
