//! Triangle rasterisation with the GPU's conventions (see the crate docs): the
//! result is a G-buffer of what each pixel's sample point sees (its centre, or
//! a point jittered by a seed: [`Positions`]).

use crate::Prepared;
use sunbeam_common::rng::SplitMix64;
use sunbeam_scene::camera::transform;

/// What a pixel's sample point sees: the front-most fragment's interpolated attributes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Fragment {
    /// Index into `Prepared::meshes`; None for the background.
    pub mesh: Option<u32>,
    /// World position; for the background (no mesh), the point at unit
    /// distance from the eye along the sample's view ray.
    pub pos: [f64; 3],
    /// Interpolated (not normalised) normal; on a mesh with scale maps, the
    /// normal map's normal (unit, `sunbeam_frame::MeshScales::perturb`).
    pub normal: [f64; 3],
    /// Interpolated (not normalised) orientation `t`; with scale maps, the
    /// texel's ridge direction (unit, orthogonal to the mapped normal).
    pub tangent: [f64; 3],
    /// Depth in [0, 1].
    pub depth: f64,
}

/// Sub-pixel precision of vertex snapping (bits), as Vulkan implementations use.
pub const SUBPIXEL_BITS: u32 = 8;
const ONE: i64 = 1 << SUBPIXEL_BITS;

/// A clip-space vertex and its barycentric weights on the original triangle.
#[derive(Clone, Copy)]
struct ClipVert {
    c: [f64; 4],
    bary: [f64; 3],
}

fn lerp_cv(a: &ClipVert, b: &ClipVert, s: f64) -> ClipVert {
    ClipVert {
        c: [0, 1, 2, 3].map(|k| a.c[k] + s * (b.c[k] - a.c[k])),
        bary: [0, 1, 2].map(|k| a.bary[k] + s * (b.bary[k] - a.bary[k])),
    }
}

/// Clip a triangle against the near plane `z >= 0` (wgpu clip space).
fn clip_near(tri: [ClipVert; 3]) -> Vec<[ClipVert; 3]> {
    let inside = |v: &ClipVert| v.c[2] >= 0.0;
    if tri.iter().all(inside) {
        return vec![tri];
    }
    if !tri.iter().any(inside) {
        return vec![];
    }
    let mut poly: Vec<ClipVert> = Vec::with_capacity(4);
    for i in 0..3 {
        let a = &tri[i];
        let b = &tri[(i + 1) % 3];
        if inside(a) {
            poly.push(*a);
        }
        if inside(a) != inside(b) {
            let s = a.c[2] / (a.c[2] - b.c[2]);
            poly.push(lerp_cv(a, b, s));
        }
    }
    (1..poly.len().saturating_sub(1))
        .map(|k| [poly[0], poly[k], poly[k + 1]])
        .collect()
}

/// Rasterise every mesh of a prepared scene into a `w x h` G-buffer (row 0 at the top).
pub fn rasterise(p: &Prepared, w: u32, h: u32) -> Vec<Fragment> {
    rasterise_rows(p, w, h, 0..h)
}

/// Rows `rows` of [`rasterise`]'s G-buffer (the same fragments; a band keeps the
/// memory of a heavily supersampled frame bounded).
pub fn rasterise_rows(p: &Prepared, w: u32, h: u32, rows: std::ops::Range<u32>) -> Vec<Fragment> {
    rasterise_rows_at(p, w, h, rows, Positions::Centres)
}

/// Where in its pixel each G-buffer sample sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Positions {
    /// The pixel centre (the GPU's convention).
    Centres,
    /// A uniform point of the pixel from this seed and the pixel's position
    /// (quantised to the [`SUBPIXEL_BITS`] grid): over a supersampled frame,
    /// stratified jitter (one point per stratum), unbiased for any coverage.
    Jittered(u64),
}

impl Positions {
    /// Offset of sample `(i, j)` in its pixel, in 1/[`ONE`] pixel units.
    fn offset(self, i: i64, j: i64) -> [i64; 2] {
        match self {
            Positions::Centres => [ONE / 2, ONE / 2],
            Positions::Jittered(seed) => {
                let mut g = SplitMix64::new(
                    seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                        ^ (j as u64).wrapping_mul(0xD1B5_4A32_D192_ED03),
                );
                let v = g.next_u64();
                [
                    (v & (ONE as u64 - 1)) as i64,
                    ((v >> 32) & (ONE as u64 - 1)) as i64,
                ]
            }
        }
    }
}

