//! Rasterizer benchmark: where a frame's time goes, and how the frame scales with the scene. Run
//! with `cargo bench --bench raster` (`-- --quick` skips the largest scenes; `-- transparency`
//! or any other section's name runs that section alone).
//!
//! 1. The showcase at 1280×720: the flat-colour floor (every surface in its material's colour, the
//!    least this GPU can do with that geometry), everything off, each technique alone, all on, and
//!    a camera-only change with the shadow maps kept; each as a ratio to the floor.
//! 2. What shadows cost for 1, 2 and 4 shadowed lights, and pass 1 alone at two map sizes.
//! 3. Transparency (`assets/scenes/transparency.toml` with more glass spheres, over a thousand
//!    transparent triangles): each drawing order as a ratio to the frame that draws the same
//!    surfaces opaque; the CPU sort per frame while the camera moves; the cost of each peeled
//!    layer.
//! 4. Planar mirrors (`assets/scenes/mirrors.toml`): one mirror, two facing mirrors at depths 1
//!    to 4, each as a ratio to the frame with mirrors off, and the cost of each mirrored view.
//! 5. Environment maps (`assets/scenes/environment.toml`, two curved mirrors): the frame with
//!    each lookup (world cube, lat–long, sphere map, dynamic cubes kept) as a ratio to the frame
//!    without lookups; a dynamic capture (six views per object) drawn every frame, and a sphere
//!    map made every frame for a turning camera, as ratios to one plain frame.
//! 6. Refraction, Fresnel and local cubes (`assets/scenes/refraction.toml`: a glass ball and a
//!    chrome ball): each refraction choice, with and without Fresnel, and each parallax proxy, as
//!    ratios to the frame with the course's straight rays; the glass's cube drawn every frame.
//! 7. Volumes: samples per second of the GPU ray-marching pass and of the tracer on a 256³ grid
//!    at 1280×720, with and without early termination, and the grid's memory on each side.
//! 8. Scenes that grow: Haines' sphereflake at sizes 2 to 4 (91 to 7,381 spheres) and a mesh of
//!    about a million triangles: upload, frame, triangles, beside `trace` of the same scene.
//! 9. The hybrid (`-- hybrid`): the showcase with its four per-pixel terms traced, still and
//!    with the camera turning (traced at every pixel, and at one in 16 as the viewer traces a
//!    moving view), as ratios to the plain frame still and turning.
//! 10. Displacement (`-- displacement`): the cobbled ball at 1280×720, bump-mapped, displaced with
//!     the tracer's uniform mesh, and tessellated on the GPU for the view at several edge lengths,
//!     still and turning (made again every frame), as ratios to the bump-mapped frame; the
//!     triangles and the buffers' memory of each; the tracer on the displaced ball against the
//!     bump-mapped one.
//!
//! Times are wall-clock from submit to the queue being idle (the median of several frames after
//! warm-up), so they include the driver's work on the CPU: on lavapipe that is all of it.

use std::time::{Duration, Instant};

use glam::Vec3;
use mirador::gpu::Gpu;
use mirador::gpu::texture::GpuTexture;
use mirador::raster::{Figure, FrameReport, FrameTargets, OUTPUT_FORMAT, Renderer, drawn_size};
use mirador::scene::sphereflake::{sphere_count, sphereflake_toml};
use mirador::scene::{Attenuation, Light, LightKind, Mesh, Object, Shape};
use mirador::settings::{
    EnvironmentMap, Parallax, Prepass, Refraction, ShadowFit, SphereView, TransparencySort, VolumeGradient,
};
use mirador::trace::whitted::RayCounts;
use mirador::trace::{RenderControl, Tracer};
use mirador::{RenderSettings, Scene};

const FRAMES: usize = 9;

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A renderer with `scene` loaded, ready to draw frames.
struct Bench<'g> {
    gpu: &'g Gpu,
    renderer: Renderer,
    targets: FrameTargets,
    output: GpuTexture,
}

