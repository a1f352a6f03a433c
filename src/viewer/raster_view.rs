//! The rasterizer's image in the window: the one place the viewer calls [`Renderer`].
//!
//! The frame is drawn offscreen, into a texture of the 3D view's size times the render scale
//! (lower while the camera moves: `frame::Viewer::scale`), exactly as `mirador render` draws it.
//! The image has the sRGB twin of the window surface's format, so the window takes it by a copy
//! of its bytes, or stretches it over the view ([`super::upscale`]) through a plain view of the
//! same bytes (`screen::Composition::Copied`). Where the surface takes no copies, the image is
//! `Rgba8UnormSrgb` and is copied into an `Rgba8Unorm` twin that egui samples: egui expects sRGB-encoded values in a texture it does not decode, and a copy
//! between formats that differ only in their sRGB-ness moves the bytes unchanged, so the window
//! shows the very pixels a screenshot of `render` holds, on every backend (the GL backend cannot
//! reinterpret one texture through a view of another format).
//!
//! A frame whose inputs (camera, lights, settings, scene revision, size) are those of the image
//! already drawn is not drawn again: the window shows the kept image. Hovering, the panel and the
//! overlays then cost only the window's composition. Where the hybrid traces terms
//! (`settings.hybrid`), a new image's are traced at one pixel in 16 and refined, one pixel in 4
//! then every pixel, in the frames that follow while its inputs stay, as the traced view refines.

use std::time::Duration;

use web_time::Instant;

use super::screen::{Composition, PendingImage, Screen};
use super::upscale::Reencode;
use crate::gpu::Gpu;
use crate::gpu::texture::GpuTexture;
use crate::raster::traced::TracedAt;
use crate::raster::{FrameReport, FrameTargets, Renderer, drawn_size};
use crate::scene::{Camera, Light};
use crate::shaders::{Profile, Wgsl};
use crate::{RenderSettings, Scene};

/// The format egui samples the image from ([`Composition::Textured`]).
const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

pub(in crate::viewer) struct RasterView {
    renderer: Renderer,
    /// What the device's shaders may use (the page's labs need it).
    device_profile: Profile,
    composition: Composition,
    format: wgpu::TextureFormat,
    /// The scene revision the renderer loaded.
    revision: u64,
    /// Everything that depends on the image size.
    frame: Option<SizedTargets>,
    /// What the image shows.
    drawn: Option<Inputs>,
    /// How egui refers to the displayed image ([`Composition::Textured`]); the same id across
    /// resizes, so the UI can lay out a frame before its image is drawn.
    texture_id: egui::TextureId,
    /// Bound to `texture_id` until the first frame is drawn.
    _placeholder: wgpu::Texture,
    /// The image size and filter the egui texture was last bound with.
    bound: Option<((u32, u32), wgpu::FilterMode)>,
    /// What the last frame drawn did: its passes' times (when profiled), the shadow layers it
    /// redrew.
    pub report: FrameReport,
    /// The image on its way back to the CPU ([`RasterView::read_back`]).
    readback: Option<PendingImage>,
    /// Draws the image into the one egui shows where a copy cannot (the WebGL2 profile).
    reencode: Option<Reencode>,
    /// The stride the hybrid's traced terms of the image shown were traced at (1: every pixel):
    /// a new image's are traced coarse, and refined frame by frame while its inputs stay.
    traced_stride: u32,
    /// The page's Web Workers trace the terms at every pixel (`TracedAt::Elsewhere`): a new
    /// image's frame traces them coarse here and asks the workers for all, and is refined in one
    /// step when their terms come back.
    elsewhere: bool,
    /// Terms came back from the workers, or they failed while some were due: draw again.
    terms_arrived: bool,
    /// The bands of each view asked of the workers, as they come back.
    #[cfg(target_arch = "wasm32")]
    terms: terms::TermsInWorkers,
}

#[cfg(target_arch = "wasm32")]
mod terms;

/// The stride a new image's traced terms start at: one pixel in 16, refined to 4, then to all.
const COARSE_TRACED_STRIDE: u32 = 4;

/// Everything a raster image depends on (the lab's difference view keeps the same).
#[derive(Clone, PartialEq)]
pub(super) struct Inputs {
    camera: Camera,
    lights: Vec<Light>,
    settings: RenderSettings,
    revision: u64,
}

impl Inputs {
    /// What `scene` (at its `revision`) drawn with `settings` depends on.
    pub(super) fn of(scene: &Scene, settings: &RenderSettings, revision: u64) -> Inputs {
        Inputs { camera: scene.camera.clone(), lights: scene.lights.clone(), settings: settings.clone(), revision }
    }
}

