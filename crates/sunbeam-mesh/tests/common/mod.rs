#![allow(dead_code)]
//! Test meshes built in memory.

use serde_json::json;
use std::path::Path;
use sunbeam_mesh::gltf::Document;

/// A single-primitive document from raw arrays (NORMAL/UV optional), one node with `node` JSON merged in.
pub fn doc_from(
    pos: &[[f64; 3]],
    nrm: Option<&[[f64; 3]]>,
    uv: Option<&[[f64; 2]]>,
    idx: &[u32],
    node: serde_json::Value,
) -> Document {
    let mut d = Document::new_empty(Path::new("test.glb"));
    let fp: Vec<f32> = pos.iter().flat_map(|v| v.map(|x| x as f32)).collect();
    let pa = d.push_f32_accessor(&fp, 3, true);
    let mut attrs = serde_json::Map::new();
    attrs.insert("POSITION".into(), json!(pa));
    if let Some(n) = nrm {
        let f: Vec<f32> = n.iter().flat_map(|v| v.map(|x| x as f32)).collect();
        attrs.insert("NORMAL".into(), json!(d.push_f32_accessor(&f, 3, false)));
    }
    if let Some(u) = uv {
        let f: Vec<f32> = u.iter().flat_map(|v| v.map(|x| x as f32)).collect();
        attrs.insert(
            "TEXCOORD_0".into(),
            json!(d.push_f32_accessor(&f, 2, false)),
        );
    }
    let ia = d.push_index_accessor(idx);
    d.json_array_mut("meshes")
        .push(json!({"primitives": [{"attributes": attrs, "indices": ia}]}));
    let mut n = json!({"mesh": 0});
    if let Some(o) = node.as_object() {
        for (k, v) in o {
            n[k] = v.clone();
        }
    }
    d.json_array_mut("nodes").push(n);
    d.json_array_mut("scenes").push(json!({"nodes": [0]}));
    d.json["scene"] = json!(0);
    d
}

/// An n x n vertex grid on [0,1]^2 in the x-y plane (z = height(x,y)), UV = (x, y).
pub fn grid(
    n: usize,
    height: impl Fn(f64, f64) -> f64,
) -> (Vec<[f64; 3]>, Vec<[f64; 2]>, Vec<u32>) {
    let mut pos = Vec::new();
    let mut uv = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64);
            pos.push([x, y, height(x, y)]);
            uv.push([x, y]);
        }
    }
    let mut idx = Vec::new();
    for j in 0..n as u32 - 1 {
        for i in 0..n as u32 - 1 {
            let a = j * n as u32 + i;
            idx.extend_from_slice(&[
                a,
                a + 1,
                a + n as u32 + 1,
                a,
                a + n as u32 + 1,
                a + n as u32,
            ]);
        }
    }
    (pos, uv, idx)
}

/// Deterministic pseudo-random numbers in [0,1): the project's seeded
/// `SplitMix64` (`sunbeam_common::rng`), state in `.0`.
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        let mut g = sunbeam_common::rng::SplitMix64(self.0);
        let v = g.unit();
        self.0 = g.0;
        v
    }
}

pub fn tmpdir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("sunbeam-mesh-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Axial angle difference in radians, in [0, pi/2].
pub fn axial_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::PI);
    d.min(std::f64::consts::PI - d)
}
