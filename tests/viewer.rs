//! The viewer as a person meets it, run under Xvfb (`xvfb-run -a`): it opens the showcase with
//! every technique on, switches view modes and toggles by scripted steps, writes screenshots and
//! exits cleanly. The 3D region of a screenshot is compared by FLIP with what the headless
//! renderers draw at the same size, so the window shows the same pixels as `mirador render` and
//! `mirador trace`, and the split view's halves line up.
//!
//! These tests need an X display: install Xvfb (`apt-get install xvfb`; `.ci/run` does).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use mirador::Scene;

/// The greatest mean FLIP error between the window's 3D view and the headless image. The same
/// device draws both (lavapipe); what remains is egui's dithering of its output.
const MAX_FLIP_MEAN: f32 = 0.01;

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

/// The viewer with `args`, under `xvfb-run -a` when it exists, else on the current display.
fn viewer(args: &[&str], config_home: &Path) -> Output {
    viewer_with(args, config_home, None)
}

/// [`viewer`] with one more variable in its environment.
fn viewer_with(args: &[&str], config_home: &Path, variable: Option<(&str, &str)>) -> Output {
    let binary = env!("CARGO_BIN_EXE_mirador");
    let mut command = if on_path("xvfb-run") {
        let mut c = Command::new("xvfb-run");
        c.args(["-a", "-s", "-screen 0 1920x1080x24", binary]);
        c
    } else if std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty()) {
        Command::new(binary)
    } else {
        panic!(
            "the viewer tests need an X display: install Xvfb (`sudo apt-get install xvfb`, as .ci/run does) \
             or run them under a desktop session"
        );
    };
    command.arg("view").args(args).env("XDG_CONFIG_HOME", config_home).env_remove("WAYLAND_DISPLAY");
    if let Some((key, value)) = variable {
        command.env(key, value);
    }
    let output = command.output().expect("running the viewer");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("panicked"), "the viewer panicked: {stderr}");
    output
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mirador-viewer-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("creating a scratch directory");
    dir
}

/// Where the 3D view sat in each screenshot, from the viewer's `screenshot FILE window WxH view X
/// Y W H` lines.
fn views(output: &Output) -> Vec<(PathBuf, [u32; 4])> {
    views_in(&String::from_utf8_lossy(&output.stdout))
}

/// [`views`] from the viewer's standard output as text.
fn views_in(stdout: &str) -> Vec<(PathBuf, [u32; 4])> {
    stdout
        .lines()
        .filter_map(|line| {
            let rest = line.strip_prefix("screenshot ")?;
            let (path, geometry) = rest.split_once(" window ")?;
            let numbers: Vec<u32> =
                geometry.split_once(" view ")?.1.split(' ').filter_map(|n| n.parse().ok()).collect();
            Some((PathBuf::from(path), numbers.try_into().ok()?))
        })
        .collect()
}

