//! Nanonis `.sxm`: a text header of `:KEY:` blocks up to `:SCANIT_END:`, then
//! 0x1A 0x04 and big-endian float32 images: per channel of `:DATA_INFO:`, the
//! forward scan, then the backward scan when its direction is `both`.
//! Scans stored bottom row first when `:SCAN_DIR:` is `up`; backward scans right to left.

use std::collections::HashMap;

use sunbeam_common::Result;

use crate::util::{
    bail, channel, check_dims, decode, flip_rows, leading_f64, parse_unit, Endian, Sample,
};
use crate::{Channel, Format};

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    if !b.starts_with(b":NANONIS_VERSION:") {
        bail!("not a Nanonis SXM file (no :NANONIS_VERSION: at the start)");
    }
    let Some(end) = b.windows(12).position(|w| w == b":SCANIT_END:") else {
        bail!("Nanonis SXM: header has no :SCANIT_END: (truncated?)")
    };
    let Some(start) = b[end..]
        .windows(2)
        .position(|w| w == [0x1a, 0x04])
        .map(|p| end + p + 2)
    else {
        bail!("Nanonis SXM: no 0x1A 0x04 data marker after :SCANIT_END: (truncated?)")
    };
    let head = String::from_utf8_lossy(&b[..end]);
    let mut blocks: HashMap<String, String> = HashMap::new();
    let mut key: Option<String> = None;
    for line in head.lines() {
        let t = line.trim_end_matches('\r');
        if t.len() > 2 && t.starts_with(':') && t.ends_with(':') && !t[1..t.len() - 1].contains(':')
        {
            key = Some(t[1..t.len() - 1].to_string());
            if let Some(k) = &key {
                blocks.entry(k.clone()).or_default();
            }
        } else if let Some(k) = &key {
            let e = blocks.entry(k.clone()).or_default();
            e.push_str(t);
            e.push('\n');
        }
    }
    let get = |k: &str| blocks.get(k).map(|s| s.as_str());
    let two = |k: &str| -> Result<(f64, f64)> {
        let Some(s) = get(k) else {
            bail!("Nanonis SXM: missing :{k}:")
        };
        let Some((a, r)) = leading_f64(s) else {
            bail!("Nanonis SXM: cannot parse :{k}: {s:?}")
        };
        let Some((c, _)) = leading_f64(r) else {
            bail!("Nanonis SXM: cannot parse :{k}: {s:?}")
        };
        Ok((a, c))
    };
    let (xr, yr) = two("SCAN_PIXELS")?;
    let (xres, yres) = check_dims(
        xr.round() as i64,
        yr.round() as i64,
        "Nanonis SXM :SCAN_PIXELS:",
    )?;
    let (xreal, yreal) = two("SCAN_RANGE")?;
    let (xo, yo) = two("SCAN_OFFSET").unwrap_or((0.0, 0.0));
    let up = get("SCAN_DIR").map(|s| s.trim() == "up").unwrap_or(true);
    let endian = match get("SCANIT_TYPE") {
        Some(s) if s.contains("LSBFIRST") => Endian::Little,
        _ => Endian::Big,
    };
    if let Some(s) = get("SCANIT_TYPE") {
        if !s.contains("FLOAT") {
            bail!(
                "Nanonis SXM: :SCANIT_TYPE: {:?} is not supported (only FLOAT)",
                s.trim()
            );
        }
    }
    let Some(info) = get("DATA_INFO") else {
        bail!("Nanonis SXM: missing :DATA_INFO:")
    };
    let mut out = Vec::new();
    let n = xres * yres;
    let mut idx = 0usize;
    for line in info.lines().skip(1) {
        let cols: Vec<&str> = line
            .split('\t')
            .map(|c| c.trim())
            .filter(|c| !c.is_empty())
            .collect();
        if cols.len() < 4 {
            continue;
        }
        let (name, unit, dir) = (cols[1], cols[2], cols[3]);
        let dirs: &[(bool, &str)] = match dir {
            "both" => &[(false, "Forward"), (true, "Backward")],
            "backward" => &[(true, "Backward")],
            _ => &[(false, "Forward")],
        };
        let (m, base) = parse_unit(unit);
        for &(backward, label) in dirs {
            if out.len() >= 256 {
                bail!("Nanonis SXM: more than 256 images");
            }
            let off = start + idx * n * 4;
            let what = format!("Nanonis SXM image {idx} '{name} ({label})'");
            let mut data = decode(b, off, n, Sample::F32, endian, &what)?;
            idx += 1;
            for v in &mut data {
                *v *= m;
                if !v.is_finite() {
                    *v = f64::NAN;
                }
            }
            if up {
                flip_rows(&mut data, xres, yres);
            }
            if backward {
                for row in data.chunks_exact_mut(xres) {
                    row.reverse();
                }
            }
            let mut ch = channel(
                Format::Sxm,
                &format!("{name} ({label})"),
                &base,
                "m",
                xres,
                yres,
                xreal,
                yreal,
                data,
            )?;
            ch.offset = (xo - xreal / 2.0, yo - yreal / 2.0);
            out.push(ch);
        }
    }
    if out.is_empty() {
        bail!("Nanonis SXM: :DATA_INFO: lists no channel");
    }
    Ok(out)
}
