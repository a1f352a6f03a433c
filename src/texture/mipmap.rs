//! Mip chains and the filters that read them (docs/course/03-mipmaps.md), on the CPU.
//!
//! A mipmap ("multum in parvo") of a `2^n × 2^n` texture is `n + 1` images; level `i + 1` halves
//! level `i` by the box filter
//!
//! `M_{i+1}[j, k] = ¼ (M_i[2j, 2k] + M_i[2j+1, 2k] + M_i[2j, 2k+1] + M_i[2j+1, 2k+1])`.
//!
//! The averages are taken on **linear** values: an sRGB colour texture is decoded first (the
//! mean of sRGB-encoded black and white is encoded 128, linear 0.22, where the light the two
//! texels give is linear 0.5). Levels are kept as linear `Vec4` (f32), so the formula holds
//! exactly in tests; alpha is always linear.
//!
//! **Non-power-of-two sizes.** Each next level is `max(1, ⌊size/2⌋)` per axis (the sizes a GPU
//! gives its levels, so the CPU and GPU chains line up level for level), down to 1×1: a `w × h`
//! texture has `⌊log2 max(w, h)⌋ + 1` levels. Output texel `j` of an axis of `n` source texels
//! averages the source interval `[j·n/n', (j+1)·n/n')`, `n' = max(1, ⌊n/2⌋)`, each source texel
//! weighted by how much of it that interval covers:
//!
//! - `n` even: texels `2j, 2j+1`, weights `½, ½` — the formula above;
//! - `n = 2n' + 1` odd (n ≥ 3): texels `2j, 2j+1, 2j+2`, weights `(n'−j)/n, n'/n, (j+1)/n`
//!   (the "3-tap on odd sizes" box filter: the footprint is `2 + 2/(n−1)` texels wide);
//! - `n = 1`: the texel itself.
//!
//! 2D weights are products of the two axes' (up to 3×3 taps). The footprints tile the source
//! exactly, so every level has the same mean as level 0 (up to rounding) for every size, and
//! power-of-two sizes reduce to the notes' formula bit for bit. `shaders/mipmap.wgsl` computes
//! the same weights on the GPU.
//!
//! **Sampling** ([`MipChain::sample`]) follows the GPU sampler (Vulkan's rules) so that the ray
//! tracer and the rasterizer read the same values: repeat wrapping, texel centres at
//! `(i + ½)/width`, the level of detail `λ` clamped to `[0, levels − 1]`; *nearest-mip* reads
//! level `⌈λ + ½⌉ − 1` (round half down), *trilinear* blends levels `⌊λ⌋` and `⌊λ⌋ + 1` by
//! `λ − ⌊λ⌋`. Anisotropic filtering exists only on the GPU (its footprint shape is left to the
//! implementation); the CPU has no twin for it.
//!
//! Limits: the box filter is the notes', not the best downsampler (it blurs less evenly than a
//! wider kernel and aliases a little); levels are not renormalized for alpha coverage.

use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;

use crate::output::{srgb_decode, srgb_encode};
use crate::scene::{ColorSpace, Texture, Wrap};

/// How a texture is read. [`MipChain::sample`] implements each on the CPU;
/// `crate::gpu::mipmap::sampler_descriptor` gives the GPU sampler that does the same.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The nearest texel of level 0 (no mipmaps): blocky up close, aliased far away.
    Nearest,
    /// Bilinear within level 0 (no mipmaps): smooth up close, still aliased far away.
    Bilinear,
    /// Bilinear within the nearest level: no aliasing, but visible seams where the level changes.
    NearestMip,
    /// Bilinear in the two nearest levels, blended by the fractional level: no seams.
    #[default]
    Trilinear,
    /// Teaching view: the colour of the level trilinear filtering would read
    /// ([`LEVEL_PALETTE`], blended with trilinear's weights) instead of the texture.
    LevelColour,
}

impl Filter {
    pub const ALL: [Filter; 5] =
        [Filter::Nearest, Filter::Bilinear, Filter::NearestMip, Filter::Trilinear, Filter::LevelColour];

    /// Whether this filter reads levels other than 0.
    pub fn uses_mipmaps(self) -> bool {
        matches!(self, Filter::NearestMip | Filter::Trilinear | Filter::LevelColour)
    }

    pub fn name(self) -> &'static str {
        match self {
            Filter::Nearest => "nearest",
            Filter::Bilinear => "bilinear",
            Filter::NearestMip => "nearest-mip",
            Filter::Trilinear => "trilinear",
            Filter::LevelColour => "level-colour",
        }
    }
}

