//! The output transform both renderers share: linear radiance × exposure, clamped to [0, 1],
//! encoded as sRGB 8-bit. The rasterizer runs it in `shaders/present.wgsl` (the clamp in the
//! shader, the encoding by the `Rgba8UnormSrgb` target); the ray tracer runs it here.
//! `tests/output_transform.rs` checks that both give the same bytes.

use glam::Vec3;

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 { 12.92 * linear } else { 1.055 * linear.powf(1.0 / 2.4) - 0.055 }
}

/// The inverse of [`srgb_encode`].
pub fn srgb_decode(encoded: f32) -> f32 {
    if encoded <= 0.040_45 { encoded / 12.92 } else { ((encoded + 0.055) / 1.055).powf(2.4) }
}

/// One pixel through the output transform. NaN maps to 0.
pub fn to_srgb8(radiance: Vec3, exposure: f32) -> [u8; 3] {
    (radiance * exposure).to_array().map(|c| {
        let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
        (srgb_encode(c) * 255.0).round() as u8
    })
}

/// A whole image of linear radiance, row-major from the top, to an RGBA8 image.
pub fn encode_image(width: u32, height: u32, radiance: &[Vec3], exposure: f32) -> image::RgbaImage {
    assert_eq!(radiance.len(), (width * height) as usize, "one radiance value per pixel");
    let bytes = radiance
        .iter()
        .flat_map(|&c| {
            let [r, g, b] = to_srgb8(c, exposure);
            [r, g, b, 255]
        })
        .collect();
    image::RgbaImage::from_raw(width, height, bytes).expect("the buffer holds width × height pixels")
}

/// Writes a PNG atomically: encoded in memory, written to a temporary file beside the target,
/// then renamed over it, so a failure never leaves a half-written image.
pub fn write_png_atomically(image: &image::RgbaImage, path: &std::path::Path) -> std::io::Result<()> {
    let mut encoded = Vec::new();
    image.write_to(&mut std::io::Cursor::new(&mut encoded), image::ImageFormat::Png).map_err(std::io::Error::other)?;
    write_atomically(&encoded, path)
}

/// Writes bytes to a temporary file beside `path`, then renames it into place.
pub fn write_atomically(bytes: &[u8], path: &std::path::Path) -> std::io::Result<()> {
    let file_name = path.file_name().ok_or_else(|| std::io::Error::other("the output path names no file"))?;
    let mut temporary_name = std::ffi::OsString::from(".");
    temporary_name.push(file_name);
    temporary_name.push(format!(".{}.tmp", std::process::id()));
    let temporary = path.with_file_name(temporary_name);
    let result = std::fs::write(&temporary, bytes).and_then(|()| std::fs::rename(&temporary, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips_and_hits_known_values() {
        assert_eq!(to_srgb8(Vec3::new(0.0, 1.0, 0.5), 1.0), [0, 255, 188]);
        assert_eq!(to_srgb8(Vec3::new(-1.0, 7.0, f32::NAN), 1.0), [0, 255, 0]);
        for i in 0..=255 {
            let encoded = i as f32 / 255.0;
            assert!((srgb_encode(srgb_decode(encoded)) - encoded).abs() < 1e-5);
        }
    }
}