impl<'g> Bench<'g> {
    fn new(gpu: &'g Gpu, scene: &Scene) -> Bench<'g> {
        let renderer = Renderer::new(gpu, scene, OUTPUT_FORMAT);
        let size = (scene.camera.width, scene.camera.height);
        let targets = FrameTargets::new(&gpu.device, drawn_size(size, scene.settings.raster.render_scale));
        let output = GpuTexture::target(&gpu.device, "bench::output", size, OUTPUT_FORMAT);
        Bench { gpu, renderer, targets, output }
    }

    fn frame(&mut self, scene: &Scene, settings: &RenderSettings) -> (Duration, FrameReport) {
        let start = Instant::now();
        let report = self.renderer.render(self.gpu, scene, settings, &mut self.targets, &self.output.view);
        self.gpu.wait();
        (start.elapsed(), report)
    }

    /// The median frame time after two warm-up frames (which compile the shader variants and
    /// fill the caches).
    fn median_frame(&mut self, scene: &Scene, settings: &RenderSettings) -> Duration {
        let times = (0..FRAMES + 2).map(|_| self.frame(scene, settings).0).skip(2).collect();
        median(times)
    }
}

fn frame_time(gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> Duration {
    Bench::new(gpu, scene).median_frame(scene, settings)
}

/// The showcase with every technique switched off: no shadows, no bumps, no mip filtering.
fn everything_off(base: &RenderSettings) -> RenderSettings {
    let mut s = base.clone();
    s.shadows.enabled = false;
    s.bump.enabled = false;
    s.textures.filter = mirador::settings::TextureFilter::Bilinear;
    s
}

fn showcase_breakdown(gpu: &Gpu) {
    let scene = Scene::showcase().expect("the built-in showcase loads");
    let all = scene.settings.clone();
    let off = everything_off(&all);
    let mut flat = all.clone();
    flat.raster.flat_colour = true;
    let floor = frame_time(gpu, &scene, &flat);
    println!("showcase, 1280×720, median of {FRAMES} frames, ratios to the flat-colour floor");
    let row = |name: &str, t: Duration| {
        println!("{name:>44} {:>9.1} ms {:>7.2}×", ms(t), t.as_secs_f64() / floor.as_secs_f64())
    };
    row("flat colour (the floor)", floor);
    row("everything off (illumination model only)", frame_time(gpu, &scene, &off));
    let mut alone = off.clone();
    alone.textures.filter = all.textures.filter;
    row("+ trilinear mipmaps alone", frame_time(gpu, &scene, &alone));
    let mut alone = off.clone();
    alone.bump.enabled = true;
    row("+ bump mapping alone", frame_time(gpu, &scene, &alone));
    let mut alone = off.clone();
    alone.shadows.enabled = true;
    row("+ shadow maps alone (kept across frames)", frame_time(gpu, &scene, &alone));
    row("all on (kept shadow maps)", frame_time(gpu, &scene, &all));
    let mut no_cache = all.clone();
    no_cache.shadows.cache = false;
    row("all on, shadow maps redrawn every frame", frame_time(gpu, &scene, &no_cache));
    let mut never = all.clone();
    never.raster.depth_prepass = Prepass::Never;
    row("all on, no depth prepass", frame_time(gpu, &scene, &never));
    let mut half = all.clone();
    half.raster.render_scale = 0.5;
    row("all on, render scale 0.5", frame_time(gpu, &scene, &half));

    // A camera-only change: the point light's six layers are kept; the directional light's one
    // layer follows the view frustum (fit = "view") and is redrawn, unless it is fitted to the
    // scene.
    for fit in [ShadowFit::View, ShadowFit::Scene] {
        let mut settings = all.clone();
        settings.shadows.fit = fit;
        let mut bench = Bench::new(gpu, &scene);
        let mut moving = scene.clone();
        bench.median_frame(&moving, &settings);
        let mut times = Vec::new();
        let mut redrawn = 0;
        for step in 0..FRAMES {
            let angle = 0.01 * (step + 1) as f32;
            moving.camera.eye = glam::Quat::from_rotation_y(angle) * scene.camera.eye;
            let (t, report) = bench.frame(&moving, &settings);
            times.push(t);
            redrawn += report.count("shadow maps", "layers drawn");
        }
        let t = median(times);
        row(&format!("all on, camera orbiting, fit {fit:?} ({redrawn} layers redrawn)"), t);
    }

    let traced = trace_time(&scene);
    let raster = frame_time(gpu, &scene, &all);
    println!(
        "{:>44} {:>9.1} ms   raster is {:.2}× faster",
        "trace (1 ray per pixel centre, 2 threads)",
        ms(traced),
        traced.as_secs_f64() / raster.as_secs_f64()
    );
}

fn spot(name: &str, position: Vec3) -> Light {
    Light {
        name: name.into(),
        kind: LightKind::Spot {
            position,
            direction: (Vec3::new(0.0, 0.5, 0.0) - position).normalize(),
            inner: 25f32.to_radians(),
            outer: 35f32.to_radians(),
        },
        color: Vec3::ONE,
        intensity: 0.4,
        attenuation: Attenuation::None,
    }
}

fn shadow_costs(gpu: &Gpu) {
    let showcase = Scene::showcase().expect("the built-in showcase loads");
    let extra = [spot("spot A", Vec3::new(-3.0, 4.0, 4.0)), spot("spot B", Vec3::new(3.0, 3.5, -3.0))];
    let all: Vec<Light> = showcase.lights.iter().cloned().chain(extra).collect();
    println!("\nshadows at 1280×720, median of {FRAMES} frames (kept maps; redrawn maps in the last column)");
    println!("{:>8} {:>14} {:>13} {:>7} {:>15}", "lights", "shadows off", "shadows on", "ratio", "maps redrawn");
    for count in [1, 2, 4] {
        let mut scene = showcase.clone();
        scene.lights = all[..count].to_vec();
        let on = scene.settings.clone();
        let mut off = on.clone();
        off.shadows.enabled = false;
        let mut redrawn = on.clone();
        redrawn.shadows.cache = false;
        let (t_off, t_on, t_redrawn) =
            (frame_time(gpu, &scene, &off), frame_time(gpu, &scene, &on), frame_time(gpu, &scene, &redrawn));
        println!(
            "{count:>8} {:>11.1} ms {:>10.1} ms {:>6.2}× {:>12.1} ms",
            ms(t_off),
            ms(t_on),
            t_on.as_secs_f64() / t_off.as_secs_f64(),
            ms(t_redrawn)
        );
    }
}

fn trace_time(scene: &Scene) -> Duration {
    let start = Instant::now();
    let tracer = Tracer::new(scene, &scene.settings);
    tracer.render(&RenderControl::default()).expect("nothing cancels the benchmark");
    start.elapsed()
}

/// A sphere displaced into a bumpy mesh of about `triangles` triangles, as a scene's only mesh.
fn million_triangle_scene() -> Scene {
    let mut scene = Scene::showcase().expect("the built-in showcase loads");
    let mut mesh = Mesh::sphere(Vec3::ZERO, 1.0, 1024);
    for (p, n) in mesh.positions.iter_mut().zip(&mesh.normals) {
        let bump = 0.03 * ((13.0 * p.x).sin() * (11.0 * p.y).sin() * (7.0 * p.z).cos());
        *p += *n * bump;
    }
    mesh.compute_normals();
    scene.meshes.push(mesh);
    let material = scene.objects.iter().find(|o| o.name == "shiny sphere").expect("the showcase has it").material;
    scene.objects.retain(|o| o.name == "floor");
    scene.objects.push(Object {
        name: "bumpy mesh".into(),
        shape: Shape::Mesh(scene.meshes.len() - 1),
        material,
        world_from_local: glam::Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0)),
    });
    scene
}