/// [`rasterise_rows`] with the samples at `at` in their pixels.
pub fn rasterise_rows_at(
    p: &Prepared,
    w: u32,
    h: u32,
    rows: std::ops::Range<u32>,
    at: Positions,
) -> Vec<Fragment> {
    rasterise_rows_where(p, w, h, rows, at, None)
}

/// Which samples [`rasterise_rows_where`] rasterises: `keep(i, j)` for the
/// sample in column `i`, row `j` of the `w x h` G-buffer.
pub type Keep<'a> = &'a (dyn Fn(i64, i64) -> bool + Sync);

/// [`rasterise_rows_at`] at the samples `keep` admits only (all with
/// `None`); the others stay empty (`mesh` None, depth 1, no position):
/// the converged reference's later rounds, which shade a few pixels of a
/// finely sampled frame.
pub fn rasterise_rows_where(
    p: &Prepared,
    w: u32,
    h: u32,
    rows: std::ops::Range<u32>,
    at: Positions,
    keep: Option<Keep>,
) -> Vec<Fragment> {
    let vp = p.scene.camera.view_proj(w, h);
    let mut buf = vec![
        Fragment {
            depth: f64::INFINITY,
            ..Default::default()
        };
        (w as usize) * (rows.len())
    ];
    for (mi, (mesh, mat)) in p.meshes.iter().enumerate() {
        let scales = mat.scales.as_deref();
        let clip: Vec<[f64; 4]> = mesh
            .positions
            .iter()
            .map(|q| transform(&vp, [q[0] as f64, q[1] as f64, q[2] as f64, 1.0]))
            .collect();
        for tri in mesh.indices.chunks_exact(3) {
            let idx = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
            let cv = [0, 1, 2].map(|k| {
                let mut bary = [0.0; 3];
                bary[k] = 1.0;
                ClipVert {
                    c: clip[idx[k]],
                    bary,
                }
            });
            for t in clip_near(cv) {
                raster_triangle(
                    &mut buf,
                    w,
                    h,
                    &rows,
                    (at, keep),
                    (mi as u32, mesh, scales),
                    idx,
                    &t,
                );
            }
        }
    }
    let eye = p.scene.camera.eye;
    for (k, f) in buf.iter_mut().enumerate() {
        if f.mesh.is_none() {
            f.depth = 1.0;
            let (i, j) = (
                (k % w as usize) as i64,
                (k / w as usize) as i64 + rows.start as i64,
            );
            if keep.is_some_and(|keep| !keep(i, j)) {
                continue;
            }
            let o = at.offset(i, j);
            let (x, y) = (
                (i * ONE + o[0]) as f64 / ONE as f64,
                (j * ONE + o[1]) as f64 / ONE as f64,
            );
            let d = p.scene.camera.ray(w, h, x, y);
            f.pos = std::array::from_fn(|c| eye[c] + d[c]);
        }
    }
    buf
}

