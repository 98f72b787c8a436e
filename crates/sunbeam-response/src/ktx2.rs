//! KTX2 files of response maps: one 3D texture, `VK_FORMAT_R16G16B16A16_SFLOAT`,
//! one level, no supercompression, the [`Info`](crate::Info) JSON under the key
//! `sunbeam.response` (and `KTXwriter`). Hand-written rather than through a
//! crate because the `ktx2` crate only reads, and the layout is a few fixed
//! fields (KTX 2.0 spec sections 3-4; the same rules as sunbeam-pack's
//! 2D-array writer, which this mirrors for a 3D, four-channel texture; the
//! identifier comes from `sunbeam_common::magic`).

use crate::{Info, Response, INFO_KEY};
use sunbeam_common::magic::KTX2 as IDENTIFIER;
use sunbeam_common::{Error, Result};

/// VK_FORMAT_R16G16B16A16_SFLOAT.
pub const VK_R16G16B16A16_SFLOAT: u32 = 97;
const HEADER_LEN: usize = 80;
const LEVEL_INDEX_LEN: usize = 24;
const TEXEL: usize = 8;

fn dfd() -> Vec<u8> {
    let block = 24 + 16 * 4;
    let mut d = Vec::with_capacity(4 + block);
    d.extend_from_slice(&((4 + block) as u32).to_le_bytes());
    d.extend_from_slice(&0u32.to_le_bytes()); // Khronos, basic descriptor
    d.extend_from_slice(&(2u32 | ((block as u32) << 16)).to_le_bytes());
    d.extend_from_slice(&[1, 1, 1, 0]); // RGBSDA, BT.709 primaries, linear, flags 0
    d.extend_from_slice(&[0, 0, 0, 0]); // 1x1x1x1 block
    d.extend_from_slice(&[TEXEL as u8, 0, 0, 0, 0, 0, 0, 0]);
    for (c, id) in [0u32, 1, 2, 15].into_iter().enumerate() {
        let w0 = (c as u32 * 16) | (15 << 16) | ((id | 0xC0) << 24); // signed float
        d.extend_from_slice(&w0.to_le_bytes());
        d.extend_from_slice(&0u32.to_le_bytes());
        d.extend_from_slice(&(-1.0f32).to_bits().to_le_bytes());
        d.extend_from_slice(&1.0f32.to_bits().to_le_bytes());
    }
    d
}

fn kvd(key: &str, info_json: &str) -> Vec<u8> {
    let writer = format!("sunbeam-response {}", env!("CARGO_PKG_VERSION"));
    let mut out = Vec::new();
    // Sorted by key bytes: "KTXwriter" < "sunbeam.*".
    for (k, v) in [("KTXwriter", writer.as_str()), (key, info_json)] {
        let len = k.len() + 1 + v.len() + 1;
        out.extend_from_slice(&(len as u32).to_le_bytes());
        out.extend_from_slice(k.as_bytes());
        out.push(0);
        out.extend_from_slice(v.as_bytes());
        out.push(0);
        while out.len() % 4 != 0 {
            out.push(0);
        }
    }
    out
}

/// Encode a map as KTX2 bytes (deterministic).
pub fn encode(r: &Response) -> Vec<u8> {
    let g = &r.info.grid;
    let info = serde_json::to_string(&r.info).expect("info serialises");
    encode_texture(INFO_KEY, &info, [g.n_theta, g.n_rho, g.n_s], &r.data)
}

/// A 3D RGBA16F texture of `size` texels (`data`: f16 bits, layer-major) with
/// `info_json` under `key`, as KTX2 bytes (deterministic).
pub(crate) fn encode_texture(
    key: &str,
    info_json: &str,
    size: [usize; 3],
    data: &[u16],
) -> Vec<u8> {
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    encode_levels(
        VK_R16G16B16A16_SFLOAT,
        2,
        dfd(),
        key,
        info_json,
        size,
        &[bytes],
    )
}

