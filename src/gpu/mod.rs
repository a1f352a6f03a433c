//! The thin wgpu layer: a device (headless, or for a window surface), textures, depth copies,
//! typed uniform buffers and readback. Nothing here knows about scenes or techniques.

pub mod depth_copy;
pub mod layout;
pub mod mipmap;
pub mod readback;
pub mod texture;
pub mod uniform;

use std::sync::Arc;

pub use crate::shaders::Profile;
use web_time::Instant;

/// A wgpu device and the instance and adapter it came from. A clone shares the same device (wgpu's
/// handles are counted references), for work that outlives a borrow: the page's lab checks.
#[derive(Clone)]
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
    #[error("MIRADOR_LIMITS={0}: unknown value; `downlevel` and `webgl2` are the ones there are")]
    UnknownLimits(String),
    #[error(
        "a {width}×{height} image does not fit this device ({adapter}): its max_texture_dimension_2d \
         limit is {limit} pixels a side"
    )]
    ImageTooLarge { width: u32, height: u32, limit: u32, adapter: String },
    #[error("the GPU reported {kind}: {message}")]
    Reported { kind: &'static str, message: String },
}

impl Gpu {
    /// A device with no window, preferring Vulkan and falling back to GL, unless `WGPU_BACKEND`
    /// names the backends to try.
    pub fn headless() -> Result<Gpu, GpuError> {
        Gpu::first_headless(backend_order())
    }

    /// A device with no window on `backends`, whatever `WGPU_BACKEND` says: how one process
    /// compares two backends (`tests/gl_backend.rs`).
    pub fn headless_on(backends: wgpu::Backends) -> Result<Gpu, GpuError> {
        Gpu::first_headless(vec![backends])
    }

    /// [`Gpu::headless_on`] with a device of the WebGL2 profile whatever the adapter offers, as
    /// `MIRADOR_LIMITS=webgl2` makes: how one process compares the profiles (`tests/gl_backend.rs`).
    pub fn headless_webgl2_on(backends: wgpu::Backends) -> Result<Gpu, GpuError> {
        let (instance, adapter) = pollster::block_on(Gpu::first_adapter(
            vec![backends],
            wgpu::InstanceDescriptor::new_without_display_handle,
            |_| Some(()),
            |instance, adapter| async move { Ok((instance, adapter)) },
        ))?
        .0;
        pollster::block_on(Gpu::with_limits(instance, adapter, Some(Limits::WebGl2)))
    }

    fn first_headless(order: Vec<wgpu::Backends>) -> Result<Gpu, GpuError> {
        let (gpu, ()) = pollster::block_on(Gpu::first_adapter(
            order,
            wgpu::InstanceDescriptor::new_without_display_handle,
            |_| Some(()),
            Gpu::with_adapter_async,
        ))?;
        Ok(gpu)
    }

