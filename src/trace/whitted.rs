//! Whitted ray tracing (docs/course/09-ray-tracing.md, `RayTracing` and `EvaluaMILRec`; seeds
//! 003 and 004):
//!
//! ```text
//! RayTracing(o, u, n):  nearest hit p of the ray o + t·u, or the environment L_env(u) if none;
//!   ME + AG + Σ_i V_i·S_i·L_dir(p, v, l_i)
//!      + kps·MPS·RayTracing(p, r, n + 1)      r = 2(n·v)n − v
//!      + kt·MT·RayTracing(p, t, n + 1)        t by Snell's law
//! ```
//!
//! - **Depth.** Primary rays have depth 0; the reflected and refracted rays of a depth-`n` hit
//!   have depth `n + 1` and are traced only while `n < max_depth`, so two facing mirrors end.
//! - **Visibility `V_i`** is a shadow ray towards the light. Opaque occluders block it;
//!   transparent ones (kt > 0) let `kt·MT` through, so shadows behind glass are partial and
//!   coloured (0 < s < 1, docs/course/05-shadows.md#through-glass). Occluders are not refracted: a shadow ray goes straight.
//! - **Alpha (coverage)**, `material.alpha_mode`: `α = alpha ×` the colour texture's alpha at the
//!   hit (linear, filtered like the colour; `super::texture`). *Opaque* ignores `α`. *Mask*: the
//!   surface exists only where `α ≥ cutoff`; camera, mirror, refracted and shadow rays alike go on
//!   from `ε` beyond a hit where `α < cutoff`, along their own direction, as if nothing were there
//!   (the same ray, not counted again; its cone continued). *Blend* is the notes'
//!   transparency (docs/course/06-transparency.md) with `Im` scaled by `α` and `kt·Mt = 1 − α`:
//!
//!   ```text
//!   L = α·(ME + AG + Σ V·L_dir + kps·MPS·L(r) + kt·MT·L(t)) + (1 − α)·L(p, u, n + 1)
//!   ```
//!
//!   the ray continued straight past the surface, one level deeper like a refracted ray (at the
//!   maximum depth the `1 − α` share is dropped, as `kt·MT·L(t)` is). Through a surface covering
//!   `α`, a shadow ray carries `α·kt·MT + (1 − α)`: grey `1 − α` for a blended surface without
//!   kt, 1 through a mask's holes. Shadow rays carry no cone, so they read the texture's alpha at
//!   level 0. A ray gives up after [`MAX_LAYERS`] masked hits (seeing the environment) or occluders.
//! - **Refraction** (`crate::scene::optics`). The side is read from the geometric normal: a ray
//!   against it enters the object (`η = 1/ior`), a ray along it leaves (`η = ior`). With
//!   `sin²θt = η²(1 − cos²θi) > 1` there is total internal reflection: no ray leaves, and the
//!   `kt·MT` energy goes to the reflected direction instead. With `terms.fresnel` the same split
//!   happens at every angle: `F·kt·MT` joins the reflected ray, `(1 − F)·kt·MT` the refracted
//!   one (`F` = 1 on total internal reflection, so the two rules agree there). Shadow rays
//!   through glass carry `kt·MT` unweighted.
//! - **Self-intersection.** Secondary and shadow rays start a small distance off the surface, on
//!   the side they leave towards, along the geometric normal: `ε = 1e-4·max(1, |p|∞)`, which
//!   scales with the scene's coordinates (a fixed ε is too small far from the origin, where
//!   `f32` spacing grows). Rays then accept hits from `t > 0`.
//! - **Textures and bumps** (docs/course/03-mipmaps.md, docs/course/04-bump-mapping.md; `super::texture`). Every ray that can see a
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
//! - **Teaching views** (`settings.bump.view`) replace the radiance of primary hits (of the
//!   nearest surface that is there, blended or not), with no lighting or recursion: `normals`
//!   shows `0.5 + 0.5·n` for the final shading normal (bumped, turned to the viewer), `tangents`
//!   shows `0.5 + 0.5·normalize(∂p/∂u)`.

