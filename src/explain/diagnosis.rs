//! Why the two renderers differ at a pixel, in one sentence, read from what each recorded: the
//! surfaces they hit, each light's visibility and the shadow map's depths, the reflections, the
//! transparent layers, the mip levels. The rules go from the most specific to the most general;
//! the first that applies speaks.

use glam::Vec3;

use super::{RasterSide, TraceSide};
use crate::scene::Scene;
use crate::settings::{RenderSettings, TransparencySort};
use crate::trace::explain::{RayKind, RayNode};

/// The most two radiances may differ by and count as the same: 1 % of the brighter plus 0.005
/// (half-float rounding, the tessellated outline's shading, one level of 8-bit output).
pub fn same(a: Vec3, b: Vec3) -> bool {
    let scale = a.max_element().max(b.max_element()).max(0.0);
    (a - b).abs().max_element() <= 0.005 + 0.01 * scale
}

/// The depth difference below which a receiver's stored depth is its own surface, resampled:
/// a surface shadowing itself. Depths of the shadow maps are in [0, 1].
const SELF_SHADOW_DEPTH: f32 = 0.005;

/// One sentence naming the technique behind the difference, or `None` where the radiances agree.
/// `raster` is the rasterizer's pixel and, on a planar mirror, what its mirrored camera saw
/// there.
pub fn diagnose(
    scene: &Scene,
    settings: &RenderSettings,
    (raster, through_mirror): (&RasterSide, Option<&RasterSide>),
    trace: &TraceSide,
) -> Option<String> {
    if same(raster.radiance, trace.radiance) {
        return None;
    }
    let rays = &trace.rays;
    let traced_object = rays.hit.as_ref().and_then(|h| h.object.clone());
    let raster_object = raster.surface.as_ref().and_then(|s| s.object.clone());
    let background = raster.surface.as_ref().is_none_or(|s| s.kind == "background");
    // The tracer's nearest hit may be a transparent layer the rasterizer blended over its surface.
    let in_layers = traced_object.is_some() && raster.layers.iter().any(|l| l.object == traced_object);
    let elsewhere = !background && raster_object != traced_object && traced_object.is_some() && !in_layers;
    if (background && !in_layers) != rays.hit.is_none() || elsewhere {
        let seen = |name: Option<String>, none: bool| {
            if none { "nothing".to_string() } else { format!("`{}`", name.unwrap_or_else(|| "an isosurface".into())) }
        };
        return Some(format!(
            "The renderers see different surfaces here: the rasterizer {} (its tessellated outline), the tracer {} \
             (the exact shape): a pixel on an edge.",
            seen(raster_object, background),
            seen(traced_object, rays.hit.is_none()),
        ));
    }
    shadows(scene, settings, raster, rays)
        .or_else(|| planar_mirror(raster, through_mirror, rays))
        .or_else(|| refraction(scene, raster, rays))
        .or_else(|| transparency(settings, raster))
        .or_else(|| environment(raster, rays))
        .or_else(|| mip_level(raster, rays))
        .or_else(|| Some(largest(raster, trace)))
}

/// A planar mirror whose mirrored camera saw another surface at the pixel than the reflected
/// ray hits: the outline of what the mirror shows (the tessellated shape against the exact one),
/// or the mirror's own edge.
fn planar_mirror(raster: &RasterSide, through_mirror: Option<&RasterSide>, rays: &RayNode) -> Option<String> {
    let mirror = raster.surface.as_ref()?.object.clone()?;
    let seen = through_mirror?.surface.as_ref();
    let reflected = rays.children.iter().find(|c| c.kind == RayKind::Reflected)?;
    let camera_saw = seen.filter(|s| s.kind != "background").and_then(|s| s.object.clone());
    let ray_hit = reflected.hit.as_ref().and_then(|h| h.object.clone());
    if camera_saw == ray_hit {
        return None;
    }
    let name = |object: Option<String>| object.map_or("nothing (the background)".to_string(), |o| format!("`{o}`"));
    Some(format!(
        "In the mirror `{mirror}` the two see different surfaces: the mirrored camera saw {} at this pixel, the \
         reflected ray hits {}: an outline seen in the mirror (the tessellated shape against the exact one), or the \
         mirror's edge.",
        name(camera_saw),
        name(ray_hit),
    ))
}