fn growing_scenes(gpu: &Gpu, quick: bool) {
    println!("\nscenes that grow, 1280×720, all techniques on, median of {FRAMES} frames (kept shadow maps)");
    println!(
        "{:>22} {:>9} {:>11} {:>13} {:>11} {:>11} {:>10}",
        "scene", "objects", "triangles", "first frame", "frame", "trace", "trace/raster"
    );
    println!("{:>22} (first frame: load, upload, tessellation, shader compilation and shadow maps)", "");
    let mut scenes: Vec<(String, Scene)> = Vec::new();
    for size in if quick { 2..=3 } else { 2..=4 } {
        let path = std::path::PathBuf::from(format!("sphereflake-{size}.toml"));
        let scene =
            mirador::scene::file::parse(&sphereflake_toml(size, 1280, 720), &path).expect("a sphereflake parses");
        assert_eq!(scene.objects.len() as u64, sphere_count(size) + 1);
        scenes.push((format!("sphereflake {size}"), scene));
    }
    if !quick {
        scenes.push(("1M-triangle mesh".into(), million_triangle_scene()));
    }
    for (name, scene) in &scenes {
        let start = Instant::now();
        let mut bench = Bench::new(gpu, scene);
        bench.frame(scene, &scene.settings);
        let first = start.elapsed();
        let frame = bench.median_frame(scene, &scene.settings);
        let (_, report) = bench.frame(scene, &scene.settings);
        let traced = trace_time(scene);
        println!(
            "{name:>22} {:>9} {:>11} {:>10.1} ms {:>8.1} ms {:>8.1} ms {:>9.2}×",
            scene.objects.len(),
            report.triangles,
            ms(first),
            ms(frame),
            ms(traced),
            traced.as_secs_f64() / frame.as_secs_f64()
        );
    }
}

