//! An explanation as text: the two renderers side by side, section by section, then the
//! diagnosis and the ray tree.

use glam::{Vec2, Vec3};

use super::{Explanation, RasterSide, TraceSide};
use crate::trace::explain::{RayKind, RayNode, Term};

/// The width of the rasterizer's column.
const COLUMN: usize = 62;

fn v3(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

fn v2(v: Vec2) -> String {
    format!("({:.4}, {:.4})", v.x, v.y)
}

/// Lines of `text` cut to `width` characters, at spaces where possible.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split(' ') {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// One section: a title and the two columns' lines.
fn section(out: &mut String, title: &str, left: Vec<String>, right: Vec<String>) {
    if left.is_empty() && right.is_empty() {
        return;
    }
    out.push_str(&format!("\n{title}\n"));
    let left: Vec<String> = left.iter().flat_map(|l| wrap(l, COLUMN - 2)).collect();
    let right: Vec<String> = right.iter().flat_map(|l| wrap(l, COLUMN)).collect();
    for k in 0..left.len().max(right.len()) {
        let l = left.get(k).map_or("", String::as_str);
        let r = right.get(k).map_or("", String::as_str);
        let pad = COLUMN - l.chars().count().min(COLUMN);
        out.push_str(&format!("  {l}{} │ {r}\n", " ".repeat(pad)));
    }
}

fn terms(terms: &[Term]) -> Vec<String> {
    terms.iter().filter(|t| t.radiance != Vec3::ZERO).map(|t| format!("{} {}", v3(t.radiance), t.name)).collect()
}

fn raster_surface(raster: &RasterSide) -> Vec<String> {
    let Some(s) = &raster.surface else { return vec!["nothing drawn: the background colour".into()] };
    if s.kind == "background" {
        return vec!["the world, drawn where no surface is".into()];
    }
    let mut lines = vec![format!(
        "`{}` ({}, material `{}`), depth {:.6}",
        s.object.clone().unwrap_or_else(|| "isosurface".into()),
        s.kind,
        s.material.clone().unwrap_or_default(),
        s.depth
    )];
    lines.push(format!("at {}, normal {}", v3(s.point), v3(s.normal)));
    lines
}

fn traced_surface(rays: &RayNode) -> Vec<String> {
    let Some(hit) = &rays.hit else { return vec!["the primary ray hits nothing: the environment".into()] };
    vec![
        format!(
            "`{}` (material `{}`), {:.4} from the eye",
            hit.object.clone().unwrap_or_else(|| "isosurface".into()),
            hit.material,
            hit.distance
        ),
        format!("at {}, normal {}", v3(hit.point), v3(rays.surface.as_ref().map_or(hit.normal, |s| s.normal))),
    ]
}

fn raster_lights(raster: &RasterSide) -> Vec<String> {
    let mut lines = Vec::new();
    for light in &raster.lights {
        lines.push(format!("`{}`: V = {}", light.name, v3(light.visibility)));
        if let Some(s) = &light.shadow {
            match (s.method, s.layer, s.texel) {
                ("map", Some(layer), Some([x, y])) => lines.push(format!(
                    "  shadow map layer {layer}, texel ({x}, {y}) stores {:.6}; this point at {:.6}; bias {:.2e}, normal offset {:.4}; {:.0} % of the taps lit",
                    s.stored_depth.unwrap_or(0.0),
                    s.receiver_depth.unwrap_or(0.0),
                    s.bias.unwrap_or(0.0),
                    s.normal_offset.unwrap_or(0.0),
                    100.0 * s.lit
                )),
                ("map", ..) => lines.push("  outside the light's shadow map".into()),
                _ => lines.push(format!("  projected polygons: {:.0} % lit (1 − the mask)", 100.0 * s.lit)),
            }
        }
    }
    lines
}

fn traced_lights(rays: &RayNode) -> Vec<String> {
    let mut lines = Vec::new();
    for light in &rays.lights {
        lines.push(format!("`{}`: V = {}", light.name, v3(light.visibility)));
        let ray = rays.children.iter().find(|c| c.kind == RayKind::Shadow && c.light.as_deref() == Some(&light.name));
        if let Some(ray) = ray {
            if ray.occluders.is_empty() {
                lines.push("  its shadow ray reaches the light".into());
            }
            for (hit, through) in &ray.occluders {
                lines.push(format!(
                    "  shadow ray crosses `{}` at {:.4}, which lets {} through",
                    hit.object.clone().unwrap_or_default(),
                    hit.distance,
                    v3(*through)
                ));
            }
        }
    }
    lines
}

fn raster_textures(raster: &RasterSide) -> Vec<String> {
    let Some(s) = raster.surface.as_ref().filter(|s| s.kind != "background") else { return Vec::new() };
    let mut lines = vec![format!("uv {}, C = {}", v2(s.uv), v3(s.colour))];
    if let Some(lod) = s.lod {
        lines.push(format!(
            "mip level {lod:.3} (screen derivatives; the pixel spans {:.2} × {:.2} texels)",
            s.footprint.x, s.footprint.y
        ));
    }
    if let Some(b) = &s.bump {
        lines.push(format!("bump: k = {:.3}, Δ = {}, (du, dv) = {}", b.k, v2(b.delta), v2(b.slopes)));
    }
    lines
}

fn traced_textures(rays: &RayNode) -> Vec<String> {
    let Some(s) = &rays.surface else { return Vec::new() };
    let mut lines = vec![format!("uv {}, C = {}", v2(s.uv), v3(s.colour))];
    if let Some(lod) = s.lod {
        lines.push(format!("mip level {lod:.3} (the ray cone, {:.5} wide at the hit)", s.footprint));
    }
    if let Some(b) = s.bump {
        lines.push(format!("bump: (du, dv) = {}", v2(b)));
    }
    lines
}

fn raster_reflections(raster: &RasterSide) -> Vec<String> {
    let Some(s) = &raster.surface else { return Vec::new() };
    let mut lines = Vec::new();
    if let Some(e) = &s.environment {
        lines.push(format!("{} looked up along r = {}, {}: {}", e.map, v3(e.direction), e.texel, v3(e.radiance)));
        if let Some(c) = e.centre {
            lines.push(format!("the cube was captured at {}, read along {}", v3(c), v3(e.read_along)));
        }
    }
    if let Some(f) = s.fresnel {
        lines.push(format!("Fresnel: F = {f:.4} of kt·Mt reflected"));
    }
    if let Some(r) = &s.refraction {
        let exit = r.exit.map_or("not found (taken as unbent)".to_string(), v3);
        lines.push(format!(
            "refraction ({}): leaves the glass at {exit} along t2 = {}, F2 = {:.4}; L(t2) from {}: {}",
            r.mode,
            v3(r.direction),
            r.exit_fresnel,
            r.source,
            v3(r.radiance)
        ));
    }
    if let Some(m) = &s.mirror {
        lines.push(format!(
            "mirrored camera at {}; its image's texel ({}, {}) × kps·MPS = {}",
            v3(m.mirrored_eye),
            m.texel[0],
            m.texel[1],
            v3(m.radiance)
        ));
    }
    lines
}

fn traced_secondary(rays: &RayNode) -> Vec<String> {
    rays.children
        .iter()
        .filter(|c| c.kind != RayKind::Shadow)
        .map(|c| {
            let hit = c.hit.as_ref().map_or("nothing".to_string(), |h| {
                format!("`{}` at {:.3}", h.object.clone().unwrap_or_else(|| "isosurface".into()), h.distance)
            });
            format!("{:?} ray along {} hits {hit}, brings {}", c.kind, v3(c.direction), v3(c.radiance))
        })
        .collect()
}

fn raster_layers(raster: &RasterSide) -> Vec<String> {
    raster
        .layers
        .iter()
        .map(|l| match l.kind {
            "volume" => format!(
                "volume: adds {}, lets {} through ({} samples)",
                v3(l.adds),
                v3(l.lets_through),
                l.samples.unwrap_or(0)
            ),
            _ => format!(
                "`{}` at depth {:.5}: adds Im = {}, lets kt·Mt = {} through",
                l.object.clone().or(l.material.clone()).unwrap_or_default(),
                l.depth,
                v3(l.adds),
                v3(l.lets_through)
            ),
        })
        .collect()
}

fn traced_volumes(rays: &RayNode) -> Vec<String> {
    rays.volumes
        .iter()
        .map(|v| {
            format!(
                "volumes: {} samples ({} saved), α = {:.4}, adds {}{}",
                v.samples,
                v.saved,
                v.alpha,
                v3(v.colour),
                if v.stopped_early { "; the ray stopped there" } else { "" }
            )
        })
        .collect()
}

/// The ray tree, one ray a line, indented by depth.
pub fn ray_tree(node: &RayNode) -> String {
    let mut out = String::new();
    fn walk(node: &RayNode, indent: usize, out: &mut String) {
        let what = match node.kind {
            RayKind::Shadow => format!(
                "shadow ray to `{}`: {}",
                node.light.clone().unwrap_or_default(),
                if node.occluders.is_empty() {
                    "reaches the light".to_string()
                } else {
                    format!("V = {}", v3(node.radiance))
                }
            ),
            kind => {
                let hit = node.hit.as_ref().map_or("hits nothing".to_string(), |h| {
                    format!(
                        "hits `{}` at {} ({:.4} away)",
                        h.object.clone().unwrap_or_else(|| "isosurface".into()),
                        v3(h.point),
                        h.distance
                    )
                });
                format!(
                    "{kind:?} ray from {} along {}: {hit}; L = {}",
                    v3(node.origin),
                    v3(node.direction),
                    v3(node.radiance)
                )
            }
        };
        out.push_str(&format!("{}{what}\n", "  ".repeat(indent)));
        for child in &node.children {
            walk(child, indent + 1, out);
        }
    }
    walk(node, 1, &mut out);
    out
}

/// The whole explanation as text.
pub fn render(explanation: &Explanation) -> String {
    let (raster, trace): (&RasterSide, &TraceSide) = (&explanation.raster, &explanation.trace);
    let [x, y] = explanation.pixel;
    let mut out = format!("pixel ({x}, {y})\n\n  {:<COLUMN$} │ {}\n", "RASTERIZER", "RAY TRACER");
    section(
        &mut out,
        "radiance (linear, before exposure and tone mapping)",
        vec![v3(raster.radiance)],
        vec![v3(trace.radiance)],
    );
    section(&mut out, "surface", raster_surface(raster), traced_surface(&trace.rays));
    section(&mut out, "terms (they add up to the radiance)", terms(&raster.terms), terms(&trace.terms));
    section(&mut out, "lights and shadows", raster_lights(raster), traced_lights(&trace.rays));
    section(&mut out, "textures and bumps", raster_textures(raster), traced_textures(&trace.rays));
    section(&mut out, "reflections and transmission", raster_reflections(raster), traced_secondary(&trace.rays));
    if let Some(seen) = &explanation.through_mirror {
        // The mirrored camera's pixel beside the reflected ray: the same question one level down.
        let reflected = trace.rays.children.iter().find(|c| c.kind == RayKind::Reflected);
        let traced = |lines: fn(&RayNode) -> Vec<String>| reflected.map_or_else(Vec::new, lines);
        let radiance = |node: &RayNode| vec![v3(node.radiance)];
        section(
            &mut out,
            "in the mirror: what its camera saw here, and what the reflected ray hits",
            [vec![format!("radiance {}", v3(seen.radiance))], raster_surface(seen)].concat(),
            [traced(radiance).into_iter().map(|r| format!("radiance {r}")).collect(), traced(traced_surface)].concat(),
        );
        section(
            &mut out,
            "in the mirror: terms",
            terms(&seen.terms),
            reflected.map_or_else(Vec::new, |r| terms(&r.terms)),
        );
    }
    section(
        &mut out,
        "transparent layers and volumes, in blend order",
        raster_layers(raster),
        traced_volumes(&trace.rays),
    );
    out.push_str("\ndiagnosis\n");
    match &explanation.diagnosis {
        Some(sentence) => wrap(sentence, 2 * COLUMN).iter().for_each(|l| out.push_str(&format!("  {l}\n"))),
        None => {
            out.push_str("  The two renderers agree here.\n");
            let sentence = match &explanation.nearest {
                Some(n) => format!(
                    "FLIP spreads a pixel's error over its neighbours, so an error map can be bright here: the nearest \
                     pixel that differs is ({}, {}), {:.1} px away (its displayed colours {} levels apart). Explain that \
                     one.",
                    n.pixel[0], n.pixel[1], n.distance, n.levels
                ),
                None => format!(
                    "No pixel within {} px differs by {} levels or more.",
                    super::NEAREST_RADIUS,
                    super::DIFFERS_BY
                ),
            };
            wrap(&sentence, 2 * COLUMN).iter().for_each(|l| out.push_str(&format!("  {l}\n")));
        }
    }
    if let Some(sentence) = &explanation.relief {
        out.push_str("\nwhat the relief would change\n");
        wrap(sentence, 2 * COLUMN).iter().for_each(|l| out.push_str(&format!("  {l}\n")));
    }
    out.push_str("\nthe tracer's ray tree\n");
    out.push_str(&ray_tree(&trace.rays));
    out
}
