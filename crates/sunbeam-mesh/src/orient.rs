//! Orientation sources (axis, spine curve, scattered samples, UV direction)
//! and the axial interpolation of scattered samples in UV space.
//!
//! Ridge directions are *axial*: `d` and `-d` are the same direction. Samples
//! are therefore interpolated as the doubled-angle vector `(cos 2a, sin 2a)`
//! (equivalently the 2D structure tensor `d d^T` minus its trace part), never
//! as raw vectors that would cancel, and the result is halved back.

use crate::geom::{normalize, sub, V3};
use serde_json::Value;
use spade::{
    Barycentric, DelaunayTriangulation, FloatTriangulation, HasPosition, NaturalNeighbor, Point2,
    Triangulation,
};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};

/// Which direction of the UV parameterisation `--uv-direction` follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UvAxis {
    U,
    V,
}

/// Interpolation of scattered samples in UV space.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interp {
    /// Sibson natural-neighbour interpolation (spade), the default: C1 away from
    /// the samples, exact at them.
    #[default]
    Natural,
    /// Sibson's C1 natural-neighbour interpolant (Sibson 1981, as in spade's
    /// `interpolate_gradient`, flatness 1), with per-sample gradients from a
    /// weighted least-squares plane fit over the Delaunay neighbours: smooth
    /// through the samples, more accurate on smooth fields.
    SibsonC1,
    /// Piecewise-linear (barycentric) on the Delaunay triangulation: what
    /// scipy's `LinearNDInterpolator` / `griddata(method="linear")` computes.
    Linear,
}

/// Where the orientation comes from.
#[derive(Debug, Clone)]
pub enum Source {
    /// A world direction projected onto each tangent plane.
    Axis(V3),
    /// The tangent of a spine polyline at the nearest point, projected.
    Curve(Curve),
    /// Scattered samples, interpolated in UV space.
    Samples(Samples),
    /// The direction of increasing u or v.
    UvDirection(UvAxis),
}

impl Source {
    pub fn describe(&self) -> String {
        match self {
            Source::Axis(a) => format!("axis {},{},{}", a[0], a[1], a[2]),
            Source::Curve(c) => format!("curve {} ({} points)", c.path.display(), c.points.len()),
            Source::Samples(s) => format!("samples {} ({} rows)", s.path.display(), s.items.len()),
            Source::UvDirection(UvAxis::U) => "uv-direction u".into(),
            Source::UvDirection(UvAxis::V) => "uv-direction v".into(),
        }
    }
}

/// Parse `X,Y,Z` (a non-zero finite vector).
pub fn parse_axis(s: &str) -> Result<V3> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| {
            t.trim()
                .parse::<f64>()
                .map_err(|_| Error::usage(format!("--axis {s:?}: {t:?} is not a number")))
        })
        .collect::<Result<_>>()?;
    if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
        return Err(Error::usage(format!(
            "--axis {s:?}: need three finite numbers X,Y,Z"
        )));
    }
    normalize([v[0], v[1], v[2]])
        .ok_or_else(|| Error::usage(format!("--axis {s:?} is the zero vector")))
}

// ---------------------------------------------------------------- curve

/// A spine polyline.
#[derive(Debug, Clone)]
pub struct Curve {
    pub path: PathBuf,
    pub points: Vec<V3>,
    /// Unit tangent at each point (average of the adjacent segments).
    tangents: Vec<V3>,
    /// Segments as degenerate triangles `[a, b, b]` for nearest-point queries.
    bvh: crate::bvh::Bvh,
}

