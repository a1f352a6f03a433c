//! `--exr`: the linear radiance before the output transform, as OpenEXR, from `render`, `trace`
//! and `compare`. The tracer's file must hold exactly the radiance it computed; the
//! rasterizer's, put through the output transform (× exposure, clamp, sRGB), must give its PNG
//! within 1/255.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use glam::Vec3;
use mirador::linear_output::LinearImage;
use mirador::trace::{RenderControl, Tracer};
use mirador::{Scene, output};

fn mirador(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mirador")).args(args).output().expect("running the mirador binary")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mirador-exr-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("creating a scratch directory");
    dir
}

fn asset(relative: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets").join(relative).display().to_string()
}

fn run_ok(args: &[&str]) {
    let output = mirador(args);
    assert!(output.status.success(), "{args:?}: {}", String::from_utf8_lossy(&output.stderr));
}

/// The tracer's radiance for `scene_path` at `width × height` with the `--set` assignments
/// `set`, computed here.
fn traced(scene_path: &str, width: u32, height: u32, set: &[&str]) -> LinearImage {
    let mut scene = Scene::load(Path::new(scene_path)).unwrap_or_else(|e| panic!("{e}"));
    (scene.camera.width, scene.camera.height) = (width, height);
    for assignment in set {
        scene.settings.set(assignment).unwrap();
    }
    let tracer = Tracer::new(&scene, &scene.settings);
    let (radiance, _) = tracer.render(&RenderControl::default()).expect("not cancelled");
    LinearImage::new(radiance.width, radiance.height, radiance.pixels).unwrap()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

#[test]
fn trace_writes_the_radiance_it_computed() {
    let dir = scratch("trace");
    let (png, exr) = (dir.join("seed.png"), dir.join("seed.exr"));
    let scene = asset("scenes/seed-simple.toml");
    run_ok(&[
        "trace",
        &scene,
        "--width",
        "48",
        "--height",
        "40",
        "-o",
        png.to_str().unwrap(),
        "--exr",
        exr.to_str().unwrap(),
    ]);
    assert_eq!(files_in(&dir), ["seed.exr", "seed.png"], "both outputs, no temporary file");

    let written = LinearImage::read_exr(&exr).unwrap_or_else(|e| panic!("{e}"));
    let expected = traced(&scene, 48, 40, &[]);
    assert_eq!((written.width, written.height), (48, 40));
    // 32-bit floats, stored exactly: the same numbers, not merely close ones.
    assert_eq!(written, expected);
    assert!(written.pixels.iter().any(|c| c.max_element() > 0.0), "the image is not black");
}

#[test]
fn the_rasterizers_exr_through_the_output_transform_is_its_png() {
    let dir = scratch("render");
    let (png, exr) = (dir.join("showcase.png"), dir.join("showcase.exr"));
    // The showcase at exposure 3: much of it is brighter than 1 after exposure, which the PNG
    // clamps and the EXR must keep.
    let exposure = 3.0;
    run_ok(&[
        "render",
        "--width",
        "64",
        "--height",
        "36",
        "--set",
        &format!("exposure={exposure}"),
        "-o",
        png.to_str().unwrap(),
        "--exr",
        exr.to_str().unwrap(),
    ]);
    let linear = LinearImage::read_exr(&exr).unwrap_or_else(|e| panic!("{e}"));
    let png = image::open(&png).unwrap().into_rgba8();
    assert_eq!((linear.width, linear.height), png.dimensions());
    let mut worst = 0;
    for (radiance, pixel) in linear.pixels.iter().zip(png.pixels()) {
        let encoded = output::to_srgb8(*radiance, exposure);
        for c in 0..3 {
            worst = worst.max(encoded[c].abs_diff(pixel[c]));
        }
    }
    let clamped = linear.pixels.iter().filter(|c| c.max_element() * exposure > 1.0).count();
    let peak = linear.pixels.iter().map(|c| c.max_element()).fold(0.0, f32::max);
    eprintln!("raster EXR vs PNG: worst {worst}/255; {clamped} pixels clamped by the PNG; peak radiance {peak}");
    assert!(worst <= 1, "EXR × exposure, clamped and sRGB-encoded, differs from the PNG by {worst}/255");
    assert!(clamped > 0, "some radiance × exposure exceeds 1, kept in the EXR and clamped in the PNG");
    assert!(linear.pixels.iter().all(|c| c.is_finite() && c.min_element() >= 0.0));
}

#[test]
fn compare_writes_both_renderers_side_by_side() {
    let dir = scratch("compare");
    let (sheet, exr) = (dir.join("sheet.png"), dir.join("both.exr"));
    let scene = asset("scenes/seed-simple.toml");
    run_ok(&[
        "compare",
        &scene,
        "--width",
        "40",
        "--height",
        "30",
        "-o",
        sheet.to_str().unwrap(),
        "--exr",
        exr.to_str().unwrap(),
        "--set",
        "shadows.enabled=false",
    ]);
    let both = LinearImage::read_exr(&exr).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((both.width, both.height), (80, 30), "raster | traced");
    let traced = traced(&scene, 40, 30, &["shadows.enabled=false"]);
    let right: Vec<Vec3> = (0..30).flat_map(|y| both.pixels[y * 80 + 40..y * 80 + 80].to_vec()).collect();
    assert_eq!(right, traced.pixels, "the right half is the tracer's radiance");
    // The left half is the rasterizer's: the same scene, so close to the tracer's on average.
    let left: Vec<Vec3> = (0..30).flat_map(|y| both.pixels[y * 80..y * 80 + 40].to_vec()).collect();
    let mean_difference = left.iter().zip(&traced.pixels).map(|(a, b)| (*a - *b).abs().element_sum()).sum::<f32>()
        / (3.0 * left.len() as f32);
    eprintln!("compare EXR: raster vs traced radiance differ by {mean_difference} on average");
    assert!(mean_difference < 0.05, "raster and traced radiance differ by {mean_difference} on average");
}

#[test]
fn a_wrong_exr_extension_or_a_failed_run_writes_nothing() {
    let dir = scratch("refused");
    let png = dir.join("out.png");
    let output = mirador(&["trace", "-o", png.to_str().unwrap(), "--exr", dir.join("out.png").to_str().unwrap()]);
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success() && message.contains(".exr file"), "{message}");
    let output = mirador(&[
        "render",
        "missing.toml",
        "-o",
        png.to_str().unwrap(),
        "--exr",
        dir.join("out.exr").to_str().unwrap(),
    ]);
    assert!(!output.status.success());
    assert!(files_in(&dir).is_empty(), "a failed run left {:?}", files_in(&dir));
}

