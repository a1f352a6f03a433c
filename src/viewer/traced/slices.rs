//! The traced image in the browser, which gives a page one thread: the worker's work done in
//! slices of [`SLICE`] between frames, on the page's thread. The progressive levels come first,
//! one level a slice; then the full image a few rows at a time ([`Tracer::render_rows`], the rows
//! `Tracer::render` would trace), shown as it goes over the last progressive level. The window asks
//! for the next frame while [`TracedWorker::busy`].

use std::time::Duration;

use glam::Vec3;
use image::RgbaImage;
use web_time::Instant;

use super::{DifferenceFrame, LAST_BLOCK, START_BLOCK, TracedFrame, Update, compare_ready};
use crate::output::OutputTransform;
use crate::trace::{Progressive, RadianceImage, Tracer};
use crate::{RenderSettings, Scene};

/// How long one frame lends the tracer: a page at 60 Hz has 16 ms a frame, so this keeps the page
/// answering at about 20 frames a second while the tracer works.
const SLICE: Duration = Duration::from_millis(30);
/// How often the image in progress is shown while the full image is traced.
const SHOW_EVERY: Duration = Duration::from_millis(300);

self_cell::self_cell!(
    /// A tracer and the scene and settings it reads, kept together between slices.
    struct OwnedTracer {
        owner: Box<(Scene, RenderSettings)>,
        #[covariant]
        dependent: Tracer,
    }
);

/// The request being traced.
struct Job {
    key: u64,
    tracer: OwnedTracer,
    progressive: Progressive,
    /// The full image's rows traced so far (`None` while progressive levels remain).
    rows: Option<Vec<Vec3>>,
    started: Instant,
    shown: Instant,
}

/// The window's handle on the tracer: the same calls as the native worker thread's.
pub struct TracedWorker {
    job: Option<Job>,
    updates: Vec<Update>,
    compared: Option<u64>,
    raster: Option<(u64, RgbaImage)>,
    finished: Option<(u64, RgbaImage)>,
}

impl TracedWorker {
    /// Nothing runs beside the page: `wake` is not needed, frames are asked for while
    /// [`TracedWorker::busy`].
    pub fn start(_wake: impl Fn() + Send + 'static) -> TracedWorker {
        TracedWorker { job: None, updates: Vec::new(), compared: None, raster: None, finished: None }
    }

    /// Makes sure request `key` is being traced: a new key drops the previous request.
    pub fn trace(&mut self, key: u64, scene: &Scene, settings: &RenderSettings) {
        if self.job.as_ref().is_some_and(|job| job.key == key) || self.finished.as_ref().is_some_and(|(k, _)| *k == key)
        {
            return;
        }
        let tracer =
            OwnedTracer::new(Box::new((scene.clone(), settings.clone())), |owned| Tracer::new(&owned.0, &owned.1));
        let progressive = tracer.with_dependent(|_, tracer| Progressive::new(tracer, START_BLOCK));
        let now = Instant::now();
        self.job = Some(Job { key, tracer, progressive, rows: None, started: now, shown: now });
    }

    /// Stops the current request (the view no longer shows traced images).
    pub fn stop(&mut self) {
        self.job = None;
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

    /// Whether work is left: the window asks for the next frame at once.
    pub fn busy(&self) -> bool {
        let comparable = matches!((&self.raster, &self.finished), (Some((a, _)), Some((b, _))) if a == b);
        self.job.is_some() || comparable
    }

    /// Works for one slice, then returns the newest traced image and difference made since the
    /// last call.
    pub fn poll(&mut self) -> (Option<TracedFrame>, Option<DifferenceFrame>) {
        let deadline = Instant::now() + SLICE;
        while Instant::now() < deadline && self.job.is_some() {
            self.work();
        }
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

    /// One step of the current job: a progressive level, or a few rows of the full image.
    fn work(&mut self) {
        let Some(job) = &mut self.job else { return };
        let transform = OutputTransform::of(&job.tracer.borrow_owner().1);
        let (width, height) = (job.progressive.image().width, job.progressive.image().height);
        let Some(rows) = &mut job.rows else {
            let progressive = &mut job.progressive;
            let block = job.tracer.with_dependent(|_, tracer| progressive.refine(tracer)).unwrap_or(1);
            let image = progressive.image().to_rgba8(transform);
            self.updates.push(Update::Traced(frame(job.key, image, block, job.started)));
            if block <= LAST_BLOCK {
                job.rows = Some(Vec::with_capacity((width * height) as usize));
            }
            return;
        };
        let done = rows.len() as u32 / width.max(1);
        let next = (done + 4).min(height);
        rows.extend(job.tracer.with_dependent(|_, tracer| tracer.render_rows(done..next).0));
        if next == height {
            let radiance = RadianceImage { width, height, pixels: std::mem::take(rows) };
            let image = radiance.to_rgba8(transform);
            // In the page's console, where web/test.sh reads it.
            log::info!("traced {width}×{height} in {:.2} s", job.started.elapsed().as_secs_f64());
            self.updates.push(Update::Traced(frame(job.key, image.clone(), 1, job.started)));
            self.finished = Some((job.key, image));
            self.job = None;
        } else if job.shown.elapsed() >= SHOW_EVERY {
            // The rows traced so far over the last progressive level.
            let mut pixels = job.progressive.image().pixels.clone();
            pixels[..rows.len()].copy_from_slice(rows);
            let image = RadianceImage { width, height, pixels }.to_rgba8(transform);
            self.updates.push(Update::Traced(frame(job.key, image, LAST_BLOCK, job.started)));
            job.shown = Instant::now();
        }
    }
}

fn frame(key: u64, image: RgbaImage, block: u32, started: Instant) -> TracedFrame {
    TracedFrame { key, image, block, complete: block == 1, elapsed: started.elapsed() }
}
