//! glTF import: a valid two-node file read number by number, a GLB, broken files that must give
//! an error naming the file and the problem instead of a panic, and the extensions real files
//! use (texture transforms, quantized attributes, material extensions, required ones Mirador
//! lacks).

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3, Vec4};
use mirador::base::TextureId;
use mirador::scene::gltf::{GltfImport, GltfProjection, import};
use mirador::scene::{Attenuation, ColorSpace, LightKind, Material, SceneError};

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
fn a_missing_image_file_is_a_warning_naming_it_and_the_material_goes_without() {
    // As Blender and three.js draw such a model (issue 35): the image's material, untextured.
    let import = load("missing_image.gltf");
    let warning = import.warnings.iter().find(|w| w.contains("missing_texture.png"));
    let warning = warning.unwrap_or_else(|| panic!("no warning names the image: {:?}", import.warnings));
    assert!(warning.contains("image 0") && warning.contains("without it"), "{warning}");
    assert!(import.materials.iter().all(|m| m.texture.is_none()), "drawn without the texture");
    assert!(import.textures.is_empty());
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

// ---------------------------------------------------------------------------------------------
// Extensions real files use. The fixtures are written by hand (the buffers as `data:` URIs); each
// says what it holds in `asset.extras.about`.

fn material<'a>(import: &'a GltfImport, name: &str) -> &'a Material {
    import.materials.iter().find(|m| m.name == name).unwrap_or_else(|| panic!("no material `{name}`"))
}

fn assert_close2(actual: &[Vec2], expected: &[Vec2], what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}");
    for (a, e) in actual.iter().zip(expected) {
        assert!(a.abs_diff_eq(*e, 1e-5), "{what}: {actual:?} ≠ {expected:?}");
    }
}

#[test]
fn texture_transform_is_baked_into_the_texture_coordinates() {
    let import = load("texture_transform.gltf");
    let mesh = |i: usize| &import.meshes[import.objects[i].mesh];

    // `rotated`: TEXCOORD_1 (the transform's texCoord overrides the texture's 0) through
    // offset (0.5, 0.25), rotation π/2, scale (2, 3): u' = 3v + 0.5, v' = −2u + 0.25.
    let uv1 = [Vec2::new(0.0, 0.0), Vec2::new(0.5, 0.0), Vec2::new(0.5, 0.5), Vec2::new(0.0, 0.5)];
    let expected: Vec<Vec2> = uv1.iter().map(|uv| Vec2::new(3.0 * uv.y + 0.5, -2.0 * uv.x + 0.25)).collect();
    assert_close2(&mesh(0).uvs, &expected, "rotated");
    assert_close2(
        &expected,
        &[Vec2::new(0.5, 0.25), Vec2::new(0.5, -0.75), Vec2::new(2.0, -0.75), Vec2::new(2.0, 0.25)],
        "by hand",
    );
    // u' grows with v, and v = y/2 on this quad: the new tangent ∂p/∂u' is +y, same handedness.
    for t in &mesh(0).tangents {
        assert!(t.abs_diff_eq(Vec4::new(0.0, 1.0, 0.0, 1.0), 1e-6), "rotated tangent {t}");
    }

    // `mismatched`: the base colour's scale 2 wins over the normal texture's scale 4.
    let uv0 = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
    assert_close2(&mesh(1).uvs, &uv0.map(|uv| uv * 2.0), "mismatched");
    assert_eq!(mesh(1).tangents, vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4], "a uniform scale keeps the tangents");

    // `normal-only-mirrored`: u' = 1 − u mirrors the texture: the tangent turns to −x and its
    // handedness flips, so the bitangent w·(n × t) stays +y.
    assert_close2(&mesh(2).uvs, &uv0.map(|uv| Vec2::new(1.0 - uv.x, uv.y)), "mirrored");
    assert_eq!(mesh(2).tangents, vec![Vec4::new(-1.0, 0.0, 0.0, -1.0); 4]);

    // One warning, for the material whose textures disagree, naming both transforms.
    assert_eq!(import.warnings.len(), 1, "{:?}", import.warnings);
    let warning = &import.warnings[0];
    for word in ["mismatched", "scale (4, 4)", "scale (2, 2)", "base colour"] {
        assert!(warning.contains(word), "the warning should mention `{word}`: {warning}");
    }
    assert!(material(&import, "rotated").texture.is_some() && material(&import, "rotated").normal_map.is_some());
}