/// Projected shadows (object precision) seen differently from the shadow ray, from what is
/// recorded: whether the surface is a `plane` (the only receivers the polygons are projected
/// onto) and which way the two disagree. On a receiver, the polygons are the caster's
/// tessellation projected, so they differ from the exact shape's shadow along its outline.
fn projected(
    scene: &Scene,
    raster: &RasterSide,
    (name, v_raster, v_traced): (&str, f32, f32),
    occluder: Option<&crate::trace::explain::Hit>,
) -> String {
    let surface = raster.surface.as_ref().and_then(|s| s.object.as_deref());
    let receiver = surface.is_some_and(|surface| {
        scene.objects.iter().any(|o| o.name == surface && crate::raster::shadow::projected::is_receiver(o))
    });
    let by = occluder.and_then(|h| h.object.clone()).map_or(String::new(), |o| format!(" by `{o}`"));
    let on = surface.map_or("this surface".to_string(), |s| format!("`{s}`"));
    match (receiver, v_raster < v_traced) {
        (false, false) => format!(
            "Projected shadows fall only on `plane` receivers and {on} is not one: it gets no shadow from light `{name}`, \
             though its shadow ray is blocked{by}."
        ),
        (false, true) => format!(
            "Projected shadows: a shadow polygon of light `{name}` covers this point of {on}, but its shadow ray reaches \
             the light."
        ),
        (true, false) => format!(
            "On the edge of a projected shadow: {on} receives the polygons of light `{name}`, but none covers this pixel's \
             centre (V = {v_raster:.2}) while its shadow ray is blocked{by} (V = {v_traced:.2}). The polygons are the \
             caster's tessellation projected from the light, so their outline differs from the exact shape's shadow."
        ),
        (true, true) => format!(
            "On the edge of a projected shadow: a polygon of light `{name}` covers this pixel's centre on {on} \
             (V = {v_raster:.2}) where its shadow ray reaches the light (V = {v_traced:.2}). The polygons are the caster's \
             tessellation projected from the light, so their outline differs from the exact shape's shadow."
        ),
    }
}

/// A light seen differently: acne, peter-panning, the map's reach or its texels.
fn shadows(scene: &Scene, settings: &RenderSettings, raster: &RasterSide, rays: &RayNode) -> Option<String> {
    for light in &raster.lights {
        let traced = rays.lights.iter().find(|l| l.light == light.light)?;
        let (v_raster, v_traced) = (light.visibility.max_element(), traced.visibility.max_element());
        if (v_raster - v_traced).abs() < 0.25 {
            continue;
        }
        let name = &light.name;
        let ray = rays.children.iter().find(|c| c.kind == RayKind::Shadow && c.light.as_deref() == Some(name));
        let occluder = ray.and_then(|r| r.hit.as_ref());
        let Some(lookup) = &light.shadow else {
            return Some(format!(
                "Light `{name}` casts no shadow in the rasterizer here (V = {v_raster:.2}) but the tracer's shadow ray \
                 gives V = {v_traced:.2}."
            ));
        };
        if lookup.method == "projected" {
            return Some(projected(scene, raster, (name, v_raster, v_traced), occluder));
        }
        let (Some(stored), Some(receiver), Some([tx, ty]), Some(layer)) =
            (lookup.stored_depth, lookup.receiver_depth, lookup.texel, lookup.layer)
        else {
            return Some(format!(
                "This point lies outside light `{name}`'s shadow map (shadows.distance and shadows.fit bound a directional \
                 light's map), so the rasterizer finds it lit; the tracer's shadow ray is blocked."
            ));
        };
        let bias = lookup.bias.unwrap_or(0.0);
        let taps = format!("{:.0} % of the filter's taps lit", 100.0 * lookup.lit);
        let depths = format!(
            "texel ({tx}, {ty}) of layer {layer} stores depth {stored:.6}, this point is at {receiver:.6}, bias {bias:.2e}, {taps}"
        );
        if v_raster < v_traced {
            let difference = receiver - stored;
            return Some(if occluder.is_none() && difference > 0.0 && difference < SELF_SHADOW_DEPTH {
                format!(
                    "Shadow acne: light `{name}` is shadowed by the shadow map ({depths}) but the shadow ray reaches the \
                     light: the surface shadows itself, its own depth resampled in the map lying {difference:.2e} in front \
                     of it; raise shadows.depth_bias ({}), shadows.slope_bias ({}) or shadows.normal_offset ({}).",
                    settings.shadows.depth_bias, settings.shadows.slope_bias, settings.shadows.normal_offset
                )
            } else {
                format!(
                    "The shadow map shadows this point from light `{name}` ({depths}) where the shadow ray finds it lit: the \
                     map's texel (and its filter) covers more than the occluder's outline."
                )
            });
        }
        let what = occluder.map_or("an occluder".to_string(), |h| {
            format!("`{}` {:.3} away", h.object.clone().unwrap_or_else(|| "an isosurface".into()), h.distance)
        });
        return Some(format!(
            "Peter-panning: the shadow ray towards light `{name}` is blocked by {what}, but the shadow map finds this point \
             lit ({depths}): the depth bias and the normal offset lift the comparison past an occluder this close to the \
             receiver; lower shadows.depth_bias ({}) or shadows.normal_offset ({}).",
            settings.shadows.depth_bias, settings.shadows.normal_offset
        ));
    }
    None
}