fn transparency_costs(gpu: &Gpu) {
    let mut scene = Scene::load(&mirador::scene::builtin_path("transparency.toml")).expect("the transparency scene");
    scene.camera.width = 1280;
    scene.camera.height = 720;
    let glass = scene.objects.iter().find(|o| o.name == "glass sphere").expect("a glass sphere").clone();
    for i in 0..6 {
        let mut sphere = glass.clone();
        sphere.name = format!("glass sphere {i}");
        sphere.shape = Shape::Sphere { center: Vec3::new(-2.5 + i as f32, 0.35, 1.6), radius: 0.3 };
        scene.objects.push(sphere);
    }
    // A fixed tessellation: the moving camera below must change the order, not the meshes.
    scene.settings.sphere_segments = 32;
    let mut base = scene.settings.clone();
    base.raster.adaptive_tessellation = false;
    let mut opaque = base.clone();
    opaque.transparency.enabled = false;
    let mut bench = Bench::new(gpu, &scene);
    let floor = bench.median_frame(&scene, &opaque);
    bench.frame(&scene, &base);
    let transparent = bench.renderer.scene_gpu().geometry.transparent_triangles();
    println!(
        "\ntransparency, 1280×720, {transparent} transparent triangles in {} objects, ratios to drawing them opaque",
        bench.renderer.scene_gpu().geometry.transparent.len()
    );
    let row = |name: &str, t: Duration| {
        println!("{name:>44} {:>9.1} ms {:>7.2}×", ms(t), t.as_secs_f64() / floor.as_secs_f64())
    };
    row("drawn opaque (transparency off)", floor);
    let with = |sort: TransparencySort, layers: u32| {
        let mut s = base.clone();
        s.transparency.sort = sort;
        s.transparency.peel_layers = layers;
        s
    };
    row("unsorted", bench.median_frame(&scene, &with(TransparencySort::Unsorted, 1)));
    row("per object", bench.median_frame(&scene, &with(TransparencySort::Object, 1)));
    row("per triangle, still camera (sorted once)", bench.median_frame(&scene, &with(TransparencySort::Triangle, 1)));
    // A moving camera re-sorts every frame.
    let settings = with(TransparencySort::Triangle, 1);
    let mut moving = scene.clone();
    let (mut times, mut sorts) = (Vec::new(), Vec::new());
    for step in 0..FRAMES + 2 {
        moving.camera.eye = glam::Quat::from_rotation_y(0.01 * (step + 1) as f32) * scene.camera.eye;
        let (t, report) = bench.frame(&moving, &settings);
        assert!(report.flag("transparency sort", "sorted"), "a moved camera re-sorts");
        times.push(t);
        let sort_time = match report.figure("transparency sort", "sort time") {
            Some(Figure::Time(time)) => time,
            _ => Duration::ZERO,
        };
        sorts.push(sort_time);
    }
    let sort = median(sorts.split_off(2));
    row("per triangle, moving camera (re-sorted)", median(times.split_off(2)));
    println!("{:>44} {:>9.3} ms (CPU, median)", "  of which the sort of every triangle", ms(sort));
    let mut peeled = Vec::new();
    for layers in [1, 2, 4, 8] {
        let t = bench.median_frame(&scene, &with(TransparencySort::Exact, layers));
        row(&format!("exact, {layers} peeled layers"), t);
        peeled.push((layers, t));
    }
    let (first, last) = (peeled[0], peeled[peeled.len() - 1]);
    let per_layer = (last.1.as_secs_f64() - first.1.as_secs_f64()) / f64::from(last.0 - first.0);
    println!(
        "{:>44} {:>9.1} ms {:>7.2}× per layer",
        "each further peeled layer",
        per_layer * 1e3,
        per_layer / floor.as_secs_f64()
    );
}

fn mirror_costs(gpu: &Gpu) {
    let mut scene = Scene::load(&mirador::scene::builtin_path("mirrors.toml")).expect("the mirrors scene");
    scene.camera.width = 1280;
    scene.camera.height = 720;
    let mut one = scene.clone();
    let right = one.objects.iter().position(|o| o.name == "right mirror").expect("the right mirror");
    let matte = one.materials.iter().position(|m| m.name == "frame").expect("the frame material");
    one.objects[right].material = mirador::base::MaterialId(matte);
    let with = |scene: &Scene, enabled: bool, depth: u32| {
        let mut settings = scene.settings.clone();
        settings.mirrors.enabled = enabled;
        settings.mirrors.depth = depth;
        settings
    };
    let mut cases = vec![
        ("mirrors off".to_string(), scene.clone(), with(&scene, false, 0)),
        ("one mirror".to_string(), one.clone(), with(&one, true, 3)),
    ];
    for depth in 1..=4 {
        cases.push((format!("two facing mirrors, depth {depth}"), scene.clone(), with(&scene, true, depth)));
    }
    // Frames of every case interleaved, round after round: this VM's speed drifts by tens of
    // percent over seconds, and interleaving spreads the drift over all cases alike.
    let mut benches: Vec<Bench> = cases.iter().map(|(_, scene, _)| Bench::new(gpu, scene)).collect();
    let mut times = vec![Vec::new(); cases.len()];
    let mut views = vec![0; cases.len()];
    for round in 0..FRAMES + 2 {
        for (k, (_, scene, settings)) in cases.iter().enumerate() {
            let (t, report) = benches[k].frame(scene, settings);
            views[k] = report.count("mirror views", "views");
            if round >= 2 {
                times[k].push(t);
            }
        }
    }
    let medians: Vec<Duration> = times.into_iter().map(median).collect();
    let plain = medians[0].as_secs_f64();
    println!("\nplanar mirrors, 1280×720, frames of every case interleaved, ratios to mirrors off");
    for (k, (name, ..)) in cases.iter().enumerate() {
        let t = medians[k].as_secs_f64();
        let each = if views[k] > 0 {
            format!("   {} views, {:.2}× a plain frame each", views[k], (t - plain) / plain / views[k] as f64)
        } else {
            String::new()
        };
        println!("{name:>44} {:>9.1} ms {:>7.2}×{each}", t * 1e3, t / plain);
    }
}

/// One case of an interleaved comparison: a name, the settings, and whether the camera turns a
/// little every frame.
struct EnvCase {
    name: &'static str,
    settings: RenderSettings,
    turning: bool,
}

