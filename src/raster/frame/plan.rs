//! What a frame draws, decided before anything is recorded: its views (the main camera, the tree
//! of mirrored cameras, the cube faces due), each with its slot, toggles and limits; the light
//! views whose shadow-map layers it may redraw; and which phases run.

use super::super::environment::pass::CubeFace;
use super::super::keys::FrameKey;
use super::super::mirror::pass::{MAX_MIRROR_VIEWS, MirrorNode, plan as plan_mirrors, scissor};
use super::super::shadow::views::{ShadowLayout, shadow_layout_in};
use super::super::view::{FrameView, VIEW_SLOTS, View, ViewKind, ViewSlot};
use crate::raster::geometry::SceneGeometry;
use crate::raster::mirror::Mirror;
use crate::scene::Scene;
use crate::settings::{Prepass, RenderSettings, ShadowMethod};

/// The slots a frame hands out: the main camera, the shadow-map layers, the mirrored cameras,
/// then the cube faces.
const _: () = assert!(
    1 + super::super::shadow::views::MAX_LAYERS as u32
        + MAX_MIRROR_VIEWS
        + 6 * super::super::environment::MAX_ENV_CUBES as u32
        <= VIEW_SLOTS
);

pub struct FramePlan {
    /// The size the frame is drawn at.
    pub size: (u32, u32),
    /// Every shadowed light's views (what the shadow uniform describes).
    pub lights: ShadowLayout,
    /// The layers pass 1 fills: the lights' views for shadow maps, none for projected shadows.
    pub maps: ShadowLayout,
    /// The view slot of shadow-map layer 0 (layer `k` is slot `first + k`).
    pub first_shadow_slot: u32,
    /// Object-precision shadows: each view draws the polygons into a mask of its own pixels.
    pub projected: bool,
    /// Transparent surfaces are drawn after the opaque ones in their own pass (`false`: as
    /// opaque surfaces, or there are none).
    pub transparency: bool,
    pub main: FrameView,
    /// The mirror tree, breadth first, and each node's view.
    pub mirror_nodes: Vec<MirrorNode>,
    pub mirror_views: Vec<FrameView>,
    /// The cube faces due this frame, each view's kind naming its cube and face.
    pub cube_views: Vec<FrameView>,
}

impl FramePlan {
    /// Every view of the frame: cube faces, mirrored cameras, the main camera.
    pub fn views(&self) -> impl Iterator<Item = &FrameView> {
        self.cube_views.iter().chain(&self.mirror_views).chain(std::iter::once(&self.main))
    }
}

/// Plans a frame of `scene` drawn at `size`, with the cube faces `faces` due.
pub fn plan(
    scene: &Scene,
    geometry: &SceneGeometry,
    settings: &RenderSettings,
    (size, mirrors): ((u32, u32), &[Mirror]),
    faces: Vec<CubeFace>,
) -> FramePlan {
    let shadows = &settings.shadows;
    let lights = shadow_layout_in(scene, geometry.bounds, shadows);
    let projected = shadows.enabled && shadows.method == ShadowMethod::Projected;
    let maps = if projected { ShadowLayout::default() } else { lights.clone() };
    let transmission = shadows.transmission && geometry.has_transparent();
    let key = FrameKey::new(settings, !lights.views.is_empty(), transmission);
    let prepass = projected
        || match settings.raster.depth_prepass {
            Prepass::Always => true,
            Prepass::Never => false,
            Prepass::Auto => geometry.triangles() * 4 < u64::from(size.0) * u64::from(size.1),
        };
    let main_view = View::of_camera(&scene.camera);
    let main = FrameView {
        kind: ViewKind::Main,
        slot: ViewSlot(0),
        view: main_view,
        key,
        skip: None,
        scissor: None,
        prepass,
        projected,
    };
    let first_shadow_slot = 1;
    let mut next = first_shadow_slot + maps.views.len() as u32;
    let mut slot = || {
        next += 1;
        ViewSlot(next - 1)
    };
    let (mirror_nodes, truncated) = if settings.mirrors.enabled {
        plan_mirrors(&main_view, mirrors, settings.mirrors.depth)
    } else {
        (Vec::new(), false)
    };
    if truncated {
        log::debug!("more than {MAX_MIRROR_VIEWS} mirrored views: the deepest are left out");
    }
    let secondary = |kind, slot, view, skip, scissor| FrameView {
        kind,
        slot,
        view,
        key,
        skip,
        scissor,
        // The projected polygons are depth-tested against the view's own surfaces.
        prepass: projected,
        projected,
    };
    let mirror_views = mirror_nodes
        .iter()
        .enumerate()
        .map(|(k, node)| {
            let skip = Some(mirrors[node.mirror].object);
            secondary(ViewKind::Mirror(k), slot(), node.view, skip, Some(scissor(node.window, size)))
        })
        .collect();
    let cube_views = faces
        .into_iter()
        .map(|face| {
            let kind = ViewKind::CubeFace { cube: face.cube, face: face.face };
            secondary(kind, slot(), face.view, Some(face.object), None)
        })
        .collect();
    FramePlan {
        size,
        lights,
        maps,
        first_shadow_slot,
        projected,
        transparency: settings.transparency.enabled && geometry.has_transparent(),
        main,
        mirror_nodes,
        mirror_views,
        cube_views,
    }
}
