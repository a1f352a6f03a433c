//! Environment maps on the CPU (`src/scene/environment.rs`, docs/course/08-environment-maps.md): `[world.environment]`
//! loads each source or fails naming the file and the problem, and the ray tracer's missed rays,
//! primary and reflected, see the environment.
//!
//! The images are tiny files written by each test into its own temporary folder.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Vec2, Vec3};
use mirador::scene::environment::{self, CUBE_FACES, EnvImage, Environment, EnvironmentSource, Sky};
use mirador::scene::file::parse;
use mirador::trace::Tracer;
use mirador::trace::whitted::RayCounts;
use mirador::{RenderSettings, Scene};

// ---------------------------------------------------------------------------------------------
// Helpers.

/// A fresh, empty folder under the system's temporary folder, unique to this process and call.
fn temp_dir(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("mirador-environment-{}-{n}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the temporary folder can be made");
    dir
}

/// Writes an 8-bit PNG whose pixel (x, y) is `f(x, y)`.
fn write_png(path: &Path, width: u32, height: u32, f: impl Fn(u32, u32) -> [u8; 3]) {
    image::RgbImage::from_fn(width, height, |x, y| image::Rgb(f(x, y))).save(path).expect("the PNG can be written");
}

/// Writes a Radiance HDR whose pixel (x, y) is `f(x, y)`.
fn write_hdr(path: &Path, width: u32, height: u32, f: impl Fn(u32, u32) -> [f32; 3]) {
    let pixels: Vec<image::Rgb<f32>> =
        (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| image::Rgb(f(x, y))).collect();
    let file = std::io::BufWriter::new(std::fs::File::create(path).expect("the HDR can be created"));
    image::codecs::hdr::HdrEncoder::new(file)
        .encode(&pixels, width as usize, height as usize)
        .expect("the HDR can be written");
}

/// A scene file `scene.toml` in `dir` with `environment` as its `[world.environment]` table body.
fn scene_text(environment: &str) -> String {
    format!("[world]\nambient = [0, 0, 0]\n\n[world.environment]\n{environment}\n")
}

fn load(dir: &Path, environment: &str) -> Result<Scene, String> {
    parse(&scene_text(environment), &dir.join("scene.toml")).map_err(|e| e.to_string())
}

fn load_ok(dir: &Path, environment: &str) -> Environment {
    let scene = load(dir, environment).unwrap_or_else(|e| panic!("this environment should load: {e}\n{environment}"));
    scene.environment.expect("the scene has an environment")
}

/// The environment must fail to load with a message that contains every word.
fn assert_fails(dir: &Path, environment: &str, words: &[&str]) {
    let message = match load(dir, environment) {
        Ok(_) => panic!("this environment should not load:\n{environment}"),
        Err(message) => message,
    };
    for word in words {
        assert!(message.contains(word), "the message does not mention `{word}`: {message}\nfor:\n{environment}");
    }
}

fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
    a.abs_diff_eq(b, eps)
}

/// A distinct colour per face and texel of a cube of side 2, as 8-bit values.
fn face_texel(face: usize, x: u32, y: u32) -> [u8; 3] {
    [40 * face as u8, 100 + 50 * x as u8, 100 + 50 * y as u8]
}

// ---------------------------------------------------------------------------------------------
// Loading.

#[test]
fn a_sky_loads_with_its_defaults_and_keys_in_degrees() {
    let dir = temp_dir("sky");
    let environment = load_ok(&dir, "sky = {}");
    assert_eq!(environment.source, EnvironmentSource::Sky(Sky::default()));
    assert_eq!((environment.intensity, environment.path), (1.0, None));
    let environment = load_ok(
        &dir,
        "sky = { zenith = [0, 0, 1], sun_direction = [0, 2, 0], sun_radius = 3, sun_color = [5, 5, 5] }\nintensity = 0.5",
    );
    let EnvironmentSource::Sky(sky) = &environment.source else { panic!("a sky") };
    assert_eq!(sky.zenith, Vec3::Z);
    assert_eq!(sky.horizon, Sky::default().horizon);
    assert_eq!(sky.sun_direction, Vec3::Y, "normalised");
    assert!((sky.sun_radius - 3f32.to_radians()).abs() < 1e-7);
    assert_eq!(environment.intensity, 0.5);
    // Straight up is the zenith plus the whole sun, halved by the intensity.
    assert!(close(environment.radiance(Vec3::Y), 0.5 * (Vec3::Z + Vec3::splat(5.0)), 1e-5));
}

