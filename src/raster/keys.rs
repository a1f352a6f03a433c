//! Shader variants' keys: which toggles of a frame and which inputs of a material switch code on
//! or off in the scene module (`shaders/scene.wgsl`'s `override`s). Each pass that draws with the
//! scene module compiles one pipeline per key it meets; toggles are pipeline constants rather
//! than uniform flags because a software GPU runs both sides of a branch on a uniform value.

use super::uniforms::alpha_mode_code;
use crate::scene::{Material, ProceduralHeight};
use crate::settings::{
    BumpView, EnvironmentMap, EnvironmentSettings, RenderSettings, ShadowFilter, ShadowMethod, ShadowView,
    TangentSource, TextureFilter,
};

/// The frame's toggles that switch shader code on or off (the `override`s of
/// `shaders/scene.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FrameKey {
    pub shadow_method: u32,
    pub shadow_filter: u32,
    pub shadow_transmission: bool,
    pub shadow_texels_view: bool,
    pub level_colour: bool,
    pub bump: bool,
    pub bump_view: u32,
    pub tangents_per_vertex: bool,
    pub bump_analytic: bool,
    pub flat_colour: bool,
    /// `ENV_MAP_*`: where curved mirrors look their reflection up; 0: nowhere.
    pub environment: u32,
    /// Record what the shading computes at the inspected pixel (`shaders/inspect.wgsl`): the
    /// main view of an inspected frame only.
    pub inspect: bool,
}

/// `ENVIRONMENT` codes: the world's cube, its sphere map, its lat–long map, or each reflective
/// object's own dynamic cube (the world's for objects without one).
pub const ENV_MAP_CUBE: u32 = 1;
pub const ENV_MAP_SPHERE: u32 = 2;
pub const ENV_MAP_LATLONG: u32 = 3;
pub const ENV_MAP_DYNAMIC: u32 = 4;

/// `SHADOW_METHOD`: no shadows at all (no light casts one, or shadows are off).
pub const SHADOWS_OFF: u32 = 0;
pub const SHADOWS_MAP: u32 = 1;
pub const SHADOWS_PROJECTED: u32 = 2;

impl FrameKey {
    /// `shadowed`: some light casts a shadow this frame; `transmission`: transparent occluders
    /// were drawn into the transmission maps.
    pub fn new(settings: &RenderSettings, shadowed: bool, transmission: bool) -> FrameKey {
        let shadows = &settings.shadows;
        FrameKey {
            shadow_method: match (shadowed && shadows.enabled, shadows.method) {
                (false, _) => SHADOWS_OFF,
                (true, ShadowMethod::Map) => SHADOWS_MAP,
                (true, ShadowMethod::Projected) => SHADOWS_PROJECTED,
            },
            shadow_filter: shadow_filter_code(shadows.filter),
            shadow_transmission: transmission,
            shadow_texels_view: shadows.view == ShadowView::Texels,
            level_colour: settings.textures.filter == TextureFilter::LevelColour,
            bump: settings.bump.enabled,
            bump_view: match settings.bump.view {
                BumpView::Off => 0,
                BumpView::Normals => BUMP_VIEW_NORMALS,
                BumpView::Tangents => BUMP_VIEW_TANGENTS,
            },
            tangents_per_vertex: settings.bump.tangents == TangentSource::PerVertex,
            bump_analytic: settings.bump.analytic,
            flat_colour: settings.raster.flat_colour,
            environment: environment_code(&settings.environment),
            inspect: false,
        }
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

/// What a material brings to the shader: which textures and which height field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialKey {
    pub color_texture: bool,
    /// `HEIGHT_*` of `shaders/scene.wgsl`: 0 none, 1 a height map, 2 a sine field, 3 value noise.
    pub height_kind: u32,
    pub normal_map: bool,
    /// `ALPHA_*` of `shaders/common/types.wgsl`.
    pub alpha_mode: u32,
}

impl MaterialKey {
    pub fn of(material: &Material) -> MaterialKey {
        MaterialKey {
            color_texture: material.texture.is_some(),
            height_kind: match (&material.height_field, &material.height_map) {
                (Some(ProceduralHeight::Sine { .. }), _) => HEIGHT_SINE,
                (Some(ProceduralHeight::Noise { .. }), _) => HEIGHT_NOISE,
                (None, Some(_)) => HEIGHT_TEXTURE,
                (None, None) => HEIGHT_NONE,
            },
            normal_map: material.normal_map.is_some(),
            alpha_mode: alpha_mode_code(material.alpha_mode),
        }
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

/// The names of the pipeline constants, in the order [`constants`] gives their values.
pub const CONSTANT_NAMES: [&str; 16] = [
    "SHADOW_METHOD",
    "SHADOW_FILTER",
    "SHADOW_TRANSMISSION",
    "SHADOW_TEXELS_VIEW",
    "LEVEL_COLOUR",
    "BUMP",
    "BUMP_VIEW",
    "TANGENTS_PER_VERTEX",
    "BUMP_ANALYTIC",
    "FLAT_COLOUR",
    "ENVIRONMENT",
    "COLOR_TEXTURE",
    "HEIGHT_KIND",
    "NORMAL_MAP",
    "ALPHA_MODE",
    "INSPECT",
];

/// The pipeline constants of one variant.
pub fn constants(frame: &FrameKey, material: &MaterialKey) -> [(&'static str, f64); 16] {
    let flag = |b: bool| f64::from(u8::from(b));
    let values = [
        f64::from(frame.shadow_method),
        f64::from(frame.shadow_filter),
        flag(frame.shadow_transmission),
        flag(frame.shadow_texels_view),
        flag(frame.level_colour),
        flag(frame.bump),
        f64::from(frame.bump_view),
        flag(frame.tangents_per_vertex),
        flag(frame.bump_analytic),
        flag(frame.flat_colour),
        f64::from(frame.environment),
        flag(material.color_texture),
        f64::from(material.height_kind),
        flag(material.normal_map),
        f64::from(material.alpha_mode),
        flag(frame.inspect),
    ];
    std::array::from_fn(|i| (CONSTANT_NAMES[i], values[i]))
}
