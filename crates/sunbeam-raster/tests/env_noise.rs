//! Measurement, not a check (ignored): the environment estimator's noise at
//! single shading points (docs/LIGHTING.md "Noise"). For a pack (the ridge
//! field below, or `SUNBEAM_PACK=path.ktx2`), a few views under a constant
//! white map and under the sky, it prints the mean Y, one sample's relative
//! standard deviation of Y, and the relative standard deviation of X, Y, Z
//! of a 256-sample pixel (wavelengths stratified as in the renderer) over 48
//! pixels.
//!   cargo test --release -p sunbeam-raster --test env_noise -- --ignored --nocapture

use std::f64::consts::PI;
use std::sync::Arc;
use sunbeam_light::{sky::Sky, EnvMap, Environment};
use sunbeam_optics::colour;
use sunbeam_pack::{build::BuildOptions, FieldRef, Pack};
use sunbeam_raster::environment::{EnvShader, Uniforms};

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

#[test]
#[ignore]
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
        for (th, ph) in [(0.0f64, 0.0f64), (40.0, 30.0), (65.0, 100.0), (80.0, 200.0)] {
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
                    let xyz = y_of(u);
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
