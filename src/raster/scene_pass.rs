//! The scene pass: the z-buffer algorithm, drawn from one [`View`](super::view::View) with a
//! variant. Every fragment of every surface is depth-tested against the nearest so far; the
//! survivor is shaded by the illumination model (`shaders/scene.wgsl`, with the model itself in
//! `shaders/common/lighting.wgsl`) for all lights, each weighted by its visibility from the
//! shadow pass, into the linear HDR target.
//!
//! Variants, one shading module:
//! - **Depth prepass** ([`ScenePass::record_prepass`]): the depth of the nearest surface at every
//!   pixel, and nothing else. The shading pass that follows tests `Equal` against it, so the
//!   illumination model runs once per pixel instead of once per fragment drawn: on a software
//!   GPU, where fragment shading is nearly all of the frame, overdraw is paid in full.
//! - **Opaque** ([`ScenePass::record_opaque`]): the plain z-buffer (`Less`, depth written) or,
//!   after a prepass, shading only where the prepass's depth is.
//!
//! Pipeline constants specialise the shader per frame toggles ([`FrameKey`]) and per material
//! inputs ([`MaterialKey`]); each combination is compiled once, the first time it is drawn.
//! No back-face culling: planes are two-sided, and the shader turns the normal to the viewer.

use std::collections::HashMap;
use std::ops::Range;

use super::scene_gpu::{SceneGpu, SceneLayouts};
use super::uniforms::{ALPHA_MASK, GpuInstance, Vertex, alpha_mode_code};
use super::view::ViewSlot;
use super::{DEPTH_FORMAT, HDR_FORMAT};
use crate::gpu::layout;
use crate::scene::{Material, ProceduralHeight};
use crate::settings::{
    BumpView, EnvironmentMap, EnvironmentSettings, RenderSettings, ShadowFilter, ShadowMethod, ShadowView,
    TangentSource, TextureFilter,
};
use crate::shaders;

/// The frame's toggles that switch shader code on or off (the `override`s of
/// `shaders/scene.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FrameKey {
    pub shadow_method: u32,
    pub shadow_filter: u32,
    pub shadow_transmission: bool,
    pub shadow_texels_view: bool,
    pub level_colour: bool,
    pub bump: bool,
    pub bump_view: u32,
    pub tangents_per_vertex: bool,
    pub bump_analytic: bool,
    pub flat_colour: bool,
    /// `ENV_MAP_*`: where curved mirrors look their reflection up; 0: nowhere.
    pub environment: u32,
}

/// `ENVIRONMENT` codes: the world's cube, its sphere map, its lat–long map, or each reflective
/// object's own dynamic cube (the world's for objects without one).
pub const ENV_MAP_CUBE: u32 = 1;
pub const ENV_MAP_SPHERE: u32 = 2;
pub const ENV_MAP_LATLONG: u32 = 3;
pub const ENV_MAP_DYNAMIC: u32 = 4;

/// `SHADOW_METHOD`: no shadows at all (no light casts one, or shadows are off).
pub const SHADOWS_OFF: u32 = 0;
pub const SHADOWS_MAP: u32 = 1;
pub const SHADOWS_PROJECTED: u32 = 2;

impl FrameKey {
    /// `shadowed`: some light casts a shadow this frame; `transmission`: transparent occluders
    /// were drawn into the transmission maps.
    pub fn new(settings: &RenderSettings, shadowed: bool, transmission: bool) -> FrameKey {
        let shadows = &settings.shadows;
        FrameKey {
            shadow_method: match (shadowed && shadows.enabled, shadows.method) {
                (false, _) => SHADOWS_OFF,
                (true, ShadowMethod::Map) => SHADOWS_MAP,
                (true, ShadowMethod::Projected) => SHADOWS_PROJECTED,
            },
            shadow_filter: shadow_filter_code(shadows.filter),
            shadow_transmission: transmission,
            shadow_texels_view: shadows.view == ShadowView::Texels,
            level_colour: settings.textures.filter == TextureFilter::LevelColour,
            bump: settings.bump.enabled,
            bump_view: match settings.bump.view {
                BumpView::Off => 0,
                BumpView::Normals => BUMP_VIEW_NORMALS,
                BumpView::Tangents => BUMP_VIEW_TANGENTS,
            },
            tangents_per_vertex: settings.bump.tangents == TangentSource::PerVertex,
            bump_analytic: settings.bump.analytic,
            flat_colour: settings.raster.flat_colour,
            environment: environment_code(&settings.environment),
        }
    }
}

/// The `ENVIRONMENT` code of the environment settings.
pub fn environment_code(settings: &EnvironmentSettings) -> u32 {
    match (settings.enabled, settings.map, settings.dynamic) {
        (false, ..) => 0,
        (true, EnvironmentMap::Cube, false) => ENV_MAP_CUBE,
        (true, EnvironmentMap::Cube, true) => ENV_MAP_DYNAMIC,
        (true, EnvironmentMap::Sphere, _) => ENV_MAP_SPHERE,
        (true, EnvironmentMap::Latlong, _) => ENV_MAP_LATLONG,
    }
}

