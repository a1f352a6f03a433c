//! Mirador in the browser: the viewer of [`crate::viewer`] on the page's canvas, WebGPU through
//! wgpu, built by `web/build.sh` for `wasm32-unknown-unknown` (web/README.md).
//!
//! The viewer's frame, panel, techniques and view modes are the native ones. What the browser
//! changes, and where:
//! - The device is asked for asynchronously ([`crate::gpu::Gpu::for_window_async`]): the page
//!   opens its canvas, and the viewer starts when the device arrives ([`App::user_event`]).
//! - Readbacks arrive a frame or two later ([`crate::gpu::readback::Pending`]): the difference
//!   view's raster image and screenshots.
//! - The tracer works in Web Workers, one a core, started after the first frame, with a coarse
//!   level in slices between frames on the page's thread, and every row there where workers
//!   cannot run (`crate::viewer::traced`).
//! - Files come from memory ([`crate::files`]): the built-in assets, and the files the page hands
//!   over ([`page`]). The difference view shows FLIP, as natively (`flip-rs`, pure Rust).
//! - No configuration file is remembered, and the scene is not watched for changes.

mod page;
pub mod tracer;

use std::cell::RefCell;
use std::rc::Rc;
use std::sync::Arc;

use wasm_bindgen::prelude::*;
use web_time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{StartCause, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::platform::web::{EventLoopExtWebSys, WindowAttributesExtWebSys};
use winit::window::{Window, WindowId};

use crate::gpu::{Gpu, GpuError};
use crate::viewer::config::ViewerConfig;
use crate::viewer::frame::Viewer;
use crate::viewer::screen::Screen;

/// What wakes the page's event loop besides input.
#[derive(Clone, Copy, Debug)]
enum Wake {
    /// The device asked for at start has answered.
    Device,
    /// The page queued steps ([`page::step`]).
    Steps,
    /// The tracer's workers have the traced image, or failed (`crate::viewer::traced`).
    Traced,
}

/// The device and the canvas's surface, or why there is none, once the browser answers.
type DeviceAnswer = Rc<RefCell<Option<Result<(Gpu, wgpu::Surface<'static>), GpuError>>>>;

/// Starts the viewer on the page's `<canvas id="mirador">`; called once the module is loaded.
#[wasm_bindgen(start)]
pub fn start() {
    std::panic::set_hook(Box::new(|info| {
        let message = format!("Mirador stopped: {info}");
        web_sys::console::error_1(&message.as_str().into());
        page::show_error(&message);
    }));
    let _ = log::set_logger(&page::CONSOLE).map(|()| log::set_max_level(log::LevelFilter::Info));
    for (path, bytes) in crate::files::builtin_bytes() {
        crate::files::add(std::path::Path::new(path), bytes.to_vec());
    }
    // A tracer worker (web/tracer.js) has no window: it traces, and draws nothing.
    if web_sys::window().is_none() {
        return;
    }
    let event_loop = match EventLoop::<Wake>::with_user_event().build() {
        Ok(event_loop) => event_loop,
        Err(e) => return page::show_error(&format!("Mirador cannot start: {e}")),
    };
    page::set_proxy(event_loop.create_proxy());
    let scene = match crate::viewer::scene_state::load(None, &[]) {
        Ok(scene) => scene,
        Err(e) => return page::show_error(&format!("the built-in scene does not load: {e}")),
    };
    event_loop.spawn_app(App {
        scene: Some(scene),
        window: None,
        device: Rc::default(),
        running: None,
        next_frame: None,
        first_frame_shown: false,
    });
}

struct App {
    /// The scene, until the viewer starts.
    scene: Option<crate::Scene>,
    window: Option<Arc<Window>>,
    device: DeviceAnswer,
    running: Option<(Screen, Viewer)>,
    /// When the last frame asked for the next one.
    next_frame: Option<Instant>,
    first_frame_shown: bool,
}

impl App {
    /// Takes the device the browser answered with and starts the viewer on it.
    fn start_viewer(&mut self) -> anyhow::Result<()> {
        let answer = self.device.borrow_mut().take();
        let (Some(answer), Some(window)) = (answer, self.window.clone()) else { return Ok(()) };
        let (gpu, surface) = answer.map_err(|e| match e {
            GpuError::NoAdapter { .. } => anyhow::anyhow!(
                "this browser offers neither WebGPU nor WebGL2, one of which Mirador's page needs: every \
                 browser since 2021 has WebGL2 unless it is turned off (chrome://gpu, about:support say)"
            ),
            other => other.into(),
        })?;
        // A device the browser takes away (its GPU process stopped: most often a frame longer
        // than the browser's GPU watchdog allows, on a GPU in software) draws nothing more: the
        // page says so, rather than a readback's failure later. WebGL2's lost context is heard
        // by the page (web/index.html).
        gpu.device.set_device_lost_callback(|reason, message| {
            if reason != wgpu::DeviceLostReason::Destroyed {
                page::device_lost(&message);
            }
        });
        let mut screen = Screen::new(window, gpu, surface, true)?;
        screen.screenshot_sink = Some(Box::new(page::screenshot_taken));
        let scene = self.scene.take().ok_or_else(|| anyhow::anyhow!("the viewer starts once"))?;
        let wake = || page::wake(Wake::Traced);
        let viewer = Viewer::new(&mut screen, scene, &ViewerConfig::default(), Vec::new(), wake, None);
        log::info!("adapter: {}, {:?} profile", screen.gpu.describe(), screen.gpu.profile());
        screen.window.request_redraw();
        self.running = Some((screen, viewer));
        Ok(())
    }

    fn redraw(&mut self) {
        let Some((screen, viewer)) = &mut self.running else { return };
        if screen.is_minimised() {
            return;
        }
        viewer.push_steps(page::take_steps());
        if let Some(name) = page::take_lab_asked() {
            viewer.open_lab(&name);
        }
        if let Some(text) = page::take_lab_text() {
            viewer.set_lab_text(text);
        }
        match viewer.frame(screen) {
            Ok(end) => {
                // The next frame asked for, the look at the lab's text after a pause in the
                // typing, or the next scripted step's, whichever first (the page watches no scene
                // file). A scripted wait draws no frames: on a page drawn on the CPU they take the
                // cores the tracer's workers use.
                let lab = viewer.lab.as_ref().map(crate::viewer::lab::LabMode::next_poll);
                let script = viewer.script_next(Instant::now());
                self.next_frame = [end.next, lab, script].into_iter().flatten().min();
                if !self.first_frame_shown {
                    self.first_frame_shown = true;
                    // From the start of the page's load: what a cold visit waits (web/README.md).
                    let since_start = web_sys::window().and_then(|w| w.performance()).map_or(0.0, |p| p.now());
                    log::info!("first frame {since_start:.0} ms after the page started loading");
                    viewer.start_tracer_workers();
                }
            }
            Err(e) => {
                page::show_error(&format!("{e:#}"));
                self.next_frame = None;
            }
        }
        page::remember_view(viewer.view.pixels);
        page::remember_lab_file(viewer.lab_file());
        if let Some(json) = viewer.lab.as_mut().and_then(|lab| lab.results.take()) {
            page::lab_checked(json);
        }
    }
}

impl ApplicationHandler<Wake> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title("Mirador")
            .with_canvas(page::canvas())
            .with_append(page::canvas().is_none())
            .with_prevent_default(true)
            .with_focusable(true);
        let window = match event_loop.create_window(attributes) {
            Ok(window) => Arc::new(window),
            Err(e) => return page::show_error(&format!("Mirador cannot use the page's canvas: {e}")),
        };
        self.window = Some(window.clone());
        let answer = self.device.clone();
        wasm_bindgen_futures::spawn_local(async move {
            let device = match page::asks_for_webgl2() {
                true => Gpu::for_window_on(window, vec![wgpu::Backends::GL]).await,
                false => Gpu::for_window_async(window).await,
            };
            *answer.borrow_mut() = Some(device);
            page::wake(Wake::Device);
        });
    }

    fn user_event(&mut self, _: &ActiveEventLoop, wake: Wake) {
        if let Wake::Device = wake
            && let Err(e) = self.start_viewer()
        {
            page::show_error(&format!("{e:#}"));
        }
        if let Some((screen, _)) = &self.running {
            screen.window.request_redraw();
        }
    }

    fn window_event(&mut self, _: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some((screen, _)) = &mut self.running else { return };
        let response = screen.input.on_window_event(&screen.window, &event);
        match event {
            WindowEvent::Resized(size) => screen.resize(size),
            WindowEvent::RedrawRequested => return self.redraw(),
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
        if self.next_frame.is_some_and(|t| t <= Instant::now())
            && let Some((screen, _)) = &self.running
        {
            self.next_frame = None;
            screen.window.request_redraw();
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        event_loop.set_control_flow(self.next_frame.map_or(ControlFlow::Wait, ControlFlow::WaitUntil));
    }
}
