//! The window and what draws into it: the wgpu device and the window's surface, egui's input
//! (egui-winit) and its painter (egui-wgpu), and screenshots of the whole window.
//!
//! A frame of the window is composed by copies wherever it can ([`Screen::paint`]): the 3D view's
//! image (the rasterizer's frame, already through the output transform) is copied into the view's
//! rectangle, the side panel's pixels are copied from where egui last drew them, and egui draws
//! only the rest (the overlays over the view) each frame. The panel is drawn again only when its
//! shapes change: they are the front of egui's list of shapes, up to the first that reaches into
//! the view ([`panel_shapes`]). A surface that takes no copies (the GL backend's) falls back to
//! egui drawing everything, the image as a texture ([`Composition::Textured`]; forced with
//! `MIRADOR_COMPOSITION=textured`). Measured on lavapipe at 1280×720 (docs/performance.md), the
//! copies save about 2 ms of a still frame's 12.6 and 4 ms of an orbiting frame's 44: less than
//! keeping an unchanged image and drawing moving frames small, which is where the time went.
//!
//! The window can go away under the program: a minimised window has a zero size (nothing is drawn
//! until it comes back), a resized one is reconfigured, an outdated surface is reconfigured and a
//! lost one recreated; each of those skips one frame instead of failing. The window's size is
//! followed from its `Resized` events and never asked of the window: winit's X11 backend panics
//! when a window destroyed from outside (`xdotool windowclose`, `xkill`, a window manager) is
//! asked its size. Errors of the surface itself (it may fail before the `Destroyed` event
//! arrives) skip frames too and are reported only if they last ([`Screen::surface_failing`]).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use web_time::Instant;

use anyhow::Context as _;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

use super::upscale::Upscale;
use crate::gpu::{Gpu, layout, readback};

pub struct Screen {
    pub window: Arc<Window>,
    pub gpu: Gpu,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    pub composition: Composition,
    pub egui: egui::Context,
    pub input: egui_winit::State,
    pub painter: egui_wgpu::Renderer,
    /// The window has no pixels (its last `Resized` event said zero).
    zero_size: bool,
    /// egui's clock.
    started: Instant,
    /// Since when every frame's surface has failed, and the last error.
    failing: Option<(Instant, String)>,
    /// The side panel as egui last drew it ([`Composition::Copied`]).
    panel: Option<PanelCache>,
    upscale: Option<Upscale>,
    /// Screenshots on their way back from the GPU, and where they go.
    screenshots: Vec<(PathBuf, PendingImage)>,
    /// Where screenshots go instead of PNG files (the browser's page hands them to its script).
    pub screenshot_sink: Option<ScreenshotSink>,
}

/// Where a screenshot goes instead of a PNG file: given the name it was asked for and its pixels.
pub(in crate::viewer) type ScreenshotSink = Box<dyn Fn(&Path, &image::RgbaImage)>;

/// The side panel's pixels and the shapes they were drawn from.
struct PanelCache {
    /// The window's size, in the surface's format; the panel is its left `width` pixels.
    texture: wgpu::Texture,
    width: u32,
    pixels_per_point: f32,
    shapes: Vec<egui::epaint::ClippedShape>,
}

/// How the 3D view's image reaches the window.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Composition {
    /// Copied into the surface, under egui's drawing.
    Copied,
    /// Drawn by egui as a texture (a surface that takes no copies).
    Textured,
}

/// The 3D view's image and where it goes in the window, in pixels: copied when it has the view's
/// size, stretched over it when it was drawn at a lower render scale.
#[derive(Clone, Copy)]
pub struct ViewImage<'a> {
    pub texture: &'a wgpu::Texture,
    /// The image's bytes as a plain (not sRGB) 8-bit view, for stretching.
    pub plain: &'a wgpu::TextureView,
    /// The view's rectangle: `x, y, width, height`.
    pub rect: [u32; 4],
}

/// What became of one frame's presentation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Presented {
    Shown,
    /// The surface was not ready (minimised, outdated, lost, failing): nothing was drawn.
    Skipped,
}

/// How long a surface may keep failing before the viewer stops with its error: a window destroyed
/// from outside fails its surface just before its `Destroyed` event arrives.
const FAILING_FOR: Duration = Duration::from_secs(2);

