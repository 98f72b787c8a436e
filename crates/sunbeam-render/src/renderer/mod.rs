//! The diffraction renderer: buffers for meshes and packs, the pipeline of
//! the [`Mode`]'s technique, drawing into any colour target, and headless
//! frames.
//!
//! Each technique is a shader of its own: the shared shading
//! (shaders/diffraction.wgsl: the `Globals` and `Material` uniforms, the
//! vertex stage, `shade`) composed with the technique's file, which gives a
//! point light's diffraction term and the fragment entry point, and, where
//! it needs them, its own uniform and bind group:
//!
//! - the default mode: [`SHADER`], shaders/default.wgsl's `fs_main`, the
//!   response map ([`response_map`]) and the environment ([`environment`]:
//!   sky and map lighting, the extended-light maps). The Lambert mode is
//!   this pipeline with no pack bound (the base colour alone).
//! - the baselines (table, direct, thesis; behind the `baselines` feature,
//!   on by default): `baselines::BASELINE_SHADER`, shaders/baselines.wgsl's
//!   `fs_baseline` specialised per mode by a pipeline constant, with their
//!   own uniform (`Baseline`: series, crop, kernel, term and response
//!   tables) in bind group 3, which the default pipeline does not have.
//!
//! The shared parts: [`uniforms`] (the uniform structs, checked against the
//! WGSL), [`pipeline`] (layouts, buffers, the render pipeline), [`targets`]
//! (depth, colour and offscreen targets, readback), `cells_rate` (the
//! first-frame cells shaded on a coarser grid by a pre-pass, bind group 0's
//! bindings 2-4).

pub mod background;
#[cfg(feature = "baselines")]
pub mod baselines;
mod cells_rate;
pub mod environment;
pub mod pipeline;
pub mod response_map;
pub mod targets;
pub mod uniforms;

#[cfg(feature = "baselines")]
pub use baselines::term_table;
pub use cells_rate::{
    default_cells_rate, half_grid, DEFAULT_CELLS_RATE, DEFAULT_CELLS_RATE_LARGE, HALF_GRID_PATCH_M,
};
pub use targets::{
    colour_view, depth_view, depth_view_ms, lattice_jitter, subpixel_jitter, Offscreen,
    OFFSCREEN_FORMAT,
};

use crate::gpu::Gpu;
use pipeline::{
    bind_group_layouts, dummy_texture, mesh_buffers, render_pipeline, rgba8_texture, scale_wraps,
    Technique,
};
use std::sync::Arc;
use sunbeam_common::{Error, Result};
use sunbeam_frame::Prepared;
use sunbeam_optics::colour::{self, ToneCurve, ToneMap};
use sunbeam_scene::{camera, Background, Camera, Light};
use uniforms::{spectral_samples, spectrum_table, Globals, MaterialU};
use wgpu::util::DeviceExt;

/// The WGSL of a technique (`$technique`: its file, relative to this
/// folder, defining `point_xyz` and its fragment entry point): the skin's
/// material functions (shaders/material.wgsl: Fresnel, G, masking, the
/// diffuse base's share, the frame), the response-map material
/// (shaders/response_map.wgsl; both also what `--export-shader` translates),
/// the scale maps' frame (shaders/scales.wgsl), the environment's table and
/// the sun's disc (shaders/env_table.wgsl, shaders/sun_gain.wgsl), the shared shading
/// (shaders/diffraction.wgsl), the technique's file, and the environment's
/// estimators (shaders/environment.wgsl; shaders/env_cells.wgsl: the cells,
/// shared with the export; shaders/env_hotspots.wgsl: a map's hot spots as
/// lights).
macro_rules! player_shader {
    ($technique:literal) => {
        concat!(
            include_str!("../../../../shaders/material.wgsl"),
            include_str!("../../../../shaders/scales.wgsl"),
            include_str!("../../../../shaders/display.wgsl"),
            include_str!("../../../../shaders/env_table.wgsl"),
            include_str!("../../../../shaders/sun_gain.wgsl"),
            include_str!("../../../../shaders/response_map.wgsl"),
            include_str!("../../../../shaders/diffraction.wgsl"),
            include_str!($technique),
            include_str!("../../../../shaders/environment.wgsl"),
            include_str!("../../../../shaders/env_cells.wgsl"),
            include_str!("../../../../shaders/env_hotspots.wgsl")
        )
    };
}
// By path, for baselines.rs (`super::player_shader!`).
#[cfg(feature = "baselines")]
use player_shader;

/// The default technique's WGSL: the shared shading with shaders/default.wgsl
/// (the response map; `fs_main`).
pub const SHADER: &str = player_shader!("../../../../shaders/default.wgsl");

/// shaders/env_table.wgsl alone: the environment table's texel, the
/// equirectangular mapping and the sun's disc points (`sb_sun_disc_dir`),
/// which the player, the export and the background pass include.
pub const ENV_TABLE_WGSL: &str = include_str!("../../../../shaders/env_table.wgsl");

/// shaders/sun_gain.wgsl alone: G with the masking over the sun's disc as a
/// plane (`sb_sun_gain_plane`, `sb_sun_gain_at`; needs [`MATERIAL_WGSL`] and
/// [`ENV_TABLE_WGSL`]), the player's first-frame sun; the root package's
/// tests/sun_gain_wgsl.rs runs it against float64.
pub const SUN_GAIN_WGSL: &str = include_str!("../../../../shaders/sun_gain.wgsl");