impl Curve {
    /// Read `{"points": [[x,y,z], ...]}` or a bare `[[x,y,z], ...]`.
    pub fn load(path: &Path) -> Result<Curve> {
        let bytes = std::fs::read(path)
            .map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
        let v: Value = serde_json::from_slice(&bytes)
            .map_err(|e| Error::input_file(path, format!("not valid JSON: {e}")))?;
        let arr = v.get("points").unwrap_or(&v).as_array().ok_or_else(|| {
            Error::input_file(
                path,
                "expected {\"points\": [[x,y,z], ...]} or [[x,y,z], ...]",
            )
        })?;
        let mut pts = Vec::with_capacity(arr.len());
        for (i, p) in arr.iter().enumerate() {
            let c: Vec<f64> = p
                .as_array()
                .map(|a| a.iter().filter_map(Value::as_f64).collect())
                .unwrap_or_default();
            if c.len() != 3 || c.iter().any(|x| !x.is_finite()) {
                return Err(Error::input_file(
                    path,
                    format!("points[{i}] is not three finite numbers"),
                ));
            }
            pts.push([c[0], c[1], c[2]]);
        }
        Curve::from_points(path, pts)
    }

    /// Build from points; consecutive duplicates are dropped; needs two distinct points.
    pub fn from_points(path: &Path, pts: Vec<V3>) -> Result<Curve> {
        let mut points: Vec<V3> = Vec::with_capacity(pts.len());
        for p in pts {
            if points.last().is_none_or(|q| *q != p) {
                points.push(p);
            }
        }
        if points.len() < 2 {
            return Err(Error::input_file(
                path,
                "a curve needs at least two distinct points",
            ));
        }
        let seg: Vec<V3> = points
            .windows(2)
            .map(|w| normalize(sub(w[1], w[0])).unwrap_or([1.0, 0.0, 0.0]))
            .collect();
        let n = points.len();
        let tangents = (0..n)
            .map(|i| {
                let a = if i > 0 { seg[i - 1] } else { seg[0] };
                let b = if i < n - 1 { seg[i] } else { seg[n - 2] };
                // A hairpin (a = -b) has no average: keep the incoming segment.
                normalize(crate::geom::add(a, b)).unwrap_or(a)
            })
            .collect();
        let bvh = crate::bvh::Bvh::new(points.windows(2).map(|w| [w[0], w[1], w[1]]).collect());
        Ok(Curve {
            path: path.to_path_buf(),
            points,
            tangents,
            bvh,
        })
    }

    /// Tangent at the nearest point of the polyline to `p`, blended linearly
    /// between the point tangents so the field is continuous along the spine.
    pub fn tangent_at(&self, p: V3) -> V3 {
        let (i, s) = match self.bvh.closest(p) {
            // Barycentrics of [a, b, b]: the parameter along the segment is b1 + b2.
            Some(h) => (h.tri, (h.bary[1] + h.bary[2]).clamp(0.0, 1.0)),
            None => (0, 0.0),
        };
        let t = crate::geom::add(
            crate::geom::scale(self.tangents[i], 1.0 - s),
            crate::geom::scale(self.tangents[i + 1], s),
        );
        normalize(t).unwrap_or(self.tangents[i])
    }

