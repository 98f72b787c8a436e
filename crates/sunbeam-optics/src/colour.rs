//! Colour science: XYZ -> linear sRGB, CIELAB (D65), CIEDE2000, and the ONE
//! display transform (exposure, tone mapping, sRGB encoding) that the player's
//! shader and the CPU reference renderer both implement.
//!
//! # The display transform (shared contract)
//!
//! For each linear sRGB channel `c` (from [`xyz_to_linear_srgb`]):
//!
//! 1. exposure: `x = c * 2^EV`;
//! 2. negative values (out of the sRGB gamut) are clamped to 0: `x = max(x, 0)`;
//! 3. tone curve, per channel: [`ToneCurve::Clamp`] `y = min(x, 1)` or
//!    [`ToneCurve::Reinhard`] `y = x / (1 + x)`;
//! 4. the sRGB OETF (IEC 61966-2-1): `v = 12.92 y` if `y <= 0.0031308`, else
//!    `1.055 y^(1/2.4) - 0.055`;
//! 5. 8-bit quantisation: `round(255 v)` (`floor(255 v + 0.5)`).
//!
//! NaN inputs map to 0. Implementations elsewhere (WGSL) must follow these
//! steps in this order; [`display_encode`] is the reference.

/// XYZ (D65, Y = 1 for the white) to linear sRGB: the standard matrix derived from
/// the sRGB primaries and the D65 white (0.3127, 0.3290) of IEC 61966-2-1.
pub const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.2404542, -1.5371385, -0.4985314],
    [-0.9692660, 1.8760108, 0.0415560],
    [0.0556434, -0.2040259, 1.0572252],
];

/// Linear sRGB to XYZ (inverse of [`XYZ_TO_SRGB`]).
pub const SRGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.4124564, 0.3575761, 0.1804375],
    [0.2126729, 0.7151522, 0.0721750],
    [0.0193339, 0.1191920, 0.9503041],
];

/// The D65 reference white used for CIELAB (2-degree observer, ASTM E308 / CIE 15).
pub const D65_WHITE: [f64; 3] = [0.95047, 1.0, 1.08883];

fn mat3(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// XYZ -> linear sRGB (no clamping: negative channels are out of gamut).
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    mat3(&XYZ_TO_SRGB, xyz)
}

/// Linear sRGB -> XYZ.
pub fn linear_srgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    mat3(&SRGB_TO_XYZ, rgb)
}

/// XYZ -> CIELAB with the reference white `white` (Y of the white = 1 scale).
pub fn xyz_to_lab_white(xyz: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    const EPS: f64 = 216.0 / 24389.0;
    const KAPPA: f64 = 24389.0 / 27.0;
    let f = |t: f64| {
        if t > EPS {
            t.cbrt()
        } else {
            (KAPPA * t + 16.0) / 116.0
        }
    };
    let fx = f(xyz[0] / white[0]);
    let fy = f(xyz[1] / white[1]);
    let fz = f(xyz[2] / white[2]);
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// XYZ -> CIELAB with the D65 white ([`D65_WHITE`]).
pub fn xyz_to_lab(xyz: [f64; 3]) -> [f64; 3] {
    xyz_to_lab_white(xyz, D65_WHITE)
}

/// CIEDE2000 colour difference (kL = kC = kH = 1), following Sharma, Wu and
/// Dalal (2005), including their notes on hue angle and mean hue.
pub fn ciede2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    use std::f64::consts::PI;
    let (l1, a1, b1) = (lab1[0], lab1[1], lab1[2]);
    let (l2, a2, b2) = (lab2[0], lab2[1], lab2[2]);
    let c1 = a1.hypot(b1);
    let c2 = a2.hypot(b2);
    let cbar = 0.5 * (c1 + c2);
    let cbar7 = cbar.powi(7);
    let g = 0.5 * (1.0 - (cbar7 / (cbar7 + 25f64.powi(7))).sqrt());
    let a1p = (1.0 + g) * a1;
    let a2p = (1.0 + g) * a2;
    let c1p = a1p.hypot(b1);
    let c2p = a2p.hypot(b2);
    let hp = |b: f64, a: f64| {
        if b == 0.0 && a == 0.0 {
            0.0
        } else {
            let h = b.atan2(a);
            if h < 0.0 {
                h + 2.0 * PI
            } else {
                h
            }
        }
    };
    let h1p = hp(b1, a1p);
    let h2p = hp(b2, a2p);
    let dlp = l2 - l1;
    let dcp = c2p - c1p;
    let dhp = if c1p * c2p == 0.0 {
        0.0
    } else {
        let d = h2p - h1p;
        if d > PI {
            d - 2.0 * PI
        } else if d < -PI {
            d + 2.0 * PI
        } else {
            d
        }
    };
    let dhp_big = 2.0 * (c1p * c2p).sqrt() * (0.5 * dhp).sin();
    let lbarp = 0.5 * (l1 + l2);
    let cbarp = 0.5 * (c1p + c2p);
    let hbarp = if c1p * c2p == 0.0 {
        h1p + h2p
    } else if (h1p - h2p).abs() <= PI {
        0.5 * (h1p + h2p)
    } else if h1p + h2p < 2.0 * PI {
        0.5 * (h1p + h2p + 2.0 * PI)
    } else {
        0.5 * (h1p + h2p - 2.0 * PI)
    };
    let t = 1.0 - 0.17 * (hbarp - PI / 6.0).cos()
        + 0.24 * (2.0 * hbarp).cos()
        + 0.32 * (3.0 * hbarp + PI / 30.0).cos()
        - 0.20 * (4.0 * hbarp - 63f64.to_radians()).cos();
    let dtheta = 30f64.to_radians() * (-((hbarp.to_degrees() - 275.0) / 25.0).powi(2)).exp();
    let cbarp7 = cbarp.powi(7);
    let rc = 2.0 * (cbarp7 / (cbarp7 + 25f64.powi(7))).sqrt();
    let l50 = (lbarp - 50.0).powi(2);
    let sl = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let sc = 1.0 + 0.045 * cbarp;
    let sh = 1.0 + 0.015 * cbarp * t;
    let rt = -(2.0 * dtheta).sin() * rc;
    let x = dlp / sl;
    let y = dcp / sc;
    let z = dhp_big / sh;
    (x * x + y * y + z * z + rt * y * z).max(0.0).sqrt()
}

