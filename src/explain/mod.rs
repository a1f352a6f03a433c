//! Explaining a pixel: what each renderer computed there, term by term, and why they differ.
//!
//! The rasterizer's side comes from the GPU: an inspecting frame ([`crate::raster::inspect`])
//! records every fragment its shaders drew at the pixel: the terms of the illumination model,
//! each light's visibility and shadow-map lookup, the texture's level, the bumped normal, the
//! reflections, the transparent layers and volumes blended over the surface. This module works out
//! which fragments the depth test and the blend kept, in which order, and writes the pixel's
//! radiance as a sum of terms (each weighted by what the layers in front let through). The passes
//! say what their records are: each declares its kinds (`RECORDS`: the part each takes in the
//! pixel and the terms of its own light paths), and turns a record into its evidence (the mirror's
//! lookup, the refraction's path, the environment's and the shadow's lookups), read against what
//! the frame decided before it drew (`crate::raster::frame::FrameFacts`), never decided again
//! here. The tracer's side is its ray tree (`crate::trace::explain`): every ray the pixel cast,
//! each with the terms of its radiance. [`diagnosis`] names the technique behind a difference.
//!
//! Used by `mirador explain`, the viewer's inspect mode and the tests.

pub mod diagnosis;
pub mod text;

use glam::{Vec2, Vec3};
use serde::Serialize;

use crate::gpu::texture::GpuTexture;
use crate::gpu::{Gpu, Profile};
pub use crate::raster::environment::EnvironmentLookup;
use crate::raster::frame::{FrameFacts, record_kinds};
use crate::raster::inspect::{GpuInspectFragment, INSPECT_MIRROR, INSPECT_REFRACTION, Part, RasterPixel, RecordKind};
pub use crate::raster::mirror::MirrorLookup;
pub use crate::raster::refraction::RefractionPath;
pub use crate::raster::shadow::{ShadowLookup, constant_bias};
use crate::raster::uniforms::{UNKNOWN_OBJECT, transmittance};
use crate::raster::{FrameTargets, OUTPUT_FORMAT, Renderer};
use crate::scene::shading::lights_surface;
use crate::scene::{Light, Scene};
use crate::settings::{RenderSettings, TransparencySort};
use crate::shaders::Wgsl;
use crate::trace::Tracer;
use crate::trace::explain::{RayNode, RayTree, Term};

/// Both renderers at one pixel, and why they differ.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Explanation {
    pub pixel: [u32; 2],
    pub raster: RasterSide,
    pub trace: TraceSide,
    /// One sentence naming the technique behind the difference, where the radiances differ.
    pub diagnosis: Option<String>,
    /// Where they agree: the nearest pixel whose displayed colours differ, within
    /// [`NEAREST_RADIUS`] pixels ([`Nearest`]).
    pub nearest: Option<Nearest>,
    /// On a planar mirror: what its mirrored camera saw at this pixel (the surface, its terms
    /// and lights), the rasterizer's counterpart of the tracer's reflected ray.
    pub through_mirror: Option<Box<RasterSide>>,
    /// Where the scene bump or parallax maps a height field: what the displaced surface those
    /// stand for is at this pixel, against the smooth one both renderers shaded
    /// ([`diagnosis::relief`]).
    pub relief: Option<String>,
}

/// A pixel near an agreeing one where the two renderers' displayed colours differ. FLIP's error
/// map spreads each pixel's error over its neighbours (its filters span a few pixels), so the
/// brightest spot of `compare`'s map may itself agree; the pixel to explain is this one.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Nearest {
    pub pixel: [u32; 2],
    /// Its distance from the pixel asked about, in pixels.
    pub distance: f32,
    /// The largest difference of its displayed channels, in levels of 255.
    pub levels: u8,
}

/// How far [`Nearest`] looks, in pixels.
pub const NEAREST_RADIUS: u32 = 8;

/// Displayed channels this many levels (of 255) apart or more differ, for [`Nearest`]: what an
/// eye sees in a flat area, well above a level of rounding.
pub const DIFFERS_BY: u8 = 8;

