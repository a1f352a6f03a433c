//! The traced image in the browser, which gives a page one thread: the progressive levels come
//! first, one level a slice of [`SLICE`] between frames on the page's thread. Then the full image
//! ([`Tracer::render_rows`], the rows `Tracer::render` would trace), shown as it goes over the
//! last progressive level: in bands handed to Web Workers, one a core ([`super::pool`]), or where
//! the browser gives none, a few rows a slice on the page's thread. The window asks for the next
//! frame at once while [`TracedWorker::busy`] (work is left for the page's thread), and at
//! [`TracedWorker::due`] while the workers trace: to show their rows so far every [`SHOW_WORKERS`],
//! or when the pool wakes the page with the last band. A page drawn on the CPU (no GPU, or none
//! the browser uses) draws each frame on the cores the workers trace on, so it draws few.
//!
//! With workers, they are given the job with the request, before the page's thread draws one
//! coarse level to show meanwhile, and they return their rows encoded for display: the page's
//! thread, which also draws the page (on a computer without a GPU, on the CPU), only copies them.

use std::rc::Rc;
use std::time::Duration;

use image::RgbaImage;
use web_time::Instant;

use super::SceneRecipe;
use super::pool::Pool;
use super::{DifferenceFrame, LAST_BLOCK, START_BLOCK, TracedFrame, Update, compare_ready};
use crate::output::{OutputTransform, encode_image};
use crate::trace::{Progressive, Tracer};
use crate::{RenderSettings, Scene};

/// How long one frame lends the tracer: a page at 60 Hz has 16 ms a frame, so this keeps the page
/// answering at about 20 frames a second while the tracer works.
const SLICE: Duration = Duration::from_millis(30);
/// How often the image in progress is shown while the page's thread traces the full image.
const SHOW_EVERY: Duration = Duration::from_millis(300);
/// How often the workers' rows so far are shown. Seldom: each frame the page draws on the CPU
/// (SwiftShader, about 0.1 s for the split view at 950×624) takes the cores the workers trace on,
/// and the showcase's rows are all in within a second.
const SHOW_WORKERS: Duration = Duration::from_secs(1);

self_cell::self_cell!(
    /// A tracer and the scene and settings it reads, kept together between slices (and in the
    /// page's tracer workers, `src/web/tracer.rs`).
    pub(crate) struct OwnedTracer {
        owner: Box<(Scene, RenderSettings)>,
        #[covariant]
        dependent: Tracer,
    }
);

/// The request being traced.
struct Job {
    key: u64,
    /// Its number in the workers' pool (0 without workers).
    number: u64,
    tracer: OwnedTracer,
    progressive: Progressive,
    /// The full image in progress (`None` while progressive levels remain).
    full: Option<Full>,
    started: Instant,
    shown: Instant,
}

/// The full image in progress.
struct Full {
    /// The rows received so far over the last progressive level, encoded for display.
    image: RgbaImage,
    /// That level's block size.
    below: u32,
    /// How many rows were received.
    received: u32,
    /// The first row not yet traced, where the page's thread traces them.
    next: u32,
    /// When the last band so far came from a worker.
    arrived: Option<Instant>,
}

/// The window's handle on the tracer: the same calls as the native worker thread's.
pub struct TracedWorker {
    job: Option<Job>,
    /// The workers, started after the page's first frame ([`TracedWorker::start_workers`]) so
    /// that they are ready (their module loaded and compiled, the files fetched) when the first
    /// traced view is asked for, or at that request if it comes first; `None` before, after they
    /// fail, or where the browser gives none.
    pool: Option<Pool>,
    pool_tried: bool,
    /// Wakes the page's event loop (the pool does, when a job's last band is in).
    wake: Rc<dyn Fn()>,
    updates: Vec<Update>,
    compared: Option<u64>,
    raster: Option<(u64, RgbaImage)>,
    finished: Option<(u64, RgbaImage)>,
}

