//! Planar mirrors by a mirrored camera (docs/course/07-planar-mirrors.md): the rasterizer's mirrors against the
//! tracer's reflected rays, which they must match where the lighting, objects and depth are the
//! same; what lies behind a mirror stays out of its reflection; winding flips in mirrored views;
//! and the degenerate cases. The matrices themselves are tested by hand in
//! `src/raster/mirror/mod.rs`.

mod common;

use common::flip;
use mirador::settings::{MirrorView, TransparencySort};
use mirador::{RenderSettings, Scene};

fn scene() -> Scene {
    let mut scene = common::load("scenes/mirrors.toml");
    (scene.camera.width, scene.camera.height) = (240, 150);
    scene
}

/// Raster with `mirrors.depth = depth` against the tracer with `max_depth = depth`.
fn parity(scene: &Scene, raster_depth: u32, traced_depth: u32) -> f32 {
    let mut settings = scene.settings.clone();
    settings.mirrors.depth = raster_depth;
    settings.trace.max_depth = traced_depth;
    let raster = common::raster(scene, &settings);
    let traced = mirador::trace::render_image(scene, &settings);
    flip(&traced, &raster)
}

/// The fraction of pixels that are the yellow post's colour.
fn yellow(image: &image::RgbaImage) -> f32 {
    let count = image.pixels().filter(|p| p[0] > 150 && i32::from(p[1]) - i32::from(p[2]) > 60).count();
    count as f32 / (image.width() * image.height()) as f32
}

#[test]
fn one_mirror_agrees_with_the_tracers_reflected_rays() {
    let mut scene = scene();
    // Make the right mirror matte: the left one is then the only mirror.
    let right = scene.objects.iter().position(|o| o.name == "right mirror").unwrap();
    let matte = scene.materials.iter().position(|m| m.name == "frame").unwrap();
    scene.objects[right].material = mirador::base::MaterialId(matte);
    let with = parity(&scene, 3, 3);
    assert!(with < 0.04, "one mirror vs traced: FLIP {with}");
    // The test can tell: without the reflection the mirror is black where the tracer's is not.
    let mut off = scene.settings.clone();
    off.mirrors.enabled = false;
    let without = flip(&mirador::trace::render_image(&scene, &off), &common::raster(&scene, &off));
    assert!(without > with + 0.02, "mirrors off {without}, on {with}");
}

#[test]
fn two_facing_mirrors_give_the_tracers_corridor_at_depths_one_and_three() {
    let scene = scene();
    let (one, three) = (parity(&scene, 1, 1), parity(&scene, 3, 3));
    assert!(one < 0.04 && three < 0.04, "FLIP at depth 1: {one}, at depth 3: {three}");
    // Depth matters: the rasterizer's depth 1 is not the tracer's depth 3.
    let crossed = parity(&scene, 1, 3);
    assert!(crossed > three + 0.005, "raster depth 1 vs traced depth 3: {crossed}; matched: {three}");
}

#[test]
fn what_lies_behind_a_mirror_stays_out_of_its_reflection() {
    let scene = scene();
    // The yellow post behind the left mirror shows above it in the main view…
    let main = common::raster(&scene, &scene.settings);
    assert!(yellow(&main) > 0.001, "the post shows above the mirror");
    // …but the mirror camera, which sits behind the mirror, must not draw it: its near plane is
    // the mirror's plane. Without that clip the post would stand right in front of it.
    let mut settings = scene.settings.clone();
    settings.mirrors.view = MirrorView::Image;
    settings.mirrors.depth = 1;
    let mirrored = common::raster(&scene, &settings);
    assert!(yellow(&mirrored) == 0.0, "{} of the mirror camera's image is the post", yellow(&mirrored));
    assert_ne!(mirrored, main, "the mirror camera's view is a view of its own");
}