/// The rasterizer at the pixel, as its shaders computed it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RasterSide {
    /// Linear radiance, before exposure and tone mapping (the HDR target's half floats).
    pub radiance: Vec3,
    /// What the radiance is made of; the terms add up to it (to half-float precision).
    pub terms: Vec<Term>,
    /// The surface the z-buffer kept (`None`: nothing was drawn, the background colour).
    pub surface: Option<RasterSurface>,
    /// The surface's lights, with each one's visibility and shadow lookup.
    pub lights: Vec<RasterLight>,
    /// Transparent surfaces and composited volumes blended over the surface, in blend order.
    pub layers: Vec<Layer>,
}

/// The surface the z-buffer kept at the pixel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RasterSurface {
    /// `opaque`, `mirror`, `refraction` (glass the refraction pass drew), `isosurface` or
    /// `background`.
    pub kind: &'static str,
    pub object: Option<String>,
    /// The object's index in the scene (names need not be unique).
    #[serde(skip)]
    pub object_index: Option<usize>,
    pub material: Option<String>,
    pub point: Vec3,
    /// The depth buffer's value.
    pub depth: f32,
    pub normal: Vec3,
    pub geometric_normal: Vec3,
    pub uv: Vec2,
    /// The colour texture's mip level from the screen derivatives (`None`: no texture).
    pub lod: Option<f32>,
    /// Texels the pixel spans along the screen's x and y.
    pub footprint: Vec2,
    pub colour: Vec3,
    pub bump: Option<Bump>,
    /// A curved mirror's lookup: the direction `r` and the map.
    pub environment: Option<EnvironmentLookup>,
    /// A planar mirror's: the mirrored camera and the texel of its image.
    pub mirror: Option<MirrorLookup>,
    /// Glass that refracts: the ray's path through it.
    pub refraction: Option<RefractionPath>,
    /// Fresnel's `F` at the surface, for glass weighted by it.
    pub fresnel: Option<f32>,
}

/// Bump mapping at the pixel: `k`, `Δ` and the slopes `(du, dv) = k·∇f_h`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bump {
    pub k: f32,
    pub delta: Vec2,
    pub slopes: Vec2,
}

/// A light at the raster surface.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RasterLight {
    pub light: usize,
    pub name: String,
    /// `V`: the filter's lit fraction times the tint of transparent occluders.
    pub visibility: Vec3,
    #[serde(flatten)]
    pub shadow: Option<ShadowLookup>,
}

/// A transparent surface or a composited volume blended over what was behind it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Layer {
    /// `transparent` or `volume`.
    pub kind: &'static str,
    pub object: Option<String>,
    pub material: Option<String>,
    pub depth: f32,
    /// What it adds: `Im` (`α·Im` when alpha-blended), or the volume's premultiplied colour.
    pub adds: Vec3,
    /// What it lets through of what is behind: `kt·Mt`, `1 − α`.
    pub lets_through: Vec3,
    /// Volumes: samples taken.
    pub samples: Option<u32>,
}

/// The tracer at the pixel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TraceSide {
    /// Linear radiance, as `trace --exr` writes it.
    pub radiance: Vec3,
    /// The primary ray's terms; they add up to the radiance.
    pub terms: Vec<Term>,
    /// The lights at the primary hit, each with its shadow ray's visibility.
    pub lights: Vec<crate::trace::explain::LightState>,
    /// The ray tree: the primary ray and every ray it cast, to `max_depth`.
    pub rays: RayNode,
}

/// Why a pixel cannot be explained.
#[derive(Debug, thiserror::Error)]
pub enum ExplainError {
    #[error("pixel ({0}, {1}) lies outside the {2}×{3} image")]
    Outside(u32, u32, u32, u32),
    #[error(
        "this device cannot inspect pixels: it lacks storage buffers written by fragment shaders, as WebGL2 does \
         (try the Vulkan backend, or WebGPU in the page)"
    )]
    Unsupported,
    #[error("reading the inspection back failed")]
    Readback,
}

