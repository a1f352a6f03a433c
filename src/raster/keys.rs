//! Shader variants' keys: which toggles of a frame and which inputs of a material switch code on
//! or off in the surface passes' modules (the `override`s of `shaders/common/surface.wgsl` and of
//! a pass's own file). Each surface pass compiles one pipeline per key it meets; toggles are pipeline constants rather
//! than uniform flags because a software GPU runs both sides of a branch on a uniform value.
//!
//! A toggle is declared once, in a [`pipeline_constants!`] key: its field, the `override` it
//! sets and how it is derived from the key's inputs, on one line. The struct, its constructor,
//! its constants' names (checked against the WGSL by `tests/layouts.rs`) and their values are
//! generated from that line.

use super::uniforms::alpha_mode_code;
use crate::scene::{Material, ProceduralHeight};
use crate::settings::{
    BumpView, EnvironmentMap, EnvironmentSettings, HybridSettings, RenderSettings, ShadowFilter, ShadowMethod,
    ShadowView, TangentSource, TextureFilter,
};

/// A value a pipeline constant takes (WGSL's `override`s are set as `f64`).
pub trait ConstantValue: Copy {
    fn constant(self) -> f64;
}

impl ConstantValue for bool {
    fn constant(self) -> f64 {
        f64::from(u8::from(self))
    }
}

impl ConstantValue for u32 {
    fn constant(self) -> f64 {
        f64::from(self)
    }
}

