//! GPU layouts of the scene's CPU types (`Light → GpuLight`, …), `#[repr(C)]` and bytemuck.
//! Their WGSL twins are in `shaders/common/types.wgsl`; `tests/layouts.rs` compares the sizes
//! through naga's reflection, so the padding is checked rather than kept in step by hand.

use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Mat4, Vec3};

use crate::scene::{AlphaMode, Attenuation, Light, LightKind, Material, ProceduralHeight};
use crate::settings::RenderSettings;

/// The codes and sizes the uniforms share with the WGSL, defined once in `crate::shaders::constants`.
pub use crate::shaders::constants::{
    ALPHA_BLEND, ALPHA_MASK, ALPHA_OPAQUE, ATTENUATION_INVERSE_SQUARE, ATTENUATION_NONE, ENV_CUBE, ENV_LATLONG,
    ENV_LAYER_NONE, ENV_LAYER_WORLD, ENV_NONE, ENV_SKY, ENV_SPHERE, LIGHT_DIRECTIONAL, LIGHT_POINT, LIGHT_SPOT,
    MAX_ENV_CUBES, MAX_LIGHTS, PARALLAX_BOX, PARALLAX_GROUND, PARALLAX_INFINITE, TERM_AMBIENT, TERM_DIFFUSE,
    TERM_EMISSION, TERM_FRESNEL, TERM_SPECULAR,
};

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
            LightKind::Point { position } => (LIGHT_POINT, position, Vec3::ZERO, 1.0, 1.0),
            LightKind::Directional { direction } => (LIGHT_DIRECTIONAL, Vec3::ZERO, direction, 1.0, 1.0),
            LightKind::Spot { position, direction, inner, outer } => {
                (LIGHT_SPOT, position, direction, inner.cos(), outer.cos())
            }
        };
        GpuLight {
            position: position.to_array(),
            kind,
            direction: direction.to_array(),
            attenuation: match self.attenuation {
                Attenuation::None => ATTENUATION_NONE,
                Attenuation::InverseSquare => ATTENUATION_INVERSE_SQUARE,
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

/// Group 0, binding 1: what every view of a frame shares.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuFrame {
    pub ambient: [f32; 3],
    pub light_count: u32,
    pub terms: u32,
    pub lod_bias: f32,
    pub bump_scale: f32,
    pub bump_delta_texels: f32,
    /// `TRACED_*` bits, one a row of the approximations table (`crate::settings::hybrid`): the
    /// hybrid's terms read from the view's traced image. A uniform, not a pipeline constant, so
    /// that swapping a term makes no new shading variant.
    pub traced: u32,
    pub _pad: [u32; 3],
    pub lights: [GpuLight; MAX_LIGHTS],
}

impl GpuFrame {
    /// The per-frame uniform. Lights past [`MAX_LIGHTS`] are dropped (the loader warns).
    /// `shadow_layers[i]` is light `i`'s first shadow-map layer, if it casts shadows.
    pub fn new(ambient: Vec3, lights: &[Light], shadow_layers: &[Option<u32>], settings: &RenderSettings) -> GpuFrame {
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
        let bit = |on: bool, bit: u32| if on { bit } else { 0 };
        let terms = bit(t.ambient, TERM_AMBIENT)
            | bit(t.diffuse, TERM_DIFFUSE)
            | bit(t.specular, TERM_SPECULAR)
            | bit(t.emission, TERM_EMISSION)
            | bit(t.fresnel, TERM_FRESNEL);
        GpuFrame {
            ambient: ambient.to_array(),
            light_count: lights.len().min(MAX_LIGHTS) as u32,
            terms,
            lod_bias: settings.textures.lod_bias,
            bump_scale: settings.bump.scale,
            bump_delta_texels: settings.bump.delta_texels,
            traced: settings.hybrid.traced().0,
            _pad: [0; 3],
            lights: gpu_lights,
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    pub color: [f32; 3],
    pub ka: f32,
    pub kd: f32,
    pub ks: f32,
    pub shininess: f32,
    pub transparent: u32,
    pub specular_color: [f32; 3],
    pub bump_scale: f32,
    pub emission: [f32; 3],
    pub normal_scale: f32,
    pub transmission: [f32; 3],
    pub height_amplitude: f32,
    pub height_frequency: [f32; 2],
    pub noise_seed: u32,
    pub noise_cells: u32,
    pub noise_octaves: u32,
    /// Coverage `α` (before the colour texture's alpha) and the cut-off of `ALPHA_MASK`.
    pub alpha: f32,
    pub alpha_cutoff: f32,
    /// `ALPHA_*` of `shaders/common/types.wgsl`.
    pub alpha_mode: u32,
    /// `kps·MPS`: what a mirror reflects.
    pub reflectance: [f32; 3],
    /// The material's index in the scene (set by the upload; for inspecting a pixel).
    pub index: u32,
    /// The index of refraction, for Fresnel and refraction.
    pub ior: f32,
    pub _pad: [f32; 3],
}

pub fn alpha_mode_code(mode: AlphaMode) -> u32 {
    match mode {
        AlphaMode::Opaque => ALPHA_OPAQUE,
        AlphaMode::Mask { .. } => ALPHA_MASK,
        AlphaMode::Blend => ALPHA_BLEND,
    }
}

/// What a transparent surface lets through, the factor of `I = Im + kt·Mt·I`: `kt·Mt`, and for
/// alpha blending `α·kt·Mt + (1 − α)` with the material's `α` (the texture's alpha, where there is
/// one, is applied per pixel instead; see `src/raster/transparency.rs`).
pub fn transmittance(material: &Material) -> Vec3 {
    let through = material.transmission * material.transmission_color;
    match material.alpha_mode {
        AlphaMode::Blend => material.alpha * through + Vec3::splat(1.0 - material.alpha),
        _ => through,
    }
}

impl Material {
    pub fn to_gpu(&self) -> GpuMaterial {
        let (amplitude, frequency, seed, cells, octaves) = match self.height_field {
            Some(ProceduralHeight::Sine { amplitude, frequency }) => (amplitude, frequency.to_array(), 0, 0, 0),
            Some(ProceduralHeight::Noise { amplitude, seed, cells, octaves }) => {
                (amplitude, [0.0; 2], seed, cells, octaves)
            }
            None => (0.0, [0.0; 2], 0, 0, 0),
        };
        GpuMaterial {
            color: self.color.to_array(),
            ka: self.ka,
            kd: self.kd,
            ks: self.ks,
            shininess: self.shininess,
            transparent: u32::from(self.is_transparent()),
            specular_color: self.specular_color.to_array(),
            bump_scale: self.bump_scale,
            emission: self.emission.to_array(),
            normal_scale: self.normal_scale,
            transmission: (self.transmission * self.transmission_color).to_array(),
            height_amplitude: amplitude,
            height_frequency: frequency,
            noise_seed: seed,
            noise_cells: cells,
            noise_octaves: octaves,
            alpha: self.alpha,
            alpha_cutoff: match self.alpha_mode {
                AlphaMode::Mask { cutoff } => cutoff,
                _ => 0.0,
            },
            alpha_mode: alpha_mode_code(self.alpha_mode),
            reflectance: (self.mirror * self.mirror_color).to_array(),
            index: 0,
            ior: self.ior,
            _pad: [0.0; 3],
        }
    }
}

/// Per object: its transforms, as instance attributes (vertex buffer 1, `Instance` in
/// `shaders/common/types.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuInstance {
    pub world_from_local: [[f32; 4]; 4],
    /// Inverse transpose of `world_from_local`'s upper 3×3, by columns.
    pub normal_from_local: [[f32; 3]; 3],
    /// Layer of the object's own cube among the dynamic environment cubes; −1: the world's.
    pub env_layer: i32,
    /// The object's index in the scene, [`UNKNOWN_OBJECT`] where the instance stands for many.
    pub object: u32,
}

/// `GpuInstance::object` of an instance that draws several objects' triangles.
pub const UNKNOWN_OBJECT: u32 = u32::MAX;

impl GpuInstance {
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 9] = wgpu::vertex_attr_array![
        4 => Float32x4, 5 => Float32x4, 6 => Float32x4, 7 => Float32x4,
        8 => Float32x3, 9 => Float32x3, 10 => Float32x3, 11 => Sint32, 12 => Uint32,
    ];

    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<GpuInstance>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &Self::ATTRIBUTES,
    };

    /// An instance whose environment lookups read `env_layer`: a dynamic cube's layer, or
    /// [`ENV_LAYER_WORLD`], or [`ENV_LAYER_NONE`] for planar mirrors (their mirrored camera
    /// reflects for them, and past `mirrors.depth` nothing does, as the tracer's `max_depth`).
    pub fn new(world_from_local: Mat4, env_layer: i32, object: u32) -> GpuInstance {
        GpuInstance {
            world_from_local: world_from_local.to_cols_array_2d(),
            normal_from_local: Mat3::from_mat4(world_from_local).inverse().transpose().to_cols_array_2d(),
            env_layer,
            object,
        }
    }
}

