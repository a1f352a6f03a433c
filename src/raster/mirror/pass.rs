//! The planar-mirror pass (docs/course/07-planar-mirrors.md): before the main view is shaded, every mirror it
//! sees is drawn from its mirrored camera into an image of the frame's size; the mirror's own
//! fragments then add `kps·MPS` times that image at their pixel (`MIRROR` in
//! `shaders/scene.wgsl`), as the tracer adds `kps·MPS·L(r)`.
//!
//! - **Recursion.** A mirrored view sees the other mirrors too, each of which needs its own view
//!   of that view: the views form a tree, planned breadth first ([`plan`]) up to
//!   `mirrors.depth` levels and [`MAX_MIRROR_VIEWS`] views, and drawn deepest first so that each
//!   view's mirrors find their images ready. At the deepest level mirrors show their plain
//!   material, as the tracer's mirror rays stop at `max_depth`: two facing mirrors give the same
//!   corridor of images in both renderers.
//! - **Two-sided.** Mirador's planes are two-sided in both renderers, so a camera behind a mirror
//!   sees a mirror too: the view mirrors about the plane turned towards it. A mirror whose plane
//!   passes through the camera is seen edge on and gets no view.
//! - **Only where it shows.** A view's image is read only inside its mirror as the parent view
//!   sees it, so each view draws inside that screen rectangle (a scissor), nested views inside
//!   their parents'; a mirror whose rectangle misses its parent's gets no view at all.
//! - **What a mirrored view draws.** The whole frame's passes but the depth prepass and the
//!   teaching overlays: opaque surfaces (the mirror it looks out of left out, as it lies on the
//!   view's near plane), their mirrors with their images, and the transparent surfaces in the
//!   chosen order (its winding flipped). Shadow maps are the frame's; object-precision shadows
//!   are a mask of the main view's pixels, so mirrored views draw without them.

use super::{Mirror, Side, camera_side, find_mirrors, mirrored_view};
use crate::raster::scene_pass::{MirrorImages, ScenePass};
use crate::raster::targets::{FrameTargets, ViewImage};
use crate::raster::view::{View, frustum_corners};
use crate::scene::Scene;

/// The most mirrored cameras one frame draws (mirrors that see each other, at every depth).
pub const MAX_MIRROR_VIEWS: u32 = 32;

/// The planar mirrors of a scene and the targets their mirrored cameras draw into.
#[derive(Default)]
pub struct MirrorPass {
    /// The scene's mirrors, found by [`Self::load`]; transparent ones are left out (a mirror's
    /// reflection is drawn by the opaque pass, so glass that reflects is drawn as glass alone).
    pub mirrors: Vec<Mirror>,
    /// One mirrored camera's targets per node of the largest frame so far, and the group 3
    /// through which its mirror reads its image (made once with the targets).
    targets: Vec<(FrameTargets, wgpu::BindGroup)>,
}

impl MirrorPass {
    /// Finds the planar mirrors of `scene`, in place of the last scene's; returns their objects.
    pub fn load(&mut self, scene: &Scene) -> Vec<usize> {
        let (mut mirrors, warnings) = find_mirrors(scene);
        for warning in warnings {
            log::warn!("{warning}");
        }
        mirrors.retain(|m| {
            let object = &scene.objects[m.object];
            let transparent = scene.materials[object.material.0].is_transparent();
            if transparent {
                log::warn!("`{}` is transparent: the rasterizer draws it without its reflection", object.name);
            }
            !transparent
        });
        self.mirrors = mirrors;
        self.targets.clear();
        self.mirrors.iter().map(|m| m.object).collect()
    }

    /// Makes targets of `size` for `nodes` mirrored cameras (the targets of another size are
    /// remade).
    pub fn prepare(&mut self, device: &wgpu::Device, scene_pass: &ScenePass, nodes: usize, size: (u32, u32)) {
        if self.targets.first().is_some_and(|(t, _)| t.size != size) {
            self.targets.clear();
        }
        while self.targets.len() < nodes {
            let targets = FrameTargets::new(device, size);
            let image = scene_pass.mirror_image_group(device, &targets.hdr.view);
            self.targets.push((targets, image));
        }
    }

    /// Makes `image` at full size in every mirrored camera's targets (an image made on demand).
    pub fn ensure_images(&mut self, device: &wgpu::Device, image: ViewImage) {
        for (targets, _) in &mut self.targets {
            targets.images.ensure(device, image, targets.size);
        }
    }

    /// The targets node `k`'s camera draws into.
    pub fn targets(&self, k: usize) -> &FrameTargets {
        &self.targets[k].0
    }

    /// The reflections the mirrors seen from `parent` (`None`: the main view) show: every part of
    /// every mirror, with the image of the node that looks out of it, where there is one.
    pub fn images(&self, nodes: &[MirrorNode], parent: Option<usize>) -> MirrorImages {
        let mut images = MirrorImages::default();
        for (index, mirror) in self.mirrors.iter().enumerate() {
            let child = nodes.iter().position(|n| n.parent == parent && n.mirror == index);
            let image = child.map(|k| self.targets[k].1.clone());
            images.parts.entry(mirror.object).or_default().push((mirror.indices.clone(), image));
        }
        images
    }
}

