//! The error budget (`src/budget`, docs/course/12-error-budget.md) and the hybrid it is measured
//! with (`settings.hybrid`): each test is two-sided, so a swap that does nothing, or one that
//! changes what it should not, fails.

mod common;

use mirador::Scene;
use mirador::budget::{Budget, Drawn, budget_reporting, frames};
use mirador::scene::file::parse;
use mirador::settings::RenderSettings;

fn traced(scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    mirador::trace::render_image(scene, settings)
}

/// The budget, and a check of the progress it reports (`mirador budget`'s bar): every frame it
/// draws, in order, named, and counted against [`frames`].
fn budget_of(scene: &Scene, settings: &RenderSettings) -> Budget {
    let reference = mirador::budget::reference_scene(scene, settings);
    let mut reported = Vec::new();
    let mut drawn = |frame: Drawn| reported.push((frame.done, frame.frames, frame.what.to_string()));
    let budget =
        budget_reporting(common::gpu(), (scene, &reference), settings, traced(&reference, settings), &mut drawn);
    eprintln!("{}", budget.report());
    let mut expected = vec!["raster".to_string(), "every approximation traced".to_string()];
    for item in &budget.items {
        expected.extend([format!("{} traced alone", item.name), format!("all but {} traced", item.name)]);
    }
    let total = frames(budget.items.len());
    assert_eq!(expected.len(), total, "two frames, and two for each approximation");
    let wanted: Vec<_> = expected.into_iter().enumerate().map(|(k, what)| (k + 1, total, what)).collect();
    assert_eq!(reported, wanted, "the frames reported, against those the budget draws");
    budget
}

/// Boxes and planes only (no tessellation, no texture, no mirror, nothing transparent), lit by a
/// low directional light: with `bias` off the shadow maps' acne covers the floor and the boxes'
/// lit faces, and it is the one difference the rasterizer makes.
fn acne(bias: bool) -> Scene {
    let text = r#"
        [camera]
        eye = [0, 3, 6]
        center = [0, 0.5, 0]
        fovy = 45
        width = 200
        height = 140
        [world]
        ambient = [0.1, 0.1, 0.1]
        background = [0.3, 0.4, 0.5]
        [[lights]]
        type = "directional"
        direction = [-1, -0.35, -0.4]
        [materials.grey]
        color = [0.8, 0.8, 0.8]
        [materials.red]
        color = [0.8, 0.2, 0.1]
        [[objects]]
        type = "plane"
        size = [12, 12]
        material = "grey"
        [[objects]]
        type = "box"
        min = [-0.5, 0, -0.5]
        max = [0.5, 1.2, 0.5]
        material = "red"
        [settings.shadows]
        fit = "scene"
    "#;
    let mut scene = parse(text, &common::asset("scenes/shadows.toml")).unwrap_or_else(|e| panic!("{e}"));
    if !bias {
        let shadows = &mut scene.settings.shadows;
        (shadows.depth_bias, shadows.slope_bias, shadows.normal_offset) = (0, 0.0, 0.0);
    }
    scene
}

#[test]
fn where_the_only_difference_is_shadow_acne_the_budget_puts_it_on_shadows() {
    let scene = acne(false);
    let b = budget_of(&scene, &scene.settings);
    let names: Vec<&str> = b.items.iter().map(|i| i.name).collect();
    assert_eq!(names, ["shadows"], "the scene uses shadows and nothing else the hybrid swaps");
    let shadows = &b.items[0];
    // Measured: whole 0.24, shadows alone 0.24, floor 0.0000; with the bias, shadows 0.0009.
    assert!(b.whole > 0.05, "the acne is there: FLIP {}", b.whole);
    assert!(shadows.alone > 0.8 * b.whole, "shadows alone {} of {}", shadows.alone, b.whole);
    assert!(b.floor < 0.1 * b.whole, "traced shadows leave {} of {}", b.floor, b.whole);
    // The other side: with the bias that cures the acne, the shadows cost little.
    let cured = acne(true);
    let c = budget_of(&cured, &cured.settings);
    assert!(c.items[0].alone < 0.25 * shadows.alone, "cured {} against acne {}", c.items[0].alone, shadows.alone);
}

/// The pixels of `object` in the tracer's image: where it shows when its material is magenta.
fn pixels_of(scene: &Scene, material: &str) -> Vec<bool> {
    let mut magenta = scene.clone();
    let m = magenta.materials.iter_mut().find(|m| m.name == material).expect("the material");
    (m.color, m.texture, m.mirror, m.ka, m.kd, m.ks) = (glam::Vec3::new(1.0, 0.0, 1.0), None, 0.0, 1.0, 1.0, 0.0);
    let image = traced(&magenta, &magenta.settings);
    image.pixels().map(|p| p[0] > 200 && p[2] > 200 && p[1] < 40).collect()
}

/// The share of an error map's sum that lies on the pixels `inside`.
fn share(errors: &[f32], inside: &[bool]) -> f32 {
    let total: f32 = errors.iter().sum();
    errors.iter().zip(inside).filter(|(_, i)| **i).map(|(e, _)| e).sum::<f32>() / total.max(1e-9)
}

