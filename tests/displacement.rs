//! Displacement mapping (`bump.method = "displacement"`, src/texture/displacement.rs): the height
//! field's surface made as triangles, for both renderers alike. Checked against the theory:
//!
//! - the rasterizer and the tracer draw one displaced surface, so they agree as on any surface;
//! - bump mapping is that surface's shading without its geometry: against the traced displaced
//!   surface it is measurably worse, at the silhouette (sky where the relief stands) and in the
//!   self-shadows;
//! - the displaced sphere is closed (no sky through it), whatever the seam and the poles;
//! - bad input (a huge scale, a bound on triangles) ends in a surface or a said level, never a
//!   panic or unbounded memory.

mod common;

use mirador::Scene;
use mirador::settings::BumpMethod;
use mirador::texture::displacement::{self, MAX_TRIANGLES};

/// `path`'s scene with `method`, displaced when asked.
fn with_method(path: &str, method: BumpMethod) -> Scene {
    let mut scene = common::load(path);
    scene.settings.bump.method = method;
    displacement::displace(&mut scene);
    scene
}

/// FLIP of the rasterizer's image of `raster` against the tracer's of `traced`.
fn raster_against_traced(raster: &Scene, traced: &Scene) -> f32 {
    let reference = mirador::trace::render_image(traced, &traced.settings);
    common::flip(&reference, &common::raster(raster, &raster.settings))
}

/// The displaced sphere and plane: raster against the tracer on one displaced surface, and bump
/// mapping against the same traced surface.
#[test]
fn both_renderers_draw_one_displaced_surface_and_bump_mapping_misses_it() {
    for path in ["scenes/course/displacement-sphere.toml", "scenes/course/displacement-plane.toml"] {
        let displaced = with_method(path, BumpMethod::Displacement);
        let bumped = with_method(path, BumpMethod::Normal);
        let agree = raster_against_traced(&displaced, &displaced);
        let bump = raster_against_traced(&bumped, &displaced);
        eprintln!("{path}: displaced raster vs displaced tracer {agree:.4}; bump raster vs displaced tracer {bump:.4}");
        // Measured on lavapipe: see tests/README.md.
        assert!(agree < 0.02, "{path}: the two renderers on one displaced surface: FLIP {agree}");
        assert!(bump > 2.0 * agree, "{path}: bump mapping {bump} is not worse than displacement {agree}");
    }
}

/// Parallax mapping, between the two: its two renderers agree (the same march in WGSL and in
/// Rust), and against the traced displaced surface it is nearer than bump mapping (the relief
/// hides itself) and farther than displacement (the outline and the shadows stay flat).
#[test]
fn parallax_mapping_lies_between_bump_mapping_and_displacement() {
    for path in ["scenes/course/displacement-sphere.toml", "scenes/course/displacement-plane.toml"] {
        let displaced = with_method(path, BumpMethod::Displacement);
        let parallax = with_method(path, BumpMethod::Parallax);
        let bumped = with_method(path, BumpMethod::Normal);
        let agree = raster_against_traced(&parallax, &parallax);
        let reference = mirador::trace::render_image(&displaced, &displaced.settings);
        let against = |scene: &Scene| common::flip(&reference, &common::raster(scene, &scene.settings));
        let (bump, between, displacement) = (against(&bumped), against(&parallax), against(&displaced));
        eprintln!(
            "{path}: parallax raster vs parallax tracer {agree:.4}; against the traced displaced surface: bump {bump:.4}, parallax {between:.4}, displacement {displacement:.4}"
        );
        assert!(agree < 0.02, "{path}: parallax in the two renderers: FLIP {agree}");
        assert!(displacement < between && between < bump, "{path}: {displacement} < {between} < {bump} does not hold");
    }
}

/// Where the relief stands out of the sphere, the displaced image has the ball and bump mapping
/// the sky: the silhouette is the one thing no shading can fix.
#[test]
fn bump_mapping_keeps_a_circular_silhouette_and_displacement_breaks_it() {
    let path = "scenes/course/displacement-sphere.toml";
    let displaced = with_method(path, BumpMethod::Displacement);
    let bumped = with_method(path, BumpMethod::Normal);
    let sky = displaced.background;
    let is_sky = |p: &image::Rgba<u8>, reference: &image::Rgba<u8>| {
        p.0.iter().zip(reference.0).take(3).all(|(a, b)| a.abs_diff(b) <= 2)
    };
    let traced_displaced = mirador::trace::render_image(&displaced, &displaced.settings);
    let bump_image = common::raster(&bumped, &bumped.settings);
    let plain = mirador::trace::render_image(&common::load(path), &common::load(path).settings);
    // The sky's own colour, read where no ball can be (the top-left corner).
    let sky_pixel = *plain.get_pixel(0, 0);
    assert!(sky.max_element() > 0.0);
    let (mut ball_in_displaced_only, mut sky_in_both) = (0, 0);
    for (d, b) in traced_displaced.pixels().zip(bump_image.pixels()) {
        match (is_sky(d, &sky_pixel), is_sky(b, &sky_pixel)) {
            (false, true) => ball_in_displaced_only += 1,
            (true, true) => sky_in_both += 1,
            _ => {}
        }
    }
    eprintln!("pixels of relief outside the bump-mapped circle: {ball_in_displaced_only}");
    assert!(sky_in_both > 10_000, "the sky is found: {sky_in_both}");
    assert!(ball_in_displaced_only > 200, "the displaced outline adds {ball_in_displaced_only} pixels of ball");
}

