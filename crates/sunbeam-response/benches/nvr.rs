//! The cost of the `n = v = r` prefilter approximation on a sphere
//! (docs/bench/prefilter.md): a sky-lit and a white-lit sphere, per pixel the
//! converged exact twin, a second seed of it (the noise floor) and the
//! converged `n = v = r` twin; CIEDE2000 as `sunbeam-eval render --compare`
//! computes it. Prints markdown tables. A benchmark:
//!
//!     cargo bench -p sunbeam-response --bench nvr
//!
//! The helpers (packs, environments, the per-pixel means) are tests/nvr.rs'.

#[path = "../tests/nvr.rs"]
#[allow(dead_code, unused_imports)]
mod nvr;

use nvr::*;
use rayon::prelude::*;
use sunbeam_frame::linear::{compare_linear, luminance, LinearImage, LIT_Y};
use sunbeam_light::Environment;
use sunbeam_optics::colour;
use sunbeam_response::env::{build_env, EnvResponse, Frame};
use sunbeam_response::Options;

/// One pixel's three estimates (linear sRGB, exposure applied) and its view
/// angle: the exact twin with seeds 1 and 2, the `n = v = r` twin with seed 1.
struct Pixel {
    exact: [f32; 3],
    exact2: [f32; 3],
    nvr: [f32; 3],
    theta_r_deg: f64,
}

/// A sphere seen by an orthographic camera along -z (`size x size` pixels
/// over `[-1, 1]^2`, y up), normal `(x, y, sqrt(1 - x^2 - y^2))`, tangent
/// eastwards along the latitude as `builtin:sphere` (`t = cross(+y, n)`,
/// perpendicular to `n`, so the reference's shading frame is `(t, n x t, n)`
/// normalised), view `+z`. Unlit (background) pixels are None.
fn sphere(
    e: &EnvResponse,
    env: &Environment,
    size: usize,
    n: usize,
    scale: f64,
) -> Vec<Option<Pixel>> {
    (0..size * size)
        .into_par_iter()
        .map(|p| {
            let h = size as f64 / 2.0;
            let x = ((p % size) as f64 + 0.5) / h - 1.0;
            let y = 1.0 - ((p / size) as f64 + 0.5) / h;
            let r2 = x * x + y * y;
            if r2 >= 1.0 {
                return None;
            }
            let nrm = [x, y, (1.0 - r2).sqrt()];
            let f = frame(nrm);
            let v = [0.0, 0.0, 1.0];
            let dot = |a: [f64; 3]| a[0] * v[0] + a[1] * v[1] + a[2] * v[2];
            let wr = [dot(f.0), dot(f.1), dot(f.2)];
            let px = p as u64;
            let run = |est, seed: u64| {
                mean(e, env, est, f, wr, n, seed * 0x1_0000_0000 + px).map(|c| (c * scale) as f32)
            };
            Some(Pixel {
                exact: run(Est::Exact, 1),
                exact2: run(Est::Exact, 2),
                nvr: run(Est::Nvr, 1),
                theta_r_deg: wr[2].acos().to_degrees(),
            })
        })
        .collect()
}

/// The frame `(t, b, n)` of the unit sphere's normal `nrm`: `t = cross(+y, n)`
/// normalised, `b = n x t`.
fn frame(nrm: [f64; 3]) -> Frame {
    let unit = |a: [f64; 3]| {
        let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        a.map(|x| x / l)
    };
    let n = unit(nrm);
    let t = unit([n[2], 0.0, -n[0]]);
    let b = [
        n[1] * t[2] - n[2] * t[1],
        n[2] * t[0] - n[0] * t[2],
        n[0] * t[1] - n[1] * t[0],
    ];
    (t, b, n)
}

fn image(px: &[Option<Pixel>], size: usize, pick: fn(&Pixel) -> [f32; 3]) -> LinearImage {
    let mut im = LinearImage::new(size as u32, size as u32);
    for (o, p) in im.rgb.iter_mut().zip(px) {
        if let Some(p) = p {
            *o = pick(p);
        }
    }
    im
}

