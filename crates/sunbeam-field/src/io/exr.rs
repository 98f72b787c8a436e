//! Single-channel float32 OpenEXR height fields.
//!
//! Written by hand (scanline, uncompressed, one line per chunk, increasing Y)
//! so that the bytes are fully deterministic: the `exr` crate keeps custom
//! attributes in a `HashMap` whose write order changes from run to run. Read
//! with the `exr` crate, so anything another EXR tool wrote is accepted too.
//!
//! Layout written:
//! - one channel `Z`, FLOAT, heights in metres, row 0 = top (EXR's first line);
//! - `sunbeam_dx_m`, `sunbeam_dy_m` (`double`): pixel size in metres;
//! - `sunbeam_z_unit` = `m`, `sunbeam_source_file`, `sunbeam_source_format`,
//!   `sunbeam_channel`, `sunbeam_processing` (`string`; steps joined by `; `);
//! - `pixelAspectRatio` = dx/dy so viewers show non-square pixels right.

use crate::{HeightField, Provenance, MAX_SIDE};
use sunbeam_common::{Error, Result};

/// OpenEXR magic number.
pub const MAGIC: [u8; 4] = sunbeam_common::magic::EXR;

/// Attribute names (shared with the readers of other crates).
pub const ATTR_DX: &str = "sunbeam_dx_m";
pub const ATTR_DY: &str = "sunbeam_dy_m";
pub const ATTR_Z_UNIT: &str = "sunbeam_z_unit";
pub const ATTR_SOURCE_FILE: &str = "sunbeam_source_file";
pub const ATTR_SOURCE_FORMAT: &str = "sunbeam_source_format";
pub const ATTR_CHANNEL: &str = "sunbeam_channel";
pub const ATTR_PROCESSING: &str = "sunbeam_processing";
/// Name of the height channel.
pub const CHANNEL: &str = "Z";

fn attr(out: &mut Vec<u8>, name: &str, ty: &str, value: &[u8]) {
    out.extend_from_slice(name.as_bytes());
    out.push(0);
    out.extend_from_slice(ty.as_bytes());
    out.push(0);
    out.extend_from_slice(&(value.len() as i32).to_le_bytes());
    out.extend_from_slice(value);
}

fn box2i(w: usize, h: usize) -> Vec<u8> {
    let mut v = Vec::with_capacity(16);
    for x in [0i32, 0, w as i32 - 1, h as i32 - 1] {
        v.extend_from_slice(&x.to_le_bytes());
    }
    v
}

/// EXR attribute names and strings may not hold NUL; keep them printable.
fn clean(s: &str) -> String {
    s.chars().filter(|c| *c != '\0').collect()
}

/// Encode `field` as an uncompressed single-channel float32 scanline EXR.
pub fn encode(field: &HeightField) -> Result<Vec<u8>> {
    let (w, h) = (field.width, field.height);
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE || field.data.len() != w * h {
        return Err(Error::internal(format!(
            "cannot write a {w}x{h} field with {} values",
            field.data.len()
        )));
    }
    let mut out = Vec::with_capacity(w * h * 4 + h * 16 + 1024);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&2u32.to_le_bytes()); // version 2, single-part scanline
                                                // Standard attributes, in alphabetical order as OpenEXR writes them.
    let mut ch = Vec::new();
    ch.extend_from_slice(CHANNEL.as_bytes());
    ch.push(0);
    ch.extend_from_slice(&2i32.to_le_bytes()); // FLOAT
    ch.extend_from_slice(&[0, 0, 0, 0]); // pLinear + reserved
    ch.extend_from_slice(&1i32.to_le_bytes());
    ch.extend_from_slice(&1i32.to_le_bytes());
    ch.push(0);
    attr(&mut out, "channels", "chlist", &ch);
    attr(&mut out, "compression", "compression", &[0]); // NO_COMPRESSION
    attr(&mut out, "dataWindow", "box2i", &box2i(w, h));
    attr(&mut out, "displayWindow", "box2i", &box2i(w, h));
    attr(&mut out, "lineOrder", "lineOrder", &[0]); // INCREASING_Y
    attr(
        &mut out,
        "pixelAspectRatio",
        "float",
        &((field.dx / field.dy) as f32).to_le_bytes(),
    );
    let mut v2f = Vec::new();
    v2f.extend_from_slice(&0f32.to_le_bytes());
    v2f.extend_from_slice(&0f32.to_le_bytes());
    attr(&mut out, "screenWindowCenter", "v2f", &v2f);
    attr(&mut out, "screenWindowWidth", "float", &1f32.to_le_bytes());
    // Sunbeam's attributes.
    attr(&mut out, ATTR_DX, "double", &field.dx.to_le_bytes());
    attr(&mut out, ATTR_DY, "double", &field.dy.to_le_bytes());
    attr(&mut out, ATTR_Z_UNIT, "string", b"m");
    let p = &field.provenance;
    attr(
        &mut out,
        ATTR_SOURCE_FILE,
        "string",
        clean(&p.source_file).as_bytes(),
    );
    attr(
        &mut out,
        ATTR_SOURCE_FORMAT,
        "string",
        clean(&p.source_format).as_bytes(),
    );
    attr(
        &mut out,
        ATTR_CHANNEL,
        "string",
        clean(&p.channel).as_bytes(),
    );
    attr(
        &mut out,
        ATTR_PROCESSING,
        "string",
        clean(&p.processing.join("; ")).as_bytes(),
    );
    out.push(0); // end of header
                 // Offset table: one chunk per scanline.
    let line_bytes = w * 4;
    let chunk_bytes = 8 + line_bytes;
    let first = out.len() + h * 8;
    for y in 0..h {
        out.extend_from_slice(&((first + y * chunk_bytes) as u64).to_le_bytes());
    }
    for y in 0..h {
        out.extend_from_slice(&(y as i32).to_le_bytes());
        out.extend_from_slice(&(line_bytes as i32).to_le_bytes());
        for &v in &field.data[y * w..(y + 1) * w] {
            out.extend_from_slice(&(v as f32).to_le_bytes());
        }
    }
    Ok(out)
}

