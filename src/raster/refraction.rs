//! Refraction in the rasterizer (docs/course/06-transparency.md#refraction): glass whose rays
//! bend (`kt > 0`, `ior ≠ 1`; `Material::bends_light`), when `transparency.refraction` is not
//! `none`. The course's transparency takes `n_i = n_t` because a z-buffer cannot bend rays; this
//! pass follows each ray through the glass in screen space instead, with two images of the glass
//! drawn first:
//!
//! 1. **Back faces**: the glass's nearest back faces, their depth and outward normals
//!    (`fs_refraction_back`, front faces culled).
//! 2. **The scene behind** (`screen` only): copies of the view's colour and depth as the opaque
//!    phase left them (the depth copied by drawing, [`DepthCopy`]: GL cannot copy a depth
//!    texture).
//! 3. **Front faces** (`fs_refraction`, back faces culled, depth tested and written): each
//!    fragment refracts the view ray into the glass, marches it against the back faces to find
//!    where it leaves, refracts it out, and reads what it then meets: the object's environment
//!    cube (`environment`), or the copied image where the ray passes behind the copied depth
//!    (`screen`; the cube where it leaves the screen). `shaders/refraction.wgsl` says how.
//!
//! The glass is then in the depth buffer like an opaque surface: the transparent surfaces in
//! front of it blend over it in their phase, those behind it are hidden (the tracer sees them
//! through it; the environment cube does too, from the object's centre).
//!
//! What each choice assumes, against the tracer's rays:
//! - both: the path crosses the glass once, entering through the front face the pixel sees and
//!   leaving through a back face (exact for a sphere, to the pixel); rays reflected inside the
//!   glass, and its model at the exit point, are left out; on total internal reflection at the
//!   exit, the ray is taken to leave along the reflected direction;
//! - `environment`: what the ray meets is as seen from the cube's centre (see `parallax`), a
//!   frame old for other objects' cubes;
//! - `screen`: what the ray meets is on screen and was drawn by the opaque phase: transparent
//!   surfaces, and other glass, are not seen through the glass; surfaces hidden in the image
//!   (behind others, or off screen) are not found.
//!
//! Materials have no roughness (the Whitted model's transmission is a perfect specular one), so
//! nothing is blurred.

use std::collections::HashMap;

use super::context::{Figure, FrameContext, FrameEncoder};
use super::geometry::TransparentObject;
pub use crate::shaders::constants::{REFRACTION_ENVIRONMENT, REFRACTION_SCREEN};
use glam::Vec3;
use serde::Serialize;

use super::inspect::{GpuInspectFragment, INSPECT_REFRACTION, Part, RecordKind};
use super::keys::{FrameKey, MaterialKey, constants, pipeline_constants};
use super::scene_gpu::{SceneLayouts, SurfaceLayout, SurfaceModule};
use super::scene_pass::scissor;
use super::targets::{DEPTH_FORMAT, FrameTargets, HDR_FORMAT, PerTarget};
use super::view::{FrameView, ViewTargets};
use crate::gpu::depth_copy::{DepthCopy, DepthImageCopy};
use crate::gpu::layout;
use crate::gpu::texture::GpuTexture;
use crate::settings::{Refraction, RenderSettings};
use crate::shaders;

pipeline_constants! {
    /// The pipeline constant the refraction pass sets besides the surface code's: where the
    /// refracted ray is read (`REFRACTION_*` of `shaders/refraction.wgsl`).
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    pub struct RefractionKey(mode: Refraction) {
        source: u32 = "REFRACTION" <- refraction_source(mode),
    }
}

/// The `REFRACTION_*` code of where a refraction mode reads the refracted ray.
fn refraction_source(mode: Refraction) -> u32 {
    match mode {
        Refraction::Screen => REFRACTION_SCREEN,
        Refraction::Environment | Refraction::None => REFRACTION_ENVIRONMENT,
    }
}

/// The image the back faces' normals are drawn into.
const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Which faces a draw keeps, as a cull mode: the faces culled.
type Culled = wgpu::Face;

