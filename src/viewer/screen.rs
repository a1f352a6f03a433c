//! The window and what draws into it: the wgpu device and the window's surface, egui's input
//! (egui-winit) and its painter (egui-wgpu), and screenshots of the whole window.
//!
//! A surface can go away under the program: a minimised window has a zero size (nothing is drawn
//! until it comes back), a resized one is reconfigured, an outdated surface is reconfigured and a
//! lost one recreated; each of those skips one frame instead of failing.

use std::path::Path;
use std::sync::Arc;

use anyhow::Context as _;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

use crate::gpu::{Gpu, readback};

pub struct Screen {
    pub window: Arc<Window>,
    pub gpu: Gpu,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    pub egui: egui::Context,
    pub input: egui_winit::State,
    pub painter: egui_wgpu::Renderer,
}

/// What became of one frame's presentation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Presented {
    Shown,
    /// The surface was not ready (minimised, outdated, lost): nothing was drawn this time.
    Skipped,
}

impl Screen {
    /// Opens the window (`size` in logical pixels) and a device that can present to it.
    pub fn open(event_loop: &ActiveEventLoop, title: &str, size: [u32; 2], vsync: bool) -> anyhow::Result<Screen> {
        let attributes = Window::default_attributes()
            .with_title(title)
            .with_inner_size(winit::dpi::LogicalSize::new(size[0], size[1]))
            .with_min_inner_size(winit::dpi::LogicalSize::new(320, 240));
        let window = Arc::new(event_loop.create_window(attributes).context("cannot open a window")?);
        let (gpu, surface) = Gpu::for_window(window.clone())?;
        let capabilities = surface.get_capabilities(&gpu.adapter);
        // egui blends in sRGB-encoded values, so a plain 8-bit format is its natural target.
        let format = capabilities
            .formats
            .iter()
            .copied()
            .find(|f| matches!(f, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm))
            .or_else(|| capabilities.formats.first().copied())
            .context("the window's surface offers no format")?;
        let physical = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: physical.width.max(1),
            height: physical.height.max(1),
            present_mode: if vsync { wgpu::PresentMode::AutoVsync } else { wgpu::PresentMode::AutoNoVsync },
            desired_maximum_frame_latency: 2,
            alpha_mode: capabilities.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        if physical.width > 0 && physical.height > 0 {
            surface.configure(&gpu.device, &config);
        }
        let egui = egui::Context::default();
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
        log::info!("window surface: {format:?} on {}", gpu.describe());
        Ok(Screen { window, gpu, surface, config, egui, input, painter })
    }

    /// The surface's size in physical pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.config.width, self.config.height)
    }

    /// Follows the window's new size; a zero size (minimised) is remembered and drawn no more.
    pub fn resize(&mut self, size: winit::dpi::PhysicalSize<u32>) {
        if size.width == 0 || size.height == 0 {
            return;
        }
        self.config.width = size.width;
        self.config.height = size.height;
        self.surface.configure(&self.gpu.device, &self.config);
    }

    /// Whether the window has no pixels (minimised): rendering is skipped.
    pub fn is_minimised(&self) -> bool {
        let size = self.window.inner_size();
        size.width == 0 || size.height == 0 || self.window.is_minimized() == Some(true)
    }

    /// Tessellates and draws egui's output into the window; with `screenshot`, also draws it into
    /// an offscreen texture and writes that as a PNG (atomically).
    pub fn paint(&mut self, output: egui::FullOutput, screenshot: Option<&Path>) -> anyhow::Result<Presented> {
        self.input.handle_platform_output(&self.window, output.platform_output);
        let jobs = self.egui.tessellate(output.shapes, output.pixels_per_point);
        let mut textures = output.textures_delta;
        for (id, deltas) in textures.set.drain() {
            for delta in &deltas {
                self.painter.update_texture(&self.gpu.device, &self.gpu.queue, id, delta);
            }
        }
        let freed: Vec<egui::TextureId> = textures.free.drain().collect();
        textures.clear();
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame) => Some((frame, false)),
            wgpu::CurrentSurfaceTexture::Suboptimal(frame) => Some((frame, true)),
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => None,
            wgpu::CurrentSurfaceTexture::Outdated => {
                self.resize(self.window.inner_size());
                None
            }
            wgpu::CurrentSurfaceTexture::Lost => {
                self.surface =
                    self.gpu.instance.create_surface(self.window.clone()).context("recreating the lost surface")?;
                self.resize(self.window.inner_size());
                None
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                log::warn!("the surface reported a validation error; frame skipped");
                None
            }
        };
        let Some((frame, suboptimal)) = frame else {
            for id in &freed {
                self.painter.free_texture(id);
            }
            return Ok(Presented::Skipped);
        };
        let (device, queue) = (&self.gpu.device, &self.gpu.queue);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: output.pixels_per_point,
        };
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("viewer::ui") });
        let extra = self.painter.update_buffers(device, queue, &mut encoder, &jobs, &screen);
        let view = frame
            .texture
            .create_view(&wgpu::TextureViewDescriptor { label: Some("viewer::surface_view"), ..Default::default() });
        self.record_ui(&mut encoder, &view, &jobs, &screen);
        let shot = screenshot.map(|_| {
            let texture =
                crate::gpu::texture::GpuTexture::target(device, "viewer::screenshot", self.size(), self.config.format);
            self.record_ui(&mut encoder, &texture.view, &jobs, &screen);
            texture
        });
        queue.submit(extra.into_iter().chain([encoder.finish()]));
        queue.present(frame);
        for id in &freed {
            self.painter.free_texture(id);
        }
        if suboptimal {
            self.resize(self.window.inner_size());
        }
        if let (Some(path), Some(texture)) = (screenshot, shot) {
            self.write_screenshot(&texture.texture, path)?;
        }
        Ok(Presented::Shown)
    }

    fn record_ui(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        jobs: &[egui::ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) {
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("viewer::ui_pass"),
            color_attachments: &[Some(crate::gpu::layout::color_attachment(
                target,
                wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            ))],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.painter.render(&mut pass.forget_lifetime(), jobs, screen);
    }

    fn write_screenshot(&self, texture: &wgpu::Texture, path: &Path) -> anyhow::Result<()> {
        let format = self.config.format;
        if format.block_copy_size(None) != Some(4) {
            anyhow::bail!("screenshots of a {format:?} surface are not supported");
        }
        let mut pixels =
            readback::read_rgba8(&self.gpu.device, &self.gpu.queue, texture).context("reading the screenshot back")?;
        if matches!(format, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb) {
            for texel in pixels.chunks_exact_mut(4) {
                texel.swap(0, 2);
            }
        }
        for texel in pixels.chunks_exact_mut(4) {
            texel[3] = 255;
        }
        let (width, height) = self.size();
        let image = image::RgbaImage::from_raw(width, height, pixels).expect("one RGBA8 texel per pixel");
        crate::output::write_png_atomically(&image, path)
            .with_context(|| format!("{}: cannot write the screenshot", path.display()))
    }
}
