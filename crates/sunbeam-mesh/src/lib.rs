//! Meshes for Sunbeam: glTF 2.0 (`.gltf` with external or embedded buffers,
//! `.glb`) and Wavefront OBJ input, the nanostructure orientation field that
//! `sunbeam-bake` puts on a mesh, a GLB writer that keeps everything the input
//! had, and the loader the renderers use.
//!
//! # For the renderers: [`load_scene_mesh`]
//!
//! ```no_run
//! let m = sunbeam_mesh::load_scene_mesh(std::path::Path::new("snake.glb")).unwrap();
//! for tri in m.indices.chunks(3) { let _n = m.normals[tri[0] as usize]; }
//! let (lo, hi) = m.bounds();
//! # let _ = (lo, hi);
//! ```
//!
//! It returns one indexed triangle list ([`TriMesh`]) of the whole default
//! scene, **in world space** (every node transform applied; a mesh used by
//! several nodes appears once per node):
//! - `positions` (M p), `normals` (unit, M^-T n; computed angle-weighted and
//!   welded across UV seams when the file has none), `uvs` (TEXCOORD_0, zeros
//!   where missing: see `has_uvs`),
//! - `orientation`: the unit direction `t` that the height patch's +x axis
//!   points to (PHYSICS.md 1), orthogonal to the normal. Taken from the
//!   `_ORIENTATION` attribute, else from `TANGENT.xyz`, else derived (the
//!   direction of increasing u, else an arbitrary perpendicular):
//!   [`TriMesh::orientation_source`] says which, so a player can warn about an
//!   unbaked mesh. The shading frame is `n`, `t`, `b = n x t`.
//! - `tangents`: `TANGENT` (xyz unit, w = +-1, the glTF bitangent sign for normal
//!   maps; w is negated under a mirroring node transform). The diffraction frame
//!   uses `b = n x t` whatever w is.
//! - `submeshes`: one per (node, primitive), with the material index and base colour.
//!
//! Points and lines primitives are skipped. Errors are `sunbeam_common::Error`
//! (exit code 2, message starting with the file name).
//!
//! # For the baker
//! [`bake::bake`] computes the field from an [`orient::Source`] and writes a GLB
//! through [`gltf::Document`]; [`snake::generate`] makes the demo snake.

#![allow(clippy::needless_range_loop)] // index loops over parallel per-vertex arrays read best

pub mod bake;
pub mod bvh;
pub mod diffraction_ext;
pub mod geom;
pub mod gltf;
pub mod nodes;
pub mod obj;
pub mod orient;
pub mod scale_maps;
pub mod scales;
pub mod snake;
pub mod texture;

use geom::{any_perpendicular, normalize, project, Xform, V3};
use gltf::Document;
use std::path::Path;
use sunbeam_common::{Error, Result};

/// Where [`TriMesh::orientation`] came from (the least specific over all primitives).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum OrientationSource {
    /// `_ORIENTATION` on every primitive (a baked mesh).
    Baked,
    /// `TANGENT` on every primitive (no `_ORIENTATION`).
    Tangent,
    /// Derived from UVs or arbitrary: the mesh was not baked.
    Derived,
}

/// One (node, primitive) range of [`TriMesh::indices`].
#[derive(Debug, Clone)]
pub struct SubMesh {
    pub first_index: u32,
    pub index_count: u32,
    pub node: usize,
    pub mesh: usize,
    pub primitive: usize,
    pub material: Option<usize>,
    /// `pbrMetallicRoughness.baseColorFactor` of the material (white when none).
    pub base_color: [f32; 4],
}

/// An indexed triangle mesh in world space (see the crate docs).
#[derive(Debug, Clone, Default)]
pub struct TriMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub tangents: Vec<[f32; 4]>,
    pub orientation: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
    pub submeshes: Vec<SubMesh>,
    /// Every primitive had TEXCOORD_0.
    pub has_uvs: bool,
    pub orientation_source: Option<OrientationSource>,
}

impl TriMesh {
    /// Axis-aligned bounds (min, max) of the positions; zeros for an empty mesh.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        if self.positions.is_empty() {
            return ([0.0; 3], [0.0; 3]);
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k] as f64);
                hi[k] = hi[k].max(p[k] as f64);
            }
        }
        (lo, hi)
    }
}

/// Load `.gltf`, `.glb` or `.obj` (told apart by content) as a [`Document`].
pub fn load_document(path: &Path) -> Result<Document> {
    let mut head = [0u8; 64];
    let n = {
        use std::io::Read;
        let mut f = std::fs::File::open(path)
            .map_err(|e| Error::input_file(path, format!("cannot open: {e}")))?;
        f.read(&mut head)
            .map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?
    };
    let h = &head[..n];
    let text = String::from_utf8_lossy(h);
    let t = text.trim_start_matches('\u{feff}').trim_start();
    if h.starts_with(b"glTF") || t.starts_with('{') {
        Document::load(path)
    } else if n == 0 {
        Err(Error::input_file(path, "empty file"))
    } else {
        obj::load_obj(path)
    }
}

