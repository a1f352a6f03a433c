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
    BumpMethod, BumpView, EnvironmentMap, EnvironmentSettings, RenderSettings, ShadowFilter, ShadowMethod, ShadowView,
    TangentSource, TextureFilter,
};
pub use crate::shaders::constants::{
    BUMP_VIEW_NORMALS, BUMP_VIEW_TANGENTS, ENV_MAP_CUBE, ENV_MAP_DYNAMIC, ENV_MAP_LATLONG, ENV_MAP_SPHERE,
    HEIGHT_NOISE, HEIGHT_NONE, HEIGHT_SINE, HEIGHT_TEXTURE, SHADOWS_MAP, SHADOWS_OFF, SHADOWS_PROJECTED,
};
use crate::shaders::constants::{
    SHADOW_FILTER_HARDWARE, SHADOW_FILTER_NONE, SHADOW_FILTER_PCF3, SHADOW_FILTER_PCF5, SHADOW_FILTER_POISSON,
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
        parallax: bool = "PARALLAX" <- settings.bump.enabled && settings.bump.method == BumpMethod::Parallax,
        flat_colour: bool = "FLAT_COLOUR" <- settings.raster.flat_colour,
        /// `ENV_MAP_*`: where curved mirrors look their reflection up; 0: nowhere.
        environment: u32 = "ENVIRONMENT" <- environment_code(&settings.environment),
        /// Whether any of the hybrid's terms is traced: which ones is `GpuFrame::traced`, so that
        /// swapping one term for another makes no new variant.
        hybrid: bool = "HYBRID" <- !settings.hybrid.traced().is_empty(),
        /// Record what the shading computes at the inspected pixel (`shaders/common/inspect.wgsl`): the
        /// main view of an inspected frame only.
        inspect: bool = "INSPECT" <- false,
    }
}

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
        BumpView::Off | BumpView::Tessellation => 0,
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
        ShadowFilter::None => SHADOW_FILTER_NONE,
        ShadowFilter::Hardware => SHADOW_FILTER_HARDWARE,
        ShadowFilter::Pcf3x3 => SHADOW_FILTER_PCF3,
        ShadowFilter::Pcf5x5 => SHADOW_FILTER_PCF5,
        ShadowFilter::Poisson => SHADOW_FILTER_POISSON,
    }
}

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

/// The pipeline constants of one scene-module variant: the frame's toggles and the material's.
pub fn constants(frame: &FrameKey, material: &MaterialKey) -> Vec<(&'static str, f64)> {
    let mut constants = frame.constants();
    constants.extend(material.constants());
    constants
}