type BackKey = (Culled, FrameKey, MaterialKey);
type FrontKey = (Culled, Refraction, FrameKey, MaterialKey);

/// The records the refraction pass's `*_inspect` entry point writes: glass that bends light, a
/// surface the z-buffer keeps, with the light refracted through it.
pub const RECORDS: [RecordKind; 1] =
    [RecordKind { code: INSPECT_REFRACTION, name: "refraction", part: Part::Surface, terms: refraction_terms }];

/// The path the refraction pass found through glass (`shaders/refraction.wgsl`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RefractionPath {
    /// `environment` or `screen`.
    pub mode: &'static str,
    /// Where the ray leaves the glass, found against its back faces (`None`: not found, the
    /// ray taken to go on unbent).
    pub exit: Option<Vec3>,
    /// The direction it leaves in, `t2`.
    pub direction: Vec3,
    /// Fresnel's `F` at the exit.
    pub exit_fresnel: f32,
    /// Where `L(t2)` was read: `the opaque image` or `the environment cube`.
    pub source: &'static str,
    /// `(1 − F1)·kt·Mt·(Im2 + (1 − F2)·kt·Mt·L(t2))`.
    pub radiance: Vec3,
}

/// The path a refraction record took through the glass, for `mirador explain`.
pub fn path(record: &GpuInspectFragment, settings: &RenderSettings) -> RefractionPath {
    RefractionPath {
        mode: if settings.transparency.refraction == Refraction::Screen { "screen" } else { "environment" },
        exit: (record.refraction_found > 0.0).then_some(record.refraction_exit),
        direction: record.refracted_direction,
        exit_fresnel: record.fresnel_exit,
        source: if record.refraction_source > 1.5 { "the opaque image" } else { "the environment cube" },
        radiance: record.refracted,
    }
}

/// The light through the glass: `(1 − F1)·kt·Mt·(Im2 + (1 − F2)·kt·Mt·L(t2))`.
fn refraction_terms(record: &GpuInspectFragment) -> Vec<(&'static str, Vec3)> {
    vec![("refracted (1 − F1)·kt·Mt·(Im2 + (1 − F2)·kt·Mt·L(t2))", record.refracted)]
}

pub struct RefractionPass {
    /// `shaders/refraction.wgsl` with the surface code.
    module: SurfaceModule,
    group_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    back: HashMap<BackKey, wgpu::RenderPipeline>,
    front: HashMap<FrontKey, wgpu::RenderPipeline>,
    /// The images of each view's targets (by the targets' depth image), kept while those targets
    /// are drawn into.
    images: PerTarget<RefractionImages>,
    depth_copy: DepthCopy,
}

/// One view's back faces and copies, and the group 3 that reads them.
struct RefractionImages {
    back_depth: GpuTexture,
    back_normal: GpuTexture,
    opaque: GpuTexture,
    opaque_depth: DepthImageCopy,
    group: wgpu::BindGroup,
}

