//! Progressive accumulation of the environment mode (docs/PLAY.md
//! "Environment"): every frame draws one set of Monte Carlo samples (seeded by
//! the frame index) into the RGBA16F frame target; a compute pass
//! (shaders/accumulate.wgsl) adds it (under MSAA one sample of it, or the
//! samples' mean: `Accumulator::add`) into an RGBA32F sum (a storage buffer, one
//! `vec4<f32>` per pixel, so no float blending or storage-texture format is
//! needed); headless frames read the sum back and divide by the count, the
//! window resolves it onto the surface (shaders/resolve.wgsl). Any change of
//! camera, light, exposure or size resets the count.

use crate::gpu::Gpu;
use sunbeam_common::{Error, Result};
use sunbeam_frame::LinearImage;
use sunbeam_optics::colour::ToneCurve;
use wgpu::util::DeviceExt;

/// The accumulation shader's uniform (shaders/accumulate.wgsl `AccU`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct AccU {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) count: u32,
    pub(crate) sample: u32,
}

/// The resolve shader's uniform (shaders/resolve.wgsl `ResolveU`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ResolveU {
    pub(crate) width: u32,
    pub(crate) inv_n: f32,
    pub(crate) curve: u32,
    pub(crate) output: u32,
}

pub(crate) const ACCUMULATE_WGSL: &str = include_str!("../../../shaders/accumulate.wgsl");
pub(crate) const RESOLVE_WGSL: &str = concat!(
    include_str!("../../../shaders/display.wgsl"),
    include_str!("../../../shaders/resolve.wgsl")
);

/// An RGBA32F running sum of frames of one size.
pub struct Accumulator {
    pub width: u32,
    pub height: u32,
    sum: wgpu::Buffer,
    uniform: wgpu::Buffer,
    bind: wgpu::BindGroup,
    pipeline: wgpu::ComputePipeline,
    readback: Option<wgpu::Buffer>,
    count: std::cell::Cell<u32>,
}

