//! Direct volume rendering (docs/course/11-volumes.md): the rasterizer's GPU ray marching against the
//! tracer's, which march the same samples of the same field by construction, so they must agree
//! up to the GPU's 16-bit field and hardware filtering; opacity correction against the step;
//! early termination against marching to the end; the reconstruction against the analytic
//! Marschner–Lobb signal; and scene-file errors. Compositing, interpolation and gradients are
//! tested by hand in `src/volume/`.

mod common;

use common::flip;
use glam::{UVec3, Vec3};
use mirador::settings::{VolumeMode, VolumeView};
use mirador::volume::{Grid, Reconstruction, fields};
use mirador::{RenderSettings, Scene};

fn stage() -> Scene {
    let mut scene = common::load("scenes/volume.toml");
    (scene.camera.width, scene.camera.height) = (240, 150);
    scene
}

fn traced(scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    mirador::trace::render_image(scene, settings)
}

/// Raster against traced FLIP.
fn parity(scene: &Scene, settings: &RenderSettings) -> f32 {
    flip(&traced(scene, settings), &common::raster(scene, settings))
}

/// The bound of the composited parity test, measured: 0.0039 on the machines the goldens come
/// from, 0.0041 with another CPU's images (below).
const COMPOSITE_PARITY: f32 = 0.01;

#[test]
fn composited_volumes_agree_with_the_tracer() {
    let scene = stage();
    let mut settings = scene.settings.clone();
    settings.volume.mode = VolumeMode::Composite;
    let error = parity(&scene, &settings);
    eprintln!("composite raster vs traced: FLIP {error:.5}");
    assert!(error < COMPOSITE_PARITY, "composite raster vs traced: FLIP {error}");
    // The comparison can tell: a raster without gradient shading is far from the shaded tracer.
    let mut unshaded = settings.clone();
    unshaded.set("volume.gradient=\"off\"").unwrap();
    let off = flip(&traced(&scene, &settings), &common::raster(&scene, &unshaded));
    eprintln!("unshaded raster vs shaded traced: FLIP {off:.5}");
    assert!(off > 2.0 * error + 0.005, "unshaded raster {off} vs shaded {error}");
}

/// The same comparison holds on images another CPU made (`tests/data/cross-cpu/README.md`): its
/// raster floor is one level darker in red than its traced one, 38 % of the image, which FLIP
/// alone counts as 0.0154.
#[test]
fn composited_parity_holds_for_another_cpus_images() {
    let image = |name: &str| common::data_image(&format!("cross-cpu/{name}"));
    let (raster, traced) = (image("composite-raster-avx512.png"), image("composite-traced-avx512.png"));
    let plain = mirador::compare::difference(&traced, &raster).unwrap().flip_mean;
    let error = flip(&traced, &raster);
    eprintln!("another CPU's composite: FLIP {plain:.5}, beyond {} levels {error:.5}", common::CPU_LEVELS);
    assert!(plain > COMPOSITE_PARITY, "the images show the rounding this test is about: {plain}");
    assert!(error < COMPOSITE_PARITY, "another CPU's composite raster vs traced: FLIP {error}");
}

#[test]
fn isosurfaces_agree_with_the_tracer_shadows_included() {
    let scene = stage();
    let mut settings = scene.settings.clone();
    settings.volume.mode = VolumeMode::Isosurface;
    settings.shadows.enabled = true;
    let error = parity(&scene, &settings);
    eprintln!("isosurface raster vs traced: FLIP {error:.5}");
    assert!(error < 0.02, "isosurface raster vs traced: FLIP {error}");
}

#[test]
fn nearest_reconstruction_agrees_with_the_tracer() {
    let scene = stage();
    let mut settings = scene.settings.clone();
    settings.set("volume.reconstruction=\"nearest\"").unwrap();
    let error = parity(&scene, &settings);
    eprintln!("nearest raster vs traced: FLIP {error:.5}");
    assert!(error < 0.02, "nearest raster vs traced: FLIP {error}");
}

