//! Transparent surfaces in sorted Z order (docs/course/06-transparency.md). A z-buffer cannot
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
//! # Composited volumes in the same order
//! A composited volume (`super::volume`) lies between transparent surfaces as well as in front
//! of the opaque ones, so the pass decides when the volumes are marched and over which part of
//! each ray ([`RaySpan`]), through a callback the frame gives it:
//! - `exact`: between the peeled layers. After peel `k`'s depth is known, the volumes are
//!   marched between it and peel `k − 1` (the opaque surface for `k = 0`), then layer `k` is
//!   blended over them; after the last layer, what lies in front of it. Every ray is cut at every
//!   transparent surface it crosses, the order the tracer composites in;
//! - `object` and `triangle`: each volume is one more item of the sorted list, by its box's
//!   centre, marched whole: right where a volume and the surfaces do not overlap in depth;
//! - `unsorted`: the volumes first, behind every transparent surface.
//!
//! # Against the ray tracer
//! The tracer refracts for real (`ior`); with `ior = 1` its rays go straight through too, and its
//! image and the exactly ordered one agree (tests/transparency.rs). Transparent surfaces receive
//! shadows like any other; as casters they tint the shadow maps' transmission layers.

use std::collections::HashMap;
use std::ops::Range;
use std::time::Duration;

use web_time::Instant;

use glam::{Mat3, Mat4, Vec3};
use wgpu::util::DeviceExt;

use super::context::{Figure, FrameContext, FrameEncoder};
use super::geometry::{DrawListId, TransparentObject, build_mesh};
use super::inspect::{INSPECT_TRANSPARENT, Part, RecordKind, no_terms};
use super::keys::{FrameKey, MaterialKey, constants};
use super::refraction::refracts;
use super::scene_gpu::{SceneLayouts, SurfaceLayout, SurfaceModule};
use super::scene_pass::scissor;
use super::targets::{DEPTH_FORMAT, FrameTargets, HDR_FORMAT, PerTarget};
use super::uniforms::{ALPHA_BLEND, GpuInstance, Vertex};
use super::view::{FrameView, ViewSlot, ViewTargets};
use super::volume::{RaySpan, VolumeSet};
use crate::gpu::layout;
use crate::gpu::texture::GpuTexture;
use crate::scene::Scene;
use crate::settings::{Refraction, TransparencySort};
use crate::shaders;
use crate::texture::tangents::tangents_or_generate;

/// How the blend finds `kt·Mt`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Blend {
    /// The material's `kt·Mt`, one constant per draw.
    Constant,
    /// `1 − α`, with the fragment's coverage `α` in the source alpha.
    Coverage,
    /// Glass weighted by Fresnel, first draw: `I·(1 − F)·kt·Mt`, the factor from the fragment.
    Transmit,
    /// Glass weighted by Fresnel, second draw: `Im + F·kt·Mt·L(r)` added.
    Add,
    /// The transparency lab's blend, by hand (`BLEND_BY_HAND` in shaders/transparency.wgsl),
    /// first draw: what the pixel holds times the fragment's `b`.
    ByHandFactor,
    /// The lab's blend, second draw: the fragment's `a` added.
    ByHandTerm,
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

/// One draw of the pass.
#[derive(Clone, Debug)]
enum Draw {
    /// One object's triangles, or only its back or front faces; `winding` is the faces in terms
    /// of the triangles' winding (swapped where the object's transform or the view mirrors).
    Object { object: usize, winding: Faces },
    /// A run of sorted triangles of one material, from the view's sorted triangle list.
    Triangles { material: usize, indices: Range<u32> },
}

/// What a view's transparent phase does, in order.
#[derive(Clone, Debug)]
enum Step {
    Draw(Draw),
    /// March the composited volumes (one, or all) over whole rays.
    Volumes(VolumeSet),
}

/// The records the transparency pass's `*_inspect` entry points write: a transparent surface's
/// fragment, blended over what is behind it.
pub const RECORDS: [RecordKind; 1] =
    [RecordKind { code: INSPECT_TRANSPARENT, name: "transparent", part: Part::Transparent, terms: no_terms }];

pub struct TransparencyPass {
    /// `shaders/transparency.wgsl` with the surface code.
    module: SurfaceModule,
    peel_group_layout: wgpu::BindGroupLayout,
    peel_layout: wgpu::PipelineLayout,
    pipelines: HashMap<PipelineKey, wgpu::RenderPipeline>,
    peel_pipelines: HashMap<(FrameKey, MaterialKey), wgpu::RenderPipeline>,
    /// Peel depths of each view's targets (by the targets' depth image), kept while those
    /// targets are drawn into.
    peels: PerTarget<PeelTargets>,
    triangles: Option<TriangleList>,
}

