//! Web Workers for the page's traced image, one a core (web/tracer.js, `crate::web::tracer`):
//! each is given the job (the scene as the page has it) and then rows of the full image, one band
//! at a time, and posts back their pixels encoded for display (sRGB, 8 bits), as the page shows
//! them. A worker's answer is followed at once by its next band, from the job's queue, in the
//! answer's message handler: the workers never wait for the page's next frame, which on a page
//! drawn on the CPU can take a second. The page's thread assembles the bands between frames; no
//! memory is shared, so the page needs no special headers from its server.
//!
//! The page draws few frames while the workers trace: a frame drawn on the CPU takes the cores
//! they trace on. The handler wakes the page when the job's last band is in (or a worker failed);
//! the progress between is shown once a second ([`super::slices`]).
//!
//! Each job has a number of its own, sent with its bands and returned with them: a request asked
//! again (the traced view left and opened again) is a new job, and a band of the old one, still
//! in flight, is not counted as the new one's.
//!
//! The same workers trace the hybrid's terms of the raster frame ([`Pool::terms`],
//! `crate::raster::traced::TermsRequest`): a terms job (the frame's scene) and bands of each view
//! asked for, answered with the terms' header and numbers. Their own job and tracer in each worker
//! keep them apart from the traced image's; the page wakes when the last band asked for is in.

use std::cell::RefCell;
use std::collections::{HashMap, VecDeque};
use std::rc::Rc;

use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;
use web_time::Instant;

/// The rows a worker traces at a time: small enough to share the image evenly, large enough that
/// messages cost little beside the tracing.
const BAND: u32 = 8;
/// Bands a worker holds at a time: the one it traces and the next, so that it starts the next
/// without waiting for the page's thread to answer. A new job then finds at most this many bands
/// of the old one before its own.
const AHEAD: usize = 2;

/// A band traced: its job's number ([`Pool::job`]), its first row and its pixels (RGBA, 8 bits a
/// channel).
pub(super) struct Band {
    pub job: u64,
    pub first: u32,
    pub rgba: Vec<u8>,
    /// When its message reached the page.
    pub arrived: Instant,
}

/// The hybrid's terms of a band of a view, traced: the key it was asked with ([`Pool::terms`]),
/// and `crate::raster::traced::encode`'s header and numbers.
pub(in crate::viewer) struct TermsAnswer {
    pub key: String,
    pub header: String,
    pub values: Vec<f32>,
}

/// A piece of work for a worker.
enum Work {
    /// Rows `first..end` of the traced image of job number `job`.
    Rows { job: u64, first: u32, end: u32 },
    /// The terms request `request` (JSON), answered with `key`.
    Terms { key: String, request: String },
}

/// What the workers' messages leave for the page's thread.
#[derive(Default)]
struct Inbox {
    bands: Vec<Band>,
    terms: Vec<TermsAnswer>,
    /// The terms asked for and not yet answered.
    terms_left: usize,
    /// A worker's index for each band it may be given now (up to [`AHEAD`] a worker).
    idle: Vec<usize>,
    /// The work not yet given to a worker: the current job's bands, the terms asked for.
    pending: VecDeque<Work>,
    /// The current (or last) job's number, and how many of its bands have not come back (it
    /// stays as it was when the job is cancelled; the next job sets both).
    job: u64,
    left: usize,
    /// A worker's error: the pool is then given up and the page's thread traces.
    failed: Option<String>,
}

pub(in crate::viewer) struct Pool {
    workers: Vec<web_sys::Worker>,
    inbox: Rc<RefCell<Inbox>>,
    /// The opened files every worker has, as they were sent.
    sent: RefCell<HashMap<String, Rc<[u8]>>>,
    /// The terms job every worker has.
    terms_job: RefCell<String>,
    _listeners: Vec<Closure<dyn FnMut(web_sys::MessageEvent)>>,
    _on_error: Closure<dyn FnMut(JsValue)>,
}

