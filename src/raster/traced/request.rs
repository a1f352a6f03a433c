//! One view's traced terms as a piece of work that can travel: what the tracer needs to trace
//! them (the view's rays, its window, the terms, the stride, the lights' slots), and the terms it
//! returns as a header and their numbers. The frame traces its views through it here, and the page
//! hands it to its Web Workers (`crate::web::tracer`), which rebuild the scene and trace it as the
//! page's thread would, to the bit: a view's rays are made from numbers the request carries, not
//! from the frame that asked.

use glam::{Mat4, Vec2, Vec3, Vec4};
use serde::{Deserialize, Serialize};

use super::SceneInputs;
use crate::base::Ray;
use crate::raster::view::{FrameView, ViewKind};
use crate::scene::{Camera, Scene};
use crate::settings::TracedSet;
use crate::texture::RayCone;
use crate::trace::Tracer;
use crate::trace::terms::{TracedTerms, ViewRays, Wanted};

/// The terms of one view (or of a band of its rows) to trace.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TermsRequest {
    /// The inputs it was asked under ([`super::KeptTraced::receive`] drops an older one's).
    pub ticket: u64,
    /// Its number among the views asked under that ticket.
    pub view: usize,
    camera: ViewCamera,
    /// The view's image, in pixels.
    size: (u32, u32),
    /// The part of the image traced (the view's scissor, or all of it); `None`: nothing (a mirror
    /// at the screen's edge may leave its camera an empty window).
    pub window: Option<[u32; 4]>,
    /// The object the view looks out of.
    skip: Option<usize>,
    wanted: TracedSet,
    stride: u32,
    /// The scene light of each shadowed light's slot.
    slots: Vec<usize>,
}

/// Where a view's rays come from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
enum ViewCamera {
    /// The scene camera's own primary rays, as the tracer casts them.
    Scene,
    /// Unprojected from the view's `clip_from_world` ([`Unprojected`]).
    Unprojected { clip_from_world: Mat4, eye: Vec3, orthographic: bool, view_axis: Vec3, clip_plane: Option<Vec4> },
}

impl TermsRequest {
    /// The request for `view` drawn at `size`, with the frame's `inputs`.
    pub(super) fn new(
        (ticket, number): (u64, usize),
        (view, size): (&FrameView, (u32, u32)),
        inputs: &SceneInputs,
    ) -> TermsRequest {
        let window = view.scissor.unwrap_or([0, 0, size.0, size.1]);
        let v = &view.view;
        let camera = match view.kind {
            ViewKind::Main => ViewCamera::Scene,
            _ => ViewCamera::Unprojected {
                clip_from_world: v.clip_from_world,
                eye: v.eye,
                orthographic: v.orthographic,
                view_axis: v.view_axis,
                clip_plane: v.clip_plane,
            },
        };
        TermsRequest {
            ticket,
            view: number,
            camera,
            size,
            window: (window[2] > 0 && window[3] > 0).then_some(window),
            skip: view.skip,
            wanted: inputs.wanted,
            stride: inputs.stride,
            slots: inputs.slots.clone(),
        }
    }

    /// The request at another stride: one pixel traced in each block of `stride × stride`.
    pub fn with_stride(&self, stride: u32) -> TermsRequest {
        TermsRequest { stride: stride.max(1), ..self.clone() }
    }

    /// The terms, traced by `tracer` (of the scene the request was made from); `None` for an
    /// empty window.
    pub fn trace(&self, tracer: &Tracer) -> Option<TracedTerms> {
        self.trace_with(tracer, |view, wanted| tracer.terms(view, wanted))
    }

    /// `trace(view, wanted)` of the request's view and terms, as `tracer` (of the scene the
    /// request was made from) looks through it; `None` for an empty window.
    pub fn trace_with<T>(&self, tracer: &Tracer, trace: impl FnOnce(&ViewRays, Wanted) -> T) -> Option<T> {
        let window = self.window?;
        let (ray, cone) = camera_rays(tracer.scene, &self.camera, self.size);
        let view_rays = ViewRays {
            size: self.size,
            window,
            ray: &*ray,
            cone,
            skip: self.skip,
            lights: &self.slots,
            stride: self.stride,
        };
        Some(trace(&view_rays, self.wanted))
    }

    /// The request split into bands of at least `rows` rows (rounded up to the stride, so that
    /// each band's blocks are the whole request's), top to bottom: pieces for workers to share,
    /// whose terms [`join`] puts back together.
    pub fn bands(&self, rows: u32) -> Vec<TermsRequest> {
        let Some([x, y, width, height]) = self.window else { return vec![self.clone()] };
        let rows = rows.max(1).next_multiple_of(self.stride.max(1));
        (y..y + height)
            .step_by(rows as usize)
            .map(|first| TermsRequest { window: Some([x, first, width, rows.min(y + height - first)]), ..self.clone() })
            .collect()
    }
}

/// The terms of a request's bands ([`TermsRequest::bands`]), in order, as one request's.
pub fn join(bands: Vec<TracedTerms>) -> Result<TracedTerms, String> {
    let mut bands = bands.into_iter();
    let mut whole = bands.next().ok_or("no band to join")?;
    for band in bands {
        let [x, y, width, height] = whole.window;
        let same_layers = band.layers.iter().map(|(l, _)| l).eq(whole.layers.iter().map(|(l, _)| l));
        if band.window[0] != x || band.window[2] != width || band.window[1] != y + height || !same_layers {
            return Err(format!("a band {:?} that does not follow {:?}", band.window, whole.window));
        }
        whole.window[3] += band.window[3];
        for ((_, values), (_, more)) in whole.layers.iter_mut().zip(band.layers) {
            values.extend(more);
        }
        whole.rays += band.rays;
    }
    Ok(whole)
}

