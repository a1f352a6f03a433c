//! The local illumination model ("MIL", docs/course/02-illumination.md, `EvaluaMILRec` and
//! `Directa`), evaluated once here for the ray tracer and once in `shaders/common/lighting.wgsl`
//! for the rasterizer. `tests/illumination.rs` runs both on the same inputs.
//!
//! ```text
//! L = ME + AG(p) + Σ_i V_i · S_i ⊗ ( ka·C + [n·l > 0] · ( kd·C·(n·l) + ks·Sc·max(0, r·v)^e ) )
//! r = 2(n·l)n − l          AG(p) = A ⊗ kd·C
//! ```
//!
//! `S_i` is what light `i` delivers (colour, intensity, attenuation; see `light.rs`), `V_i` its
//! visibility (1 without shadows), `A` the scene's global ambient radiance. Two choices the notes
//! leave open, made once for both renderers:
//! - `AG(p)`: the notes call it "radiancia ambiente global"; the Portuguese notes write it `Ia ⊗ kd`. We
//!   reflect `A` by the diffuse colour, so a perfect mirror (kd = 0) shows no ambient haze.
//! - A light behind the surface (n·l ≤ 0) adds no diffuse or specular term. The notes' own shadow
//!   test gives the same for closed objects; for open ones (a quad seen from its back) it stops
//!   a highlight leaking through.
//!
//! The normal is turned to face the viewer first, so thin surfaces are lit on both sides.

use glam::Vec3;

use super::light::Incidence;
use super::material::Material;

/// The material parameters at one surface point, after texturing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSample {
    /// `C(p)`: material colour times texture, linear RGB.
    pub color: Vec3,
    pub ka: f32,
    pub kd: f32,
    pub ks: f32,
    pub specular_color: Vec3,
    pub shininess: f32,
    pub emission: Vec3,
}

impl SurfaceSample {
    /// The material's constants with `C` replaced by the textured colour.
    pub fn new(material: &Material, color: Vec3) -> SurfaceSample {
        SurfaceSample {
            color,
            ka: material.ka,
            kd: material.kd,
            ks: material.ks,
            specular_color: material.specular_color,
            shininess: material.shininess,
            emission: material.emission,
        }
    }
}

/// Which terms of the model are drawn: the teaching toggles of `RenderSettings::terms`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Terms {
    pub ambient: bool,
    pub diffuse: bool,
    pub specular: bool,
    pub emission: bool,
}

impl From<crate::settings::TermSettings> for Terms {
    fn from(t: crate::settings::TermSettings) -> Terms {
        Terms { ambient: t.ambient, diffuse: t.diffuse, specular: t.specular, emission: t.emission }
    }
}

impl Terms {
    pub const ALL: Terms = Terms { ambient: true, diffuse: true, specular: true, emission: true };
}

/// Whether a light adds anything to a surface: it faces it (`n·l > 0`), or it lights it with its
/// ambient term `ka·C`. A light that does neither casts no shadow ray in the tracer, and
/// `mirador explain` lists it on neither side.
pub fn lights_surface(n: Vec3, l: Vec3, ka: f32, terms: Terms) -> bool {
    l.dot(n) > 0.0 || (ka != 0.0 && terms.ambient)
}

/// `n` turned to the viewer's side: the shading normal of a two-sided surface.
pub fn facing_viewer(n: Vec3, v: Vec3) -> Vec3 {
    if n.dot(v) < 0.0 { -n } else { n }
}

/// `L_dir(p, v, l)` of the notes, times the light's radiance `S_i`: the contribution of one
/// visible light. `n` and `v` are unit vectors; `n` already faces the viewer.
pub fn direct(surface: &SurfaceSample, n: Vec3, v: Vec3, light: &Incidence, terms: Terms) -> Vec3 {
    let mut rad = Vec3::ZERO;
    if terms.ambient {
        rad += surface.ka * surface.color;
    }
    let n_dot_l = n.dot(light.l);
    if n_dot_l > 0.0 {
        if terms.diffuse {
            rad += surface.kd * surface.color * n_dot_l;
        }
        if terms.specular && surface.ks > 0.0 {
            let r = 2.0 * n_dot_l * n - light.l;
            rad += surface.ks * surface.specular_color * r.dot(v).max(0.0).powf(surface.shininess);
        }
    }
    light.radiance * rad
}

/// The three parts of [`direct`], each times `S_i`: for explaining a pixel term by term (their
/// sum is `direct`'s up to rounding).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct DirectTerms {
    /// `ka·C`.
    pub ambient: Vec3,
    /// `kd·C·(n·l)`, where the light is in front.
    pub diffuse: Vec3,
    /// `ks·Sc·max(0, r·v)^e`, where the light is in front.
    pub specular: Vec3,
}

/// [`direct`], part by part.
pub fn direct_terms(surface: &SurfaceSample, n: Vec3, v: Vec3, light: &Incidence, terms: Terms) -> DirectTerms {
    let mut parts = DirectTerms::default();
    if terms.ambient {
        parts.ambient = light.radiance * surface.ka * surface.color;
    }
    let n_dot_l = n.dot(light.l);
    if n_dot_l > 0.0 {
        if terms.diffuse {
            parts.diffuse = light.radiance * surface.kd * surface.color * n_dot_l;
        }
        if terms.specular && surface.ks > 0.0 {
            let r = 2.0 * n_dot_l * n - light.l;
            parts.specular =
                light.radiance * surface.ks * surface.specular_color * r.dot(v).max(0.0).powf(surface.shininess);
        }
    }
    parts
}

/// The two parts of [`emitted_and_ambient`]: `ME`, and `AG = A ⊗ kd·C`.
pub fn emission_and_global_ambient(surface: &SurfaceSample, ambient: Vec3, terms: Terms) -> (Vec3, Vec3) {
    let emission = if terms.emission { surface.emission } else { Vec3::ZERO };
    let global = if terms.ambient { ambient * surface.kd * surface.color } else { Vec3::ZERO };
    (emission, global)
}

/// `ME + AG(p)`: the light a point gives off whatever the lights do.
pub fn emitted_and_ambient(surface: &SurfaceSample, ambient: Vec3, terms: Terms) -> Vec3 {
    let mut rad = Vec3::ZERO;
    if terms.emission {
        rad += surface.emission;
    }
    if terms.ambient {
        rad += ambient * surface.kd * surface.color;
    }
    rad
}

/// The whole local model at one point: `ME + AG + Σ V_i·S_i·L_dir`, with each light given as its
/// incidence and its visibility `V_i`, an RGB fraction (0 or 1 behind opaque occluders, the notes'
/// 0 < s < 1 through transparent ones). The recursive mirror and transmission terms are the tracer's.
pub fn local_illumination<'a>(
    surface: &SurfaceSample,
    n: Vec3,
    v: Vec3,
    ambient: Vec3,
    lights: impl IntoIterator<Item = (&'a Incidence, Vec3)>,
    terms: Terms,
) -> Vec3 {
    let n = facing_viewer(n, v);
    let mut rad = emitted_and_ambient(surface, ambient, terms);
    for (incidence, visibility) in lights {
        if visibility != Vec3::ZERO {
            rad += visibility * direct(surface, n, v, incidence, terms);
        }
    }
    rad
}
