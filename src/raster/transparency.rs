//! Transparent surfaces in sorted Z order (TECHNIQUES.md §5; seed 000 §1.4). A z-buffer cannot
//! bend rays, so the rasterizer takes `n_i = n_t` (the ray goes straight through) and draws:
//!
//! 1. every opaque surface, depth written (the scene pass);
//! 2. then every transparent surface in Z order, farthest first, depth tested against the opaque
//!    surfaces but not written, each pixel updated as `I = Im + kt·Mt·I`, where `Im` is the
//!    illumination model at the transparent surface and `I` what the pixel held.
//!
//! # The blend
//!
//! The fragment shader (`shaders/transparency.wgsl`) returns `Im`; the blend state computes
//! `Im·1 + I·kt·Mt`: source factor `One`, destination factor the blend constant, set to the
//! material's `kt·Mt` before each draw. Usual alpha blending, `I = α·C + (1 − α)·I`, is the same
//! formula with `Im = α·C` and `kt·Mt = 1 − α` (grey): that is how alpha-blended materials (glTF's
//! `BLEND`) are drawn. Where their `α` varies per pixel (a texture's alpha) the shader returns
//! `(α·Im, α)` and the destination factor is `OneMinusSrcAlpha`; a material with both a coloured
//! `kt·Mt` and a per-pixel `α` would need dual-source blending and gets `1 − α` alone (see
//! docs/scene-format.md).
//!
//! # The order
//!
//! Over two panes the formula gives `I_z + Mt1·I_y + Mt1·Mt2·I_x` only when the far pane is
//! drawn first; [`TransparencySort`] picks how the order is found:
//! - `unsorted`: the scene's order, to show the error;
//! - `object`: objects farthest first by their bounding box's centre along the view axis, each
//!   drawn twice, back faces then front faces (so a glass sphere shows its far wall through its
//!   near one); wrong where objects interleave;
//! - `triangle`: every transparent triangle farthest first by its centroid, re-sorted on the CPU
//!   whenever the view moves; wrong only for intersecting or cyclically overlapping triangles;
//! - `exact`: depth peeling, back to front. Peel `k` keeps, at every pixel, the farthest
//!   transparent fragment nearer than both the opaque surface and peel `k − 1` (a depth-only pass
//!   testing `Greater`); a second pass shades that layer with the same blend, testing `Equal`.
//!   `peel_layers` peels are drawn; a pixel with more layers loses the nearest ones.
//!
//! Ties keep the scene's order (stable sorts), so coplanar surfaces do not flicker.
//!
//! # Against the ray tracer
//! The tracer refracts for real (`ior`); with `ior = 1` its rays go straight through too, and its
//! image and the exactly ordered one agree (tests/transparency.rs). Transparent surfaces receive
//! shadows like any other; as casters they tint the shadow maps' transmission layers.

use std::collections::HashMap;
use std::ops::Range;
use std::time::{Duration, Instant};

use glam::{Mat3, Mat4, Vec3};
use wgpu::util::DeviceExt;

use super::geometry::{TransparentObject, build_mesh};
use super::scene_gpu::SceneGpu;
use super::scene_pass::{FrameKey, MaterialKey, ScenePass, constants, vertex_state};
use super::uniforms::{ALPHA_BLEND, GpuInstance, Vertex};
use super::view::{View, ViewSlot};
use super::{DEPTH_FORMAT, FrameTargets, HDR_FORMAT};
use crate::gpu::layout;
use crate::gpu::texture::GpuTexture;
use crate::scene::Scene;
use crate::settings::{TransparencySettings, TransparencySort};
use crate::texture::tangents::tangents_or_generate;

/// How the blend finds `kt·Mt`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Blend {
    /// The material's `kt·Mt`, one constant per draw.
    Constant,
    /// `1 − α`, with the fragment's coverage `α` in the source alpha.
    Coverage,
}

/// Which faces a draw keeps, in the view's terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Faces {
    Both,
    /// Facing away from the viewer: an object's far walls.
    Back,
    /// Facing the viewer.
    Front,
}

