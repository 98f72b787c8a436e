//! Environment lighting on the GPU (docs/PLAY.md "Environment",
//! shaders/environment.wgsl): per pack the extended-light maps `E_0..E_2` (+
//! `E_sun`) and the proposal pyramid of `sunbeam_response::env::build_env`; per
//! scene the coefficient table of the environment, the 3x3 matrix from basis
//! coefficients to linear sRGB and the sun's disc. Bind group 2 of the
//! diffraction pipeline (a stand-in without an environment).

use crate::gpu::Gpu;
use std::sync::Arc;
use sunbeam_common::{Error, Result};
use sunbeam_light::Environment;
use sunbeam_optics::{cie, colour};
use sunbeam_response::env::EnvResponse;
use wgpu::util::DeviceExt;

/// Rows of the sky's coefficient table (its width is twice this).
pub const SKY_TABLE_HEIGHT: usize = 256;
/// Most pyramid levels the uniform holds.
pub const MAX_LEVELS: usize = 16;
/// Proposal samples per pixel per frame (the sun and the diffuse part take one each).
pub const DEFAULT_ENV_SAMPLES: u32 = 1;

/// Cells of the first-frame estimator's top cut (`--env-cells`) for a patch
/// under 10 um (from 10 um: [`sunbeam_response::cells::first_frame_top`]), twice the
/// CPU twin's [`sunbeam_response::cells::DEFAULT_TOP`]. On a 64 x 64 sphere
/// (5 um pack, masked; the first frame 4 x 4 supersampled against two
/// 64-sample reference seeds, 2026-11-27) the interior's CIEDE2000 p99 at
/// 128 / 256 / 512 cells was 2.17 / 1.71 / 1.36 under the sky, 3.95 / 2.86 /
/// 1.66 under studio.exr and 2.58 / 1.98 / 1.20 under night.exr, at about
/// 0.55 / 1 / 1.6 times the time (docs/LIGHTING.md "How many cells").
pub const DEFAULT_ENV_CELLS: u64 = sunbeam_response::cells::FIRST_FRAME_TOP as u64;
/// The cells' (top cut, levels) for `pack`: the top cut asked for, or the
/// pack's own (`sunbeam_response::cells::first_frame_top_for`, from its
/// patch's size).
pub fn pack_cells(cells: (Option<usize>, usize), pack: &sunbeam_pack::Pack) -> (usize, usize) {
    (
        cells
            .0
            .unwrap_or_else(|| sunbeam_response::cells::first_frame_top_for(&pack.manifest)),
        cells.1,
    )
}

/// Levels kept below the top cut for views whose horizon a cell reaches.
pub const ENV_CELLS_DEPTH: usize = sunbeam_response::cells::DEFAULT_DEPTH;
/// The environment's hot spots as at most this many lights (`--env-hot-spots`).
pub const DEFAULT_ENV_HOT_SPOTS: usize = sunbeam_light::hotspots::DEFAULT_MAX_LIGHTS;
/// A texel is hot above this many times the map's mean (`--env-hot-threshold`).
pub const DEFAULT_ENV_HOT_THRESHOLD: f64 = sunbeam_light::hotspots::DEFAULT_THRESHOLD;

