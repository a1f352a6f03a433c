//! glTF import: a valid two-node file read number by number, a GLB, and broken files that must
//! give an error naming the file and the problem instead of a panic.

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3};
use mirador::scene::gltf::{GltfImport, GltfProjection, import};
use mirador::scene::{Attenuation, ColorSpace, LightKind, SceneError, TextureId};

fn fixture(name: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/gltf/")).join(name)
}

fn load(name: &str) -> GltfImport {
    import(&fixture(name)).unwrap_or_else(|e| panic!("{name} should load: {e}"))
}

fn assert_close(actual: f32, expected: f32, what: &str) {
    assert!((actual - expected).abs() < 1e-5, "{what}: {actual} ≠ {expected}");
}

fn assert_close3(actual: Vec3, expected: Vec3, what: &str) {
    assert!(actual.abs_diff_eq(expected, 1e-5), "{what}: {actual} ≠ {expected}");
}

/// The file must fail with a glTF error whose message names it and says what is wrong.
fn assert_gltf_error(name: &str, words: &[&str]) -> String {
    let message = match import(&fixture(name)) {
        Ok(_) => panic!("{name} should not load"),
        Err(e @ SceneError::Gltf { .. }) => e.to_string(),
        Err(e) => panic!("{name}: expected a glTF error, got {e:?}"),
    };
    assert!(message.contains(name), "the message does not name {name}: {message}");
    for word in words {
        assert!(message.contains(word), "the message for {name} does not mention `{word}`: {message}");
    }
    message
}

#[test]
fn two_node_file_composes_transforms_and_shares_the_mesh() {
    let import = load("two_nodes.gltf");
    let names: Vec<&str> = import.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["parent/0", "parent/1", "child/0", "child/1"]);
    // Two primitives, each read once although two nodes draw them.
    assert_eq!(import.meshes.len(), 2);
    assert_eq!(import.objects[0].mesh, import.objects[2].mesh);
    assert_eq!(import.objects[1].mesh, import.objects[3].mesh);
    assert!(import.warnings.is_empty(), "{:?}", import.warnings);

    let parent = &import.objects[0];
    assert_eq!(parent.world_from_local, Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)));
    // child = T(1, 2, 3) · S(2): the quad's corner (1, 1, 0) lands at (3, 4, 3).
    let child = &import.objects[2];
    let corner = import.meshes[child.mesh].positions[2];
    assert_eq!(corner, Vec3::new(1.0, 1.0, 0.0));
    assert_close3(child.world_from_local.transform_point3(corner), Vec3::new(3.0, 4.0, 3.0), "child corner");

    let quad = &import.meshes[parent.mesh];
    assert_eq!(quad.name, "quad/0");
    assert_eq!(quad.indices, [0, 1, 2, 0, 2, 3]);
    assert_eq!(quad.normals, vec![Vec3::Z; 4]);
    assert_eq!(quad.uvs[1], Vec2::new(1.0, 1.0));

    // The strip primitive: four vertices unrolled into two triangles, normals computed.
    let strip = &import.meshes[import.objects[1].mesh];
    assert_eq!(strip.indices, [0, 1, 2, 1, 3, 2]);
    assert_eq!(strip.normals.len(), 4);
    assert_eq!(strip.uvs, vec![Vec2::ZERO; 4]);
}

#[test]
fn metallic_roughness_maps_by_the_documented_rule() {
    let import = load("two_nodes.gltf");
    assert_eq!(import.materials.len(), 2);
    let m = &import.materials[import.objects[0].material];
    assert_eq!(m.name, "painted");
    // C = (0.8, 0.4, 0.2), metallic 0.5, roughness 0.5, worked out by hand.
    let c = Vec3::new(0.8, 0.4, 0.2);
    assert_close3(m.color, c, "color");
    assert_eq!(m.texture, Some(TextureId(0)));
    assert_eq!(m.ka, 0.0);
    assert_close(m.kd, 0.5, "kd = 1 − m");
    assert_close(m.ks, (0.04 * 0.5 + 0.5) * 0.5, "ks");
    assert_close(m.ks, 0.26, "ks");
    assert_close3(m.specular_color, Vec3::new(0.9, 0.7, 0.6), "specular colour = mix(white, C, m)");
    // α = 0.5² = 0.25, e = 2/α² − 2 = 30.
    assert_close(m.shininess, 30.0, "shininess");
    assert_close(m.mirror, 0.5 * 0.25, "mirror = m·(1 − r)²");
    assert_close3(m.mirror_color, m.specular_color, "mirror colour");
    // emissiveFactor (0.1, 0.2, 0.3) × emissiveStrength 2.
    assert_close3(m.emission, Vec3::new(0.2, 0.4, 0.6), "emission");
    assert_eq!(m.transmission, 0.0);
    assert_eq!(m.ior, 1.0);

    let default = &import.materials[import.objects[1].material];
    assert_eq!(default.name, "gltf-default");
    assert_eq!(default.color, mirador::scene::Material::default().color);
}

#[test]
fn base_colour_texture_is_an_srgb_image() {
    let import = load("two_nodes.gltf");
    assert_eq!(import.textures.len(), 1);
    let t = &import.textures[0];
    assert_eq!((t.width, t.height), (4, 4));
    assert_eq!(t.color_space, ColorSpace::Srgb);
    assert_eq!(t.rgba8.len(), 4 * 4 * 4);
    assert_eq!(t.rgba8[..8], [255, 0, 0, 255, 0, 255, 0, 255]);
    assert!(t.path.to_string_lossy().ends_with("two_nodes.gltf#image0"), "{}", t.path.display());
}

