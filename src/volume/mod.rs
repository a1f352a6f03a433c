//! Direct volume rendering (docs/course/11-volumes.md, "Volume de dados" to "Partição na
//! grade"): the CPU half both renderers share.
//!
//! A [`Volume`] is a scalar field sampled on a Cartesian grid, placed in the scene by a transform
//! like any object, and shown either by **compositing** (every sample classified into colour and
//! opacity by a transfer function, shaded with the notes' voxel illumination
//! `C = C_amb + C_luz·k_dif·(n·L)`, `n` the normalized gradient, and composited front to back) or
//! as an **isosurface** `f = iso` shaded like any surface.
//!
//! - [`grid`]: the field on its grid, trilinear and nearest reconstruction, gradients.
//! - [`transfer`]: classification, and the opacity's correction for the sample step.
//! - [`march`]: one ray through one volume: samples, compositing, early termination, the
//!   isosurface search.
//! - [`fields`]: procedural fields (Marschner–Lobb, signed distances, a CT-like phantom).
//!
//! This is the math of the grids only, below the scene that holds them (docs/architecture.md,
//! "Layers"): NRRD and raw files are read beside the other file formats, in `scene::nrrd`, and the
//! ray and the material index come from [`crate::base`].
//!
//! The tracer marches these functions directly (`trace::volume`); the rasterizer runs their WGSL
//! twin (`shaders/volume.wgsl`) over a 3D texture of the same normalized values.

pub mod fields;
pub mod grid;
pub mod march;
pub mod transfer;

use std::sync::Arc;

use glam::{Mat3, Mat4, Vec3};

pub use grid::{Differences, Grid, Reconstruction};
pub use march::{Composite, LocalRay, March, Sample};
pub use transfer::{ControlPoint, Preset, Table, TransferFunction};

use crate::base::{MaterialId, Ray};
use crate::settings::{VolumeGradient, VolumeMode, VolumeReconstruction, VolumeSettings};

/// Cells a side up to which the rasterizer's wireframe (`volume.wireframe`) draws every grid
/// plane; a grid with more draws every k-th, `k = ⌈cells / WIREFRAME_CELLS⌉`.
pub const WIREFRAME_CELLS: u32 = 32;

/// How a volume is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rendering {
    /// Classified samples composited front to back.
    Composite,
    /// The surface where the normalized field equals the volume's `iso`, shaded with its material.
    Isosurface,
}

/// A voxel grid in the scene.
#[derive(Clone, Debug)]
pub struct Volume {
    pub name: String,
    /// The field, normalized to `[0, 1]` over `range`.
    pub grid: Arc<Grid>,
    /// The data values mapped to 0 and 1 (for messages and the viewer's plot).
    pub range: (f32, f32),
    pub world_from_local: Mat4,
    pub transfer: TransferFunction,
    /// The transfer function as the renderers read it.
    pub table: Table,
    pub rendering: Rendering,
    /// The isosurface's value (normalized), kept whatever `rendering` says, so the settings can
    /// show a composited volume's isosurface.
    pub iso: f32,
    /// The isosurface's material.
    pub material: MaterialId,
}

impl Volume {
    /// The centre of the volume's box in the world: where the sorted transparency orders place
    /// it among transparent surfaces.
    pub fn centre(&self) -> glam::Vec3 {
        self.world_from_local.transform_point3(glam::Vec3::ZERO)
    }

    /// The rendering the settings ask for: the volume's own, or every volume composited or shown
    /// as its isosurface.
    pub fn rendering(&self, settings: &VolumeSettings) -> Rendering {
        match settings.mode {
            VolumeMode::Scene => self.rendering,
            VolumeMode::Composite => Rendering::Composite,
            VolumeMode::Isosurface => Rendering::Isosurface,
        }
    }

    pub fn local_from_world(&self) -> Mat4 {
        self.world_from_local.inverse()
    }

    /// The matrix that carries local gradients to world normals (inverse transpose).
    pub fn normal_from_local(&self) -> Mat3 {
        Mat3::from_mat4(self.world_from_local).inverse().transpose()
    }

    /// `ray` in local coordinates, with the same parameter `t`.
    pub fn local_ray(&self, ray: &Ray) -> LocalRay {
        let local_from_world = self.local_from_world();
        LocalRay {
            origin: local_from_world.transform_point3(ray.origin),
            direction: local_from_world.transform_vector3(ray.direction),
        }
    }

    /// The part of `[0, t_max]` where the local `ray` is inside the volume's box, if any.
    pub fn segment(&self, ray: &LocalRay, t_max: f32) -> Option<(f32, f32)> {
        let (near, far) = ray.box_interval(self.grid.half_extent())?;
        let (t0, t1) = (near.max(0.0), far.min(t_max));
        (t0 < t1).then_some((t0, t1))
    }

    /// The eight corners of the volume's box in world space.
    pub fn world_corners(&self) -> [Vec3; 8] {
        let h = self.grid.half_extent();
        std::array::from_fn(|i| {
            let sign = Vec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            self.world_from_local.transform_point3(sign * h)
        })
    }

