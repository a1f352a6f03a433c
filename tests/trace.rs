//! The ray tracer: radiance known by hand, Whitted's recursion (mirrors, glass, transparent
//! shadows, depth), anti-aliasing and determinism, and agreement with the rasterizer where the
//! theory says the two must agree.

mod common;

use std::path::Path;
use std::sync::atomic::AtomicBool;

use glam::{Vec2, Vec3};
use mirador::scene::file::parse;
use mirador::settings::AntiAliasing;
use mirador::trace::accel::AccelKind;
use mirador::trace::whitted::RayCounts;
use mirador::trace::{Cancelled, Progressive, RenderControl, Tracer};
use mirador::{RenderSettings, Scene};

fn scene(text: &str) -> Scene {
    parse(text, Path::new("test.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// A unit sphere at the origin, kd = 0.5, white, seen from +z; one point light on the z axis.
const UNIT_SPHERE: &str = r#"
    [camera]
    eye = [0, 0, 5]
    center = [0, 0, 0]
    fovy = 30
    near = 1
    far = 10
    width = 31
    height = 31
    [world]
    ambient = [0, 0, 0]
    background = [0, 0, 0]
    [materials.matte]
    color = [1, 1, 1]
    kd = 0.5
    [[lights]]
    type = "point"
    position = [0, 0, 3]
    intensity = 4
    attenuation = "inverse_square"
    [[objects]]
    type = "sphere"
    radius = 1
    material = "matte"
"#;

#[test]
fn unit_sphere_radiance_matches_the_hand_computation() {
    let scene = scene(UNIT_SPHERE);
    let tracer = Tracer::new(&scene, &scene.settings);
    let mut counts = RayCounts::default();
    // The centre pixel's ray runs down −z and hits (0, 0, 1): n = l = +z, d = 2,
    // S = 4/2² = 1, L = kd·C·(n·l)·S = 0.5.
    let centre = tracer.primary(Vec2::new(15.5, 15.5), &mut counts);
    assert!(centre.abs_diff_eq(Vec3::splat(0.5), 1e-5), "{centre}");
    // Any other pixel: intersect by hand and evaluate kd·C·(n·l)·I/d².
    for (x, y) in [(12.5, 15.5), (15.5, 19.5), (10.5, 11.5)] {
        let ray = scene.camera.ray_through(x, y);
        let b = ray.origin.dot(ray.direction);
        let t = -b - (b * b - (ray.origin.length_squared() - 1.0)).sqrt();
        let p = ray.at(t);
        let to_light = Vec3::new(0.0, 0.0, 3.0) - p;
        let expected = 0.5 * p.dot(to_light.normalize()).max(0.0) * 4.0 / to_light.length_squared();
        let got = tracer.primary(Vec2::new(x, y), &mut counts);
        assert!((got.x - expected).abs() < 1e-5, "pixel ({x}, {y}): {got} vs {expected}");
    }
    // A ray that misses sees the background.
    assert_eq!(tracer.primary(Vec2::new(0.5, 0.5), &mut counts), Vec3::ZERO);
}

const MIRROR_AND_GLASS: &str = r#"
    [camera]
    eye = [0, 0, 5]
    center = [0, 0, 0]
    fovy = 40
    near = 0.5
    far = 50
    width = 21
    height = 21
    [world]
    ambient = [0, 0, 0]
    background = [0.2, 0.4, 0.6]
    [materials.mirror]
    color = [0, 0, 0]
    kd = 0
    mirror = 0.5
    mirror_color = [1, 0.5, 1]
    [[objects]]
    type = "plane"
    size = [10, 10]
    rotate = [90, 0, 0]
    material = "mirror"
"#;

#[test]
fn a_mirror_shows_kps_mps_times_what_it_reflects() {
    let scene = scene(MIRROR_AND_GLASS);
    let tracer = Tracer::new(&scene, &scene.settings);
    let mut counts = RayCounts::default();
    // The mirror faces the camera; the reflected ray runs back past the eye to the background.
    let got = tracer.primary(Vec2::new(10.5, 10.5), &mut counts);
    let expected = 0.5 * Vec3::new(1.0, 0.5, 1.0) * Vec3::new(0.2, 0.4, 0.6);
    assert!(got.abs_diff_eq(expected, 1e-6), "{got} vs {expected}");
    assert_eq!((counts.primary, counts.reflected), (1, 1));
}

#[test]
fn two_facing_mirrors_stop_at_the_maximum_depth() {
    let text = MIRROR_AND_GLASS.replace("eye = [0, 0, 5]", "eye = [0, 0, 4]").to_string()
        + r#"
    [[objects]]
    type = "plane"
    size = [10, 10]
    rotate = [90, 0, 0]
    translate = [0, 0, 4.5]
    material = "mirror"
    "#;
    let mut scene = scene(&text);
    for depth in [0, 3, 7] {
        scene.settings.trace.max_depth = depth;
        let tracer = Tracer::new(&scene, &scene.settings);
        let mut counts = RayCounts::default();
        let got = tracer.primary(Vec2::new(10.5, 10.5), &mut counts);
        assert_eq!(counts.reflected, u64::from(depth), "depth {depth}");
        // Each bounce multiplies by kps·MPS; the last ray ends with the local model, here 0.
        assert!(got.is_finite() && got == Vec3::ZERO, "depth {depth}: {got}");
    }
}

/// A floor lit from straight above, with a pane of coloured glass between the floor and light.
fn pane_scene(panes: usize) -> Scene {
    let mut text = String::from(
        r#"
        [camera]
        eye = [0, 10, 0.001]
        center = [0, 0, 0]
        fovy = 20
        near = 1
        far = 50
        width = 9
        height = 9
        [world]
        ambient = [0, 0, 0]
        [materials.floor]
        color = [1, 1, 1]
        [materials.glass]
        color = [0, 0, 0]
        kd = 0
        transmission = 0.5
        transmission_color = [1, 0.5, 0.25]
        ior = 1
        [[lights]]
        type = "point"
        position = [0, 8, 0]
        [[objects]]
        type = "plane"
        size = [4, 4]
        material = "floor"
        "#,
    );
    for k in 0..panes {
        text += &format!(
            "[[objects]]\ntype = \"plane\"\nsize = [40, 40]\ntranslate = [0, {}, 0]\nmaterial = \"glass\"\n",
            4 + k
        );
    }
    scene(&text)
}

#[test]
fn transparent_occluders_cast_partial_coloured_shadows() {
    let clear = pane_scene(0);
    let tracer = Tracer::new(&clear, &clear.settings);
    let mut counts = RayCounts::default();
    let p = Vec3::new(0.0, 0.0, 0.0);
    assert_eq!(tracer.whitted.visibility(p, Vec3::Y, 8.0, &mut counts), Vec3::ONE);
    for panes in [1, 2] {
        let scene = pane_scene(panes);
        let tracer = Tracer::new(&scene, &scene.settings);
        let expected = (0.5 * Vec3::new(1.0, 0.5, 0.25)).powf(panes as f32);
        let got = tracer.whitted.visibility(p, Vec3::Y, 8.0, &mut counts);
        assert!(got.abs_diff_eq(expected, 1e-6), "{panes} panes: {got} vs {expected}");
    }
    // An opaque occluder blocks the light entirely.
    let mut opaque = pane_scene(1);
    opaque.materials[1].transmission = 0.0;
    let tracer = Tracer::new(&opaque, &opaque.settings);
    assert_eq!(tracer.whitted.visibility(p, Vec3::Y, 8.0, &mut counts), Vec3::ZERO);
}

#[test]
fn glass_of_index_one_is_invisible_when_it_transmits_everything() {
    let mut with_pane = pane_scene(1);
    let glass = &mut with_pane.materials[1];
    (glass.transmission, glass.transmission_color) = (1.0, Vec3::ONE);
    with_pane.settings.shadows.enabled = false;
    let mut without = pane_scene(0);
    without.settings.shadows.enabled = false;
    let a = mirador::trace::render_image(&with_pane, &with_pane.settings);
    let b = mirador::trace::render_image(&without, &without.settings);
    assert_same_image(&a, &b, "a straight-through pane must not change the image");
}

#[test]
fn a_scene_without_lights_shows_emission_and_ambient_only() {
    let mut scene = scene(&UNIT_SPHERE.replace("[[lights]]\n    type = \"point\"\n    position = [0, 0, 3]\n    intensity = 4\n    attenuation = \"inverse_square\"\n", ""));
    assert!(scene.lights.is_empty());
    scene.ambient = Vec3::splat(0.2);
    let tracer = Tracer::new(&scene, &scene.settings);
    let got = tracer.primary(Vec2::new(15.5, 15.5), &mut RayCounts::default());
    assert!(got.abs_diff_eq(Vec3::splat(0.2 * 0.5), 1e-6), "AG = A ⊗ kd·C: {got}");
}

#[test]
fn a_camera_inside_a_sphere_sees_its_inside() {
    let text = UNIT_SPHERE.replace("eye = [0, 0, 5]", "eye = [0, 0, 0.5]").replace("near = 1", "near = 0.1");
    let scene = scene(&text);
    let image = mirador::trace::render_image(&scene, &scene.settings);
    assert!(image.pixels().all(|p| p[3] == 255));
}

/// Fails with the number of differing pixels (not a dump of both images) when `a` ≠ `b`.
fn assert_same_image(a: &image::RgbaImage, b: &image::RgbaImage, what: &str) {
    assert_eq!(a.dimensions(), b.dimensions(), "{what}: sizes differ");
    let differing: Vec<(u32, u32)> =
        a.enumerate_pixels().filter(|(x, y, p)| *p != b.get_pixel(*x, *y)).map(|(x, y, _)| (x, y)).take(1000).collect();
    assert!(
        differing.is_empty(),
        "{what}: {} pixels differ, first at {:?}",
        differing.len(),
        &differing[..differing.len().min(8)]
    );
}

fn small_showcase() -> Scene {
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (96, 54);
    scene
}

#[test]
fn jittered_sampling_is_deterministic_across_runs_and_threads() {
    let mut scene = small_showcase();
    scene.settings.trace.anti_aliasing = AntiAliasing::Jittered;
    scene.settings.trace.samples = 2;
    let render = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| mirador::trace::render_image(&scene, &scene.settings))
    };
    let once = render(2);
    assert_same_image(&once, &render(2), "two runs");
    assert_same_image(&once, &render(1), "one thread and two threads");
    scene.settings.trace.seed = 1;
    assert!(once != mirador::trace::render_image(&scene, &scene.settings), "the seed changes nothing");
}

#[test]
fn every_accelerator_draws_the_same_image() {
    let scene = small_showcase();
    let reference = mirador::trace::render_image(&scene, &scene.settings);
    for accelerator in [AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree, AccelKind::None] {
        let mut settings = scene.settings.clone();
        settings.trace.accelerator = accelerator;
        assert_same_image(
            &mirador::trace::render_image(&scene, &settings),
            &reference,
            &format!("{accelerator:?} vs the wide BVH"),
        );
    }
}

/// The wide BVH (the default) and the binary one the course builds draw the same image of
/// every scene under `assets/scenes/`, at a fifth of its size.
#[test]
fn the_wide_and_the_binary_bvh_draw_the_same_image_of_every_scene() {
    let mut folders = vec![common::asset("scenes")];
    let mut scenes = 0;
    while let Some(folder) = folders.pop() {
        let mut entries: Vec<_> = std::fs::read_dir(&folder).unwrap().map(|e| e.unwrap().path()).collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                folders.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "toml") {
                continue;
            }
            let mut scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
            (scene.camera.width, scene.camera.height) = (scene.camera.width / 5, scene.camera.height / 5);
            let wide = mirador::trace::render_image(&scene, &scene.settings);
            let mut settings = scene.settings.clone();
            assert_eq!(settings.trace.accelerator, AccelKind::Wide, "{}: the default", path.display());
            settings.trace.accelerator = AccelKind::Bvh;
            assert_same_image(&mirador::trace::render_image(&scene, &settings), &wide, &path.display().to_string());
            scenes += 1;
        }
    }
    assert!(scenes >= 26, "only {scenes} scenes found");
}