/// One view's part of a prepared frame.
struct ViewSteps {
    slot: ViewSlot,
    steps: Vec<Step>,
    /// The exact order: the peel depths of the view's targets, and the draws of one layer.
    peel: Option<usize>,
}

impl TransparencyPass {
    pub fn new(device: &wgpu::Device, layouts: &SceneLayouts, shader: &SurfaceLayout) -> TransparencyPass {
        let depth = |binding| layout::depth_texels(binding, wgpu::TextureViewDimension::D2);
        let peel_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("transparency::peel_group_layout"),
            entries: &[depth(0), depth(1)],
        });
        let peel_layout = shader.layout_with(device, layouts, "transparency::peel_layout", &peel_group_layout);
        TransparencyPass {
            module: SurfaceModule::new(device, shader, "transparency::shader", shaders::TRANSPARENCY),
            peel_group_layout,
            peel_layout,
            pipelines: HashMap::new(),
            peel_pipelines: HashMap::new(),
            peels: PerTarget::default(),
            triangles: None,
        }
    }

    /// Decides each view's order (sorting per object, or the triangles per view, where the view
    /// moved), compiles the pipelines the order needs and makes each view's peel depths.
    pub fn prepare<'p>(
        &'p mut self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        views: &[ViewTargets<'_>],
    ) -> PreparedTransparency<'p> {
        let settings = &ctx.settings.transparency;
        let geometry = &ctx.scene_gpu.geometry;
        let (mut sorted, mut sort_time) = (false, Duration::ZERO);
        let mut prepared = Vec::new();
        self.peels.keep_drawn(views.iter().map(|(_, t)| *t));
        for &(view, targets) in views {
            // An environment cube's views leave out the object they are drawn from, sorted per
            // object (the triangle list has no room for a left-out object).
            let sort = if view.skip.is_some() && settings.sort == TransparencySort::Triangle {
                TransparencySort::Object
            } else {
                settings.sort
            };
            let (steps, peel) = match sort {
                TransparencySort::Exact => {
                    let draws = drawn(ctx, view)
                        .map(|object| Step::Draw(Draw::Object { object, winding: Faces::Both }))
                        .collect();
                    (draws, Some(self.peel_index(ctx.device(), targets)))
                }
                TransparencySort::Triangle => {
                    let start = Instant::now();
                    sorted |= self.sort_triangles(ctx, view);
                    sort_time += start.elapsed();
                    (self.triangle_steps(ctx, view), None)
                }
                TransparencySort::Object | TransparencySort::Unsorted => (object_steps(ctx, view, sort), None),
            };
            let depth = if peel.is_some() { Depth::Equal } else { Depth::Less };
            for step in &steps {
                if let Step::Draw(draw) = step {
                    for key in pipeline_keys(ctx, view.key, draw, depth) {
                        self.pipelines.entry(key).or_insert_with(|| shading_pipeline(ctx, &self.module, key));
                    }
                }
            }
            if peel.is_some() {
                for object in drawn(ctx, view).map(|i| &geometry.transparent[i]) {
                    let key = (view.key, ctx.scene_gpu.material_keys[object.material]);
                    if !self.peel_pipelines.contains_key(&key) {
                        let pipeline = peel_pipeline(ctx, (&self.peel_layout, &self.module), key);
                        self.peel_pipelines.insert(key, pipeline);
                    }
                }
            }
            prepared.push(ViewSteps { slot: view.slot, steps, peel });
        }
        let mut figures = vec![("sorted", Figure::Flag(sorted))];
        if settings.sort == TransparencySort::Triangle {
            figures.push(("sort time", Figure::Time(sort_time)));
        }
        frame.end("transparency sort", &figures);
        PreparedTransparency { pass: self, views: prepared }
    }

    /// The index in `self.peels` of the peel depths for `targets`, made if they have none.
    fn peel_index(&mut self, device: &wgpu::Device, targets: &FrameTargets) -> usize {
        let layout = &self.peel_group_layout;
        self.peels.index_or_insert_with(targets, || PeelTargets::new(device, layout, targets))
    }

    /// Sorts the transparent triangles for `view`, unless its order is still right; rebuilds the
    /// list first when the draw list changed. Returns whether it sorted.
    fn sort_triangles(&mut self, ctx: &FrameContext, view: &FrameView) -> bool {
        let geometry = &ctx.scene_gpu.geometry;
        let current = (geometry.draw_list(), ctx.settings.transparency.refraction);
        if self.triangles.as_ref().is_none_or(|t| t.geometry != current) {
            let objects: Vec<TransparentObject> =
                geometry.transparent.iter().filter(|o| !refracts(ctx.settings, o)).cloned().collect();
            self.triangles = Some(TriangleList::new(ctx.device(), ctx.scene, &objects, current));
        }
        let list = self.triangles.as_mut().expect("made just above");
        list.sort(ctx.device(), ctx.queue(), view.slot, view.view.eye, -view.view.view_axis)
    }

    /// The sorted triangles of `view` in runs of one material, with each composited volume placed
    /// by its centre among them.
    fn triangle_steps(&self, ctx: &FrameContext, view: &FrameView) -> Vec<Step> {
        let list = self.triangles.as_ref().expect("sorted before");
        let order = &list.orders[&view.slot];
        let forward = -view.view.view_axis;
        let depth = |p: Vec3| (p - view.view.eye).dot(forward);
        let mut volumes = volume_depths(ctx, view);
        let mut steps = Vec::new();
        for (material, indices) in &order.runs {
            // A run is split where a volume's centre falls between its triangles.
            let mut start = indices.start;
            for t in (indices.start..indices.end).step_by(3) {
                let triangle_depth = depth(list.centroids[order.sequence[(t / 3) as usize] as usize]);
                while let Some(&(volume_depth, volume)) = volumes.last()
                    && volume_depth > triangle_depth
                {
                    if t > start {
                        steps.push(Step::Draw(Draw::Triangles { material: *material, indices: start..t }));
                        start = t;
                    }
                    steps.push(Step::Volumes(VolumeSet::One(volume)));
                    volumes.pop();
                }
            }
            steps.push(Step::Draw(Draw::Triangles { material: *material, indices: start..indices.end }));
        }
        steps.extend(volumes.into_iter().rev().map(|(_, v)| Step::Volumes(VolumeSet::One(v))));
        steps
    }
}

