//! Scales (`sunbeam-bake --scales`, docs/BAKE.md "Scales"): a tiling of
//! imbricate scales in the mesh's body-aligned UV parameterisation, baked into
//! two textures embedded in the GLB.
//!
//! The parameterisation: `u` runs along the body (toward the head), `v` around
//! it, periodic with period 1 (the procedural snake's layout, and the
//! `--uv-direction u` convention). `rows` scales tile one turn of `v`; the
//! number along `u` follows from the scale length (in scale widths) and the
//! mesh's mean metric (area-weighted mean |dP/du| and |dP/dv|). Odd rows are
//! offset by half a scale (the quincunx of a snake's dorsal scales). Each
//! scale's free edge points to decreasing `u` (toward the tail) and overlaps the
//! base of the scale behind it by `overlap` scale lengths; where two overlap the
//! anterior one lies on top. The free edge is rounded (its corners lie a
//! quarter of a scale length behind its tip). Each scale is a low dome, and
//! may carry a keel: a ridge along its midline that fades out toward the free
//! edge's tip (the keeled scales of *Elaphe*).
//!
//! Textures (8-bit RGBA PNG, sampled with `TEXCOORD_n`, wrap `v` repeat, `u` clamp):
//! - **normal map** (`normalTexture`): the glTF tangent-space normal, RGB =
//!   0.5 + 0.5 (X, Y, Z) with X along `TANGENT` (the direction of increasing
//!   `u`) and Y along the glTF bitangent (image up, decreasing `v`); A = 255.
//! - **orientation map** (`SUNBEAM_materials_diffraction.orientationTexture`):
//!   the ridge direction `d = cos(a) T + sin(a) (N x T)` (T = `TANGENT.xyz`) as
//!   R = 0.5 + 0.5 cos a, G = 0.5 + 0.5 sin a (a unit vector in the tangent
//!   plane, to be interpolated as a vector and renormalised); B = the groove
//!   mask (1 on a scale, falling to 0 in the grooves between scales); A = the
//!   scale id modulo 256 (a change of A marks a scale border).
//!
//! Everything is a pure function of the texel and the seed (one SplitMix64 per
//! scale, seeded from the seed and the scale's indices): byte-identical
//! output on every run and thread count.

use crate::bake::Work;
use crate::geom::{cross, norm, sub};
use crate::gltf::Document;
use serde::Serialize;
use serde_json::{json, Value};
use sunbeam_common::rng::SplitMix64;
use sunbeam_common::{Error, Result};

/// Parameters of the tiling (ranges in docs/BAKE.md; checked by [`ScaleParams::check`]).
#[derive(Debug, Clone, Serialize)]
pub struct ScaleParams {
    /// Scale rows around the body (one turn of `v`).
    pub rows: u32,
    /// Scale length along the body, in scale widths.
    pub length: f64,
    /// Overlap of a scale over the one behind it, in scale lengths.
    pub overlap: f64,
    /// Dome height, in scale widths.
    pub dome: f64,
    /// Keel height (a ridge along the scale's midline), in scale widths.
    pub keel: f64,
    /// Tilt of the free edge (rotation of the scale's normal toward the head), degrees.
    pub tilt_deg: f64,
    /// Per-scale jitter of the tilt (uniform in +-), degrees.
    pub tilt_jitter_deg: f64,
    /// Per-scale jitter of the ridge angle about the normal (uniform in +-), degrees.
    pub ridge_jitter_deg: f64,
    /// Texels across one scale width.
    pub texels_per_scale: u32,
    pub seed: u64,
}

impl Default for ScaleParams {
    /// Xenopeltis-like: smooth, wide, short dorsal scales (docs/BAKE.md).
    fn default() -> Self {
        ScaleParams {
            rows: 20,
            length: 1.0,
            overlap: 0.3,
            dome: 0.06,
            keel: 0.0,
            tilt_deg: 6.0,
            tilt_jitter_deg: 4.0,
            ridge_jitter_deg: 6.0,
            texels_per_scale: 32,
            seed: 1,
        }
    }
}

/// The largest texture side written.
pub const MAX_SIDE: u32 = 8192;
/// Groove width, in scale widths (the mask falls from 1 to 0 over it).
const GROOVE: f64 = 0.06;
/// How far the free edge's corners lie behind its tip (a rounded edge), in scale lengths.
const ROUND: f64 = 0.25;
/// Half-width of the keel, in scale widths (the ridge spans the middle 30 % of the scale).
pub const KEEL_HALF_WIDTH: f64 = 0.15;
/// The keel fades in over this fraction of the scale from its free edge's tip
/// (xi, 0 at the tip, 1 at the base): keels stop short of the tip.
pub const KEEL_FADE: f64 = 0.35;

