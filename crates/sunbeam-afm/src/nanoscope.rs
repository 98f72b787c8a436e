//! Bruker/Veeco Nanoscope (v4.3x, v5+, v9+): a text header of `\Key: value`
//! lines in `\*Section` lists, then little-endian int16/int32 images.
//!
//! z = raw / 256^bpp * (Z scale hard value, V) * (@Sens. <soft scale>, e.g. nm/V);
//! images are stored bottom row first.

use std::collections::HashMap;

use sunbeam_common::Result;

use crate::util::{
    bail, channel, check_dims, decode, flip_rows, leading_f64, parse_unit, slice, Endian, Sample,
};
use crate::{Channel, Format};

pub fn detect(b: &[u8]) -> bool {
    b.starts_with(b"\\*File list")
        || b.starts_with(b"\\*EC File list")
        || b.starts_with(b"?*File list")
}

/// One `\*Section` of the header: its name and `key -> raw value` (first wins).
struct Section {
    name: String,
    kv: Vec<(String, String)>,
}

impl Section {
    fn get(&self, k: &str) -> Option<&str> {
        self.kv
            .iter()
            .find(|(kk, _)| kk.eq_ignore_ascii_case(k))
            .map(|(_, v)| v.as_str())
    }
}

/// Header parsed into sections (lines after `\*File list end` are not read).
fn parse_header(b: &[u8]) -> Result<(Vec<Section>, usize)> {
    // The header length is the first `\Data length` of the file list; the text
    // ends at `\*File list end` at the latest.
    let limit = b.len().min(1 << 22);
    let text = &b[..limit];
    let end = find(text, b"\\*File list end").unwrap_or(limit);
    let head = String::from_utf8_lossy(&text[..end]);
    let mut sections: Vec<Section> = Vec::new();
    for raw in head.split(['\r', '\n']) {
        let line = raw.trim_end();
        if line.is_empty() {
            continue;
        }
        let line = line
            .strip_prefix('?')
            .map(|l| format!("\\{l}"))
            .unwrap_or_else(|| line.to_string());
        let Some(rest) = line.strip_prefix('\\') else {
            continue;
        };
        if let Some(name) = rest.strip_prefix('*') {
            sections.push(Section {
                name: name.trim().to_string(),
                kv: Vec::new(),
            });
            continue;
        }
        // Key: "@2:Z scale" keeps its "@2:" prefix; the separator is ": " after it.
        let start = if rest.len() > 3
            && rest.starts_with('@')
            && rest.as_bytes()[1].is_ascii_digit()
            && rest.as_bytes()[2] == b':'
        {
            3
        } else {
            0
        };
        let Some(pos) = rest[start..].find(':').map(|p| p + start) else {
            continue;
        };
        let key = rest[..pos].trim().to_string();
        let val = rest[pos + 1..].trim().to_string();
        if let Some(s) = sections.last_mut() {
            s.kv.push((key, val));
        }
    }
    if sections.is_empty() {
        bail!("Nanoscope header: no `\\*File list` section");
    }
    Ok((sections, end))
}

fn find(h: &[u8], n: &[u8]) -> Option<usize> {
    h.windows(n.len()).position(|w| w == n)
}

/// A parsed `@` value: "V [Sens. Zscan] (0.0065 V/LSB) 41.6 V".
#[derive(Debug, Default)]
struct Value {
    soft_scale: Option<String>,
    hard_value: f64,
    hard_unit: String,
}

