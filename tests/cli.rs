//! The `mirador` binary as a user meets it: images written whole or not at all, and errors that
//! name the file and the problem.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn mirador(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mirador")).args(args).output().expect("running the mirador binary")
}

/// `mirador` on a device that offers only wgpu's downlevel limits: textures of at most 2048
/// pixels a side, as on many small GPUs.
fn mirador_on_a_small_device(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mirador"))
        .args(args)
        .env("MIRADOR_LIMITS", "downlevel")
        .output()
        .expect("running the mirador binary")
}

/// A fresh, empty directory for one test's outputs.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mirador-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("creating a scratch directory");
    dir
}

fn asset(relative: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets").join(relative).display().to_string()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Fails unless the command failed, said all of `needles`, and left `dir` empty.
fn assert_fails_cleanly(output: &Output, needles: &[&str], dir: &Path) {
    let message = stderr(output);
    assert!(!output.status.success(), "expected a failure, stderr: {message}");
    assert!(!message.contains("panicked"), "a panic instead of an error: {message}");
    for needle in needles {
        assert!(message.contains(needle), "the error should mention `{needle}`: {message}");
    }
    let left: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "a failed run left files behind: {left:?}");
}

#[test]
fn render_writes_a_png_of_the_requested_size() {
    let dir = scratch("size");
    let out = dir.join("seed.png");
    let output = mirador(&[
        "render",
        &asset("scenes/seed-simple.toml"),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "100",
        "--height",
        "60",
        "--stats",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let image = image::open(&out).expect("the output is a PNG").into_rgba8();
    assert_eq!(image.dimensions(), (100, 60));
    let stats = String::from_utf8_lossy(&output.stdout);
    for step in ["device", "scene load", "upload", "frame"] {
        assert!(stats.contains(step), "--stats should report `{step}`: {stats}");
    }
    let entries = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(entries, 1, "only the image is left, no temporary file");
}

#[test]
fn no_scene_renders_the_showcase() {
    let dir = scratch("default");
    let out = dir.join("showcase.png");
    let output = mirador(&["render", "-o", out.to_str().unwrap(), "--width", "64", "--height", "36"]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(image::open(&out).unwrap().into_rgba8().dimensions(), (64, 36));
}

#[test]
fn a_missing_scene_is_named_and_nothing_is_written() {
    let dir = scratch("missing");
    let out = dir.join("out.png");
    let output = mirador(&["render", "no/such/scene.toml", "-o", out.to_str().unwrap()]);
    assert_fails_cleanly(&output, &["no/such/scene.toml", "cannot read"], &dir);
    let message = stderr(&output);
    assert_eq!(message.matches("No such file or directory").count(), 1, "the cause said once: {message}");
}

#[test]
fn a_malformed_scene_is_reported_with_line_and_column() {
    let dir = scratch("malformed");
    let scene = dir.join("bad.toml");
    std::fs::write(&scene, "[camera]\neye = [1, 2, 3]\ncenter = [0, 0, 0]\nfovy = nan\n").unwrap();
    let out = dir.join("out.png");
    let output = mirador(&["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    std::fs::remove_file(&scene).unwrap();
    assert_fails_cleanly(&output, &["bad.toml:4:8", "finite"], &dir);
}

#[test]
fn bad_sizes_and_settings_are_rejected() {
    let dir = scratch("sizes");
    let out = dir.join("out.png");
    let out = out.to_str().unwrap();
    let seed = asset("scenes/seed-simple.toml");
    assert_fails_cleanly(&mirador(&["render", &seed, "-o", out, "--width", "0"]), &["at least one pixel"], &dir);
    assert_fails_cleanly(&mirador(&["render", &seed, "-o", out, "--height", "100000"]), &["at most 16384"], &dir);
    assert_fails_cleanly(&mirador(&["render", &seed, "-o", out, "--set", "terms.glow=true"]), &["terms.glow"], &dir);
    assert_fails_cleanly(&mirador(&["render", &seed, "-o", out, "--set", "exposure=-2"]), &["exposure"], &dir);
    let jpeg = dir.join("out.jpg");
    assert_fails_cleanly(&mirador(&["render", &seed, "-o", jpeg.to_str().unwrap()]), &["out.jpg", ".png"], &dir);
}

/// Fails unless one line of stderr holds all of `needles`: the error is one line, whichever
/// notices the driver prints around it.
fn assert_one_line(output: &Output, needles: &[&str]) {
    let message = stderr(output);
    assert!(
        message.lines().any(|line| needles.iter().all(|needle| line.contains(needle))),
        "no single line says all of {needles:?}: {message}"
    );
}

#[test]
fn a_size_beyond_the_devices_texture_limit_names_the_limit() {
    let dir = scratch("texture-limit");
    let out = dir.join("out.png");
    let output = mirador_on_a_small_device(&[
        "render",
        &asset("scenes/seed-simple.toml"),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "3000",
        "--height",
        "2000",
    ]);
    let needles = ["error: a 3000×2000 image", "max_texture_dimension_2d", "2048"];
    assert_fails_cleanly(&output, &needles, &dir);
    assert_one_line(&output, &needles);
}

#[test]
fn a_gpu_validation_error_is_an_error_not_a_panic() {
    // Shadow maps of 4096² pass the settings' own check but not a 2048-pixel device: wgpu's
    // validation error must come back through the error scopes as one line.
    let dir = scratch("validation");
    let out = dir.join("out.png");
    let output = mirador_on_a_small_device(&[
        "render",
        "-o",
        out.to_str().unwrap(),
        "--width",
        "64",
        "--height",
        "36",
        "--set",
        "shadows.enabled=true",
        "--set",
        "shadows.map_size=4096",
    ]);
    let needles = ["error: the GPU reported a validation error", "shadow::", "4096 exceeds the limit of 2048"];
    assert_fails_cleanly(&output, &needles, &dir);
    assert_one_line(&output, &needles);
}

#[test]
fn an_unknown_limits_setting_is_named() {
    let dir = scratch("limits");
    let out = dir.join("out.png");
    let output = Command::new(env!("CARGO_BIN_EXE_mirador"))
        .args(["render", "-o", out.to_str().unwrap(), "--width", "8", "--height", "8"])
        .env("MIRADOR_LIMITS", "tiny")
        .output()
        .expect("running the mirador binary");
    assert_fails_cleanly(&output, &["MIRADOR_LIMITS=tiny", "downlevel"], &dir);
}

#[test]
fn an_unwritable_output_is_named() {
    let dir = scratch("unwritable");
    let out = dir.join("no-such-dir").join("out.png");
    let output = mirador(&["render", &asset("scenes/seed-simple.toml"), "-o", out.to_str().unwrap()]);
    assert_fails_cleanly(&output, &["no-such-dir/out.png", "cannot write"], &dir);
}

#[test]
fn an_existing_image_survives_a_failed_render() {
    let dir = scratch("survives");
    let out = dir.join("keep.png");
    std::fs::write(&out, b"previous image").unwrap();
    let output = mirador(&["render", "missing.toml", "-o", out.to_str().unwrap()]);
    assert!(!output.status.success());
    assert_eq!(std::fs::read(&out).unwrap(), b"previous image");
}

#[test]
fn no_arguments_open_the_viewer_or_say_there_is_no_display() {
    let output = Command::new(env!("CARGO_BIN_EXE_mirador"))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("running the mirador binary");
    let message = stderr(&output);
    assert!(!output.status.success());
    assert!(!message.contains("panicked"), "{message}");
    assert!(message.contains("no display") && message.contains("mirador render"), "{message}");
    assert_eq!(message.trim().lines().count(), 1, "one line: {message}");
}

#[test]
fn trace_writes_the_ray_traced_image_and_reports_rays() {
    let dir = scratch("trace");
    let out = dir.join("rt.png");
    let output = mirador(&[
        "trace",
        &asset("scenes/seed-simple.toml"),
        "-o",
        out.to_str().unwrap(),
        "--stats",
        "--spp",
        "4",
        "--threads",
        "1",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(image::open(&out).unwrap().into_rgba8().dimensions(), (230, 230));
    let stats = String::from_utf8_lossy(&output.stdout);
    for word in ["bvh", "primary", "shadow", "Mrays/s", "threads: 1"] {
        assert!(stats.contains(word), "--stats should report `{word}`: {stats}");
    }
    // 4 jittered rays per pixel.
    assert!(stats.contains(&format!("{} primary", 230 * 230 * 4)), "{stats}");
}

#[test]
fn trace_rejects_a_sample_count_that_is_not_a_square() {
    let dir = scratch("spp");
    let out = dir.join("rt.png");
    let output = mirador(&["trace", &asset("scenes/seed-simple.toml"), "-o", out.to_str().unwrap(), "--spp", "3"]);
    assert_fails_cleanly(&output, &["--spp 3", "square"], &dir);
}

#[test]
fn compare_writes_a_sheet_and_prints_the_metrics() {
    let dir = scratch("compare");
    let sheet = dir.join("sheet.png");
    let traced = dir.join("traced.png");
    let output = mirador(&[
        "compare",
        &asset("scenes/seed-simple.toml"),
        "-o",
        sheet.to_str().unwrap(),
        "--trace-out",
        traced.to_str().unwrap(),
        "--set",
        "shadows.enabled=false",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let stdout = String::from_utf8_lossy(&output.stdout);
    let flip: f32 = stdout
        .lines()
        .find_map(|l| l.strip_prefix("FLIP mean: "))
        .unwrap_or_else(|| panic!("no FLIP line in {stdout}"))
        .parse()
        .unwrap();
    assert!(flip < 0.01, "seed-simple without shadows agrees closely, got {flip}");
    assert!(stdout.lines().any(|l| l.starts_with("PSNR: ") && l.ends_with(" dB")), "{stdout}");
    let sheet = image::open(&sheet).unwrap().into_rgba8();
    assert!(sheet.width() > 3 * 230 && sheet.height() > 230, "three panels side by side: {:?}", sheet.dimensions());
    assert_eq!(image::open(&traced).unwrap().into_rgba8().dimensions(), (230, 230));
}

/// `diff` prints the mean beyond rounding beside the plain mean: an image one level off
/// everywhere differs by rounding alone (plain mean above 0, beyond rounding 0), three levels off
/// it differs beyond rounding too; a mask gives both under the mask.
#[test]
fn diff_tells_rounding_from_a_difference() {
    let dir = scratch("rounding");
    let base = image::RgbaImage::from_fn(64, 48, |x, y| image::Rgba([(x * 3) as u8 + 40, (y * 4) as u8 + 30, 90, 255]));
    let shifted = |levels: u8| {
        image::RgbaImage::from_fn(64, 48, |x, y| {
            let p = base.get_pixel(x, y).0;
            image::Rgba([p[0] + levels, p[1], p[2], 255])
        })
    };
    let save = |name: &str, image: &image::RgbaImage| {
        let path = dir.join(name);
        image.save(&path).unwrap();
        path.display().to_string()
    };
    let (a, one, three) = (save("a.png", &base), save("one.png", &shifted(1)), save("three.png", &shifted(3)));
    let means = |args: &[&str], under: &str| {
        let output = mirador(args);
        assert!(output.status.success(), "{}", stderr(&output));
        let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
        let read = |prefix: &str| -> f32 {
            let line = stdout
                .lines()
                .find_map(|l| l.strip_prefix(prefix))
                .unwrap_or_else(|| panic!("no {prefix} in {stdout}"));
            line.split_whitespace().next().unwrap().parse().unwrap()
        };
        (read(&format!("FLIP mean{under}: ")), read(&format!("FLIP mean{under} beyond rounding: ")))
    };
    let (plain, beyond) = means(&["diff", &a, &one], "");
    assert!(plain > 0.001 && beyond == 0.0, "one level off: plain {plain}, beyond rounding {beyond}");
    let (plain, beyond) = means(&["diff", &a, &three], "");
    assert!(beyond > 0.001 && beyond <= plain, "three levels off: plain {plain}, beyond rounding {beyond}");
    let (plain, beyond) = means(&["diff", &a, &one, "--mask", &a], " under the mask");
    assert!(plain > 0.001 && beyond == 0.0, "under the mask: plain {plain}, beyond rounding {beyond}");
}

/// `--set` reaches the scene file's own values (issue 35): the camera, a light, a material, an
/// object, by index or name, each changing the image; a bad one fails naming the override and
/// what the scene has, and writes nothing; a model file takes none.
#[test]
fn set_overrides_the_scenes_own_values() {
    let dir = scratch("overrides");
    let seed = asset("scenes/seed-simple.toml");
    let render = |name: &str, sets: &[&str]| {
        let out = dir.join(name);
        let mut args = vec!["render", &seed, "-o", out.to_str().unwrap(), "--width", "96", "--height", "72"];
        for set in sets {
            args.extend(["--set", set]);
        }
        let output = mirador(&args);
        assert!(output.status.success(), "{sets:?}: {}", stderr(&output));
        image::open(&out).unwrap().into_rgba8()
    };
    let plain = render("plain.png", &[]);
    for (name, set) in [
        ("fovy.png", "camera.fovy=30"),
        ("light.png", "lights.0.intensity=0.2"),
        ("light-by-name.png", "lights.lamp.intensity=0.2"),
        ("ambient.png", "world.ambient=[0.5, 0.5, 0.5]"),
    ] {
        assert_ne!(render(name, &[set]), plain, "{set} changes the image");
    }
    assert_eq!(render("same.png", &["lights.0.intensity=0.2"]), render("again.png", &["lights.lamp.intensity=0.2"]));
    let bad = scratch("overrides-bad");
    let out = bad.join("x.png");
    let fails = |set: &str, needles: &[&str]| {
        assert_fails_cleanly(&mirador(&["render", &seed, "-o", out.to_str().unwrap(), "--set", set]), needles, &bad);
    };
    fails("camera.fovyy=30", &["--set camera.fovyy=30", "fovy", "seed-simple.toml"]);
    fails("lights.9.intensity=1", &["no lights `9`", "`lamp`"]);
    fails("materials.nothing.ks=1", &["no material `nothing`"]);
    fails("camera.fovy=nan", &["--set camera.fovy=nan"]);
    let teapot = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/obj/teapot.obj");
    assert_fails_cleanly(
        &mirador(&["render", teapot.to_str().unwrap(), "-o", out.to_str().unwrap(), "--set", "camera.fovy=30"]),
        &["model file", "TOML scene"],
        &bad,
    );
}

/// A course scene copied out of Mirador's tree still renders (issue 35): what it names is found
/// in Mirador's own files when it is not beside the copy; a file found nowhere is named with
/// every place looked, and nothing is written.
#[test]
fn a_copied_course_scene_renders_and_a_missing_file_names_every_place_looked() {
    let dir = scratch("copied-scene");
    for name in ["mipmaps-floor.toml", "acceleration-teapot.toml", "volume-phantom.toml"] {
        let copy = dir.join(name);
        std::fs::copy(asset(&format!("scenes/course/{name}")), &copy).unwrap();
        let out = dir.join(name).with_extension("png");
        let output = mirador(&[
            "render",
            copy.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--width",
            "64",
            "--height",
            "36",
        ]);
        assert!(output.status.success(), "{name}: {}", stderr(&output));
        assert!(out.exists(), "{name} rendered");
    }
    let bad = scratch("copied-scene-bad");
    let text = std::fs::read_to_string(asset("scenes/course/mipmaps-floor.toml")).unwrap();
    let scene = bad.join("scene.toml");
    std::fs::write(&scene, text.replace("checker.png", "nothing.png")).unwrap();
    let out = bad.join("x.png");
    let output = mirador(&["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    std::fs::remove_file(&scene).unwrap();
    assert_fails_cleanly(
        &output,
        &["nothing.png", "cannot open", "assets/textures/nothing.png", "looked beside the scene"],
        &bad,
    );
}

/// `mirador copy`: a course scene and everything it reads land in a folder of the student's,
/// named there by the copy, so the copy reads nothing outside the folder (a texture, and a model
/// with its MTL library) and draws what the course scene draws; a second copy into the same
/// folder overwrites nothing.
#[test]
fn copy_writes_a_scene_and_its_files_into_a_folder_that_reads_nothing_outside() {
    use mirador::Scene;
    use mirador::scene::file::copy::files_read;
    let dir = scratch("copy");
    for (scene, needs) in
        [("course/mirror-pair.toml", "textures/checker.png"), ("course/acceleration-teapot.toml", "teapot.mtl")]
    {
        let name = Path::new(scene).file_name().unwrap().to_str().unwrap();
        let folder = dir.join(name.trim_end_matches(".toml"));
        let output = mirador(&["copy", scene, folder.to_str().unwrap()]);
        assert!(output.status.success(), "{}", stderr(&output));
        let copy = folder.join(name);
        let read = files_read(&copy).expect("the copy loads");
        assert!(!read.is_empty());
        for (named, found) in &read {
            assert!(found.starts_with(&folder), "{scene}: the copy reads `{named}` from {}", found.display());
        }
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(stdout.contains(needs), "{scene}: {stdout}");

        let original = Scene::load(Path::new(&asset(&format!("scenes/{scene}")))).expect("the course scene");
        let copied = Scene::load(&copy).expect("the copy");
        assert_eq!((original.objects.len(), original.textures.len()), (copied.objects.len(), copied.textures.len()));
        let size = |mut s: Scene| {
            s.camera.width = 96;
            s.camera.height = 54;
            s
        };
        let (original, copied) = (size(original), size(copied));
        let trace = |s: &Scene| mirador::trace::render_image(s, &s.settings);
        assert!(trace(&original) == trace(&copied), "{scene}: the copy draws another image");

        let again = mirador(&["copy", scene, folder.to_str().unwrap()]);
        assert!(!again.status.success() && stderr(&again).contains("already exists"), "{}", stderr(&again));
    }
    // A texture named by an absolute path has no place in the folder: refused, nothing written.
    let absolute = dir.join("absolute.toml");
    let checker = asset("textures/checker.png");
    let text =
        format!("[materials.floor]\ntexture = \"{checker}\"\n[[objects]]\ntype = \"plane\"\nmaterial = \"floor\"\n");
    std::fs::write(&absolute, text).unwrap();
    let into = dir.join("absolute-copy");
    let refused = mirador(&["copy", absolute.to_str().unwrap(), into.to_str().unwrap()]);
    assert!(!refused.status.success() && stderr(&refused).contains("absolute path"), "{}", stderr(&refused));
    assert!(!into.join("absolute.toml").exists(), "a refused copy writes nothing");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A reader that stops reading (`mirador lab list | head -1`) ends the command quietly, with the
/// status a closed pipe gives, not a panic.
#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let output = Command::new(env!("CARGO_BIN_EXE_mirador"))
        .args(["lab", "list"])
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .expect("running the mirador binary");
    assert!(!stderr(&output).contains("panicked"), "{}", stderr(&output));
    assert_eq!(output.status.code(), Some(141));
}

#[test]
fn budget_writes_its_json_and_its_sheet_even_for_a_tiny_image() {
    let dir = scratch("budget");
    let sheet = dir.join("budget.png");
    let scene = asset("scenes/seed-simple.toml");
    let args = ["budget", &scene, "--width", "48", "--height", "32", "--json", "-", "--sheet", sheet.to_str().unwrap()];
    let output = mirador(&args);
    assert!(output.status.success(), "{}", stderr(&output));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("the budget's JSON on standard output");
    assert!(json["whole"].as_f64().is_some() && json["floor"].as_f64().is_some(), "{json}");
    assert_eq!(json["approximations"][0]["name"], "shadows", "{json}");
    let image = image::open(&sheet).expect("the sheet");
    assert!(image.width() > 48 && image.height() > 32);
    // The other side: a sheet that is no PNG is refused before anything is drawn.
    let wrong = dir.join("budget.jpg");
    let output = mirador(&["budget", &scene, "--sheet", wrong.to_str().unwrap()]);
    assert!(!output.status.success() && !wrong.exists(), "{}", stderr(&output));
}

/// `mirador` on a device of the WebGL2 profile (`MIRADOR_LIMITS=webgl2` on GL): what the page
/// draws with in a browser without WebGPU.
fn mirador_as_webgl2(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mirador"))
        .args(args)
        .env("MIRADOR_LIMITS", "webgl2")
        .env("WGPU_BACKEND", "gl")
        .output()
        .expect("running the mirador binary")
}

/// The WebGL2 profile draws (`tests/gl_backend.rs` compares its images), and what it cannot run
/// says why: pixel inspection needs storage buffers, the lab's checks compute shaders.
#[test]
fn the_webgl2_profile_draws_and_names_what_it_cannot_run() {
    let dir = scratch("webgl2");
    let out = dir.join("showcase.png");
    let output = mirador_as_webgl2(&["render", "-o", out.to_str().unwrap(), "--width", "160", "--height", "90"]);
    assert!(output.status.success(), "render on the WebGL2 profile: {}", stderr(&output));
    assert_eq!(image::image_dimensions(&out).expect("a PNG"), (160, 90));
    std::fs::remove_file(&out).unwrap();
    let output = mirador_as_webgl2(&["explain", "--pixel", "80,45", "--width", "160", "--height", "90"]);
    assert_fails_cleanly(&output, &["cannot inspect pixels", "storage buffers", "WebGL2"], &dir);
}
