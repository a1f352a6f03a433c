//! Copies of a depth image, made by drawing rather than by `copy_texture_to_texture`.
//!
//! A pass that writes the depth it also reads (isosurfaces end their rays at the view's depth and
//! write their own) or that reads the depth as an earlier phase left it (screen-space refraction)
//! reads a copy. wgpu's GL backend cannot copy a depth texture: it reads the source through a
//! colour attachment, GL refuses (`GL_INVALID_FRAMEBUFFER_OPERATION`) and the copy stays empty.
//! So the copy is drawn: one fullscreen triangle whose fragments `textureLoad` the source's depth,
//! bound as unfilterable floats ([`layout::depth_texels`]), and write it as their `frag_depth`
//! into an image of the source's format, tested `Always` (`shaders/depth_copy.wgsl`). A depth
//! written is stored as given, so the copy equals what a texture copy gives, bit for bit, and its
//! readers bind it as they bind any depth image. (An `R32Float` colour copy would do the same
//! where float colour is renderable; llvmpipe's GL context does not offer it to wgpu.)
//!
//! Limits: single-sampled 2D depth images of one level, without stencil; a depth outside
//! `[0, 1]` would be clamped (Mirador's never is).

use super::layout;
use super::texture::GpuTexture;
use crate::shaders;

/// The pipeline that draws depth copies of one format. Made once per pass that copies.
pub struct DepthCopy {
    format: wgpu::TextureFormat,
    group_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

/// The copy of one depth image: the image it is drawn into and the group that reads the source.
pub struct DepthImageCopy {
    pub image: GpuTexture,
    group: wgpu::BindGroup,
}

impl DepthCopy {
    /// The copier of depth images of `format` (a float depth format without stencil).
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> DepthCopy {
        let module = shaders::module(device, "depth_copy::shader", shaders::DEPTH_COPY);
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth_copy::group_layout"),
            entries: &[layout::depth_texels(0, wgpu::TextureViewDimension::D2)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth_copy::pipeline_layout"),
            bind_group_layouts: &[Some(&group_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("depth_copy::pipeline"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_depth_copy"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: layout::depth_test(format, wgpu::CompareFunction::Always, true),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_depth_copy"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        DepthCopy { format, group_layout, pipeline }
    }

    /// An image of `size` texels for copies of `source` (a depth image of that size and of the
    /// copier's format), called `label`.
    pub fn image_for(
        &self,
        device: &wgpu::Device,
        label: &str,
        source: &wgpu::TextureView,
        size: (u32, u32),
    ) -> DepthImageCopy {
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("depth_copy::group"),
            layout: &self.group_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(source) }],
        });
        DepthImageCopy { image: GpuTexture::target(device, label, size, self.format), group }
    }

    /// Copies the source's depth as it is now into `copy`'s image. Every texel is drawn, so the
    /// image's old contents are not loaded.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, copy: &DepthImageCopy) {
        let mut pass = encoder.begin_render_pass(&layout::pass(
            "depth_copy::pass",
            &[],
            Some(layout::depth_attachment(&copy.image.view, wgpu::LoadOp::Clear(1.0))),
        ));
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &copy.group, &[]);
        pass.draw(0..3, 0..1);
    }
}
