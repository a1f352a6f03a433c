//! The hybrid (`settings.hybrid`, `src/raster/traced/mod.rs`): with every approximation the rasterizer
//! makes swapped for its traced term, the raster frame is the tracer's image, up to what no swap
//! removes (primary visibility). Checked on every scene of `assets/scenes/` and its course, and
//! two-sided: each scene's plain raster frame must be measurably farther from the tracer wherever
//! the scene uses something the hybrid swaps, so a swap that did nothing would fail.

mod common;

use mirador::Scene;
use mirador::settings::{RenderSettings, Traced};

/// `scene` drawn at most `width` pixels wide, its aspect kept.
fn smaller(mut scene: Scene, width: u32) -> Scene {
    let camera = &mut scene.camera;
    if camera.width > width {
        camera.height = (camera.height * width).div_ceil(camera.width);
        camera.width = width;
    }
    scene
}

/// `settings` with every row of the approximations table traced.
fn every_term_traced(settings: &RenderSettings) -> RenderSettings {
    traced(settings, Traced::ALL)
}

/// `settings` with `terms` traced.
fn traced(settings: &RenderSettings, terms: &[Traced]) -> RenderSettings {
    let mut hybrid = settings.clone();
    for term in terms {
        *term.switch(&mut hybrid.hybrid) = true;
    }
    hybrid
}

#[test]
fn every_scene_with_every_term_traced_is_the_tracers_image() {
    let mut report = Vec::new();
    for path in common::scene_files() {
        let scene = smaller(Scene::load(&path).unwrap_or_else(|e| panic!("{e}")), 240);
        let traced = mirador::trace::render_image(&scene, &scene.settings);
        let hybrid = common::flip(&traced, &common::raster(&scene, &every_term_traced(&scene.settings)));
        let plain = common::flip(&traced, &common::raster(&scene, &scene.settings));
        let name = path.file_name().expect("a file").to_string_lossy().into_owned();
        eprintln!("{name:<36} raster {plain:.4}, every term traced {hybrid:.4}");
        report.push((name, plain, hybrid));
    }
    for (name, plain, hybrid) in &report {
        // Measured at most 0.0010 (the silhouettes of tessellated shapes), at 240 pixels wide;
        // the bound is 0.01.
        assert!(*hybrid < 0.003, "{name}: every term traced vs the tracer: FLIP {hybrid}");
        // Where nothing is swapped (volumes) the two are equal but for the shader variant, which
        // another CPU may round a level apart: a tenth of the bound of tolerance.
        assert!(
            *hybrid <= plain + 0.0003,
            "{name}: the hybrid {hybrid} is farther from the tracer than the raster {plain}"
        );
    }
    // The other side: where the approximations show, the swaps are what closes the gap.
    let shown = report.iter().filter(|(_, plain, hybrid)| *plain > 0.02 && *plain > 10.0 * hybrid).count();
    assert!(shown >= 5, "scenes whose raster frame the swaps bring from over 0.02 to a tenth: {shown}");
}

/// The viewer's coarse traced terms (`stride` > 1) are the full terms at one pixel of each block,
/// given to the whole block; refined to stride 1 they are every pixel's own.
#[test]
fn coarse_traced_terms_are_the_full_terms_of_each_blocks_first_pixel() {
    use mirador::settings::hybrid::SURFACE_LAYER;
    use mirador::settings::{Traced, TracedSet};
    use mirador::trace::terms::ViewRays;
    let scene = smaller(common::load("scenes/mirrors.toml"), 96);
    let tracer = mirador::trace::Tracer::new(&scene, &scene.settings);
    let camera = scene.camera.clone();
    let ray = move |x: f32, y: f32| Some((camera.ray_through(x, y), 0.0));
    let size = (scene.camera.width, scene.camera.height);
    let rays = |stride| ViewRays {
        size,
        window: [0, 0, size.0, size.1],
        ray: &ray,
        cone: mirador::trace::primary_cone(&scene.camera),
        skip: None,
        lights: &[0],
        stride,
    };
    let wanted = TracedSet::of(&[Traced::Shadows, Traced::Reflections, Traced::Textures]);
    let full = tracer.terms(&rays(1), wanted);
    let coarse = tracer.terms(&rays(4), wanted);
    let layer = |terms: &mirador::trace::terms::TracedTerms, layer: u32| terms.layer(layer).expect("traced").to_vec();
    let (surface, full_surface) = (layer(&coarse, SURFACE_LAYER), layer(&full, SURFACE_LAYER));
    let (shadows, full_shadows) = (layer(&coarse, Traced::Shadows.layer()), layer(&full, Traced::Shadows.layer()));
    let width = size.0 as usize;
    let mut differing = 0;
    for (i, (c, f)) in surface.iter().zip(&full_surface).enumerate() {
        let (x, y) = (i % width, i / width);
        let first = (y - y % 4) * width + (x - x % 4);
        assert_eq!(*c, full_surface[first], "pixel ({x}, {y}) holds its block's first pixel's terms");
        assert_eq!(shadows[i], full_shadows[first]);
        differing += usize::from(c != f);
    }
    // The other side: the coarse image is not the full one.
    assert!(differing > surface.len() / 10, "{differing} of {} pixels differ", surface.len());
    assert!(
        coarse.rays.primary * 10 < full.rays.primary,
        "{} against {} primary rays",
        coarse.rays.primary,
        full.rays.primary
    );
}

