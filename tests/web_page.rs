//! The browser build's page, checked against the native renderers: `web/test.sh` builds the page,
//! loads it in Chromium under Xvfb twice (WebGPU on SwiftShader, then WebGL2 where WebGPU is
//! missing), lets the page's test (`web/test.js`) take its screenshots through the page's own
//! interface, and then runs this file on each run's folder (`MIRADOR_WEB_CAPTURE`). It needs a browser and the web
//! build, more than CI's time allows, so it is `#[ignore]`d in `cargo test`; `tests/web.rs` keeps
//! the web build compiling there.
//!
//! What must hold: the page's 3D view is `mirador render` of the showcase at the view's size
//! (another GPU draws it: SwiftShader, not lavapipe, so within that GPU difference), toggling
//! shadows in the page gives the headless image without shadows, the split view's halves are the raster and the traced
//! images (the tracer ran in the page, in slices: exactly the native image), and the difference view is the page's
//! FLIP map of those two images, as `compare` makes it; the hybrid's traced shadows are `render`'s;
//! a lab's stub, reference, difference, a student's solution typed into the editor and then a
//! typo are drawn as the native renderer compiled from the same WGSL draws them; and the lab's
//! checks in the page score a wrong solution and a right one as the native checker does.

mod common;

use std::path::{Path, PathBuf};

use mirador::Scene;

/// The greatest mean FLIP between the page's raster images and lavapipe's: another GPU draws them
/// (SwiftShader), whose texture filtering differs along the checkerboard's edges and whose
/// rounding bands the bump map's shading. Measured 0.031–0.037 (web/README.md); a technique
/// missing costs more (shadows: 0.068).
const MAX_CROSS_GPU_FLIP: f32 = 0.05;
/// The page's difference view against `compare`'s FLIP map of the page's own two images: the same
/// FLIP (flip-rs) of the same images, so only the view's drawing of the map (a texture shown on the
/// screen) may differ. Measured 0.00000 (2026-11-27); the map of the native raster image instead
/// of the page's measured 0.113–0.126, and must stay farther than the page's own.
const MAX_DIFFERENCE_MAP_FLIP: f32 = 0.01;
/// The tracer is the same code on the same CPU, in WebAssembly: measured 0.00000.
const MAX_TRACED_FLIP: f32 = 0.01;
/// Shadows off in the page must be this many times nearer `render` with shadows off than with
/// them on (measured 0.068 / 0.034 = 2.0, and 0.0705 / 0.0372 = 1.9).
const MIN_TOGGLE_RATIO: f32 = 1.5;

fn capture() -> PathBuf {
    let dir = std::env::var_os("MIRADOR_WEB_CAPTURE")
        .expect("MIRADOR_WEB_CAPTURE names the page's screenshots: run this test through `bash web/test.sh`");
    PathBuf::from(dir)
}

/// A screenshot the page posted, and the 3D view's rectangle in it.
fn shot(dir: &Path, name: &str) -> (image::RgbaImage, [u32; 4]) {
    let path = dir.join(name);
    let image = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).into_rgba8();
    let view = std::fs::read_to_string(dir.join(format!("{name}.view"))).expect("the view's rectangle");
    let view: Vec<u32> = view.split_whitespace().map(|n| n.parse().expect("four numbers")).collect();
    (image, view.try_into().expect("x y width height"))
}

fn crop(image: &image::RgbaImage, [x, y, w, h]: [u32; 4]) -> image::RgbaImage {
    image::imageops::crop_imm(image, x, y, w, h).to_image()
}

fn showcase(w: u32, h: u32, shadows: bool) -> Scene {
    let mut scene = Scene::showcase().expect("the showcase loads");
    (scene.camera.width, scene.camera.height) = (w, h);
    scene.settings.shadows.enabled = shadows;
    scene
}

