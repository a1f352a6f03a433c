//! Golden images of the built-in scenes, compared by FLIP: the mean over the image and the mean
//! over its worst 32×32 region. Lavapipe renders these bit-identically run to run; the
//! thresholds leave room for other drivers and versions (see [`TOLERANCE`]) while catching any
//! visible change: moving the seed-simple light by 5 units, or halving the
//! ambient light, costs more than 0.01 of mean; a wrong 40×40 patch, which the mean dilutes below
//! 0.01, costs far more than the region threshold (see the tests at the end).

mod common;

use common::{GoldenError, Tolerance};

/// What a golden image may differ by. Measured on lavapipe (llvmpipe, LLVM 15) against these
/// goldens: mean FLIP 0.0006 (seed-simple) to 0.0036 (shadows), worst region 0.004
/// (seed-simple) to 0.027 (bumps); the region threshold leaves twice the largest. Visible changes
/// measure far above it: a 40×40 patch 20% darker 0.44, the seed-simple light moved 5 units
/// 0.20, the bottom 8 rows left black 0.30.
const TOLERANCE: Tolerance = Tolerance { flip_mean: 0.01, worst_region: 0.05 };

#[test]
fn seed_simple() {
    let scene = common::load("scenes/seed-simple.toml");
    common::assert_golden("seed-simple", &common::raster(&scene, &scene.settings), TOLERANCE);
}

#[test]
fn showcase() {
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (640, 360);
    common::assert_golden("showcase", &common::raster(&scene, &scene.settings), TOLERANCE);
}

/// The transparency stage in two orders: per object (the default; its crossing panes are
/// wrong on one side) and exact (depth peeling).
#[test]
fn transparency_stage_per_object_and_exact() {
    use mirador::settings::TransparencySort;
    let scene = common::load("scenes/transparency.toml");
    for (name, sort) in
        [("transparency-object", TransparencySort::Object), ("transparency-exact", TransparencySort::Exact)]
    {
        let mut settings = scene.settings.clone();
        settings.transparency.sort = sort;
        common::assert_golden(name, &common::raster(&scene, &settings), TOLERANCE);
    }
}

/// The refraction stage: the glass ball through the environment cube and in screen space, with
/// Fresnel, and the cubes read on the ground (the chrome ball's floor).
#[test]
fn refraction_stage_through_the_environment_and_the_screen() {
    use mirador::settings::{Parallax, Refraction};
    let scene = common::load("scenes/refraction.toml");
    for (name, refraction) in
        [("refraction-environment", Refraction::Environment), ("refraction-screen", Refraction::Screen)]
    {
        let mut settings = scene.settings.clone();
        settings.transparency.refraction = refraction;
        settings.terms.fresnel = true;
        settings.environment.parallax = Parallax::Ground;
        common::assert_golden(name, &common::raster(&scene, &settings), TOLERANCE);
    }
}

/// Two facing mirrors: the corridor of reflections at the default depth.
#[test]
fn facing_mirrors() {
    let scene = common::load("scenes/mirrors.toml");
    common::assert_golden("mirrors", &common::raster(&scene, &scene.settings), TOLERANCE);
}

/// Environment maps: the chrome ball and copper torus under the sky, with dynamic cubes.
#[test]
fn environment_stage_with_dynamic_cubes() {
    let mut scene = common::load("scenes/environment.toml");
    (scene.camera.width, scene.camera.height) = (480, 270);
    common::assert_golden("environment", &common::raster(&scene, &scene.settings), TOLERANCE);
}

#[test]
fn volume_stage_composited_phantom_and_isosurface_torus() {
    let scene = common::load("scenes/volume.toml");
    common::assert_golden("volume", &common::raster(&scene, &scene.settings), TOLERANCE);
}

#[test]
fn shadow_stage_with_shadow_maps() {
    let scene = common::load("scenes/shadows.toml");
    common::assert_golden("shadows-map", &common::raster(&scene, &scene.settings), TOLERANCE);
}

#[test]
fn shadow_stage_with_projected_polygons() {
    let scene = common::load("scenes/shadows.toml");
    let mut settings = scene.settings.clone();
    settings.shadows.method = mirador::settings::ShadowMethod::Projected;
    common::assert_golden("shadows-projected", &common::raster(&scene, &settings), TOLERANCE);
}

