//! A measurement that prints, not a check: the environment estimator's noise at
//! single shading points (docs/LIGHTING.md "Noise"). For a pack (the ridge
//! field below, or `SUNBEAM_PACK=path.ktx2`), a few views under a constant
//! white map and under the sky, it prints the mean Y, one sample's relative
//! standard deviation of Y, and the relative standard deviation of X, Y, Z
//! of a 256-sample pixel (wavelengths stratified as in the renderer) over 48
//! pixels.
//!   cargo bench -p sunbeam-raster --bench env_noise [-- NAME...]
//! runs every measurement, or those whose names contain a NAME.
//! `THETAS=85,89` picks the views; `FIXED_LAMBDA=0.37` holds the wavelengths
//! constant (the spectral share of the noise); `lobe_technique_alone`,
//! `r_inside_bins` and `worst_pixels` (`A=a.exr B=b.exr`) dissect the rest;
//! `grazing_views` and `grazing_band_sum` follow a limb's light.

use std::f64::consts::PI;
use std::sync::Arc;
use sunbeam_light::{sky::Sky, EnvMap, Environment};
use sunbeam_optics::{colour, masking::Masking};
use sunbeam_pack::{build::BuildOptions, FieldRef, Pack};
use sunbeam_raster::environment::{EnvShader, Uniforms};

/// A pixel's colour difference and its index.
type Px = (f64, usize);
use sunbeam_response::quadrature::{EnvQuadrature, Query};

fn ridge_pack() -> Arc<Pack> {
    let (n, dx, period, amp) = (64usize, 50e-9, 1.3e-6, 420e-9);
    let data: Vec<f64> = (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            0.5 * amp * (1.0 + (2.0 * PI * (i * dx) / period + 0.3 * (0.7 * j).sin()).sin())
        })
        .collect();
    let f = FieldRef {
        width: n,
        height: n,
        dx,
        dy: dx,
        data: &data,
    };
    Arc::new(sunbeam_pack::build(f, &BuildOptions::default(), &mut |_, _| {}).unwrap())
}

fn noise_at_shading_points() {
    let pack = match std::env::var("SUNBEAM_PACK") {
        Ok(p) => Arc::new(Pack::read(std::path::Path::new(&p)).unwrap()),
        Err(_) => ridge_pack(),
    };
    // World up is +y: the frame's normal.
    let (t, b, n) = ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]);
    let world = |d: [f64; 3]| [0, 1, 2].map(|k| d[0] * t[k] + d[1] * b[k] + d[2] * n[k]);
    let envs = [
        ("white", Environment::Map(EnvMap::constant([1.0; 3]))),
        (
            "sky",
            Environment::Sky(Box::new(Sky::new(25.0, 120.0, 3.0, 1.0))),
        ),
    ];
    for (name, env) in envs {
        let es = EnvShader::new(Arc::new(env), &[Some(pack.clone())]);
        for (th, ph) in th_list() {
            let (th, ph) = (th.to_radians(), ph.to_radians());
            let wr = world([th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()]);
            let y_of = |u: &Uniforms| {
                colour::linear_srgb_to_xyz(es.sample(0, (t, b, n), wr, [0.0; 3], 0.0, u))
            };
            // One sample's spread (independent samples).
            let m = 20_000u64;
            let (mut s1, mut s2) = (0.0, 0.0);
            for k in 0..m {
                let mut rng = EnvShader::rng(9, 1, k);
                let y = y_of(&Uniforms::random(&mut rng))[1];
                s1 += y;
                s2 += y * y;
            }
            let mean = s1 / m as f64;
            let sd1 = (s2 / m as f64 - mean * mean).max(0.0).sqrt() / mean;
            // Pixels of 256 samples, as the renderer draws them.
            let (px, ns) = (48u64, 256u64);
            let mut v = vec![[0.0; 3]; px as usize];
            let t0 = std::time::Instant::now();
            for (p, acc) in v.iter_mut().enumerate() {
                let uniforms = sunbeam_raster::environment::pixel_uniforms(3, p as u64 + 100, ns);
                for u in &uniforms {
                    let mut u = *u;
                    if let Ok(v) = std::env::var("FIXED_LAMBDA") {
                        u.lambda = v.parse().unwrap();
                    }
                    let xyz = y_of(&u);
                    for c in 0..3 {
                        acc[c] += xyz[c] / ns as f64;
                    }
                }
            }
            let us = t0.elapsed().as_secs_f64() * 1e6 / (px * ns) as f64;
            let rel = [0, 1, 2].map(|c| {
                let mu = v.iter().map(|x| x[c]).sum::<f64>() / px as f64;
                let var = v.iter().map(|x| (x[c] - mu).powi(2)).sum::<f64>() / (px - 1) as f64;
                var.sqrt() / mu
            });
            eprintln!(
                "{name:5} th_r {:4.0} deg: Y {mean:.4}, one sample {sd1:.2}, 256-sample pixel X/Y/Z {:.3} / {:.3} / {:.3} ({us:.0} us/sample)",
                th.to_degrees(),
                rel[0],
                rel[1],
                rel[2]
            );
        }
    }
}