/// One colour per mip level for the level-colour view, linear RGB: red, orange, yellow, green,
/// cyan, blue, magenta, then grey for level 7 and every smaller level. Written into the WGSL as
/// `MIP_LEVEL_PALETTE` (`crate::shaders::constants::prelude`).
pub const LEVEL_PALETTE: [Vec3; 8] = [
    Vec3::new(1.0, 0.0, 0.0),
    Vec3::new(1.0, 0.5, 0.0),
    Vec3::new(1.0, 1.0, 0.0),
    Vec3::new(0.0, 1.0, 0.0),
    Vec3::new(0.0, 1.0, 1.0),
    Vec3::new(0.0, 0.0, 1.0),
    Vec3::new(1.0, 0.0, 1.0),
    Vec3::new(0.5, 0.5, 0.5),
];

/// The level-colour view at level of detail `lod`: the palette blended between levels `⌊lod⌋`
/// and `⌊lod⌋ + 1` like trilinear filtering blends texels. `lod` is clamped to the palette.
pub fn level_colour(lod: f32) -> Vec3 {
    let last = (LEVEL_PALETTE.len() - 1) as f32;
    let lod = if lod.is_nan() { 0.0 } else { lod.clamp(0.0, last) };
    let lo = lod.floor();
    let hi = (lo + 1.0).min(last);
    LEVEL_PALETTE[lo as usize].lerp(LEVEL_PALETTE[hi as usize], lod - lo)
}

/// The size of the level after one of `size` texels along an axis: `max(1, ⌊size/2⌋)`.
pub fn next_size(size: u32) -> u32 {
    (size / 2).max(1)
}

/// How many levels a full chain of a `width × height` texture has: `⌊log2 max(w, h)⌋ + 1`
/// (zero sizes count as 1).
pub fn mip_level_count(width: u32, height: u32) -> u32 {
    u32::BITS - width.max(height).max(1).leading_zeros()
}

/// The source texels one output texel averages along one axis: `count` texels from `first`,
/// with `weights[..count]` (see the module header for the rule).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxTaps {
    pub first: u32,
    pub count: u32,
    pub weights: [f32; 3],
}

/// The taps of output texel `j` when an axis of `n` source texels is halved.
pub fn box_taps(j: u32, n: u32) -> BoxTaps {
    if n <= 1 {
        BoxTaps { first: 0, count: 1, weights: [1.0, 0.0, 0.0] }
    } else if n.is_multiple_of(2) {
        BoxTaps { first: 2 * j, count: 2, weights: [0.5, 0.5, 0.0] }
    } else {
        // Written exactly as in shaders/mipmap.wgsl, so both round the same way.
        let (h, nf) = (n / 2, n as f32);
        BoxTaps { first: 2 * j, count: 3, weights: [(h - j) as f32 / nf, h as f32 / nf, (j + 1) as f32 / nf] }
    }
}

/// One level of a chain: linear RGBA, rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct MipLevel {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec4>,
}

impl MipLevel {
    /// Level 0 of `texture`: its texels as linear values (sRGB colour decoded, alpha as stored).
    pub fn from_texture(texture: &Texture) -> MipLevel {
        let decode: [f32; 256] = std::array::from_fn(|i| {
            let stored = i as f32 / 255.0;
            match texture.color_space {
                ColorSpace::Srgb => srgb_decode(stored),
                ColorSpace::Linear => stored,
            }
        });
        let count = texture.width as usize * texture.height as usize;
        let mut texels: Vec<Vec4> = texture
            .rgba8
            .chunks_exact(4)
            .take(count)
            .map(|t| {
                Vec4::new(decode[t[0] as usize], decode[t[1] as usize], decode[t[2] as usize], t[3] as f32 / 255.0)
            })
            .collect();
        // A texture whose pixel data is short (a malformed file) reads as black, not out of bounds.
        texels.resize(count, Vec4::ZERO);
        MipLevel { width: texture.width, height: texture.height, texels }
    }

    /// The texel at integer coordinates, wrapped (repeat) into the level.
    pub fn texel(&self, i: i64, j: i64) -> Vec4 {
        self.texel_wrapped(i, j, [Wrap::Repeat; 2])
    }