#[test]
fn corner_rays_are_shared_between_neighbours() {
    let mut scene = common::load("scenes/seed-simple.toml");
    (scene.camera.width, scene.camera.height) = (96, 54);
    scene.settings.trace.anti_aliasing = AntiAliasing::Corners;
    let tracer = Tracer::new(&scene, &scene.settings);
    let (_, stats) = tracer.render(&RenderControl::default()).unwrap();
    assert_eq!(stats.rays.primary, (96 + 1) * (54 + 1));

    scene.settings.trace.anti_aliasing = AntiAliasing::Adaptive;
    let adaptive = Tracer::new(&scene, &scene.settings);
    let (_, adaptive_stats) = adaptive.render(&RenderControl::default()).unwrap();
    let extra = adaptive_stats.rays.primary - stats.rays.primary;
    assert!(extra > 0 && extra % 5 == 0, "each split adds five rays, got {extra} extra");
    // Seed-simple is mostly flat shading: far fewer rays than supersampling every pixel to the
    // same depth (8 × 8 rays a pixel at level 3) would take, and more than corners alone.
    assert!(adaptive_stats.rays.primary < 96 * 54 * 4, "{}", adaptive_stats.rays.primary);
}

#[test]
fn progressive_refinement_ends_at_the_centre_sampled_image() {
    let scene = small_showcase();
    let tracer = Tracer::new(&scene, &scene.settings);
    let (full, _) = tracer.render(&RenderControl::default()).unwrap();
    let mut progressive = Progressive::new(&tracer, 16);
    let mut levels = Vec::new();
    while let Some(block) = progressive.refine(&tracer) {
        levels.push(block);
    }
    assert_eq!(levels, vec![16, 8, 4, 2, 1]);
    assert_eq!(progressive.image(), &full);
    assert_eq!(progressive.rays().primary, 96 * 54, "each pixel is traced exactly once over all levels");
}