impl Pool {
    /// One worker a core (at most 16), or `None` where the browser gives one core or no workers,
    /// or the page's address asks for none (`?workers=0`).
    /// `wake` wakes the page when a job's last band is in, or a worker failed.
    pub fn start(wake: Rc<dyn Fn()>) -> Option<Pool> {
        // The workers load the module the page loaded (web/index.html), from the browser's cache.
        const WORKER: &str = if cfg!(feature = "webgl2") {
            "./tracer.js?module=mirador_webgl2.js"
        } else {
            "./tracer.js?module=mirador.js"
        };
        let window = web_sys::window()?;
        let cores = window.navigator().hardware_concurrency() as usize;
        // `?workers=0`: how a teacher sees the page as a one-core machine shows it, and how
        // web/time.sh times the page's thread against the workers.
        let search = window.location().search().unwrap_or_default();
        if cores < 2 || search.trim_start_matches('?').split('&').any(|p| p == "workers=0") {
            return None;
        }
        let inbox = Rc::new(RefCell::new(Inbox::default()));
        let options = web_sys::WorkerOptions::new();
        options.set_type(web_sys::WorkerType::Module);
        // A worker that cannot start (web/tracer.js missing from the host, a module error) never
        // answers: the page's thread then traces, rather than wait for ever.
        let (shared, woken) = (inbox.clone(), wake.clone());
        let on_error = Closure::<dyn FnMut(JsValue)>::new(move |_| {
            shared.borrow_mut().failed = Some("a tracer worker did not start (web/tracer.js)".into());
            woken();
        });
        let (mut workers, mut listeners) = (Vec::new(), Vec::new());
        for index in 0..cores.min(16) {
            let Ok(worker) = web_sys::Worker::new_with_options(WORKER, &options) else {
                workers.iter().for_each(web_sys::Worker::terminate);
                return None;
            };
            let (shared, answered, woken) = (inbox.clone(), worker.clone(), wake.clone());
            let listener = Closure::<dyn FnMut(web_sys::MessageEvent)>::new(move |event: web_sys::MessageEvent| {
                let mut inbox = shared.borrow_mut();
                let done = match answer(&event.data()) {
                    Ok(Answer::Band(band)) => {
                        let last = band.job == inbox.job && inbox.left == 1;
                        if band.job == inbox.job {
                            inbox.left = inbox.left.saturating_sub(1);
                        }
                        inbox.bands.push(band);
                        last
                    }
                    Ok(Answer::Terms(terms)) => {
                        inbox.terms.push(terms);
                        inbox.terms_left = inbox.terms_left.saturating_sub(1);
                        inbox.terms_left == 0
                    }
                    Err(error) => {
                        inbox.failed = Some(error);
                        true
                    }
                };
                match inbox.pending.pop_front() {
                    Some(work) => ask(&answered, work),
                    None => inbox.idle.push(index),
                }
                drop(inbox);
                if done {
                    woken();
                }
            });
            worker.set_onmessage(Some(listener.as_ref().unchecked_ref()));
            worker.set_onerror(Some(on_error.as_ref().unchecked_ref()));
            inbox.borrow_mut().idle.extend([index; AHEAD]);
            workers.push(worker);
            listeners.push(listener);
        }
        Some(Pool {
            workers,
            inbox,
            sent: RefCell::default(),
            terms_job: RefCell::default(),
            _listeners: listeners,
            _on_error: on_error,
        })
    }

    /// Gives every worker the job (JSON of [`super::SceneRecipe`]) and the files the person
    /// opened that it has not been given yet (the same bytes are sent once, not with every
    /// request), then the image's `height` rows in bands: as many as the workers may hold now, the
    /// rest as they answer. The previous job's bands not yet given are dropped. Returns the job's
    /// number, which its [`Band`]s carry.
    pub fn job(&self, job: &str, files: &[(String, Rc<[u8]>)], height: u32) -> u64 {
        let list = self.new_files(files);
        let mut inbox = self.inbox.borrow_mut();
        let number = inbox.job + 1;
        for worker in &self.workers {
            let message = message(&number.to_string());
            set(&message, "job", &job.into());
            set(&message, "files", &list);
            let _ = worker.post_message(&message);
        }
        inbox.pending.retain(|work| matches!(work, Work::Terms { .. }));
        let rows = (0..height).step_by(BAND as usize).map(|first| (first, (first + BAND).min(height)));
        inbox.pending.extend(rows.map(|(first, end)| Work::Rows { job: number, first, end }));
        (inbox.job, inbox.left) = (number, height.div_ceil(BAND) as usize);
        self.give_out(&mut inbox);
        number
    }

