//! Scale maps on a mesh (`sunbeam-bake --scales`, docs/BAKE.md "Scales"): the
//! normal map and the ridge orientation per texel, applied per fragment.
//!
//! A mesh file's first material with a `SUNBEAM_materials_diffraction`
//! `orientationTexture` gives the maps for the whole mesh (the bake writes the
//! same maps on every material). The maps are sampled at `TEXCOORD_0`
//! bilinearly with the texture's wrap modes, normals and ridge directions
//! interpolated as vectors and renormalised (`sunbeam_mesh::scale_maps`).

use std::path::Path;
use sunbeam_common::{Error, Result};
use sunbeam_mesh::geom::{cross, dot, normalize as unit};
use sunbeam_mesh::scale_maps::ScaleMaps;

/// The maps of a mesh and its per-vertex `TANGENT` (world xyz, w = bitangent sign).
#[derive(Debug, Clone)]
pub struct MeshScales {
    pub maps: ScaleMaps,
    pub tangents: Vec<[f32; 4]>,
}

fn along(a: [f64; 3], n: [f64; 3]) -> Option<[f64; 3]> {
    let d = dot(a, n);
    unit([a[0] - d * n[0], a[1] - d * n[1], a[2] - d * n[2]])
}

impl MeshScales {
    /// The scale maps of the mesh file `doc` (its scene mesh `tm`), or None.
    pub fn from_document(
        doc: &mut sunbeam_mesh::gltf::Document,
        tm: &sunbeam_mesh::TriMesh,
    ) -> Result<Option<MeshScales>> {
        for m in 0..doc.array("materials").len() {
            if let Some(maps) = sunbeam_mesh::scale_maps::read(doc, m)? {
                if maps.texcoord != 0 {
                    return Err(Error::input_file(
                        &doc.source,
                        format!(
                            "materials[{m}]: the scale maps use TEXCOORD_{}; the reference reads TEXCOORD_0 only",
                            maps.texcoord
                        ),
                    ));
                }
                if !tm.has_uvs {
                    return Err(Error::input_file(
                        &doc.source,
                        "scale maps on a mesh without TEXCOORD_0",
                    ));
                }
                return Ok(Some(MeshScales {
                    maps,
                    tangents: tm.tangents.clone(),
                }));
            }
        }
        Ok(None)
    }

    /// The shading normal and orientation at a fragment: `normal` and
    /// `tangent` (TANGENT xyz, w) interpolated from the vertices, `uv` its
    /// TEXCOORD_0. The normal map's (X, Y, Z) are along T, B = w (n x T) and
    /// n; the ridge direction cos(a) T + sin(a) (n x T) is made orthogonal to
    /// the new normal. None when the frame is degenerate.
    pub fn perturb(
        &self,
        normal: [f64; 3],
        tangent: [f64; 4],
        uv: [f64; 2],
    ) -> Option<([f64; 3], [f64; 3])> {
        let n = unit(normal)?;
        let t = along([tangent[0], tangent[1], tangent[2]], n)?;
        let nxt = cross(n, t);
        let w = if tangent[3] < 0.0 { -1.0 } else { 1.0 };
        let s = self.maps.sample(uv);
        let m = s.normal;
        let n2 = unit([0, 1, 2].map(|k| m[0] * t[k] + m[1] * w * nxt[k] + m[2] * n[k]))?;
        let d = [0, 1, 2].map(|k| s.ridge[0] * t[k] + s.ridge[1] * nxt[k]);
        let t2 = along(d, n2)?;
        Some((n2, t2))
    }
}

/// Load a mesh file with its scale maps (None for builtins and unscaled meshes).
pub fn load_mesh_with_scales(path: &Path) -> Result<(crate::Mesh, Option<MeshScales>)> {
    if let Some(b) = crate::Mesh::builtin(path) {
        return Ok((b.map_err(Error::input)?, None));
    }
    let mut doc = sunbeam_mesh::load_document(path)?;
    let tm = sunbeam_mesh::scene_mesh(&doc)?;
    let scales = MeshScales::from_document(&mut doc, &tm)?;
    Ok((crate::mesh_from_trimesh(tm, path)?, scales))
}
