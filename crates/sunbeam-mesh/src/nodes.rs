//! The glTF node walk: reading a mesh primitive's attributes and walking the
//! default scene's node hierarchy of a [`Document`] into mesh instances with
//! world transforms. (Not the render scene: that is the sunbeam-scene crate.)

use crate::geom::{Mat4, V3};
use crate::gltf::Document;
use serde_json::Value;
use sunbeam_common::Result;

/// One triangle primitive, in its mesh's local space.
#[derive(Debug, Clone)]
pub struct Prim {
    pub mesh: usize,
    pub prim: usize,
    pub positions: Vec<V3>,
    pub normals: Option<Vec<V3>>,
    pub uvs: Option<Vec<[f64; 2]>>,
    pub tangents: Option<Vec<[f64; 4]>>,
    pub orientation: Option<Vec<V3>>,
    /// Triangles as vertex indices (strips and fans are expanded).
    pub triangles: Vec<[u32; 3]>,
    pub material: Option<usize>,
}

fn attr(p: &Value, name: &str) -> Option<usize> {
    p.get("attributes")
        .and_then(|a| a.get(name))
        .and_then(Value::as_u64)
        .map(|x| x as usize)
}

fn to_v3(doc: &Document, acc: usize, what: &str, n: usize) -> Result<Vec<V3>> {
    let (d, c) = doc.read_accessor(acc)?;
    if c != 3 {
        return Err(crate::gltf::bad(
            &doc.source,
            format!("{what} accessor {acc} is not VEC3"),
        ));
    }
    if d.len() / 3 != n {
        return Err(crate::gltf::bad(
            &doc.source,
            format!(
                "{what} accessor {acc} has {} elements, POSITION has {n}",
                d.len() / 3
            ),
        ));
    }
    Ok(d.chunks(3).map(|c| [c[0], c[1], c[2]]).collect())
}

/// The primitive's mode (4 triangles when absent).
pub fn prim_mode(p: &Value) -> u64 {
    p.get("mode").and_then(Value::as_u64).unwrap_or(4)
}

/// Read mesh `m`, primitive `k`. Returns None for points and lines (no surface).
pub fn read_primitive(doc: &Document, m: usize, k: usize, uv_set: usize) -> Result<Option<Prim>> {
    let what = format!("meshes[{m}].primitives[{k}]");
    let p = doc
        .array("meshes")
        .get(m)
        .and_then(|x| x.get("primitives"))
        .and_then(Value::as_array)
        .and_then(|a| a.get(k))
        .ok_or_else(|| crate::gltf::bad(&doc.source, format!("{what} does not exist")))?;
    let mode = prim_mode(p);
    if !(4..=6).contains(&mode) {
        return Ok(None);
    }
    let pacc = attr(p, "POSITION")
        .ok_or_else(|| crate::gltf::bad(&doc.source, format!("{what} has no POSITION")))?;
    let positions: Vec<V3> = {
        let (d, c) = doc.read_accessor(pacc)?;
        if c != 3 {
            return Err(crate::gltf::bad(
                &doc.source,
                format!("{what}.POSITION is not VEC3"),
            ));
        }
        d.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()
    };
    let n = positions.len();
    let normals = attr(p, "NORMAL")
        .map(|a| to_v3(doc, a, &format!("{what}.NORMAL"), n))
        .transpose()?;
    let orientation = attr(p, "_ORIENTATION")
        .map(|a| to_v3(doc, a, &format!("{what}._ORIENTATION"), n))
        .transpose()?;
    let uvs = match attr(p, &format!("TEXCOORD_{uv_set}")) {
        Some(a) => {
            let (d, c) = doc.read_accessor(a)?;
            if c != 2 || d.len() / 2 != n {
                return Err(crate::gltf::bad(
                    &doc.source,
                    format!("{what}.TEXCOORD_{uv_set} is not VEC2 with one element per vertex"),
                ));
            }
            Some(d.chunks(2).map(|c| [c[0], c[1]]).collect())
        }
        None => None,
    };
    let tangents = match attr(p, "TANGENT") {
        Some(a) => {
            let (d, c) = doc.read_accessor(a)?;
            if c != 4 || d.len() / 4 != n {
                return Err(crate::gltf::bad(
                    &doc.source,
                    format!("{what}.TANGENT is not VEC4 with one element per vertex"),
                ));
            }
            Some(d.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect())
        }
        None => None,
    };
    let idx: Vec<u32> = match p.get("indices").and_then(Value::as_u64) {
        Some(a) => {
            let (d, c) = doc.read_accessor(a as usize)?;
            if c != 1 {
                return Err(crate::gltf::bad(
                    &doc.source,
                    format!("{what}.indices is not SCALAR"),
                ));
            }
            d.into_iter().map(|x| x as u32).collect()
        }
        None => (0..n as u32).collect(),
    };
    if let Some(bad_i) = idx.iter().find(|&&i| i as usize >= n) {
        return Err(crate::gltf::bad(
            &doc.source,
            format!("{what}: index {bad_i} >= vertex count {n}"),
        ));
    }
    let mut triangles = Vec::new();
    match mode {
        4 => triangles.extend(idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]])),
        5 => {
            for i in 0..idx.len().saturating_sub(2) {
                if i % 2 == 0 {
                    triangles.push([idx[i], idx[i + 1], idx[i + 2]]);
                } else {
                    triangles.push([idx[i + 1], idx[i], idx[i + 2]]);
                }
            }
        }
        _ => {
            for i in 1..idx.len().saturating_sub(1) {
                triangles.push([idx[0], idx[i], idx[i + 1]]);
            }
        }
    }
    let material = p
        .get("material")
        .and_then(Value::as_u64)
        .map(|x| x as usize);
    Ok(Some(Prim {
        mesh: m,
        prim: k,
        positions,
        normals,
        uvs,
        tangents,
        orientation,
        triangles,
        material,
    }))
}

