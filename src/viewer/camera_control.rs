//! Camera controls as pure functions on the notes' camera (`eye`, `center`, `up`, `fovy`, `near`,
//! `far`, see `scene/camera.rs`): each takes a camera and returns the moved one, so they are
//! tested without a window.
//!
//! - **Orbit** (left drag) turns `eye` around `center` on a sphere: yaw about `up`, pitch about
//!   the eye frame's `xe`, kept short of the poles so that `up × ze` never vanishes.
//! - **Pan** (right or middle drag) slides `eye` and `center` together along `xe` and `ye`, by
//!   the world size of a pixel at the distance of `center`, so the point under the cursor
//!   follows it.
//! - **Zoom** (wheel) moves `eye` towards `center` geometrically (an orthographic camera shrinks
//!   its window instead).
//! - **Fly** (WASD, Q/E, and left drag to look) moves `eye` and `center` together along the eye
//!   frame and turns `center` around `eye`.
//! - **Frame** (F) keeps the view direction and places `center` at the bounds' centre and `eye`
//!   far enough for their bounding sphere to fit both fields of view.

use glam::{Quat, Vec2, Vec3};

use crate::scene::{Camera, Projection};

/// Radians of orbit or look per pixel of mouse drag.
pub(in crate::viewer) const RADIANS_PER_PIXEL: f32 = 0.008;
/// The closest the view direction may come to `up` or `−up`, in radians.
const POLE_MARGIN: f32 = 0.02;
/// Distance factor per wheel step.
const ZOOM_PER_STEP: f32 = 0.9;

/// Which way mouse and keys move the camera.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Navigation {
    /// Turn around `center` (left drag), pan (right or middle drag), zoom (wheel).
    #[default]
    Orbit,
    /// Walk with WASD (Q/E down and up), look around with a left drag.
    Fly,
}

/// Turns `eye` around `center`: `yaw` about `up`, `pitch` about `xe` (radians, positive pitch
/// raises the eye). The distance to `center` is kept.
pub fn orbit(camera: &Camera, yaw: f32, pitch: f32) -> Camera {
    let up = camera.up.normalize();
    let offset = camera.eye - camera.center;
    let pitch = clamp_pitch(offset, up, pitch);
    let xe = camera.frame().xe;
    let rotation = Quat::from_axis_angle(up, -yaw) * Quat::from_axis_angle(xe, -pitch);
    Camera { eye: camera.center + rotation * offset, ..camera.clone() }
}

/// Turns `center` around `eye` (fly mode's mouse look), keeping their distance.
pub fn look(camera: &Camera, yaw: f32, pitch: f32) -> Camera {
    let up = camera.up.normalize();
    let offset = camera.center - camera.eye;
    let pitch = clamp_pitch(offset, up, pitch);
    let xe = camera.frame().xe;
    let rotation = Quat::from_axis_angle(up, -yaw) * Quat::from_axis_angle(xe, pitch);
    Camera { center: camera.eye + rotation * offset, ..camera.clone() }
}

/// Limits a rotation about `xe` so that `offset` stays `POLE_MARGIN` away from `±up`.
fn clamp_pitch(offset: Vec3, up: Vec3, pitch: f32) -> f32 {
    let elevation = (offset.normalize().dot(up)).clamp(-1.0, 1.0).asin();
    let limit = std::f32::consts::FRAC_PI_2 - POLE_MARGIN;
    (elevation + pitch).clamp(-limit, limit) - elevation
}

/// The world size of one pixel at the distance of `center`.
pub(in crate::viewer) fn world_per_pixel(camera: &Camera) -> f32 {
    let window_height = match camera.projection {
        Projection::Perspective => {
            2.0 * (camera.eye - camera.center).length() * (camera.fovy_degrees.to_radians() / 2.0).tan()
        }
        Projection::Orthographic => camera.ortho_height,
    };
    window_height / camera.height.max(1) as f32
}

/// Slides `eye` and `center` together so that the scene follows a drag of `pixels` (x right, y
/// down, as the mouse moves).
pub fn pan(camera: &Camera, pixels: Vec2) -> Camera {
    let frame = camera.frame();
    let step = world_per_pixel(camera);
    let shift = (-pixels.x * frame.xe + pixels.y * frame.ye) * step;
    Camera { eye: camera.eye + shift, center: camera.center + shift, ..camera.clone() }
}

