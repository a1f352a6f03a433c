//! What every render setting means, in the course's terms: the one table the viewer's panel reads
//! its tooltips, choices and ranges from.
//!
//! The panel is generated from `RenderSettings` itself (serialized to TOML and walked), so a new
//! technique's section appears in the viewer by being added to `src/settings.rs`. What cannot be
//! read from the struct — a one-line explanation of what the toggle changes in the formula, the
//! range a number may take — lives here, keyed by the same dotted path `--set` uses
//! (`shadows.map_size`). A unit test serializes the default settings and fails for any key this
//! table does not describe, so a toggle cannot land without its tooltip.
//!
//! The choices of an enum setting come from its `clap::ValueEnum` variants (their doc comments are
//! the help of each choice) spelled as serde writes them, so they are always the values `--set`
//! and scene files accept.

use clap::ValueEnum;
use serde::Serialize;

use crate::settings::{
    AccelKind, AntiAliasing, BumpView, EnvironmentMap, EnvironmentView, MirrorView, Prepass, ShadowFilter, ShadowFit,
    ShadowMethod, ShadowView, SphereView, TangentSource, TextureFilter, ToneMap, TracerLod, TransparencySort,
    VolumeGradient, VolumeMode, VolumeReconstruction, VolumeView,
};

/// One value an enum setting can take.
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    /// As serde writes it: the value of `--set key="value"`.
    pub value: String,
    /// The variant's doc comment, when it has one.
    pub help: Option<String>,
}

/// What the panel needs to know about one setting or section.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldDoc {
    /// One line: what the toggle changes, in the formula's or the course's terms.
    pub tooltip: &'static str,
    /// For enum settings, every value they accept (empty otherwise).
    pub choices: Vec<Choice>,
    /// For numbers, the inclusive range the panel's control allows (validation may be stricter).
    pub range: Option<(f64, f64)>,
}

/// The choices of an enum, spelled as serde writes them, with each variant's doc comment.
pub fn choices_of<T: ValueEnum + Serialize>() -> Vec<Choice> {
    T::value_variants()
        .iter()
        .filter_map(|variant| {
            let value = match toml::Value::try_from(variant) {
                Ok(toml::Value::String(name)) => name,
                _ => return None,
            };
            let help = variant.to_possible_value().and_then(|p| p.get_help().map(|h| h.to_string()));
            Some(Choice { value, help })
        })
        .collect()
}

fn doc(tooltip: &'static str) -> FieldDoc {
    FieldDoc { tooltip, choices: Vec::new(), range: None }
}

fn number(tooltip: &'static str, low: f64, high: f64) -> FieldDoc {
    FieldDoc { tooltip, choices: Vec::new(), range: Some((low, high)) }
}

fn choice<T: ValueEnum + Serialize>(tooltip: &'static str) -> FieldDoc {
    FieldDoc { tooltip, choices: choices_of::<T>(), range: None }
}

