//! The optional direction map: the baked field in UV space, as a tangent-space
//! angle, for engines that prefer a texture over a vertex attribute.
//!
//! Tangent space here is the UV frame: `T` = direction of increasing u
//! projected onto the tangent plane (what MikkTSpace gives on an unmirrored
//! layout), `B = n x T`. A texel holds the direction `d = cos(a) T + sin(a) B`
//! with `a` in (-90, 90] degrees (the axial representative that points to +u):
//! - PNG (16-bit RGB): R = 0.5 + 0.5 cos a, G = 0.5 + 0.5 sin a, B = coverage.
//! - EXR (float RGBA): R = cos a, G = sin a, B = cos 2a, A = coverage.
//!
//! Coverage is 1 where a triangle covers the texel centre, 0.5 where the value
//! was dilated (across UV seams and island borders, `dilate` texels), 0 empty.
//! Row 0 of the image is v = 0 (glTF's UV origin is the image's top-left).
//! Values are interpolated across each triangle as the doubled-angle vector
//! (axial data), never as raw directions.

use crate::bake::Work;
use crate::geom::{cross, dot};
use serde_json::json;
use std::path::PathBuf;
use sunbeam_common::{Error, Result};

#[derive(Debug, Clone)]
pub struct TextureOptions {
    pub size: u32,
    pub dilate: u32,
    pub path: PathBuf,
}

