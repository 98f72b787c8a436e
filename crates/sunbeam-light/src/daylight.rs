//! The CIE daylight basis (CIE 15:2004, table T.2): any daylight spectrum is
//! `S0 + M1 S1 + M2 S2`, with `M1`, `M2` from the chromaticity `(x, y)`. The
//! sky model gives a chromaticity per direction, and this turns it into a
//! spectrum, as Preetham et al. (1999, appendix) do. The table is 10 nm over
//! 380..780 nm, linearly interpolated (zero outside).

/// First wavelength of the table, nm.
const FIRST_NM: f64 = 380.0;
/// Table step, nm.
const STEP_NM: f64 = 10.0;

/// `[S0, S1, S2]` at 380, 390, ..., 780 nm.
const BASIS: [[f64; 3]; 41] = [
    [63.4, 38.5, 3.0],
    [65.8, 35.0, 1.2],
    [94.8, 43.4, -1.1],
    [104.8, 46.3, -0.5],
    [105.9, 43.9, -0.7],
    [96.8, 37.1, -1.2],
    [113.9, 36.7, -2.6],
    [125.6, 35.9, -2.9],
    [125.5, 32.6, -2.8],
    [121.3, 27.9, -2.6],
    [121.3, 24.3, -2.6],
    [113.5, 20.1, -1.8],
    [113.1, 16.2, -1.5],
    [110.8, 13.2, -1.3],
    [106.5, 8.6, -1.2],
    [108.8, 6.1, -1.0],
    [105.3, 4.2, -0.5],
    [104.4, 1.9, -0.3],
    [100.0, 0.0, 0.0],
    [96.0, -1.6, 0.2],
    [95.1, -3.5, 0.5],
    [89.1, -3.5, 2.1],
    [90.5, -5.8, 3.2],
    [90.3, -7.2, 4.1],
    [88.4, -8.6, 4.7],
    [84.0, -9.5, 5.1],
    [85.1, -10.9, 6.7],
    [81.9, -10.7, 7.3],
    [82.6, -12.0, 8.6],
    [84.9, -14.0, 9.8],
    [81.3, -13.6, 10.2],
    [71.9, -12.0, 8.3],
    [74.3, -13.3, 9.6],
    [76.4, -12.9, 8.5],
    [63.3, -10.6, 7.0],
    [71.7, -11.6, 7.6],
    [77.0, -12.2, 8.0],
    [65.2, -10.2, 6.7],
    [47.7, -7.8, 5.2],
    [68.6, -11.2, 7.4],
    [65.0, -10.4, 6.8],
];

/// `[S0, S1, S2]` at `lambda_m` (metres), linearly interpolated; zero outside 380..780 nm.
pub fn basis_at(lambda_m: f64) -> [f64; 3] {
    let x = (lambda_m * 1e9 - FIRST_NM) / STEP_NM;
    if !(x >= 0.0 && x <= (BASIS.len() - 1) as f64) {
        return [0.0; 3];
    }
    let i = (x.floor() as usize).min(BASIS.len() - 2);
    let t = x - i as f64;
    let (a, b) = (BASIS[i], BASIS[i + 1]);
    [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]))
}

/// The weights `[1, M1, M2]` of the daylight spectrum of chromaticity `(x, y)`.
pub fn weights(x: f64, y: f64) -> [f64; 3] {
    let d = 0.0241 + 0.2562 * x - 0.7341 * y;
    [
        1.0,
        (-1.3515 - 1.7703 * x + 5.9114 * y) / d,
        (0.0300 - 31.4424 * x + 30.0717 * y) / d,
    ]
}

/// XYZ (CIE 1931, 1 nm sums over 380..=780 nm, divided by `sum D65 ybar`, the
/// scene's units) of `S0`, `S1`, `S2`.
pub fn basis_xyz() -> [[f64; 3]; 3] {
    use sunbeam_optics::cie;
    let norm = cie::d65_y_norm(cie::DEFAULT_RANGE_NM);
    let mut out = [[0.0; 3]; 3];
    for nm in cie::DEFAULT_RANGE_NM.0..=cie::DEFAULT_RANGE_NM.1 {
        let b = basis_at(nm as f64 * 1e-9);
        let c = cie::cmf_nm(nm);
        for (k, o) in out.iter_mut().enumerate() {
            for m in 0..3 {
                o[m] += b[k] * c[m] / norm;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use sunbeam_optics::cie;

    /// Independent truth: the CIE D65 table of sunbeam-optics. The daylight
    /// basis at D65's chromaticity (0.31271, 0.32902) reproduces it to the
    /// table's rounding (CIE defines D65 by this basis, at 10 nm, then
    /// interpolates; values agree to 1 %).
    #[test]
    fn d65_chromaticity_gives_d65() {
        let m = weights(0.31271, 0.32902);
        for nm in (380..=780).step_by(10) {
            let b = basis_at(nm as f64 * 1e-9);
            let s = b[0] + m[1] * b[1] + m[2] * b[2];
            let d65 = cie::d65_nm(nm);
            assert!((s / d65 - 1.0).abs() < 0.012, "{nm} nm: {s} vs {d65}");
        }
    }

    /// The spectrum of chromaticity (x, y) has that chromaticity (the
    /// definition of M1, M2), across the daylight locus.
    #[test]
    fn chromaticity_round_trip() {
        let bx = basis_xyz();
        for (x, y) in [
            (0.25, 0.26),
            (0.2848, 0.2932),
            (0.3457, 0.3585),
            (0.40, 0.39),
        ] {
            let m = weights(x, y);
            let xyz: [f64; 3] = [0, 1, 2].map(|c| (0..3).map(|k| m[k] * bx[k][c]).sum());
            let s = xyz[0] + xyz[1] + xyz[2];
            assert!((xyz[0] / s - x).abs() < 4e-3, "x {} vs {x}", xyz[0] / s);
            assert!((xyz[1] / s - y).abs() < 4e-3, "y {} vs {y}", xyz[1] / s);
        }
    }
}
