//! Command line of sunbeam-eval (clap).

use crate::input;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use sunbeam_common::{cli, Result};
use sunbeam_optics::truth::{Model, Params};

#[derive(Parser)]
#[command(
    name = "sunbeam-eval",
    version,
    about = "Ground truth, errors, grating check and BRDF pictures for Sunbeam packs"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) cmd: Cmd,
    /// Less output.
    #[arg(short, long, global = true)]
    pub(crate) quiet: bool,
    /// More output.
    #[arg(short, long, global = true)]
    pub(crate) verbose: bool,
}

#[derive(clap::Args)]
pub(crate) struct SheetArgs {
    /// Output PNG.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// Pictures per row.
    #[arg(long, default_value_t = 4)]
    pub(crate) columns: usize,
    /// Input PNGs, in order.
    #[arg(required = true)]
    pub(crate) inputs: Vec<PathBuf>,
}

#[derive(Subcommand)]
pub(crate) enum Cmd {
    /// R(u, v, w, lambda) at the points of a CSV file, one value per line on stdout (docs/EVAL.md).
    Probe(ProbeArgs),
    /// The thesis' grating evaluation: peak viewing angle per wavelength and the period.
    Grating(GratingArgs),
    /// Spectral and colour errors of a pack against the ground truth of its height field.
    Compare(CompareArgs),
    /// Picture of a pack's reflected colour over the hemisphere and R over (angle, wavelength).
    Brdf(BrdfArgs),
    /// Run time against error sweeps (CSV, Pareto plot, markdown summary on stdout).
    Bench(BenchArgs),
    /// The CPU reference image of a scene (needs sunbeam-raster).
    Render(RenderArgs),
    /// Contact sheet: PNGs on a grid, row by row (the demo's overview picture).
    Sheet(SheetArgs),
    /// CIEDE2000 of a linear frame (EXR) against a reference frame: all lit, interior and edge pixels; optional error map.
    Diff(DiffArgs),
}

#[derive(clap::Args)]
pub(crate) struct DiffArgs {
    /// The frame to judge (linear EXR, e.g. `sunbeam-play --headless -o f.exr`).
    pub(crate) image: PathBuf,
    /// The reference frame (linear EXR, e.g. `sunbeam-eval render -o r.exr`).
    pub(crate) reference: PathBuf,
    /// Write a false-colour PNG of the per-pixel error (black 0, red, yellow at --scale; unlit dark blue).
    #[arg(long)]
    pub(crate) heatmap: Option<PathBuf>,
    /// CIEDE2000 shown as yellow in the heat map.
    #[arg(long, default_value_t = 10.0, value_parser = positive)]
    pub(crate) scale: f64,
    /// Judge only the pixels lit in this frame (linear EXR, the same size; e.g. the object lit from the eye with the background off), its interior and edge: an object in front of a drawn background.
    #[arg(long)]
    pub(crate) mask: Option<PathBuf>,
    /// Machine-readable report on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

fn positive(s: &str) -> std::result::Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("`{s}` is not a positive number")),
    }
}

#[derive(clap::Args)]
pub(crate) struct CompareArgs {
    /// The pack (KTX2/EXR).
    pub(crate) pack: PathBuf,
    /// The height field it was built from.
    pub(crate) height: PathBuf,
    /// Random (wi, wr, lambda) points for the spectral error.
    #[arg(long, default_value_t = 2000)]
    pub(crate) points: usize,
    /// View directions per light for the colour error.
    #[arg(long, default_value_t = 64)]
    pub(crate) views: usize,
    /// Light directions `THETA[,PHI]` (repeatable); default 0, 30, 60, 75 deg at phi 0 and 60 deg at phi 90.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_light)]
    pub(crate) light: Vec<[f64; 3]>,
    /// Wavelength samples of the pack's colour integral (the truth uses 1 nm).
    #[arg(long, default_value_t = 64)]
    pub(crate) lambda_samples: usize,
    /// Fail (exit 5) when max |dR| exceeds this.
    #[arg(long, default_value_t = 1e-3)]
    pub(crate) tolerance: f64,
    /// Fail (exit 5) when the 99th percentile CIEDE2000 exceeds this.
    #[arg(long, default_value_t = 1.0)]
    pub(crate) de_tolerance: f64,
    /// Machine-readable report on stdout.
    #[arg(long)]
    pub(crate) json: bool,
    #[command(flatten)]
    pub(crate) heights: input::HeightArgs,
}

