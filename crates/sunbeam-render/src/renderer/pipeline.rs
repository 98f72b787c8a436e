//! The pipeline of the player's shaders ([`super::SHADER`]): the bind group
//! layouts, a mesh's vertex and index buffers, the render pipeline, the
//! stand-in texture of materials without a response map.

use super::uniforms::Vertex;
use super::{DEPTH_FORMAT, SHADER};
use crate::gpu::Gpu;
use bytemuck::Zeroable;
use sunbeam_common::{Error, Result};
use wgpu::util::DeviceExt;

/// Bind group layouts: 0 = globals and spectrum, 1 = one material (uniforms,
/// terms, term table, response table, response map and its sampler).
pub(super) fn bind_group_layouts(device: &wgpu::Device) -> [wgpu::BindGroupLayout; 2] {
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
pub(super) fn mesh_buffers(
    device: &wgpu::Device,
    mesh: &sunbeam_frame::Mesh,
) -> (wgpu::Buffer, wgpu::Buffer) {
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
pub(super) fn render_pipeline(
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
pub(super) fn dummy_texture(gpu: &Gpu) -> wgpu::TextureView {
    crate::response::texture_3d(gpu, [1, 1, 1], &[0; 4])
}
