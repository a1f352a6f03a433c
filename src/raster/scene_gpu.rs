//! The scene on the GPU: vertex and index buffers, and bind groups by how often they change
//! (0 per frame, 1 per material, 2 per object). Built once per scene; a frame only rewrites the
//! frame uniform.

use wgpu::util::DeviceExt;

use super::uniforms::{GpuFrame, Vertex};
use crate::gpu::mipmap::{MipmapGenerator, sampler_descriptor, upload_with_mipmaps};
use crate::gpu::texture::GpuTexture;
use crate::gpu::uniform::UniformBuffer;
use crate::gpu::{Gpu, layout};
use crate::scene::{Mesh, Scene};
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
            entries: &[
                layout::uniform(0, both),
                layout::sampler(1, wgpu::SamplerBindingType::Filtering),
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
    /// Group 0 for each texture filter used so far: the frame uniform and that filter's sampler.
    frame_groups: Vec<((TextureFilter, u16), wgpu::BindGroup)>,
    height_sampler: wgpu::Sampler,
    pub materials: Vec<wgpu::BindGroup>,
    pub drawables: Vec<Drawable>,
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
        let materials = scene
            .materials
            .iter()
            .map(|m| {
                let uniform = UniformBuffer::new(device, &format!("scene::material {}", m.name), &m.to_gpu());
                let color = m.texture.map_or(&white.view, |id| &textures[id.0].view);
                let height = m.height_map.map_or(&flat.view, |id| &textures[id.0].view);
                let normal = m.normal_map.map_or(&straight.view, |id| &textures[id.0].view);
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("scene::material_group {}", m.name)),
                    layout: &layouts.material,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: uniform.binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(color) },
                        wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(height) },
                        wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(normal) },
                    ],
                })
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
        SceneGpu { frame, frame_groups: Vec::new(), height_sampler, materials, drawables }
    }

    /// Makes group 0 for `settings`' texture filter, the first time that filter is used.
    pub fn prepare_frame_group(&mut self, device: &wgpu::Device, layouts: &SceneLayouts, settings: &TextureSettings) {
        let key = frame_group_key(settings);
        if self.frame_groups.iter().any(|(k, _)| *k == key) {
            return;
        }
        let filter = match settings.filter {
            TextureFilter::Nearest => Filter::Nearest,
            TextureFilter::Bilinear => Filter::Bilinear,
            TextureFilter::NearestMip => Filter::NearestMip,
            TextureFilter::Trilinear | TextureFilter::LevelColour | TextureFilter::Anisotropic => Filter::Trilinear,
        };
        let sampler = device.create_sampler(&sampler_descriptor(filter, key.1));
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene::frame_group"),
            layout: &layouts.frame,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.frame.binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&sampler) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&self.height_sampler) },
            ],
        });
        self.frame_groups.push((key, group));
    }

    /// Group 0 for `settings`' texture filter; [`Self::prepare_frame_group`] made it.
    pub fn frame_group(&self, settings: &TextureSettings) -> &wgpu::BindGroup {
        let key = frame_group_key(settings);
        let (_, group) = self.frame_groups.iter().find(|(k, _)| *k == key).expect("prepare_frame_group() runs first");
        group
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

/// The filter and its anisotropy: what tells frame groups apart.
fn frame_group_key(settings: &TextureSettings) -> (TextureFilter, u16) {
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
