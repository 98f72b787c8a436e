//! Test and benchmark fixtures shared by the renderers' tests: the thesis' grey
//! height maps (`../shared/data/snake`) as packs, and the three test scenes of
//! docs/PLAY.md (blazed grating on a quad, Elaphe on a sphere, Xenopeltis on the
//! snake). Not part of the rendering path.

use crate::{Material, Mesh, Prepared};
use std::path::Path;
use std::sync::Arc;
use sunbeam_common::{Error, Result};
use sunbeam_pack::build::{BuildOptions, FieldRef};
use sunbeam_pack::Pack;
use sunbeam_scene::{Light, Scene};

/// A grey height map with its physical scale (snake/README.md).
#[derive(Debug, Clone, Copy)]
pub struct Patch {
    /// File name in `shared/data/snake`.
    pub file: &'static str,
    pub pixel_m: f64,
    pub range_m: f64,
}

/// Blazed grating: one 2.5 um period over 100 px, 246.23 nm.
pub const BLAZED: Patch = Patch {
    file: "BlazingBump.bmp",
    pixel_m: 25e-9,
    range_m: 246.23e-9,
};
/// Elaphe guttata: 65 nm pixels, 375 nm.
pub const ELAPHE: Patch = Patch {
    file: "Elaph100x100.png",
    pixel_m: 65e-9,
    range_m: 375e-9,
};
/// Xenopeltis unicolor: 65 nm pixels, 443.45 nm.
pub const XENO: Patch = Patch {
    file: "Xeno100x100.png",
    pixel_m: 65e-9,
    range_m: 443.45e-9,
};

/// Read an 8-bit grey image (BMP with a palette or 24-bit, PNG grey/RGB/RGBA) as
/// values in [0, 1], row 0 at the top. Colour images use their first channel.
pub fn read_grey(path: &Path) -> Result<(usize, usize, Vec<f64>)> {
    let bytes = std::fs::read(path).map_err(|e| Error::input_file(path, e))?;
    if bytes.starts_with(b"BM") {
        return read_bmp(&bytes).map_err(|e| Error::input_file(path, e));
    }
    let img = crate::Image::read_png(path)?;
    let v = img
        .rgb
        .iter()
        .map(|p| (p[0] as f64 * 255.0).round() / 255.0)
        .collect();
    Ok((img.width as usize, img.height as usize, v))
}

fn read_bmp(b: &[u8]) -> std::result::Result<(usize, usize, Vec<f64>), String> {
    let u32_at = |o: usize| -> std::result::Result<u32, String> {
        b.get(o..o + 4)
            .map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
            .ok_or_else(|| "truncated BMP".to_string())
    };
    let u16_at = |o: usize| -> std::result::Result<u16, String> {
        b.get(o..o + 2)
            .map(|s| u16::from_le_bytes([s[0], s[1]]))
            .ok_or_else(|| "truncated BMP".to_string())
    };
    let off = u32_at(10)? as usize;
    let hdr = u32_at(14)? as usize;
    let w = u32_at(18)? as i32;
    let h = u32_at(22)? as i32;
    let bpp = u16_at(28)?;
    let comp = u32_at(30)?;
    if comp != 0 || w <= 0 || h == 0 || w > 1 << 14 || h.unsigned_abs() > 1 << 14 {
        return Err(format!("unsupported BMP (compression {comp}, {w}x{h})"));
    }
    let (w, hh) = (w as usize, h.unsigned_abs() as usize);
    let row = (bpp as usize * w).div_ceil(32) * 4;
    if b.len() < off + row * hh {
        return Err("truncated BMP pixel data".into());
    }
    let palette = 14 + hdr;
    let mut out = vec![0.0; w * hh];
    for r in 0..hh {
        let src = if h > 0 { hh - 1 - r } else { r }; // bottom-up unless the height is negative
        let line = &b[off + src * row..off + (src + 1) * row];
        for c in 0..w {
            let g = match bpp {
                8 => {
                    let i = line[c] as usize;
                    *b.get(palette + 4 * i + 2)
                        .ok_or("palette index out of range")? // red of BGRA
                }
                24 => line[3 * c + 2],
                32 => line[4 * c + 2],
                _ => return Err(format!("unsupported BMP depth {bpp}")),
            };
            out[r * w + c] = g as f64 / 255.0;
        }
    }
    Ok((w, hh, out))
}

