//! Gwyddion Simple Field `.gsf`: a text header `Key = Value` after the magic
//! line, NUL padding to a multiple of 4, then little-endian float32 data, row 0 at the top.

use sunbeam_common::Result;

use crate::util::{bail, channel, check_dims, decode, leading_f64, Endian, Sample};
use crate::{Channel, Format};

pub const MAGIC: &[u8] = b"Gwyddion Simple Field 1.0\n";

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    if !b.starts_with(MAGIC) {
        bail!("not a GSF file (first line is not `Gwyddion Simple Field 1.0`)");
    }
    let Some(nul) = b.iter().position(|&c| c == 0) else {
        bail!("GSF header is not terminated by NUL padding (truncated?)")
    };
    let head = String::from_utf8_lossy(&b[MAGIC.len()..nul]);
    let mut get = std::collections::HashMap::new();
    for line in head.lines() {
        if let Some((k, v)) = line.split_once('=') {
            get.entry(k.trim().to_string())
                .or_insert_with(|| v.trim().to_string());
        }
    }
    let n = |k: &str| -> Result<Option<f64>> {
        match get.get(k) {
            None => Ok(None),
            Some(v) => match leading_f64(v) {
                Some((x, _)) if x.is_finite() => Ok(Some(x)),
                _ => bail!("GSF header: `{k}` is not a number ({v:?})"),
            },
        }
    };
    let Some(xres) = n("XRes")? else {
        bail!("GSF header: missing `XRes`")
    };
    let Some(yres) = n("YRes")? else {
        bail!("GSF header: missing `YRes`")
    };
    let (xres, yres) = check_dims(xres as i64, yres as i64, "GSF XRes x YRes")?;
    let xreal = n("XReal")?.unwrap_or(1.0);
    let yreal = n("YReal")?.unwrap_or(1.0);
    let data_start = (nul / 4 + 1) * 4;
    if b[nul..data_start.min(b.len())].iter().any(|&c| c != 0) {
        bail!("GSF header padding is not NUL bytes");
    }
    let mut data = decode(
        b,
        data_start,
        xres * yres,
        Sample::F32,
        Endian::Little,
        "GSF data",
    )?;
    if b.len() > data_start + xres * yres * 4 {
        bail!(
            "GSF data: {} bytes after the {xres}x{yres} float32 values",
            b.len() - data_start - xres * yres * 4
        );
    }
    for v in &mut data {
        if !v.is_finite() {
            *v = f64::NAN;
        }
    }
    let title = get.get("Title").cloned().unwrap_or_else(|| "Data".into());
    let xy = get.get("XYUnits").cloned().unwrap_or_default();
    let z = get.get("ZUnits").cloned().unwrap_or_default();
    let mut ch = channel(Format::Gsf, &title, &z, &xy, xres, yres, xreal, yreal, data)?;
    ch.offset = (n("XOffset")?.unwrap_or(0.0), n("YOffset")?.unwrap_or(0.0));
    Ok(vec![ch])
}