/// Explains pixel `(x, y)` of `scene` as drawn by both renderers with `settings`.
pub fn explain(
    gpu: &Gpu,
    scene: &Scene,
    settings: &RenderSettings,
    pixel: (u32, u32),
) -> Result<Explanation, ExplainError> {
    Explainer::new(gpu, scene, settings)?.explain(gpu, pixel)
}

/// Both renderers ready to explain pixels of one scene: an inspecting rasterizer (render scale 1:
/// the pixel is the image's) and a tracer.
pub struct Explainer<'s> {
    scene: &'s Scene,
    settings: RenderSettings,
    renderer: Renderer,
    targets: FrameTargets,
    output: GpuTexture,
    tracer: Tracer<'s>,
}

impl<'s> Explainer<'s> {
    pub fn new(gpu: &Gpu, scene: &'s Scene, settings: &RenderSettings) -> Result<Explainer<'s>, ExplainError> {
        Explainer::with_wgsl(gpu, scene, settings, Wgsl::builtin())
    }

    /// [`Self::new`], the rasterizer's passes compiled from `wgsl` (a lab's student functions:
    /// the viewer's lab mode explains the student's pixels with them).
    pub fn with_wgsl(
        gpu: &Gpu,
        scene: &'s Scene,
        settings: &RenderSettings,
        wgsl: Wgsl,
    ) -> Result<Explainer<'s>, ExplainError> {
        let flags = gpu.adapter.get_downlevel_capabilities().flags;
        if !flags.contains(wgpu::DownlevelFlags::FRAGMENT_WRITABLE_STORAGE) || gpu.profile() == Profile::WebGl2 {
            return Err(ExplainError::Unsupported);
        }
        let mut settings = settings.clone();
        settings.raster.render_scale = 1.0;
        // The rasterizer's own approximations are what is explained: a term the hybrid traces is
        // the tracer's, which the tracer's side shows already.
        settings.hybrid = crate::settings::HybridSettings::default();
        let size = (scene.camera.width, scene.camera.height);
        Ok(Explainer {
            scene,
            renderer: Renderer::with_wgsl(gpu, scene, OUTPUT_FORMAT, wgsl, true),
            targets: FrameTargets::new(&gpu.device, size),
            output: GpuTexture::target(&gpu.device, "explain::output", size, OUTPUT_FORMAT),
            tracer: Tracer::new(scene, &settings),
            settings,
        })
    }

    /// Both renderers at pixel `(x, y)`: one inspected frame of the rasterizer, the tracer's ray
    /// tree, and the diagnosis.
    pub fn explain(&mut self, gpu: &Gpu, (x, y): (u32, u32)) -> Result<Explanation, ExplainError> {
        let (scene, settings) = (self.scene, &self.settings);
        let (width, height) = (scene.camera.width, scene.camera.height);
        if x >= width || y >= height {
            return Err(ExplainError::Outside(x, y, width, height));
        }
        self.renderer.inspect(Some((x, y)));
        self.renderer.render(gpu, scene, settings, &mut self.targets, &self.output.view);
        let pixel = self.renderer.inspection(gpu, &self.targets).ok_or(ExplainError::Readback)?;
        let rays = trace_pixel(&self.tracer, (x, y));
        let trace = TraceSide { radiance: rays.radiance, terms: rays.terms.clone(), lights: rays.lights.clone(), rays };
        let raster = raster_side(scene, settings, (&pixel, self.renderer.facts()));
        let through_mirror = self.through_mirror(gpu, &raster)?;
        let diagnosis = diagnosis::diagnose(scene, &self.settings, (&raster, through_mirror.as_deref()), &trace);
        let nearest = match diagnosis {
            Some(_) => None,
            None => self.nearest_difference(gpu, (x, y))?,
        };
        let relief = self.relief((x, y), &trace.rays);
        Ok(Explanation { pixel: [x, y], raster, trace, diagnosis, nearest, through_mirror, relief })
    }

