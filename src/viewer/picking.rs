//! Picking: the object under a clicked pixel, found by casting that pixel's primary ray with the
//! ray tracer's own geometry and accelerator — exact shapes, the same nearest-hit rule, so the
//! object picked is the one both renderers draw there.

use glam::Vec2;

use crate::scene::Scene;
use crate::trace::accel::{self, AccelKind, Accelerator};
use crate::trace::geometry::{Primitive, scene_primitives};

/// The scene's primitives and a BVH over them, built on the first click after a (re)load.
pub struct Picker {
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
}