/// The depth test of a transparent draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Depth {
    /// Nearer than the opaque surface; nothing written.
    Less,
    /// Exactly at the peeled layer's depth (depth peeling's shading pass).
    Equal,
}

type PipelineKey = (Blend, Faces, Depth, FrameKey, MaterialKey);

/// What one frame of the pass did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TransparencyReport {
    /// Transparent draws recorded (per object, per run of one material, or per peel).
    pub draws: u32,
    /// The triangles were sorted anew this frame, and how long the CPU took.
    pub sorted: bool,
    pub sort_time: Duration,
    /// Layers peeled (the exact order).
    pub layers: u32,
}

/// One draw of the pass.
enum Draw {
    /// One object's triangles, or only its back or front faces; `winding` is the faces in terms
    /// of the triangles' winding (swapped where the object's transform or the view mirrors).
    Object { object: usize, winding: Faces },
    /// A run of sorted triangles of one material, from the triangle list in `order`'s order.
    Triangles { material: usize, indices: Range<u32>, order: ViewSlot },
}

pub struct TransparencyPass {
    peel_group_layout: wgpu::BindGroupLayout,
    peel_layout: wgpu::PipelineLayout,
    pipelines: HashMap<PipelineKey, wgpu::RenderPipeline>,
    peel_pipelines: HashMap<MaterialKey, wgpu::RenderPipeline>,
    /// Peel depths for each set of frame targets drawn into (the main view's, mirrored views').
    peel: Vec<PeelTargets>,
    triangles: Option<TriangleList>,
}

