//! Wavefront OBJ (+ MTL) to a glTF [`Document`] (one mesh, one primitive per
//! `usemtl` group, one node, one scene).
//!
//! OBJ texture coordinates have v up; glTF's have v down: `v_gltf = 1 - v_obj`.
//! Normals given in the file are normalised; where a group lacks normals on
//! any corner, the group's normals are computed (angle-weighted, welded).

use crate::geom::{angle_weighted_normals, normalize, V3};
use crate::gltf::Document;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::Path;
use sunbeam_common::{Error, Result};

#[derive(Default)]
struct Group {
    material: Option<String>,
    verts: Vec<(usize, Option<usize>, Option<usize>)>,
    map: HashMap<(usize, Option<usize>, Option<usize>), u32>,
    idx: Vec<u32>,
}

fn perr(path: &Path, line: usize, msg: impl std::fmt::Display) -> Error {
    Error::input_file(path, format!("line {line}: {msg}"))
}

fn floats(
    path: &Path,
    ln: usize,
    it: &mut std::str::SplitWhitespace,
    min: usize,
    what: &str,
) -> Result<Vec<f64>> {
    let v: Vec<f64> = it
        .map(|t| {
            t.parse::<f64>()
                .map_err(|_| perr(path, ln, format!("{what}: {t:?} is not a number")))
        })
        .collect::<Result<_>>()?;
    if v.len() < min {
        return Err(perr(
            path,
            ln,
            format!("{what} needs {min} numbers, has {}", v.len()),
        ));
    }
    if v.iter().take(min).any(|x| !x.is_finite()) {
        return Err(perr(path, ln, format!("{what} holds NaN or infinity")));
    }
    Ok(v)
}

/// Resolve an OBJ index (1-based, negative = relative to the end).
fn resolve(path: &Path, ln: usize, tok: &str, len: usize, what: &str) -> Result<usize> {
    let i: i64 = tok
        .parse()
        .map_err(|_| perr(path, ln, format!("{what} index {tok:?} is not an integer")))?;
    let r = if i > 0 { i - 1 } else { len as i64 + i };
    if i == 0 || r < 0 || r as usize >= len {
        return Err(perr(
            path,
            ln,
            format!("{what} index {i} out of range (have {len})"),
        ));
    }
    Ok(r as usize)
}

