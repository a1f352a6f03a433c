//! Cast shadows (TECHNIQUES.md §4; seed 000 §1.3), two ways:
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
//! **Transparent occluders** (seed 003: 0 < s < 1) are drawn after the opaque depth of each
//! layer into a colour map that multiplies their `kt·MT` and keeps the nearest one's depth in
//! alpha. A receiver behind that depth is tinted by the product. The approximation: every
//! transparent surface in front of the nearest opaque one counts, even those behind the
//! receiver, when the receiver lies between two of them; the tracer gets that case right.

pub mod projected;
pub mod views;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use super::FrameTargets;
use super::scene_gpu::{SceneGpu, SceneLayouts};
use super::uniforms::Vertex;
use super::{DEPTH_FORMAT, HDR_FORMAT};
use crate::gpu::uniform::UniformBuffer;
use crate::gpu::{Gpu, layout};
use crate::settings::{ShadowFilter, ShadowMethod, ShadowSettings, ShadowView};
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

/// The `Shadows` uniform of `shaders/common/shadow.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuShadows {
    pub layers: [GpuShadowLayer; MAX_LAYERS],
    pub enabled: u32,
    pub method: u32,
    pub filter: u32,
    pub map_size: u32,
    pub normal_offset: f32,
    pub transmission: u32,
    pub view: u32,
    pub view_layer: u32,
}

impl GpuShadows {
    pub fn new(layout: &ShadowLayout, settings: &ShadowSettings, has_transparent: bool) -> GpuShadows {
        let mut layers = [GpuShadowLayer::zeroed(); MAX_LAYERS];
        for (gpu, view) in layers.iter_mut().zip(&layout.views) {
            *gpu = GpuShadowLayer {
                clip_from_world: view.clip_from_world.to_cols_array_2d(),
                texel_size: view.texel_size,
                perspective: u32::from(view.perspective),
                _pad: [0.0; 2],
            };
        }
        GpuShadows {
            layers,
            enabled: u32::from(settings.enabled && !layout.views.is_empty()),
            method: match settings.method {
                ShadowMethod::Map => 0,
                ShadowMethod::Projected => 1,
            },
            filter: match settings.filter {
                ShadowFilter::None => 0,
                ShadowFilter::Hardware => 1,
                ShadowFilter::Pcf3x3 => 2,
                ShadowFilter::Pcf5x5 => 3,
                ShadowFilter::Poisson => 4,
            },
            map_size: settings.map_size,
            normal_offset: settings.normal_offset,
            transmission: u32::from(settings.transmission && has_transparent),
            view: match settings.view {
                ShadowView::Off => 0,
                ShadowView::Map => 1,
                ShadowView::Texels => 2,
            },
            view_layer: settings.view_layer,
        }
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

fn array_texture(
    device: &wgpu::Device,
    label: &str,
    size: u32,
    layers: u32,
    format: wgpu::TextureFormat,
) -> (wgpu::Texture, wgpu::TextureView, Vec<wgpu::TextureView>) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: layers },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let array = texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some(label),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
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
    (texture, array, per_layer)
}