struct SizedTargets {
    size: (u32, u32),
    targets: FrameTargets,
    image: GpuTexture,
    /// The image's bytes through the plain (not sRGB) twin of its format
    /// ([`Composition::Copied`]).
    plain: Option<wgpu::TextureView>,
    /// The twin egui samples ([`Composition::Textured`]).
    display: Option<(wgpu::Texture, wgpu::TextureView)>,
}

/// What [`RasterView::render`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::viewer) enum Drawn {
    /// Nothing changed: the image is the last one.
    Kept,
    /// A new image, in this time from submission to completion.
    New(Duration),
}

impl RasterView {
    /// What the device's shaders may use.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    pub fn profile(&self) -> Profile {
        self.device_profile
    }

    /// The view of `scene`, drawn by passes compiled from `wgsl` (Mirador's own, or a lab's:
    /// `super::lab`).
    pub fn new(screen: &mut Screen, scene: &Scene, revision: u64, wgsl: Wgsl) -> RasterView {
        let gpu = &screen.gpu;
        let format = screen.image_format();
        let renderer = Renderer::with_wgsl(gpu, scene, format, wgsl, false);
        let placeholder = display_texture(&gpu.device, (1, 1));
        let view = placeholder.create_view(&wgpu::TextureViewDescriptor {
            label: Some("viewer::raster::placeholder_view"),
            ..Default::default()
        });
        let texture_id = screen.painter.register_native_texture(&gpu.device, &view, wgpu::FilterMode::Nearest);
        RasterView {
            renderer,
            device_profile: gpu.profile(),
            composition: screen.composition,
            format,
            revision,
            frame: None,
            drawn: None,
            texture_id,
            _placeholder: placeholder,
            readback: None,
            bound: None,
            report: FrameReport::default(),
            // GL copies an sRGB texture into a plain one only with glCopyImageSubData, which
            // WebGL2 and OpenGL ES 3.0 lack; a draw does it everywhere.
            reencode: (screen.composition == Composition::Textured && gl_without_image_copies(gpu))
                .then(|| Reencode::new(&gpu.device, DISPLAY_FORMAT)),
            traced_stride: 1,
            elsewhere: false,
            terms_arrived: false,
            #[cfg(target_arch = "wasm32")]
            terms: Default::default(),
        }
    }

    /// Draws from now on with passes compiled from `wgsl` (lab mode: the student's functions
    /// saved, or the reference shown), `scene` of `revision` loaded into them.
    pub(in crate::viewer) fn set_wgsl(&mut self, gpu: &Gpu, (scene, revision): (&Scene, u64), wgsl: Wgsl) {
        self.renderer = Renderer::with_wgsl(gpu, scene, self.format, wgsl, false);
        self.revision = revision;
        self.drawn = None;
    }

    /// The displayed image's egui id ([`Composition::Textured`]).
    pub(in crate::viewer) fn texture_id(&self) -> egui::TextureId {
        self.texture_id
    }

    /// The image to copy into the window ([`Composition::Copied`]) and its plain view, once one
    /// is drawn.
    pub fn image(&self) -> Option<(&wgpu::Texture, &wgpu::TextureView)> {
        let frame = self.frame.as_ref().filter(|_| self.drawn.is_some())?;
        Some((&frame.image.texture, frame.plain.as_ref()?))
    }

    /// Renders `scene` (whose camera has the image's size) with `settings` unless the image
    /// already shows it. Waits for the frame to measure it; with `profile`, each pass is also
    /// submitted and timed on its own, in [`Self::report`]. `filter` is how egui samples the
    /// image ([`Composition::Textured`]): linear when it is smaller than the view.
    pub fn render(
        &mut self,
        screen: &mut Screen,
        (scene, revision): (&Scene, u64),
        settings: &RenderSettings,
        (profile, filter): (bool, wgpu::FilterMode),
    ) -> Drawn {
        let inputs = Inputs::of(scene, settings, revision);
        if self.drawn.as_ref() == Some(&inputs) {
            if !self.refining() {
                return Drawn::Kept;
            }
            // Terms that came back are drawn at the stride they were asked at.
            if !std::mem::take(&mut self.terms_arrived) {
                self.traced_stride = if self.elsewhere { 1 } else { self.traced_stride / 2 };
            }
        } else {
            // Elsewhere, the coarse terms are the stand-ins of the frame that asks for all.
            let coarse = settings.hybrid.any() && !self.elsewhere;
            self.traced_stride = if coarse { COARSE_TRACED_STRIDE } else { 1 };
            self.terms_arrived = false;
        }
        let gpu = &screen.gpu;
        if revision != self.revision {
            self.renderer.load(gpu, scene);
            self.revision = revision;
        }
        let size = (scene.camera.width, scene.camera.height);
        if self.frame.as_ref().is_none_or(|f| f.size != size) {
            self.frame = Some(self.sized_targets(gpu, size, settings));
        }
        let frame = self.frame.as_mut().expect("made just above");
        let start = Instant::now();
        self.renderer.profile = profile;
        self.renderer.traced_stride = self.traced_stride;
        self.renderer.traced_at =
            if self.elsewhere { TracedAt::Elsewhere { coarse: COARSE_TRACED_STRIDE } } else { TracedAt::Here };
        self.report = self.renderer.render(gpu, scene, settings, &mut frame.targets, &frame.image.view);
        if let Some((display, display_view)) = &frame.display {
            let mut encoder = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("viewer::raster::copy") });
            match &mut self.reencode {
                Some(reencode) => reencode.record(&gpu.device, &mut encoder, &frame.image.view, display_view),
                None => encoder.copy_texture_to_texture(
                    frame.image.texture.as_image_copy(),
                    display.as_image_copy(),
                    frame.image.texture.size(),
                ),
            }
            gpu.queue.submit([encoder.finish()]);
        }
        gpu.wait();
        let elapsed = start.elapsed();
        if let Some((_, display_view)) = &frame.display
            && self.bound != Some((size, filter))
        {
            screen.painter.update_egui_texture_from_wgpu_texture(&gpu.device, display_view, filter, self.texture_id);
            self.bound = Some((size, filter));
        }
        self.drawn = Some(inputs);
        self.readback = None;
        Drawn::New(elapsed)
    }

    /// Whether the image shown is drawn with `settings` and its hybrid's terms traced at every
    /// pixel (here, or by the page's workers and drawn).
    pub(in crate::viewer) fn terms_complete(&self, settings: &RenderSettings) -> bool {
        let drawn = self.drawn.as_ref().is_some_and(|d| d.settings == *settings);
        drawn && !self.refining() && !self.renderer.traced.awaiting()
    }

    /// Whether the image shown has traced terms still to refine: the viewer draws again at once.
    pub(in crate::viewer) fn refining(&self) -> bool {
        (self.traced_stride > 1 || self.terms_arrived) && self.drawn.as_ref().is_some_and(|d| d.settings.hybrid.any())
    }

    fn sized_targets(&self, gpu: &Gpu, size: (u32, u32), settings: &RenderSettings) -> SizedTargets {
        let targets = FrameTargets::new(&gpu.device, drawn_size(size, settings.raster.render_scale));
        let copied = self.composition == Composition::Copied;
        let plain_format = self.format.remove_srgb_suffix();
        let plain_formats = [plain_format];
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("viewer::raster::image"),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: if copied { &plain_formats } else { &[] },
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let plain = copied.then(|| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some("viewer::raster::plain_view"),
                format: Some(plain_format),
                ..Default::default()
            })
        });
        let image = GpuTexture { texture, view };
        let display = (!copied).then(|| {
            let display = display_texture(&gpu.device, size);
            let view = display.create_view(&wgpu::TextureViewDescriptor {
                label: Some("viewer::raster::display_view"),
                ..Default::default()
            });
            (display, view)
        });
        SizedTargets { size, targets, image, plain, display }
    }

    /// The last rendered image, read back (sRGB RGBA8, as `mirador render` writes it): asked for
    /// by the first call after a frame is drawn and handed over by a later one once the GPU has
    /// copied it (natively by the same call, which waits; in the browser a frame or two later).
    pub(in crate::viewer) fn read_back(&mut self, gpu: &Gpu) -> Option<image::RgbaImage> {
        let frame = self.frame.as_ref()?;
        if self.readback.is_none() {
            self.readback = Some(PendingImage::start(gpu, &frame.image.texture).ok()?);
            gpu.wait();
        }
        let image = self.readback.as_ref()?.take(gpu)?;
        self.readback = None;
        image.ok()
    }

    /// Whether a readback is under way: the next frame is asked for, to take it.
    pub(in crate::viewer) fn reading_back(&self) -> bool {
        self.readback.is_some()
    }
}

/// Whether `gpu` is GL without copies between textures of formats that differ in sRGB-ness:
/// WebGL2 and OpenGL ES 3.0 (the WebGL2 profile's devices), or GL in the browser whatever its
/// profile.
fn gl_without_image_copies(gpu: &Gpu) -> bool {
    gpu.adapter.get_info().backend == wgpu::Backend::Gl
        && (gpu.profile() == Profile::WebGl2 || cfg!(target_arch = "wasm32"))
}

/// The texture egui samples: the raster image's bytes, not decoded.
fn display_texture(device: &wgpu::Device, size: (u32, u32)) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("viewer::raster::display"),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: DISPLAY_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    })
}
