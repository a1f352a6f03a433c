//! Cast shadows (docs/course/05-shadows.md): the light-space matrices by hand, no acne at default
//! settings, and agreement with the ray tracer's shadow rays, which are the exact answer the
//! shadow map approximates: for both the shadow-map and the projected-polygon methods, for a
//! point light's six cube faces, and for transparent occluders.

mod common;

use std::path::Path;

use glam::{Vec2, Vec3};
use mirador::raster::shadow::views::{LightView, cube_face, project, shadow_layout};
use mirador::scene::file::parse;
use mirador::settings::{ShadowFilter, ShadowMethod};
use mirador::{RenderSettings, Scene};

fn scene(text: &str) -> Scene {
    parse(text, Path::new("shadows.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// Raster and ray-traced images of `scene` with its settings, and their mean FLIP difference.
fn parity(scene: &Scene, settings: &RenderSettings) -> (image::RgbaImage, image::RgbaImage, f32) {
    let raster = common::raster(scene, settings);
    let traced = mirador::trace::render_image(scene, settings);
    let flip = common::difference(&traced, &raster).flip_mean;
    (raster, traced, flip)
}

/// The fraction of pixels whose channels differ by more than `tolerance`.
fn fraction_differing(a: &image::RgbaImage, b: &image::RgbaImage, tolerance: u8) -> f32 {
    let differing = a.pixels().zip(b.pixels()).filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > tolerance)).count();
    differing as f32 / (a.width() * a.height()) as f32
}

const CAMERA: &str = r#"
    [camera]
    eye = [0, 6, 8]
    center = [0, 0, 0]
    fovy = 50
    near = 0.1
    far = 50
    width = 160
    height = 120
    [world]
    ambient = [0.1, 0.1, 0.1]
    [materials.white]
    color = [0.8, 0.8, 0.8]
"#;

#[test]
fn a_directional_light_straight_down_maps_x_and_z_to_the_map_by_hand() {
    // One box from (−1, 0, −1) to (1, 2, 1); the camera's reach is larger than the scene, so the
    // map's window is the scene's footprint: x ∈ [−1, 1], z ∈ [−1, 1] (plus a 1e-3 margin).
    let text = format!(
        "{CAMERA}\n[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0]\n[[objects]]\ntype = \"box\"\nmin = [-1, 0, -1]\nmax = [1, 2, 1]\nmaterial = \"white\"\n"
    );
    let scene = scene(&text);
    let layout = shadow_layout(&scene, &scene.settings.shadows);
    assert_eq!(layout.views.len(), 1);
    assert_eq!(layout.first_layer, vec![Some(0)]);
    let view = &layout.views[0];
    assert!(!view.perspective);
    // Looking down −y with up = +z: the map's right is +x... or −x, depending on the frame; the
    // centre of the footprint lands at the centre of the map either way, and the corners of the
    // footprint at its corners.
    let centre = project(view, Vec3::new(0.0, 1.0, 0.0)).unwrap();
    assert!(centre.truncate().abs_diff_eq(Vec2::splat(0.5), 1e-3), "{centre}");
    for corner in [Vec3::new(1.0, 0.0, 1.0), Vec3::new(-1.0, 2.0, -1.0)] {
        let p = project(view, corner).unwrap();
        assert!(((p.x - 0.5).abs() - 0.5).abs() < 2e-3 && ((p.y - 0.5).abs() - 0.5).abs() < 2e-3, "{corner} → {p}");
    }
    // Depth grows downwards, away from the light: the top of the box is nearer than its bottom.
    let top = project(view, Vec3::new(0.0, 2.0, 0.0)).unwrap().z;
    let bottom = project(view, Vec3::new(0.0, 0.0, 0.0)).unwrap().z;
    assert!((0.0..1.0).contains(&top) && top < bottom && bottom <= 1.0, "top {top}, bottom {bottom}");
    // The texel covers 2 world units over the map's 2048 texels.
    assert!((view.texel_size - 2.002 / 2048.0).abs() < 1e-6, "{}", view.texel_size);
}

#[test]
fn a_spot_light_maps_its_axis_to_the_map_centre_and_its_cone_inside() {
    let text = format!(
        "{CAMERA}\n[[lights]]\ntype = \"spot\"\nposition = [0, 4, 0]\ndirection = [0, -1, 0]\nouter_angle = 30\n[[objects]]\ntype = \"plane\"\nsize = [10, 10]\nmaterial = \"white\"\n"
    );
    let scene = scene(&text);
    let layout = shadow_layout(&scene, &scene.settings.shadows);
    let view: &LightView = &layout.views[0];
    assert!(view.perspective);
    let below = project(view, Vec3::new(0.0, 0.0, 0.0)).unwrap();
    assert!(below.truncate().abs_diff_eq(Vec2::splat(0.5), 1e-4), "{below}");
    // A point on the cone's edge, 30° off the axis, lies just inside the map: tan 30° of the
    // half-width tan(30° + margin).
    let edge = project(view, Vec3::new(4.0 * 30f32.to_radians().tan(), 0.0, 0.0)).unwrap();
    let offset = (edge.truncate() - Vec2::splat(0.5)).abs().max_element();
    assert!(offset > 0.49 && offset < 0.5, "the cone's edge at {edge}");
}

#[test]
fn point_lights_get_six_faces_and_every_direction_lands_inside_its_face() {
    let text = format!(
        "{CAMERA}\n[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\n[[objects]]\ntype = \"box\"\nmin = [-3, -3, -3]\nmax = [-2, 3, 3]\nmaterial = \"white\"\n"
    );
    let scene = scene(&text);
    let layout = shadow_layout(&scene, &scene.settings.shadows);
    assert_eq!(layout.views.len(), 6);
    let light = Vec3::new(0.0, 1.0, 0.0);
    let mut seed = 12345u32;
    for _ in 0..2000 {
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32 * 2.0 - 1.0
        };
        let d = Vec3::new(next(), next(), next());
        if d.length() < 1e-3 {
            continue;
        }
        let face = cube_face(d);
        let p = project(&layout.views[face], light + d).expect("in front of its own face");
        assert!(p.x > 0.0 && p.x < 1.0 && p.y > 0.0 && p.y < 1.0, "direction {d} on face {face} lands at {p}");
    }
}