/// Mean FLIP beyond the CPU levels (tests/README.md); the images are kept when it is too large.
fn flip(reference: &image::RgbaImage, test: &image::RgbaImage, what: &str, dir: &Path) -> f32 {
    let d = common::difference(reference, test);
    println!("{what}: mean FLIP {:.5}", d.flip_mean);
    if d.flip_mean > MAX_TRACED_FLIP {
        let _ = reference.save(dir.join(format!("{what}-expected.png")));
        let _ = d.error_map.save(dir.join(format!("{what}-diff.png")));
    }
    d.flip_mean
}

#[test]
#[ignore = "needs the web build and Chromium: bash web/test.sh"]
fn the_page_draws_what_the_native_renderers_draw() {
    let dir = capture();
    assert!(!dir.join("failed").exists(), "the page failed: {}", std::fs::read_to_string(dir.join("failed")).unwrap());

    let (image, view) = shot(&dir, "raster.png");
    assert!(view[0] > 100 && view[2] > 100 && view[3] > 100, "a side panel and a 3D view: {view:?}");
    let scene = showcase(view[2], view[3], true);
    let raster = common::raster(&scene, &scene.settings);
    let error = flip(&raster, &crop(&image, view), "raster", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "the page's 3D view differs from `render`: mean FLIP {error}");

    let (toggled, toggled_view) = shot(&dir, "no-shadows.png");
    assert_eq!(toggled_view, view);
    let without = showcase(view[2], view[3], false);
    let expected = common::raster(&without, &without.settings);
    let error = flip(&expected, &crop(&toggled, view), "no-shadows", &dir);
    assert!(
        error <= MAX_CROSS_GPU_FLIP,
        "shadows off in the page differ from `render --set shadows.enabled=false`: {error}"
    );
    let against_on = flip(&raster, &crop(&toggled, view), "no-shadows-against-shadows", &dir);
    assert!(
        against_on >= MIN_TOGGLE_RATIO * error,
        "turning shadows off in the page did not give the image without shadows: mean FLIP {error} against it, \
         {against_on} against the image with them"
    );

    // The split view: raster left of the divider, traced right, clear of the divider and its labels.
    let (split, split_view) = shot(&dir, "split.png");
    assert_eq!(split_view, view);
    let traced = mirador::trace::render_image(&scene, &scene.settings);
    let half = view[2] / 2;
    let left = [view[0], view[1], half - 4, view[3] - 30];
    let right = [view[0] + half + 4, view[1], view[2] - half - 4, view[3] - 30];
    let in_view = |[x, y, w, h]: [u32; 4]| [x - view[0], y - view[1], w, h];
    let error = flip(&crop(&raster, in_view(left)), &crop(&split, left), "split-left", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "split, left half: mean FLIP {error} against `render`");
    let error = flip(&crop(&traced, in_view(right)), &crop(&split, right), "split-right", &dir);
    assert!(error <= MAX_TRACED_FLIP, "split, right half: mean FLIP {error} against `trace` (traced in the page)");

    // The difference view: the page's FLIP map (flip-rs, as natively) of its own two images, the
    // traced one (the native one, above) and its raster one (the first screenshot), against the
    // map `compare` makes of those same two images.
    let (difference, difference_view) = shot(&dir, "difference.png");
    assert_eq!(difference_view, view);
    let page_raster = crop(&image, view);
    let map = mirador::compare::difference(&traced, &page_raster).expect("the same size").error_map;
    let error = flip(&map, &crop(&difference, view), "difference", &dir);
    assert!(error <= MAX_DIFFERENCE_MAP_FLIP, "the difference view is not the map of its traced and raster: {error}");
    // Two-sided: the map of the native raster image differs from it (the GPUs' differences).
    let native_map = mirador::compare::difference(&traced, &raster).expect("the same size").error_map;
    let against_native = flip(&native_map, &crop(&difference, view), "difference-against-native-raster", &dir);
    assert!(
        against_native > error,
        "the page's map is as close to the native raster's map ({against_native}) as to its own ({error})"
    );

    // The hybrid in the page: shadow maps without bias, their visibility traced instead
    // (`settings.hybrid`, traced on the page's thread), against `render` with the same settings,
    // and two-sided against the acne those maps draw without the hybrid (measured 0.033 and
    // 0.199).
    let (hybrid, hybrid_view) = shot(&dir, "hybrid.png");
    assert_eq!(hybrid_view, view);
    let mut acne = scene.settings.clone();
    (acne.shadows.depth_bias, acne.shadows.slope_bias, acne.shadows.normal_offset) = (0, 0.0, 0.0);
    let mut traced_shadows = acne.clone();
    traced_shadows.hybrid.shadows = true;
    let expected = common::raster(&scene, &traced_shadows);
    let error = flip(&expected, &crop(&hybrid, view), "hybrid", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "the page's hybrid differs from `render`'s: mean FLIP {error}");
    let against_acne = flip(&common::raster(&scene, &acne), &crop(&hybrid, view), "hybrid-against-acne", &dir);
    assert!(
        against_acne >= MIN_TOGGLE_RATIO * error,
        "the page's hybrid is as close to the acne ({against_acne}) as to the traced shadows ({error})"
    );

    // A scene whose volume the page fetched beside its module (files::FETCHED), as `render` draws it.
    let (phantom, phantom_view) = shot(&dir, "phantom.png");
    assert_eq!(phantom_view, view);
    let path = mirador::scene::builtin_path("course/volume-phantom.toml");
    let mut scene = Scene::load(&path).expect("the phantom's scene");
    (scene.camera.width, scene.camera.height) = (view[2], view[3]);
    let expected = common::raster(&scene, &scene.settings);
    let error = flip(&expected, &crop(&phantom, view), "phantom", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "the phantom in the page differs from `render`'s: {error}");
    let against_showcase = flip(&raster, &crop(&phantom, view), "phantom-against-showcase", &dir);
    assert!(against_showcase >= MIN_TOGGLE_RATIO * error, "the page did not draw the phantom: {against_showcase}");

    // Screen-space refraction, which reads the view's depth with textureLoad (WebGL2 read zeros
    // from a depth texture that filtered linearly), as `render` draws it.
    let (refraction, refraction_view) = shot(&dir, "refraction.png");
    assert_eq!(refraction_view, view);
    let mut scene = Scene::load(&mirador::scene::builtin_path("refraction.toml")).expect("the refraction scene");
    (scene.camera.width, scene.camera.height) = (view[2], view[3]);
    scene.settings.transparency.refraction = mirador::settings::Refraction::Screen;
    let expected = common::raster(&scene, &scene.settings);
    let error = flip(&expected, &crop(&refraction, view), "screen-refraction", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "screen-space refraction in the page differs from `render`'s: {error}");
    let mut straight = scene.settings.clone();
    straight.transparency.refraction = mirador::settings::Refraction::None;
    let against =
        flip(&common::raster(&scene, &straight), &crop(&refraction, view), "screen-refraction-against-none", &dir);
    assert!(against >= MIN_TOGGLE_RATIO * error, "the page's refraction is as near no refraction ({against})");

    // Displacement in the page: tessellated on the GPU for the view with WebGPU (a compute
    // shader), the uniform mesh with WebGL2 (no compute), each as `render` draws it on that kind
    // of device; two-sided against the bump-mapped ball (its outline a circle).
    let (displaced, displaced_view) = shot(&dir, "displaced.png");
    assert_eq!(displaced_view, view);
    let path = mirador::scene::builtin_path("course/displacement-sphere.toml");
    let mut bumped = Scene::load(&path).expect("the displaced ball's scene");
    (bumped.camera.width, bumped.camera.height) = (view[2], view[3]);
    let mut scene = bumped.clone();
    scene.settings.bump.method = mirador::settings::BumpMethod::Displacement;
    if dir.file_name().is_some_and(|name| name == "webgl2") {
        scene.settings.bump.tessellation = mirador::settings::Tessellation::Uniform;
    }
    mirador::texture::displacement::displace(&mut scene);
    let expected = common::raster(&scene, &scene.settings);
    let error = flip(&expected, &crop(&displaced, view), "displaced", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "the displaced ball in the page differs from `render`'s: {error}");
    let against =
        flip(&common::raster(&bumped, &bumped.settings), &crop(&displaced, view), "displaced-against-bump", &dir);
    assert!(
        against >= MIN_TOGGLE_RATIO * error,
        "the page's displaced ball is as near the bump-mapped one ({against})"
    );

    // The lab in the page: the planar-mirrors lab's scene drawn with the stub's functions and with
    // Mirador's, each against the native renderer compiled from the same WGSL (the editor beside
    // the view leaves the view narrower).
    let lab = mirador::lab::find("planar-mirrors").expect("a built-in lab");
    let mut scene = mirador::lab::images::scene(&lab.images[0], None).expect("the lab's scene");
    let (stub, lab_view) = shot(&dir, "lab-stub.png");
    (scene.camera.width, scene.camera.height) = (lab_view[2], lab_view[3]);
    let gpu = common::gpu();
    let native = |wgsl| mirador::lab::images::raster(gpu, &scene, &wgsl).expect("the lab's scene draws");
    let native_stub = native(mirador::lab::source::student(&lab, &lab.stub()));
    let native_reference = native(mirador::lab::source::reference(&lab));
    let (reference, reference_view) = shot(&dir, "lab-reference.png");
    assert_eq!(reference_view, lab_view);
    let error = flip(&native_stub, &crop(&stub, lab_view), "lab-stub", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "the lab's stub in the page differs from the native stub: {error}");
    let error = flip(&native_reference, &crop(&reference, lab_view), "lab-reference", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "the lab's reference in the page differs from the native: {error}");
    let apart = flip(&native_reference, &crop(&stub, lab_view), "lab-stub-against-reference", &dir);
    assert!(
        apart >= MIN_TOGGLE_RATIO * error,
        "the page's stub is as near the reference ({apart}) as the page's reference is ({error})"
    );

    // The lab's difference view in the page: the error map between the reference and the stub,
    // as `compare` makes it from the native images (the page's own images differ from the
    // native ones by a little, so the map does too; against the stub's image it is far).
    let (difference, difference_view) = shot(&dir, "lab-difference.png");
    assert_eq!(difference_view, lab_view);
    let native_map = mirador::compare::difference(&native_reference, &native_stub).expect("same sizes").error_map;
    let error = flip(&native_map, &crop(&difference, lab_view), "lab-difference", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "the page's lab difference differs from the native map: {error}");
    let apart = flip(&native_map, &crop(&stub, lab_view), "lab-difference-against-stub", &dir);
    assert!(apart >= MIN_TOGGLE_RATIO * error, "the page's difference view is as near the stub ({apart}) as the map");

    // The student's reflection typed into the editor draws the reference's image; a typo then
    // keeps it drawn (the last version that compiled), with the problem over the view's top left.
    let (solved, solved_view) = shot(&dir, "lab-solved.png");
    assert_eq!(solved_view, lab_view);
    let solved_error = flip(&native_reference, &crop(&solved, lab_view), "lab-solved", &dir);
    assert!(
        solved_error <= MAX_CROSS_GPU_FLIP,
        "the student's reflection in the page differs from the reference: {solved_error}"
    );
    let error = flip(&native_stub, &crop(&solved, lab_view), "lab-solved-against-stub", &dir);
    assert!(
        error >= MIN_TOGGLE_RATIO * solved_error,
        "the page did not draw the student's edit: {error} from the stub"
    );
    let (typo, typo_view) = shot(&dir, "lab-typo.png");
    assert_eq!(typo_view, lab_view);
    let lower = [lab_view[0], lab_view[1] + lab_view[3] / 2, lab_view[2], lab_view[3] / 2];
    let in_view = |[x, y, w, h]: [u32; 4]| [x - lab_view[0], y - lab_view[1], w, h];
    let error = flip(&crop(&native_reference, in_view(lower)), &crop(&typo, lower), "lab-typo", &dir);
    assert!(error <= MAX_CROSS_GPU_FLIP, "a typo did not keep the last version drawn: {error}");
    let boxed = flip(&crop(&solved, lab_view), &crop(&typo, lab_view), "lab-typo-box", &dir);
    assert!(boxed > 0.001, "the typo's problem is not shown over the view: {boxed}");

    lab_checks_in_the_page(&dir, &lab, gpu);
}

