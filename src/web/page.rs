//! The page around the canvas (web/index.html): what its script may call — hand over files,
//! queue steps, list the built-in scenes — and what Mirador tells it: errors and screenshots.
//!
//! The script's calls are the viewer's scripted steps (`crate::viewer::script`): the page's scene
//! menu and file picker send `load PATH`, its test sends `set …` and `screenshot NAME`. They are
//! queued here and run one a frame, as `--step` runs them natively.

use std::cell::RefCell;
use std::collections::VecDeque;
use std::path::Path;

use wasm_bindgen::prelude::*;
use winit::event_loop::EventLoopProxy;

use super::Wake;
use crate::viewer::script::{self, Step};

thread_local! {
    static PROXY: RefCell<Option<EventLoopProxy<Wake>>> = const { RefCell::new(None) };
    static STEPS: RefCell<VecDeque<Step>> = const { RefCell::new(VecDeque::new()) };
    /// The 3D view's rectangle in the canvas at the last frame: `x, y, width, height` pixels.
    static VIEW: RefCell<Option<[u32; 4]>> = const { RefCell::new(None) };
    /// The lab the page's menu asked for, until the next frame opens it.
    static LAB_ASKED: RefCell<Option<String>> = const { RefCell::new(None) };
    /// A text for the open lab's editor, from the page, until the next frame takes it.
    static LAB_TEXT: RefCell<Option<String>> = const { RefCell::new(None) };
    /// The open lab's file name and text at the last frame, for the download.
    static LAB_FILE: RefCell<Option<(String, String)>> = const { RefCell::new(None) };
    /// The last finished check's `results.json`, for the download.
    static LAB_RESULTS: RefCell<Option<String>> = const { RefCell::new(None) };
}

pub(super) fn set_proxy(proxy: EventLoopProxy<Wake>) {
    PROXY.with(|p| *p.borrow_mut() = Some(proxy));
}

pub(super) fn wake(wake: Wake) {
    PROXY.with(|p| {
        if let Some(proxy) = p.borrow().as_ref() {
            let _ = proxy.send_event(wake);
        }
    });
}

pub(super) fn take_steps() -> Vec<Step> {
    STEPS.with(|s| s.borrow_mut().drain(..).collect())
}

/// Adds a file the person opened (picked or dropped) under `opened/NAME`, where scenes that name
/// it by a relative path find it when they are opened from the same folder.
#[wasm_bindgen]
pub fn add_file(name: &str, bytes: Vec<u8>) {
    crate::files::add(&Path::new("opened").join(name), bytes);
}

/// The files the page fetches when it starts (`files::FETCHED`), by their paths relative to the
/// page (web/files.js).
#[wasm_bindgen]
pub fn fetched_files() -> Vec<String> {
    crate::files::FETCHED.iter().map(|path| path.to_string()).collect()
}

/// Adds a file the page fetched (web/files.js) at its own path, `assets/volumes/phantom.nrrd`.
#[wasm_bindgen]
pub fn add_asset(path: &str, bytes: Vec<u8>) {
    crate::files::add(Path::new(path), bytes);
}

/// Queues one scripted step (`load opened/scene.toml`, `set shadows.enabled=false`, `view split`,
/// `screenshot NAME`); an error names what is wrong with it.
#[wasm_bindgen]
pub fn step(line: &str) -> Result<(), JsError> {
    let step = script::parse(line).map_err(|e| JsError::new(&e.to_string()))?;
    STEPS.with(|s| s.borrow_mut().push_back(step));
    wake(Wake::Steps);
    Ok(())
}

/// Whether the page's address asks for WebGL2 even where WebGPU is offered (`?webgl2`): how a
/// teacher sees what students without WebGPU get, and how web/test.sh tries both.
pub(super) fn asks_for_webgl2() -> bool {
    let search = web_sys::window().and_then(|w| w.location().search().ok()).unwrap_or_default();
    search.trim_start_matches('?').split('&').any(|p| p == "webgl2")
}

/// The built-in labs' names, for the page's lab menu.
#[wasm_bindgen]
pub fn labs() -> Vec<String> {
    crate::lab::catalog().into_iter().map(|lab| lab.name).collect()
}

/// Opens the built-in lab `name` at the next frame: its scene, and an editor with its stub.
#[wasm_bindgen]
pub fn open_lab(name: &str) {
    LAB_ASKED.with(|l| *l.borrow_mut() = Some(name.to_owned()));
    wake(Wake::Steps);
}

/// The open lab's file as the editor holds it, `[name, text]`, for the page's download button;
/// empty when no lab is open.
#[wasm_bindgen]
pub fn lab_file() -> Vec<String> {
    LAB_FILE.with(|f| f.borrow().clone().map(|(name, text)| vec![name, text]).unwrap_or_default())
}

/// Replaces the open lab's text (the page's "open my file": a file saved from an earlier
/// visit), checked and drawn as an edit is.
#[wasm_bindgen]
pub fn set_lab_text(text: String) {
    LAB_TEXT.with(|t| *t.borrow_mut() = Some(text));
    wake(Wake::Steps);
}

