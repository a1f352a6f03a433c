//! Scene files (`src/scene/file.rs`, `docs/scene-format.md`): bad files must fail with
//! `file:line:column: message` at the offending value or table and say what is wrong; good files
//! must load number by number, with the documented defaults filling in what they leave out.
//!
//! Inline scenes are written one line per array element (`lines(&[...])`), so an element's index
//! plus one is its line number; expected columns are counted by hand in the comments.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Vec2, Vec3};
use mirador::scene::file::parse;
use mirador::scene::{AlphaMode, Attenuation, ColorSpace, LightKind, Material, Projection, SceneError, Shape};
use mirador::{RenderSettings, Scene};

// ---------------------------------------------------------------------------------------------
// Helpers.

/// The scene text of `lines`, one element per line (line `i + 1` is `lines[i]`).
fn lines(lines: &[&str]) -> String {
    lines.join("\n") + "\n"
}

fn repo(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// A fresh path under the system's temporary folder, unique to this process and call.
fn temp_path(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("mirador-scene-files-{}-{n}-{name}", std::process::id()))
}

/// Parses `text` as `bad.toml`, which must fail; returns the message.
fn error_of(text: &str) -> String {
    match parse(text, Path::new("bad.toml")) {
        Ok(_) => panic!("this scene should not load:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// `text` must fail at `line:column` of `bad.toml` with a message that contains every word.
fn assert_error_at(text: &str, line: usize, column: usize, words: &[&str]) {
    let message = error_of(text);
    let place = format!("bad.toml:{line}:{column}: ");
    assert!(message.starts_with(&place), "expected the error at {place}got: {message}\nfor:\n{text}");
    for word in words {
        assert!(message.contains(word), "the message does not mention `{word}`: {message}\nfor:\n{text}");
    }
}

fn load_ok(text: &str) -> Scene {
    parse(text, Path::new("good.toml")).unwrap_or_else(|e| panic!("this scene should load: {e}\n{text}"))
}

fn assert_close3(actual: Vec3, expected: Vec3, what: &str) {
    assert!(actual.abs_diff_eq(expected, 1e-4), "{what}: {actual} ≠ {expected}");
}

/// A `[camera]` table that is valid on its own, taking lines 1 to 3.
const CAMERA: [&str; 3] = ["[camera]", "eye = [0, 0, 10]", "center = [0, 0, 0]"];

/// `CAMERA` followed by `more`, which therefore starts on line 4.
fn with_camera(more: &[&str]) -> String {
    let mut all = CAMERA.to_vec();
    all.extend_from_slice(more);
    lines(&all)
}

fn material<'a>(scene: &'a Scene, name: &str) -> &'a Material {
    scene.materials.iter().find(|m| m.name == name).unwrap_or_else(|| panic!("no material `{name}`"))
}

// ---------------------------------------------------------------------------------------------
// Files that cannot be read.

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let path = temp_path("does-not-exist.toml");
    let error = Scene::load(&path).expect_err("a missing file cannot load");
    assert!(matches!(error, SceneError::Io { .. }), "{error:?}");
    assert_eq!(error.path(), path);
    let message = error.to_string();
    assert!(message.starts_with(&format!("{}: cannot read the file", path.display())), "{message}");
}

#[test]
fn a_directory_is_not_a_scene_file() {
    let dir = temp_path("folder.toml");
    std::fs::create_dir_all(&dir).unwrap();
    let error = Scene::load(&dir).expect_err("a directory cannot load");
    std::fs::remove_dir(&dir).unwrap();
    assert!(matches!(error, SceneError::Io { .. }), "{error:?}");
    let message = error.to_string();
    assert!(message.starts_with(&format!("{}: cannot read the file", dir.display())), "{message}");
}

