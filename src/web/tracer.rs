//! The page's tracer workers: the same module as the page, run in Web Workers (web/tracer.js), one
//! a core, each tracing the rows of the full image it is asked for
//! (`crate::viewer::traced::pool` hands them out). A worker has no window and no share of the
//! page's memory, so it rebuilds the scene: it reads the same scene file (the built-in assets are
//! in the module; the files the person opened come with the job) with the same overrides, then
//! takes what the viewer changes in place: the camera, the lights, the materials and the
//! settings. The rows it returns are the ones `Tracer::render_rows` returns on the page's thread,
//! encoded as the page would encode them, to the bit (web/test.sh checks the finished image
//! against `mirador trace`).
//!
//! The workers also trace the hybrid's terms of the page's raster frame
//! (`crate::raster::traced::TermsRequest`), with a tracer of their own for them: the frame's
//! scene, and its settings with what the traced terms replace left out, as the frame's own
//! tracer has them.

use std::cell::RefCell;

use wasm_bindgen::prelude::*;

use crate::output::{OutputTransform, encode_image};
use crate::raster::traced::{TermsRequest, encode};
use crate::trace::Tracer;
use crate::viewer::traced::{OwnedTracer, SceneRecipe};

thread_local! {
    static TRACER: RefCell<Option<OwnedTracer>> = const { RefCell::new(None) };
    static TERMS_TRACER: RefCell<Option<OwnedTracer>> = const { RefCell::new(None) };
}

/// Rebuilds the scene of `job` (JSON of [`SceneRecipe`]) and a tracer of it, for the rows asked
/// next.
#[wasm_bindgen]
pub fn tracer_job(job: &str) -> Result<(), JsError> {
    // A job that fails leaves no tracer of the last one to trace its rows.
    TRACER.with(|t| *t.borrow_mut() = None);
    let job: SceneRecipe = serde_json::from_str(job).map_err(|e| JsError::new(&format!("a tracer job: {e}")))?;
    let owned = job.scene().map_err(|e| JsError::new(&e))?;
    let tracer = OwnedTracer::new(Box::new(owned), |owned| Tracer::new(&owned.0, &owned.1));
    TRACER.with(|t| *t.borrow_mut() = Some(tracer));
    Ok(())
}

/// Rows `first..end` of the full image as the page shows them: RGBA, 8 bits a channel, row by
/// row, through the job's exposure, tone curve and sRGB encoding (here, so that the page's thread
/// only copies them).
#[wasm_bindgen]
pub fn trace_rows(first: u32, end: u32) -> Result<Vec<u8>, JsError> {
    TRACER.with(|t| {
        let tracer = t.borrow();
        let tracer = tracer.as_ref().ok_or_else(|| JsError::new("rows asked before a tracer job"))?;
        let transform = OutputTransform::of(&tracer.borrow_owner().1);
        let (rows, _) = tracer.with_dependent(|_, tracer| tracer.render_rows(first..end));
        let height = end.saturating_sub(first);
        let width = rows.len() as u32 / height.max(1);
        Ok(encode_image(width, height, &rows, transform).into_raw())
    })
}

/// Rebuilds the scene of `job` (JSON of [`SceneRecipe`]: the page's raster frame's) and a tracer
/// of it for the hybrid's terms asked next.
#[wasm_bindgen]
pub fn terms_job(job: &str) -> Result<(), JsError> {
    TERMS_TRACER.with(|t| *t.borrow_mut() = None);
    let job: SceneRecipe = serde_json::from_str(job).map_err(|e| JsError::new(&format!("a terms job: {e}")))?;
    let (scene, settings) = job.scene().map_err(|e| JsError::new(&e))?;
    let settings = settings.hybrid.raster_settings(&settings).unwrap_or(settings);
    let tracer = OwnedTracer::new(Box::new((scene, settings)), |owned| Tracer::new(&owned.0, &owned.1));
    TERMS_TRACER.with(|t| *t.borrow_mut() = Some(tracer));
    Ok(())
}

/// The hybrid's terms of `request` (JSON of [`TermsRequest`]), as `[header, numbers]`
/// ([`crate::raster::traced::encode`]): a string and a `Float32Array`.
#[wasm_bindgen]
pub fn trace_terms(request: &str) -> Result<js_sys::Array, JsError> {
    let request: TermsRequest =
        serde_json::from_str(request).map_err(|e| JsError::new(&format!("a terms request: {e}")))?;
    TERMS_TRACER.with(|t| {
        let tracer = t.borrow();
        let tracer = tracer.as_ref().ok_or_else(|| JsError::new("terms asked before a terms job"))?;
        // The page asks for no view with an empty window.
        let terms = tracer
            .with_dependent(|_, tracer| request.trace(tracer))
            .ok_or_else(|| JsError::new("terms asked for an empty window"))?;
        let (header, values) = encode(&terms);
        Ok(js_sys::Array::of2(&header.into(), &js_sys::Float32Array::from(&values[..])))
    })
}