/// The lab's checks run in the page (the panel's Check button) on a wrong solution and a right
/// one: the wrong fails, naming the known mistake it makes, the right passes every test, and
/// each test scores as the native checker scores the same text on the same kind of device (the
/// standard profile natively for the page's WebGPU, the WebGL2 profile on GL for its WebGL2).
fn lab_checks_in_the_page(dir: &Path, lab: &mirador::lab::Lab, gpu: &mirador::gpu::Gpu) {
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    // web/test.sh names each run's folder after the API the page drew with.
    let webgl2 = dir.file_name().is_some_and(|name| name == "webgl2");
    let gl;
    let device = if webgl2 {
        gl = mirador::gpu::Gpu::headless_webgl2_on(wgpu::Backends::GL).expect("a GL device");
        &gl
    } else {
        gpu
    };
    for (case, passes) in [("lab-wrong", false), ("lab-right", true)] {
        let text = read(&format!("{case}.wgsl"));
        let page: serde_json::Value = serde_json::from_str(&read(&format!("{case}.json"))).expect("results.json");
        let mut native = mirador::lab::checks::Progress::start(device, lab, &text);
        while !native.done() {
            if !native.advance() {
                device.wait();
            }
        }
        let tests = page["tests"].as_array().expect("results.json lists its tests");
        assert_eq!(tests.len(), native.results().len(), "{case}");
        for (theirs, ours) in tests.iter().zip(native.results()) {
            let what = format!("{case}, {}:\npage: {}\nnative: {}", ours.name, theirs["output"], ours.output);
            assert_eq!(theirs["name"], ours.name.as_str(), "{what}");
            assert_eq!(theirs["score"].as_f64(), Some(f64::from(ours.score)), "{what}");
            assert_eq!(theirs["mistake"].as_str(), ours.mistake.as_deref(), "{what}");
        }
        let (score, max) = (page["score"].as_f64().unwrap(), page["max_score"].as_f64().unwrap());
        eprintln!("{case}: {score} / {max} points in the page ({} s)", page["execution_time"]);
        if passes {
            assert_eq!(score, max, "the right solution does not pass in the page:\n{page:#}");
        } else {
            assert!(score < max, "the wrong solution passes in the page:\n{page:#}");
            let named = tests.iter().any(|t| t["mistake"] == "d not doubled");
            assert!(named, "no failing test names the mistake the wrong solution makes:\n{page:#}");
        }
    }
}

