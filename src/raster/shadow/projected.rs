//! Cast shadows at object precision (docs/course/05-shadows.md#shadow-maps-image-precision, "algoritmo de fuerza bruta"): for every pair
//! of a caster polygon `P` and a planar receiver `Q`, the shadow polygon `S` that `P` casts on
//! `Q`'s plane from the light, clipped by `Q` (Sutherland–Hodgman). The results are detail
//! polygons in which the light is not visible (drawn by `shaders/shadow_projected.wgsl`).
//!
//! Projection from a light at `y` onto the plane `n·x = d`, with heights `h(x) = n·x − d`:
//! `x' = y + (x − y)·h(y)/(h(y) − h(x))`; for a directional light travelling along `D`:
//! `x' = x − D·h(x)/(n·D)`. Only the part of a caster between the light and the plane casts, so
//! each triangle is first clipped to that slab.
//!
//! Limits, as the notes say: quadratic cost (every caster triangle against every receiver), and
//! receivers must be planar: here, the scene's `plane` objects. Transparent casters are skipped
//! (their coloured shadows need the shadow-map method). A light in the receiver's plane, or a
//! directional light parallel to it, casts nothing on it.
//!
//! The polygons depend on the lights and the objects, not on the camera: they are computed once
//! and kept until a light or the scene's geometry changes.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use super::views::ShadowLayout;
use crate::gpu::layout;
use crate::raster::context::{Figure, FrameContext, FrameEncoder};
use crate::raster::geometry::DrawListId;
use crate::raster::scene_gpu::SceneLayouts;
use crate::raster::targets::{DEPTH_FORMAT, FrameTargets, ViewImage};
use crate::raster::view::FrameView;
use crate::scene::{Light, LightKind, Scene, Shape};
use crate::shaders;

/// A convex shadow polygon on a receiver, for the shadowed light in mask channel `slot`.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowPolygon {
    pub slot: u32,
    pub points: Vec<Vec3>,
}

/// Keeps the part of a convex polygon where `inside(x) ≥ 0`, `inside` being affine in `x`.
fn clip(polygon: &[Vec3], inside: impl Fn(Vec3) -> f32) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(polygon.len() + 2);
    for (k, &a) in polygon.iter().enumerate() {
        let b = polygon[(k + 1) % polygon.len()];
        let (fa, fb) = (inside(a), inside(b));
        if fa >= 0.0 {
            out.push(a);
        }
        if (fa >= 0.0) != (fb >= 0.0) {
            out.push(a + (b - a) * (fa / (fa - fb)));
        }
    }
    out
}

/// A planar receiver: its corners counter-clockwise seen from `normal`.
struct Receiver {
    object: usize,
    corners: [Vec3; 4],
    normal: Vec3,
    offset: f32,
}

/// Whether `object` receives projected shadows: the notes' receivers are planar, here the
/// scene's `plane` objects.
pub fn is_receiver(object: &crate::scene::Object) -> bool {
    matches!(object.shape, Shape::Plane { .. })
}

fn receivers(scene: &Scene) -> Vec<Receiver> {
    scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(index, object)| {
            let Shape::Plane { size, .. } = object.shape else { return None };
            let (hx, hz) = (size.x / 2.0, size.y / 2.0);
            let local =
                [Vec3::new(-hx, 0.0, hz), Vec3::new(hx, 0.0, hz), Vec3::new(hx, 0.0, -hz), Vec3::new(-hx, 0.0, -hz)];
            let corners = local.map(|p| object.world_from_local.transform_point3(p));
            let normal = (corners[1] - corners[0]).cross(corners[3] - corners[0]).try_normalize()?;
            Some(Receiver { object: index, corners, normal, offset: normal.dot(corners[0]) })
        })
        .collect()
}