    /// The grid's cells drawn on the box's six faces, in world space: on each face a line at every
    /// grid plane that crosses it, and the box's twelve edges. An axis of more than `max_cells`
    /// cells gets a line at every k-th plane only, `k = ⌈cells / max_cells⌉`.
    pub fn wireframe_lines(&self, max_cells: u32) -> Vec<[Vec3; 2]> {
        let h = self.grid.half_extent();
        // The inner planes along each axis, as local coordinates.
        let inner: [Vec<f32>; 3] = std::array::from_fn(|axis| {
            let cells = self.grid.dims[axis] - 1;
            let k = cells.div_ceil(max_cells.max(1)).max(1);
            (k..cells).step_by(k as usize).map(|i| i as f32 * self.grid.spacing[axis] - h[axis]).collect()
        });
        let mut lines = Vec::new();
        for axis in 0..3 {
            // Lines along `axis`, through (u, v) on the other two axes `a` and `b`.
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut line = |u: f32, v: f32| {
                let mut p = Vec3::ZERO;
                (p[a], p[b], p[axis]) = (u, v, -h[axis]);
                let mut q = p;
                q[axis] = h[axis];
                lines.push([p, q]);
            };
            for side in [-1.0, 1.0] {
                inner[b].iter().for_each(|&v| line(side * h[a], v));
                inner[a].iter().for_each(|&u| line(u, side * h[b]));
                line(side * h[a], -h[b]);
                line(side * h[a], h[b]);
            }
        }
        let world = |p: Vec3| self.world_from_local.transform_point3(p);
        lines.into_iter().map(|[p, q]| [world(p), world(q)]).collect()
    }
}

impl March {
    /// The march `[settings.volume]` asks for.
    pub fn of(settings: &VolumeSettings) -> March {
        March {
            reconstruction: match settings.reconstruction {
                VolumeReconstruction::Nearest => Reconstruction::Nearest,
                VolumeReconstruction::Trilinear => Reconstruction::Trilinear,
            },
            gradient: match settings.gradient {
                VolumeGradient::Off => None,
                VolumeGradient::Forward => Some(Differences::Forward),
                VolumeGradient::Central => Some(Differences::Central),
            },
            step: settings.step,
            opacity_correction: settings.opacity_correction,
            termination: settings.early_termination.then_some(settings.threshold),
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, UVec3};

    use super::*;

    fn volume(dims: UVec3) -> Volume {
        let grid = Grid::from_function(dims, |p| p.x).unwrap();
        let transfer = TransferFunction::new(vec![ControlPoint { value: 0.0, colour: Vec3::ONE, alpha: 0.1 }]).unwrap();
        Volume {
            name: "test".into(),
            grid: Arc::new(grid),
            range: (0.0, 1.0),
            world_from_local: Mat4::from_scale_rotation_translation(
                Vec3::new(0.5, 2.0, 1.5),
                Quat::from_rotation_y(0.7),
                Vec3::new(1.0, -2.0, 3.0),
            ),
            table: transfer.table(),
            transfer,
            rendering: Rendering::Composite,
            iso: 0.5,
            material: MaterialId(0),
        }
    }

    #[test]
    fn the_wireframe_draws_every_cell_on_the_faces_and_the_edges() {
        // 6 × 5 × 4 points: 5 × 4 × 3 cells, so 4 + 3 + 2 inner planes. Each inner plane crosses
        // four faces; the box adds its 12 edges.
        let volume = volume(UVec3::new(6, 5, 4));
        let lines = volume.wireframe_lines(WIREFRAME_CELLS);
        assert_eq!(lines.len(), 4 * (4 + 3 + 2) + 12);
        let h = volume.grid.half_extent();
        let local_from_world = volume.local_from_world();
        for [p, q] in lines {
            let (p, q) = (local_from_world.transform_point3(p), local_from_world.transform_point3(q));
            // Each line runs along one axis from face to face, on a face of the box and inside it.
            let d = (q - p).abs();
            let along: Vec<usize> = (0..3).filter(|&i| d[i] > 1e-4).collect();
            assert_eq!(along.len(), 1, "{p} – {q}");
            assert!((d[along[0]] - 2.0 * h[along[0]]).abs() < 1e-4, "{p} – {q} spans the box");
            for point in [p, q] {
                assert!((point.abs() - h).max_element() < 1e-4, "{point} is in the box");
                assert!((0..3).any(|i| i != along[0] && (point[i].abs() - h[i]).abs() < 1e-4), "{point} on a face");
            }
        }
    }

    #[test]
    fn a_fine_grid_gets_every_kth_plane() {
        // 70 cells along x: k = ⌈70/32⌉ = 3, inner planes 3, 6, …, 69 (23 of them); y has one.
        let volume = volume(UVec3::new(71, 3, 2));
        let lines = volume.wireframe_lines(32);
        assert_eq!(lines.len(), 4 * (23 + 1) + 12);
        // The planes the lines not along x lie in, in cells from the box's −x face.
        let local_from_world = volume.local_from_world();
        let mut planes: Vec<u32> = lines
            .iter()
            .map(|&[p, q]| (local_from_world.transform_point3(p), local_from_world.transform_point3(q)))
            .filter(|(p, q)| (q.x - p.x).abs() < 1e-4)
            .map(|(p, _)| ((p.x + volume.grid.half_extent().x) / volume.grid.spacing.x).round() as u32)
            .collect();
        planes.sort();
        planes.dedup();
        let expected: Vec<u32> = (0..70).step_by(3).chain([70]).collect();
        assert_eq!(planes, expected);
    }
}