/// What [`encode`] writes besides the numbers.
#[derive(Serialize, Deserialize)]
struct Header {
    window: [u32; 4],
    layers: Vec<u32>,
}

/// `terms` as a header (JSON) and their numbers, layer after layer, four a pixel: what a worker
/// posts back (the numbers as a `Float32Array`, moved, not copied).
pub fn encode(terms: &TracedTerms) -> (String, Vec<f32>) {
    let header = Header { window: terms.window, layers: terms.layers.iter().map(|(layer, _)| *layer).collect() };
    let values = terms.layers.iter().flat_map(|(_, values)| values.iter().flatten().copied()).collect();
    (serde_json::to_string(&header).expect("a header is plain data"), values)
}

/// The terms [`encode`] wrote, checked against their header.
pub fn decode(header: &str, values: &[f32]) -> Result<TracedTerms, String> {
    let header: Header = serde_json::from_str(header).map_err(|e| format!("traced terms' header: {e}"))?;
    let pixels = header.window[2] as usize * header.window[3] as usize;
    if values.len() != pixels * 4 * header.layers.len() {
        return Err(format!("{} numbers for {} layers of {pixels} pixels", values.len(), header.layers.len()));
    }
    let layers = header
        .layers
        .iter()
        .zip(values.chunks(pixels * 4))
        .map(|(&layer, values)| (layer, values.chunks(4).map(|p| [p[0], p[1], p[2], p[3]]).collect()))
        .collect();
    // The rays stay uncounted: the frame's figures count the rays traced here.
    Ok(TracedTerms { window: header.window, layers, rays: Default::default() })
}

type RayFn = Box<dyn Fn(f32, f32) -> Option<(Ray, f32)> + Sync>;

/// The rays of a view drawn at `size`, and a pixel's cone along them.
fn camera_rays(scene: &Scene, camera: &ViewCamera, size: (u32, u32)) -> (RayFn, RayCone) {
    let &ViewCamera::Unprojected { clip_from_world, eye, orthographic, view_axis, clip_plane } = camera else {
        // The tracer's own primary rays, scaled from the drawn size to the camera's, and a pixel
        // of the drawn size's cone.
        let camera = &scene.camera;
        let (sx, sy) = (camera.width as f32 / size.0 as f32, camera.height as f32 / size.1 as f32);
        let cone = crate::trace::primary_cone(&Camera { width: size.0, height: size.1, ..camera.clone() });
        let rays = camera.rays();
        return (Box::new(move |x, y| Some((rays.through(x * sx, y * sy), 0.0))), cone);
    };
    let unprojected = Unprojected {
        world_from_clip: clip_from_world.inverse(),
        size: Vec2::new(size.0 as f32, size.1 as f32),
        eye: (!orthographic).then_some(eye),
        view_axis,
        clip_plane,
    };
    let centre = (size.0 as f32 / 2.0, size.1 as f32 / 2.0);
    let (a, b) = (unprojected.line(centre.0, centre.1), unprojected.line(centre.0 + 1.0, centre.1));
    let cone = if orthographic {
        RayCone::orthographic(a.origin.distance(b.origin))
    } else {
        RayCone { width: 0.0, spread: a.direction.angle_between(b.direction) }
    };
    (Box::new(move |x, y| unprojected.ray(x, y)), cone)
}

/// A view's rays, unprojected from its `clip_from_world`.
struct Unprojected {
    world_from_clip: Mat4,
    size: Vec2,
    eye: Option<Vec3>,
    view_axis: Vec3,
    clip_plane: Option<Vec4>,
}

impl Unprojected {
    /// The line through image point `(x, y)`: from the eye through the point of the near plane,
    /// or from that point along the view axis (orthographic). Not through the far plane's point:
    /// a mirrored camera's far plane is tilted ([`super::mirror::oblique_near_plane`]) and may
    /// lie behind the eye at a corner.
    fn line(&self, x: f32, y: f32) -> Ray {
        let ndc = Vec2::new(2.0 * x / self.size.x - 1.0, 1.0 - 2.0 * y / self.size.y);
        let near = self.world_from_clip.project_point3(ndc.extend(0.0));
        match self.eye {
            Some(eye) => Ray { origin: eye, direction: (near - eye).normalize() },
            None => Ray { origin: near, direction: -self.view_axis },
        }
    }

    /// The ray through `(x, y)` from where the view starts seeing, its clip plane if the line
    /// starts behind it, and how far along the line that is; `None` if the line never crosses
    /// into what the view sees.
    fn ray(&self, x: f32, y: f32) -> Option<(Ray, f32)> {
        let mut ray = self.line(x, y);
        let mut start = 0.0;
        if let Some(plane) = self.clip_plane {
            let side = plane.truncate().dot(ray.origin) + plane.w;
            if side < 0.0 {
                let towards = plane.truncate().dot(ray.direction);
                if towards <= 0.0 {
                    return None;
                }
                start = -side / towards;
                ray.origin = ray.at(start);
            }
        }
        Some((ray, start))
    }
}
