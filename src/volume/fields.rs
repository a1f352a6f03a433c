//! Procedural scalar fields on the cube `[−1, 1]³`, sampled onto grids by
//! [`Grid::from_function`](super::Grid::from_function).
//!
//! - **Marschner–Lobb** (Marschner and Lobb, "An evaluation of reconstruction filters for volume
//!   rendering", 1994): the standard test of volume reconstruction. A slowly varying term in z
//!   plus a radial ripple of frequency `f_M = 6` whose crests are close to what a 40³ grid can
//!   hold, so every reconstruction filter's errors show as distortions of the rings.
//! - **Signed distances** to a sphere and a torus (negative inside): the isosurface `f = 0` is
//!   the exact surface, which makes them the test of isosurface search and gradient normals.
//! - **A CT-like phantom** made for Mirador: a head of ellipsoids in Hounsfield-like units (air
//!   −1000, scalp 40, brain 30, ventricles 0, bone 1000, two lesions of 400), edges blurred over
//!   about a voxel as a scanner's partial-volume effect blurs them.

use std::f32::consts::PI;

use glam::Vec3;

/// The Marschner–Lobb test signal, with values in `[0, 1]`:
/// `ρ = (1 − sin(πz/2) + α·(1 + ρ_r(√(x² + y²)))) / (2(1 + α))`,
/// `ρ_r(r) = cos(2π·f_M·cos(πr/2))`, `f_M = 6`, `α = 0.25`.
pub fn marschner_lobb(p: Vec3) -> f32 {
    const F_M: f32 = 6.0;
    const ALPHA: f32 = 0.25;
    let r = (p.x * p.x + p.y * p.y).sqrt();
    let ripple = (2.0 * PI * F_M * (PI * r / 2.0).cos()).cos();
    (1.0 - (PI * p.z / 2.0).sin() + ALPHA * (1.0 + ripple)) / (2.0 * (1.0 + ALPHA))
}

/// The signed distance to the sphere of `radius` about the origin.
pub fn sphere_distance(p: Vec3, radius: f32) -> f32 {
    p.length() - radius
}

/// The signed distance to the torus about the y axis with `major` radius to the tube's centre
/// and tube radius `minor`.
pub fn torus_distance(p: Vec3, major: f32, minor: f32) -> f32 {
    let ring = (p.x * p.x + p.z * p.z).sqrt() - major;
    (ring * ring + p.y * p.y).sqrt() - minor
}

/// One ellipsoid of the phantom: centre, semi-axes, and the value inside it.
struct Ellipsoid {
    centre: [f32; 3],
    axes: [f32; 3],
    value: f32,
}

/// The phantom's ellipsoids, each painted over those before it: scalp, skull, the skull's base,
/// brain, ventricles and two lesions, in air.
const PHANTOM: [Ellipsoid; 8] = [
    Ellipsoid { centre: [0.0, 0.0, 0.0], axes: [0.72, 0.92, 0.80], value: 40.0 },
    Ellipsoid { centre: [0.0, 0.0, 0.0], axes: [0.66, 0.86, 0.74], value: 1000.0 },
    Ellipsoid { centre: [0.0, -0.70, 0.0], axes: [0.50, 0.16, 0.58], value: 1000.0 },
    Ellipsoid { centre: [0.0, 0.02, 0.0], axes: [0.60, 0.78, 0.68], value: 30.0 },
    Ellipsoid { centre: [-0.14, 0.10, 0.0], axes: [0.08, 0.26, 0.12], value: 0.0 },
    Ellipsoid { centre: [0.14, 0.10, 0.0], axes: [0.08, 0.26, 0.12], value: 0.0 },
    Ellipsoid { centre: [0.0, -0.40, 0.25], axes: [0.12, 0.12, 0.12], value: 400.0 },
    Ellipsoid { centre: [0.30, 0.32, -0.28], axes: [0.14, 0.10, 0.12], value: 400.0 },
];

/// The phantom's value at `p`; `blur` is the width of each edge in the units of `p` (about a
/// voxel).
pub fn phantom(p: Vec3, blur: f32) -> f32 {
    let mut value = -1000.0;
    for e in &PHANTOM {
        let q = (p - Vec3::from(e.centre)) / Vec3::from(e.axes);
        // Distance outside the ellipsoid's surface, roughly in units of p near it.
        let outside = (q.length() - 1.0) * Vec3::from(e.axes).min_element();
        let inside = 1.0 - smoothstep(-0.5 * blur, 0.5 * blur, outside);
        value += (e.value - value) * inside;
    }
    value
}

fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marschner_lobb_stays_in_the_unit_interval_and_has_its_known_values() {
        // On the z axis the ripple is cos(2π·6) = 1: ρ = (1 − sin(πz/2) + 0.5)/2.5.
        assert!((marschner_lobb(Vec3::ZERO) - 0.6).abs() < 1e-6);
        assert!((marschner_lobb(Vec3::new(0.0, 0.0, 1.0)) - 0.2).abs() < 1e-6);
        for i in 0..1000 {
            let t = i as f32 / 999.0;
            let p = Vec3::new(2.0 * t - 1.0, (7.0 * t).sin(), (13.0 * t).cos());
            let v = marschner_lobb(p);
            assert!((0.0..=1.0).contains(&v), "{v} at {p}");
        }
    }

    #[test]
    fn distances_are_zero_on_the_surfaces() {
        assert_eq!(sphere_distance(Vec3::new(0.0, 0.6, 0.0), 0.6), 0.0);
        assert!(torus_distance(Vec3::new(0.7, 0.0, 0.0), 0.5, 0.2).abs() < 1e-6);
        assert!((torus_distance(Vec3::new(0.5, 0.3, 0.0), 0.5, 0.2) - 0.1).abs() < 1e-6);
        assert!(torus_distance(Vec3::ZERO, 0.5, 0.2) > 0.0);
    }

    #[test]
    fn the_phantom_has_its_tissues() {
        assert!((phantom(Vec3::new(0.0, 0.0, 0.99), 0.03) + 1000.0).abs() < 1.0, "air");
        assert!((phantom(Vec3::new(0.0, 0.2, 0.0), 0.03) - 30.0).abs() < 1.0, "brain");
        assert!((phantom(Vec3::new(0.0, 0.0, 0.70), 0.03) - 1000.0).abs() < 1.0, "skull");
        assert!((phantom(Vec3::new(-0.14, 0.1, 0.0), 0.03) - 0.0).abs() < 1.0, "ventricle");
    }
}