/// Each composited volume's depth along the view (its box's centre), nearest first, so the
/// farthest is last.
fn volume_depths(ctx: &FrameContext, view: &FrameView) -> Vec<(f32, usize)> {
    let forward = -view.view.view_axis;
    let mut volumes: Vec<(f32, usize)> =
        ctx.scene.volumes.iter().enumerate().map(|(i, v)| ((v.centre() - view.view.eye).dot(forward), i)).collect();
    volumes.sort_by(|a, b| a.0.total_cmp(&b.0));
    volumes
}

/// The order of `object` and `unsorted`: objects farthest first by their bounds' centre, each
/// drawn back faces then front faces, the volumes among them; or the scene's order after the
/// volumes.
fn object_steps(ctx: &FrameContext, view: &FrameView, sort: TransparencySort) -> Vec<Step> {
    let objects = &ctx.scene_gpu.geometry.transparent;
    let forward = -view.view.view_axis;
    let object_draw = |object: usize, faces: Faces| {
        Step::Draw(Draw::Object {
            object,
            winding: if objects[object].flipped != view.view.mirrored { faces.swapped() } else { faces },
        })
    };
    let kept = drawn(ctx, view);
    if sort == TransparencySort::Unsorted {
        let volumes = std::iter::once(Step::Volumes(VolumeSet::All));
        return volumes.chain(kept.map(|object| object_draw(object, Faces::Both))).collect();
    }
    // Farthest first; a stable sort keeps the scene's order between equals, objects before
    // volumes.
    let mut items: Vec<(f32, Option<usize>, Option<usize>)> =
        kept.map(|i| ((objects[i].centre - view.view.eye).dot(forward), Some(i), None)).collect();
    items.extend(volume_depths(ctx, view).into_iter().map(|(depth, v)| (depth, None, Some(v))));
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    items
        .into_iter()
        .flat_map(|item| match item {
            (_, Some(object), _) => vec![object_draw(object, Faces::Back), object_draw(object, Faces::Front)],
            (_, None, Some(volume)) => vec![Step::Volumes(VolumeSet::One(volume))],
            _ => vec![],
        })
        .collect()
}

