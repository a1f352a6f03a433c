//! Linear output: the radiance a renderer computed, before the output transform of
//! [`crate::output`] (no exposure, no tone curve, no sRGB encoding), written as an OpenEXR
//! file (`render`, `trace` and `compare` with `--exr FILE`).
//!
//! A PNG holds what the output transform made of the radiance: `encode(tone_map(L · exposure))`,
//! 8 bits a channel, everything above 1 lost. The EXR holds `L` itself, so an image can be
//! re-exposed, tone mapped or measured afterwards (the sun's disc, a highlight's peak), and two
//! renderers can be compared in radiance rather than in display values.
//!
//! The file is one layer of 32-bit float R, G, B (no alpha), rows from the top, ZIP-compressed
//! (lossless). The ray tracer's radiance is stored exactly; the rasterizer's comes from its
//! `Rgba16Float` target (`raster::HDR_FORMAT`), so it carries half-float precision (11
//! significant bits, largest value 65504), stored exactly in the 32-bit file. Values are written
//! as the renderer made them: a NaN or an infinity stays one.
//!
//! Like every output, the file is encoded in memory and written through a temporary file that
//! is renamed into place ([`crate::output::write_atomically`]), so a failed run never leaves half
//! a file.

use std::path::Path;

use exr::prelude::traits::*;
use exr::prelude::{Encoding, Image, Layer, LayerAttributes, SpecificChannels};
use glam::Vec3;

/// An image of linear RGB radiance, row-major from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

/// Why an EXR could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum ExrError {
    #[error("OpenEXR: {0}")]
    Exr(#[from] exr::error::Error),
    #[error(transparent)]
    Io(#[from] std::io::Error),
    #[error("the image has {pixels} pixels, not {width}×{height}")]
    Size { width: u32, height: u32, pixels: usize },
}

impl LinearImage {
    /// Checks that `pixels` holds one value per pixel.
    pub fn new(width: u32, height: u32, pixels: Vec<Vec3>) -> Result<LinearImage, ExrError> {
        if pixels.len() != width as usize * height as usize {
            return Err(ExrError::Size { width, height, pixels: pixels.len() });
        }
        Ok(LinearImage { width, height, pixels })
    }

    /// `left` and `right` side by side, `left` first, each at its own size, the shorter padded
    /// with black at the bottom.
    pub fn side_by_side(left: &LinearImage, right: &LinearImage) -> LinearImage {
        let (width, height) = (left.width + right.width, left.height.max(right.height));
        let texel = |image: &LinearImage, x: u32, y: u32| {
            if y < image.height { image.pixels[(y * image.width + x) as usize] } else { Vec3::ZERO }
        };
        let pixels = (0..height)
            .flat_map(|y| {
                (0..width).map(
                    move |x| {
                        if x < left.width { texel(left, x, y) } else { texel(right, x - left.width, y) }
                    },
                )
            })
            .collect();
        LinearImage { width, height, pixels }
    }

    /// The OpenEXR file's bytes.
    pub fn encode_exr(&self) -> Result<Vec<u8>, ExrError> {
        let width = self.width as usize;
        let channels = SpecificChannels::rgb(|at: exr::math::Vec2<usize>| {
            let c = self.pixels[at.y() * width + at.x()];
            (c.x, c.y, c.z)
        });
        let layer =
            Layer::new((width, self.height as usize), LayerAttributes::default(), Encoding::SMALL_LOSSLESS, channels);
        let mut bytes = std::io::Cursor::new(Vec::new());
        Image::from_layer(layer).write().to_buffered(&mut bytes)?;
        Ok(bytes.into_inner())
    }

    /// Writes the OpenEXR file atomically: a failure leaves no file, or the previous one.
    pub fn write_exr_atomically(&self, path: &Path) -> Result<(), ExrError> {
        let bytes = self.encode_exr()?;
        crate::output::write_atomically(&bytes, path)?;
        Ok(())
    }

    /// Reads the first layer's R, G and B of an OpenEXR file as 32-bit floats (for tests and
    /// tools; Mirador's scenes do not read EXR).
    pub fn read_exr(path: &Path) -> Result<LinearImage, ExrError> {
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .rgb_channels(
                |size, _| LinearImage {
                    width: size.width() as u32,
                    height: size.height() as u32,
                    pixels: vec![Vec3::ZERO; size.area()],
                },
                |image: &mut LinearImage, at, (r, g, b): (f32, f32, f32)| {
                    let width = image.width as usize;
                    image.pixels[at.y() * width + at.x()] = Vec3::new(r, g, b);
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_file(path)?;
        Ok(image.layer_data.channel_data.pixels)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radiance_survives_the_file_exactly() {
        let pixels = vec![
            Vec3::new(0.0, 0.5, 1.0),
            Vec3::new(12.25, 1e-6, 65504.0),
            Vec3::new(3.0e5, 0.1, 0.2),
            Vec3::new(1.0 / 3.0, 2.0 / 3.0, 7.0),
            Vec3::ZERO,
            Vec3::ONE,
        ];
        let image = LinearImage::new(3, 2, pixels).unwrap();
        let path = std::env::temp_dir().join(format!("mirador-linear-{}.exr", std::process::id()));
        image.write_exr_atomically(&path).unwrap();
        let read = LinearImage::read_exr(&path);
        std::fs::remove_file(&path).unwrap();
        assert_eq!(read.unwrap(), image, "32-bit floats are stored exactly");
    }

    #[test]
    fn side_by_side_puts_the_left_image_first_and_pads_the_shorter() {
        let left = LinearImage::new(1, 2, vec![Vec3::X, Vec3::Y]).unwrap();
        let right = LinearImage::new(2, 1, vec![Vec3::Z, Vec3::ONE]).unwrap();
        let both = LinearImage::side_by_side(&left, &right);
        assert_eq!((both.width, both.height), (3, 2));
        assert_eq!(both.pixels, [Vec3::X, Vec3::Z, Vec3::ONE, Vec3::Y, Vec3::ZERO, Vec3::ZERO]);
        assert!(LinearImage::new(2, 2, vec![Vec3::ZERO]).is_err());
    }
}
