//! Transparent surfaces in sorted Z order, side by side (docs/course/06-transparency.md).
//!
//! A z-buffer keeps one surface per pixel, so transparency is drawn in two steps: every opaque
//! surface first, then the transparent ones farthest first, each pixel updated as
//! `I = Im + kt·Mt·I` (its own illumination model plus what it lets through of what lies
//! behind). The formula is right only in that order: over two panes it must give
//! `I_z + Mt1·I_y + Mt1·Mt2·I_x`. The orders compared here: the file's (wrong on purpose), per
//! object (wrong where objects cut through each other), per triangle (wrong only where
//! triangles intersect or overlap in a cycle) and depth peeling (exact at every pixel). A
//! z-buffer cannot bend rays either: the ray tracer with `ior = 1` must agree with the exact
//! order, and with `ior = 1.5` shows what refraction adds. The last row follows the bent rays in
//! the rasterizer too (`transparency.refraction`, docs/course/06-transparency.md#refraction):
//! through the glass ball's environment cube and through the opaque image, beside the tracer.
//!
//! Run with `cargo run --release --example transparency [OUT.png]`; writes `transparency.png` by
//! default.

use std::path::PathBuf;

use anyhow::Context;
use mirador::compare::sheet::{Panel, rows, sheet};
use mirador::gpu::Gpu;
use mirador::raster::Headless;
use mirador::settings::{Parallax, Refraction, TransparencySort};
use mirador::{RenderSettings, Scene};

const EXPLANATION: &str = "\
Transparent surfaces drawn after the opaque ones with I = Im + kt·Mt·I, in four orders:
top: unsorted (file order, nearest pane first: the panes' colours stack wrongly) | per object
(one crossing pane covers the other on both sides of their intersection) | per triangle (the
crossing panes' triangles split along their diagonals); bottom: exact (depth peeling) | ray
traced with ior 1.0 (agrees with the exact order) | ray traced with ior 1.5 (refraction bends
the post behind the sphere, which no z-buffer order can).
Last row, a solid glass ball (ior 1.5) before three boxes: the course's straight rays | refracted
through the ball's environment cube, read on the ground (parallax), with Fresnel | refracted in
screen space (the opaque image behind), with Fresnel | ray traced, with Fresnel.";

fn main() -> anyhow::Result<()> {
    let out = std::env::args().nth(1).map_or_else(|| PathBuf::from("transparency.png"), PathBuf::from);
    println!("{EXPLANATION}");
    let scene = Scene::load(&mirador::scene::builtin_path("transparency.toml"))?;
    let gpu = Gpu::headless()?;
    let mut headless = Headless::new(&gpu, &scene);
    let mut settings = scene.settings.clone();
    // Enough recursion for the rays that cross every pane and both walls of the sphere.
    settings.trace.max_depth = 10;
    let mut raster = |label: &str, sort: TransparencySort| {
        let mut settings: RenderSettings = settings.clone();
        settings.transparency.sort = sort;
        Panel::new(label, headless.render(&gpu, &scene, &settings))
    };
    let top = vec![
        raster("unsorted (file order)", TransparencySort::Unsorted),
        raster("per object", TransparencySort::Object),
        raster("per triangle", TransparencySort::Triangle),
    ];
    let mut straight = scene.clone();
    for material in &mut straight.materials {
        material.ior = 1.0;
    }
    let bottom = vec![
        raster("exact (depth peeling)", TransparencySort::Exact),
        Panel::new("ray traced, ior 1.0", mirador::trace::render_image(&straight, &settings)),
        Panel::new("ray traced, ior 1.5", mirador::trace::render_image(&scene, &settings)),
    ];
    let glass = Scene::load(&mirador::scene::builtin_path("refraction.toml"))?;
    let mut headless = Headless::new(&gpu, &glass);
    let mut refracted = |label: &str, refraction: Refraction| {
        let mut settings = glass.settings.clone();
        settings.transparency.refraction = refraction;
        settings.terms.fresnel = refraction != Refraction::None;
        settings.environment.parallax = Parallax::Ground;
        Panel::new(label, headless.render(&gpu, &glass, &settings))
    };
    let mut fresnel = glass.settings.clone();
    fresnel.terms.fresnel = true;
    let refraction = vec![
        refracted("straight rays (the course)", Refraction::None),
        refracted("through the environment cube", Refraction::Environment),
        refracted("screen space", Refraction::Screen),
        Panel::new("ray traced", mirador::trace::render_image(&glass, &fresnel)),
    ];
    let image = rows(&[sheet(&top), sheet(&bottom), sheet(&refraction)]);
    mirador::output::write_png_atomically(&image, &out).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
