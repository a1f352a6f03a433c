//! The scene on the GPU: its geometry ([`SceneGeometry`]), textures, and bind groups by how often
//! they change: 0 per view (the view's slot, chosen by a dynamic offset) and per frame (lights,
//! numeric settings), 1 per material, 2 per view (the view group of `super::view_group`: what
//! the view's shading reads). Built once per scene; a frame rewrites the uniforms and, when tessellations
//! change, the draw list. What a technique keeps per scene (a volume's 3D texture, the
//! environment maps, the planar mirrors) belongs to its pass.
//!
//! [`SurfaceLayout`] is the pipeline layout of groups 0 to 2 every surface pass shares, and
//! [`SurfaceModule`] a surface pass's own module (the shared surface code and its file).

use super::geometry::SceneGeometry;
use super::keys::MaterialKey;
use super::uniforms::{GpuFrame, GpuInstance, GpuMaterial, Vertex};
use super::view::ViewBuffer;
use crate::gpu::mipmap::{MipmapGenerator, sampler_descriptor, upload_with_mipmaps};
use crate::gpu::texture::GpuTexture;
use crate::gpu::uniform::UniformBuffer;
use crate::gpu::{Gpu, layout};
use crate::scene::{ColorSpace, Scene, Wrap};
use crate::settings::RenderSettings;
use crate::settings::{TextureFilter, TextureSettings};
use crate::shaders::Wgsl;
use crate::texture::mipmap::Filter;

/// The bind group layouts every scene pass shares.
pub struct SceneLayouts {
    /// Group 0: the view (dynamic offset), the frame uniform, the height maps' sampler.
    pub frame: wgpu::BindGroupLayout,
    /// Group 1: a material's uniform, textures and colour sampler.
    pub material: wgpu::BindGroupLayout,
    /// Group 2, the view group (`super::view_group`): the shadow maps and how to read them, the
    /// environment maps, and the images the view's earlier phases made.
    pub view: wgpu::BindGroupLayout,
}

impl SceneLayouts {
    /// The layouts; `inspect` adds the inspection buffer and the shadow maps read as floats to
    /// the view group (bindings 11 and 12, `shaders/common/inspect.wgsl`), for a renderer that
    /// inspects pixels.
    pub fn new(device: &wgpu::Device, inspect: bool) -> SceneLayouts {
        let both = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let frame = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene::frame_layout"),
            entries: &[
                layout::dynamic_uniform(0, both),
                layout::uniform(1, wgpu::ShaderStages::FRAGMENT),
                layout::sampler(2, wgpu::SamplerBindingType::Filtering),
            ],
        });
        let material = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene::material_layout"),
            entries: &[
                layout::uniform(0, wgpu::ShaderStages::FRAGMENT),
                layout::texture_2d(1),
                layout::texture_2d(2),
                layout::texture_2d(3),
                layout::sampler(4, wgpu::SamplerBindingType::Filtering),
            ],
        });
        let view = super::view_group::layout(device, inspect);
        SceneLayouts { frame, material, view }
    }
}

/// The pipeline layout of groups 0 to 2 that every pass drawing the scene's surfaces shares, and
/// the WGSL their modules compile (Mirador's own, or with a lab's functions in place of some of
/// its own: [`Wgsl`]); a pass with a group 3 of its own makes its layout with
/// [`Self::layout_with`].
pub struct SurfaceLayout {
    pub layout: wgpu::PipelineLayout,
    pub wgsl: Wgsl,
}

/// The vertex buffers of every scene pipeline: the mesh's vertices, and the instances.
pub const VERTEX_BUFFERS: [Option<wgpu::VertexBufferLayout<'static>>; 2] =
    [Some(Vertex::LAYOUT), Some(GpuInstance::LAYOUT)];

impl SurfaceLayout {
    pub fn new(device: &wgpu::Device, layouts: &SceneLayouts, wgsl: Wgsl) -> SurfaceLayout {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene::layout"),
            bind_group_layouts: &[Some(&layouts.frame), Some(&layouts.material), Some(&layouts.view)],
            immediate_size: 0,
        });
        SurfaceLayout { layout, wgsl }
    }

    /// A pipeline layout of groups 0 to 2 and `group3`.
    pub fn layout_with(
        &self,
        device: &wgpu::Device,
        layouts: &SceneLayouts,
        label: &str,
        group3: &wgpu::BindGroupLayout,
    ) -> wgpu::PipelineLayout {
        device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&layouts.frame), Some(&layouts.material), Some(&layouts.view), Some(group3)],
            immediate_size: 0,
        })
    }
}

