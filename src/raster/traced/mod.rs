//! The hybrid's traced terms in the raster frame (docs/course/12-error-budget.md): for every view
//! of the frame (the main camera, each mirrored camera, each cube face due), the ray tracer
//! computes the terms `settings.hybrid` asks for at each pixel's first opaque surface
//! (`crate::trace::terms`), and the view's phases read them from its traced image
//! (`ViewImage::Traced`) in place of the rasterizer's approximations: shadow rays for shadow maps
//! and projected polygons, the traced `L(r)` for mirrored cameras and environment maps, the
//! traced transmission for sorted blending and refraction, the ray cone's filtering for trilinear
//! filtering. `mirador budget` swaps them one at a time.
//!
//! A view's rays are its own camera's: the scene camera's primary rays for the main view (the
//! tracer's own, so the two agree to the bit), and for the other views the ray through each
//! pixel unprojected from the view's `clip_from_world`, starting on its clip plane (a mirrored
//! camera sees only what lies beyond its mirror) and passing the object it looks out of. Each view
//! is traced into a buffer before the frame is recorded, and copied into its image just before
//! the view draws: the cube faces share one set of targets, so a copy made earlier would be
//! overwritten by the next face's. A view drawn again as the last frame drew it, with nothing else
//! changed, draws the terms it was traced with then ([`KeptTraced`]): where its image is its own
//! (the main view's, a mirrored camera's), the image still holds them and nothing is copied;
//! where views share an image (the cube faces), they are copied again from the buffer kept.

mod request;
mod upload;

pub use request::{TermsRequest, decode, encode, join};
use upload::{SpareBuffers, Upload};

use super::context::{Figure, FrameEncoder};
use super::shadow::views::{MAX_SHADOWED_LIGHTS, ShadowLayout};
use super::targets::{FrameTargets, ViewImage};
use super::view::{FrameView, ViewKind, ViewSlot, ViewTargets};
use crate::scene::{Camera, Scene};
use crate::settings::RenderSettings;
use crate::trace::Tracer;
use crate::trace::terms::{TracedTerms, Wanted};

const _: () = assert!(crate::trace::terms::MAX_SLOTS == MAX_SHADOWED_LIGHTS);

/// The terms `settings` asks to trace, or `None`.
pub fn wanted(settings: &RenderSettings) -> Option<Wanted> {
    Some(settings.hybrid.traced()).filter(|wanted| !wanted.is_empty())
}

/// Every view's traced terms, ready to be copied into its image: each view's buffer holds the
/// layers traced, one after another, each the view's window.
pub struct PreparedTraced {
    views: Vec<(ViewSlot, Upload)>,
}

/// The last frame's terms and what they were traced from, kept for the next frames: while the
/// scene, its camera and lights and the settings are the same, a view drawn again from the same
/// camera at the same size has the same terms, and the frame draws them again rather than
/// tracing them again (as a raster frame keeps its shadow maps). A view that changed, or any
/// change of the scene or the settings, is traced anew: here, or elsewhere ([`TracedAt`]).
#[derive(Default)]
pub struct KeptTraced {
    last: Option<(SceneInputs, Vec<Kept>)>,
    /// Counts the scenes loaded ([`Self::forget`]): a new scene is never the last one.
    generation: u64,
    /// Counts the inputs traced elsewhere: an answer for older inputs is dropped.
    ticket: u64,
    /// The views asked for and not yet taken ([`Self::take_requests`]).
    requests: Vec<TermsRequest>,
    /// Counts the cube faces whose terms were handed back ([`Self::faces_key`]).
    faces_received: u64,
    /// The buffers of terms no frame draws any more, for the next terms.
    spare: SpareBuffers,
}

/// Where a frame's traced terms are traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TracedAt {
    /// Here, before the frame is recorded (on the tracer's threads, where there are some).
    #[default]
    Here,
    /// Elsewhere (the page's Web Workers): a view not kept is asked for ([`TermsRequest`],
    /// [`KeptTraced::take_requests`]) and drawn, until its terms are handed back
    /// ([`KeptTraced::receive`]), with the terms the last frame drew it with (a coarser stride's),
    /// else with terms traced here at one pixel in each block of `coarse` pixels on a side.
    Elsewhere { coarse: u32 },
}