impl Screen {
    /// Opens the window (`size` in logical pixels) and a device that can present to it.
    pub fn open(event_loop: &ActiveEventLoop, title: &str, size: [u32; 2], vsync: bool) -> anyhow::Result<Screen> {
        let attributes = Window::default_attributes()
            .with_title(title)
            .with_inner_size(winit::dpi::LogicalSize::new(size[0], size[1]))
            .with_min_inner_size(winit::dpi::LogicalSize::new(320, 240));
        let window = Arc::new(event_loop.create_window(attributes).context("cannot open a window")?);
        let (gpu, surface) = Gpu::for_window(window.clone())?;
        Screen::new(window, gpu, surface, vsync)
    }

    /// The screen of `window`, given a device and the window's surface (the browser makes them
    /// asynchronously, `src/web/`).
    pub fn new(window: Arc<Window>, gpu: Gpu, surface: wgpu::Surface<'static>, vsync: bool) -> anyhow::Result<Screen> {
        let capabilities = surface.get_capabilities(&gpu.adapter);
        // egui blends in sRGB-encoded values, so a plain 8-bit format is its natural target.
        let format = capabilities
            .formats
            .iter()
            .copied()
            .find(|f| matches!(f, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm))
            .or_else(|| capabilities.formats.first().copied())
            .context("the window's surface offers no format")?;
        // The raster image is drawn in the sRGB twin of the surface's format and copied in: the
        // same bytes, which only formats that differ in their sRGB-ness alone can exchange. A
        // moving frame is stretched through a plain view of those bytes, which needs view formats
        // (wgpu's GL backend has none).
        let view_formats = gpu.adapter.get_downlevel_capabilities().flags.contains(wgpu::DownlevelFlags::VIEW_FORMATS);
        let copyable = matches!(format, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm)
            && capabilities.usages.contains(wgpu::TextureUsages::COPY_DST)
            && view_formats;
        // `MIRADOR_COMPOSITION=textured` takes the other surfaces' path on any surface: to test it
        // and to measure what the copies save (benches/viewer.sh).
        let forced = std::env::var("MIRADOR_COMPOSITION").is_ok_and(|v| v == "textured");
        let composition = if copyable && !forced { Composition::Copied } else { Composition::Textured };
        let usage = match composition {
            Composition::Copied => wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_DST,
            Composition::Textured => wgpu::TextureUsages::RENDER_ATTACHMENT,
        };
        // Asked once, while the window surely exists; afterwards its `Resized` events say.
        let physical = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: physical.width.max(1),
            height: physical.height.max(1),
            present_mode: if vsync { wgpu::PresentMode::AutoVsync } else { wgpu::PresentMode::AutoNoVsync },
            desired_maximum_frame_latency: 2,
            alpha_mode: capabilities.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        let zero_size = physical.width == 0 || physical.height == 0;
        if !zero_size {
            surface.configure(&gpu.device, &config);
        }
        let egui = egui::Context::default();
        egui.set_fonts(course_fonts());
        let max_texture_side = gpu.device.limits().max_texture_dimension_2d as usize;
        let input = egui_winit::State::new(
            egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(max_texture_side),
        );
        let painter = egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default());
        let upscale = (composition == Composition::Copied).then(|| Upscale::new(&gpu.device, format));
        log::info!("window surface: {format:?}, the 3D view {composition:?}, on {}", gpu.describe());
        Ok(Screen {
            window,
            gpu,
            surface,
            config,
            composition,
            egui,
            input,
            painter,
            zero_size,
            started: Instant::now(),
            failing: None,
            panel: None,
            upscale,
            screenshots: Vec::new(),
            screenshot_sink: None,
        })
    }

    /// The surface's size in physical pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.config.width, self.config.height)
    }

    /// The format the 3D view's image must have: the surface's own bytes to copy in, else what
    /// egui samples from (see `raster_view`).
    pub(in crate::viewer) fn image_format(&self) -> wgpu::TextureFormat {
        match self.composition {
            Composition::Copied => self.config.format.add_srgb_suffix(),
            Composition::Textured => crate::raster::OUTPUT_FORMAT,
        }
    }

    /// Follows the window's new size; a zero size (minimised) is remembered and drawn no more.
    pub fn resize(&mut self, size: winit::dpi::PhysicalSize<u32>) {
        self.zero_size = size.width == 0 || size.height == 0;
        if self.zero_size {
            return;
        }
        self.config.width = size.width;
        self.config.height = size.height;
        self.configure();
    }

    /// Configures the surface at the size last reported; an error is kept as a failing surface.
    fn configure(&mut self) {
        if let Err(e) = self.gpu.checked(|| self.surface.configure(&self.gpu.device, &self.config)) {
            self.fail(format!("configuring it: {e}"));
        }
    }

    fn fail(&mut self, error: String) {
        log::info!("the window's surface failed: {error}");
        let since = self.failing.take().map_or_else(Instant::now, |(since, _)| since);
        self.failing = Some((since, error));
    }

    /// The surface's error once it has failed every frame for a while: the viewer stops with it.
    pub(in crate::viewer) fn surface_failing(&self) -> Option<String> {
        let (since, error) = self.failing.as_ref()?;
        (since.elapsed() >= FAILING_FOR).then(|| format!("the window's surface keeps failing: {error}"))
    }

    /// Whether the window has no pixels (minimised): rendering is skipped.
    pub fn is_minimised(&self) -> bool {
        self.zero_size || self.window.is_minimized() == Some(true)
    }

    /// egui's input since the last frame. `egui_winit::State::take_egui_input` would do, but it
    /// asks the window its size (see the module's header).
    pub(in crate::viewer) fn take_input(&mut self) -> egui::RawInput {
        let pixels_per_point = egui_winit::pixels_per_point(&self.egui, &self.window);
        let native = self.window.scale_factor() as f32;
        let (width, height) = self.size();
        let zero_size = self.zero_size;
        let raw = self.input.egui_input_mut();
        raw.time = Some(self.started.elapsed().as_secs_f64());
        let points = egui::vec2(width as f32, height as f32) / pixels_per_point;
        raw.screen_rect = (!zero_size).then(|| egui::Rect::from_min_size(egui::Pos2::ZERO, points));
        raw.viewport_id = egui::ViewportId::ROOT;
        raw.viewports.entry(egui::ViewportId::ROOT).or_default().native_pixels_per_point = Some(native);
        raw.take()
    }

    /// The next image of the surface, or `None` (and the surface mended) when it is not ready.
    fn acquire(&mut self) -> Option<(wgpu::SurfaceTexture, bool)> {
        let current = match self.gpu.checked(|| self.surface.get_current_texture()) {
            Ok(current) => current,
            Err(e) => {
                self.fail(format!("getting its image: {e}"));
                return None;
            }
        };
        match current {
            wgpu::CurrentSurfaceTexture::Success(frame) => Some((frame, false)),
            wgpu::CurrentSurfaceTexture::Suboptimal(frame) => Some((frame, true)),
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => None,
            wgpu::CurrentSurfaceTexture::Outdated => {
                self.configure();
                None
            }
            wgpu::CurrentSurfaceTexture::Lost => {
                match self.gpu.instance.create_surface(self.window.clone()) {
                    Ok(surface) => {
                        self.surface = surface;
                        self.configure();
                    }
                    Err(e) => self.fail(format!("recreating it: {e}")),
                }
                None
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                self.fail("a validation error".into());
                None
            }
        }
    }

    /// Composes the window from egui's output and the 3D view's image: with
    /// [`Composition::Copied`], `view` is copied in, the panel copied from its cache (drawn again
    /// first if its shapes changed), and egui draws the rest over them; otherwise egui draws it all.
    /// With `screenshot`, composes the same into an offscreen texture and writes that as a PNG
    /// (atomically).
    pub fn paint(
        &mut self,
        output: egui::FullOutput,
        view: Option<ViewImage>,
        screenshot: Option<&Path>,
    ) -> anyhow::Result<Presented> {
        self.input.handle_platform_output(&self.window, output.platform_output);
        let pixels_per_point = output.pixels_per_point;
        let view = view.filter(|_| self.composition == Composition::Copied);
        let mut textures = output.textures_delta;
        // A changed font atlas changes the panel's glyphs without changing its shapes.
        let atlas_changed = !textures.set.is_empty();
        let mut shapes = output.shapes;
        let mut panel = None;
        if let Some(image) = view
            && image.rect[0] > 0
        {
            let edge = image.rect[0];
            let rest = shapes.split_off(panel_shapes(&shapes, edge as f32 / pixels_per_point));
            let front = std::mem::replace(&mut shapes, rest);
            let kept = self.panel.as_ref().is_some_and(|cache| {
                cache.width == edge
                    && cache.pixels_per_point == pixels_per_point
                    && cache.texture.size() == self.surface_size()
                    && cache.shapes == front
            });
            panel = Some((edge, (!kept || atlas_changed).then_some(front)));
        }
        let jobs = self.egui.tessellate(shapes, pixels_per_point);
        for (id, deltas) in textures.set.drain() {
            for delta in &deltas {
                self.painter.update_texture(&self.gpu.device, &self.gpu.queue, id, delta);
            }
        }
        let freed: Vec<egui::TextureId> = textures.free.drain().collect();
        textures.clear();
        let acquired = self.acquire();
        let Some((frame, suboptimal)) = acquired else {
            for id in &freed {
                self.painter.free_texture(id);
            }
            return Ok(Presented::Skipped);
        };
        let screen =
            egui_wgpu::ScreenDescriptor { size_in_pixels: [self.config.width, self.config.height], pixels_per_point };
        if let Some((width, Some(front))) = &mut panel {
            self.draw_panel(*width, std::mem::take(front), &screen);
        }
        let (device, queue) = (&self.gpu.device, &self.gpu.queue);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("viewer::ui") });
        let extra = self.painter.update_buffers(device, queue, &mut encoder, &jobs, &screen);
        let panel = panel.and(self.panel.as_ref());
        let copies = Copies { view, panel };
        let mut composer = Composer { device, painter: &self.painter, upscale: self.upscale.as_mut() };
        composer.compose(&mut encoder, &frame.texture, &copies, (&jobs, &screen));
        let shot = screenshot.map(|_| {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("viewer::screenshot"),
                size: frame.texture.size(),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: self.config.format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_DST
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            composer.compose(&mut encoder, &texture, &copies, (&jobs, &screen));
            texture
        });
        queue.submit(extra.into_iter().chain([encoder.finish()]));
        if let Err(e) = self.gpu.checked(|| queue.present(frame)) {
            self.fail(format!("presenting: {e}"));
        } else {
            self.failing = None;
        }
        for id in &freed {
            self.painter.free_texture(id);
        }
        if suboptimal {
            self.configure();
        }
        if let (Some(path), Some(texture)) = (screenshot, shot) {
            let pending = PendingImage::start(&self.gpu, &texture).context("reading the screenshot back")?;
            self.screenshots.push((path.to_path_buf(), pending));
            // Natively the screenshot is written before this returns; the browser's arrives later
            // ([`Screen::write_screenshots`]).
            self.gpu.wait();
            self.write_screenshots()?;
        }
        Ok(Presented::Shown)
    }

    fn surface_size(&self) -> wgpu::Extent3d {
        wgpu::Extent3d { width: self.config.width, height: self.config.height, depth_or_array_layers: 1 }
    }

    /// Draws the panel's shapes into its cache, in a submission of its own: egui's painter keeps
    /// one vertex buffer, which the rest of the frame's shapes overwrite.
    fn draw_panel(
        &mut self,
        width: u32,
        shapes: Vec<egui::epaint::ClippedShape>,
        screen: &egui_wgpu::ScreenDescriptor,
    ) {
        let size = self.surface_size();
        let texture = match self.panel.take() {
            Some(cache) if cache.texture.size() == size => cache.texture,
            _ => self.gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("viewer::panel"),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: self.config.format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            }),
        };
        let jobs = self.egui.tessellate(shapes.clone(), screen.pixels_per_point);
        let (device, queue) = (&self.gpu.device, &self.gpu.queue);
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("viewer::panel") });
        let extra = self.painter.update_buffers(device, queue, &mut encoder, &jobs, screen);
        let view = texture
            .create_view(&wgpu::TextureViewDescriptor { label: Some("viewer::panel_view"), ..Default::default() });
        let pass = encoder.begin_render_pass(&layout::pass(
            "viewer::panel_pass",
            &[Some(layout::color_attachment(&view, wgpu::LoadOp::Clear(wgpu::Color::BLACK)))],
            None,
        ));
        self.painter.render(&mut pass.forget_lifetime(), &jobs, screen);
        queue.submit(extra.into_iter().chain([encoder.finish()]));
        self.panel = Some(PanelCache { texture, width, pixels_per_point: screen.pixels_per_point, shapes });
    }

    /// Writes the screenshots whose pixels have arrived: as PNG files (atomically), or to the
    /// [`Screen::screenshot_sink`] when one is set.
    pub(in crate::viewer) fn write_screenshots(&mut self) -> anyhow::Result<()> {
        let mut waiting = Vec::new();
        for (path, pending) in std::mem::take(&mut self.screenshots) {
            match pending.take(&self.gpu) {
                None => waiting.push((path, pending)),
                Some(image) => {
                    let image = image.context("reading the screenshot back")?;
                    match &self.screenshot_sink {
                        Some(sink) => sink(&path, &image),
                        None => crate::output::write_png_atomically(&image, &path)
                            .with_context(|| format!("{}: cannot write the screenshot", path.display()))?,
                    }
                }
            }
        }
        self.screenshots = waiting;
        Ok(())
    }

    /// Whether a screenshot waits for its pixels (the browser's): the next frame is asked for.
    pub(in crate::viewer) fn screenshots_pending(&self) -> bool {
        !self.screenshots.is_empty()
    }
}