/// Moves `eye` towards `center` by `ZOOM_PER_STEP` per step (positive steps come closer).
pub fn zoom(camera: &Camera, steps: f32) -> Camera {
    let factor = ZOOM_PER_STEP.powf(steps);
    match camera.projection {
        Projection::Perspective => {
            let offset = camera.eye - camera.center;
            let distance = (offset.length() * factor).max(camera.near * 1.5);
            Camera { eye: camera.center + offset.normalize() * distance, ..camera.clone() }
        }
        Projection::Orthographic => Camera { ortho_height: camera.ortho_height * factor, ..camera.clone() },
    }
}

/// Moves `eye` and `center` together by `local` in the eye frame: x right, y up, z forward.
pub fn fly(camera: &Camera, local: Vec3) -> Camera {
    let frame = camera.frame();
    let shift = local.x * frame.xe + local.y * camera.up.normalize() - local.z * frame.ze;
    Camera { eye: camera.eye + shift, center: camera.center + shift, ..camera.clone() }
}

/// Keeps the view direction and fits the box `(min, max)` in view: `center` at its centre, `eye`
/// back along `ze` until the box's bounding sphere fits the narrower field of view; `near` and
/// `far` widened when the sphere would be clipped.
pub(in crate::viewer) fn frame_bounds(camera: &Camera, (min, max): (Vec3, Vec3)) -> Camera {
    let middle = (min + max) / 2.0;
    let radius = ((max - min).length() / 2.0).max(1e-3);
    let ze = camera.frame().ze;
    let mut framed = camera.clone();
    framed.center = middle;
    match camera.projection {
        Projection::Perspective => {
            let half_fovy = camera.fovy_degrees.to_radians() / 2.0;
            let half_fovx = (half_fovy.tan() * camera.aspect()).atan();
            let distance = radius / half_fovy.min(half_fovx).sin();
            framed.eye = middle + ze * distance;
            if distance - radius < framed.near {
                framed.near = ((distance - radius) * 0.5).max(1e-3);
            }
        }
        Projection::Orthographic => {
            framed.ortho_height = 2.0 * radius * (1.0 / camera.aspect()).max(1.0);
            framed.eye = middle + ze * (radius + 2.0 * camera.near);
        }
    }
    let distance = (framed.eye - framed.center).length();
    framed.far = framed.far.max((distance + radius) * 1.01);
    framed
}

/// What the mouse and keyboard did during one frame, gathered by the UI.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraInput {
    /// Left-button drag, in pixels.
    pub rotate: Vec2,
    /// Right- or middle-button drag, in pixels.
    pub pan: Vec2,
    /// Wheel steps (positive: towards the scene).
    pub zoom: f32,
    /// Fly keys held: x right (D − A), y up (E − Q), z forward (W − S).
    pub walk: Vec3,
    /// Shift held: fly faster.
    pub fast: bool,
    /// Seconds since the last frame.
    pub dt: f32,
}

impl CameraInput {
    /// Whether this input moves the camera at all.
    pub fn moves(&self) -> bool {
        self.rotate != Vec2::ZERO || self.pan != Vec2::ZERO || self.zoom != 0.0 || self.walk != Vec3::ZERO
    }
}

