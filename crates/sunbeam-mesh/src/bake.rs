//! The bake: per-vertex orientation field on every triangle primitive, written
//! back as `TANGENT` and `_ORIENTATION` into a GLB that keeps everything else.
//!
//! Frames: sources given in world space (axis, curve, 3D samples) are applied
//! to the mesh as placed by the first node that instantiates it (depth-first in
//! the default scene); the result is stored in the mesh's local space, so a
//! renderer that applies the node transform gets the world direction back. A
//! mesh placed by several nodes with different transforms is baked for the
//! first placement (a warning says so). Meshes no node uses are baked in their
//! own frame.
//!
//! Every vertex gets a unit direction orthogonal to its normal. Vertices the
//! source gives none (axis parallel to the normal, degenerate UVs, samples that
//! cancel...) take the axial average of their neighbours' directions along mesh
//! edges (breadth first); a connected part with no direction at all gets an
//! arbitrary perpendicular. The report counts both, by reason.

use crate::bvh::Bvh;
use crate::geom::{add, any_perpendicular, cross, dot, normalize, project, scale, Mat4, Xform, V3};
use crate::gltf::Document;
use crate::nodes::{self, Prim};
use crate::orient::{AxialField, AxialValue, Interp, SampleAt, Source, UvAxis};
use serde::Serialize;
use serde_json::json;
use std::collections::{BTreeMap, HashMap};
use sunbeam_common::{Error, Result};

/// Options of a bake.
#[derive(Debug, Clone)]
pub struct BakeOptions {
    pub source: Source,
    /// Extra rotation about the normal, degrees (counter-clockwise seen from outside).
    pub rotate_deg: f64,
    /// Which TEXCOORD_n the UV modes use.
    pub uv_set: usize,
    pub interp: Interp,
    /// 3D samples farther than this from the surface are rejected; None: 2% of
    /// the bounding-box diagonal.
    pub max_snap: Option<f64>,
    /// Write `TANGENT.xyz` as the UV frame (direction of increasing u, what
    /// normal maps need, `--scales`) instead of the orientation field;
    /// `_ORIENTATION` keeps the field either way.
    pub uv_tangents: bool,
}

impl BakeOptions {
    pub fn new(source: Source) -> Self {
        BakeOptions {
            source,
            rotate_deg: 0.0,
            uv_set: 0,
            interp: Interp::Natural,
            max_snap: None,
            uv_tangents: false,
        }
    }
}

#[derive(Debug, Clone, Serialize, Default)]
pub struct RejectedSample {
    pub row: usize,
    pub reason: String,
}

#[derive(Debug, Clone, Serialize, Default)]
pub struct SampleReport {
    pub rows: usize,
    pub used: usize,
    pub merged_duplicates: usize,
    pub rejected: Vec<RejectedSample>,
    pub interpolation: String,
    pub max_snap_distance: Option<f64>,
    /// Largest distance a used 3D sample was moved to reach the surface.
    pub max_snapped: Option<f64>,
    pub extrapolated_vertices: usize,
    /// Vertices on UV islands without any 3D sample: given the nearest sample's direction.
    pub nearest_sample_vertices: usize,
    pub layout_notes: Vec<String>,
}

/// The `--json` report of a bake.
#[derive(Debug, Clone, Serialize, Default)]
pub struct Report {
    pub input: String,
    pub output: Option<String>,
    pub vertices: usize,
    pub triangles: usize,
    pub primitives: usize,
    pub degenerate_triangles: usize,
    pub source: String,
    pub rotate_deg: f64,
    pub samples: Option<SampleReport>,
    /// Vertices whose direction did not come from the source, by reason.
    pub without_direction: BTreeMap<String, usize>,
    /// Of those: filled from neighbours along mesh edges.
    pub filled_from_neighbours: usize,
    /// Of those: no neighbour had one either, an arbitrary perpendicular was used.
    pub arbitrary: usize,
    /// Primitives whose NORMAL was computed (missing) or rewritten (not unit length).
    pub normals_written: usize,
    pub skipped_primitives: Vec<String>,
    pub warnings: Vec<String>,
    pub texture: Option<serde_json::Value>,
    /// `--scales`: the tiling and its textures (set by the caller that bakes them).
    pub scales: Option<serde_json::Value>,
}