/// What composes a window: the device, egui's painter and the upscale pass.
struct Composer<'a> {
    device: &'a wgpu::Device,
    painter: &'a egui_wgpu::Renderer,
    upscale: Option<&'a mut Upscale>,
}

impl Composer<'_> {
    /// Records one composed window into `target`: the copies, then egui's shapes over them.
    fn compose(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::Texture,
        copies: &Copies,
        (jobs, screen): (&[egui::ClippedPrimitive], &egui_wgpu::ScreenDescriptor),
    ) {
        let target_view = target
            .create_view(&wgpu::TextureViewDescriptor { label: Some("viewer::window_view"), ..Default::default() });
        let pass = |encoder: &mut wgpu::CommandEncoder, label, load| {
            encoder
                .begin_render_pass(&layout::pass(label, &[Some(layout::color_attachment(&target_view, load))], None))
                .forget_lifetime()
        };
        let (width, height) = (target.width(), target.height());
        let copy = |encoder: &mut wgpu::CommandEncoder, source: &wgpu::Texture, (x, y): (u32, u32), (w, h)| {
            let (w, h) = (u32::min(w, width.saturating_sub(x)), u32::min(h, height.saturating_sub(y)));
            if w > 0 && h > 0 {
                let destination = wgpu::TexelCopyTextureInfo {
                    texture: target,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x, y, z: 0 },
                    aspect: wgpu::TextureAspect::All,
                };
                let extent = wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 };
                encoder.copy_texture_to_texture(source.as_image_copy(), destination, extent);
            }
        };
        let load = match copies.view {
            Some(image) => {
                let panel_width = copies.panel.map_or(0, |p| p.width);
                let [x, y, w, h] = image.rect;
                // The view and the panel tile the window but for rounding or a hidden panel;
                // what they leave is cleared first.
                if !(x == panel_width && y == 0 && x + w >= width && h >= height) {
                    drop(pass(encoder, "viewer::clear_pass", wgpu::LoadOp::Clear(wgpu::Color::BLACK)));
                }
                if let Some(panel) = copies.panel {
                    copy(encoder, &panel.texture, (0, 0), (panel.width, height));
                }
                let size = image.texture.size();
                match &mut self.upscale {
                    Some(upscale) if (size.width, size.height) != (w, h) => {
                        let [w, h] = [w.min(width.saturating_sub(x)), h.min(height.saturating_sub(y))];
                        if w > 0 && h > 0 {
                            upscale.record(self.device, encoder, image.plain, &target_view, [x, y, w, h]);
                        }
                    }
                    _ => copy(encoder, image.texture, (x, y), (size.width, size.height)),
                }
                wgpu::LoadOp::Load
            }
            None => wgpu::LoadOp::Clear(wgpu::Color::BLACK),
        };
        self.painter.render(&mut pass(encoder, "viewer::ui_pass", load), jobs, screen);
    }
}