/// CIEDE2000 between two XYZ colours (D65 white).
pub fn ciede2000_xyz(xyz1: [f64; 3], xyz2: [f64; 3]) -> f64 {
    ciede2000(xyz_to_lab(xyz1), xyz_to_lab(xyz2))
}

/// The per-channel tone curve of the display transform (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ToneCurve {
    /// `min(x, 1)`: exact colours below 1, hard clip above (the default).
    #[default]
    Clamp,
    /// `x / (1 + x)`: never clips, compresses highlights.
    Reinhard,
}

impl std::str::FromStr for ToneCurve {
    type Err = sunbeam_common::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "clamp" => Ok(Self::Clamp),
            "reinhard" => Ok(Self::Reinhard),
            _ => Err(sunbeam_common::Error::usage(format!(
                "unknown tone curve '{s}' (clamp, reinhard)"
            ))),
        }
    }
}

/// Exposure in stops plus the tone curve: everything between linear sRGB and the OETF.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ToneMap {
    /// Exposure value: linear values are multiplied by `2^exposure_ev`.
    pub exposure_ev: f64,
    pub curve: ToneCurve,
}

impl ToneMap {
    /// Steps 1-3 of the display transform for one linear channel; result in [0, 1].
    pub fn apply(&self, linear: f64) -> f64 {
        let x = linear * self.exposure_ev.exp2();
        let x = if x.is_nan() { 0.0 } else { x.max(0.0) };
        match self.curve {
            ToneCurve::Clamp => x.min(1.0),
            ToneCurve::Reinhard => {
                if x.is_infinite() {
                    1.0
                } else {
                    x / (1.0 + x)
                }
            }
        }
    }
}

/// The sRGB OETF (IEC 61966-2-1) on [0, 1] (input clamped to [0, 1]).
pub fn srgb_oetf(y: f64) -> f64 {
    let y = if y.is_nan() { 0.0 } else { y.clamp(0.0, 1.0) };
    if y <= 0.0031308 {
        12.92 * y
    } else {
        1.055 * y.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`srgb_oetf`] (sRGB-encoded value in [0, 1] -> linear).
pub fn srgb_eotf(v: f64) -> f64 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Quantise an encoded value in [0, 1] to 8 bits: `floor(255 v + 0.5)`.
pub fn quantise8(v: f64) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8
}

/// The whole display transform for one pixel: linear sRGB -> encoded sRGB in [0, 1].
pub fn display_encode(linear_rgb: [f64; 3], tm: &ToneMap) -> [f64; 3] {
    linear_rgb.map(|c| srgb_oetf(tm.apply(c)))
}

/// The whole display transform to 8 bits (what a PNG frame holds).
pub fn display_encode8(linear_rgb: [f64; 3], tm: &ToneMap) -> [u8; 3] {
    display_encode(linear_rgb, tm).map(quantise8)
}

/// XYZ straight to an 8-bit sRGB pixel through [`display_encode8`].
pub fn xyz_to_srgb8(xyz: [f64; 3], tm: &ToneMap) -> [u8; 3] {
    display_encode8(xyz_to_linear_srgb(xyz), tm)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_are_inverse() {
        let v = [0.3, 0.5, 0.7];
        let b = linear_srgb_to_xyz(xyz_to_linear_srgb(v));
        for i in 0..3 {
            assert!((b[i] - v[i]).abs() < 1e-6);
        }
        // D65 white maps to (1, 1, 1).
        let w = xyz_to_linear_srgb(D65_WHITE);
        for c in w {
            assert!((c - 1.0).abs() < 1e-4, "{w:?}");
        }
    }

    #[test]
    fn lab_of_white_and_grey() {
        let l = xyz_to_lab(D65_WHITE);
        assert!((l[0] - 100.0).abs() < 1e-12 && l[1].abs() < 1e-12 && l[2].abs() < 1e-12);
        // Y = 0.18 -> L* = 49.496 (closed form 116 * 0.18^(1/3) - 16).
        let g = xyz_to_lab(D65_WHITE.map(|c| 0.18 * c));
        assert!((g[0] - (116.0 * 0.18f64.cbrt() - 16.0)).abs() < 1e-12);
    }

    #[test]
    fn display_transform() {
        let tm = ToneMap::default();
        assert_eq!(display_encode8([1.0, 0.0, 2.0], &tm), [255, 0, 255]);
        assert_eq!(display_encode8([-1.0, f64::NAN, 0.5], &tm), [0, 0, 188]);
        let tm = ToneMap {
            exposure_ev: 1.0,
            curve: ToneCurve::Reinhard,
        };
        // 0.5 * 2 = 1 -> 0.5 -> sRGB 0.7354 -> 188.
        assert_eq!(display_encode8([0.5, 0.0, 0.0], &tm), [188, 0, 0]);
        assert!((srgb_eotf(srgb_oetf(0.2)) - 0.2).abs() < 1e-12);
        assert!((srgb_oetf(0.0031308) - 0.04045).abs() < 1e-5);
    }
}