#[test]
fn lights_and_camera_sit_at_their_nodes() {
    let import = load("two_nodes.gltf");
    assert_eq!(import.lights.len(), 2);
    let bulb = &import.lights[0];
    assert_eq!(bulb.name, "bulb");
    let LightKind::Point { position } = bulb.kind else { panic!("bulb: {:?}", bulb.kind) };
    // T(1, 2, 3) · T(0, 5, 0).
    assert_close3(position, Vec3::new(1.0, 7.0, 3.0), "bulb position");
    assert_eq!(bulb.attenuation, Attenuation::InverseSquare);
    assert_eq!(bulb.color, Vec3::new(1.0, 0.9, 0.8));
    // 50 cd, converted to the course model's units: 50 / (683·π).
    assert!((bulb.intensity - 0.023_302).abs() < 1e-6, "{}", bulb.intensity);

    let torch = &import.lights[1];
    let LightKind::Spot { position, direction, inner, outer } = torch.kind else { panic!("torch: {:?}", torch.kind) };
    assert_close3(position, Vec3::new(1.0, 2.0, 7.0), "torch position");
    // The node turns −90° about x, so its −z points down.
    assert_close3(direction, Vec3::NEG_Y, "torch direction");
    assert_eq!((inner, outer), (0.3, 0.6));
    assert!((torch.intensity - 0.046_604).abs() < 1e-6, "{}", torch.intensity);

    assert_eq!(import.cameras.len(), 1);
    let camera = &import.cameras[0];
    assert_eq!(camera.name, "main-camera");
    assert!(camera.world_from_camera.abs_diff_eq(Mat4::from_translation(Vec3::new(1.0, 2.0, 13.0)), 1e-6));
    assert_eq!(camera.projection, GltfProjection::Perspective { yfov_radians: 0.8, znear: 0.1, zfar: Some(100.0) });
}

#[test]
fn glb_triangle_loads() {
    let import = load("triangle.glb");
    assert_eq!(import.objects.len(), 1);
    assert_eq!(import.objects[0].name, "node 0/0");
    assert_eq!(import.objects[0].world_from_local, Mat4::IDENTITY);
    let mesh = &import.meshes[0];
    assert_eq!(mesh.positions, [Vec3::ZERO, Vec3::X, Vec3::Y]);
    assert_eq!(mesh.indices, [0, 1, 2]);
    assert_eq!(mesh.normals, vec![Vec3::Z; 3]);
    assert_eq!(import.materials[0].name, "gltf-default");
}

#[test]
fn zero_area_triangle_is_removed_with_a_warning() {
    let import = load("degenerate.gltf");
    let mesh = &import.meshes[import.objects[0].mesh];
    assert_eq!(mesh.triangle_count(), 1);
    assert_eq!(mesh.indices, [0, 1, 2]);
    assert_eq!(import.warnings.len(), 1, "{:?}", import.warnings);
    assert!(import.warnings[0].contains("degenerate") && import.warnings[0].contains("degenerate.gltf"));
}

#[test]
fn malformed_json_is_an_error() {
    assert_gltf_error("malformed.gltf", &["JSON"]);
}

#[test]
fn missing_buffer_file_is_named() {
    assert_gltf_error("missing_bin.gltf", &["does_not_exist.bin", "buffer 0"]);
}

#[test]
fn missing_image_file_is_named() {
    assert_gltf_error("missing_image.gltf", &["missing_texture.png", "image 0"]);
}

#[test]
fn accessor_past_the_end_of_its_view_is_an_error() {
    assert_gltf_error("accessor_past_end.gltf", &["accessor 0", "past the end"]);
}

#[test]
fn view_past_the_end_of_its_buffer_is_an_error() {
    assert_gltf_error("view_past_end.gltf", &["buffer view 0", "past the end"]);
}

#[test]
fn index_out_of_range_is_an_error() {
    assert_gltf_error("index_out_of_range.gltf", &["out of range", "index 7", "shape-mesh/0"]);
}

#[test]
fn infinite_node_transform_is_an_error() {
    // 1e39 does not fit in an f32: it parses as infinity, which the importer must catch.
    assert_gltf_error("infinite_matrix.gltf", &["node `shape`", "not finite"]);
}

#[test]
fn node_cycle_is_an_error() {
    assert_gltf_error("cycle.gltf", &["cycle"]);
}

#[test]
fn truncated_glb_is_an_error() {
    assert_gltf_error("truncated.glb", &["GLB"]);
}

#[test]
fn missing_or_empty_path_is_an_error_naming_it() {
    let missing = fixture("no_such_model.gltf");
    match import(&missing) {
        Err(e @ SceneError::Io { .. }) => assert!(e.to_string().contains("no_such_model.gltf"), "{e}"),
        other => panic!("expected an I/O error, got {other:?}"),
    }
    match import(Path::new("")) {
        Err(e @ SceneError::Gltf { .. }) => assert!(e.to_string().contains("empty"), "{e}"),
        other => panic!("expected a glTF error, got {other:?}"),
    }
}
