//! The hybrid (docs/course/12-error-budget.md): any of the rasterizer's approximations swapped for
//! its traced counterpart inside the raster frame, per pixel of every view, so that what each
//! approximation costs can be measured (`mirador budget`).

use super::field::section;

section! {
    /// Terms of the raster frame taken from the ray tracer instead, each in place of the
    /// approximation that makes it. The traced term is computed at the first opaque surface along
    /// each pixel's ray of each view (the main camera, mirrored cameras, cube faces); a fragment
    /// of another surface there (a silhouette the two renderers draw a pixel apart, a transparent
    /// surface) keeps the rasterizer's own.
    #[derive(Copy, Eq)]
    pub struct HybridSettings {
        /// The visibility `V_i` of each shadowed light from shadow rays, in place of shadow maps
        /// or projected polygons.
        shadows: bool = false,
        /// The mirror term `kps·MPS·L(r)` with `L(r)` traced (the tracer's whole recursion along
        /// the reflected ray), in place of the mirrored cameras of planar mirrors and the
        /// environment maps of curved ones (glass still reads the maps: its reflection and
        /// refraction are transmission's to swap).
        reflections: bool = false,
        /// What transparent surfaces let through, traced (`α·((1 − F)·kt·MT·L(t) + F·kt·MT·L(r))
        /// + (1 − α)·L(behind)`), in place of sorted blending and the screen-space refraction:
        /// the frame draws transparent surfaces as opaque ones, each adding its traced share.
        transmission: bool = false,
        /// The surface colour `C` filtered as the tracer filters it (its mip level from a ray
        /// cone), in place of trilinear filtering from screen derivatives. The swap goes the
        /// tracer's way: neither filter is exact, the tracer's is the reference's.
        textures: bool = false,
    }
}

impl HybridSettings {
    /// Whether any term is traced.
    pub fn any(&self) -> bool {
        self.shadows || self.reflections || self.transmission || self.textures
    }
}
