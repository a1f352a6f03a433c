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
//! changed, copies the buffer it was traced into then ([`KeptTraced`]).

use glam::{Vec2, Vec3, Vec4};

use super::context::{Figure, FrameEncoder};
use super::shadow::views::{MAX_SHADOWED_LIGHTS, ShadowLayout};
use super::targets::{FrameTargets, ViewImage};
use super::view::{FrameView, View, ViewKind, ViewSlot, ViewTargets};
use crate::base::Ray;
use crate::scene::{Camera, Scene};
use crate::settings::RenderSettings;
use crate::texture::RayCone;
use crate::trace::Tracer;
use crate::trace::terms::{TracedTerms, ViewRays, Wanted};

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
/// camera at the same size has the same terms, and the frame copies them again rather than
/// tracing them again (as a raster frame keeps its shadow maps). A view that changed, or any
/// change of the scene or the settings, is traced anew.
#[derive(Default)]
pub struct KeptTraced {
    last: Option<(SceneInputs, Vec<(ViewInputs, Upload)>)>,
    /// Counts the scenes loaded ([`Self::forget`]): a new scene is never the last one.
    generation: u64,
}

/// What every view's traced terms depend on.
#[derive(PartialEq)]
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
        self.last = None;
        self.generation += 1;
    }

    /// The terms `wanted` for every view of `views`, each into a buffer of its image's layers:
    /// the last frame's where nothing they depend on changed, else traced ([`trace`]); and kept.
    /// `lights` are the frame's shadowed lights, whose slots the visibility layers follow.
    pub fn prepare(
        &mut self,
        (device, scene, settings): (&wgpu::Device, &Scene, &RenderSettings),
        frame: &mut FrameEncoder,
        (wanted, stride): (Wanted, u32),
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
        let last = self.last.take().filter(|(kept, _)| *kept == inputs).map(|(_, views)| views).unwrap_or_default();
        let (mut rays, mut kept) = (0, 0);
        let mut now = Vec::new();
        let tracer = std::cell::OnceCell::new();
        for &(view, targets) in views {
            let key = (view.clone(), targets.size);
            let upload = match last.iter().find(|(k, _)| *k == key) {
                Some((_, upload)) => {
                    kept += 1;
                    Some(upload.clone())
                }
                None => {
                    let tracer = tracer.get_or_init(|| Tracer::new(scene, settings));
                    trace(device, tracer, (view, targets), (wanted, stride), &inputs.slots, &mut rays)
                }
            };
            now.extend(upload.map(|upload| (key, upload)));
        }
        frame.end("traced terms", &[("rays", Figure::Count(rays)), ("views kept", Figure::Count(kept))]);
        let prepared =
            PreparedTraced { views: now.iter().map(|((view, _), upload)| (view.slot, upload.clone())).collect() };
        self.last = Some((inputs, now));
        prepared
    }
}

/// One view's terms in a buffer: the window they cover and the image layer of each.
#[derive(Clone)]
struct Upload {
    buffer: wgpu::Buffer,
    window: [u32; 4],
    layers: Vec<u32>,
}

/// Bytes of one pixel of one layer (`Rgba32Float`).
const PIXEL_BYTES: u32 = 16;

/// Traces one view's terms into a buffer of its image's layers, adding its rays to `rays`; `None`
/// for a view with an empty window (a mirror at the screen's edge may leave its camera one).
fn trace(
    device: &wgpu::Device,
    tracer: &Tracer,
    (view, targets): ViewTargets<'_>,
    (wanted, stride): (Wanted, u32),
    slots: &[usize],
    rays: &mut u64,
) -> Option<Upload> {
    let size = targets.size;
    let window = view.scissor.unwrap_or([0, 0, size.0, size.1]);
    if window[2] == 0 || window[3] == 0 {
        return None;
    }
    let (ray, cone) = camera_rays(tracer.scene, view, size);
    let view_rays = ViewRays { size, window, ray: &*ray, cone, skip: view.skip, lights: slots, stride };
    let terms = tracer.terms(&view_rays, wanted);
    *rays += terms.rays.total();
    Some(upload(device, &terms))
}

