//! Light sources of the course notes (docs/course/02-illumination.md#what-it-computes): point, directional and spot.
//!
//! Each light gives, at a surface point `p`, the unit vector `l` towards it, the distance to it and
//! the radiance `S_i` it delivers there: `colour · intensity · fat · spot`. `fat` is the
//! attenuation factor of the notes (1 as in the course notes, or the physical `1/d²`); `spot` is a
//! smooth cone falloff. The WGSL twin is `light_incidence` in `shaders/common/lighting.wgsl`.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Lumens per watt at 555 nm: the luminous efficacy that turns photometric units back into the
/// radiometric ones Blender renders in (its glTF exporter and importer use the same constant).
pub const LUMENS_PER_WATT: f32 = 683.0;

/// The course model's light intensity for a physical light of `photometric` candela (point and
/// spot lights: lm/sr) or lux (directional lights: lm/m²), as `KHR_lights_punctual` gives them.
///
/// A white Lambertian surface (albedo ρ) at distance `d` from a point light of `I` candela,
/// facing it, receives the illuminance `E = I/d²` and sends back the luminance `ρ·E/π`; in the
/// radiometric units a renderer such as Blender writes, that is `ρ·E/(683·π)`. The course's
/// diffuse term `kd·C·S·(n·l)`, with the light's `1/d²`, gives `ρ·S/d²`, so
/// `S = I / (683·π)`: the 683 converts lumens to watts, the π is Lambert's, which the course
/// model leaves to the light. The same holds for lux and directional lights. Blender's exporter
/// writes a point light of `P` watts as `P·683/(4π)` cd, so such a light ends up with
/// `S = P/(4π²)`, exactly what Cycles renders (tests/data/blender).
pub fn from_photometric(photometric: f32) -> f32 {
    photometric / (LUMENS_PER_WATT * std::f32::consts::PI)
}

/// How a positional light's radiance falls off with distance `d`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Attenuation {
    /// `fat = 1`, as in the course notes' examples.
    #[default]
    None,
    /// `fat = 1/d²`, the physical falloff of a point source.
    InverseSquare,
}

impl Attenuation {
    pub fn factor(self, distance: f32) -> f32 {
        match self {
            Attenuation::None => 1.0,
            Attenuation::InverseSquare => 1.0 / (distance * distance).max(f32::MIN_POSITIVE),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum LightKind {
    /// Radiates equally in all directions from `position`.
    Point { position: Vec3 },
    /// Parallel light travelling along `direction` (unit), from infinitely far away.
    Directional { direction: Vec3 },
    /// A point light restricted to a cone around `direction` (unit): full strength inside
    /// `inner` radians of the axis, none beyond `outer`, smoothstep in between.
    Spot { position: Vec3, direction: Vec3, inner: f32, outer: f32 },
}

/// Serializable for the page's tracer workers, which receive the lights as the viewer has edited
/// them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    /// Linear RGB colour; multiplied by `intensity`.
    pub color: Vec3,
    pub intensity: f32,
    /// Ignored by directional lights.
    pub attenuation: Attenuation,
}

/// What one light delivers at one surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incidence {
    /// Unit vector from the point towards the light.
    pub l: Vec3,
    /// Distance to the light (`f32::INFINITY` for directional lights): shadow rays stop there.
    pub distance: f32,
    /// `S_i`: colour · intensity · attenuation · spot falloff.
    pub radiance: Vec3,
}

impl Light {
    /// Where a point or spot light is; `None` for a directional light.
    pub fn position(&self) -> Option<Vec3> {
        match self.kind {
            LightKind::Point { position } | LightKind::Spot { position, .. } => Some(position),
            LightKind::Directional { .. } => None,
        }
    }

    /// Light arriving at `p`, or `None` when `p` is at the light's own position.
    pub fn incidence(&self, p: Vec3) -> Option<Incidence> {
        let emitted = self.color * self.intensity;
        match self.kind {
            LightKind::Directional { direction } => {
                Some(Incidence { l: -direction, distance: f32::INFINITY, radiance: emitted })
            }
            LightKind::Point { position } => {
                let (l, distance) = towards(p, position)?;
                Some(Incidence { l, distance, radiance: emitted * self.attenuation.factor(distance) })
            }
            LightKind::Spot { position, direction, inner, outer } => {
                let (l, distance) = towards(p, position)?;
                let cone = smoothstep(outer.cos(), inner.cos(), (-l).dot(direction));
                Some(Incidence { l, distance, radiance: emitted * self.attenuation.factor(distance) * cone })
            }
        }
    }
}

fn towards(p: Vec3, position: Vec3) -> Option<(Vec3, f32)> {
    let to_light = position - p;
    let distance = to_light.length();
    (distance > 0.0).then(|| (to_light / distance, distance))
}

/// Hermite interpolation of WGSL's `smoothstep`, with `edge0 == edge1` read as a hard step.
pub fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    if edge1 <= edge0 {
        return if x >= edge0 { 1.0 } else { 0.0 };
    }
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}