/// shaders/environment.wgsl `EnvGlobals`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Default)]
pub(crate) struct EnvGlobals {
    pub(crate) basis_to_rgb: [[f32; 4]; 3],
    pub(crate) sun_dir: [f32; 4],
    pub(crate) sun_rgb: [f32; 4],
    pub(crate) sun_t: [f32; 4],
    pub(crate) sun_b: [f32; 4],
    pub(crate) table_w: u32,
    pub(crate) table_h: u32,
    pub(crate) frame: u32,
    pub(crate) on: u32,
    pub(crate) has_sun: u32,
    pub(crate) samples: u32,
    /// 0: the cells (first-frame estimator), 1: Monte Carlo.
    pub(crate) estimator: u32,
    /// Levels of the prefiltered chain (binding 9).
    pub(crate) chain_levels: u32,
    /// The skin index the transmitted irradiance table was built for.
    pub(crate) irr_ior: f32,
    /// Where the table's and the chain's columns start, turns after phi = 0
    /// (`Environment::table_phase`).
    pub(crate) table_phase: f32,
    /// 1: the hot spots' taps read the maps over the pixel's footprint.
    pub(crate) hot_footprint: u32,
    /// The part of the pixel, along each axis, that one frame of a running
    /// mean stands for (the footprint's scale for the hot spots and the
    /// sun): 1 for a frame alone, 1 / m for each of a headless run's m x m
    /// lattice frames, 0 for the window's jittered frames after the first
    /// (their jitter covers the pixel; a footprint as well would widen the
    /// pixel's kernel to a tent).
    pub(crate) frame_share: f32,
    /// Under MSAA, the one sample (0..4) of each pixel that a frame of a
    /// running mean is read at, 4 for the resolved pixel (a frame alone, the
    /// window's first, or no MSAA): the frames' jitter then places that
    /// sample on the pixel's lattice point (the renderer's `frame_sample`), so the
    /// mean is the pixel's box, where the resolved samples' pattern would
    /// widen it (docs/PLAY.md "Environment").
    pub(crate) frame_sample: u32,
    pub(crate) _f0: [u32; 3],
}

/// How the player integrates an environment (`sunbeam-play --env-estimator`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EnvEstimator {
    /// Close in the first frame: the maps' cells against the prefiltered
    /// environment, the diffuse part from the irradiance tables; frames
    /// accumulate for anti-aliasing only (docs/LIGHTING.md "The first frame").
    Cells,
    /// Progressive Monte Carlo: unbiased, settles over thousands of frames.
    #[default]
    MonteCarlo,
}

impl EnvEstimator {
    /// The estimator's number in the shaders (`EnvGlobals::estimator` and the
    /// pipeline constant `SB_ENV_ESTIMATOR`, which equal it): 0 the cells, 1
    /// Monte Carlo.
    pub(crate) fn index(self) -> u32 {
        match self {
            EnvEstimator::Cells => 0,
            EnvEstimator::MonteCarlo => 1,
        }
    }
}

/// shaders/environment.wgsl `EnvProposal`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Default)]
pub(crate) struct EnvProposalU {
    pub(crate) offsets: [[u32; 4]; 4],
    pub(crate) pw: u32,
    pub(crate) ph: u32,
    pub(crate) top: u32,
    pub(crate) n_s: u32,
    pub(crate) n_theta: f32,
    pub(crate) n_rho: f32,
    pub(crate) n_s_f: f32,
    pub(crate) r0: f32,
    pub(crate) rho_scale: f32,
    pub(crate) on: u32,
    pub(crate) has_sun: u32,
    /// Cells of the top cut (shaders/environment.wgsl env_cells).
    pub(crate) n_cells: u32,
}

/// XYZ (scene units, the response maps' normalisation: 1 nm sums over
/// 380..780 nm divided by `sum D65 ybar`) of a spectrum.
pub(crate) fn spectrum_xyz(f: impl Fn(f64) -> f64) -> [f64; 3] {
    let range = cie::DEFAULT_RANGE_NM;
    let norm = cie::d65_y_norm(range);
    let mut xyz = [0.0; 3];
    for nm in range.0..=range.1 {
        let s = f(nm as f64 * 1e-9) / norm;
        let c = cie::cmf_nm(nm);
        for k in 0..3 {
            xyz[k] += s * c[k];
        }
    }
    xyz
}

