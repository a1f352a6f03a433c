//! Golden images of the built-in scenes, compared by mean FLIP. Lavapipe renders these
//! bit-identically run to run; the threshold leaves room for other drivers (Vulkan and GL differ
//! by a FLIP mean of about 0.002) while catching any visible change: moving the seed-simple light
//! by 5 units, or halving the ambient light, costs more than 0.01 (see the last test).

mod common;

/// The largest mean FLIP error a golden image may show.
const MAX_FLIP_MEAN: f32 = 0.01;

#[test]
fn seed_simple() {
    let scene = common::load("scenes/seed-simple.toml");
    common::assert_golden("seed-simple", &common::raster(&scene, &scene.settings), MAX_FLIP_MEAN);
}

#[test]
fn showcase() {
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (640, 360);
    common::assert_golden("showcase", &common::raster(&scene, &scene.settings), MAX_FLIP_MEAN);
}

#[test]
fn shadow_stage_with_shadow_maps() {
    let scene = common::load("scenes/shadows.toml");
    common::assert_golden("shadows-map", &common::raster(&scene, &scene.settings), MAX_FLIP_MEAN);
}

#[test]
fn shadow_stage_with_projected_polygons() {
    let scene = common::load("scenes/shadows.toml");
    let mut settings = scene.settings.clone();
    settings.shadows.method = mirador::settings::ShadowMethod::Projected;
    common::assert_golden("shadows-projected", &common::raster(&scene, &settings), MAX_FLIP_MEAN);
}

/// The showcase's floor running to the horizon, in each texture filter (TECHNIQUES.md §2).
#[test]
fn floor_in_every_texture_filter() {
    use mirador::settings::TextureFilter;
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (320, 180);
    // Look down the floor, away from the wall and the objects.
    scene.camera.eye = glam::Vec3::new(2.0, 1.2, 8.0);
    scene.camera.center = glam::Vec3::new(6.0, 0.2, -20.0);
    for (name, filter) in [
        ("floor-nearest", TextureFilter::Nearest),
        ("floor-bilinear", TextureFilter::Bilinear),
        ("floor-nearest-mip", TextureFilter::NearestMip),
        ("floor-trilinear", TextureFilter::Trilinear),
        ("floor-anisotropic", TextureFilter::Anisotropic),
        ("floor-level-colour", TextureFilter::LevelColour),
    ] {
        let mut settings = scene.settings.clone();
        settings.textures.filter = filter;
        common::assert_golden(name, &common::raster(&scene, &settings), MAX_FLIP_MEAN);
    }
}

#[test]
fn bump_mapped_tile_and_ball() {
    let scene = common::load("scenes/bumps.toml");
    common::assert_golden("bumps", &common::raster(&scene, &scene.settings), MAX_FLIP_MEAN);
}

/// The threshold is meaningful: small but visible changes to the scene exceed it.
#[test]
fn the_threshold_catches_visible_changes() {
    let scene = common::load("scenes/seed-simple.toml");
    let reference = common::raster(&scene, &scene.settings);
    let mut moved = scene.clone();
    if let mirador::scene::LightKind::Point { position } = &mut moved.lights[0].kind {
        position.x -= 5.0;
    }
    let flip = mirador::compare::difference(&reference, &common::raster(&moved, &moved.settings)).unwrap().flip_mean;
    assert!(flip > MAX_FLIP_MEAN, "moving the light 5 units changed the image by only {flip}");

    let mut dimmer = scene.clone();
    dimmer.ambient = glam::Vec3::splat(0.1);
    let flip = mirador::compare::difference(&reference, &common::raster(&dimmer, &dimmer.settings)).unwrap().flip_mean;
    assert!(flip > MAX_FLIP_MEAN, "halving the ambient light changed the image by only {flip}");
}
