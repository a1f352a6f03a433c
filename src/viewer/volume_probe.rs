//! The volume ray under the cursor: what `march::composite` does along the primary ray through
//! the pixel the mouse (or a script's `cursor X Y`) is over, drawn as a small plot in a lower
//! corner of the 3D view. For a composited volume: each sample's normalized value, its
//! classified opacity (corrected for the sample's length), the accumulated opacity `α_out`, and
//! its shaded colour as a swatch, with the samples taken out of those planned (what early
//! termination saved). For an isosurface volume: the values the same samples read, the iso value
//! and the crossing `march::isosurface` finds.
//!
//! The ray and the march are the renderers': the camera's ray through the pixel, each volume's box
//! cut at the nearest surface (found by the picker's BVH) and, for composited volumes, at the
//! nearest isosurface crossing, as the tracer does; `March::of(&settings.volume)`. The volume shown
//! is the first the ray enters. Samples are shaded with the tracer's voxel illumination
//! (`trace::volume::voxel_illumination`) without shadow rays: with `volume.shadows` on, the
//! tracer's samples in shadow are darker than the swatches.
//!
//! Marching is CPU work, so it is not done while egui lays the window out: the frame makes the
//! probe before the UI ([`CursorProbe::update`], at the cursor the last layout saw, or a
//! script's) and keeps it while its inputs (pixel, view size, camera, settings, scene revision,
//! lights) stay the same; the layout only draws it ([`show`]). A cursor that moved is probed in
//! the next frame, which the frame asks for at once ([`CursorProbe::is_current`]).

use egui::{Color32, Pos2, Rect, Stroke, pos2, vec2};
use glam::{Vec2, Vec3};

use super::kept::Kept;
use super::scene_state::SceneState;
use crate::RenderSettings;
use crate::base::Ray;
use crate::output::OutputTransform;
use crate::scene::{Camera, Light, Scene};
use crate::trace::volume::{voxel_illumination, world_normal};
use crate::volume::march::{self, LocalRay, Sample};
use crate::volume::{March, Rendering, Volume};

/// What the ray under the cursor does in the first volume it enters.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    /// The volume's name.
    pub volume: String,
    /// The data values the normalized 0 and 1 stand for.
    pub range: (f32, f32),
    /// The ray's `t` where it enters the volume's box and where the march ends.
    pub segment: (f32, f32),
    /// Every sample taken, in order.
    pub samples: Vec<Sample>,
    pub taken: u32,
    pub planned: u32,
    /// The accumulated opacity at the end.
    pub alpha: f32,
    /// An isosurface volume: its iso value and the crossing's `t`, if the ray crosses it.
    pub isosurface: Option<(f32, Option<f32>)>,
}

/// The probe of `ray`, whose nearest surface is at `t_surface` (∞ for none), or `None` when it
/// enters no volume in front of it.
pub fn probe(scene: &Scene, settings: &RenderSettings, ray: &Ray, t_surface: f32) -> Option<Probe> {
    let volume_settings = &settings.volume;
    if !volume_settings.enabled {
        return None;
    }
    let march = March::of(volume_settings);
    let crossed: Vec<(&Volume, LocalRay, (f32, f32))> = scene
        .volumes
        .iter()
        .filter_map(|volume| {
            let local = volume.local_ray(ray);
            volume.segment(&local, t_surface).map(|segment| (volume, local, segment))
        })
        .collect();
    let crossing = |(volume, local, segment): &(&Volume, LocalRay, (f32, f32))| {
        let isosurface = volume.rendering(volume_settings) == Rendering::Isosurface;
        isosurface.then(|| march::isosurface(&volume.grid, local, *segment, volume.iso, &march)).flatten()
    };
    // The nearest isosurface ends the composited segments, as in the tracer.
    let t_iso = crossed.iter().filter_map(crossing).fold(f32::INFINITY, f32::min);
    let (volume, local, segment) = crossed
        .into_iter()
        .map(|(volume, local, (t0, t1))| match volume.rendering(volume_settings) {
            Rendering::Composite => (volume, local, (t0, t1.min(t_iso))),
            Rendering::Isosurface => (volume, local, (t0, t1)),
        })
        .filter(|(_, _, (t0, t1))| t0 < t1)
        .min_by(|a, b| a.2.0.total_cmp(&b.2.0))?;
    Some(march_volume(scene, settings, volume, ray, &local, segment, &march))
}

