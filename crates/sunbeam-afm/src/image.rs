//! Grey images as height maps: 8/16-bit PNG (with Gwyddion's `Gwy::*` scale
//! text chunks when present), uncompressed grey TIFF, BMP. Without scale
//! metadata, the pixel size and height range come from `ReadOptions`
//! (`--pixel-size`, `--z-range` or `--z-scale`): 0 = lowest, full scale = z_range.

use std::collections::HashMap;

use sunbeam_common::Result;

use crate::tiffdir::Tiff;
use crate::util::{
    bail, channel, check_dims, decode, i32_at, leading_f64, slice, u16_at, u32_at, Endian, Sample,
};
use crate::{Channel, Format, ReadOptions};

/// Grey values of an image, row 0 at the top, and the full-scale value.
struct Grey {
    w: usize,
    h: usize,
    v: Vec<f64>,
    full: f64,
}

/// Scale an uncalibrated grey image with the user's options.
fn uncalibrated(fmt: Format, g: Grey, opts: &ReadOptions, what: &str) -> Result<Vec<Channel>> {
    let mut missing = Vec::new();
    let mut example = Vec::new();
    if opts.pixel_size.is_none() {
        missing.push("--pixel-size");
        example.push("--pixel-size 65nm");
    }
    if opts.z_range.is_none() && opts.z_scale.is_none() {
        missing.push("--z-range (or --z-scale)");
        example.push("--z-range 375nm");
    }
    if !missing.is_empty() {
        bail!(
            "{what} {}x{} carries no physical scale: give {} (e.g. {})",
            g.w,
            g.h,
            missing.join(" and "),
            example.join(" ")
        );
    }
    let (dx, dy) = opts.pixel_size.unwrap_or((1.0, 1.0));
    let q = match (opts.z_range, opts.z_scale) {
        (Some(r), _) => r / g.full,
        (None, Some(s)) => s,
        _ => 1.0,
    };
    let data: Vec<f64> = g.v.iter().map(|v| v * q).collect();
    let mut ch = channel(
        fmt,
        "Height",
        "m",
        "m",
        g.w,
        g.h,
        dx * g.w as f64,
        dy * g.h as f64,
        data,
    )?;
    ch.is_height = true;
    Ok(vec![ch])
}

/// Largest decoded size accepted for a compressed image: deflate expands at most ~1032:1.
/// Also capped at 1 GiB.
fn decoded_limit(file_len: usize) -> usize {
    file_len.saturating_mul(1100).min(1 << 30)
}

