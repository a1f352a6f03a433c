//! Whitted ray tracing (TECHNIQUES.md §7; seed 000 §2, `RayTracing` and `EvaluaMILRec`; seeds
//! 003 and 004):
//!
//! ```text
//! RayTracing(o, u, n):  nearest hit p of the ray o + t·u, or the background if none;
//!   ME + AG + Σ_i V_i·S_i·L_dir(p, v, l_i)
//!      + kps·MPS·RayTracing(p, r, n + 1)      r = 2(n·v)n − v
//!      + kt·MT·RayTracing(p, t, n + 1)        t by Snell's law
//! ```
//!
//! - **Depth.** Primary rays have depth 0; the reflected and refracted rays of a depth-`n` hit
//!   have depth `n + 1` and are traced only while `n < max_depth`, so two facing mirrors end.
//! - **Visibility `V_i`** is a shadow ray towards the light. Opaque occluders block it;
//!   transparent ones (kt > 0) let `kt·MT` through, so shadows behind glass are partial and
//!   coloured (seed 003: 0 < s < 1). Occluders are not refracted: a shadow ray goes straight.
//! - **Refraction.** The side is read from the geometric normal: a ray against it enters the
//!   object (`η = 1/ior`), a ray along it leaves (`η = ior`). With `sin²θt = η²(1 − cos²θi) > 1`
//!   there is total internal reflection: no ray leaves, and the `kt·MT` energy goes to the
//!   reflected direction instead.
//! - **Self-intersection.** Secondary and shadow rays start a small distance off the surface, on
//!   the side they leave towards, along the geometric normal: `ε = 1e-4·max(1, |p|∞)`, which
//!   scales with the scene's coordinates (a fixed ε is too small far from the origin, where
//!   `f32` spacing grows). Rays then accept hits from `t > 0`.
//! - **Textures and bumps** (TECHNIQUES.md §2, §3; `super::texture`). Every ray that can see a
//!   texture carries a [`RayCone`]: the primary ray the camera's, the mirror and refracted rays
//!   that cone continued from the hit, so a texture seen in a mirror is filtered for its whole
//!   path length; shadow rays carry none. The bump-mapped normal `n'` replaces the shading normal
//!   in the local model and in the mirror and refraction directions, but not in the
//!   self-intersection offset, which follows the geometric surface the ray actually leaves.
//!   `n'` is built on the unturned `hit.normal` and then turned to the viewer
//!   (`facing_viewer(n', v)`, as the rasterizer's fragment shader does), so a plane seen from
//!   below shows the same relief as from above, mirrored: a bump from the front is a dent from
//!   the back. (Where a bump tilts `n'` past the view direction, at grazing angles, the turn
//!   flips it; both renderers do the same.)
//! - **Teaching views** (`settings.bump.view`) replace the radiance of primary hits, with no
//!   lighting or recursion: `normals` shows `0.5 + 0.5·n` for the final shading normal (bumped,
//!   turned to the viewer), `tangents` shows `0.5 + 0.5·normalize(∂p/∂u)`.

use glam::Vec3;

use super::accel::Accelerator;
use super::geometry::{Primitive, SurfaceHit};
use super::texture::SceneTextures;
use crate::scene::shading::{SurfaceSample, Terms, direct, emitted_and_ambient, facing_viewer};
use crate::scene::{Ray, Scene};
use crate::settings::{BumpSettings, BumpView, TextureSettings};
use crate::texture::RayCone;

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub primary: u64,
    pub shadow: u64,
    pub reflected: u64,
    pub refracted: u64,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.reflected + self.refracted
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.reflected += o.reflected;
        self.refracted += o.refracted;
    }
}

/// The scene as the tracer sees it: primitives, an accelerator over them, the lights and
/// materials of the scene, and its textures prepared for filtering.
pub struct Whitted<'s> {
    pub scene: &'s Scene,
    pub primitives: Vec<Primitive>,
    pub accelerator: Box<dyn Accelerator>,
    pub terms: Terms,
    pub max_depth: u32,
    /// Whether shadow rays are cast; without them every light is visible everywhere.
    pub shadows: bool,
    /// Mip chains and height fields, built once per scene.
    pub textures: SceneTextures,
    pub texture_settings: TextureSettings,
    pub bump: BumpSettings,
}

/// How far a new ray starts off the surface it leaves.
pub fn surface_offset(p: Vec3) -> f32 {
    1e-4 * p.abs().max_element().max(1.0)
}

