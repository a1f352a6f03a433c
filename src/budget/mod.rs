//! The error budget (docs/course/12-error-budget.md): how much of the difference between the
//! rasterizer and the ray tracer each of the rasterizer's approximations costs, measured by
//! swapping it for its traced counterpart inside the raster frame (`settings.hybrid`,
//! `crate::raster::traced`) and comparing by FLIP.
//!
//! For a scene, with `R` the raster image, `T` the traced one, `R+a` the raster image with
//! approximation `a` traced and `R−a` the one with every approximation but `a` traced:
//!
//! - **whole**: `FLIP(R, T)`;
//! - **alone** (what `a` costs, added alone to the rest): `FLIP(R, R+a)`, the change swapping
//!   `a` alone makes; its error map is where `a` errs;
//! - **left alone** (what `a` costs, left alone): `FLIP(R−a, T)`, the difference left when `a`
//!   is the only approximation not traced; it includes the floor;
//! - **floor**: `FLIP(R+all, T)`, what remains with every approximation swapped: the
//!   rasterization of primary visibility itself (curved shapes tessellated, a pixel's surface
//!   chosen by coverage rather than by a ray) and every approximation that has no traced
//!   counterpart yet ([`unswapped`]).
//!
//! FLIP does not add: two errors on one pixel cost less than their sum, so the figures are a
//! ranking and a map of where each approximation errs, not shares that sum to the whole (Arvo,
//! Torrance and Smits split the error by its sources in the same spirit, with bounds rather
//! than measurements).

pub mod sheet;

use image::RgbaImage;

use crate::Scene;
use crate::compare::difference_beyond;
use crate::gpu::Gpu;
use crate::raster::Headless;
use crate::raster::uniforms::MAX_LIGHTS;
use crate::settings::{HybridSettings, RenderSettings, Traced};

/// Differences of up to this many levels (of 255, in every channel) are not counted: they are
/// rounding, not an approximation (the rasterizer's radiance passes through a half-float target:
/// a flat sky of 0.78 comes out one level below the tracer's, which costs a mean FLIP of 0.02 on
/// its own; lavapipe and libm round their last bits differently from CPU to CPU). The tests'
/// comparisons look past the same two levels (tests/README.md).
pub const ROUNDING_LEVELS: u8 = 2;

/// What keeps the fully swapped frame from the tracer's image in `scene`: the approximations
/// without a traced counterpart that it uses, and what no swap removes.
pub fn unswapped(scene: &Scene, settings: &RenderSettings) -> Vec<&'static str> {
    let mut causes =
        vec!["primary visibility: triangles rasterized by coverage (curved shapes tessellated) against exact ray hits"];
    if !scene.volumes.is_empty() {
        causes.push(
            "volumes: marched by the same algorithm in both (the grid in half floats on the GPU); no traced swap",
        );
        if settings.shadows.enabled {
            causes.push("volumes' shadows (isosurfaces, volume.shadows): shadow maps, not traced");
        }
    }
    if scene.lights.len() > MAX_LIGHTS {
        causes.push("lights past the sixteenth: the rasterizer draws sixteen");
    }
    if settings.raster.render_scale < 1.0 {
        causes.push("raster.render_scale < 1: the frame is drawn smaller and stretched");
    }
    if settings.trace.anti_aliasing != crate::settings::AntiAliasing::Center {
        causes.push("anti-aliasing: the tracer samples more than each pixel's centre");
    }
    causes
}

/// One approximation's two figures, and its error map.
pub struct Item {
    pub name: &'static str,
    pub swap: &'static str,
    /// `FLIP(R, R+a)`.
    pub alone: f32,
    /// `FLIP(R−a, T)`.
    pub left_alone: f32,
    /// `R` against `R+a`: where the approximation errs, as a picture and per pixel.
    pub error_map: RgbaImage,
    pub errors: Vec<f32>,
}

/// A scene's error budget.
pub struct Budget {
    /// `FLIP(R, T)`.
    pub whole: f32,
    /// The approximations the scene uses, in the table's order (`crate::settings::hybrid`).
    pub items: Vec<Item>,
    /// `FLIP(R+all, T)`.
    pub floor: f32,
    /// What the floor is made of ([`unswapped`]).
    pub floor_causes: Vec<&'static str>,
    /// The images: raster, traced, every approximation swapped.
    pub raster: RgbaImage,
    pub traced: RgbaImage,
    pub hybrid: RgbaImage,
}

/// The scene the budget's reference is traced on: `scene` itself, or, where it bump or parallax
/// maps a height field, the displaced surface those stand for (the approximations table's
/// `relief`, whose counterpart is geometry, not a traced term).
pub fn reference_scene<'s>(scene: &'s Scene, settings: &RenderSettings) -> std::borrow::Cow<'s, Scene> {
    if (Traced::Relief.row().in_use)(&scene.facts(), settings) {
        std::borrow::Cow::Owned(crate::texture::displacement::displaced(scene))
    } else {
        std::borrow::Cow::Borrowed(scene)
    }
}