/// The lights past the fourth, traced (the approximations table's row added to show what a new
/// row costs: the row, the tracer's term, the shading's branch). The shadow scene with four point
/// lights more above it: the rasterizer shadows the key, the fill and the first two, and draws
/// the last two as if nothing stood in their way, so their light shows through the casters; with
/// the shadows and the lights past the fourth traced, the frame is the tracer's image again.
#[test]
fn the_lights_past_the_fourth_traced_cast_their_shadows() {
    let mut scene = smaller(common::load("scenes/shadows.toml"), 200);
    let key = scene.lights[0].clone();
    for (k, position) in [[-2.5, 4.0, 2.0], [2.5, 4.0, 2.0], [0.0, 4.5, -0.5], [3.5, 2.5, 3.0]].into_iter().enumerate()
    {
        let mut light = key.clone();
        light.name = format!("point {k}");
        light.kind = mirador::scene::LightKind::Point { position: position.into() };
        light.intensity = 0.12;
        scene.lights.push(light);
    }
    assert!((Traced::Lights.row().in_use)(&scene.facts(), &scene.settings), "six lights: the row is in use");
    let tracer = mirador::trace::render_image(&scene, &scene.settings);
    let flip = |terms: &[Traced]| common::flip(&tracer, &common::raster(&scene, &traced(&scene.settings, terms)));
    let (shadows, lights) = (flip(&[Traced::Shadows]), flip(&[Traced::Shadows, Traced::Lights]));
    eprintln!("shadows traced {shadows:.4}, and the lights past the fourth {lights:.4}");
    // Measured on lavapipe: see tests/README.md.
    assert!(lights < 0.003, "the lights past the fourth traced vs the tracer: FLIP {lights}");
    assert!(shadows > 4.0 * lights, "without the row the two unshadowed lights show: {shadows} against {lights}");
}

/// A frame drawn like the last one (the same scene, camera, lights, settings and views) keeps
/// its traced terms rather than tracing them again: no ray, no copy (the main view's image holds
/// them still), and the image a frame that traced them draws. A dimmer light, a moved camera or
/// another setting traces them anew, and copies them in: the image a fresh renderer draws.
#[test]
fn a_frame_like_the_last_keeps_its_traced_terms() {
    let gpu = common::gpu();
    let mut scene = smaller(common::load("scenes/showcase.toml"), 160);
    let settings = every_term_traced(&scene.settings);
    let mut headless = mirador::raster::Headless::new(gpu, &scene);
    let rays = |headless: &mirador::raster::Headless| headless.report.count("traced terms", "rays");
    headless.render(gpu, &scene, &settings);
    assert!(rays(&headless) > 0, "the first frame traces");
    // The second frame may draw other views (a cube's faces are drawn once, then kept); by the
    // third every view is one the last frame drew.
    headless.render(gpu, &scene, &settings);
    let kept = headless.render(gpu, &scene, &settings);
    assert_eq!(rays(&headless), 0, "a frame like the last traces nothing");
    assert!(headless.report.count("traced terms", "views kept") > 0);
    let copied = |headless: &mirador::raster::Headless| headless.report.count("traced terms", "views copied");
    assert_eq!(copied(&headless), 0, "a frame like the last copies nothing: its image holds the terms");
    // Traced again after another setting, then the first settings traced again: the same image.
    let mut other = settings.clone();
    other.exposure *= 0.5;
    headless.render(gpu, &scene, &other);
    assert!(rays(&headless) > 0, "another setting traces anew");
    let traced = headless.render(gpu, &scene, &settings);
    assert!(rays(&headless) > 0);
    assert_eq!(kept, traced, "kept terms draw the image traced terms draw");
    // The scene's own values: a light and the camera.
    scene.lights[0].intensity *= 0.5;
    let dimmer = headless.render(gpu, &scene, &settings);
    assert!(rays(&headless) > 0 && copied(&headless) > 0, "a dimmer light traces anew, and copies");
    let fresh = mirador::raster::Headless::new(gpu, &scene).render(gpu, &scene, &settings);
    assert_eq!(dimmer, fresh, "the terms traced anew are drawn, not the image's last");
    scene.camera.eye += glam::Vec3::new(0.1, 0.0, 0.0);
    headless.render(gpu, &scene, &settings);
    assert!(rays(&headless) > 0, "a moved camera traces anew");
}

