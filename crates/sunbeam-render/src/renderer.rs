//! The diffraction renderer: buffers for meshes and packs, the pipeline of
//! shaders/diffraction.wgsl, drawing into any colour target, and headless frames.

use crate::gpu::Gpu;
use std::sync::Arc;
use sunbeam_common::{Error, Result};
use sunbeam_frame::spectral::Samples;
use sunbeam_frame::{Image, LinearImage, Prepared};
use sunbeam_optics::cie;
use sunbeam_optics::colour::{self, ToneCurve, ToneMap};
use sunbeam_pack::{Basis, Model, Pack};
use sunbeam_scene::{camera, Camera, Light};
use wgpu::util::DeviceExt;

/// The WGSL source: the skin's material functions (shaders/material.wgsl:
/// Fresnel, G, masking, the diffuse base's share, the frame), the response-map
/// material (shaders/response_map.wgsl; both also what `--export-shader`
/// translates), the player's shading (shaders/diffraction.wgsl) and the
/// environment's estimator (shaders/environment.wgsl).
pub const SHADER: &str = concat!(
    include_str!("../../../shaders/material.wgsl"),
    include_str!("../../../shaders/response_map.wgsl"),
    include_str!("../../../shaders/diffraction.wgsl"),
    include_str!("../../../shaders/environment.wgsl")
);

/// shaders/material.wgsl alone: the skin's functions every shader calls
/// (`sb_fresnel`, `sb_gain`, `sb_masking`, `sb_base_transmission`, `sb_frame`);
/// [`SHADER`] and [`crate::export::SOURCE`] begin with it, and
/// the root package's tests/material_wgsl.rs runs it in a compute pass.
pub const MATERIAL_WGSL: &str = include_str!("../../../shaders/material.wgsl");

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

/// Which shading the pipeline does.
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
    pub table: crate::table::Dims,
    /// How the default mode builds a response map when none is beside the pack.
    pub response: sunbeam_response::Options,
    /// Multisample count of the colour target (1 or 4): anti-aliased silhouettes.
    pub msaa: u32,
    /// Default mode: average the response over the pixel's footprint (up to 4 x 4
    /// samples) instead of reading it at the pixel centre.
    pub footprint: bool,
    /// Environment: proposal samples per pixel per frame (crate::env).
    pub env_samples: u32,
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
            table: Default::default(),
            response: Default::default(),
            msaa: 4,
            footprint: true,
            env_samples: crate::env::DEFAULT_ENV_SAMPLES,
        }
    }
}

/// What can change between frames (the window's orbit camera, light, exposure).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameState {
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub exposure: f64,
    pub background: [f64; 3],
}

