//! Command line of sunbeam-play (clap).

use clap::Parser;
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(
    name = "sunbeam-play",
    version,
    about = "Diffraction colour from term packs: window or headless frames"
)]
pub(crate) struct Cli {
    /// Scene file (JSON, docs/SCENE.md). Or use --mesh and --pack.
    pub(crate) scene: Option<PathBuf>,
    /// Mesh (GLB/glTF/OBJ, or builtin:quad / builtin:sphere) for the default scene.
    #[arg(long)]
    pub(crate) mesh: Option<PathBuf>,
    /// Pack (KTX2/EXR) for the default scene.
    #[arg(long)]
    pub(crate) pack: Option<PathBuf>,
    /// What lights the default scene of --mesh/--pack: the built-in sky (default) or the
    /// point light (docs/SCENE.md "The default scene").
    #[arg(long, default_value = "sky", value_parser = clap::builder::PossibleValuesParser::new(["sky", "point"]))]
    pub(crate) lighting: String,
    /// Render offscreen (no window) and write -o.
    #[arg(long)]
    pub(crate) headless: bool,
    /// Output FRAME.png (display values) or FRAME.exr (headless: linear light, exposure
    /// applied), or the PNG screenshot of the window (with --frames).
    #[arg(short, long)]
    pub(crate) output: Option<PathBuf>,
    /// Multisample anti-aliasing of silhouettes: 1 (off) or 4. Default 4, except for
    /// a headless environment scene accumulated over --frames > 1 (1: the frames'
    /// sub-pixel jitter is its anti-aliasing, an exact box filter; MSAA on top widens it).
    #[arg(long)]
    pub(crate) msaa: Option<u32>,
    /// Headless: render K x K times the size and box-filter in linear light.
    #[arg(long, default_value_t = 1)]
    pub(crate) supersample: u32,
    /// Headless: render again, at M x M positions each, the pixels whose sub-pixels
    /// (with their neighbours') disagree: silhouettes, the limb's sheen, scale
    /// borders (0..=64; 0: off; tiles of about 256 x 256 positions; after --supersample and
    /// --frames; docs/LIGHTING.md "Edge refinement").
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=sunbeam_render::refine::MAX_POSITIONS as i64))]
    pub(crate) edge_supersample: u32,
    /// Headless, --edge-supersample: besides the outlines, a pixel is refined where a
    /// sub-pixel's luminance differs from its neighbours' mean by more than this times
    /// the pixel's mean (0.001..=10: a gradient is not flagged, a step of 4x this is),
    /// and so are its neighbours.
    #[arg(long, default_value_t = sunbeam_render::refine::DEFAULT_THRESHOLD, value_parser = sunbeam_common::cli::ranged(0.001, 10.0))]
    pub(crate) edge_threshold: f64,
    /// Headless, --edge-supersample M: levels of refinement (1..=4). Each further level
    /// renders again, at twice the positions per side, the refined pixels whose
    /// positions are still unsettled: one of their four interleaved quarter-lattices
    /// off the pixel's mean by more than --edge-threshold (M even; M doubled at the
    /// last level at most 64).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4))]
    pub(crate) edge_levels: u32,
    /// Read the response maps at the pixel centre only (no footprint filter): the point
    /// lights' map, and the environment's hot spots and the sun's disc points under the
    /// cells estimator.
    #[arg(long)]
    pub(crate) no_footprint: bool,
    /// Frame size WxH (headless: default the scene's size; window: initial size).
    #[arg(long, value_name = "WxH", value_parser = sunbeam_common::units::parse_size)]
    pub(crate) size: Option<(usize, usize)>,
    /// Headless: frames rendered (the last one is written; environment scenes: the
    /// average of the N frames). Window: exit after N frames.
    #[arg(long)]
    pub(crate) frames: Option<u32>,
    /// Window: seconds to keep showing after --frames.
    #[arg(long, default_value_t = 0.0)]
    pub(crate) hold_secs: f64,
    /// GPU backend.
    #[arg(long, default_value = "auto", value_parser = |s: &str| s.parse::<sunbeam_render::Backend>())]
    pub(crate) backend: sunbeam_render::Backend,
    /// Shading: default (response map), table (the former Cartesian table, built at load),
    /// direct (per-fragment sum), thesis (39 terms, 5 nm, nearest bin), lambert (base colour only).
    #[arg(long, default_value = "default", value_parser = |s: &str| s.parse::<sunbeam_render::Mode>())]
    pub(crate) mode: sunbeam_render::Mode,
    /// Same as --mode thesis.
    #[arg(long)]
    pub(crate) thesis: bool,
    /// Same as --mode lambert.
    #[arg(long)]
    pub(crate) lambert: bool,
    /// Environment scenes: proposal samples of the diffraction lobes per pixel per
    /// frame (the sun and the diffuse part take one each).
    #[arg(long, default_value_t = sunbeam_render::env::DEFAULT_ENV_SAMPLES)]
    pub(crate) env_samples: u32,
    /// Environment scenes: `monte-carlo` (progressive, unbiased, settles over
    /// thousands of frames), `cells` (close in the first frame, frames only
    /// anti-alias; on a CPU rasteriser tens of times a Lambert frame) or `auto`
    /// (the default: `cells` for a single headless frame, the one written;
    /// `monte-carlo` in the window, for `--frames` > 1 and for `--bench`).
    /// docs/LIGHTING.md "The first frame".
    #[arg(long, value_enum, default_value_t = EnvEstimatorArg::Auto)]
    pub(crate) env_estimator: EnvEstimatorArg,
    /// Environment scenes, `--env-estimator cells`: cells every view visits
    /// (1..4096; more: closer to the reference, slower; default: each pack's
    /// own, 512 for a patch under 10 um, 1024 from it; docs/LIGHTING.md "How
    /// many cells").
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub(crate) env_cells: Option<u64>,
    /// Environment scenes, `--env-estimator cells`: the map's hot spots (its
    /// lamps, softboxes) as at most this many small lights through the maps,
    /// the rest for the cells (0..=256; 0: none; docs/LIGHTING.md "The first
    /// frame"); `--export-environment` writes them for the engines too.
    #[arg(long, default_value_t = sunbeam_render::env::DEFAULT_ENV_HOT_SPOTS as u64, value_parser = clap::value_parser!(u64).range(0..=256))]
    pub(crate) env_hot_spots: u64,
    /// Environment scenes, `--env-estimator cells`: a map's texel is a hot
    /// spot above this many times the map's mean brightness (1..=1000; lower:
    /// more of the map through the exact lights, but broad bright regions are
    /// poorly served by a light's four taps; docs/LIGHTING.md "Hot spots as
    /// lights").
    #[arg(long, default_value_t = sunbeam_render::env::DEFAULT_ENV_HOT_THRESHOLD, value_parser = sunbeam_common::cli::ranged(1.0, 1000.0))]
    pub(crate) env_hot_threshold: f64,
    /// Environment scenes, `--env-estimator cells`: shade the cells on a grid
    /// of one pixel in K x K and interpolate them where the surface is smooth,
    /// elsewhere at every other pixel and interpolate those where they allow,
    /// once per pixel where not (1..=16; 1: once per pixel; 0: once per
    /// fragment, every triangle touching a pixel, the slow path kept for
    /// comparisons; default: 4 for a patch under 32 um, 2 from 32 um, the
    /// finest of the scene's packs; docs/LIGHTING.md "Cells at a lower
    /// rate").
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=16))]
    pub(crate) env_cells_rate: Option<u32>,
    /// Environment scenes, `--env-estimator cells`, a grid of 2 and up: mix
    /// the grid's own points from every other grid point where those blocks
    /// of 2K pixels are smooth, and walk the rest (true or false; default:
    /// true where every pack is under 10 um, the size it was measured at;
    /// docs/LIGHTING.md "The half grid").
    #[arg(long)]
    pub(crate) env_cells_half: Option<bool>,
    /// Wavelength samples of the default mode.
    #[arg(long, default_value_t = sunbeam_render::renderer::DEFAULT_LAMBDA_SAMPLES)]
    pub(crate) lambda_samples: usize,
    /// Truncation bound on |dR| per fragment (default: the pack's).
    #[arg(long)]
    pub(crate) term_tolerance: Option<f64>,
    /// Tone curve after exposure: clamp or reinhard.
    #[arg(long, default_value = "clamp", value_parser = |s: &str| s.parse::<sunbeam_optics::colour::ToneCurve>())]
    pub(crate) tone: sunbeam_optics::colour::ToneCurve,
    /// Exposure in stops (overrides the scene's).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) exposure: Option<f64>,
    /// Render with the CPU reference (sunbeam-raster) instead of the GPU.
    #[arg(long)]
    pub(crate) cpu: bool,
    /// Compare the frame with a reference: PNG (8-bit, every pixel) or EXR (linear,
    /// lit pixels): CIEDE2000 mean / p99 / max in the report.
    #[arg(long)]
    pub(crate) compare: Option<PathBuf>,
    /// Headless benchmark: time --frames frames (default 10) and print the frame times.
    #[arg(long)]
    pub(crate) bench: bool,
    /// Print a JSON report on stdout.
    #[arg(long)]
    pub(crate) json: bool,
    /// Write a Make depfile for -o.
    #[arg(long)]
    pub(crate) depfile: Option<PathBuf>,
    /// Write the diffraction material's shader for another engine to -o and exit:
    /// glsl (4.50), glsl-es (3.00, WebGL2), hlsl, msl, spv (SPIR-V), wgsl (docs/ENGINES.md).
    #[arg(long, value_name = "LANG", value_parser = sunbeam_common::cli::one_of::<sunbeam_render::export::Lang>(&sunbeam_render::export::Lang::NAMES))]
    pub(crate) export_shader: Option<sunbeam_render::export::Lang>,
    /// Write the scene's environment for engines into DIR and exit: its prefiltered
    /// table, irradiance tables and each pack's cells, as KTX2, with
    /// environment.json (what `sunbeam_shade_environment` of --export-shader binds;
    /// docs/ENGINES.md "Environment"). Needs a scene with "environment".
    #[arg(long, value_name = "DIR")]
    pub(crate) export_environment: Option<PathBuf>,
    /// Less output.
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

/// `--env-estimator` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum EnvEstimatorArg {
    Auto,
    Cells,
    MonteCarlo,
}
