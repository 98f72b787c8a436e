//! Quantities with units on the command line: `20nm`, `65um`, `1.5µm`,
//! `380nm..780nm`, `75deg`. Values come back in SI (metres, radians).

use crate::error::{Error, Result};

const LENGTH_UNITS: &[(&str, f64)] = &[
    ("pm", 1e-12),
    ("nm", 1e-9),
    ("um", 1e-6),
    ("µm", 1e-6),
    ("μm", 1e-6),
    ("mm", 1e-3),
    ("cm", 1e-2),
    ("m", 1.0),
    ("A", 1e-10),
    ("Å", 1e-10),
];

fn split_number(s: &str) -> (&str, &str) {
    let s = s.trim();
    let end = s
        .char_indices()
        .find(|&(i, c)| {
            !(c.is_ascii_digit()
                || c == '.'
                || c == '+'
                || c == '-'
                || ((c == 'e' || c == 'E')
                    && s[i + 1..]
                        .starts_with(|d: char| d.is_ascii_digit() || d == '-' || d == '+')))
        })
        .map(|(i, _)| i)
        .unwrap_or(s.len());
    (s[..end].trim(), s[end..].trim())
}

/// A length such as `20nm` in metres. A bare number is refused (units are required)
/// unless `default_unit` is given.
pub fn parse_length(s: &str) -> Result<f64> {
    parse_length_default(s, None)
}

/// Like [`parse_length`], but a bare number is taken in `default_unit` (e.g. "nm").
pub fn parse_length_default(s: &str, default_unit: Option<&str>) -> Result<f64> {
    let (num, unit) = split_number(s);
    let v: f64 = num
        .parse()
        .map_err(|_| Error::usage(format!("'{s}' is not a length (expected e.g. 20nm, 1.5um)")))?;
    let unit = if unit.is_empty() {
        default_unit
            .ok_or_else(|| Error::usage(format!("'{s}' has no unit (write e.g. {s}nm or {s}um)")))?
    } else {
        unit
    };
    let scale = LENGTH_UNITS
        .iter()
        .find(|(u, _)| *u == unit)
        .map(|(_, f)| *f)
        .ok_or_else(|| {
            Error::usage(format!(
                "'{s}': unknown length unit '{unit}' (pm, nm, um, mm, m)"
            ))
        })?;
    let m = v * scale;
    if !m.is_finite() {
        return Err(Error::usage(format!("'{s}' is not a finite length")));
    }
    Ok(m)
}

/// A positive length.
pub fn parse_positive_length(s: &str) -> Result<f64> {
    let v = parse_length(s)?;
    if v <= 0.0 {
        return Err(Error::usage(format!("'{s}' must be positive")));
    }
    Ok(v)
}

/// A range `380nm..780nm` (the unit may be given once at the end: `380..780nm`).
pub fn parse_length_range(s: &str) -> Result<(f64, f64)> {
    let (a, b) = s.split_once("..").ok_or_else(|| {
        Error::usage(format!("'{s}' is not a range (expected e.g. 380nm..780nm)"))
    })?;
    let (_, unit_b) = split_number(b);
    let (_, unit_a) = split_number(a);
    let lo = if unit_a.is_empty() && !unit_b.is_empty() {
        parse_length_default(a, Some(unit_b))?
    } else {
        parse_length(a)?
    };
    let hi = parse_length(b)?;
    if !(lo > 0.0 && hi > lo) {
        return Err(Error::usage(format!("'{s}': need 0 < low < high")));
    }
    Ok((lo, hi))
}

/// An angle: `75deg`, `75°`, `1.3rad`; a bare number is degrees. Radians out.
pub fn parse_angle(s: &str) -> Result<f64> {
    let (num, unit) = split_number(s);
    let v: f64 = num
        .parse()
        .map_err(|_| Error::usage(format!("'{s}' is not an angle (expected e.g. 75deg)")))?;
    let r = match unit {
        "" | "deg" | "°" => v.to_radians(),
        "rad" => v,
        _ => {
            return Err(Error::usage(format!(
                "'{s}': unknown angle unit '{unit}' (deg, rad)"
            )))
        }
    };
    if !r.is_finite() {
        return Err(Error::usage(format!("'{s}' is not a finite angle")));
    }
    Ok(r)
}

/// `WxH` such as `512x512`.
pub fn parse_size(s: &str) -> Result<(usize, usize)> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| Error::usage(format!("'{s}' is not a size (expected WxH, e.g. 512x512)")))?;
    let w: usize = w
        .trim()
        .parse()
        .map_err(|_| Error::usage(format!("'{s}': bad width")))?;
    let h: usize = h
        .trim()
        .parse()
        .map_err(|_| Error::usage(format!("'{s}': bad height")))?;
    if w == 0 || h == 0 || w > 1 << 16 || h > 1 << 16 {
        return Err(Error::usage(format!(
            "'{s}': width and height must be 1..65536"
        )));
    }
    Ok((w, h))
}

/// Format a length for people: `65 nm`, `1.769 um`.
pub fn format_length(m: f64) -> String {
    let a = m.abs();
    let (v, u) = if a == 0.0 {
        (0.0, "m")
    } else if a < 1e-9 {
        (m * 1e12, "pm")
    } else if a < 1e-6 {
        (m * 1e9, "nm")
    } else if a < 1e-3 {
        (m * 1e6, "um")
    } else if a < 1.0 {
        (m * 1e3, "mm")
    } else {
        (m, "m")
    };
    format!("{} {u}", trim_float(v))
}

fn trim_float(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths() {
        assert!((parse_length("20nm").unwrap() - 20e-9).abs() < 1e-24);
        assert!((parse_length("1.5um").unwrap() - 1.5e-6).abs() < 1e-21);
        assert!((parse_length("1.5µm").unwrap() - 1.5e-6).abs() < 1e-21);
        assert!((parse_length("2e-3m").unwrap() - 2e-3).abs() < 1e-18);
        assert!((parse_length("1e3nm").unwrap() - 1e-6).abs() < 1e-21);
        assert!(parse_length("20").is_err());
        assert!(parse_length("20 parsecs").is_err());
        assert!(parse_length("nm").is_err());
        assert!((parse_length_default("20", Some("nm")).unwrap() - 20e-9).abs() < 1e-24);
    }

    #[test]
    fn ranges_angles_sizes() {
        let (a, b) = parse_length_range("380nm..780nm").unwrap();
        assert!((a - 380e-9).abs() < 1e-20 && (b - 780e-9).abs() < 1e-20);
        let (a, _) = parse_length_range("380..780nm").unwrap();
        assert!((a - 380e-9).abs() < 1e-20);
        assert!(parse_length_range("780nm..380nm").is_err());
        assert!((parse_angle("75deg").unwrap() - 75f64.to_radians()).abs() < 1e-15);
        assert!((parse_angle("90").unwrap() - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(parse_size("640x480").unwrap(), (640, 480));
        assert!(parse_size("0x5").is_err());
        assert_eq!(format_length(65e-9), "65 nm");
    }
}
