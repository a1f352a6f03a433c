//! Texture filtering: mipmaps and the sampling modes (docs/course/03-mipmaps.md).

use super::field::{choices, section};

section! {
    /// How colour textures are filtered, in both renderers.
    #[derive(Copy)]
    pub struct TextureSettings {
        /// How colour textures are sampled: one texel, bilinear, within one mip level, between two
        /// (trilinear), anisotropic, or each level in its own colour.
        filter: TextureFilter = TextureFilter::Trilinear,
        /// How the ray tracer picks a texture's mip level at a hit: the ray cone's footprint, or
        /// the notes' `log(distance)` rule.
        tracer_lod: TracerLod = TracerLod::RayCone,
        /// Most samples along the footprint's long axis for the `anisotropic` filter (1 is
        /// isotropic), where the device allows.
        #[values(closed(1.0, 16.0))]
        anisotropy: u16 = 16,
        /// Added to every level of detail `λ`: positive blurs, negative sharpens and brings back
        /// the aliasing mipmaps remove.
        #[values(closed(-8.0, 8.0))]
        lod_bias: f32 = 0.0,
    }
}

choices! {
    /// How colour textures are filtered.
    pub enum TextureFilter {
        /// The nearest texel of the full-size image: aliasing and moiré in the distance.
        Nearest,
        /// Bilinear on the full-size image (level 0 only), no mipmaps: still moiré.
        Bilinear,
        /// Bilinear within the nearest mip level: hard seams where the level changes.
        NearestMip,
        /// Bilinear in the two nearest levels, blended by the fractional level.
        Trilinear,
        /// Anisotropic filtering, up to `anisotropy` samples along the footprint's long axis (the
        /// rasterizer only; the tracer uses trilinear).
        Anisotropic,
        /// Each mip level painted in its own colour: where the level changes, and the blend.
        LevelColour,
    }
}

choices! {
    /// How the ray tracer picks a texture's mip level at a hit.
    pub enum TracerLod {
        /// The footprint of the pixel's ray cone on the surface, stretched by the angle of
        /// incidence.
        RayCone,
        /// The notes' simple rule: the level grows with the logarithm of the distance travelled,
        /// whatever the angle (orthographic cameras, whose rays do not spread, use the cone).
        Distance,
    }
}
