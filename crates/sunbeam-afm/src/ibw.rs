//! Igor binary wave v5 (Asylum Research): a 64-byte BinHeader5, a 320-byte
//! WaveHeader5, the data (dimension 0 fastest), then formula, note (Asylum
//! scan parameters), units and dimension labels (channel names, 32 bytes each).
//!
//! An image wave is nDim[0] x nDim[1] (x, y) with one layer per channel;
//! Gwyddion shows row r, column c = wave[c, nDim1-1-r]: x along columns, y up.
//! xreal = nDim[0] * sfA[0] (Asylum writes sfA = ScanSize/(N-1)).

use sunbeam_common::Result;

use crate::util::{
    bail, channel, check_dims, decode, f64_at, flip_rows, i16_at, i32_at, parse_unit, slice,
    Endian, Sample,
};
use crate::{Channel, Format};

const BIN_HEADER: usize = 64;
const WAVE_HEADER: usize = 320;

fn endian(b: &[u8]) -> Option<Endian> {
    if b.len() < 2 {
        return None;
    }
    match (b[0], b[1]) {
        (5, 0) => Some(Endian::Little),
        (0, 5) => Some(Endian::Big),
        _ => None,
    }
}

pub fn detect(b: &[u8]) -> bool {
    let Some(e) = endian(b) else { return false };
    if b.len() < BIN_HEADER + WAVE_HEADER {
        return false;
    }
    // wfmSize must cover the wave header, and whVersion (offset 26 in the wave header) is 1.
    let wfm = i32_at(b, 4, e, "").unwrap_or(0);
    let whv = i16_at(b, BIN_HEADER + 26, e, "").unwrap_or(0);
    wfm >= WAVE_HEADER as i32 && whv == 1
}

fn cstr(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).trim().to_string()
}

