//! Reading the scale maps back (`sunbeam-bake --scales`, docs/BAKE.md
//! "Scales"): the material's `normalTexture` and the
//! `SUNBEAM_materials_diffraction.orientationTexture`, decoded, with the
//! bilinear lookup the reference renderer uses.
//!
//! The lookup follows the texture's sampler (wrap REPEAT or CLAMP_TO_EDGE per
//! axis, so a periodic `v` has no seam at the UV border). Normals and ridge
//! directions are interpolated as vectors and renormalised (never as angles);
//! the ridge vectors are weighted by the groove mask as well, so that across a
//! scale border the scale that shows dominates and the border lies in the
//! groove, where the mask takes the light away.

use crate::gltf::Document;
use serde_json::Value;
use sunbeam_common::{Error, Result};

/// One decoded RGBA8 texture with its wrap modes.
#[derive(Debug, Clone)]
pub struct Rgba8 {
    pub size: [u32; 2],
    pub data: Vec<u8>,
    /// Wrap REPEAT (true) or clamp (false) along s (u) and t (v).
    pub repeat: [bool; 2],
}

/// The two maps of a scaled material.
#[derive(Debug, Clone)]
pub struct ScaleMaps {
    pub normal: Rgba8,
    pub orient: Rgba8,
    /// TEXCOORD set the maps use.
    pub texcoord: usize,
}

/// What a lookup returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleSample {
    /// Tangent-space normal (unit; X along TANGENT, Y along the glTF bitangent).
    pub normal: [f64; 3],
    /// Ridge direction (cos a, sin a) in the (T, N x T) frame, unit.
    pub ridge: [f64; 2],
    /// Groove mask in [0, 1].
    pub mask: f64,
}

