//! Bump mapping: perturbing the shading normal with a height field (docs/course/04-bump-mapping.md
//! §1.2; Blinn 1978).
//!
//! The surface is `p = f_p(u, v)` with tangents `t_u = ∂p/∂u`, `t_v = ∂p/∂v` and unit normal `n`;
//! the rough surface is `q = p + f_h(u, v)·n`. Its tangents, dropping the small `f_h·∂n` terms,
//! are `t'_u = t_u + d_u·n` and `t'_v = t_v + d_v·n`, with `d_u = k·∂f_h/∂u`, `d_v = k·∂f_h/∂v`
//! (`k` scales the relief; a negative `k` turns bumps into dents), and the perturbed normal is
//! `n' = normalize(t'_u × t'_v)`, **oriented like `n`**.
//!
//! The derivatives are analytic where the field has them, or central differences:
//! `d_u = k·(f_h(u+Δ, v) − f_h(u−Δ, v))/2Δ`, `d_v = k·(f_h(u, v+Δ) − f_h(u, v−Δ))/2Δ`, error
//! `O(Δ²)`, with `Δ` one texel by default.
//!
//! **Why orient like `n`.** `t'_u × t'_v` is a normal of the rough surface whatever the layout
//! of the texture coordinates; only its sign depends on it. When the texture is mirrored
//! (`u` runs the other way, so `t_u × t_v` points along `−n`; the ray tracer's spheres, boxes and
//! planes are like that, see `SurfaceHit::dpdu`) the cross product points into the surface.
//! Turning it to the side of `n` gives the normal of `p + f_h·n` on the outside: a point where
//! `f_h` is high is still a bump standing out along `n`, lit from the side it faces. Mirroring
//! moves the bumps with the texture, as it should, but never inverts them. (Normal maps are
//! different: they store a direction in the tangent frame, so a mirrored frame must be carried
//! by the bitangent's sign, see [`super::tangents::normal_map_normal`].)
//!
//! Limits: the height is in world units times `k`, so on a larger object with the same texture
//! coordinates (longer `t_u`) the same `k` gives gentler slopes (Blinn's bumps do not scale with
//! the object); the terms in `∂n` are dropped, so the result is exact for flat surfaces only;
//! silhouettes and shadows stay smooth (the geometry does not move).

use glam::{Vec2, Vec3};

use super::height::HeightField;

/// The user's bump settings: the relief scale `k` and the finite-difference step `Δ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BumpParams {
    /// `k`; the material's `bump_scale`.
    pub k: f32,
    /// `Δ` in texture coordinates, per axis; `None` (or a value that is not finite and positive)
    /// uses the field's default, one texel for a texture.
    pub delta: Option<Vec2>,
    /// Use the field's closed-form derivatives where it has them instead of finite differences.
    pub analytic: bool,
}

impl Default for BumpParams {
    fn default() -> Self {
        BumpParams { k: 1.0, delta: None, analytic: false }
    }
}

impl BumpParams {
    /// The `Δ` to use with `field`.
    pub fn delta_for(&self, field: &dyn HeightField) -> Vec2 {
        match self.delta {
            Some(d) if d.is_finite() && d.cmpgt(Vec2::ZERO).all() => d,
            _ => field.default_delta(),
        }
    }
}

/// `(d_u, d_v)` by central differences from the four samples `f(u+Δ, v)`, `f(u−Δ, v)`,
/// `f(u, v+Δ)`, `f(u, v−Δ)`: `k·(f₊ − f₋)/2Δ` per axis. WGSL twin: `bump_central_differences`.
pub fn central_differences(u_plus: f32, u_minus: f32, v_plus: f32, v_minus: f32, delta: Vec2, k: f32) -> Vec2 {
    k * Vec2::new(u_plus - u_minus, v_plus - v_minus) / (2.0 * delta)
}

/// `(d_u, d_v)` of `field` at `uv` by central differences with step `delta`.
pub fn finite_difference_gradient(field: &dyn HeightField, uv: Vec2, delta: Vec2, k: f32) -> Vec2 {
    central_differences(
        field.height(uv + Vec2::new(delta.x, 0.0)),
        field.height(uv - Vec2::new(delta.x, 0.0)),
        field.height(uv + Vec2::new(0.0, delta.y)),
        field.height(uv - Vec2::new(0.0, delta.y)),
        delta,
        k,
    )
}

