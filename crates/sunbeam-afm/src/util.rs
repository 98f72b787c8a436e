//! Small helpers shared by the parsers: bounds-checked binary reads, SI unit
//! prefixes, building channels.

use sunbeam_common::{Error, Result};
use sunbeam_field::{HeightField, Provenance};

/// Largest image side accepted (the same guard as `sunbeam_field::HeightField::new`).
pub const MAX_SIDE: usize = 1 << 15;

use crate::{Channel, Format};

/// Error for input data: `Error::input(format!(...))`.
macro_rules! bail {
    ($($t:tt)*) => { return Err(sunbeam_common::Error::input(format!($($t)*))) };
}
pub(crate) use bail;

/// Byte order of a binary format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Endian {
    Little,
    Big,
}

/// `bytes[off..off+len]`, or an input error naming `what`.
pub fn slice<'a>(bytes: &'a [u8], off: usize, len: usize, what: &str) -> Result<&'a [u8]> {
    let end = off
        .checked_add(len)
        .ok_or_else(|| Error::input(format!("{what}: offset overflows")))?;
    bytes.get(off..end).ok_or_else(|| {
        Error::input(format!(
            "{what}: needs bytes {off}..{end} but the file has only {} bytes (truncated?)",
            bytes.len()
        ))
    })
}

pub fn u16_at(b: &[u8], off: usize, e: Endian, what: &str) -> Result<u16> {
    let s = slice(b, off, 2, what)?;
    let a = [s[0], s[1]];
    Ok(match e {
        Endian::Little => u16::from_le_bytes(a),
        Endian::Big => u16::from_be_bytes(a),
    })
}
pub fn i16_at(b: &[u8], off: usize, e: Endian, what: &str) -> Result<i16> {
    Ok(u16_at(b, off, e, what)? as i16)
}
pub fn u32_at(b: &[u8], off: usize, e: Endian, what: &str) -> Result<u32> {
    let s = slice(b, off, 4, what)?;
    let a = [s[0], s[1], s[2], s[3]];
    Ok(match e {
        Endian::Little => u32::from_le_bytes(a),
        Endian::Big => u32::from_be_bytes(a),
    })
}
pub fn i32_at(b: &[u8], off: usize, e: Endian, what: &str) -> Result<i32> {
    Ok(u32_at(b, off, e, what)? as i32)
}
pub fn f64_at(b: &[u8], off: usize, e: Endian, what: &str) -> Result<f64> {
    let s = slice(b, off, 8, what)?;
    let mut a = [0u8; 8];
    a.copy_from_slice(s);
    Ok(match e {
        Endian::Little => f64::from_le_bytes(a),
        Endian::Big => f64::from_be_bytes(a),
    })
}

/// Numeric sample types found in the formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sample {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Sample {
    pub fn size(self) -> usize {
        match self {
            Sample::I8 | Sample::U8 => 1,
            Sample::I16 | Sample::U16 => 2,
            Sample::I32 | Sample::U32 | Sample::F32 => 4,
            Sample::F64 => 8,
        }
    }
}

/// Decode `n` samples at `off` (checked against the buffer first).
pub fn decode(
    bytes: &[u8],
    off: usize,
    n: usize,
    t: Sample,
    e: Endian,
    what: &str,
) -> Result<Vec<f64>> {
    let len = n
        .checked_mul(t.size())
        .ok_or_else(|| Error::input(format!("{what}: data size overflows")))?;
    let s = slice(bytes, off, len, what)?;
    let mut out = Vec::with_capacity(n);
    // One tight loop per sample type and byte order (the match stays outside).
    macro_rules! run {
        ($ty:ty, $sz:expr, $conv:ident) => {
            out.extend(s.chunks_exact($sz).map(|c| {
                let mut a = [0u8; $sz];
                a.copy_from_slice(c);
                <$ty>::$conv(a) as f64
            }))
        };
    }
    match (t, e) {
        (Sample::I8, _) => out.extend(s.iter().map(|&x| x as i8 as f64)),
        (Sample::U8, _) => out.extend(s.iter().map(|&x| x as f64)),
        (Sample::I16, Endian::Little) => run!(i16, 2, from_le_bytes),
        (Sample::I16, Endian::Big) => run!(i16, 2, from_be_bytes),
        (Sample::U16, Endian::Little) => run!(u16, 2, from_le_bytes),
        (Sample::U16, Endian::Big) => run!(u16, 2, from_be_bytes),
        (Sample::I32, Endian::Little) => run!(i32, 4, from_le_bytes),
        (Sample::I32, Endian::Big) => run!(i32, 4, from_be_bytes),
        (Sample::U32, Endian::Little) => run!(u32, 4, from_le_bytes),
        (Sample::U32, Endian::Big) => run!(u32, 4, from_be_bytes),
        (Sample::F32, Endian::Little) => run!(f32, 4, from_le_bytes),
        (Sample::F32, Endian::Big) => run!(f32, 4, from_be_bytes),
        (Sample::F64, Endian::Little) => run!(f64, 8, from_le_bytes),
        (Sample::F64, Endian::Big) => run!(f64, 8, from_be_bytes),
    }
    Ok(out)
}