impl FrameState {
    pub fn from_scene(p: &Prepared) -> FrameState {
        FrameState {
            camera: p.scene.camera.clone(),
            lights: p.scene.lights.clone(),
            exposure: p.scene.exposure,
            background: p.scene.background,
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    pos: [f32; 3],
    normal: [f32; 3],
    tangent: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Globals {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    lights: [[f32; 4]; MAX_LIGHTS],
    xyz_to_rgb: [[f32; 4]; 3],
    background: [f32; 4],
    n_lights: u32,
    mode: u32,
    curve: u32,
    output: u32,
    exposure_scale: f32,
    n_lambda: u32,
    /// Samples per pixel of the colour target (the shader tells covered pixels from silhouettes).
    msaa: u32,
    _g0: u32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Default)]
struct MaterialU {
    base: [f32; 4],
    has_pack: u32,
    basis: u32,
    model: u32,
    taps: u32,
    crop_w: u32,
    crop_h: u32,
    kx: i32,
    ky: i32,
    terms: u32,
    fixed_terms: u32,
    n_table: u32,
    _p0: u32,
    bin_scale_um: [f32; 2],
    half_range_um: f32,
    beta: f32,
    sigma_bins: [f32; 2],
    kb_norm: f32,
    table_dt: f32,
    tab_nu: u32,
    tab_nv: u32,
    tab_nw: u32,
    tab_on: u32,
    tab_u0: f32,
    tab_du: f32,
    tab_dv: f32,
    tab_w0: f32,
    tab_dw: f32,
    mask_sx: f32,
    mask_sy: f32,
    /// The skin's refractive index (scene `meshes[].ior`).
    ior: f32,
    resp_on: u32,
    resp_n_theta: f32,
    resp_n_rho: f32,
    resp_n_s: f32,
    resp_r0: f32,
    resp_rho_scale: f32,
    resp_footprint: u32,
    /// What G is divided by: `sunbeam_optics::gain::Material::norm` (1
    /// absolute, F(0) relative).
    norm: f32,
    /// The window's sigma in um (window model: R_U in the direct mode), 0 = R.
    window_sigma_um: f32,
    _s: [f32; 3],
}

struct GpuMesh {
    vbuf: wgpu::Buffer,
    ibuf: wgpu::Buffer,
    count: u32,
    bind: wgpu::BindGroup,
    /// Bind group 2: the environment (this mesh's pack's maps, or stand-ins).
    env_bind: wgpu::BindGroup,
}

/// Smallest term count whose truncation bound stays below `tol` for every |t| up to `t`.
fn terms_for(basis: Basis, t: f64, tol: f64, start: usize, cap: usize) -> usize {
    let mut n = start.max(1);
    while n < cap && sunbeam_pack::series::tail_bound_upto(basis, t, n) >= tol {
        n += 1;
    }
    n
}

/// The per-|t| term table of a pack: entry i covers |t| <= (i + 1) dt.
pub fn term_table(pack: &Pack, t_max: f64, tol: f64) -> (Vec<u32>, f64) {
    let m = &pack.manifest;
    let cap = m.terms.min(MAX_TERMS);
    let dt = (t_max / TERM_TABLE as f64).max(1e-6);
    let mut out = Vec::with_capacity(TERM_TABLE);
    let mut n = 1;
    for i in 0..TERM_TABLE {
        n = terms_for(m.basis, (i + 1) as f64 * dt, tol, n, cap);
        out.push(n as u32);
    }
    (out, dt)
}

/// The renderer of one prepared scene.
pub struct Renderer {
    pipeline: wgpu::RenderPipeline,
    globals: wgpu::Buffer,
    global_bind: wgpu::BindGroup,
    meshes: Vec<GpuMesh>,
    settings: Settings,
    n_lambda: u32,
    env: crate::env::EnvScene,
    /// Colour target format the pipeline writes.
    pub format: wgpu::TextureFormat,
    /// Notes for the user (packs cut to MAX_TERMS, ...).
    pub warnings: Vec<String>,
    /// What start-up did that took time (environment maps built, ...).
    pub notes: Vec<String>,
}

/// Depth format of every pass.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

impl Renderer {
    pub fn new(
        gpu: &Gpu,
        p: &Prepared,
        settings: &Settings,
        format: wgpu::TextureFormat,
    ) -> Result<Renderer> {
        let device = &gpu.device;
        let mut warnings = Vec::new();
        let samples = spectral_samples(settings);
        let spec = spectrum_table(&samples);
        let lambda_min = samples
            .0
            .iter()
            .map(|s| s.lambda_m)
            .fold(f64::INFINITY, f64::min);
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
        // The environment (docs/PLAY.md "Environment"): the default mode shades
        // it progressively; the Lambert baseline ignores it.
        let environment = match settings.mode {
            Mode::Default => p.environment.clone(),
            Mode::Lambert => None,
            m => {
                if p.environment.is_some() {
                    return Err(Error::usage(format!(
                        "environment: the player shades sky and map lighting in the default mode only (not --mode {})",
                        format!("{m:?}").to_lowercase()
                    )));
                }
                None
            }
        };
        let env_scene = crate::env::EnvScene::new(gpu, environment.clone(), settings.env_samples);
        let mut notes = Vec::new();
        let mut env_maps: Vec<(*const Pack, Arc<crate::env::EnvMaps>)> = Vec::new();
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
        let mut resp_views: Vec<(Arc<sunbeam_response::Response>, Arc<wgpu::TextureView>)> =
            Vec::new();
        let global_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("globals"),
            layout: &gl0,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: globals.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: spectrum.as_entire_binding(),
                },
            ],
        });

        // Packs: one terms buffer per distinct pack.
        let max_binding = device.limits().max_storage_buffer_binding_size;
        let mut pack_bufs: Vec<(*const Pack, Arc<wgpu::Buffer>, usize)> = Vec::new();
        let mut meshes = Vec::new();
        for (mi, (mesh, mat)) in p.meshes.iter().enumerate() {
            let (vbuf, ibuf) = mesh_buffers(device, mesh);
            let mut mu = MaterialU {
                base: [
                    mat.base_color[0] as f32,
                    mat.base_color[1] as f32,
                    mat.base_color[2] as f32,
                    mat.diffuse_weight as f32,
                ],
                n_table: 1,
                table_dt: 1.0,
                mask_sx: mat.masking.rms_slope()[0] as f32,
                mask_sy: mat.masking.rms_slope()[1] as f32,
                ior: mat.skin.ior as f32,
                norm: mat.skin.norm() as f32,
                ..Default::default()
            };
            let mut response: Option<Vec<[f32; 4]>> = None;
            let mut resp_map: Option<Arc<sunbeam_response::Response>> = None;
            let (terms_buf, table): (Arc<wgpu::Buffer>, Vec<u32>) = match &mat.pack {
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
                    let key = Arc::as_ptr(pack);
                    // Only the per-fragment modes read the terms on the GPU; the
                    // default and table modes read their precomputed maps.
                    let gpu_terms = matches!(settings.mode, Mode::Direct | Mode::Thesis);
                    let buf = match pack_bufs.iter().find(|(k, _, _)| *k == key) {
                        Some((_, b, _)) => b.clone(),
                        None if !gpu_terms => {
                            let b = Arc::new(device.create_buffer_init(
                                &wgpu::util::BufferInitDescriptor {
                                    label: Some("no terms"),
                                    contents: bytemuck::cast_slice(&[0.0f32; 4]),
                                    usage: wgpu::BufferUsages::STORAGE,
                                },
                            ));
                            pack_bufs.push((key, b.clone(), used));
                            b
                        }
                        None => {
                            let n = used * m.layer_texels() * 2;
                            let bytes = (n * 4) as u64;
                            if bytes > max_binding {
                                return Err(Error::input(format!(
                                    "meshes[{mi}].pack: {used} terms of {}x{} ({} MiB) exceed this GPU's storage \
                                     buffer limit ({} MiB); build the pack with fewer terms or a smaller crop",
                                    m.crop.width,
                                    m.crop.height,
                                    bytes >> 20,
                                    max_binding >> 20
                                )));
                            }
                            let b = Arc::new(device.create_buffer_init(
                                &wgpu::util::BufferInitDescriptor {
                                    label: Some("terms"),
                                    contents: bytemuck::cast_slice(&pack.terms[..n]),
                                    usage: wgpu::BufferUsages::STORAGE,
                                },
                            ));
                            pack_bufs.push((key, b.clone(), used));
                            b
                        }
                    };
                    let (table, dt) = pack_uniforms(&mut mu, pack, used, settings, lambda_min);
                    // The point map serves point lights only: an environment scene
                    // without any needs just the environment's maps (built below).
                    let point_lit = environment.is_none() || !p.scene.lights.is_empty();
                    if settings.mode == Mode::Default && point_lit {
                        let path = p.scene.meshes.get(mi).and_then(|m| m.pack.as_deref());
                        let t0 = std::time::Instant::now();
                        let (resp, note) =
                            crate::response::load_or_build(pack, path, &settings.response)?;
                        log::info!(
                            "response map {:?} ready in {:.2?}",
                            resp.info.grid,
                            t0.elapsed()
                        );
                        warnings.extend(note);
                        let gr = resp.info.grid;
                        mu.resp_on = 1;
                        mu.resp_n_theta = gr.n_theta as f32;
                        mu.resp_n_rho = gr.n_rho as f32;
                        mu.resp_n_s = gr.n_s as f32;
                        mu.resp_r0 = gr.r0 as f32;
                        mu.resp_rho_scale = gr.rho_scale() as f32;
                        mu.resp_footprint = u32::from(settings.footprint);
                        resp_map = Some(resp);
                    }
                    if settings.mode == Mode::Table {
                        let t0 = std::time::Instant::now();
                        let tt = table.clone();
                        let terms_at = move |at: f64| -> usize {
                            let i = ((at / dt).floor() as usize).min(tt.len() - 1);
                            tt[i] as usize
                        };
                        let rt = crate::table::build(pack, &samples, settings.table, &terms_at);
                        let bytes = (rt.data.len() * 16) as u64;
                        if bytes > max_binding {
                            return Err(Error::input(format!(
                                "meshes[{mi}]: the response table ({} MiB) exceeds this GPU's storage buffer limit; \
                                 use a smaller table",
                                bytes >> 20
                            )));
                        }
                        log::info!("response table {:?} built in {:.2?}", rt.dims, t0.elapsed());
                        mu.tab_nu = rt.dims.nu as u32;
                        mu.tab_nv = rt.dims.nv as u32;
                        mu.tab_nw = rt.dims.nw as u32;
                        mu.tab_on = 1;
                        mu.tab_u0 = crate::table::U_MIN as f32;
                        mu.tab_du = rt.du as f32;
                        mu.tab_dv = rt.dv as f32;
                        mu.tab_w0 = crate::table::W_MIN as f32;
                        mu.tab_dw = rt.dw as f32;
                        response = Some(rt.data);
                    }
                    (buf, table)
                }
                _ => (
                    Arc::new(
                        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some("no terms"),
                            contents: bytemuck::cast_slice(&[0.0f32; 4]),
                            usage: wgpu::BufferUsages::STORAGE,
                        }),
                    ),
                    vec![1u32],
                ),
            };
            let mbuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("material"),
                contents: bytemuck::bytes_of(&mu),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let tbuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("term table"),
                contents: bytemuck::cast_slice(&table),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let rdata = response.unwrap_or_else(|| vec![[0.0f32; 4]]);
            let rbuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("response table"),
                contents: bytemuck::cast_slice(&rdata),
                usage: wgpu::BufferUsages::STORAGE,
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
            let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("material"),
                layout: &gl1,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: mbuf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: terms_buf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: tbuf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: rbuf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: wgpu::BindingResource::TextureView(&resp_view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: wgpu::BindingResource::Sampler(&resp_sampler),
                    },
                ],
            });
            let maps = match (&environment, &mat.pack) {
                (Some(env), Some(pack)) => {
                    let key = Arc::as_ptr(pack);
                    match env_maps.iter().find(|(k, _)| *k == key) {
                        Some((_, m)) => Some(m.clone()),
                        None => {
                            if !pack.has_terms() {
                                return Err(Error::internal(format!(
                                    "meshes[{mi}].pack: the environment's maps need the pack's terms (read it whole)"
                                )));
                            }
                            let t0 = std::time::Instant::now();
                            let er =
                                sunbeam_response::env::build_env(pack, env, &settings.response);
                            notes.push(format!(
                                "built the environment's response maps for meshes[{mi}].pack ({} x {} x {} texels, {} maps, \
                                 {} pyramid levels) in {:.2} s",
                                er.grid.n_theta,
                                er.grid.n_rho,
                                er.grid.n_s,
                                er.basis.len() + usize::from(er.sun.is_some()),
                                er.proposal.offsets.len(),
                                t0.elapsed().as_secs_f64()
                            ));
                            let m = Arc::new(crate::env::EnvMaps::new(gpu, &er)?);
                            env_maps.push((key, m.clone()));
                            Some(m)
                        }
                    }
                }
                _ => None,
            };
            let env_bind = env_scene.bind(gpu, maps.as_deref());
            meshes.push(GpuMesh {
                vbuf,
                ibuf,
                count: mesh.indices.len() as u32,
                bind,
                env_bind,
            });
        }

        let pipeline = render_pipeline(
            device,
            [&gl0, &gl1, &env_scene.layout],
            format,
            settings.msaa,
        )?;
        Ok(Renderer {
            pipeline,
            globals,
            global_bind,
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

    /// Set the frame index that seeds the next frame's random numbers.
    pub fn set_frame(&self, gpu: &Gpu, frame: u32) {
        if self.progressive() {
            self.env.set_frame(gpu, frame);
        }
    }

    /// Upload the per-frame uniforms for a `w x h` target.
    pub fn update(&self, gpu: &Gpu, state: &FrameState, w: u32, h: u32) {
        self.update_jittered(gpu, state, w, h, [0.0; 2]);
    }

    /// [`Renderer::update`] with the image shifted by `jitter` pixels (x
    /// right, y down): the progressive sum's frames each take another
    /// sub-pixel position ([`subpixel_jitter`]), so the settled frame is the
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
            xyz_to_rgb: [row(0), row(1), row(2)],
            background: [
                state.background[0] as f32,
                state.background[1] as f32,
                state.background[2] as f32,
                1.0,
            ],
            n_lights: n as u32,
            mode: match self.settings.mode {
                Mode::Default | Mode::Table => 0,
                Mode::Thesis => 1,
                Mode::Lambert => 2,
                Mode::Direct => 3,
            },
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
            _g0: 0,
        };
        gpu.queue
            .write_buffer(&self.globals, 0, bytemuck::bytes_of(&g));
    }

    /// The clear colour: the background through the display transform (linear for an sRGB target).
    pub fn clear_colour(&self, state: &FrameState) -> wgpu::Color {
        let tm = ToneMap {
            exposure_ev: state.exposure,
            curve: self.settings.curve,
        };
        let mut e = colour::display_encode(state.background, &tm);
        if self.format == OFFSCREEN_FORMAT {
            // Offscreen targets hold linear light times the exposure (the shader's
            // output 2); the display transform follows on the CPU.
            let k = state.exposure.exp2();
            e = state.background.map(|v| (v * k).max(0.0));
        } else if self.format.is_srgb() {
            e = e.map(colour::srgb_eotf);
        }
        wgpu::Color {
            r: e[0],
            g: e[1],
            b: e[2],
            a: 1.0,
        }
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
        rp.set_bind_group(0, &self.global_bind, &[]);
        for m in &self.meshes {
            if m.count == 0 {
                continue;
            }
            rp.set_bind_group(1, &m.bind, &[]);
            rp.set_bind_group(2, &m.env_bind, &[]);
            rp.set_vertex_buffer(0, m.vbuf.slice(..));
            rp.set_index_buffer(m.ibuf.slice(..), wgpu::IndexFormat::Uint32);
            rp.draw_indexed(0..m.count, 0, 0..1);
        }
    }
}