impl TransparencyPass {
    pub fn new(device: &wgpu::Device, scene_layouts: &super::scene_gpu::SceneLayouts) -> TransparencyPass {
        let depth = |binding| layout::texture(binding, wgpu::TextureSampleType::Depth, wgpu::TextureViewDimension::D2);
        let peel_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("transparency::peel_group_layout"),
            entries: &[depth(0), depth(1)],
        });
        let peel_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("transparency::peel_layout"),
            bind_group_layouts: &[
                Some(&scene_layouts.frame),
                Some(&scene_layouts.material),
                Some(&scene_layouts.lighting),
                Some(&peel_group_layout),
            ],
            immediate_size: 0,
        });
        TransparencyPass {
            peel_group_layout,
            peel_layout,
            pipelines: HashMap::new(),
            peel_pipelines: HashMap::new(),
            peel: Vec::new(),
            triangles: None,
        }
    }

    /// Draws the transparent surfaces of `scene_gpu` seen from `view` (in `slot`) over the opaque
    /// image and depth of `targets`, in the order `settings` asks for.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene_pass: &ScenePass,
        scene: &Scene,
        scene_gpu: &SceneGpu,
        lighting: &wgpu::BindGroup,
        frame: FrameKey,
        (slot, view): (ViewSlot, &View),
        targets: &FrameTargets,
        settings: &TransparencySettings,
        skip: Option<usize>,
    ) -> TransparencyReport {
        let mut report = TransparencyReport::default();
        if scene_gpu.geometry.transparent.is_empty() {
            return report;
        }
        let forward = -view.view_axis;
        let objects = &scene_gpu.geometry.transparent;
        let object_draw = |object: usize, faces: Faces| Draw::Object {
            object,
            winding: if objects[object].flipped != view.mirrored { faces.swapped() } else { faces },
        };
        // An environment cube's views leave out the object they are drawn from (sorted per object).
        let kept = (0..objects.len()).filter(|&i| Some(objects[i].object) != skip);
        let sort = if skip.is_some() { TransparencySort::Object } else { settings.sort };
        let draws: Vec<Draw> = match sort {
            TransparencySort::Unsorted => kept.map(|object| object_draw(object, Faces::Both)).collect(),
            TransparencySort::Object => {
                let mut order: Vec<usize> = kept.collect();
                // Farthest first; a stable sort keeps the scene's order between equals.
                order.sort_by(|&a, &b| {
                    let depth = |i: usize| (objects[i].centre - view.eye).dot(forward);
                    depth(b).total_cmp(&depth(a))
                });
                order
                    .into_iter()
                    .flat_map(|object| [object_draw(object, Faces::Back), object_draw(object, Faces::Front)])
                    .collect()
            }
            TransparencySort::Triangle => {
                let version = scene_gpu.geometry.version();
                if self.triangles.as_ref().is_none_or(|t| t.geometry != version) {
                    self.triangles = Some(TriangleList::new(device, scene, &scene_gpu.geometry.transparent, version));
                }
                let list = self.triangles.as_mut().expect("made just above");
                let start = Instant::now();
                report.sorted = list.sort(device, queue, slot, view.eye, forward);
                report.sort_time = start.elapsed();
                list.orders[&slot]
                    .runs
                    .iter()
                    .map(|(material, indices)| Draw::Triangles {
                        material: *material,
                        indices: indices.clone(),
                        order: slot,
                    })
                    .collect()
            }
            TransparencySort::Exact => {
                report.layers = settings.peel_layers;
                report.draws = self.record_peeled(
                    device,
                    encoder,
                    scene_pass,
                    scene_gpu,
                    lighting,
                    frame,
                    slot,
                    targets,
                    settings.peel_layers,
                );
                return report;
            }
        };
        self.prepare(device, scene_pass, scene_gpu, frame, &draws, Depth::Less);
        let mut pass = begin(encoder, "transparency::sorted", targets, &targets.depth.view);
        pass.set_bind_group(0, scene_gpu.frame_group(), &[scene_gpu.views.offset(slot)]);
        pass.set_bind_group(2, lighting, &[]);
        for draw in &draws {
            self.record_draw(&mut pass, scene_gpu, frame, draw, Depth::Less);
            report.draws += 1;
        }
        report
    }

    /// Compiles the pipelines `draws` need that were not compiled before.
    fn prepare(
        &mut self,
        device: &wgpu::Device,
        scene_pass: &ScenePass,
        scene_gpu: &SceneGpu,
        frame: FrameKey,
        draws: &[Draw],
        depth: Depth,
    ) {
        for draw in draws {
            let key = self.key(scene_gpu, frame, draw, depth);
            self.pipelines.entry(key).or_insert_with(|| shading_pipeline(device, scene_pass, key));
        }
    }

    fn key(&self, scene_gpu: &SceneGpu, frame: FrameKey, draw: &Draw, depth: Depth) -> PipelineKey {
        let (material, faces) = match *draw {
            Draw::Object { object, winding } => (scene_gpu.geometry.transparent[object].material, winding),
            Draw::Triangles { material, .. } => (material, Faces::Both),
        };
        let key = scene_gpu.material_keys[material];
        let blend = if key.alpha_mode == ALPHA_BLEND && key.color_texture { Blend::Coverage } else { Blend::Constant };
        (blend, faces, depth, frame, key)
    }

    fn record_draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene_gpu: &SceneGpu,
        frame: FrameKey,
        draw: &Draw,
        depth: Depth,
    ) {
        let key = self.key(scene_gpu, frame, draw, depth);
        pass.set_pipeline(&self.pipelines[&key]);
        let material = match *draw {
            Draw::Object { object, .. } => scene_gpu.geometry.transparent[object].material,
            Draw::Triangles { material, .. } => material,
        };
        let t = scene_gpu.transmittance[material].as_dvec3();
        pass.set_blend_constant(wgpu::Color { r: t.x, g: t.y, b: t.z, a: 1.0 });
        pass.set_bind_group(1, &scene_gpu.materials()[material], &[]);
        match draw {
            Draw::Object { object, .. } => {
                let object: &TransparentObject = &scene_gpu.geometry.transparent[*object];
                scene_gpu.geometry.draw_instances(pass, object.mesh, object.instance..object.instance + 1);
            }
            Draw::Triangles { indices, order, .. } => {
                let list = self.triangles.as_ref().expect("sorted before drawing");
                pass.set_vertex_buffer(0, list.vertices.slice(..));
                pass.set_vertex_buffer(1, list.identity.slice(..));
                pass.set_index_buffer(list.orders[order].indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(indices.clone(), 0, 0..1);
            }
        }
    }

    /// The exact order: `layers` peels from the back, each a depth pass and a shading pass.
    /// Returns the draws recorded.
    #[allow(clippy::too_many_arguments)]
    fn record_peeled(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene_pass: &ScenePass,
        scene_gpu: &SceneGpu,
        lighting: &wgpu::BindGroup,
        frame: FrameKey,
        slot: ViewSlot,
        targets: &FrameTargets,
        layers: u32,
    ) -> u32 {
        let objects = &scene_gpu.geometry.transparent;
        let draws: Vec<Draw> = (0..objects.len()).map(|object| Draw::Object { object, winding: Faces::Both }).collect();
        self.prepare(device, scene_pass, scene_gpu, frame, &draws, Depth::Equal);
        for object in objects {
            let key = scene_gpu.material_keys[object.material];
            if !self.peel_pipelines.contains_key(&key) {
                let pipeline = peel_pipeline(device, scene_pass, &self.peel_layout, frame, key);
                self.peel_pipelines.insert(key, pipeline);
            }
        }
        let index = match self.peel.iter().position(|p| p.for_targets == targets.generation) {
            Some(index) => index,
            None => {
                // Targets are remade on resize: forget the peels of targets that are gone.
                if self.peel.len() > 2 * super::view::MAX_MIRROR_VIEWS as usize {
                    self.peel.clear();
                }
                self.peel.push(PeelTargets::new(device, &self.peel_group_layout, targets));
                self.peel.len() - 1
            }
        };
        let peel = &self.peel[index];
        let view_offset = [scene_gpu.views.offset(slot)];
        let mut recorded = 0;
        for layer in 0..layers as usize {
            let depth = &peel.depth[layer % 2].view;
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("transparency::peel"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(layout::depth_attachment(depth, wgpu::LoadOp::Clear(0.0))),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                scissor(&mut pass, targets);
                pass.set_bind_group(0, scene_gpu.frame_group(), &view_offset);
                pass.set_bind_group(2, lighting, &[]);
                // Layer 0 peels below the opaque depth alone; layer k below layer k − 1 too.
                let limits = if layer == 0 { &peel.first } else { &peel.below[(layer - 1) % 2] };
                pass.set_bind_group(3, limits, &[]);
                for object in objects {
                    pass.set_pipeline(&self.peel_pipelines[&scene_gpu.material_keys[object.material]]);
                    pass.set_bind_group(1, &scene_gpu.materials()[object.material], &[]);
                    scene_gpu.geometry.draw_instances(&mut pass, object.mesh, object.instance..object.instance + 1);
                }
            }
            let mut pass = begin(encoder, "transparency::peeled_layer", targets, depth);
            pass.set_bind_group(0, scene_gpu.frame_group(), &view_offset);
            pass.set_bind_group(2, lighting, &[]);
            for draw in &draws {
                self.record_draw(&mut pass, scene_gpu, frame, draw, Depth::Equal);
            }
            recorded += 2 * objects.len() as u32;
        }
        recorded
    }
}

