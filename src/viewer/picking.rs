//! Picking: the object under a clicked pixel, found by casting that pixel's primary ray with the
//! ray tracer's own geometry and accelerator — exact shapes, the same nearest-hit rule, so the
//! object picked is the one both renderers draw there. The same ray gives the direction an
//! environment map is read in at that pixel (the lat–long view's marker).

use glam::{Vec2, Vec3};

use crate::base::Ray;
use crate::scene::Scene;
use crate::trace::accel::{self, AccelKind, Accelerator};
use crate::trace::geometry::{Primitive, scene_primitives};

/// The scene's primitives and a BVH over them, built on the first click after a (re)load.
pub(in crate::viewer) struct Picker {
    primitives: Vec<Primitive>,
    accelerator: Box<dyn Accelerator>,
}

/// What a click found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Picked {
    /// Index into `Scene::objects`.
    pub object: usize,
    /// Index into `Scene::materials`.
    pub material: usize,
}

impl Picker {
    pub fn new(scene: &Scene) -> Picker {
        let primitives = scene_primitives(scene);
        let accelerator = accel::build(AccelKind::Bvh, &primitives);
        Picker { primitives, accelerator }
    }

    /// The nearest object along the primary ray through image point `pixel` (pixel `(i, j)` spans
    /// `[i, i + 1] × [j, j + 1]` of an image of the camera's size).
    pub fn pick(&self, scene: &Scene, pixel: Vec2) -> Option<Picked> {
        let ray = scene.camera.ray_through(pixel.x, pixel.y);
        let hit = self.accelerator.closest(&self.primitives, &ray, 0.0, f32::INFINITY)?;
        let primitive = &self.primitives[hit.primitive as usize];
        Some(Picked { object: primitive.object(), material: primitive.material().0 })
    }

    /// The distance along `ray` to the nearest surface, ∞ where it hits none.
    pub fn nearest(&self, ray: &Ray) -> f32 {
        self.accelerator.closest(&self.primitives, ray, 0.0, f32::INFINITY).map_or(f32::INFINITY, |hit| hit.t)
    }

    /// The direction the environment is seen in at image point `pixel`: `r = reflect(d, n)` at
    /// the surface the primary ray `d` hits there (its shading normal turned to the viewer, as
    /// the shaders turn it), or `d` itself where the ray hits nothing and the world is drawn.
    pub(in crate::viewer) fn seen_direction(&self, scene: &Scene, pixel: Vec2) -> SeenDirection {
        let ray = scene.camera.ray_through(pixel.x, pixel.y);
        let Some(hit) = self.accelerator.closest(&self.primitives, &ray, 0.0, f32::INFINITY) else {
            return SeenDirection { direction: ray.direction, object: None };
        };
        let primitive = &self.primitives[hit.primitive as usize];
        let surface = primitive.surface(&ray, hit.t);
        let n = if surface.normal.dot(ray.direction) > 0.0 { -surface.normal } else { surface.normal };
        let r = ray.direction - 2.0 * ray.direction.dot(n) * n;
        SeenDirection { direction: r.normalize(), object: Some(primitive.object()) }
    }
}

/// What [`Picker::seen_direction`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeenDirection {
    /// Unit, in world space.
    pub direction: Vec3,
    /// The object reflecting it (`Scene::objects`); `None` over the background.
    pub object: Option<usize>,
}