/// The browser traces a few rows between frames (`Tracer::render_rows`); joined, the slices must
/// be the image `render` gives, in every anti-aliasing mode (the corner modes compute a corner
/// grid for each slice).
#[test]
fn an_image_traced_in_slices_of_rows_is_the_whole_render() {
    for mode in [
        AntiAliasing::Center,
        AntiAliasing::Regular,
        AntiAliasing::Jittered,
        AntiAliasing::Corners,
        AntiAliasing::Adaptive,
    ] {
        let mut scene = small_showcase();
        scene.settings.trace.anti_aliasing = mode;
        scene.settings.trace.samples = 2;
        let tracer = Tracer::new(&scene, &scene.settings);
        let (full, _) = tracer.render(&RenderControl::default()).unwrap();
        let mut sliced = Vec::new();
        for first in (0..54).step_by(7) {
            sliced.extend(tracer.render_rows(first..(first + 7).min(54)).0);
        }
        assert_eq!(sliced.len(), full.pixels.len(), "{mode:?}");
        assert!(sliced == full.pixels, "{mode:?}: the slices differ from the whole render");
    }
}

#[test]
fn a_cancelled_render_stops_with_an_error() {
    let scene = small_showcase();
    let tracer = Tracer::new(&scene, &scene.settings);
    let cancel = AtomicBool::new(true);
    let result = tracer.render(&RenderControl { cancel: Some(&cancel), progress: false });
    assert!(matches!(result, Err(Cancelled)));
}

