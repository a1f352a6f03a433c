//! The interactive viewer (`mirador`, `mirador view [SCENE]`): a winit window with an egui side
//! panel, showing the rasterizer's image, the ray tracer's, both split by a divider, or their
//! FLIP difference, of a scene you can orbit, fly through, pick and edit.
//!
//! - [`frame`]: one frame, top to bottom, and the state it works on ([`frame::Viewer`]).
//! - [`screen`]: the window, the device and surface, egui's input and painter, the window's
//!   composition (the 3D view and the panel copied in, egui over them), screenshots.
//! - [`ui`]: the layout; [`panel`] the settings sections generated from `RenderSettings`;
//!   [`scene_panel`] the camera, light and material editors; [`hud`] frame times and help.
//! - [`camera_control`]: orbit, pan, zoom, fly and frame as pure functions on the camera.
//! - [`raster_view`]: the one place the rasterizer is called; [`traced`]: the background tracer;
//!   [`budget`]: the render scale while the camera moves; [`upscale`]: a moving frame stretched
//!   over the view.
//! - [`scene_state`] and [`picking`]: the scene, reloading, the picked object;
//!   [`volume_probe`]: the samples of the volume ray under the cursor; [`inspect`]: a pixel
//!   explained by both renderers, its ray tree drawn in 3D.
//! - [`config`]: what is remembered between runs; [`script`]: scripted steps for tests.
//!
//! This module holds the winit `ApplicationHandler`: it opens the window when the event loop
//! resumes, forwards events to egui, and asks for frames: on input, on the background tracer's
//! news, when a frame asks for the next one ([`frame::FrameEnd`]), and when the scene file
//! changed. In between it sleeps: a still window costs no CPU (the file is polled, not drawn).
//!
//! The window may go away in three ways, none of them a panic: closed (a close request: the
//! settings are remembered and the viewer exits), destroyed from outside (the `Destroyed` event:
//! the same, with a line saying so), or the display lost (Xlib prints its one line and exits).

mod budget;
mod camera_control;
pub(crate) mod config;
mod error_budget;
pub(crate) mod frame;
mod hud;
mod inspect;
mod kept;
pub(crate) mod lab;
mod lab_difference;
mod lab_frame;
mod panel;
mod picking;
mod raster_view;
mod scene_panel;
mod scene_settings;
pub(crate) mod scene_state;
pub(crate) mod screen;
pub mod script;
mod seen;
mod steps;
mod tools;
pub(crate) mod traced;
pub mod ui;
mod upscale;
mod view_mode;
mod volume_probe;

use std::path::PathBuf;
use web_time::Instant;

use anyhow::Context as _;
use winit::application::ApplicationHandler;
use winit::event::{StartCause, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::window::WindowId;

use config::ViewerConfig;
use frame::Viewer;
use screen::Screen;
use script::Step;

/// How the viewer was started.
#[derive(Clone, Debug, Default)]
pub struct ViewerOptions {
    /// A scene file or glTF model; the showcase when `None`.
    pub scene: Option<PathBuf>,
    /// `--set key=value` over the scene's settings.
    pub set: Vec<String>,
    /// Run this many frames, then exit (scripted runs).
    pub frames: Option<u64>,
    /// The window's image after the last frame.
    pub screenshot: Option<PathBuf>,
    pub steps: Vec<Step>,
    /// Print frame statistics at the end.
    pub stats: bool,
    /// The window's inner size in logical pixels (default: remembered, else 1280×720).
    pub size: Option<[u32; 2]>,
    /// Lab mode: the lab's folder (`mirador lab new`), its scene drawn with the student's file.
    pub lab: Option<PathBuf>,
}

impl ViewerOptions {
    /// Scripted runs neither read nor write the remembered configuration: a test must not
    /// depend on, or change, what a person last left in the window.
    fn scripted(&self) -> bool {
        self.frames.is_some()
    }

    /// Whether the remembered configuration is read and written: not by scripted runs, nor in
    /// lab mode, which starts from the lab's own scene and settings.
    fn remembers(&self) -> bool {
        !self.scripted() && self.lab.is_none()
    }
}

/// Why the viewer cannot start.
#[derive(Debug, thiserror::Error)]
pub(in crate::viewer) enum ViewerError {
    #[error(
        "no display to open a window on (DISPLAY and WAYLAND_DISPLAY are unset); `mirador render [SCENE] -o \
         out.png` renders without one"
    )]
    NoDisplay,
}