/// No sky through a closed displaced sphere: every pixel well inside its outline is the ball,
/// across the seam (u = 0 = 1) and at the poles, where vertices at one point are moved together.
#[test]
fn a_displaced_sphere_is_closed() {
    let mut scene = with_method("scenes/course/displacement-sphere.toml", BumpMethod::Displacement);
    // A background no shading of the ball makes, and the ball turned so that its seam and a
    // pole face the camera.
    scene.background = glam::Vec3::new(1.0, 0.0, 1.0);
    let turn = glam::Mat4::from_rotation_x(1.1) * glam::Mat4::from_rotation_y(3.0);
    for object in &mut scene.objects {
        object.world_from_local = turn * object.world_from_local;
    }
    let image = common::raster(&scene, &scene.settings);
    let (w, h) = (image.width() as f32, image.height() as f32);
    // The ball's outline on screen: radius 0.8 at distance ~2.92 with fovy 40°.
    let radius_pixels = 0.8 / (2.92 * (20f32.to_radians()).tan()) * h / 2.0;
    let mut holes = 0;
    for (x, y, p) in image.enumerate_pixels() {
        let d = ((x as f32 + 0.5 - w / 2.0).powi(2) + (y as f32 + 0.5 - h / 2.0 + 0.0).powi(2)).sqrt();
        if d < 0.85 * radius_pixels && p.0[0] > 200 && p.0[1] < 60 && p.0[2] > 200 {
            holes += 1;
        }
    }
    assert_eq!(holes, 0, "{holes} background pixels inside the displaced ball");
}

/// What `bump.method = "normal"` does to a scene: nothing; and the summary says what was made.
#[test]
fn bump_mapping_leaves_the_scene_alone_and_displacement_says_what_it_made() {
    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    let before = (scene.objects.len(), scene.meshes.len(), scene.materials.len());
    assert_eq!(displacement::displace(&mut scene), Default::default());
    assert_eq!(before, (scene.objects.len(), scene.meshes.len(), scene.materials.len()));
    scene.settings.bump.method = BumpMethod::Displacement;
    let made = displacement::displace(&mut scene);
    assert_eq!(made.objects.len(), 1);
    assert!(made.triangles > 10_000, "{made:?}");
    let summary = made.summary().expect("a summary");
    assert!(summary.starts_with("displacement: 1 objects,") && !summary.contains("forced"), "{summary}");
    // The displaced material has no height field left: the geometry carries the relief.
    let material = &scene.materials[scene.objects[0].material.0];
    assert!(material.height_map.is_none() && material.height_field.is_none());
}

/// Bad input: a scale of 10³⁰ moves the surface off to where f32 ends, and the offsets that
/// are not finite stay unmoved: both renderers draw something, nothing panics. A tessellation
/// finer than the bound is made at the level the bound allows, and the summary says so.
#[test]
fn a_huge_scale_and_a_level_past_the_bound_are_handled() {
    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    scene.settings.bump.method = BumpMethod::Displacement;
    scene.settings.bump.scale = 1e30;
    displacement::displace(&mut scene);
    assert!(scene.meshes.iter().all(|m| m.positions.iter().all(|p| p.is_finite())));
    let _ = common::raster(&scene, &scene.settings);
    let _ = mirador::trace::render_image(&scene, &scene.settings);

    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    scene.settings.bump.method = BumpMethod::Displacement;
    scene.settings.bump.displacement_texels = 0.25;
    scene.settings.sphere_segments = 192;
    let made = displacement::displace(&mut scene);
    assert!(made.triangles <= MAX_TRIANGLES, "{made:?}");
    let summary = made.summary().expect("a summary");
    assert!(summary.contains("forced `ball` at level"), "{summary}");
}

