//! `sunbeam-eval render`: the CPU reference image of a scene, through
//! `sunbeam_raster::render` (the same scene loading and defaults as
//! `sunbeam-play`: a scene file, or `--mesh M --pack P` for
//! `Scene::default_for`). `--samples N` averages a stratified grid of sub-pixel
//! samples in linear light (the anti-aliased reference); `-o F.exr` writes the
//! linear frame (exposure applied, no tone curve) instead of display values.
//! A scene with an `environment` is lit by Monte Carlo (`--samples` per pixel,
//! `--seed S`; docs/LIGHTING.md). `--turntable N` orbits the camera about its
//! `up` axis (or `--axis`) through the target in N steps and writes an animated PNG
//! (APNG, written by the `png` crate the renderer already uses) and, with
//! `--frames-dir`, the frames.

use sunbeam_common::{Error, Result};
use sunbeam_scene::{DefaultLighting, Scene};

/// `--lighting` (clap has checked the value).
fn lighting(a: &crate::args::RenderArgs) -> Result<DefaultLighting> {
    a.lighting.parse().map_err(Error::usage)
}

pub fn run(a: &crate::args::RenderArgs, quiet: bool) -> Result<()> {
    let mut scene = match (&a.scene, &a.mesh) {
        (Some(_), Some(_)) => {
            return Err(Error::usage(
                "give either SCENE.json or --mesh/--pack, not both",
            ))
        }
        (Some(s), None) => {
            if a.pack.is_some() {
                return Err(Error::usage(
                    "--pack goes with --mesh (a scene file names its own packs)",
                ));
            }
            Scene::load(s)?
        }
        (None, Some(m)) => sunbeam_raster::default_scene(m, a.pack.as_deref(), lighting(a)?)?,
        (None, None) => {
            return Err(Error::usage(
                "nothing to render: give SCENE.json or --mesh M.glb --pack P.ktx2",
            ))
        }
    };
    if let Some(ev) = a.exposure {
        if !ev.is_finite() {
            return Err(Error::usage("--exposure must be finite"));
        }
        scene.exposure = ev;
    }
    if let Some((w, h)) = a.size {
        scene.size = [w as u32, h as u32];
        scene.validate()?;
    }
    // Monte Carlo under an environment needs more than one sample per pixel.
    let samples = a
        .samples
        .unwrap_or(if scene.environment.is_some() { 16 } else { 1 });
    let opts = sunbeam_raster::Options {
        samples,
        lambda_step_nm: a.lambda_step,
        seed: a.seed[0],
        estimator: match a.env_estimator.as_str() {
            "monte-carlo" => sunbeam_raster::environment::EnvEstimator::MonteCarlo,
            _ => sunbeam_raster::environment::EnvEstimator::Quadrature,
        },
        ..Default::default()
    };
    sunbeam_raster::samples_side(samples)?;
    if let Some(n) = a.turntable {
        if a.seed.len() > 1 {
            return Err(Error::usage("--turntable takes one --seed"));
        }
        return turntable(&scene, &opts, n, a);
    }
    // The scene's files, read once (an environment map is checked here: its
    // negative values set to 0 make one warning line and the report's count).
    let prepared = sunbeam_raster::prepare(&scene)?;
    let mut report = serde_json::json!({
        "tool": "sunbeam-eval render",
        "output": a.output.display().to_string(),
        "samples": samples,
        // null: the adaptive step (docs/EVAL.md "Wavelength step")
        "lambda_step_nm": a.lambda_step,
    });
    if let Some((line, c)) = sunbeam_raster::environment_clamped_warning(&prepared) {
        if !quiet {
            eprintln!("sunbeam-eval: warning: {line}");
        }
        report["environment_negatives_zeroed"] = serde_json::json!({"values": c.values, "texels": c.texels, "min": c.min, "bound": c.bound});
    }
    if let Some(c) = render_frame(a, &prepared, &opts)? {
        report["converge"] = serde_json::json!({
            "de": a.converge, "max_samples": a.max_samples, "max_seeds": a.max_seeds,
            "rounds": c.rounds, "samples_mean": c.samples_mean, "samples_max": c.samples_max,
            "open": c.open, "estimate_p99": c.estimate_p99, "estimate_max": c.estimate_max,
        });
        if c.open > 0 && !quiet {
            eprintln!(
                "sunbeam-eval: warning: {} pixels are still above --converge {} at --max-samples {} and --max-seeds {} (estimated max {:.3})",
                c.open,
                a.converge.unwrap_or_default(),
                a.max_samples,
                a.max_seeds,
                c.estimate_max
            );
        }
    }
    if a.json {
        println!("{report}");
    }
    Ok(())
}

