//! Teaching overlays drawn over the shaded HDR image, before the output transform: a shadow map
//! layer as grey levels (near black, far white), and the lights' view volumes as lines in the
//! scene (`shadows.view = "map"`, `shadows.show_frusta`). They read what the passes made and
//! change nothing the techniques compute.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use super::scene_gpu::{SceneGpu, SceneLayouts};
use super::shadow::ShadowMaps;
use super::shadow::views::ShadowLayout;
use super::view::ViewSlot;
use super::{DEPTH_FORMAT, FrameTargets, HDR_FORMAT};
use crate::gpu::layout;
use crate::gpu::uniform::UniformBuffer;
use crate::settings::{ShadowSettings, ShadowView};
use crate::shaders;

pub struct Overlays {
    module: wgpu::ShaderModule,
    /// Made on first use: GL cannot read a depth texture without comparing it, so there this
    /// one view fails (with a clear error) while every other pass runs.
    map_view: std::cell::OnceCell<MapView>,
    frusta: Frusta,
}

impl Overlays {
    pub fn new(device: &wgpu::Device, scene_layouts: &SceneLayouts) -> Overlays {
        let module = shaders::module(device, "overlays::shader", shaders::OVERLAYS);
        let frusta = Frusta::new(device, &module, scene_layouts);
        Overlays { module, map_view: std::cell::OnceCell::new(), frusta }
    }

    /// Draws the overlays that `settings` asks for over `frame`'s HDR image.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        settings: &ShadowSettings,
        scene: &SceneGpu,
        layout: &ShadowLayout,
        maps: &ShadowMaps,
        frame: &FrameTargets,
    ) {
        if layout.views.is_empty() {
            return;
        }
        if settings.view == ShadowView::Map {
            let layer = settings.view_layer.min(layout.views.len() as u32 - 1);
            let ratio = layout.views[layer as usize].depth_ratio;
            let map_view = self.map_view.get_or_init(|| MapView::new(device, &self.module));
            map_view.record(device, queue, encoder, maps.depth, layer, ratio, frame.size, &frame.hdr.view);
        }
        if settings.show_frusta {
            let volumes: Vec<[Vec3; 8]> = (0..layout.views.len()).map(|layer| layout.corners(layer)).collect();
            self.frusta.record(device, encoder, scene, &volumes, &frame.hdr.view, &frame.depth.view);
        }
    }
}

impl Overlays {
    /// Draws the edges of each of `volumes` (eight corners, as `view::frustum_corners` orders
    /// them) into the scene: the mirrored cameras' view volumes (`mirrors.view = "camera"`).
    pub fn record_volumes(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        volumes: &[[Vec3; 8]],
        frame: &FrameTargets,
    ) {
        self.frusta.record(device, encoder, scene, volumes, &frame.hdr.view, &frame.depth.view);
    }
}

/// One map layer drawn over the image as grey levels.
struct MapView {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: UniformBuffer<GpuShownLayer>,
    sampler: wgpu::Sampler,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct GpuShownLayer {
    layer: u32,
    width: u32,
    height: u32,
    depth_ratio: f32,
}

impl MapView {
    fn new(device: &wgpu::Device, module: &wgpu::ShaderModule) -> MapView {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("overlays::map_view_layout"),
            entries: &[
                layout::texture(1, wgpu::TextureSampleType::Depth, wgpu::TextureViewDimension::D2Array),
                layout::uniform(2, wgpu::ShaderStages::FRAGMENT),
                layout::sampler(3, wgpu::SamplerBindingType::NonFiltering),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("overlays::map_view_pipeline_layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = layout::fullscreen_pipeline(
            device,
            "overlays::map_view_pipeline",
            &pipeline_layout,
            module,
            ("vs_shadow_map_view", "fs_shadow_map_view"),
            &[Some(HDR_FORMAT.into())],
        );
        let uniform = UniformBuffer::new(device, "overlays::map_view_uniform", &GpuShownLayer::zeroed());
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("overlays::map_view_sampler"),
            ..Default::default()
        });
        MapView { pipeline, layout, uniform, sampler }
    }

    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        maps: &wgpu::TextureView,
        layer: u32,
        depth_ratio: f32,
        size: (u32, u32),
        hdr: &wgpu::TextureView,
    ) {
        self.uniform.write(queue, &GpuShownLayer { layer, width: size.0, height: size.1, depth_ratio });
        // A teaching view, drawn only while it is on: a bind group made here costs nothing when off.
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("overlays::map_view_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(maps) },
                wgpu::BindGroupEntry { binding: 2, resource: self.uniform.binding() },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&self.sampler) },
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("overlays::map_view_pass"),
            color_attachments: &[Some(layout::color_attachment(hdr, wgpu::LoadOp::Load))],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// The edges of each light view's volume, drawn into the scene from the main view.
struct Frusta {
    pipeline: wgpu::RenderPipeline,
}

impl Frusta {
    fn new(device: &wgpu::Device, module: &wgpu::ShaderModule, scene_layouts: &SceneLayouts) -> Frusta {
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("overlays::frusta_pipeline_layout"),
            bind_group_layouts: &[Some(&scene_layouts.frame)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("overlays::frusta_pipeline"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_frustum"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 12,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3],
                })],
            },
            primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::LineList, ..Default::default() },
            depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::LessEqual, false),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_frustum"),
                compilation_options: Default::default(),
                targets: &[Some(HDR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Frusta { pipeline }
    }

    fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        volumes: &[[Vec3; 8]],
        hdr: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) {
        const EDGES: [(usize, usize); 12] =
            [(0, 1), (2, 3), (0, 2), (1, 3), (4, 5), (6, 7), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];
        let lines: Vec<Vec3> = volumes
            .iter()
            .flat_map(|corners| EDGES.into_iter().flat_map(move |(a, b)| [corners[a], corners[b]]))
            .collect();
        // A teaching view, drawn only while it is on: a buffer made here costs nothing when off.
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("overlays::frusta_vertices"),
            contents: bytemuck::cast_slice(&lines),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("overlays::frusta_pass"),
            color_attachments: &[Some(layout::color_attachment(hdr, wgpu::LoadOp::Load))],
            depth_stencil_attachment: Some(layout::depth_attachment(depth, wgpu::LoadOp::Load)),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, scene.frame_group(), &[scene.views.offset(ViewSlot::Main)]);
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.draw(0..lines.len() as u32, 0..1);
    }
}
