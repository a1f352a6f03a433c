//! Planar mirrors by a mirrored camera, side by side (docs/course/07-planar-mirrors.md).
//!
//! A z-buffer sees only what its camera sees, and a mirror shows what a camera behind it would
//! see: the camera mirrored about the mirror's plane. So the scene is drawn once more from that
//! mirrored camera, keeping only what lies in front of the mirror (its near plane is made the
//! mirror's plane), and the image is shown in the mirror's pixels, weighted by `kps·MPS` and
//! added to the mirror's own illumination model, as the ray tracer adds its reflected ray. Two
//! mirrors that face each other see each other: each level of reflection is one more mirrored
//! camera, up to `mirrors.depth`, as the tracer's `max_depth` bounds its mirror rays.
//!
//! Run with `cargo run --release --example planar_mirror [OUT.png]`; writes `planar_mirror.png`
//! by default.

use std::path::PathBuf;

use anyhow::Context;
use mirador::compare::sheet::{Panel, rows, sheet};
use mirador::gpu::Gpu;
use mirador::raster::Headless;
use mirador::settings::MirrorView;
use mirador::{RenderSettings, Scene};

const EXPLANATION: &str = "\
Planar mirrors: the scene drawn again by the camera mirrored about each mirror's plane.
Top: mirrors off (their illumination model alone) | one mirror (the right one made matte) |
two facing mirrors at depth 1 (the far mirror shows its plain material) | at depth 3 (the
corridor). Bottom: ray traced at max_depth 1 | at max_depth 3 | the left mirror's camera's own
image (the yellow post behind the mirror is clipped away by the oblique near plane) | the
mirrored cameras' view volumes drawn in the scene.";

fn main() -> anyhow::Result<()> {
    let out = std::env::args().nth(1).map_or_else(|| PathBuf::from("planar_mirror.png"), PathBuf::from);
    println!("{EXPLANATION}");
    let scene = Scene::load(&mirador::scene::builtin_path("mirrors.toml"))?;
    let mut one_mirror = scene.clone();
    let right = one_mirror.objects.iter().position(|o| o.name == "right mirror").context("the right mirror")?;
    let matte = one_mirror.materials.iter().position(|m| m.name == "frame").context("the frame material")?;
    one_mirror.objects[right].material = mirador::base::MaterialId(matte);

    let gpu = Gpu::headless()?;
    let base = scene.settings.clone();
    let variant = |change: &dyn Fn(&mut RenderSettings)| {
        let mut settings = base.clone();
        change(&mut settings);
        settings
    };
    let raster = |label: &str, scene: &Scene, settings: RenderSettings| {
        Panel::new(label, Headless::new(&gpu, scene).render(&gpu, scene, &settings))
    };
    let traced = |label: &str, depth: u32| {
        let settings = variant(&|s| s.trace.max_depth = depth);
        Panel::new(label, mirador::trace::render_image(&scene, &settings))
    };
    let top = vec![
        raster("mirrors off", &scene, variant(&|s| s.mirrors.enabled = false)),
        raster("one mirror", &one_mirror, base.clone()),
        raster("two mirrors, depth 1", &scene, variant(&|s| s.mirrors.depth = 1)),
        raster("two mirrors, depth 3", &scene, variant(&|s| s.mirrors.depth = 3)),
    ];
    let bottom = vec![
        traced("ray traced, max_depth 1", 1),
        traced("ray traced, max_depth 3", 3),
        raster("the mirror camera's own image", &scene, variant(&|s| s.mirrors.view = MirrorView::Image)),
        raster("the mirrored cameras", &scene, variant(&|s| s.mirrors.view = MirrorView::Camera)),
    ];
    let image = rows(&[sheet(&top), sheet(&bottom)]);
    mirador::output::write_png_atomically(&image, &out).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