    /// Where the scene bump or parallax maps a height field (the approximations table's
    /// `relief`): the pixel traced again on the displaced surface, and what that changes.
    fn relief(&self, pixel: (u32, u32), smooth: &RayNode) -> Option<String> {
        let settings = &self.settings;
        let used = crate::settings::Traced::Relief.row().in_use;
        if !used(&self.scene.facts(), settings) {
            return None;
        }
        let displaced = crate::texture::displacement::displaced(self.scene);
        let rays = trace_pixel(&Tracer::new(&displaced, settings), pixel);
        diagnosis::relief(smooth, &rays)
    }

    /// Where the inspected pixel shows a planar mirror: one more inspected frame, recorded by
    /// that mirror's camera instead of the main one, read at the same pixel (the mirrored
    /// camera's image is pixel-aligned with the view's). `None` elsewhere, or where the mirror
    /// drew no camera (too deep, or seen edge-on).
    fn through_mirror(&mut self, gpu: &Gpu, raster: &RasterSide) -> Result<Option<Box<RasterSide>>, ExplainError> {
        let (scene, settings) = (self.scene, &self.settings);
        let Some(surface) = raster.surface.as_ref().filter(|s| s.mirror.is_some()) else { return Ok(None) };
        let Some(object) = surface.object_index else { return Ok(None) };
        self.renderer.inspect_through(Some((object, surface.point)));
        self.renderer.render(gpu, scene, settings, &mut self.targets, &self.output.view);
        let pixel = self.renderer.inspected_through().then(|| self.renderer.inspection(gpu, &self.targets));
        self.renderer.inspect_through(None);
        match pixel {
            None => Ok(None),
            Some(pixel) => {
                let pixel = pixel.ok_or(ExplainError::Readback)?;
                Ok(Some(Box::new(raster_side(scene, settings, (&pixel, self.renderer.facts())))))
            }
        }
    }

    /// The nearest pixel to `(x, y)`, within [`NEAREST_RADIUS`], whose displayed colours differ
    /// by [`DIFFERS_BY`] levels or more: the rasterizer's from the frame just drawn, the
    /// tracer's from its ray through the pixel's centre (as `explain` traces it). Nearest first,
    /// then the largest difference.
    fn nearest_difference(&self, gpu: &Gpu, (x, y): (u32, u32)) -> Result<Option<Nearest>, ExplainError> {
        let (width, height) = (self.scene.camera.width, self.scene.camera.height);
        let image = crate::gpu::readback::read_rgba8(&gpu.device, &gpu.queue, &self.output.texture)
            .map_err(|_| ExplainError::Readback)?;
        let transform = crate::output::OutputTransform::of(&self.settings);
        let r = NEAREST_RADIUS as i64;
        let mut around: Vec<(i64, i64)> = (-r..=r)
            .flat_map(|j| (-r..=r).map(move |i| (i, j)))
            .filter(|&(i, j)| (i, j) != (0, 0) && i * i + j * j <= r * r)
            .collect();
        around.sort_by_key(|&(i, j)| i * i + j * j);
        let mut best: Option<Nearest> = None;
        for (i, j) in around {
            let distance = ((i * i + j * j) as f32).sqrt();
            if best.as_ref().is_some_and(|b| distance > b.distance) {
                break;
            }
            let (px, py) = (x as i64 + i, y as i64 + j);
            if px < 0 || py < 0 || px >= width as i64 || py >= height as i64 {
                continue;
            }
            let (px, py) = (px as u32, py as u32);
            let at = 4 * (py as usize * width as usize + px as usize);
            let raster = &image[at..at + 3];
            let mut counts = crate::trace::whitted::RayCounts::default();
            let traced =
                transform.to_srgb8(self.tracer.primary(glam::Vec2::new(px as f32 + 0.5, py as f32 + 0.5), &mut counts));
            let levels = (0..3).map(|c| raster[c].abs_diff(traced[c])).max().unwrap_or(0);
            if levels >= DIFFERS_BY && best.as_ref().is_none_or(|b| levels > b.levels) {
                best = Some(Nearest { pixel: [px, py], distance, levels });
            }
        }
        Ok(best)
    }
}

