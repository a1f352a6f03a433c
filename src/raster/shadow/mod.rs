//! Cast shadows (docs/course/05-shadows.md), two ways:
//!
//! - **Image precision, the two-pass z-buffer algorithm.** Pass 1 ([`ShadowPass::record`])
//!   renders the scene's depth as each light sees it ([`views`]) into one layer of a depth-texture
//!   array per light view: the "Z-buffer A" of the notes. Pass 2 is the opaque pass: each shaded
//!   point `q` is projected into the light's view and its depth compared with the stored one
//!   (`shaders/common/shadow.wgsl`): farther than what the light sees means shadowed.
//! - **Object precision** ([`projected`]): shadow polygons projected onto planar receivers.
//!
//! The classic artefacts and their cures are all settings (`[shadows]`): acne (a surface
//! shadowing itself because its own depth, resampled, falls behind itself) is cured by a
//! constant and a slope-scaled depth bias in pass 1 and a normal offset of the lookup point in
//! pass 2; too much of either detaches shadows from their casters (peter-panning). Map texels
//! larger than a pixel alias; map size and percentage-closer filtering (PCF: several hardware
//! comparisons averaged) trade that for blur.
//!
//! **Transparent occluders** (0 < s < 1, docs/course/05-shadows.md#through-glass) are drawn after the opaque depth of each
//! layer into a colour map that multiplies their `kt·MT` and keeps the nearest one's depth in
//! alpha. A receiver behind that depth is tinted by the product. The approximation: every
//! transparent surface in front of the nearest opaque one counts, even those behind the
//! receiver, when the receiver lies between two of them; the tracer gets that case right.
//!
//! **The maps are kept across frames.** A layer depends on its light view, the casters and the
//! bias, not on the camera: [`ShadowPass::record`] redraws only the layers whose inputs changed,
//! so orbiting the camera around a point or spot light redraws nothing. A directional light's
//! window follows the view frustum (to spend its texels where the camera looks), so its one
//! layer is redrawn when the camera moves; `shadows.fit = "scene"` fits it to the whole scene
//! instead, which makes it camera-independent at the cost of coarser texels.

pub mod projected;
pub mod views;

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};
use serde::Serialize;

use super::context::{Figure, FrameEncoder};
use super::geometry::DrawListId;
use super::inspect::GpuInspectLight;
use super::scene_gpu::{SceneGpu, SceneLayouts, VERTEX_BUFFERS};
use super::targets::DEPTH_FORMAT;
use super::uniforms::ALPHA_MASK;
use super::view::{View, ViewSlot};
use crate::gpu::texture::{GpuTexture, Layers};
use crate::gpu::uniform::UniformBuffer;
use crate::gpu::{Gpu, layout};
use crate::scene::Light;
use crate::settings::{ShadowMethod, ShadowSettings};
use crate::shaders;
use views::{MAX_LAYERS, ShadowLayout};

/// Transparent occluders' transmission and nearest depth.
pub const TRANSMISSION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuShadowLayer {
    pub clip_from_world: [[f32; 4]; 4],
    pub texel_size: f32,
    pub perspective: u32,
    pub _pad: [f32; 2],
}

/// The `Shadows` uniform of `shaders/common/shadow.wgsl`: the light views and the lookup's
/// numbers. Which method and filter are used are pipeline constants of the scene pass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuShadows {
    pub layers: [GpuShadowLayer; MAX_LAYERS],
    pub map_size: u32,
    pub normal_offset: f32,
    pub _pad: [f32; 2],
}

impl GpuShadows {
    pub fn new(layout: &ShadowLayout, settings: &ShadowSettings) -> GpuShadows {
        let mut layers = [GpuShadowLayer::zeroed(); MAX_LAYERS];
        for (gpu, view) in layers.iter_mut().zip(&layout.views) {
            *gpu = GpuShadowLayer {
                clip_from_world: view.clip_from_world.to_cols_array_2d(),
                texel_size: view.texel_size,
                perspective: u32::from(view.perspective),
                _pad: [0.0; 2],
            };
        }
        GpuShadows { layers, map_size: settings.map_size, normal_offset: settings.normal_offset, _pad: [0.0; 2] }
    }
}

/// The maps of pass 1: a depth layer per light view, and the transmission layers.
struct ShadowTargets {
    size: u32,
    layers: u32,
    with_transmission: bool,
    depth_array: wgpu::TextureView,
    depth_layers: Vec<wgpu::TextureView>,
    transmission_array: wgpu::TextureView,
    transmission_layers: Vec<wgpu::TextureView>,
}