pub(super) fn take_lab_text() -> Option<String> {
    LAB_TEXT.with(|t| t.borrow_mut().take())
}

pub(super) fn take_lab_asked() -> Option<String> {
    LAB_ASKED.with(|l| l.borrow_mut().take())
}

pub(super) fn remember_lab_file(file: Option<(String, String)>) {
    LAB_FILE.with(|f| *f.borrow_mut() = file);
}

/// The last finished check's `results.json` (Gradescope's format, as `mirador lab check` writes
/// it), for the page's download button; empty before the first check.
#[wasm_bindgen]
pub fn lab_results() -> String {
    LAB_RESULTS.with(|r| r.borrow().clone().unwrap_or_default())
}

/// A check finished: its `results.json` is kept for the download, and handed to the page's
/// `window.miradorLabChecked(json)` if it defines one (web/test.js does).
pub(super) fn lab_checked(json: String) {
    call_page("miradorLabChecked", &[JsValue::from_str(&json)]);
    LAB_RESULTS.with(|r| *r.borrow_mut() = Some(json));
}

/// The built-in scenes' paths, for the page's menu.
#[wasm_bindgen]
pub fn builtin_scenes() -> Vec<String> {
    crate::files::BUILTIN
        .iter()
        .filter(|path| path.starts_with("assets/scenes/") && path.ends_with(".toml"))
        .map(|path| path.to_string())
        .collect()
}

/// The page's canvas, `<canvas id="mirador">`; `None` if it has none (one is appended).
pub(super) fn canvas() -> Option<web_sys::HtmlCanvasElement> {
    let element = web_sys::window()?.document()?.get_element_by_id("mirador")?;
    element.dyn_into().ok()
}

/// Calls the page's `window.NAME(...)`, if it defines one.
fn call_page(name: &str, arguments: &[JsValue]) {
    let Some(window) = web_sys::window() else { return };
    let Ok(function) = js_sys::Reflect::get(&window, &name.into()) else { return };
    let Some(function) = function.dyn_ref::<js_sys::Function>() else { return };
    let arguments: js_sys::Array = arguments.iter().collect();
    if let Err(e) = function.apply(&JsValue::NULL, &arguments) {
        web_sys::console::error_2(&format!("window.{name} failed:").into(), &e);
    }
}

/// Says that the browser took the GPU device away (WebGPU's device lost, src/web/mod.rs; WebGL2's
/// context lost, which the page hears from the canvas): nothing more is drawn, and the page says
/// why it most likely happened and what to ask for instead.
#[wasm_bindgen]
pub fn device_lost(why: &str) {
    show_error(&format!(
        "The browser stopped Mirador's GPU device ({why}). A frame most likely took longer than the browser \
         allows, as it can on a GPU in software (SwiftShader) with a fine volume.step, many rays or a large \
         window: reload the page, and ask for less (a coarser setting, raster.render_scale below 1)."
    ));
}

/// Shows an error on the page (`window.miradorError(message)`) and in the console.
pub(super) fn show_error(message: &str) {
    log::error!("{message}");
    call_page("miradorError", &[message.into()]);
}

/// After each frame: remembers where the 3D view is, for the screenshots' rectangle.
pub(super) fn remember_view(view: Option<(u32, u32, u32, u32)>) {
    VIEW.with(|v| *v.borrow_mut() = view.map(|(x, y, w, h)| [x, y, w, h]));
}

/// Hands a screenshot to the page as PNG bytes: `window.miradorScreenshot(name, png, [x, y,
/// width, height])`, the last the 3D view's rectangle in it.
pub(super) fn screenshot_taken(path: &Path, image: &image::RgbaImage) {
    let mut png = Vec::new();
    let encoded = image.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png);
    if let Err(e) = encoded {
        return show_error(&format!("cannot encode the screenshot: {e}"));
    }
    let view = VIEW.with(|v| *v.borrow()).unwrap_or_default();
    let view: js_sys::Array = view.iter().map(|&n| JsValue::from(n)).collect();
    let bytes = js_sys::Uint8Array::from(png.as_slice());
    call_page("miradorScreenshot", &[path.display().to_string().into(), bytes.into(), view.into()]);
}

/// `log` to the browser's console.
pub(super) struct Console;
pub(super) static CONSOLE: Console = Console;

impl log::Log for Console {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::Level::Info && metadata.target().starts_with("mirador")
            || metadata.level() <= log::Level::Warn
    }

    fn log(&self, record: &log::Record) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let line = format!("{}: {}", record.target(), record.args());
        match record.level() {
            log::Level::Error => web_sys::console::error_1(&line.into()),
            log::Level::Warn => web_sys::console::warn_1(&line.into()),
            _ => web_sys::console::log_1(&line.into()),
        }
    }

    fn flush(&self) {}
}
