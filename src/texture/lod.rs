//! Level of detail: which mip level a lookup reads (docs/course/03-mipmaps.md).
//!
//! The level is `λ = log2 ρ + bias`, `ρ` the number of level-0 texels one pixel covers along its
//! longer side. Three ways to estimate `ρ`, from the simplest to the GPU's own:
//!
//! - **Distance** (the notes' rule, [`lod_from_distance`]): "the level grows linearly with
//!   log(d)": `λ = log2(d / d₀)`, `d₀` the distance at which one texel fills one pixel. Exact only
//!   for a surface facing the camera with a uniform texture scale; it knows nothing of slanted
//!   surfaces or of how the texture is stretched.
//! - **Ray cone** (for the ray tracer, [`RayCone`] and [`lod_from_footprint`]; Akenine-Möller et
//!   al., "Texture Level of Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems ch. 20):
//!   each primary ray carries a cone whose spread is the angle of one pixel,
//!   `γ = atan(2·tan(fovy/2)/height)`, so at distance `t` it is `w = t·γ` wide (a constant pixel
//!   width for orthographic cameras). On a surface seen at an angle `θ` the footprint is stretched
//!   to `w/|cos θ|`. The footprint spans `w/|∂p/∂u|` in `u`, i.e. `width·w/|∂p/∂u|` texels, and
//!   `ρ = max` of that and the same in `v`.
//! - **Screen derivatives** (the GPU's rule, [`lod_from_uv_derivatives`], WGSL twin `mip_lod`):
//!   `ρ = max(|∂(u·w, v·h)/∂x|, |∂(u·w, v·h)/∂y|)` from the change of texture coordinates between
//!   neighbouring pixels. A frontal surface gives the same `λ` by all three rules (a test checks).
//!
//! Limits: all three are isotropic (one `ρ` for the longer side), so a surface seen at a grazing
//! angle is blurred along both axes; the GPU's anisotropic filtering takes several taps along the
//! longer axis instead. The ray cone ignores the curvature of mirrors and refracting surfaces
//! (Ray Tracing Gems §20.3.2 widens the cone there): secondary rays keep the spread they had.

use glam::Vec2;

/// The smallest `|cos θ|` used to stretch a footprint, so that a ray grazing a surface gives a
/// large but finite level (the sampler clamps it to the smallest level anyway).
pub const MIN_COS_INCIDENCE: f32 = 1e-4;

/// The notes' rule: `λ = log2(distance / texel_distance) + bias`, where `texel_distance` is the
/// distance at which one level-0 texel covers one pixel (for a frontal surface,
/// `(|∂p/∂u| / width) / γ` with `γ` the pixel's angle, see [`pixel_spread_angle`]). Negative
/// values (magnification) are returned as they are; the sampler clamps them to level 0.
pub fn lod_from_distance(distance: f32, texel_distance: f32, bias: f32) -> f32 {
    (distance / texel_distance).log2() + bias
}

/// The level of detail of a footprint `footprint_width` wide (world units, on the surface) on a
/// texture of `size` texels whose parametrization has `|∂p/∂u| = dpdu_length`,
/// `|∂p/∂v| = dpdv_length` (world units per unit of texture coordinate):
/// `λ = log2 max(size.x·w/|∂p/∂u|, size.y·w/|∂p/∂v|) + bias`.
///
/// A zero-length derivative (a degenerate parametrization, e.g. at a sphere's pole) makes that
/// axis's count infinite and so the level the smallest one, which is what the texture squeezed
/// into a point looks like.
pub fn lod_from_footprint(
    footprint_width: f32,
    dpdu_length: f32,
    dpdv_length: f32,
    size: (u32, u32),
    bias: f32,
) -> f32 {
    let texels_u = footprint_width * size.0 as f32 / dpdu_length;
    let texels_v = footprint_width * size.1 as f32 / dpdv_length;
    texels_u.max(texels_v).log2() + bias
}

/// The GPU's rule from the screen-space derivatives of the texture coordinates:
/// `λ = log2 max(|duv_dx ⊙ size|, |duv_dy ⊙ size|) + bias` (WGSL twin: `mip_lod`).
pub fn lod_from_uv_derivatives(duv_dx: Vec2, duv_dy: Vec2, size: Vec2, bias: f32) -> f32 {
    (duv_dx * size).length().max((duv_dy * size).length()).log2() + bias
}