#[test]
fn both_renderers_take_the_same_samples_per_pixel() {
    // The samples view: a heat map of the samples each pixel took. Equal counts give equal
    // colours; a count off by one changes a pixel by 3/512 of the ramp.
    let scene = stage();
    let mut settings = scene.settings.clone();
    settings.volume.view = VolumeView::Samples;
    let (raster, traced) = (common::raster(&scene, &settings), traced(&scene, &settings));
    let differing = raster
        .pixels()
        .zip(traced.pixels())
        .filter(|(a, b)| a.0.iter().zip(b.0.iter()).any(|(x, y)| x.abs_diff(*y) > 8));
    let fraction = differing.count() as f32 / (raster.width() * raster.height()) as f32;
    eprintln!("{:.3} % of pixels took different sample counts", 100.0 * fraction);
    assert!(fraction < 0.01, "{:.2} % of the pixels took different sample counts", 100.0 * fraction);
}

#[test]
fn opacity_correction_keeps_the_image_when_the_step_changes() {
    let scene = stage();
    let at = |step: f32, correction: bool| {
        let mut settings = scene.settings.clone();
        settings.volume.mode = VolumeMode::Composite;
        settings.volume.step = step;
        settings.volume.opacity_correction = correction;
        traced(&scene, &settings)
    };
    let corrected = flip(&at(0.25, true), &at(1.0, true));
    let uncorrected = flip(&at(0.25, false), &at(1.0, false));
    eprintln!("steps 0.25 vs 1, traced: corrected FLIP {corrected:.5}, uncorrected {uncorrected:.5}");
    assert!(corrected < 0.02, "corrected steps 0.25 and 1: FLIP {corrected}");
    assert!(uncorrected > 2.0 * corrected, "uncorrected {uncorrected} vs corrected {corrected}");
    // The rasterizer corrects the same way.
    let mut settings = scene.settings.clone();
    settings.volume.step = 0.25;
    let fine = common::raster(&scene, &settings);
    settings.volume.step = 1.0;
    let coarse = common::raster(&scene, &settings);
    let raster = flip(&fine, &coarse);
    eprintln!("steps 0.25 vs 1, raster: corrected FLIP {raster:.5}");
    assert!(raster < 0.02, "raster corrected steps 0.25 and 1: FLIP {raster}");
}

#[test]
fn early_termination_saves_samples_and_little_else() {
    let scene = stage();
    let run = |early: bool| {
        let mut settings = scene.settings.clone();
        settings.volume.mode = VolumeMode::Composite;
        settings.volume.early_termination = early;
        let tracer = mirador::trace::Tracer::new(&scene, &settings);
        let control = mirador::trace::RenderControl::default();
        let (radiance, stats) = tracer.render(&control).unwrap();
        (radiance.to_rgba8(mirador::output::OutputTransform::of(&settings)), stats.rays)
    };
    let (with, counts_with) = run(true);
    let (without, counts_without) = run(false);
    assert_eq!(counts_without.volume_samples_saved, 0);
    assert!(counts_with.volume_samples_saved > 0);
    // Every sample is taken or saved: the planned total is the same.
    assert_eq!(counts_with.volume_samples + counts_with.volume_samples_saved, counts_without.volume_samples,);
    let error = flip(&with, &without);
    eprintln!(
        "early termination: {} samples taken, {} saved; FLIP {error:.5}",
        counts_with.volume_samples, counts_with.volume_samples_saved
    );
    assert!(error < 0.005, "early termination changed the image by FLIP {error}");
}

/// The RMS error of trilinear reconstruction of the Marschner–Lobb signal sampled on an `n`³ grid
/// over [−1, 1]³, at fixed pseudo-random points.
fn marschner_lobb_error(n: u32) -> f32 {
    let grid = Grid::from_function(UVec3::splat(n), fields::marschner_lobb).unwrap();
    let mut state = 12345u32;
    let mut next = || {
        state = state.wrapping_mul(1664525).wrapping_add(1013904223);
        (state >> 8) as f32 / (1u32 << 24) as f32 * 1.6 - 0.8
    };
    let mut sum = 0.0;
    let count = 20_000;
    for _ in 0..count {
        let p = Vec3::new(next(), next(), next());
        let error = grid.sample(grid.grid_coordinates(p), Reconstruction::Trilinear) - fields::marschner_lobb(p);
        sum += error * error;
    }
    (sum / count as f32).sqrt()
}

