//! Keysight/Agilent (Molecular Imaging) PicoView `.mi` images, as Gwyddion's
//! `mifile` module reads them.
//!
//! A text header of `key` (14 columns, space padded) + value lines, starting
//! with `fileType      Image`. Global keys (`xPixels`, `yPixels`, `xLength`,
//! `yLength` in metres) come first; each `bufferLabel` line starts a channel
//! whose `bufferRange` and `bufferUnit` follow. The line `data          BINARY`
//! (int16) or `BINARY_32` (int32) ends the header; the images follow, one after
//! another, little-endian, bottom row first. z = raw / 2^(bits-1) * bufferRange
//! (in `bufferUnit`). ASCII data and spectroscopy files are refused.

use sunbeam_common::Result;

use crate::text::{atol, latin1_or_utf8, lines_with_offsets};
use crate::util::{bail, channel, check_dims, decode, flip_rows, leading_f64, parse_unit};
use crate::util::{Endian, Sample};
use crate::{Channel, Format};

const IMAGE: &[u8] = b"fileType      Image";
const SPECT: &[u8] = b"fileType      Spectroscopy";
const KEY_LEN: usize = 14;

/// Content detection: `fileType      Image` (or `Spectroscopy`) at the start.
pub fn detect(b: &[u8]) -> bool {
    b.starts_with(IMAGE) || b.starts_with(SPECT)
}

#[derive(Default)]
struct Buffer {
    label: String,
    range: Option<f64>,
    unit: String,
}

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    if b.starts_with(SPECT) {
        bail!("PicoView MI: a spectroscopy file (fileType Spectroscopy), not an image");
    }
    if !b.starts_with(IMAGE) {
        bail!("not a PicoView MI image (no `fileType      Image` at the start)");
    }
    let mut xres: i64 = 0;
    let mut yres: i64 = 0;
    let mut xlen: Option<f64> = None;
    let mut ylen: Option<f64> = None;
    let mut bufs: Vec<Buffer> = Vec::new();
    let mut data: Option<(usize, Sample)> = None;
    for (s, e, next) in lines_with_offsets(b) {
        let line = latin1_or_utf8(&b[s..e]);
        let (k, v) = match line.char_indices().nth(KEY_LEN) {
            Some((i, _)) => (line[..i].trim(), line[i..].trim()),
            None => (line.trim(), ""),
        };
        if k == "data" {
            if next > b.len() {
                bail!("PicoView MI: the `data` line is the end of the file (no image data)");
            }
            let t = match v {
                "BINARY" | "" => Sample::I16,
                "BINARY_32" => Sample::I32,
                "ASCII" => {
                    bail!("PicoView MI: ASCII data is not supported (only BINARY, BINARY_32)")
                }
                o => {
                    bail!("PicoView MI: data type {o:?} is not supported (only BINARY, BINARY_32)")
                }
            };
            data = Some((next, t));
            break;
        }
        if line.starts_with(' ') {
            continue;
        }
        if k == "bufferLabel" {
            if bufs.len() >= 1024 {
                bail!("PicoView MI: more than 1024 buffers");
            }
            bufs.push(Buffer {
                label: v.to_string(),
                ..Default::default()
            });
            continue;
        }
        match (k, bufs.last_mut()) {
            ("xPixels", _) => xres = atol(v),
            ("yPixels", _) => yres = atol(v),
            ("xLength", None) => xlen = leading_f64(v).map(|x| x.0),
            ("yLength", None) => ylen = leading_f64(v).map(|x| x.0),
            ("bufferRange", Some(buf)) => buf.range = leading_f64(v).map(|x| x.0),
            ("bufferUnit", Some(buf)) => buf.unit = v.to_string(),
            _ => {}
        }
    }
    let Some((start, sample)) = data else {
        bail!("PicoView MI: no `data` line ends the header (truncated?)")
    };
    if bufs.is_empty() {
        bail!("PicoView MI: the header lists no image buffer (bufferLabel)");
    }
    let (xres, yres) = check_dims(xres, yres, "PicoView MI xPixels x yPixels")?;
    let Some(xreal) = xlen else {
        bail!("PicoView MI: missing or invalid xLength")
    };
    let Some(yreal) = ylen else {
        bail!("PicoView MI: missing or invalid yLength")
    };
    let n = xres * yres;
    let q = if sample == Sample::I32 {
        2147483648.0
    } else {
        32768.0
    };
    let mut out = Vec::new();
    for (i, buf) in bufs.iter().enumerate() {
        let off = start + i * n * sample.size();
        let what = format!("PicoView MI buffer {i} '{}'", buf.label);
        let mut d = decode(b, off, n, sample, Endian::Little, &what)?;
        let (m, unit) = parse_unit(&buf.unit);
        let f = match buf.range {
            Some(r) => r * m / q,
            None => 1.0 / q,
        };
        for v in &mut d {
            *v *= f;
        }
        flip_rows(&mut d, xres, yres);
        let name = if buf.label.is_empty() {
            "Unknown Channel"
        } else {
            &buf.label
        };
        out.push(channel(
            Format::Mi,
            name,
            &unit,
            "m",
            xres,
            yres,
            xreal,
            yreal,
            d,
        )?);
    }
    Ok(out)
}