#[test]
fn quantized_attributes_are_read_as_khr_mesh_quantization_defines_them() {
    // The file *requires* KHR_mesh_quantization, which the `gltf` crate's own validation refuses.
    let import = load("quantized.gltf");
    assert!(import.warnings.is_empty(), "{:?}", import.warnings);
    let shorts = &import.meshes[import.objects[0].mesh];
    // SHORT positions convert by value; the node's scale 0.01 is the dequantization.
    assert_eq!(
        shorts.positions,
        [Vec3::ZERO, Vec3::new(100.0, 0.0, 0.0), Vec3::new(100.0, 100.0, 0.0), Vec3::new(0.0, 100.0, 0.0)]
    );
    let corner = import.objects[0].world_from_local.transform_point3(shorts.positions[2]);
    assert_close3(corner, Vec3::new(1.0, 1.0, 0.0), "dequantized corner");
    // Normalized BYTE normals (0, 0, 127) and normalized UNSIGNED_SHORT uvs: 127/127, 65535/65535.
    assert_eq!(shorts.normals, vec![Vec3::Z; 4]);
    assert_eq!(shorts.uvs, [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y]);

    let bytes = &import.meshes[import.objects[1].mesh];
    // Normalized BYTE positions: −128 clamps to −1, 127 is 1.
    assert_eq!(bytes.positions, [Vec3::NEG_X, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]);
    assert_eq!(bytes.normals, vec![Vec3::Z; 4], "normalized SHORT normals");
    // UNSIGNED_BYTE uvs 0..255, scaled by the material's KHR_texture_transform (1/255).
    assert_close2(&bytes.uvs, &[Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y], "dequantized uvs");
}

#[test]
fn material_extensions_map_by_the_documented_rules() {
    let import = load("material_extensions.gltf");

    // Clear glass: transmission 1 takes the whole diffuse lobe (kd = (1 − m)(1 − kt) = 0); its
    // reflectance is F0 = ((ior − 1)/(ior + 1))² with KHR_materials_ior's 1.45.
    let glass = material(&import, "glass");
    assert_eq!((glass.kd, glass.transmission, glass.ior), (0.0, 1.0, 1.45));
    assert_close(glass.ks, (0.45f32 / 2.45).powi(2), "glass ks = F0(1.45)");
    assert_close(glass.ks, 0.033_736, "glass ks by hand");
    assert_eq!((glass.mirror, glass.transmission_color), (0.0, Vec3::ONE));
    assert!(glass.is_transparent());

    // KHR_materials_specular with ior 2: F0 = 1/9, × colour (1, 0.5, 0.25), × factor 0.5 =
    // (1/18, 1/36, 1/72): ks = 1/18 · (1 − r) = 1/36, S = its hue.
    let tinted = material(&import, "tinted-specular");
    assert_close(tinted.ks, 1.0 / 36.0, "tinted ks");
    assert_close3(tinted.specular_color, Vec3::new(1.0, 0.5, 0.25), "tinted S");
    assert_close3(tinted.mirror_color, Vec3::new(1.0, 0.5, 0.25), "tinted MPS");
    assert_eq!((tinted.kd, tinted.ior, tinted.mirror), (1.0, 2.0, 0.0));

    // KHR_materials_clearcoat 1, roughness 0, over a rough red plastic (ks = 0, e = 1): the coat
    // reflects F = 0.04 in white; the base keeps 0.96 of its diffuse.
    let coat = material(&import, "clearcoat");
    assert_close(coat.kd, 0.96, "coat kd");
    assert_close(coat.ks, 0.04, "coat ks");
    assert_close(coat.mirror, 0.04, "coat mirror");
    assert_eq!((coat.specular_color, coat.mirror_color, coat.shininess), (Vec3::ONE, Vec3::ONE, 2048.0));
    assert_close3(coat.color, Vec3::new(0.8, 0.1, 0.1), "coat C");

    // emissiveFactor (1, 0.5, 0) × KHR_materials_emissive_strength 5.
    assert_close3(material(&import, "emissive").emission, Vec3::new(5.0, 2.5, 0.0), "emission");

    let frosted = material(&import, "frosted");
    assert_eq!((frosted.transmission, frosted.kd, frosted.ior), (0.5, 0.5, 1.2));
    assert_close3(frosted.transmission_color, Vec3::new(0.9, 0.9, 1.0), "frosted MT");

    // Sheen and volume are used by two materials but named in one warning.
    assert_eq!(import.warnings.len(), 1, "{:?}", import.warnings);
    let warning = &import.warnings[0];
    assert!(
        warning.contains("KHR_materials_sheen") && warning.contains("KHR_materials_volume"),
        "the warning names the ignored extensions: {warning}"
    );
    assert!(!warning.contains("clearcoat") && !warning.contains("specular"), "{warning}");
}

