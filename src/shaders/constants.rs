//! Every constant the Rust code and the WGSL share, written once, here, in Rust: the codes of
//! the uniforms' fields, the pipeline constants' values, the sizes of the shaders' arrays, and
//! (from the approximations table, `crate::settings::hybrid`) the hybrid's bits and layers.
//! [`prelude`] writes them as WGSL `const`s, which [`super::Wgsl`] composes ahead of every
//! module, before the device's profile: no WGSL file declares one, so no test has to keep two
//! spellings equal.
//!
//! The constants Mirador's other modules own (a volume's march, the level-colour palette) are
//! named here by their path, not copied; those of the rasterizer's data are defined here, and
//! `crate::raster` uses them from here.

use crate::settings::hybrid::{APPROXIMATIONS, SURFACE_LAYER, TRACED_LAYERS, Traced};

/// A constant's WGSL type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Type {
    U32,
    I32,
}

/// Declares the shared constants: `NAME: RustType as WgslType = value;`, its documentation
/// above it. Generates each `pub const` (unless it is `use`d from its owner, `NAME = path;`)
/// and [`ALL`], what [`prelude`] writes.
macro_rules! wgsl_constants {
    ($(
        $(#[doc = $doc:literal])*
        $name:ident: $rust:ty as $wgsl:ident = $value:expr;
    )+) => {
        $( $(#[doc = $doc])* pub const $name: $rust = $value; )+

        /// Every shared constant: its name, documentation, WGSL type and value.
        pub const ALL: &[(&str, &[&str], Type, i64)] = &[$(
            (stringify!($name), &[$($doc),*], Type::$wgsl, $name as i64),
        )+];
    };
}

wgsl_constants! {
    /// The most lights the frame draws (`Frame.lights` of `shaders/common/types.wgsl`).
    MAX_LIGHTS: usize as U32 = 16;
    /// The most objects with a dynamic environment cube of their own (six views each); the
    /// others reflect the world's.
    MAX_ENV_CUBES: usize as U32 = 8;
    /// `Light.kind` codes.
    LIGHT_POINT: u32 as U32 = 0;
    LIGHT_DIRECTIONAL: u32 as U32 = 1;
    LIGHT_SPOT: u32 as U32 = 2;
    /// `Light.attenuation` codes.
    ATTENUATION_NONE: u32 as U32 = 0;
    ATTENUATION_INVERSE_SQUARE: u32 as U32 = 1;
    /// Bits of `Frame.terms`: which terms of the illumination model are drawn.
    TERM_AMBIENT: u32 as U32 = 1;
    TERM_DIFFUSE: u32 as U32 = 2;
    TERM_SPECULAR: u32 as U32 = 4;
    TERM_EMISSION: u32 as U32 = 8;
    /// Not a term of the model: glass's reflection and transmission weighted by Fresnel.
    TERM_FRESNEL: u32 as U32 = 16;
    /// `Material.alpha_mode` (`ALPHA_MODE`): how coverage α (glTF's base colour alpha) is read.
    ALPHA_OPAQUE: u32 as U32 = 0;
    ALPHA_MASK: u32 as U32 = 1;
    ALPHA_BLEND: u32 as U32 = 2;
    /// `Instance.env_layer` of objects that look the world's environment up.
    ENV_LAYER_WORLD: i32 as I32 = -1;
    /// `Instance.env_layer` of objects that look nothing up (planar mirrors).
    ENV_LAYER_NONE: i32 as I32 = -2;
    /// `Environment.source`: what the world's environment is made of.
    ENV_NONE: u32 as U32 = 0;
    ENV_SKY: u32 as U32 = 1;
    ENV_LATLONG: u32 as U32 = 2;
    ENV_CUBE: u32 as U32 = 3;
    ENV_SPHERE: u32 as U32 = 4;
    /// `Environment.parallax`: where a dynamic cube's lookup assumes the ray ends.
    PARALLAX_INFINITE: u32 as U32 = 0;
    PARALLAX_GROUND: u32 as U32 = 1;
    PARALLAX_BOX: u32 as U32 = 2;
    /// `ENVIRONMENT` (a pipeline constant): where curved mirrors look their reflection up, the
    /// world's cube, its sphere map, its lat–long map, or each reflective object's own dynamic
    /// cube (the world's for objects without one); 0: nowhere.
    ENV_MAP_CUBE: u32 as U32 = 1;
    ENV_MAP_SPHERE: u32 as U32 = 2;
    ENV_MAP_LATLONG: u32 as U32 = 3;
    ENV_MAP_DYNAMIC: u32 as U32 = 4;
    /// `SHADOW_METHOD`: no shadows at all (no light casts one, or shadows are off), shadow maps
    /// or projected polygons.
    SHADOWS_OFF: u32 as U32 = 0;
    SHADOWS_MAP: u32 as U32 = 1;
    SHADOWS_PROJECTED: u32 as U32 = 2;
    /// `SHADOW_FILTER`: how a shadow map's lookups are filtered.
    SHADOW_FILTER_NONE: u32 as U32 = 0;
    SHADOW_FILTER_HARDWARE: u32 as U32 = 1;
    SHADOW_FILTER_PCF3: u32 as U32 = 2;
    SHADOW_FILTER_PCF5: u32 as U32 = 3;
    SHADOW_FILTER_POISSON: u32 as U32 = 4;
    /// The shadow maps' layers: six for each shadowed light (a point light's cube).
    MAX_SHADOW_LAYERS: usize as U32 = 6 * crate::settings::MAX_SHADOWED_LIGHTS;
    /// `BUMP_VIEW`: the bumped normals or the tangents shown instead of the shading.
    BUMP_VIEW_NORMALS: u32 as U32 = 1;
    BUMP_VIEW_TANGENTS: u32 as U32 = 2;
    /// `HEIGHT_KIND`: where a material's bump heights come from.
    HEIGHT_NONE: u32 as U32 = 0;
    HEIGHT_TEXTURE: u32 as U32 = 1;
    HEIGHT_SINE: u32 as U32 = 2;
    HEIGHT_NOISE: u32 as U32 = 3;
    /// The level-colour view's last colour (levels past it are grey):
    /// `crate::texture::mipmap::LEVEL_PALETTE`'s.
    MIP_PALETTE_LAST: usize as U32 = crate::texture::mipmap::LEVEL_PALETTE.len() - 1;
    /// `REFRACTION` of `shaders/refraction.wgsl`: where the light along the twice-refracted ray
    /// is read.
    REFRACTION_ENVIRONMENT: u32 as U32 = 1;
    REFRACTION_SCREEN: u32 as U32 = 2;
    /// The records one inspected pixel keeps (`shaders/common/inspect.wgsl`).
    MAX_INSPECTED: usize as U32 = 32;
    /// `INSPECT_*` kinds of fragment in an inspected pixel's records.
    INSPECT_OPAQUE: u32 as U32 = 1;
    INSPECT_MIRROR: u32 as U32 = 2;
    INSPECT_TRANSPARENT: u32 as U32 = 3;
    INSPECT_BACKGROUND: u32 as U32 = 4;
    INSPECT_ISOSURFACE: u32 as U32 = 5;
    INSPECT_VOLUME: u32 as U32 = 6;
    INSPECT_REFRACTION: u32 as U32 = 7;
    /// Parallax mapping's march: its equal steps through the relief's slab and the secant steps
    /// that refine the crossing (`crate::texture::parallax`'s).
    PARALLAX_STEPS: u32 as U32 = crate::texture::parallax::STEPS;
    PARALLAX_REFINEMENTS: u32 as U32 = crate::texture::parallax::REFINEMENTS;
    /// `Volume.gradient`: how a volume's normals are estimated.
    VOLUME_GRADIENT_OFF: u32 as U32 = 0;
    VOLUME_GRADIENT_FORWARD: u32 as U32 = 1;
    VOLUME_GRADIENT_CENTRAL: u32 as U32 = 2;
    /// `Volume.view` of the samples view (0: the volume itself).
    VOLUME_VIEW_SAMPLES: u32 as U32 = 1;
    /// A ray's most samples through a volume: `crate::volume::march`'s.
    VOLUME_MAX_SAMPLES: u32 as U32 = crate::volume::march::MAX_SAMPLES;
    /// The bisection steps that place an isosurface's crossing: `crate::volume::march`'s.
    VOLUME_BISECTION_STEPS: u32 as U32 = crate::volume::march::BISECTION_STEPS;
    /// The transfer function's table entries: `crate::volume::transfer`'s.
    VOLUME_TABLE_SIZE: usize as U32 = crate::volume::transfer::TABLE_SIZE;
    /// `tone_map` of `shaders/present.wgsl`: the curves of `crate::settings::ToneMap`, in its
    /// order.
    TONE_MAP_CLAMP: u32 as U32 = 0;
    TONE_MAP_REINHARD: u32 as U32 = 1;
    TONE_MAP_ACES: u32 as U32 = 2;
    TONE_MAP_PBR_NEUTRAL: u32 as U32 = 3;
    /// The projected-shadow mask's first layer of the view's `drawn_images`, the array its raster
    /// passes draw and blend (each view image is layers of one of the view's two arrays,
    /// `crate::raster::targets::ViewImage`).
    PROJECTED_MASK_LAYER: u32 as I32 = 0;
    /// The hybrid's traced terms' first layer of the view's `copied_images`, the array the CPU
    /// copies into (`TRACED_SURFACE_LAYER` and each row's `TRACED_NAME_LAYER` count from it).
    TRACED_FIRST_LAYER: u32 as I32 = 0;
}

/// The WGSL `const`s of [`ALL`] and of the approximations table: `TRACED_NAME`, the row's bit in
/// the frame's `traced` uniform, and `TRACED_NAME_LAYER`, its term's first layer in the view's
/// traced image (after `TRACED_SURFACE_LAYER`). Written once, the first time a module is
/// composed.
pub fn prelude() -> &'static str {
    static PRELUDE: std::sync::LazyLock<String> = std::sync::LazyLock::new(written);
    &PRELUDE
}

/// The text of [`prelude`].
fn written() -> String {
    let mut out = String::from("// Written by src/shaders/constants.rs from the Rust constants: edit them there.\n");
    for (name, doc, ty, value) in ALL {
        for line in *doc {
            out.push_str(&format!("//{line}\n"));
        }
        match ty {
            Type::U32 => out.push_str(&format!("const {name}: u32 = {value}u;\n")),
            Type::I32 => out.push_str(&format!("const {name}: i32 = {value};\n")),
        }
    }
    out.push_str("// One colour per mip level for the level-colour view (linear RGB); levels past the last are\n");
    out.push_str("// grey: crate::texture::mipmap::LEVEL_PALETTE.\n");
    let palette = crate::texture::mipmap::LEVEL_PALETTE;
    out.push_str(&format!("const MIP_LEVEL_PALETTE = array<vec3f, {}>(\n", palette.len()));
    for colour in palette {
        out.push_str(&format!("    vec3f({:?}, {:?}, {:?}),\n", colour.x, colour.y, colour.z));
    }
    out.push_str(");\n");
    out.push_str("// The hybrid's approximations table (src/settings/hybrid.rs): each row's bit of TRACED and\n");
    out.push_str("// its term's first layer of the view's traced image, after the surface's.\n");
    out.push_str(&format!("const TRACED_SURFACE_LAYER: i32 = {SURFACE_LAYER};\n"));
    out.push_str(&format!("const TRACED_LAYERS: i32 = {TRACED_LAYERS};\n"));
    for (row, term) in APPROXIMATIONS.iter().zip(Traced::ALL) {
        let name = row.name.to_uppercase();
        out.push_str(&format!("const TRACED_{name}: u32 = {}u;\n", term.bit()));
        out.push_str(&format!("const TRACED_{name}_LAYER: i32 = {};\n", term.layer()));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prelude_declares_each_constant_once_and_parses() {
        let prelude = prelude();
        for (name, ..) in ALL {
            assert_eq!(prelude.matches(&format!("const {name}:")).count(), 1, "{name}");
        }
        assert!(prelude.contains("const ENV_LAYER_NONE: i32 = -2;"));
        assert!(prelude.contains("const MIP_PALETTE_LAST: u32 = 7u;"));
        assert!(prelude.contains("const TRACED_REFLECTIONS: u32 = 2u;"));
        naga::front::wgsl::parse_str(prelude).unwrap_or_else(|e| panic!("{}", e.emit_to_string(prelude)));
    }
}
