//! KTX2 2D-array textures, RG32F or RG16F, one layer per term, the manifest in
//! the key/value data (key `sunbeam.manifest`). Follows the KTX 2.0 spec rules
//! listed in ../shared/notes/validators-and-engines.md.

use crate::manifest::{Manifest, Precision, MANIFEST_KEY};
use crate::pack::Pack;
use sunbeam_common::{Error, Result};

/// The 12-byte file identifier «KTX 20»\r\n\x1A\n.
pub const IDENTIFIER: [u8; 12] = sunbeam_common::magic::KTX2;
/// VK_FORMAT_R32G32_SFLOAT.
pub const VK_R32G32_SFLOAT: u32 = 103;
/// VK_FORMAT_R16G16_SFLOAT.
pub const VK_R16G16_SFLOAT: u32 = 83;

const HEADER_LEN: usize = 80;
const LEVEL_INDEX_LEN: usize = 24;

fn align(v: usize, a: usize) -> usize {
    v.div_ceil(a) * a
}

/// The Data Format Descriptor for RG32F / RG16F (basic block, two float samples).
pub fn dfd(precision: Precision) -> Vec<u8> {
    let (bits, bytes_plane) = match precision {
        Precision::F32 => (32u32, 8u8),
        Precision::F16 => (16u32, 4u8),
    };
    let block_size = 24 + 16 * 2;
    let mut d = Vec::with_capacity(4 + block_size);
    d.extend_from_slice(&((4 + block_size) as u32).to_le_bytes()); // dfdTotalSize
    d.extend_from_slice(&0u32.to_le_bytes()); // vendorId 0 (Khronos), descriptorType 0 (basic)
    d.extend_from_slice(&(2u32 | ((block_size as u32) << 16)).to_le_bytes()); // version 2, block size
                                                                              // colorModel RGBSDA (1), primaries unspecified (0), transfer LINEAR (1), flags 0
    d.extend_from_slice(&[1, 0, 1, 0]);
    d.extend_from_slice(&[0, 0, 0, 0]); // texelBlockDimension 1x1x1x1 (stored minus 1)
    d.extend_from_slice(&[bytes_plane, 0, 0, 0]); // bytesPlane0..3
    d.extend_from_slice(&[0, 0, 0, 0]); // bytesPlane4..7
    for ch in 0..2u32 {
        let bit_offset = ch * bits;
        let channel_type = ch | 0x40 | 0x80; // R=0/G=1, signed, float
        let w0 = bit_offset | ((bits - 1) << 16) | (channel_type << 24);
        d.extend_from_slice(&w0.to_le_bytes());
        d.extend_from_slice(&0u32.to_le_bytes()); // samplePosition 0
        d.extend_from_slice(&(-1.0f32).to_bits().to_le_bytes()); // sampleLower
        d.extend_from_slice(&1.0f32.to_bits().to_le_bytes()); // sampleUpper
    }
    d
}

/// Key/value data: entries sorted by key bytes, each padded to 4 bytes with zeros.
fn kvd(entries: &mut [(Vec<u8>, Vec<u8>)]) -> Vec<u8> {
    entries.sort_by(|a, b| a.0.cmp(&b.0));
    let mut out = Vec::new();
    for (k, v) in entries.iter() {
        let len = k.len() + 1 + v.len();
        out.extend_from_slice(&(len as u32).to_le_bytes());
        out.extend_from_slice(k);
        out.push(0);
        out.extend_from_slice(v);
        while out.len() % 4 != 0 {
            out.push(0);
        }
    }
    out
}

/// Total file size for a pack (for reports and preallocation).
pub fn encoded_len(m: &Manifest, writer: &str) -> usize {
    encode_parts(m, writer).0
}