    /// A device that can present to `window`, and the window's surface, preferring Vulkan and
    /// falling back to GL as [`Gpu::headless`] does. GL needs the display at instance creation
    /// to present, so the instance is made with it.
    pub fn for_window<W>(window: Arc<W>) -> Result<(Gpu, wgpu::Surface<'static>), GpuError>
    where
        W: wgpu::rwh::HasWindowHandle + wgpu::rwh::HasDisplayHandle + std::fmt::Debug + Send + Sync + 'static,
    {
        pollster::block_on(Gpu::for_window_async(window))
    }

    /// [`Gpu::for_window`] as a future: the browser answers its WebGPU requests asynchronously,
    /// and a page must not block waiting for them (`src/web/`).
    pub async fn for_window_async<W>(window: Arc<W>) -> Result<(Gpu, wgpu::Surface<'static>), GpuError>
    where
        W: wgpu::rwh::HasWindowHandle + wgpu::rwh::HasDisplayHandle + std::fmt::Debug + Send + Sync + 'static,
    {
        Gpu::for_window_on(window, backend_order()).await
    }

    /// [`Gpu::for_window_async`] on the backends of `order`, tried in turn (the page's
    /// `?webgl2` asks for WebGL2 alone).
    pub async fn for_window_on<W>(
        window: Arc<W>,
        order: Vec<wgpu::Backends>,
    ) -> Result<(Gpu, wgpu::Surface<'static>), GpuError>
    where
        W: wgpu::rwh::HasWindowHandle + wgpu::rwh::HasDisplayHandle + std::fmt::Debug + Send + Sync + 'static,
    {
        let descriptor = || wgpu::InstanceDescriptor::new_with_display_handle(Box::new(window.clone()));
        let attach = |instance: &wgpu::Instance| match instance.create_surface(window.clone()) {
            Ok(surface) => Some(surface),
            Err(e) => {
                log::info!("no surface for the window: {e}");
                None
            }
        };
        Gpu::first_adapter(order, descriptor, attach, Gpu::with_adapter_async).await
    }

    /// Tries the backends of `order` in turn; for each, `attach` may make something the adapter
    /// must be compatible with (a window's surface), and the first adapter found wins.
    async fn first_adapter<T: SurfaceLike, D, F: Future<Output = Result<D, GpuError>>>(
        order: Vec<wgpu::Backends>,
        descriptor: impl Fn() -> wgpu::InstanceDescriptor,
        attach: impl Fn(&wgpu::Instance) -> Option<T>,
        device: impl Fn(wgpu::Instance, wgpu::Adapter) -> F,
    ) -> Result<(D, T), GpuError> {
        let mut tried = Vec::new();
        for backends in order {
            let mut d = descriptor().with_env();
            d.backends = backends;
            // In the browser, WebGPU is offered only where it gives an adapter (Chrome on Linux
            // has `navigator.gpu` and none), and WebGL2 otherwise: a canvas takes one kind of
            // context, so the choice is made before its surface is.
            #[cfg(target_arch = "wasm32")]
            let instance = wgpu::util::new_instance_with_webgpu_detection(d).await;
            #[cfg(not(target_arch = "wasm32"))]
            let instance = wgpu::Instance::new(d);
            tried.push(format!("{backends:?}"));
            let Some(attached) = attach(&instance) else { continue };
            let options = wgpu::RequestAdapterOptions { compatible_surface: attached.surface(), ..Default::default() };
            match instance.request_adapter(&options).await {
                Ok(adapter) => return Ok((device(instance, adapter).await?, attached)),
                Err(e) => log::info!("no {backends:?} adapter: {e}"),
            }
        }
        Err(GpuError::NoAdapter { tried: tried.join(", ") })
    }

    /// A device for `adapter`, asking only for what every backend Mirador supports can give,
    /// and for the adapter's largest textures. `MIRADOR_LIMITS=downlevel` leaves the texture size
    /// at wgpu's downlevel default (2048 pixels a side), to try Mirador as a small device runs it.
    ///
    /// An adapter without cube-map arrays (WebGL2, OpenGL ES 3.0) gets a device of the WebGL2
    /// profile ([`Profile`]): wgpu's WebGL2 limits, and shaders that do without what it lacks.
    /// `MIRADOR_LIMITS=webgl2` makes such a device on any adapter, to run those paths natively.
    pub fn with_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Gpu, GpuError> {
        pollster::block_on(Gpu::with_adapter_async(instance, adapter))
    }

    /// [`Gpu::with_adapter`] as a future.
    pub async fn with_adapter_async(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Gpu, GpuError> {
        let asked = match std::env::var("MIRADOR_LIMITS") {
            Ok(value) if value == "downlevel" => Some(Limits::Downlevel),
            Ok(value) if value == "webgl2" => Some(Limits::WebGl2),
            Ok(value) => return Err(GpuError::UnknownLimits(value)),
            Err(_) => None,
        };
        Gpu::with_limits(instance, adapter, asked).await
    }

    /// The device of [`Gpu::with_adapter`], with the limits `asked` for (else the adapter's
    /// resolution).
    async fn with_limits(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        asked: Option<Limits>,
    ) -> Result<Gpu, GpuError> {
        let info = adapter.get_info();
        log::info!("adapter: {} ({:?})", info.name, info.backend);
        let cube_arrays =
            adapter.get_downlevel_capabilities().flags.contains(wgpu::DownlevelFlags::CUBE_ARRAY_TEXTURES);
        let webgl2 = !cube_arrays || asked == Some(Limits::WebGl2);
        let base = if webgl2 { wgpu::Limits::downlevel_webgl2_defaults() } else { wgpu::Limits::downlevel_defaults() };
        let required_limits = match asked {
            Some(Limits::Downlevel) => base,
            _ => base.using_resolution(adapter.limits()),
        };
        log::info!("shader profile: {}", if webgl2 { "WebGL2" } else { "standard" });
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("mirador::device"),
                required_features: wgpu::Features::empty(),
                required_limits,
                ..Default::default()
            })
            .await
            .map_err(|source| GpuError::Device { adapter: info.name.clone(), source })?;
        seamless_cubes_on_desktop_gl(&device);
        // The browser's errors are not captured ([`Gpu::checked`]): the console shows them.
        #[cfg(target_arch = "wasm32")]
        device.on_uncaptured_error(Arc::new(|error| log::error!("{}", reported(&error))));
        Ok(Gpu { instance, adapter, device, queue })
    }

    /// What this device's shaders may use.
    pub fn profile(&self) -> Profile {
        Profile::of(&self.device)
    }

    /// Whether a frame records its debug groups (a capture tool's tree of views and phases). Not
    /// on Vulkan on a CPU (Mesa's lavapipe): the lavapipe of Debian 12 (Mesa 22.3) crashes in
    /// `vkCmdBeginDebugUtilsLabelEXT` on a frame's groups, and no capture tool is aimed at it.
    pub fn debug_groups(&self) -> bool {
        let info = self.adapter.get_info();
        !(info.backend == wgpu::Backend::Vulkan && info.device_type == wgpu::DeviceType::Cpu)
    }

    /// "name (backend)", for logs and `--stats`.
    pub fn describe(&self) -> String {
        let info = self.adapter.get_info();
        format!("{} ({:?})", info.name, info.backend)
    }

    /// Blocks until the queue has finished everything submitted so far. The browser's page
    /// cannot block: there it only lets finished work report (WebGL2 answers a wait with a
    /// timeout), and what waits on the GPU is answered a frame or two later
    /// ([`readback::Pending`]).
    pub fn wait(&self) {
        #[cfg(target_arch = "wasm32")]
        let _ = self.device.poll(wgpu::PollType::Poll);
        #[cfg(not(target_arch = "wasm32"))]
        self.device.poll(wgpu::PollType::wait_indefinitely()).expect("polling the device for completion");
    }

    /// Whether render targets of `size` fit this device; checked before anything is created, so
    /// that a too-large request names the limit instead of failing inside wgpu.
    pub fn check_image_size(&self, size: (u32, u32)) -> Result<(), GpuError> {
        check_image_size(&self.device.limits(), size).map_err(|limit| GpuError::ImageTooLarge {
            width: size.0,
            height: size.1,
            limit,
            adapter: self.describe(),
        })
    }

    /// [`Gpu::checked`] in the browser, where error scopes answer only after the page returns to
    /// its event loop: `work` runs unchecked, and its errors reach the device's handler, which
    /// logs them to the console.
    #[cfg(target_arch = "wasm32")]
    pub fn checked<T>(&self, work: impl FnOnce() -> T) -> Result<T, GpuError> {
        Ok(work())
    }

    /// [`Gpu::checked`] as a future, which the page can wait for too: the error scopes are pushed
    /// and popped around `work` at once, and their answers awaited (in the browser they come after
    /// the page returns to its event loop). The lab's checks draw this way, so that a student's
    /// function the device rejects is a failed test with the device's reason in the page as
    /// natively, not an image of zeros.
    pub async fn checked_later<T>(&self, work: impl FnOnce() -> T) -> Result<T, GpuError> {
        let out_of_memory = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let internal = self.device.push_error_scope(wgpu::ErrorFilter::Internal);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let value = work();
        // Popped innermost first, as scopes must be; answered later.
        let (validation, internal, out_of_memory) = (validation.pop(), internal.pop(), out_of_memory.pop());
        let (validation, internal, out_of_memory) = (validation.await, internal.await, out_of_memory.await);
        match out_of_memory.or(internal).or(validation) {
            None => Ok(value),
            Some(error) => Err(reported(&error)),
        }
    }

    /// Runs `work` with its GPU errors captured: an out-of-memory, internal or validation error
    /// raised by any wgpu call `work` makes on this thread becomes `Err(GpuError::Reported)`
    /// instead of reaching wgpu's default handler, which panics. Each scope keeps its first
    /// error; out of memory is reported before the others, which usually follow from it (a
    /// texture that could not be allocated is invalid wherever it is used next). `work`'s own
    /// result is returned when the GPU reported nothing.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn checked<T>(&self, work: impl FnOnce() -> T) -> Result<T, GpuError> {
        pollster::block_on(self.checked_later(work))
    }
}

/// Turns on seamless cube-map filtering where wgpu's GL backend runs on a desktop OpenGL context
/// (as it does on Mesa's llvmpipe), which leaves it off. WebGPU filters across a cube's faces,
/// as Vulkan and OpenGL ES 3 always do; without it, a lookup near an edge clamps to its own face,
/// and every mirror ball showed its cube's seams as faint lines (FLIP 0.02 over the worst
/// region of the environment stage against Vulkan; none with it, `tests/gl_backend.rs`).
#[cfg_attr(target_arch = "wasm32", allow(unused_variables))]
fn seamless_cubes_on_desktop_gl(device: &wgpu::Device) {
    #[cfg(any(windows, target_os = "linux", target_os = "android", target_os = "freebsd"))]
    {
        use glow::HasContext;
        // SAFETY: the context is wgpu's own, locked (and made current) for the call; enabling a
        // capability wgpu never sets changes nothing wgpu keeps track of.
        unsafe {
            if let Some(hal) = device.as_hal::<wgpu::hal::api::Gles>() {
                let gl = hal.context().lock();
                // An ES context has no such switch: its cube maps are always seamless.
                if !gl.version().is_embedded {
                    gl.enable(glow::TEXTURE_CUBE_MAP_SEAMLESS);
                }
            }
        }
    }
}

/// The limits `MIRADOR_LIMITS` asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Limits {
    /// wgpu's downlevel defaults as they are (textures of 2048 pixels a side).
    Downlevel,
    /// A device of the WebGL2 profile, with the adapter's resolution.
    WebGl2,
}

