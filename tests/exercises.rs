//! The course's exercises say what a student will see; where that is a measurable claim, it is
//! measured here on the exercise's own scene and settings, so a change that breaks an exercise
//! fails a test rather than a class (docs/course/, "Things to try").
//!
//! Each test names its chapter and exercise. Images are drawn at the exercise's size unless the
//! claim holds at any size, then smaller, to keep the suite quick.

mod common;

use mirador::{RenderSettings, Scene};

/// The exercise's scene with `sets` applied as `--set` applies settings.
fn scene_with(relative: &str, sets: &[&str]) -> (Scene, RenderSettings) {
    let scene = common::load(relative);
    let mut settings = scene.settings.clone();
    for assignment in sets {
        settings.set(assignment).unwrap_or_else(|e| panic!("{assignment}: {e}"));
    }
    (scene, settings)
}

/// The mean FLIP of the rasterizer's image against the tracer's (what `compare` prints), beyond
/// the level or two by which another CPU rounds a flat area differently (tests/README.md).
fn compared(scene: &Scene, settings: &RenderSettings) -> f32 {
    let raster = common::raster(scene, settings);
    let traced = mirador::trace::render_image(scene, settings);
    common::difference(&traced, &raster).flip_mean
}

/// How many pixels of `image` are `colour`, each channel within `levels`.
fn pixels_of(image: &image::RgbaImage, colour: [u8; 3], levels: u8) -> usize {
    image.pixels().filter(|p| (0..3).all(|c| p.0[c].abs_diff(colour[c]) <= levels)).count()
}

/// Chapter 5, exercise 1: without bias every lit surface is striped (acne); a depth bias of 2000
/// cures it; 10000 detaches the shadows (peter-panning, worse again); a slope bias of 1.5 alone
/// cures it without moving them.
#[test]
fn chapter_5_exercise_1_the_bias_sequence() {
    let scene = "scenes/course/shadows-bias.toml";
    let flip = |sets: &[&str]| {
        let (scene, settings) = scene_with(scene, sets);
        compared(&scene, &settings)
    };
    let zero = ["shadows.depth_bias=0", "shadows.slope_bias=0", "shadows.normal_offset=0"];
    let acne = flip(&zero);
    let with = |bias: &str| flip(&[bias, zero[1], zero[2]]);
    let (cured, panning) = (with("shadows.depth_bias=2000"), with("shadows.depth_bias=10000"));
    let slope = flip(&["shadows.depth_bias=0", "shadows.slope_bias=1.5", zero[2]]);
    eprintln!("acne {acne:.4}, depth bias 2000 {cured:.4}, 10000 {panning:.4}, slope bias 1.5 {slope:.4}");
    assert!(acne > 5.0 * cured, "acne must dwarf the cured image's error");
    assert!(panning > 1.5 * cured, "peter-panning must show against the cured image");
    assert!(slope < 1.2 * cured, "the slope bias alone must cure as well as the depth bias");
}

/// Chapter 5, exercise 3: layer 4 (+z) of the point light's cube sees nothing (all white), layer
/// 5 (−z) the ring, the block and the wall; a layer past the last (9 of 6) shows the last.
#[test]
fn chapter_5_exercise_3_the_cube_faces() {
    let map = |layer: u32| {
        let (mut scene, settings) = scene_with(
            "scenes/course/shadows-methods.toml",
            &["shadows.view=\"map\"", &format!("shadows.view_layer={layer}")],
        );
        (scene.camera.width, scene.camera.height) = (240, 136);
        common::raster(&scene, &settings)
    };
    // The map is drawn as a square in the middle of the image.
    let square = |image: &image::RgbaImage| {
        let side = image.height();
        image::imageops::crop_imm(image, (image.width() - side) / 2, 0, side, side).to_image()
    };
    let (four, five, nine) = (square(&map(4)), square(&map(5)), square(&map(9)));
    let total = (four.width() * four.height()) as usize;
    assert_eq!(pixels_of(&four, [255, 255, 255], 0), total, "layer 4 sees nothing: all white");
    assert!(pixels_of(&five, [255, 255, 255], 0) < total / 2, "layer 5 shows the casters and the wall");
    assert!(nine == five, "a layer past the last shows the last");
}

