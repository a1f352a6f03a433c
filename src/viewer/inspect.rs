//! The viewer's inspect mode (key I, then a click; or the script step `inspect X Y`): both
//! renderers explain the pixel (`crate::explain`). A window shows the two columns side by side,
//! and the tracer's ray tree is drawn over the 3D view in world space, so it stays where it is as
//! the camera orbits and can be looked at from the side: the primary ray white, reflected rays
//! cyan, refracted ones green, rays continued past a blended surface grey, shadow rays yellow
//! where they reach their light and red up to the occluder that blocks them. Beside it, the
//! rasterizer's stand-ins for those rays, in magenta: the mirrored camera a planar mirror was
//! drawn from, the centre a cube map was captured at (with the direction it was read along), and
//! the shadow-map texels the lookups read.

use egui::{Color32, Pos2, Rect, Stroke};
use glam::{Vec3, Vec4Swizzles};

use crate::explain::{Explainer, Explanation};
use crate::gpu::Gpu;
use crate::scene::{Camera, Scene};
use crate::settings::RenderSettings;
use crate::shaders::Wgsl;
use crate::trace::explain::{RayKind, RayNode};

pub(in crate::viewer) const PRIMARY: Color32 = Color32::WHITE;
pub(in crate::viewer) const REFLECTED: Color32 = Color32::from_rgb(0, 220, 255);
pub(in crate::viewer) const REFRACTED: Color32 = Color32::from_rgb(80, 255, 120);
pub(in crate::viewer) const CONTINUED: Color32 = Color32::from_gray(160);
pub(in crate::viewer) const SHADOW_LIT: Color32 = Color32::from_rgb(255, 220, 0);
pub(in crate::viewer) const SHADOW_BLOCKED: Color32 = Color32::from_rgb(255, 40, 40);
pub(in crate::viewer) const STAND_IN: Color32 = Color32::from_rgb(255, 0, 255);

/// An inspected pixel: its explanation and where the scene's lights are.
pub struct Inspection {
    pub explanation: Explanation,
    /// Each light's position (`None`: directional) and direction towards it.
    lights: Vec<(String, Option<Vec3>)>,
    /// How far a ray that leaves the scene is drawn.
    reach: f32,
}

impl Inspection {
    /// Explains `pixel` of `scene` as its camera sees it now (its size: the 3D view's), the
    /// rasterizer's side drawn by passes compiled from `wgsl` (what the view draws with).
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        settings: &RenderSettings,
        pixel: (u32, u32),
        wgsl: Wgsl,
    ) -> anyhow::Result<Inspection> {
        let explanation = Explainer::with_wgsl(gpu, scene, settings, wgsl)?.explain(gpu, pixel)?;
        let lights = scene.lights.iter().map(|l| (l.name.clone(), l.position())).collect();
        let reach = scene.bounds().map_or(10.0, |(lo, hi)| (hi - lo).length());
        Ok(Inspection { explanation, lights, reach })
    }

    /// One line for the notices.
    pub fn summary(&self) -> String {
        let [x, y] = self.explanation.pixel;
        match &self.explanation.diagnosis {
            Some(diagnosis) => format!("inspected ({x}, {y}): {diagnosis}"),
            None => match &self.explanation.nearest {
                Some(n) => format!(
                    "inspected ({x}, {y}): the two renderers agree; the nearest pixel that differs is ({}, {})",
                    n.pixel[0], n.pixel[1]
                ),
                None => format!("inspected ({x}, {y}): the two renderers agree"),
            },
        }
    }
}

/// The explanation's window: the two columns, the diagnosis, the ray tree.
pub fn window(ctx: &egui::Context, inspection: &Inspection, open: &mut bool) {
    let [x, y] = inspection.explanation.pixel;
    egui::Window::new(format!("pixel ({x}, {y}): the rasterizer and the ray tracer"))
        .id(egui::Id::unique("mirador::inspect"))
        .open(open)
        .anchor(egui::Align2::LEFT_BOTTOM, egui::vec2(8.0, -8.0))
        .default_size(egui::vec2(900.0, 230.0))
        .resizable(true)
        .show(ctx, |ui| {
            egui::ScrollArea::both().show(ui, |ui| {
                let text = crate::explain::text::render(&inspection.explanation);
                ui.add(
                    egui::Label::new(egui::RichText::new(text).monospace().size(11.0))
                        .wrap_mode(egui::TextWrapMode::Extend),
                );
            });
        });
}