impl RefractionPass {
    pub fn new(device: &wgpu::Device, layouts: &SceneLayouts, shader: &SurfaceLayout) -> RefractionPass {
        let depth = |binding| layout::depth_texels(binding, wgpu::TextureViewDimension::D2);
        let colour = |binding| {
            layout::texture(
                binding,
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2,
            )
        };
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("refraction::group_layout"),
            entries: &[depth(0), depth(1), colour(2), colour(3)],
        });
        let layout = shader.layout_with(device, layouts, "refraction::layout", &group_layout);
        RefractionPass {
            module: SurfaceModule::new(device, shader, "refraction::shader", shaders::REFRACTION),
            group_layout,
            layout,
            back: HashMap::new(),
            front: HashMap::new(),
            images: PerTarget::default(),
            depth_copy: DepthCopy::new(device, DEPTH_FORMAT),
        }
    }

    /// The glass this pass draws, by its index in the draw list's transparent objects.
    pub fn objects(ctx: &FrameContext) -> Vec<usize> {
        let objects = &ctx.scene_gpu.geometry.transparent;
        (0..objects.len()).filter(|&i| refracts(ctx.settings, &objects[i])).collect()
    }

    /// Compiles the pipelines the views need and makes each view's images; `None` when no glass
    /// is refracted.
    pub fn prepare<'p>(&'p mut self, ctx: &FrameContext, views: &[ViewTargets<'_>]) -> Option<PreparedRefraction<'p>> {
        let objects = RefractionPass::objects(ctx);
        if objects.is_empty() {
            return None;
        }
        let mode = ctx.settings.transparency.refraction;
        self.images.keep_drawn(views.iter().map(|(_, t)| *t));
        for &(view, targets) in views {
            for &index in &objects {
                let object = &ctx.scene_gpu.geometry.transparent[index];
                let material = ctx.scene_gpu.material_keys[object.material];
                let back = (culled(object, view, wgpu::Face::Front), view.key, material);
                self.back.entry(back).or_insert_with(|| back_pipeline(ctx, &self.module, back));
                let front = (culled(object, view, wgpu::Face::Back), mode, view.key, material);
                let layout = &self.layout;
                self.front.entry(front).or_insert_with(|| front_pipeline(ctx, (layout, &self.module), front));
            }
            let (layout, copy) = (&self.group_layout, &self.depth_copy);
            self.images.index_or_insert_with(targets, || RefractionImages::new(ctx.device(), (layout, copy), targets));
        }
        Some(PreparedRefraction { pass: self, objects, mode })
    }
}

/// Whether this pass draws `object` (the transparency pass draws it otherwise): glass that bends
/// light, when the settings refract.
pub fn refracts(settings: &RenderSettings, object: &TransparentObject) -> bool {
    let transparency = &settings.transparency;
    transparency.enabled && transparency.refraction != Refraction::None && object.bends_light
}

/// The face to cull to keep `object`'s back (`cull = Front`) or front faces (`cull = Back`) as
/// `view` sees them: swapped where the object's transform or the view mirrors its winding.
fn culled(object: &TransparentObject, view: &FrameView, cull: wgpu::Face) -> Culled {
    match (object.flipped != view.view.mirrored, cull) {
        (false, face) => face,
        (true, wgpu::Face::Front) => wgpu::Face::Back,
        (true, wgpu::Face::Back) => wgpu::Face::Front,
    }
}

/// The pass with its pipelines compiled and its images made for every view of the frame.
pub struct PreparedRefraction<'p> {
    pass: &'p RefractionPass,
    objects: Vec<usize>,
    mode: Refraction,
}

impl PreparedRefraction<'_> {
    /// Draws the refracting glass seen from `view` into `targets`: its back faces, the copies of
    /// the scene behind it, then its front faces with the refracted light.
    pub fn record(&self, ctx: &FrameContext, frame: &mut FrameEncoder, view: &FrameView, targets: &FrameTargets) {
        let scene_gpu = ctx.scene_gpu;
        let objects: Vec<&TransparentObject> = self
            .objects
            .iter()
            .map(|&i| &scene_gpu.geometry.transparent[i])
            .filter(|o| Some(o.object) != view.skip)
            .collect();
        if objects.is_empty() {
            return;
        }
        let images = self.pass.images.get(targets).expect("RefractionPass::prepare made images for every view");
        let view_offset = [scene_gpu.views.offset(view.slot)];
        {
            let mut pass = frame.encoder.begin_render_pass(&layout::pass(
                "refraction::back_faces",
                &[Some(layout::color_attachment(
                    &images.back_normal.view,
                    wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                ))],
                Some(layout::depth_attachment(&images.back_depth.view, wgpu::LoadOp::Clear(1.0))),
            ));
            scissor(&mut pass, view);
            pass.set_bind_group(0, scene_gpu.frame_group(), &view_offset);
            pass.set_bind_group(2, ctx.view_group(view), &[]);
            for object in &objects {
                let key = (culled(object, view, wgpu::Face::Front), view.key, scene_gpu.material_keys[object.material]);
                pass.set_pipeline(&self.pass.back[&key]);
                pass.set_bind_group(1, &scene_gpu.materials()[object.material], &[]);
                scene_gpu.geometry.draw_instances(&mut pass, object.mesh, object.instance..object.instance + 1);
            }
        }
        if self.mode == Refraction::Screen {
            let size = targets.hdr.texture.size();
            frame.encoder.copy_texture_to_texture(
                targets.hdr.texture.as_image_copy(),
                images.opaque.texture.as_image_copy(),
                size,
            );
            self.pass.depth_copy.record(&mut frame.encoder, &images.opaque_depth);
        }
        {
            let mut pass = frame.encoder.begin_render_pass(&layout::pass(
                "refraction::front_faces",
                &[Some(layout::color_attachment(&targets.hdr.view, wgpu::LoadOp::Load))],
                Some(layout::depth_attachment(&targets.depth.view, wgpu::LoadOp::Load)),
            ));
            scissor(&mut pass, view);
            pass.set_bind_group(0, scene_gpu.frame_group(), &view_offset);
            pass.set_bind_group(2, ctx.view_group(view), &[]);
            pass.set_bind_group(3, &images.group, &[]);
            for object in &objects {
                let material = scene_gpu.material_keys[object.material];
                let key = (culled(object, view, wgpu::Face::Back), self.mode, view.key, material);
                pass.set_pipeline(&self.pass.front[&key]);
                pass.set_bind_group(1, &scene_gpu.materials()[object.material], &[]);
                scene_gpu.geometry.draw_instances(&mut pass, object.mesh, object.instance..object.instance + 1);
            }
        }
        frame.end("refraction", &[("objects", Figure::Count(objects.len() as u64))]);
    }
}