/// Chapter 6, exercise 1: where the three panes overlap, sorted farthest first, `I = (0.5,
/// 0.25, 0.125)`, stored as sRGB (188, 137, 99) (the rasterizer's 187 for 0.5); in the file's
/// order, nearest first, `(0.125, 0.25, 0.5)`.
#[test]
fn chapter_6_exercise_1_the_overlap_by_hand() {
    let (scene, sorted) = scene_with("scenes/course/transparency-order.toml", &[]);
    let (_, unsorted) = scene_with("scenes/course/transparency-order.toml", &["transparency.sort=\"unsorted\""]);
    let (sorted_image, unsorted_image) = (common::raster(&scene, &sorted), common::raster(&scene, &unsorted));
    let traced = mirador::trace::render_image(&scene, &sorted);
    for (image, what) in [(&sorted_image, "the rasterizer's"), (&traced, "the tracer's")] {
        assert!(pixels_of(image, [188, 137, 99], 1) > 500, "no overlap of (188, 137, 99) in {what} sorted image");
    }
    assert!(pixels_of(&unsorted_image, [99, 137, 188], 1) > 500, "the file's order gives (99, 137, 188)");
    assert_eq!(pixels_of(&unsorted_image, [188, 137, 99], 1), 0, "the file's order is not the sorted one");
}

/// Chapter 8, exercise 3: 16 texels a face blur the reflection, but over a small ball: the mean
/// FLIP against the tracer barely moves from 256.
#[test]
fn chapter_8_exercise_3_a_small_cube_barely_moves_the_mean() {
    let flip = |size: u32| {
        let (scene, settings) =
            scene_with("scenes/course/environment-ball.toml", &[&format!("environment.cube_size={size}")]);
        compared(&scene, &settings)
    };
    let (small, large) = (flip(16), flip(256));
    eprintln!("cube 16: {small:.4}, cube 256: {large:.4}");
    assert!(small >= large - 0.001, "a coarser cube cannot agree better");
    assert!(small - large < 0.005, "the text says the mean barely moves");
}

/// Chapter 9, exercise 2: the five accelerators give the same image, byte for byte.
#[test]
fn chapter_9_exercise_2_every_accelerator_draws_the_same_image() {
    let (mut scene, settings) = scene_with("scenes/course/acceleration-teapot.toml", &[]);
    (scene.camera.width, scene.camera.height) = (160, 90);
    let image = |accel: &str| {
        let mut settings = settings.clone();
        settings.set(&format!("trace.accelerator=\"{accel}\"")).unwrap_or_else(|e| panic!("{e}"));
        mirador::trace::render_image(&scene, &settings)
    };
    let bvh = image("bvh");
    for accel in ["wide", "grid", "octree", "none"] {
        assert!(image(accel) == bvh, "{accel} draws another image than the BVH");
    }
}

/// Chapter 12's budget of an exercise scene with `sets`: each approximation's cost alone, by name.
fn budget_alone(relative: &str, sets: &[&str]) -> std::collections::BTreeMap<&'static str, f32> {
    let (scene, settings) = scene_with(relative, sets);
    let reference = mirador::budget::reference_scene(&scene, &settings);
    let traced = mirador::trace::render_image(&reference, &settings);
    let budget = mirador::budget::budget(common::gpu(), (&scene, &reference), &settings, traced);
    eprintln!("{relative} {sets:?}\n{}", budget.report());
    budget.items.iter().map(|i| (i.name, i.alone)).collect()
}

#[test]
fn chapter_12_exercise_1_the_mirrors_cost_falls_with_the_depth_and_the_filtering_stays() {
    let flat = budget_alone("scenes/course/mirror-pair.toml", &["mirrors.depth=0"]);
    let deep = budget_alone("scenes/course/mirror-pair.toml", &["mirrors.depth=3"]);
    // Measured: reflections 0.171 and 0.0024, filtering 0.0144 and 0.0159.
    assert!(flat["reflections"] > 20.0 * deep["reflections"], "{flat:?} {deep:?}");
    let (a, b) = (flat["texture filtering"], deep["texture filtering"]);
    assert!((a - b).abs() < 0.2 * b, "the filtering at depth 0 and 3: {a}, {b}");
    assert!(b > 4.0 * deep["reflections"], "at depth 3 the filtering costs more than the mirrors: {deep:?}");
}

#[test]
fn chapter_12_exercise_3_screen_refraction_removes_most_of_the_transmissions_cost() {
    let none = budget_alone("scenes/course/transparency-refraction.toml", &["transparency.refraction=\"none\""]);
    let screen = budget_alone("scenes/course/transparency-refraction.toml", &["transparency.refraction=\"screen\""]);
    // Measured 0.062 and 0.0073.
    assert!(none["transmission"] > 5.0 * screen["transmission"], "{none:?} {screen:?}");
}