/// The frames a budget of `items` approximations draws: the raster frame, the frame with every
/// approximation traced, and two for each approximation (it alone traced, all but it traced).
pub fn frames(items: usize) -> usize {
    2 + 2 * items
}

/// A frame the budget has drawn, for a progress report ([`budget_reporting`]).
pub struct Drawn<'a> {
    /// Frames drawn so far, this one included, of `frames`.
    pub done: usize,
    pub frames: usize,
    /// Which: "raster", "every approximation traced", "NAME traced alone", "all but NAME traced".
    pub what: &'a str,
}

/// The budget of `scene` with `settings`, drawn on `gpu`, against `traced`: the tracer's image of
/// `reference` ([`reference_scene`]) with `settings`.
pub fn budget(gpu: &Gpu, scenes: (&Scene, &Scene), settings: &RenderSettings, traced: RgbaImage) -> Budget {
    budget_reporting(gpu, scenes, settings, traced, &mut |_| {})
}

/// [`budget`], calling `drawn` after each of its frames ([`frames`] of them): `mirador budget`'s
/// progress bar.
pub fn budget_reporting(
    gpu: &Gpu,
    (scene, reference): (&Scene, &Scene),
    settings: &RenderSettings,
    traced: RgbaImage,
    drawn: &mut dyn FnMut(Drawn),
) -> Budget {
    let facts = scene.facts();
    let used: Vec<Traced> = Traced::ALL.iter().copied().filter(|t| (t.row().in_use)(&facts, settings)).collect();
    // The relief's swap draws the displaced scene, the reference: a frame of its own.
    let mut headless = Headless::new(gpu, scene);
    let mut relief: Option<Headless> = None;
    let mut done = 0;
    let mut raster = |settings: &RenderSettings, what: &str| {
        let image = if settings.hybrid.relief {
            relief.get_or_insert_with(|| Headless::new(gpu, reference)).render(gpu, reference, settings)
        } else {
            headless.render(gpu, scene, settings)
        };
        done += 1;
        drawn(Drawn { done, frames: frames(used.len()), what });
        image
    };
    let with = |traced_ones: &mut dyn Iterator<Item = &Traced>| {
        let mut settings = settings.clone();
        settings.hybrid = HybridSettings::default();
        for term in traced_ones {
            *term.switch(&mut settings.hybrid) = true;
        }
        settings
    };
    let flip = |a: &RgbaImage, b: &RgbaImage| {
        difference_beyond(a, b, ROUNDING_LEVELS).expect("every image has the camera's size")
    };
    let plain = raster(&with(&mut std::iter::empty()), "raster");
    let hybrid = raster(&with(&mut used.iter()), "every approximation traced");
    let items = used
        .iter()
        .map(|term| {
            let name = term.row().budget;
            let added = raster(&with(&mut std::iter::once(term)), &format!("{name} traced alone"));
            let others =
                raster(&with(&mut used.iter().filter(|other| *other != term)), &format!("all but {name} traced"));
            let alone = flip(&plain, &added);
            Item {
                name,
                swap: term.row().swap,
                alone: alone.flip_mean,
                left_alone: flip(&traced, &others).flip_mean,
                error_map: alone.error_map,
                errors: alone.flip_errors,
            }
        })
        .collect();
    Budget {
        whole: flip(&traced, &plain).flip_mean,
        items,
        floor: flip(&traced, &hybrid).flip_mean,
        floor_causes: unswapped(scene, settings),
        raster: plain,
        traced,
        hybrid,
    }
}

impl Budget {
    /// The report `mirador budget` prints.
    pub fn report(&self) -> String {
        let mut text = format!(
            "raster against traced: FLIP {:.4} (differences of up to {ROUNDING_LEVELS} levels are rounding, not counted)\n",
            self.whole
        );
        if self.items.is_empty() {
            text += "the scene uses none of the approximations the hybrid can trace\n";
        } else {
            let width = self.items.iter().map(|i| i.name.chars().count()).max().unwrap_or(0).max(18);
            text += &format!("{:<width$} {:>8} {:>11}  swapped\n", "approximation", "alone", "left alone");
            let mut items: Vec<&Item> = self.items.iter().collect();
            items.sort_by(|a, b| b.alone.total_cmp(&a.alone));
            for item in items {
                text +=
                    &format!("{:<width$} {:>8.4} {:>11.4}  {}\n", item.name, item.alone, item.left_alone, item.swap);
            }
        }
        text += &format!("every approximation traced: FLIP {:.4}, the floor:\n", self.floor);
        for cause in &self.floor_causes {
            text += &format!("  - {cause}\n");
        }
        text
    }

    /// The budget as JSON: `whole`, `floor`, `floor_causes` and, for each approximation in use,
    /// its `name`, `alone` and `left_alone`.
    pub fn json(&self) -> serde_json::Value {
        let items: Vec<serde_json::Value> = self
            .items
            .iter()
            .map(
                |i| serde_json::json!({ "name": i.name, "alone": i.alone, "left_alone": i.left_alone, "swap": i.swap }),
            )
            .collect();
        serde_json::json!({
            "whole": self.whole,
            "approximations": items,
            "floor": self.floor,
            "floor_causes": self.floor_causes,
        })
    }
}
