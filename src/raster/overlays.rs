//! Teaching overlays drawn over the shaded HDR image, before the output transform: a shadow map
//! layer as grey levels (near black, far white), and lines in the scene, depth tested against the
//! frame: the lights' and mirrored cameras' view volumes (`shadows.view = "map"`,
//! `shadows.show_frusta`, `mirrors.view = "camera"`) and the volumes' grid cells
//! (`volume.wireframe`). They read what the passes made and change nothing the techniques
//! compute.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use super::context::{Figure, FrameContext, FrameEncoder};
use super::scene_gpu::SceneLayouts;
use super::shadow::ShadowMaps;
use super::shadow::views::ShadowLayout;
use super::targets::{DEPTH_FORMAT, FrameTargets, HDR_FORMAT};
use super::view::ViewTargets;
use crate::gpu::layout;
use crate::gpu::uniform::UniformBuffer;
use crate::settings::ShadowView;
use crate::shaders;

pub struct Overlays {
    module: wgpu::ShaderModule,
    /// Made on first use: GL cannot read a depth texture without comparing it, so there this
    /// one view fails (with a clear error) while every other pass runs.
    map_view: std::cell::OnceCell<MapView>,
    lines: Lines,
}

/// The colour of view volumes' edges.
pub const FRUSTUM_COLOUR: Vec3 = Vec3::new(1.0, 0.8, 0.1);
/// The colour of the volumes' grid wireframe.
pub const WIREFRAME_COLOUR: Vec3 = Vec3::new(0.2, 0.85, 1.0);
/// The colour of the meshes' triangle edges (`bump.view = "tessellation"`).
pub const TESSELLATION_COLOUR: Vec3 = Vec3::new(0.1, 1.0, 0.3);
/// The most edges the tessellation view draws: past them, a mesh's are skipped (said in the log).
const MAX_EDGES: usize = 3_000_000;

/// Every edge of every mesh object's triangles (a displaced surface is one), once, as world-space
/// segments: the tessellation view (`bump.view = "tessellation"`). `adaptive` holds the objects
/// whose triangles the GPU made this frame (their CPU twin, in world coordinates), drawn instead
/// of their own mesh. Analytic shapes are left out: the rasterizer tessellates them by their size
/// on screen, frame by frame.
pub fn mesh_edges(scene: &crate::Scene, adaptive: &[(usize, crate::scene::Mesh)]) -> Vec<Vec3> {
    let mut lines = Vec::new();
    for (index, object) in scene.objects.iter().enumerate() {
        let (mesh, world_from_mesh) = match adaptive.iter().find(|(o, _)| *o == index) {
            Some((_, mesh)) => (mesh, glam::Mat4::IDENTITY),
            None => {
                let crate::scene::Shape::Mesh(mesh) = object.shape else { continue };
                let Some(mesh) = scene.meshes.get(mesh) else { continue };
                (mesh, object.world_from_local)
            }
        };
        let mut edges: Vec<(u32, u32)> = mesh
            .indices
            .chunks_exact(3)
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        if lines.len() / 2 + edges.len() > MAX_EDGES {
            log::warn!("the tessellation view draws at most {MAX_EDGES} edges: `{}`'s are left out", object.name);
            continue;
        }
        // Lifted off the surface along the normals by a thousandth of the mesh's size, so that the
        // depth test keeps the edges in front of the triangles they bound (not half of them).
        let (low, high) =
            mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| (l.min(*p), h.max(*p)));
        let lift = 1e-3 * (high - low).length();
        let world = |i: u32| {
            let p = *mesh.positions.get(i as usize)?;
            let n = mesh.normals.get(i as usize).copied().unwrap_or(Vec3::ZERO);
            Some(world_from_mesh.transform_point3(p + lift * n))
        };
        for (a, b) in edges {
            if let (Some(a), Some(b)) = (world(a), world(b)) {
                lines.extend([a, b]);
            }
        }
    }
    lines
}

impl Overlays {
    pub fn new(device: &wgpu::Device, scene_layouts: &SceneLayouts) -> Overlays {
        let module = shaders::module(device, "overlays::shader", shaders::OVERLAYS);
        let lines = Lines::new(device, &module, scene_layouts);
        Overlays { module, map_view: std::cell::OnceCell::new(), lines }
    }

    /// Draws the shadow technique's overlays that the settings ask for over the view's image:
    /// a map layer, the lights' frusta.
    pub fn record_shadows(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        (view, targets): ViewTargets<'_>,
        (layout, maps): (&ShadowLayout, &ShadowMaps),
    ) {
        let settings = &ctx.settings.shadows;
        if layout.views.is_empty() {
            return;
        }
        if settings.view == ShadowView::Map {
            // A layer past the last shows the last; the figures say which, of how many.
            let layers = layout.views.len() as u32;
            let layer = settings.view_layer.min(layers - 1);
            let ratio = layout.views[layer as usize].depth_ratio;
            let map_view = self.map_view.get_or_init(|| MapView::new(ctx.device(), &self.module));
            map_view.record(ctx, frame, maps.depth, (layer, ratio), targets);
            let figures = [("map layer shown", Figure::Count(layer.into())), ("layers", Figure::Count(layers.into()))];
            frame.end("overlays", &figures);
        }
        if settings.show_frusta {
            let volumes: Vec<[Vec3; 8]> = (0..layout.views.len()).map(|layer| layout.corners(layer)).collect();
            self.record_lines(ctx, frame, (view, targets), &box_edges(&volumes), FRUSTUM_COLOUR);
        }
    }

