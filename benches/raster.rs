//! Rasterizer benchmark: what shadows cost. Run with `cargo bench --bench raster`.
//!
//! 1. Frame time of the showcase at 1280×720 with 1, 2 and 4 shadowed lights, each against the
//!    same lights with shadows off, measured in the same run: the ratio is the shadows' cost.
//! 2. The cost of bump mapping: the showcase and the bump scene with it off and on.
//! 3. Pass 1 alone (one spot light's depth map) at 1024² and 4096².
//!
//! Times are wall-clock from submit to the queue being idle (the median of several frames after
//! warm-up), so they include the driver's work on the CPU: on lavapipe that is all of it.

use std::time::{Duration, Instant};

use glam::Vec3;
use mirador::gpu::Gpu;
use mirador::gpu::texture::GpuTexture;
use mirador::raster::shadow::views::shadow_layout;
use mirador::raster::{OUTPUT_FORMAT, Renderer};
use mirador::scene::{Attenuation, Light, LightKind};
use mirador::{RenderSettings, Scene};

const FRAMES: usize = 7;

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
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

/// The median frame time of `scene` with `settings`.
fn frame_time(gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> Duration {
    let mut renderer = Renderer::new(&gpu.device, OUTPUT_FORMAT);
    let mut scene_gpu = renderer.upload(gpu, scene);
    let size = (scene.camera.width, scene.camera.height);
    let targets = renderer.targets(&gpu.device, size);
    let output = GpuTexture::target(&gpu.device, "bench::output", size, OUTPUT_FORMAT);
    let mut times = Vec::new();
    for frame in 0..FRAMES + 2 {
        let start = Instant::now();
        renderer.render(gpu, scene, &mut scene_gpu, settings, &targets, &output.view);
        gpu.wait();
        if frame >= 2 {
            times.push(start.elapsed());
        }
    }
    median(times)
}

/// The median time of pass 1 alone for `scene`'s lights.
fn shadow_pass_time(gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> Duration {
    let mut renderer = Renderer::new(&gpu.device, OUTPUT_FORMAT);
    let scene_gpu = renderer.upload(gpu, scene);
    let layout = shadow_layout(scene, &settings.shadows);
    renderer.shadow.prepare(&gpu.device, &gpu.queue, &layout, &settings.shadows, scene_gpu.has_transparent());
    let mut times = Vec::new();
    for frame in 0..FRAMES + 2 {
        let start = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        renderer.shadow.record(&mut encoder, &scene_gpu, &layout);
        gpu.queue.submit([encoder.finish()]);
        gpu.wait();
        if frame >= 2 {
            times.push(start.elapsed());
        }
    }
    median(times)
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    let gpu = Gpu::headless().expect("the benchmark needs a graphics adapter");
    println!("adapter: {}", gpu.describe());
    let showcase = Scene::showcase().expect("the built-in showcase loads");
    let extra = [spot("spot A", Vec3::new(-3.0, 4.0, 4.0)), spot("spot B", Vec3::new(3.0, 3.5, -3.0))];
    // The showcase's point light (six map layers) and directional light (one), then two spots.
    let all: Vec<Light> = showcase.lights.iter().cloned().chain(extra).collect();

    println!("\nshowcase, 1280×720, median of {FRAMES} frames");
    println!("{:>8} {:>7} {:>14} {:>13} {:>7}", "lights", "layers", "shadows off", "shadows on", "ratio");
    for count in [1, 2, 4] {
        let mut scene = showcase.clone();
        scene.lights = all[..count].to_vec();
        let on = scene.settings.clone();
        let mut off = on.clone();
        off.shadows.enabled = false;
        let layers = shadow_layout(&scene, &on.shadows).views.len();
        let (t_off, t_on) = (frame_time(&gpu, &scene, &off), frame_time(&gpu, &scene, &on));
        println!(
            "{count:>8} {layers:>7} {:>11.1} ms {:>10.1} ms {:>6.2}×",
            ms(t_off),
            ms(t_on),
            t_on.as_secs_f64() / t_off.as_secs_f64()
        );
    }

    println!("\nbump mapping at 1280×720, median of {FRAMES} frames");
    for name in ["showcase.toml", "bumps.toml"] {
        let mut scene = Scene::load(&mirador::scene::builtin_path(name)).expect("a built-in scene loads");
        (scene.camera.width, scene.camera.height) = (1280, 720);
        let on = scene.settings.clone();
        let mut off = on.clone();
        off.bump.enabled = false;
        let (t_off, t_on) = (frame_time(&gpu, &scene, &off), frame_time(&gpu, &scene, &on));
        println!(
            "{name:>14}: off {:>7.1} ms, on {:>7.1} ms, {:.2}×",
            ms(t_off),
            ms(t_on),
            t_on.as_secs_f64() / t_off.as_secs_f64()
        );
    }

    println!("\npass 1 for one spot light (one layer), showcase geometry, median of {FRAMES}");
    let mut scene = showcase.clone();
    scene.lights = vec![spot("spot", Vec3::new(-3.0, 4.0, 4.0))];
    let mut base = None;
    for size in [1024, 4096] {
        let mut settings = scene.settings.clone();
        settings.shadows.map_size = size;
        let t = shadow_pass_time(&gpu, &scene, &settings);
        let ratio = base.map_or(1.0, |b: Duration| t.as_secs_f64() / b.as_secs_f64());
        base.get_or_insert(t);
        println!("{:>6}²: {:>8.2} ms  ({ratio:.2}× the 1024² pass)", size, ms(t));
    }
}