/// Marches `segment` of `volume` as the renderers do, recording every sample.
fn march_volume(
    scene: &Scene,
    settings: &RenderSettings,
    volume: &Volume,
    ray: &Ray,
    local: &LocalRay,
    segment: (f32, f32),
    march: &March,
) -> Probe {
    let (isosurface, march) = match volume.rendering(&settings.volume) {
        Rendering::Composite => (None, *march),
        // The values along the whole segment, with the crossing marked.
        Rendering::Isosurface => (
            Some((volume.iso, march::isosurface(&volume.grid, local, segment, volume.iso, march))),
            March { termination: None, ..*march },
        ),
    };
    let normal_from_local = volume.normal_from_local();
    let terms = settings.terms.into();
    let mut shade = |t: f32, gradient: Vec3, colour: Vec3| {
        let normal = world_normal(normal_from_local, gradient);
        voxel_illumination(scene, terms, colour, normal, -ray.direction, ray.at(t), &mut |_| Vec3::ONE)
    };
    let mut samples = Vec::new();
    let out = march::composite(&volume.grid, &volume.table, local, segment, &march, &mut shade, Some(&mut samples));
    Probe {
        volume: volume.name.clone(),
        range: volume.range,
        segment,
        samples,
        taken: out.taken,
        planned: out.planned,
        alpha: out.alpha,
        isosurface,
    }
}

impl Probe {
    /// One line for scripts (the `probe` step): `volume probe volume=NAME mode=composite|isosurface
    /// taken=N planned=M alpha=A [iso=V crossing=T|none] alpha_out=a,b,… value=v,w,…`.
    pub fn report(&self) -> String {
        let list =
            |f: fn(&Sample) -> f32| self.samples.iter().map(|s| format!("{:.5}", f(s))).collect::<Vec<_>>().join(",");
        let mode = match self.isosurface {
            None => "composite".to_string(),
            Some((iso, crossing)) => {
                let crossing = crossing.map_or("none".to_string(), |t| format!("{t:.5}"));
                format!("isosurface iso={iso:.5} crossing={crossing}")
            }
        };
        format!(
            "volume probe volume={} mode={mode} taken={} planned={} alpha={:.5} alpha_out={} value={}",
            self.volume,
            self.taken,
            self.planned,
            self.alpha,
            list(|s| s.alpha_out),
            list(|s| s.value)
        )
    }
}

const VALUE_COLOUR: Color32 = Color32::from_rgb(235, 235, 235);
const OPACITY_COLOUR: Color32 = Color32::from_rgb(255, 150, 40);
const ACCUMULATED_COLOUR: Color32 = Color32::from_rgb(60, 200, 255);
const ISO_COLOUR: Color32 = Color32::from_rgb(255, 220, 60);
const CROSSING_COLOUR: Color32 = Color32::from_rgb(255, 0, 255);

/// Where the probe is asked for: a pixel of the 3D view (the cursor's or a script's), and the
/// view's size, both in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::viewer) struct ProbeAt {
    pub pixel: Vec2,
    pub size: (u32, u32),
}

/// What the view shows of the volume ray: a ring at `pixel`, and the probe, or "no volume under
/// the cursor" for `None`.
#[derive(Clone, Debug, PartialEq)]
pub struct Shown {
    pub pixel: Vec2,
    pub probe: Option<Probe>,
}

/// Everything a probe is made from; the camera at the view's size.
#[derive(Clone, Debug, PartialEq)]
struct Inputs {
    at: ProbeAt,
    camera: Camera,
    settings: RenderSettings,
    revision: u64,
    lights: Vec<Light>,
}

/// The probe the view shows, made before the UI is laid out and kept while its inputs stay the
/// same.
#[derive(Default)]
pub(in crate::viewer) struct CursorProbe {
    kept: Kept<Inputs, Shown>,
}

impl CursorProbe {
    /// Makes the probe at `at` for the current scene and settings, unless it is the one kept.
    pub fn update(&mut self, scene: &mut SceneState, settings: &RenderSettings, at: Option<ProbeAt>) {
        let inputs = inputs(scene, settings, at);
        self.kept.update(inputs, |inputs| Shown {
            pixel: inputs.at.pixel,
            probe: probe_at(scene, inputs.at.pixel, inputs.at.size, settings),
        });
    }

    /// Whether the kept probe is the one [`CursorProbe::update`] would make now.
    pub(in crate::viewer) fn is_current(
        &self,
        scene: &SceneState,
        settings: &RenderSettings,
        at: Option<ProbeAt>,
    ) -> bool {
        self.kept.is_current(&inputs(scene, settings, at))
    }

