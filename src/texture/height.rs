//! Height fields `f_h(u, v)` for bump mapping (docs/course/04-bump-mapping.md): "a grey-level
//! texture, or a procedural function with known derivatives".
//!
//! - [`TextureHeight`]: a grey-level texture, read as the **red channel** of its level 0 (a grey
//!   image has R = G = B; a one-channel PNG decodes to R = G = B), bilinearly filtered with
//!   repeat wrapping, in the texture's linear values (height maps are `ColorSpace::Linear`, so
//!   the stored value `/255` is the height). The GPU reads the same value as
//!   `textureSampleLevel(height_map, linear_sampler, uv, 0.0).r`. No analytic derivatives: bump
//!   mapping takes finite differences of it.
//! - [`SineField`]: `f = a·sin(2π·f_u·u)·sin(2π·f_v·v)`, an egg-crate of bumps and dents, with
//!   `∂f/∂u = a·2π·f_u·cos(2π·f_u·u)·sin(2π·f_v·v)` and likewise in `v`. Tileable on `[0, 1)²`
//!   for integer frequencies. WGSL twin: `sine_height`, `sine_height_gradient`.
//! - [`ValueNoise`]: seeded value noise: random values on an `n × n` lattice (wrapped, so the
//!   field tiles on `[0, 1)²`) interpolated with the quintic `s(t) = 6t⁵ − 15t⁴ + 10t³`, whose
//!   first and second derivatives vanish at lattice lines, so the field is C² and its analytic
//!   gradient `Σ a_o·(∂/∂u of the bilinear blend)·s'(t)·n_o` is continuous. Octaves double the
//!   lattice and halve the amplitude.
//!
//! Limits: a texture height field is only C⁰ (bilinear between texels), so its finite
//! differences depend on Δ and show the texel grid up close; the procedural fields are evaluated
//! in f32, like the GPU, so finite differences stop converging around Δ ≈ 1/1000 (tests/bump.rs
//! prints the table).

use std::f32::consts::TAU;

use glam::Vec2;

use super::mipmap::MipLevel;
use crate::scene::{Material, ProceduralHeight, Texture};

/// A scalar height over texture coordinates.
pub trait HeightField: Sync {
    /// `f_h(u, v)`.
    fn height(&self, uv: Vec2) -> f32;

    /// `(∂f_h/∂u, ∂f_h/∂v)` where the field knows it in closed form.
    fn gradient(&self, _uv: Vec2) -> Option<Vec2> {
        None
    }

    /// The finite-difference step `Δ` to use when the user gives none: one texel for a texture
    /// (`Δ ≈ 1/n_t`).
    fn default_delta(&self) -> Vec2;

    /// The least and the greatest height the field can take: the slab parallax mapping marches
    /// through (WGSL twin: `height_range` in `shaders/common/surface.wgsl`).
    fn range(&self) -> (f32, f32);
}

/// `f` of `material`'s height field: its procedural one, or `map`, its height map as a
/// [`TextureHeight`]; `None` with neither. (A material has one or the other.)
pub fn with_material_field<T>(
    material: &Material,
    map: Option<&TextureHeight>,
    f: impl FnOnce(&dyn HeightField) -> T,
) -> Option<T> {
    match material.height_field {
        Some(ProceduralHeight::Sine { frequency, amplitude }) => Some(f(&SineField { amplitude, frequency })),
        Some(ProceduralHeight::Noise { seed, cells, octaves, amplitude }) => {
            Some(f(&ValueNoise { seed, cells, octaves, amplitude }))
        }
        None => map.map(|h| f(h)),
    }
}

/// A grey-level texture as a height field: the red channel of level 0, bilinear, repeat.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureHeight {
    pub level: MipLevel,
}

impl TextureHeight {
    pub fn new(texture: &Texture) -> TextureHeight {
        TextureHeight { level: MipLevel::from_texture(texture) }
    }
}

impl HeightField for TextureHeight {
    fn height(&self, uv: Vec2) -> f32 {
        self.level.bilinear(uv).x
    }

    fn default_delta(&self) -> Vec2 {
        Vec2::new(1.0 / self.level.width as f32, 1.0 / self.level.height as f32)
    }

    fn range(&self) -> (f32, f32) {
        (0.0, 1.0)
    }
}

/// `a·sin(2π·f_u·u)·sin(2π·f_v·v)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SineField {
    pub amplitude: f32,
    /// Periods per unit of texture coordinate; integers make the field tile.
    pub frequency: Vec2,
}

impl HeightField for SineField {
    fn height(&self, uv: Vec2) -> f32 {
        let a = TAU * self.frequency * uv;
        self.amplitude * a.x.sin() * a.y.sin()
    }

    fn gradient(&self, uv: Vec2) -> Option<Vec2> {
        // Same operations, in the same order, as `sine_height_gradient` in bump.wgsl.
        let w = TAU * self.frequency;
        let a = w * uv;
        Some(self.amplitude * Vec2::new(w.x * a.x.cos() * a.y.sin(), w.y * a.x.sin() * a.y.cos()))
    }

    fn default_delta(&self) -> Vec2 {
        // A 64th of the shortest period: fine enough to look smooth, far from f32's limit.
        1.0 / (64.0 * self.frequency.abs().max(Vec2::ONE))
    }

    fn range(&self) -> (f32, f32) {
        (-self.amplitude.abs(), self.amplitude.abs())
    }
}

/// Seeded, tileable value noise with quintic interpolation and `octaves` octaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ValueNoise {
    pub seed: u32,
    /// Lattice cells per unit of texture coordinate in the first octave (at least 1).
    pub cells: u32,
    /// At least 1; octave `o` has `cells·2^o` cells and amplitude `amplitude/2^o`.
    pub octaves: u32,
    /// Lattice values are uniform in `[−amplitude, amplitude]`.
    pub amplitude: f32,
}