impl ScaleParams {
    /// Range checks (the CLI's value parsers check the same ranges).
    pub fn check(&self) -> std::result::Result<(), String> {
        let r = |name: &str, v: f64, lo: f64, hi: f64| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(format!("{name} {v} is outside [{lo}, {hi}]"))
            }
        };
        r("rows", self.rows as f64, 3.0, 200.0)?;
        r("length", self.length, 0.25, 4.0)?;
        r("overlap", self.overlap, 0.0, 0.6)?;
        r("dome", self.dome, 0.0, 0.3)?;
        r("keel", self.keel, 0.0, 0.1)?;
        r("tilt_deg", self.tilt_deg, -30.0, 30.0)?;
        r("tilt_jitter_deg", self.tilt_jitter_deg, 0.0, 20.0)?;
        r("ridge_jitter_deg", self.ridge_jitter_deg, 0.0, 45.0)?;
        r("texels_per_scale", self.texels_per_scale as f64, 4.0, 256.0)
    }
}

/// What one texel sees: the visible scale's normal (tangent space, unit, z > 0),
/// ridge angle (radians, from T toward N x T), groove mask and id.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Texel {
    pub normal: [f64; 3],
    pub ridge: f64,
    pub mask: f64,
    pub id: u64,
}

/// The tiling: `along` scales per unit of `u`, `rows` per unit of `v`.
#[derive(Debug, Clone)]
pub struct Tiling {
    pub p: ScaleParams,
    pub along: u32,
}

impl Tiling {
    /// Tilt and ridge angle (radians) of scale (i, j).
    pub fn scale_angles(&self, i: i64, j: u32) -> (f64, f64) {
        let key = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ ((j as u64) << 40);
        let mut rng = SplitMix64::new(self.p.seed ^ key);
        let a = 2.0 * rng.unit() - 1.0;
        let b = 2.0 * rng.unit() - 1.0;
        (
            (self.p.tilt_deg + a * self.p.tilt_jitter_deg).to_radians(),
            (b * self.p.ridge_jitter_deg).to_radians(),
        )
    }

    /// The texel at (u, v).
    pub fn eval(&self, u: f64, v: f64) -> Texel {
        let rows = self.p.rows;
        let y = v.rem_euclid(1.0) * rows as f64;
        let j = (y.floor() as u32).min(rows - 1);
        let eta = y - j as f64;
        let o = self.p.overlap;
        let x = u * self.along as f64 + if j % 2 == 1 { 0.5 } else { 0.0 };
        // Scale k covers x from its rounded free edge, k - o + ROUND (2 eta - 1)^2,
        // to k + 1; the anterior (higher k) lies on top.
        let edge = ROUND * (2.0 * eta - 1.0).powi(2);
        let k = (x + o - edge).floor();
        let xi = (x - k + o) / (1.0 + o); // 0 at the free edge's tip, 1 at the base
        let behind_edge = x - k + o - edge; // scale lengths behind the free edge
        let (tilt, ridge) = self.scale_angles(k as i64, j);
        // Dome h = dome W (1 - (2 eta - 1)^2)(1 - (2 xi - 1)^2); slopes per unit length.
        let (fe, fx) = (
            1.0 - (2.0 * eta - 1.0).powi(2),
            1.0 - (2.0 * xi - 1.0).powi(2),
        );
        let (de, dx) = (-4.0 * (2.0 * eta - 1.0), -4.0 * (2.0 * xi - 1.0));
        let len = self.p.length * (1.0 + o);
        // Keel h = keel W b(eta) f(xi): a quartic bump b = (1 - (t/a)^2)^2 across
        // the midline (t = eta - 1/2, |t| < a = KEEL_HALF_WIDTH), its height
        // faded in from the tip by f = smoothstep(xi / KEEL_FADE).
        let (kb, kdb) = keel_profile(eta - 0.5);
        let (kf, kdf) = keel_fade(xi);
        let slope_u = (self.p.dome * fe * dx + self.p.keel * kb * kdf) / len - tilt.tan();
        let slope_v = self.p.dome * de * fx + self.p.keel * kdb * kf;
        // Tangent-space normal: X along +u, Y along decreasing v (the glTF bitangent).
        let g = [-slope_u, slope_v, 1.0];
        let l = norm(g);
        let normal = [g[0] / l, g[1] / l, g[2] / l];
        let d_edge = eta.min(1.0 - eta).min(behind_edge * self.p.length);
        let s = (d_edge / GROOVE).clamp(0.0, 1.0);
        let mask = s * s * (3.0 - 2.0 * s);
        let id = (k as i64 as u64)
            .wrapping_mul(rows as u64)
            .wrapping_add(j as u64);
        Texel {
            normal,
            ridge,
            mask,
            id,
        }
    }
}

