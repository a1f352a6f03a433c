//! The rasterizer's speed work changes no image and redoes only what changed: shadow maps kept
//! while the camera moves and redrawn when a light moves, projected polygons likewise, one mesh
//! shared by every sphere, the depth prepass and the specialised shader variants drawing the same
//! pixels as the plain z-buffer, and the render scale upscaling to the output's size.

mod common;

use glam::{Quat, Vec3};
use mirador::raster::Headless;
use mirador::scene::LightKind;
use mirador::settings::{Prepass, ShadowFit, ShadowMethod};

fn showcase_small() -> mirador::Scene {
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (320, 180);
    scene
}

#[test]
fn a_camera_move_redraws_no_shadow_map_and_a_light_move_redraws_its_own() {
    let mut scene = showcase_small();
    // Fitted to the scene, the directional light's map no longer follows the camera.
    scene.settings.shadows.fit = ShadowFit::Scene;
    let settings = scene.settings.clone();
    let gpu = common::gpu();
    let mut headless = Headless::new(gpu, &scene);
    headless.render(gpu, &scene, &settings);
    assert_eq!(
        headless.report.count("shadow maps", "layers drawn"),
        7,
        "first frame: six cube faces and one directional layer"
    );

    scene.camera.eye = Quat::from_rotation_y(0.02) * scene.camera.eye;
    headless.render(gpu, &scene, &settings);
    assert_eq!(headless.report.count("shadow maps", "layers drawn"), 0, "a camera move keeps every layer");

    let LightKind::Point { position } = &mut scene.lights[0].kind else {
        panic!("the showcase's first light is a point")
    };
    *position += Vec3::new(0.2, 0.0, 0.0);
    headless.render(gpu, &scene, &settings);
    assert_eq!(
        headless.report.count("shadow maps", "layers drawn"),
        6,
        "moving the point light redraws its six faces, not the sun's"
    );

    let mut biased = settings.clone();
    biased.shadows.depth_bias += 1;
    headless.render(gpu, &scene, &biased);
    assert_eq!(headless.report.count("shadow maps", "layers drawn"), 7, "a new bias redraws every layer");
}

#[test]
fn a_view_fitted_directional_map_follows_the_camera() {
    let mut scene = showcase_small();
    scene.settings.shadows.fit = ShadowFit::View;
    let settings = scene.settings.clone();
    let gpu = common::gpu();
    let mut headless = Headless::new(gpu, &scene);
    headless.render(gpu, &scene, &settings);
    scene.camera.eye = Quat::from_rotation_y(0.02) * scene.camera.eye;
    headless.render(gpu, &scene, &settings);
    assert_eq!(
        headless.report.count("shadow maps", "layers drawn"),
        1,
        "only the directional light's layer follows the view"
    );
}

#[test]
fn kept_shadow_maps_draw_the_same_image_as_fresh_ones() {
    let mut scene = showcase_small();
    let gpu = common::gpu();
    let mut headless = Headless::new(gpu, &scene);
    let mut settings = scene.settings.clone();
    settings.shadows.fit = ShadowFit::Scene;
    headless.render(gpu, &scene, &settings);
    scene.camera.eye = Quat::from_rotation_y(0.05) * scene.camera.eye;
    let kept = headless.render(gpu, &scene, &settings);
    assert_eq!(headless.report.count("shadow maps", "layers drawn"), 0);
    let fresh = mirador::raster::render_image(gpu, &scene, &settings);
    assert_eq!(kept.as_raw(), fresh.as_raw(), "a kept map is the map that would be drawn");
}

#[test]
fn projected_polygons_are_kept_until_a_light_moves() {
    let mut scene = common::load("scenes/shadows.toml");
    scene.settings.shadows.method = ShadowMethod::Projected;
    let settings = scene.settings.clone();
    let gpu = common::gpu();
    let mut headless = Headless::new(gpu, &scene);
    headless.render(gpu, &scene, &settings);
    assert!(headless.report.flag("projected shadows", "recomputed"));
    scene.camera.eye += Vec3::new(0.3, 0.0, 0.0);
    headless.render(gpu, &scene, &settings);
    assert!(!headless.report.flag("projected shadows", "recomputed"), "the camera does not change the polygons");
    scene.lights[0].intensity *= 0.5;
    headless.render(gpu, &scene, &settings);
    assert!(headless.report.flag("projected shadows", "recomputed"), "any change to the lights recomputes them");
}

