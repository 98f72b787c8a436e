//! The pipeline of a technique's shader ([`Technique`]: [`super::SHADER`]
//! or the baselines'): the bind group layouts every technique shares, a
//! mesh's vertex and index buffers, the render pipeline, the stand-in
//! texture of materials without a response map.

use super::uniforms::Vertex;
use super::DEPTH_FORMAT;
use crate::gpu::Gpu;
use bytemuck::Zeroable;
use sunbeam_common::{Error, Result};
use wgpu::util::DeviceExt;

/// Bind group layouts: 0 = globals, spectrum and the cells' pre-pass grid
/// ([`super::cells_rate`]), 1 = one material (uniform,
/// response map and its sampler, the scale maps). Group 2 is the
/// environment's ([`crate::env::EnvScene`]); the baselines add group 3.
pub(super) fn bind_group_layouts(device: &wgpu::Device) -> [wgpu::BindGroupLayout; 2] {
    let storage_entry = crate::gpu::fragment_storage_entry;
    let gl0 = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("globals"),
        entries: &[
            uniform_entry(0),
            storage_entry(1),
            texture_2d_unfiltered_entry(2),
            texture_2d_unfiltered_entry(3),
            texture_2d_unfiltered_entry(4),
            texture_2d_unfiltered_entry(5),
        ],
    });
    let gl1 = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("material"),
        entries: &[
            uniform_entry(0),
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
            texture_2d_entry(6),
            texture_2d_entry(7),
        ],
    });
    [gl0, gl1]
}

/// A uniform buffer both stages read.
pub(super) fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A 2D texture read by `textureLoad` (the scale maps).
fn texture_2d_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A 2D float texture read by `textureLoad` that need not be filterable
/// (the cells' grid: 32-bit floats).
fn texture_2d_unfiltered_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    let mut e = texture_2d_entry(binding);
    e.ty = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: false },
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: false,
    };
    e
}

/// Vertex and index buffers of a mesh (one dummy element when empty); with
/// `scales`, the vertices carry TEXCOORD_0 and the maps' TANGENT too.
pub(super) fn mesh_buffers(
    device: &wgpu::Device,
    mesh: &sunbeam_frame::Mesh,
    scales: Option<&sunbeam_frame::MeshScales>,
) -> (wgpu::Buffer, wgpu::Buffer) {
    let mut verts: Vec<Vertex> = (0..mesh.positions.len())
        .map(|i| {
            let (uv, uv_tangent) = match scales {
                Some(s) => (
                    mesh.uvs.get(i).copied().unwrap_or_default(),
                    s.tangents.get(i).copied().unwrap_or_default(),
                ),
                None => ([0.0; 2], [0.0; 4]),
            };
            Vertex {
                pos: mesh.positions[i],
                normal: mesh.normals[i],
                tangent: mesh.tangents[i],
                uv,
                uv_tangent,
            }
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

/// A technique's shader: the composed WGSL, its fragment entry point and the
/// values of its pipeline constants.
#[derive(Clone)]
pub(super) struct Technique {
    pub(super) label: &'static str,
    pub(super) source: &'static str,
    pub(super) entry: &'static str,
    pub(super) constants: Vec<(&'static str, f64)>,
}

/// The pipeline of `technique` for colour formats (one per target of its
/// entry point) and a sample count, with bind groups `layouts` (0, 1, 2
/// shared; more for the technique's own), drawing the meshes.
pub(super) fn render_pipeline(
    device: &wgpu::Device,
    layouts: &[&wgpu::BindGroupLayout],
    formats: &[wgpu::TextureFormat],
    msaa: u32,
    technique: &Technique,
) -> Result<wgpu::RenderPipeline> {
    pipeline_for(device, layouts, formats, msaa, technique, false)
}

/// [`render_pipeline`] drawing one full-screen triangle (`vs_fullscreen`,
/// no vertex buffer, no depth), single-sampled: the cells' grid walk.
pub(super) fn fullscreen_pipeline(
    device: &wgpu::Device,
    layouts: &[&wgpu::BindGroupLayout],
    formats: &[wgpu::TextureFormat],
    technique: &Technique,
) -> Result<wgpu::RenderPipeline> {
    pipeline_for(device, layouts, formats, 1, technique, true)
}

fn pipeline_for(
    device: &wgpu::Device,
    layouts: &[&wgpu::BindGroupLayout],
    formats: &[wgpu::TextureFormat],
    msaa: u32,
    technique: &Technique,
    full_screen: bool,
) -> Result<wgpu::RenderPipeline> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(technique.label),
        source: wgpu::ShaderSource::Wgsl(technique.source.into()),
    });
    let bind_group_layouts: Vec<_> = layouts.iter().map(|l| Some(*l)).collect();
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(technique.label),
        bind_group_layouts: &bind_group_layouts,
        immediate_size: 0,
    });
    // Every stage gets the constants: wgpu resolves all of a module's
    // overrides for each stage.
    let options = || wgpu::PipelineCompilationOptions {
        constants: &technique.constants,
        ..Default::default()
    };
    let vlayout = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x4, 3 => Float32x2, 4 => Float32x4],
    };
    let meshes = [Some(vlayout)];
    let (vs, buffers, primitive, depth_stencil) = if full_screen {
        ("vs_fullscreen", &[][..], Default::default(), None)
    } else {
        (
            "vs_main",
            &meshes[..],
            wgpu::PrimitiveState {
                cull_mode: Some(wgpu::Face::Back),
                front_face: wgpu::FrontFace::Ccw,
                ..Default::default()
            },
            Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
        )
    };
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(technique.label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some(vs),
            compilation_options: options(),
            buffers,
        },
        primitive,
        depth_stencil,
        multisample: wgpu::MultisampleState {
            count: msaa.max(1),
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some(technique.entry),
            compilation_options: options(),
            targets: &formats
                .iter()
                .map(|&format| {
                    Some(wgpu::ColorTargetState {
                        format,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })
                })
                .collect::<Vec<_>>(),
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
pub(super) fn dummy_texture(gpu: &Gpu) -> wgpu::TextureView {
    crate::response::texture_3d(gpu, [1, 1, 1], &[0; 4])
}

/// An RGBA8 (unorm, not sRGB: the maps hold vectors) 2D texture of a scale
/// map, or of the 1 x 1 stand-in of meshes without maps.
pub(super) fn rgba8_texture(gpu: &Gpu, size: [u32; 2], data: &[u8]) -> wgpu::TextureView {
    gpu.device
        .create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("scale map"),
                size: wgpu::Extent3d {
                    width: size[0].max(1),
                    height: size[1].max(1),
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8Unorm,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            data,
        )
        .create_view(&Default::default())
}

/// The scale maps' wrap bits of the material uniform (`scales_wrap`): bits
/// 0-1 the normal map's REPEAT along s and t, bits 2-3 the orientation map's.
pub(super) fn scale_wraps(scales: &sunbeam_frame::MeshScales) -> u32 {
    let bits = |r: [bool; 2]| u32::from(r[0]) | (u32::from(r[1]) << 1);
    bits(scales.maps.normal.repeat) | (bits(scales.maps.orient.repeat) << 2)
}
