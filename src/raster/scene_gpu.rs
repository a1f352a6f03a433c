//! The scene on the GPU: vertex and index buffers, and bind groups by how often they change
//! (0 per frame, 1 per material, 2 per object). Built once per scene; a frame only rewrites the
//! frame uniform.

use wgpu::util::DeviceExt;

use super::uniforms::{GpuFrame, GpuMaterial, Vertex};
use crate::gpu::mipmap::{MipmapGenerator, sampler_descriptor, upload_with_mipmaps};
use crate::gpu::texture::GpuTexture;
use crate::gpu::uniform::UniformBuffer;
use crate::gpu::{Gpu, layout};
use crate::scene::{Mesh, Scene, Wrap};
use crate::settings::RenderSettings;
use crate::settings::{TextureFilter, TextureSettings};
use crate::texture::mipmap::Filter;
use crate::texture::tangents::tangents_or_generate;

/// The bind group layouts every scene pass shares.
pub struct SceneLayouts {
    pub frame: wgpu::BindGroupLayout,
    pub material: wgpu::BindGroupLayout,
    pub object: wgpu::BindGroupLayout,
}

impl SceneLayouts {
    pub fn new(device: &wgpu::Device) -> SceneLayouts {
        let both = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let frame = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene::frame_layout"),
            entries: &[layout::uniform(0, both), layout::sampler(1, wgpu::SamplerBindingType::Filtering)],
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
        let object = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene::object_layout"),
            entries: &[layout::uniform(0, wgpu::ShaderStages::VERTEX)],
        });
        SceneLayouts { frame, material, object }
    }
}

/// One drawable: an object's geometry with its material and transform bind groups.
pub struct Drawable {
    pub name: String,
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub index_count: u32,
    pub material: usize,
    /// Its material lets light through (kt > 0): it tints shadows rather than casting them.
    pub transparent: bool,
    pub object: wgpu::BindGroup,
}

pub struct SceneGpu {
    pub frame: UniformBuffer<GpuFrame>,
    /// Group 0: the frame uniform and the height maps' bilinear sampler.
    frame_group: wgpu::BindGroup,
    /// What each material binds, kept to make its group 1 for each texture filter.
    material_inputs: Vec<MaterialInputs>,
    /// Group 1 of every material, for each texture filter used so far: a material's sampler
    /// carries both the filter (a setting) and the wrap modes (the material's).
    material_groups: Vec<(FilterKey, Vec<wgpu::BindGroup>)>,
    /// Which entry of `material_groups` this frame uses.
    active: usize,
    pub drawables: Vec<Drawable>,
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

impl SceneGpu {
    pub fn upload(gpu: &Gpu, layouts: &SceneLayouts, mipmaps: &MipmapGenerator, scene: &Scene) -> SceneGpu {
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
            &GpuFrame::new(&scene.camera, scene.ambient, &scene.lights, &[], &scene.settings),
        );
        // Every texture gets its whole mip chain, averaged in linear space (TECHNIQUES.md §2).
        let textures: Vec<GpuTexture> = scene
            .textures
            .iter()
            .map(|t| {
                upload_with_mipmaps(device, &gpu.queue, mipmaps, &format!("scene::texture {}", t.path.display()), t)
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
                wgpu::BindGroupEntry { binding: 0, resource: frame.binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&height_sampler) },
            ],
        });
        let material_inputs = scene
            .materials
            .iter()
            .map(|m| MaterialInputs {
                name: m.name.clone(),
                uniform: UniformBuffer::new(device, &format!("scene::material {}", m.name), &m.to_gpu()),
                color: m.texture.map_or(&white.view, |id| &textures[id.0].view).clone(),
                height: m.height_map.map_or(&flat.view, |id| &textures[id.0].view).clone(),
                normal: m.normal_map.map_or(&straight.view, |id| &textures[id.0].view).clone(),
                wrap: m.wrap,
            })
            .collect();

        let drawables = scene
            .objects
            .iter()
            .map(|object| {
                let mesh = scene.tessellate(object);
                let (vertices, indices) = mesh_buffers(device, &object.name, &mesh);
                let uniform = UniformBuffer::new(device, &format!("scene::object {}", object.name), &object.to_gpu());
                let object_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("scene::object_group {}", object.name)),
                    layout: &layouts.object,
                    entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.binding() }],
                });
                Drawable {
                    name: object.name.clone(),
                    vertices,
                    indices,
                    index_count: mesh.indices.len() as u32,
                    material: object.material.0,
                    transparent: scene.materials[object.material.0].is_transparent(),
                    object: object_group,
                }
            })
            .collect();
        SceneGpu { frame, frame_group, material_inputs, material_groups: Vec::new(), active: 0, drawables }
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

    /// Rewrites the per-frame uniform: camera, lights, their shadow layers, and toggles.
    pub fn update_frame(&self, gpu: &Gpu, scene: &Scene, shadow_layers: &[Option<u32>], settings: &RenderSettings) {
        self.frame
            .write(&gpu.queue, &GpuFrame::new(&scene.camera, scene.ambient, &scene.lights, shadow_layers, settings));
    }

    pub fn has_transparent(&self) -> bool {
        self.drawables.iter().any(|d| d.transparent)
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

fn mesh_buffers(device: &wgpu::Device, name: &str, mesh: &Mesh) -> (wgpu::Buffer, wgpu::Buffer) {
    // The file's tangents where it has them, MikkTSpace's otherwise (TECHNIQUES.md §3's
    // per-vertex source).
    let existing = (!mesh.tangents.is_empty()).then_some(mesh.tangents.as_slice());
    let tangents = tangents_or_generate(mesh, existing);
    let vertices: Vec<Vertex> = (0..mesh.positions.len())
        .map(|i| Vertex {
            position: mesh.positions[i].to_array(),
            normal: mesh.normals[i].to_array(),
            uv: mesh.uvs[i].to_array(),
            tangent: tangents[i].to_array(),
        })
        .collect();
    let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(&format!("scene::vertices {name}")),
        contents: bytemuck::cast_slice(&vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(&format!("scene::indices {name}")),
        contents: bytemuck::cast_slice(&mesh.indices),
        usage: wgpu::BufferUsages::INDEX,
    });
    (vertex_buffer, index_buffer)
}
