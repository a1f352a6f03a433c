//! The z-buffer renderer. Each technique is one pass (one file or folder here, one WGSL file of
//! the same name in `shaders/`); the frame ([`frame`]) plans what to draw and records every view
//! with the same phases. Three layers, each importing only from those before it:
//!
//! - **data**: what the passes read and share: [`targets`], [`keys`], [`uniforms`], [`view`],
//!   [`view_group`] (what a view's shading reads), [`geometry`], [`scene_gpu`] (the scene's
//!   buffers, textures, bind groups and the scene shader), [`context`] (the frame context,
//!   encoder and report);
//! - **passes**: [`shadow`], [`scene_pass`], [`refraction`], [`transparency`], [`volume`],
//!   [`mirror`], [`environment`], [`overlays`], [`present`], [`inspect`], each owning what it
//!   keeps per scene and per target, with a `prepare` that hands out what can record;
//! - **frame**: [`frame`] (the plan, [`Renderer`], and the one function that draws a view).

pub mod context;
pub mod environment;
pub mod frame;
pub mod geometry;
pub mod inspect;
pub mod keys;
pub mod mirror;
pub mod overlays;
pub mod present;
pub mod refraction;
pub mod scene_gpu;
pub mod scene_pass;
pub mod shadow;
pub mod targets;
pub mod tessellation;
pub mod traced;
pub mod transparency;
pub mod uniforms;
pub mod view;
pub mod view_group;
pub mod volume;

pub use context::{Figure, FrameReport, PassReport};
pub use frame::Renderer;
pub use targets::{DEPTH_FORMAT, FrameTargets, HDR_FORMAT, OUTPUT_FORMAT, drawn_size};

use crate::gpu::texture::GpuTexture;
use crate::gpu::{Gpu, readback};
use crate::scene::Scene;
use crate::settings::RenderSettings;

/// A headless frame: renders `scene` at its camera's size and reads it back as sRGB RGBA8.
/// The same passes the viewer runs, drawn into an offscreen texture.
pub struct Headless {
    pub renderer: Renderer,
    pub targets: FrameTargets,
    pub output: GpuTexture,
    /// What the last frame did.
    pub report: FrameReport,
}

impl Headless {
    pub fn new(gpu: &Gpu, scene: &Scene) -> Headless {
        Headless::with_renderer(gpu, scene, Renderer::new(gpu, scene, OUTPUT_FORMAT))
    }

    /// A headless renderer whose passes compile `wgsl` (a lab's functions: src/lab).
    pub fn with_wgsl(gpu: &Gpu, scene: &Scene, wgsl: crate::shaders::Wgsl) -> Headless {
        Headless::with_renderer(gpu, scene, Renderer::with_wgsl(gpu, scene, OUTPUT_FORMAT, wgsl, false))
    }

    fn with_renderer(gpu: &Gpu, scene: &Scene, renderer: Renderer) -> Headless {
        let size = (scene.camera.width, scene.camera.height);
        let targets = FrameTargets::new(&gpu.device, drawn_size(size, scene.settings.raster.render_scale));
        let output = GpuTexture::target(&gpu.device, "frame::output", size, OUTPUT_FORMAT);
        Headless { renderer, targets, output, report: FrameReport::default() }
    }

    pub fn render(&mut self, gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
        self.report = self.renderer.render(gpu, scene, settings, &mut self.targets, &self.output.view);
        let size = self.output.texture.size();
        let (width, height) = (size.width, size.height);
        let pixels =
            readback::read_rgba8(&gpu.device, &gpu.queue, &self.output.texture).expect("reading the frame back");
        image::RgbaImage::from_raw(width, height, pixels).expect("readback returns width × height RGBA8 pixels")
    }

    /// [`Headless::render`] without blocking: the frame is submitted and its readback started
    /// here; the image comes when the returned readback is awaited ([`readback::Pending::texels`]).
    /// The page's lab checks draw this way.
    pub fn render_later(
        &mut self,
        gpu: &Gpu,
        scene: &Scene,
        settings: &RenderSettings,
    ) -> Result<readback::Pending, readback::ReadbackError> {
        self.report = self.renderer.render(gpu, scene, settings, &mut self.targets, &self.output.view);
        readback::Pending::start(&gpu.device, &gpu.queue, &self.output.texture, 4)
    }
}

/// Renders `scene` once, headless, with `settings`.
pub fn render_image(gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    Headless::new(gpu, scene).render(gpu, scene, settings)
}
