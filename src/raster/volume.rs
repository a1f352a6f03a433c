//! Volumes in the rasterizer (docs/course/11-volumes.md): a GPU ray-marching pass over the opaque image,
//! the twin of `crate::volume::march` (`shaders/volume.wgsl`).
//!
//! Per scene, each volume's normalized field becomes a 3D texture (`R16Float`, filterable, so the
//! hardware does the nearest or trilinear reconstruction) and its transfer function a uniform
//! array of 256 entries ([`VolumePass::load`]). In every view (the main camera, mirrored cameras, cube faces),
//! each volume's box is drawn, back faces only, so a camera inside the box still marches it:
//! - **isosurfaces** with the opaque surfaces ([`PreparedVolumes::record_isosurfaces`]): the
//!   view's depth is copied (by drawing, [`DepthCopy`]: GL cannot copy a depth texture), rays end
//!   at the copy, and each crossing writes its colour and depth like any surface, so what lies
//!   behind it is hidden;
//! - **composited volumes** in the transparency pass's order ([`PreparedVolumes::composite`]):
//!   each ray is marched over the span the order gives it (between two peeled transparent layers,
//!   or whole) and blended `C + (1 − α)·L_behind` (One, OneMinusSrcAlpha).
//!
//! Where the rasterizer differs from the tracer, and why:
//! - an isosurface shows its local model without mirror reflections;
//! - the field is stored as 16-bit floats (about 3 decimal digits of the normalized value);
//! - with the sorted transparency orders a volume is placed among the transparent surfaces by its
//!   centre, whole; only `exact` cuts each ray at every transparent layer as the tracer does;
//! - early termination ends the march, but the blend still adds the last `1 − α` of what is
//!   behind, which the tracer leaves out.
//!
//! A grid larger than the device's 3D texture limit is resampled (trilinearly) to fit, with a
//! warning: the rasterizer then shows a coarser field than the tracer.

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec3, Vec3};

use super::context::{Figure, FrameContext, FrameEncoder};
use super::inspect::{INSPECT_ISOSURFACE, INSPECT_VOLUME, Part, RecordKind, no_terms};
use super::keys::{FrameKey, MaterialKey, constants, pipeline_constants};
use super::scene_gpu::{SceneLayouts, SurfaceLayout, SurfaceModule};
use super::scene_pass::scissor;
use super::targets::{DEPTH_FORMAT, FrameTargets, HDR_FORMAT, PerTarget};
use super::view::{FrameView, ViewTargets};
use crate::gpu::Gpu;
use crate::gpu::depth_copy::{DepthCopy, DepthImageCopy};
use crate::gpu::layout;
use crate::gpu::uniform::UniformBuffer;
use crate::scene::Scene;
use crate::settings::{VOLUME_SAMPLES_WHITE, VolumeGradient, VolumeReconstruction, VolumeSettings, VolumeView};
use crate::shaders;
use crate::shaders::constants::{
    VOLUME_GRADIENT_CENTRAL, VOLUME_GRADIENT_FORWARD, VOLUME_GRADIENT_OFF, VOLUME_VIEW_SAMPLES,
};
use crate::volume::transfer::TABLE_SIZE;
use crate::volume::{Grid, Reconstruction, Rendering, Volume};

/// `volume` in `shaders/volume.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVolume {
    pub world_from_local: Mat4,
    pub local_from_world: Mat4,
    pub normal_from_local: Mat4,
    pub half_extent: Vec3,
    pub voxel_length: f32,
    pub spacing: Vec3,
    pub step: f32,
    pub dims: Vec3,
    pub iso: f32,
    pub termination: f32,
    pub opacity_correction: u32,
    pub view: u32,
    pub samples_white: f32,
}

pipeline_constants! {
    /// The volume pipelines' own `override`s in `shaders/volume.wgsl`, besides the scene's:
    /// the gradient, shadowed samples, and whether transparent layers bound the rays behind
    /// (`far`) and in front (`near`).
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    pub struct VolumeKey(settings: &VolumeSettings, limits: (bool, bool)) {
        gradient: u32 = "VOLUME_GRADIENT" <- gradient_code(settings.gradient),
        shadows: bool = "VOLUME_SHADOWS" <- settings.shadows,
        far_limit: bool = "VOLUME_FAR_LIMIT" <- limits.0,
        near_limit: bool = "VOLUME_NEAR_LIMIT" <- limits.1,
    }
}