#[test]
fn a_lit_plane_without_occluders_has_no_acne_at_default_settings() {
    // Lights at grazing and steep angles over a bare floor: with shadows on, not one pixel may
    // come out darker than with shadows off.
    for (kind, extra) in [
        ("directional", "direction = [1, -0.35, 0.2]"),
        ("directional", "direction = [0.1, -1, 0.1]"),
        ("point", "position = [3, 1.5, -2]"),
        ("spot", "position = [0, 3, 3]\ndirection = [0, -1, -1]\nouter_angle = 40"),
    ] {
        let text = format!(
            "{CAMERA}\n[[lights]]\ntype = \"{kind}\"\n{extra}\n[[objects]]\ntype = \"plane\"\nsize = [40, 40]\nmaterial = \"white\"\n"
        );
        let scene = scene(&text);
        let mut off = scene.settings.clone();
        off.shadows.enabled = false;
        let shadowed = common::raster(&scene, &scene.settings);
        let unshadowed = common::raster(&scene, &off);
        let acne = fraction_differing(&shadowed, &unshadowed, 1);
        assert!(acne == 0.0, "{kind} light: {:.3} % of the plane is shadowed by itself", 100.0 * acne);
    }
}

/// Seed-simple with shadows: the sphere's shadow on the floor. Measured: FLIP mean 0.0048 with
/// the default 2048² map and 3×3 PCF, as without shadows; what differs is the sphere's
/// tessellated silhouette and the PCF-softened shadow edge (the traced shadow is hard).
#[test]
fn the_shadow_map_agrees_with_shadow_rays_on_seed_simple() {
    let scene = common::load("scenes/seed-simple.toml");
    let (raster, traced, flip) = parity(&scene, &scene.settings);
    assert!(flip < 0.01, "FLIP mean {flip}");
    assert!(fraction_differing(&raster, &traced, 24) < 0.01);
}

#[test]
fn projected_polygons_agree_with_shadow_rays_on_their_receiver() {
    // Seed-simple's floor and wall are boxes, and the method needs planar receivers: cover the
    // slab's top and the wall's front with planes, just in front of them.
    let mut text = std::fs::read_to_string(common::asset("scenes/seed-simple.toml")).unwrap();
    text.push_str("\n[[objects]]\nname = \"floor top\"\ntype = \"plane\"\nsize = [130, 100]\ntranslate = [-15, -44.99, 0]\nmaterial = \"yellow\"\n");
    text.push_str("\n[[objects]]\nname = \"wall front\"\ntype = \"plane\"\nsize = [130, 100]\nrotate = [90, 0, 0]\ntranslate = [-15, 0, -49.99]\nmaterial = \"yellow\"\n");
    let mut scene = scene(&text);
    scene.settings.shadows.method = ShadowMethod::Projected;
    let (raster, traced, flip) = parity(&scene, &scene.settings);
    assert!(flip < 0.01, "FLIP mean {flip}");
    assert!(fraction_differing(&raster, &traced, 24) < 0.01);
    let mut unshadowed = scene.settings.clone();
    unshadowed.shadows.enabled = false;
    let without = common::raster(&scene, &unshadowed);
    assert!(fraction_differing(&raster, &without, 8) > 0.02, "the projected shadow is missing");
}