/// The matrix from basis coefficients to linear sRGB: for a map the identity
/// (its coefficients are its linear RGB), for the sky `XYZ -> RGB` of the XYZ of
/// `S0, S1, S2`.
pub fn basis_to_rgb(env: &Environment) -> [[f64; 3]; 3] {
    match env {
        Environment::Map(_) => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        Environment::Sky(_) => {
            let cols: [[f64; 3]; 3] = std::array::from_fn(|k| {
                colour::xyz_to_linear_srgb(spectrum_xyz(|l| env.basis_at(l)[k]))
            });
            std::array::from_fn(|r| std::array::from_fn(|k| cols[k][r]))
        }
    }
}

fn orthonormal(d: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a = if d[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let dot = a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
    let t = [a[0] - dot * d[0], a[1] - dot * d[1], a[2] - dot * d[2]];
    let l = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
    let t = t.map(|v| v / l);
    let b = [
        d[1] * t[2] - d[2] * t[1],
        d[2] * t[0] - d[0] * t[2],
        d[0] * t[1] - d[1] * t[0],
    ];
    (t, b)
}

/// A coefficient table's hot spots as lights (sunbeam_light::hotspots) and
/// the residual the prefiltered chain is built from: what the player's
/// first-frame cells and the engines' export (`--export-environment`) both use.
pub(crate) struct HotSpots {
    /// Every light's taps (sunbeam_response::hotspots::taps, made once: they
    /// do not depend on the view), as shaders/env_hotspots.wgsl reads them:
    /// (world direction, 0) and (the light's basis power times the tap's
    /// weight, 0).
    pub taps: Vec<[[f32; 4]; 2]>,
    /// The table without the lights (RGBA f32, the table's layout).
    pub residual: Vec<f32>,
}

impl HotSpots {
    /// As `opts` chooses them (`max_lights` 0: none, the residual is the
    /// table), for a table whose columns start `phase` turns after `phi = 0`
    /// (`Environment::table_phase`): the taps turn with it.
    pub fn split(
        w: usize,
        h: usize,
        table: &[f32],
        phase: f64,
        opts: sunbeam_light::hotspots::SplitOptions,
    ) -> HotSpots {
        let split = sunbeam_light::hotspots::split(w, h, table, opts);
        // phi = atan2(z, x) grows by the phase's angle
        let turn = |d: [f64; 3]| sunbeam_light::rot_y(d, 360.0 * phase);
        if !split.lights.is_empty() {
            log::info!(
                "{} hot spots as lights ({:.1} % of the environment's energy)",
                split.lights.len(),
                100.0 * split.share
            );
        }
        let taps = split
            .lights
            .iter()
            .flat_map(|l| {
                sunbeam_response::hotspots::taps(l)
                    .into_iter()
                    .map(|(d, w)| [v4(turn(d), 0.0), v4(l.power.map(|p| p * w), 0.0)])
            })
            .collect();
        HotSpots {
            taps,
            residual: split.residual,
        }
    }
}

fn v4(v: [f64; 3], w: f64) -> [f32; 4] {
    [v[0] as f32, v[1] as f32, v[2] as f32, w as f32]
}

/// The scene-wide part: uniforms, coefficient table, layout, sampler, stand-ins.
pub(crate) struct EnvScene {
    pub(crate) layout: wgpu::BindGroupLayout,
    pub(crate) globals: wgpu::Buffer,
    pub(crate) values: EnvGlobals,
    table: wgpu::TextureView,
    chain: wgpu::TextureView,
    irradiance: [wgpu::TextureView; 2],
    sampler: wgpu::Sampler,
    dummy_map: wgpu::TextureView,
    dummy_buf: wgpu::Buffer,
    /// The hot spots as lights (shaders/env_hotspots.wgsl `env_lights`).
    lights: wgpu::Buffer,
    pub(crate) env: Option<Arc<Environment>>,
}

impl EnvScene {
    pub(crate) fn new(
        gpu: &Gpu,
        env: Option<Arc<Environment>>,
        samples: u32,
        estimator: EnvEstimator,
        ior: f64,
        hot_spots: sunbeam_light::hotspots::SplitOptions,
        footprint: bool,
    ) -> EnvScene {
        let device = &gpu.device;
        let layout = layout(device);
        let mut values = EnvGlobals {
            samples: samples.max(1),
            estimator: estimator.index(),
            irr_ior: ior as f32,
            hot_footprint: u32::from(footprint),
            frame_share: 1.0,
            frame_sample: 4,
            _f0: [0; 3],
            table_w: 1,
            table_h: 1,
            ..Default::default()
        };
        let (tw, th, tdata) = match &env {
            Some(e) => {
                values.on = 1;
                let m = basis_to_rgb(e);
                values.basis_to_rgb = std::array::from_fn(|r| v4(m[r], 0.0));
                if let Some(sky) = e.sun() {
                    let omega = sky.sun_solid_angle();
                    let d = sky.sun_direction();
                    let (t, b) = orthonormal(d);
                    let rgb = colour::xyz_to_linear_srgb(spectrum_xyz(|l| sky.sun_spectral(l)));
                    values.has_sun = 1;
                    values.sun_dir = v4(d, 1.0 - omega / (2.0 * std::f64::consts::PI));
                    values.sun_rgb = v4(rgb, omega);
                    values.sun_t = v4(t, 0.0);
                    values.sun_b = v4(b, 0.0);
                }
                values.table_phase = e.table_phase() as f32;
                e.coefficient_table(SKY_TABLE_HEIGHT)
            }
            None => (1, 1, vec![0.0f32; 4]),
        };
        values.table_w = tw as u32;
        values.table_h = th as u32;
        // The prefiltered chain and the irradiance tables (the first-frame
        // estimator's; one texel stand-ins for Monte Carlo).
        let cells = estimator == EnvEstimator::Cells && env.is_some();
        // The first-frame estimator: the table's hot spots as lights, the rest
        // (the residual) prefiltered for the cells.
        let mut light_data = vec![[0.0f32; 4]; 2];
        let chain_levels = if cells {
            let hot = HotSpots::split(tw, th, &tdata, values.table_phase.into(), hot_spots);
            if !hot.taps.is_empty() {
                light_data = hot.taps.concat();
            }
            sunbeam_light::prefilter::Prefiltered::new(tw, th, hot.residual).levels
        } else {
            vec![(1, 1, vec![0.0f32; 4])]
        };
        let lights = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("environment hot spots"),
            contents: bytemuck::cast_slice(&light_data),
            usage: wgpu::BufferUsages::STORAGE,
        });
        values.chain_levels = chain_levels.len() as u32;
        let chain = texture_2d_f16(gpu, "prefiltered environment", &chain_levels);
        let irradiance = match (&env, cells) {
            (Some(e), true) => {
                let (plain, tr) = sunbeam_light::irradiance::Irradiance::pair(e, ior);
                let (plain, tr) = (plain.table_rgba(), tr.table_rgba());
                [
                    texture_2d_f16(gpu, "transmitted irradiance", &[tr]),
                    texture_2d_f16(gpu, "irradiance", &[plain]),
                ]
            }
            _ => {
                let one = [(1, 1, vec![0.0f32; 4])];
                [
                    texture_2d_f16(gpu, "no irradiance", &one),
                    texture_2d_f16(gpu, "no irradiance", &one),
                ]
            }
        };
        let globals = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("environment globals"),
            contents: bytemuck::bytes_of(&values),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let table = device
            .create_texture_with_data(
                &gpu.queue,
                &wgpu::TextureDescriptor {
                    label: Some("environment coefficients"),
                    size: wgpu::Extent3d {
                        width: tw as u32,
                        height: th as u32,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba32Float,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                bytemuck::cast_slice(&tdata),
            )
            .create_view(&Default::default());
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("environment maps"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let dummy_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("no pyramid"),
            contents: bytemuck::cast_slice(&[0.0f32; 4]),
            usage: wgpu::BufferUsages::STORAGE,
        });
        EnvScene {
            layout,
            globals,
            values,
            table,
            chain,
            irradiance,
            sampler,
            dummy_map: crate::response::texture_3d(gpu, [1, 1, 1], &[0; 4]),
            dummy_buf,
            lights,
            env,
        }
    }

    /// The coefficient table (also the background pass's environment).
    pub(crate) fn table(&self) -> &wgpu::TextureView {
        &self.table
    }

    /// Set the frame index (the random numbers' seed), its share of the
    /// pixel and the sample it is read at (4: resolved) for the next frame.
    pub(crate) fn set_frame(&self, gpu: &Gpu, frame: u32, share: f32, sample: u32) {
        let mut v = self.values;
        v.frame = frame;
        v.frame_share = share;
        v.frame_sample = sample;
        gpu.queue
            .write_buffer(&self.globals, 0, bytemuck::bytes_of(&v));
    }

    /// Bind group 2 of a mesh: its pack's maps and pyramid, or stand-ins (the
    /// diffuse part only).
    pub(crate) fn bind(&self, gpu: &Gpu, maps: Option<&EnvMaps>) -> wgpu::BindGroup {
        let device = &gpu.device;
        type Parts<'a> = (
            EnvProposalU,
            &'a wgpu::Buffer,
            &'a wgpu::Buffer,
            [&'a wgpu::TextureView; 4],
        );
        let (u, pyr, cells, views): Parts<'_> = match maps {
            Some(m) => (
                m.uniform,
                &m.pyramid,
                &m.cells,
                [
                    m.views.as_ref().map_or(&self.dummy_map, |v| &v[0]),
                    m.views.as_ref().map_or(&self.dummy_map, |v| &v[1]),
                    m.views.as_ref().map_or(&self.dummy_map, |v| &v[2]),
                    m.sun.as_ref().unwrap_or(&self.dummy_map),
                ],
            ),
            None => (
                EnvProposalU::default(),
                &self.dummy_buf,
                &self.dummy_buf,
                [&self.dummy_map; 4],
            ),
        };
        let ubuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("environment proposal"),
            contents: bytemuck::bytes_of(&u),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        fn tex(b: u32, v: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding: b,
                resource: wgpu::BindingResource::TextureView(v),
            }
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("environment"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.globals.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: ubuf.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: pyr.as_entire_binding(),
                },
                tex(3, views[0]),
                tex(4, views[1]),
                tex(5, views[2]),
                tex(6, views[3]),
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
                tex(8, &self.table),
                tex(9, &self.chain),
                tex(10, &self.irradiance[0]),
                tex(11, &self.irradiance[1]),
                wgpu::BindGroupEntry {
                    binding: 12,
                    resource: cells.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 13,
                    resource: self.lights.as_entire_binding(),
                },
            ],
        })
    }
}