/// A surface pass's shader module: the surface code of `shaders/common/surface.wgsl` and the
/// pass's own file (`src/shaders.rs`, `Wgsl::compose_surface`).
pub struct SurfaceModule {
    pub module: wgpu::ShaderModule,
}

impl SurfaceModule {
    pub fn new(device: &wgpu::Device, surface: &SurfaceLayout, label: &str, pass: &str) -> SurfaceModule {
        SurfaceModule { module: surface.wgsl.surface_module(device, label, pass) }
    }

    /// The vertex stage every surface pipeline shares (`vs_scene`, its position `@invariant`).
    pub fn vertex(&self) -> wgpu::VertexState<'_> {
        wgpu::VertexState {
            module: &self.module,
            entry_point: Some("vs_scene"),
            compilation_options: Default::default(),
            buffers: &VERTEX_BUFFERS,
        }
    }
}

pub struct SceneGpu {
    frame: UniformBuffer<GpuFrame>,
    /// Every view of the frame, a slot each.
    pub views: ViewBuffer,
    /// Group 0: a view slot, the frame uniform and the height maps' bilinear sampler.
    frame_group: wgpu::BindGroup,
    /// What each material binds, kept to make its group 1 for each texture filter.
    material_inputs: Vec<MaterialInputs>,
    /// Group 1 of every material, for each texture filter used so far: a material's sampler
    /// carries both the filter (a setting) and the wrap modes (the material's).
    material_groups: Vec<(FilterKey, Vec<wgpu::BindGroup>)>,
    /// Which entry of `material_groups` this frame uses.
    active: usize,
    /// Per material: which shader variant draws it.
    pub material_keys: Vec<MaterialKey>,
    /// Per material: what it lets through, the blend constant `kt·Mt` of the transparency pass.
    pub transmittance: Vec<glam::Vec3>,
    pub geometry: SceneGeometry,
}

/// The filter and its anisotropy: what tells sets of material groups apart.
type FilterKey = (TextureFilter, u16);

struct MaterialInputs {
    name: String,
    uniform: UniformBuffer<GpuMaterial>,
    color: wgpu::TextureView,
    height: wgpu::TextureView,
    normal: wgpu::TextureView,
    wrap: [Wrap; 2],
}

/// Which objects the geometry draws alone, and why: planar mirrors show their own reflection,
/// objects with a dynamic environment cube (by layer) are left out of their cube's views.
pub struct DrawnAlone<'a> {
    pub mirrors: &'a [usize],
    pub env_objects: &'a [usize],
}

