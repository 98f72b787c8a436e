//! Reading equirectangular environment maps: OpenEXR (RGB, first layer) and
//! Radiance RGBE (`.hdr`, flat or new-style run-length encoded).

use crate::EnvMap;
use std::path::Path;
use sunbeam_common::{Error, Result};

/// Load `path` (`.exr` or `.hdr`) as an [`EnvMap`]; any failure (unreadable,
/// not an image, not equirectangular, bad pixels, bad intensity) is an input
/// error naming the file and, where it is one, the scene field.
pub fn load(path: &Path, rotation_deg: f64, intensity: f64) -> Result<EnvMap> {
    let io_err = |e: std::io::Error| Error::input_file(path, format!("environment.map: {e}"));
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    // OpenEXR is read from the file through a buffer (an 8192 x 4096 map's
    // file is not held next to its texels: docs/bench/hdri.md).
    let decoded = if ext.as_deref() == Some("exr") {
        let f = std::fs::File::open(path).map_err(io_err)?;
        read_exr_from(std::io::BufReader::new(f))
    } else {
        let bytes = std::fs::read(path).map_err(io_err)?;
        decode(&bytes, ext.as_deref().unwrap_or(""))
    };
    let (w, h, rgb) =
        decoded.map_err(|e| Error::input_file(path, format!("environment.map: {e}")))?;
    EnvMap::new(w, h, rgb, rotation_deg, intensity).map_err(|e| {
        let field = match e {
            crate::EnvError::BadIntensity(_) => "environment.intensity",
            _ => "environment.map",
        };
        Error::input_file(path, format!("{field}: {e}"))
    })
}

/// Width, height and row-major RGB texels.
pub type Pixels = (usize, usize, Vec<[f32; 3]>);

/// Decode a map's bytes by its extension (`exr` or `hdr`, lower case): the
/// pixels or why not (never a panic; fuzzed by `fuzz/fuzz_targets/envmap.rs`).
pub fn decode(bytes: &[u8], ext: &str) -> std::result::Result<Pixels, String> {
    match ext {
        "exr" => read_exr(bytes),
        "hdr" => read_rgbe(bytes),
        _ => Err("must be a .hdr or .exr file".to_string()),
    }
}

fn read_exr(bytes: &[u8]) -> std::result::Result<Pixels, String> {
    read_exr_from(std::io::Cursor::new(bytes))
}