fn object_name(scene: &Scene, index: u32) -> Option<String> {
    (index != UNKNOWN_OBJECT).then(|| scene.objects.get(index as usize).map(|o| o.name.clone())).flatten()
}

fn material_name(scene: &Scene, index: u32) -> Option<String> {
    scene.materials.get(index as usize).map(|m| m.name.clone())
}

/// What the depth test and the blend kept of the recorded fragments, in blend order: the
/// surface, then each blended layer with what it lets through.
struct Kept<'r> {
    surface: Option<&'r GpuInspectFragment>,
    layers: Vec<(&'r GpuInspectFragment, Vec3)>,
}

/// Which recorded fragments were blended. Fragment shaders that write storage run before the
/// depth test, so the records hold rejected fragments too; this replays the tests: opaque
/// surfaces (and isosurfaces) keep the nearest, `Less`; the world fills the pixel only where
/// nothing was; transparent fragments are blended where nearer than it, in draw order; with
/// depth peeling each peel's shading pass draws every transparent fragment and keeps the one at
/// its layer's depth (layers farthest first, `peel_layers` of them).
/// The kind of a record, as the pass that wrote it declared it.
fn kind_of(record: &GpuInspectFragment) -> Option<&'static RecordKind> {
    record_kinds().find(|kind| kind.code == record.kind)
}

fn kept<'r>(scene: &Scene, settings: &RenderSettings, pixel: &'r RasterPixel, by_hand: bool) -> Kept<'r> {
    let records = &pixel.fragments;
    let part = |r: &GpuInspectFragment| kind_of(r).map(|k| k.part);
    let surface = records
        .iter()
        .filter(|r| part(r) == Some(Part::Surface))
        .min_by(|a, b| a.depth.total_cmp(&b.depth))
        .or_else(|| records.iter().find(|r| part(r) == Some(Part::Background)));
    let depth = surface.filter(|s| part(s) == Some(Part::Surface)).map_or(1.0, |s| s.depth);
    // The blend's `kt·Mt`: the material's constant, `(1 − F)·kt·Mt` for glass weighted by
    // Fresnel, or `1 − α` where a texture's alpha blends it per pixel
    // (`crate::raster::transparency`); a volume lets `1 − α` through.
    let lets_through = |r: &GpuInspectFragment| -> Vec3 {
        if part(r) == Some(Part::Composited) {
            return Vec3::splat(1.0 - r.alpha);
        }
        // A lab's blend by hand: the student's b, as the record holds it.
        if by_hand && part(r) == Some(Part::Transparent) {
            return r.blend_factor;
        }
        let material = &scene.materials[r.material as usize];
        if settings.terms.fresnel && material.bends_light() {
            (1.0 - r.fresnel) * transmittance(material)
        } else if material.alpha_mode == crate::scene::AlphaMode::Blend && material.texture.is_some() {
            Vec3::splat(1.0 - r.alpha)
        } else {
            transmittance(material)
        }
    };
    let transparent: Vec<&GpuInspectFragment> = records.iter().filter(|r| part(r) == Some(Part::Transparent)).collect();
    let peeled = settings.transparency.enabled && settings.transparency.sort == TransparencySort::Exact;
    let mut layers = Vec::new();
    if peeled && !transparent.is_empty() {
        // Each peel's shading pass recorded the same fragments; the layers are their depths
        // nearer than the surface, farthest first.
        let passes = settings.transparency.peel_layers as usize;
        let group = (transparent.len() / passes).max(1);
        let mut depths: Vec<f32> = transparent.iter().map(|r| r.depth).filter(|&d| d < depth).collect();
        depths.sort_by(|a, b| b.total_cmp(a));
        depths.dedup();
        depths.truncate(passes);
        let mut seen = 0;
        for record in records {
            match part(record) {
                Some(Part::Composited) => layers.push((record, lets_through(record))),
                Some(Part::Transparent) => {
                    let pass = seen / group;
                    seen += 1;
                    if depths.get(pass) == Some(&record.depth) {
                        layers.push((record, lets_through(record)));
                    }
                }
                _ => {}
            }
        }
    } else {
        for record in records {
            let blended = match part(record) {
                Some(Part::Composited) => true,
                Some(Part::Transparent) => record.depth < depth,
                _ => false,
            };
            if blended {
                layers.push((record, lets_through(record)));
            }
        }
    }
    Kept { surface, layers }
}

