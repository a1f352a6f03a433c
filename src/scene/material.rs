//! Materials: the whole illumination model of docs/course/02-illumination.md and docs/course/09-ray-tracing.md, even where a later issue
//! is the one that draws a term (mirrors, transparency, bump maps).

use std::path::PathBuf;

use glam::{Vec2, Vec3};

use crate::base::TextureId;

/// How a texture's stored values are to be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorSpace {
    /// Colour textures: stored sRGB-encoded, decoded to linear before any filtering.
    Srgb,
    /// Data textures (height maps, normal maps): the stored values are the data.
    Linear,
}

/// A decoded image, 8 bits per channel, RGBA.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub path: PathBuf,
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
    pub color_space: ColorSpace,
}

/// How texture coordinates outside [0, 1] are brought back into the image, per axis (glTF's
/// `wrapS` / `wrapT`; the GPU sampler's address modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Wrap {
    #[default]
    Repeat,
    /// Clamp to the edge texel.
    Clamp,
    /// Repeat, every other copy mirrored.
    Mirror,
}

impl Wrap {
    /// Texel index `i` of an axis `n` texels long, brought into `0..n`.
    pub fn index(self, i: i64, n: i64) -> i64 {
        match self {
            // A power of two's remainder is its low bits (two's complement: below 0 too).
            Wrap::Repeat if n & (n - 1) == 0 => i & (n - 1),
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        }
    }
}

/// A height field given by a formula rather than an image (docs/course/04-bump-mapping.md), with closed-form
/// derivatives so finite differences can be compared with them.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ProceduralHeight {
    /// `a·sin(2π·f_u·u)·sin(2π·f_v·v)`.
    Sine { frequency: Vec2, amplitude: f32 },
    /// Seeded, tileable value noise with quintic interpolation and `octaves` octaves of `cells`,
    /// `2·cells`, … lattice cells per unit of texture coordinate.
    Noise { seed: u32, cells: u32, octaves: u32, amplitude: f32 },
}

/// How a material's coverage `α` is read (glTF's `alphaMode`). `α` is [`Material::alpha`] times
/// the colour texture's alpha where there is a texture.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum AlphaMode {
    /// `α` is ignored: the surface covers all of its area.
    #[default]
    Opaque,
    /// The surface exists only where `α ≥ cutoff` (leaves, fences), for the camera and for the
    /// lights alike.
    Mask { cutoff: f32 },
    /// A fraction `α` of the surface covers what lies behind it: `I = α·Im + (1 − α)·I`, the notes'
    /// transparency (docs/course/06-transparency.md) with `Im` scaled by `α` and `kt·Mt = 1 − α`, grey.
    Blend,
}

impl AlphaMode {
    /// The cutoff of a mask that names none (glTF's `alphaCutoff` default).
    pub const DEFAULT_CUTOFF: f32 = 0.5;
}

/// One material of the model
/// `ME + AG + Σ V·S·(ka·C + kd·C·max(0, n·l) + ks·S·max(0, r·v)^e) + kps·MPS·L(r) + kt·MT·L(t)`.
/// Serializable whole for the page's tracer workers (`src/web/tracer.rs`), which receive the
/// materials as the viewer has edited them.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    pub name: String,
    /// `C`: linear RGB surface colour, multiplied by `texture` where there is one.
    pub color: Vec3,
    pub texture: Option<TextureId>,
    /// How the material's textures wrap along u and v.
    pub wrap: [Wrap; 2],
    /// Per-light ambient coefficient (the notes' `Directa`: `ka·C`, counted only where the light
    /// is visible).
    pub ka: f32,
    pub kd: f32,
    pub ks: f32,
    /// Specular colour `S` of the `ks` term (white for plastics, the base colour for metals).
    pub specular_color: Vec3,
    /// Phong exponent `e`.
    pub shininess: f32,
    /// `ME`: emitted radiance, linear RGB.
    pub emission: Vec3,
    /// `kps` and `MPS`: perfect mirror reflection.
    pub mirror: f32,
    pub mirror_color: Vec3,
    /// `kt` and `MT`: transmission through the surface, with index of refraction `ior`.
    pub transmission: f32,
    pub transmission_color: Vec3,
    pub ior: f32,
    /// Grey-level height field and its scale `k` for bump mapping (docs/course/04-bump-mapping.md).
    pub height_map: Option<TextureId>,
    /// Or a procedural height field (a material has one or the other).
    pub height_field: Option<ProceduralHeight>,
    pub bump_scale: f32,
    /// A tangent-space normal map (glTF's `normalTexture`): RGB = (n + 1)/2 in the frame
    /// (tangent, bitangent, normal), its x and y scaled by `normal_scale`.
    pub normal_map: Option<TextureId>,
    pub normal_scale: f32,
    /// Coverage: how much of the surface is there (glTF's base colour alpha), read as
    /// `alpha_mode` says.
    pub alpha: f32,
    pub alpha_mode: AlphaMode,
}

impl Material {
    /// Whether it reflects a mirror term `kps·MPS·L(r)` (a planar or curved mirror).
    pub fn reflects(&self) -> bool {
        self.mirror > 0.0 && self.mirror_color != glam::Vec3::ZERO
    }

    /// Whether light passes through (kt > 0, or alpha blending): such surfaces are drawn after the
    /// opaque ones, and tint shadows instead of blocking them.
    pub fn is_transparent(&self) -> bool {
        self.transmission > 0.0 || self.alpha_mode == AlphaMode::Blend
    }

    /// Whether rays through it bend (kt > 0 and ior ≠ 1; alpha-blended coverage passes straight
    /// through): what the rasterizer's refraction draws, and what Fresnel weights.
    pub fn bends_light(&self) -> bool {
        self.transmission > 0.0 && self.ior != 1.0 && self.alpha_mode != AlphaMode::Blend
    }
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: "default".into(),
            color: Vec3::splat(0.8),
            texture: None,
            wrap: [Wrap::Repeat; 2],
            ka: 0.0,
            kd: 1.0,
            ks: 0.0,
            specular_color: Vec3::ONE,
            shininess: 32.0,
            emission: Vec3::ZERO,
            mirror: 0.0,
            mirror_color: Vec3::ONE,
            transmission: 0.0,
            transmission_color: Vec3::ONE,
            ior: 1.0,
            height_map: None,
            height_field: None,
            bump_scale: 1.0,
            normal_map: None,
            normal_scale: 1.0,
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
        }
    }
}
