//! What sunbeam-play does with its parsed arguments.

use crate::args::*;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Duration;
use sunbeam_common::{Error, Result};
use sunbeam_frame::{Image, LinearImage, Prepared};
use sunbeam_optics::colour::ToneCurve;
use sunbeam_render::env::EnvEstimator;
use sunbeam_render::window::{self, WindowOptions};
use sunbeam_render::{Backend, Gpu, Mode, Settings};
use sunbeam_scene::Scene;

fn load_scene(cli: &Cli) -> Result<Scene> {
    let mut scene = match (&cli.scene, &cli.mesh) {
        (Some(_), Some(_)) => {
            return Err(Error::usage(
                "give either SCENE.json or --mesh/--pack, not both",
            ))
        }
        (Some(s), None) => {
            if cli.pack.is_some() {
                return Err(Error::usage(
                    "--pack goes with --mesh (a scene file names its own packs)",
                ));
            }
            Scene::load(s)?
        }
        (None, Some(m)) => sunbeam_frame::default_scene(
            m,
            cli.pack.as_deref(),
            cli.lighting.parse().map_err(Error::usage)?,
        )?,
        (None, None) => {
            return Err(Error::usage(
                "nothing to render: give SCENE.json or --mesh M.glb --pack P.ktx2",
            ))
        }
    };
    if let Some(ev) = cli.exposure {
        if !ev.is_finite() {
            return Err(Error::usage("--exposure must be finite"));
        }
        scene.exposure = ev;
    }
    if let Some((w, h)) = cli.size {
        scene.size = [w as u32, h as u32];
        scene.validate()?;
    }
    Ok(scene)
}

/// `--msaa`, or its default: 1 for a headless frame accumulated under an
/// environment over more than one frame (the settled frame averages frames
/// jittered over the pixel, a box filter of one pixel; each frame's 4 samples
/// at +-0.375 px would widen it to 1.75 px, which blurred the snake's
/// silhouettes against the reference: CIEDE2000 p99 19.6 against 9.3 at 256
/// frames), else 4: a single frame (the first-frame estimator's) has no
/// jitter to anti-alias it, and without MSAA its silhouettes are one sample
/// per pixel (the sky-lit sphere's edge pixels at p99 34.9 against 13.9 with
/// MSAA, docs/bench/play.md "The first frame with the energy bound").
fn msaa_for(cli: &Cli, scene: &Scene) -> u32 {
    let accumulating = scene.environment.is_some() && headless_frames(cli).is_some_and(|n| n > 1);
    cli.msaa.unwrap_or(if accumulating { 1 } else { 4 })
}

/// The frames a headless run writes (their mean, under an environment);
/// None for the window and `--bench`.
fn headless_frames(cli: &Cli) -> Option<u32> {
    (cli.headless && !cli.bench).then(|| cli.frames.unwrap_or(1))
}

/// `--env-estimator`, `auto` resolved: a single headless frame is the whole
/// product, so it takes the estimator that is right in one frame (`cells`:
/// a Monte Carlo frame alone is coloured grain, docs/LIGHTING.md "The first
/// frame"); the window, `--bench` (the window's frame times) and more than
/// one `--frames` (the settled frame: the mean of progressive frames) take `monte-carlo`,
/// whose frames cost a few Lambert frames where the cells' cost tens.
fn estimator_for(cli: &Cli) -> EnvEstimator {
    match cli.env_estimator {
        EnvEstimatorArg::Cells => EnvEstimator::Cells,
        EnvEstimatorArg::MonteCarlo => EnvEstimator::MonteCarlo,
        EnvEstimatorArg::Auto => {
            if headless_frames(cli) == Some(1) {
                EnvEstimator::Cells
            } else {
                EnvEstimator::MonteCarlo
            }
        }
    }
}