    /// The same by brute force over all segments (a check for the BVH path).
    pub fn tangent_at_brute_force(&self, p: V3) -> V3 {
        let mut best = (f64::INFINITY, 0usize, 0.0f64);
        for i in 0..self.points.len() - 1 {
            let (a, b) = (self.points[i], self.points[i + 1]);
            let ab = sub(b, a);
            let l2 = crate::geom::dot(ab, ab);
            let s = if l2 > 0.0 {
                (crate::geom::dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let q = crate::geom::add(a, crate::geom::scale(ab, s));
            let d = sub(p, q);
            let d2 = crate::geom::dot(d, d);
            if d2 < best.0 {
                best = (d2, i, s);
            }
        }
        let (_, i, s) = best;
        let t = crate::geom::add(
            crate::geom::scale(self.tangents[i], 1.0 - s),
            crate::geom::scale(self.tangents[i + 1], s),
        );
        normalize(t).unwrap_or(self.tangents[i])
    }
}

// ---------------------------------------------------------------- samples

/// Where a sample is and which way it points.
#[derive(Debug, Clone, Copy)]
pub enum SampleAt {
    /// 3D position (snapped to the surface) and 3D direction (projected).
    Xyz { p: V3, d: V3 },
    /// UV position and angle (radians) from +u, counter-clockwise about the normal.
    Uv { uv: [f64; 2], angle: f64 },
}

#[derive(Debug, Clone, Copy)]
pub struct Sample {
    /// 1-based line (CSV) or array index (JSON), for messages.
    pub line: usize,
    pub at: SampleAt,
}

#[derive(Debug, Clone)]
pub struct Samples {
    pub path: PathBuf,
    pub items: Vec<Sample>,
}

const XYZ: [&str; 6] = ["x", "y", "z", "dx", "dy", "dz"];
const UVA: [&str; 3] = ["u", "v", "angle_deg"];

impl Samples {
    /// Read CSV (header `x,y,z,dx,dy,dz` or `u,v,angle_deg`, any column order,
    /// extra columns ignored) or JSON (`[{...}]` or `{"samples": [{...}]}` with
    /// the same field names). NaN or infinite numbers are an error naming the row.
    pub fn load(path: &Path) -> Result<Samples> {
        let bytes = std::fs::read(path)
            .map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
        let text = String::from_utf8_lossy(&bytes);
        let t = text.trim_start_matches('\u{feff}').trim_start();
        let items = if t.starts_with('[') || t.starts_with('{') {
            Self::parse_json(path, t)?
        } else {
            Self::parse_csv(path, t)?
        };
        if items.is_empty() {
            return Err(Error::input_file(path, "no samples"));
        }
        Ok(Samples {
            path: path.to_path_buf(),
            items,
        })
    }

    fn make(
        path: &Path,
        line: usize,
        get: &dyn Fn(&str) -> Option<f64>,
        xyz: bool,
    ) -> Result<Sample> {
        let names: &[&str] = if xyz { &XYZ } else { &UVA };
        let mut v = [0.0; 6];
        for (i, n) in names.iter().enumerate() {
            let x = get(n).ok_or_else(|| {
                Error::input_file(
                    path,
                    format!("row {line}: field {n} missing or not a number"),
                )
            })?;
            if !x.is_finite() {
                return Err(Error::input_file(
                    path,
                    format!("row {line}: {n} is {x} (NaN or infinite)"),
                ));
            }
            v[i] = x;
        }
        Ok(Sample {
            line,
            at: if xyz {
                SampleAt::Xyz {
                    p: [v[0], v[1], v[2]],
                    d: [v[3], v[4], v[5]],
                }
            } else {
                SampleAt::Uv {
                    uv: [v[0], v[1]],
                    angle: v[2].to_radians(),
                }
            },
        })
    }

    fn parse_csv(path: &Path, t: &str) -> Result<Vec<Sample>> {
        let mut lines = t
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let (_, header) = lines
            .next()
            .ok_or_else(|| Error::input_file(path, "empty CSV"))?;
        let cols: Vec<String> = header
            .split(',')
            .map(|c| c.trim().trim_matches('"').to_ascii_lowercase())
            .collect();
        let has = |n: &str| cols.iter().any(|c| c == n);
        let xyz = XYZ.iter().all(|n| has(n));
        if !xyz && !UVA.iter().all(|n| has(n)) {
            return Err(Error::input_file(
                path,
                format!("CSV header {header:?} must name x,y,z,dx,dy,dz or u,v,angle_deg"),
            ));
        }
        let mut out = Vec::new();
        for (i, l) in lines {
            let f: Vec<&str> = l.split(',').map(str::trim).collect();
            let get = |n: &str| -> Option<f64> {
                let k = cols.iter().position(|c| c == n)?;
                let s = f.get(k)?.trim_matches('"');
                match s.to_ascii_lowercase().as_str() {
                    "nan" => Some(f64::NAN),
                    _ => s.parse::<f64>().ok(),
                }
            };
            out.push(Self::make(path, i + 1, &get, xyz)?);
        }
        Ok(out)
    }

    fn parse_json(path: &Path, t: &str) -> Result<Vec<Sample>> {
        let v: Value = serde_json::from_str(t)
            .map_err(|e| Error::input_file(path, format!("not valid JSON: {e}")))?;
        let arr =
            v.get("samples").unwrap_or(&v).as_array().ok_or_else(|| {
                Error::input_file(path, "expected [{...}] or {\"samples\": [{...}]}")
            })?;
        let mut out = Vec::new();
        for (i, s) in arr.iter().enumerate() {
            let xyz = s.get("x").is_some();
            let get = |n: &str| -> Option<f64> {
                match s.get(n)? {
                    Value::Null => Some(f64::NAN),
                    Value::String(x) if x.eq_ignore_ascii_case("nan") => Some(f64::NAN),
                    x => x.as_f64(),
                }
            };
            out.push(Self::make(path, i, &get, xyz)?);
        }
        Ok(out)
    }
}

// ---------------------------------------------------------------- axial interpolation

/// The triangulation, with spade's default last-used-vertex hint: queries come
/// in mesh vertex order, which is spatially coherent, so walks are short.
/// (`HierarchyHintGenerator` was not faster in the benchmark.)
type Tri = DelaunayTriangulation<Node>;

#[derive(Debug, Clone, Copy)]
struct Node {
    p: Point2<f64>,
    /// Doubled-angle unit vector (cos 2a, sin 2a).
    c: f64,
    s: f64,
}

impl HasPosition for Node {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.p
    }
}

/// What an evaluation gave.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxialValue {
    /// Angle (radians, in (-pi/2, pi/2]); `extrapolated` when outside the samples' hull.
    Angle { angle: f64, extrapolated: bool },
    /// The weighted doubled-angle vectors cancel (e.g. perpendicular samples in equal weight).
    Cancelled,
}