/// Group 0, binding 0: one view's camera (`View` in `shaders/common/types.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuView {
    pub clip_from_world: [[f32; 4]; 4],
    pub world_from_clip: [[f32; 4]; 4],
    pub eye: [f32; 3],
    pub orthographic: u32,
    pub view_axis: [f32; 3],
    pub mirrored: u32,
    pub clip_plane: [f32; 4],
    pub clip_from_reflected: [[f32; 4]; 4],
}

/// The world's environment and the sphere map's rotations (`Environment` in
/// `shaders/common/environment.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuEnvironment {
    /// World to the sphere map's view space, for lookups (columns padded to four).
    pub sphere_from_world: [[f32; 4]; 3],
    /// Sphere-map view space to world, for making the map.
    pub world_from_map: [[f32; 4]; 3],
    pub zenith: [f32; 3],
    pub source: u32,
    pub horizon: [f32; 3],
    pub intensity: f32,
    pub ground: [f32; 3],
    pub sun_cos_outer: f32,
    pub sun_direction: [f32; 3],
    pub sun_cos_inner: f32,
    pub sun_color: [f32; 3],
    pub _pad0: f32,
    pub background: [f32; 3],
    pub _pad1: f32,
    /// The parallax proxy (`PARALLAX_*`): the box around the scene, its bottom the ground.
    pub proxy_min: [f32; 3],
    pub parallax: u32,
    pub proxy_max: [f32; 3],
    pub _pad2: f32,
    /// Each dynamic cube's centre, where its six views were drawn from.
    pub cube_centres: [[f32; 4]; MAX_ENV_CUBES],
}

/// A 3×3 matrix as WGSL's `mat3x3f` lays it out: columns of four floats.
pub fn mat3_columns(m: Mat3) -> [[f32; 4]; 3] {
    [m.x_axis.extend(0.0).to_array(), m.y_axis.extend(0.0).to_array(), m.z_axis.extend(0.0).to_array()]
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuPresent {
    pub exposure: f32,
    /// `TONE_MAP_*` in `shaders/present.wgsl`, [`crate::settings::ToneMap`] in order.
    pub tone_map: u32,
    /// The HDR image's size over the output's.
    pub scale: [f32; 2],
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