#[test]
fn scenes_without_an_environment_see_their_background() {
    let scene = parse("[world]\nbackground = [0.1, 0.2, 0.3]\n", Path::new("plain.toml")).unwrap();
    assert!(scene.environment.is_none());
    assert_eq!(scene.environment_radiance(Vec3::new(0.3, -1.0, 2.0)), Vec3::new(0.1, 0.2, 0.3));
    let scene = parse("", Path::new("empty.toml")).unwrap();
    assert!(scene.environment.is_none());
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf/alpha.gltf");
    assert!(Scene::load(&model).unwrap().environment.is_none(), "a bare glTF model has none");
}

#[test]
fn a_latlong_hdr_loads_as_linear_radiance() {
    let dir = temp_dir("latlong");
    // Powers of two survive the HDR format's shared exponent exactly.
    write_hdr(&dir.join("env.hdr"), 8, 4, |x, y| [x as f32, 2f32.powi(y as i32), 0.25]);
    let environment = load_ok(&dir, "latlong = \"env.hdr\"\nintensity = 2");
    assert_eq!(environment.path.as_deref(), Some(dir.join("env.hdr").as_path()));
    let EnvironmentSource::LatLong(image) = &environment.source else { panic!("a lat–long image") };
    assert_eq!((image.width, image.height), (8, 4));
    assert_eq!(image.texel(5, 3), Vec3::new(5.0, 8.0, 0.25));
    // The texel centre (5.5/8, 2.5/4) is read exactly, times the intensity.
    let d = environment::latlong_direction(Vec2::new(5.5 / 8.0, 2.5 / 4.0));
    assert!(close(environment.radiance(d), 2.0 * Vec3::new(5.0, 4.0, 0.25), 1e-4), "{}", environment.radiance(d));
}

#[test]
fn a_png_environment_is_decoded_from_srgb() {
    let dir = temp_dir("srgb");
    write_png(&dir.join("ball.png"), 2, 2, |_, _| [255, 128, 0]);
    let EnvironmentSource::Sphere(image) = load_ok(&dir, "sphere = \"ball.png\"").source else {
        panic!("a sphere map")
    };
    let expected = Vec3::new(1.0, mirador::output::srgb_decode(128.0 / 255.0), 0.0);
    assert!(close(image.texel(1, 1), expected, 1e-6), "{}", image.texel(1, 1));
}

#[test]
fn a_cross_and_a_strip_load_to_the_same_faces_as_six_files() {
    let dir = temp_dir("cube");
    let s = 2;
    for (face, name) in ["px", "nx", "py", "ny", "pz", "nz"].iter().enumerate() {
        write_png(&dir.join(format!("{name}.png")), s, s, |x, y| face_texel(face, x, y));
    }
    let cube = load_ok(&dir, r#"cube = ["px.png", "nx.png", "py.png", "ny.png", "pz.png", "nz.png"]"#);
    let EnvironmentSource::Cube(faces) = &cube.source else { panic!("a cube") };
    let decoded = |c: [u8; 3]| Vec3::from_array(c.map(|c| mirador::output::srgb_decode(c as f32 / 255.0)));
    assert_eq!(faces[3].texel(1, 0), decoded(face_texel(3, 1, 0)), "−Y, the fourth file");

    // The horizontal cross: +Y over +Z, then −X +Z +X −Z, then −Y under +Z.
    let cells = [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)];
    let at = |x: u32, y: u32| -> Option<[u8; 3]> {
        let face = cells.iter().position(|&c| c == (x / s, y / s))?;
        Some(face_texel(face, x % s, y % s))
    };
    write_png(&dir.join("cross.png"), 4 * s, 3 * s, |x, y| at(x, y).unwrap_or([0, 0, 0]));
    // The vertical cross: −Z below −Y, turned 180°.
    write_png(&dir.join("vertical.png"), 3 * s, 4 * s, |x, y| {
        if y >= 3 * s {
            if x / s == 1 { face_texel(5, s - 1 - x % s, s - 1 - y % s) } else { [0, 0, 0] }
        } else {
            at(x, y).unwrap_or([0, 0, 0])
        }
    });
    write_png(&dir.join("strip.png"), 6 * s, s, |x, y| face_texel((x / s) as usize, x % s, y));
    for file in ["cross.png", "vertical.png", "strip.png"] {
        let folded = load_ok(&dir, &format!("cross = \"{file}\""));
        assert_eq!(folded.source, cube.source, "{file}");
    }

    // A direction reads the face the table says, upright: +X's top-left texel is towards (1, 1, 1).
    let d = environment::cube_direction(0, Vec2::splat(0.25));
    assert!(close(cube.radiance(d), decoded(face_texel(0, 0, 0)), 1e-6));
}

