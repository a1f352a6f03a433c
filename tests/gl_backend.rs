//! The GL backend against Vulkan (issue 30): the same scenes rendered by wgpu's GL backend (Mesa's
//! llvmpipe) and by Vulkan (lavapipe) in one process, compared by FLIP, with no error logged by
//! wgpu on the way. GL decides what a layered texture is when it is made and samples it only
//! through a view of that kind (`src/gpu/texture.rs`, `Layers`); a cube or array sampled another
//! way reads black, so the showcase's red ball lost its reflection while the rest of the image
//! stayed right. The ball's own test below catches that, which the whole image's mean dilutes.
//! Isosurfaces and screen-space refraction read copies of a depth image, which wgpu's GL backend
//! cannot make with `copy_texture_to_texture` (it reads the source through a colour attachment
//! and logs `GL_INVALID_FRAMEBUFFER_OPERATION`): the torus was missing and the glass showed
//! nothing behind it, until the copies were drawn instead (`src/gpu/depth_copy.rs`).
//!
//! The same GL device with WebGL2's limits draws with the WebGL2 shader profile
//! (`shaders/profile/webgl2.wgsl`, issue 36): what the page draws with in a browser without
//! WebGPU. Every scene is compared with Vulkan's image.
//!
//! The devices are made here whatever `WGPU_BACKEND` says ([`Gpu::headless_on`]). A machine
//! without either backend fails these tests with the reason, as every image test of the project
//! fails without an adapter (`tests/README.md`).

mod common;

use std::sync::{Mutex, OnceLock};

use common::{GoldenError, REGION, Tolerance};
use mirador::gpu::Gpu;
use mirador::raster::environment::object_centre;
use mirador::{RenderSettings, Scene};

/// What GL's image may differ from Vulkan's by. Measured (Mesa's llvmpipe behind both, the
/// showcase at 640×360, the environment stage at 480×270, the volume and refraction stages at
/// their cameras' 480×300 and 480×270): mean FLIP 0.00000 and worst 32×32
/// region 0.00000 in both, beyond the two levels every comparison of the tests leaves aside
/// (`common::CPU_LEVELS`). Before the fix of issue 30 the showcase measured 0.0070 and 0.68
/// (its ball unreflected), the environment stage 0.37 and 0.97; with every cube read through the
/// right view but filtered with seams (desktop GL's default, `src/gpu/mod.rs`), 0.0008 and 0.019
/// for the environment stage. The volume stage measures 0.00000 and 0.00000, screen-space
/// refraction 0.00002 and 0.0016 (two pixels of the glass's rim differ visibly; the same glass
/// refracting the environment cube, which reads no copy, differs by at most 2/255 anywhere);
/// with their depth copied by `copy_texture_to_texture`, which GL leaves empty, they measured
/// 0.030 and 0.85, and 0.058 and 0.79. The bounds catch all five. The largest difference measured
/// between the two backends anywhere else, the anti-aliasing course scene's edges (mean 0.0001,
/// region 0.006, shaders compiled two ways), fits under them.
const TOLERANCE: Tolerance = Tolerance { flip_mean: 0.001, worst_region: 0.01 };

/// The largest mean FLIP between GL's and Vulkan's red ball in the showcase. Measured 0.0000;
/// the ball without its reflection (GL before the fix) 0.60, Vulkan's own ball with environment
/// maps off 0.62.
const BALL_TOLERANCE: f32 = 0.05;

/// The three devices, made once for every test of this binary, after the error log is installed.
struct Devices {
    vulkan: Gpu,
    gl: Gpu,
    /// GL with WebGL2's limits and the WebGL2 profile's shaders (`MIRADOR_LIMITS=webgl2`): what
    /// the page draws with where the browser has no WebGPU.
    webgl2: Gpu,
}

fn devices() -> &'static Devices {
    static DEVICES: OnceLock<Devices> = OnceLock::new();
    DEVICES.get_or_init(|| {
        ErrorLog::install();
        let on = |backends: wgpu::Backends| {
            Gpu::headless_on(backends)
                .unwrap_or_else(|e| panic!("the GL comparison needs a {backends:?} adapter (see README.md): {e}"))
        };
        let webgl2 = Gpu::headless_webgl2_on(wgpu::Backends::GL)
            .unwrap_or_else(|e| panic!("the WebGL2 comparison needs a GL adapter (see README.md): {e}"));
        let devices = Devices { vulkan: on(wgpu::Backends::VULKAN), gl: on(wgpu::Backends::GL), webgl2 };
        // Mesa's EGL logs a failed driver probe while it looks for llvmpipe: not a rendering error.
        ErrorLog::take();
        devices
    })
}

