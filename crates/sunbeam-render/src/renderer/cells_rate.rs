//! The first-frame cells shaded once per pixel, and at a lower rate than the
//! pixels where the surface is smooth (docs/LIGHTING.md "Cells at a lower
//! rate", "One walk per pixel"). Two pre-passes draw the meshes before the
//! frame:
//!
//! 1. At a rate K > 1, the coarse grid: every K-th pixel corner (the same
//!    camera, a viewport K times smaller) with shaders/default.wgsl's
//!    `fs_cells`, which writes the view and whether the cells are shaded
//!    there, the frame's normal with the distance to the eye, and its
//!    tangent with the mesh (`MaterialU::cells_id`) into three float
//!    targets; then one full-screen pass per mesh (`fs_cells_walk`) walks
//!    the cells at that mesh's points into the grid's XYZ (with the half
//!    grid, [`half_grid`], a pass before it walks every other point, and
//!    the grid's walk mixes its other points from them where their blocks
//!    are smooth). A walk in the
//!    raster pass ran in SIMD blocks that triangles smaller than a few grid
//!    pixels leave mostly empty: on lavapipe it cost twice as much at a
//!    grid of 4 on a 512 x 512 sphere (docs/LIGHTING.md "What a grid's walk
//!    costs"). Both walks render into targets laid out in bands ([`Bands`])
//!    and copy them back into the grid's layout.
//! 2. The centre pass, single-sampled at the frame's size (`fs_cells_centre`):
//!    each pixel centre takes the bilinear mix of its K x K block's corners
//!    where they saw one smooth patch of surface (shaders/environment.wgsl
//!    `env_cells_mixed`) and marks the pixel elsewhere; it writes the XYZ,
//!    the normal with the distance, and the view and tangent as the grid's
//!    raster pass does. Then one full-screen pass per mesh walks the marked
//!    pixels into the XYZ (`fs_cells_walk` again, the target loaded, not
//!    cleared): walked in the raster pass, those walks ran in SIMD blocks
//!    half filled by pixels that mixed, on triangles a few pixels wide.
//!
//! The frame's pass (bind group 0, bindings 2-3) then reads its pixel's
//! centre value where its own normal and distance match it, and walks the
//! cells only where they do not (a silhouette's other surface). Without the
//! centre pass a multisampled frame walked once per triangle touching a
//! pixel: a dense mesh (the generated snake, several triangles per pixel)
//! paid that about 6 times on lavapipe. A mesh with scale maps under MSAA
//! neither reads nor is shaded by the pre-passes (its samples walk for
//! themselves; renderer/mod.rs `reads_centre` decides it once and passes it
//! to the shaders as `MaterialU::reads_cells`), so the renderer makes no
//! pre-passes for a frame none of whose meshes reads them.
//!
//! The walk over the cells is what a cells frame costs (docs/LIGHTING.md
//! "Cost"); the sun, the hot spots and the diffuse part stay at every pixel.

use super::pipeline::{fullscreen_pipeline, render_pipeline, Technique};
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

/// The grid pass's clip volume reaches this share of the frame's width and
/// height past each edge (the vertex shader's `SB_CLIP_SCALE` is 1 / (1 + 2
/// GRID_PAD), the viewport as much wider). The grid's points lie on the
/// frame's pixel corners 0, K, ... w, and the last, on the frame's edge,
/// would lie on the clip volume's border, which the rasteriser leaves out:
/// the last K rows and columns of pixels then had no corners and walked the
/// cells each (on a 512 x 512 sphere at K = 4, half of the pixels that
/// walked). An eighth also covers the point past a frame whose size is not
/// a multiple of K from 8 grid points across.
const GRID_PAD: f64 = 0.125;

/// The rows of a band of the walk targets, at the least ([`Bands`]): a
/// multiple of the 4 x 4 pixels a CPU rasteriser shades together.
const BAND_ROWS: u32 = 8;

/// A CPU rasteriser's tile side (lavapipe: 64 x 64 pixels), the tallest
/// band ([`Bands`]).
const TILE: u32 = 64;

