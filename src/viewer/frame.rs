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

use std::collections::{BTreeMap, VecDeque};
use std::path::{Path, PathBuf};
use std::time::Duration;

use web_time::Instant;

use anyhow::{Context as _, bail};
use glam::Vec2;

use super::budget::FrameBudget;
use super::camera_control::{self, CameraInput, Navigation};
use super::config::{ViewerConfig, scene_key};
use super::hud::{FrameStats, FrameTimes};
use super::inspect::Inspection;
use super::lab::LabMode;
use super::raster_view::{Drawn, RasterView};
use super::scene_panel;
use super::scene_state::SceneState;
use super::screen::{Composition, Presented, Screen, ViewImage};
use super::script::Step;
use super::seen::CursorDirection;
use super::traced::TracedView;
use super::ui::{self, Action, UiModel, UiOutput};
use super::view_mode::{ViewMode, ViewState};
use super::volume_probe::{CursorProbe, ProbeAt};
use crate::RenderSettings;
use crate::scene::{Camera, Light};
use crate::shaders::Wgsl;

/// How long the camera counts as moving after its last change: the render scale stays low.
const SETTLE: Duration = Duration::from_millis(250);
/// How soon a frame the surface was not ready for is tried again.
const RETRY: Duration = Duration::from_millis(50);
/// The longest a screenshot waits for egui's animations to end.
const SCREENSHOT_PATIENCE: Duration = Duration::from_secs(2);
/// The longest a `wait traced` step waits.
const TRACE_TIMEOUT: Duration = Duration::from_secs(600);

/// The widest view the panel's error budget is measured at: wider views are measured smaller.
#[cfg(not(target_arch = "wasm32"))]
const BUDGET_WIDTH: u32 = 480;

/// Everything the viewer holds, grouped by concern.
pub struct Viewer {
    pub scene: SceneState,
    pub settings: RenderSettings,
    pub navigation: Navigation,
    pub view: ViewState,
    raster: RasterView,
    traced: TracedView,
    budget: FrameBudget,
    pub stats: FrameStats,
    script: Script,
    camera_error: Option<String>,
    pub notices: Vec<String>,
    /// When the camera last moved plus [`SETTLE`].
    moving_until: Option<Instant>,
    /// When the last frame started, and whether it asked for the next one at once.
    last_frame: Option<(Instant, bool)>,
    /// A scripted run: every frame follows the last at once.
    pub scripted: bool,
    /// What the current traced request was made from, and its key.
    request: Option<(Camera, RenderSettings, u64, Vec<Light>)>,
    key: u64,
    /// The 3D view's size in pixels, and where it sits in the window.
    pub view_pixels: Option<(u32, u32, u32, u32)>,
    screenshot: Option<PathBuf>,
    /// Since when a screenshot has waited for egui's animations to end.
    screenshot_waiting: Option<Instant>,
    /// Print the volume ray under the cursor after this frame's UI (the `probe` step).
    print_probe: bool,
    /// The volume ray under the cursor, made before the UI, and the cursor the last UI saw.
    probe: CursorProbe,
    /// The direction the environment is seen in under the cursor (the lat–long view's marker).
    seen: CursorDirection,
    cursor: Option<Vec2>,
    /// The inspected pixel, and a pixel to inspect once the view has its size.
    inspection: Option<Inspection>,
    inspect_next: Option<Vec2>,
    /// The last error budget measured, and whether one is due once the view has its size.
    error_budget: Option<String>,
    budget_next: bool,
    /// Lab mode (`mirador view --lab DIR`): the student's functions drawn, reloaded when saved.
    pub lab: Option<LabMode>,
    /// A check of the lab asked for (the step `lab check`), started where the frame has the GPU.
    lab_check_next: bool,
    /// The last finished check's `results.json`, until the page takes it.
    pub lab_results: Option<String>,
    /// What the device's shaders may use (the page's labs need it).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    profile: crate::shaders::Profile,
    /// The settings changed in each scene opened before (`super::config`), by scene key.
    remembered: BTreeMap<String, toml::Table>,
    /// The settings and the scene's own the panel's list of changed settings was made from, and
    /// the list.
    changed: (RenderSettings, RenderSettings, Vec<String>),
}