fn environment_costs(gpu: &Gpu) {
    let mut scene = Scene::load(&mirador::scene::builtin_path("environment.toml")).expect("the environment scene");
    scene.camera.width = 1280;
    scene.camera.height = 720;
    let base = scene.settings.clone();
    let with = |f: &dyn Fn(&mut mirador::settings::EnvironmentSettings)| {
        let mut s = base.clone();
        f(&mut s.environment);
        s
    };
    let still = |name, settings| EnvCase { name, settings, turning: false };
    let turning = |name, settings| EnvCase { name, settings, turning: true };
    let cases = [
        still("no lookups (enabled = false)", with(&|e| e.enabled = false)),
        still("world cube", with(&|e| e.dynamic = false)),
        still("lat–long map", with(&|e| (e.map, e.dynamic) = (EnvironmentMap::Latlong, false))),
        still("sphere map (fixed)", with(&|e| (e.map, e.dynamic) = (EnvironmentMap::Sphere, false))),
        still("dynamic cubes, kept", with(&|e| e.dynamic = true)),
        still("dynamic cubes, drawn every frame", with(&|e| (e.dynamic, e.refresh) = (true, 1))),
        still("  the same at cube_size 128", with(&|e| (e.dynamic, e.refresh, e.cube_size) = (true, 1, 128))),
        still("  the same at cube_size 512", with(&|e| (e.dynamic, e.refresh, e.cube_size) = (true, 1, 512))),
        turning("sphere map (fixed), turning camera", with(&|e| (e.map, e.dynamic) = (EnvironmentMap::Sphere, false))),
        turning(
            "sphere map made every frame (follow), turning",
            with(&|e| (e.map, e.dynamic, e.sphere_view) = (EnvironmentMap::Sphere, false, SphereView::Follow)),
        ),
    ];
    // Interleaved rounds, as for the mirrors: the VM's speed drifts over seconds.
    let mut benches: Vec<Bench> = cases.iter().map(|_| Bench::new(gpu, &scene)).collect();
    let mut times = vec![Vec::new(); cases.len()];
    let mut faces = vec![0u64; cases.len()];
    let mut spheres = vec![0; cases.len()];
    for round in 0..FRAMES + 2 {
        let mut turned = scene.clone();
        turned.camera.eye = glam::Quat::from_rotation_y(0.02 * (round + 1) as f32) * scene.camera.eye;
        for (k, case) in cases.iter().enumerate() {
            let (t, report) = benches[k].frame(if case.turning { &turned } else { &scene }, &case.settings);
            if round >= 2 {
                times[k].push(t);
                faces[k] += report.count("environment cubes", "faces");
                spheres[k] += u32::from(report.flag("environment maps", "sphere map made"));
            }
        }
    }
    let medians: Vec<f64> = times.into_iter().map(|t| median(t).as_secs_f64()).collect();
    let plain = medians[0];
    println!(
        "\nenvironment maps, 1280×720, two curved mirrors, frames of every case interleaved, ratios to the frame \
         without lookups"
    );
    for (k, case) in cases.iter().enumerate() {
        let made = match (faces[k], spheres[k]) {
            (0, 0) => String::new(),
            (f, 0) => format!("   {} faces a frame", f as usize / FRAMES),
            (_, m) => format!("   sphere map made in {m} of {FRAMES} frames"),
        };
        println!("{:>48} {:>9.1} ms {:>7.2}×{made}", case.name, medians[k] * 1e3, medians[k] / plain);
    }
    let name = |n: &str| cases.iter().position(|c| c.name == n).expect("a case of that name");
    let capture = medians[name("dynamic cubes, drawn every frame")] - medians[name("dynamic cubes, kept")];
    let objects = faces[name("dynamic cubes, drawn every frame")] as f64 / FRAMES as f64 / 6.0;
    println!(
        "{:>48} {:>9.1} ms {:>7.2}× a plain frame",
        "one capture (six views of one object)",
        capture / objects * 1e3,
        capture / objects / plain
    );
    let sphere = medians[name("sphere map made every frame (follow), turning")]
        - medians[name("sphere map (fixed), turning camera")];
    println!("{:>48} {:>9.1} ms {:>7.2}× a plain frame", "one sphere-map generation", sphere * 1e3, sphere / plain);
}

