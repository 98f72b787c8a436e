//! `"background": "environment"` (docs/PLAY.md "Background"): a full-screen
//! pass of shaders/background.wgsl drawn after the meshes at the far plane
//! (depth `LessEqual`, no depth write), so it fills exactly the samples no
//! mesh covers with the environment along each pixel's view ray. It reads the
//! coefficient table and the sun the lighting uploads ([`crate::env::EnvScene`]).

use super::DEPTH_FORMAT;
use crate::env::EnvScene;
use crate::gpu::Gpu;
use sunbeam_common::{Error, Result};
use sunbeam_scene::Camera;
use wgpu::util::DeviceExt;

/// The WGSL of the pass.
pub const BACKGROUND_WGSL: &str = concat!(
    include_str!("../../../../shaders/display.wgsl"),
    include_str!("../../../../shaders/env_table.wgsl"),
    include_str!("../../../../shaders/background.wgsl")
);

/// shaders/background.wgsl `BgGlobals`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Default)]
struct BgGlobals {
    ray_o: [f32; 4],
    ray_x: [f32; 4],
    ray_y: [f32; 4],
    basis_to_rgb: [[f32; 4]; 3],
    sun_dir: [f32; 4],
    sun_rgb: [f32; 4],
    size: [f32; 2],
    table_w: u32,
    table_h: u32,
    has_sun: u32,
    exposure_scale: f32,
    curve: u32,
    output: u32,
    keep_negative: u32,
    /// Where the table's columns start, turns after phi = 0.
    table_phase: f32,
    _b: [u32; 2],
}

/// The pass: its pipeline, uniforms and bind group.
pub(super) struct Background {
    pipeline: wgpu::RenderPipeline,
    buffer: wgpu::Buffer,
    bind: wgpu::BindGroup,
    values: BgGlobals,
}

/// What a frame's uniforms need besides the scene-wide part.
pub(super) struct BgFrame<'a> {
    pub camera: &'a Camera,
    pub size: [u32; 2],
    pub exposure_scale: f32,
    pub curve: u32,
    pub output: u32,
    pub keep_negative: bool,
}

impl Background {
    pub(super) fn new(
        gpu: &Gpu,
        env: &EnvScene,
        format: wgpu::TextureFormat,
        msaa: u32,
    ) -> Result<Background> {
        let device = &gpu.device;
        let v = env.values;
        let values = BgGlobals {
            basis_to_rgb: v.basis_to_rgb,
            sun_dir: v.sun_dir,
            sun_rgb: v.sun_rgb,
            table_w: v.table_w,
            table_h: v.table_h,
            table_phase: v.table_phase,
            has_sun: v.has_sun,
            ..Default::default()
        };
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("background globals"),
            contents: bytemuck::bytes_of(&values),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("background"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("background"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(env.table()),
                },
            ],
        });
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("background.wgsl"),
            source: wgpu::ShaderSource::Wgsl(BACKGROUND_WGSL.into()),
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("background"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("background"),
            layout: Some(&pl),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_bg"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState {
                count: msaa.max(1),
                ..Default::default()
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_bg"),
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
                "background pipeline creation failed: {e}"
            )));
        }
        Ok(Background {
            pipeline,
            buffer,
            bind,
            values,
        })
    }

    /// Upload a frame's uniforms.
    pub(super) fn update(&self, gpu: &Gpu, f: &BgFrame) {
        let [w, h] = f.size.map(|v| v.max(1));
        // No sub-pixel jitter: every frame averages the pixel's box itself
        // (shaders/background.wgsl), so a running mean is that box too.
        let (o, rx, ry) = f.camera.ray_basis(w, h);
        let v4 = |a: [f64; 3]| [a[0] as f32, a[1] as f32, a[2] as f32, 0.0];
        let v = BgGlobals {
            ray_o: v4(o),
            ray_x: v4(rx),
            ray_y: v4(ry),
            size: [w as f32, h as f32],
            exposure_scale: f.exposure_scale,
            curve: f.curve,
            output: f.output,
            keep_negative: u32::from(f.keep_negative),
            ..self.values
        };
        gpu.queue
            .write_buffer(&self.buffer, 0, bytemuck::bytes_of(&v));
    }

    /// Draw the pass into the current render pass (after the meshes).
    pub(super) fn draw(&self, rp: &mut wgpu::RenderPass<'_>) {
        rp.set_pipeline(&self.pipeline);
        rp.set_bind_group(0, &self.bind, &[]);
        rp.draw(0..3, 0..1);
    }
}