impl ShadowTargets {
    /// At least one layer of each, so the opaque pass can always bind them; 1×1 when unused.
    fn new(device: &wgpu::Device, size: u32, layers: u32, with_transmission: bool) -> ShadowTargets {
        let layers = layers.max(1);
        let (_, depth_array, depth_layers) = array_texture(device, "shadow::depth_maps", size, layers, DEPTH_FORMAT);
        let (transmission_size, transmission_layers_count) = if with_transmission { (size, layers) } else { (1, 1) };
        let (_, transmission_array, transmission_layers) = array_texture(
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

/// Pass 1 of the shadow-map algorithm, its targets, and the shadow inputs of the opaque pass.
pub struct ShadowPass {
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    depth_pipeline: Option<(Bias, wgpu::RenderPipeline)>,
    transmission_pipeline: wgpu::RenderPipeline,
    layer_views: Vec<(UniformBuffer<[[f32; 4]; 4]>, wgpu::BindGroup)>,
    targets: Option<ShadowTargets>,
    /// Bumped whenever the targets are recreated, so bind groups that read them can follow.
    pub generation: u64,
    pub uniform: UniformBuffer<GpuShadows>,
    /// Group 3 of the opaque pass: what pass 2 reads.
    pub input_layout: wgpu::BindGroupLayout,
    linear: wgpu::Sampler,
    nearest: wgpu::Sampler,
    map_view: MapView,
    frusta: Frusta,
}

impl ShadowPass {
    pub fn new(device: &wgpu::Device, scene_layouts: &SceneLayouts) -> ShadowPass {
        let module = shaders::module(device, "shadow::shader", shaders::SHADOW);
        let layer_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow::layer_layout"),
            entries: &[layout::uniform(0, wgpu::ShaderStages::VERTEX)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow::layout"),
            bind_group_layouts: &[Some(&layer_layout), Some(&scene_layouts.material), Some(&scene_layouts.object)],
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
        let layer_views = (0..MAX_LAYERS)
            .map(|layer| {
                let uniform = UniformBuffer::new(
                    device,
                    &format!("shadow::layer_view {layer}"),
                    &glam::Mat4::IDENTITY.to_cols_array_2d(),
                );
                let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("shadow::layer_group {layer}")),
                    layout: &layer_layout,
                    entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.binding() }],
                });
                (uniform, group)
            })
            .collect();
        let input_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow::input_layout"),
            entries: &[
                layout::uniform(0, wgpu::ShaderStages::FRAGMENT),
                layout::texture(1, wgpu::TextureSampleType::Depth, wgpu::TextureViewDimension::D2Array),
                layout::sampler(2, wgpu::SamplerBindingType::Comparison),
                layout::sampler(3, wgpu::SamplerBindingType::Comparison),
                layout::texture(
                    4,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2Array,
                ),
                layout::texture(
                    5,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
            ],
        });
        let comparison = |label, filter| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                address_mode_u: wgpu::AddressMode::ClampToEdge,
                address_mode_v: wgpu::AddressMode::ClampToEdge,
                mag_filter: filter,
                min_filter: filter,
                // Lit where the reference (the point's depth) is no farther than the stored one.
                compare: Some(wgpu::CompareFunction::LessEqual),
                ..Default::default()
            })
        };
        let linear = comparison("shadow::linear_sampler", wgpu::FilterMode::Linear);
        let nearest = comparison("shadow::nearest_sampler", wgpu::FilterMode::Nearest);
        let uniform = UniformBuffer::new(device, "shadow::uniform", &GpuShadows::zeroed());
        let map_view = MapView::new(device, &module);
        let frusta = Frusta::new(device, &module);
        ShadowPass {
            module,
            pipeline_layout,
            depth_pipeline: None,
            transmission_pipeline,
            layer_views,
            targets: None,
            generation: 0,
            uniform,
            input_layout,
            linear,
            nearest,
            map_view,
            frusta,
        }
    }

    /// Makes the targets and the depth pipeline fit this frame's layout and settings, and writes
    /// the shadow uniforms.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &ShadowLayout,
        settings: &ShadowSettings,
        has_transparent: bool,
    ) {
        let layers = layout.views.len() as u32;
        let with_transmission = settings.transmission && has_transparent && layers > 0;
        let size = if layers > 0 { settings.map_size } else { 1 };
        let fits = self
            .targets
            .as_ref()
            .is_some_and(|t| t.size == size && t.layers == layers.max(1) && t.with_transmission == with_transmission);
        if !fits {
            self.targets = Some(ShadowTargets::new(device, size, layers, with_transmission));
            self.generation += 1;
        }
        let bias = Bias { constant: settings.depth_bias, slope: settings.slope_bias };
        if self.depth_pipeline.as_ref().is_none_or(|(b, _)| *b != bias) {
            self.depth_pipeline = Some((bias, self.depth_pipeline(device, bias)));
        }
        for (view, (uniform, _)) in layout.views.iter().zip(&self.layer_views) {
            uniform.write(queue, &view.clip_from_world.to_cols_array_2d());
        }
        self.uniform.write(queue, &GpuShadows::new(layout, settings, has_transparent));
    }

    fn depth_pipeline(&self, device: &wgpu::Device, bias: Bias) -> wgpu::RenderPipeline {
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
            fragment: None,
            multiview_mask: None,
            cache: None,
        })
    }

    /// The opaque pass's group 3, reading this pass's targets and `projected_mask`.
    pub fn inputs(&self, device: &wgpu::Device, projected_mask: &wgpu::TextureView) -> wgpu::BindGroup {
        let targets = self.targets.as_ref().expect("prepare() runs before inputs()");
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow::inputs"),
            layout: &self.input_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.uniform.binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&targets.depth_array) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&self.linear) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&self.nearest) },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(&targets.transmission_array),
                },
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(projected_mask) },
            ],
        })
    }

    /// Pass 1: every layer's depth, then its transparent occluders' transmission.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, scene: &SceneGpu, layout: &ShadowLayout) {
        let targets = self.targets.as_ref().expect("prepare() runs before record()");
        let (_, depth_pipeline) = self.depth_pipeline.as_ref().expect("prepare() builds the depth pipeline");
        encoder.push_debug_group("shadow maps");
        for (layer, _) in layout.views.iter().enumerate() {
            let depth_view = &targets.depth_layers[layer];
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("shadow::depth_pass"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: depth_view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(depth_pipeline);
                pass.set_bind_group(0, &self.layer_views[layer].1, &[]);
                draw(&mut pass, scene, false);
            }
            if targets.with_transmission {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("shadow::transmission_pass"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &targets.transmission_layers[layer],
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::WHITE),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: depth_view,
                        depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.transmission_pipeline);
                pass.set_bind_group(0, &self.layer_views[layer].1, &[]);
                draw(&mut pass, scene, true);
            }
        }
        encoder.pop_debug_group();
    }

    /// The teaching views drawn over the shaded HDR image: the map itself, or the frusta.
    pub fn record_views(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        settings: &ShadowSettings,
        layout: &ShadowLayout,
        camera_clip_from_world: glam::Mat4,
        frame: &FrameTargets,
    ) {
        let (device, queue) = (&gpu.device, &gpu.queue);
        let (hdr, depth, size) = (&frame.hdr.view, &frame.depth.view, frame.size);
        let Some(targets) = self.targets.as_ref() else { return };
        if settings.view == ShadowView::Map && !layout.views.is_empty() {
            let layer = settings.view_layer.min(layout.views.len() as u32 - 1);
            let ratio = layout.views[layer as usize].depth_ratio;
            self.map_view.record(device, queue, encoder, &targets.depth_array, layer, ratio, size, hdr);
        }
        if settings.show_frusta && !layout.views.is_empty() {
            self.frusta.record(device, queue, encoder, layout, camera_clip_from_world, hdr, depth);
        }
    }
}

