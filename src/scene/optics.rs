//! Light crossing a smooth interface between two media (docs/course/06-transparency.md): Snell's
//! law for the direction it goes on in, Fresnel's equations for how much of it is reflected
//! instead. The tracer follows these rays; the rasterizer's twin is
//! `shaders/common/optics.wgsl`, and `tests/refraction.rs` runs both on hand-computed cases.
//!
//! Both functions take the view vector `v` (unit, pointing away from the surface, towards where
//! the light goes) and the interface's outward geometric normal: which side `v` is on says
//! whether the ray enters the object (`η = n_i/n_t = 1/ior`) or leaves it (`η = ior`).

use glam::Vec3;

/// The relative index `η = n_i/n_t` for a ray seen along `v` at a surface with outward
/// geometric normal `geometric`: `1/ior` entering (`v` on the outside), `ior` leaving.
pub fn relative_index(v: Vec3, geometric: Vec3, ior: f32) -> f32 {
    if v.dot(geometric) > 0.0 { 1.0 / ior } else { ior }
}

/// The refracted direction of `v` at a surface with outward geometric normal `geometric` and
/// shading normal `n` (facing `v`), by Snell's law `sin θt = η·sin θi`; `None` on total
/// internal reflection (`η·sin θi > 1`).
pub fn refract(v: Vec3, geometric: Vec3, n: Vec3, ior: f32) -> Option<Vec3> {
    let eta = relative_index(v, geometric, ior);
    let cos_i = n.dot(v).clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-eta * v + (eta * cos_i - cos_t) * n).normalize())
}

/// Fresnel's reflectance `F` of a smooth dielectric interface for unpolarized light: the mean of
/// the exact equations for the two polarizations,
///
/// ```text
/// r_s = (η·cos θi − cos θt) / (η·cos θi + cos θt)     r_p = (cos θi − η·cos θt) / (cos θi + η·cos θt)
/// F = (r_s² + r_p²) / 2
/// ```
///
/// for light meeting it at `cos_i = cos θi` from the side of relative index `eta` (`η = n_i/n_t`);
/// 1 on total internal reflection, 0 when `η = 1` (no interface). Head-on through glass (ior 1.5)
/// `F = ((1 − 1.5)/(1 + 1.5))² = 0.04`; at Brewster's angle `r_p = 0`.
pub fn fresnel(cos_i: f32, eta: f32) -> f32 {
    if eta == 1.0 {
        return 0.0;
    }
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_s = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_p = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_s * r_s + r_p * r_p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snell_bends_towards_the_normal_entering_glass() {
        // 45° incidence onto glass (ior 1.5): sin θt = sin 45° / 1.5.
        let v = Vec3::new(-1.0, 1.0, 0.0).normalize();
        let t = refract(v, Vec3::Y, Vec3::Y, 1.5).unwrap();
        let sin_t = t.x.abs();
        assert!((sin_t - 45f32.to_radians().sin() / 1.5).abs() < 1e-6);
        assert!(t.y < 0.0 && t.x > 0.0, "the ray goes on into the glass: {t}");
    }

    #[test]
    fn total_internal_reflection_past_the_critical_angle() {
        // Leaving glass: critical angle asin(1/1.5) ≈ 41.81°.
        let critical = (1.0f32 / 1.5).asin();
        let inside_normal = Vec3::NEG_Y; // the shading normal faces v, which is inside
        for (angle, escapes) in [(critical - 0.01, true), (critical + 0.01, false)] {
            let v = Vec3::new(-angle.sin(), -angle.cos(), 0.0);
            assert_eq!(refract(v, Vec3::Y, inside_normal, 1.5).is_some(), escapes, "at {} degrees", angle.to_degrees());
            assert_eq!(
                fresnel(angle.cos(), relative_index(v, Vec3::Y, 1.5)) == 1.0,
                !escapes,
                "F = 1 exactly when no ray leaves"
            );
        }
    }

    #[test]
    fn index_one_passes_straight_through() {
        let v = Vec3::new(0.3, 0.8, -0.2).normalize();
        let t = refract(v, Vec3::Y, Vec3::Y, 1.0).unwrap();
        assert!(t.abs_diff_eq(-v, 1e-6));
        assert_eq!(fresnel(v.y, 1.0), 0.0, "no interface, nothing reflected");
    }
}
