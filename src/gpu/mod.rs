//! The thin wgpu layer: a device (headless, or for a window surface), textures, typed uniform
//! buffers and readback. Nothing here knows about scenes or techniques.

pub mod layout;
pub mod mipmap;
pub mod readback;
pub mod texture;
pub mod uniform;

use std::sync::Arc;
use std::time::Instant;

/// A wgpu device and the instance and adapter it came from.
pub struct Gpu {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
}

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no graphics adapter was found (tried {tried}). Mirador needs Vulkan or OpenGL: on Debian or \
         Ubuntu, `apt-get install mesa-vulkan-drivers libvulkan1` gives a CPU Vulkan driver \
         (lavapipe) that needs no GPU; WGPU_BACKEND=vulkan|gl picks a backend"
    )]
    NoAdapter { tried: String },
    #[error("the {adapter} adapter refused to create a device: {source}")]
    Device { adapter: String, source: wgpu::RequestDeviceError },
}

impl Gpu {
    /// A device with no window, preferring Vulkan and falling back to GL, unless `WGPU_BACKEND`
    /// names the backends to try.
    pub fn headless() -> Result<Gpu, GpuError> {
        let (gpu, ()) = Gpu::first_adapter(wgpu::InstanceDescriptor::new_without_display_handle, |_| Some(()))?;
        Ok(gpu)
    }

    /// A device that can present to `window`, and the window's surface, preferring Vulkan and
    /// falling back to GL as [`Gpu::headless`] does. GL needs the display at instance creation
    /// to present, so the instance is made with it.
    pub fn for_window<W>(window: Arc<W>) -> Result<(Gpu, wgpu::Surface<'static>), GpuError>
    where
        W: wgpu::rwh::HasWindowHandle + wgpu::rwh::HasDisplayHandle + std::fmt::Debug + Send + Sync + 'static,
    {
        let descriptor = || wgpu::InstanceDescriptor::new_with_display_handle(Box::new(window.clone()));
        Gpu::first_adapter(descriptor, |instance| match instance.create_surface(window.clone()) {
            Ok(surface) => Some(surface),
            Err(e) => {
                log::info!("no surface for the window: {e}");
                None
            }
        })
    }

    /// Tries the backends in order; for each, `attach` may make something the adapter must be
    /// compatible with (a window's surface), and the first adapter found wins.
    fn first_adapter<T: SurfaceLike>(
        descriptor: impl Fn() -> wgpu::InstanceDescriptor,
        attach: impl Fn(&wgpu::Instance) -> Option<T>,
    ) -> Result<(Gpu, T), GpuError> {
        let order = match wgpu::Backends::from_env() {
            Some(chosen) => vec![chosen],
            None => vec![wgpu::Backends::VULKAN, wgpu::Backends::GL],
        };
        let mut tried = Vec::new();
        for backends in order {
            let mut d = descriptor().with_env();
            d.backends = backends;
            let instance = wgpu::Instance::new(d);
            tried.push(format!("{backends:?}"));
            let Some(attached) = attach(&instance) else { continue };
            let options = wgpu::RequestAdapterOptions { compatible_surface: attached.surface(), ..Default::default() };
            match pollster::block_on(instance.request_adapter(&options)) {
                Ok(adapter) => return Ok((Gpu::with_adapter(instance, adapter)?, attached)),
                Err(e) => log::info!("no {backends:?} adapter: {e}"),
            }
        }
        Err(GpuError::NoAdapter { tried: tried.join(", ") })
    }

    /// A device for `adapter`, asking only for what every backend Mirador supports can give.
    pub fn with_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Gpu, GpuError> {
        let info = adapter.get_info();
        log::info!("adapter: {} ({:?})", info.name, info.backend);
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("mirador::device"),
            required_features: wgpu::Features::empty(),
            required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .map_err(|source| GpuError::Device { adapter: info.name.clone(), source })?;
        Ok(Gpu { instance, adapter, device, queue })
    }

    /// "name (backend)", for logs and `--stats`.
    pub fn describe(&self) -> String {
        let info = self.adapter.get_info();
        format!("{} ({:?})", info.name, info.backend)
    }

    /// Blocks until the queue has finished everything submitted so far.
    pub fn wait(&self) {
        self.device.poll(wgpu::PollType::wait_indefinitely()).expect("polling the device for completion");
    }
}

/// What an adapter must be able to draw to: a window's surface, or nothing.
trait SurfaceLike {
    fn surface(&self) -> Option<&wgpu::Surface<'static>>;
}

impl SurfaceLike for () {
    fn surface(&self) -> Option<&wgpu::Surface<'static>> {
        None
    }
}

impl SurfaceLike for wgpu::Surface<'static> {
    fn surface(&self) -> Option<&wgpu::Surface<'static>> {
        Some(self)
    }
}

/// Wall-clock timings of named steps, printed by `--stats`.
#[derive(Debug, Default)]
pub struct Stopwatch {
    pub laps: Vec<(&'static str, std::time::Duration)>,
}

impl Stopwatch {
    /// Runs `f` and records how long it took under `name`.
    pub fn time<T>(&mut self, name: &'static str, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let value = f();
        self.laps.push((name, start.elapsed()));
        value
    }

    pub fn report(&self) -> String {
        self.laps
            .iter()
            .map(|(name, d)| format!("{name:>16}: {:9.3} ms", d.as_secs_f64() * 1e3))
            .collect::<Vec<_>>()
            .join("\n")
    }
}