/// shaders/material.wgsl alone: the skin's functions every shader calls
/// (`sb_fresnel`, `sb_gain`, `sb_masking`, `sb_base_transmission`, `sb_frame`);
/// [`SHADER`] and [`crate::export::SOURCE`] begin with it, and
/// the root package's tests/material_wgsl.rs runs it in a compute pass.
pub const MATERIAL_WGSL: &str = include_str!("../../../../shaders/material.wgsl");

/// Most lights a frame shades with.
pub const MAX_LIGHTS: usize = 4;
/// Most series terms the shader evaluates (packs with more are cut, with a warning).
pub const MAX_TERMS: usize = 64;
/// Most kernel taps per axis the shader supports.
pub const MAX_TAPS: usize = 16;
/// Entries of the per-|t| term-count table.
pub const TERM_TABLE: usize = 256;
/// Term count of the thesis mode.
pub const THESIS_TERMS: u32 = 39;

/// Which shading the pipeline does (table, direct and thesis: the
/// `baselines` feature).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// PHYSICS.md 2 through the pack's response map (sunbeam-response: built by
    /// `sunbeam-pack --response`, loaded; polar grid, filtered over the pixel footprint).
    #[default]
    Default,
    /// The former default: a Cartesian 256 x 256 x 32 table over (u, v, w) built on
    /// the CPU at load (crate::table). Kept as the benchmark baseline.
    Table,
    /// PHYSICS.md 2 summed per fragment (terms, taps, wavelengths), no table.
    Direct,
    /// The thesis' shader: fixed 39 terms, 5 nm steps, nearest bin.
    Thesis,
    /// Plain Lambert with the base colour (benchmark baseline).
    Lambert,
}

impl std::str::FromStr for Mode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "default" | "response" => Ok(Mode::Default),
            "table" | "direct" | "thesis" if !cfg!(feature = "baselines") => {
                Err(Error::usage(no_baselines(s)))
            }
            "table" => Ok(Mode::Table),
            "direct" => Ok(Mode::Direct),
            "thesis" => Ok(Mode::Thesis),
            "lambert" => Ok(Mode::Lambert),
            _ => Err(Error::usage(format!(
                "unknown mode '{s}' (default, table, direct, thesis, lambert)"
            ))),
        }
    }
}

impl Mode {
    /// True for the modes the `baselines` feature builds (table, direct, thesis).
    pub fn is_baseline(self) -> bool {
        matches!(self, Mode::Table | Mode::Direct | Mode::Thesis)
    }
}

/// Why a baseline mode is refused by a build without the `baselines` feature.
fn no_baselines(mode: &str) -> String {
    format!(
        "mode '{mode}' is a baseline, and this build of sunbeam-render has no `baselines` \
         feature (build with it: it is on by default)"
    )
}

/// Renderer settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub mode: Mode,
    /// Wavelength samples of the default mode (midpoints over 380..780 nm).
    pub lambda_samples: usize,
    pub curve: ToneCurve,
    /// Bound on |dR| from truncating the series per fragment (None: the pack's own
    /// tolerance or series bound, whichever is larger).
    pub term_tolerance: Option<f64>,
    /// Response table resolution of the table mode.
    #[cfg(feature = "baselines")]
    pub table: crate::table::Dims,
    /// How the default mode builds a response map when none is beside the pack.
    pub response: sunbeam_response::Options,
    /// Multisample count of the colour target (1 or 4): anti-aliased silhouettes.
    pub msaa: u32,
    /// Average the response over the pixel's footprint (up to 4 x 4 samples)
    /// instead of reading it at the pixel centre: the point lights' map in the
    /// default mode, and the environment's hot spots (cells estimator).
    pub footprint: bool,
    /// Environment: proposal samples per pixel per frame (crate::env).
    pub env_samples: u32,
    /// Environment: the first-frame cells or progressive Monte Carlo.
    pub env_estimator: crate::env::EnvEstimator,
    /// Environment, cells estimator: the top cut's cells (none: each pack's
    /// own, `sunbeam_response::cells::first_frame_top_for`) and the levels
    /// kept below it (sunbeam_response::cells).
    pub env_cells: (Option<usize>, usize),
    /// Environment, cells estimator: the map's hot spots pulled out as at most
    /// this many lights (sunbeam_light::hotspots; 0: none).
    pub env_hot_spots: usize,
    /// Environment, cells estimator: a texel is hot above this many times
    /// the map's mean (sunbeam_light::hotspots::SplitOptions::threshold).
    pub env_hot_threshold: f64,
    /// Environment, cells estimator: shade the cells on a grid of one pixel
    /// in K x K and interpolate where the surface is smooth, once per pixel
    /// elsewhere (1: once per pixel; 0: once per fragment, no pre-pass;
    /// docs/LIGHTING.md "Cells at a lower rate", "One walk per pixel").
    /// None: the finest of the defaults ([`default_cells_rate`]) of the
    /// packs whose meshes read the pre-passes.
    pub env_cells_rate: Option<u32>,
    /// Environment, cells estimator, a grid of K > 1: mix the grid's own
    /// points from every other grid point where those blocks of 2K pixels
    /// are smooth. None: where every reading pack is under
    /// [`HALF_GRID_PATCH_M`] ([`half_grid`]).
    pub env_cells_half: Option<bool>,
}