pub fn read_png(b: &[u8], opts: &ReadOptions) -> Result<Vec<Channel>> {
    let limit = decoded_limit(b.len());
    let mut dec =
        png::Decoder::new_with_limits(std::io::Cursor::new(b), png::Limits { bytes: limit });
    dec.set_transformations(png::Transformations::EXPAND);
    let mut reader = dec
        .read_info()
        .map_err(|e| sunbeam_common::Error::input(format!("PNG: {e}")))?;
    let (w, h) = {
        let i = reader.info();
        (i.width as i64, i.height as i64)
    };
    let (w, h) = check_dims(w, h, "PNG width x height")?;
    let mut text: HashMap<String, String> = HashMap::new();
    {
        let i = reader.info();
        for t in &i.uncompressed_latin1_text {
            text.insert(t.keyword.clone(), t.text.clone());
        }
        for t in &i.utf8_text {
            if let Ok(s) = t.get_text() {
                text.insert(t.keyword.clone(), s);
            }
        }
    }
    let (ct, bd) = reader.output_color_type();
    let chans = ct.samples();
    let bytes_per = if bd == png::BitDepth::Sixteen { 2 } else { 1 };
    let need = w * h * chans * bytes_per;
    if need > limit {
        bail!(
            "PNG: {w}x{h} image decodes to {need} bytes, more than a file of {} bytes can hold",
            b.len()
        );
    }
    let mut buf = vec![0u8; reader.output_buffer_size()];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| sunbeam_common::Error::input(format!("PNG image data: {e}")))?;
    let line = info.line_size;
    let mut v = Vec::with_capacity(w * h);
    let mut not_grey = false;
    for r in 0..h {
        let row = slice(&buf, r * line, w * chans * bytes_per, "PNG row")?;
        for c in 0..w {
            let px = &row[c * chans * bytes_per..(c + 1) * chans * bytes_per];
            let s = |k: usize| -> f64 {
                if bytes_per == 2 {
                    u16::from_be_bytes([px[2 * k], px[2 * k + 1]]) as f64
                } else {
                    px[k] as f64
                }
            };
            let val = if chans >= 3 {
                let (r_, g_, b_) = (s(0), s(1), s(2));
                if r_ != g_ || g_ != b_ {
                    not_grey = true;
                }
                (r_ + g_ + b_) / 3.0
            } else {
                s(0)
            };
            v.push(val);
        }
    }
    let full = if bytes_per == 2 { 65535.0 } else { 255.0 };
    let _ = not_grey;
    let num = |k: &str| -> Result<Option<f64>> {
        match text.get(k) {
            None => Ok(None),
            Some(s) => match leading_f64(s) {
                Some((x, _)) if x.is_finite() => Ok(Some(x)),
                _ => bail!("PNG text chunk `{k}` is not a number ({s:?})"),
            },
        }
    };
    if let (Some(xr), Some(zmin), Some(zmax)) =
        (num("Gwy::XReal")?, num("Gwy::ZMin")?, num("Gwy::ZMax")?)
    {
        let yr = num("Gwy::YReal")?.unwrap_or(xr * h as f64 / w as f64);
        let q = (zmax - zmin) / full;
        let data: Vec<f64> = v.iter().map(|x| zmin + x * q).collect();
        let title = text
            .get("Gwy::Title")
            .or_else(|| text.get("Title"))
            .cloned()
            .unwrap_or_else(|| "Data".into());
        let zu = text.get("Gwy::ZUnit").cloned().unwrap_or_default();
        let xyu = text.get("Gwy::XYUnit").cloned().unwrap_or_default();
        let mut ch = channel(Format::Png, &title, &zu, &xyu, w, h, xr, yr, data)?;
        ch.offset = (
            num("Gwy::XOffset")?.unwrap_or(0.0),
            num("Gwy::YOffset")?.unwrap_or(0.0),
        );
        return Ok(vec![ch]);
    }
    uncalibrated(Format::Png, Grey { w, h, v, full }, opts, "PNG image")
}

pub fn read_tiff(b: &[u8], opts: &ReadOptions) -> Result<Vec<Channel>> {
    let t = Tiff::parse(b)?;
    let Some(ifd) = t.ifds.first() else {
        bail!("TIFF: no image directory")
    };
    let w = t.uint(ifd, 256)?.unwrap_or(0);
    let h = t.uint(ifd, 257)?.unwrap_or(0);
    let (w, h) = check_dims(
        w.min(i64::MAX as u64) as i64,
        h.min(i64::MAX as u64) as i64,
        "TIFF ImageWidth x ImageLength",
    )?;
    let spp = t.uint(ifd, 277)?.unwrap_or(1) as usize;
    let bps = t.uint(ifd, 258)?.unwrap_or(1);
    let fmt = t.uint(ifd, 339)?.unwrap_or(1);
    if spp != 1 {
        bail!("TIFF: {spp} samples per pixel; only single-channel grey images are read as heights");
    }
    let st = match (bps, fmt) {
        (8, 1) => Sample::U8,
        (8, 2) => Sample::I8,
        (16, 1) => Sample::U16,
        (16, 2) => Sample::I16,
        (32, 1) => Sample::U32,
        (32, 2) => Sample::I32,
        (32, 3) => Sample::F32,
        (64, 3) => Sample::F64,
        _ => bail!("TIFF: {bps}-bit samples (SampleFormat {fmt}) are not supported"),
    };
    let raw = t.strips(ifd, w * h * st.size(), "TIFF image")?;
    let mut v = decode(&raw, 0, w * h, st, t.e, "TIFF image")?;
    if t.uint(ifd, 262)? == Some(0) {
        // WhiteIsZero
        let m = match st {
            Sample::U8 => 255.0,
            Sample::U16 => 65535.0,
            _ => 0.0,
        };
        for x in &mut v {
            *x = m - *x;
        }
    }
    let full = match st {
        Sample::U8 | Sample::I8 => 255.0,
        Sample::U16 | Sample::I16 => 65535.0,
        Sample::U32 | Sample::I32 => u32::MAX as f64,
        _ => 1.0,
    };
    uncalibrated(Format::Tiff, Grey { w, h, v, full }, opts, "TIFF image")
}