/// The showcase's floor running to the horizon, in each texture filter (docs/course/03-mipmaps.md).
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
        common::assert_golden(name, &common::raster(&scene, &settings), TOLERANCE);
    }
}

#[test]
fn bump_mapped_tile_and_ball() {
    let scene = common::load("scenes/bumps.toml");
    common::assert_golden("bumps", &common::raster(&scene, &scene.settings), TOLERANCE);
}

/// Another CPU generation's render of the volume stage passes (`tests/data/cross-cpu/`): one
/// level less red on every floor pixel, up to 22 levels on a few dozen pixels at the volumes'
/// edges. FLIP alone puts it at 0.0134, over the threshold; beyond the CPU's levels it is well
/// inside.
#[test]
fn another_cpus_volume_stage_passes() {
    let golden = image::open(common::golden_dir().join("volume.png")).expect("the volume golden").into_rgba8();
    let other = common::data_image("cross-cpu/golden-volume-avx512.png");
    let plain = mirador::compare::difference(&golden, &other).unwrap().flip_mean;
    assert!(plain > TOLERANCE.flip_mean, "the image shows the rounding this test is about: {plain}");
    let error = GoldenError::between(&golden, &other).unwrap();
    eprintln!("another CPU's volume stage: FLIP {plain:.5}; beyond {} levels {error:?}", common::CPU_LEVELS);
    assert!(error.excesses(TOLERANCE).is_empty(), "{:?}", error.excesses(TOLERANCE));
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
    let flip = common::flip(&reference, &common::raster(&moved, &moved.settings));
    assert!(flip > TOLERANCE.flip_mean, "moving the light 5 units changed the image by only {flip}");

    let mut dimmer = scene.clone();
    dimmer.ambient = glam::Vec3::splat(0.1);
    let flip = common::flip(&reference, &common::raster(&dimmer, &dimmer.settings));
    assert!(flip > TOLERANCE.flip_mean, "halving the ambient light changed the image by only {flip}");
}

/// The showcase golden (640×360), the image the tests below damage.
fn showcase_golden() -> image::RgbaImage {
    image::open(common::golden_dir().join("showcase.png")).expect("the showcase golden").into_rgba8()
}

/// A local change fails though the whole-image mean stays under its threshold: the case the
/// region statistic is there for. A 40×40 patch painted magenta, or made 20% darker.
#[test]
fn a_wrong_patch_fails_though_the_mean_passes() {
    let golden = showcase_golden();
    let paints: [fn(&mut image::Rgba<u8>); 2] = [
        |pixel| *pixel = image::Rgba([255, 0, 255, 255]),
        |pixel| pixel.0[..3].iter_mut().for_each(|c| *c = (f32::from(*c) * 0.8) as u8),
    ];
    for paint in paints {
        let mut patched = golden.clone();
        for y in 280..320 {
            for x in 300..340 {
                paint(patched.get_pixel_mut(x, y));
            }
        }
        let error = GoldenError::between(&golden, &patched).unwrap();
        assert!(error.flip_mean < TOLERANCE.flip_mean, "the mean alone would pass: {error:?}");
        let excesses = error.excesses(TOLERANCE);
        assert!(excesses.len() == 1 && excesses[0].contains("region"), "{excesses:?}");
    }
}

/// A render that lost its last 8 rows (a readback band left black) fails.
#[test]
fn a_missing_band_fails() {
    let golden = showcase_golden();
    let mut damaged = golden.clone();
    for y in golden.height() - 8..golden.height() {
        for x in 0..golden.width() {
            damaged.put_pixel(x, y, image::Rgba([0, 0, 0, 255]));
        }
    }
    let error = GoldenError::between(&golden, &damaged).unwrap();
    assert!(!error.excesses(TOLERANCE).is_empty(), "a black band passed: {error:?}");
}

