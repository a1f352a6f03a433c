//! One frame of the viewer, top to bottom: scripted step → file watch → traced images in → the
//! volume ray under the cursor (CPU work kept out of the layout) → UI (egui) → camera and settings
//! changes → raster image at the view's size (drawn at the render scale, unless nothing it
//! depends on changed) → traced request → compose and present the window (and a screenshot when
//! asked) → when the next frame is due.
//!
//! Frames are drawn only when something asks for one: input (egui says), a scripted step, a
//! traced image arriving, the camera moving or settling, an egui animation. Otherwise the event
//! loop sleeps (`super` polls the scene file without drawing). While the camera moves the image
//! is drawn at the render scale the frame budget picks ([`FrameBudget`]); the frame after it
//! stops ([`SETTLE`]) is drawn at full scale.

use std::path::PathBuf;
use std::time::Duration;

use web_time::Instant;

use glam::Vec2;

use super::budget::Pace;
use super::camera_control::{self, CameraInput, Navigation};
use super::config::{Remembered, ViewerConfig, scene_key};
use super::error_budget::ErrorBudget;
use super::hud::{FrameStats, FrameTimes, Notices};
use super::inspect::InspectTool;
use super::lab::LabMode;
use super::raster_view::{Drawn, RasterView};
use super::scene_state::SceneState;
use super::screen::{Composition, Presented, Screen, ViewImage};
use super::script::{Script, Step};
use super::traced::TracedView;
use super::ui::{self, Action, UiModel, UiOutput};
use super::view_mode::{ViewMode, ViewState};
use super::volume_probe::{CursorTools, ProbeAt};
use crate::RenderSettings;
use crate::scene::Camera;
use crate::shaders::Wgsl;

/// How long the camera counts as moving after its last change: the render scale stays low.
pub(super) const SETTLE: Duration = Duration::from_millis(250);
/// How soon a frame the surface was not ready for is tried again.
const RETRY: Duration = Duration::from_millis(50);

/// Everything the viewer holds, grouped by concern.
pub struct Viewer {
    pub scene: SceneState,
    pub settings: RenderSettings,
    pub navigation: Navigation,
    pub view: ViewState,
    pub(super) raster: RasterView,
    pub(super) traced: TracedView,
    /// The frames' pace: the render scale while moving, when the camera last moved.
    pub(super) pace: Pace,
    pub stats: FrameStats,
    pub script: Script,
    /// The panel's notices and the camera section's error.
    pub notices: Notices,
    /// What is under the cursor: the volume ray's samples and the environment's direction.
    pub(super) cursor: CursorTools,
    /// The inspected pixel (`super::inspect`).
    pub(super) inspect: InspectTool,
    /// The error budget measured from the panel (`super::error_budget`).
    pub(super) error_budget: ErrorBudget,
    /// Lab mode (`mirador view --lab DIR`): the student's functions drawn, reloaded when saved.
    pub lab: Option<LabMode>,
    /// The settings changed in each scene opened before (`super::config`).
    pub(super) remembered: Remembered,
}

/// What a frame tells the event loop.
pub struct FrameEnd {
    /// When the window should be drawn again (`None`: only when something happens).
    pub next: Option<Instant>,
}

/// What the viewer says when its device is of the WebGL2 profile (`shaders/profile/webgl2.wgsl`):
/// what is drawn otherwise, and what cannot run, with why.
const WEBGL2_NOTICE: &str = "drawn with WebGL2 (no WebGPU here): every technique runs; the dynamic environment \
     cubes are six 2D layers each, so their lookups do not filter across a face's edge; clicking a pixel \
     to inspect it needs storage buffers, which WebGL2 lacks (WebGPU or Vulkan have them); the shadow map's own \
     view (shadows.view = \"map\") is black, as WebGL2 cannot read a depth texture's texels";