pub fn read_bmp(b: &[u8], opts: &ReadOptions) -> Result<Vec<Channel>> {
    let le = Endian::Little;
    if !b.starts_with(b"BM") {
        bail!("not a BMP file (no BM magic)");
    }
    let data_off = u32_at(b, 10, le, "BMP pixel data offset")? as usize;
    let hsize = u32_at(b, 14, le, "BMP header size")? as usize;
    let (w, h, bpp, comp) = if hsize == 12 {
        (
            u16_at(b, 18, le, "BMP width")? as i64,
            u16_at(b, 20, le, "BMP height")? as i16 as i64,
            u16_at(b, 24, le, "BMP bits per pixel")?,
            0,
        )
    } else if hsize >= 40 {
        (
            i32_at(b, 18, le, "BMP width")? as i64,
            i32_at(b, 22, le, "BMP height")? as i64,
            u16_at(b, 28, le, "BMP bits per pixel")?,
            u32_at(b, 30, le, "BMP compression")?,
        )
    } else {
        bail!("BMP: unknown header size {hsize}");
    };
    let top_down = h < 0;
    let (w, h) = check_dims(w, h.abs(), "BMP width x height")?;
    if !matches!(bpp, 1 | 2 | 4 | 8 | 24 | 32) {
        bail!("BMP: {bpp} bits per pixel is not supported");
    }
    if comp != 0 && comp != 3 {
        bail!("BMP: compressed BMP (compression {comp}) is not supported");
    }
    let pal = if bpp <= 8 {
        let n = if hsize >= 40 {
            u32_at(b, 46, le, "BMP colours used")? as usize
        } else {
            0
        };
        let n = if n == 0 { 1usize << bpp } else { n.min(256) };
        let entry = if hsize == 12 { 3 } else { 4 };
        let p = slice(b, 14 + hsize, n * entry, "BMP palette")?;
        let mut pal = Vec::with_capacity(n);
        for c in p.chunks_exact(entry) {
            pal.push((c[0] as f64 + c[1] as f64 + c[2] as f64) / 3.0);
        }
        pal
    } else {
        Vec::new()
    };
    let row_bytes = (w * bpp as usize).div_ceil(32) * 4;
    let pix = slice(b, data_off, row_bytes * h, "BMP pixel data")?;
    let mut v = vec![0.0; w * h];
    for r in 0..h {
        let row = &pix[r * row_bytes..(r + 1) * row_bytes];
        let dst = if top_down { r } else { h - 1 - r };
        for c in 0..w {
            let val = match bpp {
                1 | 4 | 8 => {
                    let bit = c * bpp as usize;
                    let byte = row[bit / 8];
                    let idx = ((byte >> (8 - bpp as usize - bit % 8)) & ((1u16 << bpp) - 1) as u8)
                        as usize;
                    match pal.get(idx) {
                        Some(&g) => g,
                        None => bail!(
                            "BMP: palette index {idx} out of range ({} colours)",
                            pal.len()
                        ),
                    }
                }
                24 | 32 => {
                    let k = c * bpp as usize / 8;
                    (row[k] as f64 + row[k + 1] as f64 + row[k + 2] as f64) / 3.0
                }
                _ => bail!("BMP: {bpp} bits per pixel is not supported"),
            };
            v[dst * w + c] = val;
        }
    }
    uncalibrated(
        Format::Bmp,
        Grey {
            w,
            h,
            v,
            full: 255.0,
        },
        opts,
        "BMP image",
    )
}