/// Chris Wellons' `lowbias32` integer hash: every input bit affects every output bit.
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

fn quintic(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

fn quintic_derivative(t: f32) -> f32 {
    30.0 * t * t * (t * (t - 2.0) + 1.0)
}

impl ValueNoise {
    /// The lattice value at `(i, j)` of octave `octave` (indices already wrapped), in `[−1, 1)`.
    fn lattice(&self, i: u32, j: u32, octave: u32) -> f32 {
        let h = hash(i.wrapping_add(hash(j.wrapping_add(hash(octave.wrapping_add(hash(self.seed)))))));
        (h >> 8) as f32 / (1u32 << 23) as f32 - 1.0
    }

    /// The field and its gradient, together (they share the lattice lookups).
    pub fn evaluate(&self, uv: Vec2) -> (f32, Vec2) {
        let (mut value, mut gradient) = (0.0, Vec2::ZERO);
        let mut amplitude = self.amplitude;
        for octave in 0..self.octaves.max(1) {
            let n = self.cells.max(1).saturating_mul(1 << octave.min(20));
            let p = uv * n as f32;
            if !p.is_finite() {
                return (0.0, Vec2::ZERO);
            }
            let cell = p.floor();
            let f = p - cell;
            let wrap = |c: f32, d: u32| ((c as i64 + i64::from(d)).rem_euclid(i64::from(n))) as u32;
            let (i0, i1, j0, j1) = (wrap(cell.x, 0), wrap(cell.x, 1), wrap(cell.y, 0), wrap(cell.y, 1));
            let a = self.lattice(i0, j0, octave);
            let b = self.lattice(i1, j0, octave);
            let c = self.lattice(i0, j1, octave);
            let d = self.lattice(i1, j1, octave);
            let (sx, sy) = (quintic(f.x), quintic(f.y));
            let cross = a - b - c + d;
            value += amplitude * (a + (b - a) * sx + (c - a) * sy + cross * sx * sy);
            // ∂/∂u of the blend is ∂/∂s_x · s'(f_x) · ∂f_x/∂u, and ∂f_x/∂u = n.
            let scale = amplitude * n as f32;
            gradient += scale
                * Vec2::new(
                    ((b - a) + cross * sy) * quintic_derivative(f.x),
                    ((c - a) + cross * sx) * quintic_derivative(f.y),
                );
            amplitude *= 0.5;
        }
        (value, gradient)
    }
}

impl HeightField for ValueNoise {
    fn height(&self, uv: Vec2) -> f32 {
        self.evaluate(uv).0
    }

    fn gradient(&self, uv: Vec2) -> Option<Vec2> {
        Some(self.evaluate(uv).1)
    }

    fn default_delta(&self) -> Vec2 {
        // A 16th of the finest octave's cell.
        let finest = self.cells.max(1) << (self.octaves.max(1) - 1).min(20);
        Vec2::splat(1.0 / (16.0 * finest as f32))
    }

    fn range(&self) -> (f32, f32) {
        // Octave o adds at most a/2^o: less than 2a in all.
        (-2.0 * self.amplitude.abs(), 2.0 * self.amplitude.abs())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ColorSpace;

    #[test]
    fn texture_height_is_the_red_channel_of_level_0() {
        let texture = Texture {
            path: "h".into(),
            width: 2,
            height: 1,
            rgba8: vec![0, 255, 255, 255, 255, 0, 0, 255],
            color_space: ColorSpace::Linear,
        };
        let field = TextureHeight::new(&texture);
        assert_eq!(field.height(Vec2::new(0.25, 0.5)), 0.0);
        assert_eq!(field.height(Vec2::new(0.75, 0.5)), 1.0);
        assert_eq!(field.height(Vec2::new(0.5, 0.5)), 0.5);
        assert_eq!(field.default_delta(), Vec2::new(0.5, 1.0));
    }

    #[test]
    fn noise_tiles_and_is_seeded() {
        let noise = ValueNoise { seed: 7, cells: 4, octaves: 3, amplitude: 1.0 };
        for uv in [Vec2::new(0.1, 0.2), Vec2::new(0.55, 0.9), Vec2::new(0.0, 0.0)] {
            let here = noise.height(uv);
            assert!((noise.height(uv + Vec2::X) - here).abs() < 1e-5);
            assert!((noise.height(uv - Vec2::Y) - here).abs() < 1e-5);
        }
        let other = ValueNoise { seed: 8, ..noise };
        assert_ne!(noise.height(Vec2::new(0.1, 0.2)), other.height(Vec2::new(0.1, 0.2)));
        // At a lattice point the field is the lattice value, and s'(0) = 0 leaves only finer octaves.
        let single = ValueNoise { octaves: 1, ..noise };
        assert_eq!(single.height(Vec2::new(0.25, 0.5)), single.lattice(1, 2, 0));
        assert_eq!(single.gradient(Vec2::new(0.25, 0.5)), Some(Vec2::ZERO));
    }

    #[test]
    fn quintic_derivative_is_the_derivative() {
        for t in [0.0, 0.2, 0.5, 0.9, 1.0] {
            let numeric = (quintic(t + 1e-3) - quintic(t - 1e-3)) / 2e-3;
            assert!((numeric - quintic_derivative(t)).abs() < 1e-3, "t = {t}");
        }
        assert_eq!((quintic(0.0), quintic(1.0), quintic_derivative(1.0)), (0.0, 1.0, 0.0));
    }
}