/// A minimal document using (and, with `required`, requiring) `extension`, in a scratch file.
fn file_with_extension(extension: &str, required: bool) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mirador-gltf-ext-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{extension}-{}.gltf", if required { "required" } else { "used" }));
    let required = if required { format!(r#", "extensionsRequired": ["{extension}"]"#) } else { String::new() };
    std::fs::write(&path, format!(r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["{extension}"]{required}}}"#))
        .unwrap();
    path
}

#[test]
fn a_required_extension_mirador_lacks_is_refused_by_name() {
    for extension in ["KHR_draco_mesh_compression", "EXT_meshopt_compression", "KHR_texture_basisu", "ACME_unheard_of"]
    {
        let path = file_with_extension(extension, true);
        let message = match import(&path) {
            Err(e @ SceneError::Gltf { .. }) => e.to_string(),
            other => panic!("{extension}: expected a glTF error, got {other:?}"),
        };
        assert!(message.contains(extension) && message.contains("requires"), "{message}");
        assert!(message.contains(path.file_name().unwrap().to_str().unwrap()), "names the file: {message}");

        // Used but not required: the file loads, with one warning naming the extension.
        let used = import(&file_with_extension(extension, false)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(used.warnings.len(), 1, "{:?}", used.warnings);
        assert!(used.warnings[0].contains(extension), "{:?}", used.warnings);
    }
}

#[test]
fn a_glass_sphere_with_transmission_1_is_traced_see_through() {
    use mirador::trace::Tracer;
    use mirador::trace::whitted::RayCounts;

    // The exporters' clear glass: white, metallic 0, roughness 0, transmission 1.
    let text = r#"
        [camera]
        eye = [0, 0, 5]
        center = [0, 0, 0]
        fovy = 30
        width = 33
        height = 33
        [world]
        ambient = [0.2, 0.2, 0.2]
        background = [0.2, 0.4, 0.6]
        [[lights]]
        type = "point"
        position = [-5, 5, 5]
        [[objects]]
        type = "gltf"
        path = "glass_sphere.gltf"
    "#;
    let mut scene = mirador::scene::file::parse(text, &fixture("glass.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.materials.iter().filter(|m| m.name == "glass").count(), 1);
    let glass = scene.materials.iter().position(|m| m.name == "glass").unwrap();
    assert_eq!((scene.materials[glass].kd, scene.materials[glass].transmission), (0.0, 1.0));

    let background = Vec3::new(0.2, 0.4, 0.6);
    // The centre, and points halfway to the rim on the right and below (the highlight of the
    // light at the upper left is elsewhere). Straight through a sphere of uniform background,
    // every refracted ray leaves it and sees the background: L = kt·MT·L(t) = background.
    let pixels = [Vec2::new(16.5, 16.5), Vec2::new(22.5, 16.5), Vec2::new(16.5, 22.5)];
    let tracer = Tracer::new(&scene, &scene.settings);
    for p in pixels {
        let got = tracer.primary(p, &mut RayCounts::default());
        assert!(got.abs_diff_eq(background, 2e-3), "pixel {p}: {got}, not the background seen through the glass");
    }

    // The bug the issue describes, kd = 1 − m with the transmitted share kept: a lit white ball.
    scene.materials[glass].kd = 1.0;
    let tracer = Tracer::new(&scene, &scene.settings);
    let white = tracer.primary(pixels[0], &mut RayCounts::default());
    assert!((white - background).min_element() > 0.15, "kd = 1 would add a white diffuse ball: {white}");
}

/// A glTF 1.0 file, as JSON or as a version-1 GLB, is refused by its name, not by the shape of
/// its JSON (issue 35).
#[test]
fn gltf_1_0_is_named_as_such() {
    let json = br#"{"asset": {"version": "1.0"}, "meshes": {"mesh": {"primitives": []}}}"#;
    let error = mirador::scene::gltf::import_bytes(Path::new("old.gltf"), json).unwrap_err().to_string();
    assert!(error.contains("glTF 1.0 is not supported (2.0 is)"), "{error}");
    let mut glb = b"glTF".to_vec();
    glb.extend(1u32.to_le_bytes());
    glb.extend(20u32.to_le_bytes());
    glb.extend([0u8; 8]);
    let error = mirador::scene::gltf::import_bytes(Path::new("old.glb"), &glb).unwrap_err().to_string();
    assert!(error.contains("glTF 1.0 is not supported"), "{error}");
    // 2.0 still reads.
    load("two_nodes.gltf");
}

/// A glTF object in a scene may name one of the scene's materials: every part of the model is
/// drawn in it (a downloaded model as an exercise's mirror), and its own materials are left out.
#[test]
fn a_gltf_object_may_take_a_scene_material() {
    let text = r#"
        [materials.chrome]
        color = [0.05, 0.05, 0.05]
        mirror = 0.9
        [[objects]]
        name = "model"
        type = "gltf"
        path = "glass_sphere.gltf"
        material = "chrome"
    "#;
    let scene = mirador::scene::file::parse(text, &fixture("chrome.toml")).unwrap_or_else(|e| panic!("{e}"));
    let chrome = scene.materials.iter().position(|m| m.name == "chrome").expect("the scene's material");
    let parts: Vec<_> = scene.objects.iter().filter(|o| o.name.starts_with("model/")).collect();
    assert!(!parts.is_empty());
    assert!(parts.iter().all(|o| o.material.0 == chrome), "every part in the scene's material");
    assert!(!scene.materials.iter().any(|m| m.name == "glass"), "the model's own materials are left out");
    let unknown = mirador::scene::file::parse(
        &text.replace("material = \"chrome\"", "material = \"gold\""),
        &fixture("chrome.toml"),
    )
    .expect_err("an unknown material");
    assert!(unknown.to_string().contains("chrome"), "the error lists the names that exist: {unknown}");
}
