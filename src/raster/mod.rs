//! The z-buffer renderer. Each technique is one pass (one file here, one WGSL file of the same
//! name in `shaders/`); [`Renderer::render`] records them in order, top to bottom:
//!
//! ```text
//! shadow maps (pass 1 of §4)  ─┐
//! or projected shadow polygons ┴→ opaque (z-buffer + illumination model + pass 2 of §4)
//!                                 → teaching views → present (output transform to sRGB)
//! ```
//!
//! Later techniques slot in where DESIGN.md puts them: environment captures and mirror views
//! before `opaque`; the sky and sorted transparent surfaces after it.

pub mod opaque;
pub mod present;
pub mod scene_gpu;
pub mod shadow;
pub mod uniforms;

use crate::gpu::mipmap::MipmapGenerator;
use crate::gpu::texture::GpuTexture;
use crate::gpu::{Gpu, readback};
use crate::scene::Scene;
use crate::settings::{RenderSettings, ShadowMethod};
use opaque::{OpaquePass, OpaqueTargets};
use present::PresentPass;
use scene_gpu::{SceneGpu, SceneLayouts};
use shadow::ShadowPass;
use shadow::projected::{MASK_FORMAT, ProjectedPass, projected_shadows};
use shadow::views::shadow_layout;

/// Linear radiance, before the output transform.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The format of offscreen screenshots.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The passes, built once per device and output format.
pub struct Renderer {
    pub layouts: SceneLayouts,
    pub mipmaps: MipmapGenerator,
    pub shadow: ShadowPass,
    projected: ProjectedPass,
    opaque: OpaquePass,
    present: PresentPass,
    /// The opaque pass's shadow inputs, and the (shadow targets, frame targets) generations they
    /// were made for.
    shadow_inputs: Option<((u64, u64), wgpu::BindGroup)>,
}

/// The intermediate images of a frame, recreated when the output size changes.
pub struct FrameTargets {
    pub size: (u32, u32),
    pub hdr: GpuTexture,
    pub depth: GpuTexture,
    /// Object-precision shadows: one channel per shadowed light.
    pub shadow_mask: GpuTexture,
    present_input: wgpu::BindGroup,
    generation: u64,
}

impl Renderer {
    pub fn new(device: &wgpu::Device, output_format: wgpu::TextureFormat) -> Renderer {
        let layouts = SceneLayouts::new(device);
        let shadow = ShadowPass::new(device, &layouts);
        let opaque = OpaquePass::new(device, &layouts, &shadow.input_layout);
        Renderer {
            mipmaps: MipmapGenerator::new(device),
            projected: ProjectedPass::new(device),
            present: PresentPass::new(device, output_format),
            layouts,
            shadow,
            opaque,
            shadow_inputs: None,
        }
    }

    pub fn upload(&self, gpu: &Gpu, scene: &Scene) -> SceneGpu {
        SceneGpu::upload(gpu, &self.layouts, &self.mipmaps, scene)
    }

    pub fn targets(&self, device: &wgpu::Device, size: (u32, u32)) -> FrameTargets {
        static GENERATION: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let hdr = GpuTexture::target(device, "frame::hdr", size, HDR_FORMAT);
        let depth = GpuTexture::target(device, "frame::depth", size, DEPTH_FORMAT);
        let shadow_mask = GpuTexture::target(device, "frame::shadow_mask", size, MASK_FORMAT);
        let present_input = self.present.bind(device, &hdr.view);
        let generation = GENERATION.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        FrameTargets { size, hdr, depth, shadow_mask, present_input, generation }
    }

    /// Records and submits one frame of `scene` into `output`, whose size must match `targets`.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &Scene,
        scene_gpu: &mut SceneGpu,
        settings: &RenderSettings,
        targets: &FrameTargets,
        output: &wgpu::TextureView,
    ) {
        let (device, queue) = (&gpu.device, &gpu.queue);
        scene_gpu.prepare_materials(device, &self.layouts, &settings.textures);
        let scene_gpu = &*scene_gpu;
        let frame_group = scene_gpu.frame_group();
        let shadows = &settings.shadows;
        let layout = shadow_layout(scene, shadows);
        scene_gpu.update_frame(gpu, scene, &layout.first_layer, settings);
        self.shadow.prepare(device, queue, &layout, shadows, scene_gpu.has_transparent());
        let key = (self.shadow.generation, targets.generation);
        if self.shadow_inputs.as_ref().is_none_or(|(k, _)| *k != key) {
            self.shadow_inputs = Some((key, self.shadow.inputs(device, &targets.shadow_mask.view)));
        }
        let (_, shadow_inputs) = self.shadow_inputs.as_ref().expect("made just above");

        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame::encoder") });
        let projected = shadows.enabled && shadows.method == ShadowMethod::Projected;
        if projected {
            let polygons = projected_shadows(scene, &layout);
            self.opaque.record_prepass(&mut encoder, scene_gpu, frame_group, shadow_inputs, &targets.depth.view);
            let clip_from_world = scene.camera.clip_from_world();
            self.projected.record(
                device,
                queue,
                &mut encoder,
                &polygons,
                clip_from_world,
                &targets.shadow_mask.view,
                &targets.depth.view,
            );
        } else {
            self.shadow.record(&mut encoder, scene_gpu, &layout);
        }
        self.opaque.record(
            &mut encoder,
            scene_gpu,
            frame_group,
            shadow_inputs,
            &OpaqueTargets { hdr: &targets.hdr.view, depth: &targets.depth.view, background: scene.background },
            projected,
        );
        self.shadow.record_views(gpu, &mut encoder, shadows, &layout, scene.camera.clip_from_world(), targets);
        self.present.record(queue, &mut encoder, &targets.present_input, output, settings.exposure);
        queue.submit([encoder.finish()]);
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

    pub fn render(&mut self, gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
        self.renderer.render(gpu, scene, &mut self.scene_gpu, settings, &self.targets, &self.output.view);
        let (width, height) = self.targets.size;
        let pixels =
            readback::read_rgba8(&gpu.device, &gpu.queue, &self.output.texture).expect("reading the frame back");
        image::RgbaImage::from_raw(width, height, pixels).expect("readback returns width × height RGBA8 pixels")
    }
}

/// Renders `scene` once, headless, with `settings`.
pub fn render_image(gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    Headless::new(gpu, scene).render(gpu, scene, settings)
}