/// The lobe technique alone at one wavelength: one sample's relative standard
/// deviation of `f / p` (the proposal's mismatch with the integrand), and the
/// share of the second moment held by the largest 1 % of the weights.
fn lobe_technique_alone() {
    let pack = match std::env::var("SUNBEAM_PACK") {
        Ok(p) => Arc::new(Pack::read(std::path::Path::new(&p)).unwrap()),
        Err(_) => ridge_pack(),
    };
    let ls = sunbeam_raster::lobe_sampler::LobeSampler::new(pack.clone());
    let skin = sunbeam_optics::gain::Material::default();
    for th in [0.0f64, 40.0, 65.0, 80.0] {
        for nm in [450.0, 550.0, 650.0] {
            let th = th.to_radians();
            let wr = [th.sin(), 0.0, th.cos()];
            let l = nm * 1e-9;
            let m = 40_000u64;
            let mut w = Vec::with_capacity(m as usize);
            let mut worst = (0.0, [0.0; 3]);
            for k in 0..m {
                let mut rng = EnvShader::rng(5, 0, k);
                let u = [rng.unit(), rng.unit(), rng.unit()];
                w.push(match ls.sample(u, wr, l, skin) {
                    Some(wi) => {
                        let v =
                            ls.brdf_cos(wi, wr, l, Masking::Off, skin) / ls.pdf(wi, wr, l, skin);
                        if v > worst.0 {
                            worst = (v, wi);
                        }
                        v
                    }
                    None => 0.0,
                });
            }
            if std::env::var("WORST").is_ok() {
                let wi = worst.1;
                let r = pack.shading_reflectance(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2], l);
                eprintln!(
                    "  worst {:.2}: wi {wi:.3?} R_U {r:.3e} G {:.3} pdf {:.3e}",
                    worst.0,
                    sunbeam_optics::gain::g(wi, wr, skin),
                    ls.pdf(wi, wr, l, skin)
                );
            }
            let mean = w.iter().sum::<f64>() / m as f64;
            let m2 = w.iter().map(|x| x * x).sum::<f64>() / m as f64;
            let sd = (m2 - mean * mean).max(0.0).sqrt() / mean;
            w.sort_by(|a, b| b.partial_cmp(a).unwrap());
            let top: f64 = w[..(m / 100) as usize].iter().map(|x| x * x).sum::<f64>() / m as f64;
            let zeros = w.iter().filter(|&&x| x == 0.0).count() as f64 / m as f64;
            eprintln!(
                "th_r {:3.0} {nm:3.0} nm: mean {mean:.4}, rel sd {sd:.3}, top 1 % share of 2nd moment {:.2}, zero {zeros:.3}",
                th.to_degrees(),
                top / m2
            );
        }
    }
}

/// How much R varies inside a bin: points uniform in bins drawn by their
/// centre's R, the relative sd of R(point) / R(centre) (at fixed w = -2).
fn r_inside_bins() {
    let pack = match std::env::var("SUNBEAM_PACK") {
        Ok(p) => Arc::new(Pack::read(std::path::Path::new(&p)).unwrap()),
        Err(_) => ridge_pack(),
    };
    let m = pack.manifest.clone();
    let l = 550e-9;
    let r_at = |kx: f64, ky: f64| {
        let u = -kx * l / m.bin_scale_m[0];
        let v = -ky * l / m.bin_scale_m[1];
        pack.reflectance(u, v, -2.0, l)
    };
    let (mut s1, mut s2, mut sw) = (0.0, 0.0, 0.0);
    let mut rng = EnvShader::rng(1, 2, 3);
    let k = 15i64;
    for by in -k..=k {
        for bx in -k..=k {
            let rc = r_at(bx as f64, by as f64);
            for _ in 0..16 {
                let r = r_at(bx as f64 + rng.unit() - 0.5, by as f64 + rng.unit() - 0.5);
                if rc > 0.0 {
                    let q = r / rc;
                    s1 += rc * q;
                    s2 += rc * q * q;
                    sw += rc;
                }
            }
        }
    }
    let mean = s1 / sw;
    eprintln!(
        "R(point) / R(bin centre): mean {mean:.3}, rel sd {:.3}",
        (s2 / sw - mean * mean).sqrt() / mean
    );
}