impl TracedWorker {
    /// `wake` wakes the page's event loop: the workers' pool calls it when a job's last band is
    /// in.
    pub fn start(wake: impl Fn() + Send + 'static) -> TracedWorker {
        TracedWorker {
            job: None,
            pool: None,
            pool_tried: false,
            wake: Rc::new(wake),
            updates: Vec::new(),
            compared: None,
            raster: None,
            finished: None,
        }
    }

    /// Makes sure request `key` is being traced: a new key drops the previous request. `overrides`
    /// are the values set over the scene file's, which the workers apply again.
    pub fn trace(&mut self, key: u64, scene: &Scene, overrides: &[String], settings: &RenderSettings) {
        if self.job.as_ref().is_some_and(|job| job.key == key) || self.finished.as_ref().is_some_and(|(k, _)| *k == key)
        {
            return;
        }
        let tracer =
            OwnedTracer::new(Box::new((scene.clone(), settings.clone())), |owned| Tracer::new(&owned.0, &owned.1));
        let progressive = tracer.with_dependent(|_, tracer| Progressive::new(tracer, START_BLOCK));
        // The workers are given each request's job at once: the page's next frame can be a second
        // away on a page drawn on the CPU.
        self.start_workers();
        let number = self.pool.as_ref().map_or(0, |pool| {
            let recipe = SceneRecipe::of(scene, overrides, settings);
            let text = serde_json::to_string(&recipe).unwrap_or_default();
            pool.job(&text, &crate::files::opened(), progressive.image().height)
        });
        let now = Instant::now();
        self.job = Some(Job { key, number, tracer, progressive, full: None, started: now, shown: now });
    }

    /// Starts the workers, once (the page calls it after its first frame: started with the page,
    /// they made that frame about 0.1 s later on two cores).
    pub(in crate::viewer) fn start_workers(&mut self) {
        if !self.pool_tried {
            self.pool_tried = true;
            self.pool = Pool::start(self.wake.clone());
        }
    }

    /// The workers, for the raster frame's hybrid terms (`super::Pool::terms`); `None` before they
    /// start, after they fail, or where the browser gives none. A failure found here gives them
    /// up as one found by the traced image does: its rows are traced on this thread, from the top.
    pub(in crate::viewer) fn pool(&mut self) -> Option<&Pool> {
        if let Some(error) = self.pool.as_ref().and_then(Pool::failed) {
            log::warn!("the tracer workers failed ({error}); tracing on the page's thread");
            self.pool = None;
            if let Some(full) = self.job.as_mut().and_then(|job| job.full.as_mut()) {
                (full.received, full.next) = (0, 0);
            }
        }
        self.pool.as_ref()
    }

    /// Stops the current request (the view no longer shows traced images).
    pub fn stop(&mut self) {
        self.job = None;
        if let Some(pool) = &self.pool {
            pool.cancel();
        }
    }

    /// Whether the raster image of request `key` was already handed over for comparison.
    pub fn compared(&self, key: u64) -> bool {
        self.compared == Some(key)
    }

    /// Hands over the raster image of request `key` for the comparison.
    pub fn compare(&mut self, key: u64, raster: RgbaImage) {
        self.raster = Some((key, raster));
        self.compared = Some(key);
    }

    /// Whether work is left for the page's thread (a progressive level, rows where there are no
    /// workers, the comparison): the window asks for the next frame at once.
    pub fn busy(&self) -> bool {
        let comparable = matches!((&self.raster, &self.finished), (Some((a, _)), Some((b, _))) if a == b);
        let on_this_thread = self.job.as_ref().is_some_and(|job| job.full.is_none() || self.pool.is_none());
        on_this_thread || comparable
    }

    /// While the workers trace: when the rows they returned are next shown. The pool wakes the
    /// page sooner when the last band is in.
    pub fn due(&self) -> Option<Instant> {
        let job = self.job.as_ref().filter(|job| job.full.is_some() && self.pool.is_some())?;
        Some(job.shown + SHOW_WORKERS)
    }

