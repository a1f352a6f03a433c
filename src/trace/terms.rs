//! The hybrid's traced terms (docs/course/12-error-budget.md): for every pixel of one view of the
//! raster frame, the terms the tracer computes at the surface that pixel shows, for the
//! rasterizer to read in place of its own approximations (`crate::raster::traced`).
//!
//! The surface is the first *opaque* one along the pixel's ray: what the raster frame's opaque
//! phase draws there. The ray goes on straight past transparent surfaces (`kt > 0` or blended),
//! past a mask's holes, and past the object the view looks out of (a mirrored camera's mirror, a
//! cube's own object). Where transmission is traced, the frame draws transparent surfaces as
//! opaque ones and the surface is the first one, transparent or not. At that surface:
//!
//! - **visibility**: `V_i` of each shadowed light, the tracer's shadow ray (tinted by the
//!   transparent occluders it passes), exactly as [`super::whitted`] weighs `L_dir`: 0 for a light
//!   the tracer does not add at all there (behind the surface, with no ambient term to light);
//! - **reflection**: `L(r)`, the tracer's whole recursion along the mirror direction
//!   `r = 2(n·v)n − v`, for surfaces with `kps > 0`; the rasterizer multiplies it by its own
//!   `kps·MPS`;
//! - **transmission**: what a transparent surface lets through, as the tracer adds it to the
//!   surface's own `α·Im`: `α·((1 − F)·kt·MT·L(t) + F·kt·MT·L(r)) + (1 − α)·L(behind)` (without
//!   Fresnel `F = 0`; on total internal reflection all of `kt·MT` is reflected);
//! - **lights**: the direct light of the lights the rasterizer draws without a shadow map (past
//!   the fourth shadowed, up to its sixteen), each weighted by its shadow ray's `V_i`;
//! - **colour**: `C`, the material's colour times its texture filtered over the ray cone's
//!   footprint, and the surface's object, so the shading uses the traced terms only on the
//!   surface they were traced on.
//!
//! Limits: visibility is traced for the rasterizer's four shadowed lights ([`MAX_SLOTS`]); the
//! surfaces are the tracer's, so an isosurface (which the rasterizer draws as a surface) is looked
//! past, its pixels keeping the rasterizer's own terms; glass's mirror term and its Fresnel share
//! each trace their `L(r)`, where the tracer casts one ray for both (the same value, twice the
//! rays).

use glam::Vec3;
use rayon::prelude::*;

use super::Tracer;
use super::explain::Unobserved;
use super::geometry::SurfaceHit;
use super::whitted::{RayCounts, surface_offset};
use crate::base::Ray;
use crate::scene::shading::{SurfaceSample, direct, facing_viewer, lights_surface};
use crate::settings::hybrid::{SURFACE_LAYER, TRACED_LAYERS};
use crate::settings::{Traced, TracedSet};
use crate::shaders::constants::MAX_LIGHTS;
use crate::texture::RayCone;

/// Which terms to trace: a set of the approximations table's rows.
pub type Wanted = TracedSet;

/// One view of the raster frame, as the tracer looks through it.
pub struct ViewRays<'a> {
    /// The view's image, in pixels.
    pub size: (u32, u32),
    /// The part of it the view draws (`[x, y, width, height]`): the rest is left empty.
    pub window: [u32; 4],
    /// The ray through image point `(x, y)` (pixel `(i, j)` spans `[i, i+1] × [j, j+1]`), starting
    /// where the view starts seeing, and how far that is from where its cone starts (a mirrored
    /// camera's rays start on the mirror, their cones at the mirrored eye); `None` where the view
    /// sees nothing.
    pub ray: &'a (dyn Fn(f32, f32) -> Option<(Ray, f32)> + Sync),
    /// A pixel's footprint along the ray, from where it starts.
    pub cone: RayCone,
    /// The object the view looks out of, which its rays pass.
    pub skip: Option<usize>,
    /// The scene light of each shadowed light's slot (the rasterizer's `shadow_slot` order).
    pub lights: &'a [usize],
    /// Trace one pixel in each block of `stride × stride` and give the block its terms: a coarse
    /// image for a viewer to refine (1: every pixel).
    pub stride: u32,
}

