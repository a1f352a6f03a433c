//! Direct volume rendering (TECHNIQUES.md §8; seed 004, "Volume de dados" to "Partição na
//! grade"): the CPU half both renderers share.
//!
//! - [`grid`]: the scalar field on a Cartesian grid, trilinear interpolation, gradients.
//! - [`nrrd`]: reading grids from NRRD and raw files.

pub mod grid;
pub mod nrrd;

pub use grid::{Differences, Grid, Reconstruction};