enum Layout {
    /// One sample (or all at one point): a constant.
    Constant(f64, f64),
    /// All samples on a line: piecewise linear along it, clamped at the ends.
    Line {
        origin: [f64; 2],
        dir: [f64; 2],
        pts: Vec<(f64, f64, f64)>,
    },
    Tri(Tri),
}

/// An axial direction field over the plane from scattered samples.
pub struct AxialField {
    layout: Layout,
    interp: Interp,
    /// Samples merged because they sat at the same position.
    pub merged_duplicates: usize,
    /// Samples dropped: duplicates whose directions cancelled, or rejected coordinates.
    pub dropped: Vec<(usize, String)>,
    /// Samples in the field.
    pub used: usize,
    /// Nearest-sample lookup for points outside the hull: the samples as
    /// zero-size triangles at z = 0, with their doubled-angle vectors.
    near: Option<(crate::bvh::Bvh, Vec<(f64, f64)>)>,
    /// The samples' convex hull (counter-clockwise) and a tolerance: points
    /// clearly outside skip spade's point location, which walks far outside
    /// thin hulls.
    hull: Option<(Vec<[f64; 2]>, f64)>,
    /// For [`Interp::SibsonC1`]: gradients of (c, s) per vertex index: [dc/du, dc/dv, ds/du, ds/dv].
    grads: Vec<[f64; 4]>,
}

