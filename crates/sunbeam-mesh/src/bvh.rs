//! A bounding-volume hierarchy over triangles for closest-point queries
//! (snapping scattered 3D samples onto the surface).

use crate::geom::{add, dot, scale, sub, V3};

#[derive(Debug, Clone)]
struct Node {
    lo: V3,
    hi: V3,
    /// Leaf: `start..start+count` in `order`; inner: children at `left`, `left+1`... stored explicitly.
    start: u32,
    count: u32,
    left: u32,
    right: u32,
}

/// Closest-point structure over a triangle soup.
#[derive(Debug, Clone)]
pub struct Bvh {
    tris: Vec<[V3; 3]>,
    order: Vec<u32>,
    nodes: Vec<Node>,
}

/// The closest point found.
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    pub tri: usize,
    pub point: V3,
    /// Barycentric coordinates of `point` in triangle `tri`.
    pub bary: [f64; 3],
    pub dist2: f64,
}

impl Bvh {
    pub fn new(tris: Vec<[V3; 3]>) -> Bvh {
        let mut b = Bvh {
            order: (0..tris.len() as u32).collect(),
            tris,
            nodes: Vec::new(),
        };
        if !b.tris.is_empty() {
            let cent: Vec<V3> = b
                .tris
                .iter()
                .map(|t| scale(add(add(t[0], t[1]), t[2]), 1.0 / 3.0))
                .collect();
            b.build(0, b.tris.len(), &cent);
        }
        b
    }

    fn bounds(&self, s: usize, e: usize) -> (V3, V3) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &i in &self.order[s..e] {
            for p in &self.tris[i as usize] {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        (lo, hi)
    }

    fn build(&mut self, s: usize, e: usize, cent: &[V3]) -> u32 {
        let (lo, hi) = self.bounds(s, e);
        let id = self.nodes.len() as u32;
        self.nodes.push(Node {
            lo,
            hi,
            start: s as u32,
            count: (e - s) as u32,
            left: 0,
            right: 0,
        });
        if e - s <= 4 {
            return id;
        }
        let ext = sub(hi, lo);
        let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
            0
        } else if ext[1] >= ext[2] {
            1
        } else {
            2
        };
        let mid = (s + e) / 2;
        self.order[s..e].select_nth_unstable_by(mid - s, |a, b| {
            cent[*a as usize][axis].total_cmp(&cent[*b as usize][axis])
        });
        let l = self.build(s, mid, cent);
        let r = self.build(mid, e, cent);
        let n = &mut self.nodes[id as usize];
        n.count = 0;
        n.left = l;
        n.right = r;
        id
    }

    fn box_dist2(n: &Node, p: V3) -> f64 {
        let mut d = 0.0;
        for k in 0..3 {
            let v = (n.lo[k] - p[k]).max(0.0).max(p[k] - n.hi[k]);
            d += v * v;
        }
        d
    }

    /// The closest point of all triangles to `p` (None for an empty BVH or a non-finite `p`).
    pub fn closest(&self, p: V3) -> Option<Hit> {
        if self.nodes.is_empty() || p.iter().any(|x| !x.is_finite()) {
            return None;
        }
        let mut best: Option<Hit> = None;
        let mut stack = vec![0u32];
        while let Some(ni) = stack.pop() {
            let n = &self.nodes[ni as usize];
            let bd = Self::box_dist2(n, p);
            if best.is_some_and(|b| bd > b.dist2) {
                continue;
            }
            if n.count > 0 {
                for &ti in &self.order[n.start as usize..(n.start + n.count) as usize] {
                    let (q, bary) = closest_on_triangle(p, &self.tris[ti as usize]);
                    let d = sub(q, p);
                    let d2 = dot(d, d);
                    if best.is_none_or(|b| d2 < b.dist2 || (d2 == b.dist2 && (ti as usize) < b.tri))
                    {
                        best = Some(Hit {
                            tri: ti as usize,
                            point: q,
                            bary,
                            dist2: d2,
                        });
                    }
                }
            } else {
                let (l, r) = (n.left, n.right);
                let (dl, dr) = (
                    Self::box_dist2(&self.nodes[l as usize], p),
                    Self::box_dist2(&self.nodes[r as usize], p),
                );
                if dl < dr {
                    stack.push(r);
                    stack.push(l);
                } else {
                    stack.push(l);
                    stack.push(r);
                }
            }
        }
        best
    }
}

/// Closest point on triangle (Ericson, Real-Time Collision Detection 5.1.5), with barycentrics.
pub fn closest_on_triangle(p: V3, t: &[V3; 3]) -> (V3, [f64; 3]) {
    let (a, b, c) = (t[0], t[1], t[2]);
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (add(a, scale(ab, v)), [1.0 - v, v, 0.0]);
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (add(a, scale(ac, w)), [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (add(b, scale(sub(c, b), w)), [0.0, 1.0 - w, w]);
    }
    let denom = va + vb + vc;
    if denom.abs() < 1e-300 || !denom.is_finite() {
        // Degenerate (zero-area) triangle that slipped through: nearest vertex.
        let ds = [dot(ap, ap), dot(bp, bp), dot(cp, cp)];
        let k = (0..3).min_by(|&i, &j| ds[i].total_cmp(&ds[j])).unwrap_or(0);
        let mut bc = [0.0; 3];
        bc[k] = 1.0;
        return (t[k], bc);
    }
    let v = vb / denom;
    let w = vc / denom;
    (add(a, add(scale(ab, v), scale(ac, w))), [1.0 - v - w, v, w])
}
