//! The output transform both renderers share: linear radiance × exposure, through a tone curve
//! ([`ToneMap`]: the course's clamp to [0, 1] by default), encoded as sRGB 8-bit. The rasterizer
//! runs it in `shaders/present.wgsl` (the curve in the shader, the encoding by the
//! `Rgba8UnormSrgb` target); the ray tracer runs it here. `tests/output_transform.rs` checks that
//! both give the same bytes for every curve.
//!
//! The 8-bit encoding is exact: a display value's level is the one its true sRGB value rounds
//! to, found in a table of where each level starts ([`Levels`]), computed once in double
//! precision. So every platform encodes alike, whatever its `powf` rounds, and an image encodes
//! several times faster than by a `powf` a channel.

use std::sync::OnceLock;

use glam::Vec3;

use crate::RenderSettings;
use crate::settings::ToneMap;

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 { 12.92 * linear } else { 1.055 * linear.powf(1.0 / 2.4) - 0.055 }
}

/// [`srgb_encode`] in double precision, of the same single-precision input (the linear segment
/// chosen by the same comparison): what [`Levels`] rounds.
fn srgb_encode_f64(linear: f32) -> f64 {
    let x = linear as f64;
    if linear <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 }
}

/// Buckets of [`Levels::first`]: a power of two, so that `c × BUCKETS` rounds nothing.
const BUCKETS: usize = 4096;

/// Where each 8-bit sRGB level starts. Level `k` (1 to 255) is the encoding of display value
/// `c` when `255 · sRGB(c) ≥ k − ½` and not `≥ k + ½`: rounding to the nearest level, halves up.
struct Levels {
    /// `starts[k − 1]`: the smallest `f32` that encodes to level `k` or above.
    starts: [f32; 255],
    /// `first[b]`: the level of `b / BUCKETS`, where the search for a value at or above it
    /// starts (at most a few levels lie in one bucket, the most near black).
    first: [u8; BUCKETS + 1],
}

impl Levels {
    fn get() -> &'static Levels {
        static LEVELS: OnceLock<Levels> = OnceLock::new();
        LEVELS.get_or_init(Levels::new)
    }

    fn new() -> Levels {
        let starts = std::array::from_fn(|i| {
            // Non-negative floats order as their bits do: a binary search over the bits of
            // [0, 1] for the first value whose sRGB value × 255 reaches the level's lower half.
            let reaches = |bits: u32| 255.0 * srgb_encode_f64(f32::from_bits(bits)) >= i as f64 + 0.5;
            let (mut low, mut high) = (0u32, 1.0f32.to_bits());
            while low < high {
                let middle = low + (high - low) / 2;
                if reaches(middle) { high = middle } else { low = middle + 1 }
            }
            f32::from_bits(low)
        });
        let first = std::array::from_fn(|b| {
            let c = b as f32 / BUCKETS as f32;
            starts.partition_point(|&start| start <= c) as u8
        });
        Levels { starts, first }
    }

    /// The 8-bit level of display value `c` (0 below, NaN included; 255 from 1 up).
    fn level(&self, c: f32) -> u8 {
        // `c × BUCKETS` is exact, so the bucket's start is at or below `c` (NaN: bucket 0).
        let bucket = ((c * BUCKETS as f32) as usize).min(BUCKETS);
        let mut level = self.first[bucket] as usize;
        while level < 255 && self.starts[level] <= c {
            level += 1;
        }
        level as u8
    }
}

/// The inverse of [`srgb_encode`].
pub fn srgb_decode(encoded: f32) -> f32 {
    if encoded <= 0.040_45 { encoded / 12.92 } else { ((encoded + 0.055) / 1.055).powf(2.4) }
}

/// Exposure and tone curve: what turns linear radiance into display values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutputTransform {
    pub exposure: f32,
    pub tone_map: ToneMap,
}

impl OutputTransform {
    /// The course's transform: × `exposure`, then the clamp.
    pub fn clamp(exposure: f32) -> OutputTransform {
        OutputTransform { exposure, tone_map: ToneMap::Clamp }
    }

    pub fn of(settings: &RenderSettings) -> OutputTransform {
        OutputTransform { exposure: settings.exposure, tone_map: settings.tone_map }
    }

    /// Linear display values in [0, 1] for `radiance`. NaN maps to 0, negative values to 0.
    pub fn display(&self, radiance: Vec3) -> Vec3 {
        let c = (radiance * self.exposure).to_array().map(|c| if c.is_nan() { 0.0 } else { c.max(0.0) });
        tone_map(Vec3::from(c), self.tone_map)
    }