/// VK_FORMAT_R32_UINT.
pub const VK_R32_UINT: u32 = 98;
/// VK_FORMAT_R32G32B32A32_UINT.
pub const VK_R32G32B32A32_UINT: u32 = 107;

/// The data format descriptor of R32_UINT (`channels` 1) or
/// R32G32B32A32_UINT (4): 32-bit unsigned samples R, G, B, A.
fn dfd_uint(channels: usize) -> Vec<u8> {
    let block = 24 + 16 * channels;
    let mut d = Vec::with_capacity(4 + block);
    d.extend_from_slice(&((4 + block) as u32).to_le_bytes());
    d.extend_from_slice(&0u32.to_le_bytes()); // Khronos, basic descriptor
    d.extend_from_slice(&(2u32 | ((block as u32) << 16)).to_le_bytes());
    d.extend_from_slice(&[1, 1, 1, 0]); // RGBSDA, BT.709 primaries, linear, flags 0
    d.extend_from_slice(&[0, 0, 0, 0]); // 1x1x1x1 block
    d.extend_from_slice(&[4 * channels as u8, 0, 0, 0, 0, 0, 0, 0]);
    for (c, id) in [0u32, 1, 2, 15].into_iter().take(channels).enumerate() {
        // bit offset, 32 bits, the channel, unsigned integer
        let w0 = (c as u32 * 32) | (31 << 16) | (id << 24);
        d.extend_from_slice(&w0.to_le_bytes());
        d.extend_from_slice(&0u32.to_le_bytes());
        d.extend_from_slice(&0u32.to_le_bytes());
        d.extend_from_slice(&u32::MAX.to_le_bytes());
    }
    d
}