fn parse_at_value(v: &str) -> Option<Value> {
    let mut s = v.trim();
    // type letter V/S/C then space
    let mut out = Value::default();
    if s.len() >= 2 && matches!(s.as_bytes()[0], b'V' | b'S' | b'C') && s.as_bytes()[1] == b' ' {
        s = s[2..].trim_start();
    }
    if let Some(r) = s.strip_prefix('[') {
        let close = r.find(']')?;
        let name = r[..close].trim();
        if !name.is_empty() {
            out.soft_scale = Some(name.to_string());
        }
        s = r[close + 1..].trim_start();
    }
    if let Some(r) = s.strip_prefix('(') {
        // Matching parenthesis: units like "log(Arb)/LSB" nest.
        let mut depth = 1usize;
        let close = r.char_indices().find_map(|(i, c)| {
            match c {
                '(' => depth += 1,
                ')' => depth -= 1,
                _ => {}
            }
            (depth == 0).then_some(i)
        })?;
        s = r[close + 1..].trim_start();
    }
    let (val, rest) = leading_f64(s)?;
    out.hard_value = val;
    out.hard_unit = rest.trim().to_string();
    Some(out)
}

struct Image {
    name: String,
    xres: usize,
    yres: usize,
    xreal: f64,
    yreal: f64,
    xy_unit: String,
    offset: usize,
    length: usize,
    bpp: usize,
    scale: f64,
    z_unit: String,
}

fn num(sec: &Section, key: &str) -> Result<f64> {
    let Some(v) = sec.get(key) else {
        bail!("Nanoscope image list: missing field `{key}`")
    };
    match leading_f64(v) {
        Some((x, _)) if x.is_finite() => Ok(x),
        _ => bail!("Nanoscope image list: field `{key}` is not a number ({v:?})"),
    }
}