/// Draws the ray tree and the stand-ins over the 3D view `rect` (`ppp` pixels per point), as
/// `camera` sees the world now.
pub fn draw(painter: &egui::Painter, inspection: &Inspection, camera: &Camera, (rect, ppp): (Rect, f32)) {
    let mut camera = camera.clone();
    (camera.width, camera.height) =
        (((rect.width() * ppp).round() as u32).max(1), ((rect.height() * ppp).round() as u32).max(1));
    let projector = Projector { camera: &camera, rect, ppp };
    let line =
        |a: Vec3, b: Vec3, colour: Color32, width: f32| projector.segment(painter, a, b, Stroke::new(width, colour));
    walk(&inspection.explanation.trace.rays, inspection, &line, &projector, painter);
    // The rasterizer's stand-ins.
    let raster = &inspection.explanation.raster;
    if let Some(surface) = &raster.surface {
        if let Some(mirror) = &surface.mirror {
            projector.marker(painter, mirror.mirrored_eye, "mirrored camera");
            line(mirror.mirrored_eye, surface.point, STAND_IN, 1.5);
        }
        if let Some(environment) = &surface.environment
            && let Some(centre) = environment.centre
        {
            projector.marker(painter, centre, "cube's centre");
            line(centre, centre + inspection.reach * 0.3 * environment.direction, STAND_IN, 1.5);
        }
    }
    for light in &raster.lights {
        if let Some(corners) = light.shadow.as_ref().and_then(|s| s.footprint) {
            for k in 0..4 {
                line(corners[k], corners[(k + 1) % 4], STAND_IN, 2.0);
            }
        }
    }
}

fn walk(
    node: &RayNode,
    inspection: &Inspection,
    line: &dyn Fn(Vec3, Vec3, Color32, f32),
    projector: &Projector,
    painter: &egui::Painter,
) {
    let end = match (&node.hit, node.kind) {
        (_, RayKind::Shadow) if !node.occluders.is_empty() => {
            node.origin + node.direction * node.occluders[0].0.distance
        }
        (_, RayKind::Shadow) => {
            let light = inspection.lights.iter().find(|(name, _)| Some(name) == node.light.as_ref());
            light.and_then(|(_, p)| *p).unwrap_or(node.origin + node.direction * inspection.reach)
        }
        (Some(hit), _) => hit.point,
        (None, _) => node.origin + node.direction * inspection.reach * 0.5,
    };
    let colour = match node.kind {
        RayKind::Primary => PRIMARY,
        RayKind::Reflected => REFLECTED,
        RayKind::Refracted => REFRACTED,
        RayKind::Continued => CONTINUED,
        RayKind::Shadow if node.occluders.is_empty() => SHADOW_LIT,
        RayKind::Shadow => SHADOW_BLOCKED,
    };
    let width = if node.kind == RayKind::Shadow { 1.5 } else { 2.5 };
    line(node.origin, end, colour, width);
    if node.kind != RayKind::Shadow && node.hit.is_some() {
        projector.dot(painter, end, colour);
    }
    for child in &node.children {
        walk(child, inspection, line, projector, painter);
    }
}

/// World points to the 3D view's points, with segments clipped at the camera's near plane.
struct Projector<'a> {
    camera: &'a Camera,
    rect: Rect,
    ppp: f32,
}

impl Projector<'_> {
    fn to_screen(&self, p: Vec3) -> Option<Pos2> {
        let pixel = self.camera.project(p)?;
        Some(self.rect.min + egui::vec2(pixel.x, pixel.y) / self.ppp)
    }

    /// The part of `a`–`b` in front of the near plane.
    fn clipped(&self, a: Vec3, b: Vec3) -> Option<(Vec3, Vec3)> {
        let view = self.camera.view_from_world();
        let near = self.camera.near;
        // In view space the camera looks along −z: a point is in front where −z ≥ near.
        let depth = |p: Vec3| -(view * p.extend(1.0)).xyz().z;
        let (da, db) = (depth(a) - near, depth(b) - near);
        match (da >= 0.0, db >= 0.0) {
            (true, true) => Some((a, b)),
            (false, false) => None,
            (true, false) => Some((a, a + (b - a) * (da / (da - db)))),
            (false, true) => Some((a + (b - a) * (da / (da - db)), b)),
        }
    }

    fn segment(&self, painter: &egui::Painter, a: Vec3, b: Vec3, stroke: Stroke) {
        let Some((a, b)) = self.clipped(a, b) else { return };
        if let (Some(a), Some(b)) = (self.to_screen(a), self.to_screen(b)) {
            painter.line_segment([a, b], Stroke::new(stroke.width + 2.0, Color32::from_black_alpha(160)));
            painter.line_segment([a, b], stroke);
        }
    }

    fn dot(&self, painter: &egui::Painter, p: Vec3, colour: Color32) {
        if let Some(at) = self.clipped(p, p).and_then(|(p, _)| self.to_screen(p)) {
            painter.circle_filled(at, 3.5, colour);
        }
    }

    fn marker(&self, painter: &egui::Painter, p: Vec3, label: &str) {
        let Some(at) = self.clipped(p, p).and_then(|(p, _)| self.to_screen(p)) else { return };
        let size = egui::vec2(6.0, 6.0);
        painter.rect_stroke(
            Rect::from_center_size(at, 2.0 * size),
            0.0,
            Stroke::new(2.0, STAND_IN),
            egui::StrokeKind::Middle,
        );
        painter.text(
            at + egui::vec2(10.0, -10.0),
            egui::Align2::LEFT_BOTTOM,
            label,
            egui::FontId::proportional(12.0),
            STAND_IN,
        );
    }
}

/// The inspect tool's state: the inspected pixel's explanation, and a pixel to inspect once the
/// view has its size (a click, the I key, the step `inspect`).
#[derive(Default)]
pub(in crate::viewer) struct InspectTool {
    pub shown: Option<Inspection>,
    pub next: Option<glam::Vec2>,
}
