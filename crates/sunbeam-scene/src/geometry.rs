//! Built-in meshes (`"mesh": "builtin:quad"`, `"builtin:sphere"`) and the plain
//! triangle mesh both renderers draw. Built-ins need no file, so test scenes and
//! quick looks at a pack work without a baked GLB.
//!
//! Conventions shared with sunbeam-mesh's `TriMesh`: world space, right-handed,
//! y up; counter-clockwise front faces; `tangents[i]` is the orientation vector `t`
//! (the direction the patch's +x axis points to, PHYSICS.md 1) in xyz and a sign in w.

use std::path::Path;

/// An indexed triangle mesh with the vertex attributes the diffraction shader needs.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    /// Orientation `t` (xyz) and handedness (w, +-1); used as is, `b = n x t`.
    pub tangents: Vec<[f32; 4]>,
    /// Triangles, counter-clockwise seen from the front.
    pub indices: Vec<u32>,
}

/// The built-in meshes a scene can name with `builtin:NAME`.
pub const BUILTINS: &[&str] = &["quad", "sphere"];

impl Mesh {
    /// Axis-aligned bounds (min, max); a unit box around the origin for an empty mesh.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        if self.positions.is_empty() {
            return ([-0.5; 3], [0.5; 3]);
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

    /// Check sizes and index ranges; the message names the attribute.
    pub fn check(&self) -> Result<(), String> {
        let n = self.positions.len();
        if self.normals.len() != n || self.uvs.len() != n || self.tangents.len() != n {
            return Err(format!(
                "attribute counts differ: {} positions, {} normals, {} uvs, {} tangents",
                n,
                self.normals.len(),
                self.uvs.len(),
                self.tangents.len()
            ));
        }
        if !self.indices.len().is_multiple_of(3) {
            return Err(format!(
                "{} indices is not a whole number of triangles",
                self.indices.len()
            ));
        }
        if let Some(i) = self.indices.iter().find(|&&i| i as usize >= n) {
            return Err(format!("index {i} out of range ({n} vertices)"));
        }
        if self.positions.iter().flatten().any(|v| !v.is_finite()) {
            return Err("non-finite vertex position".into());
        }
        Ok(())
    }

    /// A 1 x 1 square in the xy-plane centred on the origin, facing +z, `t = +x`,
    /// uv (0,0) at the bottom-left corner.
    pub fn quad() -> Mesh {
        let positions = vec![
            [-0.5, -0.5, 0.0],
            [0.5, -0.5, 0.0],
            [0.5, 0.5, 0.0],
            [-0.5, 0.5, 0.0],
        ];
        Mesh {
            positions,
            normals: vec![[0.0, 0.0, 1.0]; 4],
            uvs: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            tangents: vec![[1.0, 0.0, 0.0, 1.0]; 4],
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    /// A UV sphere of radius 0.5 around the origin, poles on y; `t` runs along the
    /// lines of latitude (east, d/d longitude), undefined only at the poles where it
    /// is set to +x.
    pub fn uv_sphere(segments: u32, rings: u32) -> Mesh {
        let (segments, rings) = (segments.max(3), rings.max(2));
        let mut m = Mesh::default();
        for r in 0..=rings {
            let v = r as f64 / rings as f64;
            let th = v * std::f64::consts::PI;
            for s in 0..=segments {
                let u = s as f64 / segments as f64;
                let ph = u * std::f64::consts::TAU;
                let n = [th.sin() * ph.cos(), th.cos(), -th.sin() * ph.sin()];
                m.positions.push([
                    (0.5 * n[0]) as f32,
                    (0.5 * n[1]) as f32,
                    (0.5 * n[2]) as f32,
                ]);
                m.normals.push([n[0] as f32, n[1] as f32, n[2] as f32]);
                m.uvs.push([u as f32, 1.0 - v as f32]);
                // d n / d ph = (-sin ph, 0, -cos ph) * sin th: eastward
                let t = if th.sin() > 1e-9 {
                    [-ph.sin(), 0.0, -ph.cos()]
                } else {
                    [1.0, 0.0, 0.0]
                };
                m.tangents
                    .push([t[0] as f32, t[1] as f32, t[2] as f32, 1.0]);
            }
        }
        let row = segments + 1;
        for r in 0..rings {
            for s in 0..segments {
                let a = r * row + s;
                let b = a + row;
                // counter-clockwise seen from outside
                if r != 0 {
                    m.indices.extend_from_slice(&[a, b, a + 1]);
                }
                if r != rings - 1 {
                    m.indices.extend_from_slice(&[a + 1, b, b + 1]);
                }
            }
        }
        m
    }

    /// The built-in mesh named by a scene path `builtin:NAME`, if it is one.
    pub fn builtin(path: &Path) -> Option<Result<Mesh, String>> {
        let s = path.to_str()?;
        let name = s.strip_prefix("builtin:")?;
        Some(match name {
            "quad" => Ok(Mesh::quad()),
            "sphere" => Ok(Mesh::uv_sphere(96, 48)),
            other => Err(format!(
                "unknown built-in mesh '{other}' (known: {})",
                BUILTINS.join(", ")
            )),
        })
    }
}

/// True when a scene's mesh path names a built-in mesh.
pub fn is_builtin(path: &Path) -> bool {
    path.to_str().is_some_and(|s| s.starts_with("builtin:"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
    fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }
    fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    #[test]
    fn builtins_are_valid_counter_clockwise_and_tangent() {
        for m in [Mesh::quad(), Mesh::uv_sphere(16, 8)] {
            m.check().unwrap();
            for tri in m.indices.chunks(3) {
                let [a, b, c] = [0, 1, 2].map(|k| m.positions[tri[k] as usize]);
                let face = cross(sub(b, a), sub(c, a));
                let n = m.normals[tri[0] as usize];
                assert!(
                    dot(face, n) > 0.0,
                    "triangle {tri:?} is not counter-clockwise from outside"
                );
            }
            for (t, n) in m.tangents.iter().zip(&m.normals) {
                assert!(dot([t[0], t[1], t[2]], *n).abs() < 1e-5);
            }
        }
        assert!(Mesh::builtin(Path::new("builtin:cube")).unwrap().is_err());
        assert!(Mesh::builtin(Path::new("a.glb")).is_none());
    }
}