/// The rasterizer's side from its records.
fn raster_side(scene: &Scene, settings: &RenderSettings, (pixel, facts): (&RasterPixel, &FrameFacts)) -> RasterSide {
    let kept = kept(scene, settings, pixel, facts.blend_by_hand);
    // What the layers in front of each element let through, nearest last.
    let mut front = vec![Vec3::ONE; kept.layers.len() + 1];
    for k in (0..kept.layers.len()).rev() {
        front[k] = front[k + 1] * kept.layers[k].1;
    }
    let mut terms = Vec::new();
    let surface_through = front[0];
    let surface = kept.surface.map(|record| raster_surface(scene, settings, record, (pixel, facts)));
    let mut lights = Vec::new();
    match kept.surface {
        Some(record) if kind_of(record).is_some_and(|k| k.part == Part::Background) => {
            terms.push(Term { name: "the world (background)".into(), radiance: surface_through * record.radiance });
        }
        Some(record) => {
            let name = object_name(scene, record.object).unwrap_or_else(|| "isosurface".into());
            fragment_terms(scene, record, &name, surface_through, &mut terms);
            lights = raster_lights(scene, settings, record, facts);
        }
        None => terms.push(Term { name: "background colour".into(), radiance: surface_through * scene.background }),
    }
    let mut layers = Vec::new();
    for (k, (record, through)) in kept.layers.iter().enumerate() {
        let weight = front[k + 1];
        let object = object_name(scene, record.object);
        let composited = kind_of(record).is_some_and(|k| k.part == Part::Composited);
        if composited {
            terms.push(Term { name: "composited volume C".into(), radiance: weight * record.radiance });
        } else {
            let name = object.clone().or_else(|| material_name(scene, record.material)).unwrap_or_default();
            // The fragment returned `α·Im` (α = 1 unless alpha-blended).
            fragment_terms(scene, record, &format!("{name} (transparent)"), weight * record.alpha, &mut terms);
        }
        layers.push(Layer {
            kind: kind_of(record).map_or("unknown", |k| k.name),
            object,
            material: (!composited).then(|| material_name(scene, record.material)).flatten(),
            depth: record.depth,
            adds: record.radiance,
            lets_through: *through,
            samples: composited.then_some(record.samples as u32),
        });
    }
    RasterSide { radiance: pixel.radiance, terms, surface, lights, layers }
}

/// The terms of one shaded fragment, times `weight` (what lies in front lets through), named
/// after `name`.
fn fragment_terms(scene: &Scene, record: &GpuInspectFragment, name: &str, weight: Vec3, terms: &mut Vec<Term>) {
    let mut push = |term: String, radiance: Vec3| {
        if radiance != Vec3::ZERO {
            terms.push(Term { name: format!("{name}: {term}"), radiance: weight * radiance });
        }
    };
    push("emission ME".into(), record.emission);
    push("global ambient AG = A·kd·C".into(), record.global_ambient);
    for (index, light) in scene.lights.iter().enumerate().take(record.lights.len()) {
        let l = &record.lights[index];
        for (part, radiance) in
            [("ambient ka·C", l.ambient), ("diffuse kd·C·(n·l)", l.diffuse), ("specular ks·S·(r·v)^e", l.specular)]
        {
            push(format!("light `{}`: {part} × V", light.name), l.visibility * radiance);
        }
    }
    let reflection = if record.fresnel > 0.0 {
        format!("reflection (kps·MPS + F·kt·Mt)·L(r) from the environment map, F = {:.4}", record.fresnel)
    } else {
        "environment map kps·MPS·L(r)".into()
    };
    push(reflection, record.environment);
    // The light paths of the pass that drew it (a mirror's reflection, the refracted light).
    for (term, radiance) in kind_of(record).map_or_else(Vec::new, |kind| (kind.terms)(record)) {
        push(term.into(), radiance);
    }
}