/// (total length, header+index+dfd+kvd+padding bytes). The level data follows the prefix.
fn encode_parts(m: &Manifest, writer: &str) -> (usize, Vec<u8>) {
    let precision = m.precision;
    let texel = match precision {
        Precision::F32 => 8usize,
        Precision::F16 => 4,
    };
    let d = dfd(precision);
    let mut writer_value = writer.as_bytes().to_vec();
    writer_value.push(0); // KTXwriter is a NUL-terminated UTF-8 string
    let mut entries = vec![
        (b"KTXwriter".to_vec(), writer_value),
        (MANIFEST_KEY.as_bytes().to_vec(), m.to_json().into_bytes()),
    ];
    let k = kvd(&mut entries);
    let dfd_off = HEADER_LEN + LEVEL_INDEX_LEN;
    let kvd_off = dfd_off + d.len();
    let data_off = align(kvd_off + k.len(), lcm(texel, 4));
    let data_len = m.terms * m.layer_texels() * texel;

    let mut h = Vec::with_capacity(data_off);
    h.extend_from_slice(&IDENTIFIER);
    let vk = match precision {
        Precision::F32 => VK_R32G32_SFLOAT,
        Precision::F16 => VK_R16G16_SFLOAT,
    };
    let type_size: u32 = match precision {
        Precision::F32 => 4,
        Precision::F16 => 2,
    };
    for v in [
        vk,
        type_size,
        m.crop.width as u32,
        m.crop.height as u32,
        0, // pixelDepth
        m.terms as u32,
        1, // faceCount
        1, // levelCount
        0, // supercompressionScheme
        dfd_off as u32,
        d.len() as u32,
        kvd_off as u32,
        k.len() as u32,
    ] {
        h.extend_from_slice(&v.to_le_bytes());
    }
    h.extend_from_slice(&0u64.to_le_bytes()); // sgdByteOffset
    h.extend_from_slice(&0u64.to_le_bytes()); // sgdByteLength
    debug_assert_eq!(h.len(), HEADER_LEN);
    for v in [data_off as u64, data_len as u64, data_len as u64] {
        h.extend_from_slice(&v.to_le_bytes());
    }
    h.extend_from_slice(&d);
    h.extend_from_slice(&k);
    h.resize(data_off, 0);
    (data_off + data_len, h)
}

