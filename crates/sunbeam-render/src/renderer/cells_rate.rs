//! The first-frame cells at a lower rate than the pixels (docs/LIGHTING.md
//! "Cells at a lower rate"): a pre-pass draws the meshes on a grid of every
//! K-th pixel corner (the same camera, a viewport K times smaller) with
//! shaders/default.wgsl's `fs_cells`, which writes the cells' XYZ, the
//! frame's normal with the distance to the eye, and its tangent into three
//! float targets; the frame's pass reads them (bind group 0, bindings 2-4)
//! and mixes the four corners of a pixel's K x K block where they saw one
//! smooth patch of surface, walking the cells itself elsewhere (shaders/environment.wgsl
//! `env_cells_shared`).
//!
//! The walk over the cells is what a cells frame costs (docs/LIGHTING.md
//! "Cost"); the sun, the hot spots and the diffuse part stay at every pixel.

use super::pipeline::{render_pipeline, Technique};
use super::SHADER;
use crate::gpu::Gpu;
use std::sync::Mutex;
use sunbeam_common::Result;

/// Formats of the grid's targets: the cells' XYZ (linear values, above 1
/// too), and the frame's normal and tangent in 32-bit floats (the test
/// compares directions to a fraction of a degree: half floats resolve
/// about 2.5 degrees near a dot product of 1).
const XYZ_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const FRAME_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// Default grid spacing in pixels (`--env-cells-rate`): measured in
/// docs/LIGHTING.md "Cells at a lower rate".
pub const DEFAULT_CELLS_RATE: u32 = 4;

/// The grid's targets for one frame size, and bind group 0 reading them.
struct Grid {
    /// The frame size (pixels) the grid was made for.
    full: [u32; 2],
    xyz: wgpu::TextureView,
    nd: wgpu::TextureView,
    t: wgpu::TextureView,
    depth: wgpu::TextureView,
    /// Bind group 0 of the frame's pass: globals, spectrum and the grid.
    bind: wgpu::BindGroup,
}

/// The pre-pass: its pipeline, bind group 0 with stand-ins for the grid
/// (a pass cannot read the targets it writes), and the grid of the last
/// frame size.
pub(super) struct CellsRate {
    rate: u32,
    pipeline: wgpu::RenderPipeline,
    pre_bind: wgpu::BindGroup,
    grid: Mutex<Option<Grid>>,
}

/// Group 0's entries: the globals, the spectrum and three grid textures.
fn group0<'a>(
    globals: &'a wgpu::Buffer,
    spectrum: &'a wgpu::Buffer,
    views: [&'a wgpu::TextureView; 3],
) -> [wgpu::BindGroupEntry<'a>; 5] {
    let [a, b, c] = views;
    [
        wgpu::BindGroupEntry {
            binding: 0,
            resource: globals.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: spectrum.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 2,
            resource: wgpu::BindingResource::TextureView(a),
        },
        wgpu::BindGroupEntry {
            binding: 3,
            resource: wgpu::BindingResource::TextureView(b),
        },
        wgpu::BindGroupEntry {
            binding: 4,
            resource: wgpu::BindingResource::TextureView(c),
        },
    ]
}

/// Bind group 0 with `views` as the grid.
pub(super) fn global_bind(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    globals: &wgpu::Buffer,
    spectrum: &wgpu::Buffer,
    views: [&wgpu::TextureView; 3],
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("globals"),
        layout,
        entries: &group0(globals, spectrum, views),
    })
}

fn target(gpu: &Gpu, w: u32, h: u32, format: wgpu::TextureFormat) -> wgpu::TextureView {
    gpu.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("cells grid"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

impl CellsRate {
    /// The pre-pass at one pixel in `rate` x `rate` (> 1), with the default
    /// pipeline's bind group layouts; `stand_in` is bound as the grid while
    /// the pre-pass draws.
    pub(super) fn new(
        device: &wgpu::Device,
        layouts: &[&wgpu::BindGroupLayout],
        rate: u32,
        globals: &wgpu::Buffer,
        spectrum: &wgpu::Buffer,
        stand_in: &wgpu::TextureView,
    ) -> Result<CellsRate> {
        let technique = Technique {
            label: "diffraction.wgsl cells pre-pass",
            source: SHADER,
            entry: "fs_cells",
            constants: Vec::new(),
        };
        let pipeline = render_pipeline(
            device,
            layouts,
            &[XYZ_FORMAT, FRAME_FORMAT, FRAME_FORMAT],
            1,
            &technique,
        )?;
        let pre_bind = global_bind(
            device,
            layouts[0],
            globals,
            spectrum,
            [stand_in, stand_in, stand_in],
        );
        Ok(CellsRate {
            rate,
            pipeline,
            pre_bind,
            grid: Mutex::new(None),
        })
    }

    /// The grid spacing K.
    pub(super) fn rate(&self) -> u32 {
        self.rate
    }

    /// Make the grid for a `w x h` frame (kept while the size stays).
    pub(super) fn prepare(
        &self,
        gpu: &Gpu,
        layout: &wgpu::BindGroupLayout,
        globals: &wgpu::Buffer,
        spectrum: &wgpu::Buffer,
        w: u32,
        h: u32,
    ) {
        let mut grid = self.grid.lock().unwrap_or_else(|e| e.into_inner());
        if grid.as_ref().is_some_and(|g| g.full == [w, h]) {
            return;
        }
        // Grid points at the frame's pixel corners 0, K, 2K, ... up to and
        // past the last pixel.
        let (gw, gh) = (w.div_ceil(self.rate) + 1, h.div_ceil(self.rate) + 1);
        let xyz = target(gpu, gw, gh, XYZ_FORMAT);
        let nd = target(gpu, gw, gh, FRAME_FORMAT);
        let t = target(gpu, gw, gh, FRAME_FORMAT);
        let depth = super::depth_view(gpu, gw, gh);
        let bind = global_bind(&gpu.device, layout, globals, spectrum, [&xyz, &nd, &t]);
        *grid = Some(Grid {
            full: [w, h],
            xyz,
            nd,
            t,
            depth,
            bind,
        });
    }

    /// Record the pre-pass (`draw` draws the meshes with groups 1 and 2 set)
    /// and call `main` with bind group 0 for the frame's pass. Without a
    /// grid (no [`CellsRate::prepare`] yet) `main` gets `fallback`.
    pub(super) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        fallback: &wgpu::BindGroup,
        draw: impl Fn(&mut wgpu::RenderPass<'_>),
        main: impl FnOnce(&mut wgpu::CommandEncoder, &wgpu::BindGroup),
    ) {
        let grid = self.grid.lock().unwrap_or_else(|e| e.into_inner());
        let Some(g) = grid.as_ref() else {
            main(enc, fallback);
            return;
        };
        {
            let clear = |view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            };
            let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("cells pre-pass"),
                color_attachments: &[clear(&g.xyz), clear(&g.nd), clear(&g.t)],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &g.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // The frame's projection onto a viewport K times smaller, half a
            // grid pixel in: grid pixel i's centre is the frame's x = i K.
            let k = self.rate as f32;
            rp.set_viewport(
                0.5,
                0.5,
                g.full[0] as f32 / k,
                g.full[1] as f32 / k,
                0.0,
                1.0,
            );
            rp.set_pipeline(&self.pipeline);
            rp.set_bind_group(0, &self.pre_bind, &[]);
            draw(&mut rp);
        }
        main(enc, &g.bind);
    }
}