fn succeeded(output: &Output) {
    assert!(
        output.status.success(),
        "the viewer failed: {}\n{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The viewer on `scene` in a 640×400 window with `extra` arguments, running `steps`; it must
/// succeed.
fn scripted(scene: &Path, extra: &[&str], steps: &[String], dir: &Path) -> Output {
    let mut args = vec![scene.to_str().expect("a UTF-8 path"), "--size", "640x400", "--frames", "2"];
    args.extend(extra);
    for step in steps {
        args.extend(["--step", step.as_str()]);
    }
    let output = viewer(&args, dir);
    succeeded(&output);
    output
}

/// The 3D view of the screenshot at `path` that `output` wrote, and where it sat in the window.
fn view_in(output: &Output, path: &Path) -> (image::RgbaImage, [u32; 4]) {
    let (_, rect) = views(output).into_iter().find(|(p, _)| p == path).expect("the screenshot was written");
    (crop(&image::open(path).expect("the screenshot").to_rgba8(), rect), rect)
}

fn crop(image: &image::RgbaImage, [x, y, w, h]: [u32; 4]) -> image::RgbaImage {
    image::imageops::crop_imm(image, x, y, w, h).to_image()
}

/// The showcase at `w × h`, as the headless command would draw it.
fn showcase(w: u32, h: u32) -> Scene {
    let mut scene = Scene::showcase().expect("the showcase loads");
    scene.camera.width = w;
    scene.camera.height = h;
    scene
}

fn flip(reference: &image::RgbaImage, test: &image::RgbaImage, what: &str, dir: &Path) -> f32 {
    let d = common::difference(reference, test);
    if d.flip_mean > MAX_FLIP_MEAN {
        let _ = reference.save(dir.join(format!("{what}-expected.png")));
        let _ = test.save(dir.join(format!("{what}-actual.png")));
        let _ = d.error_map.save(dir.join(format!("{what}-diff.png")));
    }
    d.flip_mean
}

/// The window's 3D view is the headless render, whichever way it reaches the window: copied into
/// the surface (what lavapipe's surface allows), or drawn by egui as a texture (what surfaces
/// that take no copies get, forced here by `MIRADOR_COMPOSITION`), and on wgpu's GL backend too
/// (no view formats there: the texture path; its images are Vulkan's, tests/gl_backend.rs).
#[test]
fn the_showcase_in_the_window_is_the_headless_render() {
    showcase_in_the_window("copied", None);
}

#[test]
fn the_showcase_drawn_by_egui_as_a_texture_is_the_headless_render() {
    showcase_in_the_window("textured", Some(("MIRADOR_COMPOSITION", "textured")));
}

#[test]
fn the_showcase_in_the_window_on_the_gl_backend_is_the_headless_render() {
    showcase_in_the_window("gl", Some(("WGPU_BACKEND", "gl")));
}

fn showcase_in_the_window(name: &str, variable: Option<(&str, &str)>) {
    let dir = scratch(&format!("raster-{name}"));
    let shot = dir.join("raster.png");
    let args = ["--size", "1000x600", "--frames", "3", "--step", "overlay off", "--screenshot", shot.to_str().unwrap()];
    let output = viewer_with(&args, &dir, variable);
    succeeded(&output);
    let views = views(&output);
    let [(path, view)] = &views[..] else { panic!("one screenshot line expected: {output:?}") };
    let view = *view;
    assert_eq!(path, &shot);
    let image = image::open(&shot).expect("the screenshot is a PNG").into_rgba8();
    assert!(view[0] > 100, "the side panel is left of the view: {view:?}");
    assert_eq!((view[0] + view[2], view[1] + view[3]), image.dimensions(), "the view fills the rest of the window");
    // The panel is drawn: its pixels are not all one colour.
    let panel = crop(&image, [0, 0, view[0], view[3]]);
    let first = panel.get_pixel(0, 0);
    assert!(panel.pixels().any(|p| p != first), "the side panel has content");

    let scene = showcase(view[2], view[3]);
    let expected = common::raster(&scene, &scene.settings);
    let error = flip(&expected, &crop(&image, view), "raster", &dir);
    assert!(error <= MAX_FLIP_MEAN, "the window's 3D view differs from `render`: mean FLIP {error}");
    assert!(!dir.join("mirador").exists(), "a scripted run leaves the remembered settings alone");
}

#[test]
fn scripted_toggles_and_view_modes_run_and_exit_cleanly() {
    let dir = scratch("modes");
    let shots: Vec<PathBuf> =
        ["toggled", "split", "difference", "traced"].iter().map(|n| dir.join(format!("{n}.png"))).collect();
    let step = |s: &str| s.to_string();
    let mut steps = vec![
        step("overlay off"),
        step("set shadows.enabled=false"),
        step("set bump.view=\"normals\""),
        step("set textures.filter=\"level_colour\""),
        step("set shadows.show_frusta=true"),
        format!("screenshot {}", shots[0].display()),
        step("set bump.view=\"off\""),
        step("set textures.filter=\"trilinear\""),
        step("set shadows.show_frusta=false"),
        step("set shadows.enabled=true"),
        step("orbit 30 -10"),
        step("reset"),
        step("view split"),
        step("split 0.5"),
        step("wait traced"),
        format!("screenshot {}", shots[1].display()),
        step("view difference"),
        step("wait traced"),
        format!("screenshot {}", shots[2].display()),
        step("view traced"),
        step("wait traced"),
        step("help on"),
        step("pick 200 300"),
        step("material kd=0.1"),
        step("view raster"),
    ];
    steps.push(format!("screenshot {}", shots[3].display()));
    let mut args = vec!["--size".to_string(), "640x400".to_string(), "--frames".to_string(), "2".to_string()];
    for s in &steps {
        args.push("--step".into());
        args.push(s.clone());
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let output = viewer(&args, &dir);
    succeeded(&output);
    let views = views(&output);
    assert_eq!(views.len(), 4, "every screenshot step wrote one: {views:?}");
    for (path, _) in &views {
        assert!(image::open(path).is_ok(), "{} is a PNG", path.display());
    }

    // The split view: raster left of the divider, ray traced right, both pixel-aligned with the
    // headless images of the same size.
    let view = views[1].1;
    let image = image::open(&shots[1]).unwrap().into_rgba8();
    let scene = showcase(view[2], view[3]);
    let raster = common::raster(&scene, &scene.settings);
    let traced = mirador::trace::render_image(&scene, &scene.settings);
    let half = view[2] / 2;
    // Keep clear of the divider line and its labels at the bottom.
    let left = [view[0], view[1], half - 4, view[3] - 30];
    let right = [view[0] + half + 4, view[1], view[2] - half - 4, view[3] - 30];
    let in_view = |[x, y, w, h]: [u32; 4]| [x - view[0], y - view[1], w, h];
    let raster_error = flip(&crop(&raster, in_view(left)), &crop(&image, left), "split-left", &dir);
    let traced_error = flip(&crop(&traced, in_view(right)), &crop(&image, right), "split-right", &dir);
    assert!(raster_error <= MAX_FLIP_MEAN, "split, left half: mean FLIP {raster_error} against `render`");
    assert!(traced_error <= MAX_FLIP_MEAN, "split, right half: mean FLIP {traced_error} against `trace`");

    // The difference view shows the FLIP map of the same two images.
    let difference = image::open(&shots[2]).unwrap().into_rgba8();
    let expected = mirador::compare::difference(&traced, &raster).unwrap().error_map;
    let error = flip(&expected, &crop(&difference, views[2].1), "difference", &dir);
    assert!(error <= MAX_FLIP_MEAN, "the difference view is the FLIP map of traced and raster: {error}");

    // The toggled frame differs from the default one.
    let toggled = crop(&image::open(&shots[0]).unwrap().into_rgba8(), views[0].1);
    assert!(
        flip(&crop(&raster, [0, 0, views[0].1[2], views[0].1[3]]), &toggled, "toggled", &dir) > 0.02,
        "toggles change the image"
    );
}

#[test]
fn a_scene_that_fails_to_load_keeps_the_previous_one() {
    let dir = scratch("bad-scene");
    let bad = dir.join("broken.toml");
    std::fs::write(&bad, "[camera\neye = [0, 0, 1]\n").unwrap();
    let shot = dir.join("after.png");
    let load = format!("load {}", bad.display());
    let output =
        viewer(&["--size", "640x400", "--frames", "2", "--step", &load, "--screenshot", shot.to_str().unwrap()], &dir);
    succeeded(&output);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("broken.toml"), "the load error names the file: {stderr}");
    assert!(shot.exists());
}

#[test]
fn bad_steps_and_outputs_fail_with_a_message() {
    let dir = scratch("bad-steps");
    for args in [
        vec!["--frames", "1", "--step", "dance"],
        vec!["--frames", "1", "--step", "set shadows.glow=true"],
        vec!["--frames", "1", "--screenshot", "out.jpg"],
        vec!["--frames", "1", "--step", "pick 1 1", "--step", "material glow=2"],
    ] {
        let output = viewer(&args, &dir);
        assert!(!output.status.success(), "{args:?} should fail");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains("error"), "{args:?}: {stderr}");
    }
}

#[test]
fn a_scene_file_changed_on_disk_is_reloaded() {
    let dir = scratch("reload");
    let scene = dir.join("scene.toml");
    let original = std::fs::read_to_string(common::asset("scenes/seed-simple.toml")).expect("the seed scene");
    std::fs::write(&scene, &original).unwrap();
    let binary = env!("CARGO_BIN_EXE_mirador");
    assert!(on_path("xvfb-run"), "install Xvfb (`sudo apt-get install xvfb`) to run the viewer tests");
    let mut child = Command::new("xvfb-run")
        .args(["-a", binary, "view", scene.to_str().unwrap(), "--size", "480x320", "--frames", "2"])
        .args(["--step", "wait 3s"])
        .env("XDG_CONFIG_HOME", &dir)
        .env("RUST_LOG", "mirador=info")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("starting the viewer");
    // Touch the file until the viewer is done: it polls the modification time twice a second.
    let mut edits = 0;
    while child.try_wait().expect("polling the viewer").is_none() {
        std::thread::sleep(std::time::Duration::from_millis(300));
        edits += 1;
        std::fs::write(&scene, format!("{original}\n# edit {edits}\n")).unwrap();
    }
    let output = child.wait_with_output().expect("the viewer's output");
    succeeded(&output);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("changed on disk"), "the edited scene was reloaded: {stderr}");
}

