//! Direct volume rendering of voxel grids: compositing and isosurfaces (docs/course/11-volumes.md).

use super::field::{choices, section};

/// The sample count the samples view shows as white.
pub const VOLUME_SAMPLES_WHITE: u32 = 512;

section! {
    /// Direct volume rendering in both renderers.
    #[derive(Copy)]
    pub struct VolumeSettings {
        /// Draw volumes (`[[volumes]]`) in both renderers; off, they are left out.
        enabled: bool = true,
        /// How volumes are shown: composited, as their isosurfaces `f = iso`, or each as its scene
        /// file says.
        mode: VolumeMode = VolumeMode::Scene,
        /// Distance between samples along a ray, in voxels of the grid's smallest spacing: a
        /// segment of `L` voxels is cut into `⌈L/step⌉` equal parts, sampled at their midpoints.
        /// Smaller is slower and finer; with opacity correction the image keeps its brightness.
        #[values(closed(0.05, 8.0).unit("voxels"))]
        step: f32 = 0.5,
        /// How the field is read between grid points: the nearest point (blocks) or trilinear
        /// interpolation of the eight around (the rasterizer uses the hardware's filtering of the
        /// same 3D texture).
        reconstruction: VolumeReconstruction = VolumeReconstruction::Trilinear,
        /// How samples are shaded: `C = C_amb + Σ C_luz·k_dif·(n·L)`, the normal
        /// `n = ∇f/|∇f|` by forward (first-order) or central (second-order) differences one voxel
        /// either side; off, each sample shows its classified colour unshaded.
        gradient: VolumeGradient = VolumeGradient::Central,
        /// Correct each sample's opacity for its length `ℓ` in voxels, `α' = 1 − (1 − α)^ℓ`, so
        /// the image does not change with the step; off, the transfer function's opacity is used
        /// per sample as it is.
        opacity_correction: bool = true,
        /// Stop a ray once its accumulated opacity reaches `volume.threshold`: what lies behind
        /// would add at most `1 − threshold`.
        early_termination: bool = true,
        /// The accumulated opacity at which early termination stops a ray.
        #[values(open_closed(0.0, 1.0).slider(0.5, 1.0))]
        threshold: f32 = 0.99,
        /// Shadows of opaque surfaces on composited samples: a shadow ray per sample and light in
        /// the tracer, a shadow-map lookup in the rasterizer (`shadows.method = "map"` only).
        /// Isosurfaces are shadowed like any surface whenever shadows are on; volumes cast no
        /// shadows.
        shadows: bool = false,
        /// Draw each volume's grid cells as lines on its box's faces, over the frame: a line at
        /// every grid plane up to 32 cells a side, beyond that at every k-th plane
        /// (`k = ⌈cells/32⌉`), and the box's edges. A rasterizer overlay: the ray tracer does not
        /// draw it.
        wireframe: bool = false,
        /// Teaching views: the samples each ray took in composited volumes, as a heat map.
        view: VolumeView = VolumeView::Off,
    }
}

choices! {
    /// How volumes are shown.
    pub enum VolumeMode {
        /// Each volume as its scene file says (`mode`).
        Scene,
        /// Every volume composited: classified samples, front to back.
        Composite,
        /// Every volume as its isosurface `f = iso`, shaded like a surface.
        Isosurface,
    }
}

choices! {
    /// How the field is read between grid points.
    pub enum VolumeReconstruction {
        /// The nearest grid point's value: the voxels show as blocks.
        Nearest,
        /// Trilinear interpolation of the eight surrounding grid points.
        Trilinear,
    }
}

choices! {
    /// How samples are shaded.
    pub enum VolumeGradient {
        /// No shading: each sample shows its classified colour.
        Off,
        /// Gradient normals by forward differences (first order).
        Forward,
        /// Gradient normals by central differences (second order, the notes').
        Central,
    }
}

choices! {
    /// What the volume technique shows.
    pub enum VolumeView {
        /// The scene.
        Off,
        /// Where a ray crosses a composited volume, the samples it took, as a heat map (black
        /// none, white `VOLUME_SAMPLES_WHITE` = 512): where early termination saves work.
        Samples,
    }
}