impl AxialField {
    /// `samples`: (tag for messages, position, angle in radians). Returns None when no sample is usable.
    pub fn new(samples: &[(usize, [f64; 2], f64)], interp: Interp) -> Option<AxialField> {
        // Merge exact duplicates (spade would keep only one of them).
        let mut map: HashMap<[u64; 2], usize> = HashMap::new();
        let mut merged: Vec<(usize, [f64; 2], f64, f64)> = Vec::new();
        let mut merged_duplicates = 0;
        let mut dropped = Vec::new();
        for &(tag, p, a) in samples {
            if spade::validate_coordinate(p[0]).is_err()
                || spade::validate_coordinate(p[1]).is_err()
                || !a.is_finite()
            {
                dropped.push((
                    tag,
                    "coordinate out of the range spade accepts (or not finite)".to_string(),
                ));
                continue;
            }
            let k = [(p[0] + 0.0).to_bits(), (p[1] + 0.0).to_bits()];
            let (c, s) = ((2.0 * a).cos(), (2.0 * a).sin());
            match map.get(&k) {
                Some(&i) => {
                    merged[i].2 += c;
                    merged[i].3 += s;
                    merged_duplicates += 1;
                }
                None => {
                    map.insert(k, merged.len());
                    merged.push((tag, p, c, s));
                }
            }
        }
        let mut nodes = Vec::with_capacity(merged.len());
        for (tag, p, c, s) in merged {
            let r = c.hypot(s);
            if r < 1e-9 {
                dropped.push((
                    tag,
                    "duplicates at one position whose directions cancel (e.g. perpendicular)"
                        .to_string(),
                ));
                continue;
            }
            nodes.push(Node {
                p: Point2::new(p[0], p[1]),
                c: c / r,
                s: s / r,
            });
        }
        let used = nodes.len();
        let mut near = None;
        let mut hull = None;
        let mut grads = Vec::new();
        let layout = match nodes.len() {
            0 => return None,
            1 => Layout::Constant(nodes[0].c, nodes[0].s),
            _ => {
                let tri = Tri::bulk_load_stable(nodes.clone()).ok();
                match tri {
                    Some(t) if !t.all_vertices_on_line() && t.num_inner_faces() > 0 => {
                        let pts = nodes.iter().map(|n| [[n.p.x, n.p.y, 0.0]; 3]).collect();
                        let vals = nodes.iter().map(|n| (n.c, n.s)).collect();
                        near = Some((crate::bvh::Bvh::new(pts), vals));
                        let mut h: Vec<[f64; 2]> = t
                            .convex_hull()
                            .map(|e| {
                                let p = e.from().position();
                                [p.x, p.y]
                            })
                            .collect();
                        h.reverse();
                        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
                        for q in &h {
                            for k in 0..2 {
                                lo[k] = lo[k].min(q[k]);
                                hi[k] = hi[k].max(q[k]);
                            }
                        }
                        let diag2 = (hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2);
                        if h.len() >= 3 && diag2 > 0.0 {
                            hull = Some((h, 1e-9 * diag2));
                        }
                        if interp == Interp::SibsonC1 {
                            grads = gradients(&t);
                        }
                        Layout::Tri(t)
                    }
                    _ => {
                        let o = [nodes[0].p.x, nodes[0].p.y];
                        let far = nodes
                            .iter()
                            .map(|n| [n.p.x - o[0], n.p.y - o[1]])
                            .max_by(|a, b| a[0].hypot(a[1]).total_cmp(&b[0].hypot(b[1])))
                            .unwrap_or([1.0, 0.0]);
                        let l = far[0].hypot(far[1]);
                        let dir = if l > 0.0 {
                            [far[0] / l, far[1] / l]
                        } else {
                            [1.0, 0.0]
                        };
                        let mut pts: Vec<(f64, f64, f64)> = nodes
                            .iter()
                            .map(|n| ((n.p.x - o[0]) * dir[0] + (n.p.y - o[1]) * dir[1], n.c, n.s))
                            .collect();
                        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                        Layout::Line {
                            origin: o,
                            dir,
                            pts,
                        }
                    }
                }
            }
        };
        Some(AxialField {
            layout,
            interp,
            merged_duplicates,
            dropped,
            used,
            near,
            hull,
            grads,
        })
    }

    /// A reusable evaluator (holds spade's scratch buffers; one per thread).
    pub fn evaluator(&self) -> Evaluator<'_> {
        let (nn, bc) = match (&self.layout, self.interp) {
            (Layout::Tri(t), Interp::Natural | Interp::SibsonC1) => {
                (Some(t.natural_neighbor()), None)
            }
            (Layout::Tri(t), Interp::Linear) => (None, Some(t.barycentric())),
            _ => (None, None),
        };
        Evaluator {
            f: self,
            w: Vec::new(),
            nn,
            bc,
        }
    }

    /// Whether the samples lie on one line (or one point).
    pub fn degenerate_layout(&self) -> Option<&'static str> {
        match self.layout {
            Layout::Constant(..) => Some("a single sample position: constant field"),
            Layout::Line { .. } => {
                Some("collinear samples: linear along the line, constant across it")
            }
            Layout::Tri(_) => None,
        }
    }
}

