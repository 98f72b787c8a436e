//! Park Systems TIFF (PSIA): private tags 50432 (magic 0x0E031301), 50434
//! (data), 50435 (a 580-byte little-endian header). z = raw * data_gain in
//! `z_unit`; rows stored bottom first.

use sunbeam_common::Result;

use crate::tiffdir::Tiff;
use crate::util::{
    bail, channel, check_dims, decode, f64_at, flip_rows, i32_at, parse_unit, slice, Endian, Sample,
};
use crate::{Channel, Format};

const MAGIC: u64 = 0x0E03_1301;

fn utf16(b: &[u8], off: usize, chars: usize) -> Result<String> {
    let s = slice(b, off, chars * 2, "Park header string")?;
    let u: Vec<u16> = s
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .take_while(|&c| c != 0)
        .collect();
    Ok(String::from_utf16_lossy(&u))
}

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    let t = Tiff::parse(b)?;
    let Some(ifd) = t.ifds.first() else {
        bail!("Park TIFF: no image directory")
    };
    match t.uint(ifd, 50432)? {
        Some(MAGIC) => {}
        Some(m) => bail!("Park TIFF: magic tag 50432 is {m:#x}, expected {MAGIC:#x}"),
        None => bail!("not a Park Systems TIFF (no tag 50432)"),
    }
    let Some(hdr_e) = ifd.get(50435) else {
        bail!("Park TIFF: missing header tag 50435")
    };
    let Some(dat_e) = ifd.get(50434) else {
        bail!("Park TIFF: missing data tag 50434")
    };
    let h = t.bytes(hdr_e)?;
    if h.len() < 352 {
        bail!(
            "Park TIFF: header tag 50435 has {} bytes, needs at least 352",
            h.len()
        );
    }
    let le = Endian::Little;
    let image_type = i32_at(h, 0, le, "Park header image_type")?;
    if image_type != 0 {
        bail!("Park TIFF: image_type {image_type} is not a 2D image (line profiles and spectra are not supported)");
    }
    let name = utf16(h, 4, 32)?;
    let xres = i32_at(h, 100, le, "Park header xres")?;
    let yres = i32_at(h, 104, le, "Park header yres")?;
    let (xres, yres) = check_dims(xres as i64, yres as i64, "Park header xres x yres")?;
    let xreal = f64_at(h, 140, le, "Park header xreal")? * 1e-6;
    let yreal = f64_at(h, 148, le, "Park header yreal")? * 1e-6;
    let gain = f64_at(h, 220, le, "Park header data_gain")?;
    let zunit = utf16(h, 244, 8)?;
    let dtype = i32_at(h, 348, le, "Park header data_type")?;
    let st = match dtype {
        0 => Sample::I16,
        1 => Sample::I32,
        2 => Sample::F32,
        d => bail!("Park TIFF: unknown data_type {d}"),
    };
    let raw = t.bytes(dat_e)?;
    let n = xres * yres;
    if raw.len() < n * st.size() {
        bail!(
            "Park TIFF: data tag 50434 has {} bytes, {xres}x{yres} pixels need {}",
            raw.len(),
            n * st.size()
        );
    }
    let mut data = decode(raw, 0, n, st, le, "Park TIFF data")?;
    let (m, base) = parse_unit(&zunit);
    let q = gain * m;
    if !q.is_finite() {
        bail!("Park TIFF: data_gain {gain} is not finite");
    }
    for v in &mut data {
        *v *= q;
    }
    flip_rows(&mut data, xres, yres);
    let name = if name.is_empty() {
        "Data".to_string()
    } else {
        name
    };
    Ok(vec![channel(
        Format::ParkTiff,
        &name,
        &base,
        "m",
        xres,
        yres,
        xreal,
        yreal,
        data,
    )?])
}

