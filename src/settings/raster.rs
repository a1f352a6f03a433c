//! How the rasterizer spends its time. None of these settings changes what the techniques
//! compute; each trades time for a documented, measured difference (docs/performance.md).

use super::field::{choices, section};

section! {
    /// The rasterizer's speed settings.
    #[derive(Copy)]
    pub struct RasterSettings {
        /// Draw every pixel's depth first, then run the illumination model only on the visible
        /// surface (once per pixel, not once per fragment drawn), at the price of drawing the
        /// geometry twice. It changes the speed, not the image.
        depth_prepass: Prepass = Prepass::Auto,
        /// Tessellate spheres, tori and rounded boxes by their size on screen, keeping the
        /// outline within 1/16 pixel of the true one, at most `sphere_segments`; off, every one
        /// gets `sphere_segments`.
        adaptive_tessellation: bool = true,
        /// Draw at this fraction of the output's size and upscale bilinearly in the present pass:
        /// fewer pixels shaded, a blurrier image (the viewer's trade of resolution for frame
        /// rate).
        #[values(closed(0.1, 1.0))]
        render_scale: f32 = 1.0,
        /// Every surface in its material's colour `C`, no lighting: the floor of what the GPU can
        /// do with this geometry, for benchmarks.
        flat_colour: bool = false,
    }
}

choices! {
    /// When the rasterizer draws a depth prepass.
    pub enum Prepass {
        /// When shading is what costs: the frame has fewer triangles than a quarter of its pixels
        /// (measured: the showcase is 16 % faster with it; the 7,381-sphere sphereflake, whose
        /// cost is its geometry, 30 % slower).
        Auto,
        /// Every frame.
        Always,
        /// Never: every fragment drawn runs the illumination model.
        Never,
    }
}
