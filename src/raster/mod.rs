//! The z-buffer renderer. Each technique is one pass (one file here, one WGSL file of the same
//! name in `shaders/`); [`Renderer::render`] records them in order, top to bottom:
//!
//! ```text
//! opaque (z-buffer + illumination model) → present (output transform to sRGB)
//! ```
//!
//! Later techniques slot in where DESIGN.md puts them: shadow maps, environment captures and
//! mirror views before `opaque`; the sky and sorted transparent surfaces after it.

pub mod opaque;
pub mod present;
pub mod scene_gpu;
pub mod uniforms;

use crate::gpu::texture::GpuTexture;
use crate::gpu::{Gpu, readback};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use opaque::{OpaquePass, OpaqueTargets};
use present::PresentPass;
use scene_gpu::{SceneGpu, SceneLayouts};

/// Linear radiance, before the output transform.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The format of offscreen screenshots.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The passes, built once per device and output format.
pub struct Renderer {
    pub layouts: SceneLayouts,
    opaque: OpaquePass,
    present: PresentPass,
}

/// The intermediate images of a frame, recreated when the output size changes.
pub struct FrameTargets {
    pub size: (u32, u32),
    pub hdr: GpuTexture,
    pub depth: GpuTexture,
    present_input: wgpu::BindGroup,
}

impl Renderer {
    pub fn new(device: &wgpu::Device, output_format: wgpu::TextureFormat) -> Renderer {
        let layouts = SceneLayouts::new(device);
        let opaque = OpaquePass::new(device, &layouts);
        let present = PresentPass::new(device, output_format);
        Renderer { layouts, opaque, present }
    }

    pub fn upload(&self, gpu: &Gpu, scene: &Scene) -> SceneGpu {
        SceneGpu::upload(gpu, &self.layouts, scene)
    }

    pub fn targets(&self, device: &wgpu::Device, size: (u32, u32)) -> FrameTargets {
        let hdr = GpuTexture::target(device, "frame::hdr", size, HDR_FORMAT);
        let depth = GpuTexture::target(device, "frame::depth", size, DEPTH_FORMAT);
        let present_input = self.present.bind(device, &hdr.view);
        FrameTargets { size, hdr, depth, present_input }
    }

    /// Records and submits one frame of `scene` into `output`, whose size must match `targets`.
    pub fn render(
        &self,
        gpu: &Gpu,
        scene: &Scene,
        scene_gpu: &SceneGpu,
        settings: &RenderSettings,
        targets: &FrameTargets,
        output: &wgpu::TextureView,
    ) {
        scene_gpu.update_frame(gpu, scene, settings);
        let mut encoder =
            gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame::encoder") });
        self.opaque.record(
            &mut encoder,
            scene_gpu,
            &OpaqueTargets { hdr: &targets.hdr.view, depth: &targets.depth.view, background: scene.background },
        );
        self.present.record(&gpu.queue, &mut encoder, &targets.present_input, output, settings.exposure);
        gpu.queue.submit([encoder.finish()]);
    }
}

/// A headless frame: renders `scene` at its camera's size and reads it back as sRGB RGBA8.
/// The same passes the viewer runs, drawn into an offscreen texture.
pub struct Headless {
    pub renderer: Renderer,
    pub scene_gpu: SceneGpu,
    pub targets: FrameTargets,
    pub output: GpuTexture,
}

impl Headless {
    pub fn new(gpu: &Gpu, scene: &Scene) -> Headless {
        let renderer = Renderer::new(&gpu.device, OUTPUT_FORMAT);
        let scene_gpu = renderer.upload(gpu, scene);
        let size = (scene.camera.width, scene.camera.height);
        let targets = renderer.targets(&gpu.device, size);
        let output = GpuTexture::target(&gpu.device, "frame::output", size, OUTPUT_FORMAT);
        Headless { renderer, scene_gpu, targets, output }
    }

    pub fn render(&self, gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
        self.renderer.render(gpu, scene, &self.scene_gpu, settings, &self.targets, &self.output.view);
        let (width, height) = self.targets.size;
        let pixels = readback::read_rgba8(&gpu.device, &gpu.queue, &self.output.texture);
        image::RgbaImage::from_raw(width, height, pixels).expect("readback returns width × height RGBA8 pixels")
    }
}

/// Renders `scene` once, headless, with `settings`.
pub fn render_image(gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    Headless::new(gpu, scene).render(gpu, scene, settings)
}