/// Every error wgpu (its core and its backends) logs, kept for the tests to read: the GL backend
/// reports a texture bound through a view of the wrong kind this way, and renders on.
struct ErrorLog;

static ERRORS: Mutex<Vec<String>> = Mutex::new(Vec::new());

impl ErrorLog {
    fn install() {
        static LOGGER: ErrorLog = ErrorLog;
        log::set_logger(&LOGGER).expect("no other logger in this test binary");
        log::set_max_level(log::LevelFilter::Error);
    }

    /// The errors logged since the last call.
    fn take() -> Vec<String> {
        std::mem::take(&mut *ERRORS.lock().expect("no test panicked while logging"))
    }
}

impl log::Log for ErrorLog {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() == log::Level::Error && metadata.target().starts_with("wgpu")
    }

    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            let line = format!("{}: {}", record.target(), record.args());
            ERRORS.lock().expect("no test panicked while logging").push(line);
        }
    }

    fn flush(&self) {}
}

/// `scene` rendered on Vulkan and on GL, and the errors wgpu logged meanwhile (of any test of
/// the binary running at the same time: every one of them is a failure).
fn both(scene: &Scene, settings: &RenderSettings) -> (image::RgbaImage, image::RgbaImage, Vec<String>) {
    let devices = devices();
    let vulkan = mirador::raster::render_image(&devices.vulkan, scene, settings);
    let gl = mirador::raster::render_image(&devices.gl, scene, settings);
    (vulkan, gl, ErrorLog::take())
}

/// Fails on any error wgpu logged: GL reports a texture bound through the wrong view there and
/// renders on.
fn assert_no_errors(errors: &[String]) {
    assert!(errors.is_empty(), "wgpu logged {} errors, the first: {}", errors.len(), errors[0]);
}

/// Fails where GL's image differs from Vulkan's beyond [`TOLERANCE`].
fn assert_gl_matches(name: &str, vulkan: &image::RgbaImage, gl: &image::RgbaImage) {
    let error = GoldenError::between(vulkan, gl).unwrap_or_else(|e| panic!("{e}"));
    eprintln!(
        "{name}, GL against Vulkan: mean FLIP {:.5}, worst {REGION}×{REGION} region {:.5}",
        error.flip_mean, error.worst_region
    );
    let excesses = error.excesses(TOLERANCE);
    assert!(excesses.is_empty(), "{name}: GL differs from Vulkan: {}", excesses.join("; "));
}

/// The square inside the disc that `object` (a sphere) covers in the image, as (x, y, side).
fn inside_sphere(scene: &Scene, object: &str) -> (u32, u32, u32) {
    let index = scene.objects.iter().position(|o| o.name == object).expect("the scene has the object");
    let (centre, radius) = object_centre(scene, index);
    let camera = &scene.camera;
    let middle = camera.project(centre).expect("the sphere is in front of the camera");
    let right = camera.frame().xe;
    let edge = camera.project(centre + radius * right).expect("the sphere is in front of the camera");
    // Half the side of the inscribed square, and a little less, to stay off the silhouette.
    let half = 0.9 * (edge - middle).truncate().length() / std::f32::consts::SQRT_2;
    let corner = middle.truncate() - glam::Vec2::splat(half);
    (corner.x.round() as u32, corner.y.round() as u32, (2.0 * half).round() as u32)
}

fn crop(image: &image::RgbaImage, (x, y, side): (u32, u32, u32)) -> image::RgbaImage {
    image::imageops::crop_imm(image, x, y, side, side).to_image()
}

#[test]
fn showcase_on_gl_matches_vulkan() {
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (640, 360);
    let (vulkan, gl, errors) = both(&scene, &scene.settings);
    assert_gl_matches("showcase", &vulkan, &gl);
    assert_no_errors(&errors);
}

