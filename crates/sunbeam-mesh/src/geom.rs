//! Small vector and matrix helpers and the per-vertex geometry the baker needs
//! (angle-weighted normals, the UV tangent direction).

use std::collections::HashMap;

pub type V3 = [f64; 3];

#[inline]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
#[inline]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline]
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
/// Unit vector, or None when the length is zero/not finite.
#[inline]
pub fn normalize(a: V3) -> Option<V3> {
    let n = norm(a);
    if n > 1e-300 && n.is_finite() {
        Some(scale(a, 1.0 / n))
    } else {
        None
    }
}
/// `a` minus its component along the unit `n`.
#[inline]
pub fn project(a: V3, n: V3) -> V3 {
    sub(a, scale(n, dot(a, n)))
}
/// Some unit vector orthogonal to the unit `n` (deterministic).
pub fn any_perpendicular(n: V3) -> V3 {
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    normalize(project(a, n)).unwrap_or([1.0, 0.0, 0.0])
}

/// 4x4 matrix, column-major like glTF (`m[col*4 + row]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mat4(pub [f64; 16]);

impl Mat4 {
    pub const IDENTITY: Mat4 = Mat4([
        1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.,
    ]);
    pub fn mul(&self, o: &Mat4) -> Mat4 {
        let mut r = [0.0; 16];
        for c in 0..4 {
            for row in 0..4 {
                r[c * 4 + row] = (0..4).map(|k| self.0[k * 4 + row] * o.0[c * 4 + k]).sum();
            }
        }
        Mat4(r)
    }
    pub fn from_trs(t: V3, q: [f64; 4], s: V3) -> Mat4 {
        let [x, y, z, w] = q;
        let r = [
            [
                1. - 2. * (y * y + z * z),
                2. * (x * y + z * w),
                2. * (x * z - y * w),
            ],
            [
                2. * (x * y - z * w),
                1. - 2. * (x * x + z * z),
                2. * (y * z + x * w),
            ],
            [
                2. * (x * z + y * w),
                2. * (y * z - x * w),
                1. - 2. * (x * x + y * y),
            ],
        ];
        let mut m = [0.0; 16];
        for c in 0..3 {
            for row in 0..3 {
                m[c * 4 + row] = r[c][row] * s[c];
            }
        }
        m[12] = t[0];
        m[13] = t[1];
        m[14] = t[2];
        m[15] = 1.0;
        Mat4(m)
    }
    pub fn point(&self, p: V3) -> V3 {
        let m = &self.0;
        [
            m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12],
            m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13],
            m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14],
        ]
    }
    pub fn vector(&self, p: V3) -> V3 {
        let m = &self.0;
        [
            m[0] * p[0] + m[4] * p[1] + m[8] * p[2],
            m[1] * p[0] + m[5] * p[1] + m[9] * p[2],
            m[2] * p[0] + m[6] * p[1] + m[10] * p[2],
        ]
    }
    /// The upper 3x3 as rows.
    fn lin(&self) -> [[f64; 3]; 3] {
        let m = &self.0;
        [[m[0], m[4], m[8]], [m[1], m[5], m[9]], [m[2], m[6], m[10]]]
    }
    pub fn det3(&self) -> f64 {
        let a = self.lin();
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    }
    /// Inverse of the upper 3x3 (rows), None when singular.
    pub fn inv3(&self) -> Option<[[f64; 3]; 3]> {
        let a = self.lin();
        let d = self.det3();
        if d.abs() < 1e-300 || !d.is_finite() {
            return None;
        }
        let mut r = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                let (i1, i2) = ((j + 1) % 3, (j + 2) % 3);
                let (j1, j2) = ((i + 1) % 3, (i + 2) % 3);
                r[i][j] = (a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / d;
            }
        }
        Some(r)
    }
}