/// The first RGB layer of an OpenEXR stream, at its largest resolution.
fn read_exr_from(
    r: impl std::io::Read + std::io::Seek + Send,
) -> std::result::Result<Pixels, String> {
    use exr::prelude::{read, ReadChannels, ReadLayers, Vec2};
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |res, _| {
                (
                    res.width(),
                    res.height(),
                    vec![[0f32; 3]; res.width() * res.height()],
                )
            },
            |im: &mut Pixels, p: Vec2<usize>, (r, g, b): (f32, f32, f32)| {
                let w = im.0;
                im.2[p.y() * w + p.x()] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(r)
        .map_err(|e| format!("not an RGB OpenEXR image: {e}"))?;
    Ok(img.layer_data.channel_data.pixels)
}

/// Radiance RGBE: header lines up to an empty line, then `-Y H +X W`, then
/// scanlines (flat, or new RLE when a line starts 2 2 W_hi W_lo).
pub fn read_rgbe(bytes: &[u8]) -> std::result::Result<Pixels, String> {
    let bad = || "not a Radiance RGBE (.hdr) image".to_string();
    if !(bytes.starts_with(b"#?")) {
        return Err(bad());
    }
    let mut pos = 0;
    let line = |pos: &mut usize| -> std::result::Result<String, String> {
        let start = *pos;
        while *pos < bytes.len() && bytes[*pos] != b'\n' {
            *pos += 1;
        }
        if *pos >= bytes.len() {
            return Err(bad());
        }
        *pos += 1;
        Ok(String::from_utf8_lossy(&bytes[start..*pos - 1]).into_owned())
    };
    loop {
        let l = line(&mut pos)?;
        if l.starts_with("FORMAT=") && l.trim() != "FORMAT=32-bit_rle_rgbe" {
            return Err(format!("unsupported {l}"));
        }
        if l.trim().is_empty() {
            break;
        }
    }
    let res = line(&mut pos)?;
    let parts: Vec<&str> = res.split_whitespace().collect();
    if parts.len() != 4 || parts[0] != "-Y" || parts[2] != "+X" {
        return Err(format!(
            "unsupported resolution line '{res}' (only -Y H +X W)"
        ));
    }
    let h: usize = parts[1].parse().map_err(|_| bad())?;
    let w: usize = parts[3].parse().map_err(|_| bad())?;
    if w == 0 || h == 0 || w > 1 << 15 || h > 1 << 15 {
        return Err(format!("image size {w}x{h} out of range"));
    }
    let data = &bytes[pos..];
    let mut p = 0;
    let mut out = Vec::with_capacity(w * h);
    let mut scan = vec![[0u8; 4]; w];
    let trunc = || "truncated pixel data".to_string();
    for _ in 0..h {
        let rle = (8..32768).contains(&w)
            && data.len() >= p + 4
            && data[p] == 2
            && data[p + 1] == 2
            && ((data[p + 2] as usize) << 8 | data[p + 3] as usize) == w;
        if rle {
            p += 4;
            for c in 0..4 {
                let mut x = 0;
                while x < w {
                    let n = *data.get(p).ok_or_else(trunc)? as usize;
                    p += 1;
                    if n > 128 {
                        let n = n - 128;
                        let v = *data.get(p).ok_or_else(trunc)?;
                        p += 1;
                        if x + n > w {
                            return Err("run past the end of a scanline".into());
                        }
                        for s in &mut scan[x..x + n] {
                            s[c] = v;
                        }
                        x += n;
                    } else {
                        if n == 0 || x + n > w {
                            return Err("bad run in a scanline".into());
                        }
                        let src = data.get(p..p + n).ok_or_else(trunc)?;
                        for (s, v) in scan[x..x + n].iter_mut().zip(src) {
                            s[c] = *v;
                        }
                        p += n;
                        x += n;
                    }
                }
            }
        } else {
            let src = data.get(p..p + 4 * w).ok_or_else(trunc)?;
            for (s, v) in scan.iter_mut().zip(src.chunks_exact(4)) {
                s.copy_from_slice(v);
            }
            p += 4 * w;
        }
        out.extend(scan.iter().map(|&[r, g, b, e]| {
            if e == 0 {
                [0.0; 3]
            } else {
                let f = 2f32.powi(e as i32 - 136);
                [r as f32 * f, g as f32 * f, b as f32 * f]
            }
        }));
    }
    Ok((w, h, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rgbe_flat(w: usize, h: usize, px: [u8; 4]) -> Vec<u8> {
        let mut b = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
        for _ in 0..w * h {
            b.extend_from_slice(&px);
        }
        b
    }

    /// New-style RLE scanlines (hand-encoded: one run per channel for the
    /// first 6 texels, a literal for the last 10) decode to the same values as
    /// the flat encoding.
    #[test]
    fn reads_rle_scanlines() {
        let (w, h) = (16usize, 8usize);
        let mut b = format!("#?RADIANCE\n\n-Y {h} +X {w}\n").into_bytes();
        for _ in 0..h {
            b.extend_from_slice(&[2, 2, 0, w as u8]);
            for c in [128u8, 64, 32, 129] {
                b.extend_from_slice(&[128 + 6, c]);
                b.push(10);
                b.extend(std::iter::repeat_n(c, 10));
            }
        }
        let (rw, rh, px) = read_rgbe(&b).unwrap();
        assert_eq!((rw, rh), (w, h));
        assert!(px.iter().all(|p| *p == [1.0, 0.5, 0.25]));
        // A run past the end of the scanline is refused, not a panic.
        let mut bad = b.clone();
        let at = bad.len() - (4 + 4 * 13) * h + 4;
        bad[at] = 128 + 60;
        assert!(read_rgbe(&bad).is_err());
    }

    #[test]
    fn reads_rgbe_and_refuses_bad_maps() {
        let dir = std::env::temp_dir().join(format!("sunbeam-light-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        struct Cleanup(std::path::PathBuf);
        impl Drop for Cleanup {
            fn drop(&mut self) {
                let _ = std::fs::remove_dir_all(&self.0);
            }
        }
        let _cleanup = Cleanup(dir.clone());
        let dir = dir.as_path();
        // 128 * 2^(129 - 136) = 1.0 exactly.
        let ok = dir.join("sky.hdr");
        std::fs::write(&ok, rgbe_flat(4, 2, [128, 64, 0, 129])).unwrap();
        let m = load(&ok, 0.0, 2.0).unwrap();
        assert_eq!(m.lookup([0.0, 1.0, 0.0]), [2.0, 1.0, 0.0]);

        let wide = dir.join("wide.hdr");
        std::fs::write(&wide, rgbe_flat(6, 2, [128, 64, 0, 129])).unwrap();
        let e = load(&wide, 0.0, 1.0).unwrap_err().to_string();
        assert!(
            e.contains("wide.hdr") && e.contains("environment.map"),
            "{e}"
        );
        assert_eq!(load(&wide, 0.0, 1.0).unwrap_err().exit_code(), 2);

        let e = load(&ok, 0.0, -1.0).unwrap_err().to_string();
        assert!(
            e.contains("sky.hdr") && e.contains("environment.intensity"),
            "{e}"
        );

        let junk = dir.join("junk.exr");
        std::fs::write(&junk, b"not an image").unwrap();
        let e = load(&junk, 0.0, 1.0).unwrap_err().to_string();
        assert!(
            e.contains("junk.exr") && e.contains("environment.map"),
            "{e}"
        );

        let missing = dir.join("missing.hdr");
        assert!(load(&missing, 0.0, 1.0)
            .unwrap_err()
            .to_string()
            .contains("missing.hdr"));

        let mut cut = rgbe_flat(4, 2, [1, 2, 3, 130]);
        cut.truncate(cut.len() - 3);
        let trunc = dir.join("cut.hdr");
        std::fs::write(&trunc, cut).unwrap();
        assert!(load(&trunc, 0.0, 1.0).is_err());
    }
}