impl Settings {
    /// How the cells estimator picks the map's hot spots.
    pub fn hot_spot_options(&self) -> sunbeam_light::hotspots::SplitOptions {
        sunbeam_light::hotspots::SplitOptions {
            threshold: self.env_hot_threshold,
            max_lights: self.env_hot_spots,
        }
    }
}

/// Default wavelength sample count (docs/PLAY.md: chosen by measurement).
pub const DEFAULT_LAMBDA_SAMPLES: usize = 48;

impl Default for Settings {
    fn default() -> Self {
        Settings {
            mode: Mode::Default,
            lambda_samples: DEFAULT_LAMBDA_SAMPLES,
            curve: ToneCurve::default(),
            term_tolerance: None,
            #[cfg(feature = "baselines")]
            table: Default::default(),
            response: Default::default(),
            msaa: 4,
            footprint: true,
            env_samples: crate::env::DEFAULT_ENV_SAMPLES,
            env_estimator: crate::env::EnvEstimator::default(),
            env_cells: (
                Some(sunbeam_response::cells::DEFAULT_TOP),
                sunbeam_response::cells::DEFAULT_DEPTH,
            ),
            env_hot_spots: crate::env::DEFAULT_ENV_HOT_SPOTS,
            env_hot_threshold: crate::env::DEFAULT_ENV_HOT_THRESHOLD,
            env_cells_rate: None,
            env_cells_half: None,
        }
    }
}

/// What can change between frames (the window's orbit camera, light, exposure).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameState {
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub exposure: f64,
    pub background: Background,
    /// Pixels of this frame per side of one pixel of the image it stands
    /// for: 1, or `m` in a tile of edge refinement ([`crate::refine`]).
    /// Above 1 the cells' grid serves grazing views too: a texel is `1 / m`
    /// of the pixel, so the grid's blocks pass their tests at the limb, and
    /// the pixel's `m x m` positions there mix instead of each walking the
    /// cells in the centre pass (docs/LIGHTING.md "Edge refinement"). A
    /// supersampled frame keeps 1: at a few sub-pixels the grazing band is a
    /// texel or two wide, its blocks fail, and its grid points' walks were
    /// extra work (measured).
    pub sub_pixel: u32,
}

impl FrameState {
    pub fn from_scene(p: &Prepared) -> FrameState {
        FrameState {
            camera: p.scene.camera.clone(),
            lights: p.scene.lights.clone(),
            exposure: p.scene.exposure,
            background: p.scene.background,
            sub_pixel: 1,
        }
    }
}

/// The renderer of one prepared scene.
pub struct Renderer {
    pipeline: wgpu::RenderPipeline,
    globals: wgpu::Buffer,
    spectrum: wgpu::Buffer,
    /// Bind group 0's layout and the group with stand-ins for the cells' grid.
    global_layout: wgpu::BindGroupLayout,
    global_bind: wgpu::BindGroup,
    /// The cells' pre-passes: one walk per pixel, at a lower rate where
    /// the surface is smooth (environment scenes with the cells estimator).
    cells: Option<cells_rate::CellsRate>,
    /// The MSAA sample the next frame is read at (4: resolved; set_frame):
    /// the cells' pre-passes draw their points there.
    frame_sample: std::sync::atomic::AtomicU32,
    meshes: Vec<GpuMesh>,
    settings: Settings,
    n_lambda: u32,
    env: crate::env::EnvScene,
    /// The pass of `"background": "environment"`.
    background: Option<background::Background>,
    /// Colour target format the pipeline writes.
    pub format: wgpu::TextureFormat,
    /// Notes for the user (packs cut to MAX_TERMS, ...).
    pub warnings: Vec<String>,
    /// What start-up did that took time (environment maps built, ...).
    pub notes: Vec<String>,
}

/// The default mode's shader (and the Lambert mode's): `fs_main` of [`SHADER`],
/// with the environment's estimator as a pipeline constant (none: a scene
/// without an environment; shaders/environment.wgsl `SB_ENV_ESTIMATOR`: only
/// the path the scene takes is compiled).
fn default_technique(estimator: Option<crate::env::EnvEstimator>) -> Technique {
    Technique {
        label: "diffraction.wgsl",
        source: SHADER,
        entry: "fs_main",
        constants: vec![env_estimator_constant(estimator)],
    }
}

/// shaders/environment.wgsl `SB_ENV_ESTIMATOR` for `estimator` (none: the
/// pipeline shades no environment).
pub(super) fn env_estimator_constant(
    estimator: Option<crate::env::EnvEstimator>,
) -> (&'static str, f64) {
    (
        "SB_ENV_ESTIMATOR",
        f64::from(estimator.map_or(2, |e| e.index())),
    )
}

/// Depth format of every pass.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// One mesh on the GPU: its buffers and bind groups.
struct GpuMesh {
    vbuf: wgpu::Buffer,
    ibuf: wgpu::Buffer,
    count: u32,
    bind: wgpu::BindGroup,
    /// Bind group 2: the environment (this mesh's pack's maps, or stand-ins).
    env_bind: wgpu::BindGroup,
    /// Bind group 3 of the baselines' pipelines (none in the default's).
    technique_bind: Option<wgpu::BindGroup>,
}