/// One placement of a mesh in the scene.
#[derive(Debug, Clone)]
pub struct Instance {
    pub node: usize,
    pub mesh: usize,
    pub world: Mat4,
}

fn node_local(n: &Value) -> Mat4 {
    if let Some(m) = n.get("matrix").and_then(Value::as_array) {
        if m.len() == 16 {
            let mut a = [0.0; 16];
            for (i, v) in m.iter().enumerate() {
                a[i] = v.as_f64().unwrap_or(0.0);
            }
            return Mat4(a);
        }
    }
    let f = |key: &str, def: &[f64]| -> Vec<f64> {
        n.get(key)
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .map(|x| x.as_f64().unwrap_or(0.0))
                    .collect::<Vec<_>>()
            })
            .filter(|a| a.len() == def.len())
            .unwrap_or_else(|| def.to_vec())
    };
    let t = f("translation", &[0., 0., 0.]);
    let r = f("rotation", &[0., 0., 0., 1.]);
    let s = f("scale", &[1., 1., 1.]);
    Mat4::from_trs(
        [t[0], t[1], t[2]],
        [r[0], r[1], r[2], r[3]],
        [s[0], s[1], s[2]],
    )
}

/// Every mesh instance of the default scene (`scene`, else scene 0, else every
/// root node), depth first in node order.
pub fn instances(doc: &Document) -> Vec<Instance> {
    let nodes = doc.array("nodes");
    let roots: Vec<usize> = {
        let scenes = doc.array("scenes");
        let si = doc
            .json
            .get("scene")
            .and_then(Value::as_u64)
            .map(|x| x as usize)
            .unwrap_or(0);
        match scenes
            .get(si)
            .and_then(|s| s.get("nodes"))
            .and_then(Value::as_array)
        {
            Some(a) => a
                .iter()
                .filter_map(Value::as_u64)
                .map(|x| x as usize)
                .collect(),
            None => {
                let mut is_child = vec![false; nodes.len()];
                for n in nodes {
                    for c in n
                        .get("children")
                        .and_then(Value::as_array)
                        .into_iter()
                        .flatten()
                        .filter_map(Value::as_u64)
                    {
                        if let Some(x) = is_child.get_mut(c as usize) {
                            *x = true;
                        }
                    }
                }
                (0..nodes.len()).filter(|&i| !is_child[i]).collect()
            }
        }
    };
    let mut out = Vec::new();
    let mut visited = vec![false; nodes.len()];
    let mut stack: Vec<(usize, Mat4)> = roots
        .into_iter()
        .rev()
        .map(|r| (r, Mat4::IDENTITY))
        .collect();
    while let Some((i, parent)) = stack.pop() {
        let Some(n) = nodes.get(i) else { continue };
        if std::mem::replace(&mut visited[i], true) {
            continue; // a node reached twice (invalid glTF): ignore the repeat, no cycles
        }
        let world = parent.mul(&node_local(n));
        if let Some(m) = n.get("mesh").and_then(Value::as_u64) {
            out.push(Instance {
                node: i,
                mesh: m as usize,
                world,
            });
        }
        let children: Vec<usize> = n
            .get("children")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .filter_map(Value::as_u64)
            .map(|x| x as usize)
            .collect();
        for c in children.into_iter().rev() {
            stack.push((c, world));
        }
    }
    out
}
