//! Writes Mirador's small volume data set, `assets/volumes/phantom.nrrd`: the CT-like phantom of
//! `mirador::volume::fields::phantom` (a head of ellipsoids in Hounsfield-like units) sampled on a
//! 96³ grid over [−1, 1]³ (spacing 2/95), as 16-bit integers, gzip-encoded NRRD. A made-up data
//! set, so that the file path of volume rendering (reading, normalizing, classifying) has real
//! bytes to read without shipping anyone's scan.
//!
//! Run with `cargo run --release --example phantom_nrrd [OUT.nrrd]`.

use std::path::PathBuf;

use glam::UVec3;
use mirador::scene::nrrd::{ScalarType, write_nrrd};
use mirador::volume::{Grid, fields};

/// Points per axis, and each edge's width in voxels (as the scene file's `phantom` field).
const RESOLUTION: u32 = 96;
const EDGE_VOXELS: f32 = 2.5;

fn main() -> anyhow::Result<()> {
    let out = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/volumes/phantom.nrrd"), PathBuf::from);
    let blur = EDGE_VOXELS * 2.0 / (RESOLUTION - 1) as f32;
    let grid =
        Grid::from_function(UVec3::splat(RESOLUTION), |p| fields::phantom(p, blur)).map_err(anyhow::Error::msg)?;
    write_nrrd(&out, &grid, ScalarType::I16, true).map_err(anyhow::Error::msg)?;
    println!("wrote {} ({} bytes)", out.display(), std::fs::metadata(&out)?.len());
    Ok(())
}