impl GpuMesh {
    /// Set this mesh's bind groups 1-3 on `rp`.
    fn bind_groups(&self, rp: &mut wgpu::RenderPass<'_>) {
        rp.set_bind_group(1, &self.bind, &[]);
        rp.set_bind_group(2, &self.env_bind, &[]);
        if let Some(b) = &self.technique_bind {
            rp.set_bind_group(3, b, &[]);
        }
    }
}

impl Renderer {
    pub fn new(
        gpu: &Gpu,
        p: &Prepared,
        settings: &Settings,
        format: wgpu::TextureFormat,
    ) -> Result<Renderer> {
        let device = &gpu.device;
        let mut warnings = Vec::new();
        // The environment (docs/PLAY.md "Environment"): the default mode shades
        // it progressively; the Lambert baseline ignores it.
        let environment = environment::of_scene(p, settings.mode)?;
        let estimator = environment.as_ref().map(|_| settings.env_estimator);
        // The technique's shader and, for a baseline, its own bind group.
        #[cfg(feature = "baselines")]
        let (technique, mut baselines) = match baselines::technique(settings.mode) {
            Some(t) => (t, Some(baselines::Baselines::new(device))),
            None => (default_technique(estimator), None),
        };
        #[cfg(not(feature = "baselines"))]
        let technique = if settings.mode.is_baseline() {
            return Err(Error::usage(no_baselines(
                &format!("{:?}", settings.mode).to_lowercase(),
            )));
        } else {
            default_technique(estimator)
        };
        let samples = spectral_samples(settings);
        let spec = spectrum_table(&samples);
        let spectrum = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("spectrum"),
            contents: bytemuck::cast_slice(&spec),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("globals"),
            size: std::mem::size_of::<Globals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let [gl0, gl1] = bind_group_layouts(device);
        // The transmitted irradiance table is built for the first skin's index
        // (meshes with another index shade their diffuse part by Monte Carlo).
        let skin_ior = p
            .meshes
            .iter()
            .find(|(_, m)| m.pack.is_some())
            .map_or(sunbeam_optics::gain::Material::default().ior, |(_, m)| {
                m.skin.ior
            });
        let env_scene = crate::env::EnvScene::new(
            gpu,
            environment.clone(),
            settings.env_samples,
            settings.env_estimator,
            skin_ior,
            settings.hot_spot_options(),
            settings.footprint,
        );
        let mut notes = Vec::new();
        let mut env_maps: environment::BuiltMaps = Vec::new();
        // Response maps: angle repeats, radius and s clamp, trilinear.
        let resp_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("response map"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let dummy_view = Arc::new(dummy_texture(gpu));
        // Scale maps (sunbeam-bake --scales): one pair of textures per
        // distinct maps; a 1 x 1 stand-in for meshes without.
        let dummy_2d = Arc::new(rgba8_texture(gpu, [1, 1], &[0; 4]));
        type ScaleViews = (Arc<wgpu::TextureView>, Arc<wgpu::TextureView>);
        let mut scale_views: Vec<(Arc<sunbeam_frame::MeshScales>, ScaleViews)> = Vec::new();
        let mut resp_views: Vec<(Arc<sunbeam_response::Response>, Arc<wgpu::TextureView>)> =
            Vec::new();
        let global_bind = cells_rate::global_bind(
            device,
            &gl0,
            &globals,
            &spectrum,
            [&dummy_2d, &dummy_2d, &dummy_2d, &dummy_2d],
        );

        // The cells at a lower rate need a smooth term: the sky (its sun has
        // its own path) or a map whose hot spots are lights; a map's
        // softboxes seen by the cells themselves (`env_hot_spots` 0) are
        // sharp at the cells' scale (CIEDE2000 p99 8.3 against every pixel on
        // tests/threejs_render.rs' studio scene, 0.45 with its hot spots).
        let smooth_term =
            settings.env_hot_spots > 0 || env_scene.env.as_ref().is_some_and(|e| e.sun().is_some());
        // Which meshes read the cells' pre-passes: the one definition, which
        // the shaders take from `MaterialU::reads_cells`
        // (shaders/environment.wgsl `env_cells_read`, shaders/default.wgsl
        // `cells_shaded_here`). Not a mesh with scale maps under MSAA: its
        // samples resolve the frame's turns within the pixel and walk the
        // cells once at their mean (shaders/diffraction.wgsl `shade`); the
        // centre pass's value stands for the pixel centre, its test compares
        // normals only, and a sample on the next scale has another ridge
        // angle with a normal within ENV_LOWRES_OWN (docs/LIGHTING.md "Scale
        // borders"). A frame none of whose meshes reads them makes no
        // pre-passes, which would walk once per pixel for nothing
        // (docs/LIGHTING.md "One walk per pixel"). The default rate is the
        // finest of the packs of the meshes that read them.
        let reads_centre = |m: &sunbeam_frame::Material| {
            m.pack.is_some()
                && settings.mode != Mode::Lambert
                && !(m.scales.is_some() && settings.msaa >= 4)
        };
        let readers_patch = p
            .meshes
            .iter()
            .filter(|(_, m)| reads_centre(m))
            .filter_map(|(_, m)| m.pack.as_ref())
            .map(|pack| pack.manifest.patch.lx_m.max(pack.manifest.patch.ly_m))
            .reduce(f64::max);
        let readers_rate = readers_patch.map(default_cells_rate);
        // The half grid where every reading pack is small enough.
        let half = settings
            .env_cells_half
            .unwrap_or_else(|| readers_patch.is_some_and(half_grid));
        // Without a smooth term the centre pass alone (K = 1): one walk per
        // pixel, none interpolated.
        let cells_rate = readers_rate
            .filter(|_| {
                settings.mode == Mode::Default
                    && env_scene.env.is_some()
                    && settings.env_estimator == crate::env::EnvEstimator::Cells
            })
            .map(|rate| settings.env_cells_rate.unwrap_or(rate))
            .filter(|&rate| rate > 0)
            .map(|rate| if smooth_term { rate } else { 1 });
        // The pipelines compile on another thread while the meshes' maps are
        // read and uploaded below: neither needs the other, and each is about
        // a second of an environment scene's start-up on lavapipe
        // (docs/bench/play.md "Start-up").
        let compiled = {
            let device = device.clone();
            let adapter = gpu.adapter.clone();
            #[cfg_attr(not(feature = "baselines"), allow(unused_mut))]
            let mut owned = vec![gl0.clone(), gl1.clone(), env_scene.layout.clone()];
            #[cfg(feature = "baselines")]
            if let Some(b) = &baselines {
                owned.push(b.layout.clone());
            }
            let technique = technique.clone();
            let msaa = settings.msaa;
            let (globals, spectrum, stand_in) =
                (globals.clone(), spectrum.clone(), dummy_2d.clone());
            // A rayon task (the workspace's one pool, tests/architecture.rs);
            // a panic comes back as an error, not the pool's abort.
            let (tx, rx) = std::sync::mpsc::channel();
            rayon::spawn(move || {
                let built = std::panic::catch_unwind(std::panic::AssertUnwindSafe(
                    || -> Result<(wgpu::RenderPipeline, Option<cells_rate::CellsRate>)> {
                        let layouts: Vec<&wgpu::BindGroupLayout> = owned.iter().collect();
                        let pipeline =
                            render_pipeline(&device, &layouts, &[format], msaa, &technique)?;
                        let cells = match cells_rate {
                            Some(rate) => Some(cells_rate::CellsRate::new(
                                &adapter,
                                &device,
                                &layouts,
                                cells_rate::CellsGrid { rate, half },
                                &globals,
                                &spectrum,
                                &stand_in,
                            )?),
                            None => None,
                        };
                        Ok((pipeline, cells))
                    },
                ));
                let _ = tx.send(built.unwrap_or_else(|_| {
                    Err(Error::internal("creating the render pipelines panicked"))
                }));
            });
            rx
        };

        let mut meshes = Vec::new();
        for (mi, (mesh, mat)) in p.meshes.iter().enumerate() {
            let scales = mat.scales.as_deref();
            let (vbuf, ibuf) = mesh_buffers(device, mesh, scales);
            let mut mu = MaterialU {
                base: [
                    mat.base_color[0] as f32,
                    mat.base_color[1] as f32,
                    mat.base_color[2] as f32,
                    mat.diffuse_weight as f32,
                ],
                mask_sx: mat.masking.rms_slope()[0] as f32,
                mask_sy: mat.masking.rms_slope()[1] as f32,
                ior: mat.skin.ior as f32,
                norm: mat.skin.norm() as f32,
                scales_on: u32::from(scales.is_some()),
                scales_wrap: scales.map_or(0, scale_wraps),
                reads_cells: u32::from(reads_centre(mat)),
                cells_id: mi as u32 + 1,
                ..Default::default()
            };
            let mut resp_map: Option<Arc<sunbeam_response::Response>> = None;
            #[cfg_attr(not(feature = "baselines"), allow(unused_variables))]
            let mesh_pack = match &mat.pack {
                Some(pack) if settings.mode != Mode::Lambert => {
                    let m = &pack.manifest;
                    if m.kernel.taps > MAX_TAPS {
                        return Err(Error::input(format!(
                            "meshes[{mi}].pack: kernel has {} taps, the player supports up to {MAX_TAPS}",
                            m.kernel.taps
                        )));
                    }
                    let used = m.terms.min(MAX_TERMS);
                    if m.terms > MAX_TERMS {
                        warnings.push(format!(
                            "meshes[{mi}].pack has {} terms; the player uses the first {MAX_TERMS}",
                            m.terms
                        ));
                    }
                    mu.has_pack = 1;
                    // The point map serves point lights only: an environment scene
                    // without any needs just the environment's maps (built below).
                    let point_lit = environment.is_none() || !p.scene.lights.is_empty();
                    if settings.mode == Mode::Default && point_lit {
                        let path = p.scene.meshes.get(mi).and_then(|m| m.pack.as_deref());
                        resp_map = Some(response_map::point_map(
                            pack,
                            path,
                            settings,
                            &mut mu,
                            &mut warnings,
                        )?);
                    }
                    // The energy bound (sunbeam_optics::energy) of an
                    // absolute skin, from the map's tables; the thesis mode
                    // keeps the thesis' unbounded model.
                    if settings.mode != Mode::Thesis
                        && mat.skin.reflectance == sunbeam_optics::gain::Reflectance::Absolute
                    {
                        let path = p.scene.meshes.get(mi).and_then(|m| m.pack.as_deref());
                        let info = crate::response::energy_info(
                            pack,
                            path,
                            &settings.response,
                            resp_map.as_ref(),
                            &mut warnings,
                        )?;
                        let masked = mat.masking != sunbeam_optics::masking::Masking::Off;
                        mu.energy = info.bound(mat.skin, masked).columns();
                    }
                    Some((pack, used))
                }
                _ => None,
            };
            #[cfg(feature = "baselines")]
            let technique_bind = match baselines.as_mut() {
                Some(b) => Some(b.bind(
                    device,
                    mesh_pack.map(|(pack, used)| baselines::MeshPack { pack, used }),
                    settings,
                    &samples,
                    mi,
                )?),
                None => None,
            };
            #[cfg(not(feature = "baselines"))]
            let technique_bind = None;
            let mbuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("material"),
                contents: bytemuck::bytes_of(&mu),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let resp_view = match &resp_map {
                Some(r) => resp_views
                    .iter()
                    .find(|(k, _)| Arc::ptr_eq(k, r))
                    .map(|(_, v)| v.clone())
                    .unwrap_or_else(|| {
                        let v = Arc::new(crate::response::response_texture(gpu, r));
                        resp_views.push((r.clone(), v.clone()));
                        v
                    }),
                None => dummy_view.clone(),
            };
            let (scale_normal, scale_orient) = match &mat.scales {
                Some(sc) => scale_views
                    .iter()
                    .find(|(k, _)| Arc::ptr_eq(k, sc))
                    .map(|(_, v)| v.clone())
                    .unwrap_or_else(|| {
                        let (n, o) = (&sc.maps.normal, &sc.maps.orient);
                        let v = (
                            Arc::new(rgba8_texture(gpu, n.size, &n.data)),
                            Arc::new(rgba8_texture(gpu, o.size, &o.data)),
                        );
                        scale_views.push((sc.clone(), v.clone()));
                        v
                    }),
                None => (dummy_2d.clone(), dummy_2d.clone()),
            };
            let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("material"),
                layout: &gl1,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: mbuf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: wgpu::BindingResource::TextureView(&resp_view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: wgpu::BindingResource::Sampler(&resp_sampler),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: wgpu::BindingResource::TextureView(&scale_normal),
                    },
                    wgpu::BindGroupEntry {
                        binding: 7,
                        resource: wgpu::BindingResource::TextureView(&scale_orient),
                    },
                ],
            });
            let maps = match (&environment, &mat.pack) {
                (Some(env), Some(pack)) => Some(environment::maps(
                    gpu,
                    env,
                    pack,
                    p.scene.meshes.get(mi).and_then(|m| m.pack.as_deref()),
                    mi,
                    &settings.response,
                    settings.env_cells,
                    settings.env_estimator,
                    &mut env_maps,
                    &mut notes,
                    &mut warnings,
                )?),
                _ => None,
            };
            let env_bind = env_scene.bind(gpu, maps.as_deref());
            meshes.push(GpuMesh {
                vbuf,
                ibuf,
                count: mesh.indices.len() as u32,
                bind,
                env_bind,
                technique_bind,
            });
        }

        let (pipeline, cells) = compiled
            .recv()
            .map_err(|_| Error::internal("the render pipelines were never built"))??;
        // `"background": "environment"`: the lighting's table and sun (or,
        // in the Lambert mode, which lights without them, the same built here).
        let background = match (&p.scene.background, &p.environment) {
            (Background::Environment, Some(e)) => {
                let own;
                let es = if env_scene.env.is_some() {
                    &env_scene
                } else {
                    own = crate::env::EnvScene::new(
                        gpu,
                        Some(e.clone()),
                        1,
                        crate::env::EnvEstimator::MonteCarlo,
                        1.5,
                        sunbeam_light::hotspots::SplitOptions {
                            max_lights: 0,
                            ..Default::default()
                        },
                        false,
                    );
                    &own
                };
                Some(background::Background::new(gpu, es, format, settings.msaa)?)
            }
            (Background::Environment, None) => {
                return Err(Error::input(
                    "background \"environment\" needs an \"environment\" in the scene",
                ))
            }
            _ => None,
        };
        Ok(Renderer {
            pipeline,
            background,
            globals,
            spectrum,
            global_layout: gl0,
            global_bind,
            cells,
            frame_sample: std::sync::atomic::AtomicU32::new(4),
            meshes,
            settings: settings.clone(),
            n_lambda: spec.len() as u32,
            env: env_scene,
            format,
            warnings,
            notes,
        })
    }

    /// True when frames are Monte Carlo estimates to accumulate (a scene
    /// environment in the default mode): see crate::accum.
    pub fn progressive(&self) -> bool {
        self.env.env.is_some()
    }

    /// Set the frame index that seeds the next frame's random numbers, the
    /// part of the pixel along each axis the frame stands for (1 alone) and
    /// the MSAA sample it is read at (4: the resolved pixel).
    pub fn set_frame(&self, gpu: &Gpu, frame: u32, share: f32, sample: u32) {
        self.frame_sample
            .store(sample, std::sync::atomic::Ordering::Relaxed);
        if self.progressive() {
            self.env.set_frame(gpu, frame, share, sample);
        }
    }

    /// Upload the per-frame uniforms for a `w x h` target.
    pub fn update(&self, gpu: &Gpu, state: &FrameState, w: u32, h: u32) {
        self.update_jittered(gpu, state, w, h, [0.0; 2]);
    }

    /// [`Renderer::update`] with the image shifted by `jitter` pixels (x
    /// right, y down): the progressive sum's frames each take another
    /// sub-pixel position ([`subpixel_jitter`], or [`lattice_jitter`] for a
    /// sum of planned length), so the settled frame is the
    /// average over each pixel's area, as a camera sees it (and as the
    /// reference's stratified sub-pixel samples are), not the shading at its
    /// centre.
    pub fn update_jittered(&self, gpu: &Gpu, state: &FrameState, w: u32, h: u32, jitter: [f64; 2]) {
        let mut vpm = state.camera.view_proj(w, h);
        // clip.x += (2 jx / w) clip.w, clip.y -= (2 jy / h) clip.w (NDC y is up).
        let (jx, jy) = (
            2.0 * jitter[0] / w.max(1) as f64,
            -2.0 * jitter[1] / h.max(1) as f64,
        );
        for c in &mut vpm {
            c[0] += jx * c[3];
            c[1] += jy * c[3];
        }
        let vp = camera::to_f32(&vpm);
        let mut lights = [[0.0f32; 4]; MAX_LIGHTS];
        let mut light_colors = [[0.0f32; 4]; MAX_LIGHTS];
        let mut n = 0;
        for l in state.lights.iter().take(MAX_LIGHTS) {
            let d = l.direction;
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if !(len > 0.0 && len.is_finite()) {
                continue;
            }
            lights[n] = [
                (d[0] / len) as f32,
                (d[1] / len) as f32,
                (d[2] / len) as f32,
                l.intensity as f32,
            ];
            let c = l.color;
            light_colors[n] = [c[0] as f32, c[1] as f32, c[2] as f32, 0.0];
            n += 1;
        }
        let m = colour::XYZ_TO_SRGB;
        let row = |r: usize| [m[r][0] as f32, m[r][1] as f32, m[r][2] as f32, 0.0];
        let g = Globals {
            view_proj: vp,
            eye: [
                state.camera.eye[0] as f32,
                state.camera.eye[1] as f32,
                state.camera.eye[2] as f32,
                1.0,
            ],
            lights,
            light_colors,
            xyz_to_rgb: [row(0), row(1), row(2)],
            background: {
                let b = state.background.colour().unwrap_or([0.0; 3]);
                [b[0] as f32, b[1] as f32, b[2] as f32, 1.0]
            },
            n_lights: n as u32,
            cells_band: self.cells.as_ref().map_or(0, |c| c.band_rows(w, h)),
            curve: match self.settings.curve {
                ToneCurve::Clamp => 0,
                ToneCurve::Reinhard => 1,
            },
            output: if self.format == OFFSCREEN_FORMAT {
                2
            } else {
                u32::from(self.format.is_srgb())
            },
            exposure_scale: state.exposure.exp2() as f32,
            n_lambda: self.n_lambda,
            msaa: self.msaa(),
            cells_rate: self.env_cells_rate(),
            cells_grazing: u32::from(state.sub_pixel > 1),
            _pad: [0; 3],
        };
        if let Some(c) = &self.cells {
            c.prepare(
                gpu,
                &self.global_layout,
                &self.globals,
                &self.spectrum,
                w,
                h,
            );
        }
        gpu.queue
            .write_buffer(&self.globals, 0, bytemuck::bytes_of(&g));
        if let Some(bg) = &self.background {
            bg.update(
                gpu,
                &background::BgFrame {
                    camera: &state.camera,
                    size: [w, h],
                    exposure_scale: g.exposure_scale,
                    curve: g.curve,
                    output: g.output,
                    keep_negative: self.progressive(),
                },
            );
        }
    }

    /// The clear colour: the background through the display transform (linear
    /// for an sRGB target); black under `"background": "environment"` (its
    /// pass draws over it).
    pub fn clear_colour(&self, state: &FrameState) -> wgpu::Color {
        let background = state.background.colour().unwrap_or([0.0; 3]);
        let tm = ToneMap {
            exposure_ev: state.exposure,
            curve: self.settings.curve,
        };
        let mut e = colour::display_encode(background, &tm);
        if self.format == OFFSCREEN_FORMAT {
            // Offscreen targets hold linear light times the exposure (the shader's
            // output 2); the display transform follows on the CPU.
            let k = state.exposure.exp2();
            e = background.map(|v| (v * k).max(0.0));
        } else if self.format.is_srgb() {
            e = e.map(colour::srgb_eotf);
        }
        wgpu::Color {
            r: e[0],
            g: e[1],
            b: e[2],
            // offscreen: the meshes' coverage (crate::Offscreen)
            a: if self.format == OFFSCREEN_FORMAT {
                0.0
            } else {
                1.0
            },
        }
    }

    /// The cells' pre-passes' grid spacing K (docs/LIGHTING.md "Cells at a
    /// lower rate"); 0 when the frame has none (no cells, or no fragment
    /// would read them: every fragment walks the cells itself).
    pub fn env_cells_rate(&self) -> u32 {
        self.cells.as_ref().map_or(0, |c| c.rate())
    }

    /// Whether the cells' grid mixes its points from the half grid where
    /// its blocks of 2K pixels are smooth (packs under
    /// [`HALF_GRID_PATCH_M`]).
    pub fn env_cells_half(&self) -> bool {
        self.cells.as_ref().is_some_and(|c| c.half())
    }

    /// Multisample count of the pipeline (the colour and depth targets must match).
    pub fn msaa(&self) -> u32 {
        self.settings.msaa.max(1)
    }

    /// Tone curve of the display transform.
    pub fn curve(&self) -> ToneCurve {
        self.settings.curve
    }

    /// Record a frame into `colour` (with `depth` of the same size and sample
    /// count); with MSAA, `colour` is the multisampled target and `resolve` the
    /// single-sample one that receives the average.
    pub fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        colour: &wgpu::TextureView,
        resolve: Option<&wgpu::TextureView>,
        depth: &wgpu::TextureView,
        state: &FrameState,
    ) {
        // a frame read at one MSAA sample: the pre-passes' points are that
        // sample's, not the pixel centres, so the frame's pass reads the
        // cells at its own point (targets::frame_sample)
        let sample = self.frame_sample.load(std::sync::atomic::Ordering::Relaxed);
        let shift = targets::MSAA_POSITIONS
            .get(sample as usize)
            .map_or([0.0; 2], |p| [p[0] as f32, p[1] as f32]);
        match &self.cells {
            Some(c) => c.encode(
                enc,
                &self.global_bind,
                shift,
                |rp| self.draw_meshes(rp),
                |rp| self.draw_fullscreen(rp),
                |enc, g0| self.encode_frame(enc, g0, colour, resolve, depth, state),
            ),
            None => self.encode_frame(enc, &self.global_bind, colour, resolve, depth, state),
        }
    }

    /// Groups 1-3 of each mesh and a full-screen triangle.
    fn draw_fullscreen(&self, rp: &mut wgpu::RenderPass<'_>) {
        for m in self.meshes.iter().filter(|m| m.count > 0) {
            m.bind_groups(rp);
            rp.draw(0..3, 0..1);
        }
    }

    /// Groups 1-3 and the draw of each mesh.
    fn draw_meshes(&self, rp: &mut wgpu::RenderPass<'_>) {
        for m in self.meshes.iter().filter(|m| m.count > 0) {
            m.bind_groups(rp);
            rp.set_vertex_buffer(0, m.vbuf.slice(..));
            rp.set_index_buffer(m.ibuf.slice(..), wgpu::IndexFormat::Uint32);
            rp.draw_indexed(0..m.count, 0, 0..1);
        }
    }

    /// The frame's pass, with bind group `g0`.
    fn encode_frame(
        &self,
        enc: &mut wgpu::CommandEncoder,
        g0: &wgpu::BindGroup,
        colour: &wgpu::TextureView,
        resolve: Option<&wgpu::TextureView>,
        depth: &wgpu::TextureView,
        state: &FrameState,
    ) {
        let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("frame"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: colour,
                depth_slice: None,
                resolve_target: resolve,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(self.clear_colour(state)),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        rp.set_pipeline(&self.pipeline);
        rp.set_bind_group(0, g0, &[]);
        self.draw_meshes(&mut rp);
        if let Some(bg) = &self.background {
            bg.draw(&mut rp);
        }
    }
}

