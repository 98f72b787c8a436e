//! What sunbeam-pack does with its parsed arguments.

use crate::args::*;
use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;
use sunbeam_afm::height::{read_height_field, HeightOptions};
use sunbeam_common::cli::PixelSize;
use sunbeam_common::{depfile, Result};
use sunbeam_pack::build::{self, BuildOptions, FieldRef};
use sunbeam_pack::formats::{write_pack, OutputKind};
use sunbeam_pack::manifest::Source;
use sunbeam_pack::{Basis, Precision};

/// The triangles of a scene's mesh file (for `--scene`).
fn mesh_triangles(path: &Path) -> Result<sunbeam_scene::reach::Triangles> {
    let m = sunbeam_mesh::load_scene_mesh(path)?;
    Ok((m.positions, m.indices))
}

pub(crate) fn run(cli: Cli) -> Result<()> {
    let t0 = Instant::now();
    let kind = OutputKind::from_path(&cli.output, cli.split, cli.atlas)?;
    let coherence = cli.coherence;
    let (mut lmin, mut lmax) = cli.lambda;
    let mut warnings: Vec<String> = vec![];
    let mut notes: Vec<String> = vec![];

    let field = read_height_field(
        &cli.height,
        &HeightOptions {
            channel: cli.channel.clone(),
            pixel_size: cli.pixel_size.map(PixelSize::pair),
            z_range: cli.z_range,
            allow_implausible: cli.allow_implausible,
            ..HeightOptions::default()
        },
    )?
    .field;
    let fr = FieldRef {
        width: field.width,
        height: field.height,
        dx: field.dx,
        dy: field.dy,
        data: &field.data,
    };

    let mut max_w = cli.max_w;
    let mut freq_limit = None;
    let mut inputs = vec![cli.height.clone()];
    if let Some(sp) = &cli.scene {
        let b = sunbeam_scene::reach::reach_of_file(sp, max_w, mesh_triangles)?;
        inputs.extend(b.inputs.iter().cloned());
        if let Some((a, z)) = b.lambda {
            lmin = lmin.max(a);
            lmax = lmax.min(z);
        }
        max_w = max_w.min(b.max_w);
        freq_limit = Some(b.freq_limit(lmin));
        notes.extend(b.notes.iter().cloned());
    }

    let model = cli.model;
    let basis = match cli.basis {
        BasisArg::Chebyshev => Basis::Chebyshev,
        BasisArg::Taylor => Basis::Taylor,
    };
    let precision = match cli.precision {
        PrecisionArg::F32 => Precision::F32,
        PrecisionArg::F16 => Precision::F16,
    };
    let p = &field.provenance;
    let mut o = BuildOptions {
        basis,
        model,
        coherence_m: coherence,
        lambda_min_m: lmin,
        lambda_max_m: lmax,
        max_error: cli.max_error.unwrap_or(1e-4),
        terms: cli.terms,
        precision,
        max_w,
        freq_limit_per_m: freq_limit,
        taps: cli.taps,
        generator: format!("{TOOL} {}", env!("CARGO_PKG_VERSION")),
        source: Source {
            file: p.source_file.clone(),
            format: p.source_format.clone(),
            channel: p.channel.clone(),
            processing: p.processing.clone(),
        },
        notes,
        ..BuildOptions::default()
    };
    if let Some(t) = cli.threads {
        o.threads = t.max(1);
    }
    warnings.extend(build::check_field(fr, lmin));
    let plan = build::plan(fr, &o)?;
    let m = &plan.manifest;
    if basis == Basis::Taylor && m.error.f32_rounding_estimate > 1e-3 {
        warnings.push(format!(
            "Taylor basis at |t| up to {:.1}: float32 evaluation loses about {:.1e} to cancellation \
             (PHYSICS.md 3); use --basis chebyshev",
            m.t_max, m.error.f32_rounding_estimate
        ));
    }
    if m.error.tolerance.is_none() && m.error.series_bound > 1e-3 {
        warnings.push(format!(
            "--terms {}: the series bound on |dR| is {:.2e} at |t| = {:.1}",
            m.terms, m.error.series_bound, m.t_max
        ));
    }
    if m.crop.width > 8192 || m.crop.height > 8192 {
        warnings.push(format!(
            "the crop is {}x{} texels: many GPUs limit textures to 8192",
            m.crop.width, m.crop.height
        ));
    }
    if !cli.quiet {
        for w in &warnings {
            eprintln!("{TOOL}: warning: {w}");
        }
        for n in &m.notes {
            eprintln!("{TOOL}: note: {n}");
        }
    }
    if cli.verbose && !cli.quiet {
        eprintln!(
            "{TOOL}: {}x{} px, {:?} basis, {:?} model, {} terms (|t| <= {:.2}, bound {:.2e}), crop {}x{}",
            field.width, field.height, basis, model, m.terms, m.t_max, m.error.series_bound, m.crop.width, m.crop.height
        );
    }
    let progress_on = !cli.quiet && std::io::stderr().is_terminal();
    let mut progress = |done: usize, total: usize| {
        if progress_on {
            let w = 30;
            let f = done * w / total.max(1);
            eprint!(
                "\r{TOOL}: [{}{}] {done}/{total} terms",
                "#".repeat(f),
                " ".repeat(w - f)
            );
            if done == total {
                eprintln!();
            }
        }
    };
    let pack = build::run(fr, &plan, o.threads, &mut progress)?;
    let pack_secs = t0.elapsed().as_secs_f64();
    let response_path = cli.response_out.clone().or_else(|| {
        (cli.response || cli.response_exr.is_some() || cli.response_sky.is_some())
            .then(|| sunbeam_response::sidecar_path(&cli.output))
    });
    let sky = match &response_path {
        Some(_) => response_sky(&cli, &mut inputs)?,
        None => None,
    };
    let response = match &response_path {
        Some(_) => {
            let t = Instant::now();
            let ro = sunbeam_response::Options {
                lambda_samples: cli.response_lambda.clamp(1, 4096),
                budget_bytes: cli.response_budget,
                grid: None,
            };
            let r = sunbeam_response::build(&pack, &ro);
            let t_point = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let e = sunbeam_response::env_file::build(&pack, sky.as_ref(), &ro);
            let t_env = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let depth = sunbeam_response::cells::DEFAULT_DEPTH;
            let counts: Vec<(usize, usize)> = if cli.response_cells.is_empty() {
                // the player's default for this pack
                vec![(
                    sunbeam_response::cells::first_frame_top_for(&pack.manifest),
                    depth,
                )]
            } else {
                cli.response_cells
                    .iter()
                    .map(|&n| (n as usize, depth))
                    .collect()
            };
            let c = sunbeam_response::cells_file::build(&e, &counts);
            Some((r, t_point, e, t_env, c, t.elapsed().as_secs_f64()))
        }
        None => None,
    };
    let mut files = write_pack(&pack, &cli.output, kind)?;
    if let (Some(rp), Some((r, _, e, _, c, _))) = (&response_path, &response) {
        let bytes = sunbeam_response::ktx2::encode(r);
        sunbeam_common::output::write_atomic(rp, &bytes)?;
        files.push((rp.clone(), bytes.len() as u64));
        let ep = beside_point_map(rp, "env-response");
        let bytes = sunbeam_response::env_file::encode(e);
        sunbeam_common::output::write_atomic(&ep, &bytes)?;
        files.push((ep, bytes.len() as u64));
        let cp = beside_point_map(rp, "env-cells");
        let bytes = sunbeam_response::cells_file::encode(c);
        sunbeam_common::output::write_atomic(&cp, &bytes)?;
        files.push((cp, bytes.len() as u64));
        if let Some(ep) = &cli.response_exr {
            let bytes = sunbeam_response::exr::encode(r)?;
            sunbeam_common::output::write_atomic(ep, &bytes)?;
            files.push((ep.clone(), bytes.len() as u64));
        }
    }
    let mut bytes: u64 = files.iter().map(|f| f.1).sum();
    if let Some(mp) = &cli.manifest {
        let s = pack.manifest.to_json_pretty();
        sunbeam_common::output::write_atomic(mp, s.as_bytes())?;
        bytes += s.len() as u64;
    }
    if let Some(d) = &cli.depfile {
        let outs: Vec<&std::path::Path> = files.iter().map(|f| f.0.as_path()).collect();
        let ins: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
        depfile::write(d, &outs, &ins)?;
    }
    let secs = t0.elapsed().as_secs_f64();
    if cli.json {
        let m = &pack.manifest;
        let report = serde_json::json!({
            "tool": TOOL,
            "version": env!("CARGO_PKG_VERSION"),
            "input": cli.height.display().to_string(),
            "outputs": files.iter().map(|f| f.0.display().to_string()).collect::<Vec<_>>(),
            "terms": m.terms,
            "basis": m.basis,
            "model": m.model,
            "precision": m.precision,
            "crop": [m.crop.width, m.crop.height],
            "padding": m.padding,
            "grid": m.grid,
            "t_max": m.t_max,
            "error_bound": m.error.series_bound,
            "tolerance": m.error.tolerance,
            "f32_rounding_estimate": m.error.f32_rounding_estimate,
            "lambda_m": [m.lambda_min_m, m.lambda_max_m],
            "max_w": m.max_w,
            "bytes_written": bytes,
            "time_s": secs,
            "pack_time_s": pack_secs,
            "response": response.as_ref().map(|(r, t, e, te, c, tc)| serde_json::json!({
                "grid": [r.info.grid.n_theta, r.info.grid.n_rho, r.info.grid.n_s],
                "r0": r.info.grid.r0,
                "lambda_samples": r.info.lambda_samples,
                "bytes": r.byte_len(),
                "time_s": t,
                "environment_maps": e.maps.len(),
                "environment_sun": e.info.sun_key.is_some(),
                "environment_bytes": e.maps.iter().map(|m| m.byte_len()).sum::<usize>(),
                "environment_time_s": te,
                "cells": c.info.sets.iter().map(|s| serde_json::json!({
                    "basis": s.basis, "cells": s.cells, "depth": s.depth,
                    "n_top": s.n_top, "nodes": s.nodes,
                })).collect::<Vec<_>>(),
                "cells_time_s": tc,
            })),
            "warnings": warnings,
            "notes": m.notes,
        });
        println!("{}", serde_json::to_string_pretty(&report).expect("json"));
    } else if !cli.quiet && cli.verbose {
        eprintln!(
            "{TOOL}: wrote {} ({} bytes) in {:.2} s",
            cli.output.display(),
            bytes,
            secs
        );
    }
    Ok(())
}