#[test]
fn a_pipe_or_device_named_by_a_file_is_refused_without_reading_it() {
    // Opening a FIFO for reading waits for a writer, and `/dev/zero` never ends: a file naming one
    // as a model, a glTF buffer, an MTL library, a texture or a volume would hang or fill memory.
    let dir = temp_path("pipes");
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().expect("mkfifo runs");
    assert!(made.success(), "mkfifo {}", fifo.display());
    let fifo_name = fifo.display().to_string();
    let gltf = format!(r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":4,"uri":"{fifo_name}"}}]}}"#);
    std::fs::write(dir.join("model.gltf"), gltf).unwrap();
    std::fs::write(dir.join("model.obj"), format!("mtllib {fifo_name}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")).unwrap();
    let scenes = [
        "[[objects]]\ntype = \"gltf\"\npath = \"model.gltf\"\n".to_string(),
        "[[objects]]\ntype = \"obj\"\npath = \"model.obj\"\n".to_string(),
        format!("[[objects]]\ntype = \"ply\"\npath = \"{fifo_name}\"\n"),
        format!("[materials.a]\ntexture = \"{fifo_name}\"\n"),
        format!("[world.environment]\nlatlong = \"{fifo_name}\"\n"),
        format!("[[volumes]]\npath = \"{fifo_name}\"\n"),
        format!("[[volumes]]\nraw = {{ path = \"{fifo_name}\", dims = [2, 2, 2], type = \"uint8\" }}\n"),
    ];
    for text in scenes {
        let scene = dir.join("scene.toml");
        let (done, finished) = std::sync::mpsc::channel();
        let shown = text.clone();
        std::thread::spawn(move || done.send(parse(&text, &scene).map(|_| ()).map_err(|e| e.to_string())));
        let result = finished
            .recv_timeout(std::time::Duration::from_secs(20))
            .unwrap_or_else(|_| panic!("still reading the pipe after 20 s:\n{shown}"));
        let message = result.expect_err("a pipe is not a file to read");
        assert!(message.contains("not a regular file"), "{shown}\n{message}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_missing_gltf_file_is_an_io_error_naming_it() {
    let path = temp_path("does-not-exist.glb");
    let error = Scene::load(&path).expect_err("a missing model cannot load");
    assert!(matches!(error, SceneError::Io { .. }), "{error:?}");
    assert!(error.to_string().starts_with(&format!("{}: cannot read the file", path.display())), "{error}");
}

// ---------------------------------------------------------------------------------------------
// TOML syntax.

#[test]
fn an_unterminated_string_is_a_syntax_error_at_the_end_of_the_line() {
    // `name = "lamp` is 12 characters; the closing quote was expected in column 13.
    let text = lines(&["[[lights]]", "name = \"lamp", "type = \"point\""]);
    assert_error_at(&text, 2, 13, &["string", "expected `\"`"]);
}

#[test]
fn an_unterminated_table_header_is_a_syntax_error() {
    // `[camera` is 7 characters; the `]` was expected in column 8.
    let text = lines(&["[camera", "eye = [0, 0, 10]"]);
    assert_error_at(&text, 1, 8, &["unclosed table", "`]`"]);
}

// ---------------------------------------------------------------------------------------------
// Unknown names.

#[test]
fn an_unknown_top_level_table_is_rejected_at_its_name() {
    // `[sky]`: the name starts in column 2.
    let text = with_camera(&["[sky]", "color = [1, 1, 1]"]);
    assert_error_at(&text, 4, 2, &["unknown field `sky`", "`world`", "`objects`"]);
}

#[test]
fn an_unknown_camera_field_is_rejected_at_its_key() {
    let text = with_camera(&["fov = 45"]);
    assert_error_at(&text, 4, 1, &["unknown field `fov`", "`fovy`"]);
}

#[test]
fn an_unknown_world_field_is_rejected_at_its_key() {
    let text = with_camera(&["[world]", "ambient = [0.1, 0.1, 0.1]", "sky = [0, 0, 1]"]);
    assert_error_at(&text, 6, 1, &["unknown field `sky`", "`background`"]);
}

#[test]
fn an_unknown_material_field_is_rejected_at_its_key() {
    let text = with_camera(&["[materials.red]", "colour = [1, 0, 0]"]);
    assert_error_at(&text, 5, 1, &["unknown field `colour`", "`color`"]);
}

#[test]
fn an_unknown_light_field_is_rejected_at_its_key() {
    let text = with_camera(&["[[lights]]", "type = \"point\"", "position = [0, 5, 0]", "power = 2"]);
    assert_error_at(&text, 7, 1, &["unknown field `power`", "`intensity`"]);
}

#[test]
fn an_unknown_light_type_is_rejected_at_its_value() {
    // `type = "area"`: the value starts in column 8.
    let text = with_camera(&["[[lights]]", "type = \"area\""]);
    assert_error_at(&text, 5, 8, &["unknown variant `area`", "`point`", "`directional`", "`spot`"]);
}

#[test]
fn an_unknown_object_field_is_rejected_at_its_key() {
    let text = with_camera(&["[[objects]]", "type = \"sphere\"", "radius = 1", "colour = [1, 0, 0]"]);
    assert_error_at(&text, 7, 1, &["unknown field `colour`", "`material`"]);
}

#[test]
fn an_unknown_object_type_is_rejected_at_its_value() {
    let text = with_camera(&["[[objects]]", "type = \"cone\""]);
    assert_error_at(&text, 5, 8, &["unknown variant `cone`", "`sphere`", "`rounded_box`", "`gltf`"]);
}

#[test]
fn an_object_without_a_type_is_rejected_at_its_table() {
    let text = with_camera(&["[[objects]]", "radius = 1"]);
    assert_error_at(&text, 4, 1, &["missing field `type`"]);
}

#[test]
fn an_unknown_settings_key_is_rejected_at_its_key() {
    // `terms.glow = true`: `glow` starts in column 7.
    let text = with_camera(&["[settings]", "terms.glow = true"]);
    assert_error_at(&text, 5, 7, &["unknown field `glow`", "`specular`"]);
    let text = with_camera(&["[settings]", "brightness = 2"]);
    assert_error_at(&text, 5, 1, &["unknown field `brightness`", "`exposure`"]);
}

#[test]
fn a_settings_value_out_of_range_is_rejected_at_the_settings_table() {
    let text = with_camera(&["[settings]", "exposure = -1"]);
    assert_error_at(&text, 4, 1, &["[settings]", "exposure must be positive", "-1"]);
    let text = with_camera(&["[settings]", "sphere_segments = 2"]);
    assert_error_at(&text, 4, 1, &["sphere_segments", "3..=4096", "2"]);
}

#[test]
fn a_settings_error_is_not_placed_at_a_comment() {
    let text = lines(&["# exposure lives in [settings]", "", "[settings]", "exposure = -1"]);
    // The table header is line 3; the loader says 1:21, the comment.
    assert_error_at(&text, 3, 1, &["exposure must be positive"]);
}

#[test]
fn a_settings_error_in_an_inline_table_has_a_place() {
    // `settings = { exposure = -1 }`: the table starts in column 12. The loader gives `bad.toml: …`.
    let text = lines(&["settings = { exposure = -1 }"]);
    let message = error_of(&text);
    assert!(message.starts_with("bad.toml:1:"), "{message}");
}

#[test]
fn a_camera_without_eye_is_rejected_at_its_table() {
    let text = lines(&["# no eye", "[camera]", "center = [0, 0, 0]"]);
    assert_error_at(&text, 2, 1, &["missing field `eye`"]);
}

// ---------------------------------------------------------------------------------------------
// Bad numbers, reported at the value.

#[test]
fn nan_and_infinity_in_a_vector_are_rejected_at_the_vector() {
    // `eye = [nan, 0, 0]`: the array starts in column 7.
    let text = lines(&["[camera]", "eye = [nan, 0, 0]", "center = [0, 0, 0]"]);
    assert_error_at(&text, 2, 7, &["finite", "NaN"]);
    let text = lines(&["[camera]", "eye = [1, 2, 3]", "center = [0, -inf, 0]"]);
    assert_error_at(&text, 3, 10, &["finite", "-inf"]);
}

#[test]
fn nan_as_a_single_number_is_rejected_at_the_value() {
    // `fovy = nan`: the value starts in column 8.
    let text = with_camera(&["fovy = nan"]);
    assert_error_at(&text, 4, 8, &["expected a finite number", "NaN"]);
}

#[test]
fn a_number_too_large_for_f32_is_rejected() {
    // 1e39 is a finite f64 but overflows f32.
    let text = with_camera(&["far = 1e39"]);
    assert_error_at(&text, 4, 7, &["too large for a 32-bit float"]);
    let text = with_camera(&["up = [0, 1e39, 0]"]);
    assert_error_at(&text, 4, 6, &["finite"]);
}

#[test]
fn a_negative_colour_is_rejected_at_the_value() {
    // `color = [0.5, -0.1, 0]`: the array starts in column 9.
    let text = with_camera(&["[materials.red]", "color = [0.5, -0.1, 0]"]);
    assert_error_at(&text, 5, 9, &["colour components must be ≥ 0", "-0.1"]);
    let text = with_camera(&["[world]", "background = [0, 0, -1]"]);
    assert_error_at(&text, 5, 14, &["colour components must be ≥ 0"]);
}

#[test]
fn a_negative_coefficient_is_rejected_at_the_value() {
    let text = with_camera(&["[materials.red]", "kd = -0.5"]);
    assert_error_at(&text, 5, 6, &["expected a number ≥ 0", "-0.5"]);
    let text = with_camera(&["[[lights]]", "type = \"point\"", "position = [0, 1, 0]", "intensity = -2"]);
    assert_error_at(&text, 7, 13, &["expected a number ≥ 0", "-2"]);
}

#[test]
fn a_negative_transmission_or_emission_colour_is_rejected_at_the_value() {
    // `transmission_color = [0, -1, 0]`: the array starts in column 22.
    let text = with_camera(&["[materials.glass]", "transmission = 0.5", "transmission_color = [0, -1, 0]"]);
    assert_error_at(&text, 6, 22, &["colour components must be ≥ 0", "[0, -1, 0]"]);
    let text = with_camera(&["[materials.lamp]", "emission = [-2, 0, 0]"]);
    assert_error_at(&text, 5, 12, &["colour components must be ≥ 0"]);
}

#[test]
fn fractions_outside_0_to_1_are_rejected_at_the_value() {
    // kt and kps are the fractions of light transmitted and mirrored.
    let text = with_camera(&["[materials.glass]", "transmission = 1.5"]);
    assert_error_at(&text, 5, 16, &["expected a number in [0, 1]", "got 1.5"]);
    let text = with_camera(&["[materials.glass]", "transmission = -0.25"]);
    assert_error_at(&text, 5, 16, &["expected a number in [0, 1]", "got -0.25"]);
    let text = with_camera(&["[materials.chrome]", "mirror = 2"]);
    assert_error_at(&text, 5, 10, &["expected a number in [0, 1]", "got 2"]);
    let text = with_camera(&["[materials.leaf]", "alpha = 1.2"]);
    assert_error_at(&text, 5, 9, &["expected a number in [0, 1]", "got 1.2"]);
    let text = with_camera(&["[materials.leaf]", "alpha_mode = \"mask\"", "alpha_cutoff = -0.5"]);
    assert_error_at(&text, 6, 16, &["expected a number in [0, 1]", "got -0.5"]);
    let text = with_camera(&["[materials.leaf]", "alpha = nan"]);
    assert_error_at(&text, 5, 9, &["expected a finite number", "NaN"]);
    let text = with_camera(&["[materials.leaf]", "alpha_mode = \"mask\"", "alpha_cutoff = inf"]);
    assert_error_at(&text, 6, 16, &["expected a finite number", "inf"]);
}

#[test]
fn an_unknown_alpha_mode_is_rejected_at_the_value() {
    // `alpha_mode = "glass"`: the value starts in column 14.
    let text = with_camera(&["[materials.leaf]", "alpha_mode = \"glass\""]);
    assert_error_at(&text, 5, 14, &["unknown variant `glass`", "`opaque`", "`mask`", "`blend`"]);
}

#[test]
fn an_alpha_cutoff_without_mask_mode_is_rejected_at_the_value() {
    let text = with_camera(&["[materials.leaf]", "alpha_mode = \"blend\"", "alpha_cutoff = 0.3"]);
    assert_error_at(&text, 6, 16, &["`alpha_cutoff` applies only to alpha_mode = \"mask\"", "\"blend\""]);
    // Without `alpha_mode` the material is opaque.
    let text = with_camera(&["[materials.leaf]", "alpha = 0.5", "alpha_cutoff = 0.3"]);
    assert_error_at(&text, 6, 16, &["`alpha_cutoff` applies only", "\"opaque\""]);
}

#[test]
fn an_index_of_refraction_of_zero_is_rejected() {
    let text = with_camera(&["[materials.glass]", "ior = 0"]);
    assert_error_at(&text, 5, 7, &["expected a number > 0", "0"]);
}

#[test]
fn a_radius_of_zero_or_less_is_rejected_at_the_value() {
    // `radius = 0`: the value starts in column 10.
    let text = with_camera(&["[[objects]]", "type = \"sphere\"", "radius = 0"]);
    assert_error_at(&text, 6, 10, &["expected a number > 0", "got 0"]);
    let text = with_camera(&["[[objects]]", "type = \"sphere\"", "radius = -2.5"]);
    assert_error_at(&text, 6, 10, &["expected a number > 0", "got -2.5"]);
}

#[test]
fn a_scale_of_zero_is_rejected_at_the_value() {
    // `scale = 0`: the value starts in column 9.
    let text = with_camera(&["[[objects]]", "type = \"sphere\"", "scale = 0"]);
    assert_error_at(&text, 6, 9, &["scale of zero", "[0, 0, 0]"]);
    let text = with_camera(&["[[objects]]", "type = \"sphere\"", "scale = [1, 0, 1]"]);
    assert_error_at(&text, 6, 9, &["scale of zero", "[1, 0, 1]"]);
}

#[test]
fn a_plane_size_must_be_positive() {
    let text = with_camera(&["[[objects]]", "type = \"plane\"", "size = [4, 0]"]);
    assert_error_at(&text, 6, 8, &["two finite numbers > 0", "[4, 0]"]);
}

// ---------------------------------------------------------------------------------------------
// Wrong types.

#[test]
fn a_string_where_a_number_is_expected_is_rejected_at_the_value() {
    // `fovy = "wide"`: the value starts in column 8.
    let text = with_camera(&["fovy = \"wide\""]);
    assert_error_at(&text, 4, 8, &["invalid type", "string \"wide\"", "f64"]);
    let text = with_camera(&["[[objects]]", "type = \"sphere\"", "scale = \"big\""]);
    assert_error_at(&text, 6, 9, &["invalid type", "a number or an array of three numbers"]);
}

#[test]
fn two_numbers_where_three_are_needed_are_rejected_at_the_array() {
    // `center = [0, 0]`: the array starts in column 10.
    let text = lines(&["[camera]", "eye = [0, 0, 10]", "center = [0, 0]"]);
    assert_error_at(&text, 3, 10, &["invalid length 2", "length 3"]);
}

#[test]
fn a_negative_or_oversized_width_is_not_a_u32() {
    let text = with_camera(&["width = -1"]);
    assert_error_at(&text, 4, 9, &["-1", "u32"]);
    let text = with_camera(&["width = 4294967296"]);
    assert_error_at(&text, 4, 9, &["4294967296", "u32"]);
}

#[test]
fn objects_must_be_an_array_of_tables() {
    let text = with_camera(&["[objects]", "type = \"sphere\""]);
    assert_error_at(&text, 4, 1, &["invalid type", "sequence"]);
}

// ---------------------------------------------------------------------------------------------
// The camera, checked as a whole at its table.

/// A camera table starting on line 2 (line 1 is a comment, so the table's line is not 1).
fn camera_with(fields: &[&str]) -> String {
    let mut all = vec!["# the camera", "[camera]"];
    all.extend_from_slice(fields);
    lines(&all)
}

#[test]
fn eye_at_center_is_rejected_at_the_camera_table() {
    let text = camera_with(&["eye = [1, 2, 3]", "center = [1, 2, 3]"]);
    assert_error_at(&text, 2, 1, &["[camera]", "eye and center are the same point"]);
}

#[test]
fn up_parallel_to_the_view_is_rejected() {
    let text = camera_with(&["eye = [0, 10, 0]", "center = [0, 0, 0]", "up = [0, 1, 0]"]);
    assert_error_at(&text, 2, 1, &["[camera]", "up is parallel to the view direction"]);
    let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "up = [0, 0, -3]"]);
    assert_error_at(&text, 2, 1, &["up is parallel"]);
}

#[test]
fn fovy_must_lie_strictly_between_0_and_180() {
    for fovy in ["0", "180", "-10"] {
        let line = format!("fovy = {fovy}");
        let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", &line]);
        assert_error_at(&text, 2, 1, &["fovy must lie strictly between 0 and 180", &format!("got {fovy}")]);
    }
    let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "fovy = 179.5"]);
    assert_eq!(load_ok(&text).camera.fovy_degrees, 179.5);
}

