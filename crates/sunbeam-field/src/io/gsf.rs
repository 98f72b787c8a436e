//! Gwyddion Simple Field (`.gsf`): a text header of `Key = Value` lines after
//! the line `Gwyddion Simple Field 1.0`, NUL-padded (1 to 4 NULs) to a multiple
//! of 4 bytes, then XRes*YRes little-endian float32 values, row 0 = top.
//! Provenance goes into extra keys (`SunbeamSource`, `SunbeamFormat`,
//! `SunbeamProcessing`), which Gwyddion keeps as metadata.

use crate::{HeightField, Provenance, MAX_SIDE};
use sunbeam_common::{Error, Result};

/// First line of every GSF file.
pub const MAGIC: &str = "Gwyddion Simple Field 1.0\n";

fn one_line(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c == '\n' || c == '\r' || c == '\0' {
                ' '
            } else {
                c
            }
        })
        .collect()
}

/// Encode `field` as GSF (heights in metres, lateral units metres).
pub fn encode(field: &HeightField) -> Result<Vec<u8>> {
    let (w, h) = (field.width, field.height);
    if w == 0 || h == 0 || field.data.len() != w * h {
        return Err(Error::internal(format!(
            "cannot write a {w}x{h} field with {} values",
            field.data.len()
        )));
    }
    let p = &field.provenance;
    let mut s = String::from(MAGIC);
    s += &format!("XRes = {w}\nYRes = {h}\n");
    s += &format!(
        "XReal = {:e}\nYReal = {:e}\n",
        field.size_x(),
        field.size_y()
    );
    s += "XYUnits = m\nZUnits = m\n";
    let title = if p.channel.is_empty() {
        "Height".to_string()
    } else {
        one_line(&p.channel)
    };
    s += &format!("Title = {title}\n");
    if !p.source_file.is_empty() {
        s += &format!("SunbeamSource = {}\n", one_line(&p.source_file));
    }
    if !p.source_format.is_empty() {
        s += &format!("SunbeamFormat = {}\n", one_line(&p.source_format));
    }
    if !p.processing.is_empty() {
        s += &format!(
            "SunbeamProcessing = {}\n",
            one_line(&p.processing.join("; "))
        );
    }
    let mut out = s.into_bytes();
    let pad = 4 - out.len() % 4;
    out.resize(out.len() + pad, 0);
    out.reserve(w * h * 4);
    for &v in &field.data {
        out.extend_from_slice(&(v as f32).to_le_bytes());
    }
    Ok(out)
}

/// What a GSF header says, with the raw values.
#[derive(Debug, Clone)]
pub struct RawGsf {
    pub width: usize,
    pub height: usize,
    pub xreal: f64,
    pub yreal: f64,
    pub xy_unit: String,
    pub z_unit: String,
    pub title: String,
    pub data: Vec<f64>,
    pub provenance: Provenance,
}

/// Decode a GSF file, checking the header against the file length.
pub fn decode_raw(bytes: &[u8]) -> Result<RawGsf> {
    if !bytes.starts_with(MAGIC.as_bytes()) {
        return Err(Error::input(
            "not a Gwyddion Simple Field file (first line is not 'Gwyddion Simple Field 1.0')",
        ));
    }
    let nul = bytes.iter().position(|&b| b == 0).ok_or_else(|| {
        Error::input("GSF header is not terminated by a NUL byte (truncated file?)")
    })?;
    let data_start = (nul / 4 + 1) * 4;
    if data_start > bytes.len() || bytes[nul..data_start].iter().any(|&b| b != 0) {
        return Err(Error::input(
            "GSF header padding is not NUL bytes up to a multiple of 4",
        ));
    }
    let text = std::str::from_utf8(&bytes[MAGIC.len()..nul])
        .map_err(|_| Error::input("GSF header is not UTF-8 text"))?;
    let mut keys: Vec<(String, String)> = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let (k, v) = line.split_once('=').ok_or_else(|| {
            Error::input(format!("GSF header line '{line}' is not 'Key = Value'"))
        })?;
        keys.push((k.trim().to_string(), v.trim().to_string()));
    }
    let get = |k: &str| keys.iter().find(|(kk, _)| kk == k).map(|(_, v)| v.as_str());
    let res = |k: &str| -> Result<usize> {
        let v = get(k).ok_or_else(|| Error::input(format!("GSF header has no {k}")))?;
        let n: usize = v
            .parse()
            .map_err(|_| Error::input(format!("GSF {k} = '{v}' is not a positive integer")))?;
        if n == 0 || n > MAX_SIDE {
            return Err(Error::input(format!(
                "GSF {k} = {n} is outside 1..{MAX_SIDE}"
            )));
        }
        Ok(n)
    };
    let (w, h) = (res("XRes")?, res("YRes")?);
    let real = |k: &str| -> Result<f64> {
        match get(k) {
            None => Ok(1.0),
            Some(v) => {
                let x: f64 = v
                    .parse()
                    .map_err(|_| Error::input(format!("GSF {k} = '{v}' is not a number")))?;
                if !(x.is_finite() && x > 0.0) {
                    return Err(Error::input(format!(
                        "GSF {k} = {v} must be finite and positive"
                    )));
                }
                Ok(x)
            }
        }
    };
    let (xreal, yreal) = (real("XReal")?, real("YReal")?);
    let need = w * h * 4;
    let have = bytes.len() - data_start;
    if have < need {
        return Err(Error::input(format!(
            "GSF declares {w}x{h} float32 values ({need} bytes) but only {have} bytes follow the header (truncated file?)"
        )));
    }
    let data = bytes[data_start..data_start + need]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64)
        .collect();
    let provenance = Provenance {
        source_file: get("SunbeamSource").unwrap_or("").to_string(),
        source_format: get("SunbeamFormat").unwrap_or("").to_string(),
        channel: get("Title").unwrap_or("").to_string(),
        processing: get("SunbeamProcessing")
            .map(|s| {
                s.split("; ")
                    .filter(|x| !x.is_empty())
                    .map(str::to_string)
                    .collect()
            })
            .unwrap_or_default(),
    };
    Ok(RawGsf {
        width: w,
        height: h,
        xreal,
        yreal,
        xy_unit: get("XYUnits").unwrap_or("").to_string(),
        z_unit: get("ZUnits").unwrap_or("").to_string(),
        title: get("Title").unwrap_or("").to_string(),
        data,
        provenance,
    })
}

/// Decode a GSF height field. Lateral and z units must be metres (or absent,
/// then taken as metres).
pub fn decode(bytes: &[u8]) -> Result<HeightField> {
    let r = decode_raw(bytes)?;
    for (what, u) in [("XYUnits", &r.xy_unit), ("ZUnits", &r.z_unit)] {
        if !(u.is_empty() || u == "m") {
            return Err(Error::input(format!(
                "GSF {what} = '{u}': only metres can be read as a height field"
            )));
        }
    }
    let mut f = HeightField::new(
        r.width,
        r.height,
        r.xreal / r.width as f64,
        r.yreal / r.height as f64,
        r.data,
    )?;
    f.provenance = r.provenance;
    Ok(f)
}