/// Heights in metres of a patch (grey 0..1 -> 0..range).
pub fn heights(p: &Patch, dir: &Path) -> Result<(usize, usize, Vec<f64>)> {
    let (w, h, v) = read_grey(&dir.join(p.file))?;
    Ok((w, h, v.into_iter().map(|g| g * p.range_m).collect()))
}

/// Build a pack of a patch with `opts` (basis, model, terms ...).
pub fn pack(p: &Patch, dir: &Path, opts: &BuildOptions) -> Result<Pack> {
    let (w, h, data) = heights(p, dir)?;
    let f = FieldRef {
        width: w,
        height: h,
        dx: p.pixel_m,
        dy: p.pixel_m,
        data: &data,
    };
    sunbeam_pack::build::build(f, opts, &mut |_, _| {})
}

/// A scene of one mesh with its material, ready to render (no files needed).
pub fn prepared(scene: Scene, mesh: Mesh, pack: Option<Arc<Pack>>) -> Prepared {
    let mi = &scene.meshes[0];
    let mat = Material {
        pack,
        base_color: mi.base_color,
        diffuse_weight: mi.diffuse_weight,
        masking: sunbeam_optics::masking::Masking::Off,
        skin: sunbeam_optics::gain::Material::default(),
        scales: None,
    };
    Prepared {
        meshes: vec![(Arc::new(mesh), mat)],
        scene,
        environment: None,
        cache: Default::default(),
    }
}

fn scene_for(mesh_name: &str, mesh: &Mesh, size: [u32; 2]) -> Scene {
    let mut s = Scene::default_lit(
        mesh_name.into(),
        Some("pack".into()),
        mesh.bounds(),
        sunbeam_scene::DefaultLighting::Point,
    );
    s.size = size;
    s
}

/// Blazed grating on `builtin:quad` filling the frame (eye at z = 1.5), light at
/// 30 degrees in the x-z plane so that the first orders cross the image.
pub fn quad_scene(size: [u32; 2]) -> (Scene, Mesh) {
    let mesh = Mesh::quad();
    let mut s = scene_for("builtin:quad", &mesh, size);
    // close enough that the quad fills the frame
    s.camera.eye = [0.0, 0.0, 1.5];
    s.lights = vec![Light {
        direction: [-0.5, 0.0, 0.866],
        intensity: 1.0,
        spectrum: "D65".into(),
        color: [1.0; 3],
    }];
    (s, mesh)
}

/// Elaphe on `builtin:sphere` with the default camera and light.
pub fn sphere_scene(size: [u32; 2]) -> (Scene, Mesh) {
    let mesh = Mesh::uv_sphere(96, 48);
    (scene_for("builtin:sphere", &mesh, size), mesh)
}

/// The demo snake (sunbeam-mesh's procedural snake at reduced detail, orientation
/// along the body), seen from above, light from the upper left.
pub fn snake_scene(size: [u32; 2]) -> Result<(Scene, Mesh)> {
    let doc = sunbeam_mesh::snake::generate(&sunbeam_mesh::snake::SnakeParams::with_detail(0.25));
    let tm = sunbeam_mesh::scene_mesh(&doc)?;
    let tangents = tm
        .orientation
        .iter()
        .map(|o| [o[0], o[1], o[2], 1.0])
        .collect();
    let mesh = Mesh {
        positions: tm.positions,
        normals: tm.normals,
        uvs: tm.uvs,
        tangents,
        indices: tm.indices,
    };
    mesh.check().map_err(Error::internal)?;
    let mut s = scene_for("snake.glb", &mesh, size);
    s.lights = vec![Light {
        direction: [-0.4, 0.5, 0.77],
        intensity: 1.0,
        spectrum: "D65".into(),
        color: [1.0; 3],
    }];
    Ok((s, mesh))
}