    /// One pixel, encoded: each channel's sRGB value × 255 rounded to the nearest level.
    pub fn to_srgb8(&self, radiance: Vec3) -> [u8; 3] {
        let levels = Levels::get();
        self.display(radiance).to_array().map(|c| levels.level(c))
    }
}

/// The tone curve `curve` at exposed, non-negative radiance `c`; the result lies in [0, 1].
pub fn tone_map(c: Vec3, curve: ToneMap) -> Vec3 {
    let mapped = match curve {
        ToneMap::Clamp => c,
        ToneMap::Reinhard => c / (Vec3::ONE + c),
        // Narkowicz (2015), "ACES Filmic Tone Mapping Curve": a rational fit of the ACES
        // reference rendering and output transforms, applied per channel.
        ToneMap::Aces => (c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14),
        ToneMap::PbrNeutral => pbr_neutral(c),
    };
    mapped.clamp(Vec3::ZERO, Vec3::ONE)
}

/// Khronos PBR Neutral (Khronos 3D Commerce, 2024): a small toe offset, identity up to
/// `1 − 0.24` on the brightest channel, then a rational shoulder towards 1 that keeps the hue and
/// desaturates towards white as it compresses.
fn pbr_neutral(c: Vec3) -> Vec3 {
    const START_COMPRESSION: f32 = 0.8 - 0.04;
    const DESATURATION: f32 = 0.15;
    let x = c.min_element();
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    let c = c - Vec3::splat(offset);
    let peak = c.max_element();
    if peak < START_COMPRESSION {
        return c;
    }
    let d = 1.0 - START_COMPRESSION;
    let new_peak = 1.0 - d * d / (peak + d - START_COMPRESSION);
    let c = c * (new_peak / peak);
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.lerp(Vec3::splat(new_peak), g)
}

/// One pixel through the course's transform (exposure, clamp, sRGB).
pub fn to_srgb8(radiance: Vec3, exposure: f32) -> [u8; 3] {
    OutputTransform::clamp(exposure).to_srgb8(radiance)
}