/// Load an OBJ file as a glTF document.
pub fn load_obj(path: &Path) -> Result<Document> {
    let bytes =
        std::fs::read(path).map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    let text = String::from_utf8_lossy(&bytes);
    let mut pos: Vec<V3> = Vec::new();
    let mut tex: Vec<[f64; 2]> = Vec::new();
    let mut nrm: Vec<V3> = Vec::new();
    let mut groups: Vec<Group> = vec![Group::default()];
    let mut cur = 0usize;
    let mut mtllibs: Vec<String> = Vec::new();
    let mut name: Option<String> = None;
    for (ln0, raw) in text.lines().enumerate() {
        let ln = ln0 + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let mut it = line.split_whitespace();
        let kw = it.next().unwrap_or("");
        match kw {
            "v" => {
                let v = floats(path, ln, &mut it, 3, "v")?;
                pos.push([v[0], v[1], v[2]]);
            }
            "vt" => {
                let v = floats(path, ln, &mut it, 1, "vt")?;
                tex.push([v[0], 1.0 - v.get(1).copied().unwrap_or(0.0)]);
            }
            "vn" => {
                let v = floats(path, ln, &mut it, 3, "vn")?;
                nrm.push([v[0], v[1], v[2]]);
            }
            "f" => {
                let mut corners = Vec::new();
                for t in it {
                    let mut parts = t.split('/');
                    let vi = resolve(path, ln, parts.next().unwrap_or(""), pos.len(), "vertex")?;
                    let ti = match parts.next() {
                        Some(s) if !s.is_empty() => {
                            Some(resolve(path, ln, s, tex.len(), "texture coordinate")?)
                        }
                        _ => None,
                    };
                    let ni = match parts.next() {
                        Some(s) if !s.is_empty() => {
                            Some(resolve(path, ln, s, nrm.len(), "normal")?)
                        }
                        _ => None,
                    };
                    corners.push((vi, ti, ni));
                }
                if corners.len() < 3 {
                    return Err(perr(
                        path,
                        ln,
                        format!("face with {} corners", corners.len()),
                    ));
                }
                let g = &mut groups[cur];
                let ids: Vec<u32> = corners
                    .into_iter()
                    .map(|c| {
                        *g.map.entry(c).or_insert_with(|| {
                            g.verts.push(c);
                            (g.verts.len() - 1) as u32
                        })
                    })
                    .collect();
                for i in 1..ids.len() - 1 {
                    g.idx.extend_from_slice(&[ids[0], ids[i], ids[i + 1]]);
                }
            }
            "usemtl" => {
                let m = it.collect::<Vec<_>>().join(" ");
                cur = match groups
                    .iter()
                    .position(|g| g.material.as_deref() == Some(m.as_str()))
                {
                    Some(i) => i,
                    None => {
                        groups.push(Group {
                            material: Some(m),
                            ..Default::default()
                        });
                        groups.len() - 1
                    }
                };
            }
            "mtllib" => mtllibs.extend(it.map(str::to_string)),
            "o" if name.is_none() => name = Some(it.collect::<Vec<_>>().join(" ")),
            _ => {}
        }
    }
    let mut doc = Document::new_empty(path);
    doc.base_dir = path.parent().map(|p| {
        if p.as_os_str().is_empty() {
            Path::new(".").to_path_buf()
        } else {
            p.to_path_buf()
        }
    });
    // Materials.
    let mtl = read_mtls(&mut doc, &mtllibs);
    let mut mat_index: HashMap<String, usize> = HashMap::new();
    let mut prims = Vec::new();
    for g in groups.iter().filter(|g| !g.idx.is_empty()) {
        let p: Vec<V3> = g.verts.iter().map(|c| pos[c.0]).collect();
        let tris: Vec<[u32; 3]> = g.idx.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
        let have_n = g
            .verts
            .iter()
            .all(|c| c.2.is_some_and(|i| normalize(nrm[i]).is_some()));
        let normals: Vec<V3> = if have_n {
            g.verts
                .iter()
                .map(|c| normalize(nrm[c.2.unwrap_or(0)]).unwrap_or([0.0, 0.0, 1.0]))
                .collect()
        } else {
            angle_weighted_normals(&p, &tris).0
        };
        let have_t = g.verts.iter().any(|c| c.1.is_some());
        let flat_p: Vec<f32> = p.iter().flat_map(|v| v.iter().map(|&x| x as f32)).collect();
        let flat_n: Vec<f32> = normals
            .iter()
            .flat_map(|v| v.iter().map(|&x| x as f32))
            .collect();
        let pa = doc.push_f32_accessor(&flat_p, 3, true);
        let na = doc.push_f32_accessor(&flat_n, 3, false);
        let mut attrs = serde_json::Map::new();
        attrs.insert("POSITION".into(), json!(pa));
        attrs.insert("NORMAL".into(), json!(na));
        if have_t {
            let flat_t: Vec<f32> = g
                .verts
                .iter()
                .flat_map(|c| c.1.map(|i| tex[i]).unwrap_or([0.0, 0.0]).map(|x| x as f32))
                .collect();
            attrs.insert(
                "TEXCOORD_0".into(),
                json!(doc.push_f32_accessor(&flat_t, 2, false)),
            );
        }
        let ia = doc.push_index_accessor(&g.idx);
        let mut prim = json!({"attributes": Value::Object(attrs), "indices": ia, "mode": 4});
        if let Some(m) = &g.material {
            let n = doc.array("materials").len();
            let mi = *mat_index.entry(m.clone()).or_insert(n);
            if mi == n {
                let mat = mtl.get(m).cloned().unwrap_or_else(|| json!({"name": m}));
                doc.json_array_mut("materials").push(mat);
            }
            prim["material"] = json!(mi);
        }
        prims.push(prim);
    }
    if prims.is_empty() {
        return Err(Error::input_file(
            path,
            "no faces: an OBJ needs at least one `f` line",
        ));
    }
    let mname = name.unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    });
    doc.json_array_mut("meshes")
        .push(json!({"name": mname, "primitives": prims}));
    doc.json_array_mut("nodes")
        .push(json!({"name": mname, "mesh": 0}));
    doc.json_array_mut("scenes").push(json!({"nodes": [0]}));
    doc.json["scene"] = json!(0);
    Ok(doc)
}