/// What [`Composer::compose`] copies into the window before egui draws.
struct Copies<'a> {
    view: Option<ViewImage<'a>>,
    panel: Option<&'a PanelCache>,
}

/// How many of egui's shapes, from the front, draw only left of `edge` (in points): the side
/// panel's, which egui lists first. The first shape that reaches into the view ends them, so
/// whatever egui draws later (windows, tooltips, overlays) stays above them.
pub(in crate::viewer) fn panel_shapes(shapes: &[egui::epaint::ClippedShape], edge: f32) -> usize {
    shapes
        .iter()
        .take_while(|clipped| {
            let bounds = clipped.shape.visual_bounding_rect();
            // An empty rectangle: the shape draws nothing.
            !bounds.is_positive() || bounds.max.x <= edge + 1e-3
        })
        .count()
}

/// An 8-bit RGBA or BGRA texture (sRGB or not: the bytes are the encoded values) as an opaque
/// RGBA image, read back without waiting ([`readback::Pending`]).
pub(in crate::viewer) struct PendingImage {
    pending: readback::Pending,
    bgra: bool,
}

impl PendingImage {
    pub fn start(gpu: &Gpu, texture: &wgpu::Texture) -> anyhow::Result<PendingImage> {
        let format = texture.format();
        if format.block_copy_size(None) != Some(4) {
            anyhow::bail!("reading back a {format:?} texture is not supported");
        }
        let bgra = matches!(format, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb);
        Ok(PendingImage { pending: readback::Pending::start(&gpu.device, &gpu.queue, texture, 4)?, bgra })
    }