/// A whole image of linear radiance, row-major from the top, to an RGBA8 image.
pub fn encode_image(width: u32, height: u32, radiance: &[Vec3], transform: OutputTransform) -> image::RgbaImage {
    assert_eq!(radiance.len(), (width * height) as usize, "one radiance value per pixel");
    // A pixel equal to the one before it is encoded once: the progressive levels fill blocks of
    // up to 16 × 16 pixels with one value, and the page encodes them on its only thread.
    let mut last: Option<(Vec3, [u8; 3])> = None;
    let bytes = radiance
        .iter()
        .flat_map(|&c| {
            let [r, g, b] = match last {
                Some((previous, encoded)) if previous == c => encoded,
                _ => {
                    let encoded = transform.to_srgb8(c);
                    last = Some((c, encoded));
                    encoded
                }
            };
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

    /// Every `step`-th float of [0, 1], by bits (and 1 itself).
    fn floats_to_one(step: u32) -> impl Iterator<Item = f32> {
        (0..1.0f32.to_bits()).step_by(step as usize).map(f32::from_bits).chain([1.0])
    }

    #[test]
    fn each_level_starts_where_the_true_srgb_value_rounds_up_to_it() {
        let levels = Levels::get();
        let mut closest = f64::INFINITY;
        for (i, &start) in levels.starts.iter().enumerate() {
            let half = i as f64 + 0.5;
            let (at, below) = (255.0 * srgb_encode_f64(start), 255.0 * srgb_encode_f64(start.next_down()));
            assert!(at >= half && below < half, "level {}: starts at {start}", i + 1);
            closest = closest.min(at - half).min(half - below);
        }
        // No float lies within a double's rounding of a level's edge, so a `powf` in double
        // precision a few units in the last place off on another platform finds the same starts.
        assert!(closest > 1e-10, "a float lies {closest:e} from a level's edge");
        assert!(levels.starts.windows(2).all(|w| w[0] < w[1]), "the levels start in order");
    }

    #[test]
    fn a_level_is_the_true_srgb_value_rounded_and_powf_in_single_precision_agrees_but_at_edges() {
        let levels = Levels::get();
        let (mut checked, mut single_differs) = (0, 0);
        for c in floats_to_one(997) {
            let exact = (255.0 * srgb_encode_f64(c)).round() as u8;
            assert_eq!(levels.level(c), exact, "{c}");
            let single = (srgb_encode(c) * 255.0).round() as u8;
            assert!(single.abs_diff(exact) <= 1, "{c}: {single} in single precision, {exact} exactly");
            single_differs += (single != exact) as u32;
            checked += 1;
        }
        // Single precision misses only values within its rounding of a level's edge.
        assert!(single_differs * 10_000 < checked, "{single_differs} of {checked} differ in single precision");
        assert_eq!([levels.level(-0.5), levels.level(f32::NAN), levels.level(7.0)], [0, 0, 255]);
    }

    #[test]
    fn srgb_round_trips_and_hits_known_values() {
        assert_eq!(to_srgb8(Vec3::new(0.0, 1.0, 0.5), 1.0), [0, 255, 188]);
        assert_eq!(to_srgb8(Vec3::new(-1.0, 7.0, f32::NAN), 1.0), [0, 255, 0]);
        for i in 0..=255 {
            let encoded = i as f32 / 255.0;
            assert!((srgb_encode(srgb_decode(encoded)) - encoded).abs() < 1e-5);
        }
    }

    #[test]
    fn an_image_encodes_each_pixel_as_on_its_own_runs_of_equal_pixels_included() {
        let (a, b) = (Vec3::new(0.2, 0.5, 0.9), Vec3::new(0.9, 0.1, 0.0));
        let radiance = [a, a, b, b, a, Vec3::NAN, Vec3::NAN, b, a];
        let transform = OutputTransform::clamp(1.0);
        let image = encode_image(3, 3, &radiance, transform);
        for (pixel, &c) in image.pixels().zip(&radiance) {
            let [r, g, b] = transform.to_srgb8(c);
            assert_eq!(pixel.0, [r, g, b, 255]);
        }
    }

    fn curve(c: f32, tone_map: ToneMap) -> f32 {
        super::tone_map(Vec3::splat(c), tone_map).x
    }

    #[test]
    fn tone_curves_at_known_points() {
        // Clamp: the identity on [0, 1], white above.
        assert_eq!(curve(0.5, ToneMap::Clamp), 0.5);
        assert_eq!(curve(3.0, ToneMap::Clamp), 1.0);
        // Reinhard: c / (1 + c).
        assert_eq!(curve(1.0, ToneMap::Reinhard), 0.5);
        assert!((curve(0.18, ToneMap::Reinhard) - 0.18 / 1.18).abs() < 1e-7);
        assert!(curve(1e6, ToneMap::Reinhard) < 1.0);
        // ACES fit: 0 at 0, (2.51 + 0.03) / (2.43 + 0.59 + 0.14) at 1, white from about 10.
        assert_eq!(curve(0.0, ToneMap::Aces), 0.0);
        assert!((curve(1.0, ToneMap::Aces) - 2.54 / 3.16).abs() < 1e-6);
        assert!(curve(0.18, ToneMap::Aces) > 0.25 && curve(0.18, ToneMap::Aces) < 0.27);
        assert_eq!(curve(12.0, ToneMap::Aces), 1.0);
        // PBR Neutral: grey 0.5 passes minus the 0.04 offset; the shoulder starts at 0.76 + 0.04;
        // its limit is 1.
        assert!((curve(0.5, ToneMap::PbrNeutral) - 0.46).abs() < 1e-6);
        assert!((curve(0.79, ToneMap::PbrNeutral) - 0.75).abs() < 1e-6);
        let at_one = curve(1.0, ToneMap::PbrNeutral);
        assert!(at_one > 0.8 && at_one < 0.9, "{at_one}");
        assert!(curve(100.0, ToneMap::PbrNeutral) > 0.99);
        // A saturated highlight desaturates towards white: its weakest channel rises.
        let red = super::tone_map(Vec3::new(8.0, 0.5, 0.5), ToneMap::PbrNeutral);
        assert!(red.y > 0.46 + 0.05, "{red}");
        // Every curve is monotonic and stays in [0, 1].
        for tone_map in [ToneMap::Clamp, ToneMap::Reinhard, ToneMap::Aces, ToneMap::PbrNeutral] {
            let mut last = 0.0;
            for i in 0..=2000 {
                let y = curve(i as f32 * 0.01, tone_map);
                assert!((0.0..=1.0).contains(&y) && y >= last - 1e-6, "{tone_map:?} at {}: {y}", i as f32 * 0.01);
                last = y;
            }
        }
    }
}