    /// What the view shows: `None` when the cursor is off the view or there is no volume to probe.
    pub fn shown(&self) -> Option<&Shown> {
        self.kept.get()
    }

    /// The probe itself: `None` also where the ray enters no volume.
    pub fn probe(&self) -> Option<&Probe> {
        self.kept.get().and_then(|shown| shown.probe.as_ref())
    }
}

/// The inputs of the probe at `at`; `None` where nothing is shown: no pixel inside the view, no
/// volume, or volumes switched off.
fn inputs(scene: &SceneState, settings: &RenderSettings, at: Option<ProbeAt>) -> Option<Inputs> {
    let ProbeAt { pixel, size } = at?;
    let inside = pixel.x >= 0.0 && pixel.y >= 0.0 && pixel.x < size.0 as f32 && pixel.y < size.1 as f32;
    if !inside || scene.scene.volumes.is_empty() || !settings.volume.enabled {
        return None;
    }
    Some(Inputs {
        at: ProbeAt { pixel, size },
        camera: Camera { width: size.0, height: size.1, ..scene.scene.camera.clone() },
        settings: settings.clone(),
        revision: scene.revision,
        lights: scene.scene.lights.clone(),
    })
}

/// Draws `shown` over the 3D view `rect`: a ring at its pixel, and the plot in the lower corner
/// across the view from it. Nothing is computed here.
pub fn show(ctx: &egui::Context, shown: &Shown, settings: &RenderSettings, (rect, ppp): (Rect, f32)) {
    let at = rect.min + vec2(shown.pixel.x, shown.pixel.y) / ppp;
    ctx.layer_painter(egui::LayerId::new(egui::Order::Foreground, egui::Id::unique("mirador::volume_probe_ring")))
        .circle_stroke(at, 4.0, Stroke::new(2.0, CROSSING_COLOUR));
    // In the lower corner across the view from the cursor, so the plot never hides it.
    let (corner, align) = if at.x < rect.center().x {
        (rect.right_bottom() + vec2(-8.0, -8.0), egui::Align2::RIGHT_BOTTOM)
    } else {
        (rect.left_bottom() + vec2(8.0, -8.0), egui::Align2::LEFT_BOTTOM)
    };
    egui::Area::new(egui::Id::unique("mirador::volume_probe")).fixed_pos(corner).pivot(align).interactable(false).show(
        ctx,
        |ui| {
            egui::Frame::popup(ui.style()).fill(Color32::from_black_alpha(200)).show(ui, |ui| match &shown.probe {
                Some(probe) => probe_ui(ui, probe, OutputTransform::of(settings)),
                None => {
                    ui.colored_label(Color32::WHITE, "Volume ray: no volume under the cursor");
                }
            });
        },
    );
}