/// Scripted steps still to run and the wait in progress.
#[derive(Default)]
struct Script {
    steps: VecDeque<Step>,
    wait_frames: u32,
    /// A `wait 2s` step's end.
    wait_until: Option<Instant>,
    wait_traced_since: Option<Instant>,
    /// A `wait checked` step's start.
    wait_checked_since: Option<Instant>,
    /// A `measure` step ran: the stats start where it said, not after the last step.
    measured: bool,
    /// Start the stats again after this frame.
    reset_stats: bool,
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
     to inspect it needs storage buffers, which WebGL2 lacks (WebGPU or Vulkan have them)";

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
        let profile = screen.gpu.profile();
        if profile == crate::shaders::Profile::WebGl2 {
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
            budget: FrameBudget::default(),
            stats: FrameStats::default(),
            script: Script { steps: steps.into(), ..Default::default() },
            camera_error: None,
            notices: warnings,
            moving_until: None,
            last_frame: None,
            scripted: false,
            request: None,
            key: 0,
            view_pixels: None,
            screenshot: None,
            screenshot_waiting: None,
            print_probe: false,
            probe: CursorProbe::default(),
            seen: CursorDirection::default(),
            cursor: None,
            inspection: None,
            inspect_next: None,
            error_budget: None,
            budget_next: false,
            lab,
            lab_check_next: false,
            lab_results: None,
            profile,
            remembered,
            changed: Default::default(),
        }
    }

    /// Whether every scripted step has run and every screenshot asked for is written.
    pub fn script_done(&self) -> bool {
        self.script.steps.is_empty()
            && self.script.wait_frames == 0
            && self.script.wait_until.is_none()
            && self.script.wait_traced_since.is_none()
            && self.script.wait_checked_since.is_none()
            && self.screenshot.is_none()
    }

    /// Starts the page's tracer workers, so that they are ready before the first traced view.
    #[cfg(target_arch = "wasm32")]
    pub fn start_tracer_workers(&mut self) {
        self.traced.worker.start_workers();
    }

    /// When the script needs its next frame (the page asks for no more than that): at once while
    /// steps or waited frames are left, a screenshot is due or a lab's check runs; at a timed
    /// wait's end; for `wait traced`, at once when it ends or fails at the next frame or the
    /// difference view still needs its raster image read back, else at its timeout (the tracer
    /// wakes the window sooner); `None` once the script is done.
    pub fn script_next(&self, now: Instant) -> Option<Instant> {
        let script = &self.script;
        if self.script_done() {
            return None;
        }
        if self.screenshot.is_some() || script.wait_frames > 0 || script.wait_checked_since.is_some() {
            return Some(now);
        }
        if let Some(until) = script.wait_until {
            return Some(until.max(now));
        }
        if let Some(since) = script.wait_traced_since {
            let reading = self.view.mode == ViewMode::Difference && !self.traced.worker.compared(self.key);
            let at_once = self.traced_waited() || !self.view.mode.needs_traced() || reading;
            return Some(if at_once { now } else { since + TRACE_TIMEOUT });
        }
        Some(now)
    }

    /// Queues more steps, run one a frame after those already queued (the browser's page sends
    /// them, `src/web/`).
    pub fn push_steps(&mut self, steps: impl IntoIterator<Item = Step>) {
        self.script.steps.extend(steps);
    }

    /// Whether a `measure` step said where the stats start.
    pub fn measured(&self) -> bool {
        self.script.measured
    }

    /// Reloads the scene when its file changed on disk (polled between frames, without drawing
    /// one); returns whether it did, so the window is drawn again.
    pub fn poll_file(&mut self) -> bool {
        let reloaded = self.scene.reload_if_changed(&self.settings);
        if reloaded {
            let what = if self.scene.error.is_some() { "it does not load; the last scene is kept" } else { "reloaded" };
            self.notice(format!("scene file changed on disk: {what}"));
        }
        let lab = self.lab.as_mut().is_some_and(LabMode::poll);
        reloaded || lab
    }

    /// When the scene file, or the lab's file, is next due a look.
    pub fn next_poll(&self) -> Option<Instant> {
        [self.scene.next_poll(), self.lab.as_ref().map(LabMode::next_poll)].into_iter().flatten().min()
    }

    /// What the configuration file should remember now.
    pub fn remembered(&self, window: [u32; 2]) -> ViewerConfig {
        ViewerConfig {
            window,
            mode: self.view.mode,
            split: self.view.split,
            motion_fps: self.view.motion_fps,
            motion_scale: self.view.motion_scale,
            scenes: self.remembered_scenes(),
        }
    }

    /// The settings changed in every scene, this one's as they are now.
    fn remembered_scenes(&self) -> BTreeMap<String, toml::Table> {
        let mut scenes = self.remembered.clone();
        let key = scene_key(self.scene.scene.source.as_deref());
        let changes = self.changed_settings();
        if changes.is_empty() {
            scenes.remove(&key);
        } else {
            scenes.insert(key, changes);
        }
        scenes
    }

    /// The settings that differ from the scene file's own.
    pub fn changed_settings(&self) -> toml::Table {
        super::config::changed_settings(&self.settings, &self.scene.seed_settings)
    }

    /// Opens a scene file (dropped, or from a script) with its own settings and what was changed
    /// in it before: nothing set in the scene left behind comes along.
    pub fn open(&mut self, path: &Path) {
        self.remembered = self.remembered_scenes();
        // Overrides belong to the scene they were set in.
        let overrides = std::mem::take(&mut self.scene.overrides);
        if self.scene.load(path, None) {
            self.camera_error = None;
            let changes = self.remembered.get(&scene_key(Some(path))).cloned().unwrap_or_default();
            let (settings, warnings) = super::config::apply_settings(&self.scene.seed_settings, &changes);
            self.settings = settings;
            self.scene.scene.settings = self.settings.clone();
            for warning in warnings {
                self.notice(warning);
            }
            let kept = if changes.is_empty() {
                String::new()
            } else {
                format!(" ({} settings as you left them)", changes.len())
            };
            self.notice(format!("opened {}{kept}", path.display()));
        } else {
            self.scene.overrides = overrides;
        }
    }

    /// Opens the built-in lab `name` (the page's lab menu): its scene, with the settings its
    /// first image test sets, drawn with the stub's functions until the student's text compiles.
    #[cfg(target_arch = "wasm32")]
    pub fn open_lab(&mut self, name: &str) {
        match LabMode::open(name, self.profile) {
            Ok((lab, scene)) => {
                let settings = scene.settings.clone();
                // The lab's scene is its own: no overrides of the scene it replaces.
                self.scene.overrides.clear();
                self.scene.replace(scene, &settings);
                self.settings = settings;
                self.notice(format!("lab {name}: {}; write its functions in the editor", lab.lab.title));
                self.lab = Some(lab);
            }
            Err(e) => self.notice(format!("lab {name}: {e:#}")),
        }
    }

    /// The step `lab student|reference|difference`.
    fn lab_step(&mut self, shown: super::lab::LabShown) -> anyhow::Result<()> {
        match &mut self.lab {
            Some(lab) => lab.show(shown),
            None => bail!("`lab {}`: the viewer is not in lab mode (mirador view --lab DIR)", shown.label()),
        }
        Ok(())
    }

    /// One step of the lab's check under way, started first when the panel's Check button or the
    /// step `lab check` asked for one. A finished check's summary is printed, and its
    /// `results.json` kept for the page's download.
    fn advance_lab_check(&mut self, screen: &Screen) {
        if let Some(lab) = self.lab.as_mut().filter(|_| std::mem::take(&mut self.lab_check_next)) {
            lab.start_check(&screen.gpu);
            let name = lab.lab.name.clone();
            self.notice(format!("lab {name}: checking"));
        }
        let ctx = &screen.egui;
        let Some(checking) = self.lab.as_mut().and_then(|lab| lab.checking.as_mut()) else { return };
        checking.advance(ctx);
        if let Some(report) = checking.take_finished() {
            print!("{}", crate::lab::report::text(&report));
            self.lab_results = Some(crate::lab::report::results_json(&report));
            let summary = format!(
                "lab {}: {} / {} points",
                report.lab.name,
                crate::lab::report::points(report.score()),
                crate::lab::report::points(report.max_score())
            );
            self.notice(summary);
        }
    }

    /// The step `lab open NAME`: the page's lab menu.
    #[cfg(target_arch = "wasm32")]
    fn lab_open_step(&mut self, name: &str) -> anyhow::Result<()> {
        self.open_lab(name);
        Ok(())
    }

    /// The step `lab open NAME`, which natively has no lab to open without a folder.
    #[cfg(not(target_arch = "wasm32"))]
    fn lab_open_step(&mut self, name: &str) -> anyhow::Result<()> {
        bail!("`lab open {name}` is the page's; natively: mirador lab new {name} DIR, then mirador view --lab DIR")
    }

    /// The page's lab: the editor's text replaced (a file the student opened), checked at once.
    #[cfg(target_arch = "wasm32")]
    pub fn set_lab_text(&mut self, text: String) {
        match self.lab.as_mut() {
            Some(lab) => lab.replace_text(text),
            None => self.notice("no lab is open: choose one first".into()),
        }
    }

    /// The page's lab: its file's name and the editor's text, for the page's download.
    #[cfg(target_arch = "wasm32")]
    pub fn lab_file(&self) -> Option<(String, String)> {
        self.lab.as_ref().map(|lab| (lab.lab.file.clone(), lab.text.clone()))
    }

    /// Every setting back to the scene file's own.
    fn reset_settings(&mut self) {
        if self.settings.sphere_segments != self.scene.seed_settings.sphere_segments {
            self.scene.touch();
        }
        let before = std::mem::replace(&mut self.settings, self.scene.seed_settings.clone());
        self.redisplace(&before);
        self.scene.scene.settings = self.settings.clone();
        self.notice("settings reset to the scene's own".into());
    }

    /// Makes the scene again from its file when the settings changed from `before` in what the
    /// displaced geometry is made of (`bump.method = "displacement"`, its scale and tessellation).
    fn redisplace(&mut self, before: &RenderSettings) {
        if !SceneState::displacement_changed(before, &self.settings) {
            return;
        }
        let size = (self.scene.scene.camera.width, self.scene.scene.camera.height);
        let camera = self.scene.scene.camera.clone();
        match self.scene.scene.source.clone() {
            Some(path) if self.scene.load(&path, Some(&self.settings)) => {
                self.scene.scene.camera = Camera { width: size.0, height: size.1, ..camera };
            }
            Some(_) => self.notice("the scene could not be made again for displacement".into()),
            None => self.notice("displacement is made from the scene's file, and this scene has none".into()),
        }
    }

    fn notice(&mut self, message: String) {
        log::info!("{message}");
        self.notices.push(message);
        if self.notices.len() > 20 {
            self.notices.remove(0);
        }
    }

    /// Asks for a screenshot of the window at the end of this frame.
    pub fn request_screenshot(&mut self, path: PathBuf) {
        self.screenshot = Some(path);
    }

    /// Draws one frame.
    pub fn frame(&mut self, screen: &mut Screen) -> anyhow::Result<FrameEnd> {
        let start = Instant::now();
        let interval = self.last_frame.filter(|(_, at_once)| *at_once).map(|(t, _)| start - t);
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
        self.probe.update(&mut self.scene, &self.settings, probe_at);
        self.seen.update(&mut self.scene, &self.settings, probe_at.map(|at| (at.pixel, at.size)));

        // The UI decides the 3D view's size and gathers input.
        let ui_start = Instant::now();
        let (output, full) = self.lay_out(screen);
        times.ui = ui_start.elapsed();
        if std::mem::take(&mut self.print_probe) {
            println!("{}", self.probe.probe().map_or("volume probe none".to_string(), |p| p.report()));
        }
        let repaint = full.viewport_output.get(&egui::ViewportId::ROOT).map(|v| v.repaint_delay);
        if output.inspection_closed {
            self.inspection = None;
        }
        self.inspect_next = output.inspect.or(self.inspect_next);
        self.cursor = output.cursor;
        self.apply(&output, input, start);
        // Compared without the image size, which the frame sets below.
        let camera = &self.scene.scene.camera;
        let moved =
            Camera { width: camera_before.width, height: camera_before.height, ..camera.clone() } != camera_before;

        // The raster image at the view's size, drawn at the render scale.
        let ppp = full.pixels_per_point;
        self.view_pixels = output.view_rect.map(|r| {
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
            self.budget.update(times.frame, target, self.view.motion_scale);
        }
        self.stats.record(times);
        if std::mem::take(&mut self.script.reset_stats) {
            self.stats.reset();
        }
        let now = Instant::now();
        let next = self.next_frame(screen, now, (moved, scale, repaint, presented));
        let at_once = self.scripted || next.is_some_and(|t| t <= now);
        self.last_frame = Some((start, at_once));
        Ok(FrameEnd { next })
    }

    /// Lays the window out with egui: the UI reads the viewer's state and returns what it
    /// gathered, with egui's output to paint.
    fn lay_out(&mut self, screen: &mut Screen) -> (UiOutput, egui::FullOutput) {
        let raw = screen.take_input();
        let raster_id = (screen.composition == Composition::Textured).then(|| self.raster.texture_id());
        // Listed again only when the settings or the scene's own change, not every frame.
        if (&self.changed.0, &self.changed.1) != (&self.settings, &self.scene.seed_settings) {
            let list = self.changed_settings().iter().map(|(key, value)| format!("{key} = {value}")).collect();
            self.changed = (self.settings.clone(), self.scene.seed_settings.clone(), list);
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
            key: self.key,
            stats: &self.stats,
            passes: &self.raster.report.passes,
            camera_error: &mut self.camera_error,
            notices: &self.notices,
            inspection: self.inspection.as_ref(),
            probe: self.probe.shown(),
            seen: self.seen.shown(),
            lab: self.lab.as_ref().map(LabMode::panel),
            changed_settings: &self.changed.2,
            error_budget: self.error_budget.as_deref(),
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
    fn probe_at(&self) -> Option<ProbeAt> {
        let (_, _, width, height) = self.view_pixels?;
        let pixel = self.view.scripted_cursor.or(self.cursor)?;
        Some(ProbeAt { pixel, size: (width, height) })
    }

    /// The raster image at the view's size (drawn at the render `scale`, unless nothing it depends
    /// on changed), the traced request for it, and the pixel to inspect once the view has a size.
    fn draw_view(&mut self, screen: &mut Screen, scale: f32, times: &mut FrameTimes) -> Drawn {
        let Some((_, _, width, height)) = self.view_pixels else { return Drawn::Kept };
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
        // Each pass is timed on its own only for the overlay, which lists them.
        let drawn = self.raster.render(screen, scene, &self.settings, (self.view.overlay_open, filter));
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
        if let Some(pixel) = self.inspect_next.take() {
            self.inspect(screen, pixel, (width, height));
        }
        if std::mem::take(&mut self.budget_next) {
            self.measure_budget(screen, (width, height));
        }
        drawn
    }

    /// Composes and presents the window, writing the screenshot that is due; a screenshot the
    /// surface was not ready for is tried again next frame.
    fn paint(
        &mut self,
        screen: &mut Screen,
        full: egui::FullOutput,
        (repaint, scale): (Option<Duration>, f32),
        times: &mut FrameTimes,
    ) -> anyhow::Result<Presented> {
        let paint_start = Instant::now();
        let screenshot = self.screenshot_due(repaint, scale);
        let view = match (self.raster.image(), self.view_pixels) {
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
                    let (x, y, w, h) = self.view_pixels.unwrap_or_default();
                    let (ww, wh) = screen.size();
                    println!("screenshot {} window {ww}x{wh} view {x} {y} {w} {h}", path.display());
                    self.notice(format!("screenshot written to {}", path.display()));
                }
                // Not drawn this time: try again next frame.
                Presented::Skipped => self.screenshot = Some(path),
            }
        }
        Ok(presented)
    }

    /// When the next frame is due: at once while the camera moves or the volume probe or the
    /// lat–long marker is behind the cursor; at the end of the settling time after a frame drawn below full scale (full
    /// scale again); when egui animates; soon after a frame the surface was not ready for; when
    /// the page's tracer workers' rows are next shown; else only when something happens.
    fn next_frame(
        &self,
        screen: &Screen,
        now: Instant,
        (moved, scale, repaint, presented): (bool, f32, Option<Duration>, Presented),
    ) -> Option<Instant> {
        let settle = (scale < 1.0).then(|| self.moving_until.map_or(now, |t| t.max(now)));
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
        let behind = !self.probe.is_current(&self.scene, &self.settings, at)
            || !self.seen.is_current(&self.scene, &self.settings, at.map(|at| (at.pixel, at.size)));
        let at_once = (moved || behind).then_some(now);
        [at_once, settle, animation, retry, working, traced].into_iter().flatten().min()
    }

    /// The screenshot to write this frame: the one asked for, unless egui is animating (a window
    /// fading in, a section opening) or the view was drawn below full scale (the camera just
    /// moved), when it waits for the animation to end and the full-scale image, up to
    /// [`SCREENSHOT_PATIENCE`]. The scripted steps wait with it, so it shows the state the steps
    /// before it set up.
    fn screenshot_due(&mut self, repaint: Option<Duration>, scale: f32) -> Option<PathBuf> {
        self.screenshot.as_ref()?;
        let since = *self.screenshot_waiting.get_or_insert_with(Instant::now);
        let animating = repaint.is_some_and(|delay| delay.is_zero());
        if (animating || scale < 1.0 || self.raster.refining()) && since.elapsed() < SCREENSHOT_PATIENCE {
            return None;
        }
        self.screenshot_waiting = None;
        self.screenshot.take()
    }

    /// Whether the camera moved within the last [`SETTLE`].
    fn moving(&self, now: Instant) -> bool {
        self.moving_until.is_some_and(|t| now < t)
    }

    /// The render scale of a frame: full when still; while moving, what the frame budget says
    /// within `[motion_scale, 1]`, or `motion_scale` when no frame rate is asked for.
    fn scale(&self, moving: bool) -> f32 {
        match (moving, self.view.motion_fps > 0.0) {
            (false, _) => 1.0,
            (true, true) => self.budget.scale(self.view.motion_scale),
            (true, false) => self.view.motion_scale,
        }
    }

    /// Applies what the UI gathered: camera input, edits, settings, picks and actions.
    fn apply(&mut self, output: &UiOutput, scripted: CameraInput, now: Instant) {
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
                    self.screenshot = Some(PathBuf::from(format!("mirador-{seconds}.png")));
                }
                Action::DismissError => self.scene.error = None,
                Action::ResetSettings => self.reset_settings(),
                Action::Budget => self.budget_next = true,
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
        self.lab_check_next |= output.lab_check;
        if self.scene.scene.camera != before || output.camera_edited {
            self.moving_until = Some(now + SETTLE);
        }
    }

    /// Applies render settings given on the command line (checked already).
    pub fn apply_settings(&mut self, assignments: &[String]) {
        for assignment in assignments {
            self.set(assignment);
        }
    }

    fn set(&mut self, assignment: &str) {
        if crate::scene::file::overrides::is_scene_override(assignment) {
            // The camera keeps the view's size, which the file does not know.
            let size = (self.scene.scene.camera.width, self.scene.scene.camera.height);
            if self.scene.set_value(assignment, &self.settings) {
                (self.scene.scene.camera.width, self.scene.scene.camera.height) = size;
                self.notice(format!("scene value set: {assignment}"));
            }
            return;
        }
        let before = self.settings.clone();
        match self.settings.set(assignment) {
            Ok(()) => {
                if self.settings.sphere_segments != self.scene.scene.settings.sphere_segments {
                    self.scene.touch();
                }
                self.scene.scene.settings = self.settings.clone();
                self.redisplace(&before);
            }
            Err(e) => self.notice(format!("setting refused: {e}")),
        }
    }

    fn frame_scene(&mut self) {
        if let Some(bounds) = self.scene.bounds {
            self.scene.scene.camera = camera_control::frame_bounds(&self.scene.scene.camera, bounds);
        }
    }

    fn reset_camera(&mut self) {
        let camera = &mut self.scene.scene.camera;
        *camera = Camera { width: camera.width, height: camera.height, ..self.scene.seed_camera.clone() };
        self.camera_error = None;
    }

    /// Picks at `pixel` of the full-resolution image.
    fn pick(&mut self, pixel: Vec2) {
        let Some((_, _, width, height)) = self.view_pixels else { return };
        let picked = self.scene.pick(pixel, (width, height));
        match picked.and_then(|p| self.scene.scene.objects.get(p.object)) {
            Some(object) => {
                let message = format!("picked `{}`", object.name);
                self.notice(message);
            }
            None => self.notice("nothing there to pick".into()),
        }
    }

    /// Explains `pixel` of the full-resolution view of `size` in both renderers.
    fn inspect(&mut self, screen: &Screen, pixel: Vec2, size: (u32, u32)) {
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
                self.inspection = Some(inspection);
            }
            Err(e) => self.notice(format!("cannot inspect ({}, {}): {e:#}", at.0, at.1)),
        }
    }

    /// Measures the error budget of the view of `size` as it is, at most [`BUDGET_WIDTH`] pixels
    /// wide (it draws the view ten times or so and traces it once, while the window waits).
    #[cfg(not(target_arch = "wasm32"))]
    fn measure_budget(&mut self, screen: &Screen, size: (u32, u32)) {
        let mut scene = self.scene.scene.clone();
        let width = size.0.min(BUDGET_WIDTH);
        (scene.camera.width, scene.camera.height) = (width, (size.1 * width).div_ceil(size.0.max(1)).max(1));
        let traced = crate::trace::render_image(&scene, &self.settings);
        let measured = screen.gpu.checked(|| crate::budget::budget(&screen.gpu, &scene, &self.settings, traced));
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
        self.error_budget = Some(report);
    }

    /// The page measures no budget: `mirador budget` does, natively.
    #[cfg(target_arch = "wasm32")]
    fn measure_budget(&mut self, _: &Screen, _: (u32, u32)) {
        self.notice("the error budget is measured natively: `mirador budget SCENE`".into());
    }

    /// Starts (or keeps) the traced request for the current view at its full size; in the
    /// difference view, hands over the raster image once it is at full resolution.
    fn request_traced(&mut self, full_size: (u32, u32), full_resolution: bool, screen: &Screen) {
        let mut camera = self.scene.scene.camera.clone();
        (camera.width, camera.height) = full_size;
        let inputs = (camera, self.settings.clone(), self.scene.revision, self.scene.scene.lights.clone());
        if self.request.as_ref() != Some(&inputs) {
            self.key += 1;
            self.request = Some(inputs);
        }
        if !self.view.mode.needs_traced() {
            self.traced.worker.stop();
            return;
        }
        let (camera, settings, _, _) = self.request.as_ref().expect("set just above");
        let mut scene = self.scene.scene.clone();
        scene.camera = camera.clone();
        self.traced.worker.trace(self.key, &scene, &self.scene.overrides, settings);
        if self.view.mode == ViewMode::Difference
            && full_resolution
            && !self.traced.worker.compared(self.key)
            && let Some(image) = self.raster.read_back(&screen.gpu)
        {
            self.traced.worker.compare(self.key, image);
        }
    }

    /// Whether a scripted wait (frames, time, the traced image, the lab's check) goes on this
    /// frame; a wait that can never end is an error.
    fn script_waits(&mut self) -> anyhow::Result<bool> {
        if self.screenshot.is_some() {
            return Ok(true);
        }
        if self.script.wait_frames > 0 {
            self.script.wait_frames -= 1;
            return Ok(true);
        }
        if let Some(until) = self.script.wait_until {
            if Instant::now() < until {
                return Ok(true);
            }
            self.script.wait_until = None;
        }
        if let Some(since) = self.script.wait_checked_since {
            if !self.lab.as_ref().is_some_and(|lab| lab.checking()) {
                self.script.wait_checked_since = None;
            } else if since.elapsed() > TRACE_TIMEOUT {
                bail!("`wait checked`: the lab's check had not finished after {} s", TRACE_TIMEOUT.as_secs());
            } else {
                return Ok(true);
            }
        }
        if let Some(since) = self.script.wait_traced_since {
            if self.traced_waited() {
                self.script.wait_traced_since = None;
            } else if since.elapsed() > TRACE_TIMEOUT {
                bail!("`wait traced`: the traced image was not complete after {} s", TRACE_TIMEOUT.as_secs());
            } else if !self.view.mode.needs_traced() {
                bail!("`wait traced` in the raster view: switch to traced, split or difference first");
            } else {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Whether what `wait traced` waits for is there: the traced image of the current request,
    /// complete, and in the difference view its FLIP map.
    fn traced_waited(&self) -> bool {
        let difference = self.view.mode == ViewMode::Difference;
        self.request.is_some() && self.traced.complete(self.key, difference)
    }

    /// Runs the next scripted step, or goes on waiting.
    fn run_script(&mut self, input: &mut CameraInput) -> anyhow::Result<()> {
        if self.script_waits()? {
            return Ok(());
        }
        let Some(step) = self.script.steps.pop_front() else { return Ok(()) };
        log::info!("step: {step:?}");
        match step {
            Step::Set(assignment) if crate::scene::file::overrides::is_scene_override(&assignment) => {
                self.set(&assignment);
                if let Some(error) = self.scene.error.take() {
                    bail!("step `set {assignment}`: {error}");
                }
            }
            Step::Set(assignment) => {
                // Checked on a copy first: a refused setting ends the script.
                self.settings.clone().set(&assignment).with_context(|| format!("step `set {assignment}`"))?;
                self.set(&assignment);
            }
            Step::View(mode) => self.view.mode = mode,
            Step::Split(x) => self.view.split = x,
            Step::Orbit(v) => input.rotate += v,
            Step::Pan(v) => input.pan += v,
            Step::Zoom(steps) => input.zoom += steps,
            Step::Walk(v) => {
                let camera = &self.scene.scene.camera;
                self.scene.scene.camera = camera_control::fly(camera, v);
                self.moving_until = Some(Instant::now() + SETTLE);
            }
            Step::Frame => self.frame_scene(),
            Step::Reset => self.reset_camera(),
            Step::ResetSettings => self.reset_settings(),
            Step::Navigate(navigation) => self.navigation = navigation,
            Step::Pick(pixel) if self.view_pixels.is_none() => {
                // The view has no size before its first frame: pick on the next one.
                self.script.steps.push_front(Step::Pick(pixel));
            }
            Step::Pick(pixel) => {
                self.pick(pixel);
                if self.scene.picked.is_none() {
                    bail!("step `pick {} {}`: no object under that pixel", pixel.x, pixel.y);
                }
            }
            Step::Material(assignment) => {
                let picked = self.scene.picked.context("step `material`: pick an object first")?;
                let material = &mut self.scene.scene.materials[picked.material];
                scene_panel::set_material(material, &assignment)
                    .map_err(|e| anyhow::anyhow!("step `material {assignment}`: {e}"))?;
                self.scene.touch();
            }
            Step::Load(path) => self.open(&path),
            Step::Scale(scale) => self.view.motion_scale = scale,
            Step::Fps(fps) => self.view.motion_fps = fps,
            Step::Budget => self.budget_next = true,
            Step::Measure => {
                self.script.measured = true;
                self.script.reset_stats = true;
            }
            Step::Help(on) => self.view.help_open = on,
            Step::Panel(on) => self.view.panel_open = on,
            Step::Overlay(on) => self.view.overlay_open = on,
            Step::Cursor(pixel) => self.view.scripted_cursor = Some(pixel),
            Step::Inspect(pixel) => self.inspect_next = Some(pixel),
            Step::Probe => self.print_probe = true,
            Step::Wait(frames) => self.script.wait_frames = frames,
            Step::WaitFor(time) => self.script.wait_until = Some(Instant::now() + time),
            Step::WaitTraced => self.script.wait_traced_since = Some(Instant::now()),
            Step::Screenshot(path) => self.screenshot = Some(path),
            Step::Lab(shown) => self.lab_step(shown)?,
            Step::LabOpen(name) => self.lab_open_step(&name)?,
            Step::LabCheck if self.lab.is_none() => bail!("`lab check`: the viewer is not in lab mode"),
            Step::LabCheck => self.lab_check_next = true,
            Step::WaitChecked => self.script.wait_checked_since = Some(Instant::now()),
        }
        Ok(())
    }
}