    /// The texel at integer coordinates, brought into the level by `wrap` along u and v.
    pub fn texel_wrapped(&self, i: i64, j: i64, wrap: [Wrap; 2]) -> Vec4 {
        let i = wrap[0].index(i, i64::from(self.width)) as usize;
        let j = wrap[1].index(j, i64::from(self.height)) as usize;
        self.texels[j * self.width as usize + i]
    }

    /// The texel whose square contains `uv` (repeat wrapping).
    pub fn nearest(&self, uv: Vec2) -> Vec4 {
        self.nearest_wrapped(uv, [Wrap::Repeat; 2])
    }

    /// The texel whose square contains `uv`, wrapped by `wrap`.
    pub fn nearest_wrapped(&self, uv: Vec2, wrap: [Wrap; 2]) -> Vec4 {
        let x = uv.x * self.width as f32;
        let y = uv.y * self.height as f32;
        if !(x.is_finite() && y.is_finite()) {
            return Vec4::ZERO;
        }
        self.texel_wrapped(x.floor() as i64, y.floor() as i64, wrap)
    }

    /// Bilinear interpolation between the four texel centres around `uv` (repeat wrapping).
    pub fn bilinear(&self, uv: Vec2) -> Vec4 {
        self.bilinear_wrapped(uv, [Wrap::Repeat; 2])
    }

    /// Bilinear interpolation between the four texel centres around `uv`, each wrapped by `wrap`
    /// as the GPU's address modes do.
    pub fn bilinear_wrapped(&self, uv: Vec2, wrap: [Wrap; 2]) -> Vec4 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        if !(x.is_finite() && y.is_finite()) {
            return Vec4::ZERO;
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (i, j) = (x0 as i64, y0 as i64);
        // Each column and row wrapped once, for the two texels on it.
        let (width, height) = (i64::from(self.width), i64::from(self.height));
        let [i0, i1] = [i, i + 1].map(|i| wrap[0].index(i, width) as usize);
        let [j0, j1] = [j, j + 1].map(|j| wrap[1].index(j, height) as usize * self.width as usize);
        let texel = |i, j| self.texels[j + i];
        let top = texel(i0, j0).lerp(texel(i1, j0), fx);
        let bottom = texel(i0, j1).lerp(texel(i1, j1), fx);
        top.lerp(bottom, fy)
    }

    /// The mean of all texels (in f64, so that a test of mean conservation measures the filter,
    /// not the summation).
    pub fn mean(&self) -> Vec4 {
        let sum = self.texels.iter().fold([0f64; 4], |mut s, t| {
            for (acc, &c) in s.iter_mut().zip(t.as_ref()) {
                *acc += f64::from(c);
            }
            s
        });
        let n = self.texels.len().max(1) as f64;
        Vec4::from_array(sum.map(|s| (s / n) as f32))
    }

    /// The level as 8-bit RGBA in `color_space` (sRGB re-encoded), rounded to nearest: what a
    /// GPU texture of the matching format stores.
    pub fn to_rgba8(&self, color_space: ColorSpace) -> Vec<u8> {
        let quantize = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        let encode = |v: f32| match color_space {
            ColorSpace::Srgb => srgb_encode(v.clamp(0.0, 1.0)),
            ColorSpace::Linear => v,
        };
        self.texels
            .iter()
            .flat_map(|t| [quantize(encode(t.x)), quantize(encode(t.y)), quantize(encode(t.z)), quantize(t.w)])
            .collect()
    }

    /// The next level down: the box filter of the module header.
    pub fn downsample(&self) -> MipLevel {
        let (w, h) = (next_size(self.width), next_size(self.height));
        let mut texels = vec![Vec4::ZERO; w as usize * h as usize];
        texels.par_chunks_mut(w as usize).enumerate().for_each(|(k, row)| {
            let ty = box_taps(k as u32, self.height);
            for (j, out) in row.iter_mut().enumerate() {
                let tx = box_taps(j as u32, self.width);
                // y outer, x inner: for power-of-two sizes the sum is
                // ((¼a + ¼b) + ¼c) + ¼d = (a + b + c + d)/4 in the notes' order, bit for bit.
                let mut sum = Vec4::ZERO;
                for b in 0..ty.count {
                    let row_start = (ty.first + b) as usize * self.width as usize;
                    for a in 0..tx.count {
                        let weight = tx.weights[a as usize] * ty.weights[b as usize];
                        sum += self.texels[row_start + (tx.first + a) as usize] * weight;
                    }
                }
                *out = sum;
            }
        });
        MipLevel { width: w, height: h, texels }
    }
}