/// Where theory says the two renderers agree: seed-simple without cast shadows (the rasterizer
/// has none until shadow maps land). What differs: the sphere is tessellated in the rasterizer
/// (96 slices), so its silhouette and interpolated normals differ slightly from the exact sphere;
/// both sample pixel centres, so aliasing is the same. Measured: FLIP mean 0.0045, PSNR 58.7 dB.
#[test]
fn raster_and_ray_traced_seed_simple_agree_without_shadows() {
    let mut scene = common::load("scenes/seed-simple.toml");
    scene.settings.shadows.enabled = false;
    let raster = common::raster(&scene, &scene.settings);
    let traced = mirador::trace::render_image(&scene, &scene.settings);
    let difference = common::difference(&traced, &raster);
    assert!(difference.flip_mean < 0.01, "FLIP mean {}", difference.flip_mean);
    assert!(difference.psnr_db > 45.0, "PSNR {} dB", difference.psnr_db);
}

/// The orthographic camera of the course (docs/course/01-camera.md): parallel rays along −ze in both
/// renderers.
#[test]
fn raster_and_ray_traced_agree_through_an_orthographic_camera() {
    let mut scene = common::load("scenes/shadows.toml");
    scene.camera.projection = mirador::scene::Projection::Orthographic;
    scene.camera.ortho_height = 5.0;
    let raster = common::raster(&scene, &scene.settings);
    let traced = mirador::trace::render_image(&scene, &scene.settings);
    let difference = common::difference(&traced, &raster);
    assert!(difference.flip_mean < 0.015, "FLIP mean {}", difference.flip_mean);
}

