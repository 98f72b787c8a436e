//! The reach of a scene: a bound on the directions `(u, v, w) = wi + wr` its
//! lights and camera can produce over its visible meshes, so a pack built for
//! it (`sunbeam-pack --scene`) needs fewer terms and a smaller crop.
//!
//! This crate does not load meshes: the caller passes a loader for mesh files
//! (sunbeam-pack's tool uses `sunbeam_mesh::load_scene_mesh`); built-in meshes
//! (`builtin:quad`, `builtin:sphere`) are handled here.
//!
//! For a directional light `l` (unit, towards the light) and a surface point `p`
//! seen from the eye `e`, `wr = (e - p)/|e - p|` and `|(u, v, w)| = |wi + wr| =
//! 2 cos(theta/2)` with theta the angle between `l` and `wr`, whatever the
//! surface frame is. So `|u|, |v|, |w| <= 2 cos(theta_min/2)` with theta_min
//! the smallest light-view angle over the visible mesh: taken over the vertices
//! of every triangle not culled by the camera frustum, less the triangle's own
//! angular size (every point of a triangle sees the eye within that angle of a
//! vertex). Conservative: no occlusion, no normals, no back-face culling.

use crate::Scene;
use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};

/// A mesh's triangles: positions and indices (three per triangle).
pub type Triangles = (Vec<[f32; 3]>, Vec<u32>);

/// What a scene can reach.
#[derive(Debug, Clone)]
pub struct Reach {
    /// Wavelength range the lights emit, if narrower than the default.
    pub lambda: Option<(f64, f64)>,
    /// Bound on |w| (and on |u|, |v|).
    pub max_w: f64,
    /// Bound on |u| and |v|.
    pub max_uv: f64,
    /// Files the scene read (for depfiles).
    pub inputs: Vec<PathBuf>,
    /// Human-readable notes: what was skipped.
    pub notes: Vec<String>,
}

impl Reach {
    /// Largest |fx|, |fy| at the shortest wavelength.
    pub fn freq_limit(&self, lambda_min: f64) -> [f64; 2] {
        [self.max_uv / lambda_min, self.max_uv / lambda_min]
    }
}

fn norm(a: [f64; 3]) -> Option<[f64; 3]> {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    (l > 0.0 && l.is_finite()).then(|| [a[0] / l, a[1] / l, a[2] / l])
}

fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
        .clamp(-1.0, 1.0)
        .acos()
}

/// Triangles of a scene mesh: built-in here, files through `load`.
fn mesh_triangles(
    path: &Path,
    load: &mut impl FnMut(&Path) -> Result<Triangles>,
) -> Result<Triangles> {
    if let Some(m) = crate::geometry::Mesh::builtin(path) {
        let m = m.map_err(Error::input)?;
        return Ok((m.positions, m.indices));
    }
    load(path)
}

/// The reach of the scene in file `path` (see the module docs); `max_w` is
/// the caller's own bound, `load` reads a mesh file's triangles.
pub fn reach_of_file(
    path: &Path,
    max_w: f64,
    load: impl FnMut(&Path) -> Result<Triangles>,
) -> Result<Reach> {
    let scene = Scene::load(path)?;
    reach(&scene, path, max_w, load)
}

/// [`reach_of_file`] on a loaded scene (`path`: the scene's file, for depfiles and messages).
pub fn reach(
    scene: &Scene,
    path: &Path,
    max_w: f64,
    mut load: impl FnMut(&Path) -> Result<Triangles>,
) -> Result<Reach> {
    let mut inputs = vec![path.to_path_buf()];
    let vp = scene.camera.view_proj(scene.size[0], scene.size[1]);
    let eye = scene.camera.eye;
    let lights: Vec<[f64; 3]> = scene
        .lights
        .iter()
        .filter_map(|l| norm(l.direction))
        .collect();
    let mut theta_min = vec![std::f64::consts::PI; lights.len()];
    let (mut kept, mut culled) = (0usize, 0usize);
    for mi in &scene.meshes {
        if !crate::geometry::is_builtin(&mi.mesh) {
            inputs.push(mi.mesh.clone());
        }
        let (pos, idx) =
            mesh_triangles(&mi.mesh, &mut load).map_err(|e| e.context(path.display()))?;
        let clip: Vec<[f64; 4]> = pos
            .iter()
            .map(|p| crate::camera::transform(&vp, [p[0] as f64, p[1] as f64, p[2] as f64, 1.0]))
            .collect();
        let dirs: Vec<Option<[f64; 3]>> = pos
            .iter()
            .map(|p| {
                norm([
                    eye[0] - p[0] as f64,
                    eye[1] - p[1] as f64,
                    eye[2] - p[2] as f64,
                ])
            })
            .collect();
        for tri in idx.chunks_exact(3) {
            let v = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
            if v.iter().any(|&i| i >= pos.len()) {
                return Err(Error::input(format!(
                    "{}: mesh index out of range",
                    mi.mesh.display()
                )));
            }
            // Culled when all three vertices lie outside the same clip plane.
            let outside = |plane: usize| {
                v.iter().all(|&i| {
                    let c = &clip[i];
                    match plane {
                        0 => c[0] < -c[3],
                        1 => c[0] > c[3],
                        2 => c[1] < -c[3],
                        3 => c[1] > c[3],
                        4 => c[2] < 0.0,
                        _ => c[2] > c[3],
                    }
                })
            };
            if (0..6).any(outside) {
                culled += 1;
                continue;
            }
            kept += 1;
            let d: Vec<[f64; 3]> = match v.iter().map(|&i| dirs[i]).collect::<Option<Vec<_>>>() {
                Some(d) => d,
                None => {
                    // The eye sits on a vertex: anything goes.
                    theta_min.iter_mut().for_each(|t| *t = 0.0);
                    continue;
                }
            };
            let size = angle(d[0], d[1])
                .max(angle(d[1], d[2]))
                .max(angle(d[0], d[2]));
            for (li, l) in lights.iter().enumerate() {
                let a = d
                    .iter()
                    .map(|x| angle(*l, *x))
                    .fold(f64::INFINITY, f64::min)
                    - size;
                theta_min[li] = theta_min[li].min(a.max(0.0));
            }
        }
    }
    let mut notes = vec![];
    let s = if kept == 0 || lights.is_empty() {
        notes.push("scene: no visible triangle or no light; nothing bounded".into());
        2.0
    } else {
        theta_min
            .iter()
            .map(|t| 2.0 * (t / 2.0).cos())
            .fold(0.0, f64::max)
    };
    let max_uv = s.min(2.0);
    let bw = max_w.min(max_uv);
    if max_uv < 2.0 {
        notes.push(format!(
            "scene: light-view angle >= {:.1} deg over {kept} visible triangles ({culled} outside the frustum): \
             |u|, |v|, |w| <= {max_uv:.4}; frequencies beyond {max_uv:.4}/lambda_min and |w| beyond {bw:.4} skipped",
            theta_min.iter().copied().fold(f64::INFINITY, f64::min).to_degrees()
        ));
    } else {
        notes.push(format!(
            "scene: {kept} visible triangles ({culled} outside the frustum); a light can be behind the viewer, \
             so all directions are kept"
        ));
    }
    Ok(Reach {
        lambda: None,
        max_w: bw,
        max_uv,
        inputs,
        notes,
    })
}