/// The grid's walks render into targets laid out in bands: the grid's rows
/// cut into bands, put side by side (shaders/default.wgsl `band_point`,
/// `Globals::cells_band`), then copied back into the grid's layout
/// ([`Bands::unband`]). A CPU rasteriser (lavapipe) shares a pass among its
/// threads by tiles of 64 x 64 pixels: the half grid of a 512 x 512 frame
/// (65 x 65 points) was one tile and three slivers, so one thread walked it
/// all (docs/LIGHTING.md "The walks' layout"). But a walk costs more in a
/// short tile: the 20 um grid of a 512 x 512 frame (129 x 129 points) took
/// 5.9 s in bands of 8 rows and 3.3 s in bands of 64 (lavapipe, 2 cores;
/// 16 rows 4.3 s, 32 rows 3.6 s, the grid's own layout 3.3 s). So a band
/// is a tile tall (64 rows) where the smallest grid walked in bands (the
/// half grid where there is one) still gives each thread a tile's worth of
/// points, and halves down to [`BAND_ROWS`] until it does (a grid too small
/// to fill the threads even then stays a tile tall); the rows double from
/// there until the strip fits the device's widest texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Bands {
    /// Rows of one band.
    pub(super) rows: u32,
}

impl Bands {
    /// The bands of a grid `size` points (walked from its half grid when
    /// `half`), for a device whose textures are at most `max` texels wide
    /// and a rasteriser of `threads` threads.
    pub(super) fn new(size: [u32; 2], half: bool, max: u32, threads: u32) -> Bands {
        let walked = if half { half_size(size) } else { size };
        let points = walked[0] * walked[1];
        // the tallest band that gives every thread a tile's worth; with too
        // few points for any height, the tallest (a grid of up to 64 rows
        // keeps its own layout)
        let mut rows = [TILE, TILE / 2, TILE / 4, BAND_ROWS]
            .into_iter()
            .find(|&rows| points >= threads.max(1) * TILE * rows)
            .unwrap_or(TILE);
        while rows < size[1] && size[0] * size[1].div_ceil(rows) > max {
            rows *= 2;
        }
        Bands { rows }
    }

    /// The size of the banded target of a grid `size` points.
    fn strip(self, size: [u32; 2]) -> [u32; 2] {
        [
            size[0] * size[1].div_ceil(self.rows),
            self.rows.min(size[1]),
        ]
    }

    /// Copy the bands of `strip` back into the grid's layout in `grid`
    /// (`size` points).
    fn unband(
        self,
        enc: &mut wgpu::CommandEncoder,
        strip: &wgpu::TextureView,
        grid: &wgpu::TextureView,
        size: [u32; 2],
    ) {
        for b in 0..size[1].div_ceil(self.rows) {
            let at = |texture, x, y| wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x, y, z: 0 },
                aspect: wgpu::TextureAspect::All,
            };
            enc.copy_texture_to_texture(
                at(strip.texture(), b * size[0], 0),
                at(grid.texture(), 0, b * self.rows),
                wgpu::Extent3d {
                    width: size[0],
                    height: self.rows.min(size[1] - b * self.rows),
                    depth_or_array_layers: 1,
                },
            );
        }
    }
}

/// The threads lavapipe shares a pass among: `LP_NUM_THREADS`, else the
/// machine's cores (what it defaults to). Only the bands' shape follows it
/// ([`Bands`]): the image is the same whatever it is.
fn rasteriser_threads() -> u32 {
    std::env::var("LP_NUM_THREADS")
        .ok()
        .and_then(|v| v.trim().parse::<u32>().ok())
        .or_else(|| {
            std::thread::available_parallelism()
                .ok()
                .and_then(|n| u32::try_from(n.get()).ok())
        })
        .unwrap_or(1)
        .max(1)
}

/// The grid's size in points for a `w x h` frame at rate `rate` > 1: the
/// frame's pixel corners 0, K, 2K, ... up to and past the last pixel.
fn grid_size(rate: u32, w: u32, h: u32) -> [u32; 2] {
    [w.div_ceil(rate) + 1, h.div_ceil(rate) + 1]
}

/// The half grid's size for a grid `size` points: its even points.
fn half_size(size: [u32; 2]) -> [u32; 2] {
    [size[0].div_ceil(2), size[1].div_ceil(2)]
}

