//! Anti-aliasing: where in each pixel the rays go, and how their radiance becomes the pixel's
//! (docs/course/10-anti-aliasing.md#sampling-patterns: four corner rays shared between
//! neighbours, Whitted's adaptive subdivision, jittered supersampling).
//!
//! Positions are image coordinates: pixel `(i, j)` covers `[i, i+1] × [j, j+1]`, centre at
//! `(i + ½, j + ½)`.
//!
//! - `center`: one ray at the centre. The only mode that samples exactly where the rasterizer
//!   does, so it is the one `compare` uses by default.
//! - `regular`: `n × n` rays at the centres of an `n × n` sub-grid; the pixel is their mean.
//! - `jittered`: one ray at a random point of each of the `n × n` strata. The random numbers
//!   come from a hash of (pixel, sample, seed), not from a generator shared across threads, so
//!   the image is the same on every run and with any number of threads.
//! - `corners`: rays at the `(w + 1)(h + 1)` pixel corners; each pixel is the mean of its four.
//! - `adaptive`: starts from the corners; a square whose corners differ by more than the
//!   threshold (largest channel difference after the output transform) is split in four, which
//!   costs five new rays (the centre and the four edge midpoints), down to the maximum level. The
//!   square's value is the mean of its four children; an unsplit square is the mean of its
//!   corners.

use glam::{Vec2, Vec3};

use crate::output::{OutputTransform, srgb_encode};
use crate::settings::{AntiAliasing, TraceSettings};

/// Sub-pixel offsets of the `regular` pattern.
pub fn regular_offsets(n: u32) -> Vec<Vec2> {
    let n = n.max(1);
    (0..n * n).map(|k| Vec2::new((k % n) as f32 + 0.5, (k / n) as f32 + 0.5) / n as f32).collect()
}

/// Sub-pixel offsets of the `jittered` pattern for pixel `(i, j)`.
pub fn jittered_offsets(n: u32, i: u32, j: u32, seed: u64) -> Vec<Vec2> {
    let n = n.max(1);
    (0..n * n)
        .map(|k| {
            let h = hash(seed, u64::from(i), u64::from(j), u64::from(k));
            let (a, b) = (unit_float(h), unit_float(h >> 32));
            Vec2::new((k % n) as f32 + a, (k / n) as f32 + b) / n as f32
        })
        .collect()
}

/// A well-mixed 64-bit hash of four integers (splitmix64 steps).
fn hash(seed: u64, a: u64, b: u64, c: u64) -> u64 {
    let mut x = seed;
    for v in [a, b, c] {
        x = x.wrapping_add(v).wrapping_add(0x9e37_79b9_7f4a_7c15);
        x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        x ^= x >> 31;
    }
    x
}

/// A float in [0, 1) from the low 24 bits.
fn unit_float(bits: u64) -> f32 {
    (bits & 0xff_ffff) as f32 / (1u64 << 24) as f32
}

/// How different four corner values look after the output transform.
fn spread(corners: &[Vec3; 4], output: OutputTransform) -> f32 {
    let shown = corners.map(|c| output.display(c).to_array().map(srgb_encode));
    let mut largest = 0.0f32;
    for channel in 0..3 {
        let values = shown.map(|c| c[channel]);
        let (lo, hi) = values.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        largest = largest.max(hi - lo);
    }
    largest
}

/// Whitted's adaptive subdivision of the square with top-left corner `origin` and side `size`,
/// given its corner values (top-left, top-right, bottom-left, bottom-right).
pub fn subdivide(
    shoot: &mut impl FnMut(Vec2) -> Vec3,
    origin: Vec2,
    size: f32,
    corners: [Vec3; 4],
    level: u32,
    settings: &TraceSettings,
    output: OutputTransform,
) -> Vec3 {
    if level >= settings.adaptive_max_level || spread(&corners, output) <= settings.adaptive_threshold {
        return (corners[0] + corners[1] + corners[2] + corners[3]) / 4.0;
    }
    let h = size / 2.0;
    let [tl, tr, bl, br] = corners;
    let top = shoot(origin + Vec2::new(h, 0.0));
    let left = shoot(origin + Vec2::new(0.0, h));
    let centre = shoot(origin + Vec2::new(h, h));
    let right = shoot(origin + Vec2::new(size, h));
    let bottom = shoot(origin + Vec2::new(h, size));
    let quads = [
        (origin, [tl, top, left, centre]),
        (origin + Vec2::new(h, 0.0), [top, tr, centre, right]),
        (origin + Vec2::new(0.0, h), [left, centre, bl, bottom]),
        (origin + Vec2::new(h, h), [centre, right, bottom, br]),
    ];
    quads.into_iter().map(|(o, c)| subdivide(shoot, o, h, c, level + 1, settings, output)).sum::<Vec3>() / 4.0
}

/// Whether a mode starts from the shared grid of pixel-corner rays.
pub fn uses_corner_grid(mode: AntiAliasing) -> bool {
    matches!(mode, AntiAliasing::Corners | AntiAliasing::Adaptive)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_stay_inside_their_strata() {
        let regular = regular_offsets(2);
        assert_eq!(
            regular,
            vec![Vec2::new(0.25, 0.25), Vec2::new(0.75, 0.25), Vec2::new(0.25, 0.75), Vec2::new(0.75, 0.75)]
        );
        let jittered = jittered_offsets(4, 7, 9, 42);
        for (k, p) in jittered.iter().enumerate() {
            let cell = Vec2::new((k % 4) as f32, (k / 4) as f32) / 4.0;
            assert!(p.cmpge(cell).all() && p.cmplt(cell + 0.25).all(), "sample {k} at {p} left its stratum");
        }
        assert_eq!(jittered, jittered_offsets(4, 7, 9, 42), "the same seed gives the same pattern");
        assert_ne!(jittered, jittered_offsets(4, 7, 9, 43));
        assert_ne!(jittered, jittered_offsets(4, 8, 9, 42));
    }

    #[test]
    fn adaptive_subdivision_splits_only_where_corners_differ() {
        let settings = TraceSettings { adaptive_threshold: 0.1, adaptive_max_level: 3, ..TraceSettings::default() };
        // An edge at x = 0.3 inside a unit square: black left of it, white right.
        let edge = |p: Vec2| if p.x < 0.3 { Vec3::ZERO } else { Vec3::ONE };
        let mut rays = 0;
        let mut shoot = |p: Vec2| {
            rays += 1;
            edge(p)
        };
        let corners = [Vec3::ZERO, Vec3::ONE, Vec3::ZERO, Vec3::ONE];
        let value = subdivide(&mut shoot, Vec2::ZERO, 1.0, corners, 0, &settings, OutputTransform::clamp(1.0));
        // Level 1 splits at 0.5, level 2 at 0.25, level 3 resolves to 1/8: coverage of white is
        // 0.7, estimated to within one eighth of a pixel.
        assert!((value.x - 0.7).abs() <= 0.125, "{value}");
        // Split once (5 rays), then only the two children on the edge (2 × 5), then their two
        // children on the edge each (2 × 2 × 5).
        assert_eq!(rays, 5 + 10 + 20);
        let mut flat_rays = 0;
        let flat = subdivide(
            &mut |_| {
                flat_rays += 1;
                Vec3::ONE
            },
            Vec2::ZERO,
            1.0,
            [Vec3::ONE; 4],
            0,
            &settings,
            OutputTransform::clamp(1.0),
        );
        assert_eq!((flat, flat_rays), (Vec3::ONE, 0));
    }
}