#[test]
fn the_rasterizers_exr_keeps_radiance_above_one() {
    // An emitter of radiance (4, 2, 0.5) and nothing else: the PNG clamps it, the EXR keeps it
    // (half-floats hold 4, 2 and 0.5 exactly).
    let dir = scratch("bright");
    let scene = dir.join("bright.toml");
    std::fs::write(
        &scene,
        r#"
        [camera]
        eye = [0, 0, 5]
        center = [0, 0, 0]
        width = 32
        height = 32
        [materials.lamp]
        kd = 0
        emission = [4, 2, 0.5]
        [[objects]]
        type = "sphere"
        material = "lamp"
        "#,
    )
    .unwrap();
    let (png, exr) = (dir.join("bright.png"), dir.join("bright.exr"));
    run_ok(&["render", scene.to_str().unwrap(), "-o", png.to_str().unwrap(), "--exr", exr.to_str().unwrap()]);
    let linear = LinearImage::read_exr(&exr).unwrap_or_else(|e| panic!("{e}"));
    let centre = linear.pixels[16 * 32 + 16];
    assert_eq!(centre, Vec3::new(4.0, 2.0, 0.5), "the emitter's radiance, unclamped");
    let png = image::open(&png).unwrap().into_rgba8();
    let [r, g, b, _] = png.get_pixel(16, 16).0;
    // sRGB(0.5) = 187.5/255: the GPU's encoding rounds it either way.
    assert!((r, g) == (255, 255) && (187..=188).contains(&b), "the PNG clamps 4 and 2 to 1: {:?}", (r, g, b));
    assert_eq!(linear.pixels[0], Vec3::ZERO, "the black background");
}
