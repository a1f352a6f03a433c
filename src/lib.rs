//! Mirador: a hybrid renderer for learning, seeing and testing the classic realistic-rendering
//! techniques. A wgpu z-buffer rasterizer adds the techniques one toggle at a time; a CPU Whitted
//! ray tracer renders the same scene, pixel-aligned, as the reference.
//!
//! - [`base`]: the ray and the material and texture indices that `scene` and `volume` share.
//! - [`scene`]: the CPU scene both renderers read (camera, lights, materials, shapes, files).
//! - [`gpu`]: the thin wgpu layer.
//! - [`raster`]: the z-buffer renderer, one pass per technique.
//! - [`output`]: the output transform both renderers share.
//! - [`linear_output`]: the radiance before that transform, as OpenEXR.
//! - [`lab`]: a student's WGSL in place of a technique's own functions, checked and graded.
//! - [`budget`]: what each of the rasterizer's approximations costs, each swapped for its traced
//!   counterpart (the hybrid).
//! - [`compare`]: image metrics for golden images and raster-vs-trace comparisons.
//! - [`course`] (native only): the course as a site: the page's address for each command a chapter
//!   prints.
//! - [`viewer`]: the interactive window (winit + egui) over both renderers.
//! - [`volume`]: scalar fields on voxel grids, classified and ray-cast by both renderers.
//! - [`files`]: where the files a scene names are read from (the disk, or the page's files).
//! - `web` (built for `wasm32` only): the viewer in the browser (web/README.md).

// Checks like `!(x > 0.0)` are written that way on purpose: unlike `x <= 0.0` they also reject
// NaN, which user input can carry.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod base;
#[cfg(not(target_arch = "wasm32"))]
pub mod budget;
pub mod compare;
#[cfg(not(target_arch = "wasm32"))]
pub mod course;
pub mod explain;
pub mod files;
pub mod gpu;
pub mod lab;
pub mod linear_output;
pub mod output;
pub mod raster;
pub mod scene;
pub mod settings;
pub mod settings_doc;
pub mod shaders;
pub mod texture;
pub mod trace;
pub mod viewer;
pub mod volume;
#[cfg(target_arch = "wasm32")]
pub mod web;

pub use scene::Scene;
pub use settings::RenderSettings;
