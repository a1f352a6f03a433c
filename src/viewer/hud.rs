//! What the window says about itself: frame times in a corner of the 3D view, the help window
//! listing the keys, and the `--stats` summary of a run.

use std::time::Duration;

/// The keys, as the help window lists them.
pub(in crate::viewer) const KEYS: &[(&str, &str)] = &[
    ("left drag", "orbit around the target (fly mode: look around)"),
    ("right or middle drag", "pan: eye and target move together"),
    ("wheel", "zoom towards the target"),
    ("G", "switch between orbit and fly navigation"),
    ("W A S D, Q E", "fly: forward, left, back, right; down, up (Shift: faster)"),
    ("F", "frame the scene"),
    ("R", "reset to the scene's camera"),
    ("1 2 3 4", "view: raster, ray traced, split, difference"),
    ("L", "lab mode: your image, the reference, their difference"),
    ("click", "pick an object and edit its material"),
    ("I, then click", "inspect a pixel: both renderers' terms, and the tracer's rays drawn in 3D (I again: off)"),
    ("hover a volume", "plot the samples its ray takes (in a lower corner)"),
    ("P", "show or hide the side panel"),
    ("O", "show or hide the frame times"),
    ("F12", "screenshot of the window (PNG in the current directory)"),
    ("F1 or H", "this help"),
    ("drop a file", "open a scene (.toml) or a model (.gltf, .glb, .obj, .ply)"),
];

pub(in crate::viewer) fn help_window(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("Keys").open(open).resizable(false).collapsible(false).show(ctx, |ui| {
        egui::Grid::new("keys").num_columns(2).striped(true).show(ui, |ui| {
            for (key, what) in KEYS {
                ui.label(egui::RichText::new(*key).monospace().strong());
                ui.label(*what);
                ui.end_row();
            }
        });
        ui.separator();
        ui.label("Hover over any setting for what it changes in the formula.");
    });
}

/// Times of one frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTimes {
    /// From the frame's start until the GPU finished it (the viewer waits for it at the end of
    /// every frame: nothing is drawn between frames, so nothing is lost by waiting).
    pub frame: Duration,
    /// Since the previous frame's start, when it asked for this one at once (scripted runs,
    /// moving cameras): the frame rate as seen.
    pub interval: Option<Duration>,
    /// Building the UI (CPU).
    pub ui: Duration,
    /// The rasterizer's frame, submission to completion; `None` when the image was kept.
    pub raster: Option<Duration>,
    /// Tessellating egui's output, composing the window and presenting it, GPU included.
    pub paint: Duration,
    /// The render scale the 3D view was drawn at.
    pub scale: f32,
}

/// Running means over the frames of a run, for the overlay and `--stats`.
#[derive(Clone, Debug, Default)]
pub struct FrameStats {
    pub last: FrameTimes,
    frames: u32,
    total: FrameTimes,
    intervals: u32,
    raster_frames: u32,
    scales: Vec<f32>,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

impl FrameStats {
    pub fn record(&mut self, times: FrameTimes) {
        self.last = times;
        self.frames += 1;
        self.total.frame += times.frame;
        self.total.ui += times.ui;
        self.total.paint += times.paint;
        if let Some(interval) = times.interval {
            self.intervals += 1;
            *self.total.interval.get_or_insert(Duration::ZERO) += interval;
        }
        if let Some(raster) = times.raster {
            self.raster_frames += 1;
            *self.total.raster.get_or_insert(Duration::ZERO) += raster;
            self.scales.push(times.scale);
        }
    }

    /// Starts the means again (after warm-up frames).
    pub fn reset(&mut self) {
        *self = FrameStats { last: self.last, ..Default::default() };
    }

    /// The last frame's times: what the overlay shows. Frames are drawn only when something
    /// changes, so this is what the last change cost, not a rate.
    pub(in crate::viewer) fn overlay_text(&self) -> String {
        let t = &self.last;
        let mut text = format!("frame {:.1} ms", ms(t.frame));
        if let Some(interval) = t.interval {
            text += &format!(" ({:.1} fps)", 1e3 / ms(interval).max(1e-3));
        }
        text += &format!("\nUI {:.1} ms + paint {:.1} ms", ms(t.ui), ms(t.paint));
        match t.raster {
            Some(raster) => text += &format!("\nraster {:.1} ms", ms(raster)),
            None => text += "\nraster: image kept",
        }
        if t.scale < 1.0 {
            text += &format!("\nrender scale {:.2} (moving)", t.scale);
        }
        text
    }

    /// The `--stats` summary: mean frame time, frames per second, where the time went, and the
    /// render scales drawn at.
    pub fn summary(&self) -> String {
        let n = self.frames.max(1) as f64;
        let frame = ms(self.total.frame) / n;
        let (ui, paint) = (ms(self.total.ui) / n, ms(self.total.paint) / n);
        let mut text = format!(
            "frames: {}, the 3D view drawn in {}\nframe: {frame:.2} ms (start to GPU done)",
            self.frames, self.raster_frames
        );
        if let Some(interval) = self.total.interval {
            let apart = ms(interval) / self.intervals.max(1) as f64;
            text += &format!("\nframes apart: {apart:.2} ms ({:.2} fps)", 1e3 / apart.max(1e-6));
        }
        text += &format!(
            "\nUI build: {ui:.2} ms; paint (tessellate, compose, present, GPU included): {paint:.2} ms; together {:.1} % of the frame",
            100.0 * (ui + paint) / frame.max(1e-6)
        );
        if let Some(raster) = self.total.raster {
            text += &format!("\nraster (submit to done): {:.2} ms", ms(raster) / self.raster_frames.max(1) as f64);
        }
        if !self.scales.is_empty() {
            let mean = self.scales.iter().sum::<f32>() / self.scales.len() as f32;
            let (low, high) = self.scales.iter().fold((f32::MAX, f32::MIN), |(l, h), &s| (l.min(s), h.max(s)));
            text += &format!("\nrender scale: mean {mean:.2}, from {low:.2} to {high:.2}");
        }
        text
    }
}

/// The panel's notices (the last twenty), and the camera section's error.
#[derive(Clone, Debug, Default)]
pub struct Notices {
    pub list: Vec<String>,
    pub camera_error: Option<String>,
}

impl Notices {
    /// Adds `message`, dropping the oldest past twenty.
    pub fn push(&mut self, message: String) {
        self.list.push(message);
        if self.list.len() > 20 {
            self.list.remove(0);
        }
    }
}