/// The transparent objects this pass draws in `view`, by index: all but the one the view looks
/// out of, and the glass the refraction pass draws.
fn drawn<'c>(ctx: &'c FrameContext, view: &FrameView) -> impl Iterator<Item = usize> + 'c {
    let objects = &ctx.scene_gpu.geometry.transparent;
    let skip = view.skip;
    (0..objects.len()).filter(move |&i| Some(objects[i].object) != skip && !refracts(ctx.settings, &objects[i]))
}

/// The pipelines of one draw, in the order they draw it: one blend, or for glass weighted by
/// Fresnel the multiplication by `(1 − F)·kt·Mt` and then the addition of `Im + F·kt·Mt·L(r)`.
fn pipeline_keys(ctx: &FrameContext, frame: FrameKey, draw: &Draw, depth: Depth) -> Vec<PipelineKey> {
    let scene_gpu = ctx.scene_gpu;
    let (material, faces) = match *draw {
        Draw::Object { object, winding } => (scene_gpu.geometry.transparent[object].material, winding),
        Draw::Triangles { material, .. } => (material, Faces::Both),
    };
    let key = scene_gpu.material_keys[material];
    if ctx.settings.terms.fresnel && ctx.scene.materials[material].bends_light() {
        return vec![(Blend::Transmit, faces, depth, frame, key), (Blend::Add, faces, depth, frame, key)];
    }
    if ctx.surface.wgsl.routes("BLEND_BY_HAND") {
        return vec![(Blend::ByHandFactor, faces, depth, frame, key), (Blend::ByHandTerm, faces, depth, frame, key)];
    }
    let blend = if key.alpha_mode == ALPHA_BLEND && key.color_texture { Blend::Coverage } else { Blend::Constant };
    vec![(blend, faces, depth, frame, key)]
}

/// The pass with every view's order decided and its pipelines compiled.
pub struct PreparedTransparency<'p> {
    pass: &'p TransparencyPass,
    views: Vec<ViewSteps>,
}

/// Marches the composited volumes over a part of every ray: what the transparency pass asks of
/// the volumes between its layers.
pub type Composite<'c> = dyn FnMut(&mut FrameEncoder, RaySpan) + 'c;