/// The views of [`noise_at_shading_points`]: `THETAS="0,85"` or the default.
fn th_list() -> Vec<(f64, f64)> {
    match std::env::var("THETAS") {
        Ok(s) => s.split(',').map(|t| (t.parse().unwrap(), 30.0)).collect(),
        Err(_) => vec![(0.0, 0.0), (40.0, 30.0), (65.0, 100.0), (80.0, 200.0)],
    }
}

/// The largest CIEDE2000 differences between two frames `A` and `B` (EXR;
/// over the pixels lit in `B`: give the reference as `B`), with their pixels
/// and luminances.
fn worst_pixels() {
    use sunbeam_raster::LinearImage;
    let a = LinearImage::read_exr(std::path::Path::new(&std::env::var("A").unwrap())).unwrap();
    let b = LinearImage::read_exr(std::path::Path::new(&std::env::var("B").unwrap())).unwrap();
    let mut d: Vec<(f64, usize)> = a
        .rgb
        .iter()
        .zip(&b.rgb)
        .enumerate()
        .filter(|(_, (_, q))| {
            sunbeam_raster::linear::luminance(**q) >= sunbeam_raster::linear::LIT_Y
        })
        .map(|(i, (p, q))| {
            let xyz = |v: &[f32; 3]| colour::linear_srgb_to_xyz(v.map(|x| f64::from(x).max(0.0)));
            (colour::ciede2000_xyz(xyz(p), xyz(q)), i)
        })
        .collect();
    // Interior pixels (all 8 neighbours lit) against silhouette pixels, and
    // the interior's luminance ratio: a bias shows in the ratio and in the
    // 2 x 2 block average, noise falls with the blocks.
    let (w, h) = (a.width as usize, a.height as usize);
    let mut inside = vec![false; w * h];
    for i in sunbeam_raster::linear::interior_pixels(&[&b]) {
        inside[i] = true;
    }
    let interior = |i: usize| inside[i];
    let pct = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let n = v.len().max(1);
        let m = v.iter().sum::<f64>() / n as f64;
        format!(
            "{} px: mean {m:.2} p99 {:.2} max {:.2}",
            v.len(),
            v.get((n - 1) * 99 / 100).copied().unwrap_or(0.0),
            v.last().copied().unwrap_or(0.0)
        )
    };
    eprintln!(
        "A against B (sunbeam-play --compare's figure): {}",
        sunbeam_raster::linear::compare_linear(&a, &b).unwrap()
    );
    eprintln!("lit in B {}", pct(d.iter().map(|x| x.0).collect()));
    let (inner, edge): (Vec<&Px>, Vec<&Px>) = d.iter().partition(|(_, i)| interior(*i));
    eprintln!("interior {}", pct(inner.iter().map(|x| x.0).collect()));
    eprintln!("silhouette {}", pct(edge.iter().map(|x| x.0).collect()));
    let (mut ya, mut yb) = (0.0, 0.0);
    for &&(_, i) in &inner {
        ya += sunbeam_raster::linear::luminance(a.rgb[i]);
        yb += sunbeam_raster::linear::luminance(b.rgb[i]);
    }
    eprintln!("interior Y ratio {:.4}", ya / yb);
    for k in [2, 4] {
        let d2 = sunbeam_raster::compare_linear(&a.downsample(k), &b.downsample(k)).unwrap();
        eprintln!("{k} x {k} blocks: {d2}");
    }
    {
        let (a4, b4) = (a.downsample(4), b.downsample(4));
        let xyz = |v: &[f32; 3]| colour::linear_srgb_to_xyz(v.map(|x| f64::from(x).max(0.0)));
        let mut e4: Vec<(f64, usize)> = (0..a4.rgb.len())
            .filter(|&i| {
                sunbeam_raster::linear::luminance(b4.rgb[i]) >= sunbeam_raster::linear::LIT_Y
            })
            .map(|i| (colour::ciede2000_xyz(xyz(&a4.rgb[i]), xyz(&b4.rgb[i])), i))
            .collect();
        e4.sort_by(|x, y| y.0.total_cmp(&x.0));
        for &(e, i) in e4.iter().take(10) {
            let (p, q) = (xyz(&a4.rgb[i]), xyz(&b4.rgb[i]));
            let s = |v: [f64; 3]| [v[0] / (v[0] + v[1] + v[2]), v[1] / (v[0] + v[1] + v[2])];
            eprintln!(
                "block dE {e:.2} at ({}, {}): Y {:.3} vs {:.3}, xy {:.4?} vs {:.4?}",
                i as u32 % a4.width,
                i as u32 / a4.width,
                p[1],
                q[1],
                s(p),
                s(q)
            );
        }
    }
    d.sort_by(|x, y| y.0.total_cmp(&x.0));
    // The 5 x 5 neighbourhoods (luminance) of the three worst pixels, or of
    // the pixel `AT=x,y`.
    let at: Option<usize> = std::env::var("AT").ok().and_then(|v| {
        let (x, y) = v.split_once(',')?;
        Some(y.trim().parse::<usize>().ok()? * w + x.trim().parse::<usize>().ok()?)
    });
    let picked: Vec<usize> = match at {
        Some(i) => vec![i],
        None => d.iter().take(3).map(|x| x.1).collect(),
    };
    for i in picked {
        let (x, y) = (i % w, i / w);
        for (name, img) in [("A", &a), ("B", &b)] {
            eprintln!("{name} around ({x}, {y}):");
            for yy in y.saturating_sub(2)..(y + 3).min(h) {
                let row: Vec<String> = (x.saturating_sub(2)..(x + 3).min(w))
                    .map(|xx| {
                        format!(
                            "{:7.4}",
                            sunbeam_raster::linear::luminance(img.rgb[yy * w + xx])
                        )
                    })
                    .collect();
                eprintln!("  {}", row.join(" "));
            }
        }
    }
    for &(e, i) in d.iter().take(25) {
        eprintln!(
            "dE {e:.1} at ({}, {}): Y {:.3} vs {:.3}",
            i as u32 % a.width,
            i as u32 / a.width,
            sunbeam_raster::linear::luminance(a.rgb[i]),
            sunbeam_raster::linear::luminance(b.rgb[i])
        );
    }
}