    /// Draws `lines` (world-space segments, two points each) in `colour` into the scene as `view`
    /// sees it, depth tested against its targets (not written).
    pub fn record_lines(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        (view, targets): ViewTargets<'_>,
        lines: &[Vec3],
        colour: Vec3,
    ) {
        if !lines.is_empty() {
            self.lines.record(ctx, frame, (view, targets), lines, colour);
            frame.end("overlays", &[]);
        }
    }
}

/// The twelve edges of each box or frustum of `volumes` (eight corners, as
/// `view::frustum_corners` orders them), as line segments.
pub fn box_edges(volumes: &[[Vec3; 8]]) -> Vec<Vec3> {
    const EDGES: [(usize, usize); 12] =
        [(0, 1), (2, 3), (0, 2), (1, 3), (4, 5), (6, 7), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];
    volumes.iter().flat_map(|corners| EDGES.into_iter().flat_map(move |(a, b)| [corners[a], corners[b]])).collect()
}

/// One map layer drawn over the image as grey levels.
struct MapView {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: UniformBuffer<GpuShownLayer>,
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
                layout::depth_texels(1, wgpu::TextureViewDimension::D2Array),
                layout::uniform(2, wgpu::ShaderStages::FRAGMENT),
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
        MapView { pipeline, layout, uniform }
    }

    fn record(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        maps: &wgpu::TextureView,
        (layer, depth_ratio): (u32, f32),
        targets: &FrameTargets,
    ) {
        let size = targets.size;
        self.uniform.write(ctx.queue(), &GpuShownLayer { layer, width: size.0, height: size.1, depth_ratio });
        // A teaching view, drawn only while it is on: a bind group made here costs nothing when off.
        let group = ctx.device().create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("overlays::map_view_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(maps) },
                wgpu::BindGroupEntry { binding: 2, resource: self.uniform.binding() },
            ],
        });
        let hdr = &targets.hdr.view;
        let mut pass = frame.encoder.begin_render_pass(&layout::pass(
            "overlays::map_view_pass",
            &[Some(layout::color_attachment(hdr, wgpu::LoadOp::Load))],
            None,
        ));
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// Line segments drawn into the scene from the main view, in one colour.
struct Lines {
    pipeline: wgpu::RenderPipeline,
}

impl Lines {
    fn new(device: &wgpu::Device, module: &wgpu::ShaderModule, scene_layouts: &SceneLayouts) -> Lines {
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("overlays::lines_pipeline_layout"),
            bind_group_layouts: &[Some(&scene_layouts.frame)],
            immediate_size: 0,
        });
        let buffer = |step_mode, attributes| wgpu::VertexBufferLayout { array_stride: 12, step_mode, attributes };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("overlays::lines_pipeline"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_lines"),
                compilation_options: Default::default(),
                // Positions per vertex; the colour per instance, so one value serves every line.
                buffers: &[
                    Some(buffer(wgpu::VertexStepMode::Vertex, &wgpu::vertex_attr_array![0 => Float32x3])),
                    Some(buffer(wgpu::VertexStepMode::Instance, &wgpu::vertex_attr_array![1 => Float32x3])),
                ],
            },
            primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::LineList, ..Default::default() },
            depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::LessEqual, false),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_lines"),
                compilation_options: Default::default(),
                targets: &[Some(HDR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Lines { pipeline }
    }

    fn record(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        (view, targets): ViewTargets<'_>,
        lines: &[Vec3],
        colour: Vec3,
    ) {
        let device = ctx.device();
        let scene = ctx.scene_gpu;
        // A teaching view, drawn only while it is on: buffers made here cost nothing when off.
        let buffer = |label, contents: &[Vec3]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(contents),
                usage: wgpu::BufferUsages::VERTEX,
            })
        };
        let vertices = buffer("overlays::lines_vertices", lines);
        let colour = buffer("overlays::lines_colour", &[colour]);
        let mut pass = frame.encoder.begin_render_pass(&layout::pass(
            "overlays::lines_pass",
            &[Some(layout::color_attachment(&targets.hdr.view, wgpu::LoadOp::Load))],
            Some(layout::depth_attachment(&targets.depth.view, wgpu::LoadOp::Load)),
        ));
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, scene.frame_group(), &[scene.views.offset(view.slot)]);
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.set_vertex_buffer(1, colour.slice(..));
        pass.draw(0..lines.len() as u32, 0..1);
    }
}