/// Per-primitive working data, in world space.
pub struct Work {
    pub mesh: usize,
    pub prim: usize,
    pub xf: Xform,
    pub local: Prim,
    pub n_local: Vec<V3>,
    pub normals_rewrite: bool,
    pub p_world: Vec<V3>,
    pub n_world: Vec<V3>,
    /// Unit direction of increasing u (v) in the world tangent plane; None where the UVs are degenerate.
    pub u_world: Option<Vec<Option<V3>>>,
    pub v_world: Option<Vec<Option<V3>>>,
    pub dir: Vec<Option<V3>>,
    pub reason: Vec<Option<&'static str>>,
    /// Final local-space directions and tangent signs.
    pub t_local: Vec<V3>,
    pub w_sign: Vec<f64>,
}

impl Work {
    fn set(&mut self, i: usize, d: Option<V3>, why: &'static str) {
        match d.and_then(|d| normalize(project(d, self.n_world[i]))) {
            Some(t) => self.dir[i] = Some(t),
            None => {
                self.dir[i] = None;
                self.reason[i] = Some(why);
            }
        }
    }
}

/// The result of [`bake`]: the document (buffers merged, attributes added) and the report.
pub struct Baked {
    pub doc: Document,
    pub work: Vec<Work>,
    pub report: Report,
}

/// Gather the triangle primitives of `doc` with their world frames.
pub fn prepare(doc: &Document, uv_set: usize, report: &mut Report) -> Result<Vec<Work>> {
    let insts = nodes::instances(doc);
    let mut first: HashMap<usize, Mat4> = HashMap::new();
    let mut count: HashMap<usize, (usize, bool)> = HashMap::new();
    for i in &insts {
        let e = count.entry(i.mesh).or_insert((0, false));
        e.0 += 1;
        if let Some(m) = first.get(&i.mesh) {
            if *m != i.world {
                e.1 = true;
            }
        } else {
            first.insert(i.mesh, i.world);
        }
    }
    let meshes = doc.array("meshes").len();
    let mut out = Vec::new();
    for m in 0..meshes {
        let (n, differ) = count.get(&m).copied().unwrap_or((0, false));
        if differ {
            report.warnings.push(format!("meshes[{m}] is placed by {n} nodes with different transforms; world-space sources were applied to the first placement"));
        }
        let world = first.get(&m).copied().unwrap_or(Mat4::IDENTITY);
        let xf = match Xform::new(world) {
            Some(x) => x,
            None => {
                report.warnings.push(format!("meshes[{m}]: its node transform is singular (zero scale); baked in the mesh's own frame"));
                Xform::new(Mat4::IDENTITY).expect("identity is invertible")
            }
        };
        let nprim = doc.array("meshes")[m]
            .get("primitives")
            .and_then(|p| p.as_array())
            .map_or(0, |a| a.len());
        for k in 0..nprim {
            let Some(p) = nodes::read_primitive(doc, m, k, uv_set)? else {
                report.skipped_primitives.push(format!(
                    "meshes[{m}].primitives[{k}]: not triangles (points/lines), left as is"
                ));
                continue;
            };
            let normals_rewrite = match &p.normals {
                None => true,
                Some(n) => n.iter().any(|v| (crate::geom::norm(*v) - 1.0).abs() > 1e-4),
            };
            let n_local = crate::local_normals(&p);
            let nv = p.positions.len();
            let p_world: Vec<V3> = p.positions.iter().map(|&q| xf.point(q)).collect();
            let n_world: Vec<V3> = n_local
                .iter()
                .map(|&n| xf.normal(n).unwrap_or([0.0, 0.0, 1.0]))
                .collect();
            let (u_world, v_world) = match &p.uvs {
                Some(uv) => {
                    let (du, dv) = crate::geom::uv_derivatives(&p.positions, uv, &p.triangles);
                    let f = |d: &Vec<V3>| -> Vec<Option<V3>> {
                        d.iter()
                            .zip(&n_world)
                            .map(|(d, n)| normalize(project(xf.tangent(*d), *n)))
                            .collect()
                    };
                    (Some(f(&du)), Some(f(&dv)))
                }
                None => (None, None),
            };
            report.vertices += nv;
            report.triangles += p.triangles.len();
            report.degenerate_triangles += p
                .triangles
                .iter()
                .filter(|t| {
                    let q = [
                        p.positions[t[0] as usize],
                        p.positions[t[1] as usize],
                        p.positions[t[2] as usize],
                    ];
                    crate::geom::norm(cross(
                        crate::geom::sub(q[1], q[0]),
                        crate::geom::sub(q[2], q[0]),
                    )) <= 0.0
                })
                .count();
            out.push(Work {
                mesh: m,
                prim: k,
                xf: xf.clone(),
                n_local,
                normals_rewrite,
                p_world,
                n_world,
                u_world,
                v_world,
                dir: vec![None; nv],
                reason: vec![None; nv],
                t_local: Vec::new(),
                w_sign: Vec::new(),
                local: p,
            });
        }
    }
    report.primitives = out.len();
    Ok(out)
}