/// Where the lat–long view's marker sits in a screenshot: the centroid of its magenta pixels
/// inside the map's rectangle `map` (window pixels), or `None` when there are none.
fn marker_centre(image: &image::RgbaImage, [x, y, w, h]: [u32; 4]) -> Option<glam::Vec2> {
    let mut sum = glam::Vec2::ZERO;
    let mut count = 0.0;
    for j in y..y + h {
        for i in x..x + w {
            let [r, g, b, _] = image.get_pixel(i, j).0;
            if r > 200 && g < 80 && b > 200 {
                sum += glam::Vec2::new(i as f32 + 0.5, j as f32 + 0.5);
                count += 1.0;
            }
        }
    }
    (count > 0.0).then(|| sum / count)
}

#[test]
fn the_latlong_view_marks_the_direction_seen_under_the_cursor() {
    use mirador::raster::environment::view_rect;
    use mirador::scene::Shape;
    use mirador::scene::environment::latlong_uv;

    let dir = scratch("latlong");
    let shots = [dir.join("ball.png"), dir.join("sky.png")];
    // The cursor over the chrome ball (right of and above its centre), then over the sky.
    let cursors = [glam::Vec2::new(280.5, 260.5), glam::Vec2::new(200.5, 40.5)];
    let scene_path = mirador::scene::builtin_path("environment.toml");
    let mut args: Vec<String> = ["--size", "1000x600", "--frames", "2"].map(String::from).to_vec();
    args.push(scene_path.display().to_string());
    for step in ["set environment.view=\"latlong\"".to_string(), "overlay off".to_string()].into_iter().chain(
        cursors.iter().zip(&shots).flat_map(|(c, shot)| {
            [format!("cursor {} {}", c.x, c.y), "wait 1".to_string(), format!("screenshot {}", shot.display())]
        }),
    ) {
        args.extend(["--step".to_string(), step]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let output = viewer(&args, &dir);
    succeeded(&output);
    let views = views(&output);
    assert_eq!(views.len(), 2, "two screenshots: {views:?}");

    let mut scene = Scene::load(&scene_path).expect("the environment scene");
    let view = views[0].1;
    (scene.camera.width, scene.camera.height) = (view[2], view[3]);
    let [mx, my, mw, mh] = view_rect((view[2], view[3]), 2.0, true);
    let map = [view[0] + mx as u32, view[1] + my as u32, mw as u32, mh as u32];
    let ball = scene.objects.iter().find(|o| o.name == "chrome ball").expect("the chrome ball");
    let Shape::Sphere { center, radius } = ball.shape else { panic!("the chrome ball is a sphere") };
    let center = ball.world_from_local.transform_point3(center);

    // Expected directions, from the camera and the sphere alone: a reflection off the exact
    // sphere, and the view ray itself over the background.
    let expected = cursors.map(|c| {
        let ray = scene.camera.ray_through(c.x, c.y);
        let oc = ray.origin - center;
        let b = oc.dot(ray.direction);
        let disc = b * b - (oc.length_squared() - radius * radius);
        if disc < 0.0 {
            return ray.direction;
        }
        let p = ray.origin + (-b - disc.sqrt()) * ray.direction;
        let n = (p - center).normalize();
        ray.direction - 2.0 * ray.direction.dot(n) * n
    });
    assert!(expected[0].dot(expected[1]) < 0.95, "the two cursors see different directions");
    for (k, (shot, d)) in shots.iter().zip(expected).enumerate() {
        let image = image::open(shot).expect("the screenshot").into_rgba8();
        let uv = latlong_uv(d);
        let want = glam::Vec2::new(map[0] as f32 + uv.x * map[2] as f32, map[1] as f32 + uv.y * map[3] as f32);
        let found = marker_centre(&image, map).unwrap_or_else(|| panic!("no marker on the map in {}", shot.display()));
        assert!(
            found.distance(want) < 2.0,
            "cursor {k}: the marker is at {found}, the direction {d} maps to {want} (map {map:?})"
        );
    }
}

/// The `key=value` fields of each of the viewer's `volume probe …` lines.
fn probe_fields(output: &Output) -> Vec<std::collections::HashMap<String, String>> {
    let stdout = String::from_utf8_lossy(&output.stdout);
    let fields = |line: &str| {
        line.split_whitespace().filter_map(|f| f.split_once('=')).map(|(k, v)| (k.into(), v.into())).collect()
    };
    stdout.lines().filter_map(|l| l.strip_prefix("volume probe ")).map(fields).collect()
}

#[test]
fn the_volume_ray_under_the_cursor_shows_its_samples() {
    use mirador::volume::{March, march};

    let dir = scratch("volume-probe");
    let shot = dir.join("probe.png");
    // Over the phantom's lower half, where the ray reaches the threshold and stops early; then
    // over the torus's isosurface.
    let cursors = [glam::Vec2::new(200.5, 350.5), glam::Vec2::new(520.5, 320.5)];
    let scene_path = common::asset("scenes/volume.toml");
    let mut args: Vec<String> =
        [scene_path.to_str().unwrap(), "--size", "1000x600", "--frames", "2"].map(String::from).to_vec();
    for step in [
        "overlay off".to_string(),
        format!("cursor {} {}", cursors[0].x, cursors[0].y),
        "probe".to_string(),
        format!("screenshot {}", shot.display()),
        format!("cursor {} {}", cursors[1].x, cursors[1].y),
        "probe".to_string(),
    ] {
        args.extend(["--step".to_string(), step]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let output = viewer(&args, &dir);
    succeeded(&output);
    let probes = probe_fields(&output);
    assert_eq!(probes.len(), 2, "two probe lines: {probes:?}");
    let fields = &probes[0];
    let number = |key: &str| fields[key].parse::<f32>().unwrap_or_else(|e| panic!("{key}: {e}"));
    let list = |key: &str| fields[key].split(',').map(|v| v.parse::<f32>().unwrap()).collect::<Vec<_>>();
    assert_eq!((fields["volume"].as_str(), fields["mode"].as_str()), ("phantom", "composite"));

    // The same ray, from the camera and the volume alone: its box cut where the floor (y = 0)
    // is, sampled as `march::samples` cuts it.
    let views = views(&output);
    let view = views[0].1;
    let mut scene = Scene::load(&scene_path).expect("the volume scene");
    (scene.camera.width, scene.camera.height) = (view[2], view[3]);
    let settings = &scene.settings.volume;
    let in_front_of_the_floor = |name: &str, cursor: glam::Vec2| {
        let ray = scene.camera.ray_through(cursor.x, cursor.y);
        let volume = scene.volumes.iter().find(|v| v.name == name).expect("the volume");
        let local = volume.local_ray(&ray);
        let (near, far) = local.box_interval(volume.grid.half_extent()).expect("the ray enters the box");
        let floor = if ray.direction.y < 0.0 { -ray.origin.y / ray.direction.y } else { f32::INFINITY };
        (volume, local, (near.max(0.0), far.min(floor)))
    };
    let (phantom, local, segment) = in_front_of_the_floor("phantom", cursors[0]);
    let planned = march::samples(&phantom.grid, &local, segment, settings.step).count;
    assert_eq!(number("planned") as u32, planned, "the samples planned along the ray");

    let alpha_out = list("alpha_out");
    let taken = number("taken") as u32;
    assert_eq!(alpha_out.len() as u32, taken, "one accumulated opacity per sample taken");
    assert_eq!(list("value").len() as u32, taken);
    assert!(alpha_out.windows(2).all(|w| w[0] <= w[1]), "the accumulated opacity never falls: {alpha_out:?}");
    let threshold = March::of(settings).termination.expect("early termination is on in the scene");
    assert!(taken < planned, "the ray stops early here: {taken} of {planned}");
    assert!(number("alpha") >= threshold && alpha_out[alpha_out.len() - 2] < threshold, "it stops at the threshold");

    // Over the torus: its values along the ray and the crossing `march::isosurface` finds.
    let torus = &probes[1];
    assert_eq!((torus["volume"].as_str(), torus["mode"].as_str()), ("torus", "isosurface"));
    let (volume, local, segment) = in_front_of_the_floor("torus", cursors[1]);
    let crossing =
        march::isosurface(&volume.grid, &local, segment, volume.iso, &March::of(settings)).expect("a crossing");
    let shown: f32 = torus["crossing"].parse().expect("the crossing's t");
    assert!((shown - crossing).abs() < 1e-4, "the crossing shown at t = {shown}, computed at {crossing}");

    // The plot is drawn in the view's lower-right corner (across from the cursor): its
    // accumulated-opacity curve's light blue is there.
    let image = image::open(&shot).expect("the screenshot").into_rgba8();
    let corner = crop(&image, [view[0] + view[2] / 2, view[1] + view[3] / 2, view[2] / 2, view[3] / 2]);
    assert!(
        corner.pixels().filter(|p| p[0] < 90 && p[1] > 170 && p[2] > 220).count() > 50,
        "the α_out curve is drawn: {}",
        shot.display()
    );
}

/// Inspect mode: the `inspect` step explains a pixel of the red ball in both renderers, the
/// window with the two columns opens over the lower left of the view, and the tracer's rays are
/// drawn in 3D, where they stay as the camera orbits (here: after the orbit, the ball's reflected
/// ray in cyan and its shadow rays in yellow). The same run without the step draws none of it.
#[test]
fn inspect_mode_shows_both_columns_and_draws_the_ray_tree() {
    let dir = scratch("inspect");
    let shot = |name: &str| dir.join(name).display().to_string();
    let run = |inspect: bool, name: &str| {
        let mut steps = vec!["panel off", "overlay off", "wait 2"];
        if inspect {
            steps.push("inspect 506 286");
        }
        steps.extend(["wait 2", "orbit 60 0", "wait 3"]);
        let mut args = vec!["--size", "900x560", "--frames", "16", "--screenshot"];
        let path = shot(name);
        args.push(&path);
        let step_args: Vec<String> = steps.iter().flat_map(|s| ["--step".to_string(), s.to_string()]).collect();
        args.extend(step_args.iter().map(String::as_str));
        let output = viewer(&args, &dir);
        succeeded(&output);
        (output, image::open(&path).unwrap().into_rgba8())
    };
    let (inspected, with) = run(true, "with.png");
    let (_, without) = run(false, "without.png");
    let stdout = String::from_utf8_lossy(&inspected.stdout);
    assert!(stdout.contains("inspected (506, 286)"), "{stdout}");
    let count = |image: &image::RgbaImage, colour: [u8; 3]| {
        image.pixels().filter(|p| (0..3).all(|c| p[c].abs_diff(colour[c]) <= 12)).count()
    };
    let cyan = [0, 220, 255];
    let yellow = [255, 220, 0];
    let (reflected, shadow) = (count(&with, cyan), count(&with, yellow));
    eprintln!(
        "ray pixels: reflected {reflected}, shadow {shadow}; without inspecting {} and {}",
        count(&without, cyan),
        count(&without, yellow)
    );
    assert!(reflected > 30 && shadow > 30, "reflected {reflected}, shadow {shadow}");
    assert!(count(&without, cyan) < 5 && count(&without, yellow) < 5, "nothing drawn without the step");
    // The explanation's window: egui's dark panel fill over the floor in the lower left.
    let dark = |image: &image::RgbaImage| {
        let region = crop(image, [20, 420, 500, 120]);
        region.pixels().filter(|p| p[0] < 40 && p[1] < 40 && p[2] < 40).count() as f32 / (500.0 * 120.0)
    };
    assert!(dark(&with) > 0.6 && dark(&without) < 0.3, "window fill {} vs {}", dark(&with), dark(&without));
}

/// The window taken away from outside, as a window manager or `xkill` does it: destroyed
/// (`xdotool windowclose`, an `XDestroyWindow`; twice, since the panic this guards against came
/// in one run of two) the viewer says so in one line and exits cleanly; its connection to the
/// display killed (`xdotool windowkill`, an `XKillClient`) it exits with Xlib's own line. Never a
/// panic, never a hang (each run is bounded by `timeout`).
///
/// Needs `xdotool` beside Xvfb (`apt-get install xdotool`; `.ci/run` does).
#[test]
fn a_window_taken_away_from_outside_ends_the_viewer_without_a_panic() {
    assert!(
        on_path("xvfb-run") && on_path("xdotool"),
        "this test needs xvfb-run and xdotool (`apt-get install xvfb xdotool`, as .ci/run does)"
    );
    let dir = scratch("window-gone");
    // The viewer in the background; once its window is up and has drawn for a while, the window
    // is taken away and the viewer waited for.
    let script = r#"
        "$0" view --size 800x450 & viewer=$!
        xdotool search --sync --onlyvisible --name '^Mirador$' > /dev/null
        sleep 3
        xdotool search --name '^Mirador$' "$1"
        wait "$viewer"
        echo "viewer exit status: $?"
    "#;
    for how in ["windowclose", "windowclose", "windowkill"] {
        let output = Command::new("timeout")
            .args(["120", "xvfb-run", "-a", "-s", "-screen 0 1280x720x24", "sh", "-c", script])
            .args([env!("CARGO_BIN_EXE_mirador"), how])
            .env("XDG_CONFIG_HOME", &dir)
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("running the viewer under Xvfb");
        let (stdout, stderr) = (String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
        let what = format!("{how}: status {:?}\nstdout: {stdout}\nstderr: {stderr}", output.status.code());
        assert!(output.status.code() != Some(124), "the viewer did not exit: {what}");
        assert!(!stderr.contains("panicked"), "the viewer panicked: {what}");
        let status = stdout.lines().find_map(|l| l.strip_prefix("viewer exit status: ")).unwrap_or("none");
        if how == "windowclose" {
            assert_eq!(status, "0", "a destroyed window ends the viewer cleanly: {what}");
            assert!(stderr.contains("the window was destroyed"), "and says so: {what}");
        } else {
            assert!(status != "none" && status != "101", "the display lost ends the viewer (101 is a panic): {what}");
        }
    }
}

/// Lab mode as a student meets it: the answer key drawn; a saved edit (a known mistake) redraws
/// the view; a broken edit shows its error over the view, at its line, with no input, and the
/// last good image stays; the difference view measures the mistake against the reference; a fix
/// brings back the first image.
#[test]
fn lab_mode_redraws_a_saved_edit_shows_a_broken_one_and_recovers() {
    use std::io::BufRead;
    let dir = scratch("lab");
    let lab_dir = dir.join("blend");
    let binary = env!("CARGO_BIN_EXE_mirador");
    let made = Command::new(binary).args(["lab", "new", "transparency"]).arg(&lab_dir).arg("--solution").output();
    assert!(made.expect("lab new").status.success());
    let file = lab_dir.join("transparency.wgsl");
    let key = std::fs::read_to_string(&file).expect("the answer key");
    let mistake = key.replace("return im + transmittance * behind;", "return im + behind;");
    let broken = key.replace("return im + transmittance * behind;", "return im + transmittance * behind");
    assert!(mistake != key && broken != key);
    let shot = |n: u32| dir.join(format!("s{n}.png"));
    // No frame times over the view: they change from one screenshot to the next.
    let mut steps = vec!["overlay off".to_owned()];
    for (n, wait, before) in [
        (1, "4s", None),
        (2, "5s", None),
        (3, "5s", None),
        (4, "4s", Some("lab difference")),
        (5, "5s", Some("lab student")),
    ] {
        steps.extend(before.map(str::to_owned));
        steps.push(format!("wait {wait}"));
        steps.push(format!("screenshot {}", shot(n).display()));
    }
    // The panel's Check button on the fixed file: every test passes, as `lab check` finds.
    steps.extend(["lab check".to_owned(), "wait checked".to_owned()]);
    assert!(on_path("xvfb-run"), "install Xvfb (`sudo apt-get install xvfb`) to run the viewer tests");
    let mut command = Command::new("xvfb-run");
    command.args(["-a", "-s", "-screen 0 1920x1080x24", binary, "view", "--lab"]).arg(&lab_dir);
    command.args(["--size", "640x400", "--frames", "2"]);
    for step in &steps {
        command.args(["--step", step]);
    }
    let mut child = command
        .env("XDG_CONFIG_HOME", &dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("starting the viewer");
    // Edit the file as each screenshot is written, as a student saving between looks.
    let stdout = std::io::BufReader::new(child.stdout.take().expect("the viewer's stdout"));
    let mut lines = Vec::new();
    for line in stdout.lines() {
        let line = line.expect("reading the viewer's output");
        let edit = match () {
            _ if line.starts_with(&format!("screenshot {}", shot(1).display())) => Some(&mistake),
            _ if line.starts_with(&format!("screenshot {}", shot(2).display())) => Some(&broken),
            _ if line.starts_with(&format!("screenshot {}", shot(4).display())) => Some(&key),
            _ => None,
        };
        if let Some(text) = edit {
            std::fs::write(&file, text).expect("saving the student's file");
        }
        lines.push(line);
    }
    let output = child.wait_with_output().expect("the viewer's end");
    let stdout = lines.join("\n");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success() && !stderr.contains("panicked"), "{stdout}\n{stderr}");

    let shots: Vec<image::RgbaImage> =
        (1..=5).map(|n| image::open(shot(n)).expect("each screenshot is written").to_rgba8()).collect();
    let rects = views_in(&stdout);
    let view = |n: usize| crop(&shots[n - 1], rects[n - 1].1);
    let error_fill = |image: &image::RgbaImage| {
        let [r, g, b, _] = mirador::viewer::ui::LAB_ERROR_FILL.to_array();
        image.pixels().filter(|p| p.0[..3] == [r, g, b]).count()
    };
    // A saved edit changes the image.
    let edited = common::difference(&view(1), &view(2)).flip_mean;
    assert!(edited > 0.02, "the saved mistake did not change the view (mean FLIP {edited}):\n{stdout}");
    // A broken edit: its error over the view, at its line, without a click; the mistake's image stays under it.
    let line = broken.lines().position(|l| l.contains("transmittance * behind")).unwrap() + 1;
    assert!(
        stdout.contains("does not compile") && stdout.contains(&format!("transparency.wgsl:{}:", line + 1)),
        "the broken edit's error should be reported at the line after the missing `;`:\n{stdout}"
    );
    assert!(error_fill(&shots[2]) > 2000, "no error box over the view:\n{stdout}");
    assert_eq!(error_fill(&shots[1]), 0, "an error box before the file broke");
    // The difference view measures the mistake against the reference.
    let mean: f32 = stdout
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("lab: difference against the reference, FLIP mean "))
        .and_then(|m| m.trim().parse().ok())
        .expect("the difference view reports its mean");
    assert!(mean > 0.02, "the mistake differs from the reference: mean {mean}");
    // The fix recovers the first image, the error gone.
    assert_eq!(error_fill(&shots[4]), 0, "the error box stayed after the fix");
    let recovered = common::difference(&view(1), &view(5)).flip_mean;
    assert!(recovered < 0.005, "the fixed file does not draw the first image (mean FLIP {recovered})");
    let lab = mirador::lab::find("transparency").expect("a built-in lab");
    let tests = lab.known_answers.len() + lab.images.len();
    let passed = format!("lab transparency: {0} / {0} points, {tests} of {tests} tests passed", lab_points(&lab));
    assert!(stdout.contains(&passed), "the panel's check of the fixed file: no `{passed}` in\n{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A lab's full marks, as the reports write them.
fn lab_points(lab: &mirador::lab::Lab) -> String {
    let total: f32 = lab.known_answers.iter().map(|t| t.points).chain(lab.images.iter().map(|t| t.points)).sum();
    mirador::lab::report::points(total)
}

/// Settings changed in one scene stay with it: the next scene opens with its own, the first
/// gets its changes back when opened again, and `reset settings` (the panel's reset) returns to
/// the scene file's own.
#[test]
fn settings_changed_in_one_scene_stay_with_it_and_reset_to_the_scenes_own() {
    let dir = scratch("per-scene");
    let text = std::fs::read_to_string(common::asset("scenes/shadows.toml")).expect("the shadows scene");
    let (a, b) = (dir.join("a.toml"), dir.join("b.toml"));
    std::fs::write(&a, &text).unwrap();
    std::fs::write(&b, &text).unwrap();
    let shot = |name: &str| dir.join(format!("{name}.png"));
    let steps = [
        "overlay off".to_string(),
        "set shadows.enabled=false".to_string(),
        "wait 2".to_string(),
        format!("load {}", b.display()),
        "wait 2".to_string(),
        format!("screenshot {}", shot("b").display()),
        format!("load {}", a.display()),
        "wait 2".to_string(),
        format!("screenshot {}", shot("a-again").display()),
        "reset settings".to_string(),
        "wait 2".to_string(),
        format!("screenshot {}", shot("a-reset").display()),
    ];
    let output = scripted(&a, &[], &steps, &dir);
    let view = |name: &str| view_in(&output, &shot(name));
    let headless = |shadows: bool, [_, _, w, h]: [u32; 4]| {
        let mut scene = Scene::load(&a).expect("the scene loads");
        scene.camera.width = w;
        scene.camera.height = h;
        scene.settings.shadows.enabled = shadows;
        let gpu = common::gpu();
        mirador::raster::render_image(gpu, &scene, &scene.settings)
    };
    let (b_view, rect) = view("b");
    let with_shadows = headless(true, rect);
    let without = headless(false, rect);
    assert!(common::difference(&with_shadows, &without).flip_mean > 0.01, "the scene must show its shadows");
    assert!(flip(&with_shadows, &b_view, "per-scene-b", &dir) < MAX_FLIP_MEAN, "b opened with a's change");
    let (a_view, _) = view("a-again");
    assert!(flip(&without, &a_view, "per-scene-a", &dir) < MAX_FLIP_MEAN, "a lost its change");
    let (reset, _) = view("a-reset");
    assert!(flip(&with_shadows, &reset, "per-scene-reset", &dir) < MAX_FLIP_MEAN, "reset kept the change");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A screenshot asked for right after the camera moves waits for the full-scale image: it is the
/// image the view settles on, not the low-resolution one drawn while moving.
#[test]
fn a_screenshot_after_a_move_waits_for_full_scale() {
    let dir = scratch("full-scale");
    let shot = |name: &str| dir.join(format!("{name}.png"));
    let steps = [
        "overlay off".to_string(),
        "fps off".to_string(),
        "scale 0.25".to_string(),
        "orbit 60 0".to_string(),
        format!("screenshot {}", shot("at-once").display()),
        "wait 1s".to_string(),
        format!("screenshot {}", shot("settled").display()),
    ];
    let output = scripted(&common::asset("scenes/seed-simple.toml"), &[], &steps, &dir);
    let view = |name: &str| view_in(&output, &shot(name)).0;
    let mean = flip(&view("settled"), &view("at-once"), "full-scale", &dir);
    assert!(mean < MAX_FLIP_MEAN, "the screenshot after the move was taken below full scale (mean FLIP {mean})");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--set` and the script's `set` reach the scene's own values in the viewer as they do in
/// `render`: the window shows what `render` draws with the same overrides, and a value the scene
/// file refuses is reported without a panic, the scene kept.
#[test]
fn scene_values_set_in_the_viewer_are_drawn_as_render_draws_them() {
    let dir = scratch("scene-values");
    let scene = common::asset("scenes/seed-simple.toml");
    let shot = dir.join("set.png");
    let steps = [
        "overlay off".to_string(),
        "set world.ambient=[0.6, 0.6, 0.6]".to_string(),
        "wait 2".to_string(),
        format!("screenshot {}", shot.display()),
    ];
    let output = scripted(&scene, &["--set", "camera.fovy=30"], &steps, &dir);
    let (window, rect) = view_in(&output, &shot);
    let headless = |overrides: &[&str]| {
        let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        let mut scene = mirador::scene::file::overrides::load(&scene, &overrides).expect("the overrides apply");
        (scene.camera.width, scene.camera.height) = (rect[2], rect[3]);
        mirador::raster::render_image(common::gpu(), &scene, &scene.settings)
    };
    let set = headless(&["camera.fovy=30", "world.ambient=[0.6, 0.6, 0.6]"]);
    assert!(flip(&set, &window, "scene-values", &dir) < MAX_FLIP_MEAN, "the window is not `render` with the overrides");
    assert!(common::difference(&headless(&[]), &window).flip_mean > 0.02, "the overrides changed nothing");
    // A value the file refuses ends a scripted run with the file's own message.
    let scene_arg = scene.to_str().unwrap();
    let refused = viewer(&[scene_arg, "--frames", "2", "--step", "set lights.9.intensity=1"], &dir);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success() && stderr.contains("lights.9"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}