#[test]
fn the_marschner_lobb_error_falls_as_the_grid_refines() {
    let errors: Vec<f32> = [21, 41, 81, 161].into_iter().map(marschner_lobb_error).collect();
    eprintln!("Marschner–Lobb RMS error at 21, 41, 81, 161 points: {errors:?}");
    for pair in errors.windows(2) {
        assert!(pair[1] < 0.6 * pair[0], "errors by resolution 21, 41, 81, 161: {errors:?}");
    }
    // Well resolved, trilinear interpolation is second order: halving the spacing quarters it.
    let ratio = errors[2] / errors[3];
    assert!(ratio > 3.0, "81 → 161 reduced the error {ratio}×: {errors:?}");
    let nearest = {
        let grid = Grid::from_function(UVec3::splat(41), fields::marschner_lobb).unwrap();
        let p = Vec3::new(0.31, -0.22, 0.17);
        (grid.sample(grid.grid_coordinates(p), Reconstruction::Nearest) - fields::marschner_lobb(p)).abs()
    };
    assert!(nearest > 0.0);
}

/// A surface inside the volume ends its rays there, in both renderers; a glass pane in front of
/// the volume is composited over it.
#[test]
fn surfaces_inside_and_in_front_of_a_volume_are_composited_in_order() {
    let text = r#"
        [camera]
        eye = [0.0, 0.3, 3.5]
        center = [0.0, 0.0, 0.0]
        fovy = 40
        width = 200
        height = 150
        [world]
        ambient = [0.3, 0.3, 0.3]
        background = [0.1, 0.1, 0.15]
        [materials.red]
        color = [0.9, 0.1, 0.1]
        [materials.glass]
        color = [0.2, 0.4, 0.9]
        transmission = 0.6
        ior = 1.0
        [[lights]]
        type = "directional"
        direction = [-0.3, -1.0, -0.5]
        [[objects]]
        type = "sphere"
        radius = 0.35
        material = "red"
        [[objects]]
        type = "plane"
        size = [1.2, 0.6]
        rotate = [90, 0, 0]
        translate = [0.3, -0.2, 1.4]
        material = "glass"
        [[volumes]]
        field = { type = "sphere", radius = 0.9, resolution = 40 }
        transfer = [{ value = 0.0, colour = [0.2, 0.8, 0.3], alpha = 0.0 }, { value = 0.3, colour = [0.2, 0.8, 0.3], alpha = 0.04 }]
    "#;
    let scene = mirador::scene::file::parse(text, std::path::Path::new("inline.toml")).unwrap();
    let mut settings = scene.settings.clone();
    settings.shadows.enabled = false;
    let error = parity(&scene, &settings);
    eprintln!("sphere inside, pane in front: FLIP {error:.5}");
    assert!(error < 0.02, "raster vs traced with a sphere inside and a pane in front: FLIP {error}");
    // The red sphere shows through the green haze: the centre pixel is reddish in both.
    let raster = common::raster(&scene, &settings);
    let centre = raster.get_pixel(100, 75);
    assert!(centre[0] > centre[1], "centre pixel {centre:?}");
}

