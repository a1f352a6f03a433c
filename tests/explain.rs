//! Explaining a pixel (`mirador explain`, `src/explain/`): both renderers' terms add up to their
//! radiance, and that radiance is the pixel of `render --exr` and `trace --exr`; a shadow-acne
//! pixel is named acne, with the depths that show why; a planar mirror, a chrome ball and a glass
//! pane get the terms and rays worked out by hand.

mod common;

use glam::Vec3;
use mirador::explain::{Explainer, Explanation, explain};
use mirador::raster::{FrameTargets, Headless};
use mirador::trace::explain::{RayKind, RayNode, Term};
use mirador::{RenderSettings, Scene};

fn explained(scene: &Scene, settings: &RenderSettings, pixel: (u32, u32)) -> Explanation {
    explain(common::gpu(), scene, settings, pixel).unwrap_or_else(|e| panic!("{e}"))
}

fn sum(terms: &[Term]) -> Vec3 {
    terms.iter().map(|t| t.radiance).sum()
}

/// Half-float precision: 11 significant bits, plus the rounding of the terms' own sums.
fn close_half(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= 2e-3 * a.abs().max_element().max(b.abs().max_element()).max(0.05)
}

fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
    (a - b).abs().max_element() <= eps
}

fn parse(text: &str) -> Scene {
    mirador::scene::file::parse(text, std::path::Path::new("inline.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// The rasterizer's HDR target and the tracer's radiance image, as `--exr` writes them.
fn linear_images(scene: &Scene, settings: &RenderSettings) -> (Vec<Vec3>, Vec<Vec3>) {
    let gpu = common::gpu();
    let mut headless = Headless::new(gpu, scene);
    headless.render(gpu, scene, settings);
    let targets: &FrameTargets = &headless.targets;
    let raster = mirador::gpu::readback::read_rgb16f(&gpu.device, &gpu.queue, &targets.hdr.texture).unwrap();
    let tracer = mirador::trace::Tracer::new(scene, settings);
    let (traced, _) = tracer.render(&mirador::trace::RenderControl::default()).unwrap();
    (raster, traced.pixels)
}

/// On the showcase (every technique on: textures, bumps, shadow maps, glass, mirrors, curved
/// mirrors), at pixels chosen to land on each, the terms of both renderers add up to their
/// radiance, and the radiance is the pixel of the linear images `--exr` writes.
#[test]
fn terms_add_up_and_the_radiance_is_the_exr_pixel() {
    let mut scene = common::load("scenes/showcase.toml");
    (scene.camera.width, scene.camera.height) = (320, 180);
    let settings = scene.settings.clone();
    let (raster_image, traced_image) = linear_images(&scene, &settings);
    let mut explainer = Explainer::new(common::gpu(), &scene, &settings).unwrap();
    // The planar mirror, the red ball's environment map, the glass pane over the floor (two
    // layers: back faces, then front), the bumped cobbles, the floor in the pane's coloured
    // shadow, the floor, the sky, the wall.
    let pixels = [(112, 70), (180, 92), (220, 90), (153, 82), (200, 125), (60, 150), (250, 30), (60, 80)];
    let mut seen = std::collections::BTreeSet::new();
    for (x, y) in pixels {
        let explanation = explainer.explain(common::gpu(), (x, y)).unwrap();
        let surface = explanation.raster.surface.as_ref().unwrap();
        seen.insert(surface.kind);
        if !explanation.raster.layers.is_empty() {
            seen.insert("transparent layer");
        }
        if surface.environment.is_some() {
            seen.insert("environment map");
        }
        if surface.bump.is_some() {
            seen.insert("bump");
        }
        let (raster, trace) = (&explanation.raster, &explanation.trace);
        let index = (y * scene.camera.width + x) as usize;
        let exr = Vec3::from_array(raster_image[index].to_array());
        assert!(close(raster.radiance, exr, 1e-6), "({x}, {y}): explained {} vs EXR {exr}", raster.radiance);
        assert!(
            close(trace.radiance, traced_image[index], 1e-6),
            "({x}, {y}): traced {} vs EXR {}",
            trace.radiance,
            traced_image[index]
        );
        assert!(
            close_half(sum(&raster.terms), raster.radiance),
            "({x}, {y}): raster terms add to {} but the pixel is {}: {:#?}",
            sum(&raster.terms),
            raster.radiance,
            raster.terms
        );
        assert!(
            close(sum(&trace.terms), trace.radiance, 1e-5 * trace.radiance.max_element().max(1.0)),
            "({x}, {y}): traced terms add to {} but the radiance is {}: {:#?}",
            sum(&trace.terms),
            trace.radiance,
            trace.terms
        );
        // Every node of the tree adds up too.
        fn each(node: &RayNode, check: &mut dyn FnMut(&RayNode)) {
            check(node);
            node.children.iter().for_each(|c| each(c, check));
        }
        each(&trace.rays, &mut |node| {
            if node.kind != RayKind::Shadow {
                let total = sum(&node.terms);
                assert!(close(total, node.radiance, 1e-5 * node.radiance.max_element().max(1.0)), "{node:#?}");
            }
        });
    }
    let expected = ["background", "bump", "environment map", "mirror", "opaque", "transparent layer"];
    assert_eq!(seen.into_iter().collect::<Vec<_>>(), expected, "the pixels cover every technique");
}

/// Shadow acne: with no bias at all the floor shadows itself in the shadow map. At such a pixel
/// the map shadows the point, the shadow ray reaches the light, the stored depth lies a hair in
/// front of the receiver's, and the diagnosis says acne; with the scene's bias the same pixel is
/// lit in both and nothing is diagnosed.
#[test]
fn shadow_acne_is_diagnosed_with_the_depths_that_show_it() {
    let mut scene = common::load("scenes/shadows.toml");
    (scene.camera.width, scene.camera.height) = (320, 200);
    let mut acne = scene.settings.clone();
    acne.shadows.depth_bias = 0;
    acne.shadows.slope_bias = 0.0;
    acne.shadows.normal_offset = 0.0;
    acne.shadows.filter = mirador::settings::ShadowFilter::None;
    // Pixels of the floor: a row near the bottom of the image.
    let mut explainer = Explainer::new(common::gpu(), &scene, &acne).unwrap();
    let mut found = None;
    for x in (10..310).step_by(7) {
        let explanation = explainer.explain(common::gpu(), (x, 185)).unwrap();
        if explanation.diagnosis.as_deref().is_some_and(|d| d.starts_with("Shadow acne")) {
            found = Some((x, explanation));
            break;
        }
    }
    let (x, explanation) = found.expect("some floor pixel shows acne with no bias");
    let diagnosis = explanation.diagnosis.as_deref().unwrap();
    // Every cure the course teaches for acne.
    for cure in ["shadows.depth_bias", "shadows.slope_bias", "shadows.normal_offset"] {
        assert!(diagnosis.contains(cure), "{cure} missing from: {diagnosis}");
    }
    let light = explanation.raster.lights.iter().find(|l| diagnosis.contains(&format!("`{}`", l.name))).unwrap();
    let shadow = light.shadow.as_ref().unwrap();
    let (stored, receiver) = (shadow.stored_depth.unwrap(), shadow.receiver_depth.unwrap());
    eprintln!("acne at ({x}, 185): stored {stored}, receiver {receiver}; {diagnosis}");
    assert!(light.visibility.max_element() < 0.5, "the map shadows the point: {light:?}");
    assert!(receiver > stored && receiver - stored < 1e-3, "stored {stored}, receiver {receiver}");
    let traced = explanation.trace.lights.iter().find(|l| l.name == light.name).unwrap();
    assert_eq!(traced.visibility, Vec3::ONE, "the shadow ray reaches the light");
    // The scene's own bias cures it.
    let cured = explained(&scene, &scene.settings, (x, 185));
    let cured_light = cured.raster.lights.iter().find(|l| l.name == light.name).unwrap();
    assert!(cured_light.visibility.max_element() > 0.99, "{cured_light:?}");
    assert!(cured.diagnosis.as_deref().is_none_or(|d| !d.contains("acne")), "{:?}", cured.diagnosis);
}

/// A room with no lights and no ambient light: what a pixel shows is emission, passed on by a
/// mirror or a pane. The glowing wall emits `E`; a planar mirror (`kps·MPS` = 0.8) in front of
/// the camera shows it; a chrome ball (0.9) reflects a world of constant background `B`; a glass
/// pane (`kt·Mt` = 0.5·(1, 0.5, 0.25), ior 1) lies over the wall.
const ROOM: &str = r#"
    [camera]
    eye = [0.0, 1.0, 4.0]
    center = [0.0, 1.0, 0.0]
    fovy = 50
    width = 160
    height = 120
    [world]
    ambient = [0.0, 0.0, 0.0]
    background = [0.2, 0.3, 0.4]
    [materials.glow]
    color = [0.0, 0.0, 0.0]
    kd = 0.0
    emission = [0.9, 0.6, 0.3]
    [materials.mirror]
    color = [0.0, 0.0, 0.0]
    kd = 0.0
    mirror = 0.8
    mirror_color = [1.0, 1.0, 1.0]
    [materials.chrome]
    color = [0.0, 0.0, 0.0]
    kd = 0.0
    mirror = 0.9
    mirror_color = [1.0, 1.0, 1.0]
    [materials.glass]
    color = [0.0, 0.0, 0.0]
    kd = 0.0
    transmission = 0.5
    transmission_color = [1.0, 0.5, 0.25]
    ior = 1.0
    [[objects]]
    name = "glowing wall"
    type = "plane"
    size = [3.0, 3.0]
    rotate = [90, 0, 0]
    translate = [-1.6, 1.0, -1.0]
    material = "glow"
    [[objects]]
    name = "wall behind the camera"
    type = "plane"
    size = [12.0, 6.0]
    rotate = [90, 0, 0]
    translate = [0.0, 1.0, 6.0]
    material = "glow"
    [[objects]]
    name = "mirror"
    type = "plane"
    size = [1.2, 1.2]
    rotate = [90, 0, 0]
    translate = [0.5, 1.0, -1.0]
    material = "mirror"
    [[objects]]
    name = "chrome ball"
    type = "sphere"
    center = [1.9, 1.0, 0.0]
    radius = 0.5
    material = "chrome"
    [[objects]]
    name = "pane"
    type = "plane"
    size = [0.8, 0.8]
    rotate = [90, 0, 0]
    translate = [-1.2, 1.0, 0.0]
    material = "glass"
"#;

const E: Vec3 = Vec3::new(0.9, 0.6, 0.3);

fn term<'t>(terms: &'t [Term], part: &str) -> &'t Term {
    terms.iter().find(|t| t.name.contains(part)).unwrap_or_else(|| panic!("no `{part}` term in {terms:#?}"))
}

/// The planar mirror at the image's centre reflects the wall behind the camera: `0.8·E` in both
/// renderers, the rasterizer's term read from its mirrored camera's image, the tracer's from its
/// reflected ray, which leaves along the mirrored view ray and hits that wall.
#[test]
fn a_planar_mirror_shows_kps_mps_times_what_its_reflected_ray_hits() {
    let scene = parse(ROOM);
    let settings = scene.settings.clone();
    // The mirror spans x from −0.1 to 1.1 on the plane z = −1: the pixel looking at x = 0.5.
    let pixel = (94, 60);
    let e = explained(&scene, &settings, pixel);
    let expected = 0.8 * E;
    let raster_mirror = term(&e.raster.terms, "planar mirror");
    assert!(close(raster_mirror.radiance, expected, 4e-3), "{raster_mirror:?}");
    assert!(close(e.raster.radiance, expected, 4e-3), "{}", e.raster.radiance);
    let surface = e.raster.surface.as_ref().unwrap();
    assert_eq!(surface.object.as_deref(), Some("mirror"));
    let mirrored = surface.mirror.as_ref().expect("the mirror's lookup");
    assert!(close(mirrored.mirrored_eye, Vec3::new(0.0, 1.0, -6.0), 1e-4), "{:?}", mirrored.mirrored_eye);
    assert_eq!(mirrored.texel, [pixel.0, pixel.1]);
    let traced = term(&e.trace.terms, "mirror kps·MPS·L(r)");
    assert!(close(traced.radiance, expected, 1e-5), "{traced:?}");
    let reflected = e.trace.rays.children.iter().find(|c| c.kind == RayKind::Reflected).expect("a reflected ray");
    let hit = reflected.hit.as_ref().expect("the reflected ray hits");
    assert_eq!(hit.object.as_deref(), Some("wall behind the camera"));
    // The view ray reflected about z = −1: its z component turns over.
    let view = e.trace.rays.direction;
    assert!(close(reflected.direction, Vec3::new(view.x, view.y, -view.z), 1e-5), "{}", reflected.direction);
    assert!((hit.point.z - 6.0).abs() < 1e-3, "{:?}", hit.point);
    assert!(e.diagnosis.is_none(), "{:?}", e.diagnosis);
}

/// The chrome ball's edge reflects the world (the background `B`, constant in every direction):
/// `0.9·B` in both, the rasterizer's from its cube map (the dynamic cube sees the background
/// there too), the tracer's from a reflected ray that hits nothing.
#[test]
fn a_chrome_ball_reflects_kps_mps_times_the_environment() {
    let scene = parse(ROOM);
    let settings = scene.settings.clone();
    let b = Vec3::new(0.2, 0.3, 0.4);
    // A pixel near the ball's top rim, where r points up and away from every object.
    let centre_pixel = scene.camera.project(Vec3::new(1.9, 1.47, 0.0)).expect("in view");
    let pixel = (centre_pixel.x as u32, centre_pixel.y as u32);
    let e = explained(&scene, &settings, pixel);
    let surface = e.raster.surface.as_ref().unwrap();
    assert_eq!(surface.object.as_deref(), Some("chrome ball"), "{pixel:?}");
    let lookup = surface.environment.as_ref().expect("a curved mirror looks its environment up");
    assert!(lookup.map.starts_with("cube"), "{}", lookup.map);
    assert!(close(lookup.radiance, 0.9 * b, 4e-3), "{lookup:?}");
    let reflected = e.trace.rays.children.iter().find(|c| c.kind == RayKind::Reflected).expect("a reflected ray");
    assert!(reflected.hit.is_none(), "{:?}", reflected.hit);
    assert!(close(reflected.radiance, b, 1e-6));
    assert!(close(term(&e.trace.terms, "mirror").radiance, 0.9 * b, 1e-5));
    // r = 2(n·v)n − v, the same direction on both sides.
    let n = e.trace.rays.surface.as_ref().unwrap().normal;
    let v = -e.trace.rays.direction;
    let r = 2.0 * n.dot(v) * n - v;
    assert!(close(reflected.direction, r.normalize(), 1e-4), "{} vs {r}", reflected.direction);
    assert!(lookup.direction.angle_between(r) < 0.05, "raster r {} vs traced {r}", lookup.direction);
}

/// The pane over the glowing wall lets `kt·Mt·E` through: the rasterizer's layer blends it with
/// `kt·Mt` = 0.5·(1, 0.5, 0.25), the tracer's refracted ray (ior 1) goes straight on and hits the
/// wall; both give `(0.225, 0.075, 0.0375)`.
#[test]
fn a_glass_pane_transmits_kt_mt_times_what_lies_behind() {
    let scene = parse(ROOM);
    let settings = scene.settings.clone();
    let pixel = scene.camera.project(Vec3::new(-1.2, 1.0, 0.0)).expect("in view");
    let pixel = (pixel.x as u32, pixel.y as u32);
    let e = explained(&scene, &settings, pixel);
    let through = 0.5 * Vec3::new(1.0, 0.5, 0.25);
    let expected = through * E;
    assert!(close(e.raster.radiance, expected, 4e-3), "{}", e.raster.radiance);
    let layer = e.raster.layers.first().expect("the pane is a layer");
    assert_eq!(layer.object.as_deref(), Some("pane"));
    assert!(close(layer.lets_through, through, 1e-6), "{layer:?}");
    assert!(close(term(&e.raster.terms, "glowing wall").radiance, expected, 4e-3), "{:#?}", e.raster.terms);
    assert!(close(e.trace.radiance, expected, 1e-5), "{}", e.trace.radiance);
    let refracted = e.trace.rays.children.iter().find(|c| c.kind == RayKind::Refracted).expect("a refracted ray");
    assert!(close(refracted.direction, e.trace.rays.direction, 1e-6), "ior 1: straight on");
    assert_eq!(refracted.hit.as_ref().and_then(|h| h.object.as_deref()), Some("glowing wall"));
    assert!(close(term(&e.trace.terms, "transmitted").radiance, expected, 1e-5));
    assert!(e.diagnosis.is_none(), "{:?}", e.diagnosis);
}

/// The JSON has the fields `mirador explain --json` promises.
#[test]
fn the_json_has_the_documented_fields() {
    let scene = parse(ROOM);
    let e = explained(&scene, &scene.settings, (94, 60));
    let json: serde_json::Value = serde_json::from_str(&e.to_json()).unwrap();
    assert_eq!(json["pixel"], serde_json::json!([94, 60]));
    for side in ["raster", "trace"] {
        assert_eq!(json[side]["radiance"].as_array().map(Vec::len), Some(3), "{side}");
        let terms = json[side]["terms"].as_array().unwrap();
        assert!(terms.iter().all(|t| t["name"].is_string() && t["radiance"].is_array()), "{side}");
        assert!(json[side]["lights"].is_array(), "{side}");
    }
    let rays = &json["trace"]["rays"];
    for field in ["kind", "origin", "direction", "hit", "children"] {
        assert!(rays.get(field).is_some(), "trace.rays.{field}");
    }
    assert!(json.get("diagnosis").is_some());
}

/// The glass ball of assets/scenes/refraction.toml at a pixel through its middle, drawn by each
/// refraction choice with Fresnel (and by the transparency pass's two Fresnel draws with
/// straight rays): the raster terms add up to the pixel, name `F` and the refracted term, the
/// path found leaves the glass where the tracer's ray does, and the diagnosis speaks of
/// refraction.
#[test]
fn refracting_glass_is_explained_with_its_path_and_fresnel() {
    use mirador::settings::Refraction;
    let scene = common::load("scenes/refraction.toml");
    let centre = scene.camera.project(Vec3::new(-0.2, 0.8, 0.6)).expect("in view");
    let pixel = (centre.x as u32 - 10, centre.y as u32 - 10);
    for refraction in [Refraction::None, Refraction::Environment, Refraction::Screen] {
        let mut settings = scene.settings.clone();
        settings.transparency.refraction = refraction;
        settings.terms.fresnel = true;
        let e = explained(&scene, &settings, pixel);
        let raster = &e.raster;
        assert!(
            close_half(sum(&raster.terms), raster.radiance),
            "{refraction:?}: terms add to {} but the pixel is {}: {:#?}",
            sum(&raster.terms),
            raster.radiance,
            raster.terms
        );
        assert!(raster.terms.iter().any(|t| t.name.contains("F = 0.04")), "{refraction:?}: {:#?}", raster.terms);
        let diagnosis = e.diagnosis.clone().unwrap_or_default();
        if refraction == Refraction::None {
            assert!(raster.layers.iter().all(|l| l.lets_through.x < 0.96 * 0.95), "(1 − F)·kt·Mt: {:?}", raster.layers);
            assert!(diagnosis.contains("n_i = n_t"), "{diagnosis}");
            continue;
        }
        let surface = raster.surface.as_ref().expect("the glass");
        assert_eq!(surface.kind, "refraction");
        let path = surface.refraction.as_ref().expect("the path through the glass");
        let traced_in = e.trace.rays.children.iter().find(|c| c.kind == RayKind::Refracted).expect("into the glass");
        let traced_out = traced_in.children.iter().find(|c| c.kind == RayKind::Refracted).expect("out of it");
        let exit = path.exit.expect("the exit on the back faces");
        assert!(exit.distance(traced_out.origin) < 0.02, "{refraction:?}: exit {exit} vs {}", traced_out.origin);
        assert!(path.direction.angle_between(traced_out.direction) < 1f32.to_radians(), "{path:?}");
        assert!(term(&raster.terms, "refracted").radiance.max_element() > 0.0);
        assert!(diagnosis.contains("glass ball"), "{refraction:?}: {diagnosis}");
    }
}

/// Projected shadows (issue 35's case): on the back wall of the course's scene, a plane that
/// receives the polygons, a pixel on the shadow's edge is named an edge, never "not a receiver";
/// a pixel inside the shadow, where both renderers agree, gets no such sentence; and a box (no
/// receiver) under a ball's shadow is named as not a receiver.
#[test]
fn projected_shadows_are_diagnosed_from_the_receiver_and_the_edge() {
    let scene = common::load("scenes/course/shadows-methods.toml");
    let mut settings = scene.settings.clone();
    settings.shadows.method = mirador::settings::ShadowMethod::Projected;
    let mut explainer = Explainer::new(common::gpu(), &scene, &settings).unwrap();
    let edge = explainer.explain(common::gpu(), (197, 80)).unwrap();
    let diagnosis = edge.diagnosis.as_deref().unwrap_or_default();
    assert_eq!(edge.raster.surface.as_ref().and_then(|s| s.object.as_deref()), Some("back wall"));
    assert!(
        diagnosis.starts_with("On the edge of a projected shadow") && diagnosis.contains("`back wall`"),
        "{diagnosis}"
    );
    assert!(!diagnosis.contains("not one"), "{diagnosis}");
    let inside = explainer.explain(common::gpu(), (175, 90)).unwrap();
    let lit = |e: &Explanation| e.raster.lights[0].visibility.max_element();
    assert!(lit(&inside) < 0.01, "inside the shadow on the wall: V = {}", lit(&inside));
    assert!(inside.diagnosis.as_deref().is_none_or(|d| !d.contains("projected")), "{:?}", inside.diagnosis);

    let scene = parse(
        r#"
        [camera]
        eye = [0, 4, 2]
        center = [0, 0, 0]
        fovy = 40
        width = 64
        height = 64
        [materials.grey]
        color = [0.8, 0.8, 0.8]
        [[lights]]
        type = "point"
        position = [0, 6, 0]
        [[objects]]
        type = "box"
        min = [-1, 0, -1]
        max = [1, 0.5, 1]
        material = "grey"
        [[objects]]
        type = "sphere"
        center = [0.6, 1.5, 0.6]
        radius = 0.3
        material = "grey"
        "#,
    );
    let mut settings = scene.settings.clone();
    settings.shadows.method = mirador::settings::ShadowMethod::Projected;
    // A pixel of the box's top inside the ball's shadow (the ball hides the light from it), but
    // not behind the ball as the camera sees it.
    let mut explainer = Explainer::new(common::gpu(), &scene, &settings).unwrap();
    let found = (0..64).step_by(3).flat_map(|y| (0..64).step_by(3).map(move |x| (x, y))).find_map(|pixel| {
        let e = explainer.explain(common::gpu(), pixel).unwrap();
        e.diagnosis.filter(|d| d.contains("is not one"))
    });
    let diagnosis = found.expect("a pixel of the box in the ball's shadow is named as no receiver");
    assert!(diagnosis.starts_with("Projected shadows fall only on `plane` receivers"), "{diagnosis}");
}

/// A light behind the surface that adds nothing to it (`n·l ≤ 0`, no ambient term) is left out
/// on both sides (issue 35: the rasterizer listed it with V = 0 from the shadow map, the tracer
/// omitted it): here the `fill` light, shining down onto the left mirror's back.
#[test]
fn both_sides_list_the_same_lights() {
    let scene = common::load("scenes/mirrors.toml");
    let explanation = explained(&scene, &scene.settings, (150, 187));
    let raster: Vec<&str> = explanation.raster.lights.iter().map(|l| l.name.as_str()).collect();
    let traced: Vec<&str> = explanation.trace.lights.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(raster, traced);
    assert_eq!(raster, ["key"], "the fill light lies behind the mirror's surface");
}

/// FLIP's error map spreads a pixel's error over its neighbours, so its brightest spot may agree
/// (`mirrors.toml`, around pixel (283, 212), beside the red sphere's outline): there `explain`
/// says the renderers agree and names the nearest pixel that differs, which has a diagnosis of its
/// own.
/// In a flat area nothing nearby differs and no pixel is named.
#[test]
fn where_the_renderers_agree_explain_names_the_nearest_pixel_that_differs() {
    let scene = Scene::load(&common::asset("scenes/mirrors.toml")).expect("the mirrors scene");
    // The pixel nearest (283, 212) along its row that agrees and has one that differs beside it
    // (a row, so that an outline a pixel away on another CPU cannot move it out).
    let agreeing = [283, 282, 284, 281, 285, 280, 286]
        .into_iter()
        .map(|x| explained(&scene, &scene.settings, (x, 212)))
        .find(|e| e.diagnosis.is_none() && e.nearest.is_some())
        .expect("a pixel beside the sphere's outline that agrees");
    let nearest = agreeing.nearest.clone().expect("found with one");
    assert!(nearest.distance <= mirador::explain::NEAREST_RADIUS as f32, "{nearest:?}");
    assert!(nearest.levels >= mirador::explain::DIFFERS_BY);
    let [x, y] = nearest.pixel;
    let differing = explained(&scene, &scene.settings, (x, y));
    assert!(differing.diagnosis.is_some(), "the pixel named differs, so it has a diagnosis");
    assert_eq!(differing.nearest, None, "a differing pixel names no other");
    let text = mirador::explain::text::render(&agreeing);
    let words = text.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(words.contains(&format!("the nearest pixel that differs is ({x}, {y})")), "{text}");

    let flat = explained(&scene, &scene.settings, (100, 100));
    assert_eq!((flat.diagnosis, flat.nearest), (None, None), "nothing near a flat pixel differs");
}

/// On a planar mirror `explain` follows the mirrored camera: what it saw at the pixel (its own
/// surface, terms and lights) beside what the tracer's reflected ray hits. Where the two see
/// different surfaces (along the red sphere's outline in the left mirror of `mirrors.toml`) the
/// diagnosis names both; where they see the same (the floor in the mirror) it does not; a pixel
/// off the mirrors has no mirrored side.
#[test]
fn on_a_planar_mirror_explain_follows_the_mirrored_camera() {
    let scene = Scene::load(&common::asset("scenes/mirrors.toml")).expect("the mirrors scene");
    let object = |s: Option<&mirador::explain::RasterSurface>| s.and_then(|s| s.object.clone());
    let reflected_hit = |e: &Explanation| {
        let reflected = e.trace.rays.children.iter().find(|c| c.kind == RayKind::Reflected)?;
        reflected.hit.as_ref().and_then(|h| h.object.clone())
    };
    // Along the outline (a row of pixels across it, so that a pixel's worth of rounding on
    // another CPU cannot move it out), at least one pixel sees two surfaces, and every pixel's
    // diagnosis says so exactly when it does.
    let mut outline = 0;
    for x in 144..=156 {
        let e = explained(&scene, &scene.settings, (x, 187));
        let seen = e.through_mirror.as_ref().expect("a pixel of the left mirror has its camera's pixel");
        assert!(close_half(sum(&seen.terms), seen.radiance), "({x}, 187): the mirrored side's terms add up");
        let (camera, ray) = (object(seen.surface.as_ref()), reflected_hit(&e));
        let named = e.diagnosis.as_deref().is_some_and(|d| d.starts_with("In the mirror `left mirror`"));
        assert_eq!(named, camera != ray, "({x}, 187): camera saw {camera:?}, the ray hits {ray:?}: {:?}", e.diagnosis);
        outline += usize::from(camera != ray);
    }
    assert!(outline > 0, "the row crosses the sphere's outline in the mirror");
    let inside = explained(&scene, &scene.settings, (120, 200));
    let seen = inside.through_mirror.as_ref().expect("the mirror's camera");
    assert_eq!(object(seen.surface.as_ref()).as_deref(), Some("floor"));
    assert_eq!(reflected_hit(&inside).as_deref(), Some("floor"));
    assert!(explained(&scene, &scene.settings, (100, 220)).through_mirror.is_none(), "the floor is no mirror");
}
