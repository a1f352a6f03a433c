//! Loading texture images from files (PNG, JPEG, HDR) into 8-bit RGBA with a known colour space,
//! with errors that name the file. Any pixel format the `image` crate reads (16-bit, grey, grey
//! with alpha, floating point) is converted to RGBA8.
//!
//! # Size and memory
//!
//! An image wider or taller than the largest GPU texture (16384) is downscaled to fit, with a
//! warning; one over [`MAX_DECODED_SIDE`] (32768) on a side is refused by its header, before any
//! pixel is decoded. The decoder may allocate at most [`MAX_DECODED_BYTES`] for the decoded image:
//! 32768² pixels × 8 bytes = 8 GiB, every PNG and JPEG pixel format at the full 32768² (8-bit RGBA
//! takes 4 GiB, 16-bit RGBA 8 GiB) and a 32768 × 16384 lat–long `.hdr` (32-bit float RGB, 6 GiB);
//! a larger float image (a 32768² `.hdr` would take 12 GiB) is refused by name. These are the
//! `image` crate's [`image::Limits`] ([`decode_limits`]), set on every decoder Mirador opens
//! (textures, glTF images, environment maps); without them the crate stops at 512 MiB, a
//! 11585² RGBA8 image.
//!
//! The downscale ([`downscaled`]) is a separable tent filter (the `image` crate's `Triangle`),
//! computed band by band in the decoded pixel format, so loading the largest image holds the
//! decoded image and the downscaled one at once and nothing else of that size: at most 8 GiB +
//! 2 GiB (16-bit RGBA), or 4 GiB + 1 GiB for 8-bit RGBA. (`image::imageops::resize` keeps a
//! 32-bit float RGBA copy of the source's full width, which for a 32768² image is 8 GiB more.)

use std::io::{BufRead, Seek};
use std::path::Path;

use image::{DynamicImage, ImageBuffer, ImageDecoder, ImageReader, Pixel};
use rayon::prelude::*;

use super::SceneError;
use super::material::{ColorSpace, Texture};
use crate::scene::camera::Camera;

/// Decodes an image file.
pub fn load(path: &Path, color_space: ColorSpace) -> Result<Texture, SceneError> {
    let error = |message: String| SceneError::Texture { path: path.to_path_buf(), message };
    super::check_regular_file(path).map_err(|e| error(format!("cannot open: {e}")))?;
    let reader = crate::files::image_reader(path).map_err(|e| error(format!("cannot read: {e}")))?;
    Ok(from_image(path, decode(reader).map_err(error)?, color_space))
}

/// Wraps an already decoded image (from a file, or embedded in a glTF), downscaled to fit the
/// largest texture if it must be.
pub fn from_image(path: &Path, image: DynamicImage, color_space: ColorSpace) -> Texture {
    let (width, height) = (image.width(), image.height());
    let image = match fitted_size(width, height) {
        Some((w, h)) => {
            log::warn!(
                "{}: the image is {width}×{height}, larger than the largest texture; downscaled to {w}×{h}",
                path.display()
            );
            downscaled(image, w, h)
        }
        None => image,
    };
    let rgba = image.into_rgba8();
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

/// The most the decoder may allocate for one image: [`MAX_DECODED_SIDE`]² pixels of 8 bytes
/// (16-bit RGBA, the widest PNG pixel), 8 GiB.
pub const MAX_DECODED_BYTES: u64 = MAX_DECODED_SIDE as u64 * MAX_DECODED_SIDE as u64 * 8;

/// The `image` crate's decoding limits for Mirador's images: the documented sides, and
/// [`MAX_DECODED_BYTES`] instead of the crate's default of 512 MiB.
pub fn decode_limits() -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_DECODED_SIDE);
    limits.max_image_height = Some(MAX_DECODED_SIDE);
    limits.max_alloc = Some(MAX_DECODED_BYTES);
    limits
}

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

/// Decodes an image under Mirador's limits ([`decode_limits`]); `reader`'s format must be known
/// (set or guessed). The size and the decoded bytes are checked from the header first, so an
/// image over either limit is refused by its size, with the limit in the message, before any
/// pixel is decoded.
pub fn decode<R: BufRead + Seek>(mut reader: ImageReader<R>) -> Result<DynamicImage, String> {
    // The sides are left to `check_size` here, whose message names them; the allocation limit is
    // given now because the PNG decoder takes its own limit when it is made.
    let mut open_limits = decode_limits();
    (open_limits.max_image_width, open_limits.max_image_height) = (None, None);
    reader.limits(open_limits);
    let mut decoder = reader.into_decoder().map_err(|e| format!("cannot decode: {e}"))?;
    let (width, height) = decoder.dimensions();
    check_size(width, height)?;
    let bytes = decoder.total_bytes();
    if bytes > MAX_DECODED_BYTES {
        return Err(format!(
            "the image is {width}×{height} {:?}, {:.1} GiB decoded; Mirador decodes at most {} GiB for one image \
             ({MAX_DECODED_SIDE}² pixels of 16-bit RGBA)",
            decoder.color_type(),
            bytes as f64 / GIB,
            MAX_DECODED_BYTES as f64 / GIB
        ));
    }
    // As `ImageReader::decode` does: the output buffer counts against the allocation limit.
    let mut limits = decode_limits();
    limits.reserve(bytes).map_err(|e| format!("cannot decode: {e}"))?;
    decoder.set_limits(limits).map_err(|e| format!("cannot decode: {e}"))?;
    DynamicImage::from_decoder(decoder).map_err(|e| format!("cannot decode: {e}"))
}