#[test]
fn near_must_be_positive_and_below_far() {
    let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "near = 50", "far = 50"]);
    assert_error_at(&text, 2, 1, &["0 < near < far", "near = 50, far = 50"]);
    let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "near = 60", "far = 50"]);
    assert_error_at(&text, 2, 1, &["0 < near < far", "near = 60, far = 50"]);
    let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "near = 0"]);
    assert_error_at(&text, 2, 1, &["0 < near < far", "near = 0, far = 1000"]);
}

#[test]
fn the_image_must_have_pixels_and_fit_a_texture() {
    let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "width = 0"]);
    assert_error_at(&text, 2, 1, &["at least one pixel", "0×720"]);
    let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "width = 20000"]);
    assert_error_at(&text, 2, 1, &["at most 16384×16384", "20000×720"]);
    let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "width = 16384", "height = 16384"]);
    assert_eq!((load_ok(&text).camera.width, load_ok(&text).camera.height), (16384, 16384));
}

#[test]
fn an_orthographic_camera_needs_a_positive_height() {
    let text =
        camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "projection = \"orthographic\"", "ortho_height = 0"]);
    assert_error_at(&text, 2, 1, &["ortho_height must be positive"]);
    let text = camera_with(&["eye = [0, 0, 10]", "center = [0, 0, 0]", "projection = \"fisheye\""]);
    assert_error_at(&text, 5, 14, &["unknown variant `fisheye`", "`orthographic`"]);
}