/// A transparent surface the tracer refracts through: where the rasterizer goes straight on
/// (`transparency.refraction = "none"`), or where its path through the glass, found in screen
/// space, leaves elsewhere than the tracer's.
fn refraction(scene: &Scene, raster: &RasterSide, rays: &RayNode) -> Option<String> {
    let refracted = rays.children.iter().find(|c| c.kind == RayKind::Refracted)?;
    let hit = rays.hit.as_ref()?;
    let material = scene.materials.iter().find(|m| m.name == hit.material)?;
    if (material.ior - 1.0).abs() < 1e-3 || raster.layers.is_empty() && raster.surface.is_none() {
        return None;
    }
    let object = hit.object.clone().unwrap_or_default();
    // The tracer's ray out of the glass: the refracted ray's own refracted child.
    let out = refracted.children.iter().find(|c| c.kind == RayKind::Refracted);
    let seen =
        |node: &RayNode| node.hit.as_ref().and_then(|h| h.object.clone()).unwrap_or_else(|| "the environment".into());
    let path = raster.surface.as_ref().and_then(|s| s.refraction.as_ref());
    let Some(path) = path else {
        let bent = refracted.direction.angle_between(rays.direction).to_degrees();
        return Some(format!(
            "Refraction is not modelled here: transparency.refraction = \"none\" takes n_i = n_t and looks straight \
             through `{object}` (ior {}), while the tracer's refracted ray turns {bent:.1}° and sees {}.",
            material.ior,
            seen(out.unwrap_or(refracted))
        ));
    };
    let Some(out) = out else {
        return Some(format!(
            "The tracer's ray does not leave `{object}` where it enters it refracted (it reflects inside, past the \
             critical angle); the refraction pass follows one path in and out ({}).",
            path.mode
        ));
    };
    let exit_gap = path.exit.map_or(f32::INFINITY, |exit| exit.distance(out.origin));
    let turn = path.direction.angle_between(out.direction).to_degrees();
    let inside = refracted.children.iter().any(|c| c.kind == RayKind::Reflected);
    if exit_gap < 0.02 && turn < 1.0 && inside {
        return Some(format!(
            "The path through `{object}` agrees with the tracer's (the exits {exit_gap:.3} apart, {turn:.1}° between the \
             rays out); the difference is the light the tracer's rays reflected inside the glass bring, which the \
             refraction pass leaves out, or what L(t2) reads from {}.",
            path.source
        ));
    }
    Some(format!(
        "Refraction in {} space: the rasterizer's ray leaves `{object}` {} and {turn:.1}° off the tracer's, and reads L(t2) \
         from {}; the tracer's leaves at ({:.2}, {:.2}, {:.2}) and sees {}.",
        if path.mode == "screen" { "screen" } else { "environment-map" },
        if exit_gap.is_finite() {
            format!("{exit_gap:.3} from where the tracer's does")
        } else {
            "where no back face was found".into()
        },
        path.source,
        out.origin.x,
        out.origin.y,
        out.origin.z,
        seen(out)
    ))
}

/// Transparent layers blended in an order other than back to front.
fn transparency(settings: &RenderSettings, raster: &RasterSide) -> Option<String> {
    let transparent: Vec<&super::Layer> = raster.layers.iter().filter(|l| l.kind == "transparent").collect();
    let out_of_order = transparent.windows(2).any(|pair| pair[1].depth > pair[0].depth);
    if !out_of_order {
        return None;
    }
    let order: Vec<String> =
        transparent.iter().map(|l| format!("`{}`", l.object.clone().unwrap_or_default())).collect();
    let why = match settings.transparency.sort {
        TransparencySort::Unsorted => "transparency.sort = \"unsorted\" draws them in the scene's order",
        TransparencySort::Object => "sorting by object centre puts them in this order though they overlap in depth",
        _ => "the sort could not order them",
    };
    Some(format!(
        "An unsorted layer order: the rasterizer blended {} in that order, a nearer layer before a farther one, and \
         I = Im + kt·Mt·I depends on the order ({why}).",
        order.join(", then ")
    ))
}