fn lcm(a: usize, b: usize) -> usize {
    fn gcd(a: usize, b: usize) -> usize {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
    a / gcd(a, b) * b
}

/// Stream a pack as KTX2 into `out` (no second copy of the level data in memory).
pub fn write_to(pack: &Pack, writer: &str, out: &mut impl std::io::Write) -> std::io::Result<u64> {
    let (total, head) = encode_parts(&pack.manifest, writer);
    out.write_all(&head)?;
    let mut buf = Vec::with_capacity(1 << 16);
    for chunk in pack.terms.chunks(1 << 14) {
        buf.clear();
        match pack.manifest.precision {
            Precision::F32 => chunk
                .iter()
                .for_each(|v| buf.extend_from_slice(&v.to_le_bytes())),
            Precision::F16 => chunk
                .iter()
                .for_each(|v| buf.extend_from_slice(&half::f16::from_f32(*v).to_le_bytes())),
        }
        out.write_all(&buf)?;
    }
    Ok(total as u64)
}

/// Encode a pack as KTX2 bytes (the terms are converted to the manifest's precision).
pub fn encode(pack: &Pack, writer: &str) -> Vec<u8> {
    let (total, mut out) = encode_parts(&pack.manifest, writer);
    out.reserve(total - out.len());
    match pack.manifest.precision {
        Precision::F32 => {
            for v in &pack.terms {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        Precision::F16 => {
            for v in &pack.terms {
                out.extend_from_slice(&half::f16::from_f32(*v).to_le_bytes());
            }
        }
    }
    debug_assert_eq!(out.len(), total);
    out
}

fn u32_at(b: &[u8], off: usize) -> Result<u32> {
    b.get(off..off + 4)
        .map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
        .ok_or_else(|| Error::input(format!("KTX2: truncated at byte {off}")))
}

fn u64_at(b: &[u8], off: usize) -> Result<u64> {
    b.get(off..off + 8)
        .map(|s| u64::from_le_bytes(s.try_into().expect("8 bytes")))
        .ok_or_else(|| Error::input(format!("KTX2: truncated at byte {off}")))
}

/// Parsed key/value entries (key without NUL, raw value).
pub fn key_values(bytes: &[u8]) -> Result<Vec<(String, Vec<u8>)>> {
    let off = u32_at(bytes, 56)? as usize;
    let len = u32_at(bytes, 60)? as usize;
    if len == 0 {
        return Ok(vec![]);
    }
    let end = off
        .checked_add(len)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| {
            Error::input(format!(
                "KTX2: key/value data {off}+{len} runs past the end of the file ({})",
                bytes.len()
            ))
        })?;
    let kv = &bytes[off..end];
    let mut p = 0;
    let mut out = Vec::new();
    while p + 4 <= kv.len() {
        let n = u32_at(kv, p)? as usize;
        let body = kv
            .get(p + 4..p + 4 + n)
            .ok_or_else(|| Error::input("KTX2: key/value entry runs past the key/value data"))?;
        let nul = body
            .iter()
            .position(|&c| c == 0)
            .ok_or_else(|| Error::input("KTX2: key without NUL"))?;
        let key = String::from_utf8(body[..nul].to_vec())
            .map_err(|_| Error::input("KTX2: key is not UTF-8"))?;
        out.push((key, body[nul + 1..].to_vec()));
        p = align(p + 4 + n, 4);
    }
    Ok(out)
}

/// The manifest and texture shape of a KTX2 pack from its head (header through
/// the key/value data; the level data need not be there), checked against
/// each other.
pub fn decode_head(bytes: &[u8]) -> Result<(Manifest, Precision, usize, usize, usize)> {
    if bytes.len() < HEADER_LEN + LEVEL_INDEX_LEN || !bytes.starts_with(&IDENTIFIER) {
        return Err(Error::input(
            "not a KTX2 file (bad identifier or too short)",
        ));
    }
    let vk = u32_at(bytes, 12)?;
    let precision = match vk {
        VK_R32G32_SFLOAT => Precision::F32,
        VK_R16G16_SFLOAT => Precision::F16,
        _ => {
            return Err(Error::input(format!(
                "KTX2: vkFormat {vk} is not RG32F (103) or RG16F (83)"
            )))
        }
    };
    let width = u32_at(bytes, 20)? as usize;
    let height = u32_at(bytes, 24)? as usize;
    let layers = u32_at(bytes, 32)?.max(1) as usize;
    let levels = u32_at(bytes, 40)?;
    let scheme = u32_at(bytes, 44)?;
    if levels != 1 || scheme != 0 {
        return Err(Error::input(format!(
            "KTX2: levelCount {levels} / supercompression {scheme}: expected 1 / 0"
        )));
    }
    let manifest_bytes = key_values(bytes)?
        .into_iter()
        .find(|(k, _)| k == MANIFEST_KEY)
        .map(|(_, v)| v)
        .ok_or_else(|| {
            Error::input(format!("KTX2: no '{MANIFEST_KEY}' key: not a sunbeam pack"))
        })?;
    let text = std::str::from_utf8(&manifest_bytes)
        .map_err(|_| Error::input("KTX2: manifest is not UTF-8"))?
        .trim_end_matches('\0');
    let manifest = Manifest::from_json(text)?;
    if manifest.crop.width != width || manifest.crop.height != height || manifest.terms != layers {
        return Err(Error::input(format!(
            "KTX2: texture {width}x{height}x{layers} does not match the manifest ({}x{}x{})",
            manifest.crop.width, manifest.crop.height, manifest.terms
        )));
    }
    if manifest.precision != precision {
        return Err(Error::input(
            "KTX2: vkFormat does not match the manifest's precision",
        ));
    }
    Ok((manifest, precision, width, height, layers))
}

/// Decode a KTX2 pack.
pub fn decode(bytes: &[u8]) -> Result<Pack> {
    let (manifest, precision, width, height, layers) = decode_head(bytes)?;
    let texel = if precision == Precision::F32 { 8 } else { 4 };
    let off = u64_at(bytes, 80)?;
    let len = u64_at(bytes, 88)?;
    let want = (width as u64) * (height as u64) * (layers as u64) * texel;
    if len != want {
        return Err(Error::input(format!(
            "KTX2: level byteLength {len}, expected {want}"
        )));
    }
    let end = off
        .checked_add(len)
        .filter(|&e| e <= bytes.len() as u64)
        .ok_or_else(|| {
            Error::input(format!(
                "KTX2: level data {off}+{len} runs past the end of the file ({} bytes)",
                bytes.len()
            ))
        })?;
    let data = &bytes[off as usize..end as usize];
    let terms: Vec<f32> = match precision {
        Precision::F32 => data
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
        Precision::F16 => data
            .chunks_exact(2)
            .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32())
            .collect(),
    };
    Pack::new(manifest, terms)
}