impl Whitted<'_> {
    /// The radiance arriving at `ray.origin` from `ray.direction` (`RayTracing(o, u, n)`); `cone`
    /// is the ray's footprint, for texture filtering.
    pub fn radiance(&self, ray: &Ray, cone: RayCone, depth: u32, counts: &mut RayCounts) -> Vec3 {
        let Some(hit) = self.accelerator.closest(&self.primitives, ray, 0.0, f32::INFINITY) else {
            return self.scene.background;
        };
        let surface = self.primitives[hit.primitive as usize].surface(ray, hit.t);
        self.shade(ray, cone, &surface, depth, counts)
    }

    /// The level of detail at which the nearest hit of `ray` (carrying `cone`) reads its colour
    /// texture, or `None` if the ray misses or the surface has no texture: the value the shader
    /// uses, for tests and teaching.
    pub fn texture_lod(&self, ray: &Ray, cone: RayCone) -> Option<f32> {
        let hit = self.accelerator.closest(&self.primitives, ray, 0.0, f32::INFINITY)?;
        let surface = self.primitives[hit.primitive as usize].surface(ray, hit.t);
        let material = &self.scene.materials[surface.material.0];
        self.textures.lod(material, &surface, ray.direction, &cone, &self.texture_settings)
    }

    /// `EvaluaMILRec`: the local model at the hit plus the mirror and transmission terms.
    fn shade(&self, ray: &Ray, cone: RayCone, hit: &SurfaceHit, depth: u32, counts: &mut RayCounts) -> Vec3 {
        let material = &self.scene.materials[hit.material.0];
        let v = -ray.direction;
        // Bumped on the unturned normal, then turned to the viewer, exactly as the rasterizer.
        let n = facing_viewer(self.textures.shading_normal(material, hit, &self.bump), v);
        if depth == 0 {
            match self.bump.view {
                BumpView::Off => {}
                BumpView::Normals => return 0.5 + 0.5 * n,
                BumpView::Tangents => return 0.5 + 0.5 * hit.dpdu.normalize_or_zero(),
            }
        }
        let color = self.textures.colour(material, hit, ray.direction, &cone, &self.texture_settings);
        let sample = SurfaceSample::new(material, color);
        // The geometric normal on the viewer's side: secondary rays leave along it or against it.
        let outside = facing_viewer(hit.geometric_normal, v);
        let offset = surface_offset(hit.point);

        let mut rad = emitted_and_ambient(&sample, self.scene.ambient, self.terms);
        for light in &self.scene.lights {
            let Some(incidence) = light.incidence(hit.point) else { continue };
            let unlit = incidence.l.dot(n) <= 0.0 && (sample.ka == 0.0 || !self.terms.ambient);
            if unlit {
                continue;
            }
            let visibility = self.visibility(hit.point + offset * outside, incidence.l, incidence.distance, counts);
            if visibility != Vec3::ZERO {
                rad += visibility * direct(&sample, n, v, &incidence, self.terms);
            }
        }
        if depth >= self.max_depth {
            return rad;
        }
        let reflected = 2.0 * n.dot(v) * n - v;
        let cone = cone.continued(hit.t);
        let mut reflect_weight = material.mirror * material.mirror_color;
        if material.transmission > 0.0 {
            let weight = material.transmission * material.transmission_color;
            match refract(v, hit.geometric_normal, n, material.ior) {
                Some(t) => {
                    counts.refracted += 1;
                    let origin = hit.point - offset * outside;
                    rad += weight * self.radiance(&Ray { origin, direction: t }, cone, depth + 1, counts);
                }
                None => reflect_weight += weight,
            }
        }
        if reflect_weight != Vec3::ZERO {
            counts.reflected += 1;
            let origin = hit.point + offset * outside;
            rad += reflect_weight * self.radiance(&Ray { origin, direction: reflected }, cone, depth + 1, counts);
        }
        rad
    }

    /// `V_i`: the fraction of a light's radiance that reaches `origin` along `l` over `distance`:
    /// 0 behind an opaque occluder, the product of `kt·MT` over transparent ones (seed 003).
    pub fn visibility(&self, origin: Vec3, l: Vec3, distance: f32, counts: &mut RayCounts) -> Vec3 {
        if !self.shadows {
            return Vec3::ONE;
        }
        let mut transmitted = Vec3::ONE;
        let mut ray = Ray { origin, direction: l };
        let mut remaining = distance;
        // Each transparent surface passed restarts the ray beyond it; 64 is far more layers than a
        // scene has, and bounds the loop whatever the geometry.
        for _ in 0..64 {
            counts.shadow += 1;
            let Some(hit) = self.accelerator.closest(&self.primitives, &ray, 0.0, remaining) else {
                return transmitted;
            };
            let material = &self.scene.materials[self.primitives[hit.primitive as usize].material().0];
            if material.transmission <= 0.0 {
                return Vec3::ZERO;
            }
            transmitted *= material.transmission * material.transmission_color;
            let p = ray.at(hit.t);
            let step = hit.t + surface_offset(p);
            ray.origin = ray.at(step);
            remaining -= step;
            if remaining <= 0.0 || transmitted == Vec3::ZERO {
                return transmitted;
            }
        }
        transmitted
    }
}

/// The refracted direction of the view vector `v` (unit, pointing away from the surface) at a
/// surface with outward geometric normal `geometric` and shading normal `n` (facing `v`), or
/// `None` on total internal reflection.
pub fn refract(v: Vec3, geometric: Vec3, n: Vec3, ior: f32) -> Option<Vec3> {
    let entering = v.dot(geometric) > 0.0;
    let eta = if entering { 1.0 / ior } else { ior };
    let cos_i = n.dot(v).clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-eta * v + (eta * cos_i - cos_t) * n).normalize())
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
        }
    }

    #[test]
    fn index_one_passes_straight_through() {
        let v = Vec3::new(0.3, 0.8, -0.2).normalize();
        let t = refract(v, Vec3::Y, Vec3::Y, 1.0).unwrap();
        assert!(t.abs_diff_eq(-v, 1e-6));
    }
}