/// One pack's maps and pyramid on the GPU.
pub(crate) struct EnvMaps {
    uniform: EnvProposalU,
    pyramid: wgpu::Buffer,
    cells: wgpu::Buffer,
    /// The basis maps' textures; None when the first frame read none
    /// (bound as the scene's stand-in, which its shader paths never sample).
    views: Option<[wgpu::TextureView; 3]>,
    sun: Option<wgpu::TextureView>,
    /// Nodes of the cells' tree: what one walk of them may visit.
    pub(crate) nodes: usize,
}

impl EnvMaps {
    pub(crate) fn new(
        gpu: &Gpu,
        r: &EnvResponse,
        cells: Option<&sunbeam_response::cells::GpuCells>,
    ) -> Result<EnvMaps> {
        let p = &r.proposal;
        let g = r.grid;
        // The first frame reads neither the proposal nor, under the sky with
        // its cells from the pipeline, the basis maps (env_file::Needs): the
        // scene's stand-ins are bound instead (`bind`).
        if p.offsets.len() > MAX_LEVELS || !(r.basis.len() == 3 || r.basis.is_empty()) {
            return Err(Error::internal(format!(
                "environment maps: {} basis maps, {} pyramid levels (the player takes 3 and up to {MAX_LEVELS})",
                r.basis.len(),
                p.offsets.len()
            )));
        }
        let bytes = (p.data.len() * 4) as u64;
        if bytes > gpu.device.limits().max_storage_buffer_binding_size {
            return Err(Error::input(format!(
                "the proposal pyramid ({} MiB) exceeds this GPU's storage buffer limit",
                bytes >> 20
            )));
        }
        let mut offsets = [[0u32; 4]; 4];
        for (l, &o) in p.offsets.iter().enumerate() {
            offsets[l / 4][l % 4] = o as u32;
        }
        let uniform = EnvProposalU {
            offsets,
            pw: p.pw as u32,
            ph: p.ph as u32,
            top: p.offsets.len().saturating_sub(1) as u32,
            n_s: p.n_s as u32,
            n_theta: g.n_theta as f32,
            n_rho: g.n_rho as f32,
            n_s_f: g.n_s as f32,
            r0: g.r0 as f32,
            rho_scale: g.rho_scale() as f32,
            on: 1,
            has_sun: u32::from(r.sun.is_some()),
            n_cells: 0,
        };
        // Without cells (Monte Carlo) a stand-in: the walk sees no top cells.
        let (n_top, nodes, cell_data) = match cells {
            Some(c) => (c.n_top, c.nodes, &c.data[..]),
            None => (0, 0, &[][..]),
        };
        let mut uniform = uniform;
        uniform.n_cells = n_top as u32;
        let cells = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("response cells"),
                contents: bytemuck::cast_slice(if cell_data.is_empty() {
                    &[0.0f32; 4][..]
                } else {
                    cell_data
                }),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let pyramid = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("proposal pyramid"),
                contents: bytemuck::cast_slice(if p.data.is_empty() {
                    &[0.0f32][..]
                } else {
                    &p.data
                }),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let view = |m: &sunbeam_response::Response| crate::response::response_texture(gpu, m);
        let views = match &r.basis[..] {
            [a, b, c] => Some([view(a), view(b), view(c)]),
            _ => None,
        };
        Ok(EnvMaps {
            uniform,
            pyramid,
            cells,
            views,
            sun: r.sun.as_ref().map(view),
            nodes,
        })
    }
}

