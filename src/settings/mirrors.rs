//! Planar mirrors by a mirrored camera, in the rasterizer (docs/course/07-planar-mirrors.md).

use super::field::{choices, section};

/// The deepest `mirrors.depth`.
pub const MAX_MIRROR_DEPTH: u32 = 8;

section! {
    /// Planar mirrors (materials with `kps > 0` on flat objects) in the rasterizer.
    #[derive(Copy)]
    pub struct MirrorSettings {
        /// Planar mirrors (flat objects whose material has `mirror` > 0): the scene rendered by
        /// the camera mirrored about the mirror's plane, added to the mirror's illumination model
        /// as `kps·MPS·L(r)`. Off, mirrors show their model alone.
        enabled: bool = true,
        /// How deep mirrors that see each other recurse (reflections of reflections); 0 draws
        /// every mirror as its plain material. The tracer's counterpart is `trace.max_depth`.
        #[values(closed(0.0, MAX_MIRROR_DEPTH as f64))]
        depth: u32 = 3,
        /// Teaching views: the first mirror camera's own image, or each mirrored camera's view
        /// volume drawn into the scene.
        view: MirrorView = MirrorView::Off,
    }
}

choices! {
    /// What the mirror technique shows.
    pub enum MirrorView {
        /// The scene, its mirrors showing their reflections.
        Off,
        /// The first mirror camera's own image, alone: the scene seen from behind the mirror,
        /// mirrored, with nothing in front of the mirror plane's far side; drawn in the window
        /// of the screen the mirror covers (the camera draws nothing else).
        Image,
        /// Each mirrored camera's view volume drawn into the scene: its near face lies on the
        /// mirror.
        Camera,
    }
}
