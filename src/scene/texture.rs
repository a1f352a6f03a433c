//! Loading texture images from files (PNG, JPEG, HDR) into 8-bit RGBA with a known colour space,
//! with errors that name the file. Any pixel format the `image` crate reads (16-bit, grey, grey
//! with alpha, floating point) is converted to RGBA8. An image wider or taller than the largest
//! GPU texture (16384) is downscaled to fit, with a warning; one over 32768 on a side is refused
//! before it is decoded (4 GiB of texels or more).

use std::path::Path;

use super::SceneError;
use super::material::{ColorSpace, Texture};
use crate::scene::camera::Camera;

/// Decodes an image file.
pub fn load(path: &Path, color_space: ColorSpace) -> Result<Texture, SceneError> {
    let error = |message: String| SceneError::Texture { path: path.to_path_buf(), message };
    let reader = image::ImageReader::open(path)
        .map_err(|e| error(format!("cannot open: {e}")))?
        .with_guessed_format()
        .map_err(|e| error(format!("cannot read: {e}")))?;
    let (width, height) = reader.into_dimensions().map_err(|e| error(format!("cannot decode: {e}")))?;
    check_size(width, height).map_err(error)?;
    let decoded = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| error(format!("cannot read: {e}")))?
        .decode()
        .map_err(|e| error(format!("cannot decode: {e}")))?;
    Ok(from_image(path, decoded, color_space))
}

/// Wraps an already decoded image (from a file, or embedded in a glTF), downscaled to fit the
/// largest texture if it must be.
pub fn from_image(path: &Path, image: image::DynamicImage, color_space: ColorSpace) -> Texture {
    let mut rgba = image.into_rgba8();
    let (width, height) = rgba.dimensions();
    if let Some((w, h)) = fitted_size(width, height) {
        log::warn!(
            "{}: the image is {width}×{height}, larger than the largest texture; downscaled to {w}×{h}",
            path.display()
        );
        rgba = image::imageops::resize(&rgba, w, h, image::imageops::FilterType::Triangle);
    }
    Texture {
        path: path.to_path_buf(),
        width: rgba.width(),
        height: rgba.height(),
        rgba8: rgba.into_raw(),
        color_space,
    }
}

/// The size an image of `width × height` is downscaled to so that it fits the largest texture
/// (its aspect kept), or `None` when it fits already.
pub fn fitted_size(width: u32, height: u32) -> Option<(u32, u32)> {
    let largest = width.max(height);
    if largest <= Camera::MAX_SIDE {
        return None;
    }
    let scale = Camera::MAX_SIDE as f64 / largest as f64;
    let fit = |side: u32| ((side as f64 * scale).round() as u32).clamp(1, Camera::MAX_SIDE);
    Some((fit(width), fit(height)))
}

/// The largest image side decoded at all: twice the largest texture (then downscaled).
pub const MAX_DECODED_SIDE: u32 = 2 * Camera::MAX_SIDE;

/// A texture must have pixels, and be small enough to decode before it is downscaled.
pub fn check_size(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("the image is empty ({width}×{height})"));
    }
    if width > MAX_DECODED_SIDE || height > MAX_DECODED_SIDE {
        return Err(format!(
            "the image is {width}×{height}; images up to {MAX_DECODED_SIDE} on a side are read (and \
             downscaled to the largest texture, {0}×{0})",
            Camera::MAX_SIDE
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_wider_than_the_largest_texture_are_downscaled_to_fit() {
        let wide = image::DynamicImage::ImageLumaA16(image::ImageBuffer::from_pixel(
            16400,
            3,
            image::LumaA([65535u16, 65535]),
        ));
        let texture = from_image(Path::new("wide.png"), wide, ColorSpace::Linear);
        assert_eq!((texture.width, texture.height), (16384, 3));
        assert!(texture.rgba8.iter().all(|&b| b == 255), "16-bit grey with alpha becomes white RGBA8");
        assert!(check_size(40000, 2).is_err());
        assert!(check_size(0, 2).is_err());
        assert!(check_size(20000, 2).is_ok());
    }
}