/// A 2D array of `layers` square maps (padded so that GL keeps it an array: [`Layers`]), the
/// view the lookups sample it through, and a view of each layer to draw it.
fn array_texture(
    device: &wgpu::Device,
    label: &str,
    size: u32,
    layers: u32,
    format: wgpu::TextureFormat,
) -> (wgpu::TextureView, Vec<wgpu::TextureView>) {
    let GpuTexture { texture, view: array } = Layers::Array(layers).texture(
        device,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
    );
    let per_layer = (0..layers)
        .map(|layer| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(label),
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer,
                array_layer_count: Some(1),
                ..Default::default()
            })
        })
        .collect();
    (array, per_layer)
}

impl ShadowTargets {
    /// At least one layer of each, so the opaque pass can always bind them; 1×1 when unused.
    fn new(device: &wgpu::Device, size: u32, layers: u32, with_transmission: bool) -> ShadowTargets {
        let layers = layers.max(1);
        let (depth_array, depth_layers) = array_texture(device, "shadow::depth_maps", size, layers, DEPTH_FORMAT);
        let (transmission_size, transmission_layers_count) = if with_transmission { (size, layers) } else { (1, 1) };
        let (transmission_array, transmission_layers) = array_texture(
            device,
            "shadow::transmission_maps",
            transmission_size,
            transmission_layers_count,
            TRANSMISSION_FORMAT,
        );
        ShadowTargets {
            size,
            layers,
            with_transmission,
            depth_array,
            depth_layers,
            transmission_array,
            transmission_layers,
        }
    }
}

/// The hardware depth bias of pass 1: the pipeline's fixed-function state, so a change of bias
/// builds a new pipeline variant.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bias {
    constant: i32,
    slope: f32,
}

/// What a layer's content depends on: when it matches the last drawn one, the layer is kept.
#[derive(Clone, Debug, PartialEq)]
struct LayerInputs {
    clip_from_world: glam::Mat4,
    /// The casters: the scene's draw list.
    geometry: DrawListId,
    bias: Bias,
}

/// What pass 1 made, for pass 2 to read: the maps, their uniform and the samplers.
pub struct ShadowMaps<'a> {
    pub uniform: &'a UniformBuffer<GpuShadows>,
    pub depth: &'a wgpu::TextureView,
    pub transmission: &'a wgpu::TextureView,
    /// The comparison sampler (bilinear, clamped to the edge) every filter reads the maps with.
    pub sampler: &'a wgpu::Sampler,
}

/// Pass 1 of the shadow-map algorithm and its targets, kept across frames.
pub struct ShadowPass {
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    /// The depth pipelines for the current bias: plain, and for cut-out casters.
    depth_pipeline: Option<(Bias, [wgpu::RenderPipeline; 2])>,
    transmission_pipeline: wgpu::RenderPipeline,
    targets: Option<ShadowTargets>,
    /// What each layer was last drawn from.
    drawn: Vec<Option<LayerInputs>>,
    uniform: UniformBuffer<GpuShadows>,
    sampler: wgpu::Sampler,
}