const GIB: f64 = (1u64 << 30) as f64;

/// `image` resized to `width × height` by a tent filter (the `image` crate's `Triangle`: weights
/// falling linearly to zero one source texel, or one output texel's footprint when shrinking,
/// from the sample's centre), in its own pixel format. Made for shrinking very large images: it
/// works through bands of output rows and never holds more than a band's worth beside the source
/// and the result.
pub fn downscaled(image: DynamicImage, width: u32, height: u32) -> DynamicImage {
    use DynamicImage as D;
    match image {
        D::ImageLuma8(i) => D::ImageLuma8(resample(&i, width, height)),
        D::ImageLumaA8(i) => D::ImageLumaA8(resample(&i, width, height)),
        D::ImageRgb8(i) => D::ImageRgb8(resample(&i, width, height)),
        D::ImageRgba8(i) => D::ImageRgba8(resample(&i, width, height)),
        D::ImageLuma16(i) => D::ImageLuma16(resample(&i, width, height)),
        D::ImageLumaA16(i) => D::ImageLumaA16(resample(&i, width, height)),
        D::ImageRgb16(i) => D::ImageRgb16(resample(&i, width, height)),
        D::ImageRgba16(i) => D::ImageRgba16(resample(&i, width, height)),
        D::ImageRgb32F(i) => D::ImageRgb32F(resample(&i, width, height)),
        D::ImageRgba32F(i) => D::ImageRgba32F(resample(&i, width, height)),
        other => other.resize_exact(width, height, image::imageops::FilterType::Triangle),
    }
}

/// A channel value [`resample`] can filter in `f32` and store back.
trait Sample: Copy + Send + Sync {
    fn to_f32(self) -> f32;
    fn from_f32(value: f32) -> Self;
}

impl Sample for u8 {
    fn to_f32(self) -> f32 {
        f32::from(self)
    }
    fn from_f32(value: f32) -> Self {
        value.round().clamp(0.0, 255.0) as u8
    }
}

impl Sample for u16 {
    fn to_f32(self) -> f32 {
        f32::from(self)
    }
    fn from_f32(value: f32) -> Self {
        value.round().clamp(0.0, 65535.0) as u16
    }
}

impl Sample for f32 {
    fn to_f32(self) -> f32 {
        self
    }
    fn from_f32(value: f32) -> Self {
        value
    }
}

/// The source texels one output texel reads along an axis, from `first` on, with their
/// weights (summing to 1).
struct Taps {
    first: usize,
    weights: Vec<f32>,
}

/// The tent filter's taps for each of `to` samples over `from` texels.
fn taps(from: u32, to: u32) -> Vec<Taps> {
    let ratio = f64::from(from) / f64::from(to);
    let support = ratio.max(1.0);
    (0..to)
        .map(|o| {
            let centre = (f64::from(o) + 0.5) * ratio;
            let first = (centre - support).floor().max(0.0) as usize;
            let end = ((centre + support).ceil() as usize).min(from as usize);
            let mut weights: Vec<f32> =
                (first..end).map(|i| (1.0 - ((i as f64 + 0.5 - centre) / support).abs()).max(0.0) as f32).collect();
            // The nearest texel's centre is at most half a texel from `centre`, so the sum is > 0.
            let sum: f32 = weights.iter().sum();
            weights.iter_mut().for_each(|w| *w /= sum);
            Taps { first, weights }
        })
        .collect()
}

/// Output rows filtered together: their source rows are filtered horizontally once per band.
const BAND_ROWS: usize = 32;

/// Separable tent resampling of `source` to `width × height`, band by band in parallel.
fn resample<P>(source: &ImageBuffer<P, Vec<P::Subpixel>>, width: u32, height: u32) -> ImageBuffer<P, Vec<P::Subpixel>>
where
    P: Pixel,
    P::Subpixel: Sample,
{
    let texels = match P::CHANNEL_COUNT {
        1 => resample_texels::<1, _>(source.as_raw(), source.dimensions(), (width, height)),
        2 => resample_texels::<2, _>(source.as_raw(), source.dimensions(), (width, height)),
        3 => resample_texels::<3, _>(source.as_raw(), source.dimensions(), (width, height)),
        4 => resample_texels::<4, _>(source.as_raw(), source.dimensions(), (width, height)),
        n => unreachable!("image pixels have 1 to 4 channels, not {n}"),
    };
    ImageBuffer::from_raw(width, height, texels).expect("the buffer holds width × height pixels")
}

