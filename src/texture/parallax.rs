//! Parallax occlusion mapping (docs/course/04-bump-mapping.md, between bump and displacement
//! mapping): the flat surface is drawn, but each point of it is shaded as the point where the
//! view ray, entering the relief's slab above it, first meets the displaced surface
//! `p + k·f(u, v)·n`. The relief hides itself and its bumps move with the eye; the outline, the
//! shadows and what the surface hides stay the flat surface's.
//!
//! The march (written by hand: it is the technique), in both renderers alike (WGSL twin:
//! `parallax_uv` in `shaders/common/surface.wgsl`, the same operations in the same order):
//!
//! ```text
//! d: the view ray's direction, n the normal, t_u, t_v the true-length tangents ∂p/∂u, ∂p/∂v
//! a point p + s·d of the ray is at height h = s·(d·n) over the flat surface, and at
//!     texture coordinates uv + s·(du/ds, dv/ds), solved from d − (d·n)·n = du/ds·t_u + dv/ds·t_v
//! from the slab's top (h = k·f_max) to its bottom (h = k·f_min), STEPS equal steps:
//!     the first step whose gap h − k·f(uv(s)) is ≤ 0 is under the surface
//! between it and the step before, REFINEMENTS secant steps on the gap; the crossing's uv
//! ```

use glam::{Vec2, Vec3};

use super::height::HeightField;

/// The march's equal steps through the slab.
pub const STEPS: u32 = 32;
/// The secant steps that refine the crossing between the last two.
pub const REFINEMENTS: u32 = 4;

/// The texture coordinates where the view ray along `d` (unit, towards the surface) through the
/// surface point at `uv` (normal `n`, true-length tangents `tu`, `tv`) first meets the surface
/// displaced by `k·f`. `uv` itself where the ray grazes or leaves the surface, or the tangents
/// are degenerate.
pub fn parallax_uv(field: &dyn HeightField, k: f32, uv: Vec2, (n, tu, tv): (Vec3, Vec3, Vec3), d: Vec3) -> Vec2 {
    let dn = d.dot(n);
    if !(dn < -1e-4) || k == 0.0 {
        return uv;
    }
    let (low, high) = field.range();
    let (h_low, h_high) = ((k * low).min(k * high), (k * low).max(k * high));
    // Degenerate tangents give no rate: the march stays at uv.
    let duv_ds = rate(d, n, tu, tv);
    let (s_top, s_bottom) = (h_high / dn, h_low / dn);
    let gap = |s: f32| s * dn - k * field.height(uv + s * duv_ds);
    let mut before = (s_top, gap(s_top));
    for step in 1..=STEPS {
        let s = s_top + (s_bottom - s_top) * (step as f32 / STEPS as f32);
        let after = (s, gap(s));
        if after.1 <= 0.0 {
            return uv + crossing(before, after, gap) * duv_ds;
        }
        before = after;
    }
    uv + s_bottom * duv_ds
}

/// How fast the texture coordinates change along `d` over the surface of normal `n` and tangents
/// `tu`, `tv`: the part of `d` in the surface's plane, `d − (d·n)·n`, written as
/// `du/ds·t_u + dv/ds·t_v` by the 2×2 normal equations (the tangents need not be orthogonal or
/// unit). Zero where they are degenerate. (WGSL twin: `parallax_rate`.)
pub fn rate(d: Vec3, n: Vec3, tu: Vec3, tv: Vec3) -> Vec2 {
    let (a, b, c) = (tu.dot(tu), tu.dot(tv), tv.dot(tv));
    let det = a * c - b * b;
    if !(det.abs() > 1e-12) {
        return Vec2::ZERO;
    }
    let along = d - d.dot(n) * n;
    let (x, y) = (along.dot(tu), along.dot(tv));
    Vec2::new(c * x - b * y, a * y - b * x) / det
}

/// Where the line through two points `(s, gap)` of the march, `above` (gap > 0) and `below`
/// (gap ≤ 0), crosses zero. (WGSL twin: `secant_crossing`.)
pub fn secant(above: (f32, f32), below: (f32, f32)) -> f32 {
    above.0 + (below.0 - above.0) * (above.1 / (above.1 - below.1))
}

/// The `s` where the gap crosses zero between `above` (gap > 0) and `below` (gap ≤ 0), by
/// [`REFINEMENTS`] secant steps, each keeping the pair that brackets the crossing.
fn crossing(mut above: (f32, f32), mut below: (f32, f32), gap: impl Fn(f32) -> f32) -> f32 {
    for _ in 0..REFINEMENTS {
        let s = secant(above, below);
        let at = (s, gap(s));
        if at.1 > 0.0 {
            above = at;
        } else {
            below = at;
        }
    }
    secant(above, below)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::height::SineField;

    /// A field that is a constant `h`: the ray meets the plane at height `k·h`, `k·h/(−d·n)` along
    /// the ray from the slab's surface, and the texture coordinates move by its tangential part.
    struct Flat(f32);
    impl HeightField for Flat {
        fn height(&self, _: Vec2) -> f32 {
            self.0
        }
        fn default_delta(&self) -> Vec2 {
            Vec2::splat(0.01)
        }
        fn range(&self) -> (f32, f32) {
            (0.0, 1.0)
        }
    }

    #[test]
    fn a_constant_height_moves_the_lookup_back_along_the_ray() {
        let frame = (Vec3::Z, Vec3::X, Vec3::Y);
        let d = Vec3::new(1.0, 0.0, -1.0).normalize();
        // The surface at height 0.1·0.5 = 0.05: met 0.05 before the flat surface along the ray
        // going down at 45°, so 0.05 back in u.
        let uv = parallax_uv(&Flat(0.5), 0.1, Vec2::new(0.3, 0.3), frame, d);
        assert!((uv - Vec2::new(0.25, 0.3)).length() < 1e-5, "{uv}");
        // Straight down, nothing moves; grazing or leaving, nothing either.
        assert_eq!(parallax_uv(&Flat(0.5), 0.1, Vec2::splat(0.3), frame, -Vec3::Z), Vec2::splat(0.3));
        assert_eq!(parallax_uv(&Flat(0.5), 0.1, Vec2::splat(0.3), frame, Vec3::X), Vec2::splat(0.3));
    }

    #[test]
    fn the_crossing_is_on_the_displaced_surface() {
        let field = SineField { amplitude: 1.0, frequency: Vec2::new(3.0, 2.0) };
        let frame = (Vec3::Z, Vec3::X * 2.0, Vec3::Y * 2.0);
        let (k, uv) = (0.05, Vec2::new(0.41, 0.17));
        let d = Vec3::new(0.6, 0.2, -0.5).normalize();
        let hit = parallax_uv(&field, k, uv, frame, d);
        // The point of the ray over `hit` is at the field's height there.
        let s = (hit - uv).x * 2.0 / d.x;
        let height = s * d.z;
        assert!((height - k * field.height(hit)).abs() < 1e-4, "{height} against {}", k * field.height(hit));
    }
}
