//! The lab's difference view: the FLIP error map between the scene drawn with Mirador's functions
//! (the reference) and with the student's, at the view's size, drawn again whenever what it
//! depends on changes (the camera, the lights, the settings, the scene, the student's functions).
//!
//! The two images are drawn by renderers kept from one view to the next (making one compiles
//! every pass) and read back as a future ([`crate::gpu::readback::Pending::texels`]): natively it
//! is waited for at once, in the page it is polled a frame at a time, as the lab's checks are.

use std::cell::RefCell;
use std::future::Future;
use std::pin::Pin;
use std::rc::Rc;

use image::RgbaImage;

use crate::Scene;
use crate::gpu::Gpu;
use crate::raster::Headless;
use crate::shaders::Wgsl;

/// The difference view of a lab mode: what it shows, and what is being drawn for it.
#[derive(Default)]
pub(in crate::viewer) struct DifferenceView {
    shown: Option<Shown>,
    /// The renderers, between two draws (a draw under way holds them).
    renderers: Rc<RefCell<Option<Renderers>>>,
    pending: Option<(Inputs, Drawing)>,
}

/// The reference's image and the student's, under way.
type Drawing = Pin<Box<dyn Future<Output = Result<(RgbaImage, RgbaImage), String>>>>;

/// The two renderers the difference view draws with, kept while the student's functions, the
/// scene and the view's size stay the same.
struct Renderers {
    /// The student's version, the scene's revision and the image size they were made for.
    made_for: (u64, u64, (u32, u32)),
    reference: Headless,
    student: Headless,
}

struct Shown {
    texture: egui::TextureHandle,
    flip_mean: f32,
    inputs: Inputs,
}

/// Everything the difference image depends on: what a raster image does, and the student's
/// functions' version.
type Inputs = (super::raster_view::Inputs, u64);

impl DifferenceView {
    /// The error map and its mean, once made for the current view.
    pub fn shown(&self) -> Option<(egui::TextureId, f32)> {
        self.shown.as_ref().map(|shown| (shown.texture.id(), shown.flip_mean))
    }

    /// Whether the images for the view are still being drawn (the page then draws the next frame).
    pub fn drawing(&self) -> bool {
        self.pending.is_some()
    }

    /// Brings the error map up to date with `scene` (at the view's size, its `revision`) and the
    /// student's functions `student` (their `generation`) for `lab`: starts drawing when it is not, and
    /// takes the images when they are ready.
    pub fn update(
        &mut self,
        gpu: &Gpu,
        ctx: &egui::Context,
        (lab, student, generation): (&crate::lab::Lab, &Wgsl, u64),
        scene: &Scene,
        revision: u64,
    ) {
        let inputs = (super::raster_view::Inputs::of(scene, &scene.settings, revision), generation);
        if self.shown.as_ref().is_some_and(|shown| shown.inputs == inputs) {
            self.pending = None;
            return;
        }
        if self.pending.as_ref().is_none_or(|(drawing, _)| *drawing != inputs) {
            let made_for = (generation, revision, (scene.camera.width, scene.camera.height));
            // Mirador's functions composed only when a drawing starts, not every frame.
            let functions = (crate::lab::source::reference(lab), student.clone());
            let drawing = draw(gpu.clone(), scene.clone(), functions, made_for, self.renderers.clone());
            self.pending = Some((inputs, Box::pin(drawing)));
        }
        let Some((_, drawing)) = self.pending.as_mut() else { return };
        #[cfg(not(target_arch = "wasm32"))]
        let drawn = Some(crate::gpu::readback::block_on(&gpu.device, drawing.as_mut()));
        #[cfg(target_arch = "wasm32")]
        let drawn = crate::gpu::readback::poll_once(drawing.as_mut());
        let Some(drawn) = drawn else { return };
        let (inputs, _) = self.pending.take().expect("a drawing under way");
        match drawn {
            Ok((reference, student)) => self.show(ctx, &reference, &student, inputs),
            Err(e) => log::warn!("lab difference: {e}"),
        }
    }

    fn show(&mut self, ctx: &egui::Context, reference: &RgbaImage, student: &RgbaImage, inputs: Inputs) {
        let Ok(difference) = crate::compare::difference(reference, student) else { return };
        let map = &difference.error_map;
        let image =
            egui::ColorImage::from_rgba_unmultiplied([map.width() as usize, map.height() as usize], map.as_raw());
        let options = egui::TextureOptions::NEAREST;
        let texture = match self.shown.take() {
            Some(mut shown) => {
                shown.texture.set(image, options);
                shown.texture
            }
            None => ctx.load_texture("viewer::lab_difference", image, options),
        };
        let line = format!(
            "lab: difference against the reference, {} mean {:.4}",
            crate::compare::METRIC,
            difference.flip_mean
        );
        println!("{line}");
        log::info!("{line}");
        self.shown = Some(Shown { texture, flip_mean: difference.flip_mean, inputs });
    }
}

/// Draws `scene` with the reference's functions and the student's, with the renderers kept in
/// `kept` when they were made for `made_for` (new ones otherwise, kept for the next draw).
async fn draw(
    gpu: Gpu,
    scene: Scene,
    (reference, student): (Wgsl, Wgsl),
    made_for: (u64, u64, (u32, u32)),
    kept: Rc<RefCell<Option<Renderers>>>,
) -> Result<(RgbaImage, RgbaImage), String> {
    let taken = kept.borrow_mut().take();
    let started = gpu
        .checked_later(|| {
            let mut renderers = match taken {
                Some(renderers) if renderers.made_for == made_for => renderers,
                _ => Renderers {
                    made_for,
                    reference: Headless::with_wgsl(&gpu, &scene, reference),
                    student: Headless::with_wgsl(&gpu, &scene, student),
                },
            };
            let readbacks = (
                renderers.reference.render_later(&gpu, &scene, &scene.settings),
                renderers.student.render_later(&gpu, &scene, &scene.settings),
            );
            (renderers, readbacks)
        })
        .await;
    // Renderers that raised an error are not kept.
    let (renderers, (reference, student)) = started.map_err(|e| e.to_string())?;
    *kept.borrow_mut() = Some(renderers);
    let image = |pending: crate::gpu::readback::Pending| async {
        let (width, height) = pending.size();
        let pixels = pending.texels(&gpu.device).await.map_err(|e| e.to_string())?;
        RgbaImage::from_raw(width, height, pixels).ok_or_else(|| "the readback has the wrong size".to_owned())
    };
    let reference = image(reference.map_err(|e| e.to_string())?).await?;
    let student = image(student.map_err(|e| e.to_string())?).await?;
    Ok((reference, student))
}