/// [`resample`] on raw texels of `N` channels. Each band of output rows filters its source rows
/// across once (in `f32`), then down; the channel count is a constant so that the inner loops
/// are plain arrays.
fn resample_texels<const N: usize, S: Sample>(texels: &[S], from: (u32, u32), to: (u32, u32)) -> Vec<S> {
    let (columns, rows) = (taps(from.0, to.0), taps(from.1, to.1));
    let source_row = from.0 as usize * N;
    let out_row = to.0 as usize * N;
    let mut out = vec![S::from_f32(0.0); out_row * to.1 as usize];
    out.par_chunks_mut(out_row * BAND_ROWS).zip(rows.par_chunks(BAND_ROWS)).for_each(|(band, band_rows)| {
        let first = band_rows[0].first;
        let end = band_rows.iter().map(|t| t.first + t.weights.len()).max().expect("a band has rows");
        // The band's source rows, filtered across.
        let mut across = vec![0.0f32; (end - first) * out_row];
        let mut line = vec![0.0f32; source_row];
        for (y, filtered) in (first..end).zip(across.chunks_exact_mut(out_row)) {
            line.iter_mut().zip(&texels[y * source_row..(y + 1) * source_row]).for_each(|(l, &t)| *l = t.to_f32());
            for (tap, texel) in columns.iter().zip(filtered.chunks_exact_mut(N)) {
                let reach = &line[tap.first * N..(tap.first + tap.weights.len()) * N];
                let mut sum = [0.0f32; N];
                for (&w, source) in tap.weights.iter().zip(reach.chunks_exact(N)) {
                    for c in 0..N {
                        sum[c] += w * source[c];
                    }
                }
                texel.copy_from_slice(&sum);
            }
        }
        // Then down.
        let mut sum = vec![0.0f32; out_row];
        for (tap, out_line) in band_rows.iter().zip(band.chunks_exact_mut(out_row)) {
            sum.fill(0.0);
            for (i, &w) in tap.weights.iter().enumerate() {
                let filtered = &across[(tap.first + i - first) * out_row..][..out_row];
                sum.iter_mut().zip(filtered).for_each(|(s, &f)| *s += w * f);
            }
            out_line.iter_mut().zip(&sum).for_each(|(o, &s)| *o = S::from_f32(s));
        }
    });
    out
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

    #[test]
    fn the_band_downscale_agrees_with_the_image_crates_triangle_filter() {
        // An uneven pattern and uneven ratios (2.0 and 1.37), in 8-bit RGB and float.
        let source = image::RgbImage::from_fn(97, 61, |x, y| {
            image::Rgb([(x * 37 + y * 11) as u8, (x * x + 3 * y) as u8, ((x ^ y) * 5) as u8])
        });
        let ours = downscaled(DynamicImage::ImageRgb8(source.clone()), 71, 30).into_rgb8();
        let theirs = image::imageops::resize(&source, 71, 30, image::imageops::FilterType::Triangle);
        let worst = ours.as_raw().iter().zip(theirs.as_raw()).map(|(&a, &b)| a.abs_diff(b)).max().unwrap();
        assert!(worst <= 1, "8-bit results differ by at most rounding, got {worst}");

        let float = DynamicImage::ImageRgb8(source).into_rgb32f();
        let ours = downscaled(DynamicImage::ImageRgb32F(float.clone()), 71, 30).into_rgb32f();
        let theirs = image::imageops::resize(&float, 71, 30, image::imageops::FilterType::Triangle);
        let worst = ours.as_raw().iter().zip(theirs.as_raw()).map(|(&a, &b)| (a - b).abs()).fold(0.0, f32::max);
        assert!(worst < 1e-5, "float results agree, got {worst}");
    }

    #[test]
    fn a_tent_of_ratio_two_weighs_three_texels_by_hand() {
        // Output texel 0 of 4 → 2 is centred on source 1.0 with support 2: texels 0, 1, 2 at
        // distances 0.5, 0.5, 1.5 weigh 0.75, 0.75, 0.25, normalized by 1.75.
        let taps = taps(4, 2);
        assert_eq!(taps[0].first, 0);
        let expected = [0.75 / 1.75, 0.75 / 1.75, 0.25 / 1.75];
        assert!(taps[0].weights.iter().zip(expected).all(|(w, e)| (w - e).abs() < 1e-6), "{:?}", taps[0].weights);
        let line = image::GrayImage::from_raw(4, 1, vec![0, 70, 140, 210]).unwrap();
        let out = downscaled(DynamicImage::ImageLuma8(line), 2, 1).into_luma8();
        // (0·0.75 + 70·0.75 + 140·0.25)/1.75 = 50; (70·0.25 + 140·0.75 + 210·0.75)/1.75 = 160.
        assert_eq!(out.as_raw(), &[50, 160]);
    }
}
