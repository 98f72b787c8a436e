//! The wgpu renderer behind `sunbeam-play` (docs/PLAY.md): diffraction shading
//! from term packs (shaders/diffraction.wgsl), headless frames that match the
//! CPU reference (`sunbeam-raster`), and a winit window with an orbit camera.
//!
//! ```no_run
//! use sunbeam_render::{gpu::{Backend, Gpu}, renderer::{Settings, Renderer, Offscreen, FrameState, OFFSCREEN_FORMAT}};
//! let scene = sunbeam_scene::Scene::load(std::path::Path::new("scene.json")).unwrap();
//! let prepared = sunbeam_frame::prepare(&scene).unwrap();
//! let gpu = Gpu::headless(Backend::Auto).unwrap();
//! let r = Renderer::new(&gpu, &prepared, &Settings::default(), OFFSCREEN_FORMAT).unwrap();
//! let target = Offscreen::new(&gpu, &r, 256, 256).unwrap();
//! let image = target.render(&gpu, &r, &FrameState::from_scene(&prepared)).unwrap();
//! # let _ = image;
//! ```

pub mod accum;
pub mod env;
pub mod env_export;
pub mod export;
pub mod gpu;
pub mod refine;
pub mod renderer;
pub mod response;
#[cfg(feature = "baselines")]
pub mod table;
pub mod window;

pub use gpu::{Backend, Gpu};
pub use renderer::{FrameState, Mode, Offscreen, Renderer, Settings, OFFSCREEN_FORMAT};

use std::time::Instant;
use sunbeam_common::Result;
use sunbeam_frame::{Image, Prepared};

/// Render one frame of a prepared scene offscreen (`size` or the scene's size).
pub fn render_headless(
    gpu: &Gpu,
    p: &Prepared,
    settings: &Settings,
    size: Option<[u32; 2]>,
    frames: u32,
) -> Result<Image> {
    let [w, h] = size.unwrap_or(p.scene.size);
    let r = Renderer::new(gpu, p, settings, OFFSCREEN_FORMAT)?;
    let mut target = Offscreen::new(gpu, &r, w, h)?;
    let state = FrameState::from_scene(p);
    Ok(target
        .render_frames_linear(gpu, &r, &state, frames)?
        .display(r.curve()))
}

/// Render one frame offscreen in linear light, `supersample` x the size in each
/// direction and box-filtered back (1: no supersampling; MSAA as in `settings`).
pub fn render_headless_linear(
    gpu: &Gpu,
    p: &Prepared,
    settings: &Settings,
    size: Option<[u32; 2]>,
    frames: u32,
    supersample: u32,
) -> Result<sunbeam_frame::LinearImage> {
    let [w, h] = size.unwrap_or(p.scene.size);
    let k = supersample.max(1);
    let r = Renderer::new(gpu, p, settings, OFFSCREEN_FORMAT)?;
    let mut target = Offscreen::new(gpu, &r, w * k, h * k)?;
    let state = FrameState::from_scene(p);
    Ok(target
        .render_frames_linear(gpu, &r, &state, frames)?
        .downsample(k))
}

/// Frame times of a headless run, milliseconds (each frame waited for).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameTimes {
    /// Pipeline and buffer creation (shader compile included).
    pub setup_ms: f64,
    /// First frame (driver-side shader compilation on some drivers).
    pub first_ms: f64,
    /// Frames after the first.
    pub rest_ms: Vec<f64>,
}

impl FrameTimes {
    pub fn median_ms(&self) -> f64 {
        let mut v = self.rest_ms.clone();
        if v.is_empty() {
            return self.first_ms;
        }
        v.sort_by(|a, b| a.total_cmp(b));
        let n = v.len();
        if n % 2 == 1 {
            v[n / 2]
        } else {
            (v[n / 2 - 1] + v[n / 2]) / 2.0
        }
    }
    pub fn mean_ms(&self) -> f64 {
        if self.rest_ms.is_empty() {
            return self.first_ms;
        }
        self.rest_ms.iter().sum::<f64>() / self.rest_ms.len() as f64
    }
}

/// Time `frames` offscreen frames (the first is reported apart) and return the
/// last image in linear light (environment scenes: one frame of samples, the
/// sum reset before each frame, as while the camera moves).
pub fn bench_headless(
    gpu: &Gpu,
    p: &Prepared,
    settings: &Settings,
    size: [u32; 2],
    frames: u32,
) -> Result<(FrameTimes, sunbeam_frame::LinearImage)> {
    let t0 = Instant::now();
    let r = Renderer::new(gpu, p, settings, OFFSCREEN_FORMAT)?;
    let target = Offscreen::new(gpu, &r, size[0], size[1])?;
    let state = FrameState::from_scene(p);
    gpu.wait()?;
    let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut times = Vec::new();
    for n in &r.notes {
        log::info!("{n}");
    }
    for _ in 0..frames.max(1) {
        let t = Instant::now();
        // Progressive (environment) frames as while moving: every frame starts
        // the sum again, so each one costs what an interactive frame does.
        target.reset();
        target.draw(gpu, &r, &state)?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let img = target.render_linear(gpu, &r, &state)?;
    let first_ms = times[0];
    Ok((
        FrameTimes {
            setup_ms,
            first_ms,
            rest_ms: times[1..].to_vec(),
        },
        img,
    ))
}