/// The pack's part of a material's uniforms (series, crop, kernel, per-|t| term
/// table; docs/PACK_FORMAT.md "Evaluation"): the term table and its |t| step.
fn pack_uniforms(
    mu: &mut MaterialU,
    pack: &Pack,
    used: usize,
    settings: &Settings,
    lambda_min: f64,
) -> (Vec<u32>, f64) {
    let m = &pack.manifest;
    let h = m.height_half_range_m;
    let t_max = 4.0 * std::f64::consts::PI * h / lambda_min;
    let tol = settings
        .term_tolerance
        .unwrap_or_else(|| m.error.tolerance.unwrap_or(0.0).max(m.error.series_bound))
        .max(1e-12);
    let (table, dt) = term_table(pack, t_max, tol);
    let w = m.kernel.taps as f64;
    mu.has_pack = 1;
    mu.basis = match m.basis {
        Basis::Chebyshev => 0,
        Basis::Taylor => 1,
    };
    mu.model = match m.model {
        Model::Window => 0,
        Model::Tiled => 1,
    };
    mu.taps = m.kernel.taps as u32;
    mu.crop_w = m.crop.width as u32;
    mu.crop_h = m.crop.height as u32;
    mu.kx = m.crop.kx as i32;
    mu.ky = m.crop.ky as i32;
    mu.terms = used as u32;
    mu.fixed_terms = if settings.mode == Mode::Thesis {
        THESIS_TERMS
    } else {
        0
    };
    mu.n_table = table.len() as u32;
    mu.bin_scale_um = [
        (m.bin_scale_m[0] * 1e6) as f32,
        (m.bin_scale_m[1] * 1e6) as f32,
    ];
    mu.half_range_um = (h * 1e6) as f32;
    mu.beta = m.kernel.beta as f32;
    mu.sigma_bins = [m.kernel.sigma_bins[0] as f32, m.kernel.sigma_bins[1] as f32];
    mu.kb_norm = if m.kernel.beta > 0.0 {
        (m.kernel.beta / (w * m.kernel.beta.sinh())) as f32
    } else {
        0.0
    };
    mu.table_dt = dt as f32;
    // PHYSICS.md 2b's exact grazing term (Pack::shading_reflectance) in the
    // direct mode; the thesis mode keeps the thesis' R.
    mu.window_sigma_um = if m.model == Model::Window && settings.mode == Mode::Direct {
        (m.window_sigma_m * 1e6) as f32
    } else {
        0.0
    };
    (table, dt)
}