/// A flat frame's light at grazing views under the sky (`SUNBEAM_PACK`
/// required, masked with the demo's slopes): the quadrature against Monte
/// Carlo (`M` samples, default 20 000), per `cos(theta_r)` down to 1e-4
/// (docs/LIGHTING.md "Grazing views: masking").
fn grazing_views() {
    let pack = Arc::new(
        Pack::read(std::path::Path::new(
            &std::env::var("SUNBEAM_PACK").unwrap(),
        ))
        .unwrap(),
    );
    let env = Arc::new(Environment::Sky(Box::new(Sky::new(35.0, 70.0, 3.0, 1.0))));
    let mask = Masking::smith([0.21, 0.43]);
    let (t, b, n) = ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]);
    let world = |d: [f64; 3]| [0, 1, 2].map(|k| d[0] * t[k] + d[1] * b[k] + d[2] * n[k]);
    let q = EnvQuadrature::build(&pack, &env, &EnvQuadrature::reference_options());
    let es = EnvShader::new(env.clone(), &[Some(pack.clone())]).with_masking(&[mask]);
    let m: u64 = std::env::var("M")
        .map(|v| v.parse().unwrap())
        .unwrap_or(20000);
    for ph in [0.0f64, 90.0, 200.0] {
        for cr in [0.3f64, 0.1, 0.03, 0.01, 0.003, 0.001, 1e-4] {
            let ph = ph.to_radians();
            let sr = (1.0 - cr * cr).sqrt();
            let wl = [sr * ph.cos(), sr * ph.sin(), cr];
            let yq = q.integrate_many(
                &env,
                &[Query {
                    frame: (t, b, n),
                    wr: wl,
                    sun_u: [0.5, 0.5],
                    masking: mask,
                    skin: sunbeam_optics::gain::Material::default(),
                }],
                (0, 1),
            )[0][1];
            let wr = world(wl);
            let mut s1 = 0.0;
            let mut s2 = 0.0;
            let us = sunbeam_raster::environment::pixel_uniforms(5, 7, m);
            for u in &us {
                let y =
                    colour::linear_srgb_to_xyz(es.sample(0, (t, b, n), wr, [0.0; 3], 0.0, u))[1];
                s1 += y;
                s2 += y * y;
            }
            let mean = s1 / m as f64;
            let se = ((s2 / m as f64 - mean * mean).max(0.0) / m as f64).sqrt();
            eprintln!("phi {:5.0} cr {cr:8.5}: quad Y {yq:10.4} (x cr {:8.5})  mc Y {mean:10.4} +- {se:8.4}", ph.to_degrees(), yq * cr);
        }
    }
}