/// The `VOLUME_GRADIENT_*` code of `gradient`.
pub fn gradient_code(gradient: VolumeGradient) -> u32 {
    match gradient {
        VolumeGradient::Off => VOLUME_GRADIENT_OFF,
        VolumeGradient::Forward => VOLUME_GRADIENT_FORWARD,
        VolumeGradient::Central => VOLUME_GRADIENT_CENTRAL,
    }
}

/// One volume on the GPU, made once per scene.
pub struct VolumeGpu {
    field: wgpu::TextureView,
    table: wgpu::Buffer,
    uniform: UniformBuffer<GpuVolume>,
    /// The grid the texture holds (smaller than the scene's when it was resampled to fit).
    grid_on_gpu: Grid,
}

impl VolumeGpu {
    pub fn upload(device: &wgpu::Device, queue: &wgpu::Queue, volume: &Volume) -> VolumeGpu {
        let limit = device.limits().max_texture_dimension_3d;
        let grid = fit_to_limit(&volume.grid, limit, &volume.name);
        let size = wgpu::Extent3d { width: grid.dims.x, height: grid.dims.y, depth_or_array_layers: grid.dims.z };
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&format!("volume::field {}", volume.name)),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let halves: Vec<u16> = grid.values.iter().map(|&v| half::f16::from_f32(v).to_bits()).collect();
        queue.write_texture(
            texture.as_image_copy(),
            bytemuck::cast_slice(&halves),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(2 * grid.dims.x),
                rows_per_image: Some(grid.dims.y),
            },
            size,
        );
        // A uniform array rather than a texture: the surface passes' fragment stage already reads
        // as many sampled textures as the downlevel limits allow (16, with an inspecting group).
        debug_assert_eq!(volume.table.0.len(), TABLE_SIZE);
        let table = {
            use wgpu::util::DeviceExt;
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("volume::transfer_table {}", volume.name)),
                contents: bytemuck::cast_slice(&volume.table.0),
                usage: wgpu::BufferUsages::UNIFORM,
            })
        };
        let uniform = UniformBuffer::new(device, "volume::uniform", &GpuVolume::zeroed());
        VolumeGpu { field: texture.create_view(&Default::default()), table, uniform, grid_on_gpu: grid }
    }

    fn uniform_of(&self, volume: &Volume, settings: &VolumeSettings) -> GpuVolume {
        let grid = &self.grid_on_gpu;
        GpuVolume {
            world_from_local: volume.world_from_local,
            local_from_world: volume.local_from_world(),
            normal_from_local: Mat4::from_mat3(volume.normal_from_local()),
            half_extent: grid.half_extent(),
            voxel_length: grid.voxel_length(),
            spacing: grid.spacing,
            step: settings.step,
            dims: grid.dims.as_vec3(),
            iso: volume.iso,
            termination: if settings.early_termination { settings.threshold } else { 2.0 },
            opacity_correction: u32::from(settings.opacity_correction),
            view: if settings.view == VolumeView::Samples { VOLUME_VIEW_SAMPLES } else { 0 },
            samples_white: VOLUME_SAMPLES_WHITE as f32,
        }
    }
}

/// The grid itself when it fits in a 3D texture of `limit` texels a side; otherwise resampled
/// trilinearly to at most `limit` points on each axis, spanning the same box.
fn fit_to_limit(grid: &Grid, limit: u32, name: &str) -> Grid {
    if grid.dims.max_element() <= limit {
        return grid.clone();
    }
    let dims = grid.dims.min(UVec3::splat(limit.max(2)));
    log::warn!(
        "volume `{name}`: its {} grid exceeds the device's 3D texture limit of {limit}; the rasterizer draws it resampled to {}",
        grid.dims,
        dims
    );
    let scale = (grid.dims - 1).as_vec3() / (dims - 1).as_vec3();
    let mut values = Vec::with_capacity(crate::volume::grid::voxel_count(dims) as usize);
    for z in 0..dims.z {
        for y in 0..dims.y {
            for x in 0..dims.x {
                values.push(grid.sample(UVec3::new(x, y, z).as_vec3() * scale, Reconstruction::Trilinear));
            }
        }
    }
    Grid { dims, spacing: grid.spacing * scale, values }
}