impl Accumulator {
    /// A sum for `frame` (a single-sample float texture of `width x height`)
    /// or, with `msaa`, for that multisampled target (4 samples) of which
    /// `frame` is the resolve; `readback`: headless (the sum can be copied
    /// back).
    pub fn new(
        gpu: &Gpu,
        frame: &wgpu::TextureView,
        msaa: Option<&wgpu::TextureView>,
        width: u32,
        height: u32,
        readback: bool,
    ) -> Result<Accumulator> {
        let device = &gpu.device;
        let bytes = width as u64 * height as u64 * 16;
        if bytes > device.limits().max_storage_buffer_binding_size {
            return Err(Error::usage(format!(
                "size {width}x{height}: the accumulation buffer ({} MiB) exceeds this GPU's storage buffer limit",
                bytes >> 20
            )));
        }
        let sum = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulation"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("accumulation uniform"),
            contents: bytemuck::bytes_of(&AccU {
                width,
                height,
                count: 0,
                sample: 4,
            }),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("accumulate.wgsl"),
            source: wgpu::ShaderSource::Wgsl(ACCUMULATE_WGSL.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("accumulate"),
            layout: None,
            module: &module,
            entry_point: Some(if msaa.is_some() {
                "cs_add_ms"
            } else {
                "cs_add"
            }),
            compilation_options: Default::default(),
            cache: None,
        });
        let layout = pipeline.get_bind_group_layout(0);
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("accumulate"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: sum.as_entire_binding(),
                },
                match msaa {
                    Some(ms) => wgpu::BindGroupEntry {
                        binding: 3,
                        resource: wgpu::BindingResource::TextureView(ms),
                    },
                    None => wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(frame),
                    },
                },
            ],
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::internal(format!("accumulation pipeline: {e}")));
        }
        let readback = readback.then(|| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("accumulation readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        Ok(Accumulator {
            width,
            height,
            sum,
            uniform,
            bind,
            pipeline,
            readback,
            count: std::cell::Cell::new(0),
        })
    }

    /// Frames in the sum.
    pub fn count(&self) -> u32 {
        self.count.get()
    }

    /// Start a new sum (the next frame overwrites it).
    pub fn reset(&self) {
        self.count.set(0);
    }

    /// Record adding the frame (drawn earlier in `enc`) to the sum: under
    /// MSAA its `sample` (0..4), or with 4 the mean of its samples (ignored
    /// without MSAA).
    pub fn add(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, sample: u32) {
        let u = AccU {
            width: self.width,
            height: self.height,
            count: self.count.get(),
            sample,
        };
        gpu.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&u));
        let mut cp = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("accumulate"),
            timestamp_writes: None,
        });
        cp.set_pipeline(&self.pipeline);
        cp.set_bind_group(0, &self.bind, &[]);
        cp.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
        drop(cp);
        self.count.set(self.count.get().saturating_add(1));
    }

    /// The sum's buffer (for the resolve pass).
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.sum
    }

    /// Read the mean of the accumulated frames back (headless).
    pub fn read(&self, gpu: &Gpu) -> Result<LinearImage> {
        Ok(self.read_with_coverage(gpu)?.0)
    }

    /// [`Accumulator::read`] with each pixel's mean alpha: on an offscreen
    /// target the part of the pixel the meshes cover ([`crate::Offscreen`]).
    pub fn read_with_coverage(&self, gpu: &Gpu) -> Result<(LinearImage, Vec<f32>)> {
        let rb = self
            .readback
            .as_ref()
            .ok_or_else(|| Error::internal("this accumulator has no readback buffer"))?;
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&self.sum, 0, rb, 0, self.sum.size());
        gpu.queue.submit([enc.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        rb.map_async(wgpu::MapMode::Read, .., move |res| {
            let _ = tx.send(res);
        });
        gpu.wait()?;
        rx.recv()
            .map_err(|e| Error::internal(format!("readback: {e}")))?
            .map_err(|e| Error::internal(format!("readback: {e}")))?;
        gpu.take_errors()?;
        let inv = 1.0 / self.count.get().max(1) as f32;
        let mut img = LinearImage::new(self.width, self.height);
        let mut coverage = vec![0.0; img.rgb.len()];
        {
            let data = rb
                .get_mapped_range(..)
                .map_err(|e| Error::internal(format!("readback: {e}")))?;
            let px: &[f32] = bytemuck::cast_slice(&data);
            for (i, (o, c)) in img.rgb.iter_mut().zip(&mut coverage).enumerate() {
                *o = [px[4 * i] * inv, px[4 * i + 1] * inv, px[4 * i + 2] * inv];
                *c = px[4 * i + 3] * inv;
            }
        }
        rb.unmap();
        Ok((img, coverage))
    }
}

/// The window's resolve pass: the mean of an [`Accumulator`] through the display
/// transform onto a surface.
pub struct Resolve {
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
}

impl Resolve {
    pub fn new(gpu: &Gpu, format: wgpu::TextureFormat) -> Result<Resolve> {
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("resolve.wgsl"),
            source: wgpu::ShaderSource::Wgsl(RESOLVE_WGSL.into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("resolve"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_full"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_resolve"),
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
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("resolve uniform"),
            size: std::mem::size_of::<ResolveU>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = pipeline.get_bind_group_layout(0);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::internal(format!("resolve pipeline: {e}")));
        }
        Ok(Resolve {
            pipeline,
            uniform,
            layout,
        })
    }

    /// Record drawing the mean of `acc` onto `target` (display values, or their
    /// linear value for an sRGB format).
    pub fn encode(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        acc: &Accumulator,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        curve: ToneCurve,
    ) {
        let u = ResolveU {
            width: acc.width,
            inv_n: 1.0 / acc.count().max(1) as f32,
            curve: match curve {
                ToneCurve::Clamp => 0,
                ToneCurve::Reinhard => 1,
            },
            output: u32::from(format.is_srgb()),
        };
        gpu.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&u));
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("resolve"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: acc.buffer().as_entire_binding(),
                },
            ],
        });
        let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("resolve"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        rp.set_pipeline(&self.pipeline);
        rp.set_bind_group(0, &bind, &[]);
        rp.draw(0..3, 0..1);
    }
}