/// The backends to try, in order: the ones `WGPU_BACKEND` names, else Vulkan, then GL; in the
/// browser, WebGPU where it has an adapter, else WebGL2.
fn backend_order() -> Vec<wgpu::Backends> {
    if cfg!(target_arch = "wasm32") {
        return vec![wgpu::Backends::BROWSER_WEBGPU | wgpu::Backends::GL];
    }
    match wgpu::Backends::from_env() {
        Some(chosen) => vec![chosen],
        None => vec![wgpu::Backends::VULKAN, wgpu::Backends::GL],
    }
}

/// `Err(limit)` when an image of `size` exceeds `limits.max_texture_dimension_2d`.
pub fn check_image_size(limits: &wgpu::Limits, (width, height): (u32, u32)) -> Result<(), u32> {
    let limit = limits.max_texture_dimension_2d;
    if width > limit || height > limit { Err(limit) } else { Ok(()) }
}

/// A wgpu error on one line: its kind, then each cause in turn ("In Device::create_texture,
/// label = 'shadow::maps': Dimension X value 4096 exceeds the limit of 2048"). wgpu's own
/// description spreads the same causes over an indented tree.
fn reported(error: &wgpu::Error) -> GpuError {
    let kind = match error {
        wgpu::Error::OutOfMemory { .. } => "an out-of-memory error",
        wgpu::Error::Validation { .. } => "a validation error",
        wgpu::Error::Internal { .. } => "an internal error",
    };
    let mut causes: Vec<String> = Vec::new();
    let mut cause = std::error::Error::source(error);
    while let Some(inner) = cause {
        let text = inner.to_string();
        if causes.last() != Some(&text) && !text.is_empty() {
            causes.push(text);
        }
        cause = inner.source();
    }
    if causes.is_empty() {
        causes.push(error.to_string());
    }
    GpuError::Reported { kind, message: causes.join(": ").replace('\n', " ") }
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