/// The description of the setting or section at the dotted path `key`, `None` for unknown keys.
pub fn describe(key: &str) -> Option<FieldDoc> {
    Some(match key {
        "terms" => doc(
            "Which terms of the illumination model L = ME + AG + Σ V·S·(ka·C + kd·C·(n·l) + ks·S·(r·v)^e) are drawn (TECHNIQUES.md §1).",
        ),
        "terms.ambient" => doc(
            "The ambient terms: global AG = A ⊗ kd·C and each light's ka·C. Off: surfaces no light reaches go black.",
        ),
        "terms.diffuse" => {
            doc("Lambert's kd·C·max(0, n·l): matte shading that depends on the angle to the light, not on the viewer.")
        }
        "terms.specular" => {
            doc("Phong's ks·S·max(0, r·v)^e: the highlight that moves with the viewer; e (shininess) sets its size.")
        }
        "terms.emission" => doc("ME, the material's own emitted radiance, added whatever the lights."),
        "exposure" => number(
            "Multiplies linear radiance before the tone curve and the sRGB encoding (the output transform both renderers share).",
            0.01,
            16.0,
        ),
        "tone_map" => choice::<ToneMap>(
            "The curve from exposed radiance to the display: clamp (the course's), Reinhard, ACES (fitted) or Khronos PBR Neutral.",
        ),
        "sphere_segments" => number(
            "Slices around the rasterizer's tessellated spheres, tori and rounded boxes; the tracer's shapes are exact, so few slices show polygonal silhouettes in the difference view.",
            3.0,
            512.0,
        ),
        "textures" => doc(
            "Texture filtering (TECHNIQUES.md §2): mip level from log(distance), trilinear blending between the two nearest levels.",
        ),
        "textures.filter" => choice::<TextureFilter>(
            "How a texel is read: one texel, bilinear, within one mip level, between two (trilinear), anisotropic, or each level in its own colour.",
        ),
        "textures.tracer_lod" => choice::<TracerLod>(
            "How the ray tracer picks the mip level at a hit: the ray cone's footprint, or the seed's log(distance) rule.",
        ),
        "textures.anisotropy" => number(
            "Most samples along the footprint's long axis for the anisotropic filter (1 = isotropic).",
            1.0,
            16.0,
        ),
        "textures.lod_bias" => number(
            "Added to the mip level λ: positive blurs, negative sharpens and brings back the aliasing mipmaps remove.",
            -8.0,
            8.0,
        ),
        "bump" => doc(
            "Bump mapping (TECHNIQUES.md §3): n' = normalize((t_u + du·n) × (t_v + dv·n)) from a height field's differences.",
        ),
        "bump.enabled" => {
            doc("Perturb the shading normal by the height field's slope; off shades with the geometric normal n.")
        }
        "bump.tangents" => {
            choice::<TangentSource>("Where the rasterizer's tangents t_u = ∂p/∂u, t_v = ∂p/∂v come from.")
        }
        "bump.scale" => number(
            "Multiplies every material's k in du = k·(f(u+Δ) − f(u−Δ))/2Δ: relief depth (negative inverts it).",
            -8.0,
            8.0,
        ),
        "bump.delta_texels" => number(
            "The finite-difference step Δ in texels of the height map: small follows detail, large smooths it.",
            0.05,
            64.0,
        ),
        "bump.analytic" => {
            doc("For procedural height fields, the exact derivatives instead of finite differences (compare the two).")
        }
        "bump.view" => choice::<BumpView>(
            "Teaching view: show the perturbed normal n' or the tangent t_u as colour instead of the shading.",
        ),
        "shadows" => doc(
            "Cast shadows (TECHNIQUES.md §4): the visibility V of each light in Σ V·S·(…), by shadow maps or projected polygons; shadow rays in the tracer.",
        ),
        "shadows.enabled" => {
            doc("Compute V for each light; off, every point sees every light (V = 1) in both renderers.")
        }
        "shadows.method" => choice::<ShadowMethod>(
            "Image precision (two-pass z-buffer from the light) or object precision (casters projected onto planar receivers).",
        ),
        "shadows.map_size" => number(
            "Texels on each side of a shadow map (pass 1's depth buffer A): small maps give blocky edges.",
            256.0,
            4096.0,
        ),
        "shadows.filter" => choice::<ShadowFilter>(
            "How the stored depth d is compared around the projected point q: one texel, 2×2, 3×3, 5×5 or a Poisson disc (PCF).",
        ),
        "shadows.depth_bias" => number(
            "Constant added to d before d < ‖q − y‖: cures self-shadowing acne; too much detaches shadows (peter-panning).",
            0.0,
            10000.0,
        ),
        "shadows.slope_bias" => number(
            "Bias that grows with the surface's depth slope as the light sees it: acne on grazing surfaces.",
            0.0,
            16.0,
        ),
        "shadows.normal_offset" => {
            number("Moves the lookup point q along n by this many shadow-map texels before projecting it.", 0.0, 16.0)
        }
        "shadows.distance" => number(
            "How far from the eye a directional light's orthographic map reaches (0: four times eye–centre, at most far).",
            0.0,
            10000.0,
        ),
        "shadows.fit" => choice::<ShadowFit>(
            "What a directional light's map covers: the view frustum (finer texels, redrawn as the camera moves) or the whole scene (kept).",
        ),
        "shadows.cache" => doc(
            "Keep each map layer across frames until its light, the casters or the bias change: pass 1 depends on the light, not the camera.",
        ),
        "shadows.transmission" => doc(
            "Transparent casters (kt > 0) let kt·MT through: coloured, partial shadows (0 < V < 1) instead of black ones.",
        ),
        "shadows.view" => {
            choice::<ShadowView>("Teaching view: the shadow map's depths, or its texels as they land on the receivers.")
        }
        "shadows.view_layer" => {
            number("Which shadow map the map view shows (a point light has six, one per cube face).", 0.0, 95.0)
        }
        "shadows.show_frusta" => {
            doc("Draw each shadowed light's view volume (the frustum pass 1 renders) into the scene.")
        }
        "transparency" => doc(
            "Transparent surfaces (TECHNIQUES.md §5): drawn after the opaque ones, farthest first, each pixel updated as I = Im + kt·Mt·I.",
        ),
        "transparency.enabled" => doc(
            "Off: transparent surfaces are drawn as opaque ones with their illumination model alone (the glass pane turns dark).",
        ),
        "transparency.sort" => choice::<TransparencySort>(
            "The drawing order: I = Im + kt·Mt·I is right only farthest first; compare the orders where they fail.",
        ),
        "transparency.peel_layers" => number(
            "Layers the exact order peels at every pixel, from the back; each costs two passes over the transparent surfaces.",
            1.0,
            32.0,
        ),
        "mirrors" => doc(
            "Planar mirrors (TECHNIQUES.md §6): the scene rendered by the camera mirrored about each mirror's plane, shown in the mirror as kps·MPS·L(r).",
        ),
        "mirrors.enabled" => doc("Off: mirrors show their illumination model alone, without the kps·MPS·L(r) term."),
        "mirrors.depth" => number(
            "How deep mirrors that see each other recurse; 0 draws every mirror as its plain material (the tracer's max_depth for mirror rays).",
            0.0,
            8.0,
        ),
        "mirrors.view" => choice::<MirrorView>(
            "Teaching views: the first mirror camera's own image, or each mirrored camera's view volume drawn in the scene.",
        ),
        "environment" => doc(
            "Environment maps (TECHNIQUES.md §6): curved mirrors look kps·MPS·L(r) up in a cube, sphere or latitude–longitude map; the world's environment is the background.",
        ),
        "environment.enabled" => {
            doc("Off: curved mirrors show their illumination model alone, without the kps·MPS·L(r) term.")
        }
        "environment.map" => choice::<EnvironmentMap>(
            "Where r = reflect(−v, n) is looked up: a cube's face and texel, a sphere map (view space), or longitude and latitude.",
        ),
        "environment.dynamic" => doc(
            "Cube maps rendered from each reflective object's centre, so it reflects the scene; off: the world's environment alone.",
        ),
        "environment.cube_size" => number("Texels on a side of each cube face the renderer makes.", 16.0, 2048.0),
        "environment.refresh" => {
            number("Draw the dynamic cubes again every N frames; 0: only when something they see changes.", 0.0, 600.0)
        }
        "environment.sphere_view" => choice::<SphereView>(
            "The sphere map belongs to one view direction: fixed keeps the first frame's, follow makes it again for every frame.",
        ),
        "environment.view" => choice::<EnvironmentView>(
            "Teaching views: the cube map unfolded as a cross, the sphere map, or the latitude–longitude map.",
        ),
        "environment.inset" => doc(
            "Draw the teaching view in the frame's lower-right corner with the scene around it (in the viewer the latitude–longitude view then marks the reflected direction under the cursor); off: over the whole frame.",
        ),
        "volume" => doc(
            "Direct volume rendering (TECHNIQUES.md §8): rays march the voxel grid, classify each sample by the transfer function, shade it C = C_amb + C_luz·k_dif·(n·L) and composite front to back; or find the isosurface f = iso.",
        ),
        "volume.enabled" => doc("Off: volumes are left out of both renderers."),
        "volume.mode" => choice::<VolumeMode>(
            "Composite every volume, show every volume as its isosurface f = iso, or each as its scene file says.",
        ),
        "volume.step" => number(
            "Distance between samples along a ray, in voxels: smaller is slower and finer. With opacity correction the image keeps its brightness.",
            0.05,
            8.0,
        ),
        "volume.reconstruction" => choice::<VolumeReconstruction>(
            "How the field is read between grid points: the nearest point (blocks) or trilinear interpolation of the eight around.",
        ),
        "volume.gradient" => choice::<VolumeGradient>(
            "Shading normals n = ∇f/|∇f| by forward (first-order) or central (second-order) differences; off: samples show their classified colour unshaded.",
        ),
        "volume.opacity_correction" => doc(
            "Correct each sample's opacity for its length, α' = 1 − (1 − α)^ℓ, so the image does not change with the step.",
        ),
        "volume.early_termination" => doc(
            "Stop a ray once its accumulated opacity reaches the threshold: what lies behind would add at most 1 − threshold.",
        ),
        "volume.threshold" => number("The accumulated opacity at which early termination stops a ray.", 0.5, 1.0),
        "volume.shadows" => doc(
            "Shadows of opaque surfaces on composited samples (a shadow ray per sample and light in the tracer, a shadow-map lookup in the rasterizer).",
        ),
        "volume.wireframe" => doc(
            "Draw each volume's grid cells as lines on its box's faces, over the frame: a line at every grid plane up to 32 cells a side, beyond that at every k-th plane (k = ⌈cells/32⌉), and the box's edges. A rasterizer overlay: the ray tracer does not draw it.",
        ),
        "volume.view" => choice::<VolumeView>(
            "Teaching views: the samples taken per pixel as a heat map (black none, white 512), showing what early termination saves.",
        ),
        "raster" => doc(
            "How the rasterizer spends its time. None of these changes what a technique computes; each trades time for a measured difference.",
        ),
        "raster.depth_prepass" => choice::<Prepass>(
            "Draw every pixel's depth first, then evaluate the illumination model once per pixel instead of once per fragment drawn.",
        ),
        "raster.adaptive_tessellation" => doc(
            "Tessellate spheres, tori and rounded boxes by their size on screen (outline within 1/16 pixel), at most sphere_segments.",
        ),
        "raster.render_scale" => number(
            "Draw at this fraction of the window's size and upscale: fewer pixels shaded, a blurrier image.",
            0.1,
            1.0,
        ),
        "raster.flat_colour" => doc(
            "Every surface in its material's colour C, no lighting: the least the GPU can do with this geometry (the benchmarks' floor).",
        ),
        "trace" => {
            doc("The Whitted ray tracer's own settings (TECHNIQUES.md §7): recursion, anti-aliasing, acceleration.")
        }
        "trace.max_depth" => number(
            "Deepest recursion of reflected kps·L(r) and refracted kt·L(t) rays; 0 leaves local shading only.",
            0.0,
            64.0,
        ),
        "trace.anti_aliasing" => choice::<AntiAliasing>(
            "How pixels are sampled: one ray through the centre (pixel-aligned with the rasterizer), grids, jitter, corners or adaptive.",
        ),
        "trace.samples" => {
            number("Rays per pixel side for regular and jittered sampling (samples² rays a pixel).", 1.0, 16.0)
        }
        "trace.seed" => number("Seed of the jittered pattern: the same seed draws the same image.", 0.0, 1.0e9),
        "trace.adaptive_threshold" => number(
            "Adaptive sampling splits a square while its corners differ by more than this (0–1 output values).",
            0.0,
            1.0,
        ),
        "trace.adaptive_max_level" => number("Deepest subdivision of adaptive sampling.", 0.0, 6.0),
        "trace.accelerator" => choice::<AccelKind>(
            "How rays find the nearest hit: BVH, uniform grid, octree, or every primitive (brute force); the image is the same.",
        ),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RenderSettings;

    /// Every dotted key of a serialized value: sections and their settings.
    fn keys(prefix: &str, table: &toml::Table, out: &mut Vec<(String, toml::Value)>) {
        for (name, value) in table {
            let key = if prefix.is_empty() { name.clone() } else { format!("{prefix}.{name}") };
            if let toml::Value::Table(inner) = value {
                keys(&key, inner, out);
            }
            out.push((key, value.clone()));
        }
    }

    #[test]
    fn every_setting_has_a_description() {
        let table = toml::Table::try_from(RenderSettings::default()).expect("settings serialize");
        let mut all = Vec::new();
        keys("", &table, &mut all);
        let missing: Vec<&str> = all.iter().filter(|(k, _)| describe(k).is_none()).map(|(k, _)| k.as_str()).collect();
        assert!(missing.is_empty(), "add a description to src/settings_doc.rs for: {missing:?}");
        for (key, value) in &all {
            let doc = describe(key).expect("checked above");
            assert!(!doc.tooltip.is_empty() && !doc.tooltip.contains('\n'), "{key}: a tooltip is one line");
            match value {
                toml::Value::String(current) => {
                    assert!(!doc.choices.is_empty(), "{key}: a string setting lists its choices");
                    assert!(doc.choices.iter().any(|c| &c.value == current), "{key}: `{current}` is among its choices");
                }
                toml::Value::Integer(_) | toml::Value::Float(_) => {
                    let (low, high) = doc.range.unwrap_or_else(|| panic!("{key}: a number has a range"));
                    assert!(low < high, "{key}: the range is not empty");
                }
                _ => {}
            }
        }
    }

    #[test]
    fn every_choice_is_accepted_by_set() {
        let table = toml::Table::try_from(RenderSettings::default()).expect("settings serialize");
        let mut all = Vec::new();
        keys("", &table, &mut all);
        for (key, _) in all.iter().filter(|(_, v)| v.is_str()) {
            for choice in describe(key).expect("described").choices {
                let mut settings = RenderSettings::default();
                settings.set(&format!("{key}=\"{}\"", choice.value)).unwrap_or_else(|e| panic!("{key}: {e}"));
            }
        }
    }

    #[test]
    fn choices_use_serde_names_and_carry_help() {
        let filters = choices_of::<TextureFilter>();
        let names: Vec<&str> = filters.iter().map(|c| c.value.as_str()).collect();
        assert!(names.contains(&"nearest_mip") && names.contains(&"level_colour"), "{names:?}");
        assert!(filters.iter().all(|c| c.help.is_some()), "every filter has a doc comment");
    }
}