impl RefractionImages {
    fn new(
        device: &wgpu::Device,
        (group_layout, depth_copy): (&wgpu::BindGroupLayout, &DepthCopy),
        targets: &FrameTargets,
    ) -> RefractionImages {
        let size = targets.size;
        let back_depth = GpuTexture::target(device, "refraction::back_depth", size, DEPTH_FORMAT);
        let back_normal = GpuTexture::target(device, "refraction::back_normal", size, NORMAL_FORMAT);
        let opaque = GpuTexture::copy_target(device, "refraction::opaque", size, HDR_FORMAT);
        let opaque_depth = depth_copy.image_for(device, "refraction::opaque_depth", &targets.depth.view, size);
        let entry =
            |binding, view| wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(view) };
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("refraction::group"),
            layout: group_layout,
            entries: &[
                entry(0, &opaque_depth.image.view),
                entry(1, &back_depth.view),
                entry(2, &back_normal.view),
                entry(3, &opaque.view),
            ],
        });
        RefractionImages { back_depth, back_normal, opaque, opaque_depth, group }
    }
}

/// The back faces' depth and normals (`Less`, written).
fn back_pipeline(ctx: &FrameContext, module: &SurfaceModule, (cull, frame, material): BackKey) -> wgpu::RenderPipeline {
    let constants = constants(&frame, &material);
    ctx.device().create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("refraction::back_pipeline"),
        layout: Some(&ctx.surface.layout),
        vertex: module.vertex(),
        primitive: wgpu::PrimitiveState { cull_mode: Some(cull), ..Default::default() },
        depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Less, true),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module.module,
            entry_point: Some("fs_refraction_back"),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            targets: &[Some(NORMAL_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The front faces, shaded with the refracted light, replacing what the pixel held (`Less`,
/// depth written).
fn front_pipeline(
    ctx: &FrameContext,
    (layout, module): (&wgpu::PipelineLayout, &SurfaceModule),
    (cull, mode, frame, material): FrontKey,
) -> wgpu::RenderPipeline {
    let mut constants = constants(&frame, &material);
    constants.extend(RefractionKey::new(mode).constants());
    ctx.device().create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("refraction::front_pipeline"),
        layout: Some(layout),
        vertex: module.vertex(),
        primitive: wgpu::PrimitiveState { cull_mode: Some(cull), ..Default::default() },
        depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Less, true),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module.module,
            entry_point: Some(if frame.inspect { "fs_refraction_inspect" } else { "fs_refraction" }),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            targets: &[Some(HDR_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}