/// The sky whose sun's map the environment's maps hold: `--response-sky`'s
/// scene's (None for a map or no environment), else the default scene's.
fn response_sky(
    cli: &Cli,
    inputs: &mut Vec<std::path::PathBuf>,
) -> Result<Option<sunbeam_light::sky::Sky>> {
    let env = match &cli.response_sky {
        Some(p) => {
            inputs.push(p.clone());
            sunbeam_scene::Scene::load(p)?.environment
        }
        None => Some(sunbeam_scene::Scene::default_sky()),
    };
    Ok(env.and_then(|e| {
        e.sky.map(|s| {
            sunbeam_light::sky::Sky::new(
                s.sun_elevation_deg,
                s.sun_azimuth_deg,
                s.turbidity,
                e.intensity,
            )
        })
    }))
}

/// Where the environment's maps (`kind` "env-response") and the first-frame
/// cells ("env-cells") go: beside the point map `dir/NAME.response.ktx2` as
/// `dir/NAME.KIND.ktx2` (for another name `dir/X.ktx2`, `dir/X.KIND.ktx2`).
fn beside_point_map(point_map: &Path, kind: &str) -> std::path::PathBuf {
    let name = point_map
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = match name.strip_suffix(".response.ktx2") {
        Some(stem) => stem.to_string(),
        None => point_map
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
    };
    point_map.with_file_name(format!("{stem}.{kind}.ktx2"))
}