/// A 2D texture for engines (`sunbeam-play --export-environment`), as KTX2
/// bytes (deterministic), `info_json` under `key`.
pub enum Texture2d<'a> {
    /// RGBA16F (f16 bits, rows top first), with its mip levels: `(width,
    /// height, texels)` level 0 first.
    Rgba16f(&'a [(usize, usize, Vec<u16>)]),
    /// R32_UINT, one level.
    R32u(usize, usize, &'a [u32]),
    /// R32G32B32A32_UINT, one level (4 words a texel).
    Rgba32u(usize, usize, &'a [u32]),
}

/// Encode a [`Texture2d`].
pub fn encode_2d(key: &str, info_json: &str, t: &Texture2d<'_>) -> Vec<u8> {
    match t {
        Texture2d::Rgba16f(levels) => {
            let bytes: Vec<Vec<u8>> = levels
                .iter()
                .map(|(_, _, d)| d.iter().flat_map(|v| v.to_le_bytes()).collect())
                .collect();
            let (w, h, _) = &levels[0];
            encode_levels(
                VK_R16G16B16A16_SFLOAT,
                2,
                dfd(),
                key,
                info_json,
                [*w, *h, 0],
                &bytes,
            )
        }
        Texture2d::R32u(w, h, data) => encode_uint(VK_R32_UINT, 1, key, info_json, [*w, *h], data),
        Texture2d::Rgba32u(w, h, data) => {
            encode_uint(VK_R32G32B32A32_UINT, 4, key, info_json, [*w, *h], data)
        }
    }
}

/// One level of 32-bit unsigned words, `channels` a texel.
fn encode_uint(
    vk_format: u32,
    channels: usize,
    key: &str,
    info_json: &str,
    [w, h]: [usize; 2],
    data: &[u32],
) -> Vec<u8> {
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    encode_levels(
        vk_format,
        4,
        dfd_uint(channels),
        key,
        info_json,
        [w, h, 0],
        &[bytes],
    )
}

/// The container around `levels` (level 0 first; stored smallest first, as
/// KTX 2.0 section 3.9 asks, each at a multiple of 8 bytes, or of the texel
/// where it is 16: the least common multiple of the texel's size and 4 that
/// section asks for, at least 8).
fn encode_levels(
    vk_format: u32,
    type_size: u32,
    dfd: Vec<u8>,
    key: &str,
    info_json: &str,
    size: [usize; 3],
    levels: &[Vec<u8>],
) -> Vec<u8> {
    let kvd = kvd(key, info_json);
    let dfd_off = HEADER_LEN + LEVEL_INDEX_LEN * levels.len();
    let kvd_off = dfd_off + dfd.len();
    let mut offsets = vec![0usize; levels.len()];
    // the texel's bytes, from the descriptor's bytesPlane0
    let align = usize::from(dfd[20]).max(TEXEL);
    let mut at = (kvd_off + kvd.len()).div_ceil(align) * align;
    for (m, level) in levels.iter().enumerate().rev() {
        offsets[m] = at;
        at = (at + level.len()).div_ceil(align) * align;
    }
    let mut out = Vec::with_capacity(at);
    out.extend_from_slice(&IDENTIFIER);
    for v in [
        vk_format,
        type_size,
        size[0] as u32,
        size[1] as u32,
        size[2] as u32,
        0, // layerCount
        1, // faceCount
        levels.len() as u32,
        0, // supercompression
        dfd_off as u32,
        dfd.len() as u32,
        kvd_off as u32,
        kvd.len() as u32,
    ] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&0u64.to_le_bytes()); // sgd offset
    out.extend_from_slice(&0u64.to_le_bytes()); // sgd length
    for (m, level) in levels.iter().enumerate() {
        let len = level.len() as u64;
        for v in [offsets[m] as u64, len, len] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out.extend_from_slice(&dfd);
    out.extend_from_slice(&kvd);
    for (m, level) in levels.iter().enumerate().rev() {
        out.resize(offsets[m], 0);
        out.extend_from_slice(level);
    }
    out
}

/// Whether `bytes` look like a response map (KTX2 with a `sunbeam.response` key).
pub fn is_response(bytes: &[u8]) -> bool {
    bytes.starts_with(&IDENTIFIER)
        && bytes.len() >= HEADER_LEN
        && u32::from_le_bytes(bytes[12..16].try_into().unwrap()) == VK_R16G16B16A16_SFLOAT
}

/// Decode KTX2 bytes; every size is checked against the file length first.
pub fn decode(bytes: &[u8]) -> Result<Response> {
    let (text, [w, h, d], raw) = decode_texture(bytes, INFO_KEY)?;
    let data = halves(raw);
    let info: Info = serde_json::from_str(&text)
        .map_err(|e| Error::input(format!("{INFO_KEY} JSON is invalid: {e}")))?;
    let g = &info.grid;
    if (g.n_theta, g.n_rho, g.n_s) != (w, h, d) {
        return Err(Error::input(format!(
            "{INFO_KEY} grid {}x{}x{} differs from the texture {w}x{h}x{d}",
            g.n_theta, g.n_rho, g.n_s
        )));
    }
    let r = Response { info, data };
    r.validate()?;
    Ok(r)
}

/// The JSON under `key`, the size and the texels (f16 bits) of a KTX2 3D
/// RGBA16F texture (raw little-endian bytes); every size is checked against
/// the file length first.
pub(crate) fn decode_texture<'a>(
    bytes: &'a [u8],
    key: &str,
) -> Result<(String, [usize; 3], &'a [u8])> {
    decode_as(bytes, key, VK_R16G16B16A16_SFLOAT, TEXEL)
}

/// The JSON under `key`, the size and the raw level of a one-level KTX2
/// R32_UINT texture (the first-frame cells, `NAME.env-cells.ktx2`); every
/// size is checked against the file length first.
pub(crate) fn decode_r32u<'a>(
    bytes: &'a [u8],
    key: &str,
) -> Result<(String, [usize; 3], &'a [u8])> {
    decode_as(bytes, key, VK_R32_UINT, 4)
}

/// The name of a vkFormat this module reads.
fn format_name(vk_format: u32) -> &'static str {
    if vk_format == VK_R32_UINT {
        "R32_UINT"
    } else {
        "a response map's R16G16B16A16_SFLOAT"
    }
}