/// Glass panes through the middle of a composited volume: the exact order (depth peeling)
/// composites each ray's stretch of the volume between the layers it crosses, as the tracer
/// does; placing the volume whole among the panes by its centre (`object`) or behind them all
/// (`unsorted`, as every order did before volumes joined it) is measurably further off.
#[test]
fn panes_through_a_volume_are_composited_between_the_peeled_layers() {
    let text = r#"
        [camera]
        eye = [0.4, 0.3, 3.2]
        center = [0.0, 0.0, 0.0]
        fovy = 40
        width = 200
        height = 150
        [world]
        ambient = [0.4, 0.4, 0.4]
        background = [0.1, 0.1, 0.12]
        [materials.blue]
        color = [0.1, 0.2, 0.9]
        transmission = 0.55
        ior = 1.0
        [materials.amber]
        color = [0.9, 0.5, 0.05]
        transmission = 0.55
        ior = 1.0
        [[lights]]
        type = "directional"
        direction = [-0.3, -1.0, -0.5]
        [[objects]]
        type = "plane"
        size = [1.4, 0.9]
        rotate = [90, 0, 0]
        translate = [-0.15, 0.0, -0.35]
        material = "blue"
        [[objects]]
        type = "plane"
        size = [1.4, 0.9]
        rotate = [90, 0, 0]
        translate = [0.15, 0.05, 0.3]
        material = "amber"
        [[volumes]]
        field = { type = "sphere", radius = 0.9, resolution = 40 }
        transfer = [{ value = 0.0, colour = [0.9, 0.95, 0.9], alpha = 0.0 }, { value = 0.3, colour = [0.9, 0.95, 0.9], alpha = 0.12 }]
    "#;
    let scene = mirador::scene::file::parse(text, std::path::Path::new("inline.toml")).unwrap();
    let mut settings = scene.settings.clone();
    settings.shadows.enabled = false;
    let traced = traced(&scene, &settings);
    let error = |sort: &str| {
        let mut settings = settings.clone();
        settings.set(&format!("transparency.sort=\"{sort}\"")).unwrap();
        flip(&traced, &common::raster(&scene, &settings))
    };
    let (exact, object, unsorted) = (error("exact"), error("object"), error("unsorted"));
    eprintln!("panes through a volume, raster vs traced: exact {exact:.5}, object {object:.5}, unsorted {unsorted:.5}");
    assert!(exact < 0.01, "exact order vs traced: FLIP {exact}");
    assert!(object > 2.0 * exact && unsorted > 2.0 * exact, "exact {exact}, object {object}, unsorted {unsorted}");
}

