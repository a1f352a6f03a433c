//! The hybrid's traced terms (`mirador::trace::terms`) against the tracer's own image, on the CPU
//! alone, in the same run: the showcase's main view at 1280×720, its traced colour alone, the
//! visibility of its two lights alone, that with the lights term (the lights without a shadow map:
//! none here), and `Tracer::render` of the whole image (every ray of every kind).
//!
//! `cargo bench --bench hybrid`; prints the median of five runs, the rays and the rate of each.

use std::time::{Duration, Instant};

use mirador::settings::{Traced, TracedSet};
use mirador::trace::terms::{TermsLayout, ViewRays};
use mirador::trace::{RenderControl, Tracer, primary_cone};

const RUNS: usize = 5;

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

fn main() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/showcase.toml");
    let scene = mirador::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let tracer = Tracer::new(&scene, &scene.settings);
    // The main view's rays as the hybrid makes them (`raster::traced`): the camera's frame and
    // window worked out once.
    let rays = scene.camera.rays();
    let ray = move |x: f32, y: f32| Some((rays.through(x, y), 0.0));
    let size = (scene.camera.width, scene.camera.height);
    let lights: Vec<usize> = (0..scene.lights.len()).collect();
    let view = ViewRays {
        size,
        window: [0, 0, size.0, size.1],
        ray: &ray,
        cone: primary_cone(&scene.camera),
        skip: None,
        lights: &lights,
        stride: 1,
    };
    println!("showcase, {}×{}, {} threads", size.0, size.1, rayon::current_num_threads());
    let rate = |name: &str, run: &mut dyn FnMut() -> u64| {
        let mut rays = 0;
        let times = (0..RUNS)
            .map(|_| {
                let start = Instant::now();
                rays = run();
                start.elapsed()
            })
            .collect();
        let time = median(times);
        let mrays = rays as f64 / time.as_secs_f64() / 1e6;
        println!("{name:>34}: {:8.1} ms, {rays:>8} rays, {mrays:5.2} Mrays/s", time.as_secs_f64() * 1e3);
        time
    };
    // Into rows kept from one run to the next, as the hybrid traces a view's terms.
    let mut rows = Vec::new();
    let mut terms = |wanted: &[Traced]| {
        let wanted = TracedSet::of(wanted);
        let layout = TermsLayout::new(&view, wanted);
        rows.resize(rows.len().max(layout.pixels()), [0.0; 4]);
        tracer.terms_into(&view, wanted, &layout, &mut rows).total()
    };
    let colour = rate("terms: colour", &mut || terms(&[Traced::Textures]));
    let visibility = rate("terms: visibility", &mut || terms(&[Traced::Shadows]));
    // The showcase's two lights both have shadow maps: the lights term has no light to add.
    let other_lights = rate("terms: visibility, other lights", &mut || terms(&[Traced::Shadows, Traced::Lights]));
    let render = rate("Tracer::render (the whole image)", &mut || {
        let (_, stats) = tracer.render(&RenderControl::default()).expect("nothing cancels it");
        stats.rays.total()
    });
    let ratio = |t: Duration| t.as_secs_f64() / render.as_secs_f64();
    println!(
        "time / render's: colour {:.2}, visibility {:.2}, visibility and other lights {:.2}",
        ratio(colour),
        ratio(visibility),
        ratio(other_lights)
    );
}