/// [`decode_texture`] for texels of `vk_format`, `texel` bytes each.
fn decode_as<'a>(
    bytes: &'a [u8],
    key: &str,
    vk_format: u32,
    texel: usize,
) -> Result<(String, [usize; 3], &'a [u8])> {
    let what = format_name(vk_format);
    if !bytes.starts_with(&IDENTIFIER) {
        return Err(Error::input("not a KTX2 file (wrong identifier)"));
    }
    if bytes.len() < HEADER_LEN + LEVEL_INDEX_LEN {
        return Err(Error::input("KTX2 file truncated in its header"));
    }
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    let u64_at = |o: usize| u64::from_le_bytes(bytes[o..o + 8].try_into().unwrap());
    if u32_at(12) != vk_format {
        return Err(Error::input(format!(
            "KTX2 vkFormat {} is not {what} ({vk_format})",
            u32_at(12)
        )));
    }
    let (w, h, d) = (
        u32_at(20) as usize,
        u32_at(24) as usize,
        u32_at(28) as usize,
    );
    if u32_at(36) != 1 || u32_at(40) != 1 || u32_at(44) != 0 {
        return Err(Error::input(
            "KTX2 response map must have one face, one level, no supercompression",
        ));
    }
    let (kvd_off, kvd_len) = (u32_at(56) as usize, u32_at(60) as usize);
    let (lv_off, lv_len) = (u64_at(80), u64_at(88));
    let need = (w as u128) * (h as u128) * (d.max(1) as u128) * texel as u128;
    if lv_len as u128 != need
        || lv_off
            .checked_add(lv_len)
            .is_none_or(|e| e > bytes.len() as u64)
        || kvd_off.checked_add(kvd_len).is_none_or(|e| e > bytes.len())
    {
        return Err(Error::input(format!(
            "KTX2 level of {lv_len} bytes at {lv_off} does not fit a {w}x{h}x{d} texture ({what}) in a {}-byte file",
            bytes.len()
        )));
    }
    let text = parse_entry(bytes, kvd_off, kvd_len, key)?;
    Ok((
        text,
        [w, h, d],
        &bytes[lv_off as usize..(lv_off + lv_len) as usize],
    ))
}

/// Little-endian f16 bits from raw texel bytes.
pub(crate) fn halves(raw: &[u8]) -> Vec<u16> {
    raw.chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect()
}

/// The value (text) under `key` in the key/value data at `kvd_off..+kvd_len`.
pub(crate) fn parse_entry(
    bytes: &[u8],
    kvd_off: usize,
    kvd_len: usize,
    key: &str,
) -> Result<String> {
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    if kvd_off.checked_add(kvd_len).is_none_or(|e| e > bytes.len()) {
        return Err(Error::input(
            "KTX2 key/value data runs past the end of the file",
        ));
    }
    let mut p = kvd_off;
    while p + 4 <= kvd_off + kvd_len {
        let len = u32_at(p) as usize;
        let Some(entry) = bytes.get(p + 4..p + 4 + len) else {
            return Err(Error::input("KTX2 key/value data truncated"));
        };
        if let Some(z) = entry.iter().position(|&b| b == 0) {
            if &entry[..z] == key.as_bytes() {
                let v = &entry[z + 1..];
                let v = v.strip_suffix(&[0]).unwrap_or(v);
                return std::str::from_utf8(v)
                    .map(str::to_owned)
                    .map_err(|_| Error::input(format!("{key} is not UTF-8")));
            }
        }
        p += 4 + len.div_ceil(4) * 4;
    }
    Err(Error::input(format!("KTX2 file has no {key} key")))
}

/// Only a map's description (grid, wavelengths, the pack's manifest), from the
/// file's head: the texels are not read (the player checks a map against its
/// pack this way before it reads either in full).
pub fn read_info(path: &std::path::Path) -> Result<Info> {
    let text = read_entry(path, INFO_KEY)?;
    serde_json::from_str(&text).map_err(|e| {
        Error::input(format!("{INFO_KEY} JSON is invalid: {e}")).context(path.display().to_string())
    })
}