    /// Asks for the hybrid's terms of `requests` (each its key and JSON), with `job` (JSON of
    /// [`super::SceneRecipe`], the raster frame's scene) and the files the person opened. Terms
    /// asked for before and not yet given out are dropped: they were for older inputs.
    pub fn terms(&self, job: &str, files: &[(String, Rc<[u8]>)], requests: Vec<(String, String)>) {
        let list = self.new_files(files);
        if *self.terms_job.borrow() != job || list.length() > 0 {
            for worker in &self.workers {
                let message = message("terms");
                set(&message, "termsJob", &job.into());
                set(&message, "files", &list);
                let _ = worker.post_message(&message);
            }
            *self.terms_job.borrow_mut() = job.to_owned();
        }
        let mut inbox = self.inbox.borrow_mut();
        inbox.pending.retain(|work| matches!(work, Work::Rows { .. }));
        inbox.terms_left = requests.len();
        inbox.pending.extend(requests.into_iter().map(|(key, request)| Work::Terms { key, request }));
        self.give_out(&mut inbox);
    }

    /// The opened files not sent to the workers yet (the same bytes are sent once), as a list of
    /// `[name, bytes]`; marked sent.
    fn new_files(&self, files: &[(String, Rc<[u8]>)]) -> js_sys::Array {
        let list = js_sys::Array::new();
        let mut sent = self.sent.borrow_mut();
        for (name, bytes) in files {
            if sent.get(name).is_some_and(|s| Rc::ptr_eq(s, bytes)) {
                continue;
            }
            list.push(&js_sys::Array::of2(&name.into(), &js_sys::Uint8Array::from(&bytes[..])));
            sent.insert(name.clone(), bytes.clone());
        }
        list
    }

    /// Gives pending work to the workers that may take some.
    fn give_out(&self, inbox: &mut Inbox) {
        while let Some(index) = inbox.idle.pop() {
            let Some(work) = inbox.pending.pop_front() else {
                inbox.idle.push(index);
                break;
            };
            ask(&self.workers[index], work);
        }
    }

    /// Drops the bands not yet given: the job was stopped or replaced. The workers finish only
    /// the ones they hold.
    pub fn cancel(&self) {
        self.inbox.borrow_mut().pending.retain(|work| matches!(work, Work::Terms { .. }));
    }

    /// The hybrid's terms that came back since the last call.
    pub fn terms_answers(&self) -> Vec<TermsAnswer> {
        std::mem::take(&mut self.inbox.borrow_mut().terms)
    }

    /// The bands that came back since the last call.
    pub(super) fn bands(&self) -> Vec<Band> {
        std::mem::take(&mut self.inbox.borrow_mut().bands)
    }

    /// Why a worker failed, if one did.
    pub fn failed(&self) -> Option<String> {
        self.inbox.borrow_mut().failed.take()
    }
}

impl Drop for Pool {
    fn drop(&mut self) {
        for worker in &self.workers {
            worker.terminate();
        }
    }
}

/// Gives `worker` a piece of work.
fn ask(worker: &web_sys::Worker, work: Work) {
    let message = match work {
        Work::Rows { job, first, end } => {
            let message = message(&job.to_string());
            set(&message, "rows", &js_sys::Array::of2(&first.into(), &end.into()));
            message
        }
        Work::Terms { key, request } => {
            let message = message(&key);
            set(&message, "terms", &request.into());
            message
        }
    };
    let _ = worker.post_message(&message);
}

/// A message with `key`, which the worker returns with its answer (as text: a u64 does not fit a
/// JavaScript number).
fn message(key: &str) -> js_sys::Object {
    let message = js_sys::Object::new();
    set(&message, "key", &key.into());
    message
}

fn set(object: &js_sys::Object, name: &str, value: &JsValue) {
    let _ = js_sys::Reflect::set(object, &name.into(), value);
}

/// A worker's answer.
enum Answer {
    Band(Band),
    Terms(TermsAnswer),
}

/// A worker's answer: `{key, first, pixels}` (a `Uint8Array` of r, g, b, a), `{key, header,
/// values}` (a `Float32Array`), or `{error}`.
fn answer(data: &JsValue) -> Result<Answer, String> {
    let get = |name: &str| js_sys::Reflect::get(data, &name.into()).unwrap_or(JsValue::UNDEFINED);
    if let Some(error) = get("error").as_string() {
        return Err(error);
    }
    if let Some(header) = get("header").as_string() {
        let key = get("key").as_string().ok_or("terms without their key")?;
        let values = js_sys::Float32Array::new(&get("values")).to_vec();
        return Ok(Answer::Terms(TermsAnswer { key, header, values }));
    }
    let job = get("key").as_string().and_then(|k| k.parse().ok()).ok_or("a band without its job's number")?;
    let first = get("first").as_f64().ok_or("a band without its first row")? as u32;
    let rgba = js_sys::Uint8Array::new(&get("pixels")).to_vec();
    Ok(Answer::Band(Band { job, first, rgba, arrived: Instant::now() }))
}
