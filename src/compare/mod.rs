//! Image metrics: FLIP (NVIDIA's perceptual difference, the metric wgpu's own image tests use),
//! PSNR, and a false-colour error map. Used by the golden-image tests and, with the ray tracer,
//! by `mirador compare`, the viewer's difference view and the page's.
//!
//! FLIP is `flip-rs`, a Rust port of NVIDIA's version 1.7, at NVIDIA's C++ tool's viewing
//! distance ([`PIXELS_PER_DEGREE`]): on Mirador's own images its error maps are NVIDIA's, bit for
//! bit (tests/flip_parity.rs).

#[cfg(not(target_arch = "wasm32"))]
pub mod sheet;

/// The metric [`Difference::flip_mean`] and the error map hold, as the viewer labels it.
pub const METRIC: &str = "FLIP";

/// The viewing distance FLIP assumes, in pixels per degree of visual angle: the value of
/// NVIDIA's C++ tool (67, a 0.7 m wide 4K monitor seen from 0.7 m, rounded), which Mirador's
/// thresholds were measured with.
pub const PIXELS_PER_DEGREE: f32 = 67.0;

use image::RgbaImage;

/// How two images of the same size differ.
pub struct Difference {
    /// Mean FLIP error over all pixels, in [0, 1]; 0 means identical.
    pub flip_mean: f32,
    /// The FLIP error of each pixel, rows from the top: for statistics the mean dilutes, such as
    /// the worst region of the golden-image tests.
    pub flip_errors: Vec<f32>,
    /// Peak signal-to-noise ratio of the 8-bit RGB values, in dB (infinite when identical).
    pub psnr_db: f64,
    /// The per-pixel FLIP error through the magma colour map (black: no error; yellow: large).
    pub error_map: RgbaImage,
}

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error)]
#[error("cannot compare a {0}×{1} image with a {2}×{3} one")]
pub struct SizeMismatch(pub u32, pub u32, pub u32, pub u32);

fn rgb_bytes(image: &RgbaImage) -> Vec<u8> {
    image.pixels().flat_map(|p| [p[0], p[1], p[2]]).collect()
}

/// Compares `test` against `reference` (alpha is ignored).
pub fn difference(reference: &RgbaImage, test: &RgbaImage) -> Result<Difference, SizeMismatch> {
    difference_beyond(reference, test, 0)
}

/// Compares `test` against `reference` as [`difference`] does, except that FLIP sees every pixel
/// whose three channels all lie within `levels` (of 255) of the reference's as equal to it; the
/// PSNR is still that of the images as they are.
///
/// Why: the same renderer on two CPUs differs by rounding. Lavapipe's generated code and libm's
/// functions round the last bit differently from one CPU generation to the next, and where a
/// flat area's true value lies near a rounding boundary every one of its pixels moves by one
/// level: one level in red over a 40 % floor costs a mean FLIP of 0.013, more than a golden
/// image's threshold, though nobody can see it. Any change worth a test is larger than a couple
/// of levels somewhere; tests compare beyond `levels` and keep their thresholds two-sided
/// (`tests/README.md`).
pub fn difference_beyond(reference: &RgbaImage, test: &RgbaImage, levels: u8) -> Result<Difference, SizeMismatch> {
    let (w, h) = reference.dimensions();
    if test.dimensions() != (w, h) {
        return Err(SizeMismatch(w, h, test.width(), test.height()));
    }
    let a = rgb_bytes(reference);
    let b = rgb_bytes(test);
    let seen: Vec<u8> = a
        .chunks_exact(3)
        .zip(b.chunks_exact(3))
        .flat_map(|(r, t)| {
            let within = r.iter().zip(t).all(|(&r, &t)| r.abs_diff(t) <= levels);
            if within { [r[0], r[1], r[2]] } else { [t[0], t[1], t[2]] }
        })
        .collect();
    let (flip_errors, flip_mean, colored) = per_pixel_error(w, h, &a, &seen);
    let error_map = RgbaImage::from_raw(w, h, colored.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 255]).collect())
        .expect("the error map has one RGB triple per pixel");
    Ok(Difference { flip_mean, flip_errors, psnr_db: psnr(&a, &b), error_map })
}

/// The FLIP error of each pixel of `test` against `reference` (RGB bytes), their mean, and the
/// errors through the magma colour map.
fn per_pixel_error(w: u32, h: u32, reference: &[u8], test: &[u8]) -> (Vec<f32>, f32, Vec<u8>) {
    let image = |bytes: &[u8]| {
        flip_rs::RgbImage::new(w as usize, h as usize, bytes.to_vec()).expect("w × h RGB triples, w, h > 0")
    };
    let error = flip_rs::ldr_flip(&image(reference), &image(test), PIXELS_PER_DEGREE)
        .expect("images of one size, finite bytes, a valid viewing distance");
    // The pooled mean, as NVIDIA's tool pools it.
    let mean = error.statistics().mean;
    let errors = error.into_pixels();
    let colored = errors.iter().flat_map(|&e| magma(e)).collect();
    (errors, mean, colored)
}

/// The magma colour of an error in [0, 1], as 8-bit sRGB: black, through purple and orange, to
/// light yellow.
pub fn magma(error: f32) -> [u8; 3] {
    flip_rs::MAGMA[(error.clamp(0.0, 1.0) * 255.0 + 0.5) as usize].map(|c| (c * 255.0 + 0.5) as u8)
}

