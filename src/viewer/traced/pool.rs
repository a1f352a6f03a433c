//! Web Workers for the page's traced image, one a core (web/tracer.js, `crate::web::tracer`):
//! each is given the job (the scene as the page has it) and then rows of the full image, one band
//! at a time, and posts back their radiance. The page's thread hands out bands and assembles them
//! between frames; no memory is shared, so the page needs no special headers from its server.

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

use glam::Vec3;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

/// The rows a worker traces at a time: small enough to share the image evenly, large enough that
/// messages cost little beside the tracing.
pub(super) const BAND: u32 = 8;
/// Bands a worker is given ahead: the page hands them out between frames, and a frame of the page
/// can take longer than a band, so each worker has the next ones queued.
const AHEAD: usize = 4;

/// A band traced: the job's key, its first row and its pixels.
pub(super) struct Band {
    pub key: u64,
    pub first: u32,
    pub pixels: Vec<Vec3>,
}

/// What the workers' messages leave for the page's thread.
#[derive(Default)]
struct Inbox {
    bands: Vec<Band>,
    /// A worker's index for each band it may be given now (up to [`AHEAD`] a worker).
    idle: Vec<usize>,
    /// A worker's error: the pool is then given up and the page's thread traces.
    failed: Option<String>,
}

pub(super) struct Pool {
    workers: Vec<web_sys::Worker>,
    inbox: Rc<RefCell<Inbox>>,
    /// The opened files every worker has, as they were sent.
    sent: RefCell<HashMap<String, Rc<[u8]>>>,
    _listeners: Vec<Closure<dyn FnMut(web_sys::MessageEvent)>>,
    _on_error: Closure<dyn FnMut(JsValue)>,
}

impl Pool {
    /// One worker a core (at most 16), or `None` where the browser gives one core or no workers.
    pub fn start() -> Option<Pool> {
        // The workers load the module the page loaded (web/index.html), from the browser's cache.
        const WORKER: &str = if cfg!(feature = "webgl2") {
            "./tracer.js?module=mirador_webgl2.js"
        } else {
            "./tracer.js?module=mirador.js"
        };
        let cores = web_sys::window()?.navigator().hardware_concurrency() as usize;
        if cores < 2 {
            return None;
        }
        let inbox = Rc::new(RefCell::new(Inbox::default()));
        let options = web_sys::WorkerOptions::new();
        options.set_type(web_sys::WorkerType::Module);
        // A worker that cannot start (web/tracer.js missing from the host, a module error) never
        // answers: the page's thread then traces, rather than wait for ever.
        let shared = inbox.clone();
        let on_error = Closure::<dyn FnMut(JsValue)>::new(move |_| {
            shared.borrow_mut().failed = Some("a tracer worker did not start (web/tracer.js)".into());
        });
        let (mut workers, mut listeners) = (Vec::new(), Vec::new());
        for index in 0..cores.min(16) {
            let worker = web_sys::Worker::new_with_options(WORKER, &options).ok()?;
            let shared = inbox.clone();
            let listener = Closure::<dyn FnMut(web_sys::MessageEvent)>::new(move |event: web_sys::MessageEvent| {
                let mut inbox = shared.borrow_mut();
                match band(&event.data()) {
                    Ok(band) => inbox.bands.push(band),
                    Err(error) => inbox.failed = Some(error),
                }
                inbox.idle.push(index);
            });
            worker.set_onmessage(Some(listener.as_ref().unchecked_ref()));
            worker.set_onerror(Some(on_error.as_ref().unchecked_ref()));
            inbox.borrow_mut().idle.extend([index; AHEAD]);
            workers.push(worker);
            listeners.push(listener);
        }
        Some(Pool { workers, inbox, sent: RefCell::default(), _listeners: listeners, _on_error: on_error })
    }

    /// Gives every worker the job `key` (JSON of [`super::SceneRecipe`]) and the files the
    /// person opened that it has not been given yet (the same bytes are sent once, not with every
    /// request); the bands asked for next are of this job.
    pub fn job(&self, key: u64, job: &str, files: &[(String, Rc<[u8]>)]) {
        let list = js_sys::Array::new();
        let mut sent = self.sent.borrow_mut();
        for (name, bytes) in files {
            if sent.get(name).is_some_and(|s| Rc::ptr_eq(s, bytes)) {
                continue;
            }
            list.push(&js_sys::Array::of2(&name.into(), &js_sys::Uint8Array::from(&bytes[..])));
            sent.insert(name.clone(), bytes.clone());
        }
        for worker in &self.workers {
            let message = message(key);
            set(&message, "job", &job.into());
            set(&message, "files", &list);
            let _ = worker.post_message(&message);
        }
    }

    /// Asks an idle worker, if there is one, for rows `first..end` of job `key`.
    pub fn ask(&self, key: u64, first: u32, end: u32) -> bool {
        let Some(index) = self.inbox.borrow_mut().idle.pop() else { return false };
        let message = message(key);
        set(&message, "rows", &js_sys::Array::of2(&first.into(), &end.into()));
        let _ = self.workers[index].post_message(&message);
        true
    }

    /// The bands that came back since the last call.
    pub fn bands(&self) -> Vec<Band> {
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

fn message(key: u64) -> js_sys::Object {
    let message = js_sys::Object::new();
    // As text: a u64 does not fit a JavaScript number.
    set(&message, "key", &key.to_string().into());
    message
}

fn set(object: &js_sys::Object, name: &str, value: &JsValue) {
    let _ = js_sys::Reflect::set(object, &name.into(), value);
}

/// A worker's answer: `{key, first, pixels}` (a `Float32Array` of r, g, b), or `{error}`.
fn band(data: &JsValue) -> Result<Band, String> {
    let get = |name: &str| js_sys::Reflect::get(data, &name.into()).unwrap_or(JsValue::UNDEFINED);
    if let Some(error) = get("error").as_string() {
        return Err(error);
    }
    let key = get("key").as_string().and_then(|k| k.parse().ok()).ok_or("a band without its job's key")?;
    let first = get("first").as_f64().ok_or("a band without its first row")? as u32;
    let pixels = js_sys::Float32Array::new(&get("pixels")).to_vec();
    let pixels = pixels.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
    Ok(Band { key, first, pixels })
}