/// Which composited volumes a span is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeSet {
    All,
    One(usize),
}

/// The part of every camera ray of a view that composited volumes are marched over: from the
/// depth image `near` (the camera when `None`) to the nearer of the opaque surface and `far`
/// (the opaque surface when `None`). Depth 0 in `near` means no bound there.
#[derive(Clone, Copy, Debug)]
pub struct RaySpan<'a> {
    pub volumes: VolumeSet,
    pub near: Option<&'a wgpu::TextureView>,
    pub far: Option<&'a wgpu::TextureView>,
}

/// What tells the pass's pipelines apart: the view's toggles (shadows), the gradient, whether
/// samples are shadowed, the rendering, whether the view is mirrored (its back faces are the
/// other winding), and which limits bound the rays (far, near).
type PipelineKey = (FrameKey, VolumeKey, bool, bool);

/// The records the volume pass's `*_inspect` entry points write: an isosurface (a surface the
/// z-buffer keeps) and a composited volume's colour along the ray.
pub const RECORDS: [RecordKind; 2] = [
    RecordKind { code: INSPECT_ISOSURFACE, name: "isosurface", part: Part::Surface, terms: no_terms },
    RecordKind { code: INSPECT_VOLUME, name: "volume", part: Part::Composited, terms: no_terms },
];

pub struct VolumePass {
    /// `shaders/volume.wgsl` with the surface code.
    module: SurfaceModule,
    group_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    pipelines: HashMap<PipelineKey, wgpu::RenderPipeline>,
    nearest: wgpu::Sampler,
    trilinear: wgpu::Sampler,
    /// Each volume of the scene, made by [`Self::load`].
    volumes: Vec<VolumeGpu>,
    /// A copy of each view's depth (by the view's depth image), which isosurfaces read while
    /// they write the depth itself; kept while those targets are drawn into.
    depth_copies: PerTarget<DepthImageCopy>,
    depth_copy: DepthCopy,
}

