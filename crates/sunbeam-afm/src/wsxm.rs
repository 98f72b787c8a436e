//! WSxM `.top`/`.stp`/`.tom` images (Nanotec/UAM), as Gwyddion's `wsxmfile`
//! module reads them.
//!
//! `WSxM file copyright ...` / `SxM Image file` / `Image header size: N`, then a
//! header of `[Section]`s with `key: value` lines up to `[Header end]`; the
//! image starts at byte N. `[General Info]`: `Number of columns`, `Number of
//! rows`, `Image Data Type` (`short` and `integer`: int16, as Gwyddion 2.62
//! reads both; `float`; `double`), `Z Amplitude` (with unit, or `a.u.`);
//! `[Control]`: `X Amplitude`, `Y Amplitude` (with units). z = raw * Z
//! Amplitude / (max raw - min raw). The image is stored rotated by 180
//! degrees (last pixel first) relative to the view Gwyddion shows.

use std::collections::HashMap;

use sunbeam_common::Result;

use crate::text::{atol, fallback_title, latin1_or_utf8};
use crate::util::{bail, channel, check_dims, decode, leading_f64, parse_unit, Endian, Sample};
use crate::{Channel, Format};

const MAGIC: &[u8] = b"WSxM file copyright ";

/// Content detection: the copyright line, then `SxM Image file`.
pub fn detect(b: &[u8]) -> bool {
    if !b.starts_with(MAGIC) {
        return false;
    }
    let head = &b[..b.len().min(200)];
    head.windows(14).any(|w| w == b"SxM Image file")
}

/// A value with its unit: (number, multiplier to SI, SI unit); `a.u.` is unitless.
fn amplitude(v: &str) -> Option<(f64, f64, String)> {
    let (x, rest) = leading_f64(v)?;
    if !(x.is_finite() && x > 0.0) {
        return None;
    }
    let u = rest.trim();
    if u == "a.u." {
        return Some((x, 1.0, String::new()));
    }
    let (m, base) = parse_unit(u);
    Some((x, m, base))
}

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    if !detect(b) {
        bail!("not a WSxM image (no `WSxM file copyright` / `SxM Image file` at the start)");
    }
    let top = &b[..b.len().min(300)];
    let Some(p) = top.windows(18).position(|w| w == b"Image header size:") else {
        bail!("WSxM: no `Image header size:` line (truncated?)")
    };
    let hs = atol(&latin1_or_utf8(&b[p + 18..b.len().min(p + 40)]));
    if hs <= 0 || hs as u64 > b.len() as u64 {
        bail!(
            "WSxM: Image header size {hs} is outside the file ({} bytes; truncated?)",
            b.len()
        );
    }
    let hs = hs as usize;
    let head = latin1_or_utf8(&b[..hs]);
    let mut meta: HashMap<String, String> = HashMap::new();
    let mut section: Option<String> = None;
    let mut ended = false;
    for line in head.lines() {
        let t = line.trim();
        if t.len() >= 2 && t.starts_with('[') && t.ends_with(']') {
            let s = &t[1..t.len() - 1];
            if s == "Header end" {
                ended = true;
                break;
            }
            section = Some(s.to_string());
            continue;
        }
        let Some(sec) = &section else { continue };
        let Some((k, v)) = t.split_once(':') else {
            continue;
        };
        let v = v.trim();
        if !v.is_empty() {
            meta.insert(format!("{sec}::{}", k.trim()), v.to_string());
        }
    }
    if !ended {
        bail!("WSxM: no [Header end] within the {hs}-byte header (truncated or damaged header)");
    }
    let get = |k: &str| meta.get(k).map(String::as_str);
    let dim = |k: &str| -> Result<i64> {
        match get(k) {
            Some(v) => Ok(atol(v)),
            None => bail!("WSxM: missing `{k}`"),
        }
    };
    let (xres, yres) = check_dims(
        dim("General Info::Number of columns")?,
        dim("General Info::Number of rows")?,
        "WSxM Number of columns x Number of rows",
    )?;
    let sample = match get("General Info::Image Data Type") {
        None | Some("short") | Some("integer") => Sample::I16,
        Some("float") => Sample::F32,
        Some("double") => Sample::F64,
        Some(o) => {
            bail!("WSxM: Image Data Type {o:?} is not supported (short, integer, float, double)")
        }
    };
    let Some((za, zm, zunit)) = get("General Info::Z Amplitude").and_then(amplitude) else {
        bail!(
            "WSxM: missing or invalid `Z Amplitude` ({:?})",
            get("General Info::Z Amplitude").unwrap_or("")
        )
    };
    let Some((xa, xm, xyunit)) = get("Control::X Amplitude").and_then(amplitude) else {
        bail!(
            "WSxM: missing or invalid `X Amplitude` ({:?})",
            get("Control::X Amplitude").unwrap_or("")
        )
    };
    let xreal = xa * xm;
    let yreal = match get("Control::Y Amplitude").and_then(amplitude) {
        Some((ya, ym, _)) => ya * ym,
        None => xreal,
    };
    let n = xres * yres;
    let mut data = decode(b, hs, n, sample, Endian::Little, "WSxM image data")?;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &v in &data {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        bail!(
            "WSxM: the image is flat (or not finite), so `Z Amplitude` / (max - min) has no scale"
        );
    }
    let f = za * zm / (hi - lo);
    for v in &mut data {
        *v *= f;
    }
    data.reverse(); // stored rotated by 180 degrees
    let name = fallback_title(&zunit, 0);
    Ok(vec![channel(
        Format::Wsxm,
        &name,
        &zunit,
        &xyunit,
        xres,
        yres,
        xreal,
        yreal,
        data,
    )?])
}
