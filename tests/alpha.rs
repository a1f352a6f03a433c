//! Coverage (`Material::alpha`, `AlphaMode`): the glTF import of `alphaMode`, `alphaCutoff`,
//! `baseColorFactor.a` and transmission, and the ray tracer's masks and blending, with radiance
//! known by hand (docs/course/06-transparency.md with `Im` scaled by `α` and `kt·Mt = 1 − α`).
//!
//! The scenes are lit so that every radiance is a short formula: no ambient unless said, surfaces
//! that only emit (`kd = 0`, emission `E`) or a white floor under one light at unit distance
//! scale. Radiance is read in linear RGB straight from the tracer, not from an 8-bit image.
//!
//! Textures (`tests/data/textures/`): `alpha-left-opaque.png` is 2×1, white, alpha 255 on the
//! left texel and 0 on the right; `alpha-128.png` is 1×1, white, alpha 128.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use mirador::Scene;
use mirador::scene::file::parse;
use mirador::scene::gltf::{GltfImport, import};
use mirador::scene::{AlphaMode, Material, Wrap};
use mirador::settings::TextureFilter;
use mirador::trace::Tracer;
use mirador::trace::whitted::RayCounts;

fn data(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(relative)
}

/// Parses `text` as if it were `tests/data/alpha.toml`, so that paths such as
/// `textures/alpha-128.png` and `gltf/alpha.gltf` resolve.
fn scene(text: &str) -> Scene {
    parse(text, &data("alpha.toml")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn assert_close3(actual: Vec3, expected: Vec3, what: &str) {
    assert!(actual.abs_diff_eq(expected, 1e-5), "{what}: {actual} ≠ {expected}");
}

const BACKGROUND: Vec3 = Vec3::new(0.2, 0.4, 0.6);
const E: Vec3 = Vec3::new(1.0, 0.5, 0.25);

/// A camera at z = 5 looking down −z at the origin over a 21 × 21 image; the background is
/// [`BACKGROUND`] and there is no ambient light. `more` adds materials and objects.
fn facing_camera(more: &str) -> Scene {
    scene(&format!(
        r#"
        [camera]
        eye = [0, 0, 5]
        center = [0, 0, 0]
        fovy = 30
        width = 21
        height = 21
        [world]
        ambient = [0, 0, 0]
        background = [0.2, 0.4, 0.6]
        {more}
        "#
    ))
}

/// A 2 × 2 emissive plane in z = `z`, facing the camera, with the material's other lines `lines`.
fn emissive_plane(name: &str, emission: Vec3, z: f32, lines: &str) -> String {
    format!(
        r#"
        [materials.{name}]
        color = [0, 0, 0]
        kd = 0
        emission = [{}, {}, {}]
        {lines}
        [[objects]]
        type = "plane"
        size = [2, 2]
        rotate = [90, 0, 0]
        translate = [0, 0, {z}]
        material = "{name}"
        "#,
        emission.x, emission.y, emission.z
    )
}

/// The centre pixel's radiance and the rays it took.
fn centre(scene: &Scene) -> (Vec3, RayCounts) {
    let tracer = Tracer::new(scene, &scene.settings);
    let mut counts = RayCounts::default();
    let radiance = tracer.primary(Vec2::new(10.5, 10.5), &mut counts);
    (radiance, counts)
}

// ---------------------------------------------------------------------------------------------
// Blending: L = α·(the surface's own radiance) + (1 − α)·L(behind).

#[test]
fn a_blended_plane_shows_alpha_of_itself_and_the_rest_of_the_background() {
    let mut scene = facing_camera(&emissive_plane("veil", E, 0.0, "alpha_mode = \"blend\"\nalpha = 0.25"));
    let (got, counts) = centre(&scene);
    assert_close3(got, 0.25 * E + 0.75 * BACKGROUND, "α·E + (1 − α)·background");
    assert_eq!((counts.primary, counts.refracted), (1, 1), "one ray continued through the veil");

    // At the deepest level the ray through is not traced, as a refracted ray would not be.
    scene.settings.trace.max_depth = 0;
    let (got, counts) = centre(&scene);
    assert_close3(got, 0.25 * E, "α·E alone at the maximum depth");
    assert_eq!(counts.refracted, 0);
}

#[test]
fn blended_layers_compose_front_to_back() {
    let green = Vec3::new(0.0, 1.0, 0.0);
    let scene = facing_camera(
        &(emissive_plane("front", E, 0.0, "alpha_mode = \"blend\"\nalpha = 0.25")
            + &emissive_plane("back", green, -1.0, "alpha_mode = \"blend\"\nalpha = 0.5")),
    );
    let (got, counts) = centre(&scene);
    let expected = 0.25 * E + 0.75 * (0.5 * green + 0.5 * BACKGROUND);
    assert_close3(got, expected, "α₁·E₁ + (1 − α₁)·(α₂·E₂ + (1 − α₂)·background)");
    assert_eq!(counts.refracted, 2);
}

#[test]
fn texture_alpha_is_linear_and_multiplies_the_material_alpha() {
    // alpha-128.png: 128/255 = 0.502 read linearly (as sRGB it would be 0.216).
    let scene = facing_camera(&emissive_plane(
        "veil",
        E,
        0.0,
        "alpha_mode = \"blend\"\nalpha = 0.5\ntexture = \"textures/alpha-128.png\"",
    ));
    let alpha = 0.5 * 128.0 / 255.0;
    // A 1×1 texture reads the same under every filter; the level-colour view replaces the colour,
    // not the coverage.
    for filter in [TextureFilter::Nearest, TextureFilter::Trilinear, TextureFilter::LevelColour] {
        let mut scene = scene.clone();
        scene.settings.textures.filter = filter;
        let (got, _) = centre(&scene);
        assert_close3(got, alpha * E + (1.0 - alpha) * BACKGROUND, &format!("α = alpha × texture alpha, {filter:?}"));
    }
}

#[test]
fn blending_and_transmission_are_both_kept() {
    // A covered fraction α that is glass (kt = 0.5, MT, ior 1: straight through) and 1 − α hole:
    // α·kt·MT·background + (1 − α)·background.
    let mt = Vec3::new(0.5, 1.0, 0.5);
    let scene = facing_camera(&emissive_plane(
        "frosted",
        Vec3::ZERO,
        0.0,
        "alpha_mode = \"blend\"\nalpha = 0.4\ntransmission = 0.5\ntransmission_color = [0.5, 1, 0.5]",
    ));
    let (got, counts) = centre(&scene);
    assert_close3(got, 0.4 * 0.5 * mt * BACKGROUND + 0.6 * BACKGROUND, "α·kt·MT·L(t) + (1 − α)·L");
    assert_eq!(counts.refracted, 2, "the refracted ray and the ray through the hole");
}

#[test]
fn blend_with_full_coverage_is_opaque() {
    let blended = facing_camera(&emissive_plane("veil", E, 0.0, "alpha_mode = \"blend\""));
    let opaque = facing_camera(&emissive_plane("veil", E, 0.0, ""));
    let ((a, a_counts), (b, b_counts)) = (centre(&blended), centre(&opaque));
    assert_eq!((a, a_counts), (b, b_counts));
    assert_close3(a, E, "the surface alone");
}

// ---------------------------------------------------------------------------------------------
// Masks: the surface exists only where α ≥ cutoff.

/// The texture coordinate u where the ray through pixel centre (i, 10.5) meets the plane z = 0
/// of a 2 × 2 plane (u = (x + 1)/2), or `None` off the plane.
fn u_at(scene: &Scene, i: u32) -> Option<f32> {
    let ray = scene.camera.ray_through(i as f32 + 0.5, 10.5);
    let x = ray.at(-ray.origin.z / ray.direction.z).x;
    (x.abs() < 1.0).then_some((x + 1.0) / 2.0)
}

#[test]
fn a_mask_shows_its_surface_where_the_texture_covers_and_the_background_elsewhere() {
    // Bilinear magnification of the 2×1 texture, clamped at the edges: α = 1 for u ≤ ¼, 0 for
    // u ≥ ¾ and linear between, so α ≥ 0.5 exactly for u ≤ ½ (x ≤ 0).
    let scene = facing_camera(&emissive_plane(
        "leaf",
        E,
        0.0,
        "alpha_mode = \"mask\"\ntexture = \"textures/alpha-left-opaque.png\"\nwrap = \"clamp\"",
    ));
    let tracer = Tracer::new(&scene, &scene.settings);
    let (mut surface, mut holes) = (0, 0);
    for i in 0..21 {
        let Some(u) = u_at(&scene, i) else { continue };
        let got = tracer.primary(Vec2::new(i as f32 + 0.5, 10.5), &mut RayCounts::default());
        if u < 0.49 {
            assert_close3(got, E, &format!("pixel {i}, u = {u}: the surface"));
            surface += 1;
        } else if u > 0.51 {
            assert_close3(got, BACKGROUND, &format!("pixel {i}, u = {u}: the hole"));
            holes += 1;
        }
    }
    assert!(surface >= 5 && holes >= 5, "{surface} surface and {holes} hole pixels");
}

#[test]
fn a_mask_without_texture_compares_the_material_alpha_with_the_cutoff() {
    for (alpha, cutoff, visible) in [(0.3, 0.5, false), (0.5, 0.5, true), (0.3, 0.25, true), (1.0, 1.0, true)] {
        let lines = format!("alpha_mode = \"mask\"\nalpha = {alpha}\nalpha_cutoff = {cutoff}");
        let (got, counts) = centre(&facing_camera(&emissive_plane("leaf", E, 0.0, &lines)));
        let expected = if visible { E } else { BACKGROUND };
        assert_close3(got, expected, &format!("α = {alpha}, cutoff = {cutoff}"));
        assert_eq!(counts.refracted, 0, "a mask is passed by the same ray, not a new one");
    }
}

#[test]
fn a_camera_ray_through_a_mask_finds_the_surface_behind() {
    let green = Vec3::new(0.0, 1.0, 0.0);
    let scene = facing_camera(
        &(emissive_plane("leaf", E, 0.0, "alpha_mode = \"mask\"\nalpha = 0.2")
            + &emissive_plane("wall", green, -1.0, "")),
    );
    assert_close3(centre(&scene).0, green, "the wall behind the hole");
}

#[test]
fn a_reflected_ray_passes_a_mask_too() {
    // A mirror in z = 0 sends the centre ray back along +z, past the eye, to a masked plane at
    // z = 8 that the camera's own rays (going −z) never meet.
    let mirror = r#"
        [materials.mirror]
        color = [0, 0, 0]
        kd = 0
        mirror = 1
        [[objects]]
        type = "plane"
        size = [10, 10]
        rotate = [90, 0, 0]
        material = "mirror"
    "#;
    for (alpha, expected) in [(0.7, E), (0.3, BACKGROUND)] {
        let lines = format!("alpha_mode = \"mask\"\nalpha = {alpha}");
        let scene = facing_camera(&(mirror.to_string() + &emissive_plane("leaf", E, 8.0, &lines)));
        let (got, counts) = centre(&scene);
        assert_close3(got, expected, &format!("mask α = {alpha} seen in the mirror"));
        assert_eq!(counts.reflected, 1);
    }
}

// ---------------------------------------------------------------------------------------------
// Shadows: through a surface covering α, a shadow ray carries α·kt·MT + (1 − α).

/// A white 4 × 4 floor in y = 0 (kd = 1) under a point light at (0, 8, 0), seen from (0, 2, 2)
/// below a 4 × 4 occluder in y = 4 with the material lines `occluder`; the centre pixel sees
/// the floor's origin, where `n·l = 1`, so it is lit to exactly `V`.
fn shadow_scene(occluder: &str) -> Scene {
    scene(&format!(
        r#"
        [camera]
        eye = [0, 2, 2]
        center = [0, 0, 0]
        fovy = 40
        width = 21
        height = 21
        [world]
        ambient = [0, 0, 0]
        [materials.floor]
        color = [1, 1, 1]
        [materials.occluder]
        color = [0, 0, 0]
        {occluder}
        [[lights]]
        type = "point"
        position = [0, 8, 0]
        [[objects]]
        type = "plane"
        size = [4, 4]
        material = "floor"
        [[objects]]
        type = "plane"
        size = [4, 4]
        translate = [0, 4, 0]
        material = "occluder"
        "#
    ))
}

fn visibility_at(scene: &Scene, x: f32) -> Vec3 {
    let tracer = Tracer::new(scene, &scene.settings);
    tracer.whitted.visibility(Vec3::new(x, 0.0, 0.0), Vec3::Y, 8.0, &mut RayCounts::default())
}

#[test]
fn a_blended_occluder_lets_one_minus_alpha_through() {
    let (lit, _) = centre(&shadow_scene("alpha_mode = \"blend\"\nalpha = 0"));
    assert_close3(lit, Vec3::ONE, "unshadowed: kd·C·(n·l) = 1");
    let half = shadow_scene("alpha_mode = \"blend\"\nalpha = 0.5");
    assert_close3(centre(&half).0, Vec3::splat(0.5), "α = 0.5: half the light, grey");
    assert_close3(visibility_at(&half, 0.0), Vec3::splat(0.5), "V");

    // With transmission: α·kt·MT + (1 − α).
    let mt = Vec3::new(1.0, 0.5, 0.25);
    let tinted =
        shadow_scene("alpha_mode = \"blend\"\nalpha = 0.5\ntransmission = 0.5\ntransmission_color = [1, 0.5, 0.25]");
    assert_close3(visibility_at(&tinted, 0.0), 0.25 * mt + Vec3::splat(0.5), "α·kt·MT + (1 − α)");

    // Opaque and transmissive occluders are unchanged.
    assert_eq!(visibility_at(&shadow_scene(""), 0.0), Vec3::ZERO);
    let glass = shadow_scene("transmission = 0.5\ntransmission_color = [1, 0.5, 0.25]");
    assert_close3(visibility_at(&glass, 0.0), 0.5 * mt, "kt·MT");
}

#[test]
fn a_masked_out_occluder_casts_no_shadow() {
    let hole = shadow_scene("alpha_mode = \"mask\"\nalpha = 0.3");
    assert_close3(centre(&hole).0, Vec3::ONE, "α = 0.3 < 0.5: no shadow");
    let solid = shadow_scene("alpha_mode = \"mask\"\nalpha = 0.7");
    assert_eq!(centre(&solid).0, Vec3::ZERO, "α = 0.7 ≥ 0.5: an opaque occluder");

    // The texture's alpha, read at level 0 (u = x/4 + ½): covered at x = −1.5 (u = 0.125),
    // a hole at x = 1.5 (u = 0.875).
    let leaf = shadow_scene("alpha_mode = \"mask\"\ntexture = \"textures/alpha-left-opaque.png\"\nwrap = \"clamp\"");
    assert_eq!(visibility_at(&leaf, -1.5), Vec3::ZERO);
    assert_eq!(visibility_at(&leaf, 1.5), Vec3::ONE);
}

// ---------------------------------------------------------------------------------------------
// glTF: alphaMode, alphaCutoff, baseColorFactor.a and the base colour texture's alpha.

fn alpha_gltf() -> GltfImport {
    import(&data("gltf/alpha.gltf")).unwrap_or_else(|e| panic!("{e}"))
}

fn gltf_material<'a>(import: &'a GltfImport, name: &str) -> &'a Material {
    import.materials.iter().find(|m| m.name == name).unwrap_or_else(|| panic!("no material `{name}`"))
}