/// The most shadowed lights whose visibility is traced: a layer each.
pub const MAX_SLOTS: usize = Traced::Shadows.row().layers as usize;

/// The traced terms of one view's window, row by row, four floats a pixel, as the layers of the
/// view's traced image they fill: the surface's, then those of each term asked for (of the
/// visibility, a layer per slot).
pub struct TracedTerms {
    /// The window of the view's image the terms cover: `[x, y, width, height]`.
    pub window: [u32; 4],
    /// Each layer traced, and its values: layer [`SURFACE_LAYER`] holds `C` and `object + 1`
    /// (0: no surface); the others are each term's ([`Traced::layer`]).
    pub layers: Vec<(u32, Vec<[f32; 4]>)>,
    /// The rays traced, for the frame's figures.
    pub rays: RayCounts,
}

impl TracedTerms {
    /// The values of layer `layer`, if it was traced.
    pub fn layer(&self, layer: u32) -> Option<&[[f32; 4]]> {
        self.layers.iter().find(|(l, _)| *l == layer).map(|(_, values)| &values[..])
    }
}

/// One pixel's terms, by layer of the traced image.
struct Pixel([[f32; 4]; TRACED_LAYERS as usize]);

/// Where a view's terms go, row after row of its window: each row holds every layer's pixels of
/// that row, layer after layer.
pub struct TermsLayout {
    /// The window of the view's image the terms cover: `[x, y, width, height]`.
    pub window: [u32; 4],
    /// The layers traced, in the order each row holds them: [`SURFACE_LAYER`], then those of each
    /// term asked for (of the visibility, a layer per slot).
    pub layers: Vec<u32>,
    /// The shadowed lights whose visibility is traced.
    slots: usize,
    /// One pixel traced in each block of `stride × stride`.
    stride: u32,
}

impl TermsLayout {
    /// The layout of `wanted` over `view`'s window.
    pub fn new(view: &ViewRays, wanted: Wanted) -> TermsLayout {
        let (width, height) = view.size;
        let [x0, y0, w, h] = view.window;
        let (x1, y1) = ((x0 + w).min(width), (y0 + h).min(height));
        let (x0, y0) = (x0.min(x1), y0.min(y1));
        let slots = if wanted.contains(Traced::Shadows) { view.lights.len().min(MAX_SLOTS) } else { 0 };
        let mut layers = vec![SURFACE_LAYER];
        for &term in Traced::ALL.iter().filter(|&&t| wanted.contains(t)) {
            let count = if term == Traced::Shadows { slots as u32 } else { term.row().layers };
            layers.extend(term.layer()..term.layer() + count);
        }
        let window = [x0, y0, x1 - x0, y1 - y0];
        TermsLayout { window, layers, slots, stride: view.stride.max(1) }
    }

    /// The pixels of one row: every layer's.
    pub fn row_len(&self) -> usize {
        self.layers.len() * self.window[2] as usize
    }

    /// Layer `k`'s pixels of row `y` of the window, in `rows` laid out so.
    pub fn line<'r>(&self, rows: &'r [[f32; 4]], k: usize, y: usize) -> &'r [[f32; 4]] {
        let width = self.window[2] as usize;
        &rows[y * self.row_len() + k * width..][..width]
    }

    /// The pixels of every row.
    pub fn pixels(&self) -> usize {
        self.row_len() * self.window[3] as usize
    }
}

