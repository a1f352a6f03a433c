//! The opaque pass: the z-buffer algorithm. Every fragment of every opaque surface is depth-tested
//! against the nearest so far; the survivor is shaded by the illumination model
//! (`shaders/common/lighting.wgsl`) for all lights, each weighted by its visibility from the
//! shadow pass, into the linear HDR target.
//!
//! No back-face culling: planes are two-sided, and the shader turns the normal to the viewer.
//! When object-precision shadows are on, a depth-only prepass runs first (the shadow polygons
//! are depth-tested against it), and the shading pass then only accepts the prepass's depths.

use super::scene_gpu::{SceneGpu, SceneLayouts};
use super::uniforms::Vertex;
use super::{DEPTH_FORMAT, HDR_FORMAT};
use crate::gpu::layout;
use crate::shaders;

pub struct OpaquePass {
    /// Depth test `Less` and depth writes: the plain z-buffer.
    shade: wgpu::RenderPipeline,
    /// After a prepass: depth test `LessEqual` on the prepass's depths, no writes.
    shade_after_prepass: wgpu::RenderPipeline,
    prepass: wgpu::RenderPipeline,
}

/// What the pass draws into.
pub struct OpaqueTargets<'a> {
    pub hdr: &'a wgpu::TextureView,
    pub depth: &'a wgpu::TextureView,
    /// Linear radiance where nothing is drawn.
    pub background: glam::Vec3,
}

fn depth_state(compare: wgpu::CompareFunction, write: bool) -> Option<wgpu::DepthStencilState> {
    layout::depth_test(DEPTH_FORMAT, compare, write)
}

impl OpaquePass {
    pub fn new(device: &wgpu::Device, layouts: &SceneLayouts, shadow_inputs: &wgpu::BindGroupLayout) -> OpaquePass {
        let module = shaders::module(device, "opaque::shader", shaders::OPAQUE);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("opaque::layout"),
            bind_group_layouts: &[
                Some(&layouts.frame),
                Some(&layouts.material),
                Some(&layouts.object),
                Some(shadow_inputs),
            ],
            immediate_size: 0,
        });
        let vertex = wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_opaque"),
            compilation_options: Default::default(),
            buffers: &[Some(Vertex::LAYOUT)],
        };
        let hdr_target = [Some(HDR_FORMAT.into())];
        let pipeline = |label: &str, depth: Option<wgpu::DepthStencilState>, shaded: bool| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: vertex.clone(),
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: depth,
                multisample: Default::default(),
                fragment: shaded.then(|| wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_opaque"),
                    compilation_options: Default::default(),
                    targets: &hdr_target,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        OpaquePass {
            shade: pipeline("opaque::pipeline", depth_state(wgpu::CompareFunction::Less, true), true),
            shade_after_prepass: pipeline(
                "opaque::pipeline_after_prepass",
                depth_state(wgpu::CompareFunction::LessEqual, false),
                true,
            ),
            prepass: pipeline("opaque::prepass_pipeline", depth_state(wgpu::CompareFunction::Less, true), false),
        }
    }

    /// The depth of the nearest opaque surface at every pixel, and nothing else.
    pub fn record_prepass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        frame_group: &wgpu::BindGroup,
        shadow_inputs: &wgpu::BindGroup,
        depth: &wgpu::TextureView,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("opaque::prepass"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.push_debug_group("opaque depth prepass");
        pass.set_pipeline(&self.prepass);
        draw_all(&mut pass, scene, frame_group, shadow_inputs);
        pass.pop_debug_group();
    }

    /// Shades every opaque surface; `after_prepass` when [`Self::record_prepass`] already filled
    /// the depth buffer this frame.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        frame_group: &wgpu::BindGroup,
        shadow_inputs: &wgpu::BindGroup,
        targets: &OpaqueTargets,
        after_prepass: bool,
    ) {
        let bg = targets.background.as_dvec3();
        let depth_load = if after_prepass { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(1.0) };
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
                depth_ops: Some(wgpu::Operations { load: depth_load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.push_debug_group("opaque");
        pass.set_pipeline(if after_prepass { &self.shade_after_prepass } else { &self.shade });
        draw_all(&mut pass, scene, frame_group, shadow_inputs);
        pass.pop_debug_group();
    }
}

fn draw_all(
    pass: &mut wgpu::RenderPass<'_>,
    scene: &SceneGpu,
    frame_group: &wgpu::BindGroup,
    shadow_inputs: &wgpu::BindGroup,
) {
    pass.set_bind_group(0, frame_group, &[]);
    pass.set_bind_group(3, shadow_inputs, &[]);
    for drawable in &scene.drawables {
        pass.set_bind_group(1, &scene.materials()[drawable.material], &[]);
        pass.set_bind_group(2, &drawable.object, &[]);
        pass.set_vertex_buffer(0, drawable.vertices.slice(..));
        pass.set_index_buffer(drawable.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..drawable.index_count, 0, 0..1);
    }
}