impl Viewer {
    pub fn new(
        screen: &mut Screen,
        scene: crate::Scene,
        config: &ViewerConfig,
        steps: Vec<Step>,
        wake: impl Fn() + Send + 'static,
        mut lab: Option<LabMode>,
    ) -> Viewer {
        let remembered = config.scenes.clone();
        let changes = remembered.get(&scene_key(scene.source.as_deref())).cloned().unwrap_or_default();
        let (settings, warnings) = super::config::apply_settings(&scene.settings, &changes);
        let mut scene = SceneState::new(super::scene_state::displaced(scene, &settings));
        scene.scene.settings = settings.clone();
        let wgsl = lab.as_mut().map_or_else(Wgsl::builtin, |lab| {
            lab.take_changed();
            lab.wgsl()
        });
        let raster = RasterView::new(screen, &scene.scene, scene.revision, wgsl);
        let mut warnings = warnings;
        if screen.gpu.profile() == crate::shaders::Profile::WebGl2 {
            warnings.push(WEBGL2_NOTICE.into());
        }
        Viewer {
            scene,
            settings,
            navigation: Navigation::Orbit,
            view: ViewState {
                mode: config.mode,
                split: config.split,
                motion_fps: config.motion_fps,
                motion_scale: config.motion_scale,
                ..Default::default()
            },
            raster,
            traced: TracedView::new(wake),
            pace: Pace::default(),
            stats: FrameStats::default(),
            script: Script::new(steps),
            notices: Notices { list: warnings, camera_error: None },
            cursor: CursorTools::default(),
            inspect: InspectTool::default(),
            error_budget: ErrorBudget::default(),
            lab,
            remembered: Remembered { scenes: remembered, changed: Default::default() },
        }
    }

    /// Starts the page's tracer workers, so that they are ready before the first traced view.
    #[cfg(target_arch = "wasm32")]
    pub fn start_tracer_workers(&mut self) {
        self.traced.worker.start_workers();
    }

    pub(super) fn notice(&mut self, message: String) {
        log::info!("{message}");
        self.notices.push(message);
    }

    /// Draws one frame.
    pub fn frame(&mut self, screen: &mut Screen) -> anyhow::Result<FrameEnd> {
        let start = Instant::now();
        let interval = self.pace.last_frame.filter(|(_, at_once)| *at_once).map(|(t, _)| start - t);
        let mut times = FrameTimes { interval, ..Default::default() };
        let camera_before = self.scene.scene.camera.clone();
        let mut input = CameraInput::default();
        screen.write_screenshots()?;
        self.run_script(&mut input)?;
        self.poll_file();
        self.advance_lab_check(screen);
        self.traced.poll(&screen.egui);
        // The volume ray and the environment's direction under the cursor, made here so that the
        // layout only draws them.
        let probe_at = self.probe_at();
        self.cursor.probe.update(&mut self.scene, &self.settings, probe_at);
        self.cursor.seen.update(&mut self.scene, &self.settings, probe_at.map(|at| (at.pixel, at.size)));

        // The UI decides the 3D view's size and gathers input.
        let ui_start = Instant::now();
        let (output, full) = self.lay_out(screen);
        times.ui = ui_start.elapsed();
        if std::mem::take(&mut self.script.print_probe) {
            println!("{}", self.cursor.probe.probe().map_or("volume probe none".to_string(), |p| p.report()));
        }
        let repaint = full.viewport_output.get(&egui::ViewportId::ROOT).map(|v| v.repaint_delay);
        if output.inspection_closed {
            self.inspect.shown = None;
        }
        self.inspect.next = output.inspect.or(self.inspect.next);
        self.cursor.at = output.cursor;
        self.apply(&output, input, start);
        // Compared without the image size, which the frame sets below.
        let camera = &self.scene.scene.camera;
        let moved =
            Camera { width: camera_before.width, height: camera_before.height, ..camera.clone() } != camera_before;

        // The raster image at the view's size, drawn at the render scale.
        let ppp = full.pixels_per_point;
        self.view.pixels = output.view_rect.map(|r| {
            let px = |x: f32| (x * ppp).round().max(0.0) as u32;
            (px(r.min.x), px(r.min.y), px(r.width()).max(1), px(r.height()).max(1))
        });
        let moving = self.moving(Instant::now());
        let scale = self.scale(moving);
        let drawn = self.draw_view(screen, scale, &mut times);
        let presented = self.paint(screen, full, (repaint, scale), &mut times)?;
        times.frame = start.elapsed();
        times.scale = scale;
        if moving && self.view.motion_fps > 0.0 && matches!(drawn, Drawn::New(_)) {
            let target = Duration::from_secs_f32(1.0 / self.view.motion_fps);
            self.pace.scale.update(times.frame, target, self.view.motion_scale);
        }
        self.stats.record(times);
        if std::mem::take(&mut self.script.reset_stats) {
            self.stats.reset();
        }
        let now = Instant::now();
        let next = self.next_frame(screen, now, (moved, scale, repaint, presented));
        let at_once = self.script.scripted || next.is_some_and(|t| t <= now);
        self.pace.last_frame = Some((start, at_once));
        Ok(FrameEnd { next })
    }