fn channel_unit(name: &str, data_unit: &str) -> String {
    let n = name.to_ascii_lowercase();
    if n.contains("phase") {
        "deg".into()
    } else if n.contains("current") {
        "A".into()
    } else if n.contains("potential")
        || n.contains("bias")
        || n.contains("voltage")
        || n.contains("volt")
    {
        "V".into()
    } else if n.contains("frequency") {
        "Hz".into()
    } else if !data_unit.is_empty() {
        data_unit.into()
    } else if n.contains("height")
        || n.contains("zsensor")
        || n.contains("amplitude")
        || n.contains("deflection")
    {
        "m".into()
    } else {
        String::new()
    }
}

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    let Some(e) = endian(b) else {
        if b.len() >= 2 {
            let v = i16_at(b, 0, Endian::Little, "")?;
            if (1..=3).contains(&v) || (1..=3).contains(&v.swap_bytes()) {
                bail!(
                    "Igor binary wave version {} is not supported (only version 5)",
                    v.min(v.swap_bytes())
                );
            }
        }
        bail!("not an Igor binary wave v5 (version field is not 5)");
    };
    slice(b, 0, BIN_HEADER + WAVE_HEADER, "Igor wave headers")?;
    let wfm = i32_at(b, 4, e, "Igor wfmSize")?;
    let formula = i32_at(b, 8, e, "Igor formulaSize")?;
    let note = i32_at(b, 12, e, "Igor noteSize")?;
    let data_e_units = i32_at(b, 16, e, "Igor dataEUnitsSize")?;
    let mut dim_e_units = [0i32; 4];
    let mut dim_labels = [0i32; 4];
    for k in 0..4 {
        dim_e_units[k] = i32_at(b, 20 + 4 * k, e, "Igor dimEUnitsSize")?;
        dim_labels[k] = i32_at(b, 36 + 4 * k, e, "Igor dimLabelsSize")?;
    }
    let sizes = [wfm, formula, note, data_e_units];
    if sizes
        .iter()
        .chain(&dim_e_units)
        .chain(&dim_labels)
        .any(|&s| s < 0)
    {
        bail!("Igor wave: negative section size in the binary header");
    }
    if (wfm as usize) < WAVE_HEADER {
        bail!("Igor wave: wfmSize {wfm} is smaller than the wave header");
    }
    let w = BIN_HEADER;
    let npnts = i32_at(b, w + 12, e, "Igor npnts")?;
    let typ = i16_at(b, w + 16, e, "Igor data type")?;
    let wname = cstr(slice(b, w + 28, 32, "Igor wave name")?);
    let mut ndim = [0i64; 4];
    let mut sfa = [0f64; 4];
    for k in 0..4 {
        ndim[k] = i32_at(b, w + 68 + 4 * k, e, "Igor nDim")? as i64;
        sfa[k] = f64_at(b, w + 84 + 8 * k, e, "Igor sfA")?;
    }
    let data_unit = cstr(slice(b, w + 148, 4, "Igor dataUnits")?);
    let dim_unit = [
        cstr(slice(b, w + 152, 4, "Igor dimUnits")?),
        cstr(slice(b, w + 156, 4, "Igor dimUnits")?),
    ];
    if ndim.iter().any(|&d| d < 0) {
        bail!("Igor wave: negative dimension in nDim {ndim:?}");
    }
    let is_len = |u: &str| parse_unit(u).1 == "m";
    if ndim[1] < 2
        || ndim[0] < 2
        || !(is_len(&dim_unit[0]) && is_len(&dim_unit[1])
            || dim_unit[0].is_empty() && dim_unit[1].is_empty() && ndim[0] == ndim[1])
    {
        bail!(
            "Igor wave '{wname}' ({}x{}{}, x unit '{}', y unit '{}') is not an image: a force curve or spectrum? \
             Only AFM image waves (x and y in metres) are read",
            ndim[0],
            ndim[1],
            if ndim[2] > 0 { format!("x{}", ndim[2]) } else { String::new() },
            dim_unit[0],
            dim_unit[1]
        );
    }
    if ndim[3] > 1 {
        bail!("Igor wave '{wname}': 4-dimensional waves are not supported");
    }
    let (xres, yres) = check_dims(ndim[0], ndim[1], "Igor nDim[0] x nDim[1]")?;
    let layers = ndim[2].max(1) as usize;
    if layers > 4096 {
        bail!("Igor wave '{wname}': {layers} layers (nDim[2]) is absurd");
    }
    let st = match typ {
        2 => Sample::F32,
        4 => Sample::F64,
        8 => Sample::I8,
        0x10 => Sample::I16,
        0x20 => Sample::I32,
        0x48 => Sample::U8,
        0x50 => Sample::U16,
        0x60 => Sample::U32,
        t => bail!("Igor wave '{wname}': data type {t:#x} is not supported (complex or text?)"),
    };
    let n = xres * yres;
    let total = n.checked_mul(layers).filter(|&t| t as i64 == npnts as i64);
    let Some(total) = total else {
        bail!("Igor wave '{wname}': npnts {npnts} does not match nDim {ndim:?}")
    };
    if total * st.size() > wfm as usize - WAVE_HEADER {
        bail!("Igor wave '{wname}': wfmSize {wfm} is too small for {total} values");
    }
    let data_off = BIN_HEADER + WAVE_HEADER;
    slice(
        b,
        data_off,
        total * st.size(),
        &format!("Igor wave '{wname}' data"),
    )?;
    // Sections after the wave: formula, note, data units, dim units, dim labels.
    let mut p = BIN_HEADER + wfm as usize + formula as usize;
    let note_txt = slice(b, p, note as usize, "Igor note")
        .map(|s| String::from_utf8_lossy(s).into_owned())
        .unwrap_or_default();
    p += note as usize
        + data_e_units as usize
        + dim_e_units.iter().map(|&x| x as usize).sum::<usize>();
    let mut labels: Vec<String> = Vec::new();
    if dim_labels[2] > 0 {
        let before = dim_labels[0] as usize + dim_labels[1] as usize;
        if let Ok(s) = slice(
            b,
            p + before,
            dim_labels[2] as usize,
            "Igor dimension labels",
        ) {
            // First label names the dimension itself; then one per layer.
            labels = s.chunks(32).skip(1).map(cstr).collect();
        }
    }
    let _ = note_txt;
    let (mx, bx) = parse_unit(&dim_unit[0]);
    let (my, _) = parse_unit(&dim_unit[1]);
    let xreal = xres as f64 * sfa[0] * mx;
    let yreal = yres as f64 * sfa[1] * my;
    let xy_unit = if bx == "m" { "m" } else { "" };
    let (xreal, yreal) = if xy_unit.is_empty() {
        (xres as f64 * sfa[0], yres as f64 * sfa[1])
    } else {
        (xreal, yreal)
    };
    let mut out = Vec::new();
    for k in 0..layers {
        let mut data = decode(
            b,
            data_off + k * n * st.size(),
            n,
            st,
            e,
            &format!("Igor wave '{wname}' layer {k}"),
        )?;
        flip_rows(&mut data, xres, yres);
        let name = labels
            .get(k)
            .filter(|s| !s.is_empty())
            .cloned()
            .unwrap_or_else(|| {
                if layers == 1 {
                    wname.clone()
                } else {
                    format!("{wname} {k}")
                }
            });
        let unit = channel_unit(&name, &data_unit);
        let (m, base) = parse_unit(&unit);
        if m != 1.0 {
            for v in &mut data {
                *v *= m;
            }
        }
        out.push(channel(
            Format::Ibw,
            &name,
            &base,
            xy_unit,
            xres,
            yres,
            xreal.abs(),
            yreal.abs(),
            data,
        )?);
    }
    Ok(out)
}
