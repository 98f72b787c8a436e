//! NT-MDT `.mdt`, as Gwyddion's `nt-mdt` module reads it: a 33-byte file
//! header (magic 01 B0 93 FF, size of the rest, number of frames - 1), then
//! frames, each a 22-byte header (size, type, version, date, var size) and
//! its body. Image frames read here:
//!
//! - type 0, scanned data: axis scales (offset, step, unit code) for x, y, z,
//!   the scan variables, then mode/xres/yres/ndots, the dots, int16 values,
//!   and a cp1251 title. z = offset + step * raw (unit prefix applied),
//!   xreal = xres * |x step|, yreal = yres * |y step| (both in the x unit).
//! - type 106, MDA, with 2 dimensions and 1 measurand: calibrations (name,
//!   unit, bias, scale, min/max index, data type) and the array (int8..int64,
//!   uint8..uint64, float32, float64). z = bias + scale * raw,
//!   xreal = scale_x * (nx - 1) (Gwyddion's convention).
//!
//! Both are stored bottom row first. Titles: "<title> (<frame number>)".
//! Other frames (text, palette, spectroscopy and curves, MDA spectra and
//! volume data) are skipped.

use sunbeam_common::Result;

use crate::text::{cp1251_or_utf8, fallback_title};
use crate::util::{bail, channel, check_dims, decode, flip_rows, parse_unit, slice};
use crate::util::{Endian, Sample};
use crate::{Channel, Format};

pub const MAGIC: &[u8] = &[0x01, 0xb0, 0x93, 0xff];
const FILE_HEADER: usize = 33;
const FRAME_HEADER: usize = 22;

/// Content detection: the magic number.
pub fn detect(b: &[u8]) -> bool {
    b.starts_with(MAGIC)
}

fn le_u16(b: &[u8], o: usize, what: &str) -> Result<u16> {
    let s = slice(b, o, 2, what)?;
    Ok(u16::from_le_bytes([s[0], s[1]]))
}
fn le_u32(b: &[u8], o: usize, what: &str) -> Result<u32> {
    let s = slice(b, o, 4, what)?;
    Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}
fn le_u64(b: &[u8], o: usize, what: &str) -> Result<u64> {
    let s = slice(b, o, 8, what)?;
    let mut a = [0u8; 8];
    a.copy_from_slice(s);
    Ok(u64::from_le_bytes(a))
}
fn le_f32(b: &[u8], o: usize, what: &str) -> Result<f64> {
    Ok(f32::from_bits(le_u32(b, o, what)?) as f64)
}
fn le_f64(b: &[u8], o: usize, what: &str) -> Result<f64> {
    Ok(f64::from_bits(le_u64(b, o, what)?))
}
fn add(a: usize, b: u64, what: &str) -> Result<usize> {
    usize::try_from(b)
        .ok()
        .and_then(|b| a.checked_add(b))
        .ok_or_else(|| sunbeam_common::Error::input(format!("{what}: offset overflows")))
}

/// The unit of an MDT unit code (frame axis scales).
fn unit_code(code: i16) -> &'static str {
    match code {
        -10 => "1/cm",
        -5 => "m",
        -4 => "cm",
        -3 => "mm",
        -2 => "µm",
        -1 => "nm",
        0 => "Å",
        1 | 23 => "nA",
        2 | 8 | 25 => "V",
        4 => "kHz",
        5 => "deg",
        6 => "%",
        7 => "°C",
        9 => "s",
        10 => "ms",
        11 => "µs",
        12 => "ns",
        14 => "px",
        20 => "A",
        21 => "mA",
        22 => "µA",
        24 => "pA",
        26 => "mV",
        27 => "µV",
        28 => "nV",
        29 => "pV",
        30 => "N",
        31 => "mN",
        32 => "µN",
        33 => "nN",
        34 => "pN",
        _ => "",
    }
}

