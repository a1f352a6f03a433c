//! Eric Haines' "balls" scene of the Standard Procedural Databases (1987): the sphereflake, a
//! fractal of spheres on a ground plane under three lights, the classic test of how a renderer
//! scales with the number of objects.
//!
//! The definition: a sphere of radius 1/2 at the origin; every sphere of the last level but one
//! carries nine children of a third of its radius, touching it: six around its equator, 60°
//! apart, and three above, 120° apart, tilted 60° up from the equator; "up" and the equator are
//! taken about the axis from the sphere's parent to the sphere, so every level grows outward.
//! Size `n` has `n` levels of children: `1 + 9 + … + 9ⁿ = (9ⁿ⁺¹ − 1)/8` spheres, which is 91,
//! 820 and 7,381 for the database's sizes 2, 3 and 4. Azimuths and materials here are Mirador's
//! choice (the database's exact rotation of each level's children is not reproduced); the
//! counts, radii, placement rule, plane and lights are the database's.
//!
//! [`sphereflake_toml`] writes the scene as a scene file, so `render`, `trace` and the viewer read
//! it like any other (`cargo run --release --example sphereflake -- 4`).

use std::fmt::Write;

use glam::{Quat, Vec3};

/// The number of spheres of a sphereflake of `size` levels of children.
pub fn sphere_count(size: u32) -> u64 {
    (9u64.pow(size + 1) - 1) / 8
}

/// The spheres of a sphereflake of `size` levels: centre and radius, the root first.
pub fn spheres(size: u32) -> Vec<(Vec3, f32)> {
    let mut out = Vec::with_capacity(sphere_count(size) as usize);
    out.push((Vec3::ZERO, 0.5));
    grow(&mut out, Vec3::ZERO, 0.5, Vec3::Z, size);
    out
}

/// The nine children of the sphere at `center` of `radius`, whose outward axis is `axis`.
fn grow(out: &mut Vec<(Vec3, f32)>, center: Vec3, radius: f32, axis: Vec3, levels: u32) {
    if levels == 0 {
        return;
    }
    let child = radius / 3.0;
    let to_axis = Quat::from_rotation_arc(Vec3::Z, axis);
    let directions = (0..6)
        .map(|k| (k as f32 * 60f32).to_radians())
        .map(|azimuth| Vec3::new(azimuth.cos(), azimuth.sin(), 0.0))
        .chain((0..3).map(|k| {
            let (azimuth, elevation) = ((30.0 + k as f32 * 120.0f32).to_radians(), 60f32.to_radians());
            Vec3::new(elevation.cos() * azimuth.cos(), elevation.cos() * azimuth.sin(), elevation.sin())
        }));
    for direction in directions {
        let d = to_axis * direction;
        let c = center + d * (radius + child);
        out.push((c, child));
        grow(out, c, child, d, levels - 1);
    }
}

/// The sphereflake of `size` as a Mirador scene file, at `width × height` pixels.
pub fn sphereflake_toml(size: u32, width: u32, height: u32) -> String {
    let mut text = String::new();
    let mut line = |s: String| {
        text.push_str(&s);
        text.push('\n');
    };
    line(format!("# Sphereflake of size {size} ({} spheres), after Haines' SPD \"balls\".", sphere_count(size)));
    line("# Made by src/scene/sphereflake.rs; z is up, as in the database.".into());
    line(String::new());
    line("[camera]".into());
    line("eye = [2.1, 1.3, 1.7]".into());
    line("center = [0.0, 0.0, 0.0]".into());
    line("up = [0, 0, 1]".into());
    line("fovy = 45".into());
    line("near = 0.05".into());
    line("far = 50".into());
    line(format!("width = {width}"));
    line(format!("height = {height}"));
    line(String::new());
    line("[world]".into());
    line("ambient = [0.08, 0.08, 0.08]".into());
    line("background = [0.078, 0.361, 0.753]".into());
    line(String::new());
    line("[materials.ball]".into());
    line("color = [1.0, 0.75, 0.33]".into());
    line("ks = 0.5".into());
    line("shininess = 30".into());
    line(String::new());
    line("[materials.ground]".into());
    line("color = [1.0, 0.9, 0.7]".into());
    line(String::new());
    for (name, position) in [("light 1", [4.0, 3.0, 2.0]), ("light 2", [1.0, -4.0, 4.0]), ("light 3", [-3.0, 1.0, 5.0])]
    {
        line("[[lights]]".into());
        line(format!("name = \"{name}\""));
        line("type = \"point\"".into());
        line(format!("position = [{}, {}, {}]", position[0], position[1], position[2]));
        line("intensity = 0.45".into());
        line(String::new());
    }
    // The ground: a square below the flake, facing +z.
    line("[[objects]]".into());
    line("name = \"ground\"".into());
    line("type = \"plane\"".into());
    line("size = [12, 12]".into());
    line("rotate = [90, 0, 0]".into());
    line("translate = [0, 0, -0.5]".into());
    line("material = \"ground\"".into());
    for (index, (center, radius)) in spheres(size).into_iter().enumerate() {
        let _ = write!(
            text,
            "\n[[objects]]\nname = \"ball {index}\"\ntype = \"sphere\"\ncenter = [{}, {}, {}]\nradius = {}\nmaterial = \"ball\"\n",
            center.x, center.y, center.z, radius
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_two_to_four_have_the_databases_counts() {
        for (size, count) in [(2, 91), (3, 820), (4, 7381)] {
            assert_eq!(sphere_count(size), count);
            assert_eq!(spheres(size).len() as u64, count);
        }
    }

    #[test]
    fn every_child_touches_its_parent_and_never_overlaps_the_root() {
        let flake = spheres(2);
        let (root, r0) = flake[0];
        let first_level: Vec<_> = flake.iter().filter(|(_, r)| (r - r0 / 3.0).abs() < 1e-7).collect();
        assert_eq!(first_level.len(), 9);
        for &&(c, r) in &first_level {
            assert!((c.distance(root) - (r0 + r)).abs() < 1e-6, "a first-level child touches the root");
        }
        for &(c, r) in &flake[1..] {
            assert!(c.distance(root) >= r0 + r - 1e-5, "no sphere reaches into the root");
        }
    }
}