impl ShadowPass {
    pub fn new(device: &wgpu::Device, scene_layouts: &SceneLayouts) -> ShadowPass {
        let module = shaders::module(device, "shadow::shader", shaders::SHADOW);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow::layout"),
            bind_group_layouts: &[Some(&scene_layouts.frame), Some(&scene_layouts.material)],
            immediate_size: 0,
        });
        let blend = wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Zero,
                dst_factor: wgpu::BlendFactor::Src,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Min,
            },
        };
        let transmission_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow::transmission_pipeline"),
            layout: Some(&pipeline_layout),
            vertex: vertex_state(&module),
            primitive: Default::default(),
            depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::LessEqual, false),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_shadow_transmission"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: TRANSMISSION_FORMAT,
                    blend: Some(blend),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow::comparison_sampler"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            // Lit where the reference (the point's depth) is no farther than the stored one.
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        ShadowPass {
            module,
            pipeline_layout,
            depth_pipeline: None,
            transmission_pipeline,
            targets: None,
            drawn: Vec::new(),
            uniform: UniformBuffer::new(device, "shadow::uniform", &GpuShadows::zeroed()),
            sampler,
        }
    }

    /// Pass 1's depth pipeline; with `masked`, a fragment stage drops what a cut-out caster's
    /// coverage removes.
    fn depth_pipeline(&self, device: &wgpu::Device, bias: Bias, masked: bool) -> wgpu::RenderPipeline {
        let fragment = masked.then(|| wgpu::FragmentState {
            module: &self.module,
            entry_point: Some("fs_shadow_mask"),
            compilation_options: Default::default(),
            targets: &[],
        });
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow::depth_pipeline"),
            layout: Some(&self.pipeline_layout),
            vertex: vertex_state(&self.module),
            // Both faces: open surfaces (planes, quads of a model) must cast too.
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Less, true).map(|state| {
                wgpu::DepthStencilState {
                    bias: wgpu::DepthBiasState { constant: bias.constant, slope_scale: bias.slope, clamp: 0.0 },
                    ..state
                }
            }),
            multisample: Default::default(),
            fragment,
            multiview_mask: None,
            cache: None,
        })
    }

    /// Forgets every kept layer, so the next [`Self::record`] draws them all.
    pub fn invalidate(&mut self) {
        self.drawn.clear();
    }

    /// Pass 1: makes the targets fit `layout` and `settings`, writes the light views (layer `k`
    /// into view slot `first_slot + k`) and the shadow uniform, and records every layer whose
    /// inputs changed since it was last drawn: its depth, then its transparent occluders'
    /// transmission.
    pub fn record(
        &mut self,
        gpu: &Gpu,
        frame: &mut FrameEncoder,
        scene: &SceneGpu,
        (layout, first_slot): (&ShadowLayout, u32),
        settings: &ShadowSettings,
    ) {
        let has_transparent = scene.geometry.has_transparent();
        let layers = layout.views.len() as u32;
        let with_transmission = settings.transmission && has_transparent && layers > 0;
        let size = if layers > 0 { settings.map_size } else { 1 };
        let fits = self
            .targets
            .as_ref()
            .is_some_and(|t| t.size == size && t.layers == layers.max(1) && t.with_transmission == with_transmission);
        if !fits {
            self.targets = Some(ShadowTargets::new(&gpu.device, size, layers, with_transmission));
            self.drawn.clear();
        }
        let bias = Bias { constant: settings.depth_bias, slope: settings.slope_bias };
        if self.depth_pipeline.as_ref().is_none_or(|(b, _)| *b != bias) {
            let pipelines = [false, true].map(|masked| self.depth_pipeline(&gpu.device, bias, masked));
            self.depth_pipeline = Some((bias, pipelines));
        }
        self.uniform.write(&gpu.queue, &GpuShadows::new(layout, settings));
        self.drawn.resize(layout.views.len(), None);
        let geometry = scene.geometry.draw_list();
        let stale: Vec<usize> = (0..layout.views.len())
            .filter(|&layer| {
                let inputs = LayerInputs {
                    clip_from_world: layout.views[layer].clip_from_world,
                    geometry: geometry.clone(),
                    bias,
                };
                let keep = settings.cache && self.drawn[layer].as_ref() == Some(&inputs);
                self.drawn[layer] = Some(inputs);
                !keep
            })
            .collect();
        frame.group("shadow maps", |frame| {
            for &layer in &stale {
                let slot = ViewSlot(first_slot + layer as u32);
                scene.views.write(&gpu.queue, slot, &View::projection_only(layout.views[layer].clip_from_world));
                self.record_layer(&mut frame.encoder, scene, layer, slot);
            }
        });
        frame.end("shadow maps", &[("layers drawn", Figure::Count(stale.len() as u64))]);
    }

    /// What the last [`Self::record`] made, for pass 2.
    pub fn maps(&self) -> ShadowMaps<'_> {
        let targets = self.targets.as_ref().expect("ShadowPass::record runs before the maps are read");
        ShadowMaps {
            uniform: &self.uniform,
            depth: &targets.depth_array,
            transmission: &targets.transmission_array,
            sampler: &self.sampler,
        }
    }

    fn record_layer(&self, encoder: &mut wgpu::CommandEncoder, scene: &SceneGpu, layer: usize, slot: ViewSlot) {
        let targets = self.targets.as_ref().expect("record() makes the targets first");
        let (_, depth_pipelines) = self.depth_pipeline.as_ref().expect("record() builds the depth pipelines first");
        let depth_view = &targets.depth_layers[layer];
        let view_offset = [scene.views.offset(slot)];
        {
            let mut pass = encoder.begin_render_pass(&layout::pass(
                "shadow::depth_pass",
                &[],
                Some(layout::depth_attachment(depth_view, wgpu::LoadOp::Clear(1.0))),
            ));
            pass.set_bind_group(0, scene.frame_group(), &view_offset);
            for batch in scene.geometry.batches.iter().filter(|b| !b.transparent) {
                let masked = scene.material_keys[batch.material].alpha_mode == ALPHA_MASK;
                pass.set_pipeline(&depth_pipelines[usize::from(masked)]);
                pass.set_bind_group(1, &scene.materials()[batch.material], &[]);
                scene.geometry.draw(&mut pass, batch);
            }
        }
        if targets.with_transmission {
            let mut pass = encoder.begin_render_pass(&layout::pass(
                "shadow::transmission_pass",
                &[Some(layout::color_attachment(
                    &targets.transmission_layers[layer],
                    wgpu::LoadOp::Clear(wgpu::Color::WHITE),
                ))],
                Some(layout::depth_attachment(depth_view, wgpu::LoadOp::Load)),
            ));
            pass.set_pipeline(&self.transmission_pipeline);
            pass.set_bind_group(0, scene.frame_group(), &view_offset);
            for batch in scene.geometry.batches.iter().filter(|b| b.transparent) {
                pass.set_bind_group(1, &scene.materials()[batch.material], &[]);
                scene.geometry.draw(&mut pass, batch);
            }
        }
    }
}

