//! The baselines the default mode is measured against (docs/bench/play.md):
//! the table mode (the former Cartesian response table, built on the CPU at
//! load: [`crate::table`]), the per-fragment modes (direct: PHYSICS.md 2
//! summed per fragment; thesis: the thesis' shader, 39 terms, 5 nm steps)
//! and Lambert (the base colour alone, no pack). Their shading is
//! shaders/diffraction.wgsl's branches on `Globals::mode`; here is what they
//! upload.

use super::uniforms::MaterialU;
use super::{Mode, Settings};
use std::sync::Arc;
use sunbeam_common::{Error, Result};
use sunbeam_frame::spectral::Samples;
use sunbeam_pack::Pack;
use wgpu::util::DeviceExt;

/// The terms buffers already made, per pack (the same `Arc`), with their term count.
pub(super) type TermBuffers = Vec<(*const Pack, Arc<wgpu::Buffer>, usize)>;

/// The terms buffer of `pack` (its first `used` terms) for meshes[`mi`]: the
/// per-fragment modes (direct, thesis) read the terms on the GPU; the others
/// get a stand-in. One buffer per pack (`pack_bufs`).
pub(super) fn terms_buffer(
    device: &wgpu::Device,
    pack: &Arc<Pack>,
    used: usize,
    mode: Mode,
    mi: usize,
    pack_bufs: &mut TermBuffers,
) -> Result<Arc<wgpu::Buffer>> {
    let m = &pack.manifest;
    let max_binding = device.limits().max_storage_buffer_binding_size;
    let key = Arc::as_ptr(pack);
    // Only the per-fragment modes read the terms on the GPU; the
    // default and table modes read their precomputed maps.
    let gpu_terms = matches!(mode, Mode::Direct | Mode::Thesis);
    let buf = match pack_bufs.iter().find(|(k, _, _)| *k == key) {
        Some((_, b, _)) => b.clone(),
        None if !gpu_terms => {
            let b = Arc::new(
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("no terms"),
                    contents: bytemuck::cast_slice(&[0.0f32; 4]),
                    usage: wgpu::BufferUsages::STORAGE,
                }),
            );
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
            let b = Arc::new(
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("terms"),
                    contents: bytemuck::cast_slice(&pack.terms[..n]),
                    usage: wgpu::BufferUsages::STORAGE,
                }),
            );
            pack_bufs.push((key, b.clone(), used));
            b
        }
    };
    Ok(buf)
}

/// The table mode's Cartesian response table of `pack` for meshes[`mi`]
/// (`crate::table`, built on the CPU with `table`'s term counts per |t| step
/// `dt`), its dimensions set in `mu`.
#[allow(clippy::too_many_arguments)]
pub(super) fn response_table(
    pack: &Pack,
    samples: &Samples,
    settings: &Settings,
    table: &[u32],
    dt: f64,
    mi: usize,
    device: &wgpu::Device,
    mu: &mut MaterialU,
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
    mu.tab_nu = rt.dims.nu as u32;
    mu.tab_nv = rt.dims.nv as u32;
    mu.tab_nw = rt.dims.nw as u32;
    mu.tab_on = 1;
    mu.tab_u0 = crate::table::U_MIN as f32;
    mu.tab_du = rt.du as f32;
    mu.tab_dv = rt.dv as f32;
    mu.tab_w0 = crate::table::W_MIN as f32;
    mu.tab_dw = rt.dw as f32;
    Ok(rt.data)
}
