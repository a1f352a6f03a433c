//! The frame budget while the camera moves: the render scale follows the measured frame time so
//! that orbiting, panning and flying hold a target frame rate, within a lowest scale; when the
//! camera stops, the next frame is drawn at full scale (`frame::Viewer::scale`).
//!
//! A frame's time is modelled as a part that does not depend on the number of pixels drawn (the
//! UI, the window's composition, the geometry) plus one proportional to them, so to the scale
//! squared: `t(s) = F + k s²`. Each moving frame drawn at `s` in `t` says the area should be
//! multiplied by `target / t`, so the scale by its square root. Followed frame after frame, that
//! converges on the target whatever `F` is (the fixed part only slows the approach: the error
//! shrinks by `F / target` each frame), and it needs no model fitted to the scene. Three guards
//! keep the picture steady: the ratio is limited to [½, 2], so one slow frame (a shader variant
//! compiled, a shadow map redrawn) does not throw the scale to its bound; the wanted scale is a
//! running mean of what the frames say, since one frame's time varies by ±15 % on a software GPU;
//! and the scale drawn at moves in steps of [`STEP`], only when the wanted one is more than
//! [`HYSTERESIS`] of a step away, so the render targets are not remade every frame. (A whole step
//! would stall the scale up to a step from where the frame meets the target: from 0.5 down to a
//! target at 0.39, it stopped at 0.45, 18 % over the frame time asked for.)

use std::time::Duration;

/// The frame rate held while the camera moves, by default. A software GPU (lavapipe on two
/// cores) draws the showcase's flat-colour floor at about 23 frames a second in a 950×720 view;
/// aiming at 30 keeps orbiting under the cost of that floor (docs/performance.md), and where the
/// frames are cheaper the scale rises to meet it.
pub(in crate::viewer) const DEFAULT_MOTION_FPS: f32 = 30.0;
/// The frame rates the panel offers (0, outside it, turns the target off).
pub(in crate::viewer) const MOTION_FPS: std::ops::RangeInclusive<f32> = 5.0..=120.0;
/// The lowest render scale while moving, by default: a quarter of the pixels in each direction.
pub(in crate::viewer) const DEFAULT_MOTION_SCALE: f32 = 0.25;
/// The lowest render scales the panel offers.
pub(in crate::viewer) const MOTION_SCALES: std::ops::RangeInclusive<f32> = 0.1..=1.0;

/// The scales the budget picks from are multiples of this.
pub const STEP: f32 = 0.05;

/// How far, in steps, the wanted scale must be from the drawn one for the drawn one to move: more
/// than half a step, so a scale that rounds to the drawn one stays, with a margin for noise.
const HYSTERESIS: f32 = 0.6;

/// The weight of each frame's ask in the running mean of the wanted scale.
const WEIGHT: f32 = 0.3;

/// The render scale for moving frames.
#[derive(Clone, Debug)]
pub(in crate::viewer) struct FrameBudget {
    /// The running mean of the scale the frames asked for.
    wanted: f32,
    /// The scale frames are drawn at: a multiple of [`STEP`] near `wanted`.
    scale: f32,
}

impl Default for FrameBudget {
    fn default() -> Self {
        FrameBudget { wanted: 0.5, scale: 0.5 }
    }
}

impl FrameBudget {
    /// The scale the next moving frame is drawn at, within `[lowest, 1]`.
    pub fn scale(&self, lowest: f32) -> f32 {
        self.scale.clamp(lowest.min(1.0), 1.0)
    }

    /// Learns from a moving frame drawn at [`Self::scale`]`(lowest)` that took `time`, aiming at
    /// `target` per frame.
    pub fn update(&mut self, time: Duration, target: Duration, lowest: f32) {
        let lowest = lowest.min(1.0);
        let drawn = self.scale(lowest);
        let ratio = (target.as_secs_f32() / time.as_secs_f32().max(1e-4)).clamp(0.5, 2.0);
        let asked = drawn * ratio.sqrt();
        self.wanted = (self.wanted + WEIGHT * (asked - self.wanted)).clamp(lowest, 1.0);
        if (self.wanted - drawn).abs() > HYSTERESIS * STEP || (self.wanted == 1.0 && drawn < 1.0) {
            self.scale = ((self.wanted / STEP).round() * STEP).clamp(lowest, 1.0);
        }
    }
}

/// The frames' pace: the render scale moving frames are drawn at, when the camera last moved (plus
/// the settling time), and when the last frame started and whether it asked for the next at once.
#[derive(Clone, Debug, Default)]
pub(in crate::viewer) struct Pace {
    pub scale: FrameBudget,
    pub moving_until: Option<web_time::Instant>,
    pub last_frame: Option<(web_time::Instant, bool)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame of `fixed` ms plus `per_area` ms at full scale, times the scale squared.
    fn frame(scale: f32, fixed: f32, per_area: f32) -> Duration {
        Duration::from_secs_f32((fixed + per_area * scale * scale) / 1e3)
    }

    #[test]
    fn the_scale_settles_where_the_frame_meets_the_target() {
        // 15 ms fixed, 120 ms for a full-scale image; 30 fps = 33.3 ms: the exact answer is
        // s = √((33.3 − 15) / 120) = 0.39.
        let target = Duration::from_secs_f32(1.0 / 30.0);
        let mut budget = FrameBudget::default();
        for _ in 0..40 {
            let s = budget.scale(0.1);
            budget.update(frame(s, 15.0, 120.0), target, 0.1);
        }
        let s = budget.scale(0.1);
        assert!((s - 0.39).abs() <= STEP, "settled at {s}");
        let t = frame(s, 15.0, 120.0).as_secs_f32();
        assert!((t / target.as_secs_f32() - 1.0).abs() < 0.25, "frame {t} s against {target:?}");
    }

    #[test]
    fn the_scale_stays_within_its_bounds_and_rises_to_one_when_frames_are_cheap() {
        let target = Duration::from_millis(50);
        let mut budget = FrameBudget::default();
        for _ in 0..30 {
            let s = budget.scale(0.3);
            budget.update(frame(s, 60.0, 200.0), target, 0.3);
        }
        assert_eq!(budget.scale(0.3), 0.3, "a target out of reach: the lowest scale");
        for _ in 0..30 {
            let s = budget.scale(0.3);
            budget.update(frame(s, 2.0, 10.0), target, 0.3);
        }
        assert_eq!(budget.scale(0.3), 1.0, "cheap frames: full scale");
    }

    #[test]
    fn noise_of_fifteen_percent_does_not_move_a_settled_scale() {
        let target = Duration::from_millis(40);
        let mut budget = FrameBudget { wanted: 0.6, scale: 0.6 };
        // At 0.6 the model frame is 10 + 83.3 · 0.36 = 40 ms; alternate ±15 %.
        let mut scales = Vec::new();
        for k in 0..20 {
            let noise = if k % 2 == 0 { 1.15 } else { 0.85 };
            let t = frame(budget.scale(0.25), 10.0, 83.3).mul_f32(noise);
            budget.update(t, target, 0.25);
            scales.push(budget.scale(0.25));
        }
        assert!(scales.iter().all(|&s| (s - 0.6).abs() < 1e-6), "{scales:?}");
    }
}
