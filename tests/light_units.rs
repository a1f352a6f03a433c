//! Physical light units (issue 14): glTF's photometric intensities (candela, lux) become the
//! course model's light intensity by `÷ (683·π)` (`mirador::scene::light::from_photometric`).
//!
//! Checked two ways: against hand-computed radiance (a point light of known candela over a white
//! Lambertian plane at a known distance, a sun of known lux at a known angle), and against
//! Blender, whose exporter writes the files: `tests/data/blender/make.py` exports two scenes and
//! renders them with Cycles (Standard view transform); Mirador's images of the exported files
//! must look about as bright as Blender's.

mod common;

use std::path::{Path, PathBuf};

use glam::Vec3;
use mirador::Scene;
use mirador::trace::{RenderControl, Tracer};

/// A 4 m × 4 m plane at y = 0 (white Lambertian: base colour `ALBEDO`, rough, not metallic) and
/// one `light` (a `KHR_lights_punctual` light object, JSON) on a node at `light_node` (JSON):
/// the glTF file's text and its buffer, `plane.bin`.
fn plane_gltf(light: &str, light_node: &str) -> (String, Vec<u8>) {
    let positions: [f32; 12] = [-2.0, 0.0, -2.0, 2.0, 0.0, -2.0, 2.0, 0.0, 2.0, -2.0, 0.0, 2.0];
    let normals: [f32; 12] = [0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0];
    let indices: [u16; 6] = [0, 2, 1, 0, 3, 2];
    let mut bytes: Vec<u8> = Vec::new();
    bytes.extend(positions.iter().flat_map(|v| v.to_le_bytes()));
    bytes.extend(normals.iter().flat_map(|v| v.to_le_bytes()));
    bytes.extend(indices.iter().flat_map(|v| v.to_le_bytes()));
    let gltf = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [{light}]}}}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1]}}],
  "nodes": [{{"mesh": 0}}, {light_node}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1}}, "indices": 2, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [{ALBEDO}, {ALBEDO}, {ALBEDO}, 1], "metallicFactor": 0, "roughnessFactor": 1}}}}],
  "buffers": [{{"byteLength": {len}, "uri": "plane.bin"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 12}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        len = bytes.len()
    );
    (gltf, bytes)
}

const ALBEDO: f32 = 0.8;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mirador-light-units-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    dir
}

