//! Texture lookups for the ray tracer, matching the rasterizer's sampler so the two images agree:
//! bilinear filtering with repeat wrapping, texel centres at `(i + ½)/width`, and sRGB colour
//! textures decoded to linear before filtering (as an `Rgba8UnormSrgb` texture is).

use glam::{Vec2, Vec3};

use crate::output::srgb_decode;
use crate::scene::{ColorSpace, Texture};

/// The linear RGB value of `texture` at `uv`, bilinearly filtered with repeat wrapping.
pub fn sample_bilinear(texture: &Texture, uv: Vec2) -> Vec3 {
    let (w, h) = (texture.width as i64, texture.height as i64);
    let x = uv.x * w as f32 - 0.5;
    let y = uv.y * h as f32 - 0.5;
    if !(x.is_finite() && y.is_finite()) {
        return Vec3::ZERO;
    }
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let texel = |i: i64, j: i64| -> Vec3 {
        let (i, j) = (i.rem_euclid(w) as usize, j.rem_euclid(h) as usize);
        let at = 4 * (j * texture.width as usize + i);
        let rgb =
            Vec3::new(texture.rgba8[at] as f32, texture.rgba8[at + 1] as f32, texture.rgba8[at + 2] as f32) / 255.0;
        match texture.color_space {
            ColorSpace::Srgb => Vec3::new(srgb_decode(rgb.x), srgb_decode(rgb.y), srgb_decode(rgb.z)),
            ColorSpace::Linear => rgb,
        }
    };
    let (i, j) = (x0 as i64, y0 as i64);
    let top = texel(i, j).lerp(texel(i + 1, j), fx);
    let bottom = texel(i, j + 1).lerp(texel(i + 1, j + 1), fx);
    top.lerp(bottom, fy)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(rgba8: Vec<u8>, width: u32, color_space: ColorSpace) -> Texture {
        let height = rgba8.len() as u32 / 4 / width;
        Texture { path: "test".into(), width, height, rgba8, color_space }
    }

    #[test]
    fn texel_centres_return_texels_and_midpoints_blend_linear_values() {
        let t = texture(vec![0, 0, 0, 255, 255, 255, 255, 255], 2, ColorSpace::Srgb);
        assert_eq!(sample_bilinear(&t, Vec2::new(0.25, 0.5)), Vec3::ZERO);
        assert!(sample_bilinear(&t, Vec2::new(0.75, 0.5)).abs_diff_eq(Vec3::ONE, 1e-6));
        // Halfway between black and white is linear 0.5 (not sRGB 0.5, which is linear 0.214).
        assert!(sample_bilinear(&t, Vec2::new(0.5, 0.5)).abs_diff_eq(Vec3::splat(0.5), 1e-6));
        // Repeat wrapping: u = 1.0 sits between the last texel and the first.
        assert!(sample_bilinear(&t, Vec2::new(1.0, 0.5)).abs_diff_eq(Vec3::splat(0.5), 1e-6));
        assert!(sample_bilinear(&t, Vec2::new(-0.25, 0.5)).abs_diff_eq(Vec3::ONE, 1e-6));
    }
}
