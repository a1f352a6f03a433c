//! Image tests: a scene drawn with the student's functions, against the same scene drawn with
//! Mirador's (the reference) or against the ray tracer. Errors are FLIP beyond two levels of
//! 255, the golden tests' rule: the same shader on another CPU rounds a flat area by a level.

use super::{Against, ImageTest};
use crate::compare::{self, Figures};
use crate::gpu::Gpu;
use crate::raster::Headless;
use crate::scene::Scene;
use crate::scene::file::overrides;
use crate::shaders::Wgsl;
use image::RgbaImage;
use std::path::Path;

/// Per-pixel differences of up to this many levels (of 255) are not counted: the same shader on
/// two CPUs rounds differently (tests/README.md).
pub const LEVELS: u8 = 2;

/// The test's scene at the test's size, its settings applied. `folder` is where a hidden test's
/// file lies: a scene path relative to it is read from there, any other from Mirador's
/// `assets/scenes/`.
pub fn scene(test: &ImageTest, folder: Option<&Path>) -> Result<Scene, String> {
    let local = folder.map(|f| f.join(&test.scene)).filter(|p| p.exists());
    let path = local.unwrap_or_else(|| crate::scene::builtin_path(&test.scene));
    let (values, settings): (Vec<String>, Vec<String>) =
        test.set.iter().cloned().partition(|a| overrides::is_scene_override(a));
    let mut scene = overrides::load(&path, &values).map_err(|e| format!("{e:#}"))?;
    for assignment in &settings {
        scene.settings.set(assignment).map_err(|e| format!("{assignment}: {e:#}"))?;
    }
    scene.camera.width = test.size[0];
    scene.camera.height = test.size[1];
    Ok(scene)
}

/// `scene` drawn by the rasterizer compiled from `wgsl`; a GPU error is its text. Natively, it
/// waits for the image.
#[cfg(not(target_arch = "wasm32"))]
pub fn raster(gpu: &Gpu, scene: &Scene, wgsl: &Wgsl) -> Result<RgbaImage, String> {
    crate::gpu::readback::block_on(&gpu.device, drawn(gpu, scene, wgsl))
}

/// [`raster`] as a future, which the page polls a frame at a time.
pub async fn drawn(gpu: &Gpu, scene: &Scene, wgsl: &Wgsl) -> Result<RgbaImage, String> {
    drawn_with(gpu, scene, wgsl, false).await.map(|(image, _)| image)
}

/// [`drawn`], and how many of the image's pixels were not finite (NaN or infinite in any channel)
/// before the output transform: the HDR target read back too. The transform shows a NaN as
/// whatever the device makes of it, so such pixels are named rather than compared.
pub async fn drawn_counted(gpu: &Gpu, scene: &Scene, wgsl: &Wgsl) -> Result<(RgbaImage, usize), String> {
    drawn_with(gpu, scene, wgsl, true).await
}

/// The image, and with `count` the number of its pixels that were not finite (else 0).
async fn drawn_with(gpu: &Gpu, scene: &Scene, wgsl: &Wgsl, count: bool) -> Result<(RgbaImage, usize), String> {
    use crate::gpu::readback::{Pending, ReadbackError};
    let draw = || -> Result<_, ReadbackError> {
        let mut headless = Headless::with_wgsl(gpu, scene, wgsl.clone());
        let image = headless.render_later(gpu, scene, &scene.settings)?;
        let hdr =
            count.then(|| Pending::start(&gpu.device, &gpu.queue, &headless.targets.hdr.texture, 8)).transpose()?;
        Ok((image, hdr))
    };
    let started = gpu.checked_later(draw).await;
    let (readback, hdr) = started.map_err(|e| e.to_string())?.map_err(|e| e.to_string())?;
    let (width, height) = readback.size();
    let pixels = readback.texels(&gpu.device).await.map_err(|e| e.to_string())?;
    let not_finite = match hdr {
        None => 0,
        // Rgba16Float: a half is not finite when its exponent's bits are all set.
        Some(hdr) => hdr
            .texels(&gpu.device)
            .await
            .map_err(|e| e.to_string())?
            .chunks_exact(8)
            .filter(|texel| texel.chunks_exact(2).any(|half| u16::from_le_bytes([half[0], half[1]]) & 0x7C00 == 0x7C00))
            .count(),
    };
    let image =
        RgbaImage::from_raw(width, height, pixels).ok_or_else(|| "the readback has the wrong size".to_owned())?;
    Ok((image, not_finite))
}

/// `scene` traced.
pub fn traced(scene: &Scene) -> RgbaImage {
    crate::trace::render_image(scene, &scene.settings)
}

/// What an image test found.
pub struct Outcome {
    pub passed: bool,
    /// Against the image the test compares with.
    pub figures: Figures,
    /// Against the tracer: the reference's own figures, which the student's may exceed by the
    /// test's margins.
    pub baseline: Option<Figures>,
    /// The student's error map against the image compared with.
    pub error_map: RgbaImage,
    pub output: String,
}

/// The figures of `yours` against `correct`, and their error map.
pub fn figures(correct: &RgbaImage, yours: &RgbaImage) -> (Figures, RgbaImage) {
    let difference = compare::difference_beyond(correct, yours, LEVELS).expect("both images have the test's size");
    (Figures::of(&difference.flip_errors, correct.width(), correct.height(), None), difference.error_map)
}

/// Judges `yours` against `correct` (the reference's image, or the tracer's with the
/// reference's image as `reference`).
pub fn judge(test: &ImageTest, correct: &RgbaImage, yours: &RgbaImage, reference: Option<&RgbaImage>) -> Outcome {
    let (found, error_map) = figures(correct, yours);
    let baseline = match (test.against, reference) {
        (Against::Tracer, Some(reference)) => Some(figures(correct, reference).0),
        _ => None,
    };
    let (mean_limit, region_limit) = match baseline {
        Some(base) => (base.mean + test.mean, base.worst_region + test.region),
        None => (test.mean, test.region),
    };
    let against = match test.against {
        Against::Reference => "against Mirador's image",
        Against::Tracer => "against the ray tracer's",
    };
    let within = |value: f32, limit: f32| !value.is_nan() && value <= limit;
    let passed = within(found.mean, mean_limit) && within(found.worst_region, region_limit);
    let [x, y] = found.worst_region_at;
    let mut output = format!(
        "{against}: mean FLIP {:.4} (at most {:.4}), worst 32×32 region {:.4} at ({x}, {y}) (at most {:.4})",
        found.mean, mean_limit, found.worst_region, region_limit
    );
    if let Some(base) = baseline {
        output.push_str(&format!("; Mirador's own: {:.4} and {:.4}", base.mean, base.worst_region));
    }
    Outcome { passed, figures: found, baseline, error_map, output }
}