/// The keel's cross profile b(t) and db/dt at t = eta - 1/2 (see [`Tiling::eval`]).
fn keel_profile(t: f64) -> (f64, f64) {
    let a = KEEL_HALF_WIDTH;
    if t.abs() >= a {
        return (0.0, 0.0);
    }
    let q = 1.0 - (t / a).powi(2);
    (q * q, -4.0 * t / (a * a) * q)
}

/// The keel's fade along the scale, f(xi) and df/dxi (see [`Tiling::eval`]).
fn keel_fade(xi: f64) -> (f64, f64) {
    let s = xi / KEEL_FADE;
    if s >= 1.0 {
        (1.0, 0.0)
    } else if s <= 0.0 {
        (0.0, 0.0)
    } else {
        (s * s * (3.0 - 2.0 * s), 6.0 * s * (1.0 - s) / KEEL_FADE)
    }
}

/// Metric of the UV layout: area-weighted mean |dP/du| and |dP/dv| (world units).
fn metric(work: &[Work]) -> Option<(f64, f64)> {
    let (mut su, mut sv, mut sa) = (0.0, 0.0, 0.0);
    for w in work {
        let Some(uv) = &w.local.uvs else { continue };
        let p = &w.p_world;
        for t in &w.local.triangles {
            let (i0, i1, i2) = (t[0] as usize, t[1] as usize, t[2] as usize);
            let (e1, e2) = (sub(p[i1], p[i0]), sub(p[i2], p[i0]));
            let (s1, t1) = (uv[i1][0] - uv[i0][0], uv[i1][1] - uv[i0][1]);
            let (s2, t2) = (uv[i2][0] - uv[i0][0], uv[i2][1] - uv[i0][1]);
            let det = s1 * t2 - s2 * t1;
            let area = 0.5 * norm(cross(e1, e2));
            if det.abs() < 1e-20 || !det.is_finite() || !area.is_finite() {
                continue;
            }
            let pu = crate::geom::scale(
                sub(crate::geom::scale(e1, t2), crate::geom::scale(e2, t1)),
                1.0 / det,
            );
            let pv = crate::geom::scale(
                sub(crate::geom::scale(e2, s1), crate::geom::scale(e1, s2)),
                1.0 / det,
            );
            su += norm(pu) * area;
            sv += norm(pv) * area;
            sa += area;
        }
    }
    (sa > 0.0).then(|| (su / sa, sv / sa))
}

/// Sizes the texture and the tiling from the mesh (see the module docs).
/// `source` names the mesh in errors.
pub fn plan(
    work: &[Work],
    p: &ScaleParams,
    source: &std::path::Path,
) -> Result<(Tiling, [u32; 2], u32)> {
    p.check()
        .map_err(|e| Error::usage(format!("--scales: {e}")))?;
    let (lu, lv) = metric(work).ok_or_else(|| {
        Error::input_file(
            source,
            "--scales needs UVs (TEXCOORD_n of --uv-set) spanning an area, and the mesh has none",
        )
    })?;
    let width = lv / p.rows as f64;
    let along = ((lu / (p.length * width)).round() as u32).clamp(1, 100_000);
    let tiling = Tiling {
        p: p.clone(),
        along,
    };
    // Texels per scale width; the length gets proportionally more.
    let mut tps = p.texels_per_scale;
    loop {
        let w = (along as f64 * p.length * tps as f64).ceil() as u32;
        let h = p.rows * tps;
        if (w <= MAX_SIDE && h <= MAX_SIDE) || tps <= 4 {
            return Ok((tiling, [w.min(MAX_SIDE), h.min(MAX_SIDE)], tps));
        }
        tps -= 1;
    }
}

/// 8-bit encoding of a value in [-1, 1].
fn enc(x: f64) -> u8 {
    ((0.5 + 0.5 * x).clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The two maps (RGBA8, row-major, row 0 at v = 0), texel centres sampled.
pub fn rasterize(t: &Tiling, size: [u32; 2]) -> (Vec<u8>, Vec<u8>) {
    let (w, h) = (size[0] as usize, size[1] as usize);
    let mut nm = vec![0u8; w * h * 4];
    let mut om = vec![0u8; w * h * 4];
    for y in 0..h {
        let v = (y as f64 + 0.5) / h as f64;
        for x in 0..w {
            let u = (x as f64 + 0.5) / w as f64;
            let s = t.eval(u, v);
            let o = (y * w + x) * 4;
            nm[o..o + 4].copy_from_slice(&[
                enc(s.normal[0]),
                enc(s.normal[1]),
                enc(s.normal[2]),
                255,
            ]);
            om[o..o + 4].copy_from_slice(&[
                enc(s.ridge.cos()),
                enc(s.ridge.sin()),
                (s.mask * 255.0).round() as u8,
                (s.id & 0xff) as u8,
            ]);
        }
    }
    (nm, om)
}

/// PNG (RGBA8) of a map.
pub fn png_rgba(data: &[u8], size: [u32; 2]) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, size[0], size[1]);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc
            .write_header()
            .map_err(|e| Error::internal(format!("PNG encoder: {e}")))?;
        wr.write_image_data(data)
            .map_err(|e| Error::internal(format!("PNG encoder: {e}")))?;
    }
    Ok(out)
}