/// Render and write the frame (with `--compare`, print the difference); with
/// `--converge`, what the converged render did.
fn render_frame(
    a: &crate::args::RenderArgs,
    prepared: &sunbeam_raster::Prepared,
    opts: &sunbeam_raster::Options,
) -> Result<Option<sunbeam_raster::converge::Converged>> {
    // The reference first: a bad file fails before the render.
    let reference = match &a.compare {
        Some(r) => Some((r, sunbeam_raster::LinearImage::read_exr(r)?)),
        None => None,
    };
    let reference = reference.as_ref().map(|(r, img)| (r.as_path(), img));
    if let Some(de) = a.converge {
        if a.seed.len() > 1 {
            return Err(Error::usage(
                "--converge takes one --seed (it draws its rounds' seeds from it)",
            ));
        }
        let c = sunbeam_raster::converge::render_converged(
            prepared,
            opts,
            sunbeam_raster::converge::Converge {
                de,
                max_samples: a.max_samples,
                max_seeds: a.max_seeds,
                ..Default::default()
            },
        )?;
        write_linear(a, &c.image, opts, reference)?;
        return Ok(Some(c));
    }
    // The frame in linear light: one seed's, or the mean of several seeds'.
    let linear = || -> Result<sunbeam_raster::LinearImage> {
        let mut frames = vec![sunbeam_raster::render_prepared_linear(prepared, opts)?];
        for &seed in &a.seed[1..] {
            let o = sunbeam_raster::Options {
                seed,
                ..opts.clone()
            };
            frames.push(sunbeam_raster::render_prepared_linear(prepared, &o)?);
        }
        sunbeam_raster::linear::mean_of(&frames)
    };
    let exr = a
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if reference.is_some() || exr || a.seed.len() > 1 {
        write_linear(a, &linear()?, opts, reference)?;
    } else {
        sunbeam_raster::render_prepared(prepared, opts).write_png(&a.output)?;
    }
    Ok(None)
}

/// Write a linear frame to `-o` (EXR as it is, PNG through the display
/// transform); with `--compare` (its path and image), print its difference
/// from the reference.
fn write_linear(
    a: &crate::args::RenderArgs,
    lin: &sunbeam_raster::LinearImage,
    opts: &sunbeam_raster::Options,
    reference: Option<(&std::path::Path, &sunbeam_raster::LinearImage)>,
) -> Result<()> {
    let d = match reference {
        Some((path, img)) => {
            Some(sunbeam_raster::compare_linear(lin, img).map_err(|e| e.context(path.display()))?)
        }
        None => None,
    };
    if a.output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        lin.write_exr(&a.output)?;
    } else {
        lin.display(opts.curve).write_png(&a.output)?;
    }
    if let Some(d) = d {
        println!("{d}");
    }
    Ok(())
}

/// The camera's eye turned by `deg` degrees about the axis `up` through `target`
/// (Rodrigues' rotation).
fn orbit(eye: [f64; 3], target: [f64; 3], up: [f64; 3], deg: f64) -> [f64; 3] {
    let n = (up[0] * up[0] + up[1] * up[1] + up[2] * up[2]).sqrt();
    let k = up.map(|v| v / n);
    let v = [eye[0] - target[0], eye[1] - target[1], eye[2] - target[2]];
    let (s, c) = deg.to_radians().sin_cos();
    let kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    let kxv = [
        k[1] * v[2] - k[2] * v[1],
        k[2] * v[0] - k[0] * v[2],
        k[0] * v[1] - k[1] * v[0],
    ];
    [0, 1, 2].map(|i| target[i] + v[i] * c + kxv[i] * s + k[i] * kv * (1.0 - c))
}

fn turntable(
    scene: &Scene,
    opts: &sunbeam_raster::Options,
    n: u32,
    a: &crate::args::RenderArgs,
) -> Result<()> {
    if !a
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        return Err(Error::usage(
            "--turntable writes an animated PNG: give -o FILE.png",
        ));
    }
    let prepared = sunbeam_raster::prepare(scene)?;
    let mut frames = Vec::with_capacity(n as usize);
    for k in 0..n {
        let mut p = prepared.clone();
        let c = &scene.camera;
        let axis = a.axis.unwrap_or(c.up);
        p.scene.camera.eye = orbit(c.eye, c.target, axis, 360.0 * k as f64 / n as f64);
        // Keep the camera's roll: its up turns with it.
        let top = [0, 1, 2].map(|i| c.target[i] + c.up[i]);
        let turned = orbit(top, c.target, axis, 360.0 * k as f64 / n as f64);
        p.scene.camera.up = [0, 1, 2].map(|i| turned[i] - c.target[i]);
        frames.push(sunbeam_raster::render_prepared(&p, opts));
    }
    if let Some(dir) = &a.frames_dir {
        std::fs::create_dir_all(dir).map_err(|e| Error::output_file(dir, e))?;
        for (k, f) in frames.iter().enumerate() {
            f.write_png(&dir.join(format!("frame-{k:03}.png")))?;
        }
    }
    let bytes = sunbeam_raster::Image::apng_bytes(&frames, a.fps)?;
    sunbeam_common::output::write_atomic(&a.output, &bytes)
}
