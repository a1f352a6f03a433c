//! The four ways the 3D view shows the scene: the rasterizer's image, the ray tracer's, the two
//! split by a draggable divider (raster left, traced right, pixel-aligned), or the FLIP error map
//! between them.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum ViewMode {
    /// The z-buffer rasterizer, every frame.
    #[default]
    Raster,
    /// The Whitted ray tracer, refined progressively in the background.
    Traced,
    /// Raster left of the divider, ray traced right of it, the same pixels.
    Split,
    /// The FLIP error map between the two, with its mean.
    Difference,
}

impl ViewMode {
    pub const ALL: [ViewMode; 4] = [ViewMode::Raster, ViewMode::Traced, ViewMode::Split, ViewMode::Difference];

    /// Whether this mode shows the ray-traced image (so the background tracer must run).
    pub(in crate::viewer) fn needs_traced(self) -> bool {
        self != ViewMode::Raster
    }

    pub fn label(self) -> &'static str {
        match self {
            ViewMode::Raster => "raster",
            ViewMode::Traced => "ray traced",
            ViewMode::Split => "split",
            ViewMode::Difference => "difference",
        }
    }

    pub fn parse(text: &str) -> Option<ViewMode> {
        use clap::ValueEnum;
        ViewMode::from_str(text.trim(), true).ok()
    }
}

/// How the 3D view is shown, and the window's layout.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewState {
    pub mode: ViewMode,
    /// The split view's divider, as a fraction of the view's width.
    pub split: f32,
    /// The frame rate held while the camera moves (0: none, draw at `motion_scale`).
    pub motion_fps: f32,
    /// The lowest render scale while the camera moves.
    pub motion_scale: f32,
    pub panel_open: bool,
    pub help_open: bool,
    /// The frame times in the view's corner.
    pub overlay_open: bool,
    /// Where a script holds the mouse, in pixels of the view (over the real mouse).
    pub scripted_cursor: Option<glam::Vec2>,
    /// Clicks inspect pixels (`super::inspect`) instead of picking objects.
    pub inspecting: bool,
    /// The 3D view's size in pixels, and where it sits in the window (`x, y, width, height`).
    pub pixels: Option<(u32, u32, u32, u32)>,
}

impl Default for ViewState {
    fn default() -> Self {
        ViewState {
            mode: ViewMode::Raster,
            split: 0.5,
            motion_fps: super::budget::DEFAULT_MOTION_FPS,
            motion_scale: super::budget::DEFAULT_MOTION_SCALE,
            panel_open: true,
            help_open: false,
            overlay_open: true,
            scripted_cursor: None,
            inspecting: false,
            pixels: None,
        }
    }
}
