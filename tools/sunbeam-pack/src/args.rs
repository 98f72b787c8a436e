//! Command line of sunbeam-pack (clap).

use clap::{Parser, ValueEnum};
use std::path::PathBuf;
use sunbeam_common::cli::{length_range, pixel_size, positive_length, PixelSize};
use sunbeam_pack::Model;
pub(crate) const TOOL: &str = "sunbeam-pack";

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum BasisArg {
    Chebyshev,
    Taylor,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum PrecisionArg {
    F32,
    F16,
}

/// Build a diffraction term pack (KTX2 2D array or EXR) from a height field.
#[derive(Parser, Debug)]
#[command(name = "sunbeam-pack", version, about, long_about = None)]
pub(crate) struct Cli {
    /// Height field: EXR/GSF from sunbeam-import, or any AFM file / image sunbeam-import reads.
    pub(crate) height: PathBuf,
    /// Output pack: PACK.ktx2 or PACK.exr.
    #[arg(short = 'o', long = "output")]
    pub(crate) output: PathBuf,
    /// Basis of the height expansion.
    #[arg(long, value_enum, default_value = "chebyshev")]
    pub(crate) basis: BasisArg,
    /// Model of what lies beyond the patch (PHYSICS.md 2).
    #[arg(long, default_value = "window", value_parser = sunbeam_common::cli::one_of::<Model>(&Model::NAMES))]
    pub(crate) model: Model,
    /// Spatial coherence length of the light.
    #[arg(long, default_value = "65um", value_parser = positive_length)]
    pub(crate) coherence: f64,
    /// Wavelength range.
    #[arg(long, default_value = "380nm..780nm", value_parser = length_range)]
    pub(crate) lambda: (f64, f64),
    /// Bound on max |dR| that picks the term count.
    #[arg(long, conflicts_with = "terms")]
    pub(crate) max_error: Option<f64>,
    /// Fixed term count (the error bound is reported).
    #[arg(long)]
    pub(crate) terms: Option<usize>,
    /// Storage precision.
    #[arg(long, value_enum, default_value = "f32")]
    pub(crate) precision: PrecisionArg,
    /// Largest |w| = cos(theta_i) + cos(theta_r) to cover (2: all directions).
    #[arg(long, default_value_t = 2.0)]
    pub(crate) max_w: f64,
    /// Derive wavelength range, largest |w| and reachable frequencies from a scene (sunbeam-scene JSON).
    #[arg(long)]
    pub(crate) scene: Option<PathBuf>,
    /// EXR: one file per term (PACK.nNN.exr) with plain R/G channels.
    #[arg(long)]
    pub(crate) split: bool,
    /// EXR: all terms in one grid atlas with plain R/G channels.
    #[arg(long)]
    pub(crate) atlas: bool,
    /// Also write the manifest as JSON here.
    #[arg(long)]
    pub(crate) manifest: Option<PathBuf>,
    /// Kaiser-Bessel taps per axis (window model; even).
    #[arg(long, default_value_t = 6)]
    pub(crate) taps: usize,
    /// Pixel size for files without calibration (e.g. 65nm or 65nm,70nm).
    #[arg(long, value_parser = pixel_size)]
    pub(crate) pixel_size: Option<PixelSize>,
    /// Height of the full grey range for uncalibrated images (e.g. 375nm).
    #[arg(long, value_parser = positive_length)]
    pub(crate) z_range: Option<f64>,
    /// Channel to use (name or index) in multi-channel AFM files.
    #[arg(long)]
    pub(crate) channel: Option<String>,
    /// Accept NaN/Inf heights or a height range beyond 1 mm (docs/IMPORT.md).
    #[arg(long)]
    pub(crate) allow_implausible: bool,
    /// Worker threads (the output does not depend on it).
    #[arg(long)]
    pub(crate) threads: Option<usize>,
    /// Also write the response map the player and engines read (docs/PACK_FORMAT.md
    /// "Response map"): beside the pack as NAME.response.ktx2, or to --response-out;
    /// and the environment's maps beside it as NAME.env-response.ktx2.
    #[arg(long)]
    pub(crate) response: bool,
    /// The scene whose sky's sun the environment's maps (NAME.env-response.ktx2,
    /// written with --response) hold the sun's map for (implies --response;
    /// default: the sky of `sunbeam-play --mesh M --pack P`).
    #[arg(long, value_name = "SCENE.json")]
    pub(crate) response_sky: Option<PathBuf>,
    /// Where to write the response map (implies --response).
    #[arg(long, value_name = "FILE.ktx2")]
    pub(crate) response_out: Option<PathBuf>,
    /// Also write the response map as an OpenEXR atlas for DCC tools (implies --response).
    #[arg(long, value_name = "FILE.exr")]
    pub(crate) response_exr: Option<PathBuf>,
    /// Wavelength samples of the response map's colour integral.
    #[arg(long, default_value_t = sunbeam_response::build::DEFAULT_LAMBDA_SAMPLES)]
    pub(crate) response_lambda: usize,
    /// Size bound of the response map (e.g. 64MiB; RGBA16F texels).
    #[arg(long, default_value = "64MiB", value_name = "SIZE", value_parser = sunbeam_common::cli::byte_size)]
    pub(crate) response_budget: usize,
    /// The first-frame cells written with --response beside the environment's
    /// maps as NAME.env-cells.ktx2, for these `sunbeam-play --env-cells` counts
    /// (comma-separated, each 1..=4096; default: the player's default for
    /// this pack, 512 for a patch under 10 um, 1024 from it; docs/PACK_FORMAT.md
    /// "Cells file"): the player and the engines' export cluster any other
    /// count at start.
    #[arg(long, value_name = "N[,N...]", value_delimiter = ',', value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub(crate) response_cells: Vec<u64>,
    /// Print a JSON report on stdout.
    #[arg(long)]
    pub(crate) json: bool,
    /// Write a Make-style depfile.
    #[arg(long)]
    pub(crate) depfile: Option<PathBuf>,
    /// Quiet: no warnings or progress.
    #[arg(short, long)]
    pub(crate) quiet: bool,
    /// Verbose: print the plan.
    #[arg(short, long)]
    pub(crate) verbose: bool,
}