/// Refraction, Fresnel and the parallax proxies on the refraction stage at 1280×720: each case's
/// frames interleaved with the others' (the VM's speed drifts over seconds), as ratios to the
/// frame with straight rays and no Fresnel.
fn refraction_costs(gpu: &Gpu) {
    let mut scene = Scene::load(&mirador::scene::builtin_path("refraction.toml")).expect("the refraction scene");
    scene.camera.width = 1280;
    scene.camera.height = 720;
    let base = scene.settings.clone();
    let case = |refraction, fresnel, parallax, refresh| {
        let mut s = base.clone();
        s.transparency.refraction = refraction;
        s.terms.fresnel = fresnel;
        s.environment.parallax = parallax;
        s.environment.refresh = refresh;
        s
    };
    let cases = [
        ("straight rays (none)", case(Refraction::None, false, Parallax::Infinite, 0)),
        ("straight rays, Fresnel (two draws)", case(Refraction::None, true, Parallax::Infinite, 0)),
        ("environment", case(Refraction::Environment, false, Parallax::Infinite, 0)),
        ("environment, Fresnel", case(Refraction::Environment, true, Parallax::Infinite, 0)),
        ("screen", case(Refraction::Screen, false, Parallax::Infinite, 0)),
        ("screen, Fresnel", case(Refraction::Screen, true, Parallax::Infinite, 0)),
        ("parallax ground (straight rays)", case(Refraction::None, false, Parallax::Ground, 0)),
        ("parallax box (straight rays)", case(Refraction::None, false, Parallax::Box, 0)),
        ("environment, cubes drawn every frame", case(Refraction::Environment, false, Parallax::Infinite, 1)),
    ];
    let mut benches: Vec<Bench> = cases.iter().map(|_| Bench::new(gpu, &scene)).collect();
    let mut times = vec![Vec::new(); cases.len()];
    for round in 0..FRAMES + 2 {
        for (k, (_, settings)) in cases.iter().enumerate() {
            let (t, _) = benches[k].frame(&scene, settings);
            if round >= 2 {
                times[k].push(t);
            }
        }
    }
    let medians: Vec<f64> = times.into_iter().map(|t| median(t).as_secs_f64()).collect();
    println!("\nrefraction, 1280×720, a glass ball and a chrome ball, ratios to the frame with straight rays");
    for (k, (name, _)) in cases.iter().enumerate() {
        println!("{name:>48} {:>9.1} ms {:>7.2}×", medians[k] * 1e3, medians[k] / medians[0]);
    }
}

/// The phantom on a 256³ grid (the `ct` preset), filling most of a 1280×720 frame.
const VOLUME_SCENE: &str = r#"
[camera]
eye = [1.0, 0.6, 3.0]
center = [0.0, 0.0, 0.0]
fovy = 40
width = 1280
height = 720

[world]
ambient = [0.25, 0.25, 0.28]

[[lights]]
name = "key"
type = "directional"
direction = [0.6, -0.8, 0.2]
intensity = 0.9

[[volumes]]
name = "phantom"
field = { type = "phantom", resolution = 256 }
range = [-1000, 1000]
preset = "ct"
"#;

/// Rounds of the volume comparison (three traces each round): a GPU frame of this volume takes
/// seconds on lavapipe.
const VOLUME_ROUNDS: usize = 3;

fn traced_counts(scene: &Scene, settings: &RenderSettings) -> (Duration, RayCounts) {
    let (_, stats) = Tracer::new(scene, settings).render(&RenderControl::default()).expect("nothing cancels it");
    (stats.elapsed, stats.rays)
}