    /// The image once the GPU has copied it; `None` before.
    pub fn take(&self, gpu: &Gpu) -> Option<anyhow::Result<image::RgbaImage>> {
        let taken = self.pending.take(&gpu.device)?;
        Some(taken.map_err(anyhow::Error::from).map(|mut pixels| {
            for texel in pixels.chunks_exact_mut(4) {
                if self.bgra {
                    texel.swap(0, 2);
                }
                texel[3] = 255;
            }
            let (width, height) = self.pending.size();
            image::RgbaImage::from_raw(width, height, pixels).expect("one RGBA8 texel per pixel")
        }))
    }
}

/// egui's fonts with its monospace face (Hack) as the proportional face's first fallback: the
/// course's notation in the panel's tooltips (`A ⊗ C`, `‖n‖`) is in Hack, not in Ubuntu-Light,
/// and showed as empty boxes.
pub(in crate::viewer) fn course_fonts() -> egui::FontDefinitions {
    let mut fonts = egui::FontDefinitions::default();
    if let Some(proportional) = fonts.families.get_mut(&egui::FontFamily::Proportional) {
        proportional.insert(1.min(proportional.len()), "Hack".to_owned());
    }
    fonts
}

#[cfg(test)]
mod tests {
    /// Every character the panel's tooltips (the settings' documentation), the help window and
    /// the lab panel show has a glyph in the proportional face or its fallbacks.
    #[test]
    fn the_course_notation_has_glyphs() {
        let definitions = super::course_fonts();
        let mut fonts = egui::epaint::text::Fonts::new(egui::epaint::text::TextOptions::default(), definitions);
        let mut text = crate::settings_doc::scene_format_table();
        for (key, what) in super::super::hud::KEYS {
            text.push_str(key);
            text.push_str(what);
        }
        text.push_str("⊗‖");
        // What the lab panel shows: the labs' titles, their tests' names and their mistakes'
        // sentences (a check's results).
        for lab in crate::lab::catalog() {
            text.push_str(&lab.title);
            let names = lab.known_answers.iter().map(|t| &t.name).chain(lab.images.iter().map(|t| &t.name));
            text.extend(names.map(String::as_str));
            text.extend(lab.mistakes.iter().flat_map(|m| [m.name.as_str(), m.sentence.as_str()]));
        }
        let font = egui::FontId::proportional(13.0);
        let missing: String = text.chars().filter(|c| !c.is_control() && !fonts.has_glyph(&font, *c)).collect();
        assert!(missing.is_empty(), "no glyph for {missing:?}");
    }
}
