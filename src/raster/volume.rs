//! Volumes in the rasterizer (TECHNIQUES.md §8): a GPU ray-marching pass over the opaque image,
//! the twin of `crate::volume::march` (`shaders/volume.wgsl`).
//!
//! Per scene, each volume's normalized field becomes a 3D texture (`R16Float`, filterable, so the
//! hardware does the nearest or trilinear reconstruction) and its transfer function a 256 × 1
//! table. Per frame, after the opaque surfaces and before the transparent ones, the frame's depth
//! is copied (the pass reads it to end each ray at the opaque surface while the isosurfaces write
//! their own), and each volume's box is drawn: back faces only, so a camera inside the box still
//! marches it. Composited volumes blend `C + (1 − α)·L_behind` (One, OneMinusSrcAlpha);
//! isosurfaces replace the pixel and write their depth, so transparent surfaces behind them are
//! hidden.
//!
//! Where the rasterizer differs from the tracer, and why:
//! - volumes are drawn in the main view only: planar mirrors and environment cubes do not show
//!   them, and an isosurface shows its local model without mirror reflections;
//! - the field is stored as 16-bit floats (about 3 decimal digits of the normalized value), and a
//!   transparent surface behind a composited volume is drawn over it, not behind it;
//! - early termination ends the march, but the blend still adds the last `1 − α` of what is
//!   behind, which the tracer leaves out.
//!
//! A grid larger than the device's 3D texture limit is resampled (trilinearly) to fit, with a
//! warning: the rasterizer then shows a coarser field than the tracer.

use std::collections::HashMap;
use std::sync::Mutex;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec3, Vec3};

use super::scene_gpu::{SceneGpu, SceneLayouts};
use super::scene_pass::{FrameKey, MaterialKey, ScenePass, constants};
use super::view::ViewSlot;
use super::{DEPTH_FORMAT, FrameTargets, HDR_FORMAT};
use crate::gpu::layout;
use crate::gpu::texture::GpuTexture;
use crate::gpu::uniform::UniformBuffer;
use crate::scene::Scene;
use crate::settings::{VOLUME_SAMPLES_WHITE, VolumeGradient, VolumeReconstruction, VolumeSettings, VolumeView};
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

/// The volume pipelines' own `override`s in `shaders/volume.wgsl`, besides the scene's.
pub const VOLUME_CONSTANT_NAMES: [&str; 2] = ["VOLUME_GRADIENT", "VOLUME_SHADOWS"];

/// `VOLUME_GRADIENT` codes.
pub const VOLUME_GRADIENT_NAMES: [(&str, VolumeGradient); 3] = [
    ("VOLUME_GRADIENT_OFF", VolumeGradient::Off),
    ("VOLUME_GRADIENT_FORWARD", VolumeGradient::Forward),
    ("VOLUME_GRADIENT_CENTRAL", VolumeGradient::Central),
];

pub fn gradient_code(gradient: VolumeGradient) -> u32 {
    match gradient {
        VolumeGradient::Off => 0,
        VolumeGradient::Forward => 1,
        VolumeGradient::Central => 2,
    }
}

/// One volume on the GPU, made once per scene.
pub struct VolumeGpu {
    field: wgpu::TextureView,
    table: wgpu::TextureView,
    uniform: UniformBuffer<GpuVolume>,
    /// The grid the texture holds (smaller than the scene's when it was resampled to fit).
    grid_on_gpu: Grid,
    /// Group 3, kept while the depth copy and the reconstruction it was made for stay.
    group: Mutex<Option<(GroupKey, wgpu::BindGroup)>>,
}

/// What a volume's group 3 depends on besides the volume: the depth copy (by its generation) and
/// the sampler.
type GroupKey = (u64, VolumeReconstruction);

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
        let table = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&format!("volume::transfer_table {}", volume.name)),
            size: wgpu::Extent3d { width: TABLE_SIZE as u32, height: 1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        queue.write_texture(
            table.as_image_copy(),
            bytemuck::cast_slice(&volume.table.0),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(16 * TABLE_SIZE as u32),
                rows_per_image: None,
            },
            table.size(),
        );
        let uniform = UniformBuffer::new(device, "volume::uniform", &GpuVolume::zeroed());
        VolumeGpu {
            field: texture.create_view(&Default::default()),
            table: table.create_view(&Default::default()),
            uniform,
            grid_on_gpu: grid,
            group: Mutex::new(None),
        }
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
            view: u32::from(settings.view == VolumeView::Samples),
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

/// What tells the pass's pipelines apart: the frame's toggles (shadows), the gradient, whether
/// samples are shadowed, and the rendering.
type PipelineKey = (FrameKey, u32, bool, bool);

pub struct VolumePass {
    group_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    pipelines: HashMap<PipelineKey, wgpu::RenderPipeline>,
    nearest: wgpu::Sampler,
    trilinear: wgpu::Sampler,
    /// A copy of the frame's depth: where each ray meets the opaque surfaces; and how many have
    /// been made (the volumes' groups name the one they read).
    depth_copy: Option<GpuTexture>,
    depth_copies: u64,
}

