//! The rasterizer's image in the window: the one place the viewer calls [`Renderer`].
//!
//! The frame is drawn offscreen, into an `Rgba8UnormSrgb` texture of the 3D view's size times the
//! render scale (lower while the camera moves), exactly as `mirador render` draws it; then copied
//! into an `Rgba8Unorm` twin that egui samples. egui expects sRGB-encoded values in a texture it
//! does not decode, and a copy between formats that differ only in their sRGB-ness moves the
//! bytes unchanged, so the window shows the very pixels a screenshot of `render` holds, on every
//! backend (the GL backend cannot reinterpret one texture through a view of another format).

use std::time::{Duration, Instant};

use crate::gpu::texture::GpuTexture;
use crate::gpu::{Gpu, readback};
use crate::raster::{FrameReport, FrameTargets, OUTPUT_FORMAT, Renderer};
use crate::{RenderSettings, Scene};

/// The format egui samples the image from.
const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

pub struct RasterView {
    renderer: Renderer,
    /// The scene revision the renderer loaded.
    revision: u64,
    /// Everything that depends on the image size.
    frame: Option<SizedTargets>,
    /// How egui refers to the displayed image; the same id across resizes, so the UI can lay out
    /// a frame before its image is drawn.
    texture_id: egui::TextureId,
    /// Bound to `texture_id` until the first frame is drawn.
    _placeholder: wgpu::Texture,
    /// The image size and filter the egui texture was last bound with.
    bound: Option<((u32, u32), wgpu::FilterMode)>,
    /// What the last frame did: its passes' times (when timed), the shadow layers it redrew.
    pub report: FrameReport,
}

struct SizedTargets {
    size: (u32, u32),
    targets: FrameTargets,
    output: GpuTexture,
    display: wgpu::Texture,
    display_view: wgpu::TextureView,
}

impl RasterView {
    pub fn new(gpu: &Gpu, egui_renderer: &mut egui_wgpu::Renderer, scene: &Scene, revision: u64) -> RasterView {
        let renderer = Renderer::new(gpu, scene, OUTPUT_FORMAT);
        let placeholder = display_texture(&gpu.device, (1, 1));
        let view = placeholder.create_view(&wgpu::TextureViewDescriptor {
            label: Some("viewer::raster::placeholder_view"),
            ..Default::default()
        });
        let texture_id = egui_renderer.register_native_texture(&gpu.device, &view, wgpu::FilterMode::Nearest);
        RasterView {
            renderer,
            revision,
            frame: None,
            texture_id,
            _placeholder: placeholder,
            bound: None,
            report: FrameReport::default(),
        }
    }

    /// The displayed image's egui id.
    pub fn texture_id(&self) -> egui::TextureId {
        self.texture_id
    }

    /// Renders `scene` (whose camera must have the image's size) into the displayed texture and
    /// returns the texture's egui id and the time the GPU took (measured only when `timed`, as it
    /// waits for the frame; then each pass is also timed on its own, in [`Self::report`]).
    pub fn render(
        &mut self,
        gpu: &Gpu,
        egui_renderer: &mut egui_wgpu::Renderer,
        (scene, revision): (&Scene, u64),
        settings: &RenderSettings,
        filter: wgpu::FilterMode,
        timed: bool,
    ) -> (egui::TextureId, Option<Duration>) {
        if revision != self.revision {
            self.renderer.load(gpu, scene);
            self.revision = revision;
        }
        let size = (scene.camera.width, scene.camera.height);
        if self.frame.as_ref().is_none_or(|f| f.size != size) {
            self.frame = Some(self.sized_targets(gpu, size));
        }
        let frame = self.frame.as_mut().expect("made just above");
        let start = Instant::now();
        self.renderer.profile = timed;
        self.report = self.renderer.render(gpu, scene, settings, &mut frame.targets, &frame.output.view);
        let mut encoder =
            gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("viewer::raster::copy") });
        encoder.copy_texture_to_texture(
            frame.output.texture.as_image_copy(),
            frame.display.as_image_copy(),
            frame.output.texture.size(),
        );
        gpu.queue.submit([encoder.finish()]);
        let elapsed = timed.then(|| {
            gpu.wait();
            start.elapsed()
        });
        if self.bound != Some((size, filter)) {
            egui_renderer.update_egui_texture_from_wgpu_texture(
                &gpu.device,
                &frame.display_view,
                filter,
                self.texture_id,
            );
            self.bound = Some((size, filter));
        }
        (self.texture_id, elapsed)
    }

    fn sized_targets(&self, gpu: &Gpu, size: (u32, u32)) -> SizedTargets {
        let targets = FrameTargets::new(&gpu.device, size);
        // The renderer remakes the targets itself when `raster.render_scale` asks for less.
        let output = GpuTexture::target(&gpu.device, "viewer::raster::output", size, OUTPUT_FORMAT);
        let display = display_texture(&gpu.device, size);
        let display_view = display.create_view(&wgpu::TextureViewDescriptor {
            label: Some("viewer::raster::display_view"),
            ..Default::default()
        });
        SizedTargets { size, targets, output, display, display_view }
    }

    /// The last rendered image, read back (sRGB RGBA8, as `mirador render` writes it).
    pub fn read_back(&self, gpu: &Gpu) -> Option<image::RgbaImage> {
        let frame = self.frame.as_ref()?;
        let pixels = readback::read_rgba8(&gpu.device, &gpu.queue, &frame.output.texture).ok()?;
        image::RgbaImage::from_raw(frame.size.0, frame.size.1, pixels)
    }
}

/// The texture egui samples: the raster image's bytes, not decoded.
fn display_texture(device: &wgpu::Device, size: (u32, u32)) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("viewer::raster::display"),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: DISPLAY_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}
