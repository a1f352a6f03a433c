//! The traced image on a worker thread with a rayon pool of all cores but one; a request is
//! cancelled within a tile ([`RenderControl`]) when a newer one arrives.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};

use image::RgbaImage;
use web_time::Instant;

use super::{DifferenceFrame, LAST_BLOCK, START_BLOCK, TracedFrame, Update, compare_ready};
use crate::output::OutputTransform;
use crate::trace::{Progressive, RenderControl, Tracer};
use crate::{RenderSettings, Scene};

enum Request {
    Trace { key: u64, scene: Box<Scene>, settings: RenderSettings, cancel: Arc<AtomicBool> },
    Compare { key: u64, raster: RgbaImage },
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
    pub fn trace(&mut self, key: u64, scene: &Scene, _overrides: &[String], settings: &RenderSettings) {
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

    /// The worker thread wakes the window itself: no frame needs asking for.
    pub fn busy(&self) -> bool {
        false
    }

    /// Never: the thread wakes the window when it has an image.
    pub fn due(&self) -> Option<Instant> {
        None
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
    while let Some(block) = pool.install(|| progressive.refine(&tracer)) {
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