use glam::Vec3;

use super::accel::{Accelerator, Hit};
use super::explain::{Observer, RayKind, SurfaceState, Unobserved, VolumeState};
use super::geometry::{Primitive, SurfaceHit};
use super::texture::SceneTextures;
use super::volume::{TracedVolumes, heat_colour, voxel_illumination, world_normal};
use crate::base::Ray;
use crate::scene::optics::{fresnel, refract, relative_index};
use crate::scene::shading::{
    SurfaceSample, Terms, direct, direct_terms, emission_and_global_ambient, emitted_and_ambient, facing_viewer,
    lights_surface,
};
use crate::scene::{AlphaMode, Material, Scene};
use crate::settings::{BumpSettings, BumpView, TextureSettings, VolumeView};
use crate::texture::RayCone;

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub primary: u64,
    pub shadow: u64,
    pub reflected: u64,
    /// Rays through a surface: refracted (kt > 0) and continued past a blended surface.
    pub refracted: u64,
    /// Volume samples taken, and those early ray termination saved (not rays: not in `total`).
    pub volume_samples: u64,
    pub volume_samples_saved: u64,
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
        self.volume_samples += o.volume_samples;
        self.volume_samples_saved += o.volume_samples_saved;
    }
}

/// The scene as the tracer sees it: primitives, an accelerator over them, the lights and
/// materials of the scene, and its textures prepared for filtering.
pub struct Whitted<'s> {
    pub scene: &'s Scene,
    pub primitives: Vec<Primitive>,
    pub accelerator: Box<dyn Accelerator>,
    pub terms: Terms,
    /// Weight glass's reflection and transmission by Fresnel's `F` (`terms.fresnel`).
    pub fresnel: bool,
    pub max_depth: u32,
    /// Whether shadow rays are cast; without them every light is visible everywhere.
    pub shadows: bool,
    /// Mip chains and height fields, built once per scene.
    pub textures: SceneTextures,
    pub texture_settings: TextureSettings,
    pub bump: BumpSettings,
    /// The scene's volumes, marched by every ray (`super::volume`).
    pub volumes: TracedVolumes<'s>,
}

/// Where a transparent surface sends its `kt·MT` ([`Whitted::transmission`]).
pub struct Transmission {
    /// The refracted radiance, weighted.
    pub refracted: Vec3,
    /// The weight the reflected ray gains.
    pub reflected_weight: Vec3,
    /// The reflected ray's name where it gains one.
    pub reflected_name: Option<&'static str>,
}

/// The most surfaces one ray passes (masked-out hits, shadow rays through transparent
/// occluders) before it gives up: far more layers than a scene has, and a bound on the loop
/// whatever the geometry.
pub const MAX_LAYERS: usize = 64;

/// How far a new ray starts off the surface it leaves.
pub fn surface_offset(p: Vec3) -> f32 {
    1e-4 * p.abs().max_element().max(1.0)
}