fn settings(cli: &Cli, scene: &Scene) -> Result<Settings> {
    let mut mode: Mode = cli.mode;
    if cli.thesis && cli.lambert {
        return Err(Error::usage("--thesis and --lambert exclude each other"));
    }
    if cli.thesis {
        mode = Mode::Thesis;
    }
    if cli.lambert {
        mode = Mode::Lambert;
    }
    if cli.lambda_samples == 0 || cli.lambda_samples > 4096 {
        return Err(Error::usage("--lambda-samples must be 1..4096"));
    }
    if let Some(t) = cli.term_tolerance {
        if !(t.is_finite() && t > 0.0) {
            return Err(Error::usage("--term-tolerance must be positive"));
        }
    }
    let curve: ToneCurve = cli.tone;
    let msaa = msaa_for(cli, scene);
    if msaa != 1 && msaa != 4 {
        return Err(Error::usage("--msaa must be 1 or 4"));
    }
    if !(1..=8).contains(&cli.supersample) {
        return Err(Error::usage("--supersample must be 1..8"));
    }
    if cli.edge_supersample > 0 && (!cli.headless || cli.cpu || cli.bench) {
        return Err(Error::usage(
            "--edge-supersample refines a headless GPU frame: it needs --headless, not --cpu or --bench",
        ));
    }
    if cli.edge_levels > 1 {
        let last = cli.edge_supersample << (cli.edge_levels - 1);
        if cli.edge_supersample == 0 || cli.edge_supersample % 2 == 1 {
            return Err(Error::usage(
                "--edge-levels above 1 needs an even --edge-supersample (its quarter-lattices decide the next level)",
            ));
        }
        if last > sunbeam_render::refine::MAX_POSITIONS {
            return Err(Error::usage(format!(
                "--edge-supersample {} with --edge-levels {} reaches {last} positions per pixel side; at most {}",
                cli.edge_supersample,
                cli.edge_levels,
                sunbeam_render::refine::MAX_POSITIONS
            )));
        }
    }
    if cli.env_samples == 0 || cli.env_samples > 64 {
        return Err(Error::usage("--env-samples must be 1..64"));
    }
    Ok(Settings {
        env_samples: cli.env_samples,
        env_estimator: estimator_for(cli),
        mode,
        lambda_samples: cli.lambda_samples,
        curve,
        term_tolerance: cli.term_tolerance,
        msaa,
        footprint: !cli.no_footprint,
        env_hot_spots: cli.env_hot_spots as usize,
        env_hot_threshold: cli.env_hot_threshold,
        env_cells_rate: cli.env_cells_rate,
        env_cells_half: cli.env_cells_half,
        env_cells: (
            cli.env_cells.map(|n| n as usize),
            sunbeam_render::env::ENV_CELLS_DEPTH,
        ),
        ..Default::default()
    })
}

fn is_exr(p: &std::path::Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

fn inputs(p: &Prepared, cli: &Cli) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = cli.scene.iter().cloned().collect();
    for m in &p.scene.meshes {
        if !sunbeam_scene::geometry::is_builtin(&m.mesh) {
            v.push(m.mesh.clone());
        }
        v.extend(m.pack.iter().cloned());
        // The default mode reads the response map beside the pack when it is there.
        let side = m.pack.as_deref().map(sunbeam_render::response::sidecar);
        v.extend(side.filter(|s| s.is_file()));
    }
    v.dedup();
    v
}