/// Wavelength samples of a mode: the thesis' 5 nm steps, else `lambda_samples` midpoints.
fn spectral_samples(settings: &Settings) -> Samples {
    match settings.mode {
        Mode::Thesis => Samples::stepped(380, 780, 5),
        _ => Samples::uniform(settings.lambda_samples.max(1), cie::DEFAULT_RANGE_NM),
    }
}

/// The spectrum buffer of the shader: XYZ weight and 1 / lambda in 1/um per sample.
fn spectrum_table(samples: &Samples) -> Vec<[f32; 4]> {
    samples
        .0
        .iter()
        .map(|s| {
            [
                s.weight[0] as f32,
                s.weight[1] as f32,
                s.weight[2] as f32,
                (1e-6 / s.lambda_m) as f32,
            ]
        })
        .collect()
}

/// Bind group layouts: 0 = globals and spectrum, 1 = one material (uniforms,
/// terms, term table, response table, response map and its sampler).
fn bind_group_layouts(device: &wgpu::Device) -> [wgpu::BindGroupLayout; 2] {
    let storage_entry = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let uniform_entry = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let gl0 = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("globals"),
        entries: &[uniform_entry(0), storage_entry(1)],
    });
    let gl1 = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("material"),
        entries: &[
            uniform_entry(0),
            storage_entry(1),
            storage_entry(2),
            storage_entry(3),
            wgpu::BindGroupLayoutEntry {
                binding: 4,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D3,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 5,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
        ],
    });
    [gl0, gl1]
}