#[test]
fn the_depth_prepass_changes_no_pixel() {
    let scene = showcase_small();
    let gpu = common::gpu();
    let mut with = scene.settings.clone();
    with.raster.depth_prepass = Prepass::Always;
    let mut without = scene.settings.clone();
    without.raster.depth_prepass = Prepass::Never;
    let a = mirador::raster::render_image(gpu, &scene, &with);
    let b = mirador::raster::render_image(gpu, &scene, &without);
    assert_eq!(a.as_raw(), b.as_raw(), "shading only the prepass's depths draws exactly the z-buffer's image");
}

#[test]
fn spheres_share_one_mesh_and_far_ones_get_fewer_triangles() {
    let path = std::path::Path::new("sphereflake-2.toml");
    let scene = mirador::scene::file::parse(&mirador::scene::sphereflake::sphereflake_toml(2, 320, 180), path).unwrap();
    let gpu = common::gpu();
    let mut headless = Headless::new(gpu, &scene);
    headless.render(gpu, &scene, &scene.settings);
    let geometry = &headless.renderer.scene_gpu().geometry;
    // 91 spheres in three sizes on screen, and the ground plane.
    assert!(geometry.mesh_count() <= 5, "{} meshes for 91 spheres and a plane", geometry.mesh_count());
    let adaptive = headless.report.triangles;
    let mut fixed = scene.settings.clone();
    fixed.raster.adaptive_tessellation = false;
    headless.render(gpu, &scene, &fixed);
    let full = headless.report.triangles;
    assert!(adaptive * 4 < full, "adaptive tessellation draws {adaptive} triangles, fixed {full}");
}

#[test]
fn segments_keep_the_outline_within_a_sixteenth_of_a_pixel() {
    use mirador::raster::geometry::segments_for_pixels;
    for pixels in [0.5f32, 2.0, 10.0, 40.0, 100.0, 300.0] {
        let n = segments_for_pixels(pixels, 4096);
        let sagitta = pixels * (1.0 - (std::f32::consts::PI / n as f32).cos());
        assert!(sagitta <= 1.0 / 16.0 + 1e-4, "{pixels} px: {n} segments leave {sagitta} px");
    }
    assert_eq!(segments_for_pixels(1000.0, 96), 96, "never more than the setting");
}

#[test]
fn a_half_render_scale_is_upscaled_to_the_full_image() {
    let scene = showcase_small();
    let gpu = common::gpu();
    let full = mirador::raster::render_image(gpu, &scene, &scene.settings);
    let mut half = scene.settings.clone();
    half.raster.render_scale = 0.5;
    let mut headless = Headless::new(gpu, &scene);
    let upscaled = headless.render(gpu, &scene, &half);
    assert_eq!(headless.report.drawn_size, (160, 90));
    assert_eq!(upscaled.dimensions(), full.dimensions());
    let difference = common::difference(&full, &upscaled);
    // Half the resolution blurs edges and textures: visible, but the same picture.
    assert!(difference.flip_mean < 0.12, "FLIP mean {}", difference.flip_mean);
    assert!(difference.flip_mean > 0.005, "a half-resolution image cannot be the full one");
}

#[test]
fn a_gltf_mesh_used_by_two_nodes_is_one_instanced_draw() {
    // two_nodes.gltf: two nodes draw the same two-primitive mesh.
    let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/gltf/two_nodes.gltf"));
    let mut scene = mirador::Scene::load(path).unwrap();
    assert_eq!(scene.meshes.len(), 2);
    // Its first primitive is flat and its material reflects (kps > 0): a planar mirror, which
    // is drawn on its own with its own reflection. Matte materials keep the test on instancing.
    for material in &mut scene.materials {
        material.mirror = 0.0;
    }
    let gpu = common::gpu();
    let mut headless = Headless::new(gpu, &scene);
    headless.render(gpu, &scene, &scene.settings);
    let geometry = &headless.renderer.scene_gpu().geometry;
    assert_eq!(geometry.mesh_count(), 2, "each primitive uploaded once");
    let file_batches: Vec<_> =
        geometry.batches.iter().filter(|b| matches!(b.mesh, mirador::raster::geometry::MeshKey::File(_))).collect();
    assert_eq!(file_batches.len(), 2, "one draw per primitive: {file_batches:?}");
    assert!(file_batches.iter().all(|b| b.instances.len() == 2), "each drawn for both nodes: {file_batches:?}");
}