/// The same at one wavelength (550 nm) under a white environment of radiance
/// 1, as a direct sum of `G G2 R_U A / lambda^2` over the hemisphere with `R_U`
/// from the pack (`Pack::shading_reflectance`) (`NC` x `NPHI` cells, cubic in `cos(theta_i)`), split by
/// `cos(theta_i)` bands: which directions hold a grazing view's light.
fn grazing_band_sum() {
    let pack = Pack::read(std::path::Path::new(
        &std::env::var("SUNBEAM_PACK").unwrap(),
    ))
    .unwrap();
    let mask = Masking::smith([0.21, 0.43]);
    let lam = 550e-9;
    let a = pack.manifest.coherent_area_m2() / (lam * lam);
    let nphi: usize = std::env::var("NPHI")
        .map(|v| v.parse().unwrap())
        .unwrap_or(2000);
    let nc: usize = std::env::var("NC")
        .map(|v| v.parse().unwrap())
        .unwrap_or(1000);
    for ph in [0.0f64, 90.0] {
        for cr in [0.1f64, 0.01, 0.003, 0.001, 1e-4] {
            let ph = ph.to_radians();
            let sr = (1.0 - cr * cr).sqrt();
            let wr = [sr * ph.cos(), sr * ph.sin(), cr];
            // ci from 0 to 1 in a grid uniform in sqrt(ci) near the horizon.
            let mut bands = [0.0f64; 4]; // ci<0.01, <0.1, <0.3, rest
            let mut top = (0.0, 0.0, 0.0, 0.0);
            for ic in 0..nc {
                let t0 = ic as f64 / nc as f64;
                let t1 = (ic + 1) as f64 / nc as f64;
                let (c0, c1) = (t0 * t0 * t0, t1 * t1 * t1);
                let ci = 0.5 * (c0 + c1);
                let si = (1.0 - ci * ci).sqrt();
                let mut s = 0.0;
                for ip in 0..nphi {
                    let p = (ip as f64 + 0.5) / nphi as f64 * std::f64::consts::TAU;
                    let wi = [si * p.cos(), si * p.sin(), ci];
                    let g = mask.gain(wi, wr, sunbeam_optics::gain::Material::default());
                    if g == 0.0 {
                        continue;
                    }
                    let r = pack.shading_reflectance(
                        -wi[0] - wr[0],
                        -wi[1] - wr[1],
                        -wi[2] - wr[2],
                        lam,
                    );
                    let v = g * r * a;
                    if v * (c1 - c0) > top.0 {
                        top = (v * (c1 - c0), ci, p.to_degrees(), r);
                    }
                    s += v;
                }
                s *= (c1 - c0) * std::f64::consts::TAU / nphi as f64;
                let k = if ci < 0.01 {
                    0
                } else if ci < 0.1 {
                    1
                } else if ci < 0.3 {
                    2
                } else {
                    3
                };
                bands[k] += s;
            }
            let tot: f64 = bands.iter().sum();
            eprintln!("phi {:3.0} cr {cr:7.4}: total {tot:9.3}  ci<0.01 {:8.3} <0.1 {:8.3} <0.3 {:8.3} rest {:8.3}  top cell ci {:.4} phi {:.1} R {:.3e}", ph.to_degrees(), bands[0], bands[1], bands[2], bands[3], top.1, top.2, top.3);
        }
    }
}

/// The mean of frames `A` and `B` (EXR, linear light) written to `OUT`: the
/// mean of two seeds' references without rendering them again.
fn mean_frames() {
    use sunbeam_raster::LinearImage;
    let read =
        |k: &str| LinearImage::read_exr(std::path::Path::new(&std::env::var(k).unwrap())).unwrap();
    sunbeam_raster::linear::mean_of(&[read("A"), read("B")])
        .unwrap()
        .write_exr(std::path::Path::new(&std::env::var("OUT").unwrap()))
        .unwrap();
}

/// Runs the measurements named on the command line (parts of names; none:
/// all, those that read frames (`A=.. B=..`) only when `A` is set). Options
/// (`--bench`, given by `cargo bench`) are ignored.
fn main() {
    let names: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let frames = std::env::var_os("A").is_some();
    // (name, measurement, reads the frames A and B)
    let all: [(&str, fn(), bool); 7] = [
        ("noise_at_shading_points", noise_at_shading_points, false),
        ("lobe_technique_alone", lobe_technique_alone, false),
        ("r_inside_bins", r_inside_bins, false),
        ("worst_pixels", worst_pixels, true),
        ("grazing_views", grazing_views, false),
        ("grazing_band_sum", grazing_band_sum, false),
        ("mean_frames", mean_frames, true),
    ];
    for (name, f, reads) in all {
        let picked = if names.is_empty() {
            !reads || frames
        } else {
            names.iter().any(|n| name.contains(n.as_str()))
        };
        if picked {
            println!("## {name}");
            f();
        }
    }
}
