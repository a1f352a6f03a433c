//! The ray-traced reference: a CPU Whitted ray tracer of the same `Scene` the rasterizer draws,
//! through the same camera (primary rays through pixel centres, `scene/camera.rs`), the same
//! illumination model (`scene/shading.rs`) and the same output transform (`output.rs`), so the
//! two images are pixel-aligned and comparable.
//!
//! - [`geometry`]: world-space primitives, exact intersections, hit records.
//! - [`accel`]: BVH, uniform grid, octree and brute force, which agree on every hit.
//! - [`whitted`]: the recursion of docs/course/09-ray-tracing.md.
//! - [`texture`]: mip-mapped texture lookups with ray cones, and bump mapping (§2, §3).
//! - [`sampling`]: anti-aliasing (centre, regular, jittered, corner rays, adaptive).
//! - [`render`]: tiles over threads, progress, cancellation, statistics, progressive refinement.
//!
//! Where the two renderers should differ, and why: spheres, tori and rounded boxes are exact
//! here and tessellated in the rasterizer (silhouettes differ by up to the tessellation error);
//! the rasterizer approximates what rays do exactly here (shadow maps for shadow rays, a
//! mirrored camera or a cube map for reflected rays, two refractions found in screen space for
//! refracted ones; docs/architecture.md lists each technique's assumption); only `center`
//! sampling looks at the same points the rasterizer does; textures pick their mip level from
//! ray cones here and from screen derivatives there (the same level on a surface facing the
//! camera, see `texture`).

pub mod accel;
pub mod explain;
pub mod geometry;
pub mod render;
pub mod sampling;
pub mod terms;
pub mod texture;
pub mod volume;
pub mod whitted;

use glam::{Vec2, Vec3};

use crate::scene::camera::CameraRays;
use crate::scene::{Camera, Projection, Scene};
use crate::settings::{RenderSettings, TraceSettings};
use crate::texture::RayCone;
pub use render::{Cancelled, Progressive, RadianceImage, RenderControl, TraceStats};
use texture::SceneTextures;
use whitted::{RayCounts, Whitted};

/// A scene prepared for tracing: primitives, an accelerator and texture mip chains, built once.
pub struct Tracer<'s> {
    pub scene: &'s Scene,
    pub settings: TraceSettings,
    /// The output transform: adaptive anti-aliasing measures differences after it.
    pub output: crate::output::OutputTransform,
    pub whitted: Whitted<'s>,
    /// The ray cone every primary ray carries (one pixel, see [`primary_cone`]).
    pub primary_cone: RayCone,
    /// The camera's primary rays.
    pub primary_rays: CameraRays,
}

/// The footprint of one pixel as a ray cone: the angle a pixel subtends for a perspective
/// camera, a pixel's width (window width / image width) for an orthographic one.
pub fn primary_cone(camera: &Camera) -> RayCone {
    match camera.projection {
        Projection::Perspective => RayCone::perspective(camera.fovy_degrees.to_radians(), camera.height),
        Projection::Orthographic => RayCone::orthographic(camera.window().0 / camera.width.max(1) as f32),
    }
}

impl<'s> Tracer<'s> {
    pub fn new(scene: &'s Scene, settings: &RenderSettings) -> Tracer<'s> {
        let primitives = geometry::scene_primitives(scene);
        let accelerator = accel::build(settings.trace.accelerator, &primitives);
        Tracer {
            scene,
            settings: settings.trace.clone(),
            output: crate::output::OutputTransform::of(settings),
            whitted: Whitted {
                scene,
                primitives,
                accelerator,
                terms: settings.terms.into(),
                fresnel: settings.terms.fresnel,
                max_depth: settings.trace.max_depth,
                shadows: settings.shadows.enabled,
                textures: SceneTextures::new(scene),
                texture_settings: settings.textures,
                bump: settings.bump,
                volumes: volume::TracedVolumes::new(scene, &settings.volume),
            },
            primary_cone: primary_cone(&scene.camera),
            primary_rays: scene.camera.rays(),
        }
    }

    /// The radiance seen through image point `p` (pixel `(i, j)` spans `[i, i+1] × [j, j+1]`).
    pub fn primary(&self, p: Vec2, counts: &mut RayCounts) -> Vec3 {
        counts.primary += 1;
        let ray = self.primary_rays.through(p.x, p.y);
        self.whitted.radiance(&ray, self.primary_cone, 0, counts)
    }

    /// Traces the primary ray through the centre of pixel `(x, y)`, reporting every ray and term
    /// to `observer` (`explain`); returns the radiance, as the image has it with `center`
    /// sampling.
    pub fn explain_pixel(&self, (x, y): (u32, u32), observer: &mut impl explain::Observer) -> Vec3 {
        let mut counts = RayCounts::default();
        counts.primary += 1;
        let ray = self.primary_rays.through(x as f32 + 0.5, y as f32 + 0.5);
        let kind = (0, explain::RayKind::Primary);
        self.whitted.radiance_observed(&ray, self.primary_cone, kind, &mut counts, observer)
    }

    pub fn accelerator_stats(&self) -> accel::AccelStats {
        self.whitted.accelerator.stats()
    }
}

/// Traces `scene` with `settings` and returns the sRGB image (no progress bar, no cancellation).
pub fn render_image(scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    let tracer = Tracer::new(scene, settings);
    let (radiance, _) = tracer.render(&RenderControl::default()).expect("nothing can cancel this render");
    radiance.to_rgba8(crate::output::OutputTransform::of(settings))
}
