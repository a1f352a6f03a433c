//! Loading texture images from files (PNG, JPEG, HDR) into 8-bit RGBA with a known colour space.
//! Mip chains and filtering belong to the textures issue; this is only decoding, with errors that
//! name the file.

use std::path::Path;

use super::SceneError;
use super::material::{ColorSpace, Texture};
use crate::scene::camera::Camera;

/// Decodes an image file. Images larger than the largest GPU texture side are rejected with an
/// error naming the file (downscaling is the textures issue's).
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

/// Wraps an already decoded image (from a file, or embedded in a glTF).
pub fn from_image(path: &Path, image: image::DynamicImage, color_space: ColorSpace) -> Texture {
    let rgba = image.into_rgba8();
    Texture {
        path: path.to_path_buf(),
        width: rgba.width(),
        height: rgba.height(),
        rgba8: rgba.into_raw(),
        color_space,
    }
}

/// A texture must have pixels and fit in one GPU texture.
pub fn check_size(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("the image is empty ({width}×{height})"));
    }
    if width > Camera::MAX_SIDE || height > Camera::MAX_SIDE {
        return Err(format!(
            "the image is {width}×{height}, larger than the largest texture ({0}×{0})",
            Camera::MAX_SIDE
        ));
    }
    Ok(())
}
