//! The page's hybrid: the raster frame's traced terms at every pixel traced by the tracer's Web
//! Workers (`crate::viewer::traced::Pool`), so that the page's thread only draws and uploads.
//! A new image's terms are traced coarse here (one pixel in 16, quick), then the frame asks for
//! every view it draws at the full stride (`TracedAt::Elsewhere`): each view is cut into bands
//! of rows, one a worker at a time, and once a view's bands are all back they are joined and
//! handed to the renderer, which draws them at the next frame. Where there are no workers, or they
//! fail, the page's thread refines the terms itself, as natively.

use std::collections::HashMap;

use web_time::Instant;

use crate::gpu::Gpu;
use crate::raster::traced;
use crate::trace::terms::TracedTerms;
use crate::viewer::traced::{Pool, SceneRecipe};

/// Rows in a band of a view's terms: a few tens of milliseconds of a worker's time on the
/// showcase, so that the workers share a view evenly.
const BAND_ROWS: u32 = 16;

/// The views asked of the workers: per view (its ticket and number), the terms of each of its
/// bands, as they come back.
#[derive(Default)]
pub(super) struct TermsInWorkers {
    views: HashMap<(u64, usize), Vec<Option<TracedTerms>>>,
    /// When the views were asked for, and how many.
    asked: Option<(Instant, usize)>,
}

impl super::RasterView {
    /// Before a frame: whether the workers trace the terms at every pixel (`pool`; `None`: this
    /// thread does), and the terms they traced since the last frame, handed to the renderer (the
    /// frame then draws them).
    pub(in crate::viewer) fn take_terms(&mut self, gpu: &Gpu, pool: Option<&Pool>) {
        if self.elsewhere && pool.is_none() && self.renderer.traced.awaiting() {
            // Traced here at the next frame.
            self.terms_arrived = true;
        }
        self.elsewhere = pool.is_some();
        let Some(pool) = pool else { return };
        for answer in pool.terms_answers() {
            let Some((view, band)) = key_of(&answer.key) else { continue };
            let Some(bands) = self.terms.views.get_mut(&view).filter(|bands| band < bands.len()) else { continue };
            match traced::decode(&answer.header, &answer.values) {
                Ok(terms) => bands[band] = Some(terms),
                Err(error) => log::warn!("a worker's traced terms: {error}"),
            }
            if bands.iter().all(Option::is_some) {
                let bands = self.terms.views.remove(&view).unwrap_or_default().into_iter().flatten().collect();
                match traced::join(bands) {
                    Ok(terms) => self.terms_arrived |= self.renderer.traced.receive(&gpu.device, view, &terms),
                    Err(error) => log::warn!("a worker's traced terms: {error}"),
                }
            }
        }
        if let Some((at, views)) = self.terms.asked.filter(|_| !self.renderer.traced.awaiting()) {
            log::info!(
                "the hybrid's terms of {views} views traced by the workers in {:.2} s",
                at.elapsed().as_secs_f32()
            );
            self.terms.asked = None;
        }
    }

    /// After a frame: the views it asked for, in bands, to the workers, with `job`, the scene the
    /// frame drew (made only when a view was asked for).
    pub(in crate::viewer) fn give_terms(&mut self, pool: &Pool, job: impl FnOnce() -> SceneRecipe) {
        let requests = self.renderer.traced.take_requests();
        let Some(ticket) = requests.first().map(|r| r.ticket) else { return };
        self.terms.views.retain(|(t, _), _| *t == ticket);
        let mut asked = Vec::new();
        self.terms.asked = Some((Instant::now(), requests.len()));
        for request in requests {
            let bands = request.bands(BAND_ROWS);
            self.terms.views.insert((request.ticket, request.view), bands.iter().map(|_| None).collect());
            for (k, band) in bands.iter().enumerate() {
                let text = serde_json::to_string(band).expect("a request is plain data");
                asked.push((format!("{}:{}:{k}", request.ticket, request.view), text));
            }
        }
        let job = serde_json::to_string(&job()).expect("a recipe is plain data");
        pool.terms(&job, &crate::files::opened(), asked);
    }
}

/// The view (ticket and number) and band of an answer's key.
fn key_of(key: &str) -> Option<((u64, usize), usize)> {
    let mut parts = key.split(':');
    let ticket = parts.next()?.parse().ok()?;
    let view = parts.next()?.parse().ok()?;
    let band = parts.next()?.parse().ok()?;
    Some(((ticket, view), band))
}