/// The terms traced are a uniform of the frame, not a pipeline constant: the budget swaps each
/// term in turn, and each swap drew with shading variants of its own (72 made, about 50 ms each
/// on lavapipe, for the showcase's budget). Two-sided: each swap must still draw its own term
/// (an image unlike the others'), and the image a fresh renderer draws.
#[test]
fn swapping_a_traced_term_makes_no_new_shading_variant() {
    let gpu = common::gpu();
    let scene = smaller(common::load("scenes/showcase.toml"), 160);
    let mut headless = mirador::raster::Headless::new(gpu, &scene);
    let plain = headless.render(gpu, &scene, &scene.settings);
    let plain_variants = headless.renderer.shader_variants();
    let first = traced(&scene.settings, &[Traced::Shadows]);
    let mut images = vec![plain, headless.render(gpu, &scene, &first)];
    let variants = headless.renderer.shader_variants();
    assert!(variants > plain_variants, "a frame tracing a term draws with the hybrid's variants");
    let swaps = [&[Traced::Reflections][..], &[Traced::Transmission], &[Traced::Textures], Traced::ALL];
    for terms in swaps {
        let settings = traced(&scene.settings, terms);
        let image = headless.render(gpu, &scene, &settings);
        assert_eq!(headless.renderer.shader_variants(), variants, "{terms:?} traced made a new variant");
        let fresh = mirador::raster::Headless::new(gpu, &scene).render(gpu, &scene, &settings);
        assert_eq!(image, fresh, "{terms:?}: the kept variants draw what fresh ones draw");
        assert!(!images.contains(&image), "{terms:?}: the swap drew another swap's image");
        images.push(image);
    }
}

/// The hybrid's terms traced elsewhere (`TracedAt::Elsewhere`, the page's Web Workers): a frame
/// asks for the views it does not keep and draws them meanwhile with the coarser terms it has, or
/// with coarse terms it traces; once every view's terms are handed back, traced as a worker traces them (the request through
/// JSON, in bands, the answer encoded and decoded), it draws the image of terms traced here, bit
/// for bit, and traces nothing itself.
#[test]
fn terms_traced_elsewhere_draw_the_image_of_terms_traced_here() {
    use mirador::raster::traced::{self, TermsRequest, TracedAt};
    let gpu = common::gpu();
    let scene = smaller(common::load("scenes/showcase.toml"), 160);
    let settings = every_term_traced(&scene.settings);
    let here = mirador::raster::Headless::new(gpu, &scene).render(gpu, &scene, &settings);
    let mut headless = mirador::raster::Headless::new(gpu, &scene);
    let count = |headless: &mirador::raster::Headless, figure| headless.report.count("traced terms", figure);
    headless.renderer.traced_stride = 4;
    let coarse = headless.render(gpu, &scene, &settings);
    assert_ne!(coarse, here, "the coarse terms must show");

    let elsewhere = TracedAt::Elsewhere { coarse: 4 };
    let mut fresh = mirador::raster::Headless::new(gpu, &scene);
    fresh.renderer.traced_at = elsewhere;
    assert_eq!(fresh.render(gpu, &scene, &settings), coarse, "a new image's stand-ins are traced coarse");
    assert!(count(&fresh, "rays") > 0 && !fresh.renderer.traced.take_requests().is_empty());

    headless.renderer.traced_stride = 1;
    headless.renderer.traced_at = elsewhere;
    let waiting = headless.render(gpu, &scene, &settings);
    assert_eq!(count(&headless, "rays"), 0, "the coarser terms kept stand in: nothing is traced here");
    assert_eq!(waiting, coarse);
    let requests = headless.renderer.traced.take_requests();
    assert_eq!(requests.len() as u64, count(&headless, "views asked"));
    // (The glass ball's cube faces are drawn in the first frame only, then kept with their terms.)
    assert!(!requests.is_empty(), "the main view is asked for");
    assert!(headless.renderer.traced.awaiting());
    headless.render(gpu, &scene, &settings);
    assert!(headless.renderer.traced.take_requests().is_empty(), "a view asked for is not asked again");

    // As the page's workers trace: the frame's tracer, the request as JSON, bands of 8 rows.
    let raster = settings.hybrid.raster_settings(&settings).unwrap_or(settings.clone());
    let tracer = mirador::trace::Tracer::new(&scene, &raster);
    for request in &requests {
        let sent: TermsRequest = serde_json::from_str(&serde_json::to_string(request).unwrap()).unwrap();
        assert_eq!(&sent, request);
        let bands: Vec<_> = sent
            .bands(8)
            .iter()
            .filter_map(|band| band.trace(&tracer))
            .map(|terms| {
                let (header, values) = traced::encode(&terms);
                traced::decode(&header, &values).expect("an answer decodes")
            })
            .collect();
        if bands.is_empty() {
            continue;
        }
        let terms = traced::join(bands).expect("the bands follow one another");
        assert!(headless.renderer.traced.receive(&gpu.device, (request.ticket, request.view), &terms));
    }
    assert!(!headless.renderer.traced.awaiting());
    let done = headless.render(gpu, &scene, &settings);
    assert_eq!(count(&headless, "rays"), 0);
    assert_eq!(done, here, "terms traced elsewhere draw what terms traced here draw");

    // An answer for inputs that changed since is dropped.
    let stale = &requests[0];
    let mut moved = scene.clone();
    moved.camera.eye += glam::Vec3::new(0.1, 0.0, 0.0);
    headless.render(gpu, &moved, &settings);
    let terms = stale.trace(&tracer).expect("the main view has a window");
    assert!(!headless.renderer.traced.receive(&gpu.device, (stale.ticket, stale.view), &terms));
}