// ---------------------------------------------------------------------------------------------
// Objects, checked as a whole at their table.

#[test]
fn a_box_needs_min_below_max_on_every_axis() {
    // A valid sphere first, so the box's table is on line 7, not 4.
    let text = with_camera(&[
        "[[objects]]",
        "type = \"sphere\"",
        "",
        "[[objects]]",
        "type = \"box\"",
        "min = [0, 0, 0]",
        "max = [1, 0, 1]",
    ]);
    assert_error_at(&text, 7, 1, &["a box needs min < max on every axis", "min = [0, 0, 0]", "max = [1, 0, 1]"]);
    let text = with_camera(&["[[objects]]", "type = \"box\"", "min = [0, 0, 0]"]);
    assert_error_at(&text, 4, 1, &["a box needs `min` and `max`"]);
}

#[test]
fn a_torus_needs_minor_below_major() {
    let text = with_camera(&["[[objects]]", "type = \"torus\"", "major_radius = 1", "minor_radius = 1.5"]);
    assert_error_at(&text, 4, 1, &["minor_radius < major_radius", "1.5 and 1"]);
    // The default minor radius (0.25) is too thick for a major radius of 0.2.
    let text = with_camera(&["[[objects]]", "type = \"torus\"", "major_radius = 0.2"]);
    assert_error_at(&text, 4, 1, &["minor_radius < major_radius", "0.25 and 0.2"]);
}

#[test]
fn a_rounded_box_needs_non_negative_half_extents() {
    let text = with_camera(&["[[objects]]", "type = \"rounded_box\"", "half_extents = [1, -1, 1]"]);
    assert_error_at(&text, 4, 1, &["half_extents must be ≥ 0"]);
}

#[test]
fn a_field_that_does_not_apply_to_the_type_is_rejected() {
    let text = with_camera(&["[[objects]]", "type = \"box\"", "min = [0, 0, 0]", "max = [1, 1, 1]", "radius = 2"]);
    assert_error_at(&text, 4, 1, &["`radius` does not apply to a box"]);
    let text = with_camera(&["[[objects]]", "type = \"sphere\"", "size = [1, 1]"]);
    assert_error_at(&text, 4, 1, &["`size` does not apply to a sphere"]);
    let text = with_camera(&["[[objects]]", "type = \"gltf\"", "path = \"m.glb\"", "radius = 1"]);
    assert_error_at(&text, 4, 1, &["`radius` does not apply to a gltf"]);
    let text = with_camera(&["[[objects]]", "type = \"rounded_box\"", "center = [0, 0, 0]"]);
    assert_error_at(&text, 4, 1, &["`center` does not apply to a rounded_box"]);
}

#[test]
fn an_unknown_material_name_is_reported_at_the_value_with_the_known_names() {
    let text = with_camera(&[
        "[materials.red]",
        "color = [1, 0, 0]",
        "[materials.blue]",
        "color = [0, 0, 1]",
        "",
        "[[objects]]",
        "type = \"sphere\"",
        "material = \"green\"",
    ]);
    // `material = "green"`: the value starts in column 12.
    let message = error_of(&text);
    assert!(message.starts_with("bad.toml:11:12: no material named `green`"), "{message}");
    let known = message.split("(known: ").nth(1).expect("the message lists the known names");
    let mut known: Vec<&str> = known.trim_end_matches(')').split(", ").collect();
    known.sort();
    assert_eq!(known, ["blue", "red"]);
}

#[test]
fn a_gltf_object_needs_a_path() {
    let text = with_camera(&["[[objects]]", "type = \"gltf\""]);
    assert_error_at(&text, 4, 1, &["a gltf object needs a `path`"]);
}

#[test]
fn a_gltf_object_whose_file_is_missing_names_that_file() {
    let text = with_camera(&["[[objects]]", "type = \"gltf\"", "path = \"models/nothere.gltf\""]);
    let error = parse(&text, Path::new("scenes/bad.toml")).expect_err("the model is missing");
    // Reported at the object that includes the model, naming the model's path relative to the scene.
    assert!(error.to_string().starts_with("scenes/bad.toml:4:1: "), "{error}");
    assert!(error.to_string().contains("scenes/models/nothere.gltf: cannot read the file"), "{error}");
}

#[test]
fn a_gltf_object_whose_file_is_missing_is_placed_in_the_scene_file() {
    // A texture error says `bad.toml:4:1: nothere.png: texture: …`; a glTF one only `nothere.gltf: …`.
    let text = with_camera(&["[[objects]]", "type = \"gltf\"", "path = \"nothere.gltf\""]);
    assert_error_at(&text, 4, 1, &["nothere.gltf", "cannot read"]);
}