/// Normals of a local primitive: the file's (normalised) or angle-weighted.
/// Zero or missing normals are replaced by computed ones.
pub(crate) fn local_normals(p: &nodes::Prim) -> Vec<V3> {
    let computed = || geom::angle_weighted_normals(&p.positions, &p.triangles).0;
    match &p.normals {
        Some(n) => {
            let mut c: Option<Vec<V3>> = None;
            n.iter()
                .enumerate()
                .map(|(i, v)| normalize(*v).unwrap_or_else(|| c.get_or_insert_with(computed)[i]))
                .collect()
        }
        None => computed(),
    }
}

fn base_color(doc: &Document, material: Option<usize>) -> [f32; 4] {
    let mut c = [1.0f32; 4];
    if let Some(a) = material
        .and_then(|m| doc.array("materials").get(m))
        .and_then(|m| m.pointer("/pbrMetallicRoughness/baseColorFactor"))
        .and_then(|v| v.as_array())
    {
        for (i, x) in a.iter().take(4).enumerate() {
            c[i] = x.as_f64().unwrap_or(1.0) as f32;
        }
    }
    c
}

/// Load the whole default scene as one world-space [`TriMesh`] (see the crate docs).
pub fn load_scene_mesh(path: &Path) -> Result<TriMesh> {
    let doc = load_document(path)?;
    scene_mesh(&doc)
}

/// [`load_scene_mesh`] on an already loaded document.
pub fn scene_mesh(doc: &Document) -> Result<TriMesh> {
    let mut out = TriMesh {
        has_uvs: true,
        ..Default::default()
    };
    let mut cache: std::collections::HashMap<(usize, usize), Option<nodes::Prim>> =
        Default::default();
    for inst in nodes::instances(doc) {
        let nprim = doc
            .array("meshes")
            .get(inst.mesh)
            .and_then(|m| m.get("primitives"))
            .and_then(|p| p.as_array())
            .map_or(0, |a| a.len());
        let Some(x) = Xform::new(inst.world) else {
            continue;
        }; // a zero scale hides the node
        let mirror = if x.det < 0.0 { -1.0 } else { 1.0 };
        for k in 0..nprim {
            if let std::collections::hash_map::Entry::Vacant(e) = cache.entry((inst.mesh, k)) {
                e.insert(nodes::read_primitive(doc, inst.mesh, k, 0)?);
            }
            let Some(p) = cache[&(inst.mesh, k)].as_ref() else {
                continue;
            };
            let nl = local_normals(p);
            let base = out.positions.len() as u32;
            let src = if p.orientation.is_some() {
                OrientationSource::Baked
            } else if p.tangents.is_some() {
                OrientationSource::Tangent
            } else {
                OrientationSource::Derived
            };
            out.orientation_source = Some(out.orientation_source.map_or(src, |s| s.max(src)));
            out.has_uvs &= p.uvs.is_some();
            let dpdu = p
                .uvs
                .as_ref()
                .map(|uv| geom::uv_derivatives(&p.positions, uv, &p.triangles).0);
            for i in 0..p.positions.len() {
                let pw = x.point(p.positions[i]);
                let nw = x.normal(nl[i]).unwrap_or([0.0, 0.0, 1.0]);
                let local_dir = p
                    .orientation
                    .as_ref()
                    .map(|o| o[i])
                    .or_else(|| p.tangents.as_ref().map(|t| [t[i][0], t[i][1], t[i][2]]))
                    .or_else(|| dpdu.as_ref().map(|d| d[i]));
                let ow = local_dir
                    .and_then(|d| normalize(project(x.tangent(d), nw)))
                    .unwrap_or_else(|| any_perpendicular(nw));
                let tw = match &p.tangents {
                    Some(t) => {
                        let tt = normalize(project(x.tangent([t[i][0], t[i][1], t[i][2]]), nw))
                            .unwrap_or(ow);
                        let w = if t[i][3] < 0.0 { -1.0 } else { 1.0 } * mirror;
                        [tt[0], tt[1], tt[2], w]
                    }
                    None => [ow[0], ow[1], ow[2], 1.0],
                };
                out.positions.push(pw.map(|v| v as f32));
                out.normals.push(nw.map(|v| v as f32));
                out.uvs.push(
                    p.uvs
                        .as_ref()
                        .map_or([0.0; 2], |u| [u[i][0] as f32, u[i][1] as f32]),
                );
                out.orientation.push(ow.map(|v| v as f32));
                out.tangents.push(tw.map(|v| v as f32));
            }
            let first = out.indices.len() as u32;
            for t in &p.triangles {
                // A mirroring transform flips the winding (glTF 3.7.2.1): keep CCW = front.
                let t = if x.det < 0.0 { [t[0], t[2], t[1]] } else { *t };
                out.indices.extend(t.iter().map(|&i| i + base));
            }
            out.submeshes.push(SubMesh {
                first_index: first,
                index_count: out.indices.len() as u32 - first,
                node: inst.node,
                mesh: inst.mesh,
                primitive: k,
                material: p.material,
                base_color: base_color(doc, p.material),
            });
        }
    }
    if out.positions.is_empty() {
        out.has_uvs = false;
    }
    Ok(out)
}