/// Declares a key of pipeline constants, one line a toggle:
/// `field: type = "OVERRIDE" <- how it is derived from the arguments of new`. Generates the
/// struct, `new(arguments)`, `NAMES` (every `override` it sets) and `constants()` (each name
/// with this key's value).
macro_rules! pipeline_constants {
    (
        $(#[$meta:meta])*
        pub struct $name:ident ($($arg:ident: $arg_type:ty),* $(,)?) {
            $($(#[$field_meta:meta])* $field:ident: $type:ty = $constant:literal <- $value:expr),* $(,)?
        }
    ) => {
        $(#[$meta])*
        pub struct $name {
            $($(#[$field_meta])* pub $field: $type,)*
        }

        impl $name {
            /// The `override`s this key sets, in the order of [`Self::constants`].
            pub const NAMES: &'static [&'static str] = &[$($constant),*];

            #[allow(unused_variables)]
            pub fn new($($arg: $arg_type),*) -> $name {
                $name { $($field: $value),* }
            }

            /// Each `override`'s name and its value under this key.
            pub fn constants(&self) -> Vec<(&'static str, f64)> {
                vec![$(($constant, $crate::raster::keys::ConstantValue::constant(self.$field))),*]
            }
        }
    };
}
pub(crate) use pipeline_constants;

pipeline_constants! {
    /// The frame's toggles that switch shader code on or off (the `override`s of
    /// `shaders/scene.wgsl`). `shadowed`: some light casts a shadow this frame; `transmission`:
    /// transparent occluders were drawn into the transmission maps.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    pub struct FrameKey(settings: &RenderSettings, shadowed: bool, transmission: bool) {
        shadow_method: u32 = "SHADOW_METHOD" <- shadow_method_code(settings, shadowed),
        shadow_filter: u32 = "SHADOW_FILTER" <- shadow_filter_code(settings.shadows.filter),
        shadow_transmission: bool = "SHADOW_TRANSMISSION" <- transmission,
        shadow_texels_view: bool = "SHADOW_TEXELS_VIEW" <- settings.shadows.view == ShadowView::Texels,
        level_colour: bool = "LEVEL_COLOUR" <- settings.textures.filter == TextureFilter::LevelColour,
        bump: bool = "BUMP" <- settings.bump.enabled,
        bump_view: u32 = "BUMP_VIEW" <- bump_view_code(settings.bump.view),
        tangents_per_vertex: bool = "TANGENTS_PER_VERTEX" <- settings.bump.tangents == TangentSource::PerVertex,
        bump_analytic: bool = "BUMP_ANALYTIC" <- settings.bump.analytic,
        flat_colour: bool = "FLAT_COLOUR" <- settings.raster.flat_colour,
        /// `ENV_MAP_*`: where curved mirrors look their reflection up; 0: nowhere.
        environment: u32 = "ENVIRONMENT" <- environment_code(&settings.environment),
        /// `TRACED_*` bits: the hybrid's terms read from the view's traced image.
        traced: u32 = "TRACED" <- traced_code(&settings.hybrid),
        /// Record what the shading computes at the inspected pixel (`shaders/common/inspect.wgsl`): the
        /// main view of an inspected frame only.
        inspect: bool = "INSPECT" <- false,
    }
}

/// `ENVIRONMENT` codes: the world's cube, its sphere map, its lat–long map, or each reflective
/// object's own dynamic cube (the world's for objects without one).
pub const ENV_MAP_CUBE: u32 = 1;
pub const ENV_MAP_SPHERE: u32 = 2;
pub const ENV_MAP_LATLONG: u32 = 3;
pub const ENV_MAP_DYNAMIC: u32 = 4;

/// `TRACED` bits (shaders/common/surface.wgsl): which of the hybrid's terms the shading reads.
pub const TRACED_VISIBILITY: u32 = 1;
pub const TRACED_REFLECTION: u32 = 2;
pub const TRACED_COLOUR: u32 = 4;
pub const TRACED_TRANSMISSION: u32 = 8;

fn traced_code(hybrid: &HybridSettings) -> u32 {
    let bit = |on: bool, bit: u32| if on { bit } else { 0 };
    bit(hybrid.shadows, TRACED_VISIBILITY)
        | bit(hybrid.reflections, TRACED_REFLECTION)
        | bit(hybrid.textures, TRACED_COLOUR)
        | bit(hybrid.transmission, TRACED_TRANSMISSION)
}

/// `SHADOW_METHOD`: no shadows at all (no light casts one, or shadows are off).
pub const SHADOWS_OFF: u32 = 0;
pub const SHADOWS_MAP: u32 = 1;
pub const SHADOWS_PROJECTED: u32 = 2;

/// The `SHADOW_METHOD` code: none when no light casts a shadow or shadows are off.
fn shadow_method_code(settings: &RenderSettings, shadowed: bool) -> u32 {
    match (shadowed && settings.shadows.enabled, settings.shadows.method) {
        (false, _) => SHADOWS_OFF,
        (true, ShadowMethod::Map) => SHADOWS_MAP,
        (true, ShadowMethod::Projected) => SHADOWS_PROJECTED,
    }
}

/// The `BUMP_VIEW` code.
fn bump_view_code(view: BumpView) -> u32 {
    match view {
        BumpView::Off => 0,
        BumpView::Normals => BUMP_VIEW_NORMALS,
        BumpView::Tangents => BUMP_VIEW_TANGENTS,
    }
}

/// The `ENVIRONMENT` code of the environment settings.
pub fn environment_code(settings: &EnvironmentSettings) -> u32 {
    match (settings.enabled, settings.map, settings.dynamic) {
        (false, ..) => 0,
        (true, EnvironmentMap::Cube, false) => ENV_MAP_CUBE,
        (true, EnvironmentMap::Cube, true) => ENV_MAP_DYNAMIC,
        (true, EnvironmentMap::Sphere, _) => ENV_MAP_SPHERE,
        (true, EnvironmentMap::Latlong, _) => ENV_MAP_LATLONG,
    }
}

/// The `SHADOW_FILTER_*` code of `shaders/common/shadow.wgsl`.
pub fn shadow_filter_code(filter: ShadowFilter) -> u32 {
    match filter {
        ShadowFilter::None => 0,
        ShadowFilter::Hardware => 1,
        ShadowFilter::Pcf3x3 => 2,
        ShadowFilter::Pcf5x5 => 3,
        ShadowFilter::Poisson => 4,
    }
}

/// Every `ShadowFilter` and its code, for the test that ties them to the WGSL.
pub const SHADOW_FILTER_NAMES: [(&str, ShadowFilter); 5] = [
    ("SHADOW_FILTER_NONE", ShadowFilter::None),
    ("SHADOW_FILTER_HARDWARE", ShadowFilter::Hardware),
    ("SHADOW_FILTER_PCF3", ShadowFilter::Pcf3x3),
    ("SHADOW_FILTER_PCF5", ShadowFilter::Pcf5x5),
    ("SHADOW_FILTER_POISSON", ShadowFilter::Poisson),
];

pipeline_constants! {
    /// What a material brings to the shader: which textures and which height field.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
    pub struct MaterialKey(material: &Material) {
        color_texture: bool = "COLOR_TEXTURE" <- material.texture.is_some(),
        /// `HEIGHT_*` of `shaders/scene.wgsl`: 0 none, 1 a height map, 2 a sine field, 3 value noise.
        height_kind: u32 = "HEIGHT_KIND" <- height_kind(material),
        normal_map: bool = "NORMAL_MAP" <- material.normal_map.is_some(),
        /// `ALPHA_*` of `shaders/common/types.wgsl`.
        alpha_mode: u32 = "ALPHA_MODE" <- alpha_mode_code(material.alpha_mode),
    }
}

/// The `HEIGHT_*` code of where a material's bump heights come from.
fn height_kind(material: &Material) -> u32 {
    match (&material.height_field, &material.height_map) {
        (Some(ProceduralHeight::Sine { .. }), _) => HEIGHT_SINE,
        (Some(ProceduralHeight::Noise { .. }), _) => HEIGHT_NOISE,
        (None, Some(_)) => HEIGHT_TEXTURE,
        (None, None) => HEIGHT_NONE,
    }
}

/// `BUMP_VIEW_*` codes.
pub const BUMP_VIEW_NORMALS: u32 = 1;
pub const BUMP_VIEW_TANGENTS: u32 = 2;
/// `HEIGHT_*` codes: where a material's bump heights come from.
pub const HEIGHT_NONE: u32 = 0;
pub const HEIGHT_TEXTURE: u32 = 1;
pub const HEIGHT_SINE: u32 = 2;
pub const HEIGHT_NOISE: u32 = 3;

/// The pipeline constants of one scene-module variant: the frame's toggles and the material's.
pub fn constants(frame: &FrameKey, material: &MaterialKey) -> Vec<(&'static str, f64)> {
    let mut constants = frame.constants();
    constants.extend(material.constants());
    constants
}
