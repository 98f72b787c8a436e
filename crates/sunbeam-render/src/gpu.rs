//! Instance, adapter and device: the GPU boundary. No adapter gives a message
//! that says what to install.

use std::sync::{Arc, Mutex};
use sunbeam_common::{Error, Result};

/// Which wgpu backend to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Backend {
    /// `WGPU_BACKEND` if set, else every backend wgpu knows.
    #[default]
    Auto,
    Vulkan,
    Gl,
}

impl std::str::FromStr for Backend {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(Backend::Auto),
            "vulkan" | "vk" => Ok(Backend::Vulkan),
            "gl" | "gles" | "opengl" => Ok(Backend::Gl),
            _ => Err(Error::usage(format!(
                "unknown backend '{s}' (vulkan, gl, auto)"
            ))),
        }
    }
}

impl Backend {
    pub fn backends(self) -> wgpu::Backends {
        match self {
            Backend::Auto => wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all()),
            Backend::Vulkan => wgpu::Backends::VULKAN,
            Backend::Gl => wgpu::Backends::GL,
        }
    }
}

/// What to install when no adapter is found.
pub const INSTALL_HINT: &str = "no GPU adapter found. On a machine without a GPU install Mesa's software drivers: \
     `apt-get install mesa-vulkan-drivers libvulkan1` (Vulkan, lavapipe) or `libegl1 libegl-mesa0 libgl1-mesa-dri` \
     (GL, llvmpipe; run with --backend gl)";

/// Keep a successful run free of `error:` lines from the system's display
/// probe. Mesa's Vulkan device-select layer (an implicit layer of every Mesa
/// install) looks for a Wayland compositor when wgpu enables the Wayland
/// surface extension, and libwayland prints `error: XDG_RUNTIME_DIR is invalid
/// or not set in the environment.` when that variable is missing (twice per
/// run, headless included). The layer only moves the desktop's GPU to the
/// front of the adapter list; wgpu chooses by power preference and surface
/// instead. So where the probe can only fail (no usable `XDG_RUNTIME_DIR`),
/// turn the layer off with Mesa's switch `NODEVICE_SELECT=1`, unless the user
/// set it. The environment is process-wide: call this before other threads
/// start (a tool's first step after parsing its arguments).
pub fn quiet_display_probe() {
    let runtime_dir = std::env::var_os("XDG_RUNTIME_DIR")
        .is_some_and(|d| !d.is_empty() && std::path::Path::new(&d).is_dir());
    if !runtime_dir && std::env::var_os("NODEVICE_SELECT").is_none() {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
}

/// A device and its queue, plus the errors wgpu reported outside an error scope.
pub struct Gpu {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    errors: Arc<Mutex<Vec<String>>>,
}

impl Gpu {
    /// An adapter for offscreen rendering (no window, no display).
    pub fn headless(backend: Backend) -> Result<Gpu> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.backends = backend.backends();
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| Error::input(format!("{INSTALL_HINT} (backend {backend:?}: {e})")))?;
        Self::from_adapter(instance, adapter)
    }

    /// A device on a chosen adapter.
    pub fn from_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Gpu> {
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("sunbeam"),
            required_features: wgpu::Features::empty(),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| Error::internal(format!("cannot open the GPU device: {e}")))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e| {
            if let Ok(mut v) = sink.lock() {
                v.push(e.to_string());
            }
        }));
        Ok(Gpu {
            instance,
            adapter,
            device,
            queue,
            errors,
        })
    }

    /// One line naming the adapter, driver and backend.
    pub fn describe(&self) -> String {
        let i = self.adapter.get_info();
        format!(
            "{} ({:?}, {} {}, {:?})",
            i.name, i.backend, i.driver, i.driver_info, i.device_type
        )
    }

    /// The adapter is a CPU rasteriser (lavapipe, llvmpipe, WARP).
    pub fn is_cpu(&self) -> bool {
        self.adapter.get_info().device_type == wgpu::DeviceType::Cpu
    }

    /// Errors wgpu reported since the last call (validation errors are bugs: exit 4).
    pub fn take_errors(&self) -> Result<()> {
        let v: Vec<String> = self
            .errors
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default();
        if v.is_empty() {
            Ok(())
        } else {
            Err(Error::internal(format!("GPU error: {}", v.join("; "))))
        }
    }

    /// Wait until the queue is idle.
    pub fn wait(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::internal(format!("GPU poll: {e}")))?;
        Ok(())
    }
}

/// A read-only storage buffer at `binding`, seen by the fragment stage (the
/// layouts of the material's and the environment's bind groups).
pub(crate) fn fragment_storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}