/// Parse the MTL files that exist (missing ones are skipped: an OBJ without its
/// MTL still bakes). Kd -> baseColorFactor, d -> alpha, map_Kd -> baseColorTexture.
fn read_mtls(doc: &mut Document, libs: &[String]) -> HashMap<String, Value> {
    let mut out: HashMap<String, Value> = HashMap::new();
    let base = doc
        .base_dir
        .clone()
        .unwrap_or_else(|| Path::new(".").to_path_buf());
    for lib in libs {
        let p = base.join(lib);
        let Ok(text) = std::fs::read_to_string(&p) else {
            continue;
        };
        doc.extra_inputs.push(p);
        let mut cur: Option<String> = None;
        for line in text.lines() {
            let line = line.split('#').next().unwrap_or("").trim();
            let mut it = line.split_whitespace();
            let kw = it.next().unwrap_or("");
            let rest: Vec<&str> = it.collect();
            match kw {
                "newmtl" => {
                    let n = rest.join(" ");
                    out.insert(
                        n.clone(),
                        json!({"name": n, "pbrMetallicRoughness": {"metallicFactor": 0.0}}),
                    );
                    cur = Some(n);
                }
                "Kd" | "d" | "map_Kd" if cur.is_some() => {
                    let m = out
                        .get_mut(cur.as_deref().unwrap_or(""))
                        .expect("current material exists");
                    let pbr = &mut m["pbrMetallicRoughness"];
                    if pbr.get("baseColorFactor").is_none() {
                        pbr["baseColorFactor"] = json!([1.0, 1.0, 1.0, 1.0]);
                    }
                    match kw {
                        "Kd" => {
                            for (i, t) in rest.iter().take(3).enumerate() {
                                if let Ok(x) = t.parse::<f64>() {
                                    pbr["baseColorFactor"][i] = json!(x.clamp(0.0, 1.0));
                                }
                            }
                        }
                        "d" => {
                            if let Some(x) = rest.first().and_then(|t| t.parse::<f64>().ok()) {
                                pbr["baseColorFactor"][3] = json!(x.clamp(0.0, 1.0));
                            }
                        }
                        _ => {
                            // The file name is the last token (options come first).
                            if let Some(f) = rest.last() {
                                if base.join(f).is_file() {
                                    let img = doc.array("images").len();
                                    doc.json_array_mut("images")
                                        .push(json!({"uri": f.replace('\\', "/")}));
                                    if doc.array("samplers").is_empty() {
                                        doc.json_array_mut("samplers").push(json!({}));
                                    }
                                    doc.json_array_mut("textures")
                                        .push(json!({"source": img, "sampler": 0}));
                                    let tex = doc.array("textures").len() - 1;
                                    let m = out
                                        .get_mut(cur.as_deref().unwrap_or(""))
                                        .expect("current material exists");
                                    m["pbrMetallicRoughness"]["baseColorTexture"] =
                                        json!({"index": tex});
                                }
                            }
                        }
                    }
                }
                _ => {}
            }
        }
    }
    out
}