impl Faces {
    /// The same faces for an object whose transform mirrors it (its winding flipped).
    fn swapped(self) -> Faces {
        match self {
            Faces::Both => Faces::Both,
            Faces::Back => Faces::Front,
            Faces::Front => Faces::Back,
        }
    }
}

/// A render pass over the frame's colour, testing against `depth` without writing it, inside
/// the targets' scissor.
fn begin<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &'static str,
    targets: &FrameTargets,
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(layout::color_attachment(&targets.hdr.view, wgpu::LoadOp::Load))],
        depth_stencil_attachment: Some(layout::depth_attachment(depth, wgpu::LoadOp::Load)),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    scissor(&mut pass, targets);
    pass
}

/// Limits `pass` to the targets' scissor, if they have one.
fn scissor(pass: &mut wgpu::RenderPass<'_>, targets: &FrameTargets) {
    if let Some([x, y, width, height]) = targets.scissor {
        pass.set_scissor_rect(x, y, width, height);
    }
}

/// `I = Im + kt·Mt·I`; the target's alpha is left as it is.
fn blend_state(blend: Blend) -> wgpu::BlendState {
    let dst_factor = match blend {
        Blend::Constant => wgpu::BlendFactor::Constant,
        Blend::Coverage => wgpu::BlendFactor::OneMinusSrcAlpha,
    };
    wgpu::BlendState {
        color: wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor,
            operation: wgpu::BlendOperation::Add,
        },
        alpha: wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Zero,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        },
    }
}