#[test]
fn a_malformed_gltf_object_is_a_gltf_error_naming_the_model() {
    let text = with_camera(&["[[objects]]", "type = \"gltf\"", "path = \"malformed.gltf\""]);
    let error = parse(&text, &repo("tests/data/gltf/scene.toml")).expect_err("the model is malformed");
    assert!(error.to_string().contains("scene.toml:4:1: "), "{error}");
    assert!(error.to_string().contains("malformed.gltf: glTF: "), "{error}");
}

// ---------------------------------------------------------------------------------------------
// Lights.

#[test]
fn a_directional_light_needs_a_non_zero_direction() {
    // A valid light first, so the bad one's table is on line 7.
    let point = ["[[lights]]", "type = \"point\"", "position = [0, 5, 0]"];
    let text = with_camera(&[&point[..], &["[[lights]]", "type = \"directional\""]].concat());
    assert_error_at(&text, 7, 1, &["a directional light needs a `direction`"]);
    let text = with_camera(&[&point[..], &["[[lights]]", "type = \"directional\"", "direction = [0, 0, 0]"]].concat());
    assert_error_at(&text, 7, 1, &["direction is the zero vector"]);
}

#[test]
fn point_and_spot_lights_need_a_position() {
    let text = with_camera(&["[[lights]]", "type = \"point\""]);
    assert_error_at(&text, 4, 1, &["a point light needs a `position`"]);
    let text = with_camera(&["[[lights]]", "type = \"spot\"", "direction = [0, -1, 0]"]);
    assert_error_at(&text, 4, 1, &["a spot light needs a `position`"]);
}

#[test]
fn a_light_field_that_does_not_apply_is_rejected() {
    let text = with_camera(&["[[lights]]", "type = \"point\"", "position = [0, 5, 0]", "direction = [0, -1, 0]"]);
    assert_error_at(&text, 4, 1, &["`direction` does not apply to a point light"]);
    let text = with_camera(&["[[lights]]", "type = \"directional\"", "direction = [0, -1, 0]", "position = [0, 5, 0]"]);
    assert_error_at(&text, 4, 1, &["`position` does not apply to a directional light"]);
    let text = with_camera(&[
        "[[lights]]",
        "type = \"directional\"",
        "direction = [0, -1, 0]",
        "attenuation = \"inverse_square\"",
    ]);
    assert_error_at(&text, 4, 1, &["`attenuation` does not apply to a directional light"]);
    let text = with_camera(&["[[lights]]", "type = \"point\"", "position = [0, 5, 0]", "outer_angle = 10"]);
    assert_error_at(&text, 4, 1, &["`inner_angle/outer_angle` does not apply to a point light"]);
}

#[test]
fn a_spot_light_needs_inner_at_most_outer_below_180() {
    let spot = ["[[lights]]", "type = \"spot\"", "position = [0, 5, 0]", "direction = [0, -1, 0]"];
    let text = with_camera(&[&spot[..], &["inner_angle = 40", "outer_angle = 30"]].concat());
    assert_error_at(&text, 4, 1, &["inner ≤ outer < 180°", "inner = 40, outer = 30"]);
    // Only inner given: the default outer angle (30°) is smaller.
    let text = with_camera(&[&spot[..], &["inner_angle = 35"]].concat());
    assert_error_at(&text, 4, 1, &["inner ≤ outer < 180°", "inner = 35, outer = 30"]);
    let text = with_camera(&[&spot[..], &["outer_angle = 180"]].concat());
    assert_error_at(&text, 4, 1, &["inner ≤ outer < 180°", "outer = 180"]);
}

#[test]
fn an_unknown_attenuation_is_rejected_at_the_value() {
    let text = with_camera(&["[[lights]]", "type = \"point\"", "position = [0, 5, 0]", "attenuation = \"linear\""]);
    assert_error_at(&text, 7, 15, &["unknown variant `linear`", "`none`", "`inverse_square`"]);
}

// ---------------------------------------------------------------------------------------------
// Textures.

#[test]
fn a_missing_texture_names_the_texture_file_at_the_material_table() {
    let text = with_camera(&["[materials.floor]", "texture = \"textures/nothere.png\""]);
    let message = error_of(&text);
    assert!(message.starts_with("bad.toml:4:1: textures/nothere.png: texture: cannot open"), "{message}");
    let text = with_camera(&["[materials.floor]", "height_map = \"bumps.png\""]);
    assert_error_at(&text, 4, 1, &["bumps.png: texture: cannot open"]);
}

#[test]
fn a_texture_that_is_not_an_image_cannot_be_decoded() {
    let image = temp_path("garbage.png");
    std::fs::write(&image, b"this is not a PNG file, only some text with a .png name").unwrap();
    let scene = image.with_file_name(format!("{}.toml", image.file_name().unwrap().to_string_lossy()));
    let name = image.file_name().unwrap().to_str().unwrap();
    std::fs::write(&scene, lines(&["[materials.floor]", &format!("texture = \"{name}\"")])).unwrap();
    let result = Scene::load(&scene);
    std::fs::remove_file(&image).unwrap();
    std::fs::remove_file(&scene).unwrap();
    let message = result.expect_err("the texture is garbage").to_string();
    let expected = format!("{}:1:1: {}: texture: cannot decode", scene.display(), image.display());
    assert!(message.starts_with(&expected), "expected `{expected}…`, got: {message}");
}

#[test]
fn textures_are_read_relative_to_the_scene_file_colour_as_srgb_and_height_as_linear() {
    // The file need not exist: `parse` only uses its folder, here assets/scenes/.
    let text = lines(&[
        "[materials.a]",
        "texture = \"../textures/checker.png\"",
        "height_map = \"../textures/cobbles-height.png\"",
        "[materials.b]",
        "texture = \"../textures/checker.png\"",
        "[materials.c]",
        "height_map = \"../textures/checker.png\"",
    ]);
    let scene = parse(&text, &repo("assets/scenes/inline.toml")).unwrap_or_else(|e| panic!("{e}"));
    let (a, b, c) = (material(&scene, "a"), material(&scene, "b"), material(&scene, "c"));
    let texture = |id: Option<mirador::base::TextureId>| &scene.textures[id.expect("a texture").0];
    assert!(texture(a.texture).path.ends_with("textures/checker.png"));
    assert_eq!(texture(a.texture).color_space, ColorSpace::Srgb);
    assert!(texture(a.height_map).path.ends_with("textures/cobbles-height.png"));
    assert_eq!(texture(a.height_map).color_space, ColorSpace::Linear);
    // One file read as colour twice is one texture; read as data it is another.
    assert_eq!(a.texture, b.texture);
    assert_ne!(c.height_map, a.texture);
    assert_eq!(texture(c.height_map).color_space, ColorSpace::Linear);
    assert_eq!(scene.textures.len(), 3);
    assert!(texture(a.texture).width > 0 && texture(a.texture).height > 0);
}

// ---------------------------------------------------------------------------------------------
// Valid scenes.

