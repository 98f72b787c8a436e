//! The baselines the default technique is measured against (docs/PLAY.md
//! "Modes", docs/BENCHMARKS.md), behind sunbeam-render's `baselines` feature
//! (on by default): the table mode (a Cartesian response table built on the
//! CPU at load: [`crate::table`]) and the per-fragment modes (direct:
//! PHYSICS.md 2 summed per fragment; thesis: the thesis' shader, 39 terms,
//! 5 nm steps). Their shading is shaders/baselines.wgsl, composed into
//! [`BASELINE_SHADER`] with the shared shading and its own entry point
//! (`fs_baseline`, specialised per mode by the pipeline constant
//! `BASELINE`); their data is their own bind group (group 3: the
//! `Baseline` uniform, the pack's terms, the per-|t| term table, the
//! response table), which only their pipelines bind. Here is what they
//! upload. (The Lambert mode is the default pipeline with no pack.)

use super::pipeline::{uniform_entry, Technique};
use super::uniforms::BaselineU;
use super::{Mode, Settings, MAX_TERMS, TERM_TABLE, THESIS_TERMS};
use std::sync::Arc;
use sunbeam_common::{Error, Result};
use sunbeam_frame::spectral::Samples;
use sunbeam_pack::{Basis, Model, Pack};
use wgpu::util::DeviceExt;

/// The baselines' WGSL: the shared shading with shaders/baselines.wgsl (the
/// series, kernel, taps, reflectance and table lookup; `fs_baseline`).
pub const BASELINE_SHADER: &str = super::player_shader!("../../../../shaders/baselines.wgsl");

/// The shader of a baseline mode: `fs_baseline` with `BASELINE` set (0
/// table, 1 direct, 2 thesis: shaders/baselines.wgsl); None for the others.
pub(super) fn technique(mode: Mode) -> Option<Technique> {
    let which = match mode {
        Mode::Table => 0.0,
        Mode::Direct => 1.0,
        Mode::Thesis => 2.0,
        Mode::Default | Mode::Lambert => return None,
    };
    Some(Technique {
        label: "baselines.wgsl",
        source: BASELINE_SHADER,
        entry: "fs_baseline",
        // (no environment: of_scene refuses one in these modes)
        constants: vec![("BASELINE", which), super::env_estimator_constant(None)],
    })
}

/// The terms buffers already made, per pack (the same `Arc`).
type TermBuffers = Vec<(*const Pack, Arc<wgpu::Buffer>)>;

/// What a baseline's pipeline binds besides the shared groups: group 3's
/// layout, and the terms buffers made so far (one per pack).
pub(super) struct Baselines {
    pub(super) layout: wgpu::BindGroupLayout,
    terms: TermBuffers,
}

/// A mesh's pack as a baseline reads it: the pack and its terms used (at
/// most [`MAX_TERMS`]).
pub(super) struct MeshPack<'a> {
    pub(super) pack: &'a Arc<Pack>,
    pub(super) used: usize,
}

impl Baselines {
    pub(super) fn new(device: &wgpu::Device) -> Baselines {
        let storage_entry = crate::gpu::fragment_storage_entry;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("baseline"),
            entries: &[
                uniform_entry(0),
                storage_entry(1),
                storage_entry(2),
                storage_entry(3),
            ],
        });
        Baselines {
            layout,
            terms: Vec::new(),
        }
    }

    /// Group 3 of meshes[`mi`]: with its pack, the uniform, the terms (the
    /// per-fragment modes) and the per-|t| term table or the response table
    /// (the table mode); stand-ins without one (the mesh shades its base).
    pub(super) fn bind(
        &mut self,
        device: &wgpu::Device,
        pack: Option<MeshPack>,
        settings: &Settings,
        samples: &Samples,
        mi: usize,
    ) -> Result<wgpu::BindGroup> {
        let mut bu = BaselineU {
            n_table: 1,
            table_dt: 1.0,
            ..Default::default()
        };
        let (terms, table, response) = match pack {
            Some(MeshPack { pack, used }) => {
                let lambda_min = samples
                    .0
                    .iter()
                    .map(|s| s.lambda_m)
                    .fold(f64::INFINITY, f64::min);
                let (table, dt) = pack_uniforms(&mut bu, pack, used, settings, lambda_min);
                let terms = self.terms_buffer(device, pack, used, settings.mode, mi)?;
                let response = if settings.mode == Mode::Table {
                    Some(response_table(
                        pack, samples, settings, &table, dt, mi, device, &mut bu,
                    )?)
                } else {
                    None
                };
                (terms, table, response)
            }
            None => (Arc::new(no_terms(device)), vec![1u32], None),
        };
        let ubuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("baseline"),
            contents: bytemuck::bytes_of(&bu),
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
        let buffers = [&ubuf, &*terms, &tbuf, &rbuf];
        let entries: Vec<_> = (0u32..)
            .zip(buffers)
            .map(|(binding, b)| wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            })
            .collect();
        Ok(device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("baseline"),
            layout: &self.layout,
            entries: &entries,
        }))
    }

    /// The terms buffer of `pack` (its first `used` terms) for
    /// meshes[`mi`]: the per-fragment modes (direct, thesis) read the terms
    /// on the GPU; the table mode gets a stand-in. One buffer per pack.
    fn terms_buffer(
        &mut self,
        device: &wgpu::Device,
        pack: &Arc<Pack>,
        used: usize,
        mode: Mode,
        mi: usize,
    ) -> Result<Arc<wgpu::Buffer>> {
        let key = Arc::as_ptr(pack);
        if let Some((_, b)) = self.terms.iter().find(|(k, _)| *k == key) {
            return Ok(b.clone());
        }
        let b = if matches!(mode, Mode::Direct | Mode::Thesis) {
            let m = &pack.manifest;
            let max_binding = device.limits().max_storage_buffer_binding_size;
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
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("terms"),
                contents: bytemuck::cast_slice(&pack.terms[..n]),
                usage: wgpu::BufferUsages::STORAGE,
            })
        } else {
            no_terms(device)
        };
        let b = Arc::new(b);
        self.terms.push((key, b.clone()));
        Ok(b)
    }
}

