//! Where frames go: depth and colour targets, the offscreen float target with
//! its readback and progressive sum, the sub-pixel jitter of the sum's frames.

use super::{FrameState, Renderer, DEPTH_FORMAT};
use crate::gpu::Gpu;
use sunbeam_common::{Error, Result};
use sunbeam_frame::{Image, LinearImage};

/// A depth texture view of the given size (single-sample).
pub fn depth_view(gpu: &Gpu, w: u32, h: u32) -> wgpu::TextureView {
    depth_view_ms(gpu, w, h, 1)
}

/// A depth texture view of the given size and sample count.
pub fn depth_view_ms(gpu: &Gpu, w: u32, h: u32, samples: u32) -> wgpu::TextureView {
    gpu.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("depth"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: samples.max(1),
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// A colour texture view to render into (`samples > 1`: multisampled, not
/// readable back; `bound`: shaders may load it, as the progressive sum does).
pub fn colour_view(
    gpu: &Gpu,
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
    samples: u32,
    bound: bool,
) -> wgpu::TextureView {
    let usage = if bound {
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING
    } else {
        wgpu::TextureUsages::RENDER_ATTACHMENT
    };
    gpu.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("msaa colour"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: samples.max(1),
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// An offscreen float target with readback: frames come back in linear light
/// (exposure applied) and go through the display transform on the CPU
/// (`sunbeam_frame::LinearImage::display`), so that MSAA resolves average
/// linear values, as a camera does. Its alpha is the meshes' coverage: 1
/// where a mesh is drawn, 0 where the clear colour or the background pass
/// is, so a resolved (or accumulated) pixel's alpha is the part of it the
/// meshes cover ([`Offscreen::render_frames_with_coverage`]).
pub struct Offscreen {
    pub width: u32,
    pub height: u32,
    tex: wgpu::Texture,
    view: wgpu::TextureView,
    msaa: Option<wgpu::TextureView>,
    depth: wgpu::TextureView,
    readback: wgpu::Buffer,
    padded_row: u32,
    /// The running sum of a progressive renderer (environment scenes).
    acc: Option<crate::accum::Accumulator>,
    /// The length of the sum when it is known in advance
    /// ([`Offscreen::render_frames_linear`]): its frames then take the points of one lattice
    /// ([`lattice_jitter`]) instead of the open-ended sequence.
    planned: Option<u32>,
}

/// Colour format of offscreen frames (linear values; MSAA-resolvable everywhere).
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

impl Offscreen {
    /// A target for `r`'s pipeline (its sample count).
    pub fn new(gpu: &Gpu, r: &Renderer, width: u32, height: u32) -> Result<Offscreen> {
        let lim = gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > lim || height > lim {
            return Err(Error::usage(format!(
                "size {width}x{height}: each side must be 1..{lim} on this GPU"
            )));
        }
        let tex = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("frame"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: OFFSCREEN_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = tex.create_view(&Default::default());
        let ms = r.msaa();
        let msaa = (ms > 1)
            .then(|| colour_view(gpu, width, height, OFFSCREEN_FORMAT, ms, r.progressive()));
        let acc = if r.progressive() {
            Some(crate::accum::Accumulator::new(
                gpu,
                &view,
                msaa.as_ref(),
                width,
                height,
                true,
            )?)
        } else {
            None
        };
        let padded_row = (width * 8).div_ceil(256) * 256;
        let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: padded_row as u64 * height as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Offscreen {
            width,
            height,
            tex,
            view,
            msaa,
            depth: depth_view_ms(gpu, width, height, ms),
            readback,
            padded_row,
            acc,
            planned: None,
        })
    }

    /// Render `n` frames (at least one) and read back the last in linear
    /// light: for a progressive renderer the mean of the `n` frames, whose
    /// length is known here, so they take the offsets of an `n`-point
    /// lattice over the pixel ([`lattice_jitter`]) and their mean is a
    /// midpoint rule of the pixel's area (frames drawn later, past `n`,
    /// fall back to [`subpixel_jitter`]). What a headless run renders.
    pub fn render_frames_linear(
        &mut self,
        gpu: &Gpu,
        r: &Renderer,
        state: &FrameState,
        n: u32,
    ) -> Result<LinearImage> {
        Ok(self.render_frames_with_coverage(gpu, r, state, n)?.0)
    }

    /// [`Offscreen::render_frames_linear`] with each pixel's coverage by the
    /// meshes (0..1, the mean over its MSAA samples and frames).
    pub fn render_frames_with_coverage(
        &mut self,
        gpu: &Gpu,
        r: &Renderer,
        state: &FrameState,
        n: u32,
    ) -> Result<(LinearImage, Vec<f32>)> {
        let n = n.max(1);
        self.planned = Some(n);
        for _ in 1..n {
            self.draw(gpu, r, state)?;
        }
        self.render_linear_with_coverage(gpu, r, state)
    }

    /// Frames in the progressive sum (0 for a renderer that does not accumulate).
    pub fn frames(&self) -> u32 {
        self.acc.as_ref().map_or(0, |a| a.count())
    }

    /// Start the progressive sum again (camera, light or exposure changed).
    pub fn reset(&self) {
        if let Some(a) = &self.acc {
            a.reset();
        }
    }

    fn record(&self, enc: &mut wgpu::CommandEncoder, r: &Renderer, state: &FrameState) {
        match &self.msaa {
            Some(ms) => r.encode(enc, ms, Some(&self.view), &self.depth, state),
            None => r.encode(enc, &self.view, None, &self.depth, state),
        }
    }

    /// The progressive sum (environment scenes), for the window's resolve pass.
    pub fn accumulator(&self) -> Option<&crate::accum::Accumulator> {
        self.acc.as_ref()
    }

    /// Record one frame (and, for a progressive renderer, adding it to the sum:
    /// the frame index is set from the count). The caller submits.
    pub fn encode_frame(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        r: &Renderer,
        state: &FrameState,
    ) {
        match &self.acc {
            Some(a) => {
                let k = a.count();
                // (the share of the pixel each frame stands for: the
                // footprint of the environment's sharp lights is scaled by it)
                let (point, share) = match self.planned {
                    Some(n) if k < n => (lattice_jitter(k, n), 1.0 / (n as f32).sqrt()),
                    _ if k == 0 => (subpixel_jitter(k), 1.0),
                    _ => (subpixel_jitter(k), 0.0),
                };
                let (jitter, sample) = frame_sample(point, share, self.msaa.is_some(), k);
                r.update_jittered(gpu, state, self.width, self.height, jitter);
                r.set_frame(gpu, a.count(), share, sample);
                self.record(enc, r, state);
                a.add(gpu, enc, sample);
            }
            None => {
                r.update(gpu, state, self.width, self.height);
                self.record(enc, r, state);
            }
        }
    }

    /// Render one frame and wait for it (no readback); a progressive renderer
    /// adds it to the running sum.
    pub fn draw(&self, gpu: &Gpu, r: &Renderer, state: &FrameState) -> Result<()> {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.encode_frame(gpu, &mut enc, r, state);
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        gpu.take_errors()
    }

    /// Render one frame and read it back as display values.
    pub fn render(&self, gpu: &Gpu, r: &Renderer, state: &FrameState) -> Result<Image> {
        Ok(self.render_linear(gpu, r, state)?.display(r.curve()))
    }

    /// Render one frame and read it back in linear light (exposure applied); a
    /// progressive renderer adds it to the running sum and returns the mean of
    /// the frames since the last reset (the settled frame).
    pub fn render_linear(
        &self,
        gpu: &Gpu,
        r: &Renderer,
        state: &FrameState,
    ) -> Result<LinearImage> {
        Ok(self.render_linear_with_coverage(gpu, r, state)?.0)
    }

    fn render_linear_with_coverage(
        &self,
        gpu: &Gpu,
        r: &Renderer,
        state: &FrameState,
    ) -> Result<(LinearImage, Vec<f32>)> {
        if let Some(a) = &self.acc {
            self.draw(gpu, r, state)?;
            return a.read_with_coverage(gpu);
        }
        r.update(gpu, state, self.width, self.height);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.record(&mut enc, r, state);
        enc.copy_texture_to_buffer(
            self.tex.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: None,
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: 1,
            },
        );
        gpu.queue.submit([enc.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        self.readback
            .map_async(wgpu::MapMode::Read, .., move |res| {
                let _ = tx.send(res);
            });
        gpu.wait()?;
        rx.recv()
            .map_err(|e| Error::internal(format!("readback: {e}")))?
            .map_err(|e| Error::internal(format!("readback: {e}")))?;
        gpu.take_errors()?;
        let mut img = LinearImage::new(self.width, self.height);
        let mut coverage = vec![0.0; img.rgb.len()];
        {
            let data = self
                .readback
                .get_mapped_range(..)
                .map_err(|e| Error::internal(format!("readback: {e}")))?;
            let px: &[u16] = bytemuck::cast_slice(&data);
            let stride = (self.padded_row / 2) as usize;
            let f = |b: u16| half::f16::from_bits(b).to_f32();
            for y in 0..self.height as usize {
                for x in 0..self.width as usize {
                    let i = y * stride + x * 4;
                    img.rgb[y * self.width as usize + x] = [f(px[i]), f(px[i + 1]), f(px[i + 2])];
                    coverage[y * self.width as usize + x] = f(px[i + 3]);
                }
            }
        }
        self.readback.unmap();
        Ok((img, coverage))
    }
}

/// Where frame `k` of a progressive sum, whose pixels stand for sub-pixel
/// `point` and `share` of the pixel along each axis (1: a frame alone), is
/// read: its jitter and its MSAA sample (4: the resolved pixel). Under MSAA
/// a frame of a running mean (`share` below 1) is read at one sample,
/// (k mod 4), and jittered so that this sample sees what the pixel centre
/// sees without MSAA at jitter `point`: the mean
/// of the frames is then the pixel's box, as without MSAA. Read resolved,
/// each frame's four samples sit 0.125-0.375 pixels off its point, which
/// widens the kernel of the sum to the box convolved with the samples'
/// pattern (1.75 pixels across): 16 frames of the baked snake at 96 x 48
/// under the sky with `--msaa 4` read interior pixels by the silhouette up
/// to 50 % too bright, where one sample of four reached the sky behind
/// (interior p99 6.7 against 3.5 without MSAA; docs/PLAY.md "Environment").
/// The cells' pre-passes draw their points at the same sample (the
/// renderer moves their viewport by its offset), so the frame's pass reads
/// the cells at the point it shades. A frame alone keeps the resolve: its
/// samples are its anti-aliasing.
pub fn frame_sample(point: [f64; 2], share: f32, msaa: bool, k: u32) -> ([f64; 2], u32) {
    if !msaa || share >= 1.0 {
        return (point, 4);
    }
    let j = k % 4;
    let p = MSAA_POSITIONS[j as usize];
    // the image moves by the jitter: the sample at offset p from a pixel's
    // centre sees what lay at p - jitter, and without MSAA the centre sees
    // what lay at -point
    ([p[0] + point[0], p[1] + point[1]], j)
}

/// The standard 4x MSAA sample positions (pixels from the centre, x right,
/// y down; Vulkan, D3D and Metal alike), as shaders/diffraction.wgsl
/// `msaa_position`.
pub const MSAA_POSITIONS: [[f64; 2]; 4] = [
    [-0.125, -0.375],
    [0.375, -0.125],
    [-0.375, 0.125],
    [0.125, 0.375],
];

/// The sub-pixel offset (pixels, each in [-0.5, 0.5]) of frame `k` of a
/// progressive sum of open length (the window's; a sum whose length is
/// known takes [`lattice_jitter`]). Frames 0 and 1 sit at the pixel centre (frame 0 is the
/// one shown while the view moves, and the whole of a first-frame
/// estimate); then antithetic pairs: frames 2m and 2m + 1 at h_m and -h_m,
/// h_m the Halton (2, 3) point m shifted by half a pixel (modulo the
/// pixel). Every even count of frames thus has its offsets' mean at the
/// centre, and the pairs cover the pixel evenly (stratified, unlike
/// independent random offsets). Why the mean matters: the environment's
/// frame is sharp at the scale of a pixel (the sun's orders on a 5 um pack
/// at 40 x 40 change by half their value over half a pixel) but nearly
/// linear across it, so the centre is close to the pixel's mean while a
/// running mean whose offsets lean to one side is the image shifted by
/// their mean: with the plain Halton sequence (mean -1/32 px at 16 frames)
/// 16 accumulated first-frame estimates were CIEDE2000 p99 2.70 from a 4 x 4
/// supersampled frame, with these offsets 0.78 (docs/LIGHTING.md
/// "Accumulated frames").
pub fn subpixel_jitter(k: u32) -> [f64; 2] {
    fn radical_inverse(mut i: u32, base: u32) -> f64 {
        let (mut f, mut r) = (1.0, 0.0);
        while i > 0 {
            f /= base as f64;
            r += f * (i % base) as f64;
            i /= base;
        }
        r
    }
    if k < 2 {
        return [0.0, 0.0];
    }
    let m = k / 2;
    let centred = |x: f64| if x < 0.5 { x } else { x - 1.0 };
    let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
    [
        sign * centred(radical_inverse(m, 2)),
        sign * centred(radical_inverse(m, 3)),
    ]
}

/// The sub-pixel offset (pixels, each in (-0.5, 0.5)) of frame `k` of a
/// progressive sum of `n` frames known in advance: the points of one
/// lattice, so the mean of the `n` frames is a quadrature of the pixel's
/// area of the midpoint kind. For `n = m * m` the `m x m` grid of sub-cell
/// centres (frame `k` at column `k % m`, row `k / m`): the mean is exactly
/// what `m x m` supersampling gives, the product midpoint rule, whose
/// error falls as 1 / n for an image smooth across the pixel. Other `n`
/// take the centred rank-1 lattice with the golden-ratio generator (a
/// Fibonacci lattice: ((k + 1/2) / n, (k g mod n + 1/2) / n), g near
/// n (sqrt 5 - 1) / 2 and prime to n), whose points cover the pixel as
/// evenly and each sit in their own row and column. Both have their
/// offsets' mean at the centre. Why not the open-ended sequence
/// ([`subpixel_jitter`]) when `n` is known: its antithetic pairs cancel the
/// first-order error but not the second, so a few pairs half a pixel apart
/// stray far from the pixel's mean where the frame is sharp (the sky-lit
/// sphere's sun orders: 4 frames at 4x MSAA p99 12.4 from the reference
/// against 1.10 for the first frame alone, docs/LIGHTING.md "Accumulated
/// frames").
pub fn lattice_jitter(k: u32, n: u32) -> [f64; 2] {
    if n <= 1 {
        return [0.0, 0.0];
    }
    let k = k % n;
    let m = n.isqrt();
    if m * m == n {
        let at = |i: u32| (i as f64 + 0.5) / m as f64 - 0.5;
        return [at(k % m), at(k / m)];
    }
    let g = fibonacci_generator(n);
    let at = |i: u64| (i as f64 + 0.5) / n as f64 - 0.5;
    [at(k as u64), at(k as u64 * g as u64 % n as u64)]
}

/// The generator of [`lattice_jitter`]'s rank-1 lattice of `n` points: the
/// integer nearest n (sqrt 5 - 1) / 2 that is prime to `n` (so every row
/// holds one point), searched outwards.
fn fibonacci_generator(n: u32) -> u32 {
    // Written out: the standard library has no gcd, and six lines do not
    // justify a dependency (num-integer) for this crate.
    fn gcd(a: u32, b: u32) -> u32 {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
    let g0 = (n as f64 * (5f64.sqrt() - 1.0) / 2.0).round() as i64;
    (0..n as i64)
        .flat_map(|d| [g0 - d, g0 + d])
        .find(|&g| g >= 1 && g < n as i64 && gcd(g as u32, n) == 1)
        .unwrap_or(1) as u32
}

#[cfg(test)]
mod jitter_tests {
    use super::{lattice_jitter, subpixel_jitter};

    /// A planned sum's offsets: inside the pixel, mean at the centre, one
    /// point per row and per column of an n x n split (a rank-1 lattice, or
    /// the m x m grid for a square n whose points are the sub-cell
    /// centres), and a square n gives exactly the supersampling positions.
    #[test]
    fn lattice_offsets_are_a_midpoint_rule() {
        for n in [2u32, 3, 5, 8, 10, 12, 16, 17, 64, 100, 255, 256, 1000, 4096] {
            let pts: Vec<[f64; 2]> = (0..n).map(|k| lattice_jitter(k, n)).collect();
            let mean = pts.iter().fold([0.0; 2], |a, p| [a[0] + p[0], a[1] + p[1]]);
            assert!(
                mean.iter().all(|v| (v / n as f64).abs() < 1e-12),
                "{n}: {mean:?}"
            );
            assert!(pts.iter().all(|p| p.iter().all(|v| v.abs() < 0.5)), "{n}");
            let m = n.isqrt();
            if m * m == n {
                let mut want: Vec<[i64; 2]> = (0..m)
                    .flat_map(|j| (0..m).map(move |i| [i as i64, j as i64]))
                    .collect();
                let mut got: Vec<[i64; 2]> = pts
                    .iter()
                    .map(|p| p.map(|v| ((v + 0.5) * m as f64 - 0.5).round() as i64))
                    .collect();
                want.sort();
                got.sort();
                assert_eq!(got, want, "{n}");
                let off_centre = |v: f64| {
                    let x = (v + 0.5) * m as f64 - 0.5;
                    (x - x.round()).abs()
                };
                assert!(pts.iter().all(|p| p.iter().all(|&v| off_centre(v) < 1e-9)));
            } else {
                for axis in 0..2 {
                    let mut rows: Vec<i64> = pts
                        .iter()
                        .map(|p| ((p[axis] + 0.5) * n as f64 - 0.5).round() as i64)
                        .collect();
                    rows.sort();
                    assert_eq!(rows, (0..n as i64).collect::<Vec<_>>(), "{n} axis {axis}");
                }
                // Evenly spread: no two points closer than half the grid step
                // of an equal-area square lattice (a bad generator, g = 1,
                // puts them all on the diagonal, 1 / n apart).
                let d = pts
                    .iter()
                    .enumerate()
                    .flat_map(|(i, a)| {
                        pts[i + 1..]
                            .iter()
                            .map(move |b| (a[0] - b[0]).hypot(a[1] - b[1]))
                    })
                    .fold(f64::INFINITY, f64::min);
                assert!(d > 0.5 / (n as f64).sqrt(), "{n}: closest pair {d}");
            }
        }
        assert_eq!(lattice_jitter(0, 1), [0.0, 0.0]);
    }

    /// The first frame is the pixel centre, the offsets stay inside the
    /// pixel and cover it evenly: over 64 frames, each of the 4 x 4 sub-cells
    /// gets 2 to 6 (4 on average); every even count has its mean at the
    /// centre.
    #[test]
    fn jitter_covers_the_pixel_evenly() {
        assert_eq!(
            subpixel_jitter(0),
            [0.0, 0.0],
            "the first frame at the centre"
        );
        let mut cells = [0u32; 16];
        let mut mean = [0.0; 2];
        for k in 0..64 {
            let j = subpixel_jitter(k);
            assert!(j.iter().all(|v| (-0.5..=0.5).contains(v)), "{j:?}");
            let c = |v: f64| (((v + 0.5) * 4.0) as usize).min(3);
            cells[c(j[0]) + 4 * c(j[1])] += 1;
            mean = [mean[0] + j[0], mean[1] + j[1]];
            if !k.is_multiple_of(2) {
                assert!(
                    mean[0].abs() < 1e-12 && mean[1].abs() < 1e-12,
                    "{k}: {mean:?}"
                );
            }
        }
        assert!(cells.iter().all(|n| (2..=6).contains(n)), "{cells:?}");
    }
}