#[test]
fn gltf_alpha_modes_and_factors_are_read() {
    let import = alpha_gltf();
    assert!(import.warnings.is_empty(), "{:?}", import.warnings);

    // OPAQUE keeps the factor's alpha, which the mode ignores.
    let opaque = gltf_material(&import, "opaque");
    assert_eq!((opaque.alpha, opaque.alpha_mode), (0.5, AlphaMode::Opaque));
    assert_close3(opaque.color, Vec3::new(0.8, 0.6, 0.4), "colour");
    assert!(!opaque.is_transparent());

    let leaf = gltf_material(&import, "leaf");
    assert_eq!((leaf.alpha, leaf.alpha_mode), (1.0, AlphaMode::Mask { cutoff: 0.3 }));
    assert_eq!(leaf.wrap, [Wrap::Clamp; 2]);
    let mask = gltf_material(&import, "mask-default-cutoff");
    assert_eq!((mask.alpha, mask.alpha_mode), (0.75, AlphaMode::Mask { cutoff: 0.5 }), "glTF's default cutoff");

    let veil = gltf_material(&import, "veil");
    assert_eq!((veil.alpha, veil.alpha_mode), (0.5, AlphaMode::Blend));
    assert!(veil.is_transparent());
}

#[test]
fn gltf_base_colour_textures_keep_their_alpha() {
    let import = alpha_gltf();
    let texels = |name: &str| {
        let id = gltf_material(&import, name).texture.unwrap_or_else(|| panic!("`{name}` has a texture"));
        import.textures[id.0].rgba8.clone()
    };
    assert_eq!(texels("leaf"), [255, 255, 255, 255, 255, 255, 255, 0]);
    assert_eq!(texels("veil"), [255, 255, 255, 128]);
}

