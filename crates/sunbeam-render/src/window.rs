//! The interactive window (winit 0.30): orbit camera, movable light, exposure,
//! frame time in the title. Controls (docs/PLAY.md):
//!
//! - left drag: orbit the camera around its target; wheel: zoom
//! - right drag (or shift + left drag): move the light (azimuth, elevation)
//! - `+` / `-`: exposure up / down by 1/4 stop; `r`: reset; `Esc` or `q`: quit
//!
//! `--frames N` renders N frames as fast as possible, prints `window frames: ...`,
//! optionally writes the last swapchain image (`--screenshot`), keeps the window up
//! for `--hold-secs`, then exits (the Xvfb test uses this).

use crate::accum::Resolve;
use crate::gpu::{Backend, Gpu, INSTALL_HINT};
use crate::renderer::{
    colour_view, depth_view_ms, FrameState, Mode, Offscreen, Renderer, Settings, OFFSCREEN_FORMAT,
};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};
use sunbeam_common::{Error, Result};
use sunbeam_frame::{Image, Prepared};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// Window options.
#[derive(Debug, Clone)]
pub struct WindowOptions {
    pub backend: Backend,
    pub settings: Settings,
    /// Initial inner size.
    pub size: [u32; 2],
    /// Exit after this many frames (plus `hold`); None: run until closed.
    pub frames: Option<u32>,
    pub hold: Duration,
    /// Write the swapchain image of the last counted frame here (PNG).
    pub screenshot: Option<PathBuf>,
    pub title: String,
}

struct Orbit {
    yaw: f64,
    pitch: f64,
    dist: f64,
    target: [f64; 3],
}

impl Orbit {
    fn from_camera(c: &sunbeam_scene::Camera) -> Orbit {
        let d = [
            c.eye[0] - c.target[0],
            c.eye[1] - c.target[1],
            c.eye[2] - c.target[2],
        ];
        let dist = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-9);
        Orbit {
            yaw: d[0].atan2(d[2]),
            pitch: (d[1] / dist).clamp(-1.0, 1.0).asin(),
            dist,
            target: c.target,
        }
    }
    fn eye(&self) -> [f64; 3] {
        let (cp, sp) = (self.pitch.cos(), self.pitch.sin());
        [
            self.target[0] + self.dist * cp * self.yaw.sin(),
            self.target[1] + self.dist * sp,
            self.target[2] + self.dist * cp * self.yaw.cos(),
        ]
    }
}

struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    gpu: Gpu,
    config: wgpu::SurfaceConfiguration,
    renderer: Renderer,
    depth: wgpu::TextureView,
    /// The multisampled colour target (MSAA), resolved into the surface.
    msaa: Option<wgpu::TextureView>,
    can_copy: bool,
    /// Environment scenes: the float frame target with its running sum, and the
    /// pass that resolves the mean onto the surface (crate::accum).
    progressive: Option<(Offscreen, Resolve)>,
    /// What the running sum was drawn with (a change resets it).
    drawn: Option<(FrameState, u32, u32)>,
}

struct App {
    opts: WindowOptions,
    prepared: Prepared,
    initial: FrameState,
    state: FrameState,
    orbit: Orbit,
    gfx: Option<Gfx>,
    error: Option<Error>,
    frame: u32,
    times: Vec<f64>,
    last_title: Instant,
    done_at: Option<Instant>,
    cursor: Option<(f64, f64)>,
    left: bool,
    right: bool,
    shift: bool,
}

fn light_angles(d: [f64; 3]) -> (f64, f64) {
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-12);
    (d[0].atan2(d[2]), (d[1] / len).clamp(-1.0, 1.0).asin())
}

impl App {
    fn fail(&mut self, el: &ActiveEventLoop, e: Error) {
        self.error.get_or_insert(e);
        el.exit();
    }

