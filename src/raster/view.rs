//! Views: a camera as one pass sees it. One frame draws the scene from several cameras (the main
//! camera, each light's view for pass 1 of the shadow maps, mirrored cameras and the six faces of
//! environment cubes), so each view has its own slot in one uniform buffer, chosen per pass by a
//! dynamic offset of group 0.
//!
//! Slots are written with `queue.write_buffer` before the frame's commands are submitted: every
//! pass of the frame reads its own slot, so no write can overtake another within the frame.

use glam::{Mat4, Vec3, Vec4};

use super::targets::FrameTargets;
use super::uniforms::GpuView;
use crate::scene::{Camera, Projection};

/// One view of the frame and the targets it draws into: what every phase of a view is given
/// (`record_view`), and what the passes' `prepare` is given one of per view.
pub type ViewTargets<'a> = (&'a FrameView, &'a FrameTargets);

/// A camera for one pass: where it looks from and how it projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub clip_from_world: Mat4,
    pub eye: Vec3,
    /// Every view ray runs along `-view_axis` (orthographic cameras).
    pub orthographic: bool,
    /// `ze` of the eye frame: from the scene towards the eye.
    pub view_axis: Vec3,
    /// The view is mirrored, so its triangles' winding flips.
    pub mirrored: bool,
    /// Points `p` with `plane·(p, 1) < 0` are not drawn.
    pub clip_plane: Option<Vec4>,
    /// A mirrored camera's `clip_from_world` before its last reflection, the one about its clip
    /// plane: `clip_from_world = clip_from_reflected · R`. `clip_from_world` itself where no
    /// mirror made the view. The planar-mirror lab draws with it and the student's `R`
    /// (`MIRROR_BY_HAND` in shaders/common/surface.wgsl).
    pub clip_from_reflected: Mat4,
}

impl View {
    /// The scene camera's view.
    pub fn of_camera(camera: &Camera) -> View {
        View {
            clip_from_world: camera.clip_from_world(),
            eye: camera.eye,
            orthographic: camera.projection == Projection::Orthographic,
            view_axis: camera.frame().ze,
            mirrored: false,
            clip_plane: None,
            clip_from_reflected: camera.clip_from_world(),
        }
    }

    /// A view that only projects (a light's view for pass 1 of the shadow maps, which shades
    /// nothing and so needs no eye).
    pub fn projection_only(clip_from_world: Mat4) -> View {
        View {
            clip_from_world,
            eye: Vec3::ZERO,
            orthographic: false,
            view_axis: Vec3::Z,
            mirrored: false,
            clip_plane: None,
            clip_from_reflected: clip_from_world,
        }
    }

    pub fn to_gpu(&self) -> GpuView {
        GpuView {
            clip_from_world: self.clip_from_world.to_cols_array_2d(),
            world_from_clip: self.clip_from_world.inverse().to_cols_array_2d(),
            eye: self.eye.to_array(),
            orthographic: u32::from(self.orthographic),
            view_axis: self.view_axis.to_array(),
            mirrored: u32::from(self.mirrored),
            clip_plane: self.clip_plane.unwrap_or(Vec4::ZERO).to_array(),
            clip_from_reflected: self.clip_from_reflected.to_cols_array_2d(),
        }
    }
}

/// Where a view lives in the frame's view buffer: an index the frame's plan hands out, one per
/// camera drawn this frame (the main camera, each shadow-map layer drawn, each mirrored camera,
/// each cube face).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ViewSlot(pub u32);

/// Slots one frame can hold: the main camera, 24 shadow-map layers, 32 mirrored cameras and the
/// faces of 8 cubes fit with room to spare (the plan checks its views against it).
pub const VIEW_SLOTS: u32 = 128;

/// What kind of camera a view is, and what it is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewKind {
    /// The scene's camera.
    Main,
    /// The mirrored camera of node `n` of the mirror tree (`super::mirror::pass`).
    Mirror(usize),
    /// Face `face` of the dynamic environment cube of the object with cube layer `cube`.
    CubeFace { cube: usize, face: usize },
}

impl ViewKind {
    /// Its name in a frame capture's debug groups.
    pub fn name(self) -> String {
        match self {
            ViewKind::Main => "main view".to_owned(),
            ViewKind::Mirror(n) => format!("mirrored view {n}"),
            ViewKind::CubeFace { cube, face } => format!("cube {cube}, face {face}"),
        }
    }
}

/// One camera of the frame, as every per-view phase (opaque, volumes, transparent) draws it.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameView {
    pub kind: ViewKind,
    pub slot: ViewSlot,
    pub view: View,
    /// The toggles its shading variants are compiled with.
    pub key: super::keys::FrameKey,
    /// The object the view looks out of, left out of it: the mirror a mirrored camera looks
    /// through (it lies on the view's near plane), or the object a cube is drawn from.
    pub skip: Option<usize>,
    /// Draw only inside `[x, y, width, height]` of the targets; `None`: everywhere.
    pub scissor: Option<[u32; 4]>,
    /// Draw a depth prepass first, then shade only the nearest surface.
    pub prepass: bool,
    /// Draw object-precision shadows into the view's mask (`ViewImage::ProjectedMask` of its
    /// targets), which its shading then reads: every view of the projected method.
    pub projected: bool,
}

/// The eight world-space corners of the volume a `clip_from_world` matrix sees (`x, y` = ±1,
/// `z` = 0 or 1), corner `k` with bit 0 for `x`, bit 1 for `y`, bit 2 for `z`.
pub fn frustum_corners(clip_from_world: Mat4) -> [Vec3; 8] {
    let world_from_clip = clip_from_world.inverse();
    std::array::from_fn(|k| {
        let x = if k & 1 == 0 { -1.0 } else { 1.0 };
        let y = if k & 2 == 0 { -1.0 } else { 1.0 };
        let z = if k & 4 == 0 { 0.0 } else { 1.0 };
        world_from_clip.project_point3(Vec3::new(x, y, z))
    })
}

/// One uniform buffer holding every view of the frame, a slot each.
pub struct ViewBuffer {
    pub buffer: wgpu::Buffer,
    stride: u64,
}

impl ViewBuffer {
    pub fn new(device: &wgpu::Device) -> ViewBuffer {
        let alignment = u64::from(device.limits().min_uniform_buffer_offset_alignment);
        let stride = (std::mem::size_of::<GpuView>() as u64).next_multiple_of(alignment);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("view::buffer"),
            size: stride * u64::from(VIEW_SLOTS),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ViewBuffer { buffer, stride }
    }

    pub fn write(&self, queue: &wgpu::Queue, slot: ViewSlot, view: &View) {
        queue.write_buffer(&self.buffer, u64::from(slot.0) * self.stride, bytemuck::bytes_of(&view.to_gpu()));
    }

    /// The dynamic offset that selects `slot` in group 0.
    pub fn offset(&self, slot: ViewSlot) -> u32 {
        (u64::from(slot.0) * self.stride) as u32
    }

    /// The binding of one slot (a dynamic-offset uniform of one view's size).
    pub fn binding(&self) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.buffer,
            offset: 0,
            size: wgpu::BufferSize::new(std::mem::size_of::<GpuView>() as u64),
        })
    }
}