impl VolumePass {
    pub fn new(device: &wgpu::Device, layouts: &SceneLayouts, shader: &SurfaceLayout) -> VolumePass {
        let depth = |binding| layout::depth_texels(binding, wgpu::TextureViewDimension::D2);
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("volume::group_layout"),
            entries: &[
                depth(0),
                depth(1),
                depth(2),
                layout::uniform(3, wgpu::ShaderStages::VERTEX_FRAGMENT),
                layout::texture(4, wgpu::TextureSampleType::Float { filterable: true }, wgpu::TextureViewDimension::D3),
                layout::sampler(5, wgpu::SamplerBindingType::Filtering),
                layout::uniform(6, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let layout = shader.layout_with(device, layouts, "volume::layout", &group_layout);
        let sampler = |label, filter| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                mag_filter: filter,
                min_filter: filter,
                ..Default::default()
            })
        };
        VolumePass {
            module: SurfaceModule::new(device, shader, "volume::shader", shaders::VOLUME),
            group_layout,
            layout,
            pipelines: HashMap::new(),
            nearest: sampler("volume::nearest", wgpu::FilterMode::Nearest),
            trilinear: sampler("volume::trilinear", wgpu::FilterMode::Linear),
            volumes: Vec::new(),
            depth_copies: PerTarget::default(),
            depth_copy: DepthCopy::new(device, DEPTH_FORMAT),
        }
    }

    /// Uploads every volume of `scene`, in place of the last scene's.
    pub fn load(&mut self, gpu: &Gpu, scene: &Scene) {
        self.volumes = scene.volumes.iter().map(|v| VolumeGpu::upload(&gpu.device, &gpu.queue, v)).collect();
    }

    fn pipeline(&mut self, ctx: &FrameContext, key: PipelineKey) {
        let (layout, module) = (&self.layout, &self.module);
        self.pipelines.entry(key).or_insert_with(|| {
            let (frame, volume, isosurface, mirrored) = key;
            let mut constants = constants(&frame, &MaterialKey::default());
            constants.extend(volume.constants());
            let blend = (!isosurface).then_some(wgpu::BlendState {
                color: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::One,
                    dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
                    operation: wgpu::BlendOperation::Add,
                },
                alpha: wgpu::BlendComponent::OVER,
            });
            // Back faces only: a camera inside the box still sees them. A mirrored view's winding
            // is the other way round.
            let cull_mode = Some(if mirrored { wgpu::Face::Back } else { wgpu::Face::Front });
            ctx.device().create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("volume::pipeline"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &module.module,
                    entry_point: Some("vs_volume"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState { cull_mode, ..Default::default() },
                // Isosurfaces write their depth, tested by hand against the copy; composited
                // volumes read the view's depth itself and draw with no depth attachment.
                depth_stencil: isosurface
                    .then(|| layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Always, true))
                    .flatten(),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module.module,
                    entry_point: Some(match (isosurface, frame.inspect) {
                        (true, false) => "fs_volume_isosurface",
                        (false, false) => "fs_volume_composite",
                        (true, true) => "fs_volume_isosurface_inspect",
                        (false, true) => "fs_volume_composite_inspect",
                    }),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    targets: &[Some(wgpu::ColorTargetState {
                        format: HDR_FORMAT,
                        blend,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        });
    }

    /// Writes each volume's uniform for the frame's settings, compiles the pipelines `views`
    /// need and makes the depth copies of their targets.
    pub fn prepare<'p>(&'p mut self, ctx: &FrameContext, views: &[ViewTargets<'_>]) -> PreparedVolumes<'p> {
        let settings = &ctx.settings.volume;
        let drawn = settings.enabled && !self.volumes.is_empty();
        let renderings: Vec<Rendering> = ctx.scene.volumes.iter().map(|v| v.rendering(settings)).collect();
        if drawn {
            for (volume, gpu) in ctx.scene.volumes.iter().zip(&self.volumes) {
                gpu.uniform.write(ctx.queue(), &gpu.uniform_of(volume, settings));
            }
            let isosurfaces = renderings.contains(&Rendering::Isosurface);
            for &(view, targets) in views {
                let key =
                    |isosurface, limits| (view.key, VolumeKey::new(settings, limits), isosurface, view.view.mirrored);
                if isosurfaces {
                    self.pipeline(ctx, key(true, (false, false)));
                    let (copies, copier) = (&mut self.depth_copies, &self.depth_copy);
                    copies.index_or_insert_with(targets, || {
                        copier.image_for(ctx.device(), "volume::depth_copy", &targets.depth.view, targets.size)
                    });
                }
                if renderings.contains(&Rendering::Composite) {
                    for limits in [(false, false), (false, true), (true, true), (true, false)] {
                        self.pipeline(ctx, key(false, limits));
                    }
                }
            }
        }
        self.depth_copies.keep_drawn(views.iter().map(|(_, t)| *t));
        PreparedVolumes { pass: self, renderings, drawn }
    }
}

/// The volume pass ready to draw the frame's views.
pub struct PreparedVolumes<'p> {
    pass: &'p VolumePass,
    /// How each volume of the scene is drawn this frame.
    renderings: Vec<Rendering>,
    /// Volumes are on and the scene has some.
    drawn: bool,
}

impl PreparedVolumes<'_> {
    fn key(&self, ctx: &FrameContext, view: &FrameView, isosurface: bool, limits: (bool, bool)) -> PipelineKey {
        (view.key, VolumeKey::new(&ctx.settings.volume, limits), isosurface, view.view.mirrored)
    }

    /// Group 3 of volume `index`: the depth its rays end at (`depth`), the transparent layers
    /// that bound them (`far`, `near`), and the volume's field, sampler and transfer table.
    fn group(
        &self,
        ctx: &FrameContext,
        index: usize,
        depth: &wgpu::TextureView,
        (far, near): (&wgpu::TextureView, &wgpu::TextureView),
    ) -> wgpu::BindGroup {
        let gpu = &self.pass.volumes[index];
        let sampler = match ctx.settings.volume.reconstruction {
            VolumeReconstruction::Nearest => &self.pass.nearest,
            VolumeReconstruction::Trilinear => &self.pass.trilinear,
        };
        let texture =
            |binding, view| wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(view) };
        ctx.device().create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("volume::group"),
            layout: &self.pass.group_layout,
            entries: &[
                texture(0, depth),
                texture(1, far),
                texture(2, near),
                wgpu::BindGroupEntry { binding: 3, resource: gpu.uniform.binding() },
                texture(4, &gpu.field),
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::Sampler(sampler) },
                wgpu::BindGroupEntry { binding: 6, resource: gpu.table.as_entire_binding() },
            ],
        })
    }

    /// Draws the view's isosurfaces over its opaque image, writing their depth.
    pub fn record_isosurfaces(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        view: &FrameView,
        targets: &FrameTargets,
    ) {
        let isosurfaces: Vec<usize> =
            (0..self.renderings.len()).filter(|&i| self.renderings[i] == Rendering::Isosurface).collect();
        if !self.drawn || isosurfaces.is_empty() {
            return;
        }
        let copy = self.pass.depth_copies.get(targets).expect("VolumePass::prepare made a copy for every view");
        self.pass.depth_copy.record(&mut frame.encoder, copy);
        let copy = &copy.image.view;
        let groups: Vec<wgpu::BindGroup> =
            isosurfaces.iter().map(|&i| self.group(ctx, i, copy, (copy, copy))).collect();
        let mut pass = frame.encoder.begin_render_pass(&layout::pass(
            "volume::isosurfaces",
            &[Some(layout::color_attachment(&targets.hdr.view, wgpu::LoadOp::Load))],
            Some(layout::depth_attachment(&targets.depth.view, wgpu::LoadOp::Load)),
        ));
        scissor(&mut pass, view);
        pass.set_pipeline(&self.pass.pipelines[&self.key(ctx, view, true, (false, false))]);
        self.draw(ctx, &mut pass, view, isosurfaces.iter().copied().zip(groups));
        drop(pass);
        frame.end("volumes", &[("isosurfaces", Figure::Count(isosurfaces.len() as u64))]);
    }

    /// Marches the composited volumes of `span` over that part of every ray of the view, blended
    /// over what the view's targets hold.
    pub fn composite(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        view: &FrameView,
        targets: &FrameTargets,
        span: RaySpan,
    ) {
        let chosen = |i: usize| match span.volumes {
            VolumeSet::All => true,
            VolumeSet::One(one) => one == i,
        };
        let volumes: Vec<usize> =
            (0..self.renderings.len()).filter(|&i| self.renderings[i] == Rendering::Composite && chosen(i)).collect();
        if !self.drawn || volumes.is_empty() {
            return;
        }
        let depth = &targets.depth.view;
        let limits = (span.far.is_some(), span.near.is_some());
        let bounds = (span.far.unwrap_or(depth), span.near.unwrap_or(depth));
        let groups: Vec<wgpu::BindGroup> = volumes.iter().map(|&i| self.group(ctx, i, depth, bounds)).collect();
        let mut pass = frame.encoder.begin_render_pass(&layout::pass(
            "volume::composite",
            &[Some(layout::color_attachment(&targets.hdr.view, wgpu::LoadOp::Load))],
            None,
        ));
        scissor(&mut pass, view);
        pass.set_pipeline(&self.pass.pipelines[&self.key(ctx, view, false, limits)]);
        self.draw(ctx, &mut pass, view, volumes.iter().copied().zip(groups));
        drop(pass);
        frame.end("volumes", &[("composited", Figure::Count(volumes.len() as u64))]);
    }

    fn draw(
        &self,
        ctx: &FrameContext,
        pass: &mut wgpu::RenderPass<'_>,
        view: &FrameView,
        volumes: impl Iterator<Item = (usize, wgpu::BindGroup)>,
    ) {
        let scene_gpu = ctx.scene_gpu;
        pass.set_bind_group(0, scene_gpu.frame_group(), &[scene_gpu.views.offset(view.slot)]);
        pass.set_bind_group(2, ctx.view_group(view), &[]);
        for (index, group) in volumes {
            pass.set_bind_group(1, &scene_gpu.materials()[ctx.scene.volumes[index].material.0], &[]);
            pass.set_bind_group(3, &group, &[]);
            pass.draw(0..36, 0..1);
        }
    }
}
