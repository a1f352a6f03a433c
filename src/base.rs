//! The words every part of the CPU scene speaks: a [`Ray`] `o + t·d`, and the indices that name a
//! scene's materials and textures ([`MaterialId`], [`TextureId`]).
//!
//! They sit below both `scene` and `volume` (docs/architecture.md, "Layers"): a volume marches the
//! camera's rays and names its isosurface's material, and the scene holds volumes, so if these
//! types lived in `scene` the two modules would import each other. Here they import nothing of
//! Mirador, and `volume` is the math of voxel grids below the scene that holds them.

use glam::Vec3;

/// A ray `o + t·d`, with `d` of unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
}

impl Ray {
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }
}

/// Index into [`crate::scene::Scene::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId(pub usize);

/// Index into [`crate::scene::Scene::textures`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct TextureId(pub usize);