/// A view's terms kept: traced, or (elsewhere) asked for and drawn meanwhile with `upload`.
struct Kept {
    key: ViewInputs,
    upload: Upload,
    /// Asked for elsewhere, under this ticket and number, and not yet handed back.
    asked: Option<(u64, usize)>,
}

/// What every view's traced terms depend on.
#[derive(Clone, PartialEq)]
struct SceneInputs {
    generation: u64,
    camera: Camera,
    lights: Vec<crate::scene::Light>,
    settings: RenderSettings,
    wanted: Wanted,
    stride: u32,
    /// The shadowed lights whose slots the visibility layers follow.
    slots: Vec<usize>,
}

/// What one view's terms depend on besides: its camera and the size it is drawn at.
type ViewInputs = (FrameView, (u32, u32));

impl KeptTraced {
    /// Forgets the kept terms: the renderer loaded another scene.
    pub fn forget(&mut self) {
        self.release();
        self.generation += 1;
    }

    /// Lets go of the kept terms and their buffers: a frame traces none.
    pub fn release(&mut self) {
        self.last = None;
        self.requests.clear();
        self.spare.clear();
    }

    /// The terms `wanted` for every view of `views`, each into a buffer of its image's layers:
    /// the last frame's where nothing they depend on changed, else traced `at` ([`TracedAt`]);
    /// and kept. `lights` are the frame's shadowed lights, whose slots the visibility layers
    /// follow.
    pub fn prepare(
        &mut self,
        (device, scene, settings): (&wgpu::Device, &Scene, &RenderSettings),
        frame: &mut FrameEncoder,
        (wanted, stride, at): (Wanted, u32, TracedAt),
        lights: &ShadowLayout,
        views: &[ViewTargets<'_>],
    ) -> PreparedTraced {
        let slots: Vec<usize> =
            lights.first_layer.iter().enumerate().filter(|(_, l)| l.is_some()).map(|(i, _)| i).collect();
        let slots = slots[..slots.len().min(MAX_SHADOWED_LIGHTS)].to_vec();
        let inputs = SceneInputs {
            generation: self.generation,
            camera: scene.camera.clone(),
            lights: scene.lights.clone(),
            settings: settings.clone(),
            wanted,
            stride,
            slots,
        };
        let (last_inputs, mut last) = self.last.take().unwrap_or_else(|| (inputs.clone(), Vec::new()));
        let same = last_inputs == inputs;
        // Elsewhere, a view's coarser terms stand in while its finer ones are traced.
        let elsewhere = matches!(at, TracedAt::Elsewhere { .. });
        let coarser = elsewhere && last_inputs == SceneInputs { stride: last_inputs.stride, ..inputs.clone() };
        // The buffers of terms no frame will draw again, for the terms traced next.
        let mut spare = std::mem::take(&mut self.spare);
        if !same {
            self.ticket += 1;
            self.requests.clear();
            if !coarser {
                last.drain(..).for_each(|old| spare.give_back(old.upload));
            }
            last.iter_mut().for_each(|kept| kept.asked = None);
        }
        let (mut rays, mut kept, mut asked) = (0, 0, 0);
        let mut now = Vec::new();
        let tracer = std::cell::OnceCell::new();
        let mut trace_here = |request: &TermsRequest| {
            let tracer = tracer.get_or_init(|| Tracer::new(scene, settings));
            let (upload, counts) =
                request.trace_with(tracer, |view, wanted| spare.traced(device, tracer, (view, wanted)))?;
            rays += counts.total();
            Some(upload)
        };
        for &(view, targets) in views {
            let key = (view.clone(), targets.size);
            let found = last.iter().position(|k| k.key == key).map(|i| last.swap_remove(i));
            let entry = match (found, at) {
                // Kept; elsewhere, also while asked for (and drawn with a stand-in).
                (Some(found), _) if same && (found.asked.is_none() || elsewhere) => {
                    kept += 1;
                    Some(found)
                }
                (found, TracedAt::Elsewhere { coarse }) => {
                    let number = (self.ticket, self.requests.len());
                    let request = TermsRequest::new(number, (view, targets.size), &inputs);
                    let stand_in = found.map(|k| k.upload).or_else(|| trace_here(&request.with_stride(coarse)));
                    stand_in.map(|stand_in| {
                        asked += 1;
                        self.requests.push(request);
                        Kept { key: key.clone(), upload: stand_in, asked: Some(number) }
                    })
                }
                (_, TracedAt::Here) => {
                    let request = TermsRequest::new((0, 0), (view, targets.size), &inputs);
                    trace_here(&request).map(|upload| Kept { key: key.clone(), upload, asked: None })
                }
            };
            now.extend(entry);
        }
        let prepared = PreparedTraced::copies(views, &now);
        frame.end(
            "traced terms",
            &[
                ("rays", Figure::Count(rays)),
                ("views kept", Figure::Count(kept)),
                ("views asked", Figure::Count(asked)),
                ("buffers reused", Figure::Count(spare.reused())),
                ("views copied", Figure::Count(prepared.views.len() as u64)),
            ],
        );
        // Views not drawn this frame keep their terms while nothing else changed: a cube's faces
        // are drawn only now and then, and their terms asked for elsewhere come back meanwhile.
        if same {
            now.extend(last);
        } else {
            last.into_iter().for_each(|old| spare.give_back(old.upload));
        }
        self.spare = spare;
        self.last = Some((inputs, now));
        prepared
    }

    /// The views the frames since the last call asked to be traced elsewhere.
    pub fn take_requests(&mut self) -> Vec<TermsRequest> {
        std::mem::take(&mut self.requests)
    }

    /// Whether views asked for elsewhere are still to come back.
    pub fn awaiting(&self) -> bool {
        self.last.as_ref().is_some_and(|(_, views)| views.iter().any(|k| k.asked.is_some()))
    }

    /// Hands back the terms of view `view` of request ticket `ticket`, traced elsewhere
    /// ([`TermsRequest::trace`]): the next frame like the last draws them. Returns whether they
    /// were taken; the terms of a view no longer asked for (the view or its inputs changed since)
    /// are dropped.
    pub fn receive(&mut self, device: &wgpu::Device, (ticket, view): (u64, usize), terms: &TracedTerms) -> bool {
        let Some((_, views)) = &mut self.last else { return false };
        let Some(kept) = views.iter_mut().find(|k| k.asked == Some((ticket, view))) else { return false };
        let stand_in = std::mem::replace(&mut kept.upload, self.spare.terms(device, terms));
        self.spare.give_back(stand_in);
        kept.asked = None;
        if let ViewKind::CubeFace { .. } = kept.key.0.kind {
            self.faces_received += 1;
        }
        true
    }

    /// A key of the terms the cube faces are drawn with at `stride`: it changes with the stride
    /// and when a face's terms traced elsewhere come back. A cube's faces are drawn only when what
    /// they see changes (`crate::raster::environment`), so the frame draws them again then.
    pub fn faces_key(&self, stride: u32) -> u64 {
        (u64::from(stride) << 48) | self.faces_received
    }
}

impl PreparedTraced {
    /// The copies the frame's `views` need of their terms `now`: none for a view whose image is
    /// its own and holds them already (drawn so by the last frame); each image's record of what
    /// it holds kept up to date.
    fn copies(views: &[ViewTargets<'_>], now: &[Kept]) -> PreparedTraced {
        let mut copies = Vec::new();
        for &(view, targets) in views {
            let Some(kept) = now.iter().find(|k| k.key.0.slot == view.slot) else { continue };
            let images = &targets.images;
            let shared = views.iter().filter(|(_, other)| std::ptr::eq(*other, targets)).count() > 1;
            if !shared && images.traced() == kept.upload.number {
                continue;
            }
            // Views sharing an image copy in the order they draw: what it holds after them is
            // not counted on.
            images.hold_traced(if shared { 0 } else { kept.upload.number });
            copies.push((view.slot, kept.upload.clone()));
        }
        PreparedTraced { views: copies }
    }

    /// Copies `view`'s terms into its traced image, which the view's shading then reads.
    pub fn record(&self, frame: &mut FrameEncoder, view: &FrameView, targets: &FrameTargets) {
        let Some((_, upload)) = self.views.iter().find(|(slot, _)| *slot == view.slot) else { return };
        let image = &targets.images.array_of(ViewImage::Traced).texture;
        upload.copy(&mut frame.encoder, image, ViewImage::Traced.first_layer());
    }
}