fn raster_surface(
    scene: &Scene,
    settings: &RenderSettings,
    record: &GpuInspectFragment,
    (pixel, facts): (&RasterPixel, &FrameFacts),
) -> RasterSurface {
    let kind = kind_of(record).map_or("unknown", |k| k.name);
    let background = kind_of(record).is_some_and(|k| k.part == Part::Background);
    let reflective =
        scene.materials.get(record.material as usize).is_some_and(|m| m.mirror > 0.0 || record.fresnel > 0.0);
    let looked_up = record.kind != INSPECT_MIRROR && record.env_direction != Vec3::ZERO;
    let environment = (reflective && looked_up && !background)
        .then(|| crate::raster::environment::lookup(record, settings, &facts.cubes, facts.bounds));
    let mirror = (record.kind == INSPECT_MIRROR)
        .then(|| crate::raster::mirror::lookup(record, &facts.mirrors, scene.camera.eye, pixel.pixel));
    RasterSurface {
        kind,
        object: if background { None } else { object_name(scene, record.object) },
        object_index: (!background && record.object != UNKNOWN_OBJECT).then_some(record.object as usize),
        material: if background { None } else { material_name(scene, record.material) },
        point: record.world,
        depth: record.depth,
        normal: record.normal,
        geometric_normal: record.geometric,
        uv: record.uv,
        lod: (record.lod >= 0.0 && !background).then_some(record.lod),
        footprint: record.footprint,
        colour: record.colour,
        bump: (record.bump_k != 0.0).then_some(Bump {
            k: record.bump_k,
            delta: record.bump_delta,
            slopes: record.bump,
        }),
        environment,
        mirror,
        refraction: (record.kind == INSPECT_REFRACTION).then(|| crate::raster::refraction::path(record, settings)),
        fresnel: (record.fresnel > 0.0).then_some(record.fresnel),
    }
}

fn raster_lights(
    scene: &Scene,
    settings: &RenderSettings,
    record: &GpuInspectFragment,
    facts: &FrameFacts,
) -> Vec<RasterLight> {
    let shadows = &settings.shadows;
    // The lights' views the frame drew and read its shadows with.
    let layout = &facts.lights;
    scene
        .lights
        .iter()
        .enumerate()
        .take(record.lights.len())
        .filter(|(_, light)| lights_the_surface(scene, settings, record, light))
        .map(|(index, light)| {
            let l = &record.lights[index];
            let casts = shadows.enabled && layout.first_layer.get(index).copied().flatten().is_some();
            let shadow = casts.then(|| crate::raster::shadow::lookup(light, l, record.world, layout, shadows));
            RasterLight { light: index, name: light.name.clone(), visibility: l.visibility, shadow }
        })
        .collect()
}

/// Whether `light` adds anything to the surface of `record`, by the tracer's own rule
/// ([`lights_surface`]), so both sides list the same lights.
fn lights_the_surface(scene: &Scene, settings: &RenderSettings, record: &GpuInspectFragment, light: &Light) -> bool {
    let Some(incidence) = light.incidence(record.world) else { return false };
    let ka = scene.materials.get(record.material as usize).map_or(0.0, |m| m.ka);
    lights_surface(record.normal, incidence.l, ka, settings.terms.into())
}

/// The ray-traced pixel's tree, for callers with a tracer of their own.
pub fn trace_pixel(tracer: &Tracer, pixel: (u32, u32)) -> RayNode {
    let mut tree = RayTree::new(tracer.scene);
    tracer.explain_pixel(pixel, &mut tree);
    tree.root.expect("the primary ray ends")
}

impl Explanation {
    /// The explanation as pretty-printed JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("an explanation serializes")
    }
}