impl VolumePass {
    pub fn new(device: &wgpu::Device, layouts: &SceneLayouts) -> VolumePass {
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("volume::group_layout"),
            entries: &[
                layout::texture(0, wgpu::TextureSampleType::Depth, wgpu::TextureViewDimension::D2),
                layout::uniform(4, wgpu::ShaderStages::VERTEX_FRAGMENT),
                layout::texture(5, wgpu::TextureSampleType::Float { filterable: true }, wgpu::TextureViewDimension::D3),
                layout::sampler(6, wgpu::SamplerBindingType::Filtering),
                layout::texture(
                    7,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("volume::layout"),
            bind_group_layouts: &[
                Some(&layouts.frame),
                Some(&layouts.material),
                Some(&layouts.lighting),
                Some(&group_layout),
            ],
            immediate_size: 0,
        });
        let sampler = |label, filter| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                mag_filter: filter,
                min_filter: filter,
                ..Default::default()
            })
        };
        VolumePass {
            group_layout,
            layout,
            pipelines: HashMap::new(),
            nearest: sampler("volume::nearest", wgpu::FilterMode::Nearest),
            trilinear: sampler("volume::trilinear", wgpu::FilterMode::Linear),
            depth_copy: None,
            depth_copies: 0,
        }
    }

    fn pipeline(&mut self, device: &wgpu::Device, scene_pass: &ScenePass, key: PipelineKey) -> &wgpu::RenderPipeline {
        let layout = &self.layout;
        self.pipelines.entry(key).or_insert_with(|| {
            let (frame, gradient, shadows, isosurface) = key;
            let mut constants: Vec<(&str, f64)> = constants(&frame, &MaterialKey::default()).to_vec();
            constants
                .extend(VOLUME_CONSTANT_NAMES.into_iter().zip([f64::from(gradient), f64::from(u8::from(shadows))]));
            let blend = (!isosurface).then_some(wgpu::BlendState {
                color: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::One,
                    dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
                    operation: wgpu::BlendOperation::Add,
                },
                alpha: wgpu::BlendComponent::OVER,
            });
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("volume::pipeline"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: scene_pass.module(),
                    entry_point: Some("vs_volume"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    buffers: &[],
                },
                // Back faces: a camera inside the box still sees them.
                primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Front), ..Default::default() },
                depth_stencil: layout::depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Always, isosurface),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: scene_pass.module(),
                    entry_point: Some(if isosurface { "fs_volume_isosurface" } else { "fs_volume_composite" }),
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
        })
    }

    /// Draws every volume of `scene` over the main view's opaque image in `targets`.
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
        targets: &FrameTargets,
        settings: &VolumeSettings,
    ) {
        let gradient = gradient_code(settings.gradient);
        let keys: Vec<PipelineKey> = scene
            .volumes
            .iter()
            .map(|volume| {
                let isosurface = volume.rendering(settings) == Rendering::Isosurface;
                (frame, gradient, settings.shadows, isosurface)
            })
            .collect();
        for &key in &keys {
            self.pipeline(device, scene_pass, key);
        }
        let size = targets.size;
        if self.depth_copy.as_ref().is_none_or(|d| (d.texture.width(), d.texture.height()) != size) {
            self.depth_copy = Some(depth_copy_target(device, size));
            self.depth_copies += 1;
        }
        let depth_copy = self.depth_copy.as_ref().expect("made above");
        encoder.copy_texture_to_texture(
            targets.depth.texture.as_image_copy(),
            depth_copy.texture.as_image_copy(),
            targets.depth.texture.size(),
        );
        let sampler = match settings.reconstruction {
            VolumeReconstruction::Nearest => &self.nearest,
            VolumeReconstruction::Trilinear => &self.trilinear,
        };
        let group_key = (self.depth_copies, settings.reconstruction);
        let mut draws = Vec::new();
        for ((volume, gpu), key) in scene.volumes.iter().zip(&scene_gpu.volumes).zip(keys) {
            gpu.uniform.write(queue, &gpu.uniform_of(volume, settings));
            let mut group = gpu.group.lock().expect("no panics while the lock is held");
            if group.as_ref().is_none_or(|(k, _)| *k != group_key) {
                let made = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("volume::group"),
                    layout: &self.group_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::TextureView(&depth_copy.view),
                        },
                        wgpu::BindGroupEntry { binding: 4, resource: gpu.uniform.binding() },
                        wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&gpu.field) },
                        wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::Sampler(sampler) },
                        wgpu::BindGroupEntry { binding: 7, resource: wgpu::BindingResource::TextureView(&gpu.table) },
                    ],
                });
                *group = Some((group_key, made));
            }
            let (_, group) = group.as_ref().expect("made above");
            draws.push((key, group.clone(), volume.material.0));
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("volume::pass"),
            color_attachments: &[Some(layout::color_attachment(&targets.hdr.view, wgpu::LoadOp::Load))],
            depth_stencil_attachment: Some(layout::depth_attachment(&targets.depth.view, wgpu::LoadOp::Load)),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, scene_gpu.frame_group(), &[scene_gpu.views.offset(ViewSlot::Main)]);
        pass.set_bind_group(2, lighting, &[]);
        for (key, group, material) in &draws {
            pass.set_pipeline(&self.pipelines[key]);
            pass.set_bind_group(1, &scene_gpu.materials()[*material], &[]);
            pass.set_bind_group(3, group, &[]);
            pass.draw(0..36, 0..1);
        }
    }
}

fn depth_copy_target(device: &wgpu::Device, size: (u32, u32)) -> GpuTexture {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("volume::depth_copy"),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: DEPTH_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    GpuTexture { texture, view }
}
