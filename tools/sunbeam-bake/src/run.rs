//! What sunbeam-bake does with its parsed arguments.

use crate::args::*;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};
use sunbeam_mesh::bake::{bake, BakeOptions};
use sunbeam_mesh::orient::{parse_axis, Curve, Interp, Samples, Source, UvAxis};
use sunbeam_mesh::scales::{self, ScaleParams};
use sunbeam_mesh::snake::{self, SnakeParams};
use sunbeam_mesh::texture::{self, TextureOptions};

pub(crate) fn run(cli: Cli) -> Result<()> {
    let to_stdout = cli.output.as_os_str() == "-";
    if to_stdout && cli.depfile.is_some() {
        return Err(Error::usage("--depfile needs a file output, not -o -"));
    }
    if to_stdout && cli.json {
        return Err(Error::usage(
            "--json prints on stdout; it cannot be combined with -o -",
        ));
    }
    if !(cli.max_snap.is_none_or(|d| d >= 0.0)) {
        return Err(Error::usage("--max-snap must be >= 0"));
    }
    if !cli.rotate_deg.is_finite() {
        return Err(Error::usage("--rotate-deg must be a finite number"));
    }
    if cli.texture.is_some() && !(1..=8192).contains(&cli.texture_size) {
        return Err(Error::usage("--texture-size must be 1..8192"));
    }
    let mut inputs: Vec<PathBuf> = Vec::new();
    let (doc, snake_spine) = match (&cli.mesh, cli.generate_snake) {
        (Some(_), true) => {
            return Err(Error::usage(
                "give either MESH or --generate-snake, not both",
            ))
        }
        (None, false) => return Err(Error::usage("no input: give MESH or --generate-snake")),
        (Some(m), false) => {
            let d = sunbeam_mesh::load_document(m)?;
            inputs.push(m.clone());
            (d, None)
        }
        (None, true) => {
            if !(cli.snake_detail.is_finite() && cli.snake_detail > 0.0) {
                return Err(Error::usage("--snake-detail must be > 0"));
            }
            let p = SnakeParams::with_detail(cli.snake_detail);
            (snake::generate(&p), Some(snake::spine(&p)))
        }
    };
    if cli.spine_out.is_some() && snake_spine.is_none() {
        return Err(Error::usage("--spine-out goes with --generate-snake"));
    }
    let source = if let Some(a) = &cli.axis {
        Source::Axis(parse_axis(a)?)
    } else if let Some(c) = &cli.curve {
        inputs.push(c.clone());
        Source::Curve(Curve::load(c)?)
    } else if let Some(s) = &cli.samples {
        inputs.push(s.clone());
        Source::Samples(Samples::load(s)?)
    } else if let Some(u) = cli.uv_direction {
        Source::UvDirection(match u {
            UvDir::U => UvAxis::U,
            UvDir::V => UvAxis::V,
        })
    } else if let Some(sp) = &snake_spine {
        Source::Curve(Curve::from_points(Path::new("<snake spine>"), sp.clone())?)
    } else {
        return Err(Error::usage(
            "no orientation source: give one of --axis, --curve, --samples, --uv-direction",
        ));
    };
    let opts = BakeOptions {
        source,
        rotate_deg: cli.rotate_deg,
        uv_set: cli.uv_set,
        interp: match cli.interpolation {
            InterpArg::Natural => Interp::Natural,
            InterpArg::Linear => Interp::Linear,
            InterpArg::Sibson => Interp::SibsonC1,
        },
        max_snap: cli.max_snap,
        uv_tangents: cli.scales,
    };
    let mut baked = bake(doc, &opts)?;
    // Files the document read (external buffers, images embedded while merging, MTL).
    for f in &baked.doc.extra_inputs {
        if !inputs.contains(f) {
            inputs.push(f.clone());
        }
    }
    let mut tex_bytes = None;
    if let Some(t) = &cli.texture {
        let (bytes, rep) = texture::render(
            &baked.work,
            &TextureOptions {
                size: cli.texture_size,
                dilate: cli.texture_dilate,
                path: t.clone(),
            },
        )?;
        baked.report.texture = Some(rep);
        tex_bytes = Some(bytes);
    }
    let ext = match &cli.pack {
        Some(pack) => {
            let (ext, files) = diffraction_ext(pack, &cli)?;
            inputs.extend(files);
            Some(ext)
        }
        None => None,
    };
    if cli.scales {
        let rep = scales::attach(
            &mut baked.doc,
            &baked.work,
            &scale_params(&cli),
            cli.uv_set,
            ext,
        )?;
        if rep.field_along_u < 0.5 {
            baked.report.warnings.push(format!(
                "--scales: the baked field runs along u at only {:.0} % of the vertices; the tiling assumes u runs along the body (docs/BAKE.md \"Scales\")",
                100.0 * rep.field_along_u
            ));
        }
        baked.report.scales =
            Some(serde_json::to_value(rep).map_err(|e| Error::internal(e.to_string()))?);
    } else if let Some(ext) = ext {
        sunbeam_mesh::diffraction_ext::attach(&mut baked.doc, &ext, BASE);
    }
    let glb = baked.doc.to_glb();
    if to_stdout {
        std::io::stdout()
            .lock()
            .write_all(&glb)
            .map_err(Error::stdout)?;
    } else {
        sunbeam_common::output::write_atomic(&cli.output, &glb)?;
        baked.report.output = Some(cli.output.display().to_string());
    }
    if let (Some(t), Some(b)) = (&cli.texture, tex_bytes) {
        sunbeam_common::output::write_atomic(t, &b)?;
    }
    if let (Some(p), Some(sp)) = (&cli.spine_out, &snake_spine) {
        let js = serde_json::json!({ "points": sp });
        sunbeam_common::output::write_atomic(
            p,
            serde_json::to_string_pretty(&js)
                .map_err(|e| Error::internal(e.to_string()))?
                .as_bytes(),
        )?;
    }
    if let Some(d) = &cli.depfile {
        let mut outs: Vec<&Path> = vec![cli.output.as_path()];
        if let Some(t) = &cli.texture {
            outs.push(t);
        }
        if let Some(s) = &cli.spine_out {
            outs.push(s);
        }
        let ins: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        sunbeam_common::depfile::write(d, &outs, &ins)?;
    }
    let r = &baked.report;
    if cli.json {
        println!(
            "{}",
            serde_json::to_string_pretty(r).map_err(|e| Error::internal(e.to_string()))?
        );
    }
    if !cli.quiet {
        for w in &r.warnings {
            eprintln!("sunbeam-bake: warning: {w}");
        }
        let missing: usize = r.without_direction.values().sum();
        if missing > 0 && (cli.verbose || std::io::stderr().is_terminal()) {
            eprintln!(
                "sunbeam-bake: {missing} of {} vertices had no direction from the source ({} filled from neighbours, {} arbitrary): {:?}",
                r.vertices, r.filled_from_neighbours, r.arbitrary, r.without_direction
            );
        }
        if let Some(s) = &r.samples {
            if !s.rejected.is_empty() {
                eprintln!(
                    "sunbeam-bake: warning: {} of {} samples rejected (see --json)",
                    s.rejected.len(),
                    s.rows
                );
            }
        }
        if cli.verbose {
            eprintln!(
                "sunbeam-bake: {} vertices, {} triangles, {} primitives, source {}",
                r.vertices, r.triangles, r.primitives, r.source
            );
        }
    }
    Ok(())
}