/// The `SHADOW_FILTER_*` code of `shaders/common/shadow.wgsl`.
pub fn shadow_filter_code(filter: ShadowFilter) -> u32 {
    match filter {
        ShadowFilter::None => 0,
        ShadowFilter::Hardware => 1,
        ShadowFilter::Pcf3x3 => 2,
        ShadowFilter::Pcf5x5 => 3,
        ShadowFilter::Poisson => 4,
    }
}

/// Every `ShadowFilter` and its code, for the test that ties them to the WGSL.
pub const SHADOW_FILTER_NAMES: [(&str, ShadowFilter); 5] = [
    ("SHADOW_FILTER_NONE", ShadowFilter::None),
    ("SHADOW_FILTER_HARDWARE", ShadowFilter::Hardware),
    ("SHADOW_FILTER_PCF3", ShadowFilter::Pcf3x3),
    ("SHADOW_FILTER_PCF5", ShadowFilter::Pcf5x5),
    ("SHADOW_FILTER_POISSON", ShadowFilter::Poisson),
];

/// What a material brings to the shader: which textures and which height field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialKey {
    pub color_texture: bool,
    /// `HEIGHT_*` of `shaders/scene.wgsl`: 0 none, 1 a height map, 2 a sine field, 3 value noise.
    pub height_kind: u32,
    pub normal_map: bool,
    /// `ALPHA_*` of `shaders/common/types.wgsl`.
    pub alpha_mode: u32,
}

impl MaterialKey {
    pub fn of(material: &Material) -> MaterialKey {
        MaterialKey {
            color_texture: material.texture.is_some(),
            height_kind: match (&material.height_field, &material.height_map) {
                (Some(ProceduralHeight::Sine { .. }), _) => HEIGHT_SINE,
                (Some(ProceduralHeight::Noise { .. }), _) => HEIGHT_NOISE,
                (None, Some(_)) => HEIGHT_TEXTURE,
                (None, None) => HEIGHT_NONE,
            },
            normal_map: material.normal_map.is_some(),
            alpha_mode: alpha_mode_code(material.alpha_mode),
        }
    }
}

/// `BUMP_VIEW_*` codes.
pub const BUMP_VIEW_NORMALS: u32 = 1;
pub const BUMP_VIEW_TANGENTS: u32 = 2;
/// `HEIGHT_*` codes: where a material's bump heights come from.
pub const HEIGHT_NONE: u32 = 0;
pub const HEIGHT_TEXTURE: u32 = 1;
pub const HEIGHT_SINE: u32 = 2;
pub const HEIGHT_NOISE: u32 = 3;

/// The names of the pipeline constants, in the order [`constants`] gives their values.
pub const CONSTANT_NAMES: [&str; 15] = [
    "SHADOW_METHOD",
    "SHADOW_FILTER",
    "SHADOW_TRANSMISSION",
    "SHADOW_TEXELS_VIEW",
    "LEVEL_COLOUR",
    "BUMP",
    "BUMP_VIEW",
    "TANGENTS_PER_VERTEX",
    "BUMP_ANALYTIC",
    "FLAT_COLOUR",
    "ENVIRONMENT",
    "COLOR_TEXTURE",
    "HEIGHT_KIND",
    "NORMAL_MAP",
    "ALPHA_MODE",
];

/// The pipeline constants of one variant.
pub fn constants(frame: &FrameKey, material: &MaterialKey) -> [(&'static str, f64); 15] {
    let flag = |b: bool| f64::from(u8::from(b));
    let values = [
        f64::from(frame.shadow_method),
        f64::from(frame.shadow_filter),
        flag(frame.shadow_transmission),
        flag(frame.shadow_texels_view),
        flag(frame.level_colour),
        flag(frame.bump),
        f64::from(frame.bump_view),
        flag(frame.tangents_per_vertex),
        flag(frame.bump_analytic),
        flag(frame.flat_colour),
        f64::from(frame.environment),
        flag(material.color_texture),
        f64::from(material.height_kind),
        flag(material.normal_map),
        f64::from(material.alpha_mode),
    ];
    std::array::from_fn(|i| (CONSTANT_NAMES[i], values[i]))
}

/// The depth test of a shading variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum DepthMode {
    /// The plain z-buffer: `Less`, depth written.
    Write,
    /// After a prepass: only the fragments at the prepass's depth, nothing written.
    Equal,
}

pub struct ScenePass {
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
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
}

/// What tells shading variants apart: the depth test, the frame's toggles, the material's inputs
/// and whether it is a mirror drawn with its reflection.
type ShadingKey = (DepthMode, FrameKey, MaterialKey, bool);