    /// Lays the window out with egui: the UI reads the viewer's state and returns what it
    /// gathered, with egui's output to paint.
    pub(super) fn lay_out(&mut self, screen: &mut Screen) -> (UiOutput, egui::FullOutput) {
        let raw = screen.take_input();
        let raster_id = (screen.composition == Composition::Textured).then(|| self.raster.texture_id());
        // Listed again only when the settings or the scene's own change, not every frame.
        if (&self.remembered.changed.0, &self.remembered.changed.1) != (&self.settings, &self.scene.seed_settings) {
            let list = self.changed_settings().iter().map(|(key, value)| format!("{key} = {value}")).collect();
            self.remembered.changed = (self.settings.clone(), self.scene.seed_settings.clone(), list);
        }
        let mut output = UiOutput::default();
        // The page's lab editor edits the text out of the lab while the panel reads the rest.
        #[cfg(target_arch = "wasm32")]
        let mut editing =
            self.lab.as_mut().map(|lab| (lab.lab.file.clone(), std::mem::take(&mut lab.text), lab.problems().to_vec()));
        let mut model = UiModel {
            settings: &self.settings,
            scene: &mut self.scene,
            view: &mut self.view,
            navigation: &mut self.navigation,
            raster: raster_id,
            traced: &self.traced,
            key: self.traced.key,
            stats: &self.stats,
            passes: &self.raster.report.passes,
            camera_error: &mut self.notices.camera_error,
            notices: &self.notices.list,
            inspection: self.inspect.shown.as_ref(),
            probe: self.cursor.probe.shown(),
            seen: self.cursor.seen.shown(),
            lab: self.lab.as_ref().map(LabMode::panel),
            changed_settings: &self.remembered.changed.2,
            error_budget: self.error_budget.report.as_deref(),
            #[cfg(target_arch = "wasm32")]
            lab_editor: editing.as_mut().map(|(file, text, problems)| super::lab::LabEditor { file, text, problems }),
            #[cfg(not(target_arch = "wasm32"))]
            lab_editor: None,
        };
        let full = screen.egui.run_ui(raw, |ui| output = ui::draw(ui, &mut model));
        #[cfg(target_arch = "wasm32")]
        if let (Some((_, text, _)), Some(lab)) = (editing, self.lab.as_mut()) {
            lab.text = text;
            if output.lab_edited {
                lab.edited();
            }
        }
        (output, full)
    }

    /// Where the volume ray is probed: the script's cursor or the one the last layout saw, over
    /// the view as the last frame sized it.
    pub(super) fn probe_at(&self) -> Option<ProbeAt> {
        let (_, _, width, height) = self.view.pixels?;
        let pixel = self.view.scripted_cursor.or(self.cursor.at)?;
        Some(ProbeAt { pixel, size: (width, height) })
    }

    /// The raster image at the view's size (drawn at the render `scale`, unless nothing it depends
    /// on changed), the traced request for it, and the pixel to inspect once the view has a size.
    pub(super) fn draw_view(&mut self, screen: &mut Screen, scale: f32, times: &mut FrameTimes) -> Drawn {
        let Some((_, _, width, height)) = self.view.pixels else { return Drawn::Kept };
        // The camera's image size is the drawn one while the raster image is drawn, so the
        // rasterizer's work shrinks with the scale; the view's size otherwise (picking, pans).
        let scaled = |n: u32| ((n as f32 * scale).round() as u32).clamp(1, n);
        let drawn_size = (scaled(width), scaled(height));
        let filter = if drawn_size == (width, height) { wgpu::FilterMode::Nearest } else { wgpu::FilterMode::Linear };
        (self.scene.scene.camera.width, self.scene.scene.camera.height) = drawn_size;
        let scene = (&self.scene.scene, self.scene.revision);
        if let Some(lab) = &mut self.lab
            && lab.take_changed()
        {
            self.raster.set_wgsl(&screen.gpu, scene, lab.wgsl());
        }
        // The page's workers trace the hybrid's terms at every pixel (`raster_view::terms`).
        #[cfg(target_arch = "wasm32")]
        self.raster.take_terms(&screen.gpu, self.traced.worker.pool());
        // Each pass is timed on its own only for the overlay, which lists them.
        let drawn = self.raster.render(screen, scene, &self.settings, (self.view.overlay_open, filter));
        #[cfg(target_arch = "wasm32")]
        if let Some(pool) = self.traced.worker.pool() {
            let (scene, settings) = (&self.scene, &self.settings);
            let recipe = || super::traced::SceneRecipe::of(&scene.scene, &scene.overrides, settings);
            self.raster.give_terms(pool, recipe);
        }
        (self.scene.scene.camera.width, self.scene.scene.camera.height) = (width, height);
        if scale == 1.0
            && let Some(lab) = self.lab.as_mut().filter(|lab| lab.panel().shown == super::lab::LabShown::Difference)
        {
            let mut scene = self.scene.scene.clone();
            scene.settings = self.settings.clone();
            lab.update_difference(&screen.gpu, &screen.egui, &scene, self.scene.revision);
        }
        if let Drawn::New(time) = drawn {
            times.raster = Some(time);
        }
        self.request_traced((width, height), scale == 1.0 && !self.raster.refining(), screen);
        if let Some(pixel) = self.inspect.next.take() {
            self.inspect(screen, pixel, (width, height));
        }
        if std::mem::take(&mut self.error_budget.next) {
            self.measure_budget(screen, (width, height));
        }
        drawn
    }