fn vertex_state(module: &wgpu::ShaderModule) -> wgpu::VertexState<'_> {
    wgpu::VertexState {
        module,
        entry_point: Some("vs_shadow"),
        compilation_options: Default::default(),
        buffers: &VERTEX_BUFFERS,
    }
}
/// What a shadow lookup read.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShadowLookup {
    /// `map` or `projected`.
    pub method: &'static str,
    pub layer: Option<u32>,
    pub texel: Option<[u32; 2]>,
    pub stored_depth: Option<f32>,
    pub receiver_depth: Option<f32>,
    /// The constant depth bias at the stored depth (`depth_bias` steps of the depth format's
    /// resolution there); the slope-scaled part depends on the occluder's slope.
    pub bias: Option<f32>,
    /// The lookup point moved along the normal, in world units.
    pub normal_offset: Option<f32>,
    /// The filter's fraction of lit comparisons (1 − the mask for projected shadows).
    pub lit: f32,
    /// The map texel's four corners in the world, at the stored depth: where it lies on the
    /// occluder (or the receiver) the light saw there.
    pub footprint: Option<[Vec3; 4]>,
}

/// What the shadow lookup of light `light` read at `world` (its record `l`), for `mirador
/// explain`: for shadow maps the layer, texel, depths, bias and the texel's footprint on the
/// occluder; for projected shadows the mask; both against the frame's own `layout`.
pub fn lookup(
    light: &Light,
    l: &GpuInspectLight,
    world: Vec3,
    layout: &ShadowLayout,
    settings: &ShadowSettings,
) -> ShadowLookup {
    match settings.method {
        ShadowMethod::Projected => ShadowLookup {
            method: "projected",
            layer: None,
            texel: None,
            stored_depth: None,
            receiver_depth: None,
            bias: None,
            normal_offset: None,
            lit: l.lit,
            footprint: None,
        },
        ShadowMethod::Map => {
            let looked = l.layer >= 0;
            // A map texel's world size at the point: fixed for orthographic views, growing
            // with the distance from the light for perspective ones (as the lookup has it).
            let texel_size =
                looked.then(|| layout.views.get(l.layer as usize)).flatten().map(|view| match light.position() {
                    Some(position) if view.perspective => view.texel_size * position.distance(world),
                    _ => view.texel_size,
                });
            ShadowLookup {
                method: "map",
                layer: looked.then_some(l.layer as u32),
                texel: looked.then_some([l.texel.x as u32, l.texel.y as u32]),
                stored_depth: looked.then_some(l.stored_depth),
                receiver_depth: looked.then_some(l.receiver_depth),
                bias: looked.then(|| constant_bias(l.stored_depth, settings.depth_bias)),
                normal_offset: texel_size.map(|t| settings.normal_offset * t),
                lit: l.lit,
                footprint: looked
                    .then(|| layout.views.get(l.layer as usize))
                    .flatten()
                    .map(|view| texel_footprint(view.clip_from_world, l.texel, l.stored_depth, settings.map_size)),
            }
        }
    }
}

/// The world corners of texel `texel` of a `size`² shadow map whose light sees the world through
/// `clip_from_world`, at depth `depth`.
fn texel_footprint(clip_from_world: glam::Mat4, texel: Vec2, depth: f32, size: u32) -> [Vec3; 4] {
    let world_from_clip = clip_from_world.inverse();
    let corner = |dx: f32, dy: f32| {
        let uv = (texel + Vec2::new(dx, dy)) / size as f32;
        world_from_clip.project_point3(Vec3::new(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y, depth))
    };
    [corner(0.0, 0.0), corner(1.0, 0.0), corner(1.0, 1.0), corner(0.0, 1.0)]
}

/// The constant part of the hardware depth bias at depth `z` for a 32-bit float depth buffer:
/// `steps` times the spacing of floats at `z`, `2^(⌊log2 z⌋ − 23)`.
pub fn constant_bias(z: f32, steps: i32) -> f32 {
    if z <= 0.0 {
        return 0.0;
    }
    steps as f32 * (2.0f32).powi(z.log2().floor() as i32 - 23)
}