/// The side, in pixels, of the square regions whose mean error [`Figures::worst_region`] takes.
pub const REGION: u32 = 32;

/// The figures a grader reads from a per-pixel error map: the whole image's mean dilutes a local
/// error (a wrong 40×40 patch is 0.7 % of a 640×360 image), the worst region's does not.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Figures {
    /// The mean over every pixel.
    pub mean: f32,
    /// The largest mean over any [`REGION`]×[`REGION`] square (clamped to the image).
    pub worst_region: f32,
    /// The top-left corner of that square.
    pub worst_region_at: [u32; 2],
    /// The mean over the pixels a mask keeps, when one was given (`None` also when it keeps none).
    pub masked_mean: Option<f32>,
}

impl Figures {
    /// The figures of `errors` (one per pixel, rows from the top); `mask` keeps the pixels where
    /// it is true. A NaN error makes every figure NaN.
    pub fn of(errors: &[f32], width: u32, height: u32, mask: Option<&[bool]>) -> Figures {
        assert_eq!(errors.len(), (width * height) as usize, "one error per pixel");
        let mean = (errors.iter().map(|&e| f64::from(e)).sum::<f64>() / errors.len().max(1) as f64) as f32;
        let (worst_region, worst_region_at) = worst_region(errors, width, height, REGION);
        let masked_mean = mask.and_then(|mask| {
            let kept: Vec<f64> =
                errors.iter().zip(mask).filter(|(_, keep)| **keep).map(|(&e, _)| f64::from(e)).collect();
            (!kept.is_empty()).then(|| (kept.iter().sum::<f64>() / kept.len() as f64) as f32)
        });
        Figures { mean, worst_region, worst_region_at, masked_mean }
    }
}

/// The largest mean of `errors` over any `side`×`side` square (clamped to the image) and its
/// top-left corner, from a summed-area table; NaN when any error is NaN, which `f64::max` would
/// otherwise skip.
pub fn worst_region(errors: &[f32], width: u32, height: u32, side: u32) -> (f32, [u32; 2]) {
    if errors.iter().any(|e| e.is_nan()) {
        return (f32::NAN, [0, 0]);
    }
    let (w, h) = (width as usize, height as usize);
    let (sw, sh) = (side.min(width) as usize, side.min(height) as usize);
    // table[y][x] holds the sum of errors above and left of pixel (x, y).
    let mut table = vec![0.0f64; (w + 1) * (h + 1)];
    for y in 0..h {
        let mut row = 0.0;
        for x in 0..w {
            row += f64::from(errors[y * w + x]);
            table[(y + 1) * (w + 1) + x + 1] = table[y * (w + 1) + x + 1] + row;
        }
    }
    let at = |x: usize, y: usize| table[y * (w + 1) + x];
    let (mut worst, mut corner) = (0.0f64, [0, 0]);
    for y in 0..=h.saturating_sub(sh) {
        for x in 0..=w.saturating_sub(sw) {
            let sum = at(x + sw, y + sh) - at(x, y + sh) - at(x + sw, y) + at(x, y);
            if sum > worst {
                (worst, corner) = (sum, [x as u32, y as u32]);
            }
        }
    }
    ((worst / (sw * sh).max(1) as f64) as f32, corner)
}

/// PSNR of two equally long byte buffers with peak 255.
pub fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let squared: f64 = a.iter().zip(b).map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2)).sum();
    let mse = squared / a.len().max(1) as f64;
    if mse == 0.0 { f64::INFINITY } else { 10.0 * (255.0f64 * 255.0 / mse).log10() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_no_error_and_different_ones_do() {
        let a = RgbaImage::from_fn(32, 32, |x, y| image::Rgba([(x * 8) as u8, (y * 8) as u8, 128, 255]));
        let same = difference(&a, &a).unwrap();
        assert_eq!(same.flip_mean, 0.0);
        assert!(same.psnr_db.is_infinite());
        let mut b = a.clone();
        for p in b.pixels_mut().take(512) {
            p[0] = 255 - p[0];
        }
        let diff = difference(&a, &b).unwrap();
        assert!(diff.flip_mean > 0.05, "flip mean {}", diff.flip_mean);
        assert!(diff.psnr_db < 20.0, "psnr {}", diff.psnr_db);
        assert!(difference(&a, &RgbaImage::new(2, 2)).is_err());
    }

    #[test]
    fn differences_within_the_levels_are_not_seen_and_larger_ones_are() {
        let flat = RgbaImage::from_pixel(64, 64, image::Rgba([120, 90, 60, 255]));
        let mut one_level = flat.clone();
        for p in one_level.pixels_mut() {
            p[0] -= 1;
        }
        assert!(difference(&flat, &one_level).unwrap().flip_mean > 0.0, "FLIP alone sees one level");
        let beyond = difference_beyond(&flat, &one_level, 1).unwrap();
        assert_eq!(beyond.flip_mean, 0.0);
        assert!(beyond.psnr_db.is_finite(), "the PSNR is of the images as they are");
        let mut three_levels = flat.clone();
        for p in three_levels.pixels_mut().take(64 * 16) {
            p[1] += 3;
        }
        assert!(difference_beyond(&flat, &three_levels, 2).unwrap().flip_mean > 0.0);
    }
}