/// The stand-in terms buffer of modes and meshes that read none.
fn no_terms(device: &wgpu::Device) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("no terms"),
        contents: bytemuck::cast_slice(&[0.0f32; 4]),
        usage: wgpu::BufferUsages::STORAGE,
    })
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

/// The pack's part of the baseline uniform (series, crop, kernel, per-|t| term
/// table; docs/PACK_FORMAT.md "Evaluation"): the term table and its |t| step.
fn pack_uniforms(
    bu: &mut BaselineU,
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
    bu.basis = match m.basis {
        Basis::Chebyshev => 0,
        Basis::Taylor => 1,
    };
    bu.model = match m.model {
        Model::Window => 0,
        Model::Tiled => 1,
    };
    bu.taps = m.kernel.taps as u32;
    bu.crop_w = m.crop.width as u32;
    bu.crop_h = m.crop.height as u32;
    bu.kx = m.crop.kx as i32;
    bu.ky = m.crop.ky as i32;
    bu.terms = used as u32;
    bu.fixed_terms = if settings.mode == Mode::Thesis {
        THESIS_TERMS
    } else {
        0
    };
    bu.n_table = table.len() as u32;
    bu.bin_scale_um = [
        (m.bin_scale_m[0] * 1e6) as f32,
        (m.bin_scale_m[1] * 1e6) as f32,
    ];
    bu.half_range_um = (h * 1e6) as f32;
    bu.beta = m.kernel.beta as f32;
    bu.sigma_bins = [m.kernel.sigma_bins[0] as f32, m.kernel.sigma_bins[1] as f32];
    bu.kb_norm = if m.kernel.beta > 0.0 {
        (m.kernel.beta / (w * m.kernel.beta.sinh())) as f32
    } else {
        0.0
    };
    bu.table_dt = dt as f32;
    // PHYSICS.md 2b's exact grazing term (Pack::shading_reflectance) in the
    // direct mode; the thesis mode keeps the thesis' R.
    bu.window_sigma_um = if m.model == Model::Window && settings.mode == Mode::Direct {
        (m.window_sigma_m * 1e6) as f32
    } else {
        0.0
    };
    (table, dt)
}

/// The table mode's Cartesian response table of `pack` for meshes[`mi`]
/// (`crate::table`, built on the CPU with `table`'s term counts per |t| step
/// `dt`), its dimensions set in `bu`.
#[allow(clippy::too_many_arguments)]
fn response_table(
    pack: &Pack,
    samples: &Samples,
    settings: &Settings,
    table: &[u32],
    dt: f64,
    mi: usize,
    device: &wgpu::Device,
    bu: &mut BaselineU,
) -> Result<Vec<[f32; 4]>> {
    let max_binding = device.limits().max_storage_buffer_binding_size;
    let t0 = std::time::Instant::now();
    let tt = table.to_vec();
    let terms_at = move |at: f64| -> usize {
        let i = ((at / dt).floor() as usize).min(tt.len() - 1);
        tt[i] as usize
    };
    let rt = crate::table::build(pack, samples, settings.table, &terms_at);
    let bytes = (rt.data.len() * 16) as u64;
    if bytes > max_binding {
        return Err(Error::input(format!(
            "meshes[{mi}]: the response table ({} MiB) exceeds this GPU's storage buffer limit; \
     use a smaller table",
            bytes >> 20
        )));
    }
    log::info!("response table {:?} built in {:.2?}", rt.dims, t0.elapsed());
    bu.tab_nu = rt.dims.nu as u32;
    bu.tab_nv = rt.dims.nv as u32;
    bu.tab_nw = rt.dims.nw as u32;
    bu.tab_u0 = crate::table::U_MIN as f32;
    bu.tab_du = rt.du as f32;
    bu.tab_dv = rt.dv as f32;
    bu.tab_w0 = crate::table::W_MIN as f32;
    bu.tab_dw = rt.dw as f32;
    Ok(rt.data)
}