/// The sphere under the sky (elevation 35, azimuth 120, turbidity 3) and a
/// constant white map, packs of 3.2 um (`SUNBEAM_NVR_PACKS` lists sizes in
/// samples at 100 nm; default "32 128", 128 = 12.8 um), `SUNBEAM_NVR_SAMPLES`
/// per pixel and estimator (default 4096), exposure -1.5 EV as
/// docs/bench/lighting.sh. CIEDE2000 over the pixels lit in the exact twin
/// (`Y >= LIT_Y`), as `compare_linear`; per view-angle band too.
fn main() {
    let n: usize = std::env::var("SUNBEAM_NVR_SAMPLES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4096);
    let packs: Vec<usize> = std::env::var("SUNBEAM_NVR_PACKS")
        .unwrap_or_else(|_| "32 128".into())
        .split_whitespace()
        .filter_map(|s| s.parse().ok())
        .collect();
    let size = 48;
    let scale = 2f64.powf(-1.5);
    let bands = [(0.0, 30.0), (30.0, 60.0), (60.0, 75.0), (75.0, 90.0)];
    let mut rows = Vec::new();
    let mut band_rows = Vec::new();
    for &np in &packs {
        let t0 = std::time::Instant::now();
        let pack = ridge_pack(np);
        let t_pack = t0.elapsed().as_secs_f64();
        let um = np as f64 * 0.1;
        for (ename, env) in [("sky", sky()), ("white", white())] {
            let t1 = std::time::Instant::now();
            let e = build_env(&pack, &env, &Options::default());
            let t2 = std::time::Instant::now();
            let px = sphere(&e, &env, size, n, scale);
            let t3 = std::time::Instant::now();
            eprintln!(
                "{um} um {ename}: pack {t_pack:.1} s, maps {:.1} s (grid {:?}), 3 x {n} samples/px {:.1} s",
                (t2 - t1).as_secs_f64(),
                e.grid,
                (t3 - t2).as_secs_f64()
            );
            let ex = image(&px, size, |p| p.exact);
            let ex2 = image(&px, size, |p| p.exact2);
            let nv = image(&px, size, |p| p.nvr);
            let d_nvr = compare_linear(&nv, &ex).unwrap();
            let d_floor = compare_linear(&ex2, &ex).unwrap();
            let lit: Vec<&Pixel> = px
                .iter()
                .flatten()
                .filter(|p| luminance(p.exact) >= LIT_Y)
                .collect();
            let sum_y =
                |f: fn(&Pixel) -> [f32; 3]| lit.iter().map(|p| luminance(f(p))).sum::<f64>();
            let ratio = sum_y(|p| p.nvr) / sum_y(|p| p.exact);
            let ratio2 = sum_y(|p| p.exact2) / sum_y(|p| p.exact);
            rows.push(format!(
                "| {um} um | {ename} | {:.2} / {:.2} / {:.2} | {:.2} / {:.2} / {:.2} | {ratio:.3} ({ratio2:.3}) | {} |",
                d_nvr.mean, d_nvr.p99, d_nvr.max, d_floor.mean, d_floor.p99, d_floor.max, d_nvr.pixels
            ));
            let mut cells = Vec::new();
            for &(lo, hi) in &bands {
                let de = |f: fn(&Pixel) -> [f32; 3], p: &Pixel| {
                    let xyz =
                        |c: [f32; 3]| colour::linear_srgb_to_xyz(c.map(|v| f64::from(v).max(0.0)));
                    colour::ciede2000_xyz(xyz(f(p)), xyz(p.exact))
                };
                let sel: Vec<&&Pixel> = lit
                    .iter()
                    .filter(|p| p.theta_r_deg >= lo && p.theta_r_deg < hi)
                    .collect();
                let m = |f: fn(&Pixel) -> [f32; 3]| {
                    sel.iter().map(|p| de(f, p)).sum::<f64>() / sel.len().max(1) as f64
                };
                let yr = sel.iter().map(|p| luminance(p.nvr)).sum::<f64>()
                    / sel.iter().map(|p| luminance(p.exact)).sum::<f64>();
                cells.push(format!(
                    "{:.2} ({:.2}), Y {yr:.2}, {} px",
                    m(|p| p.nvr),
                    m(|p| p.exact2),
                    sel.len()
                ));
            }
            band_rows.push(format!("| {um} um | {ename} | {} |", cells.join(" | ")));
        }
    }
    println!("\nsphere {size}x{size}, {n} samples per pixel and estimator, exposure -1.5 EV\n");
    println!("| pack | light | n=v=r vs exact: CIEDE2000 mean / p99 / max | exact seed 1 vs 2 (noise floor) | frame Y n=v=r / exact (seed 2 / seed 1) | lit px |");
    println!("|---|---|---|---|---|---|");
    for r in &rows {
        println!("{r}");
    }
    println!("\nby view angle theta_r: mean CIEDE2000 n=v=r vs exact (noise floor), Y ratio n=v=r / exact, pixels\n");
    println!("| pack | light | 0-30 deg | 30-60 deg | 60-75 deg | 75-90 deg |");
    println!("|---|---|---|---|---|---|");
    for r in &band_rows {
        println!("{r}");
    }
}
