//! Command line of sunbeam-bake (clap).

use clap::{Parser, ValueEnum};
use std::path::PathBuf;

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum UvDir {
    U,
    V,
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