#[cfg(test)]
mod env_estimator_constant_tests {
    //! The environment's estimator reaches the shaders twice: the uniform
    //! `EnvGlobals::estimator` and the pipeline constant `SB_ENV_ESTIMATOR`
    //! that prunes the other paths. naga resolves the constants as wgpu does
    //! for each pipeline, so a renamed or retyped override fails here, not
    //! on the first GPU that builds the pipeline.
    use super::*;
    use crate::env::EnvEstimator;

    /// naga's resolution of `technique`'s constants (an error names a
    /// constant the shader lacks or a value its type refuses).
    fn resolves(source: &str, technique: &Technique) {
        let module = naga::front::wgsl::parse_str(source).expect("the shader parses");
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .expect("the shader validates");
        let constants = technique
            .constants
            .iter()
            .map(|&(k, v)| (k.to_string(), v))
            .collect();
        naga::back::pipeline_constants::process_overrides(
            &module,
            &info,
            Some((naga::ShaderStage::Fragment, technique.entry)),
            &constants,
        )
        .unwrap_or_else(|e| panic!("{}: {e:?}", technique.label));
    }

    #[test]
    fn each_estimator_is_a_constant_the_shader_takes() {
        for (estimator, want) in [
            (Some(EnvEstimator::Cells), 0.0),
            (Some(EnvEstimator::MonteCarlo), 1.0),
            (None, 2.0),
        ] {
            let t = default_technique(estimator);
            assert_eq!(t.constants, [("SB_ENV_ESTIMATOR", want)], "{estimator:?}");
            resolves(t.source, &t);
        }
        // the uniform's numbering is the constant's
        assert_eq!(EnvEstimator::Cells.index(), 0);
        assert_eq!(EnvEstimator::MonteCarlo.index(), 1);
    }

    #[cfg(feature = "baselines")]
    #[test]
    fn the_baselines_take_no_environment() {
        for mode in [Mode::Table, Mode::Direct, Mode::Thesis] {
            let t = baselines::technique(mode).unwrap();
            assert!(t.constants.contains(&("SB_ENV_ESTIMATOR", 2.0)), "{mode:?}");
            resolves(t.source, &t);
        }
    }
}