fn probe_ui(ui: &mut egui::Ui, probe: &Probe, output: OutputTransform) {
    let text = |ui: &mut egui::Ui, text: String, colour: Color32| {
        ui.label(egui::RichText::new(text).color(colour).size(12.0));
    };
    let (t0, t1) = probe.segment;
    match probe.isosurface {
        None => {
            text(ui, format!("Volume ray: `{}`, composited", probe.volume), Color32::WHITE);
            let saved = probe.planned - probe.taken;
            let why = if saved > 0 { format!(" ({saved} saved by early termination)") } else { String::new() };
            text(ui, format!("{} of {} samples taken{why}", probe.taken, probe.planned), Color32::WHITE);
            text(ui, format!("α = {:.3}   t from {t0:.3} to {t1:.3}", probe.alpha), Color32::LIGHT_GRAY);
        }
        Some((iso, crossing)) => {
            text(ui, format!("Volume ray: `{}`, isosurface", probe.volume), Color32::WHITE);
            let crossing = crossing.map_or("no crossing".to_string(), |t| format!("crossing at t = {t:.3}"));
            text(ui, format!("{} samples, iso {iso:.3}: {crossing}", probe.planned), Color32::WHITE);
            text(ui, format!("t from {t0:.3} to {t1:.3}"), Color32::LIGHT_GRAY);
        }
    }
    let (lo, hi) = probe.range;
    let max_opacity = probe.samples.iter().map(|s| s.classified.w).fold(0.0, f32::max);
    ui.horizontal(|ui| {
        let short = |v: f32| (v * 1000.0).round() / 1000.0;
        text(ui, format!("value (0–1 over {} – {})", short(lo), short(hi)), VALUE_COLOUR);
        if probe.isosurface.is_none() {
            text(ui, format!("sample α (top: {max_opacity:.3})"), OPACITY_COLOUR);
            text(ui, "α_out".into(), ACCUMULATED_COLOUR);
        } else {
            text(ui, "iso".into(), ISO_COLOUR);
            text(ui, "crossing".into(), CROSSING_COLOUR);
        }
    });
    let (response, painter) = ui.allocate_painter(vec2(ui.min_rect().width().max(300.0), 120.0), egui::Sense::hover());
    let swatches = Rect::from_min_max(pos2(response.rect.min.x, response.rect.max.y - 14.0), response.rect.max);
    let plot = Rect::from_min_max(response.rect.min, pos2(response.rect.max.x, swatches.min.y - 4.0));
    painter.rect_filled(plot, 2.0, Color32::from_gray(24));
    // x: the ray's t over the segment; every planned sample has a slot, those not taken are greyed.
    let x = |t: f32| plot.min.x + (t - t0) / (t1 - t0).max(1e-12) * plot.width();
    let y = |v: f32| plot.max.y - v.clamp(0.0, 1.0) * plot.height();
    let slot = plot.width() / probe.planned.max(1) as f32;
    if probe.taken < probe.planned {
        let first_untaken = plot.min.x + probe.taken as f32 * slot;
        let skipped = Rect::from_min_max(pos2(first_untaken, plot.min.y), plot.max);
        painter.rect_filled(skipped, 0.0, Color32::from_gray(55));
        painter.text(
            skipped.center(),
            egui::Align2::CENTER_CENTER,
            "not taken",
            egui::FontId::proportional(11.0),
            Color32::GRAY,
        );
    }
    let curve = |value: fn(&Sample) -> f32, scale: f32, colour: Color32| {
        let points: Vec<Pos2> = probe.samples.iter().map(|s| pos2(x(s.t), y(value(s) * scale))).collect();
        painter.add(egui::Shape::line(points, Stroke::new(1.5, colour)));
    };
    curve(|s| s.value, 1.0, VALUE_COLOUR);
    match probe.isosurface {
        None => {
            curve(|s| s.classified.w, 1.0 / max_opacity.max(1e-6), OPACITY_COLOUR);
            curve(|s| s.alpha_out, 1.0, ACCUMULATED_COLOUR);
        }
        Some((iso, crossing)) => {
            painter.add(egui::Shape::dashed_line(
                &[pos2(plot.min.x, y(iso)), pos2(plot.max.x, y(iso))],
                Stroke::new(1.0, ISO_COLOUR),
                6.0,
                4.0,
            ));
            if let Some(t) = crossing {
                painter.vline(x(t), plot.y_range(), Stroke::new(1.5, CROSSING_COLOUR));
            }
        }
    }
    // Each sample's shaded colour, as the image would show it alone; samples without opacity
    // add nothing and are left empty.
    if probe.isosurface.is_some() {
        return;
    }
    painter.rect_filled(swatches, 0.0, Color32::from_gray(24));
    for (i, sample) in probe.samples.iter().enumerate() {
        if sample.classified.w > 0.0 {
            let [r, g, b] = output.to_srgb8(sample.shaded);
            let left = swatches.min.x + i as f32 * slot;
            let cell = Rect::from_min_max(pos2(left, swatches.min.y), pos2(left + slot.max(1.0), swatches.max.y));
            painter.rect_filled(cell, 0.0, Color32::from_rgb(r, g, b));
        }
    }
}

/// What the volume ray through `pixel` of an image of `size` pixels taken by the current camera
/// does: `None` where it enters no volume in front of the surfaces.
pub(in crate::viewer) fn probe_at(
    scene: &mut SceneState,
    pixel: glam::Vec2,
    size: (u32, u32),
    settings: &RenderSettings,
) -> Option<Probe> {
    if scene.scene.volumes.is_empty() {
        return None;
    }
    scene.with_picker(size, |picker, scene| {
        let ray = scene.camera.ray_through(pixel.x, pixel.y);
        probe(scene, settings, &ray, picker.nearest(&ray))
    })
}

/// What the viewer shows of what is under the cursor: the volume ray's samples, the direction the
/// environment is seen in (the lat–long view's marker), and the cursor the last layout saw.
#[derive(Default)]
pub(in crate::viewer) struct CursorTools {
    pub probe: CursorProbe,
    pub seen: super::seen::CursorDirection,
    pub at: Option<Vec2>,
}