#[derive(clap::Args)]
pub(crate) struct BrdfArgs {
    /// The pack (KTX2/EXR).
    pub(crate) pack: PathBuf,
    /// Light direction `THETA[,PHI]`.
    #[arg(long, default_value = "60deg,0deg", allow_hyphen_values = true, value_parser = parse_light)]
    pub(crate) light: [f64; 3],
    /// Output PNG.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// Disk resolution in pixels.
    #[arg(long, default_value_t = 200)]
    pub(crate) size: usize,
    /// Wavelength samples of the colour integral.
    #[arg(long, default_value_t = 32)]
    pub(crate) lambda_samples: usize,
    /// Exposure in stops (default: the 95th percentile of Y maps to 1).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) exposure: Option<f64>,
    /// Tone curve: clamp or reinhard.
    #[arg(long, default_value = "clamp")]
    pub(crate) tone: sunbeam_optics::colour::ToneCurve,
    #[arg(long)]
    pub(crate) json: bool,
}

#[derive(clap::Args)]
pub(crate) struct BenchArgs {
    /// Folder with the snake patches (default: ../shared/data/snake when found).
    #[arg(long)]
    pub(crate) snake: Option<PathBuf>,
    /// Output folder for bench.csv, colour.csv, stress.csv and pareto.png.
    #[arg(short, long, default_value = "bench-out")]
    pub(crate) output: PathBuf,
    /// Random evaluation points per field.
    #[arg(long, default_value_t = 400)]
    pub(crate) points: usize,
    /// Fewer configurations and smaller fields (a smoke run).
    #[arg(long)]
    pub(crate) quick: bool,
}

#[derive(clap::Args)]
pub(crate) struct ProbeArgs {
    /// A pack (KTX2/EXR) or a height field (anything sunbeam-import reads).
    pub(crate) input: PathBuf,
    /// Points, one `u,v,w,lambda_m` per line.
    #[arg(long, value_name = "FILE.csv")]
    pub(crate) points: PathBuf,
    /// Ground truth of PHYSICS.md 2 (implied for a height field; refused for a pack).
    #[arg(long)]
    pub(crate) truth: bool,
    #[command(flatten)]
    pub(crate) heights: input::HeightArgs,
    #[command(flatten)]
    pub(crate) model: TruthArgs,
}

#[derive(clap::Args)]
pub(crate) struct GratingArgs {
    /// A height field or a pack.
    pub(crate) input: PathBuf,
    /// Incidence angle in the plane of incidence.
    #[arg(long, default_value = "75deg", allow_hyphen_values = true, value_parser = cli::angle)]
    pub(crate) theta_i: f64,
    /// Azimuth of the plane of incidence from the patch's +x axis.
    #[arg(long, default_value = "0deg", allow_hyphen_values = true, value_parser = cli::angle)]
    pub(crate) azimuth: f64,
    /// Wavelength range.
    #[arg(long, default_value = "380nm..780nm", value_parser = cli::length_range)]
    pub(crate) lambda: (f64, f64),
    /// Wavelength step.
    #[arg(long, default_value = "10nm", value_parser = cli::positive_length)]
    pub(crate) lambda_step: f64,
    /// Viewing-angle step of the scan (peaks are then refined on the continuous R).
    #[arg(long, default_value = "0.1deg", value_parser = cli::angle)]
    pub(crate) angle_step: f64,
    /// Order of the brightest peaks when the orders cannot be told apart (one order visible).
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    pub(crate) order: i32,
    /// Ignore peaks whose period (1/|f|) is longer than this (default: outside the specular lobe).
    #[arg(long, value_name = "LEN", value_parser = cli::positive_length)]
    pub(crate) max_period: Option<f64>,
    /// Replicate the height field NxM times first (a periodic patch seen by a wider window).
    #[arg(long, value_name = "NxM", value_parser = input::parse_tile)]
    pub(crate) tile: Option<(usize, usize)>,
    /// The true period, if known: drawn in the plot and compared in the report.
    #[arg(long, value_name = "LEN", value_parser = cli::positive_length)]
    pub(crate) true_period: Option<f64>,
    /// Write the plot of peaks against the grating equation.
    #[arg(long, value_name = "OUT.png")]
    pub(crate) plot: Option<PathBuf>,
    /// Write the response R over (wavelength, angle) as CSV.
    #[arg(long, value_name = "OUT.csv")]
    pub(crate) csv: Option<PathBuf>,
    /// Machine-readable report on stdout.
    #[arg(long)]
    pub(crate) json: bool,
    #[command(flatten)]
    pub(crate) heights: input::HeightArgs,
    #[command(flatten)]
    pub(crate) model: TruthArgs,
}