    /// Composes and presents the window, writing the screenshot that is due; a screenshot the
    /// surface was not ready for is tried again next frame.
    pub(super) fn paint(
        &mut self,
        screen: &mut Screen,
        full: egui::FullOutput,
        (repaint, scale): (Option<Duration>, f32),
        times: &mut FrameTimes,
    ) -> anyhow::Result<Presented> {
        let paint_start = Instant::now();
        let screenshot = self.screenshot_due(repaint, scale);
        let view = match (self.raster.image(), self.view.pixels) {
            (Some((texture, plain)), Some((x, y, w, h))) => Some(ViewImage { texture, plain, rect: [x, y, w, h] }),
            _ => None,
        };
        let presented = screen.paint(full, view, screenshot.as_deref())?;
        // Nothing is drawn between frames, so waiting loses nothing, and the frame's time is then
        // the whole of it, the GPU's share included.
        screen.gpu.wait();
        times.paint = paint_start.elapsed();
        if let Some(path) = screenshot {
            match presented {
                Presented::Shown => {
                    let (x, y, w, h) = self.view.pixels.unwrap_or_default();
                    let (ww, wh) = screen.size();
                    println!("screenshot {} window {ww}x{wh} view {x} {y} {w} {h}", path.display());
                    self.notice(format!("screenshot written to {}", path.display()));
                }
                // Not drawn this time: try again next frame.
                Presented::Skipped => self.script.screenshot = Some(path),
            }
        }
        Ok(presented)
    }

    /// When the next frame is due: at once while the camera moves or the volume probe or the
    /// lat–long marker is behind the cursor; at the end of the settling time after a frame drawn below full scale (full
    /// scale again); when egui animates; soon after a frame the surface was not ready for; when
    /// the page's tracer workers' rows are next shown; else only when something happens.
    pub(super) fn next_frame(
        &self,
        screen: &Screen,
        now: Instant,
        (moved, scale, repaint, presented): (bool, f32, Option<Duration>, Presented),
    ) -> Option<Instant> {
        let settle = (scale < 1.0).then(|| self.pace.moving_until.map_or(now, |t| t.max(now)));
        let animation = repaint.filter(|d| *d < Duration::from_secs(3600)).map(|d| now + d);
        let retry = (presented == Presented::Skipped).then(|| now + RETRY);
        // In the browser the tracer works between frames ([`super::traced`]), readbacks arrive a
        // frame or two after they are asked for, and the hybrid's traced terms are refined frame
        // by frame while the camera rests.
        let busy = self.traced.worker.busy()
            || self.lab.as_ref().is_some_and(|lab| lab.checking() || lab.drawing())
            || self.raster.reading_back()
            || self.raster.refining()
            || screen.screenshots_pending();
        let working = busy.then_some(now);
        // The page's tracer workers: their rows so far are shown now and then.
        let traced = self.traced.worker.due();
        let at = self.probe_at();
        let behind = !self.cursor.probe.is_current(&self.scene, &self.settings, at)
            || !self.cursor.seen.is_current(&self.scene, &self.settings, at.map(|at| (at.pixel, at.size)));
        let at_once = (moved || behind).then_some(now);
        [at_once, settle, animation, retry, working, traced].into_iter().flatten().min()
    }