/// Whether `p` lies outside the convex counter-clockwise polygon `h` by more
/// than `eps` (a cross product, length^2). Points near the boundary say false.
fn clearly_outside(h: &[[f64; 2]], p: [f64; 2], eps: f64) -> bool {
    let cr =
        |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    let n = h.len();
    if cr(h[0], h[1]) < -eps || cr(h[0], h[n - 1]) > eps {
        return true;
    }
    let (mut lo, mut hi) = (1, n - 1);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if cr(h[0], h[mid]) >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    cr(h[lo], h[lo + 1]) < -eps
}

pub struct Evaluator<'a> {
    f: &'a AxialField,
    w: Vec<(spade::handles::FixedVertexHandle, f64)>,
    nn: Option<NaturalNeighbor<'a, Tri>>,
    bc: Option<Barycentric<'a, Tri>>,
}

fn finish(c: f64, s: f64, extrapolated: bool) -> AxialValue {
    if c.hypot(s) < 1e-12 {
        AxialValue::Cancelled
    } else {
        AxialValue::Angle {
            angle: 0.5 * s.atan2(c),
            extrapolated,
        }
    }
}

/// Per-vertex gradients of the doubled-angle components: weighted least-squares
/// plane through each vertex and its Delaunay neighbours (weights 1/r^2).
fn gradients(t: &Tri) -> Vec<[f64; 4]> {
    t.vertices()
        .map(|v| {
            let p = v.position();
            let d0 = *v.data();
            let (mut a11, mut a12, mut a22) = (0.0, 0.0, 0.0);
            let (mut bc, mut bs) = ([0.0; 2], [0.0; 2]);
            for e in v.out_edges() {
                let q = e.to();
                let dq = *q.data();
                let (dx, dy) = (q.position().x - p.x, q.position().y - p.y);
                let r2 = dx * dx + dy * dy;
                if r2 <= 0.0 {
                    continue;
                }
                let w = 1.0 / r2;
                a11 += w * dx * dx;
                a12 += w * dx * dy;
                a22 += w * dy * dy;
                bc[0] += w * dx * (dq.c - d0.c);
                bc[1] += w * dy * (dq.c - d0.c);
                bs[0] += w * dx * (dq.s - d0.s);
                bs[1] += w * dy * (dq.s - d0.s);
            }
            let det = a11 * a22 - a12 * a12;
            if det.abs() <= 1e-12 * (a11 * a22).abs().max(1e-300) {
                return [0.0; 4];
            }
            let solve = |b: [f64; 2]| {
                [
                    (a22 * b[0] - a12 * b[1]) / det,
                    (a11 * b[1] - a12 * b[0]) / det,
                ]
            };
            let (gc, gs) = (solve(bc), solve(bs));
            [gc[0], gc[1], gs[0], gs[1]]
        })
        .collect()
}

