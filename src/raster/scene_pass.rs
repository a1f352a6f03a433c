//! The scene pass: the z-buffer algorithm, drawn from one [`FrameView`] with a variant. Every
//! fragment of every surface is depth-tested against the nearest so far; the survivor is shaded
//! by the illumination model (`shaders/scene.wgsl`, with the model itself in
//! `shaders/common/lighting.wgsl`) for all lights, each weighted by its visibility from the
//! shadow pass, into the linear HDR target.
//!
//! Variants, one module (`shaders/scene.wgsl` after the surface code):
//! - **Depth prepass** ([`PreparedScene::record_prepass`]): the depth of the nearest surface at
//!   every pixel, and nothing else. The shading pass that follows tests `Equal` against it, so the
//!   illumination model runs once per pixel instead of once per fragment drawn: on a software
//!   GPU, where fragment shading is nearly all of the frame, overdraw is paid in full.
//! - **Opaque** ([`PreparedScene::record_opaque`]): the plain z-buffer (`Less`, depth written)
//!   or, after a prepass, shading only where the prepass's depth is; planar mirrors with their
//!   reflection (`fs_mirror`); then the world where nothing was drawn (`fs_background`).
//!
//! Pipeline constants specialise the shader per frame toggles ([`FrameKey`]) and per material
//! inputs ([`MaterialKey`]); each combination is compiled once, the first time a frame needs it:
//! [`ScenePass::prepare`] compiles what a frame's views need and hands out the only value that
//! can record them. No back-face culling: planes are two-sided, and the shader turns the normal
//! to the viewer.

use std::collections::HashMap;
use std::ops::Range;

use glam::Vec3;

use super::context::{FrameContext, FrameEncoder};
use super::inspect::{
    GpuInspectFragment, INSPECT_BACKGROUND, INSPECT_MIRROR, INSPECT_OPAQUE, Part, RecordKind, no_terms,
};
use super::keys::{FrameKey, MaterialKey, constants};
use super::scene_gpu::{SceneGpu, SceneLayouts, SurfaceLayout, SurfaceModule};
use super::targets::{DEPTH_FORMAT, FrameTargets, HDR_FORMAT};
use super::uniforms::ALPHA_MASK;
use super::view::{FrameView, ViewSlot, ViewTargets};
use crate::gpu::layout;
use crate::shaders;

/// The records the scene pass's `*_inspect` entry points write: opaque surfaces, planar mirrors
/// with the reflection their mirrored camera drew, and the world where nothing is.
pub const RECORDS: [RecordKind; 3] = [
    RecordKind { code: INSPECT_OPAQUE, name: "opaque", part: Part::Surface, terms: no_terms },
    RecordKind { code: INSPECT_MIRROR, name: "mirror", part: Part::Surface, terms: mirror_terms },
    RecordKind { code: INSPECT_BACKGROUND, name: "background", part: Part::Background, terms: no_terms },
];

/// A planar mirror's term: `kps·MPS·L(r)`, `L(r)` read from its mirrored camera's image.
fn mirror_terms(record: &GpuInspectFragment) -> Vec<(&'static str, Vec3)> {
    vec![("planar mirror kps·MPS·L(r)", record.mirror)]
}

/// The depth test of a shading variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum DepthMode {
    /// The plain z-buffer: `Less`, depth written.
    Write,
    /// After a prepass: only the fragments at the prepass's depth, nothing written.
    Equal,
}

/// What tells shading variants apart: the depth test, the frame's toggles, the material's inputs
/// and whether it is a mirror drawn with its reflection.
type ShadingKey = (DepthMode, FrameKey, MaterialKey, bool);

/// A batch's plain variant and, for a mirror batch, its variant with the reflection.
type BatchKeys = (ShadingKey, Option<ShadingKey>);

pub struct ScenePass {
    /// `shaders/scene.wgsl` with the surface code.
    module: SurfaceModule,
    /// Group 3 of the mirror variants: the reflection image.
    mirror_group_layout: wgpu::BindGroupLayout,
    mirror_layout: wgpu::PipelineLayout,
    prepass: wgpu::RenderPipeline,
    /// The prepass of cut-out materials (`ALPHA_MASK`): depth only where the surface is.
    prepass_masked: wgpu::RenderPipeline,
    shading: HashMap<ShadingKey, wgpu::RenderPipeline>,
    /// The world where no surface is (`fs_background`), and its (empty) group 1.
    background: wgpu::RenderPipeline,
    empty_group: wgpu::BindGroup,
    /// `fs_background_inspect`, made for the first inspected frame.
    background_inspect: Option<wgpu::RenderPipeline>,
    background_layout: wgpu::PipelineLayout,
}