pub fn mat3_vec(m: &[[f64; 3]; 3], v: V3) -> V3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}
/// `m^T v`.
pub fn mat3t_vec(m: &[[f64; 3]; 3], v: V3) -> V3 {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

/// Transforms a mesh's local data to world space and back.
#[derive(Debug, Clone)]
pub struct Xform {
    pub m: Mat4,
    inv: [[f64; 3]; 3],
    pub det: f64,
}

impl Xform {
    pub fn new(m: Mat4) -> Option<Xform> {
        Some(Xform {
            m,
            inv: m.inv3()?,
            det: m.det3(),
        })
    }
    pub fn point(&self, p: V3) -> V3 {
        self.m.point(p)
    }
    /// A tangent vector (transforms with M).
    pub fn tangent(&self, t: V3) -> V3 {
        self.m.vector(t)
    }
    /// A world tangent vector back to local space (M^-1).
    pub fn tangent_to_local(&self, t: V3) -> V3 {
        mat3_vec(&self.inv, t)
    }
    /// A normal (transforms with M^-T), normalised.
    pub fn normal(&self, n: V3) -> Option<V3> {
        normalize(mat3t_vec(&self.inv, n))
    }
}

/// Angle-weighted vertex normals; vertices at the same position are welded so
/// UV seams do not show. Degenerate triangles contribute nothing. Returns the
/// normals and how many vertices got no normal (given +z... or any fallback).
pub fn angle_weighted_normals(pos: &[V3], tris: &[[u32; 3]]) -> (Vec<V3>, usize) {
    let mut acc = vec![[0.0; 3]; pos.len()];
    for t in tris {
        let p = [pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]];
        let Some(fnrm) = normalize(cross(sub(p[1], p[0]), sub(p[2], p[0]))) else {
            continue;
        };
        for k in 0..3 {
            let (a, b) = (sub(p[(k + 1) % 3], p[k]), sub(p[(k + 2) % 3], p[k]));
            let (Some(a), Some(b)) = (normalize(a), normalize(b)) else {
                continue;
            };
            let ang = dot(a, b).clamp(-1.0, 1.0).acos();
            let i = t[k] as usize;
            acc[i] = add(acc[i], scale(fnrm, ang));
        }
    }
    // Weld by exact position.
    let mut groups: HashMap<[u64; 3], V3> = HashMap::new();
    for (p, a) in pos.iter().zip(&acc) {
        let k = key(*p);
        let e = groups.entry(k).or_insert([0.0; 3]);
        *e = add(*e, *a);
    }
    let mut missing = 0;
    let out = pos
        .iter()
        .map(|p| match normalize(groups[&key(*p)]) {
            Some(n) => n,
            None => {
                missing += 1;
                [0.0, 0.0, 1.0]
            }
        })
        .collect();
    (out, missing)
}

fn key(p: V3) -> [u64; 3] {
    // +0.0 and -0.0 weld together.
    [
        (p[0] + 0.0).to_bits(),
        (p[1] + 0.0).to_bits(),
        (p[2] + 0.0).to_bits(),
    ]
}

/// Per-vertex direction of increasing u (and of v), from the triangles' UV
/// derivatives (area-weighted), not yet projected. Triangles with degenerate UVs
/// are skipped. Returns (dP/du, dP/dv) accumulators.
pub fn uv_derivatives(pos: &[V3], uv: &[[f64; 2]], tris: &[[u32; 3]]) -> (Vec<V3>, Vec<V3>) {
    let mut du = vec![[0.0; 3]; pos.len()];
    let mut dv = vec![[0.0; 3]; pos.len()];
    for t in tris {
        let (i0, i1, i2) = (t[0] as usize, t[1] as usize, t[2] as usize);
        let (e1, e2) = (sub(pos[i1], pos[i0]), sub(pos[i2], pos[i0]));
        let (s1, t1) = (uv[i1][0] - uv[i0][0], uv[i1][1] - uv[i0][1]);
        let (s2, t2) = (uv[i2][0] - uv[i0][0], uv[i2][1] - uv[i0][1]);
        let det = s1 * t2 - s2 * t1;
        if det.abs() < 1e-20 || !det.is_finite() {
            continue;
        }
        // dP/du = (e1 t2 - e2 t1)/det, dP/dv = (e2 s1 - e1 s2)/det; weight by the
        // triangle's 3D area so that large triangles dominate: multiply by |det|*area/|det|.
        let pu = scale(sub(scale(e1, t2), scale(e2, t1)), 1.0 / det);
        let pv = scale(sub(scale(e2, s1), scale(e1, s2)), 1.0 / det);
        let area = norm(cross(e1, e2));
        let (Some(pu), Some(pv)) = (normalize(pu), normalize(pv)) else {
            continue;
        };
        for &i in &[i0, i1, i2] {
            du[i] = add(du[i], scale(pu, area));
            dv[i] = add(dv[i], scale(pv, area));
        }
    }
    (du, dv)
}