/// The text under `key`, the texture's size and the level's byte offset from
/// a KTX2 3D RGBA16F file's head (the texels are not read; the level must lie
/// inside the file).
pub(crate) fn read_head_layout(
    path: &std::path::Path,
    key: &str,
) -> Result<(String, [usize; 3], u64)> {
    read_head_as(path, key, VK_R16G16B16A16_SFLOAT, TEXEL)
}

/// [`read_head_layout`] for a one-level texture of `vk_format`, `texel`
/// bytes per texel.
pub(crate) fn read_head_as(
    path: &std::path::Path,
    key: &str,
    vk_format: u32,
    texel: usize,
) -> Result<(String, [usize; 3], u64)> {
    let text = read_entry_as(path, key, vk_format)?;
    let head = sunbeam_common::magic::read_ktx2_head(path)?
        .ok_or_else(|| Error::input_file(path, "not a KTX2 file (wrong identifier)"))?;
    let u32_at = |o: usize| u32::from_le_bytes(head[o..o + 4].try_into().unwrap());
    let u64_at = |o: usize| u64::from_le_bytes(head[o..o + 8].try_into().unwrap());
    if head.len() < HEADER_LEN + LEVEL_INDEX_LEN {
        return Err(Error::input_file(path, "KTX2 file truncated in its header"));
    }
    let size = [u32_at(20), u32_at(24), u32_at(28)].map(|v| v as usize);
    if u32_at(36) != 1 || u32_at(40) != 1 || u32_at(44) != 0 {
        return Err(Error::input_file(
            path,
            "KTX2 response map must have one face, one level, no supercompression",
        ));
    }
    let (lv_off, lv_len) = (u64_at(80), u64_at(88));
    let need = size.iter().map(|&v| v.max(1) as u128).product::<u128>() * texel as u128;
    let file_len = std::fs::metadata(path)
        .map_err(|e| Error::input_file(path, e))?
        .len();
    if lv_len as u128 != need || lv_off.checked_add(lv_len).is_none_or(|e| e > file_len) {
        return Err(Error::input_file(
            path,
            format!(
                "KTX2 level of {lv_len} bytes at {lv_off} does not fit a {}x{}x{} texture of {texel}-byte texels in a {file_len}-byte file",
                size[0], size[1], size[2]
            ),
        ));
    }
    Ok((text, size, lv_off))
}

/// The text under `key` from a KTX2 file's head (the texels are not read).
pub(crate) fn read_entry(path: &std::path::Path, key: &str) -> Result<String> {
    read_entry_as(path, key, VK_R16G16B16A16_SFLOAT)
}

/// [`read_entry`] from a texture of `vk_format`.
fn read_entry_as(path: &std::path::Path, key: &str, vk_format: u32) -> Result<String> {
    let head = sunbeam_common::magic::read_ktx2_head(path)?
        .ok_or_else(|| Error::input_file(path, "not a KTX2 file (wrong identifier)"))?;
    let ctx = |e: Error| e.context(path.display().to_string());
    if head.len() < HEADER_LEN + LEVEL_INDEX_LEN {
        return Err(ctx(Error::input("KTX2 file truncated in its header")));
    }
    let u32_at = |o: usize| u32::from_le_bytes(head[o..o + 4].try_into().unwrap());
    if u32_at(12) != vk_format {
        return Err(ctx(Error::input(format!(
            "KTX2 vkFormat {} is not {} ({vk_format})",
            u32_at(12),
            format_name(vk_format)
        ))));
    }
    parse_entry(&head, u32_at(56) as usize, u32_at(60) as usize, key).map_err(ctx)
}

/// Read a map from a file (errors name the file).
pub fn read(path: &std::path::Path) -> Result<Response> {
    let bytes = std::fs::read(path).map_err(|e| Error::input_file(path, e))?;
    decode(&bytes).map_err(|e| e.context(path.display().to_string()))
}

/// Write a map atomically.
pub fn write(r: &Response, path: &std::path::Path) -> Result<()> {
    sunbeam_common::output::write_atomic(path, &encode(r))
}