/// Vertex and index buffers of a mesh (one dummy element when empty).
fn mesh_buffers(device: &wgpu::Device, mesh: &sunbeam_frame::Mesh) -> (wgpu::Buffer, wgpu::Buffer) {
    let mut verts: Vec<Vertex> = (0..mesh.positions.len())
        .map(|i| Vertex {
            pos: mesh.positions[i],
            normal: mesh.normals[i],
            tangent: mesh.tangents[i],
        })
        .collect();
    if verts.is_empty() {
        verts.push(Vertex::zeroed());
    }
    let vbuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("vertices"),
        contents: bytemuck::cast_slice(&verts),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let ibuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("indices"),
        contents: bytemuck::cast_slice(if mesh.indices.is_empty() {
            &[0u32][..]
        } else {
            &mesh.indices
        }),
        usage: wgpu::BufferUsages::INDEX,
    });
    (vbuf, ibuf)
}

/// The pipeline of shaders/diffraction.wgsl for a colour format and sample count.
fn render_pipeline(
    device: &wgpu::Device,
    layouts: [&wgpu::BindGroupLayout; 3],
    format: wgpu::TextureFormat,
    msaa: u32,
) -> Result<wgpu::RenderPipeline> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("diffraction.wgsl"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("diffraction"),
        bind_group_layouts: &[Some(layouts[0]), Some(layouts[1]), Some(layouts[2])],
        immediate_size: 0,
    });
    let vlayout = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x4],
    };
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("diffraction"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(vlayout)],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: Some(wgpu::Face::Back),
            front_face: wgpu::FrontFace::Ccw,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: msaa.max(1),
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    });
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(Error::internal(format!(
            "shader/pipeline creation failed: {e}"
        )));
    }
    Ok(pipeline)
}

