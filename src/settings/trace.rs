//! The ray tracer's own settings (docs/course/09-ray-tracing.md): recursion, anti-aliasing
//! (docs/course/10-anti-aliasing.md), acceleration.

use super::field::{choices, section};

section! {
    /// The Whitted ray tracer's settings.
    pub struct TraceSettings {
        /// Deepest recursion of mirror `kps·L(r)` and transmitted `kt·L(t)` rays: primary rays are
        /// depth 0; each mirror or transmitted ray, and each ray continued through a blended
        /// surface, adds one. 0 leaves local shading only.
        #[values(closed(0.0, 64.0))]
        max_depth: u32 = 5,
        /// How pixels are sampled: one ray through the centre (pixel-aligned with the rasterizer),
        /// regular grids, jitter, corners or adaptive subdivision.
        anti_aliasing: AntiAliasing = AntiAliasing::Center,
        /// Rays per pixel side for `regular` and `jittered` sampling (`samples²` rays a pixel).
        #[values(closed(1.0, 16.0))]
        samples: u32 = 2,
        /// Seed of the jittered pattern: the same seed draws the same image.
        #[values(slider(0.0, 1.0e9))]
        seed: u64 = 0,
        /// Largest per-channel difference between a square's corners, in output values (0 to 1),
        /// that `adaptive` sampling leaves unsplit.
        #[values(at_least(0.0).slider(0.0, 1.0))]
        adaptive_threshold: f32 = 0.1,
        /// Deepest subdivision of `adaptive` sampling.
        #[values(closed(0.0, 6.0))]
        adaptive_max_level: u32 = 3,
        /// How rays find their nearest hit (`--accel`): a BVH (wide, or binary as the course
        /// builds it), a uniform grid, an octree, or every primitive (brute force). It changes the
        /// speed, not the image.
        accelerator: AccelKind = AccelKind::Wide,
    }
}

choices! {
    /// How the ray tracer samples pixels (docs/course/10-anti-aliasing.md#sampling-patterns).
    pub enum AntiAliasing {
        /// One ray through each pixel centre: pixel-aligned with the rasterizer.
        Center,
        /// `samples × samples` rays on a regular sub-pixel grid.
        Regular,
        /// `samples × samples` strata, one seeded random ray in each.
        Jittered,
        /// Rays through the pixel corners, each shared by the four pixels that meet there:
        /// `(width + 1)(height + 1)` rays.
        Corners,
        /// Whitted's adaptive subdivision: corner rays, and a square split in four while its
        /// corners differ by more than `adaptive_threshold`, down to `adaptive_max_level`.
        Adaptive,
    }
}

choices! {
    /// Which acceleration structure the ray tracer builds (`--accel wide|bvh|grid|octree|none`). It
    /// lives here, not in `trace`, so the layers stay one-way: scene ← settings ← renderers.
    #[derive(Default)]
    pub enum AccelKind {
        /// The bounding volume hierarchy collapsed into eight-wide nodes, tested with SIMD: the
        /// same hits as `bvh`, found faster.
        #[default]
        Wide,
        /// Bounding volume hierarchy, binned SAH, binary: the one the course describes.
        Bvh,
        /// Uniform grid walked by 3D-DDA.
        Grid,
        /// Adaptive octree: boxes divided in eight while that separates their primitives.
        Octree,
        /// Brute force: every primitive for every ray.
        None,
    }
}
