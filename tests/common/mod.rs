//! Shared test harness: one headless device per test binary, scene rendering, and golden images
//! compared by FLIP.
//!
//! Golden images live in `tests/golden/NAME.png`. A comparison that fails writes
//! `tests/golden/NAME-actual.png` and `NAME-diff.png` (the FLIP error map; both ignored by git)
//! beside the golden. To bless new goldens, run the tests with `MIRADOR_BLESS=1`, then open every
//! image that changed and look at it before committing it (see README.md).

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use mirador::gpu::Gpu;
use mirador::{RenderSettings, Scene};

/// The device every test in this binary shares (device creation dominates small renders).
pub fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| {
        Gpu::headless().unwrap_or_else(|e| panic!("image tests need a graphics adapter (see README.md): {e}"))
    })
}

pub fn asset(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets").join(relative)
}

pub fn load(relative: &str) -> Scene {
    Scene::load(&asset(relative)).unwrap_or_else(|e| panic!("{e}"))
}

/// Renders `scene` with the rasterizer at its camera's size.
pub fn raster(scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    mirador::raster::render_image(gpu(), scene, settings)
}

/// Compares `actual` with `tests/golden/{name}.png` by mean FLIP error and fails above
/// `max_flip_mean`, leaving the actual image and the error map beside the golden.
pub fn assert_golden(name: &str, actual: &image::RgbaImage, max_flip_mean: f32) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("golden");
    let golden_path = dir.join(format!("{name}.png"));
    let actual_path = dir.join(format!("{name}-actual.png"));
    let diff_path = dir.join(format!("{name}-diff.png"));
    if std::env::var_os("MIRADOR_BLESS").is_some() {
        mirador::output::write_png_atomically(actual, &golden_path).expect("writing the blessed golden");
        eprintln!("blessed {} — look at it before committing", golden_path.display());
        return;
    }
    let golden = match image::open(&golden_path) {
        Ok(image) => image.into_rgba8(),
        Err(e) => {
            actual.save(&actual_path).expect("writing the actual image");
            panic!(
                "no golden image {} ({e}); the render is in {}. Look at it, then bless with MIRADOR_BLESS=1",
                golden_path.display(),
                actual_path.display()
            );
        }
    };
    let difference = mirador::compare::difference(&golden, actual).unwrap_or_else(|e| panic!("{name}: {e}"));
    if difference.flip_mean > max_flip_mean {
        actual.save(&actual_path).expect("writing the actual image");
        difference.error_map.save(&diff_path).expect("writing the error map");
        panic!(
            "{name}: mean FLIP {:.5} > {max_flip_mean} (PSNR {:.2} dB); see {} and {}",
            difference.flip_mean,
            difference.psnr_db,
            actual_path.display(),
            diff_path.display()
        );
    }
    let _ = std::fs::remove_file(&actual_path);
    let _ = std::fs::remove_file(&diff_path);
}