/// Every shadow polygon of every shadowed light on every planar receiver.
pub fn projected_shadows(scene: &Scene, layout: &ShadowLayout) -> Vec<ShadowPolygon> {
    let receivers = receivers(scene);
    let casters: Vec<(usize, Vec<[Vec3; 3]>)> = scene
        .objects
        .iter()
        .enumerate()
        .filter(|(_, o)| !scene.materials[o.material.0].is_transparent())
        .map(|(index, object)| {
            let mesh = scene.tessellate(object);
            let triangles = mesh
                .indices
                .chunks_exact(3)
                .map(|t| {
                    [t[0], t[1], t[2]].map(|i| object.world_from_local.transform_point3(mesh.positions[i as usize]))
                })
                .collect();
            (index, triangles)
        })
        .collect();
    let mut polygons = Vec::new();
    let mut slot = 0;
    for (light_index, first_layer) in layout.first_layer.iter().enumerate() {
        if first_layer.is_none() {
            continue;
        }
        let kind = scene.lights[light_index].kind;
        for receiver in &receivers {
            let height = |x: Vec3| receiver.normal.dot(x) - receiver.offset;
            // Which side of the receiver is lit, and how a point projects onto its plane.
            let (side, light_height) = match kind {
                LightKind::Point { position } | LightKind::Spot { position, .. } => {
                    (height(position).signum(), height(position))
                }
                LightKind::Directional { direction } => (-receiver.normal.dot(direction).signum(), f32::INFINITY),
            };
            let grazing = match kind {
                LightKind::Directional { direction } => receiver.normal.dot(direction).abs() < 1e-6,
                _ => light_height.abs() < 1e-6,
            };
            if grazing {
                continue;
            }
            let project = |x: Vec3| match kind {
                LightKind::Point { position } | LightKind::Spot { position, .. } => {
                    position + (x - position) * (light_height / (light_height - height(x)))
                }
                LightKind::Directional { direction } => x - direction * (height(x) / receiver.normal.dot(direction)),
            };
            let scale = receiver.corners.iter().map(|c| c.abs().max_element()).fold(1.0, f32::max);
            let lift = receiver.normal * side * 1e-3 * scale;
            for (object, triangles) in &casters {
                if *object == receiver.object {
                    continue;
                }
                for triangle in triangles {
                    // The part strictly between the receiver's plane and the light.
                    let mut piece = clip(triangle, |x| side * height(x));
                    if light_height.is_finite() {
                        piece = clip(&piece, |x| side * (light_height - height(x)) - 1e-6 * light_height.abs());
                    }
                    if piece.len() < 3 {
                        continue;
                    }
                    let mut shadow: Vec<Vec3> = piece.into_iter().map(project).collect();
                    for k in 0..4 {
                        let (a, b) = (receiver.corners[k], receiver.corners[(k + 1) % 4]);
                        shadow = clip(&shadow, |x| receiver.normal.dot((b - a).cross(x - a)));
                        if shadow.len() < 3 {
                            break;
                        }
                    }
                    if shadow.len() >= 3 {
                        polygons.push(ShadowPolygon { slot, points: shadow.into_iter().map(|p| p + lift).collect() });
                    }
                }
            }
        }
        slot += 1;
    }
    polygons
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct MaskVertex {
    position: [f32; 3],
    slot: u32,
}

/// What the polygons were computed from.
#[derive(Clone, Debug, PartialEq)]
struct PolygonInputs {
    lights: Vec<Light>,
    first_layer: Vec<Option<u32>>,
    /// The scene's draw list: a new one is a new scene, or new tessellations.
    geometry: DrawListId,
}

/// The polygons of the last computation, as triangles ready to draw.
struct Polygons {
    inputs: PolygonInputs,
    vertices: Option<wgpu::Buffer>,
    count: u32,
}

/// Draws the shadow polygons into the mask, depth-tested against the opaque depth prepass.
pub struct ProjectedPass {
    pipeline: wgpu::RenderPipeline,
    polygons: Option<Polygons>,
}

impl ProjectedPass {
    pub fn new(device: &wgpu::Device, scene_layouts: &SceneLayouts) -> ProjectedPass {
        let module = shaders::module(device, "shadow_projected::shader", shaders::SHADOW_PROJECTED);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow_projected::pipeline_layout"),
            bind_group_layouts: &[Some(&scene_layouts.frame)],
            immediate_size: 0,
        });
        let max = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Max,
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow_projected::pipeline"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_shadow_projected"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<MaskVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Uint32],
                })],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            // No depth bias: the polygons are lifted off their receivers in world space instead. A
            // bias in depth would let polygons hidden just behind another surface (a floor's
            // shadow behind a wall standing on it) bleed through at its edge.
            depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::LessEqual, false),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_shadow_projected"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: ViewImage::ProjectedMask.array().format(),
                    blend: Some(wgpu::BlendState { color: max, alpha: max }),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        ProjectedPass { pipeline, polygons: None }
    }

    /// Computes the polygons if the lights or the geometry changed since the last call; returns
    /// whether it did.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        scene: &Scene,
        geometry: DrawListId,
        layout: &ShadowLayout,
    ) -> bool {
        let inputs = PolygonInputs { lights: scene.lights.clone(), first_layer: layout.first_layer.clone(), geometry };
        let fresh = self.polygons.as_ref().is_none_or(|p| p.inputs != inputs);
        if fresh {
            self.polygons = Some(Polygons::new(device, inputs, &projected_shadows(scene, layout)));
        }
        fresh
    }

    /// Clears the view's shadow mask and draws the polygons into it, depth-tested against the
    /// view's depth prepass. The mask starts cleared even when there is nothing to draw, since
    /// the opaque pass reads it whenever this method is chosen.
    pub fn record(&self, ctx: &FrameContext, frame: &mut FrameEncoder, view: &FrameView, targets: &FrameTargets) {
        let scene_gpu = ctx.scene_gpu;
        let mut pass = frame.encoder.begin_render_pass(&layout::pass(
            "shadow_projected::pass",
            &[Some(layout::color_attachment(
                targets.images.drawn(ViewImage::ProjectedMask),
                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
            ))],
            Some(layout::depth_attachment(&targets.depth.view, wgpu::LoadOp::Load)),
        ));
        let polygons = self.polygons.as_ref().filter(|p| p.vertices.is_some());
        if let Some(Polygons { vertices: Some(vertices), count, .. }) = polygons {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, scene_gpu.frame_group(), &[scene_gpu.views.offset(view.slot)]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.draw(0..*count, 0..1);
        }
        drop(pass);
        let polygons = self.polygons.as_ref().map_or(0, |p| u64::from(p.count / 3));
        frame.end("projected shadows", &[("triangles", Figure::Count(polygons))]);
    }
}

impl Polygons {
    fn new(device: &wgpu::Device, inputs: PolygonInputs, polygons: &[ShadowPolygon]) -> Polygons {
        let vertices: Vec<MaskVertex> = polygons
            .iter()
            .flat_map(|polygon| {
                let fan = (1..polygon.points.len() - 1).flat_map(move |k| [0, k, k + 1]);
                fan.map(move |i| MaskVertex { position: polygon.points[i].to_array(), slot: polygon.slot })
            })
            .collect();
        let buffer = (!vertices.is_empty()).then(|| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("shadow_projected::vertices"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            })
        });
        Polygons { inputs, vertices: buffer, count: vertices.len() as u32 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_keeps_the_inside_part() {
        let square = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let half = clip(&square, |p| 0.5 - p.x);
        assert_eq!(half.len(), 4);
        assert!(half.iter().all(|p| p.x <= 0.5 + 1e-6));
        assert!(clip(&square, |p| -1.0 - p.x).is_empty());
    }
}