impl Tracer<'_> {
    /// The terms `wanted` at every pixel of `view`'s window.
    pub fn terms(&self, view: &ViewRays, wanted: Wanted) -> TracedTerms {
        let layout = TermsLayout::new(view, wanted);
        let mut rows = vec![[0.0; 4]; layout.pixels()];
        let rays = self.terms_into(view, wanted, &layout, &mut rows);
        // Each layer in turn.
        let height = layout.window[3] as usize;
        let layers = (layout.layers.iter().enumerate())
            .map(|(k, &layer)| (layer, (0..height).flat_map(|y| layout.line(&rows, k, y)).copied().collect()))
            .collect();
        TracedTerms { window: layout.window, layers, rays }
    }

    /// The terms `wanted` at every pixel of `view`'s window, written in `layout` into `out` (at
    /// least [`TermsLayout::pixels`] long), its blocks of `stride` rows traced in parallel: each
    /// block's first row is traced, one pixel in each run of `stride` pixels given to all of them,
    /// and the block's other rows are copies of it. Returns the rays traced.
    pub fn terms_into(&self, view: &ViewRays, wanted: Wanted, layout: &TermsLayout, out: &mut [[f32; 4]]) -> RayCounts {
        let [x0, y0, width, _] = layout.window;
        let stride = layout.stride;
        let row_len = layout.row_len().max(1);
        out[..layout.pixels()]
            .par_chunks_mut(row_len * stride as usize)
            .enumerate()
            .map(|(b, block)| {
                let mut counts = RayCounts::default();
                let (row, rest) = block.split_at_mut(row_len.min(block.len()));
                let y = y0 + b as u32 * stride;
                for x in (0..width).step_by(stride as usize) {
                    let pixel = self.pixel_terms(view, (x0 + x, y), wanted, layout.slots, &mut counts);
                    let covered = x as usize..(x + stride).min(width) as usize;
                    for (k, &layer) in layout.layers.iter().enumerate() {
                        let start = k * width as usize;
                        row[start + covered.start..start + covered.end].fill(pixel.0[layer as usize]);
                    }
                }
                rest.chunks_mut(row_len).for_each(|copy| copy.copy_from_slice(row));
                counts
            })
            .reduce(RayCounts::default, |mut all, counts| {
                all += counts;
                all
            })
    }

    fn pixel_terms(
        &self,
        view: &ViewRays,
        (x, y): (u32, u32),
        wanted: Wanted,
        slots: usize,
        counts: &mut RayCounts,
    ) -> Pixel {
        let mut pixel = Pixel([[0.0; 4]; TRACED_LAYERS as usize]);
        let Some((ray, start)) = (view.ray)(x as f32 + 0.5, y as f32 + 0.5) else { return pixel };
        counts.primary += 1;
        let cone = view.cone.continued(start);
        let opaque = !wanted.contains(Traced::Transmission);
        let Some((hit, ray, cone)) = self.first_surface(&ray, cone, view.skip, opaque) else {
            return pixel;
        };
        let whitted = &self.whitted;
        let material = &self.scene.materials[hit.material.0];
        let v = -ray.direction;
        let outside = facing_viewer(hit.geometric_normal, v);
        let offset = surface_offset(hit.point);
        let colour = if wanted.contains(Traced::Textures) {
            whitted.textures.colour(material, &hit, ray.direction, &cone, &whitted.texture_settings)
        } else {
            Vec3::ZERO
        };
        pixel.0[SURFACE_LAYER as usize] = [colour.x, colour.y, colour.z, hit.object as f32 + 1.0];
        if wanted == TracedSet(Traced::Textures.bit()) {
            return pixel;
        }
        let n = whitted.shading_normal(material, &hit, v);
        if wanted.contains(Traced::Shadows) {
            let first = Traced::Shadows.layer() as usize;
            for (slot, &light) in view.lights.iter().enumerate().take(slots) {
                pixel.0[first + slot] = [1.0; 4];
                let Some(incidence) = self.scene.lights.get(light).and_then(|l| l.incidence(hit.point)) else {
                    continue;
                };
                // A light the tracer does not add here (behind the surface, no ambient term) is
                // weighted 0, with no ray cast.
                pixel.0[first + slot] = if lights_surface(n, incidence.l, material.ka, whitted.terms) {
                    let origin = hit.point + offset * outside;
                    whitted.visibility(origin, incidence.l, incidence.distance, counts).extend(1.0).into()
                } else {
                    [0.0, 0.0, 0.0, 1.0]
                };
            }
        }
        if wanted.contains(Traced::Reflections) && material.reflects() && whitted.max_depth > 0 {
            let radiance =
                whitted.reflected((&hit, n, v), cone.continued(hit.t), 0, (counts, &mut Unobserved), (Vec3::ONE, ""));
            pixel.0[Traced::Reflections.layer() as usize] = radiance.extend(1.0).into();
        }
        if wanted.contains(Traced::Transmission) && material.is_transparent() {
            let through = self.transmitted((&ray, cone), (&hit, n), counts);
            pixel.0[Traced::Transmission.layer() as usize] = through.extend(1.0).into();
        }
        if wanted.contains(Traced::Lights) {
            let known = wanted.contains(Traced::Textures).then_some(colour);
            let light = self.unshadowed_light((&ray, cone), (&hit, n, known), view.lights, counts);
            pixel.0[Traced::Lights.layer() as usize] = light.extend(1.0).into();
        }
        pixel
    }

    /// The direct light of the lights the rasterizer draws without a shadow (of its first
    /// [`MAX_LIGHTS`], those not in `shadowed`), as [`super::whitted`] adds it: each weighted by
    /// its shadow ray's `V_i`. The surface's colour is filtered only where such a light reaches it,
    /// if not `known` already.
    fn unshadowed_light(
        &self,
        (ray, cone): (&Ray, RayCone),
        (hit, n, known): (&SurfaceHit, Vec3, Option<Vec3>),
        shadowed: &[usize],
        counts: &mut RayCounts,
    ) -> Vec3 {
        let whitted = &self.whitted;
        let material = &self.scene.materials[hit.material.0];
        let v = -ray.direction;
        let origin = hit.point + surface_offset(hit.point) * facing_viewer(hit.geometric_normal, v);
        let mut sample = None;
        let mut light = Vec3::ZERO;
        for (index, source) in self.scene.lights.iter().enumerate().take(MAX_LIGHTS) {
            if shadowed.contains(&index) {
                continue;
            }
            let Some(incidence) = source.incidence(hit.point) else { continue };
            if lights_surface(n, incidence.l, material.ka, whitted.terms) {
                let sample = sample.get_or_insert_with(|| {
                    let colour = known.unwrap_or_else(|| {
                        whitted.textures.colour(material, hit, ray.direction, &cone, &whitted.texture_settings)
                    });
                    SurfaceSample::new(material, colour)
                });
                let visibility = whitted.visibility(origin, incidence.l, incidence.distance, counts);
                light += visibility * direct(sample, n, v, &incidence, whitted.terms);
            }
        }
        light
    }

    /// What the transparent surface `hit` lets through, as [`super::whitted`] adds it to the
    /// surface's own `α·Im`.
    fn transmitted(&self, (ray, cone): (&Ray, RayCone), (hit, n): (&SurfaceHit, Vec3), counts: &mut RayCounts) -> Vec3 {
        let whitted = &self.whitted;
        if whitted.max_depth == 0 {
            return Vec3::ZERO;
        }
        let alpha = whitted.blended_coverage(ray, cone, hit);
        let v = -ray.direction;
        let mut through = Vec3::ZERO;
        if alpha > 0.0 {
            let continued = cone.continued(hit.t);
            let transmission = whitted.transmission((hit, n, v), continued, 0, counts, &mut Unobserved);
            through += alpha * transmission.refracted;
            if transmission.reflected_weight != Vec3::ZERO {
                let weight = (transmission.reflected_weight, "");
                through += alpha * whitted.reflected((hit, n, v), continued, 0, (counts, &mut Unobserved), weight);
            }
        }
        if alpha < 1.0 {
            through += whitted.behind(ray, cone, hit, (0, alpha), counts, &mut Unobserved);
        }
        through
    }

    /// The first surface along `ray` (the first opaque one if `opaque`): past a mask's holes, the
    /// object `skip` and, if `opaque`, transparent surfaces. Returns the hit with the ray and cone
    /// that found it.
    fn first_surface(
        &self,
        ray: &Ray,
        cone: RayCone,
        skip: Option<usize>,
        opaque: bool,
    ) -> Option<(SurfaceHit, Ray, RayCone)> {
        let passed = |surface: &SurfaceHit, material: &crate::scene::Material| {
            Some(surface.object) == skip || (opaque && material.is_transparent())
        };
        self.whitted.nearest_surface_past(ray, cone, passed)
    }
}
