//! The terms of the illumination model (docs/course/02-illumination.md), each drawn or left out: teaching
//! toggles; and Fresnel's weighting of glass (docs/course/06-transparency.md#fresnel).

use super::field::section;

section! {
    /// Which terms of the illumination model are drawn.
    #[derive(Copy, Eq)]
    pub struct TermSettings {
        /// The ambient terms: the global `AG = A ⊗ kd·C` and each light's `ka·C`. Off, surfaces
        /// no light reaches go black.
        ambient: bool = true,
        /// Lambert's `kd·C·max(0, n·l)`: matte shading that depends on the angle to the light,
        /// not on the viewer.
        diffuse: bool = true,
        /// Phong's `ks·Sc·max(0, r·v)^e`: the highlight that moves with the viewer; `e`
        /// (shininess) sets its size.
        specular: bool = true,
        /// `ME`, the material's own emitted radiance, added whatever the lights.
        emission: bool = true,
        /// Fresnel's reflectance `F` of dielectrics (materials with `kt > 0`), exact for
        /// unpolarized light: the transmitted share splits into `F·kt·MT` reflected and
        /// `(1 − F)·kt·MT` transmitted, `F` rising from 4 % head-on (ior 1.5) to 1 at grazing
        /// angles. Off: the course's model, all of `kt·MT` transmitted; `ior = 1` gives `F = 0`
        /// either way.
        fresnel: bool = false,
    }
}
