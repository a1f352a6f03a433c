//! Environment maps, side by side (docs/course/08-environment-maps.md).
//!
//! A curved mirror reflects the radiance arriving along `r = 2(n·v)n − v`, which a z-buffer
//! cannot trace. It looks it up instead in a map of the radiance arriving from every direction,
//! made beforehand: a cube (six 90° images; `r` picks the face and the texel), a sphere map (one
//! image of a mirror ball, for one view direction) or a latitude–longitude map. The cube can be
//! drawn from the object's own centre, so it reflects its neighbours too (dynamic); the map is
//! then right for what is far and wrong for what is near (parallax), since it holds what arrives
//! at the centre and not at each point of the surface; a local lookup (`environment.parallax`,
//! docs/course/08-environment-maps.md#parallax) reads the cube where the ray meets a proxy of
//! the scene (its ground, or its box) instead, so what lies on the proxy lines up.
//!
//! Run with `cargo run --release --example environment_maps [OUT.png]`; writes
//! `environment_maps.png` by default.

use std::path::PathBuf;

use anyhow::Context;
use glam::Vec3;
use mirador::compare::sheet::{Panel, rows, sheet};
use mirador::gpu::Gpu;
use mirador::raster::Headless;
use mirador::settings::{EnvironmentMap, EnvironmentView, Parallax, SphereView};
use mirador::{RenderSettings, Scene};

const EXPLANATION: &str = "\
Environment maps: the chrome ball and the copper torus under the procedural sky.
Top: the world's cube (sky only: no floor, no neighbours in the reflections) | dynamic cubes
drawn from each object's centre (the floor and the neighbours appear) | the sphere map | the
lat-long map | ray traced.
Middle: the maps as images: the ball's dynamic cube unfolded as a cross | the sphere map | the
lat-long map | a fixed sphere map seen after the camera turned (the reflections turn with the
camera) | the same map made again for the new view.
Third row: parallax. A red wall near the ball, then ten times as far and as big: cube (left)
against ray traced (right) for each.
Bottom: the floor in the ball, local lookups: the cube read infinitely far (the course's rule) |
read where the reflected ray meets the ground | ray traced.";

fn main() -> anyhow::Result<()> {
    let out = std::env::args().nth(1).map_or_else(|| PathBuf::from("environment_maps.png"), PathBuf::from);
    println!("{EXPLANATION}");
    let mut scene = Scene::load(&mirador::scene::builtin_path("environment.toml"))?;
    (scene.camera.width, scene.camera.height) = (480, 270);
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
    let top = vec![
        raster("world cube", &scene, variant(&|s| s.environment.dynamic = false)),
        raster("dynamic cubes", &scene, base.clone()),
        raster("sphere map", &scene, variant(&|s| s.environment.map = EnvironmentMap::Sphere)),
        raster("lat-long map", &scene, variant(&|s| s.environment.map = EnvironmentMap::Latlong)),
        Panel::new("ray traced", mirador::trace::render_image(&scene, &base)),
    ];
    // The maps over the whole panel (not inset), so the sheet shows them at their largest.
    let view = |v: EnvironmentView| variant(&|s| (s.environment.view, s.environment.inset) = (v, false));
    // A sphere map made for the first camera, then seen from a turned one.
    let mut turned = scene.clone();
    turned.camera.eye = Vec3::new(1.5, 5.5, 3.5);
    let sphere_after_turning = |follow: SphereView| {
        let settings = variant(&|s| {
            s.environment.map = EnvironmentMap::Sphere;
            s.environment.sphere_view = follow;
        });
        let mut headless = Headless::new(&gpu, &scene);
        headless.render(&gpu, &scene, &settings);
        headless.render(&gpu, &turned, &settings)
    };
    let middle = vec![
        raster("the ball's cube, unfolded", &scene, view(EnvironmentView::Cross)),
        raster("the sphere map", &scene, view(EnvironmentView::Sphere)),
        raster("the lat-long map", &scene, view(EnvironmentView::Latlong)),
        Panel::new("fixed sphere map, camera turned", sphere_after_turning(SphereView::Fixed)),
        Panel::new("sphere map made again", sphere_after_turning(SphereView::Follow)),
    ];
    let wall = |scale: f32| -> anyhow::Result<Scene> {
        let mut scene = scene.clone();
        let index = scene.objects.iter().position(|o| o.name == "blue box").context("the blue box")?;
        let red = scene.materials.iter().position(|m| m.name == "paint").context("the paint")?;
        scene.materials[red].color = Vec3::new(0.8, 0.1, 0.08);
        let centre = Vec3::new(-0.9, 0.9, 0.0);
        let near = glam::Mat4::from_translation(centre + Vec3::new(-2.2, -0.9, 0.5) * scale)
            * glam::Mat4::from_scale(Vec3::new(0.4, 2.5, 3.0) * scale / Vec3::new(1.0, 0.8, 0.8));
        scene.objects[index].world_from_local = near * glam::Mat4::from_translation(-Vec3::new(0.4, 0.0, -1.6));
        Ok(scene)
    };
    let (near, far) = (wall(1.0)?, wall(10.0)?);
    let bottom = vec![
        raster("near wall: cube", &near, base.clone()),
        Panel::new("near wall: ray traced", mirador::trace::render_image(&near, &base)),
        raster("far wall: cube", &far, base.clone()),
        Panel::new("far wall: ray traced", mirador::trace::render_image(&far, &base)),
    ];
    let local = vec![
        raster("cube, infinitely far", &scene, base.clone()),
        raster("cube, on the ground", &scene, variant(&|s| s.environment.parallax = Parallax::Ground)),
        Panel::new("ray traced", mirador::trace::render_image(&scene, &base)),
    ];
    let image = rows(&[sheet(&top), sheet(&middle), sheet(&bottom), sheet(&local)]);
    mirador::output::write_png_atomically(&image, &out).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