impl PreparedTraced {
    /// Copies `view`'s terms into its traced image, which the view's shading then reads.
    pub fn record(&self, frame: &mut FrameEncoder, view: &FrameView, targets: &FrameTargets) {
        let Some((_, upload)) = self.views.iter().find(|(slot, _)| *slot == view.slot) else { return };
        let image = &targets.images.array_of(ViewImage::Traced).texture;
        let [x, y, width, height] = upload.window;
        let layer_bytes = u64::from(padded_row(width) * height);
        for (k, &layer) in upload.layers.iter().enumerate() {
            frame.encoder.copy_buffer_to_texture(
                wgpu::TexelCopyBufferInfo {
                    buffer: &upload.buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: k as u64 * layer_bytes,
                        bytes_per_row: Some(padded_row(width)),
                        rows_per_image: Some(height),
                    },
                },
                wgpu::TexelCopyTextureInfo {
                    texture: image,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x, y, z: ViewImage::Traced.first_layer() + layer },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            );
        }
    }
}

/// A row's bytes, padded to wgpu's copy alignment.
fn padded_row(width: u32) -> u32 {
    (width * PIXEL_BYTES).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
}

/// The terms traced, layer after layer, each row padded; and each one's layer in the image.
fn upload(device: &wgpu::Device, terms: &TracedTerms) -> Upload {
    let layers = &terms.layers;
    let [_, _, width, height] = terms.window;
    let row = padded_row(width) as usize;
    let layer_bytes = row * height as usize;
    // Written where the copy reads it, in the buffer as it is made.
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("traced::terms"),
        size: (layer_bytes * layers.len()).max(PIXEL_BYTES as usize) as u64,
        usage: wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: true,
    });
    {
        let mut bytes = buffer.slice(..).get_mapped_range_mut().expect("a buffer mapped at its creation");
        for (k, (_, values)) in layers.iter().enumerate() {
            for (y, line) in values.chunks(width.max(1) as usize).enumerate() {
                let start = layer_bytes * k + y * row;
                let line: &[u8] = bytemuck::cast_slice(line);
                bytes.slice(start..start + line.len()).copy_from_slice(line);
            }
        }
    }
    buffer.unmap();
    Upload { buffer, window: terms.window, layers: layers.iter().map(|(layer, _)| *layer).collect() }
}

type RayFn = Box<dyn Fn(f32, f32) -> Option<(Ray, f32)> + Sync>;

/// The rays of `view` drawn at `size`, and a pixel's cone along them.
fn camera_rays(scene: &Scene, view: &FrameView, size: (u32, u32)) -> (RayFn, RayCone) {
    let camera = scene.camera.clone();
    if view.kind == ViewKind::Main {
        // The tracer's own primary rays, scaled from the drawn size to the camera's, and a pixel
        // of the drawn size's cone.
        let (sx, sy) = (camera.width as f32 / size.0 as f32, camera.height as f32 / size.1 as f32);
        let cone = crate::trace::primary_cone(&Camera { width: size.0, height: size.1, ..camera.clone() });
        return (Box::new(move |x, y| Some((camera.ray_through(x * sx, y * sy), 0.0))), cone);
    }
    let unprojected = Unprojected::new(&view.view, size);
    let centre = (size.0 as f32 / 2.0, size.1 as f32 / 2.0);
    let (a, b) = (unprojected.line(centre.0, centre.1), unprojected.line(centre.0 + 1.0, centre.1));
    let cone = if view.view.orthographic {
        RayCone::orthographic(a.origin.distance(b.origin))
    } else {
        RayCone { width: 0.0, spread: a.direction.angle_between(b.direction) }
    };
    (Box::new(move |x, y| unprojected.ray(x, y)), cone)
}

/// A view's rays, unprojected from its `clip_from_world`.
struct Unprojected {
    world_from_clip: glam::Mat4,
    size: Vec2,
    eye: Option<Vec3>,
    view_axis: Vec3,
    clip_plane: Option<Vec4>,
}

impl Unprojected {
    fn new(view: &View, size: (u32, u32)) -> Unprojected {
        Unprojected {
            world_from_clip: view.clip_from_world.inverse(),
            size: Vec2::new(size.0 as f32, size.1 as f32),
            eye: (!view.orthographic).then_some(view.eye),
            view_axis: view.view_axis,
            clip_plane: view.clip_plane,
        }
    }

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