#[test]
fn a_mirror_over_a_checker_floor_splits_into_the_mirror_and_the_floors_filtering() {
    let mut scene = common::load("scenes/mirrors.toml");
    (scene.camera.width, scene.camera.height) = (320, 200);
    let mirror = pixels_of(&scene, "mirror");
    let budget_at = |depth: u32| {
        let mut settings = scene.settings.clone();
        settings.mirrors.depth = depth;
        budget_of(&scene, &settings)
    };
    let item = |b: &Budget, name: &str| {
        let i = b.items.iter().find(|i| i.name == name).unwrap_or_else(|| panic!("{name} in the budget"));
        (i.alone, share(&i.errors, &mirror))
    };
    let (flat, deep) = (budget_at(0), budget_at(3));
    let (flat_mirror, flat_mirror_share) = item(&flat, "reflections");
    let (deep_mirror, deep_mirror_share) = item(&deep, "reflections");
    let (flat_floor, floor_in_mirror) = item(&flat, "texture filtering");
    let (deep_floor, _) = item(&deep, "texture filtering");
    eprintln!(
        "mirror shares {flat_mirror_share:.3} {deep_mirror_share:.3}, filtering in the mirror {floor_in_mirror:.3}"
    );
    // The mirror's error lies on the mirror (measured 0.945 and 0.926 of it), and it is what the
    // depth changes.
    assert!(flat_mirror_share > 0.85 && deep_mirror_share > 0.8, "{flat_mirror_share}, {deep_mirror_share}");
    // Measured 0.18 and 0.0019 (filtering 0.011 at both, floors 0.0005).
    assert!(flat_mirror > 4.0 * deep_mirror, "mirror at depth 0: {flat_mirror}, at depth 3: {deep_mirror}");
    // The floor's filtering is outside the mirror (measured 0.001 of it inside), and the same at
    // either depth.
    assert!(floor_in_mirror < 0.5, "the filtering's error inside the mirror: {floor_in_mirror}");
    assert!((flat_floor - deep_floor).abs() < 0.2 * deep_floor, "filtering {flat_floor} vs {deep_floor}");
    // With every approximation traced, what is left is small at either depth.
    assert!(flat.floor < 0.005 && deep.floor < 0.005, "floors {} and {}", flat.floor, deep.floor);
}

#[test]
fn swapping_an_approximation_a_scene_does_not_use_changes_nothing() {
    // No mirror and no texture in the acne scene: tracing reflections and textures draws the
    // same image (the same bytes here; beyond the level or two another CPU may round the other
    // shader variant to, nothing).
    let scene = acne(true);
    let plain = common::raster(&scene, &scene.settings);
    let mut swapped = scene.settings.clone();
    (swapped.hybrid.reflections, swapped.hybrid.textures) = (true, true);
    let change = common::flip(&plain, &common::raster(&scene, &swapped));
    assert!(change == 0.0, "reflections and textures traced in a scene with neither: FLIP {change}");
    // The other side: the same swaps where the scene has both change the image.
    let mut mirrors = common::load("scenes/mirrors.toml");
    (mirrors.camera.width, mirrors.camera.height) = (160, 100);
    let mut swapped = mirrors.settings.clone();
    (swapped.hybrid.reflections, swapped.hybrid.textures) = (true, true);
    let change = common::flip(&common::raster(&mirrors, &mirrors.settings), &common::raster(&mirrors, &swapped));
    assert!(change > 0.003, "the swaps change a scene with a mirror and a texture: FLIP {change}");
}

#[test]
fn the_budgets_json_names_each_approximation_with_its_two_figures() {
    let scene = acne(false);
    let json = budget_of(&scene, &scene.settings).json();
    let item = &json["approximations"][0];
    assert_eq!(item["name"], "shadows");
    for key in ["alone", "left_alone"] {
        assert!(item[key].as_f64().is_some_and(|v| v > 0.0), "{key}: {}", item[key]);
    }
    for key in ["whole", "floor"] {
        assert!(json[key].as_f64().is_some(), "{key}: {json}");
    }
    assert!(json["floor_causes"][0].as_str().is_some_and(|c| c.starts_with("primary visibility")), "{json}");
}

#[test]
fn the_floor_names_what_no_swap_removes() {
    let mut scene = acne(true);
    let first = |s: &Scene| mirador::budget::unswapped(s, &s.settings);
    assert_eq!(first(&scene).len(), 1, "primary visibility alone: {:?}", first(&scene));
    // A fifth light: the rasterizer shadows four, and the lights past the fourth have a traced
    // counterpart, so they are an approximation of the budget, not a part of its floor.
    let light = scene.lights[0].clone();
    scene.lights.extend(std::iter::repeat_n(light, 4));
    assert_eq!(first(&scene).len(), 1, "{:?}", first(&scene));
    let lights = mirador::settings::Traced::Lights.row();
    assert!((lights.in_use)(&scene.facts(), &scene.settings));
    scene.settings.raster.render_scale = 0.5;
    assert!(first(&scene).iter().any(|c| c.starts_with("raster.render_scale")), "{:?}", first(&scene));
}