#[test]
fn transparent_objects_in_a_mirror_keep_their_order_with_the_winding_flipped() {
    // A glass sphere between the mirrors, ior 1: per object draws its back faces first, which in
    // a mirrored view are the ones the flipped winding calls front faces.
    let mut scene = scene();
    let text = "[materials.glass]\ncolor = [0.6, 0.8, 1.0]\nkd = 0.3\nks = 0.5\ntransmission = 0.7\nior = 1.0\n\
                [[objects]]\ntype = \"sphere\"\ncenter = [-1.4, 0.7, 0.2]\nradius = 0.5\nmaterial = \"glass\"\n";
    let extra = mirador::scene::file::parse(
        &format!("{}\n{text}", std::fs::read_to_string(common::asset("scenes/mirrors.toml")).unwrap()),
        &common::asset("scenes/mirrors.toml"),
    )
    .unwrap();
    scene.objects = extra.objects;
    scene.materials = extra.materials;
    let render = |sort| {
        let mut settings: RenderSettings = scene.settings.clone();
        settings.transparency.sort = sort;
        common::raster(&scene, &settings)
    };
    let exact = render(TransparencySort::Exact);
    let error = flip(&exact, &render(TransparencySort::Object));
    assert!(error < 0.0005, "per object vs exact, with the sphere in the mirrors: FLIP {error}");
    let mut settings = scene.settings.clone();
    settings.shadows.enabled = false;
    settings.transparency.sort = TransparencySort::Exact;
    let traced = flip(&mirador::trace::render_image(&scene, &settings), &common::raster(&scene, &settings));
    assert!(traced < 0.04, "the glass sphere in the mirrors vs traced: FLIP {traced}");
}

#[test]
fn degenerate_mirrors_are_drawn_plain_and_never_panic() {
    let scene = scene();
    let gpu = common::gpu();
    // The camera in the left mirror's plane (x = −2.5): that mirror is seen edge on and gets no
    // view; the right one still does.
    let mut edge_on = scene.clone();
    edge_on.camera.eye = glam::Vec3::new(-2.5, 1.2, 4.0);
    edge_on.camera.center = glam::Vec3::new(0.0, 1.0, -0.5);
    let mut headless = mirador::raster::Headless::new(gpu, &edge_on);
    headless.render(gpu, &edge_on, &edge_on.settings);
    assert!(headless.report.count("mirror views", "views") >= 1, "the right mirror still reflects");
    // The camera behind the left mirror, where its backing hides it: the mirror's view is
    // still planned (about the plane turned towards the camera: planes are two-sided mirrors in
    // both renderers), and the depth test hides it behind the backing, as in the tracer.
    let mut behind = scene.clone();
    behind.camera.eye = glam::Vec3::new(-4.5, 1.4, 1.5);
    behind.camera.center = glam::Vec3::new(-2.5, 1.1, -0.5);
    let mut settings = behind.settings.clone();
    settings.trace.max_depth = 3;
    let error = flip(&mirador::trace::render_image(&behind, &settings), &common::raster(&behind, &settings));
    assert!(error < 0.05, "behind the mirror: FLIP {error}");
    // A depth past the maximum is refused, not clamped silently.
    let mut settings = scene.settings.clone();
    assert!(settings.set("mirrors.depth=9").is_err());
    assert!(settings.set("mirrors.depth=8").is_ok());
}

#[test]
fn each_face_of_a_mirror_box_is_a_planar_mirror() {
    // A mirror cube between the two mirrors' stands, turned 30° so two faces face the camera.
    let mut scene = scene();
    let text = "[materials.chrome]\ncolor = [0.05, 0.05, 0.05]\nkd = 0.05\nmirror = 0.85\n\
                [[objects]]\nname = \"mirror cube\"\ntype = \"box\"\nmin = [-0.4, 0, -0.4]\nmax = [0.4, 0.8, 0.4]\n\
                rotate = [0, 30, 0]\ntranslate = [0.2, 0, 0.9]\nmaterial = \"chrome\"\n";
    let source = std::fs::read_to_string(common::asset("scenes/mirrors.toml")).unwrap();
    let with_cube =
        mirador::scene::file::parse(&format!("{source}\n{text}"), &common::asset("scenes/mirrors.toml")).unwrap();
    scene.objects = with_cube.objects;
    scene.materials = with_cube.materials;
    let gpu = common::gpu();
    let mut headless = mirador::raster::Headless::new(gpu, &scene);
    let mut settings = scene.settings.clone();
    settings.mirrors.depth = 1;
    settings.trace.max_depth = 1;
    let raster = headless.render(gpu, &scene, &settings);
    // The left mirror, and the cube's faces that face the camera (a top too, seen from above).
    assert!(
        headless.report.count("mirror views", "views") >= 3,
        "{} mirrored views",
        headless.report.count("mirror views", "views")
    );
    let traced = mirador::trace::render_image(&scene, &settings);
    let error = flip(&traced, &raster);
    assert!(error < 0.04, "the mirror cube vs traced: FLIP {error}");
    let mut off = settings.clone();
    off.mirrors.enabled = false;
    let without = flip(&traced, &common::raster(&scene, &off));
    assert!(without > error + 0.005, "mirrors off {without}, on {error}");
}