fn shading_pipeline(device: &wgpu::Device, scene_pass: &ScenePass, key: PipelineKey) -> wgpu::RenderPipeline {
    let (blend, faces, depth, frame, material) = key;
    let constants = constants(&frame, &material);
    let cull_mode = match faces {
        Faces::Both => None,
        Faces::Back => Some(wgpu::Face::Front),
        Faces::Front => Some(wgpu::Face::Back),
    };
    let compare = match depth {
        Depth::Less => wgpu::CompareFunction::Less,
        Depth::Equal => wgpu::CompareFunction::Equal,
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("transparency::shading_pipeline"),
        layout: Some(scene_pass.layout()),
        vertex: vertex_state(scene_pass.module()),
        primitive: wgpu::PrimitiveState { cull_mode, ..Default::default() },
        depth_stencil: layout::depth_test(DEPTH_FORMAT, compare, false),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: scene_pass.module(),
            entry_point: Some("fs_transparent"),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            targets: &[Some(wgpu::ColorTargetState {
                format: HDR_FORMAT,
                blend: Some(blend_state(blend)),
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The depth-only pass of one peel: the farthest surviving fragment wins (`Greater`, cleared to 0).
fn peel_pipeline(
    device: &wgpu::Device,
    scene_pass: &ScenePass,
    peel_layout: &wgpu::PipelineLayout,
    frame: FrameKey,
    material: MaterialKey,
) -> wgpu::RenderPipeline {
    let constants = constants(&frame, &material);
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("transparency::peel_pipeline"),
        layout: Some(peel_layout),
        vertex: vertex_state(scene_pass.module()),
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Greater, true),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: scene_pass.module(),
            entry_point: Some("fs_peel"),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Two peel depths, written and read in turn, and the bind groups that read them.
struct PeelTargets {
    depth: [GpuTexture; 2],
    /// Layer 0's limits: the opaque depth (twice).
    first: wgpu::BindGroup,
    /// Layer k's limits: the opaque depth and peel `(k − 1) % 2`.
    below: [wgpu::BindGroup; 2],
    for_targets: u64,
}

impl PeelTargets {
    fn new(device: &wgpu::Device, group_layout: &wgpu::BindGroupLayout, targets: &FrameTargets) -> PeelTargets {
        let depth = [0, 1]
            .map(|i| GpuTexture::target(device, &format!("transparency::peel_depth {i}"), targets.size, DEPTH_FORMAT));
        let group = |previous: &wgpu::TextureView| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("transparency::peel_group"),
                layout: group_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&targets.depth.view),
                    },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(previous) },
                ],
            })
        };
        let first = group(&targets.depth.view);
        let below = [group(&depth[0].view), group(&depth[1].view)];
        PeelTargets { depth, first, below, for_targets: targets.generation }
    }
}

/// Every transparent triangle in world space, for sorting one by one: the vertices once, and for
/// each view an index buffer rewritten in sorted order whenever that view moves. (One buffer per
/// view: buffer writes land before the frame's commands run, so views sharing one would all draw
/// the last view's order.)
struct TriangleList {
    geometry: u64,
    vertices: wgpu::Buffer,
    /// One identity instance: the vertices are already in world space.
    identity: wgpu::Buffer,
    triangles: Vec<[u32; 3]>,
    centroids: Vec<Vec3>,
    materials: Vec<usize>,
    /// Per view slot, its order.
    orders: HashMap<ViewSlot, SortedOrder>,
}