/// Applies one frame of input under `navigation`; `scene_size` (the bounds' diagonal) sets the
/// fly speed: the whole scene in about two seconds.
pub fn apply(camera: &Camera, navigation: Navigation, input: &CameraInput, scene_size: f32) -> Camera {
    let mut moved = camera.clone();
    let turn = input.rotate * RADIANS_PER_PIXEL;
    match navigation {
        Navigation::Orbit => {
            if turn != Vec2::ZERO {
                moved = orbit(&moved, turn.x, turn.y);
            }
        }
        Navigation::Fly => {
            if turn != Vec2::ZERO {
                moved = look(&moved, turn.x, -turn.y);
            }
            if input.walk != Vec3::ZERO {
                let speed = scene_size * 0.5 * if input.fast { 4.0 } else { 1.0 };
                moved = fly(&moved, input.walk.normalize() * speed * input.dt);
            }
        }
    }
    if input.pan != Vec2::ZERO {
        moved = pan(&moved, input.pan);
    }
    if input.zoom != 0.0 {
        moved = zoom(&moved, input.zoom);
    }
    if moved.validate().is_ok() { moved } else { camera.clone() }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: Vec3::new(3.0, 2.0, 6.0),
            center: Vec3::new(0.0, 0.5, 0.0),
            up: Vec3::Y,
            fovy_degrees: 45.0,
            near: 0.1,
            far: 100.0,
            width: 640,
            height: 360,
            projection: Projection::Perspective,
            ortho_height: 2.0,
        }
    }

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-4 * a.abs().max(b.abs()).max(1.0)
    }

    #[test]
    fn orbit_keeps_the_distance_to_the_target() {
        let start = camera();
        let distance = (start.eye - start.center).length();
        for (yaw, pitch) in [(0.3, 0.0), (0.0, 0.4), (-1.2, -0.7), (2.0, 3.0)] {
            let moved = orbit(&start, yaw, pitch);
            assert_eq!(moved.center, start.center, "orbit turns around the target");
            assert!(close((moved.eye - moved.center).length(), distance), "yaw {yaw}, pitch {pitch}");
            assert!(moved.validate().is_ok(), "pitch is clamped short of the pole");
        }
        let turned = orbit(&start, 0.5, 0.0);
        assert!(close(turned.eye.y, start.eye.y), "yaw alone keeps the height above the target");
    }

    #[test]
    fn pan_moves_eye_and_center_together() {
        let start = camera();
        let moved = pan(&start, Vec2::new(40.0, -25.0));
        assert!((moved.eye - moved.center - (start.eye - start.center)).length() < 1e-5);
        assert!((moved.center - start.center).length() > 0.0);
        // The target moves by the world size of the dragged pixels, in the image plane.
        let expected = world_per_pixel(&start) * Vec2::new(40.0, -25.0).length();
        assert!(close((moved.center - start.center).length(), expected));
        assert!(close((moved.center - start.center).dot(start.frame().ze), 0.0));
    }

    #[test]
    fn a_pan_keeps_the_target_under_the_cursor() {
        let start = camera();
        let (x0, y0) = (start.width as f32 / 2.0, start.height as f32 / 2.0);
        let moved = pan(&start, Vec2::new(30.0, 10.0));
        let p = moved.project(start.center).expect("in front of the eye");
        assert!(close(p.x, x0 + 30.0) && close(p.y, y0 + 10.0), "{p}");
    }

    #[test]
    fn zoom_and_fly_keep_the_view_valid() {
        let start = camera();
        let near = zoom(&start, 3.0);
        assert!((near.eye - near.center).length() < (start.eye - start.center).length());
        assert!(zoom(&start, 500.0).validate().is_ok(), "zooming never passes the target");
        let walked = fly(&start, Vec3::new(0.0, 0.0, 1.0));
        assert!(close((walked.eye - start.eye).length(), 1.0));
        assert!((walked.eye - walked.center - (start.eye - start.center)).length() < 1e-5);
        let looked = look(&start, 0.3, 0.2);
        assert_eq!(looked.eye, start.eye);
        assert!(close((looked.center - looked.eye).length(), (start.center - start.eye).length()));
    }

    #[test]
    fn frame_the_scene_fits_the_bounds() {
        let bounds = (Vec3::new(-4.0, 0.0, -2.0), Vec3::new(6.0, 3.0, 1.0));
        for start in [camera(), Camera { width: 300, height: 600, ..camera() }, zoom(&camera(), 20.0)] {
            let framed = frame_bounds(&start, bounds);
            assert!(framed.validate().is_ok());
            assert!(framed.frame().ze.abs_diff_eq(start.frame().ze, 1e-5), "the view direction is kept");
            for i in 0..8 {
                let corner = Vec3::new(
                    if i & 1 == 0 { bounds.0.x } else { bounds.1.x },
                    if i & 2 == 0 { bounds.0.y } else { bounds.1.y },
                    if i & 4 == 0 { bounds.0.z } else { bounds.1.z },
                );
                let p = framed.project(corner).expect("every corner is in front of the eye");
                assert!(p.x >= 0.0 && p.x <= framed.width as f32, "corner {corner} at x = {}", p.x);
                assert!(p.y >= 0.0 && p.y <= framed.height as f32, "corner {corner} at y = {}", p.y);
                assert!(p.z > 0.0 && p.z < 1.0, "corner {corner} between near and far");
            }
        }
    }

    #[test]
    fn apply_moves_by_mode() {
        let start = camera();
        let input = CameraInput { rotate: Vec2::new(10.0, 5.0), zoom: 1.0, ..Default::default() };
        let moved = apply(&start, Navigation::Orbit, &input, 10.0);
        assert_ne!(moved.eye, start.eye);
        assert!(!CameraInput::default().moves());
        let walk = CameraInput { walk: Vec3::Z, dt: 0.1, ..Default::default() };
        let flown = apply(&start, Navigation::Fly, &walk, 10.0);
        assert!(close((flown.eye - start.eye).length(), 0.5));
    }
}