/// The tessellation view (`bump.view = "tessellation"`) draws the displaced triangles' edges over
/// the ball, finer at a finer level; the bump-mapped ball, which is no mesh, gets none.
#[test]
fn the_tessellation_view_shows_the_displaced_triangles() {
    use mirador::settings::BumpView;
    let edge_pixels = |method: BumpMethod, texels: f32| {
        let mut scene = common::load("scenes/course/displacement-sphere.toml");
        scene.settings.bump.method = method;
        scene.settings.bump.displacement_texels = texels;
        displacement::displace(&mut scene);
        let mut settings = scene.settings.clone();
        settings.bump.view = BumpView::Tessellation;
        let image = common::raster(&scene, &settings);
        // The edges' colour: green well above red and blue (neither the ball nor the sky is).
        image.pixels().filter(|p| p.0[1] > 200 && p.0[0] < 200 && p.0[2] < 200).count()
    };
    let (coarse, fine, bumped) = (
        edge_pixels(BumpMethod::Displacement, 8.0),
        edge_pixels(BumpMethod::Displacement, 2.0),
        edge_pixels(BumpMethod::Normal, 2.0),
    );
    eprintln!("edge pixels: level 1 {coarse}, level 3 {fine}, bump-mapped {bumped}");
    assert_eq!(bumped, 0, "no mesh, no edges");
    assert!(coarse > 2_000 && fine > coarse, "{coarse} then {fine}");
}

/// What bump and parallax mapping cost, in the error budget: against the displaced surface they
/// stand for (the reference is traced on it), swapping them for it removes nearly all of the
/// difference on the grazing-lit plane, and with every approximation swapped nothing is left.
#[test]
fn the_budget_measures_bump_and_parallax_mapping_against_the_displaced_surface() {
    let gpu = common::gpu();
    for (method, least) in [(BumpMethod::Normal, 0.1), (BumpMethod::Parallax, 0.08)] {
        let mut scene = common::load("scenes/course/displacement-plane.toml");
        scene.settings.bump.method = method;
        let settings = scene.settings.clone();
        let reference = mirador::budget::reference_scene(&scene, &settings);
        let traced = mirador::trace::render_image(&reference, &settings);
        let budget = mirador::budget::budget(gpu, (&scene, &reference), &settings, traced);
        let relief = budget.items.iter().find(|i| i.name == "bump and parallax mapping").expect("the relief's row");
        eprintln!("{method:?}: whole {:.4}, relief alone {:.4}, floor {:.4}", budget.whole, relief.alone, budget.floor);
        assert!(relief.alone > least && relief.alone > 0.8 * budget.whole, "{method:?}: {}", budget.report());
        assert!(budget.floor < 0.005, "{method:?}: {}", budget.report());
    }
    // The other side: displaced already, the scene makes no such approximation.
    let mut scene = common::load("scenes/course/displacement-plane.toml");
    scene.settings.bump.method = BumpMethod::Displacement;
    let used = mirador::settings::Traced::Relief.row().in_use;
    assert!(!used(&scene.facts(), &scene.settings));
}

/// `mirador explain` on a bump-mapped ball says what the relief would change at the pixel: at
/// the outline, the relief standing out of the smooth circle; inside it, how much nearer the
/// displaced surface is met. Displaced already, or with no height field, it says nothing.
#[test]
fn explain_names_what_bump_mapping_leaves_out() {
    let gpu = common::gpu();
    let scene = common::load("scenes/course/displacement-sphere.toml");
    let explained = |scene: &Scene, pixel| {
        mirador::explain::explain(gpu, scene, &scene.settings, pixel).expect("the pixel is explained").relief
    };
    // Where the displaced ball covers the sky the bump-mapped one leaves (found on row 150).
    let traced = mirador::trace::render_image(&displacement::displaced(&scene), &scene.settings);
    let bumped = mirador::trace::render_image(&scene, &scene.settings);
    let sky = *bumped.get_pixel(0, 0);
    let is_sky = |p: &image::Rgba<u8>| p.0.iter().zip(sky.0).take(3).all(|(a, b)| a.abs_diff(b) <= 2);
    let outline = (0..scene.camera.width)
        .find(|&x| is_sky(bumped.get_pixel(x, 150)) && !is_sky(traced.get_pixel(x, 150)))
        .expect("a pixel of relief outside the circle");
    let said = explained(&scene, (outline, 150)).expect("the relief is named at the outline");
    assert!(said.contains("the relief stands out of the smooth outline"), "{said}");
    let said = explained(&scene, (230, 230)).expect("the relief is named inside");
    assert!(said.contains("nearer than the smooth one"), "{said}");
    // The other side: displaced already, and a scene without height fields.
    let displaced = with_method("scenes/course/displacement-sphere.toml", BumpMethod::Displacement);
    assert_eq!(explained(&displaced, (230, 230)), None);
    let plain = common::load("scenes/seed-simple.toml");
    assert_eq!(explained(&plain, (100, 100)), None);
}