/// The centre pass's XYZ: used as it is (not interpolated), so in 32-bit
/// floats like the frame's own walk.
const CENTRE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// Default grid spacing in pixels (`--env-cells-rate`) for a patch under
/// [`FINE_GRID_PATCH_M`]: measured in docs/LIGHTING.md "Cells at a lower
/// rate".
pub const DEFAULT_CELLS_RATE: u32 = 4;

/// Default grid spacing from [`FINE_GRID_PATCH_M`]: a larger patch's orders
/// are narrower, and so is the term's structure across the surface.
pub const DEFAULT_CELLS_RATE_LARGE: u32 = 2;

/// The patch size (longer side, metres) from which the grid is
/// [`DEFAULT_CELLS_RATE_LARGE`]. On a sky-lit sphere's band of rows at
/// `--supersample 8`, against two converged seeds (CIEDE2000 p99, grid of 4
/// / 2 / every pixel): 20 um 1.04 / 1.01 / 1.01, 31 um 1.06 / 0.91 / 0.99,
/// 41 um 1.24 / 0.83 / 0.86, 82 um 1.60 / 1.13 / 1.13. So the grid of 4 is
/// within the references' own noise of every pixel up to 31 um and costs
/// from 41 um; the bound sits just above the largest size measured safe
/// (docs/LIGHTING.md "Cells at a lower rate").
pub const FINE_GRID_PATCH_M: f64 = 32e-6;

/// Below this patch size (longer side, metres) the grid's points mix from
/// the half grid (every other point) where its blocks of 2K pixels pass the
/// same test as a pixel's block (`CellsGrid::half`). Measured at 5 um
/// (the 512 x 512 sky-lit sphere of docs/LIGHTING.md "The half grid"); a
/// 20 um pack's orders are too narrow for the 2-degree cone across blocks
/// of 8 pixels (a flat grid of 8: CIEDE2000 p99 2.30 from the converged
/// reference against 1.04 for the grid of 4).
pub const HALF_GRID_PATCH_M: f64 = 10e-6;

/// Whether a frame whose reading packs' largest patch side is `patch_m`
/// metres mixes its grid from the half grid.
pub fn half_grid(patch_m: f64) -> bool {
    patch_m < HALF_GRID_PATCH_M
}

/// The default grid spacing for a pack whose patch's longer side is
/// `patch_m` metres.
pub fn default_cells_rate(patch_m: f64) -> u32 {
    if patch_m >= FINE_GRID_PATCH_M {
        DEFAULT_CELLS_RATE_LARGE
    } else {
        DEFAULT_CELLS_RATE
    }
}

/// The coarse grid's targets (rate K > 1).
struct Coarse {
    /// The grid's size in points, and its bands.
    size: [u32; 2],
    bands: Bands,
    /// The raster pass's view with the mark (fs_cells).
    xyz: wgpu::TextureView,
    /// The walk's XYZ (fs_cells_walk) in bands, and in the grid's layout
    /// (what the centre pass reads).
    strip: wgpu::TextureView,
    walked: wgpu::TextureView,
    /// Bind group 0 of the walk: the raster pass's targets and the half
    /// grid's XYZ (a stand-in without it).
    walk_bind: wgpu::BindGroup,
    /// The half grid's XYZ in bands and in the half grid's layout, and the
    /// bind group of its walk (the raster pass's targets), with
    /// [`CellsRate`]'s half grid.
    half: Option<(wgpu::TextureView, wgpu::TextureView, wgpu::BindGroup)>,
    nd: wgpu::TextureView,
    t: wgpu::TextureView,
    depth: wgpu::TextureView,
}