fn need_uvs(doc: &Document, w: &[Work], uv_set: usize, what: &str) -> Result<()> {
    for x in w {
        if x.u_world.is_none() {
            return Err(Error::input_file(
                &doc.source,
                format!("{what} needs TEXCOORD_{uv_set}, and meshes[{}].primitives[{}] has none (use --axis or --curve for meshes without UVs)", x.mesh, x.prim),
            ));
        }
    }
    Ok(())
}

/// Direction at angle `a` from `u` counter-clockwise about `n`.
fn from_angle(u: V3, n: V3, a: f64) -> V3 {
    add(scale(u, a.cos()), scale(cross(n, u), a.sin()))
}

/// Compute the field (no output written).
pub fn compute(doc: &Document, opts: &BakeOptions) -> Result<(Vec<Work>, Report)> {
    let mut report = Report {
        input: doc.source.display().to_string(),
        source: opts.source.describe(),
        rotate_deg: opts.rotate_deg,
        ..Default::default()
    };
    let mut work = prepare(doc, opts.uv_set, &mut report)?;
    if work.is_empty() {
        return Err(Error::input_file(
            &doc.source,
            "no triangle primitives to bake",
        ));
    }
    match &opts.source {
        Source::Axis(a) => {
            for w in &mut work {
                for i in 0..w.dir.len() {
                    w.set(i, Some(*a), "axis parallel to the normal");
                }
            }
        }
        Source::Curve(c) => {
            for w in &mut work {
                for i in 0..w.dir.len() {
                    let t = c.tangent_at(w.p_world[i]);
                    w.set(i, Some(t), "spine tangent parallel to the normal");
                }
            }
        }
        Source::UvDirection(ax) => {
            need_uvs(doc, &work, opts.uv_set, "--uv-direction")?;
            for w in &mut work {
                let src = if *ax == UvAxis::U {
                    w.u_world.clone()
                } else {
                    w.v_world.clone()
                };
                let src = src.unwrap_or_default();
                for i in 0..w.dir.len() {
                    w.set(i, src[i], "degenerate UVs around the vertex");
                }
            }
        }
        Source::Samples(s) => {
            need_uvs(doc, &work, opts.uv_set, "--samples")?;
            report.samples = Some(samples(&mut work, s, opts)?);
        }
    }
    // Extra rotation about the normal.
    if opts.rotate_deg != 0.0 {
        let a = opts.rotate_deg.to_radians();
        for w in &mut work {
            for i in 0..w.dir.len() {
                if let Some(t) = w.dir[i] {
                    w.dir[i] = normalize(from_angle(t, w.n_world[i], a));
                }
            }
        }
    }
    for w in &mut work {
        fill_missing(w, &mut report);
        finish_local(w);
    }
    Ok((work, report))
}