/// Decode an RGBA8 (or RGB8) PNG.
pub fn decode_png(bytes: &[u8]) -> std::result::Result<([u32; 2], Vec<u8>), String> {
    let dec = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut r = dec.read_info().map_err(|e| format!("PNG: {e}"))?;
    let mut buf = vec![0u8; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).map_err(|e| format!("PNG: {e}"))?;
    if info.bit_depth != png::BitDepth::Eight {
        return Err("PNG: expected 8 bits per channel".into());
    }
    let px = (info.width * info.height) as usize;
    let data = match info.color_type {
        png::ColorType::Rgba => buf[..px * 4].to_vec(),
        png::ColorType::Rgb => buf[..px * 3]
            .chunks(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        c => return Err(format!("PNG: expected RGB or RGBA, got {c:?}")),
    };
    Ok(([info.width, info.height], data))
}

/// The decoded image of `textures[tex]` (a bufferView or URI PNG).
fn texture(doc: &mut Document, tex: usize, what: &str) -> Result<Rgba8> {
    let source = doc.source.clone();
    let err = |m: String| Error::input_file(&source, format!("{what}: {m}"));
    let t = doc
        .array("textures")
        .get(tex)
        .cloned()
        .ok_or_else(|| err(format!("textures[{tex}] does not exist")))?;
    let src = t
        .get("source")
        .and_then(Value::as_u64)
        .ok_or_else(|| err(format!("textures[{tex}].source missing")))? as usize;
    let wrap = |k: &str| {
        t.get("sampler")
            .and_then(Value::as_u64)
            .and_then(|s| doc.array("samplers").get(s as usize))
            .and_then(|s| s.get(k))
            .and_then(Value::as_u64)
            .is_none_or(|w| w != 33071)
    };
    let repeat = [wrap("wrapS"), wrap("wrapT")];
    let img = doc
        .array("images")
        .get(src)
        .cloned()
        .ok_or_else(|| err(format!("images[{src}] does not exist")))?;
    let bytes = if let Some(bv) = img.get("bufferView").and_then(Value::as_u64) {
        doc.view_bytes(bv as usize, what)?.0.to_vec()
    } else if let Some(uri) = img.get("uri").and_then(Value::as_str) {
        doc.read_uri(uri, what)?.0
    } else {
        return Err(err(format!("images[{src}] has neither bufferView nor uri")));
    };
    let (size, data) = decode_png(&bytes).map_err(|m| err(format!("images[{src}]: {m}")))?;
    Ok(Rgba8 { size, data, repeat })
}

/// The scale maps of material `m`, or None when it has no orientation texture.
pub fn read(doc: &mut Document, m: usize) -> Result<Option<ScaleMaps>> {
    let mat = doc
        .array("materials")
        .get(m)
        .cloned()
        .unwrap_or(Value::Null);
    let Some(ot) = mat.pointer(&format!(
        "/extensions/{}/orientationTexture",
        crate::diffraction_ext::EXTENSION
    )) else {
        return Ok(None);
    };
    let what = format!("materials[{m}]");
    let idx = |v: &Value, k: &str| -> Result<usize> {
        v.get("index")
            .and_then(Value::as_u64)
            .map(|i| i as usize)
            .ok_or_else(|| Error::input_file(&doc.source, format!("{what}: {k}.index missing")))
    };
    let oi = idx(ot, "orientationTexture")?;
    let nt = mat.get("normalTexture").ok_or_else(|| {
        Error::input_file(
            &doc.source,
            format!("{what}: orientationTexture without normalTexture"),
        )
    })?;
    let ni = idx(nt, "normalTexture")?;
    let texcoord = ot.get("texCoord").and_then(Value::as_u64).unwrap_or(0) as usize;
    let normal = texture(doc, ni, &format!("{what}.normalTexture"))?;
    let orient = texture(doc, oi, &format!("{what}.orientationTexture"))?;
    Ok(Some(ScaleMaps {
        normal,
        orient,
        texcoord,
    }))
}

impl Rgba8 {
    /// The four bilinear taps at `uv` (texel centres at (i + 0.5) / size):
    /// (weight, byte offset of the texel).
    pub fn taps(&self, uv: [f64; 2]) -> [(f64, usize); 4] {
        let axis = |x: f64, n: u32, rep: bool| -> ([usize; 2], f64) {
            let n = n.max(1) as i64;
            let t = x * n as f64 - 0.5;
            let f = t.floor();
            let w = t - f;
            let f = f as i64;
            let idx = |i: i64| if rep { i.rem_euclid(n) } else { i.clamp(0, n - 1) } as usize;
            ([idx(f), idx(f + 1)], w)
        };
        let u = if uv[0].is_finite() { uv[0] } else { 0.0 };
        let v = if uv[1].is_finite() { uv[1] } else { 0.0 };
        let ([x0, x1], wx) = axis(u, self.size[0], self.repeat[0]);
        let ([y0, y1], wy) = axis(v, self.size[1], self.repeat[1]);
        let w = self.size[0] as usize;
        let at = |x: usize, y: usize| (y * w + x) * 4;
        [
            ((1.0 - wx) * (1.0 - wy), at(x0, y0)),
            (wx * (1.0 - wy), at(x1, y0)),
            ((1.0 - wx) * wy, at(x0, y1)),
            (wx * wy, at(x1, y1)),
        ]
    }
}

/// 8-bit channel to [-1, 1].
fn snorm(b: u8) -> f64 {
    b as f64 / 255.0 * 2.0 - 1.0
}

fn unit3(v: [f64; 3]) -> Option<[f64; 3]> {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (l > 1e-9).then(|| v.map(|x| x / l))
}

impl ScaleMaps {
    /// Bilinear lookup at `uv` (see the module docs).
    pub fn sample(&self, uv: [f64; 2]) -> ScaleSample {
        let n = &self.normal;
        let mut nv = [0.0; 3];
        for (w, o) in n.taps(uv) {
            for k in 0..3 {
                nv[k] += w * snorm(n.data[o + k]);
            }
        }
        let normal = unit3(nv).unwrap_or([0.0, 0.0, 1.0]);
        let t = &self.orient;
        let (mut r, mut mask, mut best) = ([0.0; 3], 0.0, (-1.0, 0));
        for (w, o) in t.taps(uv) {
            let m = t.data[o + 2] as f64 / 255.0;
            mask += w * m;
            r[0] += w * (m + 1e-3) * snorm(t.data[o]);
            r[1] += w * (m + 1e-3) * snorm(t.data[o + 1]);
            if w > best.0 {
                best = (w, o);
            }
        }
        let ridge = unit3(r).or_else(|| {
            let o = best.1;
            unit3([snorm(t.data[o]), snorm(t.data[o + 1]), 0.0])
        });
        let ridge = ridge.map_or([1.0, 0.0], |r| [r[0], r[1]]);
        ScaleSample {
            normal,
            ridge,
            mask,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn enc(x: f64) -> u8 {
        ((0.5 + 0.5 * x) * 255.0).round() as u8
    }

    /// Two texels along u (ridges at +-40 deg, normals tilted +-x), one row
    /// repeated around v: u clamps, v wraps with no seam.
    fn maps() -> ScaleMaps {
        let (a, n) = (40f64.to_radians(), 0.3f64);
        let nz = (1.0 - n * n).sqrt();
        let normal = Rgba8 {
            size: [2, 2],
            data: [[enc(n), 128, enc(nz), 255], [enc(-n), 128, enc(nz), 255]]
                .repeat(2)
                .concat(),
            repeat: [false, true],
        };
        let orient = Rgba8 {
            size: [2, 2],
            data: [
                [enc(a.cos()), enc(a.sin()), 255, 0],
                [enc(a.cos()), enc(-a.sin()), 255, 1],
            ]
            .repeat(2)
            .concat(),
            repeat: [false, true],
        };
        ScaleMaps {
            normal,
            orient,
            texcoord: 0,
        }
    }

    #[test]
    fn vectors_are_interpolated_and_renormalised() {
        let m = maps();
        let mid = m.sample([0.5, 0.25]);
        // Halfway: the ridge vectors' mean points along +u, unit (an angle
        // average would agree here; the length check is the vector's).
        assert!((mid.ridge[0] - 1.0).abs() < 1e-9 && mid.ridge[1].abs() < 0.01);
        let l = mid.normal.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((l - 1.0).abs() < 1e-12 && mid.normal[0].abs() < 0.01);
        // At a texel centre, the texel's own value.
        let c = m.sample([0.25, 0.25]);
        assert!((c.ridge[1].atan2(c.ridge[0]).to_degrees() - 40.0).abs() < 0.5);
        // u clamps at the borders.
        assert_eq!(m.sample([0.0, 0.25]), m.sample([0.25, 0.25]));
    }

    #[test]
    fn v_wraps_without_a_seam() {
        let m = maps();
        let a = m.sample([0.3, 1e-9]);
        let b = m.sample([0.3, 1.0 - 1e-9]);
        for k in 0..3 {
            assert!((a.normal[k] - b.normal[k]).abs() < 1e-6);
        }
        assert!((a.mask - b.mask).abs() < 1e-6);
        assert_eq!(m.sample([0.3, 0.1]), m.sample([0.3, 1.1]));
    }
}