/// Parse the header into image descriptions (no data read).
fn images(b: &[u8]) -> Result<Vec<Image>> {
    let (sections, _end) = parse_header(b)?;
    let version = sections
        .iter()
        .find(|s| s.name.ends_with("File list"))
        .and_then(|s| s.get("Version"))
        .and_then(|v| {
            u32::from_str_radix(
                v.trim().trim_start_matches("0x").trim_start_matches("0X"),
                16,
            )
            .ok()
        })
        .unwrap_or(0);
    // Sensitivities (@Sens. xxx) from the scanner and scan lists; first wins.
    let mut sens: HashMap<String, Value> = HashMap::new();
    let (mut gxres, mut gyres) = (None, None);
    for s in &sections {
        let lname = s.name.to_ascii_lowercase();
        if lname == "scanner list"
            || lname == "microscope list"
            || lname == "ciao scan list"
            || lname == "afm list"
        {
            for (k, v) in &s.kv {
                if let Some(n) = k.strip_prefix('@') {
                    if n.starts_with("Sens.") && !sens.contains_key(n) {
                        if let Some(pv) = parse_at_value(v) {
                            sens.insert(n.to_string(), pv);
                        }
                    }
                }
            }
            if lname == "ciao scan list" {
                gxres = s.get("Samps/line").and_then(leading_f64).map(|x| x.0);
                gyres = s.get("Lines").and_then(leading_f64).map(|x| x.0);
            }
        }
    }
    let mut out = Vec::new();
    for s in &sections {
        let lname = s.name.to_ascii_lowercase();
        if lname != "ciao image list" && lname != "afm image list" && lname != "ncafm image list" {
            continue;
        }
        let idx = out.len();
        let ctx = |m: String| format!("Nanoscope image #{idx}: {m}");
        let xres_f = num(s, "Samps/line")?;
        let yres_f = num(s, "Number of lines")?;
        let (mut xres, mut yres) = check_dims(
            xres_f.round() as i64,
            yres_f.round() as i64,
            "Nanoscope Samps/line x Number of lines",
        )?;
        let bpp_hdr = s
            .get("Bytes/pixel")
            .and_then(leading_f64)
            .map(|x| x.0.round() as i64)
            .unwrap_or(2);
        if !matches!(bpp_hdr, 1 | 2 | 4) {
            bail!(
                "{}",
                ctx(format!("`Bytes/pixel` is {bpp_hdr} (expected 2 or 4)"))
            );
        }
        let offset = num(s, "Data offset")?;
        let length = num(s, "Data length")?;
        if !(0.0..=u32::MAX as f64).contains(&offset) || !(0.0..=u32::MAX as f64).contains(&length)
        {
            bail!(
                "{}",
                ctx(format!(
                    "`Data offset` {offset} / `Data length` {length} out of range"
                ))
            );
        }
        let (offset, length) = (offset as usize, length as usize);
        // Scan size: "1.76908 1.76908 ~m" (x y unit) or old "1769.08 nm".
        let Some(ss) = s.get("Scan size").or_else(|| s.get("Scan Size")) else {
            bail!("{}", ctx("missing field `Scan size`".into()))
        };
        let Some((x, rest)) = leading_f64(ss) else {
            bail!("{}", ctx(format!("cannot parse `Scan size` {ss:?}")))
        };
        let (y, unit) = match leading_f64(rest) {
            Some((y, u)) => (y, u.trim()),
            None => (x, rest.trim()),
        };
        let (m, base) = parse_unit(unit.split_whitespace().next().unwrap_or(""));
        let mut xreal = x * m;
        let mut yreal = y * m;
        // Storage size: int32 from version 9.2 on, or as Bytes/pixel says.
        let n = xres * yres;
        let mut bpp = if version >= 0x0920_0000 {
            4
        } else {
            bpp_hdr as usize
        };
        if length != bpp * n {
            if version >= 0x0920_0000 && length == 2 * n {
                bpp = 2;
            } else if length == 4 * n {
                bpp = 4;
            } else if let (Some(gx), Some(gy)) = (gxres, gyres) {
                // Sizes in the image list may be bogus; the scan list's count.
                let (gx, gy) = check_dims(
                    gx.round() as i64,
                    gy.round() as i64,
                    "Nanoscope scan list Samps/line x Lines",
                )?;
                if length == bpp * gx * gy {
                    xreal *= gx as f64 / xres as f64;
                    yreal *= gy as f64 / yres as f64;
                    xres = gx;
                    yres = gy;
                } else {
                    bail!("{}", ctx(format!("`Data length` {length} does not match {xres}x{yres} pixels of {bpp} bytes")));
                }
            } else {
                bail!(
                    "{}",
                    ctx(format!(
                        "`Data length` {length} does not match {xres}x{yres} pixels of {bpp} bytes"
                    ))
                );
            }
        }
        // Lines fewer than samples: the slow axis is shorter (square pixels).
        yreal *= yres as f64 / xres as f64;
        // Name: `@2:Image Data: S [Height] "Height"` or old `Image data: Height`.
        let name = if let Some(v) = s.get("@2:Image Data").or_else(|| s.get("@Image Data")) {
            let quoted = v.split('"').nth(1).filter(|q| !q.trim().is_empty());
            let bracket = v.find('[').and_then(|a| {
                v[a + 1..]
                    .find(']')
                    .map(|b| v[a + 1..a + 1 + b].to_string())
            });
            quoted
                .map(|q| q.to_string())
                .or(bracket)
                .unwrap_or_else(|| format!("Channel {idx}"))
        } else if let Some(v) = s.get("Image data") {
            v.trim().to_string()
        } else {
            format!("Channel {idx}")
        };
        // Z scale.
        let (scale, z_unit) = if let Some(v) = s.get("@2:Z scale").or_else(|| s.get("@Z scale")) {
            let Some(zv) = parse_at_value(v) else {
                bail!("{}", ctx(format!("cannot parse `Z scale` {v:?}")))
            };
            let soft = zv.soft_scale.clone().unwrap_or_default();
            match sens.get(&soft) {
                Some(sv) => {
                    let raw_unit = sv.hard_unit.split_whitespace().next().unwrap_or("");
                    if raw_unit.is_empty() {
                        let u = if soft == "Sens. Phase" { "deg" } else { "V" };
                        (zv.hard_value * sv.hard_value, u.to_string())
                    } else {
                        // "nm/V" times the V of the hard value.
                        let num_unit = raw_unit.strip_suffix("/V").unwrap_or(raw_unit);
                        let (m, base) = parse_unit(num_unit);
                        (zv.hard_value * sv.hard_value * m, base)
                    }
                }
                None => (zv.hard_value, String::new()),
            }
        } else if let Some(v) = s.get("Z scale") {
            // v4.1 style: "Z scale: 41.6 V (0.0065 V/LSB)" or a value with unit.
            let Some((val, rest)) = leading_f64(v) else {
                bail!("{}", ctx(format!("cannot parse `Z scale` {v:?}")))
            };
            let u = rest.split('(').next().unwrap_or("").trim();
            let (m, base) = parse_unit(u);
            (val * m * 65536.0 / 65536.0, base)
        } else {
            bail!("{}", ctx("missing field `Z scale`".into()))
        };
        if !scale.is_finite() {
            bail!("{}", ctx("Z scale is not finite".into()));
        }
        let _ = ctx;
        out.push(Image {
            name,
            xres,
            yres,
            xreal,
            yreal,
            xy_unit: base,
            offset,
            length,
            bpp,
            scale,
            z_unit,
        });
    }
    Ok(out)
}