/// The viewer's coarse terms refined (`traced_stride` 4, then 1) draw the image of terms traced
/// at every pixel at once: the cube faces too, which a frame draws only when what they see
/// changed, so they are drawn again at each stride, and again when their terms traced elsewhere
/// come back.
#[test]
fn refined_terms_reach_the_cube_faces() {
    use mirador::raster::traced::{TermsRequest, TracedAt};
    let gpu = common::gpu();
    let scene = smaller(common::load("scenes/showcase.toml"), 160);
    let settings = traced(&scene.settings, &[Traced::Shadows]);
    let whole = mirador::raster::Headless::new(gpu, &scene).render(gpu, &scene, &settings);
    let mut headless = mirador::raster::Headless::new(gpu, &scene);
    let faces = |headless: &mirador::raster::Headless| headless.report.count("environment cubes", "faces");
    headless.renderer.traced_stride = 4;
    headless.render(gpu, &scene, &settings);
    assert_eq!(faces(&headless), 6, "the glass ball's cube is drawn");
    headless.renderer.traced_stride = 1;
    assert!(headless.render(gpu, &scene, &settings) == whole, "refined here, cube faces and all");

    // Elsewhere: the faces' terms handed back are drawn.
    let mut elsewhere = mirador::raster::Headless::new(gpu, &scene);
    elsewhere.renderer.traced_at = TracedAt::Elsewhere { coarse: 4 };
    elsewhere.render(gpu, &scene, &settings);
    let requests: Vec<TermsRequest> = elsewhere.renderer.traced.take_requests();
    assert!(requests.len() > 6, "the main view and the cube's faces are asked for");
    let raster = settings.hybrid.raster_settings(&settings).unwrap_or(settings.clone());
    let tracer = mirador::trace::Tracer::new(&scene, &raster);
    for request in &requests {
        let terms = request.trace(&tracer).expect("every view has a window");
        assert!(elsewhere.renderer.traced.receive(&gpu.device, (request.ticket, request.view), &terms));
    }
    assert!(elsewhere.render(gpu, &scene, &settings) == whole, "the terms traced elsewhere, cube faces and all");
}

/// A moving view's terms are traced into the buffers of terms no frame draws any more (mapped
/// again once the frames that copied from them are done), not into new ones: the frames count
/// the buffers reused. Two-sided by the images: every frame of a turning camera, on the showcase
/// (its main view and a glass ball's cube) and on the mirrors (whose windows change size as the
/// camera turns), at every pixel and at one in 16, is the image a fresh renderer draws.
#[test]
fn a_moving_views_terms_reuse_the_buffers_of_the_last() {
    let gpu = common::gpu();
    for name in ["showcase", "mirrors"] {
        let mut scene = smaller(common::load(&format!("scenes/{name}.toml")), 160);
        let settings = every_term_traced(&scene.settings);
        for stride in [1, 4] {
            let mut moving = mirador::raster::Headless::new(gpu, &scene);
            moving.renderer.traced_stride = stride;
            let mut reused = 0;
            for frame in 0..5 {
                let (c, e) = (scene.camera.center, scene.camera.eye - scene.camera.center);
                scene.camera.eye = c + glam::Quat::from_rotation_y(3f32.to_radians()) * e;
                let image = moving.render(gpu, &scene, &settings);
                reused += moving.report.count("traced terms", "buffers reused");
                let mut fresh = mirador::raster::Headless::new(gpu, &scene);
                fresh.renderer.traced_stride = stride;
                assert!(image == fresh.render(gpu, &scene, &settings), "{name}, stride {stride}, frame {frame}");
            }
            assert!(reused >= 3, "{name}, stride {stride}: {reused} buffers reused in 5 frames");
        }
    }
}
