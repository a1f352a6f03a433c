//! Cast shadows (docs/course/05-shadows.md): shadow maps or projected polygons in the rasterizer, shadow
//! rays in the tracer.

use super::field::{choices, section};

/// At most this many lights cast shadows in the rasterizer; the others light everything they face.
pub const MAX_SHADOWED_LIGHTS: usize = 4;

section! {
    /// How both renderers find the visibility `V_i` of each light.
    #[derive(Copy)]
    pub struct ShadowSettings {
        /// Compute the visibility `V_i` of each light: shadow maps or projected polygons in the
        /// rasterizer, shadow rays in the tracer. Off, every point sees every light (`V_i = 1`) in
        /// both renderers.
        enabled: bool = true,
        /// How the rasterizer finds cast shadows: at image precision (a two-pass z-buffer from the
        /// light) or at object precision (casters projected onto planar receivers).
        method: ShadowMethod = ShadowMethod::Map,
        /// Texels on each side of a shadow map (pass 1's depth buffer): small maps give blocky
        /// edges.
        #[values(closed(256.0, 4096.0).unit("texels"))]
        map_size: u32 = 2048,
        /// How the stored depth `d` is compared around the projected point `q`
        /// (percentage-closer filtering): one texel, 2×2, 3×3, 5×5 or a Poisson disc.
        filter: ShadowFilter = ShadowFilter::Pcf3x3,
        /// Constant added to `d` before the test `d < ‖q − y‖`, in the depth buffer's smallest
        /// steps: cures self-shadowing acne; too much detaches shadows from their casters
        /// (peter-panning).
        #[values(closed(0.0, 10000.0))]
        depth_bias: i32 = 4,
        /// Depth bias proportional to the surface's depth slope as the light sees it: cures the
        /// acne of grazing surfaces.
        #[values(at_least(0.0).slider(0.0, 16.0))]
        slope_bias: f32 = 1.5,
        /// The receiver's lookup point `q` moves this far along its normal `n`, in shadow-map
        /// texels, before it is projected.
        #[values(at_least(0.0).unit("texels").slider(0.0, 16.0))]
        normal_offset: f32 = 1.0,
        /// How far from the eye a directional light's orthographic map reaches, in scene units;
        /// 0: four times the distance from the eye to the view centre, at most the far plane.
        #[values(at_least(0.0).slider(0.0, 10000.0))]
        distance: f32 = 0.0,
        /// What a directional light's map covers: the view frustum (finer texels, redrawn as the
        /// camera moves) or the whole scene (kept while it moves).
        fit: ShadowFit = ShadowFit::View,
        /// Keep each map layer across frames until its light, the casters or the bias change:
        /// pass 1 depends on the light, not on the camera.
        cache: bool = true,
        /// Transparent occluders (`kt > 0`) let `kt·MT` through: coloured, partial shadows
        /// (`0 < V_i < 1`) instead of black ones.
        transmission: bool = true,
        /// Teaching view: the shadow map's depths, or its texels as they land on the receivers.
        view: ShadowView = ShadowView::Off,
        /// Which shadow map layer the `map` view shows (a point light has six, one per cube
        /// face, in the order +x, −x, +y, −y, +z, −z); past the last layer, the last. `--stats`
        /// and the viewer's frame times give the layer shown and how many there are.
        #[values(slider(0.0, 95.0))]
        view_layer: u32 = 0,
        /// Draw each shadowed light's view volume (the frustum pass 1 renders) into the scene.
        show_frusta: bool = false,
    }
}

choices! {
    /// How the rasterizer finds cast shadows (docs/course/05-shadows.md).
    pub enum ShadowMethod {
        /// Image precision: the two-pass z-buffer algorithm (shadow maps).
        Map,
        /// Object precision: casters projected from the light onto planar receivers (`plane`
        /// objects) and clipped to them (the notes' brute force), drawn as detail polygons.
        Projected,
    }
}

choices! {
    /// How a shadow map is filtered where a receiver looks it up.
    pub enum ShadowFilter {
        /// One comparison with the nearest texel: hard, aliased edges.
        None,
        /// The hardware's 2×2 comparison with bilinear weights (4 taps).
        Hardware,
        /// 3×3 hardware taps.
        Pcf3x3,
        /// 5×5 hardware taps.
        Pcf5x5,
        /// 16 hardware taps on a Poisson disc of radius 2.5 texels.
        Poisson,
    }
}

choices! {
    /// What a directional light's shadow map covers.
    pub enum ShadowFit {
        /// The part of the view frustum within `distance` of the eye: finer texels where the
        /// camera looks, redrawn when the camera moves.
        View,
        /// The whole scene: coarser texels, but independent of the camera, so kept while it
        /// moves.
        Scene,
    }
}

choices! {
    /// What the teaching view shows instead of, or over, the shaded image.
    pub enum ShadowView {
        /// The shaded image.
        Off,
        /// The shadow map of `view_layer` as grey levels, near black and far white.
        Map,
        /// A checker of the map's texels as they land on the receivers.
        Texels,
    }
}