    /// Works for one slice, then returns the newest traced image and difference made since the
    /// last call.
    pub fn poll(&mut self) -> (Option<TracedFrame>, Option<DifferenceFrame>) {
        let deadline = Instant::now() + SLICE;
        // The workers' bands arrive between frames: with them at work, one step a frame.
        while Instant::now() < deadline && self.job.is_some() && !self.work() {}
        if let Some(frame) = compare_ready(&mut self.raster, &self.finished) {
            self.updates.push(Update::Difference(frame));
        }
        let (mut traced, mut difference) = (None, None);
        for update in self.updates.drain(..) {
            match update {
                Update::Traced(frame) => traced = Some(frame),
                Update::Difference(frame) => difference = Some(frame),
            }
        }
        (traced, difference)
    }

    /// One step of the current job: a progressive level, or the full image's next rows from the
    /// workers or from this thread. Returns whether the workers have it, so the frame should not
    /// wait for them.
    fn work(&mut self) -> bool {
        let Some(job) = &mut self.job else { return false };
        let transform = OutputTransform::of(&job.tracer.borrow_owner().1);
        let (width, height) = (job.progressive.image().width, job.progressive.image().height);
        if job.full.is_none() {
            let progressive = &mut job.progressive;
            let block = job.tracer.with_dependent(|_, tracer| progressive.refine(tracer)).unwrap_or(1);
            let image = progressive.image().to_rgba8(transform);
            // With workers the full image comes soon: one coarse level to show meanwhile.
            if block <= LAST_BLOCK || self.pool.is_some() {
                job.full = Some(Full { image: image.clone(), below: block, received: 0, next: 0, arrived: None });
            }
            self.updates.push(Update::Traced(frame(job.key, image, block, job.started)));
            if self.pool.is_none() {
                return false;
            }
        }
        let Some(full) = &mut job.full else { return false };
        // A row's first byte in the RGBA image.
        let row = |y: u32| (y * width * 4) as usize;
        let by_workers = match &self.pool {
            Some(pool) => {
                for band in pool.bands().into_iter().filter(|band| band.job == job.number) {
                    let start = row(band.first);
                    full.image.as_mut()[start..start + band.rgba.len()].copy_from_slice(&band.rgba);
                    full.received += band.rgba.len() as u32 / row(1).max(1) as u32;
                    full.arrived = full.arrived.max(Some(band.arrived));
                }
                if let Some(error) = pool.failed() {
                    // Traced on this thread instead, from the top.
                    log::warn!("the tracer workers failed ({error}); tracing on the page's thread");
                    self.pool = None;
                    (full.received, full.next) = (0, 0);
                }
                self.pool.is_some()
            }
            None => {
                let next = (full.next + 4).min(height);
                let rows = job.tracer.with_dependent(|_, tracer| tracer.render_rows(full.next..next).0);
                let rows = encode_image(width, next - full.next, &rows, transform);
                full.image.as_mut()[row(full.next)..row(next)].copy_from_slice(&rows);
                full.received += next - full.next;
                full.next = next;
                false
            }
        };
        if full.received >= height {
            let image = std::mem::take(&mut full.image);
            // In the page's console, where web/test.sh reads it. With workers, also when their
            // last band reached the page: the rest is the wait for the page's next frame (on a
            // page drawn on the CPU, as long as the browser takes to draw the last one).
            let by = match full.arrived.filter(|_| by_workers) {
                Some(at) => format!("workers; every row in at {:.2} s", (at - job.started).as_secs_f64()),
                None => "the page's thread".to_string(),
            };
            log::info!("traced {width}×{height} in {:.2} s ({by})", job.started.elapsed().as_secs_f64());
            self.updates.push(Update::Traced(frame(job.key, image.clone(), 1, job.started)));
            self.finished = Some((job.key, image));
            self.job = None;
        } else if job.shown.elapsed() >= if by_workers { SHOW_WORKERS } else { SHOW_EVERY } {
            // The rows traced so far over the last progressive level.
            self.updates.push(Update::Traced(frame(job.key, full.image.clone(), full.below, job.started)));
            job.shown = Instant::now();
        }
        by_workers
    }
}

fn frame(key: u64, image: RgbaImage, block: u32, started: Instant) -> TracedFrame {
    TracedFrame { key, image, block, complete: block == 1, elapsed: started.elapsed() }
}
