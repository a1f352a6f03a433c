//! The scene on the GPU: vertex and index buffers, and bind groups by how often they change
//! (0 per frame, 1 per material, 2 per object). Built once per scene; a frame only rewrites the
//! frame uniform.

use wgpu::util::DeviceExt;

use super::uniforms::{GpuFrame, Vertex};
use crate::gpu::Gpu;
use crate::gpu::texture::GpuTexture;
use crate::gpu::uniform::UniformBuffer;
use crate::scene::{Mesh, Scene};
use crate::settings::RenderSettings;

/// The bind group layouts every scene pass shares.
pub struct SceneLayouts {
    pub frame: wgpu::BindGroupLayout,
    pub material: wgpu::BindGroupLayout,
    pub object: wgpu::BindGroupLayout,
}

fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl SceneLayouts {
    pub fn new(device: &wgpu::Device) -> SceneLayouts {
        let both = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let frame = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene::frame_layout"),
            entries: &[uniform_entry(0, both)],
        });
        let material = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene::material_layout"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::FRAGMENT),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let object = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene::object_layout"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::VERTEX)],
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
    pub frame_group: wgpu::BindGroup,
    pub materials: Vec<wgpu::BindGroup>,
    pub drawables: Vec<Drawable>,
}

impl SceneGpu {
    pub fn upload(gpu: &Gpu, layouts: &SceneLayouts, scene: &Scene) -> SceneGpu {
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
        let frame_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene::frame_group"),
            layout: &layouts.frame,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: frame.binding() }],
        });

        let textures: Vec<GpuTexture> = scene
            .textures
            .iter()
            .map(|t| GpuTexture::upload(device, &gpu.queue, &format!("scene::texture {}", t.path.display()), t))
            .collect();
        let white = GpuTexture::from_rgba8(
            device,
            &gpu.queue,
            "scene::white_texture",
            (1, 1),
            &[255; 4],
            wgpu::TextureFormat::Rgba8UnormSrgb,
        );
        // Mipmaps and the sampling modes are the textures issue's; until then, bilinear.
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("scene::color_sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let materials = scene
            .materials
            .iter()
            .map(|m| {
                let uniform = UniformBuffer::new(device, &format!("scene::material {}", m.name), &m.to_gpu());
                let view = m.texture.map_or(&white.view, |id| &textures[id.0].view);
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("scene::material_group {}", m.name)),
                    layout: &layouts.material,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: uniform.binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(view) },
                        wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&sampler) },
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
        SceneGpu { frame, frame_group, materials, drawables }
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

fn mesh_buffers(device: &wgpu::Device, name: &str, mesh: &Mesh) -> (wgpu::Buffer, wgpu::Buffer) {
    let vertices: Vec<Vertex> = (0..mesh.positions.len())
        .map(|i| Vertex {
            position: mesh.positions[i].to_array(),
            normal: mesh.normals[i].to_array(),
            uv: mesh.uvs[i].to_array(),
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
