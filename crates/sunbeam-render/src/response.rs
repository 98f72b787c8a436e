//! Finding a pack's response map (sunbeam-response) for the default mode.
//!
//! `sunbeam-pack --response` writes it beside the pack as `NAME.response.ktx2`
//! (for `NAME.ktx2` or `NAME.exr`). The player loads that file when it exists
//! and was built from the same pack (the embedded manifests are equal); else it
//! builds the map itself, which takes seconds for large packs, and says so.
//! Also the GPU texture of a map (the point map and the extended-light maps).

use crate::gpu::Gpu;
use std::path::Path;
use std::sync::Arc;
use sunbeam_common::Result;
use sunbeam_pack::Pack;
use sunbeam_response::{ktx2, Response};
use wgpu::util::DeviceExt;

/// `dir/NAME.response.ktx2` for a pack `dir/NAME.ext`.
pub use sunbeam_response::sidecar_path as sidecar;

/// Read a pack for the default mode: only its manifest when a response map
/// built from it stands beside it (the map is all the default mode draws
/// with; a 4096^2 scan's pack is 430 MB), else the whole pack.
pub fn load_pack(path: &Path) -> Result<Pack> {
    let side = sidecar(path);
    if side.is_file() {
        if let (Ok(m), Ok(info)) = (Pack::read_manifest(path), ktx2::read_info(&side)) {
            if info.pack == m {
                return Ok(Pack::manifest_only(m));
            }
        }
    }
    Pack::read(path)
}

/// [`load_pack`] for a scene with an environment: only the manifest when the
/// environment's maps (`NAME.env-response.ktx2`) and the point map beside the
/// pack were both built from it (the maps still have to serve the scene's
/// environment: if not, the renderer reads the pack whole to build them).
pub fn load_pack_for_environment(path: &Path) -> Result<Pack> {
    let side = sunbeam_response::env_file::sidecar_path(path);
    if side.is_file() {
        if let (Ok(m), Ok(info)) = (
            Pack::read_manifest(path),
            sunbeam_response::env_file::read_info(&side),
        ) {
            if info.pack == m {
                return load_pack(path);
            }
        }
    }
    Pack::read(path)
}

/// The map of `pack` (read from `path`'s sidecar, or built), and a note for the
/// user when it had to be built.
pub fn load_or_build(
    pack: &Arc<Pack>,
    path: Option<&Path>,
    opts: &sunbeam_response::Options,
) -> Result<(Arc<Response>, Option<String>)> {
    // A manifest-only pack (load_pack) has no terms to build from: read it whole
    // if its map turns out not to be current after all.
    let full;
    let pack = match path {
        Some(p) if !pack.has_terms() => {
            if let Ok(r) = ktx2::read(&sidecar(p)) {
                if r.info.pack == pack.manifest {
                    return Ok((Arc::new(r), None));
                }
            }
            full = Arc::new(Pack::read(p)?);
            &full
        }
        _ => pack,
    };
    if let Some(p) = path {
        let side = sidecar(p);
        if side.is_file() {
            let r = ktx2::read(&side)?;
            if r.info.pack == pack.manifest {
                return Ok((Arc::new(r), None));
            }
            let t = std::time::Instant::now();
            let r = sunbeam_response::build(pack, opts);
            return Ok((
                Arc::new(r),
                Some(format!(
                    "{} was built from another pack; built the response map in {:.1} s \
                     (rebuild it: sunbeam-pack --response)",
                    side.display(),
                    t.elapsed().as_secs_f64()
                )),
            ));
        }
    }
    let t = std::time::Instant::now();
    let r = sunbeam_response::build(pack, opts);
    let note = path.map(|p| {
        format!(
            "no response map beside {} ({}); built it in {:.1} s: write it once with \
             `sunbeam-pack --response` to open instantly",
            p.display(),
            sidecar(p).display(),
            t.elapsed().as_secs_f64()
        )
    });
    Ok((Arc::new(r), note))
}

/// The energy bound's tables of `pack` (sunbeam_response::energy): those of
/// its point map `resp` when loaded, else of the map beside the pack, else
/// built from the pack (with a note: the pipeline's map carries them).
pub(crate) fn energy_info(
    pack: &Arc<Pack>,
    path: Option<&Path>,
    opts: &sunbeam_response::Options,
    resp: Option<&Arc<Response>>,
    warnings: &mut Vec<String>,
) -> Result<sunbeam_response::energy::EnergyInfo> {
    if let Some(e) = resp.and_then(|r| r.info.energy.clone()) {
        return Ok(e);
    }
    if let Some(p) = path {
        // The map's head only: an environment scene does not read its texels.
        if let Ok(info) = ktx2::read_info(&sidecar(p)) {
            if info.pack == pack.manifest {
                if let Some(e) = info.energy {
                    return Ok(e);
                }
            }
        }
    }
    let full;
    let pack = match path {
        Some(p) if !pack.has_terms() => {
            full = Arc::new(Pack::read(p)?);
            &full
        }
        _ => pack,
    };
    let t = std::time::Instant::now();
    let e = sunbeam_response::energy::EnergyInfo::from_pack(pack, opts);
    warnings.push(format!(
        "built the energy bound's tables of {} in {:.1} s (`sunbeam-pack --response` stores them in the response map)",
        path.map_or("the pack".to_string(), |p| p.display().to_string()),
        t.elapsed().as_secs_f64()
    ));
    Ok(e)
}

/// A 3D RGBA16F texture holding a response map.
pub(crate) fn response_texture(gpu: &Gpu, r: &sunbeam_response::Response) -> wgpu::TextureView {
    let g = r.info.grid;
    texture_3d(
        gpu,
        [g.n_theta as u32, g.n_rho as u32, g.n_s as u32],
        &r.data,
    )
}

/// A 3D RGBA16F texture of `size` texels (layer-major f16 bits).
pub(crate) fn texture_3d(gpu: &Gpu, size: [u32; 3], data: &[u16]) -> wgpu::TextureView {
    gpu.device
        .create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("response map"),
                size: wgpu::Extent3d {
                    width: size[0],
                    height: size[1],
                    depth_or_array_layers: size[2],
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(data),
        )
        .create_view(&Default::default())
}
