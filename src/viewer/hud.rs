//! What the window says about itself: frame times in a corner of the 3D view, the help window
//! listing the keys, and the `--stats` summary of a run.

use std::time::Duration;

/// The keys, as the help window lists them.
pub const KEYS: &[(&str, &str)] = &[
    ("left drag", "orbit around the target (fly mode: look around)"),
    ("right or middle drag", "pan: eye and target move together"),
    ("wheel", "zoom towards the target"),
    ("G", "switch between orbit and fly navigation"),
    ("W A S D, Q E", "fly: forward, left, back, right; down, up (Shift: faster)"),
    ("F", "frame the scene"),
    ("R", "reset to the scene's camera"),
    ("1 2 3 4", "view: raster, ray traced, split, difference"),
    ("click", "pick an object and edit its material"),
    ("I, then click", "inspect a pixel: both renderers' terms, and the tracer's rays drawn in 3D (I again: off)"),
    ("hover a volume", "plot the samples its ray takes (in a lower corner)"),
    ("P", "show or hide the side panel"),
    ("O", "show or hide the frame times"),
    ("F12", "screenshot of the window (PNG in the current directory)"),
    ("F1 or H", "this help"),
    ("drop a file", "open a scene (.toml) or a model (.gltf, .glb, .obj, .ply)"),
];

pub fn help_window(ctx: &egui::Context, open: &mut bool) {
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
    /// From one frame's start to the next's.
    pub frame: Duration,
    /// Building the UI and tessellating it (CPU).
    pub ui: Duration,
    /// Recording egui's draw and presenting (CPU side of the UI's painting).
    pub paint: Duration,
    /// The rasterizer's frame, submission to completion (only measured with `--stats` or the
    /// overlay's detailed timing, since waiting for it stalls the pipeline).
    pub raster: Option<Duration>,
}

/// Running means over the frames of a run, for the overlay and `--stats`.
#[derive(Clone, Debug, Default)]
pub struct FrameStats {
    pub last: FrameTimes,
    frames: u32,
    total: FrameTimes,
    raster_frames: u32,
    /// A smoothed frame time for the overlay.
    smooth_ms: f64,
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
        if let Some(raster) = times.raster {
            self.raster_frames += 1;
            *self.total.raster.get_or_insert(Duration::ZERO) += raster;
        }
        let now = ms(times.frame);
        self.smooth_ms = if self.frames == 1 { now } else { self.smooth_ms * 0.9 + now * 0.1 };
    }

    /// Starts the means again (after warm-up frames).
    pub fn reset(&mut self) {
        *self = FrameStats { last: self.last, smooth_ms: self.smooth_ms, ..Default::default() };
    }

    pub fn overlay_text(&self, scale: f32) -> String {
        let t = &self.last;
        let mut text = format!(
            "{:.1} ms/frame ({:.1} fps)\nUI {:.1} ms + paint {:.1} ms",
            self.smooth_ms,
            1e3 / self.smooth_ms.max(1e-3),
            ms(t.ui),
            ms(t.paint)
        );
        if let Some(raster) = t.raster {
            text += &format!("\nraster {:.1} ms", ms(raster));
        }
        if scale < 1.0 {
            text += &format!("\nrender scale {scale:.2} (moving)");
        }
        text
    }

    /// The `--stats` summary: mean frame time, frames per second, and the UI's share.
    pub fn summary(&self) -> String {
        let n = self.frames.max(1) as f64;
        let frame = ms(self.total.frame) / n;
        let ui = (ms(self.total.ui) + ms(self.total.paint)) / n;
        let mut text = format!(
            "frames: {}\nframe: {frame:.2} ms ({:.2} fps)\nUI (build + tessellate + paint, CPU): {ui:.2} ms = {:.1} % of the frame",
            self.frames,
            1e3 / frame.max(1e-6),
            100.0 * ui / frame.max(1e-6)
        );
        if let Some(raster) = self.total.raster {
            text += &format!("\nraster (submit to done): {:.2} ms", ms(raster) / self.raster_frames.max(1) as f64);
        }
        text
    }
}
