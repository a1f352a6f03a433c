//! The light's point of view for pass 1 of the shadow-map algorithm (docs/course/05-shadows.md#shadow-maps-image-precision: "el papel
//! del observador lo juega la fuente de luz"): one view per map layer.
//!
//! - **Directional light**: an orthographic view along the light (the observer is infinitely
//!   far away). Its window covers the part of the view frustum within `shadows.distance` of the
//!   eye, clipped to the scene's bounds; its depth range covers the whole scene along the light,
//!   so casters outside the view still cast into it.
//! - **Spot light**: a perspective view from the light along its axis, wide enough for its cone.
//! - **Point light**: six perspective views, the faces of a cube around the light (+x, −x, +y,
//!   −y, +z, −z). Each face's field of view is a little over 90° so that filtering taps near a
//!   face's edge still find texels of the same face: without that margin PCF would clamp at the
//!   edges and show seams.
//!
//! Depth is the light's clip-space depth, not the Euclidean distance `‖q − y‖` of the seed: along
//! one ray from the light the two grow together, so "is anything nearer the light along this ray"
//! gets the same answer.

use glam::{Mat4, Vec3, Vec4};

use crate::scene::{LightKind, Scene};
use crate::settings::{ShadowFit, ShadowSettings};

pub use crate::settings::MAX_SHADOWED_LIGHTS;
/// Six layers for each point light.
pub const MAX_LAYERS: usize = crate::shaders::constants::MAX_SHADOW_LAYERS;

/// Extra field of view of each cube face, in map texels on each side.
const CUBE_MARGIN_TEXELS: f32 = 3.0;

/// One layer of the shadow maps: a light seen as a camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightView {
    /// Index into `Scene::lights`.
    pub light: usize,
    pub clip_from_world: Mat4,
    pub perspective: bool,
    /// World size of one map texel: at unit distance from the light for perspective views.
    pub texel_size: f32,
    /// near/far of a perspective view (0 for orthographic ones), to turn its depth back into
    /// distance: `z/far = r / (1 − depth·(1 − r))`.
    pub depth_ratio: f32,
}

/// The views of every shadowed light, and where each light's layers start.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShadowLayout {
    pub views: Vec<LightView>,
    /// Per scene light: its first layer, or `None` when it casts no shadows.
    pub first_layer: Vec<Option<u32>>,
}

impl ShadowLayout {
    /// The world-space corners of layer `layer`'s view volume (near face first), for drawing
    /// frusta in teaching views.
    pub fn corners(&self, layer: usize) -> [Vec3; 8] {
        crate::raster::view::frustum_corners(self.views[layer].clip_from_world)
    }
}

/// An up vector that is not parallel to `direction`.
fn up_for(direction: Vec3) -> Vec3 {
    if direction.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y }
}

/// The scene's bounds, or a unit box for an empty scene.
fn or_unit_box(bounds: Option<(Vec3, Vec3)>) -> (Vec3, Vec3) {
    bounds.unwrap_or((Vec3::splat(-1.0), Vec3::splat(1.0)))
}

/// The eight corners of an axis-aligned box.
fn box_corners((lo, hi): (Vec3, Vec3)) -> [Vec3; 8] {
    std::array::from_fn(|k| {
        Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// Near and far distances from `position` that hold the whole scene, for perspective views.
/// Perspective depth spends its precision near the near plane (a depth step is `Δz ≈ ε·z²/near`),
/// so near is kept at 1/500 of far: anything closer to the light than that is clipped from its
/// map and casts no shadow.
fn depth_range(position: Vec3, bounds: (Vec3, Vec3)) -> (f32, f32) {
    let radius = ((bounds.1 - bounds.0).length() / 2.0).max(1e-3);
    let far = box_corners(bounds).iter().map(|c| c.distance(position)).fold(0.0, f32::max).max(radius * 1e-2);
    (far * 2e-3, far * 1.01)
}

/// The part of the view frustum that a directional light's map must cover.
fn view_frustum_points(scene: &Scene, settings: &ShadowSettings) -> Vec<Vec3> {
    let camera = &scene.camera;
    let automatic = 4.0 * camera.eye.distance(camera.center);
    let reach = if settings.distance > 0.0 { settings.distance } else { automatic }.min(camera.far).max(camera.near);
    let world_from_clip = camera.clip_from_world().inverse();
    // The depth of the point `reach` ahead, in the camera's clip space.
    let ahead = camera.eye - reach * camera.frame().ze;
    let clip = camera.clip_from_world() * ahead.extend(1.0);
    let far_depth = (clip.z / clip.w).clamp(0.0, 1.0);
    let mut points = Vec::with_capacity(8);
    for z in [0.0, far_depth] {
        for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            points.push(world_from_clip.project_point3(Vec3::new(x, y, z)));
        }
    }
    points
}

fn directional_view(scene: &Scene, bounds: (Vec3, Vec3), settings: &ShadowSettings, direction: Vec3) -> (Mat4, f32) {
    let center = (bounds.0 + bounds.1) / 2.0;
    let radius = ((bounds.1 - bounds.0).length() / 2.0).max(1e-3);
    let view = glam::camera::rh::view::look_to_mat4(center - 2.0 * radius * direction, direction, up_for(direction));
    let in_light = |points: &[Vec3]| {
        points.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| {
            let q = view.transform_point3(*p);
            (lo.min(q), hi.max(q))
        })
    };
    let (scene_lo, scene_hi) = in_light(&box_corners(bounds));
    let (view_lo, view_hi) = match settings.fit {
        ShadowFit::View => in_light(&view_frustum_points(scene, settings)),
        ShadowFit::Scene => (scene_lo, scene_hi),
    };
    // The window: the view frustum's footprint, but never beyond the scene.
    let lo = view_lo.max(scene_lo);
    let hi = view_hi.min(scene_hi);
    let (lo, hi) = if lo.x < hi.x && lo.y < hi.y { (lo, hi) } else { (scene_lo, scene_hi) };
    let pad = 1e-3 * radius;
    // View space looks down −z: the scene lies between −scene_hi.z (nearest) and −scene_lo.z.
    let projection = glam::camera::rh::proj::directx::orthographic(
        lo.x - pad,
        hi.x + pad,
        lo.y - pad,
        hi.y + pad,
        (-scene_hi.z - pad).max(1e-4 * radius),
        -scene_lo.z + pad,
    );
    let texel = ((hi.x - lo.x).max(hi.y - lo.y) + 2.0 * pad) / settings.map_size as f32;
    (projection * view, texel)
}

fn perspective_view(position: Vec3, direction: Vec3, fov: f32, bounds: (Vec3, Vec3)) -> (Mat4, f32) {
    let (near, far) = depth_range(position, bounds);
    let view = glam::camera::rh::view::look_to_mat4(position, direction, up_for(direction));
    (glam::camera::rh::proj::directx::perspective(fov, 1.0, near, far) * view, near / far)
}

/// The faces of the cube around a point light: view direction and up vector of each.
pub const CUBE_FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Y),
    (Vec3::NEG_X, Vec3::NEG_Y),
    (Vec3::Y, Vec3::Z),
    (Vec3::NEG_Y, Vec3::NEG_Z),
    (Vec3::Z, Vec3::NEG_Y),
    (Vec3::NEG_Z, Vec3::NEG_Y),
];