#[test]
fn seed_simple_loads_with_the_numbers_of_seed_004() {
    let scene = Scene::load(&repo("assets/scenes/seed-simple.toml")).unwrap_or_else(|e| panic!("{e}"));
    let c = &scene.camera;
    assert_eq!((c.eye, c.center, c.up), (Vec3::new(100.0, 40.0, 40.0), Vec3::ZERO, Vec3::Y));
    assert_eq!((c.fovy_degrees, c.near, c.far), (90.0, 30.0, 230.0));
    assert_eq!((c.width, c.height, c.projection), (230, 230, Projection::Perspective));
    assert_eq!(scene.ambient, Vec3::splat(0.2));
    assert_eq!(scene.background, Vec3::ZERO);
    assert_eq!(scene.settings, RenderSettings::default());

    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["sphere", "floor", "wall"]);
    let sphere = &scene.objects[0];
    assert_eq!(sphere.shape, Shape::Sphere { center: Vec3::new(0.0, 20.0, 0.0), radius: 25.0 });
    assert_eq!(sphere.world_from_local, glam::Mat4::IDENTITY);
    let blue = &scene.materials[sphere.material.0];
    assert_eq!((blue.name.as_str(), blue.color), ("blue", Vec3::new(0.0, 0.0, 1.0)));
    assert_eq!((blue.ka, blue.kd, blue.ks), (0.0, 1.0, 0.0), "the slide's surfaces are purely diffuse");
    assert_eq!(
        scene.objects[1].shape,
        Shape::Cuboid { min: Vec3::new(-80.0, -50.0, -50.0), max: Vec3::new(50.0, -45.0, 50.0) }
    );
    assert_eq!(scene.materials[scene.objects[2].material.0].color, Vec3::new(0.7, 0.7, 0.0));

    assert_eq!(scene.lights.len(), 1);
    let lamp = &scene.lights[0];
    assert_eq!(lamp.name, "lamp");
    assert_eq!(lamp.kind, LightKind::Point { position: Vec3::new(60.0, 120.0, 40.0) });
    assert_eq!((lamp.color, lamp.intensity, lamp.attenuation), (Vec3::splat(0.8), 1.0, Attenuation::None));
}

#[test]
fn the_showcase_loads_with_its_textures_lights_and_placed_mirror() {
    let scene = Scene::showcase().unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.source.as_deref(), Some(repo("assets/scenes/showcase.toml").as_path()));
    let c = &scene.camera;
    assert_eq!((c.eye, c.center), (Vec3::new(4.2, 1.8, 7.0), Vec3::new(-0.3, 0.7, 0.0)));
    assert_eq!((c.fovy_degrees, c.near, c.far, c.width, c.height), (50.0, 0.1, 400.0, 1280, 720));
    // The world is a sky: what rays that hit nothing see, straight up, is its zenith.
    let sky = scene.environment.as_ref().expect("the showcase's sky");
    assert!(matches!(sky.source, mirador::scene::EnvironmentSource::Sky(_)));
    assert!(scene.environment_radiance(Vec3::Y).abs_diff_eq(Vec3::new(0.3, 0.48, 0.8), 1e-6));
    assert_eq!(scene.objects.len(), 6);
    assert_eq!(scene.materials.len(), 6);

    let floor = material(&scene, "floor");
    assert_eq!(scene.textures[floor.texture.unwrap().0].color_space, ColorSpace::Srgb);
    let cobbles = material(&scene, "cobbles");
    assert_eq!(scene.textures[cobbles.height_map.unwrap().0].color_space, ColorSpace::Linear);
    let glass = material(&scene, "glass");
    assert_eq!((glass.transmission, glass.ior), (0.9, 1.5));

    assert_eq!(scene.lights.len(), 2);
    assert_eq!(scene.lights[0].kind, LightKind::Point { position: Vec3::new(4.5, 4.0, -1.0) });
    assert_eq!(scene.lights[0].intensity, 0.75);
    let LightKind::Directional { direction } = scene.lights[1].kind else { panic!("{:?}", scene.lights[1]) };
    assert_close3(direction, Vec3::new(0.45, -1.0, 0.3).normalize(), "sky light direction, normalized");

    // rotate = [0, 0, -90] turns the plane's +y normal to +x, facing into the room.
    let mirror = scene.objects.iter().find(|o| o.name == "mirror").unwrap();
    assert_eq!(mirror.shape, Shape::Plane { size: Vec2::new(3.2, 2.0), uv_scale: Vec2::ONE });
    assert_close3(mirror.world_from_local.transform_vector3(Vec3::Y), Vec3::X, "mirror normal");
    assert_close3(mirror.world_from_local.transform_point3(Vec3::ZERO), Vec3::new(-3.98, 1.3, -1.0), "mirror centre");
}

#[test]
fn omitted_fields_take_their_defaults() {
    let scene = load_ok(&with_camera(&["[[objects]]", "type = \"sphere\""]));
    let c = &scene.camera;
    assert_eq!((c.eye, c.center, c.up), (Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y));
    assert_eq!((c.fovy_degrees, c.near, c.far), (60.0, 0.1, 1000.0));
    assert_eq!((c.width, c.height), (1280, 720));
    assert_eq!((c.projection, c.ortho_height), (Projection::Perspective, 10.0));
    assert_eq!(scene.ambient, Vec3::splat(0.1));
    assert_eq!(scene.background, Vec3::ZERO);
    assert_eq!(scene.settings, RenderSettings::default());
    assert!(scene.lights.is_empty());

    let sphere = &scene.objects[0];
    assert_eq!(sphere.name, "sphere 0");
    assert_eq!(sphere.shape, Shape::Sphere { center: Vec3::ZERO, radius: 1.0 });
    assert_eq!(sphere.world_from_local, glam::Mat4::IDENTITY);
    assert_eq!(scene.materials.len(), 1);
    let m = &scene.materials[sphere.material.0];
    assert_eq!(*m, Material::default());
    assert_eq!((m.name.as_str(), m.color, m.kd, m.ks, m.shininess), ("default", Vec3::splat(0.8), 1.0, 0.0, 32.0));
}

#[test]
fn shape_defaults_fill_in() {
    let scene = load_ok(&with_camera(&[
        "[[objects]]",
        "type = \"plane\"",
        "[[objects]]",
        "type = \"torus\"",
        "[[objects]]",
        "type = \"rounded_box\"",
    ]));
    let shapes: Vec<&Shape> = scene.objects.iter().map(|o| &o.shape).collect();
    assert_eq!(
        shapes,
        [
            &Shape::Plane { size: Vec2::ONE, uv_scale: Vec2::ONE },
            &Shape::Torus { major: 1.0, minor: 0.25 },
            &Shape::RoundedBox { half: Vec3::splat(0.5), radius: 0.1 },
        ]
    );
    // All three share the one default material.
    assert!(scene.objects.iter().all(|o| o.material == scene.objects[0].material));
    assert_eq!(scene.materials.len(), 1);
}