fn volume_costs(gpu: &Gpu) {
    let start = Instant::now();
    let path = std::path::Path::new("volume-256.toml");
    let scene = mirador::scene::file::parse(VOLUME_SCENE, path).expect("the volume scene parses");
    let built = start.elapsed();
    let grid = &scene.volumes[0].grid;
    let voxels = grid.values.len() as u64;
    let termination = |on: bool| {
        let mut s = scene.settings.clone();
        s.volume.early_termination = on;
        s
    };
    let cases = [termination(true), termination(false)];
    // The samples of the full frame. Shading changes no opacity, so one unshaded trace with
    // termination counts both ways: taken, and taken + saved (what a march to the end takes).
    let mut unshaded = cases[0].clone();
    unshaded.volume.gradient = VolumeGradient::Off;
    let (_, full) = traced_counts(&scene, &unshaded);
    let full_samples = [full.volume_samples, full.volume_samples + full.volume_samples_saved];
    // The tracer at a quarter of the size each way: 1280×720 takes tens of seconds on 2 cores.
    let mut small = scene.clone();
    (small.camera.width, small.camera.height) = (320, 180);
    let mut bench = Bench::new(gpu, &scene);
    bench.renderer.profile = true;
    let (mut gpu_times, mut trace_times) = (vec![Vec::new(); 2], vec![Vec::new(); 2]);
    let mut trace_samples = [0; 2];
    // Interleaved rounds, GPU and tracer alike: the VM's speed drifts over seconds.
    for _ in 0..VOLUME_ROUNDS {
        for (k, settings) in cases.iter().enumerate() {
            let (_, report) = bench.frame(&scene, settings);
            let pass = report.time("volumes").expect("the volume pass ran, profiled");
            gpu_times[k].push(pass);
            // The tracer is quick: three traces a round make its median as steady as the GPU's.
            for _ in 0..3 {
                let (time, counts) = traced_counts(&small, settings);
                trace_times[k].push(time);
                trace_samples[k] = counts.volume_samples;
            }
        }
    }
    let gpu_times: Vec<f64> = gpu_times.into_iter().map(|t| median(t).as_secs_f64()).collect();
    let trace_times: Vec<f64> = trace_times.into_iter().map(|t| median(t).as_secs_f64()).collect();
    let mib = |bytes: u64| bytes as f64 / (1 << 20) as f64;
    let m = |n: f64| n / 1e6;
    let settings = &scene.settings.volume;
    println!(
        "\nvolumes: the phantom (ct preset) on a {}³ grid (built in {:.1} s), step {} voxels, {:?} reconstruction, \
         {:?} gradients, threshold {}; medians of {VOLUME_ROUNDS} interleaved rounds (GPU) and {} traces",
        grid.dims.x,
        built.as_secs_f64(),
        settings.step,
        settings.reconstruction,
        settings.gradient,
        settings.threshold,
        3 * VOLUME_ROUNDS
    );
    println!(
        "{:>44} {voxels} voxels: {:.1} MiB as f32 on the CPU, {:.1} MiB as R16Float on the GPU",
        "grid",
        mib(grid.bytes()),
        mib(2 * voxels)
    );
    println!(
        "{:>44} {:.1} M with early termination, {:.1} M without (counted by the tracer; the GPU pass marches the \
         same samples per pixel by construction)",
        "samples at 1280×720",
        m(full_samples[0] as f64),
        m(full_samples[1] as f64)
    );
    println!("{:>44} {:>11} {:>11} {:>13}", "", "time", "samples", "samples/s");
    let mut rates = [[0.0; 2]; 2];
    for (k, name) in ["on", "off"].iter().enumerate() {
        let rows = [
            (format!("GPU pass 1280×720, termination {name}"), gpu_times[k], full_samples[k]),
            (format!("tracer 320×180, termination {name}"), trace_times[k], trace_samples[k]),
        ];
        for (r, (label, time, samples)) in rows.iter().enumerate() {
            rates[r][k] = *samples as f64 / time;
            println!("{label:>44} {:>8.0} ms {:>9.1} M {:>9.1} M/s", time * 1e3, m(*samples as f64), m(rates[r][k]));
        }
    }
    println!(
        "{:>44} GPU {:.2}× the time, tracer {:.2}× the time; {:.2}× the samples",
        "early termination on / off",
        gpu_times[0] / gpu_times[1],
        trace_times[0] / trace_times[1],
        full_samples[0] as f64 / full_samples[1] as f64
    );
    println!(
        "{:>44} {:.2}× with termination, {:.2}× without",
        "samples/s, GPU / tracer",
        rates[0][0] / rates[1][0],
        rates[0][1] / rates[1][1]
    );
    println!("{:>44} {:.0} s (the grid, the count and the rounds)", "this section took", start.elapsed().as_secs_f64());
}

/// The hybrid with its four per-pixel terms traced (shadows, reflections, transmission,
/// textures) against the plain frame, the showcase at 1280×720: the view still (the terms kept
/// while nothing changes, `raster::traced::KeptTraced`) and moving (the camera turned a quarter
/// of a degree about the target every frame, so every view is traced again, as the plain frame
/// draws its views again), at every pixel and at one pixel in 16 (`Renderer::traced_stride`, as
/// the viewer draws a moving view). Each a median of [`FRAMES`] after two warm-up frames.
fn hybrid_costs(gpu: &Gpu) {
    let scene = Scene::showcase().expect("the built-in showcase loads");
    let plain = scene.settings.clone();
    let mut hybrid = plain.clone();
    for term in ["shadows", "reflections", "transmission", "textures"] {
        hybrid.set(&format!("hybrid.{term}=true")).expect("a hybrid switch");
    }
    let moving = |settings: &RenderSettings, stride: u32| {
        let mut scene = scene.clone();
        let mut bench = Bench::new(gpu, &scene);
        bench.renderer.traced_stride = stride;
        let times = (0..FRAMES + 2)
            .map(|_| {
                let (c, e) = (scene.camera.center, scene.camera.eye - scene.camera.center);
                scene.camera.eye =
                    c + glam::Quat::from_axis_angle(scene.camera.up.normalize(), 0.25f32.to_radians()) * e;
                bench.frame(&scene, settings).0
            })
            .skip(2)
            .collect();
        median(times)
    };
    println!("\nthe hybrid, showcase 1280×720, median of {FRAMES} frames, ratios to the plain frame");
    let (still, still_plain) = (frame_time(gpu, &scene, &hybrid), frame_time(gpu, &scene, &plain));
    let turning_plain = moving(&plain, 1);
    let (turning, coarse) = (moving(&hybrid, 1), moving(&hybrid, 4));
    let rows =
        [("still", still, still_plain), ("moving", turning, turning_plain), ("moving, 1 in 16", coarse, turning_plain)];
    for (name, frame, base) in rows {
        println!(
            "{name:>16}: plain {:>7.1} ms, all four traced {:>7.1} ms, {:>5.2}×",
            ms(base),
            ms(frame),
            frame.as_secs_f64() / base.as_secs_f64()
        );
    }
}

