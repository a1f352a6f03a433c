//! Normal maps (glTF's `normalTexture`) and bump maps: imported with their scale and the file's tangents, and
//! drawn alike by both renderers, checked against a hand computation.

mod common;

use std::path::Path;

use glam::{Vec3, Vec4};
use mirador::scene::file::parse;
use mirador::scene::{ColorSpace, Scene};
use mirador::settings::TangentSource;

fn data(relative: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(relative).display().to_string()
}

#[test]
fn gltf_normal_textures_and_tangents_are_imported() {
    let import = mirador::scene::gltf::import(Path::new(&data("gltf/normal_mapped.gltf"))).unwrap();
    let material = &import.materials[0];
    let normal = material.normal_map.expect("the material has a normal map");
    assert_eq!(material.normal_scale, 0.5);
    assert_eq!(import.textures[normal.0].color_space, ColorSpace::Linear, "normal maps are data, not colour");
    assert_eq!(import.meshes[0].tangents, vec![Vec4::new(1.0, 0.0, 0.0, -1.0); 4], "TANGENT is read as given");
}

/// A white plane facing +y whose normal map tilts every normal towards +u (= +x), under a
/// directional light from the +x side: brighter than the flat plane by exactly n'·l / n·l.
fn tilted_scene() -> Scene {
    let text = format!(
        r#"
        [camera]
        eye = [0, 4, 0.001]
        center = [0, 0, 0]
        fovy = 40
        near = 0.5
        far = 20
        width = 64
        height = 64
        [world]
        ambient = [0, 0, 0]
        [materials.tilted]
        color = [1, 1, 1]
        kd = 0.5
        normal_map = "{}"
        [[lights]]
        type = "directional"
        direction = [-1, -1, 0]
        [[objects]]
        type = "plane"
        size = [6, 6]
        material = "tilted"
        "#,
        data("textures/tilted-normal.png")
    );
    parse(&text, Path::new("normal.toml")).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_tilted_normal_map_lights_the_plane_as_computed_by_hand() {
    let scene = tilted_scene();
    // Texel (191, 128, 238): tangent-space normal 2·rgb − 1, in the frame t = +x (∂p/∂u),
    // b = +z (∂p/∂v), n = +y.
    let m = Vec3::new(191.0, 128.0, 238.0) / 255.0 * 2.0 - 1.0;
    let n_prime = Vec3::new(m.x, m.z, m.y).normalize();
    let l = Vec3::new(1.0, 1.0, 0.0).normalize();
    let expected = mirador::output::to_srgb8(Vec3::splat(0.5 * n_prime.dot(l)), 1.0);
    let flat = mirador::output::to_srgb8(Vec3::splat(0.5 * Vec3::Y.dot(l)), 1.0);
    assert!(expected[0] > flat[0] + 10, "the tilt towards the light brightens the plane");

    let mut per_vertex = scene.settings.clone();
    per_vertex.bump.tangents = TangentSource::PerVertex;
    let images = [
        ("raster, derivative tangents", common::raster(&scene, &scene.settings)),
        ("raster, per-vertex tangents", common::raster(&scene, &per_vertex)),
        ("ray traced", mirador::trace::render_image(&scene, &scene.settings)),
    ];
    for (name, image) in &images {
        let centre = image.get_pixel(32, 32);
        for c in 0..3 {
            assert!(centre[c].abs_diff(expected[c]) <= 1, "{name}: {centre:?} vs {expected:?}");
        }
    }
    let mut off = scene.settings.clone();
    off.bump.enabled = false;
    let unmapped = common::raster(&scene, &off).get_pixel(32, 32).0;
    assert!(unmapped[0].abs_diff(flat[0]) <= 1, "with bump mapping off the plane is flat: {unmapped:?} vs {flat:?}");
}

/// The bump scene (a cobbled tile and a cobbled ball under a low light) in both renderers: the
/// same finite differences on tangents from screen derivatives (raster) and from the analytic
/// surface (tracer). Measured: FLIP mean 0.0067. What differs: the ball's tessellated
/// silhouette, and the derivative tangents' 2×2-pixel quads at the edges of cobbles.
#[test]
fn bump_mapped_surfaces_agree_between_the_renderers() {
    let scene = common::load("scenes/bumps.toml");
    let raster = common::raster(&scene, &scene.settings);
    let traced = mirador::trace::render_image(&scene, &scene.settings);
    let bumped = common::difference(&traced, &raster).flip_mean;
    assert!(bumped < 0.01, "FLIP mean {bumped}");
    let mut flat = scene.settings.clone();
    flat.bump.enabled = false;
    let against_flat = common::flip(&traced, &common::raster(&scene, &flat));
    assert!(against_flat > 4.0 * bumped, "the bumps matter: {against_flat} against flat, {bumped} against bumped");
}