fn samples(
    work: &mut [Work],
    s: &crate::orient::Samples,
    opts: &BakeOptions,
) -> Result<SampleReport> {
    let mut rep = SampleReport {
        rows: s.items.len(),
        interpolation: match opts.interp {
            Interp::Natural => "natural-neighbour".into(),
            Interp::Linear => "linear".into(),
            Interp::SibsonC1 => "sibson-c1".into(),
        },
        ..Default::default()
    };
    // Domains: one for u,v samples (every primitive's UVs); for 3D samples one per
    // UV island (a chart: triangles connected through vertices of equal position and UV).
    let all_uv = s.items.iter().all(|x| matches!(x.at, SampleAt::Uv { .. }));
    let islands: Vec<(Vec<u32>, usize)> = if all_uv {
        Vec::new()
    } else {
        work.iter().map(uv_islands).collect()
    };
    let mut base = Vec::with_capacity(islands.len());
    let mut ndom = 0;
    for (_, n) in &islands {
        base.push(ndom);
        ndom += n;
    }
    let ndom = if all_uv { 1 } else { ndom };
    let mut dom: Vec<Vec<(usize, [f64; 2], f64)>> = vec![Vec::new(); ndom];
    // 3D samples: snap.
    let mut snapped: Vec<(V3, V3)> = Vec::new(); // (point, unit direction) for primitives without samples
    if !all_uv {
        let mut tris = Vec::new();
        let mut owner = Vec::new();
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for (wi, w) in work.iter().enumerate() {
            for (ti, t) in w.local.triangles.iter().enumerate() {
                tris.push([
                    w.p_world[t[0] as usize],
                    w.p_world[t[1] as usize],
                    w.p_world[t[2] as usize],
                ]);
                owner.push((wi, ti));
            }
            for p in &w.p_world {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        let diag = crate::geom::norm(crate::geom::sub(hi, lo));
        let max_snap = opts.max_snap.unwrap_or(0.02 * diag);
        rep.max_snap_distance = Some(max_snap);
        let bvh = Bvh::new(tris);
        let mut max_snapped: f64 = 0.0;
        for smp in &s.items {
            let SampleAt::Xyz { p, d } = smp.at else {
                rep.rejected.push(RejectedSample {
                    row: smp.line,
                    reason: "u,v sample mixed with x,y,z samples: the file must use one kind"
                        .into(),
                });
                continue;
            };
            let Some(hit) = bvh.closest(p) else { continue };
            let dist = hit.dist2.sqrt();
            if dist > max_snap {
                rep.rejected.push(RejectedSample {
                    row: smp.line,
                    reason: format!(
                        "{dist:.4e} from the surface (more than --max-snap {max_snap:.4e})"
                    ),
                });
                continue;
            }
            let (wi, ti) = owner[hit.tri];
            let w = &work[wi];
            let t = w.local.triangles[ti];
            let b = hit.bary;
            let mix3 = |v: &dyn Fn(usize) -> V3| -> V3 {
                add(
                    add(scale(v(t[0] as usize), b[0]), scale(v(t[1] as usize), b[1])),
                    scale(v(t[2] as usize), b[2]),
                )
            };
            let Some(n) = normalize(mix3(&|i| w.n_world[i])) else {
                rep.rejected.push(RejectedSample {
                    row: smp.line,
                    reason: "the surface normal at the snapped point is undefined".into(),
                });
                continue;
            };
            let uw = w.u_world.as_ref().expect("checked by need_uvs");
            let Some(u) = normalize(project(mix3(&|i| uw[i].unwrap_or([0.0; 3])), n)) else {
                rep.rejected.push(RejectedSample {
                    row: smp.line,
                    reason: "degenerate UVs at the snapped point".into(),
                });
                continue;
            };
            let Some(dp) = normalize(project(d, n))
                .filter(|_| crate::geom::norm(project(d, n)) > 1e-6 * crate::geom::norm(d))
            else {
                rep.rejected.push(RejectedSample {
                    row: smp.line,
                    reason: "direction is parallel to the surface normal (or zero)".into(),
                });
                continue;
            };
            let ang = dot(dp, cross(n, u)).atan2(dot(dp, u));
            let uv = w.local.uvs.as_ref().expect("checked by need_uvs");
            let (a, bb, c) = (uv[t[0] as usize], uv[t[1] as usize], uv[t[2] as usize]);
            let suv = [
                a[0] * b[0] + bb[0] * b[1] + c[0] * b[2],
                a[1] * b[0] + bb[1] * b[1] + c[1] * b[2],
            ];
            max_snapped = max_snapped.max(dist);
            dom[base[wi] + islands[wi].0[t[0] as usize] as usize].push((smp.line, suv, ang));
            snapped.push((hit.point, dp));
        }
        rep.max_snapped = Some(max_snapped);
    } else {
        for smp in &s.items {
            if let SampleAt::Uv { uv, angle } = smp.at {
                dom[0].push((smp.line, uv, angle));
            }
        }
    }
    if dom.iter().all(|d| d.is_empty()) {
        return Err(Error::input_file(
            &s.path,
            "no usable samples (see the reasons with --json); nothing to interpolate",
        ));
    }
    // Vertex lists per domain: (work index, vertex indices).
    let mut members: Vec<Vec<(usize, Vec<usize>)>> = vec![Vec::new(); ndom];
    for (wi, w) in work.iter().enumerate() {
        if all_uv {
            members[0].push((wi, (0..w.dir.len()).collect()));
        } else {
            let (isl, n) = &islands[wi];
            let mut lists: Vec<Vec<usize>> = vec![Vec::new(); *n];
            for (i, &k) in isl.iter().enumerate() {
                lists[k as usize].push(i);
            }
            for (k, l) in lists.into_iter().enumerate() {
                members[base[wi] + k].push((wi, l));
            }
        }
    }
    let near = Bvh::new(snapped.iter().map(|(p, _)| [*p, *p, *p]).collect());
    let mut without = 0usize;
    let mut notes = 0usize;
    for (di, samples) in dom.iter().enumerate() {
        let field = AxialField::new(samples, opts.interp);
        if let Some(f) = &field {
            rep.used += f.used;
            rep.merged_duplicates += f.merged_duplicates;
            for (row, why) in &f.dropped {
                rep.rejected.push(RejectedSample {
                    row: *row,
                    reason: why.clone(),
                });
            }
            if let Some(note) = f.degenerate_layout() {
                notes += 1;
                if notes <= 20 {
                    rep.layout_notes.push(if all_uv {
                        note.to_string()
                    } else {
                        let (wi, _) = &members[di][0];
                        format!(
                            "meshes[{}].primitives[{}], UV island {}: {note}",
                            work[*wi].mesh,
                            work[*wi].prim,
                            di - base[*wi]
                        )
                    });
                }
            }
        }
        for (wi, verts) in &members[di] {
            let w = &mut work[*wi];
            match &field {
                Some(f) => {
                    let uv = w.local.uvs.as_ref().expect("checked by need_uvs");
                    let pts: Vec<[f64; 2]> = verts.iter().map(|&i| uv[i]).collect();
                    let uw = w.u_world.clone().expect("checked by need_uvs");
                    for (&i, r) in verts.iter().zip(eval_parallel(f, &pts)) {
                        match (r, uw[i]) {
                            (
                                AxialValue::Angle {
                                    angle,
                                    extrapolated,
                                },
                                Some(u),
                            ) => {
                                if extrapolated {
                                    rep.extrapolated_vertices += 1;
                                }
                                let n = w.n_world[i];
                                w.set(
                                    i,
                                    Some(from_angle(u, n, angle)),
                                    "degenerate UVs around the vertex",
                                );
                            }
                            (AxialValue::Cancelled, _) => {
                                w.dir[i] = None;
                                w.reason[i] = Some("interpolated directions cancel here");
                            }
                            (_, None) => {
                                w.dir[i] = None;
                                w.reason[i] = Some("degenerate UVs around the vertex");
                            }
                        }
                    }
                }
                None => {
                    // No sample on this UV island: the nearest snapped sample in 3D, projected.
                    for &i in verts {
                        let best = near.closest(w.p_world[i]).map(|h| snapped[h.tri].1);
                        w.set(i, best, "no sample on its UV island, and the nearest 3D sample is parallel to the normal");
                        without += 1;
                    }
                }
            }
        }
    }
    if notes > 20 {
        rep.layout_notes
            .push(format!("... and {} more", notes - 20));
    }
    rep.nearest_sample_vertices = without;
    Ok(rep)
}

/// UV islands of a primitive: connected components of its triangles, where
/// vertices with the same position and UV count as one. Returns (island per
/// vertex, island count); vertices used by no triangle are islands of their own.
pub fn uv_islands(w: &Work) -> (Vec<u32>, usize) {
    let n = w.dir.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    let union = |p: &mut Vec<u32>, a: u32, b: u32| {
        let (ra, rb) = (find(p, a), find(p, b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            p[hi as usize] = lo;
        }
    };
    for t in &w.local.triangles {
        union(&mut parent, t[0], t[1]);
        union(&mut parent, t[1], t[2]);
    }
    if let Some(uv) = &w.local.uvs {
        let mut first: HashMap<[u64; 5], u32> = HashMap::new();
        for i in 0..n {
            let p = w.local.positions[i];
            let k = [
                (p[0] + 0.0).to_bits(),
                (p[1] + 0.0).to_bits(),
                (p[2] + 0.0).to_bits(),
                (uv[i][0] + 0.0).to_bits(),
                (uv[i][1] + 0.0).to_bits(),
            ];
            match first.get(&k) {
                Some(&j) => union(&mut parent, i as u32, j),
                None => {
                    first.insert(k, i as u32);
                }
            }
        }
    }
    let mut id: HashMap<u32, u32> = HashMap::new();
    let mut out = Vec::with_capacity(n);
    for i in 0..n as u32 {
        let r = find(&mut parent, i);
        let next = id.len() as u32;
        out.push(*id.entry(r).or_insert(next));
    }
    (out, id.len())
}

/// Evaluate a field at many UVs on all cores (rayon; chunks of the same size
/// as before, each with its own evaluator, results in order).
fn eval_parallel(f: &AxialField, uv: &[[f64; 2]]) -> Vec<AxialValue> {
    use rayon::prelude::*;
    let threads = rayon::current_num_threads().clamp(1, 16);
    if threads == 1 || uv.len() < 4096 {
        let mut e = f.evaluator();
        return uv.iter().map(|p| e.eval(*p)).collect();
    }
    uv.par_chunks(uv.len().div_ceil(threads))
        .flat_map_iter(|c| {
            let mut e = f.evaluator();
            c.iter().map(|p| e.eval(*p)).collect::<Vec<_>>()
        })
        .collect()
}

/// Fill vertices without a direction from their neighbours, breadth first.
fn fill_missing(w: &mut Work, report: &mut Report) {
    let nv = w.dir.len();
    let missing: Vec<usize> = (0..nv).filter(|&i| w.dir[i].is_none()).collect();
    if missing.is_empty() {
        return;
    }
    for &i in &missing {
        *report
            .without_direction
            .entry(
                w.reason[i]
                    .unwrap_or("vertex used by no triangle")
                    .to_string(),
            )
            .or_insert(0) += 1;
    }
    // Adjacency: triangle edges plus vertices welded by position.
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for t in &w.local.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        }
    }
    let mut by_pos: HashMap<[u64; 3], Vec<u32>> = HashMap::new();
    for (i, p) in w.local.positions.iter().enumerate() {
        by_pos
            .entry(p.map(|x| (x + 0.0).to_bits()))
            .or_default()
            .push(i as u32);
    }
    for g in by_pos.values().filter(|g| g.len() > 1) {
        for &a in g {
            for &b in g {
                if a != b {
                    adj[a as usize].push(b);
                }
            }
        }
    }
    let mut frontier: Vec<usize> = missing.clone();
    loop {
        let mut newly = Vec::new();
        for &i in &frontier {
            let n = w.n_world[i];
            let mut acc: Option<V3> = None;
            for &j in &adj[i] {
                if let Some(d) = w.dir[j as usize] {
                    let d = project(d, n);
                    acc = Some(match acc {
                        None => d,
                        Some(a) => add(a, if dot(a, d) < 0.0 { scale(d, -1.0) } else { d }),
                    });
                }
            }
            if let Some(d) = acc.and_then(normalize) {
                newly.push((i, d));
            }
        }
        if newly.is_empty() {
            break;
        }
        report.filled_from_neighbours += newly.len();
        for &(i, d) in &newly {
            w.dir[i] = Some(d);
        }
        frontier.retain(|&i| w.dir[i].is_none());
    }
    for i in frontier {
        w.dir[i] = Some(any_perpendicular(w.n_world[i]));
        report.arbitrary += 1;
    }
}

/// World directions to local unit vectors orthogonal to the local normal, and tangent signs.
fn finish_local(w: &mut Work) {
    let nv = w.dir.len();
    let dv_local = w
        .local
        .uvs
        .as_ref()
        .map(|uv| crate::geom::uv_derivatives(&w.local.positions, uv, &w.local.triangles));
    w.t_local = (0..nv)
        .map(|i| {
            let n = w.n_local[i];
            w.dir[i]
                .and_then(|d| normalize(project(w.xf.tangent_to_local(d), n)))
                .map(|t| normalize(project(t, n)).unwrap_or(t))
                .unwrap_or_else(|| any_perpendicular(n))
        })
        .collect();
    w.w_sign = (0..nv)
        .map(|i| match &dv_local {
            // MikkTSpace on glTF's v-down UVs: +1 for an unmirrored layout.
            Some((du, dv)) if dot(cross(w.n_local[i], du[i]), dv[i]) > 0.0 => -1.0,
            _ => 1.0,
        })
        .collect();
}

/// Unit direction of increasing u in each local tangent plane (the field where
/// the UVs are degenerate); None without UVs.
fn uv_tangents(w: &Work) -> Option<Vec<V3>> {
    let uv = w.local.uvs.as_ref()?;
    let (du, _) = crate::geom::uv_derivatives(&w.local.positions, uv, &w.local.triangles);
    Some(
        (0..w.t_local.len())
            .map(|i| normalize(project(du[i], w.n_local[i])).unwrap_or(w.t_local[i]))
            .collect(),
    )
}

/// Bake and attach the attributes: the returned document is ready for [`Document::to_glb`].
pub fn bake(mut doc: Document, opts: &BakeOptions) -> Result<Baked> {
    let (work, mut report) = compute(&doc, opts)?;
    doc.merge_buffers()?;
    for w in &work {
        let mut attrs = Vec::new();
        if w.normals_rewrite {
            let n: Vec<f32> = w.n_local.iter().flat_map(|v| v.map(|x| x as f32)).collect();
            attrs.push(("NORMAL", doc.push_f32_accessor(&n, 3, false)));
            report.normals_written += 1;
        }
        let uv_t = if opts.uv_tangents {
            uv_tangents(w)
        } else {
            None
        };
        let t: Vec<f32> = uv_t
            .as_ref()
            .unwrap_or(&w.t_local)
            .iter()
            .zip(&w.w_sign)
            .flat_map(|(v, s)| [v[0] as f32, v[1] as f32, v[2] as f32, *s as f32])
            .collect();
        attrs.push(("TANGENT", doc.push_f32_accessor(&t, 4, false)));
        let o: Vec<f32> = w.t_local.iter().flat_map(|v| v.map(|x| x as f32)).collect();
        attrs.push(("_ORIENTATION", doc.push_f32_accessor(&o, 3, false)));
        let a = doc
            .json
            .pointer_mut(&format!(
                "/meshes/{}/primitives/{}/attributes",
                w.mesh, w.prim
            ))
            .and_then(|a| a.as_object_mut())
            .ok_or_else(|| Error::internal("primitive attributes vanished"))?;
        for (k, v) in attrs {
            a.insert(k.to_string(), json!(v));
        }
    }
    Ok(Baked { doc, work, report })
}