#[test]
fn material_and_light_defaults_fill_in() {
    let scene = load_ok(&with_camera(&[
        "[materials.shiny]",
        "ks = 0.5",
        "[[lights]]",
        "type = \"spot\"",
        "position = [0, 5, 0]",
        "direction = [0, -2, 0]",
        "[[lights]]",
        "type = \"point\"",
        "position = [1, 2, 3]",
        "attenuation = \"inverse_square\"",
    ]));
    let shiny = material(&scene, "shiny");
    assert_eq!(*shiny, Material { name: "shiny".into(), ks: 0.5, ..Material::default() });
    let spot = &scene.lights[0];
    assert_eq!(spot.name, "light 0");
    assert_eq!((spot.color, spot.intensity, spot.attenuation), (Vec3::ONE, 1.0, Attenuation::None));
    let LightKind::Spot { position, direction, inner, outer } = spot.kind else { panic!("{spot:?}") };
    assert_eq!((position, direction), (Vec3::new(0.0, 5.0, 0.0), Vec3::NEG_Y));
    assert_eq!((inner, outer), (20f32.to_radians(), 30f32.to_radians()), "degrees in the file, radians loaded");
    assert_eq!(scene.lights[1].name, "light 1");
    assert_eq!(scene.lights[1].attenuation, Attenuation::InverseSquare);
}

#[test]
fn alpha_modes_load_with_their_cutoff_and_coverage() {
    let scene = load_ok(&with_camera(&[
        "[materials.plain]",
        "alpha = 0.4",
        "[materials.leaf]",
        "alpha_mode = \"mask\"",
        "[materials.fence]",
        "alpha_mode = \"mask\"",
        "alpha_cutoff = 0.25",
        "alpha = 0.9",
        "[materials.veil]",
        "alpha_mode = \"blend\"",
        "alpha = 0.3",
        "transmission = 1",
        "mirror = 0",
        "[materials.solid]",
        "alpha_mode = \"opaque\"",
    ]));
    // Opaque is the default; its alpha is kept (a viewer may switch the mode) but not used.
    let plain = material(&scene, "plain");
    assert_eq!((plain.alpha, plain.alpha_mode), (0.4, AlphaMode::Opaque));
    assert!(!plain.is_transparent());
    let leaf = material(&scene, "leaf");
    assert_eq!((leaf.alpha, leaf.alpha_mode), (1.0, AlphaMode::Mask { cutoff: 0.5 }), "glTF's default cutoff");
    assert!(!leaf.is_transparent(), "a mask is drawn with the opaque surfaces");
    let fence = material(&scene, "fence");
    assert_eq!((fence.alpha, fence.alpha_mode), (0.9, AlphaMode::Mask { cutoff: 0.25 }));
    let veil = material(&scene, "veil");
    assert_eq!((veil.alpha, veil.alpha_mode, veil.transmission), (0.3, AlphaMode::Blend, 1.0));
    assert!(veil.is_transparent());
    assert_eq!(*material(&scene, "solid"), Material { name: "solid".into(), ..Material::default() });
}

#[test]
fn a_user_material_named_default_is_used_for_objects_without_one() {
    let scene =
        load_ok(&with_camera(&["[materials.default]", "color = [1, 0, 0]", "[[objects]]", "type = \"sphere\""]));
    assert_eq!(scene.materials.len(), 1);
    assert_eq!(scene.materials[scene.objects[0].material.0].color, Vec3::X);
}