/// Header facts (no data read), for `--list` on damaged files.
pub fn header_images(b: &[u8]) -> Result<Vec<HeaderImage>> {
    if !detect(b) {
        bail!("not a Nanoscope file (no `\\*File list` at the start)");
    }
    Ok(images(b)?
        .into_iter()
        .map(|i| HeaderImage {
            name: i.name,
            xres: i.xres,
            yres: i.yres,
            xreal: i.xreal,
            yreal: i.yreal,
            z_unit: i.z_unit,
            xy_unit: i.xy_unit,
        })
        .collect())
}

pub struct HeaderImage {
    pub name: String,
    pub xres: usize,
    pub yres: usize,
    pub xreal: f64,
    pub yreal: f64,
    pub z_unit: String,
    pub xy_unit: String,
}

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    if !detect(b) {
        bail!("not a Nanoscope file (no `\\*File list` at the start)");
    }
    let imgs = images(b)?;
    if imgs.is_empty() {
        bail!("Nanoscope file has no `\\*Ciao image list` section");
    }
    let crlf = b[..b.len().min(4096)].windows(2).any(|w| w == b"\r\n");
    let mut out = Vec::new();
    for (i, im) in imgs.iter().enumerate() {
        let n = im.xres * im.yres;
        let need = n * im.bpp;
        let what = format!(
            "Nanoscope image #{i} '{}' data (`Data offset` {})",
            im.name, im.offset
        );
        if im.offset.checked_add(need).is_none_or(|e| e > b.len()) {
            bail!(
                "{what}: needs {need} bytes at offset {} but the file has only {} bytes ({})",
                im.offset,
                b.len(),
                if crlf {
                    "truncated"
                } else {
                    "truncated, or damaged by a change of line endings"
                }
            );
        }
        slice(b, im.offset, need, &what)?;
        let t = match im.bpp {
            1 => Sample::I8,
            2 => Sample::I16,
            4 => Sample::I32,
            _ => bail!(
                "Nanoscope image #{i}: unsupported {} bytes per pixel",
                im.bpp
            ),
        };
        let q = im.scale / 256f64.powi(im.bpp as i32);
        let mut data = decode(b, im.offset, n, t, Endian::Little, &what)?;
        for v in &mut data {
            *v *= q;
        }
        flip_rows(&mut data, im.xres, im.yres);
        let _ = im.length;
        out.push(channel(
            Format::Nanoscope,
            &im.name,
            &im.z_unit,
            &im.xy_unit,
            im.xres,
            im.yres,
            im.xreal,
            im.yreal,
            data,
        )?);
    }
    Ok(out)
}
