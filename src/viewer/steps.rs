//! The viewer's scripted steps run (`super::script` parses them): one step a frame, the waits
//! (frames, time, the traced image, the lab's check) and the screenshots they ask for, so that a
//! run with `--frames N --screenshot FILE` is tested under Xvfb like a person at the window.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context as _, bail};
use web_time::Instant;

use super::camera_control::{self, CameraInput};
use super::frame::{SETTLE, Viewer};
use super::scene_panel;
use super::script::Step;
use super::view_mode::ViewMode;

/// The longest a screenshot waits for egui's animations to end.
const SCREENSHOT_PATIENCE: Duration = Duration::from_secs(2);
/// The longest a `wait traced` step waits.
pub(super) const TRACE_TIMEOUT: Duration = Duration::from_secs(600);

impl Viewer {
    /// Whether every scripted step has run and every screenshot asked for is written.
    pub(in crate::viewer) fn script_done(&self) -> bool {
        self.script.steps.is_empty()
            && self.script.wait_frames == 0
            && self.script.wait_until.is_none()
            && self.script.wait_traced_since.is_none()
            && self.script.wait_checked_since.is_none()
            && self.script.screenshot.is_none()
    }

    /// When the script needs its next frame (the page asks for no more than that): at once while
    /// steps or waited frames are left, a screenshot is due or a lab's check runs; at a timed
    /// wait's end; for `wait traced`, at once when it ends or fails at the next frame or the
    /// difference view still needs its raster image read back, else at its timeout (the tracer
    /// wakes the window sooner); `None` once the script is done.
    #[cfg(target_arch = "wasm32")]
    pub fn script_next(&self, now: Instant) -> Option<Instant> {
        let script = &self.script;
        if self.script_done() {
            return None;
        }
        if self.script.screenshot.is_some() || script.wait_frames > 0 || script.wait_checked_since.is_some() {
            return Some(now);
        }
        if let Some(until) = script.wait_until {
            return Some(until.max(now));
        }
        if let Some(since) = script.wait_traced_since {
            let reading = self.view.mode == ViewMode::Difference && !self.traced.worker.compared(self.traced.key);
            // (In the raster view without the hybrid the step fails at once; with it, the terms'
            // last frames are due at once, `RasterView::refining`, and the workers wake the page.)
            let nothing = !self.view.mode.needs_traced() && !self.settings.hybrid.any();
            let at_once = self.traced_waited() || nothing || reading;
            return Some(if at_once { now } else { since + TRACE_TIMEOUT });
        }
        Some(now)
    }

    /// Queues more steps, run one a frame after those already queued (the browser's page sends
    /// them, `src/web/`).
    #[cfg(target_arch = "wasm32")]
    pub fn push_steps(&mut self, steps: impl IntoIterator<Item = Step>) {
        self.script.steps.extend(steps);
    }

    /// Whether a `measure` step said where the stats start.
    pub fn measured(&self) -> bool {
        self.script.measured
    }

    /// Asks for a screenshot of the window at the end of this frame.
    pub(in crate::viewer) fn request_screenshot(&mut self, path: PathBuf) {
        self.script.screenshot = Some(path);
    }

    /// The screenshot to write this frame: the one asked for, unless egui is animating (a window
    /// fading in, a section opening) or the view was drawn below full scale (the camera just
    /// moved), when it waits for the animation to end and the full-scale image, up to
    /// [`SCREENSHOT_PATIENCE`]. The scripted steps wait with it, so it shows the state the steps
    /// before it set up.
    pub(super) fn screenshot_due(&mut self, repaint: Option<Duration>, scale: f32) -> Option<PathBuf> {
        self.script.screenshot.as_ref()?;
        let since = *self.script.screenshot_waiting.get_or_insert_with(Instant::now);
        let animating = repaint.is_some_and(|delay| delay.is_zero());
        if (animating || scale < 1.0 || self.raster.refining()) && since.elapsed() < SCREENSHOT_PATIENCE {
            return None;
        }
        self.script.screenshot_waiting = None;
        self.script.screenshot.take()
    }

    /// Whether a scripted wait (frames, time, the traced image, the lab's check) goes on this
    /// frame; a wait that can never end is an error.
    pub(super) fn script_waits(&mut self) -> anyhow::Result<bool> {
        if self.script.screenshot.is_some() {
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
            } else if !self.view.mode.needs_traced() && !self.settings.hybrid.any() {
                bail!(
                    "`wait traced` in the raster view without the hybrid: switch to traced, split or difference first"
                );
            } else {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Whether what `wait traced` waits for is there: the traced image of the current request,
    /// complete, and in the difference view its FLIP map; in the raster view with the hybrid on,
    /// its traced terms at every pixel.
    pub(super) fn traced_waited(&self) -> bool {
        if !self.view.mode.needs_traced() && self.settings.hybrid.any() {
            return self.raster.terms_complete(&self.settings);
        }
        let difference = self.view.mode == ViewMode::Difference;
        self.traced.request.is_some() && self.traced.complete(self.traced.key, difference)
    }

    /// Runs the next scripted step, or goes on waiting.
    pub(super) fn run_script(&mut self, input: &mut CameraInput) -> anyhow::Result<()> {
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
                self.pace.moving_until = Some(Instant::now() + SETTLE);
            }
            Step::Frame => self.frame_scene(),
            Step::Reset => self.reset_camera(),
            Step::ResetSettings => self.reset_settings(),
            Step::Navigate(navigation) => self.navigation = navigation,
            Step::Pick(pixel) if self.view.pixels.is_none() => {
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
            Step::Budget => self.error_budget.next = true,
            Step::Measure => {
                self.script.measured = true;
                self.script.reset_stats = true;
            }
            Step::Help(on) => self.view.help_open = on,
            Step::Panel(on) => self.view.panel_open = on,
            Step::Overlay(on) => self.view.overlay_open = on,
            Step::Cursor(pixel) => self.view.scripted_cursor = Some(pixel),
            Step::Inspect(pixel) => self.inspect.next = Some(pixel),
            Step::Probe => self.script.print_probe = true,
            Step::Wait(frames) => self.script.wait_frames = frames,
            Step::WaitFor(time) => self.script.wait_until = Some(Instant::now() + time),
            Step::WaitTraced => self.script.wait_traced_since = Some(Instant::now()),
            Step::Screenshot(path) => self.script.screenshot = Some(path),
            Step::Lab(shown) => self.lab_step(shown)?,
            Step::LabOpen(name) => self.lab_open_step(&name)?,
            Step::LabCheck if self.lab.is_none() => bail!("`lab check`: the viewer is not in lab mode"),
            Step::LabCheck => {
                if let Some(lab) = self.lab.as_mut() {
                    lab.check_next = true;
                }
            }
            Step::WaitChecked => self.script.wait_checked_since = Some(Instant::now()),
        }
        Ok(())
    }
}