/// The red ball reflects the sky and the floor through its dynamic cube (a cube array on GL);
/// read through the wrong view, it is plain red, a change the whole image's mean dilutes below
/// any bound. Its region is compared alone, and the region is checked to be where the
/// reflection shows: there Vulkan's ball with environment maps off differs by far more.
#[test]
fn showcase_ball_reflects_on_gl() {
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (640, 360);
    let (vulkan, gl, errors) = both(&scene, &scene.settings);
    let ball = inside_sphere(&scene, "shiny sphere");
    let mut unreflected = scene.settings.clone();
    unreflected.environment.enabled = false;
    let plain = mirador::raster::render_image(&devices().vulkan, &scene, &unreflected);
    let reflection = common::flip(&crop(&vulkan, ball), &crop(&plain, ball));
    assert!(
        reflection > 10.0 * BALL_TOLERANCE,
        "the region {ball:?} misses the reflection: without it Vulkan's ball differs by only {reflection:.5}"
    );
    let error = common::flip(&crop(&vulkan, ball), &crop(&gl, ball));
    eprintln!("the ball {ball:?}: GL against Vulkan {error:.5}, Vulkan without its reflection {reflection:.5}");
    assert!(error <= BALL_TOLERANCE, "GL's ball differs from Vulkan's by mean FLIP {error:.5} > {BALL_TOLERANCE}");
    assert_no_errors(&errors);
}

/// The chrome ball and torus: the world's cube, both dynamic cubes and their mip chains.
#[test]
fn environment_stage_on_gl_matches_vulkan() {
    let mut scene = common::load("scenes/environment.toml");
    (scene.camera.width, scene.camera.height) = (480, 270);
    let (vulkan, gl, errors) = both(&scene, &scene.settings);
    assert_gl_matches("environment", &vulkan, &gl);
    assert_no_errors(&errors);
}

/// The isosurface of a torus's distance field and the composited phantom over a floor: the
/// isosurface's rays end at a copy of the view's depth (without it on GL, no torus).
#[test]
fn volume_stage_on_gl_matches_vulkan() {
    let scene = common::load("scenes/volume.toml");
    let (vulkan, gl, errors) = both(&scene, &scene.settings);
    assert_gl_matches("volume", &vulkan, &gl);
    assert_no_errors(&errors);
}

/// Screen-space refraction: the glass reads copies of the opaque image and depth (without the
/// depth on GL, nothing is found behind the glass and the environment cube shows instead).
#[test]
fn screen_refraction_on_gl_matches_vulkan() {
    let scene = common::load("scenes/refraction.toml");
    let mut settings = scene.settings.clone();
    settings.transparency.refraction = mirador::settings::Refraction::Screen;
    let (vulkan, gl, errors) = both(&scene, &settings);
    assert_gl_matches("screen refraction", &vulkan, &gl);
    assert_no_errors(&errors);
}

/// What the WebGL2 profile's image may differ from Vulkan's by, on every scene of
/// `assets/scenes/` at 320 pixels wide. Measured: the environment stage, whose two objects
/// reflect their dynamic cubes, differs most, mean FLIP 0.0014 and worst 32×32 region 0.021:
/// the cube's level of detail is computed by the profile (lavapipe's cube lookups choose theirs
/// their own way), and over the checkered floor's reflection a level apart shows. Then
/// environment-ball 0.0005 and 0.018, refraction 0.0004 and 0.012, whitted-depth 0.0003 and
/// 0.009, the showcase 0.0001 and 0.007; 21 of the 26 scenes 0.0000 and at most 0.006. A cube
/// read through the wrong face or not at all measured 0.37 and 0.97 on the environment stage
/// (issue 30's GL bug); ±X directions read from the ±Z layers (tried) measured 0.0096 and 0.20
/// here and 0.014 and 0.52 on environment-ball; the +X and −X layers swapped (tried) 0.011 and
/// 0.20 here, 0.022 and 0.46 on environment-ball, 0.0014 and 0.077 on the showcase: the bound
/// catches all three. (The swap once went unseen: the mip chains were copied through the same
/// face table, which undid it past level 0. The copy now reads each layer directly.)
const WEBGL2_TOLERANCE: Tolerance = Tolerance { flip_mean: 0.003, worst_region: 0.05 };