#[allow(clippy::too_many_arguments)]
fn raster_triangle(
    buf: &mut [Fragment],
    w: u32,
    h: u32,
    rows: &std::ops::Range<u32>,
    (at, keep): (Positions, Option<Keep>),
    (mi, mesh, scales): (u32, &crate::Mesh, Option<&sunbeam_frame::MeshScales>),
    idx: [usize; 3],
    t: &[ClipVert; 3],
) {
    if t.iter().any(|v| {
        v.c[3].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
            || v.c.iter().any(|x| !x.is_finite())
    }) {
        return;
    }
    // Screen position (y down), snapped to 1/256 pixel.
    let scr: [[i64; 2]; 3] = t.map(|v| {
        let x = (v.c[0] / v.c[3] * 0.5 + 0.5) * w as f64;
        let y = (0.5 - v.c[1] / v.c[3] * 0.5) * h as f64;
        [
            (x * ONE as f64).round() as i64,
            (y * ONE as f64).round() as i64,
        ]
    });
    let zs: [f64; 3] = t.map(|v| v.c[2] / v.c[3]);
    let inv_w: [f64; 3] = t.map(|v| 1.0 / v.c[3]);
    // Signed area in y-down coordinates: front faces (counter-clockwise in NDC) are negative.
    let area = |a: [i64; 2], b: [i64; 2], c: [i64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
    };
    let a = area(scr[0], scr[1], scr[2]);
    if a >= 0 {
        return; // back face or degenerate: culled
    }
    // Reorder so that the area is positive: v0, v2, v1.
    let order = [0usize, 2, 1];
    let s = order.map(|k| scr[k]);
    let area2 = -a;
    let edge = |p: [i64; 2], q: [i64; 2], x: i64, y: i64| {
        (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0])
    };
    // Top-left rule: an edge p->q owns its own pixels when it is a top edge
    // (horizontal, interior below) or a left edge (interior to the right).
    let owns = |p: [i64; 2], q: [i64; 2]| {
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        (dy == 0 && dx > 0) || dy < 0
    };
    let edges = [(s[1], s[2]), (s[2], s[0]), (s[0], s[1])];
    let bias: [i64; 3] = edges.map(|(p, q)| if owns(p, q) { 0 } else { -1 });
    let minx = s.iter().map(|v| v[0]).min().unwrap_or(0);
    let maxx = s.iter().map(|v| v[0]).max().unwrap_or(0);
    let miny = s.iter().map(|v| v[1]).min().unwrap_or(0);
    let maxy = s.iter().map(|v| v[1]).max().unwrap_or(0);
    // Pixel i's sample is at x = i*ONE + offset, offset in [0, ONE) (ONE/2:
    // the centre), so the pixels whose samples can fall in [minx, maxx] are
    // those the range meets.
    let i0 = minx.div_euclid(ONE).max(0);
    let i1 = maxx.div_euclid(ONE).min(w as i64 - 1);
    let j0 = miny.div_euclid(ONE).max(rows.start as i64);
    let j1 = maxy
        .div_euclid(ONE)
        .min(h as i64 - 1)
        .min(rows.end as i64 - 1);
    for j in j0..=j1 {
        for i in i0..=i1 {
            if keep.is_some_and(|keep| !keep(i, j)) {
                continue;
            }
            let o = at.offset(i, j);
            let (px, py) = (i * ONE + o[0], j * ONE + o[1]);
            let e = [0, 1, 2].map(|k| edge(edges[k].0, edges[k].1, px, py));
            if (0..3).any(|k| e[k] + bias[k] < 0) {
                continue;
            }
            // Screen-space barycentrics of s[0], s[1], s[2] -> original order t[0], t[2], t[1].
            let l_s = [
                e[0] as f64 / area2 as f64,
                e[1] as f64 / area2 as f64,
                e[2] as f64 / area2 as f64,
            ];
            let mut l = [0.0; 3];
            for k in 0..3 {
                l[order[k]] = l_s[k];
            }
            let z = l[0] * zs[0] + l[1] * zs[1] + l[2] * zs[2];
            if !(0.0..=1.0).contains(&z) {
                continue;
            }
            let pix = &mut buf[(j as usize - rows.start as usize) * w as usize + i as usize];
            if z.partial_cmp(&pix.depth) != Some(std::cmp::Ordering::Less) {
                continue;
            }
            // Perspective-correct weights on the clipped vertices, then on the original ones.
            let pw = [l[0] * inv_w[0], l[1] * inv_w[1], l[2] * inv_w[2]];
            let sum = pw[0] + pw[1] + pw[2];
            let mut bo = [0.0; 3];
            for (k, tk) in t.iter().enumerate() {
                for (o, b) in bo.iter_mut().enumerate() {
                    *b += pw[k] / sum * tk.bary[o];
                }
            }
            let attr = |v: &Vec<[f32; 3]>| -> [f64; 3] {
                [0, 1, 2].map(|c| (0..3).map(|o| bo[o] * v[idx[o]][c] as f64).sum())
            };
            let tang: [f64; 3] = [0, 1, 2].map(|c| {
                (0..3)
                    .map(|o| bo[o] * mesh.tangents[idx[o]][c] as f64)
                    .sum()
            });
            let mut normal = attr(&mesh.normals);
            let mut tangent = tang;
            // Scale maps: the normal map and the ridge direction at the texel.
            if let Some(sc) = scales {
                let uv = [0, 1].map(|c| (0..3).map(|o| bo[o] * mesh.uvs[idx[o]][c] as f64).sum());
                let t4: [f64; 4] = [0, 1, 2, 3]
                    .map(|c| (0..3).map(|o| bo[o] * sc.tangents[idx[o]][c] as f64).sum());
                if let Some((n2, t2)) = sc.perturb(normal, t4, uv) {
                    (normal, tangent) = (n2, t2);
                }
            }
            *pix = Fragment {
                mesh: Some(mi),
                pos: attr(&mesh.positions),
                normal,
                tangent,
                depth: z,
            };
        }
    }
}