/// A link of the course's site opened in the page (web/site-test.sh): its scene, settings and
/// view, as the query says them, drawn natively by the command the link stands for (`render`,
/// `trace`, both halves for the split view) at the page's view size, by Mirador's own binary.
fn native_of_link(
    query: &str,
    [w, h]: [u32; 2],
    dir: &Path,
    name: &str,
) -> (image::RgbaImage, Option<image::RgbaImage>, String) {
    let mut scene = String::from("showcase.toml");
    let mut sets = Vec::new();
    let mut view = String::from("raster");
    for pair in query.split('&') {
        let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
        let value = common::percent_decoded(value);
        match key {
            "scene" => scene = value,
            "set" => sets.push(value),
            "view" => view = value,
            _ => {}
        }
    }
    let draw = |command: &str, sets: &[String], out: &str| {
        let path = dir.join(format!("{name}-{out}.png"));
        let mut args: Vec<String> = vec![command.into(), format!("assets/scenes/{scene}"), "-o".into()];
        args.push(path.to_string_lossy().into_owned());
        args.extend(["--width".into(), w.to_string(), "--height".into(), h.to_string()]);
        for set in sets {
            args.extend(["--set".into(), set.clone()]);
        }
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_mirador"))
            .args(&args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .status()
            .expect("mirador runs");
        assert!(status.success(), "mirador {} failed", args.join(" "));
        image::open(&path).expect("its image").into_rgba8()
    };
    let image = |sets: &[String], out: &str| match view.as_str() {
        "traced" => draw("trace", sets, out),
        "split" => {
            let (raster, traced) =
                (draw("render", sets, &format!("{out}-raster")), draw("trace", sets, &format!("{out}-traced")));
            let mut split = raster.clone();
            image::imageops::replace(&mut split, &crop(&traced, [w / 2, 0, w - w / 2, h]), (w / 2) as i64, 0);
            split
        }
        _ => draw("render", sets, out),
    };
    let without = (!sets.is_empty()).then(|| image(&[], "without"));
    (image(&sets, "native"), without, view)
}

/// Scenes whose raster image another GPU draws farther from lavapipe's than the showcase: the
/// course's checkered floor to the horizon, where each GPU picks its own texels where they are
/// smaller than pixels (the aliasing chapter 3 teaches), with every filter. Measured against
/// SwiftShader 0.077–0.110 (2026-11-28, both APIs); the images look alike. What the filter does is
/// then checked by the differences between the page's own views ([`SAME_DIFFERENCE`]).
const ALIASED_SCENES: &[(&str, f32)] = &[("course/mipmaps-floor.toml", 0.15)];
/// Two links of one scene and view differ in the page as their commands' images differ natively,
/// where they differ visibly (a mean FLIP of 0.02 or more): within this factor either way. The
/// mipmap filters measured 0.71 to 1.09 (the page's nearest against bilinear, 0.022 against
/// 0.031).
const SAME_DIFFERENCE: f32 = 2.0;

/// Links whose frame outlasts Chromium's GPU watchdog on SwiftShader, a GPU in software: the
/// browser stops its GPU process after about 30 s, and the page must then say so (its
/// device-lost message, src/web/page.rs). The phantom at `volume.step = 0.25`, twice the default's
/// samples, at 1280×624 (2026-11-28, both links of chapter 11's exercise 1). A real GPU draws
/// that frame in milliseconds; where one draws it here, it is checked as every other link.
const BEYOND_A_SOFTWARE_GPU: &[&str] = &["scene=course/volume-phantom.toml&set=volume.step%3D0.25"];

/// What WebGL2 cannot draw, said in the page's notice (src/viewer/frame.rs, `WEBGL2_NOTICE`): the
/// shadow map's own view reads a depth texture's texels, which WebGL2 returns as zeros (the
/// shadow-map lab is refused there for the same reason). Two-sided: where WebGL2 draws it after
/// all, the test says this list is stale.
const WEBGL2_CANNOT: &[&str] = &["set=shadows.view%3Dmap"];

/// A link drawn by the page, and its command's image.
struct Drawn {
    link: String,
    group: String,
    page: image::RgbaImage,
    native: image::RgbaImage,
}

#[test]
#[ignore = "needs the course's site and Chromium: bash web/site-test.sh"]
fn the_course_links_draw_what_their_commands_draw() {
    let dir = capture();
    let mut queries: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "query"))
        .collect();
    queries.sort_by_key(|p| {
        p.file_stem().unwrap().to_string_lossy().trim_start_matches("link-").parse::<u32>().unwrap_or(0)
    });
    assert!(!queries.is_empty(), "no link was opened");
    let mut problems = Vec::new();
    let mut drawn: Vec<Drawn> = Vec::new();
    for path in &queries {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(path).unwrap();
        let (query, page) = text.trim_end().split_once('\n').expect("the query, then the page it is on");
        let link = format!("{page}: ?{query}");
        if let Ok(why) = std::fs::read_to_string(dir.join(format!("{name}.failed"))) {
            let why = why.lines().next().unwrap_or_default();
            let said = why.starts_with("The browser stopped Mirador's GPU device");
            if said && BEYOND_A_SOFTWARE_GPU.iter().any(|q| query.starts_with(q)) {
                println!("{link}: beyond a GPU in software, and the page says so: {why}");
            } else {
                problems.push(format!("{link}: the page failed: {why}"));
            }
            continue;
        }
        let (shot, view) = shot(&dir, &format!("{name}.png"));
        if query.starts_with("lab=") {
            // A lab's link: the page opened the lab (it fails saying why otherwise) and drew it.
            assert!(view[2] > 100 && view[3] > 100, "{link}: no view drawn");
            println!("{link}: the lab opened");
            continue;
        }
        let (native, without, mode) = native_of_link(query, [view[2], view[3]], &dir, &name);
        // The split view's divider and labels are the page's own: left out, as above.
        let area = match mode.as_str() {
            "split" => [0, 0, view[2], view[3] - 30],
            _ => [0, 0, view[2], view[3]],
        };
        let page_view = crop(&crop(&shot, view), area);
        let scene = query.split('&').find_map(|p| p.strip_prefix("scene=")).unwrap_or("showcase.toml");
        let aliased = ALIASED_SCENES.iter().find(|(s, _)| *s == scene).map(|(_, t)| *t);
        let tolerance = match mode.as_str() {
            "traced" => MAX_TRACED_FLIP,
            _ => aliased.unwrap_or(MAX_CROSS_GPU_FLIP),
        };
        let error = flip(&crop(&native, area), &page_view, &name, &dir);
        println!("{link}: {mode}, mean FLIP {error:.5}");
        if dir.ends_with("webgl2") && WEBGL2_CANNOT.iter().any(|q| query.contains(q)) {
            if error <= tolerance {
                problems.push(format!("{link}: WebGL2 draws it after all ({error:.5}): take it out of WEBGL2_CANNOT"));
            }
            continue;
        }
        if error > tolerance {
            problems.push(format!("{link}: mean FLIP {error:.5} against the native command (at most {tolerance})"));
        }
        // Two-sided where the settings change the image: nearer the command's image than the
        // scene's own.
        if let Some(without) = without {
            let apart = common::flip(&crop(&native, area), &crop(&without, area));
            let against = flip(&crop(&without, area), &page_view, &format!("{name}-without"), &dir);
            if apart > 2.0 * tolerance && against < MIN_TOGGLE_RATIO * error {
                problems.push(format!(
                    "{link}: as near the scene without its settings ({against:.5}) as with them ({error:.5})"
                ));
            }
        }
        let group = format!("{scene} {mode} {}x{}", area[2], area[3]);
        drawn.push(Drawn { link, group, page: page_view, native: crop(&native, area) });
    }
    problems.extend(same_differences(&drawn));
    assert!(problems.is_empty(), "{} of {} links:\n{}", problems.len(), queries.len(), problems.join("\n"));
}

/// Links of one scene and view, each against the one before it: the page's two views differ
/// as their commands' images do (the same GPU draws both, so what the settings change shows,
/// whatever the GPUs' differences).
fn same_differences(drawn: &[Drawn]) -> Vec<String> {
    let mut problems = Vec::new();
    for (i, b) in drawn.iter().enumerate() {
        let Some(a) = drawn[..i].iter().rev().find(|a| a.group == b.group) else { continue };
        let native = common::flip(&a.native, &b.native);
        let page = common::flip(&a.page, &b.page);
        println!("{} against {}: the page's views {page:.5} apart, the commands' {native:.5}", b.link, a.link);
        if native >= 0.02 && !(native / SAME_DIFFERENCE..=native * SAME_DIFFERENCE).contains(&page) {
            problems.push(format!(
                "{}: {page:.5} from the page's view of {}, where the commands' images are {native:.5} apart",
                b.link, a.link
            ));
        }
    }
    problems
}