/// `(d_u, d_v)` of `field` at `uv` as `params` asks: analytic where asked and available, else
/// central differences.
pub fn height_gradient(field: &dyn HeightField, uv: Vec2, params: &BumpParams) -> Vec2 {
    if params.analytic
        && let Some(gradient) = field.gradient(uv)
    {
        return params.k * gradient;
    }
    finite_difference_gradient(field, uv, params.delta_for(field), params.k)
}

/// `n' = normalize((t_u + d_u·n) × (t_v + d_v·n))`, turned to the side of `n`. `n` is unit;
/// `t_u`, `t_v` are `∂p/∂u`, `∂p/∂v` (any length, either handedness). Returns `n` unchanged when
/// the perturbed tangents are degenerate (parallel, zero, or not finite). WGSL twin:
/// `perturbed_normal`.
pub fn perturbed_normal(n: Vec3, tu: Vec3, tv: Vec3, du: f32, dv: f32) -> Vec3 {
    // The tangents are first laid in the plane of n: a smooth-shaded mesh's interpolated n is
    // not perpendicular to its flat facets' tangents, and t'u × t'v would bring the facets back.
    // On analytic surfaces they already lie there, and nothing changes.
    let (tu, tv) = (tu - tu.dot(n) * n, tv - tv.dot(n) * n);
    let m = (tu + du * n).cross(tv + dv * n);
    let length = m.length();
    if !(length > 0.0 && length.is_finite()) {
        return n;
    }
    let perturbed = m / length;
    if perturbed.dot(n) < 0.0 { -perturbed } else { perturbed }
}

/// The bump-mapped normal at `uv` of a surface with normal `n` and tangents `tu`, `tv`: what the
/// ray tracer calls at a hit (`n = hit.normal`, `tu = hit.dpdu`, `tv = hit.dpdv`).
pub fn bump_normal(field: &dyn HeightField, params: &BumpParams, uv: Vec2, n: Vec3, tu: Vec3, tv: Vec3) -> Vec3 {
    let d = height_gradient(field, uv, params);
    perturbed_normal(n, tu, tv, d.x, d.y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::height::SineField;

    #[test]
    fn a_slope_in_u_tilts_the_normal_back_along_u() {
        let n = perturbed_normal(Vec3::Z, Vec3::X, Vec3::Y, 1.0, 0.0);
        assert!(n.abs_diff_eq(Vec3::new(-1.0, 0.0, 1.0).normalize(), 1e-6), "{n}");
        // Zero slope leaves n alone in either handedness.
        assert!(perturbed_normal(Vec3::Z, Vec3::X, Vec3::Y, 0.0, 0.0).abs_diff_eq(Vec3::Z, 1e-7));
        assert!(perturbed_normal(Vec3::Z, -Vec3::X, Vec3::Y, 0.0, 0.0).abs_diff_eq(Vec3::Z, 1e-7));
        // Degenerate tangents keep n.
        assert_eq!(perturbed_normal(Vec3::Z, Vec3::ZERO, Vec3::ZERO, 0.0, 0.0), Vec3::Z);
    }

    #[test]
    fn central_differences_are_exact_for_quadratics_and_scaled_by_k() {
        // f = u² + 3v: f' = (2u, 3); central differences are exact on quadratics.
        let f = |u: f32, v: f32| u * u + 3.0 * v;
        let (u, v, d) = (0.5, 0.25, 0.125);
        let g = central_differences(f(u + d, v), f(u - d, v), f(u, v + d), f(u, v - d), Vec2::splat(d), -2.0);
        assert_eq!(g, Vec2::new(-2.0, -6.0));
    }

    #[test]
    fn analytic_is_used_only_when_asked() {
        let field = SineField { amplitude: 0.1, frequency: Vec2::new(2.0, 1.0) };
        let uv = Vec2::new(0.1, 0.3);
        let analytic = height_gradient(&field, uv, &BumpParams { k: 2.0, delta: None, analytic: true });
        assert_eq!(analytic, 2.0 * field.gradient(uv).expect("sine has a gradient"));
        let delta = Vec2::splat(1e-3);
        let numeric = height_gradient(&field, uv, &BumpParams { k: 2.0, delta: Some(delta), analytic: false });
        assert_eq!(numeric, finite_difference_gradient(&field, uv, delta, 2.0));
        assert!(numeric.abs_diff_eq(analytic, 1e-3));
        // A nonsensical Δ falls back to the default.
        let fallback = BumpParams { k: 1.0, delta: Some(Vec2::new(0.0, 1.0)), analytic: false };
        assert_eq!(fallback.delta_for(&field), field.default_delta());
    }
}