/// The WebGL2 profile (`shaders/profile/webgl2.wgsl`, issue 36) draws every scene as Vulkan does,
/// within the two places it may differ: its dynamic cubes are six 2D layers whose lookups do not
/// filter across a face's edge, and its shadow filters read four comparisons where Vulkan
/// gathers them (exactly the same texels and weights). Each scene is drawn with its own settings.
#[test]
fn webgl2_profile_matches_vulkan_on_every_scene() {
    assert_eq!(devices().webgl2.profile(), mirador::gpu::Profile::WebGl2);
    let mut failures = Vec::new();
    for path in common::scene_files() {
        let mut scene = mirador::Scene::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let (w, h) = (scene.camera.width, scene.camera.height);
        (scene.camera.width, scene.camera.height) = (320, (320 * h / w).max(1));
        let vulkan = mirador::raster::render_image(&devices().vulkan, &scene, &scene.settings);
        let webgl2 = mirador::raster::render_image(&devices().webgl2, &scene, &scene.settings);
        let error = GoldenError::between(&vulkan, &webgl2).unwrap_or_else(|e| panic!("{e}"));
        eprintln!(
            "{}: WebGL2 profile against Vulkan: mean FLIP {:.5}, worst {REGION}×{REGION} region {:.5}",
            path.display(),
            error.flip_mean,
            error.worst_region
        );
        let excesses = error.excesses(WEBGL2_TOLERANCE);
        if !excesses.is_empty() {
            failures.push(format!("{}: {}", path.display(), excesses.join("; ")));
        }
    }
    assert_no_errors(&ErrorLog::take());
    assert!(failures.is_empty(), "the WebGL2 profile differs from Vulkan:\n{}", failures.join("\n"));
}

/// Every shadow filter on the WebGL2 profile: the tent filters' four lookups at texel centres
/// give what the gather gives, and the red ball's dynamic cube is read, not missed.
#[test]
fn webgl2_profile_shadow_filters_and_cubes_match_vulkan() {
    use mirador::settings::ShadowFilter;
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (480, 270);
    for filter in [ShadowFilter::None, ShadowFilter::Hardware, ShadowFilter::Pcf3x3, ShadowFilter::Pcf5x5] {
        let mut settings = scene.settings.clone();
        settings.shadows.filter = filter;
        let vulkan = mirador::raster::render_image(&devices().vulkan, &scene, &settings);
        let webgl2 = mirador::raster::render_image(&devices().webgl2, &scene, &settings);
        let error = GoldenError::between(&vulkan, &webgl2).unwrap_or_else(|e| panic!("{e}"));
        eprintln!("{filter:?}: mean FLIP {:.5}, worst region {:.5}", error.flip_mean, error.worst_region);
        let excesses = error.excesses(TOLERANCE);
        assert!(excesses.is_empty(), "{filter:?} on the WebGL2 profile: {}", excesses.join("; "));
    }
    let ball = inside_sphere(&scene, "shiny sphere");
    let vulkan = mirador::raster::render_image(&devices().vulkan, &scene, &scene.settings);
    let webgl2 = mirador::raster::render_image(&devices().webgl2, &scene, &scene.settings);
    let error = common::flip(&crop(&vulkan, ball), &crop(&webgl2, ball));
    eprintln!("the ball {ball:?}: WebGL2 profile against Vulkan {error:.5}");
    assert!(error <= BALL_TOLERANCE, "the WebGL2 profile's ball differs by mean FLIP {error:.5}");
    assert_no_errors(&ErrorLog::take());
}

/// A frame's debug groups (each view's, each phase's: `FrameEncoder::group`) balance on every
/// encoder, a profiled frame's too, which submits its encoder after every phase and so must
/// close the groups open then and open them again on the next: wgpu refuses an encoder whose
/// groups do not balance. GL records the groups; Vulkan on a CPU records none
/// (`Gpu::debug_groups`). Mirrored views, cube faces, refraction and transparency each add
/// groups.
#[test]
fn a_profiled_frames_debug_groups_balance_on_gl() {
    let gl = &devices().gl;
    assert!(gl.debug_groups(), "GL records the frame's debug groups");
    for name in ["showcase.toml", "mirrors.toml", "refraction.toml"] {
        let mut scene = Scene::load(&mirador::scene::builtin_path(name)).expect("a built-in scene");
        (scene.camera.width, scene.camera.height) = (160, 90);
        let mut headless = mirador::raster::Headless::new(gl, &scene);
        headless.renderer.profile = true;
        let drawn = gl.checked(|| headless.render(gl, &scene, &scene.settings));
        assert!(drawn.is_ok(), "{name}: {:?}", drawn.err());
        assert_no_errors(&ErrorLog::take());
        let passes = headless.report.passes.iter().filter(|p| p.time.is_some()).count();
        assert!(passes >= 4, "{name}: a profiled frame times each pass, {passes} timed");
    }
}