/// The angle one pixel subtends for a perspective camera of vertical field of view `fovy`
/// (radians) rendering `image_height` rows: `γ = atan(2·tan(fovy/2)/height)`.
pub fn pixel_spread_angle(fovy: f32, image_height: u32) -> f32 {
    (2.0 * (fovy / 2.0).tan() / image_height.max(1) as f32).atan()
}

/// A ray cone: the footprint of one pixel carried along a ray. Its width at distance `t` is
/// `width + t·spread` (small-angle: `2·tan(γ/2) ≈ γ`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCone {
    /// Width at the ray's origin (world units).
    pub width: f32,
    /// Spread angle (radians); negative for a cone that narrows (a focusing mirror).
    pub spread: f32,
}

impl RayCone {
    /// The cone of a perspective camera's primary ray: a point at the eye, spreading by
    /// [`pixel_spread_angle`].
    pub fn perspective(fovy: f32, image_height: u32) -> RayCone {
        RayCone { width: 0.0, spread: pixel_spread_angle(fovy, image_height) }
    }

    /// The cone of an orthographic camera's ray: one pixel wide everywhere.
    pub fn orthographic(pixel_width: f32) -> RayCone {
        RayCone { width: pixel_width, spread: 0.0 }
    }

    /// The cone's width at distance `t` along the ray.
    pub fn width_at(&self, t: f32) -> f32 {
        (self.width + t * self.spread).abs()
    }

    /// The width of the cone's footprint on a surface hit at distance `t`, with
    /// `cos_incidence = ray direction · normal` (unit vectors; either sign): the cross-section
    /// stretched by `1/|cos θ|`.
    pub fn footprint(&self, t: f32, cos_incidence: f32) -> f32 {
        self.width_at(t) / cos_incidence.abs().max(MIN_COS_INCIDENCE)
    }

    /// The cone continuing from a hit at distance `t` (a reflected or refracted ray): the same
    /// spread, starting as wide as it arrived.
    pub fn continued(&self, t: f32) -> RayCone {
        RayCone { width: self.width_at(t), spread: self.spread }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_three_rules_agree_on_a_frontal_surface() {
        // A 256-texel texture over a 2-unit-wide quad, 10 units away, one pixel = 1/500 rad.
        let (size, extent, distance) = (256u32, 2.0f32, 10.0f32);
        let cone = RayCone { width: 0.0, spread: 1.0 / 500.0 };
        let from_cone = lod_from_footprint(cone.footprint(distance, -1.0), extent, extent, (size, size), 0.0);
        // One pixel covers 0.02 units = 2.56 texels.
        assert!((from_cone - 2.56f32.log2()).abs() < 1e-5, "{from_cone}");
        let texel_distance = (extent / size as f32) / cone.spread;
        assert!((lod_from_distance(distance, texel_distance, 0.0) - from_cone).abs() < 1e-5);
        let duv = cone.width_at(distance) / extent;
        let from_derivatives =
            lod_from_uv_derivatives(Vec2::new(duv, 0.0), Vec2::new(0.0, duv), Vec2::splat(size as f32), 0.0);
        assert!((from_derivatives - from_cone).abs() < 1e-5);
    }

    #[test]
    fn slanted_and_stretched_footprints_pick_the_longer_side() {
        // Seen at 60° the footprint doubles: one level more.
        let cone = RayCone { width: 0.0, spread: 0.01 };
        let frontal = lod_from_footprint(cone.footprint(4.0, 1.0), 1.0, 1.0, (64, 64), 0.0);
        let slanted = lod_from_footprint(cone.footprint(4.0, 0.5), 1.0, 1.0, (64, 64), 0.0);
        assert!((slanted - frontal - 1.0).abs() < 1e-5);
        // A texture squeezed 4× along v reads the level of the v axis.
        let squeezed = lod_from_footprint(cone.footprint(4.0, 1.0), 1.0, 0.25, (64, 64), 0.5);
        assert!((squeezed - frontal - 2.5).abs() < 1e-5);
    }
}
