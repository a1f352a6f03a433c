//! The camera of the course notes (docs/course/01-camera.md#the-eye-frame), shared by both renderers.
//!
//! Given `eye`, `center`, `up`, the vertical field of view `fovy`, the clip distances `near` and
//! `far` and an image of `width × height` pixels, the eye frame is
//!
//! ```text
//! ze = normalize(eye − center)     xe = normalize(up × ze)     ye = ze × xe
//! h  = 2·near·tan(fovy/2)          w  = (width/height)·h
//! ```
//!
//! The camera looks down `−ze`. The window on the near plane is `w × h`; pixel `(x, y)` (column
//! `x` from the left, row `y` from the top, as in the image file) covers the window cell whose
//! centre is
//!
//! ```text
//! q(x, y) = eye − near·ze + w·((x + ½)/width − ½)·xe + h·(½ − (y + ½)/height)·ye
//! ```
//!
//! **Pixel-centre convention.** The ray tracer shoots its primary ray through `q(x, y)` (docs/course/01-camera.md#pixel-centres:
//! `u = l + (r − l)(i + 0.5)/Nx`), and the rasterizer's `clip_from_world` maps `q(x, y)` to the
//! centre of framebuffer pixel `(x, y)`, where the GPU samples coverage and interpolates
//! attributes. So the same surface point lands on the same pixel in both images: they are
//! pixel-aligned, which is what makes `compare` meaningful. `tests/camera.rs` checks it.
//!
//! Orthographic cameras shoot parallel rays along `−ze` from the points of a window of
//! height `ortho_height` centred on the eye; the window's width follows the aspect ratio.

use glam::{Mat4, Vec3, Vec4};
use serde::{Deserialize, Serialize};

use crate::base::Ray;

/// How the camera projects: perspective through the eye, or parallel rays along `−ze`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Projection {
    Perspective,
    Orthographic,
}

/// A pinhole (or orthographic) camera in the course's terms.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub eye: Vec3,
    pub center: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees (perspective only).
    pub fovy_degrees: f32,
    pub near: f32,
    pub far: f32,
    pub width: u32,
    pub height: u32,
    pub projection: Projection,
    /// Height of the view window in world units (orthographic only).
    pub ortho_height: f32,
}

/// The orthonormal eye frame `xe, ye, ze` of the course.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeFrame {
    pub xe: Vec3,
    pub ye: Vec3,
    pub ze: Vec3,
}

/// A camera's primary rays ([`Camera::rays`]): what every ray shares, worked out once.
#[derive(Clone, Copy, Debug)]
pub struct CameraRays {
    frame: EyeFrame,
    /// The view window's `(w, h)`.
    window: (f32, f32),
    /// The image's `(width, height)` in pixels.
    size: (f32, f32),
    /// The window's centre: `eye − near·ze` (perspective), or the eye.
    plane: Vec3,
    /// The eye all rays leave from; `None` for an orthographic camera.
    perspective: Option<Vec3>,
}

impl CameraRays {
    /// `q(x, y)`, the point of the window the ray through image point `(x, y)` passes.
    pub fn window_point(&self, x: f32, y: f32) -> Vec3 {
        let EyeFrame { xe, ye, .. } = self.frame;
        let (w, h) = self.window;
        let s = w * (x / self.size.0 - 0.5);
        let t = h * (0.5 - y / self.size.1);
        self.plane + s * xe + t * ye
    }

    /// The ray through image point `(x, y)`.
    pub fn through(&self, x: f32, y: f32) -> Ray {
        let q = self.window_point(x, y);
        match self.perspective {
            Some(eye) => Ray { origin: eye, direction: (q - eye).normalize() },
            None => Ray { origin: q, direction: -self.frame.ze },
        }
    }
}

/// Why a camera cannot form an image.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CameraError {
    #[error("eye and center are the same point, so there is no view direction")]
    EyeAtCenter,
    #[error("up is parallel to the view direction, so the image has no defined orientation")]
    UpParallelToView,
    #[error("fovy must lie strictly between 0 and 180 degrees, got {0}")]
    FieldOfView(f32),
    #[error("near and far must satisfy 0 < near < far, got near = {near}, far = {far}")]
    ClipDistances { near: f32, far: f32 },
    #[error("the image must have at least one pixel, got {width}×{height}")]
    EmptyImage { width: u32, height: u32 },
    #[error("the image may be at most {max}×{max} pixels, got {width}×{height}")]
    ImageTooLarge { width: u32, height: u32, max: u32 },
    #[error("ortho_height must be positive, got {0}")]
    OrthoHeight(f32),
    #[error("the camera has a NaN or infinite coordinate")]
    NotFinite,
}

impl Camera {
    /// The largest image side: the largest 2D texture on the devices Mirador targets.
    pub const MAX_SIDE: u32 = 16384;

