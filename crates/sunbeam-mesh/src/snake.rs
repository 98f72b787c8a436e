//! A procedural snake for the demo (no real snake scan is shipped): a tube
//! swept along a Catmull-Rom spline with a rotation-minimising frame, tapered
//! to a point at the tail, with a slightly wider, rounded head, closed at both
//! ends. Units are metres (1 m long by default), the body lies in the x-y plane
//! with its back facing +z (toward the default camera).
//!
//! UVs: `u` runs along the body (0 at the tail tip, 1 at the snout), `v` around
//! it (0 and 1 at the belly seam, 0.5 along the back).

use crate::geom::{add, cross, dot, normalize, scale, sub, V3};
use crate::gltf::Document;
use serde_json::json;
use std::path::Path;

/// Shape and resolution.
#[derive(Debug, Clone)]
pub struct SnakeParams {
    /// Rings along the body (>= 8).
    pub rings: usize,
    /// Vertices around each ring (>= 3).
    pub segments: usize,
    /// Length of the spine, metres.
    pub length: f64,
    /// Largest body radius, metres.
    pub radius: f64,
}

impl Default for SnakeParams {
    /// About 29k vertices.
    fn default() -> Self {
        SnakeParams {
            rings: 600,
            segments: 48,
            length: 1.0,
            radius: 0.03,
        }
    }
}

impl SnakeParams {
    /// Scale the resolution by `detail` in each direction (vertex count ~ detail^2).
    pub fn with_detail(detail: f64) -> Self {
        let d = SnakeParams::default();
        let k = detail.clamp(0.1, 100.0);
        SnakeParams {
            rings: ((d.rings as f64 * k).round() as usize).max(8),
            segments: ((d.segments as f64 * k).round() as usize).max(3),
            ..d
        }
    }
    pub fn vertex_count(&self) -> usize {
        self.rings * (self.segments + 1) + 2
    }
}

/// Control points of the spine (an S curve with a little vertical undulation).
fn controls(len: f64) -> Vec<V3> {
    let n = 9;
    (0..n)
        .map(|i| {
            let s = i as f64 / (n - 1) as f64;
            [
                (s - 0.5) * 0.85 * len,
                0.12 * len * (std::f64::consts::TAU * 1.25 * s).sin(),
                0.01 * len * (std::f64::consts::TAU * 2.0 * s).sin(),
            ]
        })
        .collect()
}

/// Uniform Catmull-Rom through `c` at parameter s in [0,1].
fn spline(c: &[V3], s: f64) -> V3 {
    let segs = c.len() - 1;
    let x = (s.clamp(0.0, 1.0) * segs as f64).min(segs as f64 - 1e-12);
    let i = x.floor() as usize;
    let t = x - i as f64;
    let p = |k: isize| -> V3 {
        let k = k.clamp(0, segs as isize) as usize;
        c[k]
    };
    let (p0, p1, p2, p3) = (
        if i == 0 {
            sub(scale(c[0], 2.0), c[1])
        } else {
            p(i as isize - 1)
        },
        p(i as isize),
        p(i as isize + 1),
        if i + 2 > segs {
            sub(scale(c[segs], 2.0), c[segs - 1])
        } else {
            p(i as isize + 2)
        },
    );
    let t2 = t * t;
    let t3 = t2 * t;
    let mut out = [0.0; 3];
    for k in 0..3 {
        out[k] = 0.5
            * (2.0 * p1[k]
                + (-p0[k] + p2[k]) * t
                + (2.0 * p0[k] - 5.0 * p1[k] + 4.0 * p2[k] - p3[k]) * t2
                + (-p0[k] + 3.0 * p1[k] - 3.0 * p2[k] + p3[k]) * t3);
    }
    out
}

/// Radius profile: 0 at both tips.
fn radius(s: f64, r: f64) -> f64 {
    let sm = |a: f64, b: f64, x: f64| {
        let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    };
    let tail = sm(0.0, 0.45, s).powf(0.8);
    let head = if s > 0.93 {
        (1.0 - ((s - 0.93) / 0.07).powi(2)).max(0.0).sqrt()
    } else {
        1.0
    };
    let neck = 1.0 - 0.12 * (-((s - 0.9) / 0.025).powi(2)).exp()
        + 0.1 * (-((s - 0.955) / 0.025).powi(2)).exp();
    r * tail * head * neck
}

/// Ring parameters: avoid the zero-radius tips (closed by a tip vertex each).
fn ring_s(i: usize, rings: usize) -> f64 {
    let a = 0.004;
    a + (1.0 - 2.0 * a) * i as f64 / (rings - 1) as f64
}

/// The spine polyline through the ring centres (for `--curve`).
pub fn spine(p: &SnakeParams) -> Vec<V3> {
    let c = controls(p.length);
    let rings = p.rings.max(8);
    (0..rings).map(|i| spline(&c, ring_s(i, rings))).collect()
}

