//! sunbeam-bake: put the nanostructure orientation field on a mesh (docs/BAKE.md).

use clap::{Parser, ValueEnum};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};
use sunbeam_mesh::bake::{bake, BakeOptions};
use sunbeam_mesh::orient::{parse_axis, Curve, Interp, Samples, Source, UvAxis};
use sunbeam_mesh::snake::{self, SnakeParams};
use sunbeam_mesh::texture::{self, TextureOptions};

#[derive(Debug, Clone, Copy, ValueEnum)]
enum UvDir {
    U,
    V,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum InterpArg {
    Natural,
    Sibson,
    Linear,
}

/// Put the nanostructure orientation field on a mesh: glTF/GLB/OBJ in, a GLB
/// with per-vertex TANGENT and _ORIENTATION out (everything else kept).
///
/// Exit codes: 0 ok, 1 usage, 2 input unreadable or invalid, 3 output not written, 4 internal.
#[derive(Debug, Parser)]
#[command(name = "sunbeam-bake", version, about, long_about = None)]
struct Cli {
    /// Input mesh: .gltf (with its buffers), .glb or .obj (told apart by content).
    mesh: Option<PathBuf>,
    /// Output GLB ("-" for stdout).
    #[arg(short, long)]
    output: PathBuf,

    /// A world direction projected onto each tangent plane.
    #[arg(
        long,
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        group = "source"
    )]
    axis: Option<String>,
    /// A spine polyline (JSON {"points": [[x,y,z], ...]}): the tangent at the nearest spine point, projected.
    #[arg(long, value_name = "SPINE.json", group = "source")]
    curve: Option<PathBuf>,
    /// Scattered samples (CSV or JSON: x,y,z,dx,dy,dz or u,v,angle_deg), interpolated in UV space.
    #[arg(long, value_name = "FILE", group = "source")]
    samples: Option<PathBuf>,
    /// The direction of increasing u or v.
    #[arg(long, value_enum, group = "source")]
    uv_direction: Option<UvDir>,

    /// Extra rotation about the normal, degrees (counter-clockwise seen from outside).
    #[arg(
        long,
        value_name = "A",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    rotate_deg: f64,
    /// TEXCOORD set the UV modes use.
    #[arg(long, value_name = "N", default_value_t = 0)]
    uv_set: usize,
    /// Interpolation of --samples in UV space.
    #[arg(long, value_enum, default_value = "natural")]
    interpolation: InterpArg,
    /// 3D samples farther than this from the surface (mesh units) are rejected [default: 2% of the bounding-box diagonal].
    #[arg(long, value_name = "DIST")]
    max_snap: Option<f64>,

    /// Also write a tangent-space direction map in UV space (.png or .exr).
    #[arg(long, value_name = "FILE")]
    texture: Option<PathBuf>,
    /// Texture size in texels (square).
    #[arg(long, value_name = "N", default_value_t = 1024)]
    texture_size: u32,
    /// Texels to dilate the map across UV seams and island borders.
    #[arg(long, value_name = "PX", default_value_t = 8)]
    texture_dilate: u32,

    /// Generate the procedural demo snake instead of reading MESH (default source: --curve along its own spine).
    #[arg(long)]
    generate_snake: bool,
    /// Snake resolution factor (vertices grow with its square; 1 = about 29k vertices).
    #[arg(long, value_name = "K", default_value_t = 1.0)]
    snake_detail: f64,
    /// Write the snake's spine polyline (JSON, for --curve) here.
    #[arg(long, value_name = "FILE")]
    spine_out: Option<PathBuf>,

    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
    /// Write a Make-style depfile.
    #[arg(long, value_name = "FILE")]
    depfile: Option<PathBuf>,
    /// Quiet: no diagnostics but errors.
    #[arg(short, long)]
    quiet: bool,
    /// Verbose: print the report summary on stderr.
    #[arg(short, long)]
    verbose: bool,
}

fn main() {
    sunbeam_common::cli::main("sunbeam-bake", run)
}

fn run(cli: Cli) -> Result<()> {
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
    let glb = baked.doc.to_glb();
    if to_stdout {
        std::io::stdout()
            .lock()
            .write_all(&glb)
            .map_err(|e| Error::output(format!("stdout: {e}")))?;
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