/// The layers of every shadowed light: the first [`MAX_SHADOWED_LIGHTS`] lights with any
/// intensity.
pub fn shadow_layout(scene: &Scene, settings: &ShadowSettings) -> ShadowLayout {
    shadow_layout_in(scene, scene.bounds(), settings)
}

/// [`shadow_layout`] with the scene's bounds already known (the renderer computes them once per
/// scene).
pub fn shadow_layout_in(scene: &Scene, bounds: Option<(Vec3, Vec3)>, settings: &ShadowSettings) -> ShadowLayout {
    let mut layout = ShadowLayout { views: Vec::new(), first_layer: vec![None; scene.lights.len()] };
    if !settings.enabled {
        return layout;
    }
    let bounds = or_unit_box(bounds);
    let size = settings.map_size as f32;
    let mut shadowed = 0;
    for (index, light) in scene.lights.iter().enumerate() {
        if light.intensity <= 0.0 || light.color == Vec3::ZERO {
            continue;
        }
        if shadowed == MAX_SHADOWED_LIGHTS {
            log::warn!("only the first {MAX_SHADOWED_LIGHTS} lights cast shadows; `{}` does not", light.name);
            continue;
        }
        shadowed += 1;
        layout.first_layer[index] = Some(layout.views.len() as u32);
        match light.kind {
            LightKind::Directional { direction } => {
                let (clip_from_world, texel_size) = directional_view(scene, bounds, settings, direction);
                layout.views.push(LightView {
                    light: index,
                    clip_from_world,
                    perspective: false,
                    texel_size,
                    depth_ratio: 0.0,
                });
            }
            LightKind::Spot { position, direction, outer, .. } => {
                let fov = (2.0 * outer + 4.0 / size).clamp(0.01, std::f32::consts::PI - 0.01);
                let (clip_from_world, depth_ratio) = perspective_view(position, direction, fov, bounds);
                layout.views.push(LightView {
                    light: index,
                    clip_from_world,
                    perspective: true,
                    texel_size: 2.0 * (fov / 2.0).tan() / size,
                    depth_ratio,
                });
            }
            LightKind::Point { position } => {
                // tan(fov/2) = 1 + margin: the face's window is widened by the margin's texels.
                let half_width = 1.0 + 2.0 * CUBE_MARGIN_TEXELS / size;
                let fov = 2.0 * half_width.atan();
                for (direction, up) in CUBE_FACES {
                    let (near, far) = depth_range(position, bounds);
                    let view = glam::camera::rh::view::look_to_mat4(position, direction, up);
                    let projection = glam::camera::rh::proj::directx::perspective(fov, 1.0, near, far);
                    layout.views.push(LightView {
                        light: index,
                        clip_from_world: projection * view,
                        perspective: true,
                        texel_size: 2.0 * half_width / size,
                        depth_ratio: near / far,
                    });
                }
            }
        }
    }
    layout
}

/// The cube face (0..6, in [`CUBE_FACES`] order) a direction from a point light falls in: the
/// axis of its largest component. The shader picks faces the same way.
pub fn cube_face(direction: Vec3) -> usize {
    let a = direction.abs();
    if a.x >= a.y && a.x >= a.z {
        if direction.x >= 0.0 { 0 } else { 1 }
    } else if a.y >= a.z {
        if direction.y >= 0.0 { 2 } else { 3 }
    } else if direction.z >= 0.0 {
        4
    } else {
        5
    }
}

/// Where `p` lands in a view: map coordinates in [0, 1]² (v down, as textures are addressed) and
/// depth in [0, 1]; `None` behind a perspective light.
pub fn project(view: &LightView, p: Vec3) -> Option<Vec3> {
    let clip: Vec4 = view.clip_from_world * p.extend(1.0);
    if clip.w <= 0.0 {
        return None;
    }
    let ndc = clip.truncate() / clip.w;
    Some(Vec3::new(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y, ndc.z))
}