/// The one vertex buffer of pass 1: the scene's vertices.
const VERTEX_BUFFERS: [Option<wgpu::VertexBufferLayout<'static>>; 1] = [Some(Vertex::LAYOUT)];

fn vertex_state(module: &wgpu::ShaderModule) -> wgpu::VertexState<'_> {
    wgpu::VertexState {
        module,
        entry_point: Some("vs_shadow"),
        compilation_options: Default::default(),
        buffers: &VERTEX_BUFFERS,
    }
}

/// Draws the opaque (or the transparent) drawables with bind groups 1 and 2.
fn draw(pass: &mut wgpu::RenderPass<'_>, scene: &SceneGpu, transparent: bool) {
    for drawable in scene.drawables.iter().filter(|d| d.transparent == transparent) {
        pass.set_bind_group(1, &scene.materials()[drawable.material], &[]);
        pass.set_bind_group(2, &drawable.object, &[]);
        pass.set_vertex_buffer(0, drawable.vertices.slice(..));
        pass.set_index_buffer(drawable.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..drawable.index_count, 0, 0..1);
    }
}

/// Teaching view: one map layer drawn over the image as grey levels.
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
            label: Some("shadow::map_view_layout"),
            entries: &[
                layout::texture(1, wgpu::TextureSampleType::Depth, wgpu::TextureViewDimension::D2Array),
                layout::uniform(2, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow::map_view_pipeline_layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = layout::fullscreen_pipeline(
            device,
            "shadow::map_view_pipeline",
            &pipeline_layout,
            module,
            ("vs_shadow_map_view", "fs_shadow_map_view"),
            &[Some(HDR_FORMAT.into())],
        );
        let uniform = UniformBuffer::new(device, "shadow::map_view_uniform", &GpuShownLayer::zeroed());
        MapView { pipeline, layout, uniform }
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
            label: Some("shadow::map_view_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(maps) },
                wgpu::BindGroupEntry { binding: 2, resource: self.uniform.binding() },
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shadow::map_view_pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: hdr,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
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

/// Teaching view: the edges of each light view's volume, drawn into the scene.
struct Frusta {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    uniform: UniformBuffer<[[f32; 4]; 4]>,
}

impl Frusta {
    fn new(device: &wgpu::Device, module: &wgpu::ShaderModule) -> Frusta {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow::frusta_layout"),
            entries: &[layout::uniform(3, wgpu::ShaderStages::VERTEX)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow::frusta_pipeline_layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow::frusta_pipeline"),
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
        let uniform = UniformBuffer::new(device, "shadow::frusta_camera", &glam::Mat4::IDENTITY.to_cols_array_2d());
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow::frusta_group"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry { binding: 3, resource: uniform.binding() }],
        });
        Frusta { pipeline, group, uniform }
    }

    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        layout: &ShadowLayout,
        clip_from_world: glam::Mat4,
        hdr: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) {
        const EDGES: [(usize, usize); 12] =
            [(0, 1), (2, 3), (0, 2), (1, 3), (4, 5), (6, 7), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];
        let lines: Vec<Vec3> = (0..layout.views.len())
            .flat_map(|layer| {
                let corners = layout.corners(layer);
                EDGES.into_iter().flat_map(move |(a, b)| [corners[a], corners[b]])
            })
            .collect();
        self.uniform.write(queue, &clip_from_world.to_cols_array_2d());
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow::frusta_vertices"),
            contents: bytemuck::cast_slice(&lines),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shadow::frusta_pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: hdr,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.draw(0..lines.len() as u32, 0..1);
    }
}