/// Build the snake as a glTF document (POSITION, NORMAL, TEXCOORD_0, one material).
pub fn generate(p: &SnakeParams) -> Document {
    let rings = p.rings.max(8);
    let seg = p.segments.max(3);
    let c = controls(p.length);
    let centres: Vec<V3> = (0..rings).map(|i| spline(&c, ring_s(i, rings))).collect();
    let tip0 = spline(&c, 0.0);
    let tip1 = spline(&c, 1.0);
    // Rotation-minimising frame (double reflection, Wang et al. 2008) starting with up = +z.
    let tangent = |i: usize| -> V3 {
        let a = if i > 0 { centres[i - 1] } else { tip0 };
        let b = if i + 1 < rings { centres[i + 1] } else { tip1 };
        normalize(sub(b, a)).unwrap_or([1.0, 0.0, 0.0])
    };
    let mut ups = Vec::with_capacity(rings);
    let t0 = tangent(0);
    let mut up = normalize(sub([0.0, 0.0, 1.0], scale(t0, t0[2]))).unwrap_or([0.0, 1.0, 0.0]);
    ups.push(up);
    for i in 1..rings {
        let v1 = sub(centres[i], centres[i - 1]);
        let c1 = dot(v1, v1);
        if c1 > 0.0 {
            let ti = tangent(i - 1);
            let rl = sub(up, scale(v1, 2.0 / c1 * dot(v1, up)));
            let tl = sub(ti, scale(v1, 2.0 / c1 * dot(v1, ti)));
            let tn = tangent(i);
            let v2 = sub(tn, tl);
            let c2 = dot(v2, v2);
            up = if c2 > 0.0 {
                sub(rl, scale(v2, 2.0 / c2 * dot(v2, rl)))
            } else {
                rl
            };
            up = normalize(sub(up, scale(tn, dot(up, tn)))).unwrap_or(up);
        }
        ups.push(up);
    }
    let mut pos: Vec<V3> = Vec::with_capacity(rings * (seg + 1) + 2);
    let mut uv: Vec<[f64; 2]> = Vec::with_capacity(pos.capacity());
    for i in 0..rings {
        let s = ring_s(i, rings);
        let t = tangent(i);
        let up = ups[i];
        let side = cross(t, up); // right-handed (t, side, up)... side = t x up
        let r = radius(s, p.radius).max(0.02 * p.radius);
        for j in 0..=seg {
            let v = j as f64 / seg as f64;
            // v = 0 at the belly (-up), 0.5 on the back (+up).
            let phi = std::f64::consts::TAU * v;
            let (cu, cs) = (-phi.cos(), phi.sin());
            // Slightly flattened: height 0.85 of the width.
            let off = add(scale(up, 0.85 * r * cu), scale(side, r * cs));
            pos.push(add(centres[i], off));
            uv.push([s, v]);
        }
    }
    let itip0 = pos.len() as u32;
    pos.push(tip0);
    uv.push([0.0, 0.5]);
    let itip1 = pos.len() as u32;
    pos.push(tip1);
    uv.push([1.0, 0.5]);
    let row = (seg + 1) as u32;
    let mut idx: Vec<u32> = Vec::with_capacity(rings * seg * 6 + seg * 6);
    for i in 0..rings as u32 - 1 {
        for j in 0..seg as u32 {
            let a = i * row + j;
            let b = a + 1;
            let c2 = a + row;
            let d = c2 + 1;
            idx.extend_from_slice(&[a, b, d, a, d, c2]);
        }
    }
    let last = (rings as u32 - 1) * row;
    for j in 0..seg as u32 {
        idx.extend_from_slice(&[itip0, j + 1, j]);
        idx.extend_from_slice(&[itip1, last + j, last + j + 1]);
    }
    // Orientation check: make the winding match the outward normal at the middle.
    let tris: Vec<[u32; 3]> = idx.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    let mid = (rings / 2) as u32 * row + (seg as u32 / 2);
    let outward = sub(pos[mid as usize], centres[rings / 2]);
    let t = tris
        .iter()
        .find(|t| t[0] == mid)
        .copied()
        .unwrap_or(tris[0]);
    let fnrm = cross(
        sub(pos[t[1] as usize], pos[t[0] as usize]),
        sub(pos[t[2] as usize], pos[t[0] as usize]),
    );
    let tris: Vec<[u32; 3]> = if dot(fnrm, outward) < 0.0 {
        tris.iter().map(|t| [t[0], t[2], t[1]]).collect()
    } else {
        tris
    };
    let (nrm, _) = crate::geom::angle_weighted_normals(&pos, &tris);
    let idx: Vec<u32> = tris.iter().flatten().copied().collect();

    let mut doc = Document::new_empty(Path::new("<generated snake>"));
    let fp: Vec<f32> = pos.iter().flat_map(|v| v.map(|x| x as f32)).collect();
    let fnm: Vec<f32> = nrm.iter().flat_map(|v| v.map(|x| x as f32)).collect();
    let fuv: Vec<f32> = uv.iter().flat_map(|v| v.map(|x| x as f32)).collect();
    let pa = doc.push_f32_accessor(&fp, 3, true);
    let na = doc.push_f32_accessor(&fnm, 3, false);
    let ua = doc.push_f32_accessor(&fuv, 2, false);
    let ia = doc.push_index_accessor(&idx);
    doc.json_array_mut("materials").push(json!({
        "name": "snake skin",
        "pbrMetallicRoughness": {"baseColorFactor": [0.04, 0.04, 0.05, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.35}
    }));
    doc.json_array_mut("meshes").push(json!({
        "name": "snake",
        "primitives": [{"attributes": {"POSITION": pa, "NORMAL": na, "TEXCOORD_0": ua}, "indices": ia, "material": 0, "mode": 4}]
    }));
    doc.json_array_mut("nodes")
        .push(json!({"name": "snake", "mesh": 0}));
    doc.json_array_mut("scenes").push(json!({"nodes": [0]}));
    doc.json["scene"] = json!(0);
    doc.json["asset"]["extras"] = json!({"sunbeam": {"snake": {"rings": rings, "segments": seg, "length_m": p.length, "radius_m": p.radius}}});
    doc
}