fn load_error(volume: &str) -> String {
    let text = format!("[[volumes]]\n{volume}\n");
    match mirador::scene::file::parse(&text, std::path::Path::new("bad.toml")) {
        Ok(_) => panic!("accepted: {volume}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_volumes_in_scene_files_are_errors_with_their_line() {
    let field = "field = { type = \"marschner_lobb\", resolution = 9 }";
    let cases: [(String, &str); 9] = [
        (
            format!(
                "{field}\ntransfer = [\n  {{ value = 0.5, colour = [1, 1, 1], alpha = 0.1 }},\n  {{ value = 0.2, colour = [1, 1, 1], alpha = 0.1 }},\n]"
            ),
            "bad.toml:5:3: transfer: control point 2: values must not decrease",
        ),
        (
            format!("{field}\ntransfer = [{{ value = 3.0, colour = [1, 1, 1], alpha = 0.1 }}]"),
            "lies outside the volume's range",
        ),
        (format!("{field}\ntransfer = [{{ value = 0.5, colour = [1, 1, 1], alpha = 1.5 }}]"), "must lie in [0, 1]"),
        (
            format!("{field}\ntransfer = [{{ value = nan, colour = [1, 1, 1], alpha = 0.5 }}]"),
            "expected a finite number",
        ),
        ("field = { type = \"sphere\", resolution = 1 }".into(), "resolution must be at least 2, got 1"),
        ("field = { type = \"sphere\", resolution = [8, 0, 8] }".into(), "resolution must be at least 2, got 0"),
        (format!("{field}\npreset = \"bone\""), "no preset `bone`"),
        (format!("{field}\niso = 7"), "iso 7 lies outside the volume's range"),
        (format!("{field}\npath = \"x.nrrd\""), "exactly one of `path` (NRRD), `raw` or `field`"),
    ];
    for (volume, expected) in cases {
        let message = load_error(&volume);
        assert!(message.contains(expected), "{volume}\n→ {message}\n(expected `{expected}`)");
        assert!(message.starts_with("bad.toml"), "{message}");
    }
}

#[test]
fn the_phantom_file_holds_the_procedural_phantom() {
    // assets/volumes/phantom.nrrd is `fields::phantom` on 96³ points with 2.5-voxel edges,
    // written as 16-bit integers: every voxel within rounding of the function.
    let grid = mirador::scene::nrrd::read_nrrd(&common::asset("volumes/phantom.nrrd")).unwrap();
    assert_eq!(grid.dims, UVec3::splat(96));
    let blur = 2.5 * 2.0 / 95.0;
    let procedural = Grid::from_function(grid.dims, |p| fields::phantom(p, blur)).unwrap();
    let worst = grid.values.iter().zip(&procedural.values).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
    assert!(worst <= 0.5 + 1e-3, "largest difference {worst}");
    assert!((grid.spacing - Vec3::splat(2.0 / 95.0)).abs().max_element() < 1e-6);
}

#[test]
fn a_raw_file_of_the_wrong_size_is_named_with_the_scene_line() {
    let dir = std::env::temp_dir().join(format!("mirador-volumes-raw-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("short.raw"), vec![0u8; 999]).unwrap();
    let scene = dir.join("scene.toml");
    let text = "[[volumes]]\nraw = { path = \"short.raw\", dims = [10, 10, 10], type = \"uint8\" }\n";
    let error = mirador::scene::file::parse(text, &scene).unwrap_err().to_string();
    assert!(error.starts_with(&format!("{}:2:", scene.display())), "{error}");
    assert!(error.contains("short.raw") && error.contains("999") && error.contains("1000"), "{error}");
    // A good one loads.
    std::fs::write(dir.join("good.raw"), (0..1000u32).map(|i| (i % 251) as u8).collect::<Vec<_>>()).unwrap();
    let good =
        "[[volumes]]\nraw = { path = \"good.raw\", dims = [10, 10, 10], type = \"uint8\", spacing = [1, 1, 2] }\n";
    let loaded = mirador::scene::file::parse(good, &scene).unwrap();
    assert_eq!(loaded.volumes[0].grid.dims, UVec3::splat(10));
    assert_eq!(loaded.volumes[0].grid.half_extent(), Vec3::new(4.5, 4.5, 9.0));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A room whose volumes stand behind the camera: a composited sphere and a gold isosurface
/// torus, seen only in a planar mirror ahead and in a chrome ball's dynamic environment cube.
const VOLUMES_BEHIND_THE_CAMERA: &str = r#"
    [camera]
    eye = [0.0, 1.1, 2.0]
    center = [0.0, 1.0, -2.0]
    fovy = 50
    width = 240
    height = 160
    [world]
    ambient = [0.3, 0.3, 0.32]
    background = [0.12, 0.14, 0.2]
    [materials.floor]
    color = [0.6, 0.6, 0.55]
    [materials.mirror]
    color = [0.05, 0.05, 0.05]
    kd = 0.05
    mirror = 0.9
    mirror_color = [0.95, 0.95, 0.95]
    [materials.chrome]
    color = [0.05, 0.05, 0.05]
    kd = 0.05
    mirror = 0.9
    mirror_color = [0.95, 0.95, 0.97]
    [materials.gold]
    color = [0.85, 0.62, 0.22]
    [[lights]]
    type = "directional"
    direction = [-0.3, -1.0, -0.4]
    intensity = 0.8
    [[objects]]
    name = "floor"
    type = "plane"
    size = [12, 12]
    material = "floor"
    [[objects]]
    name = "mirror"
    type = "plane"
    size = [3.0, 2.0]
    rotate = [90, 0, 0]
    translate = [-0.6, 1.2, -2.5]
    material = "mirror"
    [[objects]]
    name = "chrome ball"
    type = "sphere"
    center = [1.2, 0.7, -1.0]
    radius = 0.7
    material = "chrome"
    [[volumes]]
    name = "cloud"
    field = { type = "sphere", radius = 0.6, resolution = 32 }
    mode = "composite"
    transfer = [
        { value = -1.0, colour = [0.2, 0.5, 1.0], alpha = 0.0 },
        { value = 0.0, colour = [0.2, 0.5, 1.0], alpha = 0.0 },
        { value = 0.5, colour = [0.3, 0.8, 1.0], alpha = 0.6 },
    ]
    translate = [-0.8, 1.1, 3.4]
    scale = 1.0
    [[volumes]]
    name = "torus"
    field = { type = "torus", resolution = 40 }
    mode = "isosurface"
    material = "gold"
    translate = [0.9, 1.0, 3.3]
    rotate = [70, 0, 0]
    scale = 0.8
    [settings.trace]
    max_depth = 2
"#;

/// Every view draws every phase: the composited volume and the isosurface behind the camera
/// appear in the planar mirror (a mirrored camera's view) and in the chrome ball (its dynamic
/// cube's faces), as the tracer's reflected rays see them; with the volumes left out of those
/// views (here: off) the images are measurably further from the tracer.
#[test]
fn volumes_appear_in_planar_mirrors_and_dynamic_cubes() {
    let scene = mirador::scene::file::parse(VOLUMES_BEHIND_THE_CAMERA, std::path::Path::new("behind.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let settings = scene.settings.clone();
    let traced = traced(&scene, &settings);
    let raster = common::raster(&scene, &settings);
    let mut without = settings.clone();
    without.volume.enabled = false;
    let raster_without = common::raster(&scene, &without);
    let traced_without = self::traced(&scene, &without);
    let _ = raster.save(std::env::temp_dir().join("mirador-volumes-behind-raster.png"));
    let _ = traced.save(std::env::temp_dir().join("mirador-volumes-behind-traced.png"));
    let _ = raster_without.save(std::env::temp_dir().join("mirador-volumes-behind-raster-without.png"));
    // The volumes are only in the reflections: the direct view of them is empty.
    let shown = flip(&traced_without, &traced);
    assert!(shown > 0.01, "the volumes show in the tracer's reflections: {shown}");
    let error = flip(&traced, &raster);
    let left_out = flip(&traced, &raster_without);
    eprintln!("volumes behind the camera: raster vs traced FLIP {error:.5}; volumes left out {left_out:.5}");
    // Most of the whole image's error is the chrome ball's cube map, captured at its centre
    // (parallax: the floor and the mirror reflect from the wrong place near the ball).
    assert!(error < 0.045, "volumes in mirrors and cubes, raster vs traced: FLIP {error}");
    // The planar mirror's window: a mirrored camera's view, where the two renderers agree.
    let crop =
        |image: &image::RgbaImage, [x, y, w, h]: [u32; 4]| image::imageops::crop_imm(image, x, y, w, h).to_image();
    let mirror = [40, 35, 90, 70];
    let (error, left_out) = (
        flip(&crop(&traced, mirror), &crop(&raster, mirror)),
        flip(&crop(&traced, mirror), &crop(&raster_without, mirror)),
    );
    eprintln!("in the mirror: raster vs traced FLIP {error:.5}; volumes left out {left_out:.5}");
    assert!(error < 0.01, "in the mirror: raster vs traced FLIP {error}");
    assert!(left_out > 10.0 * error, "in the mirror: left out {left_out} vs drawn {error}");
    // The middle of the ball, where it reflects what is behind the camera: its cube's faces. The
    // cube was captured at the ball's centre, so the reflections sit a few pixels off the
    // tracer's (parallax) and FLIP would measure that; count the pixels the volumes colour
    // instead (the room is grey: saturation below 30 levels).
    let ball = [170, 85, 40, 25];
    let coloured = |image: &image::RgbaImage| {
        crop(image, ball)
            .pixels()
            .filter(|p| p.0[..3].iter().max().unwrap() - p.0[..3].iter().min().unwrap() > 40)
            .count()
    };
    let (raster, traced, without) = (coloured(&raster), coloured(&traced), coloured(&raster_without));
    eprintln!(
        "in the ball: {raster} pixels coloured by the volumes in the raster, {traced} traced, {without} left out"
    );
    assert!(traced > 30, "the tracer's ball reflects the volumes: {traced} pixels");
    assert!(2 * raster > traced && raster < 2 * traced, "raster {raster} vs traced {traced} coloured pixels");
    assert_eq!(without, 0, "without the volumes the ball reflects only grey");
}
