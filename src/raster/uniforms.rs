//! GPU layouts of the scene's CPU types (`Light → GpuLight`, …), `#[repr(C)]` and bytemuck.
//! Their WGSL twins are in `shaders/common/types.wgsl`; `tests/layouts.rs` compares the sizes
//! through naga's reflection, so the padding is checked rather than kept in step by hand.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::scene::{Attenuation, Camera, Light, LightKind, Material, Object, ProceduralHeight, Projection};
use crate::settings::{BumpView, RenderSettings, TangentSource, TextureFilter};

pub const MAX_LIGHTS: usize = 16;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLight {
    pub position: [f32; 3],
    pub kind: u32,
    pub direction: [f32; 3],
    pub attenuation: u32,
    pub radiance: [f32; 3],
    pub cos_inner: f32,
    pub cos_outer: f32,
    pub shadow_layer: i32,
    pub shadow_slot: i32,
    pub _pad: f32,
}

impl Light {
    pub fn to_gpu(&self) -> GpuLight {
        let (kind, position, direction, cos_inner, cos_outer) = match self.kind {
            LightKind::Point { position } => (0, position, Vec3::ZERO, 1.0, 1.0),
            LightKind::Directional { direction } => (1, Vec3::ZERO, direction, 1.0, 1.0),
            LightKind::Spot { position, direction, inner, outer } => (2, position, direction, inner.cos(), outer.cos()),
        };
        GpuLight {
            position: position.to_array(),
            kind,
            direction: direction.to_array(),
            attenuation: match self.attenuation {
                Attenuation::None => 0,
                Attenuation::InverseSquare => 1,
            },
            radiance: (self.color * self.intensity).to_array(),
            cos_inner,
            cos_outer,
            shadow_layer: -1,
            shadow_slot: -1,
            _pad: 0.0,
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuFrame {
    pub clip_from_world: [[f32; 4]; 4],
    pub eye: [f32; 3],
    pub orthographic: u32,
    pub view_axis: [f32; 3],
    pub light_count: u32,
    pub ambient: [f32; 3],
    pub terms: u32,
    pub texture_filter: u32,
    pub lod_bias: f32,
    pub bump_enabled: u32,
    pub bump_scale: f32,
    pub bump_delta_texels: f32,
    pub bump_view: u32,
    pub bump_tangents: u32,
    pub bump_analytic: u32,
    pub lights: [GpuLight; MAX_LIGHTS],
}

impl GpuFrame {
    /// The per-frame uniform. Lights past [`MAX_LIGHTS`] are dropped (the loader warns).
    /// `shadow_layers[i]` is light `i`'s first shadow-map layer, if it casts shadows.
    pub fn new(
        camera: &Camera,
        ambient: Vec3,
        lights: &[Light],
        shadow_layers: &[Option<u32>],
        settings: &RenderSettings,
    ) -> GpuFrame {
        let mut gpu_lights = [GpuLight::zeroed(); MAX_LIGHTS];
        let mut slots = 0;
        for (i, (gpu, light)) in gpu_lights.iter_mut().zip(lights).enumerate() {
            *gpu = light.to_gpu();
            if let Some(layer) = shadow_layers.get(i).copied().flatten() {
                gpu.shadow_layer = layer as i32;
                gpu.shadow_slot = slots;
                slots += 1;
            }
        }
        let t = settings.terms;
        let terms =
            u32::from(t.ambient) | u32::from(t.diffuse) << 1 | u32::from(t.specular) << 2 | u32::from(t.emission) << 3;
        GpuFrame {
            clip_from_world: camera.clip_from_world().to_cols_array_2d(),
            eye: camera.eye.to_array(),
            orthographic: u32::from(camera.projection == Projection::Orthographic),
            view_axis: camera.frame().ze.to_array(),
            light_count: lights.len().min(MAX_LIGHTS) as u32,
            ambient: ambient.to_array(),
            terms,
            texture_filter: match settings.textures.filter {
                TextureFilter::Nearest => 0,
                TextureFilter::Bilinear => 1,
                TextureFilter::NearestMip => 2,
                TextureFilter::Trilinear => 3,
                TextureFilter::Anisotropic => 4,
                TextureFilter::LevelColour => 5,
            },
            lod_bias: settings.textures.lod_bias,
            bump_enabled: u32::from(settings.bump.enabled),
            bump_scale: settings.bump.scale,
            bump_delta_texels: settings.bump.delta_texels,
            bump_view: match settings.bump.view {
                BumpView::Off => 0,
                BumpView::Normals => 1,
                BumpView::Tangents => 2,
            },
            bump_tangents: match settings.bump.tangents {
                TangentSource::Derivatives => 0,
                TangentSource::PerVertex => 1,
            },
            bump_analytic: u32::from(settings.bump.analytic),
            lights: gpu_lights,
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    pub color: [f32; 3],
    pub has_texture: u32,
    pub ka: f32,
    pub kd: f32,
    pub ks: f32,
    pub shininess: f32,
    pub specular_color: [f32; 3],
    pub transparent: u32,
    pub emission: [f32; 3],
    pub bump_scale: f32,
    pub transmission: [f32; 3],
    pub has_height_map: u32,
    pub has_normal_map: u32,
    pub normal_scale: f32,
    /// 1: the height map, 2: a sine field, 3: value noise (0: none).
    pub height_kind: u32,
    pub height_amplitude: f32,
    pub height_frequency: [f32; 2],
    pub noise_seed: u32,
    pub noise_cells: u32,
    pub noise_octaves: u32,
    pub _pad: [f32; 3],
}

impl Material {
    pub fn to_gpu(&self) -> GpuMaterial {
        GpuMaterial {
            color: self.color.to_array(),
            has_texture: u32::from(self.texture.is_some()),
            ka: self.ka,
            kd: self.kd,
            ks: self.ks,
            shininess: self.shininess,
            specular_color: self.specular_color.to_array(),
            transparent: u32::from(self.is_transparent()),
            emission: self.emission.to_array(),
            bump_scale: self.bump_scale,
            transmission: (self.transmission * self.transmission_color).to_array(),
            has_height_map: u32::from(self.height_map.is_some() || self.height_field.is_some()),
            has_normal_map: u32::from(self.normal_map.is_some()),
            normal_scale: self.normal_scale,
            height_kind: match self.height_field {
                Some(ProceduralHeight::Sine { .. }) => 2,
                Some(ProceduralHeight::Noise { .. }) => 3,
                None => u32::from(self.height_map.is_some()),
            },
            height_amplitude: match self.height_field {
                Some(ProceduralHeight::Sine { amplitude, .. } | ProceduralHeight::Noise { amplitude, .. }) => amplitude,
                None => 0.0,
            },
            height_frequency: match self.height_field {
                Some(ProceduralHeight::Sine { frequency, .. }) => frequency.to_array(),
                _ => [0.0; 2],
            },
            noise_seed: match self.height_field {
                Some(ProceduralHeight::Noise { seed, .. }) => seed,
                _ => 0,
            },
            noise_cells: match self.height_field {
                Some(ProceduralHeight::Noise { cells, .. }) => cells,
                _ => 0,
            },
            noise_octaves: match self.height_field {
                Some(ProceduralHeight::Noise { octaves, .. }) => octaves,
                _ => 0,
            },
            _pad: [0.0; 3],
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuObject {
    pub world_from_local: [[f32; 4]; 4],
    pub normal_from_local: [[f32; 4]; 4],
}

impl Object {
    pub fn to_gpu(&self) -> GpuObject {
        GpuObject {
            world_from_local: self.world_from_local.to_cols_array_2d(),
            normal_from_local: Mat4::from_mat3(self.normal_from_local()).to_cols_array_2d(),
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuPresent {
    pub exposure: f32,
    pub _pad: [f32; 3],
}

/// One vertex of the interleaved vertex buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
    /// xyz and the bitangent's sign in w.
    pub tangent: [f32; 4],
}

impl Vertex {
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 4] =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x4];

    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &Self::ATTRIBUTES,
    };
}