#[test]
fn the_implicit_default_material_can_be_named_by_any_object() {
    // With the two objects swapped the file loads; as written it fails with
    // `bad.toml:6:12: no material named `default` (known: )`.
    let text = with_camera(&[
        "[[objects]]",
        "type = \"sphere\"",
        "material = \"default\"",
        "[[objects]]",
        "type = \"sphere\"",
    ]);
    let scene = parse(&text, Path::new("bad.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.objects[0].material, scene.objects[1].material);
}

#[test]
fn the_settings_table_sets_the_scene_defaults_and_set_changes_them() {
    let scene =
        load_ok(&with_camera(&["[settings]", "exposure = 2.5", "sphere_segments = 12", "terms.specular = false"]));
    let s = &scene.settings;
    assert_eq!((s.exposure, s.sphere_segments), (2.5, 12));
    assert!(!s.terms.specular && s.terms.diffuse && s.terms.ambient && s.terms.emission);
    // The CLI's `--set key=value` starts from the scene's settings.
    let mut s = s.clone();
    s.set("terms.specular=true").unwrap();
    s.set("exposure = 0.5").unwrap();
    assert!(s.terms.specular);
    assert_eq!((s.exposure, s.sphere_segments), (0.5, 12));
}

#[test]
fn a_scene_without_lights_loads() {
    let scene = load_ok(&with_camera(&["[world]", "ambient = [0.5, 0.5, 0.5]", "[[objects]]", "type = \"sphere\""]));
    assert!(scene.lights.is_empty());
    assert_eq!(scene.ambient, Vec3::splat(0.5));
    assert_eq!(scene.objects.len(), 1);
}

#[test]
fn an_empty_file_loads_with_a_valid_camera() {
    let scene = load_ok("");
    assert!(scene.objects.is_empty() && scene.lights.is_empty() && scene.materials.is_empty());
    scene.camera.validate().unwrap();
}

#[test]
fn a_scene_without_a_camera_is_framed() {
    let scene = load_ok(&lines(&[
        "[[objects]]",
        "type = \"box\"",
        "min = [-1, 0, -2]",
        "max = [3, 2, 1]",
        "translate = [10, 0, 0]",
    ]));
    let camera = &scene.camera;
    camera.validate().unwrap();
    assert!(camera.eye.distance(camera.center) > 1.0, "eye {} center {}", camera.eye, camera.center);
    assert_close3(camera.center, Vec3::new(11.0, 1.0, -0.5), "the camera looks at the middle of the bounds");
    let (lo, hi) = scene.bounds().unwrap();
    assert_close3(lo, Vec3::new(9.0, 0.0, -2.0), "bounds min");
    assert_close3(hi, Vec3::new(13.0, 2.0, 1.0), "bounds max");
    for i in 0..8 {
        let corner = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let p = camera.project(corner).unwrap_or_else(|| panic!("corner {corner} is behind the eye"));
        assert!(p.x > 0.0 && p.x < camera.width as f32, "corner {corner} → x = {}", p.x);
        assert!(p.y > 0.0 && p.y < camera.height as f32, "corner {corner} → y = {}", p.y);
        assert!(p.z > 0.0 && p.z < 1.0, "corner {corner} → depth = {}", p.z);
    }
}

#[test]
fn a_framing_camera_that_overflows_is_an_error() {
    // The bounds span 6e38, more than f32::MAX: the framing camera's eye, near and far are infinite,
    // yet the scene loads. A bare glTF model's framing camera is validated; this one is not.
    let text = lines(&["[[objects]]", "type = \"sphere\"", "radius = 3e38"]);
    let message = error_of(&text);
    assert!(message.starts_with("bad.toml") && message.contains("camera"), "{message}");
}

#[test]
fn transforms_scale_then_rotate_about_x_y_z_then_translate() {
    let scene = load_ok(&with_camera(&[
        "[[objects]]",
        "type = \"sphere\"",
        "scale = [1, 2, 3]",
        "rotate = [90, 0, 90]",
        "translate = [10, 20, 30]",
        "[[objects]]",
        "type = \"sphere\"",
        "scale = 2",
        "rotate = [0, 90, 0]",
        "translate = [1, 2, 3]",
    ]));
    // (1, 1, 1) scaled → (1, 2, 3); 90° about x: (x, y, z) → (x, −z, y) = (1, −3, 2);
    // 90° about z: (x, y, z) → (−y, x, z) = (3, 1, 2); translated → (13, 21, 32).
    let m = scene.objects[0].world_from_local;
    assert_close3(m.transform_point3(Vec3::ONE), Vec3::new(13.0, 21.0, 32.0), "scale, X, Z, translate");
    // Were z applied before x, (1, 2, 3) would go to (−2, 1, 3), then to (−2, −3, 1).
    // +x scaled to 2, turned 90° about y to −z, moved by (1, 2, 3).
    let m = scene.objects[1].world_from_local;
    assert_close3(m.transform_point3(Vec3::X), Vec3::new(1.0, 2.0, 1.0), "uniform scale, Y, translate");
}

#[test]
fn a_gltf_object_is_placed_with_its_lights_and_camera() {
    let scene_path = repo("tests/data/gltf/inline.toml");
    let text = lines(&[
        "[camera]",
        "eye = [0, 0, 10]",
        "center = [0, 0, 0]",
        "width = 640",
        "height = 480",
        "[[objects]]",
        "name = \"model\"",
        "type = \"gltf\"",
        "path = \"two_nodes.gltf\"",
        "translate = [10, 0, 0]",
        "camera = true",
    ]);
    let scene = parse(&text, &scene_path).unwrap_or_else(|e| panic!("{e}"));
    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["model/parent/0", "model/parent/1", "model/child/0", "model/child/1"]);
    // The parent node sits at (1, 2, 3) in the model, moved by (10, 0, 0).
    assert_close3(
        scene.objects[0].world_from_local.transform_point3(Vec3::ZERO),
        Vec3::new(11.0, 2.0, 3.0),
        "parent origin",
    );
    assert_eq!(scene.lights.len(), 2);
    let LightKind::Point { position } = scene.lights[0].kind else { panic!("{:?}", scene.lights[0]) };
    assert_close3(position, Vec3::new(11.0, 7.0, 3.0), "bulb position");
    assert_eq!(scene.lights[0].attenuation, Attenuation::InverseSquare);
    // The model's camera (at (1, 2, 13), looking down −z, yfov 0.8 rad) replaces the table's
    // eye and center; the table still gives the image size.
    let c = &scene.camera;
    assert_close3(c.eye, Vec3::new(11.0, 2.0, 13.0), "camera eye");
    assert_close3((c.center - c.eye).normalize(), Vec3::NEG_Z, "camera direction");
    // glTF gives no target: `center` sits on the view axis at the depth of the scene's centre.
    let (lo, hi) = scene.bounds().expect("the scene has objects");
    let depth = ((lo + hi) / 2.0 - c.eye).dot(Vec3::NEG_Z);
    assert!(((c.center - c.eye).length() - depth).abs() < 1e-4, "{} ≠ {depth}", (c.center - c.eye).length());
    assert!((c.fovy_degrees - 0.8f32.to_degrees()).abs() < 1e-4, "{}", c.fovy_degrees);
    assert_eq!((c.near, c.far, c.width, c.height), (0.1, 100.0, 640, 480));
    assert_eq!(scene.materials[scene.objects[0].material.0].name, "painted");

    let text = lines(&["[[objects]]", "type = \"gltf\"", "path = \"two_nodes.gltf\"", "lights = false"]);
    let scene = parse(&text, &scene_path).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.lights.is_empty(), "lights = false leaves the model's lights out");
    assert_eq!(scene.objects[0].name, "gltf 0/parent/0");
    assert_eq!(scene.camera.fovy_degrees, 45.0, "without `camera = true` the scene is framed");
}

#[test]
fn a_bare_gltf_file_is_a_scene() {
    let scene = Scene::load(&repo("tests/data/gltf/two_nodes.gltf")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.objects[0].name, "two_nodes/parent/0");
    assert_close3(scene.camera.eye, Vec3::new(1.0, 2.0, 13.0), "the model's own camera");
    assert_eq!((scene.camera.width, scene.camera.height), (1280, 720));
    assert_eq!(scene.lights.len(), 2, "the model's own lights");

    // No camera and no lights: a framing camera and a white headlight.
    let scene = Scene::load(&repo("tests/data/gltf/triangle.glb")).unwrap_or_else(|e| panic!("{e}"));
    scene.camera.validate().unwrap();
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.lights[0].name, "headlight");
    assert!(matches!(scene.lights[0].kind, LightKind::Directional { .. }));
    assert_eq!((scene.lights[0].color, scene.lights[0].intensity), (Vec3::ONE, 1.0));
}

#[test]
fn the_example_in_the_documentation_loads() {
    let doc = std::fs::read_to_string(repo("docs/scene-format.md")).unwrap();
    let example = doc.split("## Example").nth(1).expect("docs/scene-format.md has an Example section");
    let text = example.split("```toml\n").nth(1).and_then(|t| t.split("```").next()).expect("a toml block");
    // Its texture path is relative to the file, so read it as if it were in assets/.
    let scene = parse(text, &repo("assets/example.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((scene.camera.width, scene.camera.height, scene.camera.fovy_degrees), (800, 600, 45.0));
    assert_eq!(scene.settings.exposure, 1.2);
    assert_eq!((scene.lights.len(), scene.objects.len(), scene.textures.len()), (2, 2, 1));
    let ball = &scene.objects[1];
    assert_eq!(ball.name, "ball");
    assert_eq!(ball.shape, Shape::Sphere { center: Vec3::ZERO, radius: 0.8 });
    assert_close3(ball.world_from_local.transform_point3(Vec3::ZERO), Vec3::new(0.0, 0.8, 0.0), "ball centre");
    assert_eq!(scene.materials[ball.material.0].name, "red");
}

/// A key given twice is named (issue 35: "duplicate key" alone did not say which).
#[test]
fn a_duplicate_key_is_named() {
    assert_error_at(&lines(&["[camera]", "fovy = 45", "fovy = 50"]), 3, 1, &["duplicate key `fovy`"]);
}