impl Whitted<'_> {
    /// The radiance arriving at `ray.origin` from `ray.direction` (`RayTracing(o, u, n)`); `cone`
    /// is the ray's footprint, for texture filtering.
    pub fn radiance(&self, ray: &Ray, cone: RayCone, depth: u32, counts: &mut RayCounts) -> Vec3 {
        self.radiance_observed(ray, cone, (depth, RayKind::Primary), counts, &mut Unobserved)
    }

    /// [`Self::radiance`] of a primary ray whose nearest hit is `first`, found already (in a
    /// packet of neighbouring pixels' rays, `super::render`). Where the scene has volumes the
    /// hit is found again, among the volumes' isosurfaces.
    pub fn radiance_from_hit(&self, ray: &Ray, cone: RayCone, first: Option<Hit>, counts: &mut RayCounts) -> Vec3 {
        self.radiance_after(ray, cone, || first, (0, RayKind::Primary), counts, &mut Unobserved)
    }

    /// [`Self::radiance`], reporting what it does to `observer` (`super::explain`): the ray of
    /// `kind`, its hit, the terms of its radiance, and the rays it casts.
    pub fn radiance_observed<O: Observer>(
        &self,
        ray: &Ray,
        cone: RayCone,
        depth_kind: (u32, RayKind),
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Vec3 {
        let first = || self.accelerator.closest(&self.primitives, ray, 0.0, f32::INFINITY);
        self.radiance_after(ray, cone, first, depth_kind, counts, observer)
    }

    /// [`Self::radiance_observed`] with the ray's nearest hit given by `first` (asked only where
    /// the scene has no volumes, whose isosurfaces the hit must be found among).
    fn radiance_after<O: Observer>(
        &self,
        ray: &Ray,
        cone: RayCone,
        first: impl FnOnce() -> Option<Hit>,
        (depth, kind): (u32, RayKind),
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Vec3 {
        observer.begin(kind, ray, depth);
        let radiance = if !self.volumes.is_empty() {
            self.radiance_through_volumes(ray, cone, depth, counts, observer)
        } else {
            match self.nearest_surface_from(ray, cone, first(), |_, _| false) {
                Some((surface, moved, cone)) => {
                    observer.hit(&surface, (moved.origin - ray.origin).dot(ray.direction) + surface.t);
                    self.shade(&moved, cone, &surface, depth, counts, observer)
                }
                None => {
                    let environment = self.scene.environment_radiance(ray.direction);
                    observer.term("environment (missed everything)".into(), environment);
                    environment
                }
            }
        };
        observer.end(radiance);
        radiance
    }

    /// `RayTracing(o, u, n)` where the scene has volumes: the nearest surface or isosurface, with
    /// the composited volumes in front of it (`super::volume`).
    fn radiance_through_volumes<O: Observer>(
        &self,
        ray: &Ray,
        cone: RayCone,
        depth: u32,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Vec3 {
        let nearest = self.nearest_surface(ray, cone);
        let t_surface = nearest
            .as_ref()
            .map_or(f32::INFINITY, |(hit, moved, _)| (moved.origin - ray.origin).dot(ray.direction) + hit.t);
        let isosurface = self.volumes.nearest_isosurface(ray, t_surface);
        let t_end = isosurface.as_ref().map_or(t_surface, |hit| hit.t);
        let crossing = self.volumes.composite(ray, t_end, &mut |prepared, t, gradient, colour| {
            // One composited sample: the notes' voxel illumination, with shadow rays when
            // `volume.shadows` is on.
            let p = ray.at(t);
            let normal = world_normal(prepared.normal_from_local, gradient);
            voxel_illumination(self.scene, self.terms, colour, normal, -ray.direction, p, &mut |incidence| {
                if self.volumes.shadows {
                    self.visibility(p, incidence.l, incidence.distance, counts)
                } else {
                    Vec3::ONE
                }
            })
        });
        counts.volume_samples += u64::from(crossing.taken);
        counts.volume_samples_saved += u64::from(crossing.saved);
        let stopped_early = self.volumes.march.termination.is_some_and(|threshold| crossing.alpha >= threshold);
        if O::RECORDS && crossing.crossed {
            observer.volumes(VolumeState {
                samples: crossing.taken,
                saved: crossing.saved,
                alpha: crossing.alpha,
                colour: crossing.colour,
                stopped_early,
            });
            observer.term("volumes composited in front".into(), crossing.colour);
        }
        if depth == 0 && crossing.crossed && self.volumes.view == VolumeView::Samples {
            return heat_colour(crossing.taken);
        }
        if stopped_early {
            return crossing.colour;
        }
        let through = Vec3::splat(1.0 - crossing.alpha);
        observer.scale(through);
        let behind = match (isosurface, nearest) {
            (Some(hit), _) => {
                observer.hit(&hit, hit.t);
                self.shade(ray, cone, &hit, depth, counts, observer)
            }
            (None, Some((surface, moved, cone))) => {
                observer.hit(&surface, (moved.origin - ray.origin).dot(ray.direction) + surface.t);
                self.shade(&moved, cone, &surface, depth, counts, observer)
            }
            (None, None) => {
                let environment = self.scene.environment_radiance(ray.direction);
                observer.term("environment (missed everything)".into(), environment);
                environment
            }
        };
        observer.unscale();
        crossing.colour + through * behind
    }

    /// The level of detail at which the nearest hit of `ray` (carrying `cone`) reads its colour
    /// texture, or `None` if the ray misses or the surface has no texture: the value the shader
    /// uses, for tests and teaching.
    pub fn texture_lod(&self, ray: &Ray, cone: RayCone) -> Option<f32> {
        let (surface, ray, cone) = self.nearest_surface(ray, cone)?;
        let material = &self.scene.materials[surface.material.0];
        self.textures.lod(material, &surface, ray.direction, &cone, &self.texture_settings)
    }

    /// The nearest hit of `ray` on a surface that is there: a hit where a mask leaves no surface
    /// (`α < cutoff`) is passed, the ray going on from just beyond it, its cone continued. Returns
    /// the hit with the ray and the cone that found it (`hit.t` counts from that ray's origin), or
    /// `None` if the ray leaves the scene or passes [`MAX_LAYERS`] masked hits.
    pub(super) fn nearest_surface(&self, ray: &Ray, cone: RayCone) -> Option<(SurfaceHit, Ray, RayCone)> {
        self.nearest_surface_past(ray, cone, |_, _| false)
    }

    /// [`Self::nearest_surface`], passing also the surfaces `passed` says to: the hybrid's terms
    /// look past transparent surfaces and the object a view looks out of (`super::terms`).
    pub(super) fn nearest_surface_past(
        &self,
        ray: &Ray,
        cone: RayCone,
        passed: impl Fn(&SurfaceHit, &Material) -> bool,
    ) -> Option<(SurfaceHit, Ray, RayCone)> {
        let first = self.accelerator.closest(&self.primitives, ray, 0.0, f32::INFINITY);
        self.nearest_surface_from(ray, cone, first, passed)
    }

    /// [`Self::nearest_surface_past`] for a ray whose nearest hit `first` is known (traced in a
    /// packet, `super::render`).
    fn nearest_surface_from(
        &self,
        ray: &Ray,
        cone: RayCone,
        first: Option<Hit>,
        passed: impl Fn(&SurfaceHit, &Material) -> bool,
    ) -> Option<(SurfaceHit, Ray, RayCone)> {
        let (mut ray, mut cone) = (*ray, cone);
        for layer in 0..MAX_LAYERS {
            let hit = match layer {
                0 => first,
                _ => self.accelerator.closest(&self.primitives, &ray, 0.0, f32::INFINITY),
            }?;
            let surface = self.primitives[hit.primitive as usize].surface(&ray, hit.t);
            let material = &self.scene.materials[surface.material.0];
            let masked_out = match material.alpha_mode {
                AlphaMode::Mask { cutoff } => {
                    self.textures.coverage(material, &surface, ray.direction, Some(&cone), &self.texture_settings)
                        < cutoff
                }
                AlphaMode::Opaque | AlphaMode::Blend => false,
            };
            if !masked_out && !passed(&surface, material) {
                return Some((surface, ray, cone));
            }
            let step = hit.t + surface_offset(surface.point);
            ray.origin = ray.at(step);
            cone = cone.continued(step);
        }
        None
    }

    /// The radiance leaving the hit towards the viewer. A blended surface (`AlphaMode::Blend`)
    /// covers a fraction `α` of the ray: `α·(the surface's own radiance) + (1 − α)·L(the ray
    /// continued straight through)`, the continuation one level deeper like a refracted ray.
    pub(super) fn shade<O: Observer>(
        &self,
        ray: &Ray,
        cone: RayCone,
        hit: &SurfaceHit,
        depth: u32,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Vec3 {
        let material = &self.scene.materials[hit.material.0];
        let v = -ray.direction;
        // Parallax mapping shades the point of the relief the ray meets first.
        let parallaxed = self.textures.parallaxed(material, hit, ray.direction, &self.bump);
        let hit = parallaxed.as_ref().unwrap_or(hit);
        // The teaching views show the nearest surface itself, blended or not.
        if depth == 0 {
            let shown = match self.bump.view {
                BumpView::Off | BumpView::Tessellation => None,
                BumpView::Normals => Some(0.5 + 0.5 * self.shading_normal(material, hit, v)),
                BumpView::Tangents => Some(0.5 + 0.5 * hit.dpdu.normalize_or_zero()),
            };
            if let Some(shown) = shown {
                observer.term("bump mapping's teaching view".into(), shown);
                return shown;
            }
        }
        let alpha = self.blended_coverage(ray, cone, hit);
        let mut rad = Vec3::ZERO;
        if alpha > 0.0 {
            observer.scale(Vec3::splat(alpha));
            rad += alpha * self.shade_surface(ray, cone, hit, depth, counts, observer);
            observer.unscale();
        }
        if alpha < 1.0 && depth < self.max_depth {
            rad += self.behind(ray, cone, hit, (depth, alpha), counts, observer);
        }
        rad
    }

    /// `α`, the share of `ray` a blended surface covers at `hit` (1 for any other surface).
    pub(super) fn blended_coverage(&self, ray: &Ray, cone: RayCone, hit: &SurfaceHit) -> f32 {
        let material = &self.scene.materials[hit.material.0];
        match material.alpha_mode {
            AlphaMode::Blend => self
                .textures
                .coverage(material, hit, ray.direction, Some(&cone), &self.texture_settings)
                .clamp(0.0, 1.0),
            AlphaMode::Opaque | AlphaMode::Mask { .. } => 1.0,
        }
    }

    /// `(1 − α)·L`, `L` the radiance of `ray` continued straight past a blended surface it hit at
    /// `depth` that covers `α` of it.
    pub(super) fn behind<O: Observer>(
        &self,
        ray: &Ray,
        cone: RayCone,
        hit: &SurfaceHit,
        (depth, alpha): (u32, f32),
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Vec3 {
        counts.refracted += 1;
        let origin = hit.point - surface_offset(hit.point) * facing_viewer(hit.geometric_normal, -ray.direction);
        let behind = Ray { origin, direction: ray.direction };
        let kind = (depth + 1, RayKind::Continued);
        let through = self.radiance_observed(&behind, cone.continued(hit.t), kind, counts, observer);
        observer.term(format!("behind the blended surface × (1 − α), α = {alpha:.3}"), (1.0 - alpha) * through);
        (1.0 - alpha) * through
    }

    /// `EvaluaMILRec`: the local model at the hit plus the mirror and transmission terms.
    fn shade_surface<O: Observer>(
        &self,
        ray: &Ray,
        cone: RayCone,
        hit: &SurfaceHit,
        depth: u32,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Vec3 {
        let material = &self.scene.materials[hit.material.0];
        let v = -ray.direction;
        let n = self.shading_normal(material, hit, v);
        let color = self.textures.colour(material, hit, ray.direction, &cone, &self.texture_settings);
        let sample = SurfaceSample::new(material, color);
        if O::RECORDS {
            observer.surface(SurfaceState {
                uv: hit.uv,
                lod: self.textures.lod(material, hit, ray.direction, &cone, &self.texture_settings),
                footprint: cone.width_at(hit.t),
                colour: color,
                alpha: material.alpha,
                geometric_normal: hit.geometric_normal,
                normal: n,
                bump: self.textures.bump_slopes(material, hit, &self.bump),
            });
            let (emission, global) = emission_and_global_ambient(&sample, self.scene.ambient, self.terms);
            observer.term("emission ME".into(), emission);
            observer.term("global ambient AG = A·kd·C".into(), global);
        }
        // The geometric normal on the viewer's side: secondary rays leave along it or against it.
        let outside = facing_viewer(hit.geometric_normal, v);
        let offset = surface_offset(hit.point);

        let mut rad = emitted_and_ambient(&sample, self.scene.ambient, self.terms);
        for (index, light) in self.scene.lights.iter().enumerate() {
            let Some(incidence) = light.incidence(hit.point) else { continue };
            if !lights_surface(n, incidence.l, sample.ka, self.terms) {
                continue;
            }
            let origin = hit.point + offset * outside;
            let towards = (incidence.l, incidence.distance);
            let visibility = self.visibility_observed((index, depth), origin, towards, counts, observer);
            if O::RECORDS {
                observer.light(index, visibility, direct_terms(&sample, n, v, &incidence, self.terms));
            }
            if visibility != Vec3::ZERO {
                rad += visibility * direct(&sample, n, v, &incidence, self.terms);
            }
        }
        if depth >= self.max_depth {
            return rad;
        }
        let cone = cone.continued(hit.t);
        let transmission = self.transmission((hit, n, v), cone, depth, counts, observer);
        rad += transmission.refracted;
        let reflect_weight = material.mirror * material.mirror_color + transmission.reflected_weight;
        if reflect_weight != Vec3::ZERO {
            let name = transmission.reflected_name.unwrap_or("mirror kps·MPS·L(r)");
            rad += self.reflected((hit, n, v), cone, depth, (counts, observer), (reflect_weight, name));
        }
        rad
    }

    /// `weight·L(r)`, `L(r)` the radiance along the mirror direction `r = 2(n·v)n − v` of a hit at
    /// `depth` (its ray starting just off the surface, on the viewer's side), reported as `name`.
    pub(super) fn reflected<O: Observer>(
        &self,
        (hit, n, v): (&SurfaceHit, Vec3, Vec3),
        cone: RayCone,
        depth: u32,
        (counts, observer): (&mut RayCounts, &mut O),
        (weight, name): (Vec3, &str),
    ) -> Vec3 {
        counts.reflected += 1;
        let origin = hit.point + surface_offset(hit.point) * facing_viewer(hit.geometric_normal, v);
        let kind = (depth + 1, RayKind::Reflected);
        let direction = 2.0 * n.dot(v) * n - v;
        let mirrored = self.radiance_observed(&Ray { origin, direction }, cone, kind, counts, observer);
        observer.term(name.into(), weight * mirrored);
        weight * mirrored
    }

    /// Where a transparent surface's `kt·MT` goes (none for others): the refracted radiance,
    /// weighted (`(1 − F)·kt·MT·L(t)` with Fresnel, `kt·MT·L(t)` without), and the weight it adds
    /// to the reflected ray (`F·kt·MT`, or all of `kt·MT` on total internal reflection) with that
    /// ray's name.
    pub(super) fn transmission<O: Observer>(
        &self,
        (hit, n, v): (&SurfaceHit, Vec3, Vec3),
        cone: RayCone,
        depth: u32,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Transmission {
        let material = &self.scene.materials[hit.material.0];
        let mut out = Transmission { refracted: Vec3::ZERO, reflected_weight: Vec3::ZERO, reflected_name: None };
        if !(material.transmission > 0.0) {
            return out;
        }
        let weight = material.transmission * material.transmission_color;
        // Fresnel splits kt·MT between the two directions; without it, all goes on through.
        let reflectance =
            if self.fresnel { fresnel(n.dot(v), relative_index(v, hit.geometric_normal, material.ior)) } else { 0.0 };
        match refract(v, hit.geometric_normal, n, material.ior) {
            Some(t) => {
                counts.refracted += 1;
                let origin = hit.point - surface_offset(hit.point) * facing_viewer(hit.geometric_normal, v);
                let kind = (depth + 1, RayKind::Refracted);
                let through = self.radiance_observed(&Ray { origin, direction: t }, cone, kind, counts, observer);
                let (name, weight_t) = if self.fresnel {
                    (format!("transmitted (1 − F)·kt·MT·L(t), F = {reflectance:.4}"), (1.0 - reflectance) * weight)
                } else {
                    ("transmitted kt·MT·L(t)".to_string(), weight)
                };
                observer.term(name, weight_t * through);
                out.refracted = weight_t * through;
                if reflectance > 0.0 {
                    out.reflected_weight = reflectance * weight;
                    out.reflected_name = Some("mirror kps·MPS·L(r), and F·kt·MT·L(r) by Fresnel");
                }
            }
            None => {
                out.reflected_weight = weight;
                out.reflected_name = Some("mirror kps·MPS·L(r), and kt·MT·L(r) by total internal reflection");
            }
        }
        out
    }

    /// The shading normal at the hit: bumped on the unturned normal, then turned to the viewer
    /// `v`, exactly as the rasterizer does.
    pub(super) fn shading_normal(&self, material: &Material, hit: &SurfaceHit, v: Vec3) -> Vec3 {
        facing_viewer(self.textures.shading_normal(material, hit, &self.bump), v)
    }

    /// `V_i`: the fraction of a light's radiance that reaches `origin` along `l` over `distance`:
    /// the product, over the surfaces the shadow ray crosses, of what each lets through. A
    /// surface covering a fraction `α` of the ray lets `α·kt·MT + (1 − α)` through: 0 for an
    /// opaque occluder, `kt·MT` for glass, 1 where a mask leaves no surface, and
    /// `1 − α` more through a blended one. Coverage is read at level 0: shadow rays carry no cone.
    pub fn visibility(&self, origin: Vec3, l: Vec3, distance: f32, counts: &mut RayCounts) -> Vec3 {
        self.visibility_observed((0, 0), origin, (l, distance), counts, &mut Unobserved)
    }

    /// [`Self::visibility`] of light `light` from a surface hit at `depth`, reporting the shadow
    /// ray and its occluders.
    fn visibility_observed<O: Observer>(
        &self,
        (light, depth): (usize, u32),
        origin: Vec3,
        (l, distance): (Vec3, f32),
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Vec3 {
        if !self.shadows {
            return Vec3::ONE;
        }
        let mut ray = Ray { origin, direction: l };
        observer.begin(RayKind::Shadow, &ray, depth);
        observer.towards(light);
        let mut transmitted = Vec3::ONE;
        let mut remaining = distance;
        // Each surface passed restarts the ray beyond it.
        for _ in 0..MAX_LAYERS {
            counts.shadow += 1;
            let Some(hit) = self.accelerator.closest(&self.primitives, &ray, 0.0, remaining) else { break };
            let primitive = &self.primitives[hit.primitive as usize];
            let material = &self.scene.materials[primitive.material().0];
            let coverage = || {
                let surface = primitive.surface(&ray, hit.t);
                self.textures.coverage(material, &surface, ray.direction, None, &self.texture_settings)
            };
            let alpha = match material.alpha_mode {
                AlphaMode::Mask { cutoff } if coverage() < cutoff => 0.0,
                AlphaMode::Opaque | AlphaMode::Mask { .. } => 1.0,
                AlphaMode::Blend => coverage().clamp(0.0, 1.0),
            };
            let through = alpha * material.transmission * material.transmission_color + Vec3::splat(1.0 - alpha);
            if O::RECORDS {
                let mut surface = primitive.surface(&ray, hit.t);
                surface.t = (ray.origin - origin).dot(l) + hit.t;
                observer.occluder(&surface, through);
            }
            transmitted *= through;
            if transmitted == Vec3::ZERO {
                break;
            }
            let p = ray.at(hit.t);
            let step = hit.t + surface_offset(p);
            ray.origin = ray.at(step);
            remaining -= step;
            if remaining <= 0.0 {
                break;
            }
        }
        observer.end(transmitted);
        transmitted
    }
}