    /// Checks everything the eye frame and the projection divide by.
    pub fn validate(&self) -> Result<(), CameraError> {
        let numbers = [self.fovy_degrees, self.near, self.far, self.ortho_height];
        if !(self.eye.is_finite() && self.center.is_finite() && self.up.is_finite())
            || numbers.iter().any(|x| !x.is_finite())
        {
            return Err(CameraError::NotFinite);
        }
        let view = self.eye - self.center;
        if view.length_squared() <= f32::EPSILON * self.eye.length_squared().max(1.0) {
            return Err(CameraError::EyeAtCenter);
        }
        if self.up.cross(view).length_squared() <= 1e-12 * self.up.length_squared() * view.length_squared() {
            return Err(CameraError::UpParallelToView);
        }
        if self.projection == Projection::Perspective && !(self.fovy_degrees > 0.0 && self.fovy_degrees < 180.0) {
            return Err(CameraError::FieldOfView(self.fovy_degrees));
        }
        if self.projection == Projection::Orthographic && !(self.ortho_height > 0.0) {
            return Err(CameraError::OrthoHeight(self.ortho_height));
        }
        if !(self.near > 0.0 && self.far > self.near) {
            return Err(CameraError::ClipDistances { near: self.near, far: self.far });
        }
        if self.width == 0 || self.height == 0 {
            return Err(CameraError::EmptyImage { width: self.width, height: self.height });
        }
        if self.width > Self::MAX_SIDE || self.height > Self::MAX_SIDE {
            return Err(CameraError::ImageTooLarge { width: self.width, height: self.height, max: Self::MAX_SIDE });
        }
        Ok(())
    }

    /// `ze = normalize(eye − center)`, `xe = normalize(up × ze)`, `ye = ze × xe`.
    pub fn frame(&self) -> EyeFrame {
        let ze = (self.eye - self.center).normalize();
        let xe = self.up.cross(ze).normalize();
        let ye = ze.cross(xe);
        EyeFrame { xe, ye, ze }
    }

    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// Size `(w, h)` of the view window: on the near plane for perspective, the orthographic
    /// window otherwise.
    pub fn window(&self) -> (f32, f32) {
        let h = match self.projection {
            Projection::Perspective => 2.0 * self.near * (self.fovy_degrees.to_radians() / 2.0).tan(),
            Projection::Orthographic => self.ortho_height,
        };
        (self.aspect() * h, h)
    }

    /// The world-space centre of the view-window cell of pixel `(x, y)`, for any real `x, y`
    /// (pixel centres are at `x + ½`): the point the primary ray passes through.
    pub fn window_point(&self, x: f32, y: f32) -> Vec3 {
        self.rays().window_point(x, y)
    }

    /// The primary ray through the image point `(x, y)`; pixel `(i, j)` has its centre at
    /// `(i + ½, j + ½)`.
    pub fn ray_through(&self, x: f32, y: f32) -> Ray {
        self.rays().through(x, y)
    }

    /// The camera's primary rays, its eye frame and window worked out once for all of them.
    pub fn rays(&self) -> CameraRays {
        let frame = self.frame();
        let plane = match self.projection {
            Projection::Perspective => self.eye - self.near * frame.ze,
            Projection::Orthographic => self.eye,
        };
        let perspective = (self.projection == Projection::Perspective).then_some(self.eye);
        let size = (self.width as f32, self.height as f32);
        CameraRays { frame, window: self.window(), size, plane, perspective }
    }

    /// The primary ray through the centre of pixel `(i, j)`.
    pub fn primary_ray(&self, i: u32, j: u32) -> Ray {
        self.ray_through(i as f32 + 0.5, j as f32 + 0.5)
    }

    /// World to eye coordinates: the rows of the rotation are `xe`, `ye`, `ze`.
    pub fn view_from_world(&self) -> Mat4 {
        let EyeFrame { xe, ye, ze } = self.frame();
        Mat4::from_cols(
            Vec4::new(xe.x, ye.x, ze.x, 0.0),
            Vec4::new(xe.y, ye.y, ze.y, 0.0),
            Vec4::new(xe.z, ye.z, ze.z, 0.0),
            Vec4::new(-xe.dot(self.eye), -ye.dot(self.eye), -ze.dot(self.eye), 1.0),
        )
    }

    /// Eye coordinates to wgpu clip space (x, y in [−1, 1], depth in [0, 1] from near to far).
    /// The view window `w × h` maps exactly onto [−1, 1]², so window cells are pixels.
    pub fn clip_from_view(&self) -> Mat4 {
        let (w, h) = self.window();
        let (n, f) = (self.near, self.far);
        match self.projection {
            // x_ndc = (2n/w)·x / −z, y_ndc = (2n/h)·y / −z, depth = f(−z − n) / ((f − n)(−z)).
            Projection::Perspective => Mat4::from_cols(
                Vec4::new(2.0 * n / w, 0.0, 0.0, 0.0),
                Vec4::new(0.0, 2.0 * n / h, 0.0, 0.0),
                Vec4::new(0.0, 0.0, f / (n - f), -1.0),
                Vec4::new(0.0, 0.0, n * f / (n - f), 0.0),
            ),
            // x_ndc = 2x/w, y_ndc = 2y/h, depth = (−z − n)/(f − n).
            Projection::Orthographic => Mat4::from_cols(
                Vec4::new(2.0 / w, 0.0, 0.0, 0.0),
                Vec4::new(0.0, 2.0 / h, 0.0, 0.0),
                Vec4::new(0.0, 0.0, -1.0 / (f - n), 0.0),
                Vec4::new(0.0, 0.0, -n / (f - n), 1.0),
            ),
        }
    }

    pub fn clip_from_world(&self) -> Mat4 {
        self.clip_from_view() * self.view_from_world()
    }

    /// Where the rasterizer puts a world point: `(x, y)` in pixels from the top-left corner of
    /// the image (pixel centres at half-integers) and depth in [0, 1]. `None` behind the eye.
    pub fn project(&self, p: Vec3) -> Option<Vec3> {
        let clip = self.clip_from_world() * p.extend(1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        Some(Vec3::new((ndc.x + 1.0) / 2.0 * self.width as f32, (1.0 - ndc.y) / 2.0 * self.height as f32, ndc.z))
    }
}
