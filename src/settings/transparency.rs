//! Transparent surfaces in sorted Z order, in the rasterizer (docs/course/06-transparency.md).

use super::field::{choices, section};

/// The most layers `transparency.sort = "exact"` may peel.
pub const MAX_PEEL_LAYERS: u32 = 32;

section! {
    /// Transparent surfaces (`kt > 0`, or alpha-blended) in the rasterizer.
    #[derive(Copy)]
    pub struct TransparencySettings {
        /// Draw transparent surfaces (`kt > 0`, or `alpha_mode = "blend"`) after the opaque ones,
        /// each pixel updated as `I = Im + kt·Mt·I`; off, they are drawn as opaque surfaces with
        /// their illumination model alone (a glass pane turns dark).
        enabled: bool = true,
        /// The drawing order: `I = Im + kt·Mt·I` is right only farthest first (over two panes it
        /// gives `I_z + Mt1·I_y + Mt1·Mt2·I_x`); compare the orders where they fail.
        sort: TransparencySort = TransparencySort::Object,
        /// Layers the `exact` order peels at every pixel, from the back; each costs two passes
        /// over the transparent surfaces, and a pixel behind more transparent surfaces than this
        /// loses the nearest ones.
        #[values(closed(1.0, MAX_PEEL_LAYERS as f64))]
        peel_layers: u32 = 8,
        /// How a surface that bends light (`kt > 0`, `ior ≠ 1`, not alpha-blended) is drawn: the
        /// course's straight rays, or refracted at its front and back faces and looked up in its
        /// environment cube or in the opaque image behind it.
        refraction: Refraction = Refraction::None,
    }
}

choices! {
    /// How the rasterizer shows glass with `ior ≠ 1` (docs/course/06-transparency.md#refraction).
    pub enum Refraction {
        /// The course's `n_i = n_t`: rays go straight through, `I = Im + kt·Mt·I`.
        None,
        /// Refracted at the front face and at the back face (found by a search against the
        /// object's back faces), then looked up in the object's environment cube.
        Environment,
        /// Refracted at both faces, then followed through the opaque image behind the surface
        /// (a search against its depth), the world where it leaves the screen.
        Screen,
    }
}

choices! {
    /// The order the rasterizer draws transparent surfaces in. `I = Im + kt·Mt·I` depends on it:
    /// over two panes it gives `I_z + Mt1·I_y + Mt1·Mt2·I_x` only farthest first.
    pub enum TransparencySort {
        /// In the order the scene lists them, each object's triangles in its own order: shows the
        /// error the formula makes out of order.
        Unsorted,
        /// Objects farthest first by their bounds' centre, each drawn back faces then front faces:
        /// right for separate convex objects, wrong where objects interleave.
        Object,
        /// Every transparent triangle farthest first by its centroid, re-sorted when the view
        /// moves: wrong only for intersecting or cyclically overlapping triangles.
        Triangle,
        /// Depth peeling: the exact order at every pixel, `peel_layers` layers from the back.
        Exact,
    }
}