/// The reflections a view's mirrors show: per mirror object, and per part of it that is a mirror
/// (a box's face; `None`: all of it), the group 3 holding the image its mirrored camera drew.
/// `skip` is the object a mirrored view looks out of: it lies on the view's near plane (a box's
/// other faces behind it) and is not drawn.
#[derive(Default)]
pub struct MirrorImages {
    pub images: HashMap<usize, Vec<MirrorImage>>,
    pub skip: Option<usize>,
}

/// The part of a mirror object that shows an image (`None`: all of it), and its group 3.
pub type MirrorImage = (Option<Range<u32>>, wgpu::BindGroup);

/// What the pass draws into.
pub struct SceneTargets<'a> {
    pub hdr: &'a wgpu::TextureView,
    pub depth: &'a wgpu::TextureView,
    /// Linear radiance where nothing is drawn.
    pub background: glam::Vec3,
    /// Draw the world's environment where nothing is drawn (`fs_background`), over `background`.
    pub world: bool,
    /// Draw only inside `[x, y, width, height]`; `None`: everywhere.
    pub scissor: Option<[u32; 4]>,
}

/// The vertex buffers of every scene pipeline: the mesh's vertices, and the instances.
pub const VERTEX_BUFFERS: [Option<wgpu::VertexBufferLayout<'static>>; 2] =
    [Some(Vertex::LAYOUT), Some(GpuInstance::LAYOUT)];

impl ScenePass {
    pub fn new(device: &wgpu::Device, layouts: &SceneLayouts) -> ScenePass {
        let module = shaders::module(device, "scene::shader", shaders::SCENE);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene::layout"),
            bind_group_layouts: &[Some(&layouts.frame), Some(&layouts.material), Some(&layouts.lighting)],
            immediate_size: 0,
        });
        let prepass_pipeline = |label, fragment| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: vertex_state(&module),
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
                module: &module,
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
                2,
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2,
            )],
        });
        let mirror_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene::mirror_layout"),
            bind_group_layouts: &[
                Some(&layouts.frame),
                Some(&layouts.material),
                Some(&layouts.lighting),
                Some(&mirror_group_layout),
            ],
            immediate_size: 0,
        });
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
        let background = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene::background_pipeline"),
            layout: Some(&device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("scene::background_layout"),
                bind_group_layouts: &[Some(&layouts.frame), Some(&empty_layout), Some(&layouts.lighting)],
                immediate_size: 0,
            })),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_background"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            // At the far plane, where nothing was drawn.
            depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::LessEqual, false),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_background"),
                compilation_options: Default::default(),
                targets: &[Some(HDR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        ScenePass {
            module,
            layout,
            background,
            empty_group,
            mirror_group_layout,
            mirror_layout,
            prepass,
            prepass_masked,
            shading: HashMap::new(),
        }
    }

    /// Compiles the shading variants this frame needs that were not compiled before: every
    /// batch's material, and its mirror variant for mirror batches when `mirrors` are drawn.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        frame: FrameKey,
        scene: &SceneGpu,
        after_prepass: bool,
        mirrors: bool,
    ) {
        let depth = if after_prepass { DepthMode::Equal } else { DepthMode::Write };
        for batch in &scene.geometry.batches {
            let material = scene.material_keys[batch.material];
            let variants: &[bool] = if mirrors && batch.mirror { &[false, true] } else { &[false] };
            for &mirror in variants {
                let key = (depth, frame, material, mirror);
                if !self.shading.contains_key(&key) {
                    let pipeline = self.shading_pipeline(device, key);
                    self.shading.insert(key, pipeline);
                }
            }
        }
    }

    fn shading_pipeline(&self, device: &wgpu::Device, key: ShadingKey) -> wgpu::RenderPipeline {
        let (depth, frame, material, mirror) = key;
        // A mirror drawn with its image reflects through it, not through an environment map.
        let frame = if mirror { FrameKey { environment: 0, ..frame } } else { frame };
        let constants = constants(&frame, &material);
        let depth_state = match depth {
            DepthMode::Write => layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Less, true),
            DepthMode::Equal => layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Equal, false),
        };
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene::shading_pipeline"),
            layout: Some(if mirror { &self.mirror_layout } else { &self.layout }),
            vertex: vertex_state(&self.module),
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: depth_state,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                // A mirror drawn with its reflection reads group 3 (`fs_mirror`).
                entry_point: Some(if mirror { "fs_mirror" } else { "fs_scene" }),
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
            entries: &[wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(image) }],
        })
    }

    /// The shading module every scene pipeline is made from, and its pipeline layout (groups 0
    /// to 2): the transparency pass builds its variants from them.
    pub fn module(&self) -> &wgpu::ShaderModule {
        &self.module
    }

    pub fn layout(&self) -> &wgpu::PipelineLayout {
        &self.layout
    }

    /// The depth of the nearest surface at every pixel of `view`, and nothing else; transparent
    /// surfaces are left out when `opaque_only` (the transparency pass draws them later).
    pub fn record_prepass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        lighting: &wgpu::BindGroup,
        view: ViewSlot,
        depth: &wgpu::TextureView,
        opaque_only: bool,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene::prepass"),
            color_attachments: &[],
            depth_stencil_attachment: Some(layout::depth_attachment(depth, wgpu::LoadOp::Clear(1.0))),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.push_debug_group("depth prepass");
        pass.set_bind_group(0, scene.frame_group(), &[scene.views.offset(view)]);
        pass.set_bind_group(2, lighting, &[]);
        for batch in scene.geometry.batches.iter().filter(|b| !(opaque_only && b.transparent)) {
            let masked = scene.material_keys[batch.material].alpha_mode == ALPHA_MASK;
            pass.set_pipeline(if masked { &self.prepass_masked } else { &self.prepass });
            pass.set_bind_group(1, &scene.materials()[batch.material], &[]);
            scene.geometry.draw(&mut pass, batch);
        }
        pass.pop_debug_group();
    }

    /// Shades every surface seen from `view`; transparent ones are left out when `opaque_only`
    /// (the transparency pass draws them next), else drawn as opaque surfaces with their
    /// illumination model alone. `frame` must have been prepared, and `after_prepass` must match
    /// that preparation.
    #[allow(clippy::too_many_arguments)]
    pub fn record_opaque(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        lighting: &wgpu::BindGroup,
        view: ViewSlot,
        frame: FrameKey,
        targets: &SceneTargets,
        after_prepass: bool,
        opaque_only: bool,
        mirrors: &MirrorImages,
    ) {
        let bg = targets.background.as_dvec3();
        let (depth_mode, depth_load) = if after_prepass {
            (DepthMode::Equal, wgpu::LoadOp::Load)
        } else {
            (DepthMode::Write, wgpu::LoadOp::Clear(1.0))
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene::opaque"),
            color_attachments: &[Some(layout::color_attachment(
                targets.hdr,
                wgpu::LoadOp::Clear(wgpu::Color { r: bg.x, g: bg.y, b: bg.z, a: 1.0 }),
            ))],
            depth_stencil_attachment: Some(layout::depth_attachment(targets.depth, depth_load)),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.push_debug_group("opaque");
        if let Some([x, y, width, height]) = targets.scissor {
            pass.set_scissor_rect(x, y, width, height);
        }
        pass.set_bind_group(0, scene.frame_group(), &[scene.views.offset(view)]);
        pass.set_bind_group(2, lighting, &[]);
        // Batches come sorted by material: the pipeline changes only where the variant does.
        let mut current = None;
        for batch in scene.geometry.batches.iter().filter(|b| !(opaque_only && b.transparent)) {
            if batch.alone.is_some() && batch.alone == mirrors.skip {
                continue;
            }
            pass.set_bind_group(1, &scene.materials()[batch.material], &[]);
            let material = scene.material_keys[batch.material];
            let Some(object) = batch.alone.filter(|_| batch.mirror) else {
                let key = (depth_mode, frame, material, false);
                if current != Some(key) {
                    pass.set_pipeline(&self.shading[&key]);
                    current = Some(key);
                }
                scene.geometry.draw(&mut pass, batch);
                continue;
            };
            // A mirror: each of its parts with its image where its view was drawn, plain where not.
            let images = mirrors.images.get(&object);
            for part in scene.mirrors.iter().filter(|m| m.object == object).map(|m| m.indices.clone()) {
                let image = images.and_then(|list| list.iter().find(|(p, _)| *p == part)).map(|(_, group)| group);
                let key = (depth_mode, frame, material, image.is_some());
                if current != Some(key) {
                    pass.set_pipeline(&self.shading[&key]);
                    current = Some(key);
                }
                if let Some(image) = image {
                    pass.set_bind_group(3, image, &[]);
                }
                let count = scene.geometry.index_count(batch.mesh);
                scene.geometry.draw_part(&mut pass, batch.mesh, part.unwrap_or(0..count), batch.instances.clone());
            }
        }
        if targets.world {
            pass.set_pipeline(&self.background);
            pass.set_bind_group(1, &self.empty_group, &[]);
            pass.draw(0..3, 0..1);
        }
        pass.pop_debug_group();
    }
}

/// The vertex stage every scene pipeline shares (`vs_scene`).
pub fn vertex_state(module: &wgpu::ShaderModule) -> wgpu::VertexState<'_> {
    wgpu::VertexState {
        module,
        entry_point: Some("vs_scene"),
        compilation_options: Default::default(),
        buffers: &VERTEX_BUFFERS,
    }
}