#[derive(clap::Args)]
pub(crate) struct RenderArgs {
    /// Scene JSON (docs/SCENE.md); or give --mesh and --pack for the default scene.
    pub(crate) scene: Option<PathBuf>,
    /// Print a JSON report on stdout (output, samples, the environment map's
    /// negative values set to 0).
    #[arg(long)]
    pub(crate) json: bool,
    /// Output: FRAME.png (display values) or FRAME.exr (linear light, exposure applied).
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// Samples per pixel: a stratified s x s grid averaged in linear light (1, 4, 9, 16,
    /// ... 16384; under an `environment` each jittered in its cell by --seed);
    /// default 1, or 16 for a scene with an `environment`.
    #[arg(long)]
    pub(crate) samples: Option<u32>,
    /// What lights the default scene of --mesh/--pack: the built-in sky (default) or the
    /// point light (docs/SCENE.md "The default scene").
    #[arg(long, default_value = "sky", value_parser = clap::builder::PossibleValuesParser::new(["sky", "point"]))]
    pub(crate) lighting: String,
    /// Seed of the environment lighting's sampling (scenes with an `environment`:
    /// sub-pixel positions and directions; two seeds differ by the estimator's noise only). Given
    /// more than once, the frame is the mean of the seeds' frames in linear light.
    #[arg(long, default_values_t = [1u64], action = clap::ArgAction::Append)]
    pub(crate) seed: Vec<u64>,
    /// A converged reference under an `environment`: each pixel gets finer sub-pixel
    /// grids (4x --samples per level) and more seeds until its estimated CIEDE2000
    /// error is at most DE (docs/EVAL.md "A converged reference"); seeds drawn from --seed.
    #[arg(long, value_name = "DE", value_parser = positive, conflicts_with = "turntable")]
    pub(crate) converge: Option<f64>,
    /// With --converge: the finest grid, in samples per pixel (a square number).
    #[arg(long, value_name = "N", default_value_t = 16384, requires = "converge")]
    pub(crate) max_samples: u32,
    /// With --converge: the most seeds a pixel gets at the finest grid.
    #[arg(long, value_name = "N", default_value_t = 12, requires = "converge", value_parser = clap::value_parser!(u32).range(3..=4096))]
    pub(crate) max_seeds: u32,
    /// How an `environment` is integrated: `quadrature` (default: the sum over
    /// the pack's extended-light maps, no direction noise) or `monte-carlo`
    /// (the pack's R per wavelength and direction, the independent check);
    /// docs/LIGHTING.md "The reference's estimator".
    #[arg(long, default_value = "quadrature", value_parser = clap::builder::PossibleValuesParser::new(["quadrature", "monte-carlo"]))]
    pub(crate) env_estimator: String,
    /// Wavelength step of the colour integral under point lights, in nm (1: every
    /// row of the 1 nm CIE tables; default: from 1 to 5 nm by how fast the
    /// pack's R can vary there, docs/EVAL.md "Wavelength step").
    #[arg(long, value_name = "NM", value_parser = clap::value_parser!(u32).range(1..=10))]
    pub(crate) lambda_step: Option<u32>,
    /// A turntable of N frames: the camera orbits the target about its `up`
    /// axis (lights and environment stay); -o FILE.png is an animated PNG.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=720))]
    pub(crate) turntable: Option<u32>,
    /// Compare the linear frame with REF.exr (CIEDE2000 over its lit pixels,
    /// printed as `CIEDE2000 mean M p99 P max X over N px`): e.g. two seeds.
    #[arg(long, value_name = "REF.exr", conflicts_with = "turntable")]
    pub(crate) compare: Option<PathBuf>,
    /// With --turntable: the orbit's axis `X,Y,Z` through the target (default:
    /// the camera's `up`).
    #[arg(long, value_name = "X,Y,Z", requires = "turntable", allow_hyphen_values = true, value_parser = parse_axis)]
    pub(crate) axis: Option<[f64; 3]>,
    /// With --turntable: also write each frame as DIR/frame-NNN.png.
    #[arg(long, value_name = "DIR", requires = "turntable")]
    pub(crate) frames_dir: Option<PathBuf>,
    /// With --turntable: frames per second of the animation.
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u16).range(1..=120))]
    pub(crate) fps: u16,
    /// Mesh (GLB/glTF/OBJ) for the default scene of sunbeam-play --mesh --pack.
    #[arg(long)]
    pub(crate) mesh: Option<PathBuf>,
    /// Pack for the default scene.
    #[arg(long)]
    pub(crate) pack: Option<PathBuf>,
    /// Frame size WxH (default: the scene's).
    #[arg(long, value_name = "WxH", value_parser = sunbeam_common::units::parse_size)]
    pub(crate) size: Option<(usize, usize)>,
    /// Exposure in stops (default: the scene's).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) exposure: Option<f64>,
}