/// A curved mirror's cube map looked up from its centre, where the reflected ray starts on its
/// surface.
fn environment(raster: &RasterSide, rays: &RayNode) -> Option<String> {
    let lookup = raster.surface.as_ref()?.environment.as_ref()?;
    let reflected = rays.children.iter().find(|c| c.kind == RayKind::Reflected)?;
    match (&reflected.hit, lookup.centre) {
        (Some(hit), Some(centre)) => {
            let seen = (hit.point - centre).normalize_or_zero();
            let angle = seen.angle_between(lookup.direction).to_degrees();
            (angle > 1.0).then(|| {
                format!(
                    "The cube map's parallax: the curved mirror looks L(r) up as if from its centre ({:.2}, {:.2}, {:.2}); \
                     the reflected ray from this point hits `{}` {:.2} away, which the centre sees {angle:.1}° off r.",
                    centre.x,
                    centre.y,
                    centre.z,
                    hit.object.clone().unwrap_or_else(|| "an isosurface".into()),
                    hit.distance
                )
            })
        }
        (Some(hit), None) => Some(format!(
            "The environment map holds the world alone ({}): the reflected ray hits `{}` {:.2} away, which no such map shows.",
            lookup.map,
            hit.object.clone().unwrap_or_else(|| "an isosurface".into()),
            hit.distance
        )),
        (None, _) => None,
    }
}

/// The two renderers reading the colour texture at different mip levels.
fn mip_level(raster: &RasterSide, rays: &RayNode) -> Option<String> {
    let raster_lod = raster.surface.as_ref()?.lod?;
    let surface = rays.surface.as_ref()?;
    let traced_lod = surface.lod?;
    ((raster_lod - traced_lod).abs() > 0.5).then(|| {
        let footprint = raster.surface.as_ref().map_or(glam::Vec2::ZERO, |s| s.footprint);
        format!(
            "A mip level difference: the rasterizer reads level {raster_lod:.2} of the texture (screen derivatives: the pixel \
             spans {:.1} × {:.1} texels), the tracer level {traced_lod:.2} (its ray cone, {:.4} wide at the hit).",
            footprint.x, footprint.y, surface.footprint
        )
    })
}

/// Failing a rule: the size of the difference and the largest term on each side.
fn largest(raster: &RasterSide, trace: &TraceSide) -> String {
    let biggest = |terms: &[crate::trace::explain::Term]| {
        terms
            .iter()
            .max_by(|a, b| a.radiance.max_element().total_cmp(&b.radiance.max_element()))
            .map(|t| t.name.clone())
    };
    format!(
        "The renderers differ by {:.4} here (raster {:.4}, traced {:.4}); the largest terms are {} and {}.",
        (raster.radiance - trace.radiance).abs().max_element(),
        raster.radiance.max_element(),
        trace.radiance.max_element(),
        biggest(&raster.terms).unwrap_or_else(|| "none".into()),
        biggest(&trace.terms).unwrap_or_else(|| "none".into()),
    )
}

/// What bump or parallax mapping leaves out at a pixel, from the ray through it traced on the
/// smooth surface the renderers shaded and on the displaced surface `p + k·f·n` it stands for:
/// the outline (one hits, the other not), the distance (the displaced surface met nearer or
/// farther), and the relief's own shadows (a light the smooth surface sees that the displaced
/// one does not). `None` where the two rays meet alike.
pub fn relief(smooth: &RayNode, displaced: &RayNode) -> Option<String> {
    const LEAD: &str = "Bump mapping moves no geometry";
    let blocked = |node: &RayNode| {
        node.children.iter().filter(|c| c.kind == RayKind::Shadow && c.radiance.max_element() <= 0.0).count()
    };
    let stands_out = |object: Option<&str>| {
        format!(
            "{LEAD}: the relief stands out of the smooth outline here; the displaced surface covers this pixel \
             (`{}`), the smooth one leaves it to what lies behind (bump.method = \"displacement\" draws it).",
            object.unwrap_or("an isosurface")
        )
    };
    let sinks = format!(
        "{LEAD}: the displaced surface sinks inside the smooth outline here and leaves this pixel to what lies \
         behind it (bump.method = \"displacement\" draws it)."
    );
    match (&smooth.hit, &displaced.hit) {
        (None, Some(hit)) => Some(stands_out(hit.object.as_deref())),
        (Some(_), None) => Some(sinks),
        // Another surface: the relief in front of what the smooth one shows, or gone from it.
        (Some(a), Some(b)) if a.object != b.object => {
            Some(if b.distance < a.distance { stands_out(b.object.as_deref()) } else { sinks })
        }
        (Some(a), Some(b)) => {
            let nearer = a.distance - b.distance;
            let shadows = blocked(displaced).saturating_sub(blocked(smooth));
            if shadows > 0 {
                Some(format!(
                    "{LEAD}: the displaced surface shadows itself here ({shadows} light(s) hidden by its relief) where \
                     the smooth surface is lit; bump mapping casts no shadow of a bump."
                ))
            } else if nearer.abs() > 1e-3 * a.distance.max(1e-3) {
                Some(format!(
                    "{LEAD}: the tracer's ray meets the displaced surface {:.3} {} than the smooth one both \
                     renderers shaded.",
                    nearer.abs(),
                    if nearer > 0.0 { "nearer" } else { "farther" }
                ))
            } else {
                None
            }
        }
        (None, None) => None,
    }
}