/// The targets for one frame size, and the bind groups reading them.
struct Grid {
    /// The frame size (pixels) the grid was made for.
    full: [u32; 2],
    coarse: Option<Coarse>,
    centre_xyz: wgpu::TextureView,
    centre_nd: wgpu::TextureView,
    centre_depth: wgpu::TextureView,
    /// The centre pass's view with the mark and tangent with the mesh, which
    /// its walk reads.
    centre_view: wgpu::TextureView,
    centre_t: wgpu::TextureView,
    /// Bind group 0 of the centre pass: the coarse grid (stand-ins at K = 1).
    centre_bind: wgpu::BindGroup,
    /// Bind group 0 of the centre's walk: the centre pass's targets and
    /// its even pixels' XYZ (a stand-in without them).
    centre_walk_bind: wgpu::BindGroup,
    /// The centre's even pixels' XYZ and the bind group of their walk (the
    /// centre pass's targets), with a grid (rate > 1).
    centre_half: Option<(wgpu::TextureView, wgpu::BindGroup)>,
    /// Bind group 0 of the frame's pass: globals, spectrum and the centres.
    bind: wgpu::BindGroup,
}

/// The pre-passes: their pipelines, bind group 0 with stand-ins for the
/// grids (a pass cannot read the targets it writes), and the grids of the
/// last frame size.
pub(super) struct CellsRate {
    rate: u32,
    /// The device's widest 2D texture (texels).
    max_width: u32,
    /// The threads a CPU rasteriser shares a pass among ([`Bands`]).
    threads: u32,
    /// The grid's passes (rate K > 1).
    coarse: Option<CoarsePipelines>,
    /// The centre pass and its full-screen walk.
    centre: (wgpu::RenderPipeline, wgpu::RenderPipeline),
    /// The centre's even pixels' walk before it, with a grid (rate > 1).
    centre_half: Option<wgpu::RenderPipeline>,
    pre_bind: wgpu::BindGroup,
    stand_in: wgpu::TextureView,
    grid: Mutex<Option<Grid>>,
}

/// The pre-passes' grid: one pixel in `rate` x `rate` (>= 1; 1: the centre
/// pass alone), mixed from the half grid where it can (`half`,
/// [`half_grid`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct CellsGrid {
    pub(super) rate: u32,
    pub(super) half: bool,
}

/// The grid's raster pass, its full-screen walk, and the half grid's walk
/// before it where the packs are small enough ([`half_grid`]).
struct CoarsePipelines {
    raster: wgpu::RenderPipeline,
    walk: wgpu::RenderPipeline,
    half: Option<wgpu::RenderPipeline>,
}

/// Group 0's entries: the globals, the spectrum and three grid textures.
fn group0<'a>(
    globals: &'a wgpu::Buffer,
    spectrum: &'a wgpu::Buffer,
    views: [&'a wgpu::TextureView; 4],
) -> [wgpu::BindGroupEntry<'a>; 6] {
    let [a, b, c, d] = views;
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
        wgpu::BindGroupEntry {
            binding: 5,
            resource: wgpu::BindingResource::TextureView(d),
        },
    ]
}

/// Bind group 0 with `views` as the grid.
pub(super) fn global_bind(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    globals: &wgpu::Buffer,
    spectrum: &wgpu::Buffer,
    views: [&wgpu::TextureView; 4],
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("globals"),
        layout,
        entries: &group0(globals, spectrum, views),
    })
}

fn target(gpu: &Gpu, w: u32, h: u32, format: wgpu::TextureFormat) -> wgpu::TextureView {
    target_for(gpu, [w, h], format, wgpu::TextureUsages::TEXTURE_BINDING)
}