// ---------------------------------------------------------------------------------------------
// Bad input.

#[test]
fn cube_faces_must_be_square_and_of_one_size() {
    let dir = temp_dir("bad-cube");
    for name in ["px", "nx", "py", "pz", "nz"] {
        write_png(&dir.join(format!("{name}.png")), 4, 4, |_, _| [9, 9, 9]);
    }
    write_png(&dir.join("ny.png"), 2, 2, |_, _| [9, 9, 9]);
    write_png(&dir.join("wide.png"), 4, 2, |_, _| [9, 9, 9]);
    let cube = r#"cube = ["px.png", "nx.png", "py.png", "ny.png", "pz.png", "nz.png"]"#;
    assert_fails(&dir, cube, &["scene.toml:4:1", "ny.png", "cube face -Y is 2×2", "+X is 4×4"]);
    let cube = r#"cube = ["px.png", "wide.png", "py.png", "ny.png", "pz.png", "nz.png"]"#;
    assert_fails(&dir, cube, &["wide.png", "cube face -X must be square", "4×2"]);
    assert_fails(&dir, r#"cube = ["px.png", "nx.png"]"#, &["scene.toml:5:8", "2"]);
    assert_eq!(CUBE_FACES[1], "-X");
}

#[test]
fn a_cross_must_have_a_cube_map_shape() {
    let dir = temp_dir("bad-cross");
    write_png(&dir.join("square.png"), 6, 6, |_, _| [0, 0, 0]);
    write_png(&dir.join("almost.png"), 8, 7, |_, _| [0, 0, 0]);
    assert_fails(&dir, "cross = \"square.png\"", &["square.png", "6×6", "4:3", "3:4", "6:1", "1:6"]);
    assert_fails(&dir, "cross = \"almost.png\"", &["almost.png", "8×7"]);
}

#[test]
fn latlong_images_must_be_two_to_one_and_sphere_maps_square() {
    let dir = temp_dir("bad-aspect");
    write_hdr(&dir.join("square.hdr"), 4, 4, |_, _| [1.0, 1.0, 1.0]);
    write_png(&dir.join("wide.png"), 4, 2, |_, _| [0, 0, 0]);
    assert_fails(&dir, "latlong = \"square.hdr\"", &["scene.toml:4:1", "square.hdr", "2:1", "4×4"]);
    assert_fails(&dir, "sphere = \"wide.png\"", &["wide.png", "square", "4×2"]);
}

#[test]
fn missing_and_undecodable_images_are_named() {
    let dir = temp_dir("bad-file");
    std::fs::write(dir.join("junk.png"), b"not an image at all").unwrap();
    assert_fails(&dir, "latlong = \"nowhere.hdr\"", &["scene.toml:4:1", "nowhere.hdr", "cannot open"]);
    assert_fails(&dir, "sphere = \"junk.png\"", &["junk.png", "cannot"]);
    assert_fails(&dir, r#"cube = ["a.png", "b.png", "c.png", "d.png", "e.png", "f.png"]"#, &["a.png", "cannot open"]);
}

#[test]
fn bad_sky_and_intensity_values_are_errors_at_the_value() {
    let dir = temp_dir("bad-values");
    assert_fails(&dir, "sky = { sun_direction = [0, 0, 0] }", &["scene.toml:5:25", "zero vector"]);
    assert_fails(&dir, "sky = { sun_direction = [nan, 1, 0] }", &["scene.toml:5:25", "finite"]);
    assert_fails(&dir, "sky = { sun_radius = 0 }", &["scene.toml:5:22", "sun_radius", "> 0 and < 90"]);
    assert_fails(&dir, "sky = { sun_radius = 90 }", &["> 0 and < 90", "90"]);
    assert_fails(&dir, "sky = { zenith = [-1, 0, 0] }", &["scene.toml:5:18", "≥ 0"]);
    assert_fails(&dir, "sky = { moon = 1 }", &["scene.toml:5:9", "unknown field `moon`"]);
    assert_fails(&dir, "sky = {}\nintensity = -1", &["scene.toml:6:13", "≥ 0"]);
    assert_fails(&dir, "sky = {}\nintensity = nan", &["scene.toml:6:13", "finite"]);
}

#[test]
fn an_environment_has_exactly_one_source_and_no_background_beside_it() {
    let dir = temp_dir("bad-sources");
    assert_fails(&dir, "intensity = 1", &["scene.toml:4:1", "exactly one of", "got none"]);
    assert_fails(&dir, "sky = {}\nsphere = \"x.png\"", &["scene.toml:4:1", "got `sky`, `sphere`"]);
    assert_fails(&dir, "panorama = \"x.hdr\"", &["scene.toml:5:1", "unknown field `panorama`"]);
    let text = "[world]\nbackground = [1, 0, 0]\n[world.environment]\nsky = {}\n";
    let message =
        parse(text, &dir.join("both.toml")).expect_err("background and environment together fail").to_string();
    assert!(
        message.contains("both.toml:3:1") && message.contains("`background`") && message.contains("`environment`"),
        "{message}"
    );
}

// ---------------------------------------------------------------------------------------------
// The tracer.

/// A camera at (0, 0, 5) looking at the origin, 21 × 21 pixels, and whatever `objects` says.
fn traced_scene(objects: &str) -> Scene {
    let text = format!(
        "[camera]\neye = [0, 0, 5]\ncenter = [0, 0, 0]\nfovy = 40\nwidth = 21\nheight = 21\n\
         [world]\nambient = [0, 0, 0]\nbackground = [9, 0, 9]\n{objects}"
    );
    parse(&text, Path::new("traced.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// A lat–long environment that differs in every direction: a gradient in u and v, with a sky.
fn gradient_environment() -> Environment {
    let sky = Sky::default();
    let image = EnvImage::latlong_from(64, 32, |d| sky.radiance(d) * 0.1 + 0.5 * (d + Vec3::ONE));
    Environment { source: EnvironmentSource::LatLong(image), intensity: 1.5, path: None }
}

#[test]
fn rays_that_hit_nothing_see_the_environment() {
    let mut scene = traced_scene("");
    scene.environment = Some(gradient_environment());
    let tracer = Tracer::new(&scene, &RenderSettings::default());
    let mut counts = RayCounts::default();
    for (x, y) in [(0.5, 0.5), (10.5, 10.5), (20.5, 3.5), (4.5, 17.5)] {
        let expected = scene.environment_radiance(scene.camera.ray_through(x, y).direction);
        let got = tracer.primary(Vec2::new(x, y), &mut counts);
        assert!(close(got, expected, 1e-6), "pixel ({x}, {y}): {got} vs {expected}");
        assert_ne!(got, Vec3::new(9.0, 0.0, 9.0), "not the background");
    }
}

#[test]
fn a_mirror_sphere_reflects_the_environment() {
    let mut scene = traced_scene(
        "[materials.mirror]\nkd = 0\nks = 0\nka = 0\nmirror = 1\n\
         [[objects]]\ntype = \"sphere\"\nradius = 1\nmaterial = \"mirror\"\n",
    );
    scene.environment = Some(gradient_environment());
    let tracer = Tracer::new(&scene, &RenderSettings::default());
    let mut counts = RayCounts::default();
    // The centre pixel's ray meets the sphere head on and is reflected straight back, along +Z.
    let got = tracer.primary(Vec2::new(10.5, 10.5), &mut counts);
    let expected = scene.environment_radiance(Vec3::Z);
    assert!(close(got, expected, 1e-4), "{got} vs {expected}");
    assert_eq!(counts.reflected, 1);
    // Off centre, the ray is reflected about the sphere's normal where it hits.
    let ray = scene.camera.ray_through(13.5, 8.5);
    let b = ray.origin.dot(ray.direction);
    let t = -b - (b * b - (ray.origin.length_squared() - 1.0)).sqrt();
    let n = ray.at(t).normalize();
    let r = ray.direction - 2.0 * ray.direction.dot(n) * n;
    let got = tracer.primary(Vec2::new(13.5, 8.5), &mut counts);
    assert!(close(got, scene.environment_radiance(r), 1e-3), "{got} vs {}", scene.environment_radiance(r));
}

#[test]
fn the_committed_sky_hdr_is_the_default_sky() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/environments/sky.hdr");
    let image = environment::load_latlong(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((image.width, image.height), (512, 256));
    let expected = EnvImage::latlong_from(512, 256, |d| Sky::default().radiance(d));
    // The HDR format keeps 8 bits of mantissa under a shared exponent: within 1 % of the brightest
    // component.
    for (i, (got, want)) in image.texels.iter().zip(&expected.texels).enumerate() {
        assert!((*got - *want).abs().max_element() <= 0.01 * want.max_element(), "texel {i}: {got} vs {want}");
    }
    let brightest = image.texels.iter().map(|t| t.max_element()).fold(0.0, f32::max);
    assert!(brightest > 15.0, "the sun is in the file: {brightest}");
}