/// Doubled-angle map: per texel (cos 2a, sin 2a, coverage).
pub fn rasterize(work: &[Work], size: u32, dilate: u32) -> Vec<[f32; 3]> {
    let n = size as usize;
    let mut img = vec![[0.0f32; 3]; n * n];
    for w in work {
        let (Some(uv), Some(uw)) = (&w.local.uvs, &w.u_world) else {
            continue;
        };
        let ang: Vec<Option<(f64, f64)>> = (0..w.dir.len())
            .map(|i| {
                let (d, u) = (w.dir[i]?, uw[i]?);
                let nrm = w.n_world[i];
                let a = dot(d, cross(nrm, u)).atan2(dot(d, u));
                Some(((2.0 * a).cos(), (2.0 * a).sin()))
            })
            .collect();
        for t in &w.local.triangles {
            let ids = [t[0] as usize, t[1] as usize, t[2] as usize];
            let (Some(a0), Some(a1), Some(a2)) = (ang[ids[0]], ang[ids[1]], ang[ids[2]]) else {
                continue;
            };
            let p: Vec<[f64; 2]> = ids
                .iter()
                .map(|&i| [uv[i][0] * n as f64, uv[i][1] * n as f64])
                .collect();
            let area = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
            if area.abs() < 1e-18 || !area.is_finite() {
                continue;
            }
            let x0 = p
                .iter()
                .map(|q| q[0])
                .fold(f64::INFINITY, f64::min)
                .floor()
                .max(0.0) as usize;
            let x1 = (p
                .iter()
                .map(|q| q[0])
                .fold(f64::NEG_INFINITY, f64::max)
                .ceil()
                .min(n as f64)) as usize;
            let y0 = p
                .iter()
                .map(|q| q[1])
                .fold(f64::INFINITY, f64::min)
                .floor()
                .max(0.0) as usize;
            let y1 = (p
                .iter()
                .map(|q| q[1])
                .fold(f64::NEG_INFINITY, f64::max)
                .ceil()
                .min(n as f64)) as usize;
            for y in y0..y1 {
                for x in x0..x1 {
                    let c = [x as f64 + 0.5, y as f64 + 0.5];
                    let e = |a: [f64; 2], b: [f64; 2]| {
                        (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
                    };
                    let l0 = e(p[1], p[2]) / area;
                    let l1 = e(p[2], p[0]) / area;
                    let l2 = 1.0 - l0 - l1;
                    if l0 < -1e-9 || l1 < -1e-9 || l2 < -1e-9 {
                        continue;
                    }
                    let cc = l0 * a0.0 + l1 * a1.0 + l2 * a2.0;
                    let ss = l0 * a0.1 + l1 * a1.1 + l2 * a2.1;
                    let r = cc.hypot(ss);
                    if r < 1e-12 {
                        continue;
                    }
                    img[y * n + x] = [(cc / r) as f32, (ss / r) as f32, 1.0];
                }
            }
        }
    }
    // Dilation: empty texels take the axial mean of their covered 8-neighbours, ring by ring.
    for _ in 0..dilate {
        let prev = img.clone();
        let mut changed = false;
        for y in 0..n {
            for x in 0..n {
                if prev[y * n + x][2] > 0.0 {
                    continue;
                }
                let (mut c, mut s) = (0.0f64, 0.0f64);
                for dy in -1i64..=1 {
                    for dx in -1i64..=1 {
                        let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                        if (dx, dy) == (0, 0)
                            || xx < 0
                            || yy < 0
                            || xx >= n as i64
                            || yy >= n as i64
                        {
                            continue;
                        }
                        let q = prev[yy as usize * n + xx as usize];
                        if q[2] > 0.0 {
                            c += q[0] as f64;
                            s += q[1] as f64;
                        }
                    }
                }
                let r = c.hypot(s);
                if r > 1e-9 {
                    img[y * n + x] = [(c / r) as f32, (s / r) as f32, 0.5];
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    img
}

/// Render the map and encode it by the extension of `opts.path` (.png or .exr).
pub fn render(work: &[Work], opts: &TextureOptions) -> Result<(Vec<u8>, serde_json::Value)> {
    let ext = opts
        .path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if ext != "png" && ext != "exr" {
        return Err(Error::usage(format!(
            "--texture {}: the name must end in .png or .exr",
            opts.path.display()
        )));
    }
    if work.iter().all(|w| w.local.uvs.is_none()) {
        return Err(Error::input(
            "--texture needs UVs (TEXCOORD), and the mesh has none",
        ));
    }
    let n = opts.size as usize;
    let img = rasterize(work, opts.size, opts.dilate);
    let covered = img.iter().filter(|p| p[2] == 1.0).count();
    let dilated = img.iter().filter(|p| p[2] == 0.5).count();
    // Halve the doubled angle into (-90, 90].
    let half = |p: &[f32; 3]| -> (f32, f32) {
        if p[2] == 0.0 {
            return (1.0, 0.0);
        }
        let a = 0.5 * (p[1] as f64).atan2(p[0] as f64);
        (a.cos() as f32, a.sin() as f32)
    };
    let bytes = if ext == "png" {
        let mut data = Vec::with_capacity(n * n * 6);
        for p in &img {
            let (c, s) = half(p);
            for v in [0.5 + 0.5 * c, 0.5 + 0.5 * s, p[2]] {
                data.extend_from_slice(
                    &((v.clamp(0.0, 1.0) * 65535.0).round() as u16).to_be_bytes(),
                );
            }
        }
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, opts.size, opts.size);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Sixteen);
            let mut w = enc
                .write_header()
                .map_err(|e| Error::internal(format!("PNG encoder: {e}")))?;
            w.write_image_data(&data)
                .map_err(|e| Error::internal(format!("PNG encoder: {e}")))?;
        }
        out
    } else {
        use exr::prelude::*;
        let pixels = img.clone();
        let channels = SpecificChannels::rgba(move |Vec2(x, y): Vec2<usize>| {
            let p = pixels[y * n + x];
            let a = 0.5 * (p[1] as f64).atan2(p[0] as f64);
            if p[2] == 0.0 {
                (1.0f32, 0.0f32, 1.0f32, 0.0f32)
            } else {
                (a.cos() as f32, a.sin() as f32, p[0], p[2])
            }
        });
        let image = Image::from_channels((n, n), channels);
        let mut out = std::io::Cursor::new(Vec::new());
        image
            .write()
            .to_buffered(&mut out)
            .map_err(|e| sunbeam_common::Error::internal(format!("EXR encoder: {e}")))?;
        out.into_inner()
    };
    let rep = json!({"path": opts.path.display().to_string(), "size": opts.size, "covered_texels": covered, "dilated_texels": dilated, "format": ext});
    Ok((bytes, rep))
}