/// A full mip chain, level 0 (the texture) to 1×1, in linear values.
#[derive(Clone, Debug, PartialEq)]
pub struct MipChain {
    pub levels: Vec<MipLevel>,
}

impl MipChain {
    /// The chain of `texture`, decoded to linear values first.
    pub fn build(texture: &Texture) -> MipChain {
        MipChain::from_level0(MipLevel::from_texture(texture))
    }

    /// The chain whose level 0 is `level0` (already linear).
    pub fn from_level0(level0: MipLevel) -> MipChain {
        let count = mip_level_count(level0.width, level0.height) as usize;
        let mut levels = Vec::with_capacity(count);
        levels.push(level0);
        while levels.len() < count {
            let next = levels.last().expect("the chain starts with level 0").downsample();
            levels.push(next);
        }
        MipChain { levels }
    }

    /// The largest level of detail, `levels − 1`.
    pub fn max_lod(&self) -> f32 {
        (self.levels.len() - 1) as f32
    }

    /// The texture at `uv` filtered by `filter` at level of detail `lod` (ignored by
    /// [`Filter::Nearest`] and [`Filter::Bilinear`], which read level 0 only).
    pub fn sample(&self, uv: Vec2, lod: f32, filter: Filter) -> Vec4 {
        self.sample_wrapped(uv, lod, filter, [Wrap::Repeat; 2])
    }

    /// [`MipChain::sample`] with texture coordinates wrapped by `wrap` along u and v.
    pub fn sample_wrapped(&self, uv: Vec2, lod: f32, filter: Filter, wrap: [Wrap; 2]) -> Vec4 {
        let lod = if lod.is_nan() { 0.0 } else { lod.clamp(0.0, self.max_lod()) };
        match filter {
            Filter::Nearest => self.levels[0].nearest_wrapped(uv, wrap),
            Filter::Bilinear => self.levels[0].bilinear_wrapped(uv, wrap),
            Filter::NearestMip => {
                // Vulkan's nearest mip: ⌈λ + ½⌉ − 1, which rounds λ = i + ½ down to level i.
                let level = ((lod + 0.5).ceil() - 1.0).max(0.0) as usize;
                self.levels[level].bilinear_wrapped(uv, wrap)
            }
            Filter::Trilinear => {
                let lo = lod.floor();
                let fraction = lod - lo;
                let lo = lo as usize;
                let near = self.levels[lo].bilinear_wrapped(uv, wrap);
                if fraction == 0.0 {
                    return near;
                }
                near.lerp(self.levels[lo + 1].bilinear_wrapped(uv, wrap), fraction)
            }
            Filter::LevelColour => level_colour(lod).extend(1.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_counts_follow_floor_halving() {
        for ((w, h), levels) in [((1, 1), 1), ((2, 1), 2), ((4096, 4096), 13), ((5, 3), 3), ((1, 7), 3), ((3, 3), 2)] {
            assert_eq!(mip_level_count(w, h), levels, "{w}×{h}");
        }
    }

    #[test]
    fn odd_taps_cover_the_footprint_and_sum_to_one() {
        // n = 5 → 2: footprints [0, 2.5) and [2.5, 5): weights (2, 2, 1)/5 and (1, 2, 2)/5.
        assert_eq!(box_taps(0, 5), BoxTaps { first: 0, count: 3, weights: [0.4, 0.4, 0.2] });
        assert_eq!(box_taps(1, 5), BoxTaps { first: 2, count: 3, weights: [0.2, 0.4, 0.4] });
        for n in (3..41).step_by(2) {
            for j in 0..n / 2 {
                let t = box_taps(j, n);
                assert!((t.weights.iter().sum::<f32>() - 1.0).abs() < 1e-6, "n = {n}, j = {j}");
                assert!(t.first + t.count <= n);
            }
        }
    }

    #[test]
    fn level_colour_blends_between_neighbouring_levels() {
        assert_eq!(level_colour(0.0), LEVEL_PALETTE[0]);
        assert_eq!(level_colour(2.0), LEVEL_PALETTE[2]);
        assert_eq!(level_colour(0.5), Vec3::new(1.0, 0.25, 0.0));
        assert_eq!(level_colour(40.0), LEVEL_PALETTE[7]);
        assert_eq!(level_colour(-3.0), LEVEL_PALETTE[0]);
    }
}