/// Bind group layout 2 (shaders/environment.wgsl).
fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let uniform = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let plain_2d = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    let storage = crate::gpu::fragment_storage_entry;
    let map = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D3,
            multisampled: false,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("environment"),
        entries: &[
            uniform(0),
            uniform(1),
            storage(2),
            map(3),
            map(4),
            map(5),
            map(6),
            wgpu::BindGroupLayoutEntry {
                binding: 7,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 8,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            plain_2d(9),
            plain_2d(10),
            plain_2d(11),
            storage(12),
            storage(13),
        ],
    })
}

/// A filterable 2D texture in f16 from `(width, height, rgba f32)` levels
/// (level 0 first; each half the one before).
fn texture_2d_f16(
    gpu: &Gpu,
    label: &str,
    levels: &[(usize, usize, Vec<f32>)],
) -> wgpu::TextureView {
    let (w, h, _) = &levels[0];
    let tex = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: *w as u32,
            height: *h as u32,
            depth_or_array_layers: 1,
        },
        mip_level_count: levels.len() as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba16Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (m, (lw, lh, data)) in levels.iter().enumerate() {
        let bits: Vec<u16> = data
            .iter()
            .map(|&v| half::f16::from_f32(v.clamp(-65504.0, 65504.0)).to_bits())
            .collect();
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &tex,
                mip_level: m as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&bits),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(8 * *lw as u32),
                rows_per_image: Some(*lh as u32),
            },
            wgpu::Extent3d {
                width: *lw as u32,
                height: *lh as u32,
                depth_or_array_layers: 1,
            },
        );
    }
    tex.create_view(&Default::default())
}