pub(crate) fn run(cli: Cli) -> Result<()> {
    sunbeam_render::gpu::quiet_display_probe();
    if let Some(lang) = cli.export_shader {
        return export_shader(lang, &cli);
    }
    let scene = load_scene(&cli)?;
    let st = settings(&cli, &scene)?;
    if let Some(dir) = &cli.export_environment {
        return export_environment(&scene, &st, dir, cli.quiet);
    }
    let backend: Backend = cli.backend;
    // The default mode draws with the response maps: a pack with current maps
    // beside it is read as its manifest only (the CPU renderer needs the terms,
    // and so does building the environment's maps when they are not current).
    let t_prepare = std::time::Instant::now();
    let prepared = if st.mode == Mode::Default && !cli.cpu && scene.environment.is_none() {
        sunbeam_frame::prepare_with(&scene, &sunbeam_render::response::load_pack)?
    } else if st.mode == Mode::Default && !cli.cpu {
        sunbeam_frame::prepare_with(&scene, &sunbeam_render::response::load_pack_for_environment)?
    } else {
        sunbeam_frame::prepare(&scene)?
    };
    let headless = cli.headless || cli.bench || cli.cpu;
    if !headless {
        if cli.compare.is_some() || cli.depfile.is_some() {
            return Err(Error::usage("--compare and --depfile need --headless"));
        }
        let opts = WindowOptions {
            backend,
            settings: st,
            size: scene.size,
            frames: cli.frames,
            hold: Duration::from_secs_f64(cli.hold_secs.max(0.0)),
            screenshot: cli.output.clone(),
            title: "sunbeam-play".into(),
        };
        return window::run(prepared, opts);
    }
    if cli.output.is_none() && !cli.bench {
        return Err(Error::usage("--headless needs -o FRAME.png"));
    }
    let size = scene.size;
    let mut report = serde_json::json!({
        "tool": "sunbeam-play",
        "size": size,
        // reading the scene's meshes and packs (the environment's maps are
        // read or built in the renderer's set-up, `setup_ms`)
        "prepare_ms": t_prepare.elapsed().as_secs_f64() * 1e3,
        "mode": format!("{:?}", st.mode).to_lowercase(),
        "msaa": st.msaa,
    });
    if scene.environment.is_some() {
        report["env_estimator"] = match st.env_estimator {
            EnvEstimator::Cells => "cells",
            EnvEstimator::MonteCarlo => "monte-carlo",
        }
        .into();
        if st.env_estimator == EnvEstimator::Cells {
            // each pack's top cut (the first pack's as the number)
            let counts: Vec<usize> = prepared
                .meshes
                .iter()
                .filter_map(|(_, m)| m.pack.as_ref())
                .map(|p| sunbeam_render::env::pack_cells(st.env_cells, p).0)
                .collect();
            if let Some(&first) = counts.first() {
                report["env_cells"] = first.into();
                if counts.iter().any(|&c| c != first) {
                    report["env_cells_per_pack"] = counts.into();
                }
            }
        }
    }
    if let Some((line, c)) = sunbeam_frame::environment_clamped_warning(&prepared) {
        if !cli.quiet {
            eprintln!("sunbeam-play: warning: {line}");
        }
        report["environment_negatives_zeroed"] = serde_json::json!({"values": c.values, "texels": c.texels, "min": c.min, "bound": c.bound});
    }
    let image: LinearImage = if cli.cpu {
        let t = std::time::Instant::now();
        let k = cli.supersample.max(1);
        let opts = sunbeam_raster::Options {
            curve: st.curve,
            samples: k * k,
            ..Default::default()
        };
        let img = sunbeam_raster::render_prepared_linear(&prepared, &opts)?;
        report["renderer"] = "cpu reference (sunbeam-raster)".into();
        report["render_ms"] = (t.elapsed().as_secs_f64() * 1e3).into();
        img
    } else {
        let gpu = Gpu::headless(backend)?;
        report["adapter"] = gpu.describe().into();
        if st.env_estimator == EnvEstimator::Cells
            && prepared.environment.is_some()
            && gpu.is_cpu()
            && !cli.quiet
            && !cli.bench
        {
            eprintln!(
                "sunbeam-play: the first frame under an environment (--env-estimator cells) on a \
                 CPU rasteriser can take a minute or more at 512 x 512; --msaa 1 is faster on \
                 dense meshes (aliased silhouettes), --env-estimator monte-carlo quick and noisy"
            );
        }
        if cli.bench {
            let frames = cli.frames.unwrap_or(10).max(2);
            let (times, img) = sunbeam_render::bench_headless(&gpu, &prepared, &st, size, frames)?;
            report["setup_ms"] = times.setup_ms.into();
            report["first_frame_ms"] = times.first_ms.into();
            report["frame_ms_median"] = times.median_ms().into();
            report["frame_ms_mean"] = times.mean_ms().into();
            report["frame_ms"] = times.rest_ms.clone().into();
            report["msaa"] = st.msaa.into();
            // Environment scenes: the Lambert baseline in the same run (same
            // load on the machine), and the ratio.
            let lambert = if prepared.environment.is_some() && st.mode == Mode::Default {
                let lst = Settings {
                    mode: Mode::Lambert,
                    ..st.clone()
                };
                let (lt, _) = sunbeam_render::bench_headless(&gpu, &prepared, &lst, size, frames)?;
                report["lambert_frame_ms_median"] = lt.median_ms().into();
                report["ratio_to_lambert"] = (times.median_ms() / lt.median_ms().max(1e-9)).into();
                Some(lt.median_ms())
            } else {
                None
            };
            if !cli.json {
                println!(
                    "{} {:?} {}x{}: setup {:.0} ms, first frame {:.1} ms, then median {:.2} ms / mean {:.2} ms over {} frames ({:.1} fps)",
                    gpu.describe(),
                    st.mode,
                    size[0],
                    size[1],
                    times.setup_ms,
                    times.first_ms,
                    times.median_ms(),
                    times.mean_ms(),
                    times.rest_ms.len(),
                    1e3 / times.median_ms().max(1e-6)
                );
                if let Some(l) = lambert {
                    println!(
                        "environment (accumulation reset every frame): median {:.2} ms vs --lambert {:.2} ms in the same run: {:.2}x",
                        times.median_ms(),
                        l,
                        times.median_ms() / l.max(1e-9)
                    );
                }
            }
            img
        } else {
            let t = std::time::Instant::now();
            let r = sunbeam_render::Renderer::new(
                &gpu,
                &prepared,
                &st,
                sunbeam_render::OFFSCREEN_FORMAT,
            )?;
            for w in &r.warnings {
                eprintln!("sunbeam-play: warning: {w}");
            }
            if !cli.quiet {
                for n in &r.notes {
                    eprintln!("sunbeam-play: {n}");
                }
            }
            report["setup_ms"] = (t.elapsed().as_secs_f64() * 1e3).into();
            if report.get("env_cells").is_some() {
                // the pre-passes' grid (0: none, every fragment walks)
                report["env_cells_rate"] = r.env_cells_rate().into();
                // the grid mixed from every other point where smooth
                report["env_cells_half"] = r.env_cells_half().into();
            }
            let k = cli.supersample.max(1);
            let mut target = sunbeam_render::Offscreen::new(&gpu, &r, size[0] * k, size[1] * k)?;
            let state = sunbeam_render::FrameState::from_scene(&prepared);
            let t = std::time::Instant::now();
            let (sub, coverage) =
                target.render_frames_with_coverage(&gpu, &r, &state, cli.frames.unwrap_or(1))?;
            let mut img = sub.downsample(k);
            if cli.edge_supersample > 0 {
                let te = std::time::Instant::now();
                let mut flags =
                    sunbeam_render::refine::flag_pixels(&sub, &coverage, k, cli.edge_threshold);
                // each level refines the last one's unsettled pixels at twice the positions
                let (mut m, mut levels, mut pixels, mut tiles) =
                    (cli.edge_supersample, vec![], 0, 0);
                for level in 0..cli.edge_levels {
                    let tl = std::time::Instant::now();
                    let done = sunbeam_render::refine::refine(
                        &gpu,
                        &r,
                        &state,
                        &mut img,
                        &flags,
                        m,
                        cli.edge_threshold,
                    )?;
                    if level == 0 {
                        pixels = done.pixels;
                    }
                    tiles += done.tiles;
                    levels.push(serde_json::json!({
                        "positions": m,
                        "pixels": done.pixels,
                        "tiles": done.tiles,
                        "unsettled": done.unsettled.iter().filter(|&&u| u).count(),
                        "ms": tl.elapsed().as_secs_f64() * 1e3,
                    }));
                    flags = done.unsettled;
                    m *= 2;
                }
                report["edge_refine"] = serde_json::json!({
                    "positions": cli.edge_supersample,
                    "threshold": cli.edge_threshold,
                    "pixels": pixels,
                    "tiles": tiles,
                    "levels": levels,
                    "ms": te.elapsed().as_secs_f64() * 1e3,
                });
            }
            report["render_ms"] = (t.elapsed().as_secs_f64() * 1e3).into();
            if r.progressive() {
                // The environment's Monte Carlo frames, averaged (the settled frame).
                report["accumulated_frames"] = target.frames().into();
            }
            img
        }
    };
    if let Some(refp) = &cli.compare {
        let d = if is_exr(refp) {
            let reference = LinearImage::read_exr(refp)?;
            sunbeam_frame::compare_linear(&image, &reference)
                .map_err(|e| e.context(refp.display()))?
        } else {
            let reference = Image::read_png(refp)?;
            let disp = image.display(st.curve);
            let q = Image::from_rgba8(disp.width, disp.height, &disp.to_rgba8());
            sunbeam_frame::compare(&q, &reference).map_err(|e| e.context(refp.display()))?
        };
        report["ciede2000"] = serde_json::json!({"mean": d.mean, "p99": d.p99, "max": d.max});
        if !cli.json && !cli.quiet {
            println!("against {}: {d}", refp.display());
        }
    }
    if let Some(out) = &cli.output {
        if is_exr(out) {
            image.write_exr(out)?;
        } else {
            image.display(st.curve).write_png(out)?;
        }
        report["output"] = out.display().to_string().into();
        if let Some(dep) = &cli.depfile {
            let ins = inputs(&prepared, &cli);
            let refs: Vec<&std::path::Path> = ins.iter().map(|p| p.as_path()).collect();
            sunbeam_common::depfile::write(dep, &[out.as_path()], &refs)?;
        }
        if !cli.json && !cli.quiet && std::io::stderr().is_terminal() {
            eprintln!("wrote {}", out.display());
        }
    }
    if cli.json {
        println!("{report}");
    }
    Ok(())
}

