//! XYZ point lists: three numbers per line (x y z, metres unless `--z-scale`).
//! Points on a regular grid become that grid exactly; scattered points are
//! triangulated (Delaunay, `spade`) and linearly interpolated onto a regular grid:
//! the bounding box of the points, pixel size `--pixel-size` or else
//! sqrt(area / number of points) (about one grid node per point), nodes at
//! xmin + i dx, ymax - r dy; nodes outside the convex hull are NaN.

use spade::{DelaunayTriangulation, FloatTriangulation, HasPosition, Point2, Triangulation};
use sunbeam_common::Result;

use crate::ascii::{is_text, split_numbers};
use crate::util::{bail, channel, check_dims};
use crate::{Channel, Format, ReadOptions};

fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines().enumerate().filter(|(_, l)| {
        let t = l.trim_start();
        !(t.is_empty() || t.starts_with('#') || t.starts_with('%') || t.starts_with("//"))
    })
}

pub fn detect(b: &[u8]) -> bool {
    if !is_text(b) {
        return false;
    }
    let head = String::from_utf8_lossy(&b[..b.len().min(4096)]);
    let mut lines: Vec<&str> = data_lines(&head).map(|(_, l)| l).collect();
    if b.len() > 4096 {
        lines.pop(); // possibly cut
    }
    lines.len() >= 4
        && lines
            .iter()
            .all(|l| split_numbers(l).is_some_and(|v| v.len() == 3))
}

struct P {
    pos: Point2<f64>,
    z: f64,
}

impl HasPosition for P {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

/// Sorted distinct values, merging those closer than `tol`.
fn distinct(mut v: Vec<f64>, tol: f64) -> Vec<f64> {
    v.sort_by(|a, b| a.total_cmp(b));
    let mut out: Vec<f64> = Vec::new();
    for x in v {
        if out.last().is_none_or(|&l| x - l > tol) {
            out.push(x);
        }
    }
    out
}

fn evenly_spaced(v: &[f64], tol: f64) -> bool {
    if v.len() < 2 {
        return false;
    }
    let d = (v[v.len() - 1] - v[0]) / (v.len() - 1) as f64;
    v.iter()
        .enumerate()
        .all(|(i, &x)| (x - (v[0] + i as f64 * d)).abs() <= tol)
}

pub fn read(b: &[u8], opts: &ReadOptions) -> Result<Vec<Channel>> {
    if !is_text(b) {
        bail!("XYZ file: not text");
    }
    let text = String::from_utf8_lossy(b);
    let zs = opts.z_scale.unwrap_or(1.0);
    let mut pts: Vec<[f64; 3]> = Vec::new();
    for (ln, l) in data_lines(&text) {
        match split_numbers(l) {
            Some(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => {
                pts.push([v[0], v[1], v[2] * zs])
            }
            _ => bail!(
                "XYZ file line {}: expected three finite numbers x y z ({:?})",
                ln + 1,
                l.chars().take(40).collect::<String>()
            ),
        }
    }
    if pts.len() < 3 {
        bail!("XYZ file: {} points, at least 3 are needed", pts.len());
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in &pts {
        x0 = x0.min(p[0]);
        x1 = x1.max(p[0]);
        y0 = y0.min(p[1]);
        y1 = y1.max(p[1]);
    }
    let (w, h) = (x1 - x0, y1 - y0);
    if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
        bail!("XYZ file: points span {w} x {h}; they must cover an area");
    }
    // Regular grid?
    let tolx = w * 1e-6;
    let toly = h * 1e-6;
    let xs = distinct(pts.iter().map(|p| p[0]).collect(), tolx);
    let ys = distinct(pts.iter().map(|p| p[1]).collect(), toly);
    if xs.len() * ys.len() == pts.len() && evenly_spaced(&xs, tolx) && evenly_spaced(&ys, toly) {
        let (nx, ny) = check_dims(xs.len() as i64, ys.len() as i64, "XYZ grid")?;
        let dx = w / (nx - 1) as f64;
        let dy = h / (ny - 1) as f64;
        let mut data = vec![f64::NAN; nx * ny];
        let mut filled = vec![false; nx * ny];
        for p in &pts {
            let c = ((p[0] - x0) / dx).round() as usize;
            let r = ny - 1 - (((p[1] - y0) / dy).round() as usize).min(ny - 1);
            let k = r * nx + c.min(nx - 1);
            if filled[k] {
                bail!("XYZ file: two points at grid node ({}, {})", p[0], p[1]);
            }
            filled[k] = true;
            data[k] = p[2];
        }
        let mut ch = channel(
            Format::Xyz,
            "Height",
            "m",
            "m",
            nx,
            ny,
            dx * nx as f64,
            dy * ny as f64,
            data,
        )?;
        ch.is_height = true;
        ch.offset = (x0, y0);
        return Ok(vec![ch]);
    }
    // Scattered: triangulate in normalised coordinates.
    let d = match opts.pixel_size {
        Some((dx, dy)) => (dx, dy),
        None => {
            let s = (w * h / pts.len() as f64).sqrt();
            (s, s)
        }
    };
    let nx = ((w / d.0).floor() + 1.0).min(1e15) as i64;
    let ny = ((h / d.1).floor() + 1.0).min(1e15) as i64;
    let (nx, ny) = check_dims(nx, ny, "XYZ resampling grid")?;
    if nx * ny > 1 << 26 {
        bail!("XYZ resampling grid {nx}x{ny} is too large; give a larger --pixel-size");
    }
    let verts: Vec<P> = pts
        .iter()
        .map(|p| P {
            pos: Point2::new((p[0] - x0) / w, (p[1] - y0) / h),
            z: p[2],
        })
        .collect();
    let tri = DelaunayTriangulation::<P>::bulk_load(verts).map_err(|e| {
        sunbeam_common::Error::input(format!("XYZ file: triangulation failed: {e:?}"))
    })?;
    if tri.num_inner_faces() == 0 {
        bail!("XYZ file: the points are collinear; nothing to triangulate");
    }
    let bary = tri.barycentric();
    let mut data = Vec::with_capacity(nx * ny);
    for r in 0..ny {
        let y = y1 - r as f64 * d.1;
        for c in 0..nx {
            let x = x0 + c as f64 * d.0;
            let q = Point2::new((x - x0) / w, (y - y0) / h);
            data.push(bary.interpolate(|v| v.data().z, q).unwrap_or(f64::NAN));
        }
    }
    let mut ch = channel(
        Format::Xyz,
        "Height",
        "m",
        "m",
        nx,
        ny,
        d.0 * nx as f64,
        d.1 * ny as f64,
        data,
    )?;
    ch.is_height = true;
    ch.offset = (x0, y1 - (ny - 1) as f64 * d.1);
    Ok(vec![ch])
}