#[test]
fn gltf_transmission_takes_its_share_from_the_diffuse_lobe() {
    let import = alpha_gltf();
    // Metallic 0: kd = (1 − m)·(1 − kt) = 0.4, MT = baseColorFactor.rgb, ior 1.5 by default.
    let glass = gltf_material(&import, "glass");
    assert_eq!((glass.transmission, glass.alpha_mode, glass.alpha, glass.ior), (0.6, AlphaMode::Opaque, 1.0, 1.5));
    assert!((glass.kd - 0.4).abs() < 1e-6, "kd = {}", glass.kd);
    assert_close3(glass.transmission_color, Vec3::new(0.9, 0.95, 1.0), "MT");
    assert!(glass.is_transparent());

    // BLEND and transmission together keep both; BLEND ignores alphaCutoff (0.9 in the file).
    let frosted = gltf_material(&import, "frosted-veil");
    assert_eq!((frosted.alpha_mode, frosted.alpha, frosted.transmission), (AlphaMode::Blend, 0.4, 0.5));
    assert!((frosted.kd - 0.5).abs() < 1e-6, "kd = {}", frosted.kd);
    assert_close3(frosted.transmission_color, Vec3::new(0.5, 1.0, 0.5), "MT");
}

#[test]
fn a_gltf_mask_is_traced_with_its_cutoff() {
    // The `leaf` quad spans x ∈ [2, 4] in y = 0 (u = (x − 2)/2), seen from above under ambient 1:
    // L = AG = kd·C = 1 where the surface is. Bilinear α = 1 − (u − ¼)/½ reaches the cutoff 0.3
    // at u = 0.6, x = 3.2.
    let scene = scene(
        r#"
        [camera]
        eye = [3, 4, 0]
        center = [3, 0, 0]
        up = [0, 0, -1]
        fovy = 30
        width = 41
        height = 41
        [world]
        ambient = [1, 1, 1]
        background = [0.2, 0.4, 0.6]
        [[objects]]
        type = "gltf"
        path = "gltf/alpha.gltf"
        "#,
    );
    let tracer = Tracer::new(&scene, &scene.settings);
    let (mut surface, mut holes) = (0, 0);
    for i in 0..41 {
        let p = Vec2::new(i as f32 + 0.5, 20.5);
        let ray = scene.camera.ray_through(p.x, p.y);
        let x = ray.at(-ray.origin.y / ray.direction.y).x;
        if !(2.0..4.0).contains(&x) {
            continue;
        }
        let got = tracer.primary(p, &mut RayCounts::default());
        if x < 3.15 {
            assert_close3(got, Vec3::ONE, &format!("pixel {i}, x = {x}: the leaf"));
            surface += 1;
        } else if x > 3.25 {
            assert_close3(got, BACKGROUND, &format!("pixel {i}, x = {x}: the hole"));
            holes += 1;
        }
    }
    assert!(surface >= 5 && holes >= 5, "{surface} leaf and {holes} hole pixels");
}