/// The unit of an MDA SI unit code (when a calibration has no unit text).
fn si_code(code: u64) -> &'static str {
    match code {
        0x101 => "m",
        0x100001 => "A",
        0xfffd010200 => "V",
        0x1000001 => "s",
        _ => "",
    }
}

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    if !detect(b) {
        bail!("not an NT-MDT file (no magic 01 B0 93 FF at the start)");
    }
    if b.len() < FILE_HEADER {
        bail!(
            "NT-MDT: the file ({} bytes) is shorter than its 33-byte header",
            b.len()
        );
    }
    let size = le_u32(b, 4, "NT-MDT file header")? as u64;
    if size + FILE_HEADER as u64 != b.len() as u64 {
        bail!(
            "NT-MDT file header: size {} + 33 does not match the file length {} (truncated?)",
            size,
            b.len()
        );
    }
    let nframes = le_u16(b, 12, "NT-MDT file header")? as usize + 1;
    let mut out = Vec::new();
    let mut p = FILE_HEADER;
    for i in 0..nframes {
        let what = format!("NT-MDT frame {}", i + 1);
        if p + FRAME_HEADER > b.len() {
            bail!("{what}: header at byte {p} is past the end of the file (truncated?)");
        }
        let fsize = le_u32(b, p, &what)? as usize;
        if fsize < FRAME_HEADER || fsize > b.len() - p {
            bail!(
                "{what}: frame size {fsize} at byte {p} does not fit the file ({} bytes; truncated?)",
                b.len()
            );
        }
        let f = &b[p..p + fsize];
        let ftype = le_u16(f, 4, &what)?;
        let var_size = le_u16(f, 20, &what)? as usize;
        if var_size + FRAME_HEADER > fsize {
            bail!("{what}: variable block size {var_size} does not fit the frame ({fsize} bytes)");
        }
        let index = out.len();
        let ch = match ftype {
            0 => Some(scanned(f, var_size, i, index, &what)?),
            106 => mda(f, i, index, &what)?,
            _ => None,
        };
        if let Some(c) = ch {
            out.push(c);
        }
        p += fsize;
    }
    if out.is_empty() {
        bail!("NT-MDT: no image frame (only text, spectra, curves or other frames)");
    }
    Ok(out)
}

/// Frame type 0 (scanned data).
fn scanned(f: &[u8], var_size: usize, i: usize, index: usize, what: &str) -> Result<Channel> {
    if var_size < 30 + 77 {
        bail!("{what}: variable block ({var_size} bytes) too short for scanned data");
    }
    let v = FRAME_HEADER;
    let axis = |o: usize| -> Result<(f64, f64, i16)> {
        Ok((
            le_f32(f, v + o, what)?,
            le_f32(f, v + o + 4, what)?,
            le_u16(f, v + o + 8, what)? as i16,
        ))
    };
    let (_, xstep, xunit) = axis(0)?;
    let (_, ystep, _) = axis(10)?;
    let (zoff, zstep, zunit) = axis(20)?;
    let fix = |s: f64| if s == 0.0 { 1.0 } else { s.abs() };
    let (xstep, ystep) = (fix(xstep), fix(ystep));
    let zstep = if zstep == 0.0 { 1.0 } else { zstep };
    let m = FRAME_HEADER + var_size;
    let xres = le_u16(f, m + 2, what)? as i64;
    let yres = le_u16(f, m + 4, what)? as i64;
    let ndots = le_u16(f, m + 6, what)? as usize;
    let (xres, yres) = check_dims(xres, yres, &format!("{what} scanned image size"))?;
    let mut q = m + 8;
    if ndots > 0 {
        q += 14 + 16 * ndots;
    }
    let n = xres * yres;
    let mut data = decode(
        f,
        q,
        n,
        Sample::I16,
        Endian::Little,
        &format!("{what} image data"),
    )?;
    q += 2 * n;
    let (mxy, xyunit) = parse_unit(unit_code(xunit));
    let (mz, zu) = parse_unit(unit_code(zunit));
    let (o, s) = (mz * zoff, mz * zstep);
    for d in &mut data {
        *d = o + s * *d;
    }
    flip_rows(&mut data, xres, yres);
    let mut title = None;
    if f.len() - q.min(f.len()) > 4 {
        let len = le_u32(f, q, what)? as usize;
        q += 4;
        if len > 0 && f.len() - q >= len {
            title = Some(cp1251_or_utf8(&f[q..q + len]));
        }
    }
    let name = match title {
        Some(t) => format!("{t} ({})", i + 1),
        None => fallback_title(&zu, index),
    };
    let (xreal, yreal) = (xres as f64 * mxy * xstep, yres as f64 * mxy * ystep);
    channel(
        Format::Mdt,
        &name,
        &zu,
        &xyunit,
        xres,
        yres,
        xreal,
        yreal,
        data,
    )
}

struct Calibration {
    unit: String,
    bias: f64,
    scale: f64,
    min_index: u64,
    max_index: u64,
    data_type: i32,
    len: usize,
}

fn calibration(f: &[u8], c: usize, what: &str) -> Result<Calibration> {
    let tot = le_u32(f, c, what)? as u64;
    let struct_len = le_u32(f, c + 4, what)? as u64;
    let p = c + 8;
    let name_len = le_u32(f, p, what)? as u64;
    let comment_len = le_u32(f, p + 4, what)? as u64;
    let unit_len = le_u32(f, p + 8, what)? as u64;
    let si = le_u64(f, p + 12, what)?;
    let bias = le_f64(f, p + 36, what)?;
    let scale = le_f64(f, p + 44, what)?;
    let min_index = le_u64(f, p + 52, what)?;
    let max_index = le_u64(f, p + 60, what)?;
    let data_type = le_u32(f, p + 68, what)? as i32;
    let sp = add(p, struct_len, what)?;
    let name = slice(f, sp, name_len as usize, &format!("{what} name"))?;
    let up = add(add(sp, name_len, what)?, comment_len, what)?;
    let unit = slice(f, up, unit_len as usize, &format!("{what} unit"))?;
    let unit = if !unit.is_empty() {
        cp1251_or_utf8(unit)
    } else if !name.is_empty() {
        cp1251_or_utf8(name)
    } else {
        si_code(si).to_string()
    };
    if tot < 8 {
        bail!("{what}: calibration size {tot} is too small");
    }
    Ok(Calibration {
        unit,
        bias,
        scale,
        min_index,
        max_index,
        data_type,
        len: tot as usize,
    })
}