/// JPK TIFF: page 0 holds the scan geometry (tags 0x8040.. grid origin and
/// lengths), pages 1.. one channel each (0x8050 name, 0x8051 retrace flag,
/// 0x8052 display name) with calibration slots (0x8080 count, 0x8081 default
/// slot; slot k at 0x8090 + 0x30 k: +0 name, +0x12 unit, +0x13 scaling type,
/// +0x14 multiplier, +0x15 offset, each applied to the raw integers). Rows are
/// stored bottom first.
pub fn read_jpk(b: &[u8]) -> Result<Vec<Channel>> {
    let t = Tiff::parse(b)?;
    let Some(ifd0) = t.ifds.first() else {
        bail!("JPK TIFF: no image directory")
    };
    let xreal = t.num(ifd0, 0x8042)?;
    let yreal = t.num(ifd0, 0x8043)?;
    let (Some(xreal), Some(yreal)) = (xreal, yreal) else {
        bail!("JPK TIFF: missing grid lengths (tags 0x8042/0x8043)")
    };
    let (x0, y0) = (
        t.num(ifd0, 0x8040)?.unwrap_or(0.0),
        t.num(ifd0, 0x8041)?.unwrap_or(0.0),
    );
    let mut out = Vec::new();
    for (k, ifd) in t.ifds.iter().enumerate().skip(1) {
        let Some(cname) = t.ascii(ifd, 0x8050)? else {
            continue;
        };
        let ctx = format!("JPK channel {k} '{cname}'");
        let w = t.uint(ifd, 256)?.unwrap_or(0);
        let h = t.uint(ifd, 257)?.unwrap_or(0);
        let (w, h) = check_dims(
            w.min(1 << 40) as i64,
            h.min(1 << 40) as i64,
            &format!("{ctx}: ImageWidth x ImageLength"),
        )?;
        let bps = t.uint(ifd, 258)?.unwrap_or(0);
        let fmt = t.uint(ifd, 339)?.unwrap_or(1);
        let st = match (bps, fmt) {
            (32, 2) => Sample::I32,
            (32, 1) => Sample::U32,
            (32, 3) => Sample::F32,
            (16, 2) => Sample::I16,
            (16, 1) => Sample::U16,
            (64, 3) => Sample::F64,
            _ => bail!("{ctx}: {bps}-bit samples (SampleFormat {fmt}) are not supported"),
        };
        let raw = t.strips(ifd, w * h * st.size(), &ctx)?;
        let mut data = decode(&raw, 0, w * h, st, t.e, &ctx)?;
        // Calibration: the default slot's multiplier and offset.
        let nslots = t.num(ifd, 0x8080)?.unwrap_or(0.0).clamp(0.0, 64.0) as u16;
        let default = t.ascii(ifd, 0x8081)?.unwrap_or_default();
        let (mut mult, mut off, mut unit) = (1.0, 0.0, String::new());
        for s in 0..nslots {
            let base = 0x8090 + 0x30 * s;
            if t.ascii(ifd, base)?.as_deref() != Some(default.as_str()) {
                continue;
            }
            unit = t.ascii(ifd, base + 0x12)?.unwrap_or_default();
            if t.ascii(ifd, base + 0x13)?.as_deref() == Some("LinearScaling") {
                mult = t.num(ifd, base + 0x14)?.unwrap_or(1.0);
                off = t.num(ifd, base + 0x15)?.unwrap_or(0.0);
            }
        }
        let (um, base) = parse_unit(&unit);
        for v in &mut data {
            *v = (*v * mult + off) * um;
        }
        flip_rows(&mut data, w, h);
        let fancy = t.ascii(ifd, 0x8052)?.unwrap_or_else(|| cname.clone());
        let retrace = t.num(ifd, 0x8051)?.is_some_and(|x| x != 0.0);
        let name = if retrace {
            format!("{fancy} (retrace)")
        } else {
            fancy
        };
        let mut ch = channel(Format::Jpk, &name, &base, "m", w, h, xreal, yreal, data)?;
        ch.offset = (x0, y0);
        out.push(ch);
    }
    if out.is_empty() {
        bail!("JPK TIFF: no channel pages");
    }
    Ok(out)
}