/// A corrupted golden file, or one of another size, fails with the file named and the render
/// kept for inspection; an intact copy of the same golden passes.
#[test]
fn a_corrupted_or_resized_golden_fails() {
    let dir = std::env::temp_dir().join(format!("mirador-golden-corrupt-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let golden = showcase_golden();
    let bytes = std::fs::read(common::golden_dir().join("showcase.png")).unwrap();
    std::fs::write(dir.join("intact.png"), &bytes).unwrap();
    std::fs::write(dir.join("truncated.png"), &bytes[..bytes.len() / 2]).unwrap();
    image::imageops::resize(&golden, 320, 180, image::imageops::FilterType::Triangle)
        .save(dir.join("resized.png"))
        .unwrap();
    let error = common::check_golden(&dir, "intact", &golden, TOLERANCE).unwrap();
    assert_eq!((error.flip_mean, error.worst_region), (0.0, 0.0));
    for name in ["truncated", "resized"] {
        let message = common::check_golden(&dir, name, &golden, TOLERANCE).unwrap_err();
        assert!(message.contains(name), "{message}");
        assert!(dir.join(format!("{name}-actual.png")).exists(), "{name}: the render is kept");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// NaN cannot reach the comparison through the images, which are 8-bit (the output transform
/// maps NaN radiance to 0, `output.rs`); but a NaN in the per-pixel errors must fail, not slip
/// through `NaN > threshold` being false.
#[test]
fn a_nan_error_fails_every_tolerance() {
    let mut errors = vec![0.0; 64 * 64];
    errors[64 * 10 + 20] = f32::NAN;
    let error = GoldenError::from_flip(&errors, 64, 64);
    assert_eq!(error.excesses(TOLERANCE).len(), 2, "{error:?}");
    let generous = Tolerance { flip_mean: 1.0, worst_region: 1.0 };
    assert_eq!(error.excesses(generous).len(), 2, "{error:?}");
    assert!(GoldenError::from_flip(&vec![0.0; 64 * 64], 64, 64).excesses(TOLERANCE).is_empty());
}

/// The region statistic against hand-computed values: one bright 32×32 block is its own worst
/// region; the same error spread thinly is not.
#[test]
fn the_worst_region_is_the_mean_of_the_worst_window() {
    let (width, height) = (100, 60);
    let mut block = vec![0.0; width * height];
    for y in 20..52 {
        for x in 50..82 {
            block[y * width + x] = 0.5;
        }
    }
    let error = GoldenError::from_flip(&block, width as u32, height as u32);
    assert!((error.worst_region - 0.5).abs() < 1e-6, "{error:?}");
    assert!((error.flip_mean - 0.5 * 1024.0 / 6000.0).abs() < 1e-6, "{error:?}");
    let spread = vec![0.5 * 1024.0 / 6000.0; width * height];
    let error = GoldenError::from_flip(&spread, width as u32, height as u32);
    assert!((error.worst_region - error.flip_mean).abs() < 1e-6, "{error:?}");
}

/// Displacement mapping: the cobbled ball with its relief made as triangles (its outline and
/// self-shadows the relief's), the triangles the tracer traces (`bump.tessellation = "uniform"`).
#[test]
fn displaced_ball() {
    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    (scene.camera.width, scene.camera.height) = (480, 270);
    scene.settings.bump.method = mirador::settings::BumpMethod::Displacement;
    scene.settings.bump.tessellation = mirador::settings::Tessellation::Uniform;
    mirador::texture::displacement::displace(&mut scene);
    common::assert_golden("displaced-ball", &common::raster(&scene, &scene.settings), TOLERANCE);
}

/// The same ball tessellated on the GPU for the view (`bump.tessellation = "adaptive"`, the
/// default); and with edges of up to 16 pixels under the tessellation view: finer where the ball
/// faces the camera, coarser towards its outline, where its triangles are seen edge on.
#[test]
fn displaced_ball_adaptive() {
    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    (scene.camera.width, scene.camera.height) = (480, 270);
    scene.settings.bump.method = mirador::settings::BumpMethod::Displacement;
    mirador::texture::displacement::displace(&mut scene);
    let mut settings = scene.settings.clone();
    common::assert_golden("displaced-ball-adaptive", &common::raster(&scene, &settings), TOLERANCE);
    settings.bump.view = mirador::settings::BumpView::Tessellation;
    settings.bump.edge_pixels = 16.0;
    common::assert_golden("displaced-ball-adaptive-edges", &common::raster(&scene, &settings), TOLERANCE);
}