/// With shadows on, the tracer darkens exactly the sphere's shadow on the floor: every pixel
/// that changes is darker, and they form one blob below and to the left of the sphere.
#[test]
fn the_traced_shadow_falls_away_from_the_light() {
    let mut scene = common::load("scenes/seed-simple.toml");
    let lit = mirador::trace::render_image(&scene, &scene.settings);
    scene.settings.shadows.enabled = false;
    let unlit = mirador::trace::render_image(&scene, &scene.settings);
    let mut darker = 0;
    let mut centroid = Vec2::ZERO;
    for (x, y, p) in lit.enumerate_pixels() {
        let q = unlit.get_pixel(x, y);
        assert!(p[0] <= q[0] && p[1] <= q[1] && p[2] <= q[2], "shadows only darken: ({x}, {y})");
        if p != q {
            darker += 1;
            centroid += Vec2::new(x as f32, y as f32);
        }
    }
    assert!(darker > 500, "the sphere's shadow covers {darker} pixels");
    let centroid = centroid / darker as f32;
    let sphere = scene.camera.project(Vec3::new(0.0, 20.0, 0.0)).unwrap().truncate();
    assert!(centroid.y > sphere.y, "the shadow lies below the sphere: {centroid} vs {sphere}");
}

#[test]
fn default_settings_trace_with_the_wide_bvh() {
    assert_eq!(RenderSettings::default().trace.accelerator, AccelKind::Wide);
}

/// The seed's simple level rule against ray cones on the showcase floor: the cone's footprint is
/// stretched by 1/|cos θ| where the ray meets the floor at θ from its normal, and the distance
/// rule ignores θ, so the two levels differ by exactly log2(1/|cos θ|): a little below the
/// camera, and by several levels towards the horizon, where the distance rule aliases.
#[test]
fn distance_levels_ignore_the_grazing_angle_that_ray_cones_see() {
    use mirador::settings::TracerLod;
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (320, 180);
    let tracer_for = |rule: TracerLod| {
        let mut settings = scene.settings.clone();
        settings.textures.tracer_lod = rule;
        Tracer::new(&scene, &settings)
    };
    let (cone, distance) = (tracer_for(TracerLod::RayCone), tracer_for(TracerLod::Distance));
    let mut gaps = Vec::new();
    for y in [178.5, 150.5, 120.5, 95.5] {
        let ray = scene.camera.ray_through(300.5, y);
        let by_cone = cone.whitted.texture_lod(&ray, cone.primary_cone).expect("the floor is textured");
        let by_distance = distance.whitted.texture_lod(&ray, distance.primary_cone).expect("the floor is textured");
        let stretch = -ray.direction.y.abs().log2();
        assert!(
            ((by_cone - by_distance) - stretch).abs() < 1e-3,
            "row {y}: cone {by_cone}, distance {by_distance}, log2(1/cos) {stretch}"
        );
        gaps.push(stretch);
    }
    assert!(gaps.windows(2).all(|w| w[1] > w[0]) && gaps[3] > 2.0, "{gaps:?}");
}