/// The triangles in one view's order.
struct SortedOrder {
    indices: wgpu::Buffer,
    /// The (eye, forward) the order was sorted for.
    sorted_for: (Vec3, Vec3),
    /// Runs of one material in the sorted index buffer.
    runs: Vec<(usize, Range<u32>)>,
}

impl TriangleList {
    fn new(device: &wgpu::Device, scene: &Scene, objects: &[TransparentObject], geometry: u64) -> TriangleList {
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        let mut centroids = Vec::new();
        let mut materials = Vec::new();
        for object in objects {
            let mesh = build_mesh(scene, object.mesh);
            let existing = (!mesh.tangents.is_empty()).then_some(mesh.tangents.as_slice());
            let tangents = tangents_or_generate(&mesh, existing);
            let normal_from_mesh = Mat3::from_mat4(object.world_from_mesh).inverse().transpose();
            let base = vertices.len() as u32;
            for (i, t) in tangents.iter().enumerate() {
                vertices.push(Vertex {
                    position: object.world_from_mesh.transform_point3(mesh.positions[i]).to_array(),
                    normal: (normal_from_mesh * mesh.normals[i]).to_array(),
                    uv: mesh.uvs[i].to_array(),
                    tangent: object.world_from_mesh.transform_vector3(t.truncate()).extend(t.w).to_array(),
                });
            }
            for triangle in mesh.indices.chunks_exact(3) {
                let corners = [triangle[0], triangle[1], triangle[2]].map(|i| i + base);
                let centroid =
                    corners.iter().map(|&i| Vec3::from_array(vertices[i as usize].position)).sum::<Vec3>() / 3.0;
                triangles.push(corners);
                centroids.push(centroid);
                materials.push(object.material);
            }
        }
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        TriangleList {
            geometry,
            vertices: buffer("transparency::vertices", bytemuck::cast_slice(&vertices), wgpu::BufferUsages::VERTEX),
            identity: buffer(
                "transparency::identity_instance",
                bytemuck::bytes_of(&GpuInstance::new(Mat4::IDENTITY, super::uniforms::ENV_LAYER_WORLD)),
                wgpu::BufferUsages::VERTEX,
            ),
            triangles,
            centroids,
            materials,
            orders: HashMap::new(),
        }
    }

    /// Sorts the triangles farthest first along `forward` from `eye` for the view in `slot`,
    /// unless they already are. Returns whether it sorted.
    fn sort(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, slot: ViewSlot, eye: Vec3, forward: Vec3) -> bool {
        if self.orders.get(&slot).is_some_and(|o| o.sorted_for == (eye, forward)) {
            return false;
        }
        let order = sorted_far_first(&self.centroids, eye, forward);
        let indices: Vec<[u32; 3]> = order.iter().map(|&t| self.triangles[t as usize]).collect();
        let mut runs: Vec<(usize, Range<u32>)> = Vec::new();
        for (position, &t) in order.iter().enumerate() {
            let material = self.materials[t as usize];
            let index = position as u32 * 3;
            match runs.last_mut() {
                Some((m, range)) if *m == material => range.end = index + 3,
                _ => runs.push((material, index..index + 3)),
            }
        }
        match self.orders.get_mut(&slot) {
            Some(existing) => {
                queue.write_buffer(&existing.indices, 0, bytemuck::cast_slice(&indices));
                existing.sorted_for = (eye, forward);
                existing.runs = runs;
            }
            None => {
                let indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("transparency::sorted_indices"),
                    contents: bytemuck::cast_slice(&indices),
                    usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
                });
                self.orders.insert(slot, SortedOrder { indices, sorted_for: (eye, forward), runs });
            }
        }
        true
    }
}

/// Indices of `points` ordered farthest first by their depth `(p − eye)·forward`; equal depths
/// keep their order (a stable sort), so coplanar triangles keep the scene's order every frame.
pub fn sorted_far_first(points: &[Vec3], eye: Vec3, forward: Vec3) -> Vec<u32> {
    let depths: Vec<f32> = points.iter().map(|p| (*p - eye).dot(forward)).collect();
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.sort_by(|&a, &b| depths[b as usize].total_cmp(&depths[a as usize]));
    order
}