/// The reflections a view's mirrors show: per mirror object, each part of it that is a mirror
/// (a box's face; `None`: all of it) and the group 3 holding the image its mirrored camera drew,
/// `None` where no camera was drawn for it (it shows its plain material). A mirror object with no
/// entry is drawn plain.
#[derive(Default)]
pub struct MirrorImages {
    pub parts: HashMap<usize, Vec<MirrorPart>>,
}

/// A part of a mirror object (`None`: all of it), and the group 3 of its reflection if drawn.
pub type MirrorPart = (Option<Range<u32>>, Option<wgpu::BindGroup>);

impl ScenePass {
    pub fn new(device: &wgpu::Device, layouts: &SceneLayouts, shader: &SurfaceLayout) -> ScenePass {
        let module = SurfaceModule::new(device, shader, "scene::shader", shaders::SCENE);
        let prepass_pipeline = |label, fragment| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&shader.layout),
                vertex: module.vertex(),
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Less, true),
                multisample: Default::default(),
                fragment,
                multiview_mask: None,
                cache: None,
            })
        };
        let prepass = prepass_pipeline("scene::prepass_pipeline", None);
        // Untextured materials bind a white texture: the coverage is then the material's alpha.
        let mask_constants = [("COLOR_TEXTURE", 1.0), ("ALPHA_MODE", f64::from(ALPHA_MASK))];
        let prepass_masked = prepass_pipeline(
            "scene::prepass_masked_pipeline",
            Some(wgpu::FragmentState {
                module: &module.module,
                entry_point: Some("fs_mask"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &mask_constants,
                    ..Default::default()
                },
                targets: &[],
            }),
        );
        let mirror_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene::mirror_group_layout"),
            entries: &[layout::texture(
                0,
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2,
            )],
        });
        let mirror_layout = shader.layout_with(device, layouts, "scene::mirror_layout", &mirror_group_layout);
        // Group 1 is an empty group, not a gap: lavapipe (Mesa 22) crashes compiling a shader
        // that samples 2D textures of group 2 under a layout with no group 1.
        let empty_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene::empty_layout"),
            entries: &[],
        });
        let empty_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene::empty_group"),
            layout: &empty_layout,
            entries: &[],
        });
        let background_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene::background_layout"),
            bind_group_layouts: &[Some(&layouts.frame), Some(&empty_layout), Some(&layouts.view)],
            immediate_size: 0,
        });
        let background = background_pipeline(device, &module, &background_layout, "fs_background");
        ScenePass {
            module,
            background,
            empty_group,
            background_inspect: None,
            background_layout,
            mirror_group_layout,
            mirror_layout,
            prepass,
            prepass_masked,
            shading: HashMap::new(),
        }
    }

    /// Compiles the shading variants `views` need that were not compiled before (every batch's
    /// material under each view's toggles, and the mirror variant of mirror batches when
    /// `mirrors` are drawn with their reflections), and resolves each view's pipelines.
    pub fn prepare<'p>(
        &'p mut self,
        ctx: &FrameContext,
        views: &[ViewTargets<'_>],
        mirrors: bool,
    ) -> PreparedScene<'p> {
        let scene = ctx.scene_gpu;
        // Per batch, its plain variant's key and, for a mirror batch, its reflecting variant's.
        let keys = |view: &FrameView| -> Vec<BatchKeys> {
            let depth = if view.prepass { DepthMode::Equal } else { DepthMode::Write };
            let key = view.key;
            scene
                .geometry
                .batches
                .iter()
                .map(|batch| {
                    let material = scene.material_keys[batch.material];
                    let mirror = (mirrors && batch.mirror).then_some((depth, key, material, true));
                    ((depth, key, material, false), mirror)
                })
                .collect()
        };
        let keyed: Vec<(ViewSlot, Vec<BatchKeys>)> = views.iter().map(|(view, _)| (view.slot, keys(view))).collect();
        for key in keyed.iter().flat_map(|(_, keys)| keys.iter().flat_map(|(plain, mirror)| [Some(*plain), *mirror])) {
            if let Some(key) = key
                && !self.shading.contains_key(&key)
            {
                let pipeline = self.shading_pipeline(ctx, key);
                self.shading.insert(key, pipeline);
            }
        }
        if views.iter().any(|(view, _)| view.key.inspect) && self.background_inspect.is_none() {
            let device = ctx.device();
            let pipeline = background_pipeline(device, &self.module, &self.background_layout, "fs_background_inspect");
            self.background_inspect = Some(pipeline);
        }
        let this = &*self;
        let views = keyed
            .into_iter()
            .map(|(slot, keys)| {
                let batches = keys
                    .iter()
                    .map(|(plain, mirror)| (&this.shading[plain], mirror.map(|key| &this.shading[&key])))
                    .collect();
                (slot, batches)
            })
            .collect();
        PreparedScene { pass: this, views }
    }

    fn shading_pipeline(&self, ctx: &FrameContext, key: ShadingKey) -> wgpu::RenderPipeline {
        let module = &self.module;
        let (depth, frame, material, mirror) = key;
        // A mirror drawn with its image reflects through it, not through an environment map.
        let frame = if mirror { FrameKey { environment: 0, ..frame } } else { frame };
        let constants = constants(&frame, &material);
        let depth_state = match depth {
            DepthMode::Write => layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Less, true),
            DepthMode::Equal => layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Equal, false),
        };
        ctx.device().create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene::shading_pipeline"),
            layout: Some(if mirror { &self.mirror_layout } else { &ctx.surface.layout }),
            vertex: module.vertex(),
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: depth_state,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module.module,
                // A mirror drawn with its reflection reads group 3 (`fs_mirror`).
                entry_point: Some(match (mirror, frame.inspect) {
                    (false, false) => "fs_scene",
                    (true, false) => "fs_mirror",
                    (false, true) => "fs_scene_inspect",
                    (true, true) => "fs_mirror_inspect",
                }),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
                targets: &[Some(HDR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// The number of shading variants compiled so far.
    pub fn variant_count(&self) -> usize {
        self.shading.len()
    }

    /// The group 3 of the mirror variants that reads `image`, a mirrored view's HDR target.
    pub fn mirror_image_group(&self, device: &wgpu::Device, image: &wgpu::TextureView) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene::mirror_image_group"),
            layout: &self.mirror_group_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(image) }],
        })
    }
}

