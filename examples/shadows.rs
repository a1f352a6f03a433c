//! Cast shadows, side by side (docs/course/05-shadows.md).
//!
//! A shadow is where a light cannot see. The shadow-map algorithm finds it in two passes: first
//! the scene is rendered from the light, keeping only depth (the "Z-buffer A" of the notes);
//! then, while shading what the camera sees, each point is projected into that depth map and
//! compared with it: a point farther from the light than what the light saw there is in shadow.
//! The map has finitely many texels, so shadow edges alias (a 256² map shows staircases);
//! percentage-closer filtering averages several comparisons to soften them. A surface compared
//! with its own resampled depth shadows itself in stripes ("acne") unless the comparison is
//! biased; too much bias detaches shadows from their casters ("peter-panning"). The notes'
//! object-precision method instead projects each caster polygon onto each planar receiver and
//! clips it there: exact edges, quadratic cost. The ray tracer's shadow rays are the reference.
//!
//! Run with `cargo run --release --example shadows [OUT.png]`; writes `shadows.png` by default.

use std::path::PathBuf;

use anyhow::Context;
use mirador::compare::sheet::{Panel, rows, sheet};
use mirador::gpu::Gpu;
use mirador::raster::Headless;
use mirador::settings::{ShadowFilter, ShadowMethod, ShadowView};
use mirador::{RenderSettings, Scene};

const EXPLANATION: &str = "\
Shadow maps render depth from each light (pass 1) and compare every shaded point with it (pass 2).
Top row: no shadows | a 256² map with one comparison: staircase edges | a 2048² map with 3×3 PCF |
the object-precision method (casters projected onto planar receivers, clipped) | shadow rays.
Bottom row: no bias at all: acne | far too much bias: peter-panning, the shadows leave their
casters | the spot light's map as grey levels | the map's texels on the receivers.";

fn main() -> anyhow::Result<()> {
    let out = std::env::args().nth(1).map_or_else(|| PathBuf::from("shadows.png"), PathBuf::from);
    println!("{EXPLANATION}");
    let scene = Scene::load(&mirador::scene::builtin_path("shadows.toml"))?;
    let gpu = Gpu::headless()?;
    let mut headless = Headless::new(&gpu, &scene);
    let base = scene.settings.clone();
    let variant = |change: &dyn Fn(&mut RenderSettings)| {
        let mut settings = base.clone();
        change(&mut settings);
        settings
    };
    let mut raster =
        |label: &str, settings: RenderSettings| Panel::new(label, headless.render(&gpu, &scene, &settings));

    let top = vec![
        raster("no shadows", variant(&|s| s.shadows.enabled = false)),
        raster(
            "map 256², no PCF",
            variant(&|s| {
                s.shadows.map_size = 256;
                s.shadows.filter = ShadowFilter::None;
            }),
        ),
        raster(
            "map 2048², PCF 3×3",
            variant(&|s| {
                s.shadows.map_size = 2048;
                s.shadows.filter = ShadowFilter::Pcf3x3;
            }),
        ),
        raster("projected polygons", variant(&|s| s.shadows.method = ShadowMethod::Projected)),
        Panel::new("ray traced", mirador::trace::render_image(&scene, &base)),
    ];
    let bottom = vec![
        raster(
            "acne: no bias",
            variant(&|s| {
                s.shadows.depth_bias = 0;
                s.shadows.slope_bias = 0.0;
                s.shadows.normal_offset = 0.0;
                s.shadows.filter = ShadowFilter::None;
                s.shadows.map_size = 512;
            }),
        ),
        raster("peter-panning: depth bias 2000", variant(&|s| s.shadows.depth_bias = 2000)),
        raster("the spot light's map", variant(&|s| s.shadows.view = ShadowView::Map)),
        raster(
            "map texels on receivers",
            variant(&|s| {
                s.shadows.map_size = 256;
                s.shadows.view = ShadowView::Texels;
            }),
        ),
    ];
    let image = rows(&[sheet(&top), sheet(&bottom)]);
    mirador::output::write_png_atomically(&image, &out).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
