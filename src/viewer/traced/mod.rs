//! The ray-traced image, refined beside the window so the window never waits for it.
//!
//! For each request — a scene, its settings and the camera at the view's full size — the
//! [`TracedWorker`] shows progressive refinement
//! ([`crate::trace::Progressive`], docs/course/10-anti-aliasing.md#progressive-refinement): one
//! ray per 16×16 block, then 8×8, then 4×4; then it traces the whole image with the configured
//! anti-aliasing, stopping when the camera, the scene or a setting changes. With `center` sampling
//! the final image is exactly the one `mirador trace` writes, pixel-aligned with the rasterizer.
//!
//! In the difference view the window also hands over its raster image (read back only in that
//! mode); once the final traced image of the same request exists, the worker computes the FLIP
//! error map between them.
//!
//! - [`thread`] (native): one worker thread with a rayon pool of all cores but one (the other
//!   keeps the rasterizer and the UI responsive), cancelled within a tile.
//! - [`slices`] (the browser, which gives a page one thread): the progressive levels in slices of
//!   a few milliseconds between frames; the full image in rows handed to [`pool`]'s Web Workers,
//!   one a core, or in slices where there are none. The page asks for frames at once while its
//!   own thread has work, and only now and then while the workers trace.

#[cfg(target_arch = "wasm32")]
mod pool;
#[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
mod recipe;
#[cfg(target_arch = "wasm32")]
mod slices;
#[cfg(not(target_arch = "wasm32"))]
mod thread;

use std::time::Duration;

use image::RgbaImage;

#[cfg(target_arch = "wasm32")]
pub(in crate::viewer) use pool::Pool;
#[cfg(target_arch = "wasm32")]
pub(crate) use recipe::SceneRecipe;
#[cfg(target_arch = "wasm32")]
pub(crate) use slices::OwnedTracer;
#[cfg(target_arch = "wasm32")]
pub(in crate::viewer) use slices::TracedWorker;
#[cfg(not(target_arch = "wasm32"))]
pub(in crate::viewer) use thread::TracedWorker;

/// The coarsest level of progressive refinement: one ray per `START_BLOCK²` pixels.
const START_BLOCK: u32 = 16;
/// The last progressive level before the full render.
const LAST_BLOCK: u32 = 4;

/// A new traced image for request `key`.
pub struct TracedFrame {
    pub key: u64,
    pub image: RgbaImage,
    /// The side of the blocks each traced ray fills (1 when complete).
    pub block: u32,
    pub complete: bool,
    /// Since the request started.
    pub elapsed: Duration,
}

/// The FLIP comparison of request `key`.
pub struct DifferenceFrame {
    pub key: u64,
    pub flip_mean: f32,
    pub error_map: RgbaImage,
}

enum Update {
    Traced(TracedFrame),
    Difference(DifferenceFrame),
}

/// The FLIP comparison, once the raster image and the final traced image of one request are both
/// there.
fn compare_ready(
    raster: &mut Option<(u64, RgbaImage)>,
    finished: &Option<(u64, RgbaImage)>,
) -> Option<DifferenceFrame> {
    let ((raster_key, raster_image), (traced_key, traced_image)) = (raster.as_ref()?, finished.as_ref()?);
    if raster_key != traced_key {
        return None;
    }
    let key = *raster_key;
    let result = crate::compare::difference(traced_image, raster_image);
    *raster = None;
    match result {
        Ok(d) => Some(DifferenceFrame { key, flip_mean: d.flip_mean, error_map: d.error_map }),
        Err(e) => {
            log::warn!("difference view: {e}");
            None
        }
    }
}

/// The traced image and the difference map as the window shows them: the worker, and the newest
/// of its images uploaded as egui textures.
pub struct TracedView {
    pub worker: TracedWorker,
    pub image: Option<Shown>,
    pub difference: Option<ShownDifference>,
    /// What the current traced request was made from, and its key.
    pub request: Option<(crate::scene::Camera, crate::RenderSettings, u64, Vec<crate::scene::Light>)>,
    pub key: u64,
}

/// A traced image on screen.
pub struct Shown {
    pub key: u64,
    pub texture: egui::TextureHandle,
    pub block: u32,
    pub complete: bool,
    pub elapsed: Duration,
}

/// A FLIP error map on screen.
pub struct ShownDifference {
    pub key: u64,
    pub texture: egui::TextureHandle,
    pub flip_mean: f32,
}

fn color_image(image: &RgbaImage) -> egui::ColorImage {
    egui::ColorImage::from_rgba_unmultiplied([image.width() as usize, image.height() as usize], image.as_raw())
}

impl TracedView {
    pub fn new(wake: impl Fn() + Send + 'static) -> TracedView {
        TracedView { worker: TracedWorker::start(wake), image: None, difference: None, request: None, key: 0 }
    }

    /// Uploads whatever the worker finished since the last frame; returns whether anything did.
    pub fn poll(&mut self, ctx: &egui::Context) -> bool {
        let (traced, difference) = self.worker.poll();
        let arrived = traced.is_some() || difference.is_some();
        // Nearest filtering: at full resolution the texels are the window's pixels.
        let options = egui::TextureOptions::NEAREST;
        if let Some(frame) = traced {
            let image = color_image(&frame.image);
            let texture = match self.image.take() {
                Some(mut shown) => {
                    shown.texture.set(image, options);
                    shown.texture
                }
                None => ctx.load_texture("viewer::traced", image, options),
            };
            self.image = Some(Shown {
                key: frame.key,
                texture,
                block: frame.block,
                complete: frame.complete,
                elapsed: frame.elapsed,
            });
        }
        if let Some(frame) = difference {
            let image = color_image(&frame.error_map);
            let texture = match self.difference.take() {
                Some(mut shown) => {
                    shown.texture.set(image, options);
                    shown.texture
                }
                None => ctx.load_texture("viewer::difference", image, options),
            };
            self.difference = Some(ShownDifference { key: frame.key, texture, flip_mean: frame.flip_mean });
        }
        arrived
    }

    /// Whether the traced image of request `key` is complete (and, when `with_difference`, its
    /// FLIP map too).
    pub fn complete(&self, key: u64, with_difference: bool) -> bool {
        let traced = self.image.as_ref().is_some_and(|s| s.key == key && s.complete);
        traced && (!with_difference || self.difference.as_ref().is_some_and(|d| d.key == key))
    }
}