/// `--export-shader LANG -o FILE`: the material for another engine (docs/ENGINES.md).
fn export_shader(lang: sunbeam_render::export::Lang, cli: &Cli) -> Result<()> {
    let out = cli
        .output
        .as_ref()
        .ok_or_else(|| Error::usage("--export-shader needs -o FILE"))?;
    let bytes = sunbeam_render::export::export(lang)?;
    sunbeam_common::output::write_atomic(out, &bytes)?;
    if !cli.quiet {
        eprintln!(
            "sunbeam-play: wrote {} ({} bytes)",
            out.display(),
            bytes.len()
        );
    }
    Ok(())
}

/// `SCENE.json --export-environment DIR`: the environment's files for engines
/// (sunbeam_render::env_export, docs/ENGINES.md "Environment").
fn export_environment(
    scene: &Scene,
    st: &Settings,
    dir: &std::path::Path,
    quiet: bool,
) -> Result<()> {
    let prepared =
        sunbeam_frame::prepare_with(scene, &sunbeam_render::response::load_pack_for_environment)?;
    if let Some((line, _)) = sunbeam_frame::environment_clamped_warning(&prepared) {
        if !quiet {
            eprintln!("sunbeam-play: warning: {line}");
        }
    }
    let (files, notes) = sunbeam_render::env_export::export(
        &prepared,
        &st.response,
        st.env_cells,
        st.hot_spot_options(),
        dir,
    )?;
    if !quiet {
        for n in &notes {
            eprintln!("sunbeam-play: {n}");
        }
        eprintln!(
            "sunbeam-play: wrote {} files into {}",
            files.len(),
            dir.display()
        );
    }
    Ok(())
}