/// A 1x1x1 stand-in for materials without a response map.
fn dummy_texture(gpu: &Gpu) -> wgpu::TextureView {
    crate::response::texture_3d(gpu, [1, 1, 1], &[0; 4])
}

/// A depth texture view of the given size (single-sample).
pub fn depth_view(gpu: &Gpu, w: u32, h: u32) -> wgpu::TextureView {
    depth_view_ms(gpu, w, h, 1)
}

/// A depth texture view of the given size and sample count.
pub fn depth_view_ms(gpu: &Gpu, w: u32, h: u32, samples: u32) -> wgpu::TextureView {
    gpu.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("depth"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: samples.max(1),
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// A colour texture view to render into (`samples > 1`: multisampled, not readable).
pub fn colour_view(
    gpu: &Gpu,
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
    samples: u32,
) -> wgpu::TextureView {
    gpu.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("msaa colour"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: samples.max(1),
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// An offscreen float target with readback: frames come back in linear light
/// (exposure applied) and go through the display transform on the CPU
/// (`sunbeam_frame::LinearImage::display`), so that MSAA resolves average
/// linear values, as a camera does.
pub struct Offscreen {
    pub width: u32,
    pub height: u32,
    tex: wgpu::Texture,
    view: wgpu::TextureView,
    msaa: Option<wgpu::TextureView>,
    depth: wgpu::TextureView,
    readback: wgpu::Buffer,
    padded_row: u32,
    /// The running sum of a progressive renderer (environment scenes).
    acc: Option<crate::accum::Accumulator>,
}

/// Colour format of offscreen frames (linear values; MSAA-resolvable everywhere).
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

impl Offscreen {
    /// A target for `r`'s pipeline (its sample count).
    pub fn new(gpu: &Gpu, r: &Renderer, width: u32, height: u32) -> Result<Offscreen> {
        let lim = gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > lim || height > lim {
            return Err(Error::usage(format!(
                "size {width}x{height}: each side must be 1..{lim} on this GPU"
            )));
        }
        let tex = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("frame"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: OFFSCREEN_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = tex.create_view(&Default::default());
        let acc = if r.progressive() {
            Some(crate::accum::Accumulator::new(
                gpu, &view, width, height, true,
            )?)
        } else {
            None
        };
        let ms = r.msaa();
        let msaa = (ms > 1).then(|| colour_view(gpu, width, height, OFFSCREEN_FORMAT, ms));
        let padded_row = (width * 8).div_ceil(256) * 256;
        let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: padded_row as u64 * height as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Offscreen {
            width,
            height,
            tex,
            view,
            msaa,
            depth: depth_view_ms(gpu, width, height, ms),
            readback,
            padded_row,
            acc,
        })
    }

    /// Frames in the progressive sum (0 for a renderer that does not accumulate).
    pub fn frames(&self) -> u32 {
        self.acc.as_ref().map_or(0, |a| a.count())
    }

    /// Start the progressive sum again (camera, light or exposure changed).
    pub fn reset(&self) {
        if let Some(a) = &self.acc {
            a.reset();
        }
    }

    fn record(&self, enc: &mut wgpu::CommandEncoder, r: &Renderer, state: &FrameState) {
        match &self.msaa {
            Some(ms) => r.encode(enc, ms, Some(&self.view), &self.depth, state),
            None => r.encode(enc, &self.view, None, &self.depth, state),
        }
    }

    /// The progressive sum (environment scenes), for the window's resolve pass.
    pub fn accumulator(&self) -> Option<&crate::accum::Accumulator> {
        self.acc.as_ref()
    }

    /// Record one frame (and, for a progressive renderer, adding it to the sum:
    /// the frame index is set from the count). The caller submits.
    pub fn encode_frame(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        r: &Renderer,
        state: &FrameState,
    ) {
        match &self.acc {
            Some(a) => {
                let jitter = subpixel_jitter(a.count());
                r.update_jittered(gpu, state, self.width, self.height, jitter);
                r.set_frame(gpu, a.count());
            }
            None => r.update(gpu, state, self.width, self.height),
        }
        self.record(enc, r, state);
        if let Some(a) = &self.acc {
            a.add(gpu, enc);
        }
    }

    /// Render one frame and wait for it (no readback); a progressive renderer
    /// adds it to the running sum.
    pub fn draw(&self, gpu: &Gpu, r: &Renderer, state: &FrameState) -> Result<()> {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.encode_frame(gpu, &mut enc, r, state);
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        gpu.take_errors()
    }

    /// Render one frame and read it back as display values.
    pub fn render(&self, gpu: &Gpu, r: &Renderer, state: &FrameState) -> Result<Image> {
        Ok(self.render_linear(gpu, r, state)?.display(r.curve()))
    }

    /// Render one frame and read it back in linear light (exposure applied); a
    /// progressive renderer adds it to the running sum and returns the mean of
    /// the frames since the last reset (the settled frame).
    pub fn render_linear(
        &self,
        gpu: &Gpu,
        r: &Renderer,
        state: &FrameState,
    ) -> Result<LinearImage> {
        if let Some(a) = &self.acc {
            self.draw(gpu, r, state)?;
            return a.read(gpu);
        }
        r.update(gpu, state, self.width, self.height);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.record(&mut enc, r, state);
        enc.copy_texture_to_buffer(
            self.tex.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: None,
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: 1,
            },
        );
        gpu.queue.submit([enc.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        self.readback
            .map_async(wgpu::MapMode::Read, .., move |res| {
                let _ = tx.send(res);
            });
        gpu.wait()?;
        rx.recv()
            .map_err(|e| Error::internal(format!("readback: {e}")))?
            .map_err(|e| Error::internal(format!("readback: {e}")))?;
        gpu.take_errors()?;
        let mut img = LinearImage::new(self.width, self.height);
        {
            let data = self
                .readback
                .get_mapped_range(..)
                .map_err(|e| Error::internal(format!("readback: {e}")))?;
            let px: &[u16] = bytemuck::cast_slice(&data);
            let stride = (self.padded_row / 2) as usize;
            let f = |b: u16| half::f16::from_bits(b).to_f32();
            for y in 0..self.height as usize {
                for x in 0..self.width as usize {
                    let i = y * stride + x * 4;
                    img.rgb[y * self.width as usize + x] = [f(px[i]), f(px[i + 1]), f(px[i + 2])];
                }
            }
        }
        self.readback.unmap();
        Ok(img)
    }
}

use bytemuck::Zeroable;

/// The sub-pixel offset (pixels, each in [-0.5, 0.5)) of frame `k` of a
/// progressive sum: the Halton (2, 3) sequence from index 1, so any run of
/// frames covers the pixel evenly (stratified, unlike independent random
/// offsets) and the first frame (the one shown while the view moves) sits
/// near the centre, (0, -1/6).
pub fn subpixel_jitter(k: u32) -> [f64; 2] {
    fn radical_inverse(mut i: u32, base: u32) -> f64 {
        let (mut f, mut r) = (1.0, 0.0);
        while i > 0 {
            f /= base as f64;
            r += f * (i % base) as f64;
            i /= base;
        }
        r
    }
    let i = k.wrapping_add(1);
    [radical_inverse(i, 2) - 0.5, radical_inverse(i, 3) - 0.5]
}

#[cfg(test)]
mod layout_tests {
    //! The uniform structs mirror the WGSL by hand; naga's reflection of the
    //! shader checks every shared member's offset and the total size, so the two
    //! cannot drift (a field added on one side only fails here).
    use super::{Globals, MaterialU, SHADER};
    use std::mem::{offset_of, size_of};

    fn wgsl_struct(src: &str, name: &str) -> (u32, Vec<(String, u32)>) {
        let module = naga::front::wgsl::parse_str(src).expect("the shader parses");
        for (_, ty) in module.types.iter() {
            if ty.name.as_deref() == Some(name) {
                if let naga::TypeInner::Struct { members, span } = &ty.inner {
                    return (
                        *span,
                        members
                            .iter()
                            .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                            .collect(),
                    );
                }
            }
        }
        panic!("struct {name} not found in the WGSL");
    }

    fn check(name: &str, size: usize, rust: &[(&str, usize)]) {
        check_in(SHADER, name, size, rust)
    }

    fn check_in(src: &str, name: &str, size: usize, rust: &[(&str, usize)]) {
        let (span, members) = wgsl_struct(src, name);
        assert_eq!(span as usize, size, "{name}: WGSL size vs Rust size");
        let mut matched = 0;
        for (field, off) in rust {
            let Some((_, w)) = members.iter().find(|(n, _)| n == field) else {
                panic!("{name}.{field} is not in the WGSL struct");
            };
            assert_eq!(
                *w as usize, *off,
                "{name}.{field}: WGSL offset vs Rust offset"
            );
            matched += 1;
        }
        let named = members.iter().filter(|(n, _)| !n.starts_with('_')).count();
        assert_eq!(
            matched, named,
            "{name}: every named WGSL member has a Rust twin"
        );
    }

    #[test]
    fn globals_match_the_wgsl() {
        macro_rules! f {
            ($($n:ident),*) => { [$((stringify!($n), offset_of!(Globals, $n))),*] };
        }
        check(
            "Globals",
            size_of::<Globals>(),
            &f!(
                view_proj,
                eye,
                lights,
                xyz_to_rgb,
                background,
                n_lights,
                mode,
                curve,
                output,
                exposure_scale,
                n_lambda,
                msaa
            ),
        );
    }

    #[test]
    fn material_matches_the_wgsl() {
        macro_rules! f {
            ($($n:ident),*) => { [$((stringify!($n), offset_of!(MaterialU, $n))),*] };
        }
        check(
            "Material",
            size_of::<MaterialU>(),
            &f!(
                base,
                has_pack,
                basis,
                model,
                taps,
                crop_w,
                crop_h,
                kx,
                ky,
                terms,
                fixed_terms,
                n_table,
                bin_scale_um,
                half_range_um,
                beta,
                sigma_bins,
                kb_norm,
                table_dt,
                tab_nu,
                tab_nv,
                tab_nw,
                tab_on,
                tab_u0,
                tab_du,
                tab_dv,
                tab_w0,
                tab_dw,
                mask_sx,
                mask_sy,
                ior,
                resp_on,
                resp_n_theta,
                resp_n_rho,
                resp_n_s,
                resp_r0,
                resp_rho_scale,
                resp_footprint,
                norm,
                window_sigma_um
            ),
        );
    }

    #[test]
    fn environment_uniforms_match_the_wgsl() {
        use crate::env::{EnvGlobals, EnvProposalU};
        macro_rules! f {
            ($t:ty; $($n:ident),*) => { [$((stringify!($n), offset_of!($t, $n))),*] };
        }
        check(
            "EnvGlobals",
            size_of::<EnvGlobals>(),
            &f!(EnvGlobals; basis_to_rgb, sun_dir, sun_rgb, sun_t, sun_b, table_w, table_h, frame, on, has_sun, samples),
        );
        check(
            "EnvProposal",
            size_of::<EnvProposalU>(),
            &f!(EnvProposalU; offsets, pw, ph, top, n_s, n_theta, n_rho, n_s_f, r0, rho_scale, on, has_sun),
        );
    }

    #[test]
    fn accumulation_uniforms_match_the_wgsl() {
        use crate::accum::{AccU, ResolveU, ACCUMULATE_WGSL, RESOLVE_WGSL};
        macro_rules! f {
            ($t:ty; $($n:ident),*) => { [$((stringify!($n), offset_of!($t, $n))),*] };
        }
        check_in(
            ACCUMULATE_WGSL,
            "AccU",
            size_of::<AccU>(),
            &f!(AccU; width, height, count),
        );
        check_in(
            RESOLVE_WGSL,
            "ResolveU",
            size_of::<ResolveU>(),
            &f!(ResolveU; width, inv_n, curve, output),
        );
    }
}

#[cfg(test)]
mod jitter_tests {
    use super::subpixel_jitter;

    /// The offsets stay inside the pixel and cover it evenly: over 64 frames,
    /// each of the 4 x 4 sub-cells gets 3 to 5 (4 on average), and the mean is the centre.
    #[test]
    fn jitter_covers_the_pixel_evenly() {
        let mut cells = [0u32; 16];
        let mut mean = [0.0; 2];
        for k in 0..64 {
            let j = subpixel_jitter(k);
            assert!(j.iter().all(|v| (-0.5..0.5).contains(v)), "{j:?}");
            let c = |v: f64| ((v + 0.5) * 4.0) as usize;
            cells[c(j[0]) + 4 * c(j[1])] += 1;
            mean = [mean[0] + j[0] / 64.0, mean[1] + j[1] / 64.0];
        }
        assert!(cells.iter().all(|n| (3..=5).contains(n)), "{cells:?}");
        assert!(mean[0].abs() < 0.02 && mean[1].abs() < 0.02, "{mean:?}");
    }
}