/// Runs the viewer until its window is closed (or, scripted, until its frames are done).
pub fn run(options: ViewerOptions) -> anyhow::Result<()> {
    let has_display = ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()));
    if !has_display {
        return Err(ViewerError::NoDisplay.into());
    }
    // Load before opening the window: a bad scene or setting on the command line is an error
    // message, not an empty window.
    // `--set` takes the scene's own values (`camera.fovy=30`) and render settings alike.
    let (values, settings): (Vec<String>, Vec<String>) =
        options.set.iter().cloned().partition(|a| crate::scene::file::overrides::is_scene_override(a));
    let (lab, scene) = match &options.lab {
        Some(dir) if values.is_empty() => {
            let (lab, scene) = open_lab(dir)?;
            (Some(lab), scene)
        }
        Some(_) => anyhow::bail!("--set {}: in lab mode the scene is the lab's; --set takes settings only", values[0]),
        None => (None, scene_state::load(options.scene.as_deref(), &values)?),
    };
    // Checked now, so that a bad one is an error before the window opens; applied once the
    // viewer has put back what it remembered of this scene, so the command line wins, and the
    // panel counts them as changes from the scene file's own.
    let mut checked = scene.settings.clone();
    for assignment in &settings {
        checked.set(assignment).context("--set")?;
    }
    let event_loop = EventLoop::<Wake>::with_user_event().build().map_err(|e| {
        log::info!("no event loop: {e}");
        ViewerError::NoDisplay
    })?;
    let proxy = event_loop.create_proxy();
    let mut app = App {
        options,
        settings,
        scene: Some(scene),
        overrides: values,
        lab,
        proxy,
        running: None,
        outcome: Ok(()),
        frames: 0,
        next_frame: None,
        finished: false,
        screenshot_asked: false,
    };
    event_loop.run_app(&mut app).context("the window's event loop failed")?;
    app.outcome
}

/// Sent by the background tracer when it has a new image.
#[derive(Clone, Copy, Debug)]
struct Wake;

struct App {
    options: ViewerOptions,
    /// The scene, until the window opens.
    scene: Option<crate::Scene>,
    /// Lab mode's state, until the window opens.
    lab: Option<lab::LabMode>,
    /// `--set`'s overrides of the scene's own values, kept by the scene for its reloads.
    overrides: Vec<String>,
    /// `--set`'s render settings, applied over what the viewer remembered.
    settings: Vec<String>,
    proxy: EventLoopProxy<Wake>,
    running: Option<(Screen, Viewer)>,
    outcome: anyhow::Result<()>,
    frames: u64,
    /// When the last frame asked for the next one.
    next_frame: Option<Instant>,
    finished: bool,
    /// Whether the run's `--screenshot` was asked for.
    screenshot_asked: bool,
}

impl App {
    fn config_path(&self) -> Option<PathBuf> {
        if self.options.remembers() { config::config_path() } else { None }
    }

    fn open(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        let mut config = ViewerConfig::default();
        let mut notices = Vec::new();
        if let Some(path) = self.config_path() {
            let (loaded, warning) = config::load(&path);
            config = loaded;
            if let Some(warning) = warning {
                eprintln!("warning: {warning}");
                notices.push(warning);
            }
        }
        let size = self.options.size.unwrap_or(config.window);
        let vsync = !self.options.scripted();
        let mut screen = Screen::open(event_loop, "Mirador", size, vsync)?;
        if let Some(reason) = self.lab.as_ref().and_then(|lab| lab.lab.refusal(screen.gpu.profile())) {
            anyhow::bail!(
                "{} draws with the WebGL2 profile, and this lab cannot run there: {reason}",
                screen.gpu.describe()
            );
        }
        let scene = self.scene.take().context("the window opens once")?;
        let proxy = self.proxy.clone();
        let wake = move || {
            let _ = proxy.send_event(Wake);
        };
        let mut viewer = Viewer::new(&mut screen, scene, &config, self.options.steps.clone(), wake, self.lab.take());
        viewer.notices.list.extend(notices);
        viewer.scene.overrides = std::mem::take(&mut self.overrides);
        viewer.apply_settings(&self.settings);
        viewer.script.scripted = self.options.scripted();
        if self.options.stats {
            println!("adapter: {}", screen.gpu.describe());
        }
        screen.window.request_redraw();
        self.running = Some((screen, viewer));
        Ok(())
    }