/// Displacement's cost, the cobbled ball at 1280×720 (see the header).
fn displacement_costs(gpu: &Gpu) {
    use mirador::settings::{BumpMethod, Tessellation};
    let path = mirador::scene::builtin_path("course/displacement-sphere.toml");
    let mut bumped = Scene::load(&path).expect("the displaced ball's scene loads");
    (bumped.camera.width, bumped.camera.height) = (1280, 720);
    let mut displaced = bumped.clone();
    displaced.settings.bump.method = BumpMethod::Displacement;
    mirador::texture::displacement::displace(&mut displaced);
    let turning = |scene: &Scene, settings: &RenderSettings| {
        let mut scene = scene.clone();
        let mut bench = Bench::new(gpu, &scene);
        let times = (0..FRAMES + 2)
            .map(|_| {
                let (c, e) = (scene.camera.center, scene.camera.eye - scene.camera.center);
                scene.camera.eye = c + glam::Quat::from_axis_angle(Vec3::Y, 0.5f32.to_radians()) * e;
                bench.frame(&scene, settings).0
            })
            .skip(2)
            .collect();
        median(times)
    };
    println!("\ndisplacement, the cobbled ball 1280×720, median of {FRAMES} frames, ratios to bump mapping's");
    let base = (frame_time(gpu, &bumped, &bumped.settings), turning(&bumped, &bumped.settings));
    let row = |name: &str, frames: (Duration, Duration), made: &str| {
        let ratio = |a: Duration, b: Duration| a.as_secs_f64() / b.as_secs_f64();
        println!(
            "{name:>22}: still {:>6.1} ms {:>5.2}×, turning {:>6.1} ms {:>5.2}×  {made}",
            ms(frames.0),
            ratio(frames.0, base.0),
            ms(frames.1),
            ratio(frames.1, base.1)
        );
    };
    row("bump mapping", base, "");
    let mut uniform = displaced.settings.clone();
    uniform.bump.tessellation = Tessellation::Uniform;
    let mesh = displaced.meshes.last().expect("the displaced mesh");
    let bytes = mesh.positions.len() * 48 + mesh.indices.len() * 4;
    let made = format!("{} triangles, {:.1} MB", mesh.indices.len() / 3, bytes as f64 / 1e6);
    row("uniform (the tracer's)", (frame_time(gpu, &displaced, &uniform), turning(&displaced, &uniform)), &made);
    for pixels in [16.0, 8.0, 4.0, 2.0, 1.0] {
        let mut adaptive = displaced.settings.clone();
        adaptive.bump.edge_pixels = pixels;
        let mut bench = Bench::new(gpu, &displaced);
        let still = bench.median_frame(&displaced, &adaptive);
        let report = bench.renderer.tessellation_report().expect("tessellated on the GPU").clone();
        let bytes = report.vertices * 48 + report.triangles * 12;
        let made =
            format!("{} triangles, finest split {}, {:.1} MB", report.triangles, report.finest, bytes as f64 / 1e6);
        row(&format!("adaptive, {pixels} px"), (still, turning(&displaced, &adaptive)), &made);
    }
    let (traced_bumped, traced_displaced) = (trace_time(&bumped), trace_time(&displaced));
    println!(
        "{:>22}: bump-mapped {:.0} ms, displaced {:.0} ms, {:.2}×",
        "the tracer",
        ms(traced_bumped),
        ms(traced_displaced),
        traced_displaced.as_secs_f64() / traced_bumped.as_secs_f64()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    // Section names on the command line run those sections alone:
    // `cargo bench --bench raster -- transparency`.
    const SECTIONS: [&str; 10] = [
        "showcase",
        "shadows",
        "transparency",
        "mirrors",
        "environment",
        "refraction",
        "volume",
        "growing",
        "hybrid",
        "displacement",
    ];
    let chosen: Vec<&str> = SECTIONS.into_iter().filter(|s| args.iter().any(|a| a == s)).collect();
    let run = |section: &str| chosen.is_empty() || chosen.contains(&section);
    let gpu = Gpu::headless().expect("the benchmark needs a graphics adapter");
    println!("adapter: {}\n", gpu.describe());
    if run("showcase") {
        showcase_breakdown(&gpu);
    }
    if run("shadows") {
        shadow_costs(&gpu);
    }
    if run("transparency") {
        transparency_costs(&gpu);
    }
    if run("mirrors") {
        mirror_costs(&gpu);
    }
    if run("environment") {
        environment_costs(&gpu);
    }
    if run("refraction") {
        refraction_costs(&gpu);
    }
    if run("volume") {
        volume_costs(&gpu);
    }
    if run("growing") {
        growing_scenes(&gpu, quick);
    }
    if run("hybrid") {
        hybrid_costs(&gpu);
    }
    if run("displacement") {
        displacement_costs(&gpu);
    }
}