/// One mirrored camera of the frame.
#[derive(Clone, Debug, PartialEq)]
pub struct MirrorNode {
    pub view: View,
    /// The mirror this camera looks out of (an index into the scene's mirrors).
    pub mirror: usize,
    /// The node whose view sees that mirror; `None` for the main view.
    pub parent: Option<usize>,
    /// 1 for a mirror the main camera sees, 2 for a mirror seen in it, …
    pub level: u32,
    /// Where on screen this view's image is read (`[x0, y0, x1, y1]` in normalized device
    /// coordinates): around the mirror as its parent view sees it, within the parent's own
    /// window. The view draws only there (a scissor): the rest of its image is never shown.
    pub window: [f32; 4],
}

/// The mirrored cameras of a frame seen from `main`, breadth first (every parent before its
/// children), at most `depth` levels deep and [`MAX_MIRROR_VIEWS`] views. The second value says
/// whether views were left out for that limit.
pub fn plan(main: &View, mirrors: &[Mirror], depth: u32) -> (Vec<MirrorNode>, bool) {
    let mut nodes: Vec<MirrorNode> = Vec::new();
    let mut truncated = false;
    // (the view looking, its node, the mirror it looks out of, its level, its window)
    let mut queue = std::collections::VecDeque::from([(*main, None, None, 0, FULL_WINDOW)]);
    while let Some((view, node, from, level, window)) = queue.pop_front() {
        if level >= depth {
            continue;
        }
        for (index, mirror) in mirrors.iter().enumerate() {
            if Some(index) == from || !in_view(&view, mirror) {
                continue;
            }
            let Some(window) = intersect(window, screen_window(&view, mirror)) else { continue };
            let plane = match camera_side(&view, &mirror.plane) {
                Side::Front => mirror.plane,
                Side::Back => mirror.plane.flipped(),
                Side::EdgeOn => continue,
            };
            if nodes.len() as u32 == MAX_MIRROR_VIEWS {
                truncated = true;
                break;
            }
            let child = MirrorNode {
                view: mirrored_view(&view, &plane),
                mirror: index,
                parent: node,
                level: level + 1,
                window,
            };
            queue.push_back((child.view, Some(nodes.len()), Some(index), level + 1, window));
            nodes.push(child);
        }
    }
    (nodes, truncated)
}

/// The whole screen, in normalized device coordinates.
const FULL_WINDOW: [f32; 4] = [-1.0, -1.0, 1.0, 1.0];

/// The screen rectangle around `mirror`'s corners as `view` projects them; the whole screen when
/// a corner lies behind the eye (its projection would wrap around).
fn screen_window(view: &View, mirror: &Mirror) -> [f32; 4] {
    let mut window = [f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY];
    for corner in mirror.corners {
        let clip = view.clip_from_world * corner.extend(1.0);
        if clip.w <= 1e-6 {
            return FULL_WINDOW;
        }
        let (x, y) = (clip.x / clip.w, clip.y / clip.w);
        window = [window[0].min(x), window[1].min(y), window[2].max(x), window[3].max(y)];
    }
    window
}

/// The common part of two windows, `None` when they do not overlap.
fn intersect(a: [f32; 4], b: [f32; 4]) -> Option<[f32; 4]> {
    let window = [a[0].max(b[0]), a[1].max(b[1]), a[2].min(b[2]), a[3].min(b[3])];
    (window[0] < window[2] && window[1] < window[3]).then_some(window)
}

/// A window in pixels of a `size` target, `[x, y, width, height]` from the top-left corner,
/// grown to whole pixels (and one more on each side, for the rasterizer's edge rules).
pub fn scissor(window: [f32; 4], size: (u32, u32)) -> [u32; 4] {
    let (w, h) = (size.0 as f32, size.1 as f32);
    let x0 = ((window[0] + 1.0) / 2.0 * w - 1.0).floor().clamp(0.0, w);
    let x1 = ((window[2] + 1.0) / 2.0 * w + 1.0).ceil().clamp(0.0, w);
    let y0 = ((1.0 - window[3]) / 2.0 * h - 1.0).floor().clamp(0.0, h);
    let y1 = ((1.0 - window[1]) / 2.0 * h + 1.0).ceil().clamp(0.0, h);
    [
        x0 as u32,
        y0 as u32,
        ((x1 - x0).max(1.0) as u32).min(size.0 - x0 as u32),
        ((y1 - y0).max(1.0) as u32).min(size.1 - y0 as u32),
    ]
}

/// Whether any of `mirror` may be inside `view`'s volume: false only when all four corners lie
/// beyond one of its six clip planes.
fn in_view(view: &View, mirror: &Mirror) -> bool {
    let clip: Vec<glam::Vec4> = mirror.corners.iter().map(|c| view.clip_from_world * c.extend(1.0)).collect();
    let outside = |test: fn(glam::Vec4) -> bool| clip.iter().all(|&c| test(c));
    !(outside(|c| c.x < -c.w)
        || outside(|c| c.x > c.w)
        || outside(|c| c.y < -c.w)
        || outside(|c| c.y > c.w)
        || outside(|c| c.z < 0.0)
        || outside(|c| c.z > c.w))
}

/// The corners of every mirrored camera's view volume, for the `camera` teaching view.
pub fn volumes(nodes: &[MirrorNode]) -> Vec<[glam::Vec3; 8]> {
    nodes.iter().map(|node| frustum_corners(node.view.clip_from_world)).collect()
}