/// The plane seen straight down by an orthographic camera over a 0.2 m window, no ambient light,
/// as a scene file that places the glTF file.
fn plane_scene(dir: &Path, (gltf, buffer): (String, Vec<u8>)) -> Scene {
    std::fs::write(dir.join("plane.gltf"), gltf).unwrap();
    std::fs::write(dir.join("plane.bin"), buffer).unwrap();
    let toml = r#"
[camera]
eye = [0, 5, 0]
center = [0, 0, 0]
up = [0, 0, -1]
projection = "orthographic"
ortho_height = 0.2
near = 0.1
far = 10
width = 8
height = 8

[world]
ambient = [0, 0, 0]

[[objects]]
type = "gltf"
path = "plane.gltf"
"#;
    std::fs::write(dir.join("scene.toml"), toml).unwrap();
    Scene::load(&dir.join("scene.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// The traced radiance at the image's centre (the mean of its four central pixels).
fn traced_centre(scene: &Scene) -> Vec3 {
    let tracer = Tracer::new(scene, &scene.settings);
    let (radiance, _) = tracer.render(&RenderControl::default()).expect("an uncancelled render");
    let w = radiance.width as usize;
    let (cx, cy) = (w / 2, radiance.height as usize / 2);
    [(cx - 1, cy - 1), (cx, cy - 1), (cx - 1, cy), (cx, cy)]
        .iter()
        .map(|&(x, y)| radiance.pixels[y * w + x])
        .sum::<Vec3>()
        / 4.0
}

fn check(scene: &Scene, expected: f32, what: &str) {
    let traced = traced_centre(scene);
    assert!(
        (traced - Vec3::splat(expected)).abs().max_element() < 2e-3 * expected,
        "{what}: traced radiance {traced}, hand-computed {expected}"
    );
    // The rasterizer's bytes are the output transform of the same radiance.
    let raster = common::raster(scene, &scene.settings);
    let want = mirador::output::to_srgb8(Vec3::splat(expected), 1.0);
    let got = raster.get_pixel(4, 4).0;
    assert!(
        (0..3).all(|c| got[c].abs_diff(want[c]) <= 1),
        "{what}: the rasterizer shows {got:?}, the hand-computed radiance encodes as {want:?}"
    );
}

#[test]
fn a_point_light_of_known_candela_over_a_white_plane() {
    let dir = scratch("point");
    // 1,000 cd, 2 m above the plane: E = I/d² = 250 lx; a Lambertian surface of albedo 0.8 sends
    // L = ρ·E/π = 63.66 cd/m², which is 63.66/683 = 0.09321 in radiometric units.
    let gltf = plane_gltf(
        r#"{"type": "point", "intensity": 1000}"#,
        r#"{"translation": [0, 2, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}"#,
    );
    let scene = plane_scene(&dir, gltf);
    let expected = ALBEDO * 1000.0 / 4.0 / std::f32::consts::PI / 683.0;
    assert!((expected - 0.093_21).abs() < 1e-5);
    check(&scene, expected, "point light");
}

#[test]
fn a_sun_of_known_lux_at_an_angle() {
    let dir = scratch("sun");
    // 683 lx along a direction 60° from the normal: E = 683·cos 60° = 341.5 lx on the plane, so
    // L = 0.8 · 341.5 / π / 683 = 0.12732.
    // The light shines down its node's −z; turned −30° about x, −z becomes (0, −sin 30°, −cos 30°),
    // 60° from the plane's normal (checked on the loaded light below).
    let q = glam::Quat::from_rotation_x(-30f32.to_radians());
    let node = format!(
        r#"{{"rotation": [{}, {}, {}, {}], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}}"#,
        q.x, q.y, q.z, q.w
    );
    let gltf = plane_gltf(r#"{"type": "directional", "intensity": 683}"#, &node);
    let scene = plane_scene(&dir, gltf);
    let mirador::scene::LightKind::Directional { direction } = scene.lights[0].kind else { panic!("a sun") };
    let angle = direction.dot(Vec3::NEG_Y).acos().to_degrees();
    assert!((angle - 60.0).abs() < 1e-3, "the sun shines 60° from the plane's normal: {angle}°");
    let expected = ALBEDO * 683.0 * 0.5 / std::f32::consts::PI / 683.0;
    check(&scene, expected, "sun");
}

fn blender(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender").join(name)
}

#[test]
fn blender_materials_map_onto_the_model() {
    let import = mirador::scene::gltf::import(&blender("sun_materials.glb")).unwrap_or_else(|e| panic!("{e}"));
    let material = |name: &str| import.materials.iter().find(|m| m.name == name).unwrap_or_else(|| panic!("{name}"));
    let glass = material("glass");
    // Transmission replaces diffuse: a glass sphere is not a white ball.
    assert_eq!((glass.kd, glass.transmission), (0.0, 1.0), "{glass:?}");
    assert!((glass.ior - 1.45).abs() < 1e-6, "{glass:?}");
    let gold = material("gold");
    assert_eq!(gold.kd, 0.0, "metals have no diffuse term");
    assert!(gold.mirror_color.abs_diff_eq(Vec3::new(1.0, 0.77, 0.34), 1e-3), "{gold:?}");
    let red = material("red plastic");
    assert_eq!((red.kd, red.transmission), (1.0, 0.0), "{red:?}");
    // The sun: strength 3 W/m² in Blender, 2,049 lx in the file, 3/π in the model.
    let sun = &import.lights[0];
    assert!((sun.intensity - 3.0 / std::f32::consts::PI).abs() < 1e-4, "{sun:?}");
}

/// The mean linear value of an sRGB image, all channels.
fn mean_linear(image: &image::RgbaImage) -> f32 {
    let sum: f32 =
        image.pixels().flat_map(|p| (0..3).map(move |c| mirador::output::srgb_decode(f32::from(p[c]) / 255.0))).sum();
    sum / (3 * image.width() * image.height()) as f32
}

/// Blender's Cycles render of `name`.glb against Mirador's, both renderers at Blender's size
/// with the file's own camera, lights and the bare-model world: for each, the mean FLIP and the
/// ratio of mean linear brightness (Mirador's over Blender's).
fn against_blender(name: &str) -> [(f32, f32); 2] {
    let reference = image::open(blender(&format!("{name}-blender.png"))).expect("Blender's render").into_rgba8();
    let mut scene = Scene::load(&blender(&format!("{name}.glb"))).unwrap_or_else(|e| panic!("{e}"));
    (scene.camera.width, scene.camera.height) = reference.dimensions();
    let raster = common::raster(&scene, &scene.settings);
    let traced = mirador::trace::render_image(&scene, &scene.settings);
    let dir = std::env::temp_dir();
    let measure = |image: &image::RgbaImage, what: &str| {
        let _ = image.save(dir.join(format!("mirador-blender-{name}-{what}.png")));
        let flip = common::difference(&reference, image).flip_mean;
        (flip, mean_linear(image) / mean_linear(&reference))
    };
    [measure(&raster, "raster"), measure(&traced, "traced")]
}

/// Measured 2026-11-24, the bare files with their defaults for glass (Fresnel, refraction through
/// the environment, the ground as the cubes' proxy): default cube FLIP 0.009 (both renderers),
/// brightness 0.98; sun and materials FLIP 0.154 raster / 0.153 traced, brightness 0.90 / 0.90
/// (0.161 / 0.156 before Fresnel and refraction). The residual is what the course model leaves
/// out: Cycles' global illumination (light bounced off the floor brightens the cube's shadowed
/// faces and the sphere's undersides, hence Mirador a little darker), soft shadows (the sun's 0.5°
/// disc, the point light's 10 cm radius), glossy rather than mirror-sharp reflections on the
/// rough gold, and refraction caustics.
/// Without the photometric conversion (×2,146) every lit pixel of both files clamps to white.
#[test]
fn blender_exports_look_as_blender_renders_them() {
    for (name, max_flip) in [("default_cube", 0.03), ("sun_materials", 0.2)] {
        for (renderer, (flip, brightness)) in ["raster", "traced"].into_iter().zip(against_blender(name)) {
            println!("{name}, {renderer}: mean FLIP against Blender {flip:.4}, brightness ratio {brightness:.3}");
            assert!(
                flip < max_flip,
                "{name}, {renderer}: mean FLIP {flip} against Blender's render (bound {max_flip})"
            );
            assert!(
                (0.85..=1.05).contains(&brightness),
                "{name}, {renderer}: {brightness:.3}× as bright as Blender's render"
            );
        }
    }
}
