//! The opaque pass: the z-buffer algorithm. Every fragment of every opaque surface is depth-tested
//! against the nearest so far; the survivor is shaded by the illumination model
//! (`shaders/common/lighting.wgsl`) for all lights, into the linear HDR target.
//!
//! No back-face culling: planes are two-sided, and the shader turns the normal to the viewer.

use super::scene_gpu::{SceneGpu, SceneLayouts};
use super::uniforms::Vertex;
use super::{DEPTH_FORMAT, HDR_FORMAT};
use crate::shaders;

pub struct OpaquePass {
    pipeline: wgpu::RenderPipeline,
}

/// What the pass draws into.
pub struct OpaqueTargets<'a> {
    pub hdr: &'a wgpu::TextureView,
    pub depth: &'a wgpu::TextureView,
    /// Linear radiance where nothing is drawn.
    pub background: glam::Vec3,
}

impl OpaquePass {
    pub fn new(device: &wgpu::Device, layouts: &SceneLayouts) -> OpaquePass {
        let module = shaders::module(device, "opaque::shader", shaders::OPAQUE);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("opaque::layout"),
            bind_group_layouts: &layouts.all(),
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("opaque::pipeline"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_opaque"),
                compilation_options: Default::default(),
                buffers: &[Some(Vertex::layout())],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_opaque"),
                compilation_options: Default::default(),
                targets: &[Some(HDR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        OpaquePass { pipeline }
    }

    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, scene: &SceneGpu, targets: &OpaqueTargets) {
        let bg = targets.background.as_dvec3();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("opaque::pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: targets.hdr,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r: bg.x, g: bg.y, b: bg.z, a: 1.0 }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: targets.depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.push_debug_group("opaque");
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &scene.frame_group, &[]);
        for drawable in &scene.drawables {
            pass.set_bind_group(1, &scene.materials[drawable.material], &[]);
            pass.set_bind_group(2, &drawable.object, &[]);
            pass.set_vertex_buffer(0, drawable.vertices.slice(..));
            pass.set_index_buffer(drawable.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..drawable.index_count, 0, 0..1);
        }
        pass.pop_debug_group();
    }
}
