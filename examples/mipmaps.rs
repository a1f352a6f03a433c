//! Mipmaps and trilinear sampling, side by side (docs/course/03-mipmaps.md).
//!
//! A texture seen from far away squeezes many texels into one pixel. Sampling it at one point
//! per pixel (nearest or bilinear) picks texels almost at random: the checkered floor breaks up
//! into moiré near the horizon. A mip chain stores the texture averaged down by halves (each
//! texel of level i+1 the mean of four of level i, in linear light), and the sampler reads the
//! level whose texels are about a pixel wide there: the level grows with the logarithm of the
//! distance. Switching levels abruptly shows seams; trilinear sampling blends the two nearest
//! levels. The level-colour view paints each level in its own colour, so the choice of level
//! and the blend between levels can be seen. The ray tracer does the same with ray cones: the
//! footprint of the pixel's cone at the hit picks the level.
//!
//! Run with `cargo run --release --example mipmaps [OUT.png]`; writes `mipmaps.png` by default.

use std::path::PathBuf;

use anyhow::Context;
use mirador::Scene;
use mirador::compare::sheet::{Panel, sheet};
use mirador::gpu::Gpu;
use mirador::raster::Headless;
use mirador::settings::TextureFilter;

const EXPLANATION: &str = "\
The showcase's checkered floor runs to the horizon. nearest: one texel per pixel, moiré |
bilinear: still one spot of the full-size texture per pixel, still moiré | trilinear: the mip
level matching the pixel's footprint, blended between the two nearest levels: the far floor
fades to the checker's mean grey | level colours: red is level 0, then orange, yellow, green,
cyan, blue, magenta | ray traced: mip levels chosen from the footprint of each pixel's ray cone.";

fn main() -> anyhow::Result<()> {
    let out = std::env::args().nth(1).map_or_else(|| PathBuf::from("mipmaps.png"), PathBuf::from);
    println!("{EXPLANATION}");
    let mut scene = Scene::showcase()?;
    (scene.camera.width, scene.camera.height) = (480, 270);
    let gpu = Gpu::headless()?;
    let mut headless = Headless::new(&gpu, &scene);
    let mut panels = Vec::new();
    for (label, filter) in [
        ("nearest", TextureFilter::Nearest),
        ("bilinear (no mipmaps)", TextureFilter::Bilinear),
        ("trilinear", TextureFilter::Trilinear),
        ("mip level colours", TextureFilter::LevelColour),
    ] {
        let mut settings = scene.settings.clone();
        settings.textures.filter = filter;
        panels.push(Panel::new(label, headless.render(&gpu, &scene, &settings)));
    }
    panels.push(Panel::new("ray traced (ray cones)", mirador::trace::render_image(&scene, &scene.settings)));
    mirador::output::write_png_atomically(&sheet(&panels), &out)
        .with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
