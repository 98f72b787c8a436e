//! Frame-time benchmark (not a timed test): the default (response table), direct,
//! thesis and Lambert shaders in the same run, each with its colour error against
//! the CPU reference. `cargo bench -p sunbeam --bench play` (release; the root package's: it
//! needs the player and the reference).
//! Environment: PLAY_BENCH_SIZE (512), PLAY_BENCH_ERR_SIZE (256), PLAY_BENCH_FRAMES (5),
//! PLAY_BENCH_SCENES (sphere,snake,quad), PLAY_BENCH_MODES (default,thesis,lambert,direct).

use std::sync::Arc;
use std::time::Instant;
use sunbeam_frame::{fixtures, Prepared};
use sunbeam_pack::build::BuildOptions;
use sunbeam_pack::{Basis, Model};
use sunbeam_raster::Options;
use sunbeam_render::{Gpu, Mode, Settings};

fn env_u32(k: &str, d: u32) -> u32 {
    std::env::var(k)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(d)
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let size = env_u32("PLAY_BENCH_SIZE", 512);
    let err_size = env_u32("PLAY_BENCH_ERR_SIZE", 256);
    let frames = env_u32("PLAY_BENCH_FRAMES", 5);
    let scenes = std::env::var("PLAY_BENCH_SCENES").unwrap_or_else(|_| "sphere,snake,quad".into());
    let modes = std::env::var("PLAY_BENCH_MODES")
        .unwrap_or_else(|_| "default,thesis,lambert,direct".into());
    let Some(data) = sunbeam_common::testdata::shared_file("snake/BlazingBump.bmp") else {
        return;
    };
    let dir = data.parent().unwrap().to_path_buf();
    let gpu = Gpu::headless(Default::default()).expect("GPU adapter");
    println!("adapter: {}", gpu.describe());
    println!("| scene | mode | pack | setup ms | first frame ms | median frame ms ({size}x{size}) | vs thesis | CIEDE2000 mean / p99 ({err_size}x{err_size}) |");
    println!("|---|---|---|---|---|---|---|---|");
    for sc in scenes.split(',') {
        let (patch, (scene, mesh)) = match sc {
            "sphere" => (fixtures::ELAPHE, fixtures::sphere_scene([size, size])),
            "snake" => (fixtures::XENO, fixtures::snake_scene([size, size]).unwrap()),
            "quad" => (fixtures::BLAZED, fixtures::quad_scene([size, size])),
            other => panic!("unknown scene {other}"),
        };
        let cheb = Arc::new(fixtures::pack(&patch, &dir, &BuildOptions::default()).unwrap());
        let thesis_opts = BuildOptions {
            basis: Basis::Taylor,
            model: Model::Tiled,
            terms: Some(39),
            ..Default::default()
        };
        let taylor = Arc::new(fixtures::pack(&patch, &dir, &thesis_opts).unwrap());
        let p_main = fixtures::prepared(scene.clone(), mesh.clone(), Some(cheb.clone()));
        let p_thesis = fixtures::prepared(scene.clone(), mesh.clone(), Some(taylor.clone()));
        let t = Instant::now();
        let reference = sunbeam_raster::render_prepared(
            &p_main,
            &Options {
                size: Some([err_size, err_size]),
                ..Default::default()
            },
        );
        eprintln!(
            "{sc}: CPU reference {err_size}x{err_size} in {:.1?}",
            t.elapsed()
        );
        let mut thesis_ms = None;
        let mut rows = Vec::new();
        for m in modes.split(',') {
            let mode: Mode = m.parse().unwrap();
            let p: &Prepared = if mode == Mode::Thesis {
                &p_thesis
            } else {
                &p_main
            };
            let st = Settings {
                mode,
                ..Default::default()
            };
            let (times, _) =
                sunbeam_render::bench_headless(&gpu, p, &st, [size, size], frames).unwrap();
            let small =
                sunbeam_render::render_headless(&gpu, p, &st, Some([err_size, err_size]), 1)
                    .unwrap();
            let d = sunbeam_frame::compare(&small, &reference).unwrap();
            let med = times.median_ms();
            if mode == Mode::Thesis {
                thesis_ms = Some(med);
            }
            let pk = if mode == Mode::Thesis {
                format!("taylor/tiled {} terms", taylor.manifest.terms)
            } else if mode == Mode::Lambert {
                "-".into()
            } else {
                format!("chebyshev/window {} terms", cheb.manifest.terms)
            };
            rows.push((
                sc.to_string(),
                m.to_string(),
                pk,
                times.setup_ms,
                times.first_ms,
                med,
                d,
            ));
            eprintln!("{sc} {m}: median {med:.1} ms, {d}");
        }
        for (sc, m, pk, setup, first, med, d) in rows {
            let ratio = thesis_ms
                .map(|t| format!("{:.1}x", t / med))
                .unwrap_or_else(|| "-".into());
            println!(
                "| {sc} | {m} | {pk} | {setup:.0} | {first:.1} | {med:.1} | {ratio} | {:.3} / {:.3} |",
                d.mean, d.p99
            );
        }
    }
}