/// Frame type 106 (MDA): an image when it has 2 dimensions and 1 measurand.
fn mda(f: &[u8], i: usize, index: usize, what: &str) -> Result<Option<Channel>> {
    let r = FRAME_HEADER;
    let head_size = le_u32(f, r, what)? as u64;
    let sizes: Vec<u64> = (0..8)
        .map(|k| le_u32(f, r + 44 + 4 * k, what).map(|x| x as u64))
        .collect::<Result<_>>()?;
    let (name_size, comm_size, view_size, spec_size, source_size) =
        (sizes[0], sizes[1], sizes[2], sizes[3], sizes[4]);
    let mut q = add(r, head_size, what)?;
    let title = if name_size > 0 {
        let t = slice(f, q, name_size as usize, &format!("{what} title"))?;
        q += name_size as usize;
        Some(cp1251_or_utf8(t))
    } else {
        None
    };
    q = add(q, comm_size, what)?;
    q = add(q, spec_size, what)?;
    q = add(q, view_size, what)?;
    q = add(q, source_size, what)?;
    q = add(q, 4, what)?;
    let struct_len = le_u32(f, q, what)? as u64;
    let sp = q + 4;
    let ndim = le_u32(f, sp + 12, what)?;
    let nmes = le_u32(f, sp + 16, what)?;
    if (ndim, nmes) != (2, 1) {
        return Ok(None); // spectra, volume data: not an image
    }
    let mut c = add(sp, struct_len, what)?;
    let mut cals = Vec::with_capacity(3);
    for k in ["x axis", "y axis", "values"] {
        let cal = calibration(f, c, &format!("{what} MDA calibration ({k})"))?;
        c = add(c, cal.len as u64, what)?;
        cals.push(cal);
    }
    let (x, y, z) = (&cals[0], &cals[1], &cals[2]);
    let side = |a: &Calibration| -> i64 {
        a.max_index
            .checked_sub(a.min_index)
            .and_then(|d| d.checked_add(1))
            .and_then(|d| i64::try_from(d).ok())
            .unwrap_or(-1)
    };
    let (xres, yres) = check_dims(side(x), side(y), &format!("{what} MDA image size"))?;
    let n = xres * yres;
    let data_what = format!("{what} image data");
    let sample = match z.data_type {
        -1 => Some(Sample::I8),
        1 => Some(Sample::U8),
        -2 => Some(Sample::I16),
        2 => Some(Sample::U16),
        -4 => Some(Sample::I32),
        4 => Some(Sample::U32),
        -8 | 8 => None, // 64-bit integers, decoded below
        t if t == -(4 + 23 * 256) => Some(Sample::F32),
        t if t == -(8 + 52 * 256) => Some(Sample::F64),
        t => bail!("{what}: MDA data type {t} is not supported"),
    };
    let mut data = match sample {
        Some(t) => decode(f, c, n, t, Endian::Little, &data_what)?,
        None => {
            let len = n.saturating_mul(8);
            let s = slice(f, c, len, &data_what)?;
            let signed = z.data_type < 0;
            s.chunks_exact(8)
                .map(|w| {
                    let mut a = [0u8; 8];
                    a.copy_from_slice(w);
                    if signed {
                        i64::from_le_bytes(a) as f64
                    } else {
                        u64::from_le_bytes(a) as f64
                    }
                })
                .collect()
        }
    };
    let (mxy, xyunit) = parse_unit(&x.unit);
    let (mz, zu) = parse_unit(&z.unit);
    let (zs, zo) = (mz * z.scale, mz * z.bias);
    for d in &mut data {
        *d = zo + zs * *d;
    }
    flip_rows(&mut data, xres, yres);
    let xreal = mxy * x.scale * (xres as f64 - 1.0);
    let yreal = mxy * y.scale * (yres as f64 - 1.0);
    let name = match title {
        Some(t) => format!("{t} ({})", i + 1),
        None => fallback_title(&zu, index),
    };
    Ok(Some(channel(
        Format::Mdt,
        &name,
        &zu,
        &xyunit,
        xres,
        yres,
        xreal,
        yreal,
        data,
    )?))
}