/// The scene pass with every pipeline a frame's views need: per view, per batch of the draw list,
/// its plain variant and, for mirror batches, its variant with the reflection.
pub struct PreparedScene<'p> {
    pass: &'p ScenePass,
    views: Vec<(ViewSlot, Vec<BatchPipelines<'p>>)>,
}

type BatchPipelines<'p> = (&'p wgpu::RenderPipeline, Option<&'p wgpu::RenderPipeline>);

impl PreparedScene<'_> {
    fn batches(&self, view: &FrameView) -> &[BatchPipelines<'_>] {
        let found = self.views.iter().find(|(slot, _)| *slot == view.slot);
        &found.expect("ScenePass::prepare was given every view of the frame").1
    }

    /// The depth of the nearest surface at every pixel of `view`, and nothing else; transparent
    /// surfaces are left out when `opaque_only` (the transparency pass draws them later).
    pub fn record_prepass(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        view: &FrameView,
        targets: &FrameTargets,
        opaque_only: bool,
    ) {
        let scene = ctx.scene_gpu;
        let mut pass = frame.encoder.begin_render_pass(&layout::pass(
            "scene::prepass",
            &[],
            Some(layout::depth_attachment(&targets.depth.view, wgpu::LoadOp::Clear(1.0))),
        ));
        scissor(&mut pass, view);
        pass.set_bind_group(0, scene.frame_group(), &[scene.views.offset(view.slot)]);
        pass.set_bind_group(2, ctx.view_group(view), &[]);
        for batch in scene.geometry.batches.iter().filter(|b| !(opaque_only && b.transparent)) {
            if batch.alone.is_some() && batch.alone == view.skip {
                continue;
            }
            let masked = scene.material_keys[batch.material].alpha_mode == ALPHA_MASK;
            pass.set_pipeline(if masked { &self.pass.prepass_masked } else { &self.pass.prepass });
            pass.set_bind_group(1, &scene.materials()[batch.material], &[]);
            scene.geometry.draw(&mut pass, batch);
        }
    }

    /// Shades every surface seen from `view` (after its prepass when it has one); transparent
    /// ones are left out when `opaque_only` (the transparency pass draws them next), else drawn
    /// as opaque surfaces with their illumination model alone. Mirrors show the images in
    /// `mirrors`; the world fills what no surface covers.
    pub fn record_opaque(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        view: &FrameView,
        targets: &FrameTargets,
        (opaque_only, mirrors): (bool, &MirrorImages),
    ) {
        let scene: &SceneGpu = ctx.scene_gpu;
        let bg = ctx.scene.background.as_dvec3();
        let depth_load = if view.prepass { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(1.0) };
        let mut pass = frame.encoder.begin_render_pass(&layout::pass(
            "scene::opaque",
            &[Some(layout::color_attachment(
                &targets.hdr.view,
                wgpu::LoadOp::Clear(wgpu::Color { r: bg.x, g: bg.y, b: bg.z, a: 1.0 }),
            ))],
            Some(layout::depth_attachment(&targets.depth.view, depth_load)),
        ));
        scissor(&mut pass, view);
        pass.set_bind_group(0, scene.frame_group(), &[scene.views.offset(view.slot)]);
        pass.set_bind_group(2, ctx.view_group(view), &[]);
        // Batches come sorted by material: the pipeline changes only where the variant does.
        let mut current: Option<&wgpu::RenderPipeline> = None;
        for (batch, &(plain, mirror)) in scene.geometry.batches.iter().zip(self.batches(view)) {
            if (opaque_only && batch.transparent) || (batch.alone.is_some() && batch.alone == view.skip) {
                continue;
            }
            pass.set_bind_group(1, &scene.materials()[batch.material], &[]);
            let parts = batch.alone.filter(|_| batch.mirror).and_then(|object| mirrors.parts.get(&object));
            let (Some(parts), Some(mirror)) = (parts, mirror) else {
                if current != Some(plain) {
                    pass.set_pipeline(plain);
                    current = Some(plain);
                }
                scene.geometry.draw(&mut pass, batch);
                continue;
            };
            // A mirror: each of its parts with its image where its view was drawn, plain where not.
            for (part, image) in parts {
                let pipeline = if image.is_some() { mirror } else { plain };
                if current != Some(pipeline) {
                    pass.set_pipeline(pipeline);
                    current = Some(pipeline);
                }
                if let Some(image) = image {
                    pass.set_bind_group(3, image, &[]);
                }
                let count = scene.geometry.index_count(batch.mesh);
                let part = part.clone().unwrap_or(0..count);
                scene.geometry.draw_part(&mut pass, batch.mesh, part, batch.instances.clone());
            }
        }
        if ctx.scene.environment.is_some() {
            let inspected = self.pass.background_inspect.as_ref().filter(|_| view.key.inspect);
            pass.set_pipeline(inspected.unwrap_or(&self.pass.background));
            pass.set_bind_group(1, &self.pass.empty_group, &[]);
            pass.draw(0..3, 0..1);
        }
    }
}

/// Limits `pass` to the view's scissor, if it has one.
pub fn scissor(pass: &mut wgpu::RenderPass<'_>, view: &FrameView) {
    if let Some([x, y, width, height]) = view.scissor {
        pass.set_scissor_rect(x, y, width, height);
    }
}

/// The world where nothing is drawn: one triangle at the far plane, drawn where no surface is.
fn background_pipeline(
    device: &wgpu::Device,
    module: &SurfaceModule,
    layout: &wgpu::PipelineLayout,
    entry_point: &str,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("scene::background_pipeline"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: &module.module,
            entry_point: Some("vs_background"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        // At the far plane, where nothing was drawn.
        depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::LessEqual, false),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module.module,
            entry_point: Some(entry_point),
            compilation_options: Default::default(),
            targets: &[Some(HDR_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}
