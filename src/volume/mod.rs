//! Direct volume rendering (TECHNIQUES.md §8; seed 004, "Volume de dados" to "Partição na
//! grade"): the CPU half both renderers share.
//!
//! A [`Volume`] is a scalar field sampled on a Cartesian grid, placed in the scene by a transform
//! like any object, and shown either by **compositing** (every sample classified into colour and
//! opacity by a transfer function, shaded with the seed's voxel illumination
//! `C = C_amb + C_luz·k_dif·(n·L)`, `n` the normalized gradient, and composited front to back) or
//! as an **isosurface** `f = iso` shaded like any surface.
//!
//! - [`grid`]: the field on its grid, trilinear and nearest reconstruction, gradients.
//! - [`transfer`]: classification, and the opacity's correction for the sample step.
//! - [`march`]: one ray through one volume: samples, compositing, early termination, the
//!   isosurface search.
//! - [`fields`]: procedural fields (Marschner–Lobb, signed distances, a CT-like phantom).
//! - [`nrrd`]: NRRD and raw files.
//!
//! The tracer marches these functions directly (`trace::volume`); the rasterizer runs their WGSL
//! twin (`shaders/volume.wgsl`) over a 3D texture of the same normalized values.

pub mod fields;
pub mod grid;
pub mod march;
pub mod nrrd;
pub mod transfer;

use std::sync::Arc;

use glam::{Mat3, Mat4, Vec3};

pub use grid::{Differences, Grid, Reconstruction};
pub use march::{Composite, LocalRay, March, Sample};
pub use transfer::{ControlPoint, Preset, Table, TransferFunction};

use crate::scene::{MaterialId, Ray};
use crate::settings::{VolumeGradient, VolumeMode, VolumeReconstruction, VolumeSettings};

/// How a volume is shown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rendering {
    /// Classified samples composited front to back.
    Composite,
    /// The surface where the normalized field equals `iso`, shaded with the volume's material.
    Isosurface { iso: f32 },
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
    /// The isosurface's iso value (normalized) whatever `rendering` says, so the settings can switch
    /// a composited volume to its isosurface.
    pub iso: f32,
    /// The isosurface's material.
    pub material: MaterialId,
}

impl Volume {
    /// The rendering the settings ask for: the volume's own, or every volume composited or shown
    /// as its isosurface.
    pub fn rendering(&self, settings: &VolumeSettings) -> Rendering {
        match settings.mode {
            VolumeMode::Scene => self.rendering,
            VolumeMode::Composite => Rendering::Composite,
            VolumeMode::Isosurface => Rendering::Isosurface { iso: self.iso },
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