/// The `--json` report's `scales` object.
#[derive(Debug, Clone, Serialize)]
pub struct ScaleReport {
    pub params: ScaleParams,
    pub scales_along: u32,
    pub scales_total: u64,
    pub texels_per_scale_width: u32,
    pub texels_per_scale_length: f64,
    pub texture_size: [u32; 2],
    pub normal_map_bytes: usize,
    pub orientation_map_bytes: usize,
    pub uv_set: usize,
    /// Fraction of the vertices whose baked field lies within 30 deg of +-u
    /// (the tiling assumes u runs along the body; a low value warns).
    pub field_along_u: f64,
}

/// Fraction of the vertices whose baked direction is within 30 deg of the
/// direction of increasing u (either sign); 0 without UVs.
pub fn field_along_u(work: &[Work]) -> f64 {
    let (mut n, mut along) = (0usize, 0usize);
    for w in work {
        let Some(uw) = &w.u_world else { continue };
        for (d, u) in w.dir.iter().zip(uw) {
            if let (Some(d), Some(u)) = (d, u) {
                n += 1;
                if crate::geom::dot(*d, *u).abs() >= 30f64.to_radians().cos() {
                    along += 1;
                }
            }
        }
    }
    if n == 0 {
        0.0
    } else {
        along as f64 / n as f64
    }
}

/// Bake the maps into `doc`: images, a sampler and textures; every material
/// that a baked primitive uses gets `normalTexture`, and the extension object
/// `ext` (written as `SUNBEAM_materials_diffraction` on those materials, with
/// `orientationTexture` added).
pub fn attach(
    doc: &mut Document,
    work: &[Work],
    p: &ScaleParams,
    uv_set: usize,
    ext: Option<Value>,
) -> Result<ScaleReport> {
    let source = doc.source.clone();
    let (tiling, size, tps) = plan(work, p, &source)?;
    let (nm, om) = rasterize(&tiling, size);
    let (nm_png, om_png) = (png_rgba(&nm, size)?, png_rgba(&om, size)?);
    // glTF: 10497 REPEAT, 33071 CLAMP_TO_EDGE, 9729 LINEAR, 9987 LINEAR_MIPMAP_LINEAR.
    let sampler = {
        let s = doc.json_array_mut("samplers");
        s.push(json!({"magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 10497}));
        s.len() - 1
    };
    let texture = |doc: &mut Document, bytes: &[u8], name: &str| {
        let view = doc.push_bytes_view(bytes);
        let imgs = doc.json_array_mut("images");
        imgs.push(json!({"bufferView": view, "mimeType": "image/png", "name": name}));
        let img = imgs.len() - 1;
        let tex = doc.json_array_mut("textures");
        tex.push(json!({"source": img, "sampler": sampler, "name": name}));
        tex.len() - 1
    };
    let nt = texture(doc, &nm_png, "sunbeam scales normal");
    let ot = texture(doc, &om_png, "sunbeam scales orientation");
    let mut ext = ext.unwrap_or_else(|| json!({}));
    ext["orientationTexture"] = json!({"index": ot, "texCoord": uv_set});
    ext["scales"] = json!({"rows": p.rows, "along": tiling.along, "seed": p.seed});
    if ext.get("baseColor").is_none() {
        ext["baseColor"] = json!([0.05, 0.05, 0.05]);
    }
    crate::diffraction_ext::attach(doc, &ext, [0.05, 0.05, 0.05]);
    for m in doc.json_array_mut("materials").iter_mut() {
        m["normalTexture"] = json!({"index": nt, "texCoord": uv_set});
    }
    Ok(ScaleReport {
        params: p.clone(),
        scales_along: tiling.along,
        scales_total: tiling.along as u64 * p.rows as u64,
        texels_per_scale_width: tps,
        texels_per_scale_length: size[0] as f64 / tiling.along as f64,
        texture_size: size,
        normal_map_bytes: nm_png.len(),
        orientation_map_bytes: om_png.len(),
        uv_set,
        field_along_u: field_along_u(work),
    })
}
