//! The 3D view's image stretched over the view while the camera moves (`shaders/upscale.wgsl`).
//!
//! A moving frame is drawn at the render scale, the camera's image size included, so the
//! rasterizer's work (tessellation by size on screen, every pass's pixels) shrinks with it; this
//! pass then fills the view's rectangle of the window from the small image, bilinearly, between
//! its sRGB-encoded values. At full scale the image is copied instead, byte for byte.
//!
//! Why not the present pass's own upscale (`raster.render_scale`): it reads four half-float texels
//! and runs the tone curve at every window pixel, where this pass reads one 8-bit texel; and the
//! camera's size would stay the window's, tessellating for pixels that are not drawn.

use crate::gpu::layout;

pub(in crate::viewer) struct Upscale {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    /// The group reading the last image stretched, kept while that image is.
    input: Option<(wgpu::TextureView, wgpu::BindGroup)>,
}

/// A rectangle of the target, in pixels: `x, y, width, height`.
pub(in crate::viewer) type Viewport = [u32; 4];

impl Upscale {
    /// A pass writing targets of `format`, which must be a plain (not sRGB) format, like the
    /// image views it reads: the bytes move unchanged.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Upscale {
        let (pipeline, layout) = image_pipeline(device, "fs_upscale", format);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("upscale::sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Upscale { pipeline, layout, sampler, input: None }
    }

    /// Stretches `image` (a plain view) over `viewport` of `target`, keeping the rest of it.
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        image: &wgpu::TextureView,
        target: &wgpu::TextureView,
        [x, y, width, height]: Viewport,
    ) {
        let group = image_group(&mut self.input, device, (&self.layout, &self.sampler), image, "upscale::bind_group");
        let mut pass = encoder.begin_render_pass(&layout::pass(
            "upscale::pass",
            &[Some(layout::color_attachment(target, wgpu::LoadOp::Load))],
            None,
        ));
        pass.push_debug_group("upscale");
        pass.set_viewport(x as f32, y as f32, width as f32, height as f32, 0.0, 1.0);
        pass.set_scissor_rect(x, y, width, height);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
        pass.pop_debug_group();
    }
}

/// The upscale shader's `fragment` writing `format`, and the layout of the image it reads.
fn image_pipeline(
    device: &wgpu::Device,
    fragment: &str,
    format: wgpu::TextureFormat,
) -> (wgpu::RenderPipeline, wgpu::BindGroupLayout) {
    let module = crate::shaders::module(device, "upscale::shader", crate::shaders::UPSCALE);
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("upscale::bind_group_layout"),
        entries: &[
            layout::texture(0, wgpu::TextureSampleType::Float { filterable: true }, wgpu::TextureViewDimension::D2),
            layout::sampler(1, wgpu::SamplerBindingType::Filtering),
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("upscale::layout"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = layout::fullscreen_pipeline(
        device,
        "upscale::pipeline",
        &pipeline_layout,
        &module,
        ("vs_upscale", fragment),
        &[Some(format.into())],
    );
    (pipeline, layout)
}

/// The 3D view's sRGB image drawn, byte for byte, into the plain texture egui shows, where the
/// device cannot copy between the two (WebGL2: `glCopyTexSubImage2D` refuses an sRGB source for
/// a plain target). Elsewhere a copy does it.
pub(in crate::viewer) struct Reencode {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    /// The group reading the last image drawn, kept while that image is.
    input: Option<(wgpu::TextureView, wgpu::BindGroup)>,
}

impl Reencode {
    /// A pass writing `target_format`, a plain 8-bit format.
    pub fn new(device: &wgpu::Device, target_format: wgpu::TextureFormat) -> Reencode {
        let (pipeline, layout) = image_pipeline(device, "fs_reencode", target_format);
        let sampler =
            device.create_sampler(&wgpu::SamplerDescriptor { label: Some("upscale::reencode"), ..Default::default() });
        Reencode { pipeline, layout, sampler, input: None }
    }

    /// Draws `image` (an sRGB view) into `target` (a plain view of the same size).
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        image: &wgpu::TextureView,
        target: &wgpu::TextureView,
    ) {
        let group =
            image_group(&mut self.input, device, (&self.layout, &self.sampler), image, "upscale::reencode_group");
        let mut pass = encoder.begin_render_pass(&layout::pass(
            "upscale::reencode",
            &[Some(layout::color_attachment(target, wgpu::LoadOp::Clear(wgpu::Color::BLACK)))],
            None,
        ));
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// The bind group that reads `image` with `sampler`, made when `image` is not the one `kept` was
/// made for, and kept while it stays the same (the view's image changes only with its size).
fn image_group<'a>(
    kept: &'a mut Option<(wgpu::TextureView, wgpu::BindGroup)>,
    device: &wgpu::Device,
    (layout, sampler): (&wgpu::BindGroupLayout, &wgpu::Sampler),
    image: &wgpu::TextureView,
    label: &str,
) -> &'a wgpu::BindGroup {
    if kept.as_ref().is_none_or(|(view, _)| view != image) {
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(image) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(sampler) },
            ],
        });
        *kept = Some((image.clone(), group));
    }
    &kept.as_ref().expect("made just above").1
}