/// Model options of the ground truth.
#[derive(Debug, Clone, clap::Args)]
pub(crate) struct TruthArgs {
    /// What lies beyond the patch: `window` (default) or `tiled` (the thesis).
    #[arg(long, default_value = "window", value_parser = sunbeam_common::cli::one_of::<Model>(&Model::NAMES))]
    pub(crate) model: Model,
    /// Spatial coherence length of the light.
    #[arg(long, default_value = "65um", value_name = "LEN", value_parser = sunbeam_common::cli::positive_length)]
    pub(crate) coherence: f64,
}

impl TruthArgs {
    pub(crate) fn params(&self) -> Result<Params> {
        Ok(Params {
            model: self.model,
            coherence_m: self.coherence,
        })
    }
}

/// Parse a non-zero direction `X,Y,Z`.
pub(crate) fn parse_axis(s: &str) -> std::result::Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| format!("'{s}': {e}"))?;
    match v[..] {
        [x, y, z] if [x, y, z].iter().all(|c| c.is_finite()) && x * x + y * y + z * z > 0.0 => {
            Ok([x, y, z])
        }
        _ => Err(format!(
            "'{s}': give three finite numbers X,Y,Z, not all zero"
        )),
    }
}

/// Parse `THETA[,PHI]` (angles with units, e.g. `60deg,90deg`).
pub(crate) fn parse_light(s: &str) -> sunbeam_common::Result<[f64; 3]> {
    use sunbeam_common::{units, Error};
    let (a, b) = s.split_once(',').unwrap_or((s, "0deg"));
    let th = units::parse_angle(a)?;
    let ph = units::parse_angle(b)?;
    if !(0.0..89.9f64.to_radians()).contains(&th.abs()) {
        return Err(Error::usage("the polar angle must be in [0, 89.9) degrees"));
    }
    Ok(sunbeam_analysis::sample::dir(th.abs(), ph))
}
