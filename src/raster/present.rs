//! The present pass: the output transform of `src/output.rs` on the GPU. Reads the linear HDR
//! target texel for texel, applies exposure and the tone curve, and writes an sRGB target (a window's
//! surface, or an offscreen texture for screenshots), whose format does the sRGB encoding. A frame
//! drawn at a render scale below 1 is upscaled here (bilinear), so the viewer can trade
//! resolution for frame rate while the camera moves.

use super::context::FrameEncoder;
use super::uniforms::GpuPresent;
use crate::gpu::uniform::UniformBuffer;
use crate::gpu::{Gpu, layout};
use crate::output::OutputTransform;
use crate::settings::ToneMap;
use crate::shaders;
use crate::shaders::constants::{TONE_MAP_ACES, TONE_MAP_CLAMP, TONE_MAP_PBR_NEUTRAL, TONE_MAP_REINHARD};

pub struct PresentPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: UniformBuffer<GpuPresent>,
    /// The group reading the last HDR image presented, kept while that image is.
    input: Option<(wgpu::TextureView, wgpu::BindGroup)>,
}

impl PresentPass {
    /// `output_format` must be an sRGB format, so the hardware encodes.
    pub fn new(device: &wgpu::Device, output_format: wgpu::TextureFormat) -> PresentPass {
        debug_assert!(output_format.is_srgb(), "the present pass relies on an sRGB target to encode");
        let module = shaders::module(device, "present::shader", shaders::PRESENT);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("present::bind_group_layout"),
            entries: &[
                layout::texture(
                    0,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
                layout::uniform(1, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("present::layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = layout::fullscreen_pipeline(
            device,
            "present::pipeline",
            &pipeline_layout,
            &module,
            ("vs_present", "fs_present"),
            &[Some(output_format.into())],
        );
        let uniform =
            UniformBuffer::new(device, "present::uniform", &GpuPresent { exposure: 1.0, tone_map: 0, scale: [1.0; 2] });
        PresentPass { pipeline, layout, uniform, input: None }
    }

    /// Draws the HDR image `hdr` through the output transform into `output`.
    pub fn record(
        &mut self,
        gpu: &Gpu,
        frame: &mut FrameEncoder,
        hdr: &wgpu::TextureView,
        output: &wgpu::TextureView,
        transform: OutputTransform,
    ) {
        if self.input.as_ref().is_none_or(|(view, _)| view != hdr) {
            let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("present::bind_group"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(hdr) },
                    wgpu::BindGroupEntry { binding: 1, resource: self.uniform.binding() },
                ],
            });
            self.input = Some((hdr.clone(), group));
        }
        let (_, group) = self.input.as_ref().expect("made just above");
        let (input, out) = (hdr.texture().size(), output.texture().size());
        let scale = [input.width as f32 / out.width as f32, input.height as f32 / out.height as f32];
        let tone_map = tone_map_code(transform.tone_map);
        self.uniform.write(&gpu.queue, &GpuPresent { exposure: transform.exposure, tone_map, scale });
        let mut pass = frame.encoder.begin_render_pass(&layout::pass(
            "present::pass",
            &[Some(layout::color_attachment(output, wgpu::LoadOp::Clear(wgpu::Color::BLACK)))],
            None,
        ));
        pass.push_debug_group("present");
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
        pass.pop_debug_group();
        drop(pass);
        frame.end("present", &[]);
    }
}

/// `TONE_MAP_*` of `shaders/present.wgsl`: the curve the shader runs.
pub fn tone_map_code(curve: ToneMap) -> u32 {
    match curve {
        ToneMap::Clamp => TONE_MAP_CLAMP,
        ToneMap::Reinhard => TONE_MAP_REINHARD,
        ToneMap::Aces => TONE_MAP_ACES,
        ToneMap::PbrNeutral => TONE_MAP_PBR_NEUTRAL,
    }
}