impl PreparedTransparency<'_> {
    /// Draws the transparent surfaces seen from `view` over the opaque image and depth of
    /// `targets` in the chosen order, calling `composite` where the volumes belong in it.
    pub fn record(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        (view, targets): ViewTargets<'_>,
        composite: &mut Composite,
    ) {
        let prepared = self.views.iter().find(|v| v.slot == view.slot);
        let prepared = prepared.expect("TransparencyPass::prepare was given every view of the frame");
        let draws = match prepared.peel {
            Some(peel) => self.record_peeled(ctx, frame, (view, targets), prepared, peel, composite),
            None => {
                let mut draws = 0;
                let mut steps = prepared.steps.iter().peekable();
                while steps.peek().is_some() {
                    if let Some(Step::Volumes(set)) = steps.peek() {
                        composite(frame, RaySpan { volumes: *set, near: None, far: None });
                        steps.next();
                        continue;
                    }
                    let mut pass = begin(frame, "transparency::sorted", view, targets, &targets.depth.view);
                    pass.set_bind_group(0, ctx.scene_gpu.frame_group(), &[ctx.scene_gpu.views.offset(view.slot)]);
                    pass.set_bind_group(2, ctx.view_group(view), &[]);
                    while let Some(Step::Draw(draw)) = steps.peek() {
                        self.record_draw(ctx, &mut pass, view, draw, Depth::Less);
                        draws += 1;
                        steps.next();
                    }
                }
                draws
            }
        };
        let layers = if prepared.peel.is_some() { ctx.settings.transparency.peel_layers } else { 0 };
        frame.end("transparency", &[("draws", Figure::Count(draws)), ("layers peeled", Figure::Count(layers.into()))]);
    }

    fn record_draw(
        &self,
        ctx: &FrameContext,
        pass: &mut wgpu::RenderPass<'_>,
        view: &FrameView,
        draw: &Draw,
        depth: Depth,
    ) {
        let scene_gpu = ctx.scene_gpu;
        let material = match *draw {
            Draw::Object { object, .. } => scene_gpu.geometry.transparent[object].material,
            Draw::Triangles { material, .. } => material,
        };
        let t = scene_gpu.transmittance[material].as_dvec3();
        pass.set_blend_constant(wgpu::Color { r: t.x, g: t.y, b: t.z, a: 1.0 });
        pass.set_bind_group(1, &scene_gpu.materials()[material], &[]);
        let keys = pipeline_keys(ctx, view.key, draw, depth);
        let indices = match draw {
            Draw::Object { object, .. } => {
                let object: &TransparentObject = &scene_gpu.geometry.transparent[*object];
                0..scene_gpu.geometry.index_count(object.mesh)
            }
            Draw::Triangles { indices, .. } => {
                let list = self.pass.triangles.as_ref().expect("sorted in prepare");
                pass.set_vertex_buffer(0, list.vertices.slice(..));
                pass.set_vertex_buffer(1, list.identity.slice(..));
                pass.set_index_buffer(list.orders[&view.slot].indices.slice(..), wgpu::IndexFormat::Uint32);
                indices.clone()
            }
        };
        // The transparency lab's blend by hand is two draws per surface, multiply then add; a draw
        // that covers a pixel twice (a sphere's near and far walls in one run of triangles) would
        // multiply twice, then add twice. So there each triangle takes both draws before the next
        // (a triangle covers a pixel once): I' = a + b·I holds fragment by fragment, in any order.
        let by_hand = keys.first().is_some_and(|(blend, ..)| *blend == Blend::ByHandFactor);
        let parts: Vec<Range<u32>> =
            if by_hand { indices.clone().step_by(3).map(|first| first..first + 3).collect() } else { vec![indices] };
        for part in parts {
            for key in &keys {
                pass.set_pipeline(&self.pass.pipelines[key]);
                match draw {
                    Draw::Object { object, .. } => {
                        let object: &TransparentObject = &scene_gpu.geometry.transparent[*object];
                        let instances = object.instance..object.instance + 1;
                        scene_gpu.geometry.draw_part(pass, object.mesh, part.clone(), instances);
                    }
                    Draw::Triangles { .. } => pass.draw_indexed(part.clone(), 0, 0..1),
                }
            }
        }
    }

    /// The exact order: `peel_layers` peels from the back, each a depth pass, the volumes behind
    /// the layer, and the layer's shading pass; then the volumes in front of the last layer.
    /// Returns the draws recorded.
    fn record_peeled(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        (view, targets): ViewTargets<'_>,
        prepared: &ViewSteps,
        peel: usize,
        composite: &mut Composite,
    ) -> u64 {
        let scene_gpu = ctx.scene_gpu;
        let objects: Vec<&TransparentObject> = drawn(ctx, view).map(|i| &scene_gpu.geometry.transparent[i]).collect();
        let peel = self.pass.peels.at(peel);
        let view_offset = [scene_gpu.views.offset(view.slot)];
        let mut recorded = 0;
        let layers = ctx.settings.transparency.peel_layers as usize;
        for layer in 0..layers {
            let depth = &peel.depth[layer % 2].view;
            {
                let mut pass = frame.encoder.begin_render_pass(&layout::pass(
                    "transparency::peel",
                    &[],
                    Some(layout::depth_attachment(depth, wgpu::LoadOp::Clear(0.0))),
                ));
                scissor(&mut pass, view);
                pass.set_bind_group(0, scene_gpu.frame_group(), &view_offset);
                pass.set_bind_group(2, ctx.view_group(view), &[]);
                // Layer 0 peels below the opaque depth alone; layer k below layer k − 1 too.
                let limits = if layer == 0 { &peel.first } else { &peel.below[(layer - 1) % 2] };
                pass.set_bind_group(3, limits, &[]);
                for object in &objects {
                    let key = (view.key, scene_gpu.material_keys[object.material]);
                    pass.set_pipeline(&self.pass.peel_pipelines[&key]);
                    pass.set_bind_group(1, &scene_gpu.materials()[object.material], &[]);
                    scene_gpu.geometry.draw_instances(&mut pass, object.mesh, object.instance..object.instance + 1);
                }
            }
            let far = (layer > 0).then(|| &peel.depth[(layer - 1) % 2].view);
            composite(frame, RaySpan { volumes: VolumeSet::All, near: Some(depth), far });
            let mut pass = begin(frame, "transparency::peeled_layer", view, targets, depth);
            pass.set_bind_group(0, scene_gpu.frame_group(), &view_offset);
            pass.set_bind_group(2, ctx.view_group(view), &[]);
            for step in &prepared.steps {
                if let Step::Draw(draw) = step {
                    self.record_draw(ctx, &mut pass, view, draw, Depth::Equal);
                }
            }
            recorded += 2 * objects.len() as u64;
        }
        let last = &peel.depth[(layers - 1) % 2].view;
        composite(frame, RaySpan { volumes: VolumeSet::All, near: None, far: Some(last) });
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

/// A render pass over the view's colour, testing against `depth` without writing it, inside the
/// view's scissor.
fn begin<'e>(
    frame: &'e mut FrameEncoder,
    label: &'static str,
    view: &FrameView,
    targets: &FrameTargets,
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    let mut pass = frame.encoder.begin_render_pass(&layout::pass(
        label,
        &[Some(layout::color_attachment(&targets.hdr.view, wgpu::LoadOp::Load))],
        Some(layout::depth_attachment(depth, wgpu::LoadOp::Load)),
    ));
    scissor(&mut pass, view);
    pass
}