/// Check grid dimensions from a header before anything is allocated.
pub fn check_dims(xres: i64, yres: i64, what: &str) -> Result<(usize, usize)> {
    if xres <= 0 || yres <= 0 {
        bail!("{what}: image size {xres}x{yres} is not positive");
    }
    if xres > MAX_SIDE as i64 || yres > MAX_SIDE as i64 {
        bail!("{what}: image size {xres}x{yres} exceeds the {MAX_SIDE} pixel limit per side");
    }
    Ok((xres as usize, yres as usize))
}

/// Split an SI unit string with a prefix into (multiplier, base unit):
/// "nm" -> (1e-9, "m"), "~m"/"um"/"µm" -> (1e-6, "m"), "pA" -> (1e-12, "A"), "deg" -> (1, "deg").
pub fn parse_unit(u: &str) -> (f64, String) {
    let u = u.trim();
    const BASES: [&str; 12] = [
        "m", "V", "A", "N", "Hz", "s", "deg", "rad", "F", "Ohm", "W", "Pa",
    ];
    const WHOLE: [&str; 6] = ["deg", "rad", "Hz", "Pa", "Ohm", "%"];
    if u.is_empty() || u == "1" {
        return (1.0, String::new());
    }
    if WHOLE.contains(&u) {
        return (1.0, u.to_string());
    }
    if u == "°" {
        return (1.0, "deg".into());
    }
    if u == "Å" || u == "A°" || u == "Angstrom" {
        return (1e-10, "m".into());
    }
    for b in BASES {
        if let Some(p) = u.strip_suffix(b) {
            let m = match p {
                "" => Some(1.0),
                "f" => Some(1e-15),
                "p" => Some(1e-12),
                "n" => Some(1e-9),
                "u" | "~" | "µ" | "μ" => Some(1e-6),
                "m" => Some(1e-3),
                "c" => Some(1e-2),
                "k" => Some(1e3),
                "M" => Some(1e6),
                "G" => Some(1e9),
                _ => None,
            };
            if let Some(m) = m {
                return (m, b.to_string());
            }
        }
    }
    (1.0, u.to_string())
}

/// Is a channel a height/topography channel (by name and unit)?
pub fn looks_like_height(name: &str, z_unit: &str) -> bool {
    let n = name.to_ascii_lowercase();
    z_unit == "m"
        && (n.contains("height")
            || n.contains("topo")
            || n.contains("zsensor")
            || n.contains("z sensor")
            || n.starts_with('z')
            || n.contains("surface"))
        && !n.contains("amplitude")
        && !n.contains("phase")
}

/// Build a channel from row-major data (row 0 at the top) with its physical size.
#[allow(clippy::too_many_arguments)]
pub fn channel(
    fmt: Format,
    name: &str,
    z_unit: &str,
    xy_unit: &str,
    xres: usize,
    yres: usize,
    xreal: f64,
    yreal: f64,
    data: Vec<f64>,
) -> Result<Channel> {
    if !(xreal.is_finite() && xreal > 0.0 && yreal.is_finite() && yreal > 0.0) {
        bail!("channel '{name}': physical size {xreal} x {yreal} is not finite and positive");
    }
    let mut field = HeightField::new(xres, yres, xreal / xres as f64, yreal / yres as f64, data)
        .map_err(|e| e.context(format!("channel '{name}'")))?;
    field.provenance = Provenance {
        source_file: String::new(),
        source_format: fmt.name().to_string(),
        channel: name.to_string(),
        processing: Vec::new(),
    };
    Ok(Channel {
        name: name.to_string(),
        z_unit: z_unit.to_string(),
        xy_unit: xy_unit.to_string(),
        is_height: looks_like_height(name, z_unit),
        offset: (0.0, 0.0),
        field,
    })
}

/// Flip rows in place (bottom-first storage -> row 0 at the top).
pub fn flip_rows(data: &mut [f64], xres: usize, yres: usize) {
    for r in 0..yres / 2 {
        let (a, b) = data.split_at_mut((yres - 1 - r) * xres);
        a[r * xres..(r + 1) * xres].swap_with_slice(&mut b[..xres]);
    }
}

/// Parse a float the way C's strtod would accept it at the start of `s`
/// (leading spaces skipped), returning the value and the rest.
pub fn leading_f64(s: &str) -> Option<(f64, &str)> {
    let t = s.trim_start();
    let b = t.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let ds = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    if i < b.len() && b[i] == b'.' {
        i += 1;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
    }
    if i == ds || (i == ds + 1 && b[ds] == b'.') {
        return None;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        let k = j;
        while j < b.len() && b[j].is_ascii_digit() {
            j += 1;
        }
        if j > k {
            i = j;
        }
    }
    t[..i].parse::<f64>().ok().map(|v| (v, &t[i..]))
}