impl SceneGpu {
    pub fn upload(
        gpu: &Gpu,
        layouts: &SceneLayouts,
        mipmaps: &MipmapGenerator,
        scene: &Scene,
        alone: DrawnAlone,
    ) -> SceneGpu {
        let device = &gpu.device;
        if scene.lights.len() > super::uniforms::MAX_LIGHTS {
            log::warn!(
                "the scene has {} lights; the rasterizer draws the first {}",
                scene.lights.len(),
                super::uniforms::MAX_LIGHTS
            );
        }
        let frame = UniformBuffer::new(
            device,
            "scene::frame",
            &GpuFrame::new(scene.ambient, &scene.lights, &[], &scene.settings),
        );
        let views = ViewBuffer::new(device);
        // Every texture gets its whole mip chain, averaged in linear space (docs/course/03-mipmaps.md).
        let textures: Vec<GpuTexture> = scene
            .textures
            .iter()
            .map(|t| {
                let label = format!("scene::texture {}", t.path.display());
                let image = ((t.width, t.height), t.rgba8.as_slice());
                upload_with_mipmaps((device, &gpu.queue), mipmaps, &label, image, texture_format(t.color_space))
            })
            .collect();
        let one_texel =
            |label, rgba: [u8; 4], format| GpuTexture::from_rgba8(device, &gpu.queue, label, (1, 1), &rgba, format);
        let white = one_texel("scene::white_texture", [255; 4], wgpu::TextureFormat::Rgba8UnormSrgb);
        let flat = one_texel("scene::flat_height", [0, 0, 0, 255], wgpu::TextureFormat::Rgba8Unorm);
        let straight = one_texel("scene::straight_normal", [128, 128, 255, 255], wgpu::TextureFormat::Rgba8Unorm);
        let height_sampler = device.create_sampler(&sampler_descriptor(Filter::Bilinear, 1));
        let frame_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene::frame_group"),
            layout: &layouts.frame,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: views.binding() },
                wgpu::BindGroupEntry { binding: 1, resource: frame.binding() },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&height_sampler) },
            ],
        });
        let material_inputs = scene
            .materials
            .iter()
            .enumerate()
            .map(|(index, m)| MaterialInputs {
                name: m.name.clone(),
                uniform: UniformBuffer::new(
                    device,
                    &format!("scene::material {}", m.name),
                    &GpuMaterial { index: index as u32, ..m.to_gpu() },
                ),
                color: m.texture.map_or(&white.view, |id| &textures[id.0].view).clone(),
                height: m.height_map.map_or(&flat.view, |id| &textures[id.0].view).clone(),
                normal: m.normal_map.map_or(&straight.view, |id| &textures[id.0].view).clone(),
                wrap: m.wrap,
            })
            .collect();

        SceneGpu {
            frame,
            views,
            frame_group,
            material_inputs,
            material_groups: Vec::new(),
            active: 0,
            material_keys: scene.materials.iter().map(MaterialKey::new).collect(),
            transmittance: scene.materials.iter().map(super::uniforms::transmittance).collect(),
            geometry: SceneGeometry::new(scene, alone.mirrors, alone.env_objects),
        }
    }

    /// Makes every material's group 1 for `settings`' texture filter, the first time that filter
    /// is used, and makes it the one [`Self::materials`] hands out.
    pub fn prepare_materials(&mut self, device: &wgpu::Device, layouts: &SceneLayouts, settings: &TextureSettings) {
        let key = filter_key(settings);
        if let Some(index) = self.material_groups.iter().position(|(k, _)| *k == key) {
            self.active = index;
            return;
        }
        let filter = match settings.filter {
            TextureFilter::Nearest => Filter::Nearest,
            TextureFilter::Bilinear => Filter::Bilinear,
            TextureFilter::NearestMip => Filter::NearestMip,
            TextureFilter::Trilinear | TextureFilter::LevelColour | TextureFilter::Anisotropic => Filter::Trilinear,
        };
        let mut samplers: Vec<([Wrap; 2], wgpu::Sampler)> = Vec::new();
        let groups = self
            .material_inputs
            .iter()
            .map(|m| {
                let sampler = match samplers.iter().find(|(w, _)| *w == m.wrap) {
                    Some((_, sampler)) => sampler.clone(),
                    None => {
                        let [u, v] = m.wrap.map(address_mode);
                        let descriptor = wgpu::SamplerDescriptor {
                            address_mode_u: u,
                            address_mode_v: v,
                            ..sampler_descriptor(filter, key.1)
                        };
                        let sampler = device.create_sampler(&descriptor);
                        samplers.push((m.wrap, sampler.clone()));
                        sampler
                    }
                };
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("scene::material_group {}", m.name)),
                    layout: &layouts.material,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: m.uniform.binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&m.color) },
                        wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&m.height) },
                        wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&m.normal) },
                        wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::Sampler(&sampler) },
                    ],
                })
            })
            .collect();
        self.material_groups.push((key, groups));
        self.active = self.material_groups.len() - 1;
    }

    /// Group 0.
    pub fn frame_group(&self) -> &wgpu::BindGroup {
        &self.frame_group
    }

    /// Every material's group 1 for the texture filter [`Self::prepare_materials`] chose.
    pub fn materials(&self) -> &[wgpu::BindGroup] {
        &self.material_groups.get(self.active).expect("prepare_materials() runs before drawing").1
    }

    /// Rewrites the per-frame uniform: lights, their shadow layers, and numeric settings.
    pub fn update_frame(
        &self,
        queue: &wgpu::Queue,
        scene: &Scene,
        shadow_layers: &[Option<u32>],
        settings: &RenderSettings,
    ) {
        self.frame.write(queue, &GpuFrame::new(scene.ambient, &scene.lights, shadow_layers, settings));
    }
}

/// The format a scene texture is uploaded as: sRGB colour as `Rgba8UnormSrgb` (the sampler
/// decodes before filtering), data as `Rgba8Unorm`.
pub fn texture_format(color_space: ColorSpace) -> wgpu::TextureFormat {
    match color_space {
        ColorSpace::Srgb => wgpu::TextureFormat::Rgba8UnormSrgb,
        ColorSpace::Linear => wgpu::TextureFormat::Rgba8Unorm,
    }
}

/// The sampler address mode of a wrap mode.
fn address_mode(wrap: Wrap) -> wgpu::AddressMode {
    match wrap {
        Wrap::Repeat => wgpu::AddressMode::Repeat,
        Wrap::Clamp => wgpu::AddressMode::ClampToEdge,
        Wrap::Mirror => wgpu::AddressMode::MirrorRepeat,
    }
}

/// The filter and its anisotropy.
fn filter_key(settings: &TextureSettings) -> FilterKey {
    let anisotropy = if settings.filter == TextureFilter::Anisotropic { settings.anisotropy } else { 1 };
    (settings.filter, anisotropy)
}
