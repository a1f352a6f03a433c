//! The ray-traced image, refined in the background so the window never waits for it.
//!
//! One worker thread owns a rayon pool of all cores but one (the other keeps the rasterizer and
//! the UI responsive). For each request — a scene, its settings and the camera at the view's full
//! size — it shows progressive refinement ([`Progressive`], docs/course/10-anti-aliasing.md#progressive-refinement): one ray per 16×16 block,
//! then 8×8, then 4×4; then it traces the whole image with the configured anti-aliasing through
//! [`Tracer::render`], whose [`RenderControl`] cancellation flag stops it within a tile when the
//! camera, the scene or a setting changes. With `center` sampling the final image is exactly the
//! one `mirador trace` writes, pixel-aligned with the rasterizer.
//!
//! In the difference view the window also hands over its raster image (read back only in that
//! mode); once the final traced image of the same request exists, the worker computes the FLIP
//! error map between them.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::time::{Duration, Instant};

use image::RgbaImage;

use crate::output::OutputTransform;
use crate::trace::{Progressive, RenderControl, Tracer};
use crate::{RenderSettings, Scene};

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

enum Request {
    Trace { key: u64, scene: Box<Scene>, settings: RenderSettings, cancel: Arc<AtomicBool> },
    Compare { key: u64, raster: RgbaImage },
}

enum Update {
    Traced(TracedFrame),
    Difference(DifferenceFrame),
}

/// The window's handle on the worker.
pub struct TracedWorker {
    requests: Sender<Request>,
    updates: Receiver<Update>,
    /// The request being traced and its cancellation flag.
    current: Option<(u64, Arc<AtomicBool>)>,
    compared: Option<u64>,
}

impl TracedWorker {
    /// Starts the worker; `wake` is called from it whenever an update is ready (to redraw).
    pub fn start(wake: impl Fn() + Send + 'static) -> TracedWorker {
        let (requests, inbox) = channel();
        let (outbox, updates) = channel();
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get().saturating_sub(1).max(1));
        std::thread::Builder::new()
            .name("mirador-traced".into())
            .spawn(move || {
                match rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .thread_name(|i| format!("mirador-trace-{i}"))
                    .build()
                {
                    Ok(pool) => work(&pool, &inbox, &outbox, &wake),
                    Err(e) => log::error!("the ray tracer's threads could not start: {e}"),
                }
            })
            .expect("spawning the tracer's worker thread");
        TracedWorker { requests, updates, current: None, compared: None }
    }

    /// Makes sure request `key` is being traced: a new key cancels the previous request.
    pub fn trace(&mut self, key: u64, scene: &Scene, settings: &RenderSettings) {
        if self.current.as_ref().is_some_and(|(k, _)| *k == key) {
            return;
        }
        if let Some((_, cancel)) = self.current.take() {
            cancel.store(true, Ordering::Relaxed);
        }
        let cancel = Arc::new(AtomicBool::new(false));
        let request =
            Request::Trace { key, scene: Box::new(scene.clone()), settings: settings.clone(), cancel: cancel.clone() };
        if self.requests.send(request).is_ok() {
            self.current = Some((key, cancel));
        }
    }

    /// Stops the current request (the view no longer shows traced images).
    pub fn stop(&mut self) {
        if let Some((_, cancel)) = self.current.take() {
            cancel.store(true, Ordering::Relaxed);
        }
    }

    /// Whether the raster image of request `key` was already handed over for comparison.
    pub fn compared(&self, key: u64) -> bool {
        self.compared == Some(key)
    }

    /// Hands over the raster image of request `key` for the FLIP comparison.
    pub fn compare(&mut self, key: u64, raster: RgbaImage) {
        if self.requests.send(Request::Compare { key, raster }).is_ok() {
            self.compared = Some(key);
        }
    }

    /// The newest traced image and difference that arrived since the last call.
    pub fn poll(&mut self) -> (Option<TracedFrame>, Option<DifferenceFrame>) {
        let (mut traced, mut difference) = (None, None);
        while let Ok(update) = self.updates.try_recv() {
            match update {
                Update::Traced(frame) => traced = Some(frame),
                Update::Difference(frame) => difference = Some(frame),
            }
        }
        (traced, difference)
    }
}

impl Drop for TracedWorker {
    fn drop(&mut self) {
        self.stop();
    }
}

/// The worker's loop: always work on the newest trace request; compare when both images of one
/// request are there. Ends when the window drops its [`TracedWorker`].
fn work(pool: &rayon::ThreadPool, inbox: &Receiver<Request>, outbox: &Sender<Update>, wake: &dyn Fn()) {
    let mut pending: Option<Request> = None;
    let mut raster: Option<(u64, RgbaImage)> = None;
    let mut finished: Option<(u64, RgbaImage)> = None;
    loop {
        // Block only when idle; then take everything already waiting, keeping the newest.
        if pending.is_none() {
            match inbox.recv() {
                Ok(request) => file(request, &mut pending, &mut raster),
                Err(_) => return,
            }
        }
        while let Ok(request) = inbox.try_recv() {
            file(request, &mut pending, &mut raster);
        }
        if let Some(frame) = compare_ready(&mut raster, &finished) {
            if outbox.send(Update::Difference(frame)).is_err() {
                return;
            }
            wake();
        }
        if let Some(Request::Trace { key, scene, settings, cancel }) = pending.take()
            && let Some(image) = trace(pool, key, &scene, &settings, &cancel, outbox, wake)
        {
            finished = Some((key, image));
        }
    }
}

/// Keeps the newest trace request and the newest raster image.
fn file(request: Request, pending: &mut Option<Request>, raster: &mut Option<(u64, RgbaImage)>) {
    match request {
        Request::Compare { key, raster: image } => *raster = Some((key, image)),
        trace @ Request::Trace { .. } => *pending = Some(trace),
    }
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

/// Traces one request: progressive levels, then the full image. Returns the final image, or
/// `None` when cancelled.
fn trace(
    pool: &rayon::ThreadPool,
    key: u64,
    scene: &Scene,
    settings: &RenderSettings,
    cancel: &AtomicBool,
    outbox: &Sender<Update>,
    wake: &dyn Fn(),
) -> Option<RgbaImage> {
    let start = Instant::now();
    let cancelled = || cancel.load(Ordering::Relaxed);
    let send = |image: RgbaImage, block: u32| {
        let complete = block == 1;
        let frame = TracedFrame { key, image, block, complete, elapsed: start.elapsed() };
        let sent = outbox.send(Update::Traced(frame)).is_ok();
        wake();
        sent
    };
    let tracer = Tracer::new(scene, settings);
    let mut progressive = Progressive::new(&tracer, START_BLOCK);
    while let Some(block) = pool.install(|| progressive.refine()) {
        if cancelled() || !send(progressive.image().to_rgba8(OutputTransform::of(settings)), block) {
            return None;
        }
        if block <= LAST_BLOCK {
            break;
        }
    }
    let control = RenderControl { cancel: Some(cancel), progress: false };
    let (radiance, _) = pool.install(|| tracer.render(&control)).ok()?;
    let image = radiance.to_rgba8(OutputTransform::of(settings));
    send(image.clone(), 1).then_some(image)
}

/// The traced image and the difference map as the window shows them: the worker, and the newest
/// of its images uploaded as egui textures.
pub struct TracedView {
    pub worker: TracedWorker,
    pub image: Option<Shown>,
    pub difference: Option<ShownDifference>,
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
        TracedView { worker: TracedWorker::start(wake), image: None, difference: None }
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
