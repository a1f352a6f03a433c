//! Transparent surfaces in sorted Z order (docs/course/06-transparency.md): the seed's formula
//! `I = Im + kt·Mt·I` checked by hand for every drawing order, the order-dependence the unsorted
//! mode must show, two-sided objects, coplanar panes, and agreement with the ray tracer, whose
//! rays go straight through when `ior = 1`.

mod common;

use common::flip;
use std::path::Path;

use glam::Vec3;
use mirador::scene::file::parse;
use mirador::settings::TransparencySort;
use mirador::{RenderSettings, Scene};

const SORTS: [TransparencySort; 4] =
    [TransparencySort::Unsorted, TransparencySort::Object, TransparencySort::Triangle, TransparencySort::Exact];

fn scene(text: &str) -> Scene {
    parse(text, Path::new("transparency.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn with_sort(scene: &Scene, sort: TransparencySort) -> RenderSettings {
    let mut settings = scene.settings.clone();
    settings.transparency.sort = sort;
    settings.trace.max_depth = 12;
    settings
}

/// The linear value of an 8-bit sRGB channel.
fn linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

fn linear_pixel(image: &image::RgbaImage, x: u32, y: u32) -> Vec3 {
    let p = image.get_pixel(x, y);
    Vec3::new(linear(p[0]), linear(p[1]), linear(p[2]))
}

/// A pane facing the camera: emission only (no lights), so `Im = ME` exactly.
struct Pane {
    z: f32,
    emission: Vec3,
    kt: f32,
    mt: Vec3,
}

const BACKGROUND: Vec3 = Vec3::new(0.2, 0.3, 0.4);

/// Far, middle, near.
const PANES: [Pane; 3] = [
    Pane { z: -1.0, emission: Vec3::new(0.25, 0.02, 0.02), kt: 0.8, mt: Vec3::new(1.0, 0.5, 0.5) },
    Pane { z: 0.0, emission: Vec3::new(0.02, 0.2, 0.02), kt: 0.6, mt: Vec3::new(0.5, 1.0, 0.5) },
    Pane { z: 1.0, emission: Vec3::new(0.02, 0.02, 0.15), kt: 0.5, mt: Vec3::new(0.6, 0.6, 1.0) },
];

/// The three panes, listed in the file in `order`, over the background and nothing else (no
/// opaque surface at all).
fn pane_scene(order: &[usize]) -> Scene {
    let mut text = format!(
        "[camera]\neye = [0, 0, 6]\ncenter = [0, 0, 0]\nfovy = 40\nnear = 0.1\nfar = 20\nwidth = 64\nheight = 64\n\
         [world]\nambient = [0, 0, 0]\nbackground = {:?}\n",
        BACKGROUND.to_array()
    );
    for (i, pane) in PANES.iter().enumerate() {
        text += &format!(
            "[materials.pane{i}]\ncolor = [0, 0, 0]\nkd = 0\nks = 0\nemission = {:?}\ntransmission = {}\n\
             transmission_color = {:?}\nior = 1.0\n",
            pane.emission.to_array(),
            pane.kt,
            pane.mt.to_array()
        );
    }
    for &i in order {
        text += &format!(
            "[[objects]]\ntype = \"plane\"\nsize = [2, 2]\nrotate = [90, 0, 0]\ntranslate = [0, 0, {}]\nmaterial = \"pane{i}\"\n",
            PANES[i].z
        );
    }
    scene(&text)
}

/// `I = Im + kt·Mt·I` applied for the panes in `order`, starting from the background.
fn composed(order: impl IntoIterator<Item = usize>) -> Vec3 {
    order.into_iter().fold(BACKGROUND, |behind, i| PANES[i].emission + PANES[i].kt * PANES[i].mt * behind)
}

const PERMUTATIONS: [[usize; 3]; 6] = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];

#[test]
fn three_panes_give_the_seeds_formula_by_hand_in_every_sorted_order() {
    // Farthest first: I_near + Mt_near·(I_mid + Mt_mid·(I_far + Mt_far·B)).
    let right = composed([0, 1, 2]);
    for order in PERMUTATIONS {
        let scene = pane_scene(&order);
        for sort in [TransparencySort::Object, TransparencySort::Triangle, TransparencySort::Exact] {
            let image = common::raster(&scene, &with_sort(&scene, sort));
            let got = linear_pixel(&image, 32, 32);
            assert!(got.abs_diff_eq(right, 0.006), "{sort:?}, file order {order:?}: {got} instead of {right}");
        }
        // The tracer, an independent check: with ior = 1 its rays go straight through.
        let traced = mirador::trace::render_image(&scene, &with_sort(&scene, TransparencySort::Exact));
        let got = linear_pixel(&traced, 32, 32);
        assert!(got.abs_diff_eq(right, 0.006), "traced, file order {order:?}: {got} instead of {right}");
    }
}

#[test]
fn unsorted_drawing_gives_the_wrong_value_predicted_for_the_files_order() {
    let right = composed([0, 1, 2]);
    for order in PERMUTATIONS {
        let scene = pane_scene(&order);
        let image = common::raster(&scene, &with_sort(&scene, TransparencySort::Unsorted));
        let got = linear_pixel(&image, 32, 32);
        let predicted = composed(order);
        assert!(got.abs_diff_eq(predicted, 0.006), "file order {order:?}: {got} instead of {predicted}");
        if order != [0, 1, 2] {
            // The prediction is wrong, and measurably so: the test tells the orders apart.
            assert!((predicted - right).abs().max_element() > 0.03, "{order:?}: {predicted} vs {right}");
        }
    }
}

#[test]
fn coplanar_panes_keep_the_files_order_in_every_mode_and_every_frame() {
    // Two panes in the same plane, with the same centre: no depth tells them apart, so each mode
    // must fall back on the file's order (a stable order), the same in every frame.
    let mut scene = pane_scene(&[1, 2]);
    let right = composed([1, 2]);
    // pane_scene places each pane at its own z; move both into the plane z = 0.
    for object in &mut scene.objects {
        object.world_from_local.w_axis.z = 0.0;
    }
    for sort in SORTS {
        let settings = with_sort(&scene, sort);
        let mut headless = mirador::raster::Headless::new(common::gpu(), &scene);
        let first = headless.render(common::gpu(), &scene, &settings);
        let got = linear_pixel(&first, 32, 32);
        assert!(got.abs_diff_eq(right, 0.006), "{sort:?}: {got} instead of the file order's {right}");
        assert_eq!(headless.render(common::gpu(), &scene, &settings), first, "{sort:?}: frames differ");
    }
}

/// A convex glass cube and a glass sphere before two coloured posts, lit.
const TWO_SIDED: &str = r#"
    [camera]
    eye = [0, 2.5, 5]
    center = [0, 0.6, 0]
    fovy = 45
    near = 0.1
    far = 30
    width = 200
    height = 140
    [world]
    ambient = [0.1, 0.1, 0.1]
    background = [0.3, 0.4, 0.5]
    [materials.floor]
    color = [0.8, 0.78, 0.7]
    [materials.red]
    color = [0.8, 0.1, 0.1]
    [materials.green]
    color = [0.1, 0.7, 0.2]
    [materials.glass]
    color = [0.6, 0.8, 1.0]
    kd = 0.3
    ks = 0.6
    shininess = 80
    transmission = 0.7
    transmission_color = [0.7, 0.9, 1.0]
    ior = 1.0
    [[lights]]
    type = "point"
    position = [2, 5, 3]
    intensity = 0.9
    [[objects]]
    type = "plane"
    size = [12, 12]
    uv_scale = [6, 6]
    material = "floor"
    [[objects]]
    type = "box"
    min = [-1.6, 0.2, -0.6]
    max = [-0.4, 1.4, 0.6]
    rotate = [0, 30, 0]
    material = "glass"
    [[objects]]
    type = "sphere"
    center = [1.0, 0.8, 0]
    radius = 0.7
    material = "glass"
    [[objects]]
    type = "box"
    min = [-1.8, 0, -1.6]
    max = [-0.9, 1.8, -1.2]
    material = "red"
    [[objects]]
    type = "box"
    min = [0.6, 0, -1.6]
    max = [1.6, 1.5, -1.2]
    material = "green"
"#;

/// Settings for comparing with the tracer: shadows off, because the shadow maps do not tint a
/// transparent receiver by the transparent surfaces between it and the light (the shadow
/// technique's approximation, not the drawing order's; docs/scene-format.md), so the far wall
/// of a glass object is brighter than the tracer's.
fn unshadowed(scene: &Scene, sort: TransparencySort) -> RenderSettings {
    let mut settings = with_sort(scene, sort);
    settings.shadows.enabled = false;
    settings
}

#[test]
fn convex_glass_shows_its_far_walls_through_its_near_ones() {
    let scene = scene(TWO_SIDED);
    let exact = common::raster(&scene, &with_sort(&scene, TransparencySort::Exact));
    // Per object draws back faces, then front faces: exact for a convex object; per triangle
    // sorts the walls by their centroids, also right for a cube and a sphere.
    for sort in [TransparencySort::Object, TransparencySort::Triangle] {
        let image = common::raster(&scene, &with_sort(&scene, sort));
        let error = flip(&exact, &image);
        assert!(error < 0.0005, "{sort:?} vs exact: FLIP {error}");
    }
    // The file's order draws near walls before far ones somewhere: visibly wrong.
    let unsorted = common::raster(&scene, &with_sort(&scene, TransparencySort::Unsorted));
    let error = flip(&exact, &unsorted);
    assert!(error > 0.01, "unsorted vs exact: FLIP {error}");
    // The ray tracer, with ior = 1, agrees with the exact order.
    let settings = unshadowed(&scene, TransparencySort::Exact);
    let error = flip(&mirador::trace::render_image(&scene, &settings), &common::raster(&scene, &settings));
    assert!(error < 0.025, "exact vs traced: FLIP {error}");
}

#[test]
fn the_exact_order_agrees_with_the_tracer_at_ior_one_where_sorting_fails() {
    let mut scene = Scene::load(&mirador::scene::builtin_path("transparency.toml")).unwrap();
    for material in &mut scene.materials {
        material.ior = 1.0;
    }
    let traced = mirador::trace::render_image(&scene, &unshadowed(&scene, TransparencySort::Exact));
    let error = |sort| flip(&traced, &common::raster(&scene, &unshadowed(&scene, sort)));
    let exact = error(TransparencySort::Exact);
    assert!(exact < 0.03, "exact vs traced: FLIP {exact}");
    // The crossing panes are wrong per object and per triangle; the file's order is wrong too.
    for sort in [TransparencySort::Unsorted, TransparencySort::Object, TransparencySort::Triangle] {
        let e = error(sort);
        assert!(e > exact + 0.001, "{sort:?}: FLIP {e}, no worse than exact's {exact}");
    }
}

#[test]
fn turning_transparency_off_draws_the_panes_opaque() {
    let scene = pane_scene(&[0, 1, 2]);
    let mut settings = scene.settings.clone();
    settings.transparency.enabled = false;
    let image = common::raster(&scene, &settings);
    // The near pane alone, its illumination model without what lies behind.
    let got = linear_pixel(&image, 32, 32);
    assert!(got.abs_diff_eq(PANES[2].emission, 0.006), "{got}");
}

// ---- glTF's alpha modes in the rasterizer (the tracer's side is in tests/alpha.rs) ----

/// Parses `text` as if it were `tests/data/alpha.toml`, so `textures/…` resolves there.
fn alpha_scene(more: &str) -> Scene {
    let text = format!(
        "[camera]\neye = [0, 0, 5]\ncenter = [0, 0, 0]\nfovy = 30\nwidth = 64\nheight = 64\n\
         [world]\nambient = [0, 0, 0]\nbackground = {:?}\n{more}",
        BACKGROUND.to_array()
    );
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/alpha.toml");
    parse(&text, &path).unwrap_or_else(|e| panic!("{e}"))
}

const E: Vec3 = Vec3::new(0.6, 0.3, 0.15);

/// A 2 × 2 emissive plane facing the camera, with more material lines.
fn emissive_plane(lines: &str) -> String {
    format!(
        "[materials.veil]\ncolor = [0, 0, 0]\nkd = 0\nemission = {:?}\n{lines}\n\
         [[objects]]\ntype = \"plane\"\nsize = [2, 2]\nrotate = [90, 0, 0]\nmaterial = \"veil\"\n",
        E.to_array()
    )
}

#[test]
fn alpha_blending_is_the_seeds_formula_with_im_scaled_by_alpha() {
    // A constant α: I = α·E + (1 − α)·B, the blend constant 1 − α.
    let constant = alpha_scene(&emissive_plane("alpha_mode = \"blend\"\nalpha = 0.25"));
    // α from the texture (128/255) times the factor: the blend reads 1 − α from the fragment.
    let textured =
        alpha_scene(&emissive_plane("alpha_mode = \"blend\"\nalpha = 0.8\ntexture = \"textures/alpha-128.png\""));
    // Blending and transmission together: I = α·E + (α·kt·Mt + 1 − α)·B.
    let both = alpha_scene(&emissive_plane(
        "alpha_mode = \"blend\"\nalpha = 0.5\ntransmission = 0.6\ntransmission_color = [1, 0.5, 0.25]",
    ));
    let through = 0.6 * Vec3::new(1.0, 0.5, 0.25);
    let cases = [
        ("constant α", &constant, 0.25 * E + 0.75 * BACKGROUND),
        ("texture α", &textured, {
            let a = 0.8 * 128.0 / 255.0;
            a * E + (1.0 - a) * BACKGROUND
        }),
        ("α and kt", &both, 0.5 * E + (0.5 * through + Vec3::splat(0.5)) * BACKGROUND),
    ];
    for (what, scene, expected) in cases {
        for sort in SORTS {
            let got = linear_pixel(&common::raster(scene, &with_sort(scene, sort)), 32, 32);
            assert!(got.abs_diff_eq(expected, 0.006), "{what}, {sort:?}: {got} instead of {expected}");
        }
        let traced = linear_pixel(&mirador::trace::render_image(scene, &scene.settings), 32, 32);
        assert!(traced.abs_diff_eq(expected, 0.006), "{what}, traced: {traced} instead of {expected}");
    }
}

#[test]
fn a_mask_cuts_the_surface_out_with_or_without_a_depth_prepass() {
    // A 2×1 texture: alpha 255 on the left texel, 0 on the right; cut at 0.5.
    let scene = alpha_scene(&emissive_plane(
        "alpha_mode = \"mask\"\nalpha_cutoff = 0.5\ntexture = \"textures/alpha-left-opaque.png\"\nwrap = \"clamp\"",
    ));
    for prepass in [mirador::settings::Prepass::Always, mirador::settings::Prepass::Never] {
        let mut settings = scene.settings.clone();
        settings.raster.depth_prepass = prepass;
        let image = common::raster(&scene, &settings);
        let (left, right) = (linear_pixel(&image, 22, 32), linear_pixel(&image, 42, 32));
        assert!(left.abs_diff_eq(E, 0.006), "{prepass:?}: the kept half shows {left}, not {E}");
        assert!(right.abs_diff_eq(BACKGROUND, 0.006), "{prepass:?}: the cut half shows {right}, not the background");
    }
}

#[test]
fn a_masked_caster_shadows_only_where_its_surface_is() {
    // A leaf held over a lit floor: half of it is cut out, so half of its shadow is missing.
    let text = String::from(
        "[camera]\neye = [0, 4, 4]\ncenter = [0, 0, 0]\nfovy = 45\nwidth = 160\nheight = 120\n\
         [world]\nambient = [0.05, 0.05, 0.05]\n\
         [materials.floor]\ncolor = [0.8, 0.8, 0.8]\n\
         [materials.leaf]\ncolor = [0.2, 0.7, 0.2]\ntexture = \"textures/alpha-left-opaque.png\"\n\
         wrap = \"clamp\"\nalpha_mode = \"{mode}\"\n{cutoff}\n\
         [[lights]]\ntype = \"directional\"\ndirection = [0.3, -1, -0.2]\nintensity = 0.9\n\
         [[objects]]\ntype = \"plane\"\nsize = [8, 8]\nmaterial = \"floor\"\n\
         [[objects]]\ntype = \"plane\"\nsize = [1.6, 1.6]\ntranslate = [0, 1.2, 0]\nmaterial = \"leaf\"\n",
    );
    let masked = text.replace("{mode}", "mask").replace("{cutoff}", "alpha_cutoff = 0.5");
    let opaque = text.replace("{mode}", "opaque").replace("{cutoff}", "");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/alpha.toml");
    let load = |text: &str| parse(text, &path).unwrap_or_else(|e| panic!("{e}"));
    let (masked, opaque) = (load(&masked), load(&opaque));
    let traced = mirador::trace::render_image(&masked, &masked.settings);
    let agreeing = flip(&traced, &common::raster(&masked, &masked.settings));
    // The whole leaf drawn and casting: what the test would see if the mask were ignored.
    let ignoring_the_mask = flip(&traced, &common::raster(&opaque, &opaque.settings));
    assert!(agreeing < 0.01, "masked leaf vs traced: FLIP {agreeing}");
    assert!(ignoring_the_mask > 4.0 * agreeing, "an unmasked leaf differs by {ignoring_the_mask} only");
}

#[test]
fn an_alpha_blended_gltf_cube_agrees_with_the_tracer_from_every_side() {
    // tests/data/gltf/blend_cube.gltf: a hand-made unit cube, alphaMode BLEND, baseColorFactor
    // alpha 0.45, turned 45° about y; before a red post, over a floor, under one light.
    let text = |eye: [f32; 3]| {
        format!(
            "[camera]\neye = {eye:?}\ncenter = [0, 0.6, 0]\nfovy = 40\nwidth = 160\nheight = 120\n\
             [world]\nambient = [0.1, 0.1, 0.1]\nbackground = [0.3, 0.4, 0.5]\n\
             [materials.floor]\ncolor = [0.8, 0.78, 0.7]\n[materials.red]\ncolor = [0.8, 0.1, 0.1]\n\
             [[lights]]\ntype = \"point\"\nposition = [2, 5, 3]\nintensity = 0.9\n\
             [[objects]]\ntype = \"plane\"\nsize = [12, 12]\nmaterial = \"floor\"\n\
             [[objects]]\ntype = \"box\"\nmin = [-0.15, 0, -1.3]\nmax = [0.15, 1.6, -1.0]\nmaterial = \"red\"\n\
             [[objects]]\ntype = \"gltf\"\npath = \"gltf/blend_cube.gltf\"\ntranslate = [0, 0.7, 0]\n\
             lights = false\ncamera = false\n"
        )
    };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/alpha.toml");
    for eye in [[0.5, 2.0, 4.0], [-1.0, 1.5, -4.5], [4.0, 3.0, 0.5]] {
        let scene = parse(&text(eye), &path).unwrap_or_else(|e| panic!("{e}"));
        let traced = mirador::trace::render_image(&scene, &unshadowed(&scene, TransparencySort::Exact));
        for sort in [TransparencySort::Object, TransparencySort::Triangle, TransparencySort::Exact] {
            let error = flip(&traced, &common::raster(&scene, &unshadowed(&scene, sort)));
            assert!(error < 0.025, "from {eye:?}, {sort:?}: FLIP {error}");
        }
    }
}
