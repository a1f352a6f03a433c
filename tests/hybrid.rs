//! The hybrid (`settings.hybrid`, `src/raster/traced.rs`): with every approximation the rasterizer
//! makes swapped for its traced term, the raster frame is the tracer's image, up to what no swap
//! removes (primary visibility). Checked on every scene the course and the tests use, and
//! two-sided: each scene's plain raster frame must be measurably farther from the tracer wherever
//! the scene uses something the hybrid swaps, so a swap that did nothing would fail.

mod common;

use std::path::PathBuf;

use mirador::Scene;
use mirador::settings::RenderSettings;

/// Every scene under `assets/scenes/` and `assets/scenes/course/`.
fn scene_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for folder in ["scenes", "scenes/course"] {
        let folder = common::asset(folder);
        let entries = std::fs::read_dir(&folder).unwrap_or_else(|e| panic!("{}: {e}", folder.display()));
        files.extend(
            entries.map(|e| e.expect("a folder entry").path()).filter(|p| p.extension().is_some_and(|x| x == "toml")),
        );
    }
    files.sort();
    files
}

/// `scene` drawn at most `width` pixels wide, its aspect kept.
fn smaller(mut scene: Scene, width: u32) -> Scene {
    let camera = &mut scene.camera;
    if camera.width > width {
        camera.height = (camera.height * width).div_ceil(camera.width);
        camera.width = width;
    }
    scene
}

fn every_term_traced(settings: &RenderSettings) -> RenderSettings {
    let mut hybrid = settings.clone();
    let h = &mut hybrid.hybrid;
    (h.shadows, h.reflections, h.transmission, h.textures) = (true, true, true, true);
    hybrid
}

#[test]
fn every_scene_with_every_term_traced_is_the_tracers_image() {
    let mut report = Vec::new();
    for path in scene_files() {
        let scene = smaller(Scene::load(&path).unwrap_or_else(|e| panic!("{e}")), 240);
        let traced = mirador::trace::render_image(&scene, &scene.settings);
        let hybrid = common::flip(&traced, &common::raster(&scene, &every_term_traced(&scene.settings)));
        let plain = common::flip(&traced, &common::raster(&scene, &scene.settings));
        let name = path.file_name().expect("a file").to_string_lossy().into_owned();
        eprintln!("{name:<36} raster {plain:.4}, every term traced {hybrid:.4}");
        report.push((name, plain, hybrid));
    }
    for (name, plain, hybrid) in &report {
        // Measured at most 0.0010 (the silhouettes of tessellated shapes), at 240 pixels wide.
        assert!(*hybrid < 0.01, "{name}: every term traced vs the tracer: FLIP {hybrid}");
        assert!(hybrid <= plain, "{name}: the hybrid {hybrid} is farther from the tracer than the raster {plain}");
    }
    // The other side: where the approximations show, the swaps are what closes the gap.
    let shown = report.iter().filter(|(_, plain, hybrid)| *plain > 0.02 && *plain > 10.0 * hybrid).count();
    assert!(shown >= 5, "scenes whose raster frame the swaps bring from over 0.02 to a tenth: {shown}");
}