/// A target `size` texels that is also used as `usage`.
fn target_for(
    gpu: &Gpu,
    size: [u32; 2],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::TextureView {
    let [w, h] = size;
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
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | usage,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// The pre-passes write float targets (16- and 32-bit), which OpenGL adapters
/// (llvmpipe, what wgpu falls back to when no Vulkan driver is installed) may
/// not render to: say so, and what to do instead, before building them.
fn check_targets(adapter: &wgpu::Adapter) -> Result<()> {
    for format in [XYZ_FORMAT, FRAME_FORMAT, CENTRE_FORMAT] {
        let usages = adapter.get_texture_format_features(format).allowed_usages;
        if !usages.contains(wgpu::TextureUsages::RENDER_ATTACHMENT) {
            return Err(sunbeam_common::Error::internal(format!(
                "the first-frame cells (--env-estimator cells) render to {format:?} targets, \
                 which this GPU adapter ({}) refuses: install Vulkan (Debian: \
                 mesa-vulkan-drivers) or use --env-estimator monte-carlo",
                adapter.get_info().name
            )));
        }
    }
    Ok(())
}

impl CellsRate {
    /// The pre-passes on `grid`, with the default pipeline's bind group
    /// layouts;
    /// `stand_in` is bound as the grids while a pass cannot read them.
    pub(super) fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        layouts: &[&wgpu::BindGroupLayout],
        grid: CellsGrid,
        globals: &wgpu::Buffer,
        spectrum: &wgpu::Buffer,
        stand_in: &wgpu::TextureView,
    ) -> Result<CellsRate> {
        check_targets(adapter)?;
        // The grid's raster pass and its walk: both or neither.
        let pass = |label, entry| Technique {
            label,
            source: SHADER,
            entry,
            constants: Vec::new(),
        };
        let CellsGrid { rate, half } = grid;
        // The centre's walk mixes its odd pixels from its even ones where
        // they pass the block test, as the grid from its half grid: with a
        // grid (rate > 1), where the frame's values are smooth enough to
        // interpolate at all; at rate 1 every pixel walks.
        let centre_half = rate > 1;
        let coarse = if rate > 1 {
            let raster = render_pipeline(
                device,
                layouts,
                &[FRAME_FORMAT, FRAME_FORMAT, FRAME_FORMAT],
                1,
                &Technique {
                    constants: vec![("SB_CLIP_SCALE", 1.0 / (1.0 + 2.0 * GRID_PAD))],
                    ..pass("diffraction.wgsl cells pre-pass", "fs_cells")
                },
            )?;
            let walk = fullscreen_pipeline(
                device,
                layouts,
                &[XYZ_FORMAT],
                &Technique {
                    constants: vec![
                        ("SB_WALK_FROM_HALF", f64::from(u8::from(half))),
                        ("SB_WALK_BANDED", 1.0),
                    ],
                    ..pass("diffraction.wgsl cells grid walk", "fs_cells_walk")
                },
            )?;
            let half = if half {
                Some(fullscreen_pipeline(
                    device,
                    layouts,
                    &[XYZ_FORMAT],
                    &Technique {
                        constants: vec![("SB_WALK_BANDED", 1.0)],
                        ..pass("diffraction.wgsl cells half walk", "fs_cells_walk_half")
                    },
                )?)
            } else {
                None
            };
            Some(CoarsePipelines { raster, walk, half })
        } else {
            None
        };
        let centre = (
            render_pipeline(
                device,
                layouts,
                &[CENTRE_FORMAT, FRAME_FORMAT, FRAME_FORMAT, FRAME_FORMAT],
                1,
                &pass("diffraction.wgsl cells centre pass", "fs_cells_centre"),
            )?,
            fullscreen_pipeline(
                device,
                layouts,
                &[CENTRE_FORMAT],
                &Technique {
                    constants: vec![("SB_WALK_FROM_HALF", f64::from(u8::from(centre_half)))],
                    ..pass("diffraction.wgsl cells centre walk", "fs_cells_walk")
                },
            )?,
        );
        let centre_half = if centre_half {
            Some(fullscreen_pipeline(
                device,
                layouts,
                &[CENTRE_FORMAT],
                &pass(
                    "diffraction.wgsl cells centre half walk",
                    "fs_cells_walk_half",
                ),
            )?)
        } else {
            None
        };
        let pre_bind = global_bind(
            device,
            layouts[0],
            globals,
            spectrum,
            [stand_in, stand_in, stand_in, stand_in],
        );
        Ok(CellsRate {
            rate,
            max_width: device.limits().max_texture_dimension_2d,
            threads: rasteriser_threads(),
            coarse,
            centre,
            centre_half,
            pre_bind,
            stand_in: stand_in.clone(),
            grid: Mutex::new(None),
        })
    }

    /// The grid spacing K.
    pub(super) fn rate(&self) -> u32 {
        self.rate
    }

    /// The rows of a band of the walk targets for a `w x h` frame
    /// (`Globals::cells_band`); 0 without a grid.
    pub(super) fn band_rows(&self, w: u32, h: u32) -> u32 {
        if self.rate > 1 {
            self.bands(grid_size(self.rate, w, h)).rows
        } else {
            0
        }
    }

    /// Whether the grid mixes from the half grid.
    pub(super) fn half(&self) -> bool {
        self.coarse.as_ref().is_some_and(|p| p.half.is_some())
    }

    /// The bands of a grid `size` points.
    fn bands(&self, size: [u32; 2]) -> Bands {
        Bands::new(size, self.half(), self.max_width, self.threads)
    }

    /// Make the targets for a `w x h` frame (kept while the size stays).
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
        let copied = |size, usage| target_for(gpu, size, XYZ_FORMAT, usage);
        let coarse = (self.rate > 1).then(|| {
            let size = grid_size(self.rate, w, h);
            let bands = self.bands(size);
            let [gw, gh] = size;
            let xyz = target(gpu, gw, gh, FRAME_FORMAT);
            let nd = target(gpu, gw, gh, FRAME_FORMAT);
            let t = target(gpu, gw, gh, FRAME_FORMAT);
            let bind = |half| {
                global_bind(
                    &gpu.device,
                    layout,
                    globals,
                    spectrum,
                    [&xyz, &nd, &t, half],
                )
            };
            // the grid's even points, (2i, 2j)
            let half = self
                .coarse
                .as_ref()
                .is_some_and(|p| p.half.is_some())
                .then(|| {
                    let hs = half_size(size);
                    let strip = copied(bands.strip(hs), wgpu::TextureUsages::COPY_SRC);
                    let view = copied(
                        hs,
                        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                    );
                    let walk_bind = bind(&self.stand_in);
                    (strip, view, walk_bind)
                });
            let walk_bind = bind(half.as_ref().map_or(&self.stand_in, |(_, v, _)| v));
            Coarse {
                size,
                bands,
                xyz,
                strip: copied(bands.strip(size), wgpu::TextureUsages::COPY_SRC),
                walked: copied(
                    size,
                    wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                ),
                walk_bind,
                half,
                nd,
                t,
                depth: super::depth_view(gpu, gw, gh),
            }
        });
        let centre_xyz = target(gpu, w, h, CENTRE_FORMAT);
        let centre_nd = target(gpu, w, h, FRAME_FORMAT);
        let centre_depth = super::depth_view(gpu, w, h);
        let centre_view = target(gpu, w, h, FRAME_FORMAT);
        let centre_t = target(gpu, w, h, FRAME_FORMAT);
        // the centre's even pixels (2i, 2j), and the bind group of their walk
        let centre_half = self.centre_half.as_ref().map(|_| {
            let [hw, hh] = half_size([w, h]);
            let xyz = target(gpu, hw, hh, CENTRE_FORMAT);
            let bind = global_bind(
                &gpu.device,
                layout,
                globals,
                spectrum,
                [&centre_view, &centre_nd, &centre_t, &self.stand_in],
            );
            (xyz, bind)
        });
        let centre_walk_bind = global_bind(
            &gpu.device,
            layout,
            globals,
            spectrum,
            [
                &centre_view,
                &centre_nd,
                &centre_t,
                centre_half.as_ref().map_or(&self.stand_in, |(v, _)| v),
            ],
        );
        let si = &self.stand_in;
        let centre_bind = match &coarse {
            Some(c) => global_bind(
                &gpu.device,
                layout,
                globals,
                spectrum,
                [&c.walked, &c.nd, &c.t, &self.stand_in],
            ),
            None => global_bind(&gpu.device, layout, globals, spectrum, [si, si, si, si]),
        };
        let bind = global_bind(
            &gpu.device,
            layout,
            globals,
            spectrum,
            [&centre_xyz, &centre_nd, si, si],
        );
        *grid = Some(Grid {
            full: [w, h],
            coarse,
            centre_xyz,
            centre_nd,
            centre_depth,
            centre_view,
            centre_t,
            centre_bind,
            centre_walk_bind,
            centre_half,
            bind,
        });
    }

    /// Record the pre-passes (`draw` draws the meshes with groups 1 and 2
    /// set) and call `main` with bind group 0 for the frame's pass. Without
    /// targets (no [`CellsRate::prepare`] yet) `main` gets `fallback`. The
    /// pre-passes' points are the frame's pixel centres moved by `shift`
    /// (pixels): the MSAA sample a frame of a running mean is read at
    /// (targets::frame_sample), so that the frame's pass reads the cells at
    /// the point it shades.
    pub(super) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        fallback: &wgpu::BindGroup,
        shift: [f32; 2],
        draw: impl Fn(&mut wgpu::RenderPass<'_>),
        draw_full: impl Fn(&mut wgpu::RenderPass<'_>),
        main: impl FnOnce(&mut wgpu::CommandEncoder, &wgpu::BindGroup),
    ) {
        let grid = self.grid.lock().unwrap_or_else(|e| e.into_inner());
        let Some(g) = grid.as_ref() else {
            main(enc, fallback);
            return;
        };
        fn clear(view: &wgpu::TextureView) -> Option<wgpu::RenderPassColorAttachment<'_>> {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        }
        let depth = |view| {
            Some(wgpu::RenderPassDepthStencilAttachment {
                view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            })
        };
        // a full-screen walk into a cleared `view`
        let walk = |enc: &mut wgpu::CommandEncoder,
                    label: &str,
                    view: &wgpu::TextureView,
                    pipeline: &wgpu::RenderPipeline,
                    bind: &wgpu::BindGroup| {
            let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[clear(view)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            rp.set_pipeline(pipeline);
            rp.set_bind_group(0, bind, &[]);
            draw_full(&mut rp);
        };
        if let (Some(c), Some(p)) = (&g.coarse, &self.coarse) {
            let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("cells pre-pass"),
                color_attachments: &[clear(&c.xyz), clear(&c.nd), clear(&c.t)],
                depth_stencil_attachment: depth(&c.depth),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // The frame's projection onto a viewport K times smaller, half a
            // grid pixel in: grid pixel i's centre is the frame's x = i K.
            // The clip volume, shrunk by SB_CLIP_SCALE, reaches GRID_PAD
            // past the frame: the viewport grows by as much on each side.
            let pad = GRID_PAD as f32;
            let (gw, gh) = (
                g.full[0] as f32 / self.rate as f32,
                g.full[1] as f32 / self.rate as f32,
            );
            // (a shift of the frame's points is 1 / K of a grid pixel; the
            // content moves with the viewport's origin)
            rp.set_viewport(
                0.5 - pad * gw - shift[0] / self.rate as f32,
                0.5 - pad * gh - shift[1] / self.rate as f32,
                gw * (1.0 + 2.0 * pad),
                gh * (1.0 + 2.0 * pad),
                0.0,
                1.0,
            );
            rp.set_pipeline(&p.raster);
            rp.set_bind_group(0, &self.pre_bind, &[]);
            draw(&mut rp);
            drop(rp);
            if let (Some((strip, view, bind)), Some(half)) = (&c.half, &p.half) {
                walk(enc, "cells half grid walk", strip, half, bind);
                c.bands.unband(enc, strip, view, half_size(c.size));
            }
            walk(enc, "cells grid walk", &c.strip, &p.walk, &c.walk_bind);
            c.bands.unband(enc, &c.strip, &c.walked, c.size);
        }
        {
            let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("cells centre pass"),
                color_attachments: &[
                    clear(&g.centre_xyz),
                    clear(&g.centre_nd),
                    clear(&g.centre_view),
                    clear(&g.centre_t),
                ],
                depth_stencil_attachment: depth(&g.centre_depth),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if shift != [0.0; 2] {
                rp.set_viewport(
                    -shift[0],
                    -shift[1],
                    g.full[0] as f32,
                    g.full[1] as f32,
                    0.0,
                    1.0,
                );
            }
            rp.set_pipeline(&self.centre.0);
            rp.set_bind_group(0, &g.centre_bind, &[]);
            draw(&mut rp);
            drop(rp);
            if let (Some((xyz, bind)), Some(half)) = (&g.centre_half, &self.centre_half) {
                walk(enc, "cells centre half walk", xyz, half, bind);
            }
            // the pixels the grid does not serve, walked into the XYZ the
            // centre pass wrote (loaded: its mixed pixels stay)
            let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("cells centre walk"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &g.centre_xyz,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            rp.set_pipeline(&self.centre.1);
            rp.set_bind_group(0, &g.centre_walk_bind, &[]);
            draw_full(&mut rp);
        }
        main(enc, &g.bind);
    }
}

#[cfg(test)]
mod tests {
    use super::{default_cells_rate, half_grid, Bands, BAND_ROWS, TILE};

    /// The sizes measured against converged references ([`super::FINE_GRID_PATCH_M`])
    /// take the grid that was measured as good as every pixel there.
    #[test]
    fn the_measured_sizes_take_the_grid_measured_for_them() {
        for (patch_um, rate) in [(5.12, 4), (20.48, 4), (30.72, 4), (40.96, 2), (81.92, 2)] {
            assert_eq!(default_cells_rate(patch_um * 1e-6), rate, "{patch_um} um");
        }
    }

    /// A strip of bands holds every row of the grid, fits the widest
    /// texture, and keeps the rows a multiple of the rasteriser's 4 x 4
    /// blocks; a grid that fits in one band keeps its layout.
    #[test]
    fn the_bands_hold_the_grid_within_the_widest_texture() {
        // 512 x 512 and 1920 x 1080 at K = 4 and 2, a 4k frame at K = 2,
        // and a grid of 3 x 3 (a 8 x 8 frame at K = 4)
        for size in [[129, 129], [481, 271], [961, 541], [1921, 1081], [3, 3]] {
            for max in [2048, 8192, 16384] {
                for (half, threads) in [(false, 1), (true, 2), (false, 16)] {
                    let b = Bands::new(size, half, max, threads);
                    let [w, h] = b.strip(size);
                    let at = format!("{size:?} {max} {half} {threads}: {w} x {h}");
                    assert!(w <= max.max(size[0]), "{at}");
                    assert_eq!(b.rows % BAND_ROWS, 0, "{at}");
                    assert!(h * (w / size[0]) >= size[1], "{at}");
                    assert_eq!(w % size[0], 0, "{at}");
                    if size[1] <= b.rows {
                        assert_eq!([w, h], size, "{at}");
                    }
                }
            }
        }
    }

    /// Bands are a tile tall where each thread still gets a tile's worth of
    /// points, and shorter where the walked grid is small: the 20 um grid of
    /// a 512 x 512 frame (no half grid) in bands of 64 rows on 2 threads;
    /// with its half grid (65 x 65 points, 5 um) in bands of 32, so that the
    /// half grid's strip is more than one tile and its slivers.
    #[test]
    fn the_bands_are_a_tile_tall_where_the_threads_stay_busy() {
        assert_eq!(Bands::new([129, 129], false, 8192, 2).rows, TILE);
        let half = Bands::new([129, 129], true, 8192, 2);
        assert_eq!(half.rows, 32);
        assert_eq!(half.strip([65, 65]), [195, 32]);
        // many threads: shorter bands, down to BAND_ROWS
        assert_eq!(Bands::new([129, 129], false, 8192, 16).rows, 16);
        assert_eq!(Bands::new([129, 129], true, 8192, 8).rows, BAND_ROWS);
        // 1920 x 1080 at K = 4: a tile tall
        assert_eq!(Bands::new([481, 271], false, 16384, 16).rows, TILE);
        // a 40 x 40 frame at K = 4 (11 x 11 points): no height shares it
        // among 2 threads, so it keeps its own layout, a tile tall
        let small = Bands::new([11, 11], false, 8192, 2);
        assert_eq!(small.rows, TILE);
        assert_eq!(small.strip([11, 11]), [11, 11]);
    }

    /// The half grid at the size measured with it (5 um), not at the sizes
    /// whose grid of 8 was measured too coarse (20 um) or not measured.
    #[test]
    fn the_half_grid_only_where_it_was_measured() {
        for (patch_um, half) in [(3.2, true), (5.12, true), (20.48, false), (81.92, false)] {
            assert_eq!(half_grid(patch_um * 1e-6), half, "{patch_um} um");
        }
    }
}