/// A point light in the middle of a ring of pillars: the shadows cross every face of the cube
/// map. A seam would draw a line where faces meet; the images must agree everywhere.
#[test]
fn point_light_cube_shadows_have_no_seams() {
    let mut text = String::from(
        r#"
        [camera]
        eye = [0, 9, 0.01]
        center = [0, 0, 0]
        fovy = 70
        near = 0.1
        far = 50
        width = 200
        height = 200
        [world]
        ambient = [0.05, 0.05, 0.05]
        [materials.white]
        color = [0.9, 0.9, 0.9]
        [[lights]]
        type = "point"
        position = [0, 1.2, 0]
        [[objects]]
        type = "plane"
        size = [20, 20]
        material = "white"
        "#,
    );
    for k in 0..10 {
        let angle = k as f32 * std::f32::consts::TAU / 10.0 + 0.1;
        let (x, z) = (2.5 * angle.cos(), 2.5 * angle.sin());
        text += &format!(
            "[[objects]]\ntype = \"box\"\nmin = [{}, 0, {}]\nmax = [{}, 0.8, {}]\nmaterial = \"white\"\n",
            x - 0.3,
            z - 0.3,
            x + 0.3,
            z + 0.3
        );
    }
    let scene = scene(&text);
    let (raster, traced, flip) = parity(&scene, &scene.settings);
    assert!(flip < 0.01, "FLIP mean {flip}");
    assert!(fraction_differing(&raster, &traced, 32) < 0.005, "{}", fraction_differing(&raster, &traced, 32));
}

#[test]
fn transparent_occluders_tint_the_shadow_in_both_renderers() {
    let text = format!(
        r#"{CAMERA}
        [materials.glass]
        color = [0, 0, 0]
        kd = 0
        transmission = 0.6
        transmission_color = [1, 0.6, 0.3]
        ior = 1
        [[lights]]
        type = "directional"
        direction = [0.2, -1, 0.1]
        [[objects]]
        type = "plane"
        size = [20, 20]
        material = "white"
        [[objects]]
        type = "plane"
        size = [2, 2]
        translate = [0, 1.5, 0]
        material = "glass"
        "#
    );
    let mut scene = scene(&text);
    // Look at the floor from above so the pane, drawn opaque by the rasterizer until the
    // transparency issue lands, hides none of its shadow.
    scene.camera.eye = Vec3::new(-3.0, 5.0, 3.0);
    scene.camera.center = Vec3::new(0.4, 0.0, 0.2);
    let raster = common::raster(&scene, &scene.settings);
    let traced = mirador::trace::render_image(&scene, &scene.settings);
    // Where the tinted shadow falls: 1.5 units below the pane, shifted along the light.
    let centre = Vec3::new(0.3, 0.0, 0.15);
    let p = scene.camera.project(centre).unwrap();
    let (x, y) = (p.x as u32, p.y as u32);
    let (r, t) = (raster.get_pixel(x, y), traced.get_pixel(x, y));
    assert!(r[0] > r[2] + 30, "the raster shadow is tinted orange: {r:?}");
    assert!(t[0] > t[2] + 30, "the traced shadow is tinted orange: {t:?}");
    for c in 0..3 {
        assert!(r[c].abs_diff(t[c]) <= 6, "raster {r:?} and traced {t:?} differ");
    }
}

#[test]
fn every_filter_and_the_projected_method_render_the_showcase() {
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (160, 90);
    let mut images = Vec::new();
    for filter in
        [ShadowFilter::None, ShadowFilter::Hardware, ShadowFilter::Pcf3x3, ShadowFilter::Pcf5x5, ShadowFilter::Poisson]
    {
        let mut settings = scene.settings.clone();
        settings.shadows.filter = filter;
        images.push(common::raster(&scene, &settings));
    }
    // Each filter changes the shadow edges, and only them.
    for pair in images.windows(2) {
        let changed = fraction_differing(&pair[0], &pair[1], 2);
        assert!(changed > 0.0 && changed < 0.1, "{changed}");
    }
    let mut projected = scene.settings.clone();
    projected.shadows.method = ShadowMethod::Projected;
    let image = common::raster(&scene, &projected);
    assert!(fraction_differing(&image, &images[2], 24) < 0.1);
}

#[test]
fn degenerate_lights_give_defined_images() {
    let cases = [
        // Inside the box that would occlude it.
        "type = \"point\"\nposition = [0, 0.5, 0]",
        // In the receiver's plane.
        "type = \"point\"\nposition = [3, 0, 0]",
        // No light at all.
        "type = \"point\"\nposition = [0, 4, 0]\nintensity = 0",
        // Parallel to the floor.
        "type = \"directional\"\ndirection = [1, 0, 0]",
    ];
    for light in cases {
        let text = format!(
            "{CAMERA}\n[[lights]]\n{light}\n[[objects]]\ntype = \"plane\"\nsize = [20, 20]\nmaterial = \"white\"\n[[objects]]\ntype = \"box\"\nmin = [-1, 0, -1]\nmax = [1, 1, 1]\nmaterial = \"white\"\n"
        );
        let scene = scene(&text);
        for method in [ShadowMethod::Map, ShadowMethod::Projected] {
            let mut settings = scene.settings.clone();
            settings.shadows.method = method;
            let image = common::raster(&scene, &settings);
            // Defined means: no NaN reached the image (it would read back as black or garbage);
            // the ambient-lit floor is never black.
            let centre = image.get_pixel(10, 110);
            assert!(centre[0] > 0, "{light} with {method:?}: {centre:?}");
        }
    }
    // A scene with no casters at all.
    let text = format!("{CAMERA}\n[[lights]]\ntype = \"point\"\nposition = [0, 4, 0]\n");
    let scene = scene(&text);
    common::raster(&scene, &scene.settings);
}