    fn init(&mut self, el: &ActiveEventLoop) -> Result<()> {
        let window = Arc::new(
            el.create_window(
                Window::default_attributes()
                    .with_title(self.opts.title.clone())
                    .with_inner_size(winit::dpi::PhysicalSize::new(
                        self.opts.size[0],
                        self.opts.size[1],
                    )),
            )
            .map_err(|e| Error::internal(format!("cannot create a window: {e}")))?,
        );
        let mut desc = wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
            el.owned_display_handle(),
        ));
        desc.backends = self.opts.backend.backends();
        let instance = wgpu::Instance::new(desc);
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| Error::internal(format!("cannot create a surface: {e}")))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| Error::input(format!("{INSTALL_HINT} ({e})")))?;
        let gpu = Gpu::from_adapter(instance, adapter)?;
        let size = window.inner_size();
        let caps = surface.get_capabilities(&gpu.adapter);
        let mut config = surface
            .get_default_config(&gpu.adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| Error::internal("the window surface is not supported by the adapter"))?;
        // Prefer a UNORM format: the shader writes display values itself.
        if let Some(f) = caps.formats.iter().find(|f| {
            !f.is_srgb()
                && matches!(
                    f,
                    wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
                )
        }) {
            config.format = *f;
        }
        config.present_mode = wgpu::PresentMode::Fifo;
        let can_copy = caps.usages.contains(wgpu::TextureUsages::COPY_SRC);
        if can_copy && self.opts.screenshot.is_some() {
            config.usage |= wgpu::TextureUsages::COPY_SRC;
        }
        surface.configure(&gpu.device, &config);
        // Environment scenes draw Monte Carlo frames into a float target and
        // accumulate them; the surface gets the resolved mean.
        let progressive =
            self.prepared.environment.is_some() && self.opts.settings.mode == Mode::Default;
        let format = if progressive {
            OFFSCREEN_FORMAT
        } else {
            config.format
        };
        let renderer = Renderer::new(&gpu, &self.prepared, &self.opts.settings, format)?;
        for w in &renderer.warnings {
            eprintln!("sunbeam-play: warning: {w}");
        }
        for n in &renderer.notes {
            eprintln!("sunbeam-play: {n}");
        }
        let progressive = if renderer.progressive() {
            Some((
                Offscreen::new(&gpu, &renderer, config.width, config.height)?,
                Resolve::new(&gpu, config.format)?,
            ))
        } else {
            None
        };
        eprintln!(
            "sunbeam-play: {} | surface {:?} {}x{}",
            gpu.describe(),
            config.format,
            config.width,
            config.height
        );
        let ms = renderer.msaa();
        let depth = depth_view_ms(&gpu, config.width, config.height, ms);
        let msaa = (ms > 1)
            .then(|| colour_view(&gpu, config.width, config.height, config.format, ms, false));
        window.request_redraw();
        self.gfx = Some(Gfx {
            window,
            surface,
            gpu,
            config,
            renderer,
            depth,
            msaa,
            can_copy,
            progressive,
            drawn: None,
        });
        Ok(())
    }

    fn redraw(&mut self, el: &ActiveEventLoop) -> Result<()> {
        let Some(g) = self.gfx.as_mut() else {
            return Ok(());
        };
        let t = Instant::now();
        let frame = match g.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            _ => {
                g.surface.configure(&g.gpu.device, &g.config);
                g.window.request_redraw();
                return Ok(());
            }
        };
        let view = frame.texture.create_view(&Default::default());
        self.state.camera.eye = self.orbit.eye();
        let mut enc = g.gpu.device.create_command_encoder(&Default::default());
        if let Some((off, resolve)) = &g.progressive {
            // Any change of camera, light, exposure or size starts the sum again.
            let now = (self.state.clone(), g.config.width, g.config.height);
            if g.drawn.as_ref() != Some(&now) {
                off.reset();
                g.drawn = Some(now);
            }
            off.encode_frame(&g.gpu, &mut enc, &g.renderer, &self.state);
            if let Some(acc) = off.accumulator() {
                resolve.encode(
                    &g.gpu,
                    &mut enc,
                    acc,
                    &view,
                    g.config.format,
                    g.renderer.curve(),
                );
            }
        } else {
            g.renderer
                .update(&g.gpu, &self.state, g.config.width, g.config.height);
            match &g.msaa {
                Some(ms) => g
                    .renderer
                    .encode(&mut enc, ms, Some(&view), &g.depth, &self.state),
                None => g
                    .renderer
                    .encode(&mut enc, &view, None, &g.depth, &self.state),
            }
        }
        let counted = self.opts.frames.is_some_and(|n| self.frame + 1 == n);
        let shot = if counted && g.can_copy {
            self.opts.screenshot.as_ref()
        } else {
            None
        };
        let readback = shot.map(|_| {
            let (w, h) = (g.config.width, g.config.height);
            let row = (w * 4).div_ceil(256) * 256;
            let buf = g.gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("screenshot"),
                size: row as u64 * h as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            enc.copy_texture_to_buffer(
                frame.texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &buf,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row),
                        rows_per_image: None,
                    },
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
            (buf, row, w, h)
        });
        g.gpu.queue.submit([enc.finish()]);
        g.window.pre_present_notify();
        g.gpu.queue.present(frame);
        g.gpu.wait()?;
        g.gpu.take_errors()?;
        if let (Some((buf, row, w, h)), Some(path)) = (readback, shot) {
            buf.map_async(wgpu::MapMode::Read, .., |_| {});
            g.gpu.wait()?;
            let data = buf
                .get_mapped_range(..)
                .map_err(|e| Error::internal(format!("screenshot: {e}")))?;
            let bgra = matches!(
                g.config.format,
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
            );
            let mut rgba = Vec::with_capacity((w * h * 4) as usize);
            for y in 0..h {
                let r = &data[(y * row) as usize..(y * row + w * 4) as usize];
                for p in r.chunks_exact(4) {
                    if bgra {
                        rgba.extend_from_slice(&[p[2], p[1], p[0], 255]);
                    } else {
                        rgba.extend_from_slice(&[p[0], p[1], p[2], 255]);
                    }
                }
            }
            Image::from_rgba8(w, h, &rgba).write_png(path)?;
            println!("screenshot {}", path.display());
        } else if counted && self.opts.screenshot.is_some() {
            eprintln!("sunbeam-play: warning: this surface cannot be copied (no COPY_SRC); no screenshot written");
        }
        self.times.push(t.elapsed().as_secs_f64() * 1e3);
        self.frame += 1;
        if self.last_title.elapsed() > Duration::from_millis(500) || self.frame == 1 {
            let ms = self.times.last().copied().unwrap_or(0.0);
            let acc = match &g.progressive {
                Some((off, _)) => format!(" - {} frames accumulated", off.frames()),
                None => String::new(),
            };
            g.window.set_title(&format!(
                "{} - {:.1} ms/frame ({:.0} fps) - EV {:+.2}{acc}",
                self.opts.title,
                ms,
                1e3 / ms.max(1e-3),
                self.state.exposure
            ));
            self.last_title = Instant::now();
        }
        if counted {
            let rest = &self.times[1.min(self.times.len())..];
            let mean = rest.iter().sum::<f64>() / rest.len().max(1) as f64;
            println!(
                "window frames: n={} first={:.1} ms mean(rest)={:.2} ms",
                self.frame, self.times[0], mean
            );
            self.done_at = Some(Instant::now());
        }
        match self.done_at {
            None => g.window.request_redraw(),
            Some(d) if d.elapsed() >= self.opts.hold => el.exit(),
            Some(_) => el.set_control_flow(ControlFlow::WaitUntil(
                Instant::now() + Duration::from_millis(100),
            )),
        }
        Ok(())
    }

    fn request_redraw(&self) {
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.gfx.is_none() {
            if let Err(e) = self.init(el) {
                self.fail(el, e);
            }
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => el.exit(),
            WindowEvent::Resized(sz) if sz.width > 0 && sz.height > 0 => {
                if let Some(g) = self.gfx.as_mut() {
                    g.config.width = sz.width;
                    g.config.height = sz.height;
                    g.surface.configure(&g.gpu.device, &g.config);
                    let ms = g.renderer.msaa();
                    g.depth = depth_view_ms(&g.gpu, sz.width, sz.height, ms);
                    g.msaa = (ms > 1).then(|| {
                        colour_view(&g.gpu, sz.width, sz.height, g.config.format, ms, false)
                    });
                    if let Some((off, _)) = &mut g.progressive {
                        match Offscreen::new(&g.gpu, &g.renderer, sz.width, sz.height) {
                            Ok(o) => *off = o,
                            Err(e) => {
                                self.fail(el, e);
                                return;
                            }
                        }
                        g.drawn = None;
                    }
                    g.window.request_redraw();
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(el) {
                    self.fail(el, e);
                }
            }
            WindowEvent::ModifiersChanged(m) => self.shift = m.state().shift_key(),
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed;
                match button {
                    MouseButton::Left => self.left = down,
                    MouseButton::Right => self.right = down,
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let (x, y) = (position.x, position.y);
                if let Some((px, py)) = self.cursor {
                    let (dx, dy) = ((x - px) * 0.01, (y - py) * 0.01);
                    if self.right || (self.left && self.shift) {
                        for l in &mut self.state.lights {
                            let (az, el_) = light_angles(l.direction);
                            let (az, el_) = (az + dx, (el_ - dy).clamp(-1.5, 1.5));
                            l.direction = [el_.cos() * az.sin(), el_.sin(), el_.cos() * az.cos()];
                        }
                        self.request_redraw();
                    } else if self.left {
                        self.orbit.yaw -= dx;
                        self.orbit.pitch = (self.orbit.pitch + dy).clamp(-1.5, 1.5);
                        self.request_redraw();
                    }
                }
                self.cursor = Some((x, y));
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let s = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.orbit.dist *= (-0.1 * s).exp();
                self.request_redraw();
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                match event.logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) | Key::Character("q") => el.exit(),
                    Key::Character("+") | Key::Character("=") => self.state.exposure += 0.25,
                    Key::Character("-") => self.state.exposure -= 0.25,
                    Key::Character("r") => {
                        self.state = self.initial.clone();
                        self.orbit = Orbit::from_camera(&self.initial.camera);
                    }
                    _ => {}
                }
                self.request_redraw();
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _el: &ActiveEventLoop) {
        if self.done_at.is_some() {
            self.request_redraw();
        }
    }
}

/// Open the window and run until it is closed (or `frames` + `hold` have passed).
pub fn run(prepared: Prepared, opts: WindowOptions) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| {
        Error::input(format!(
            "cannot open a window ({e}); is DISPLAY (X11) or WAYLAND_DISPLAY set? Use --headless for offscreen frames"
        ))
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let initial = FrameState::from_scene(&prepared);
    let mut app = App {
        orbit: Orbit::from_camera(&initial.camera),
        state: initial.clone(),
        initial,
        prepared,
        opts,
        gfx: None,
        error: None,
        frame: 0,
        times: Vec::new(),
        last_title: Instant::now(),
        done_at: None,
        cursor: None,
        left: false,
        right: false,
        shift: false,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| Error::internal(format!("event loop: {e}")))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
