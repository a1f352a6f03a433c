//! Each tool's work on the frame, where it needs the whole viewer: the inspection of a pixel in
//! both renderers (`super::inspect`'s state) and the error budget of the view
//! (`super::error_budget`'s). The tools' states are their own modules', which know nothing of the
//! viewer; this module is where the viewer meets them.

use glam::Vec2;

#[cfg(not(target_arch = "wasm32"))]
use super::error_budget::BUDGET_WIDTH;
use super::frame::Viewer;
use super::inspect::Inspection;
use super::screen::Screen;
use crate::shaders::Wgsl;

impl Viewer {
    /// Explains `pixel` of the full-resolution view of `size` in both renderers.
    pub(super) fn inspect(&mut self, screen: &Screen, pixel: Vec2, size: (u32, u32)) {
        let mut scene = self.scene.scene.clone();
        (scene.camera.width, scene.camera.height) = size;
        let at = (pixel.x.max(0.0) as u32, pixel.y.max(0.0) as u32);
        let wgsl = self.lab.as_ref().map_or_else(Wgsl::builtin, |lab| lab.wgsl());
        match Inspection::new(&screen.gpu, &scene, &self.settings, at, wgsl) {
            Ok(inspection) => {
                let summary = inspection.summary();
                println!("{summary}");
                self.notice(summary);
                if self.settings.hybrid.any() {
                    self.notice("explained without the hybrid: its traced terms are the tracer's side".into());
                }
                self.inspect.shown = Some(inspection);
            }
            Err(e) => self.notice(format!("cannot inspect ({}, {}): {e:#}", at.0, at.1)),
        }
    }

    /// Measures the error budget of the view of `size` as it is, at most [`BUDGET_WIDTH`] pixels
    /// wide (it draws the view ten times or so and traces it once, while the window waits).
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) fn measure_budget(&mut self, screen: &Screen, size: (u32, u32)) {
        let mut scene = self.scene.scene.clone();
        let width = size.0.min(BUDGET_WIDTH);
        (scene.camera.width, scene.camera.height) = (width, (size.1 * width).div_ceil(size.0.max(1)).max(1));
        let reference = crate::budget::reference_scene(&scene, &self.settings);
        let traced = crate::trace::render_image(&reference, &self.settings);
        let measured =
            screen.gpu.checked(|| crate::budget::budget(&screen.gpu, (&scene, &reference), &self.settings, traced));
        let budget = match measured {
            Ok(budget) => budget,
            Err(e) => return self.notice(format!("cannot measure the error budget: {e:#}")),
        };
        let mut report = budget.report();
        if self.lab.is_some() {
            report = format!("(Mirador's own functions, not the lab's)\n{report}");
        }
        println!("{report}");
        self.notice(format!("error budget measured: FLIP {:.4}, floor {:.4}", budget.whole, budget.floor));
        self.error_budget.report = Some(report);
    }

    /// The page measures no budget: `mirador budget` does, natively.
    #[cfg(target_arch = "wasm32")]
    pub(super) fn measure_budget(&mut self, _: &Screen, _: (u32, u32)) {
        self.notice("the error budget is measured natively: `mirador budget SCENE`".into());
    }
}