    /// Ends the run with `result` (the first error wins).
    fn finish(&mut self, event_loop: &ActiveEventLoop, result: anyhow::Result<()>) {
        if std::mem::replace(&mut self.finished, true) {
            return;
        }
        if let Err(e) = result
            && self.outcome.is_ok()
        {
            self.outcome = Err(e);
        }
        if let (Some(path), Some((screen, viewer))) = (self.config_path(), &self.running) {
            // The surface's size, not the window's: the window may already be gone.
            let (width, height) = screen.size();
            let size = winit::dpi::PhysicalSize::new(width, height).to_logical::<u32>(screen.window.scale_factor());
            if let Err(e) = config::save(&path, &viewer.remembered([size.width, size.height])) {
                eprintln!("warning: {}: cannot remember the viewer's settings: {e:#}", path.display());
            }
        }
        if self.options.stats
            && let Some((_, viewer)) = &self.running
        {
            if let Some((_, _, w, h)) = viewer.view.pixels {
                println!("3D view: {w}x{h} pixels");
            }
            println!("{}", viewer.stats.summary());
        }
        event_loop.exit();
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let Some((screen, viewer)) = &mut self.running else { return };
        if screen.is_minimised() {
            return;
        }
        let scripted = self.options.frames;
        // The run's screenshot, asked for once, at the last frame; the run ends when it is written.
        let due = scripted.is_some_and(|n| self.frames + 1 >= n) && viewer.script_done();
        if due
            && !self.screenshot_asked
            && let Some(path) = &self.options.screenshot
        {
            self.screenshot_asked = true;
            viewer.request_screenshot(path.clone());
        }
        let was_done = viewer.script_done();
        let result = viewer.frame(screen);
        self.frames += 1;
        let last = due && viewer.script_done();
        // Measure the state the script set up, not the steps getting there nor the first frames
        // (the driver compiles its pipelines lazily), unless a `measure` step said where.
        if !viewer.measured() && ((!was_done && viewer.script_done()) || (self.frames == 2 && viewer.script_done())) {
            viewer.stats.reset();
        }
        let result = result.and_then(|end| match screen.surface_failing() {
            Some(error) => Err(anyhow::anyhow!(error)),
            None => Ok(end),
        });
        match result {
            Err(e) => self.finish(event_loop, Err(e)),
            Ok(_) if last => self.finish(event_loop, Ok(())),
            Ok(_) if scripted.is_some() => screen.window.request_redraw(),
            Ok(end) => self.next_frame = end.next,
        }
    }
}

impl ApplicationHandler<Wake> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        if let Err(e) = self.open(event_loop) {
            self.finish(event_loop, Err(e));
        }
    }

    fn user_event(&mut self, _: &ActiveEventLoop, _: Wake) {
        if let Some((screen, _)) = &self.running {
            screen.window.request_redraw();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        // A window destroyed from outside (no close request first) can no longer be asked
        // anything: end before any handler looks at it.
        if matches!(event, WindowEvent::Destroyed) {
            if !self.finished {
                eprintln!("the window was destroyed (by the window system or another program); the viewer stops");
            }
            self.finish(event_loop, Ok(()));
            self.running = None;
            return;
        }
        let Some((screen, viewer)) = &mut self.running else { return };
        let response = screen.input.on_window_event(&screen.window, &event);
        match event {
            WindowEvent::CloseRequested => {
                self.finish(event_loop, Ok(()));
                return;
            }
            WindowEvent::Resized(size) => screen.resize(size),
            WindowEvent::DroppedFile(path) => viewer.open(&path),
            WindowEvent::RedrawRequested => {
                self.redraw(event_loop);
                return;
            }
            _ => {}
        }
        if response.repaint {
            screen.window.request_redraw();
        }
    }

    fn new_events(&mut self, _: &ActiveEventLoop, cause: StartCause) {
        if !matches!(cause, StartCause::ResumeTimeReached { .. }) {
            return;
        }
        let Some((screen, viewer)) = &mut self.running else { return };
        let now = Instant::now();
        if self.next_frame.is_some_and(|t| t <= now) {
            self.next_frame = None;
            screen.window.request_redraw();
        }
        if viewer.poll_file() {
            screen.window.request_redraw();
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        // Sleep until the frame asked for or the next look at the scene file, whichever is first.
        let Some((_, viewer)) = &self.running else { return };
        let wake = [self.next_frame, viewer.next_poll()].into_iter().flatten().min();
        event_loop.set_control_flow(wake.map_or(ControlFlow::Wait, ControlFlow::WaitUntil));
    }
}

/// The lab in `dir` and its scene (lab mode).
#[cfg(not(target_arch = "wasm32"))]
fn open_lab(dir: &std::path::Path) -> anyhow::Result<(lab::LabMode, crate::Scene)> {
    lab::LabMode::open(dir)
}

#[cfg(target_arch = "wasm32")]
fn open_lab(_: &std::path::Path) -> anyhow::Result<(lab::LabMode, crate::Scene)> {
    anyhow::bail!("the page has no lab mode yet")
}
