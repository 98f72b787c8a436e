//! Command line of sunbeam-bake (clap).

use clap::{Parser, ValueEnum};
use std::path::PathBuf;

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum UvDir {
    U,
    V,
}

/// `--reflectance` values (the scene's `meshes[].reflectance`).
#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum ReflectanceArg {
    Absolute,
    Relative,
}

/// `--masking` values (the scene's `meshes[].masking`).
#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum MaskingArg {
    Off,
    Smith,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum InterpArg {
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
pub(crate) struct Cli {
    /// Input mesh: .gltf (with its buffers), .glb or .obj (told apart by content).
    pub(crate) mesh: Option<PathBuf>,
    /// Output GLB ("-" for stdout).
    #[arg(short, long)]
    pub(crate) output: PathBuf,

    /// Term pack whose diffraction the GLB's materials render: writes the
    /// SUNBEAM_materials_diffraction extension naming the pack and its response
    /// map (NAME.response.ktx2 beside it, from sunbeam-pack --response), by paths
    /// relative to the output (docs/ENGINES.md).
    #[arg(long, value_name = "PACK")]
    pub(crate) pack: Option<PathBuf>,
    /// Diffuse weight written with --pack (the scene's diffuse_weight, docs/SCENE.md).
    #[arg(long, default_value_t = 0.2, requires = "pack")]
    pub(crate) diffuse_weight: f64,
    /// The skin's refractive index written with --pack (`ior`; the scene's
    /// meshes[].ior, in (1, 4]).
    #[arg(long, value_name = "N", default_value_t = 1.5, requires = "pack",
          value_parser = ior)]
    pub(crate) ior: f64,
    /// Reflectance written with --pack (`reflectance`): absolute (physical, what
    /// engines assume for a dielectric) or relative (divided by F(0)).
    #[arg(long, value_enum, default_value = "absolute", requires = "pack")]
    pub(crate) reflectance: ReflectanceArg,
    /// Shadowing-masking written with --pack (`masking`): off, or smith (Smith with
    /// Beckmann slopes: --rms-slope, else the pack's own rms_slope).
    #[arg(long, value_enum, default_value = "off", requires = "pack")]
    pub(crate) masking: MaskingArg,
    /// The rms slopes smith uses, "S" or "SX,SY" (along the tangent, along the
    /// bitangent), written as `rmsSlope`; none: the pack's.
    #[arg(long, value_name = "S[,SY]", requires = "pack", allow_hyphen_values = true,
          value_parser = rms_slope)]
    pub(crate) rms_slope: Option<[f64; 2]>,

    /// A world direction projected onto each tangent plane.
    #[arg(
        long,
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        group = "source"
    )]
    pub(crate) axis: Option<String>,
    /// A spine polyline (JSON {"points": [[x,y,z], ...]}): the tangent at the nearest spine point, projected.
    #[arg(long, value_name = "SPINE.json", group = "source")]
    pub(crate) curve: Option<PathBuf>,
    /// Scattered samples (CSV or JSON: x,y,z,dx,dy,dz or u,v,angle_deg), interpolated in UV space.
    #[arg(long, value_name = "FILE", group = "source")]
    pub(crate) samples: Option<PathBuf>,
    /// The direction of increasing u or v.
    #[arg(long, value_enum, group = "source")]
    pub(crate) uv_direction: Option<UvDir>,

    /// Extra rotation about the normal, degrees (counter-clockwise seen from outside).
    #[arg(
        long,
        value_name = "A",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub(crate) rotate_deg: f64,
    /// TEXCOORD set the UV modes use.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub(crate) uv_set: usize,
    /// Interpolation of --samples in UV space.
    #[arg(long, value_enum, default_value = "natural")]
    pub(crate) interpolation: InterpArg,
    /// 3D samples farther than this from the surface (mesh units) are rejected [default: 2% of the bounding-box diagonal].
    #[arg(long, value_name = "DIST")]
    pub(crate) max_snap: Option<f64>,

    /// Also write a tangent-space direction map in UV space (.png or .exr).
    #[arg(long, value_name = "FILE")]
    pub(crate) texture: Option<PathBuf>,
    /// Texture size in texels (square).
    #[arg(long, value_name = "N", default_value_t = 1024)]
    pub(crate) texture_size: u32,
    /// Texels to dilate the map across UV seams and island borders.
    #[arg(long, value_name = "PX", default_value_t = 8)]
    pub(crate) texture_dilate: u32,

    /// Generate the procedural demo snake instead of reading MESH (default source: --curve along its own spine).
    #[arg(long)]
    pub(crate) generate_snake: bool,
    /// Snake resolution factor (vertices grow with its square; 1 = about 29k vertices).
    #[arg(long, value_name = "K", default_value_t = 1.0)]
    pub(crate) snake_detail: f64,
    /// Write the snake's spine polyline (JSON, for --curve) here.
    #[arg(long, value_name = "FILE")]
    pub(crate) spine_out: Option<PathBuf>,

    /// Bake scales (docs/BAKE.md "Scales"): a tiling in the UV layout (u along the
    /// body, v around it, v periodic), written as the material's normalTexture and
    /// the SUNBEAM_materials_diffraction orientationTexture; TANGENT becomes the UV
    /// frame (+u), _ORIENTATION keeps the field. Needs UVs.
    #[arg(long)]
    pub(crate) scales: bool,
    /// Scale rows around the body (one turn of v).
    #[arg(long, value_name = "N", default_value_t = 20, requires = "scales",
          value_parser = clap::value_parser!(u32).range(3..=200))]
    pub(crate) scale_rows: u32,
    /// Scale length along the body, in scale widths.
    #[arg(long, value_name = "L", default_value_t = 1.0, requires = "scales",
          value_parser = sunbeam_common::cli::ranged(0.25, 4.0))]
    pub(crate) scale_length: f64,
    /// Overlap of a scale's free edge over the scale behind it, in scale lengths.
    #[arg(long, value_name = "F", default_value_t = 0.3, requires = "scales",
          value_parser = sunbeam_common::cli::ranged(0.0, 0.6))]
    pub(crate) scale_overlap: f64,
    /// Dome height of a scale, in scale widths.
    #[arg(long, value_name = "H", default_value_t = 0.06, requires = "scales",
          value_parser = sunbeam_common::cli::ranged(0.0, 0.3))]
    pub(crate) scale_dome: f64,
    /// Keel height of a scale (a ridge along its midline), in scale widths; 0: smooth.
    #[arg(long, value_name = "H", default_value_t = 0.0, requires = "scales",
          value_parser = sunbeam_common::cli::ranged(0.0, 0.1))]
    pub(crate) scale_keel: f64,
    /// Tilt of the free edge, degrees (the scale's normal turns toward the head).
    #[arg(long, value_name = "DEG", default_value_t = 6.0, requires = "scales",
          allow_hyphen_values = true, value_parser = sunbeam_common::cli::ranged(-30.0, 30.0))]
    pub(crate) scale_tilt: f64,
    /// Per-scale jitter of the tilt (uniform in +-DEG).
    #[arg(long, value_name = "DEG", default_value_t = 4.0, requires = "scales",
          value_parser = sunbeam_common::cli::ranged(0.0, 20.0))]
    pub(crate) scale_tilt_jitter: f64,
    /// Per-scale jitter of the ridge angle about the normal (uniform in +-DEG).
    #[arg(long, value_name = "DEG", default_value_t = 6.0, requires = "scales",
          value_parser = sunbeam_common::cli::ranged(0.0, 45.0))]
    pub(crate) scale_ridge_jitter: f64,
    /// Texels across one scale width (reduced when a side would pass 8192).
    #[arg(long, value_name = "N", default_value_t = 32, requires = "scales",
          value_parser = clap::value_parser!(u32).range(4..=256))]
    pub(crate) scale_texels: u32,
    /// Seed of the per-scale jitter.
    #[arg(long, value_name = "N", default_value_t = 1, requires = "scales")]
    pub(crate) scale_seed: u64,

    /// Print a JSON report on stdout.
    #[arg(long)]
    pub(crate) json: bool,
    /// Write a Make-style depfile.
    #[arg(long, value_name = "FILE")]
    pub(crate) depfile: Option<PathBuf>,
    /// Quiet: no diagnostics but errors.
    #[arg(short, long)]
    pub(crate) quiet: bool,
    /// Verbose: print the report summary on stderr.
    #[arg(short, long)]
    pub(crate) verbose: bool,
}

/// A clap value parser for a finite f64 in [lo, hi].
/// `--ior`: in (1, 4], as the scene's meshes[].ior.
fn ior(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number"))?;
    if v > 1.0 && v <= 4.0 {
        Ok(v)
    } else {
        Err(format!("{v} is outside (1, 4]"))
    }
}

/// `--rms-slope`: one slope for both axes or two, each finite and >= 0.
fn rms_slope(s: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = s.split(',').collect();
    let parse = |t: &str| -> Result<f64, String> {
        let v: f64 = t
            .trim()
            .parse()
            .map_err(|_| format!("{t:?} is not a number"))?;
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(format!("{v} is not a slope (finite, >= 0)"))
        }
    };
    match parts.as_slice() {
        [a] => parse(a).map(|a| [a, a]),
        [a, b] => Ok([parse(a)?, parse(b)?]),
        _ => Err(format!("{s:?}: expected S or SX,SY")),
    }
}
