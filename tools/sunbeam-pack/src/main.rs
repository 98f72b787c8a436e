//! sunbeam-pack: height field -> diffraction term pack (KTX2 / EXR). See docs/PACK.md.

use clap::{Parser, ValueEnum};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;
use sunbeam_afm::height::{read_height_field, HeightOptions};
use sunbeam_common::cli::{length_range, pixel_size, positive_length, PixelSize};
use sunbeam_common::{depfile, Result};
use sunbeam_pack::build::{self, BuildOptions, FieldRef};
use sunbeam_pack::formats::{write_pack, OutputKind};
use sunbeam_pack::manifest::Source;
use sunbeam_pack::{Basis, Model, Precision};

const TOOL: &str = "sunbeam-pack";

#[derive(Debug, Clone, Copy, ValueEnum)]
enum BasisArg {
    Chebyshev,
    Taylor,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum PrecisionArg {
    F32,
    F16,
}

/// Build a diffraction term pack (KTX2 2D array or EXR) from a height field.
#[derive(Parser, Debug)]
#[command(name = "sunbeam-pack", version, about, long_about = None)]
struct Cli {
    /// Height field: EXR/GSF from sunbeam-import, or any AFM file / image sunbeam-import reads.
    height: PathBuf,
    /// Output pack: PACK.ktx2 or PACK.exr.
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
    /// Basis of the height expansion.
    #[arg(long, value_enum, default_value = "chebyshev")]
    basis: BasisArg,
    /// Model of what lies beyond the patch (PHYSICS.md 2).
    #[arg(long, default_value = "window", value_parser = sunbeam_common::cli::one_of::<Model>(&Model::NAMES))]
    model: Model,
    /// Spatial coherence length of the light.
    #[arg(long, default_value = "65um", value_parser = positive_length)]
    coherence: f64,
    /// Wavelength range.
    #[arg(long, default_value = "380nm..780nm", value_parser = length_range)]
    lambda: (f64, f64),
    /// Bound on max |dR| that picks the term count.
    #[arg(long, conflicts_with = "terms")]
    max_error: Option<f64>,
    /// Fixed term count (the error bound is reported).
    #[arg(long)]
    terms: Option<usize>,
    /// Storage precision.
    #[arg(long, value_enum, default_value = "f32")]
    precision: PrecisionArg,
    /// Largest |w| = cos(theta_i) + cos(theta_r) to cover (2: all directions).
    #[arg(long, default_value_t = 2.0)]
    max_w: f64,
    /// Derive wavelength range, largest |w| and reachable frequencies from a scene (sunbeam-scene JSON).
    #[arg(long)]
    scene: Option<PathBuf>,
    /// EXR: one file per term (PACK.nNN.exr) with plain R/G channels.
    #[arg(long)]
    split: bool,
    /// EXR: all terms in one grid atlas with plain R/G channels.
    #[arg(long)]
    atlas: bool,
    /// Also write the manifest as JSON here.
    #[arg(long)]
    manifest: Option<PathBuf>,
    /// Kaiser-Bessel taps per axis (window model; even).
    #[arg(long, default_value_t = 6)]
    taps: usize,
    /// Pixel size for files without calibration (e.g. 65nm or 65nm,70nm).
    #[arg(long, value_parser = pixel_size)]
    pixel_size: Option<PixelSize>,
    /// Height of the full grey range for uncalibrated images (e.g. 375nm).
    #[arg(long, value_parser = positive_length)]
    z_range: Option<f64>,
    /// Channel to use (name or index) in multi-channel AFM files.
    #[arg(long)]
    channel: Option<String>,
    /// Accept NaN/Inf heights or a height range beyond 1 mm (docs/IMPORT.md).
    #[arg(long)]
    allow_implausible: bool,
    /// Worker threads (the output does not depend on it).
    #[arg(long)]
    threads: Option<usize>,
    /// Also write the response map the player and engines read (docs/PACK_FORMAT.md
    /// "Response map"): beside the pack as NAME.response.ktx2, or to --response-out.
    #[arg(long)]
    response: bool,
    /// Where to write the response map (implies --response).
    #[arg(long, value_name = "FILE.ktx2")]
    response_out: Option<PathBuf>,
    /// Also write the response map as an OpenEXR atlas for DCC tools (implies --response).
    #[arg(long, value_name = "FILE.exr")]
    response_exr: Option<PathBuf>,
    /// Wavelength samples of the response map's colour integral.
    #[arg(long, default_value_t = sunbeam_response::build::DEFAULT_LAMBDA_SAMPLES)]
    response_lambda: usize,
    /// Size bound of the response map (e.g. 64MiB; RGBA16F texels).
    #[arg(long, default_value = "64MiB")]
    response_budget: String,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
    /// Write a Make-style depfile.
    #[arg(long)]
    depfile: Option<PathBuf>,
    /// Quiet: no warnings or progress.
    #[arg(short, long)]
    quiet: bool,
    /// Verbose: print the plan.
    #[arg(short, long)]
    verbose: bool,
}

fn main() {
    sunbeam_common::cli::main(TOOL, run)
}

/// A byte count with an optional KiB/MiB/GiB suffix.
fn parse_bytes(s: &str) -> Result<usize> {
    let t = s.trim();
    let (num, mult) = [
        ("GiB", 1usize << 30),
        ("MiB", 1 << 20),
        ("KiB", 1 << 10),
        ("B", 1),
    ]
    .iter()
    .find_map(|(suf, m)| t.strip_suffix(suf).map(|n| (n.trim(), *m)))
    .unwrap_or((t, 1));
    match num.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 1.0 => Ok((v * mult as f64) as usize),
        _ => Err(sunbeam_common::Error::usage(format!(
            "--response-budget '{s}': give a size such as 64MiB"
        ))),
    }
}

/// The triangles of a scene's mesh file (for `--scene`).
fn mesh_triangles(path: &Path) -> Result<sunbeam_scene::reach::Triangles> {
    let m = sunbeam_mesh::load_scene_mesh(path)?;
    Ok((m.positions, m.indices))
}

fn run(cli: Cli) -> Result<()> {
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
        (cli.response || cli.response_exr.is_some())
            .then(|| sunbeam_response::sidecar_path(&cli.output))
    });
    let response = match &response_path {
        Some(_) => {
            let t = Instant::now();
            let ro = sunbeam_response::Options {
                lambda_samples: cli.response_lambda.clamp(1, 4096),
                budget_bytes: parse_bytes(&cli.response_budget)?,
                grid: None,
            };
            let r = sunbeam_response::build(&pack, &ro);
            Some((r, t.elapsed().as_secs_f64()))
        }
        None => None,
    };
    let mut files = write_pack(&pack, &cli.output, kind)?;
    if let (Some(rp), Some((r, _))) = (&response_path, &response) {
        let bytes = sunbeam_response::ktx2::encode(r);
        sunbeam_common::output::write_atomic(rp, &bytes)?;
        files.push((rp.clone(), bytes.len() as u64));
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
            "response": response.as_ref().map(|(r, t)| serde_json::json!({
                "grid": [r.info.grid.n_theta, r.info.grid.n_rho, r.info.grid.n_s],
                "r0": r.info.grid.r0,
                "lambda_samples": r.info.lambda_samples,
                "bytes": r.byte_len(),
                "time_s": t,
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