/// `I = Im + kt·Mt·I` (or one of its two halves for glass weighted by Fresnel); the target's
/// alpha is left as it is.
fn blend_state(blend: Blend) -> wgpu::BlendState {
    let (src_factor, dst_factor) = match blend {
        Blend::Constant => (wgpu::BlendFactor::One, wgpu::BlendFactor::Constant),
        Blend::Coverage => (wgpu::BlendFactor::One, wgpu::BlendFactor::OneMinusSrcAlpha),
        Blend::Transmit | Blend::ByHandFactor => (wgpu::BlendFactor::Zero, wgpu::BlendFactor::Src),
        Blend::Add | Blend::ByHandTerm => (wgpu::BlendFactor::One, wgpu::BlendFactor::One),
    };
    wgpu::BlendState {
        color: wgpu::BlendComponent { src_factor, dst_factor, operation: wgpu::BlendOperation::Add },
        alpha: wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Zero,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        },
    }
}

fn shading_pipeline(ctx: &FrameContext, module: &SurfaceModule, key: PipelineKey) -> wgpu::RenderPipeline {
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
    ctx.device().create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("transparency::shading_pipeline"),
        layout: Some(&ctx.surface.layout),
        vertex: module.vertex(),
        primitive: wgpu::PrimitiveState { cull_mode, ..Default::default() },
        depth_stencil: layout::depth_test(DEPTH_FORMAT, compare, false),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module.module,
            entry_point: Some(match (blend, frame.inspect) {
                (Blend::Transmit, _) => "fs_transparent_transmit",
                (Blend::Add, false) => "fs_transparent_fresnel",
                (Blend::Add, true) => "fs_transparent_fresnel_inspect",
                (Blend::ByHandFactor, _) => "fs_blend_factor",
                (Blend::ByHandTerm, false) => "fs_blend_term",
                (Blend::ByHandTerm, true) => "fs_blend_term_inspect",
                (_, false) => "fs_transparent",
                (_, true) => "fs_transparent_inspect",
            }),
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
    ctx: &FrameContext,
    (peel_layout, module): (&wgpu::PipelineLayout, &SurfaceModule),
    (frame, material): (FrameKey, MaterialKey),
) -> wgpu::RenderPipeline {
    let constants = constants(&frame, &material);
    ctx.device().create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("transparency::peel_pipeline"),
        layout: Some(peel_layout),
        vertex: module.vertex(),
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Greater, true),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module.module,
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
        PeelTargets { depth, first, below }
    }
}

/// Every transparent triangle in world space, for sorting one by one: the vertices once, and for
/// each view an index buffer rewritten in sorted order whenever that view moves. (One buffer per
/// view: buffer writes land before the frame's commands run, so views sharing one would all draw
/// the last view's order.)
struct TriangleList {
    /// The draw list the triangles were taken from, and the refraction setting (glass it draws
    /// is left out).
    geometry: (DrawListId, Refraction),
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
    /// The triangles in sorted order (indices into the list's triangles).
    sequence: Vec<u32>,
}

impl TriangleList {
    fn new(
        device: &wgpu::Device,
        scene: &Scene,
        objects: &[TransparentObject],
        geometry: (DrawListId, Refraction),
    ) -> TriangleList {
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
                bytemuck::bytes_of(&GpuInstance::new(
                    Mat4::IDENTITY,
                    super::uniforms::ENV_LAYER_WORLD,
                    super::uniforms::UNKNOWN_OBJECT,
                )),
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
                existing.sequence = order;
            }
            None => {
                let indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("transparency::sorted_indices"),
                    contents: bytemuck::cast_slice(&indices),
                    usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
                });
                let sorted = SortedOrder { indices, sorted_for: (eye, forward), runs, sequence: order };
                self.orders.insert(slot, sorted);
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