/// What an EXR height field holds before calibration is decided: the pixel
/// size is optional (EXRs from other tools have none).
#[derive(Debug, Clone)]
pub struct RawExr {
    pub width: usize,
    pub height: usize,
    pub data: Vec<f64>,
    pub dx: Option<f64>,
    pub dy: Option<f64>,
    /// The channel that was read (`Z`, or the only channel).
    pub channel_name: String,
    /// The `sunbeam_z_unit` attribute when present.
    pub z_unit: Option<String>,
    pub provenance: Provenance,
}

/// Decode any single-layer EXR: the channel `Z` if present, else the only
/// channel (else `Y`, else an error listing the channels).
pub fn decode_raw(bytes: &[u8]) -> Result<RawExr> {
    use ::exr::prelude::*;
    use sunbeam_common::Error;
    if !bytes.starts_with(&MAGIC) {
        return Err(Error::input("not an OpenEXR file (wrong magic bytes)"));
    }
    // Check the header's sizes against the file length before decoding pixels.
    let meta = ::exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| Error::input(format!("invalid OpenEXR header: {e}")))?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| Error::input("OpenEXR file has no layers"))?;
    if header.deep {
        return Err(Error::input("deep OpenEXR images are not height fields"));
    }
    let (w, h) = (header.layer_size.x(), header.layer_size.y());
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(Error::input(format!(
            "OpenEXR data window {w}x{h} is outside 1..{MAX_SIDE} per side"
        )));
    }
    let nch = header.channels.list.len().max(1);
    // Uncompressed size bound: compressed data can expand at most ~1000x (zlib);
    // refuse images whose pixels could not possibly come from this many bytes.
    if (w as u128) * (h as u128) * (nch as u128) > (bytes.len() as u128) * 1100 {
        return Err(Error::input(format!(
            "OpenEXR header declares {w}x{h}x{nch} samples, more than a {}-byte file can hold",
            bytes.len()
        )));
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Error::input(format!("invalid OpenEXR data: {e}")))?;
    let layer = &image.layer_data;
    let chans = &layer.channel_data.list;
    let names: Vec<String> = chans.iter().map(|c| c.name.to_string()).collect();
    let pick = names
        .iter()
        .position(|n| n == CHANNEL)
        .or(if names.len() == 1 { Some(0) } else { None })
        .or_else(|| names.iter().position(|n| n == "Y"))
        .ok_or_else(|| {
            Error::input(format!(
                "OpenEXR file has channels [{}]: none is a height channel `Z` (and there is not exactly one channel)",
                names.join(", ")
            ))
        })?;
    let ch = &chans[pick];
    let data: Vec<f64> = match &ch.sample_data {
        FlatSamples::F16(v) => v.iter().map(|x| x.to_f32() as f64).collect(),
        FlatSamples::F32(v) => v.iter().map(|&x| x as f64).collect(),
        FlatSamples::U32(v) => v.iter().map(|&x| x as f64).collect(),
    };
    let (w, h) = (layer.size.x(), layer.size.y());
    if data.len() != w * h {
        return Err(Error::input(format!(
            "OpenEXR channel has {} samples for {w}x{h} pixels",
            data.len()
        )));
    }
    let get_f64 = |name: &str| -> Option<f64> {
        let key = Text::from(name);
        let v = layer
            .attributes
            .other
            .get(&key)
            .or_else(|| image.attributes.other.get(&key))?;
        match v {
            AttributeValue::F64(x) => Some(*x),
            AttributeValue::F32(x) => Some(*x as f64),
            _ => None,
        }
    };
    let dx = get_f64(ATTR_DX);
    let dy = get_f64(ATTR_DY);
    let get_text = |name: &str| -> Option<String> {
        let key = Text::from(name);
        let v = layer
            .attributes
            .other
            .get(&key)
            .or_else(|| image.attributes.other.get(&key))?;
        match v {
            AttributeValue::Text(t) => Some(t.to_string()),
            _ => None,
        }
    };
    let processing = get_text(ATTR_PROCESSING)
        .map(|s| {
            s.split("; ")
                .filter(|x| !x.is_empty())
                .map(str::to_string)
                .collect()
        })
        .unwrap_or_default();
    let provenance = Provenance {
        source_file: get_text(ATTR_SOURCE_FILE).unwrap_or_default(),
        source_format: get_text(ATTR_SOURCE_FORMAT).unwrap_or_default(),
        channel: get_text(ATTR_CHANNEL).unwrap_or_default(),
        processing,
    };
    Ok(RawExr {
        width: w,
        height: h,
        data,
        dx,
        dy,
        channel_name: names[pick].clone(),
        z_unit: get_text(ATTR_Z_UNIT),
        provenance,
    })
}

/// Decode an EXR height field; the pixel size attributes must be present.
pub fn decode(bytes: &[u8]) -> Result<HeightField> {
    let raw = decode_raw(bytes)?;
    let (dx, dy) = match (raw.dx, raw.dy) {
        (Some(dx), Some(dy)) => (dx, dy),
        (Some(dx), None) => (dx, dx),
        _ => {
            return Err(Error::input(format!(
                "OpenEXR file has no pixel size (attribute {ATTR_DX}); give one with --pixel-size"
            )))
        }
    };
    let mut f = HeightField::new(raw.width, raw.height, dx, dy, raw.data)?;
    f.provenance = raw.provenance;
    Ok(f)
}