impl Evaluator<'_> {
    /// Sibson's C1 blend on the natural-neighbour weights in `self.w` (non-empty).
    fn sibson(&self, t: &Tri, uv: [f64; 2]) -> AxialValue {
        let (mut c0, mut s0, mut c1, mut s1) = (0.0, 0.0, 0.0, 0.0);
        let (mut sum_w1, mut alpha, mut beta) = (0.0, 0.0, 0.0);
        for &(h, w) in &self.w {
            let v = t.vertex(h);
            let d = *v.data();
            let (dx, dy) = (uv[0] - v.position().x, uv[1] - v.position().y);
            let r2 = dx * dx + dy * dy;
            if r2 == 0.0 {
                return finish(d.c, d.s, false);
            }
            let g = self.f.grads.get(h.index()).copied().unwrap_or([0.0; 4]);
            let w1 = w / r2;
            alpha += w1 * r2;
            beta += w * r2;
            sum_w1 += w1;
            c1 += (d.c + dx * g[0] + dy * g[1]) * w1;
            s1 += (d.s + dx * g[2] + dy * g[3]) * w1;
            c0 += d.c * w;
            s0 += d.s * w;
        }
        if sum_w1 <= 0.0 || alpha + beta <= 0.0 {
            return finish(c0, s0, false);
        }
        alpha /= sum_w1;
        c1 /= sum_w1;
        s1 /= sum_w1;
        finish(
            (alpha * c0 + beta * c1) / (alpha + beta),
            (alpha * s0 + beta * s1) / (alpha + beta),
            false,
        )
    }

    pub fn eval(&mut self, uv: [f64; 2]) -> AxialValue {
        match &self.f.layout {
            Layout::Constant(c, s) => finish(*c, *s, false),
            Layout::Line { origin, dir, pts } => {
                let x = (uv[0] - origin[0]) * dir[0] + (uv[1] - origin[1]) * dir[1];
                let k = pts.partition_point(|p| p.0 <= x);
                if k == 0 {
                    finish(pts[0].1, pts[0].2, true)
                } else if k == pts.len() {
                    finish(pts[k - 1].1, pts[k - 1].2, x > pts[k - 1].0)
                } else {
                    let (a, b) = (pts[k - 1], pts[k]);
                    let t = if b.0 > a.0 {
                        (x - a.0) / (b.0 - a.0)
                    } else {
                        0.0
                    };
                    finish(a.1 + t * (b.1 - a.1), a.2 + t * (b.2 - a.2), false)
                }
            }
            Layout::Tri(t) => {
                let p = Point2::new(uv[0], uv[1]);
                if !(uv[0].is_finite() && uv[1].is_finite()) {
                    return AxialValue::Cancelled;
                }
                let outside = self
                    .f
                    .hull
                    .as_ref()
                    .is_some_and(|(h, eps)| clearly_outside(h, uv, *eps));
                if outside {
                    self.w.clear();
                } else if let Some(nn) = &self.nn {
                    nn.get_weights(p, &mut self.w);
                } else if let Some(bc) = &self.bc {
                    bc.get_weights(p, &mut self.w);
                }
                if self.w.is_empty() {
                    // Outside the convex hull: the nearest sample (a BVH: spade's
                    // nearest-neighbour walk is slow far outside thin layouts).
                    return match self
                        .f
                        .near
                        .as_ref()
                        .and_then(|(b, v)| Some(v[b.closest([uv[0], uv[1], 0.0])?.tri]))
                    {
                        Some((c, s)) => finish(c, s, true),
                        None => AxialValue::Cancelled,
                    };
                }
                if self.f.interp == Interp::SibsonC1 {
                    return self.sibson(t, uv);
                }
                let (mut c, mut s) = (0.0, 0.0);
                for &(h, w) in &self.w {
                    let d = *t.vertex(h).data();
                    c += w * d.c;
                    s += w * d.s;
                }
                finish(c, s, false)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_pretest_agrees_with_spade() {
        let s: Vec<(usize, [f64; 2], f64)> = (0..50)
            .map(|k| {
                let a = k as f64 * 0.7;
                (
                    k,
                    [
                        0.5 + 0.4 * (a * 1.3).cos() * (k as f64 / 50.0),
                        0.5 + 0.1 * (a * 0.9).sin(),
                    ],
                    a,
                )
            })
            .collect();
        let f = AxialField::new(&s, Interp::Linear).unwrap();
        let (h, eps) = f.hull.as_ref().unwrap();
        let Layout::Tri(t) = &f.layout else { panic!() };
        let mut out = 0;
        for i in 0..100 {
            for j in 0..100 {
                let p = [i as f64 / 99.0, j as f64 / 99.0];
                let spade_out = matches!(
                    t.locate(Point2::new(p[0], p[1])),
                    spade::PositionInTriangulation::OutsideOfConvexHull(_)
                );
                let ours = clearly_outside(h, p, *eps);
                assert!(!ours || spade_out, "{p:?}: we say outside, spade inside");
                out += ours as usize;
            }
        }
        assert!(out > 5000, "pre-test rejects too few: {out}");
    }
}