/// Base colour written with the extension.
const BASE: [f64; 3] = [0.05, 0.05, 0.05];

/// The `--scale-*` options.
fn scale_params(cli: &Cli) -> ScaleParams {
    ScaleParams {
        rows: cli.scale_rows,
        length: cli.scale_length,
        overlap: cli.scale_overlap,
        dome: cli.scale_dome,
        keel: cli.scale_keel,
        tilt_deg: cli.scale_tilt,
        tilt_jitter_deg: cli.scale_tilt_jitter,
        ridge_jitter_deg: cli.scale_ridge_jitter,
        texels_per_scale: cli.scale_texels,
        seed: cli.scale_seed,
    }
}

/// `--pack`: the SUNBEAM_materials_diffraction extension object for the GLB's
/// materials (docs/ENGINES.md), and the files it read (for the depfile).
fn diffraction_ext(pack: &Path, cli: &Cli) -> Result<(serde_json::Value, Vec<PathBuf>)> {
    if cli.output.as_os_str() == "-" {
        return Err(Error::usage(
            "--pack needs a file output (the URIs are relative to it)",
        ));
    }
    if !(0.0..=1.0).contains(&cli.diffuse_weight) {
        return Err(Error::usage("--diffuse-weight must be in [0, 1]"));
    }
    if !pack.is_file() {
        return Err(Error::input_file(pack, "--pack: no such file"));
    }
    let map_path = sunbeam_response::sidecar_path(pack);
    if !map_path.is_file() {
        return Err(Error::input_file(
            pack,
            format!(
                "--pack: no response map {} beside it (write it with sunbeam-pack --response)",
                map_path.display()
            ),
        ));
    }
    let map = sunbeam_response::ktx2::read(&map_path)?;
    let g = map.info.grid;
    let out_dir = cli
        .output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let uri = |p: &Path| -> Result<String> {
        let rel = relative_path(p, out_dir)?;
        Ok(rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join("/"))
    };
    let base = BASE;
    let ext = serde_json::json!({
        "responseMap": { "uri": uri(&map_path)?, "mimeType": "image/ktx2" },
        "pack": { "uri": uri(pack)? },
        "grid": { "nTheta": g.n_theta, "nRho": g.n_rho, "nS": g.n_s, "r0": g.r0 },
        // `f0` beside `ior` for readers that know only `f0`.
        "f0": sunbeam_optics::gain::f0(cli.ior),
        "ior": cli.ior,
        "reflectance": match cli.reflectance {
            ReflectanceArg::Absolute => "absolute",
            ReflectanceArg::Relative => "relative",
        },
        "masking": match cli.masking {
            MaskingArg::Off => "off",
            MaskingArg::Smith => "smith",
        },
        "diffuseWeight": cli.diffuse_weight,
        "baseColor": base,
    });
    let mut ext = ext;
    if let Some(s) = cli.rms_slope {
        ext["rmsSlope"] = serde_json::json!(s);
    }
    Ok((ext, vec![pack.to_path_buf(), map_path]))
}

/// `target` relative to the folder `from` (both made absolute first).
fn relative_path(target: &Path, from: &Path) -> Result<PathBuf> {
    let abs = |p: &Path| {
        std::path::absolute(p).map_err(|e| Error::input_file(p, format!("cannot resolve: {e}")))
    };
    let (t, f) = (abs(target)?, abs(from)?);
    let (tc, fc): (Vec<_>, Vec<_>) = (t.components().collect(), f.components().collect());
    let common = tc.iter().zip(&fc).take_while(|(a, b)| a == b).count();
    let mut rel = PathBuf::new();
    for _ in common..fc.len() {
        rel.push("..");
    }
    for c in &tc[common..] {
        rel.push(c);
    }
    Ok(rel)
}