    /// Whether the camera moved within the last [`SETTLE`].
    pub(super) fn moving(&self, now: Instant) -> bool {
        self.pace.moving_until.is_some_and(|t| now < t)
    }

    /// The render scale of a frame: full when still; while moving, what the frame budget says
    /// within `[motion_scale, 1]`, or `motion_scale` when no frame rate is asked for.
    pub(super) fn scale(&self, moving: bool) -> f32 {
        match (moving, self.view.motion_fps > 0.0) {
            (false, _) => 1.0,
            (true, true) => self.pace.scale.scale(self.view.motion_scale),
            (true, false) => self.view.motion_scale,
        }
    }

    /// Applies what the UI gathered: camera input, edits, settings, picks and actions.
    pub(super) fn apply(&mut self, output: &UiOutput, scripted: CameraInput, now: Instant) {
        let mut input = output.camera;
        input.rotate += scripted.rotate;
        input.pan += scripted.pan;
        input.zoom += scripted.zoom;
        input.walk += scripted.walk;
        let before = self.scene.scene.camera.clone();
        if input.moves() {
            let size = self.scene.size();
            self.scene.scene.camera = camera_control::apply(&before, self.navigation, &input, size);
        }
        for action in &output.actions {
            match action {
                Action::Frame => self.frame_scene(),
                Action::Reset => self.reset_camera(),
                Action::Screenshot => {
                    let seconds =
                        web_time::SystemTime::now().duration_since(web_time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
                    self.script.screenshot = Some(PathBuf::from(format!("mirador-{seconds}.png")));
                }
                Action::DismissError => self.scene.error = None,
                Action::ResetSettings => self.reset_settings(),
                Action::Budget => self.error_budget.next = true,
            }
        }
        for assignment in &output.settings {
            self.set(assignment);
        }
        if output.material_edited {
            self.scene.touch();
        }
        if let Some(pixel) = output.pick {
            self.pick(pixel);
        }
        if let (Some(shown), Some(lab)) = (output.lab_shown, &mut self.lab) {
            lab.show(shown);
        }
        if let Some(lab) = self.lab.as_mut() {
            lab.check_next |= output.lab_check;
        }
        if self.scene.scene.camera != before || output.camera_edited {
            self.pace.moving_until = Some(now + SETTLE);
        }
    }

    pub(super) fn frame_scene(&mut self) {
        if let Some(bounds) = self.scene.bounds {
            self.scene.scene.camera = camera_control::frame_bounds(&self.scene.scene.camera, bounds);
        }
    }

    pub(super) fn reset_camera(&mut self) {
        let camera = &mut self.scene.scene.camera;
        *camera = Camera { width: camera.width, height: camera.height, ..self.scene.seed_camera.clone() };
        self.notices.camera_error = None;
    }

    /// Picks at `pixel` of the full-resolution image.
    pub(super) fn pick(&mut self, pixel: Vec2) {
        let Some((_, _, width, height)) = self.view.pixels else { return };
        let picked = self.scene.pick(pixel, (width, height));
        match picked.and_then(|p| self.scene.scene.objects.get(p.object)) {
            Some(object) => {
                let message = format!("picked `{}`", object.name);
                self.notice(message);
            }
            None => self.notice("nothing there to pick".into()),
        }
    }

    /// Starts (or keeps) the traced request for the current view at its full size; in the
    /// difference view, hands over the raster image once it is at full resolution.
    pub(super) fn request_traced(&mut self, full_size: (u32, u32), full_resolution: bool, screen: &Screen) {
        let mut camera = self.scene.scene.camera.clone();
        (camera.width, camera.height) = full_size;
        let inputs = (camera, self.settings.clone(), self.scene.revision, self.scene.scene.lights.clone());
        if self.traced.request.as_ref() != Some(&inputs) {
            self.traced.key += 1;
            self.traced.request = Some(inputs);
        }
        if !self.view.mode.needs_traced() {
            self.traced.worker.stop();
            return;
        }
        let (camera, settings, _, _) = self.traced.request.as_ref().expect("set just above");
        let mut scene = self.scene.scene.clone();
        scene.camera = camera.clone();
        self.traced.worker.trace(self.traced.key, &scene, &self.scene.overrides, settings);
        if self.view.mode == ViewMode::Difference
            && full_resolution
            && !self.traced.worker.compared(self.traced.key)
            && let Some(image) = self.raster.read_back(&screen.gpu)
        {
            self.traced.worker.compare(self.traced.key, image);
        }
    }
}
