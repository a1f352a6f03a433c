//! Displacement mapping (`bump.method = "displacement"`, src/texture/displacement.rs): the height
//! field's surface made as triangles, for both renderers alike. Checked against the theory:
//!
//! - the rasterizer and the tracer draw one displaced surface, so they agree as on any surface;
//! - bump mapping is that surface's shading without its geometry: against the traced displaced
//!   surface it is measurably worse, at the silhouette (sky where the relief stands) and in the
//!   self-shadows;
//! - the displaced sphere is closed (no sky through it), whatever the seam and the poles;
//! - bad input (a huge scale, a bound on triangles) ends in a surface or a said level, never a
//!   panic or unbounded memory;
//! - adaptive tessellation on the GPU (`bump.tessellation = "adaptive"`, the default) makes the
//!   triangles its CPU twin makes, closed where neighbours have different levels and across a
//!   seam whose two sides have different heights, finer near the camera, within its bound.

mod common;

use glam::Vec3;
use mirador::Scene;
use mirador::raster::geometry::SceneGeometry;
use mirador::raster::tessellation::pass::TessellationPass;
use mirador::raster::tessellation::{self, Patches};
use mirador::settings::{BumpMethod, Tessellation};
use mirador::texture::displacement::{self, MAX_TRIANGLES};

/// `path`'s scene with `method`, displaced when asked.
fn with_method(path: &str, method: BumpMethod) -> Scene {
    let mut scene = common::load(path);
    scene.settings.bump.method = method;
    displacement::displace(&mut scene);
    scene
}

/// FLIP of the rasterizer's image of `raster` against the tracer's of `traced`.
fn raster_against_traced(raster: &Scene, traced: &Scene) -> f32 {
    let reference = mirador::trace::render_image(traced, &traced.settings);
    common::flip(&reference, &common::raster(raster, &raster.settings))
}

/// The displaced sphere and plane: raster against the tracer on one displaced surface, and bump
/// mapping against the same traced surface. The rasterizer draws the tracer's triangles
/// (`uniform`) or its own, made on the GPU for the view (`adaptive`): either agrees with it.
#[test]
fn both_renderers_draw_one_displaced_surface_and_bump_mapping_misses_it() {
    for path in ["scenes/course/displacement-sphere.toml", "scenes/course/displacement-plane.toml"] {
        let displaced = with_method(path, BumpMethod::Displacement);
        let bumped = with_method(path, BumpMethod::Normal);
        let bump = raster_against_traced(&bumped, &displaced);
        for tessellation in [Tessellation::Uniform, Tessellation::Adaptive] {
            let mut raster = displaced.clone();
            raster.settings.bump.tessellation = tessellation;
            let agree = raster_against_traced(&raster, &displaced);
            eprintln!(
                "{path}: {tessellation:?} displaced raster vs tracer {agree:.4}; bump raster vs displaced tracer {bump:.4}"
            );
            // Measured on lavapipe: see tests/README.md.
            assert!(agree < 0.02, "{path}, {tessellation:?}: the two renderers on one displaced surface: FLIP {agree}");
            assert!(bump > 2.0 * agree, "{path}: bump mapping {bump} is not worse than displacement {agree}");
        }
    }
}

/// Parallax mapping, between the two: its two renderers agree (the same march in WGSL and in
/// Rust), and against the traced displaced surface it is nearer than bump mapping (the relief
/// hides itself) and farther than displacement (the outline and the shadows stay flat).
#[test]
fn parallax_mapping_lies_between_bump_mapping_and_displacement() {
    for path in ["scenes/course/displacement-sphere.toml", "scenes/course/displacement-plane.toml"] {
        let displaced = with_method(path, BumpMethod::Displacement);
        let parallax = with_method(path, BumpMethod::Parallax);
        let bumped = with_method(path, BumpMethod::Normal);
        let agree = raster_against_traced(&parallax, &parallax);
        let reference = mirador::trace::render_image(&displaced, &displaced.settings);
        let against = |scene: &Scene| common::flip(&reference, &common::raster(scene, &scene.settings));
        let (bump, between, displacement) = (against(&bumped), against(&parallax), against(&displaced));
        eprintln!(
            "{path}: parallax raster vs parallax tracer {agree:.4}; against the traced displaced surface: bump {bump:.4}, parallax {between:.4}, displacement {displacement:.4}"
        );
        assert!(agree < 0.02, "{path}: parallax in the two renderers: FLIP {agree}");
        assert!(displacement < between && between < bump, "{path}: {displacement} < {between} < {bump} does not hold");
    }
}

/// Where the relief stands out of the sphere, the displaced image has the ball and bump mapping
/// the sky: the silhouette is the one thing no shading can fix.
#[test]
fn bump_mapping_keeps_a_circular_silhouette_and_displacement_breaks_it() {
    let path = "scenes/course/displacement-sphere.toml";
    let displaced = with_method(path, BumpMethod::Displacement);
    let bumped = with_method(path, BumpMethod::Normal);
    let sky = displaced.background;
    let is_sky = |p: &image::Rgba<u8>, reference: &image::Rgba<u8>| {
        p.0.iter().zip(reference.0).take(3).all(|(a, b)| a.abs_diff(b) <= 2)
    };
    let traced_displaced = mirador::trace::render_image(&displaced, &displaced.settings);
    let bump_image = common::raster(&bumped, &bumped.settings);
    let plain = mirador::trace::render_image(&common::load(path), &common::load(path).settings);
    // The sky's own colour, read where no ball can be (the top-left corner).
    let sky_pixel = *plain.get_pixel(0, 0);
    assert!(sky.max_element() > 0.0);
    let (mut ball_in_displaced_only, mut sky_in_both) = (0, 0);
    for (d, b) in traced_displaced.pixels().zip(bump_image.pixels()) {
        match (is_sky(d, &sky_pixel), is_sky(b, &sky_pixel)) {
            (false, true) => ball_in_displaced_only += 1,
            (true, true) => sky_in_both += 1,
            _ => {}
        }
    }
    eprintln!("pixels of relief outside the bump-mapped circle: {ball_in_displaced_only}");
    assert!(sky_in_both > 10_000, "the sky is found: {sky_in_both}");
    assert!(ball_in_displaced_only > 200, "the displaced outline adds {ball_in_displaced_only} pixels of ball");
}

/// No sky through a closed displaced sphere: every pixel well inside its outline is the ball,
/// across the seam (u = 0 = 1) and at the poles, where vertices at one point are moved together;
/// in the tracer's triangles and in the GPU's adaptive ones alike.
#[test]
fn a_displaced_sphere_is_closed() {
    let mut scene = with_method("scenes/course/displacement-sphere.toml", BumpMethod::Displacement);
    // A background no shading of the ball makes, and the ball turned so that its seam and a
    // pole face the camera.
    scene.background = glam::Vec3::new(1.0, 0.0, 1.0);
    let turn = glam::Mat4::from_rotation_x(1.1) * glam::Mat4::from_rotation_y(3.0);
    for object in &mut scene.objects {
        object.world_from_local = turn * object.world_from_local;
    }
    for tessellation in [Tessellation::Uniform, Tessellation::Adaptive] {
        scene.settings.bump.tessellation = tessellation;
        let image = common::raster(&scene, &scene.settings);
        let (w, h) = (image.width() as f32, image.height() as f32);
        // The ball's outline on screen: radius 0.8 at distance ~2.92 with fovy 40°.
        let radius_pixels = 0.8 / (2.92 * (20f32.to_radians()).tan()) * h / 2.0;
        let mut holes = 0;
        for (x, y, p) in image.enumerate_pixels() {
            let d = ((x as f32 + 0.5 - w / 2.0).powi(2) + (y as f32 + 0.5 - h / 2.0 + 0.0).powi(2)).sqrt();
            if d < 0.85 * radius_pixels && p.0[0] > 200 && p.0[1] < 60 && p.0[2] > 200 {
                holes += 1;
            }
        }
        assert_eq!(holes, 0, "{tessellation:?}: {holes} background pixels inside the displaced ball");
    }
}

/// The edges of a triangle list not met by exactly two triangles, by their ends' bits (triangles
/// folded to a line or a point left out: snapping makes some, and they cover nothing).
fn open_edges(positions: &[Vec3], indices: &[u32]) -> usize {
    let key = |i: u32| (positions[i as usize] + Vec3::ZERO).to_array().map(f32::to_bits);
    let mut edges: std::collections::HashMap<([u32; 3], [u32; 3]), i32> = Default::default();
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
        if (b - a).cross(c - a).length_squared() == 0.0 {
            continue;
        }
        for (p, q) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let (p, q) = (key(p), key(q));
            *edges.entry(if p < q { (p, q) } else { (q, p) }).or_default() += 1;
        }
    }
    edges.values().filter(|&&count| count != 2).count()
}

/// The displaced ball seen from near by (its triangles' levels differ: long edges in front, short
/// ones at the outline), its height map made a ramp `f = u` that does not tile, so the seam's two
/// sides have different heights.
fn ball_near_with_a_seam() -> Scene {
    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    for texture in &mut scene.textures {
        let width = texture.width.max(2) as usize;
        for (i, texel) in texture.rgba8.chunks_exact_mut(4).enumerate() {
            texel[..3].fill(((i % width) * 255 / (width - 1)) as u8);
        }
    }
    scene.settings.bump.method = BumpMethod::Displacement;
    scene.settings.bump.edge_pixels = 6.0;
    displacement::displace(&mut scene);
    scene.camera.eye = Vec3::new(0.6, 0.5, 1.9);
    scene
}

/// The pass that tessellated `scene`'s displaced objects on the GPU, and the geometry it gave
/// them to.
fn tessellated_on_the_gpu(scene: &Scene) -> (TessellationPass, SceneGeometry) {
    let gpu = common::gpu();
    let mut pass = TessellationPass::default();
    pass.load(gpu, scene);
    let mut geometry = SceneGeometry::new(scene, &[], &[]);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    pass.prepare(gpu, &mut encoder, scene, &scene.settings, &mut geometry).expect("a report");
    gpu.queue.submit([encoder.finish()]);
    (pass, geometry)
}

/// The GPU's adaptive triangles: closed, where neighbours have different levels and across a seam
/// whose two sides' heights differ (each edge point made once, from the edge alone, on either
/// side), and the very triangles the CPU twin makes (`Patches::tessellate`).
#[test]
fn adaptive_tessellation_is_closed_between_levels_and_is_the_cpus() {
    let scene = ball_near_with_a_seam();
    let (pass, geometry) = tessellated_on_the_gpu(&scene);
    assert!(geometry.has_displaced());
    let made = pass.read_back(common::gpu());
    let twins = pass.cpu_meshes(&scene);
    assert_eq!((made.len(), twins.len()), (1, 1));
    let ((vertices, indices), (_, twin)) = (&made[0], &twins[0]);
    eprintln!("{}", pass.report.as_ref().expect("a report").summary());
    // The levels differ from triangle to triangle, and some edges are coarser than their
    // triangles: the case snapping is for.
    let patches = Patches::new(&scene, 0).expect("patches");
    let bump = &scene.settings.bump;
    let levels = patches.levels(&scene.camera, bump.edge_pixels, bump.displacement_texels);
    let splits: Vec<u32> = levels.patches.iter().map(|l| l[3]).collect();
    let (least, most) = (splits.iter().min().unwrap(), splits.iter().max().unwrap());
    let snapped = levels.patches.iter().filter(|l| l[..3].iter().any(|&e| e < l[3])).count();
    eprintln!("splits {least} to {most}; {snapped} of {} triangles have a coarser edge", splits.len());
    assert!(least < most && snapped > 100, "the levels do not vary: {least} to {most}, {snapped} snapped");
    assert_eq!((vertices.len() as u64, indices.len() as u64 / 3), (levels.vertices, levels.triangles));
    assert!(indices.iter().all(|&i| (i as usize) < vertices.len()));
    let positions: Vec<Vec3> = vertices.iter().map(|v| Vec3::from_array(v.position)).collect();
    assert_eq!(open_edges(&twin.positions, &twin.indices), 0, "the CPU twin's triangles are closed");
    assert_eq!(open_edges(&positions, indices), 0, "the GPU's triangles are closed");
    // The same triangles as the CPU twin's: positions to f32 rounding, normals to a fraction of
    // a degree.
    assert_eq!(twin.indices, *indices);
    let (mut far, mut turned) = (0f32, 1f32);
    for (v, (p, n)) in vertices.iter().zip(twin.positions.iter().zip(&twin.normals)) {
        far = far.max(Vec3::from_array(v.position).distance(*p));
        turned = turned.min(Vec3::from_array(v.normal).dot(*n));
    }
    eprintln!("GPU against CPU: positions within {far:e}, normals within {:.3}°", turned.min(1.0).acos().to_degrees());
    assert!(far < 1e-4 && turned > 0.9999, "GPU against CPU: {far}, {turned}");
}

/// Adaptive tessellation follows the screen: nearer, or with shorter edges asked, more
/// triangles; never finer than the height field's own rule.
#[test]
fn adaptive_tessellation_is_finer_near_the_camera() {
    let scene = ball_near_with_a_seam();
    let patches = Patches::new(&scene, 0).expect("patches");
    let texels = scene.settings.bump.displacement_texels;
    let triangles = |eye: Vec3, pixels: f32| {
        let mut camera = scene.camera.clone();
        camera.eye = eye;
        patches.levels(&camera, pixels, texels).triangles
    };
    let (near, far) = (triangles(Vec3::new(0.0, 0.3, 1.6), 6.0), triangles(Vec3::new(0.0, 3.0, 16.0), 6.0));
    let (coarse, fine) = (triangles(Vec3::new(0.0, 0.3, 2.9), 12.0), triangles(Vec3::new(0.0, 0.3, 2.9), 3.0));
    eprintln!("near {near}, far {far}; 12 px {coarse}, 3 px {fine}");
    assert!(near > 4 * far && fine > 4 * coarse, "near {near}, far {far}; 12 px {coarse}, 3 px {fine}");
    // The field's rule bounds it: no more than the uniform mesh has, however short the edges.
    let uniform = scene.meshes.last().expect("the uniform mesh").indices.len() as u64 / 3;
    assert!(triangles(Vec3::new(0.0, 0.3, 1.2), 0.5) <= uniform);
}

/// The bound: edges asked half a pixel long on a finely tessellated ball would make tens of
/// millions of triangles; the levels are made coarser until at most two million remain, and the
/// report says the edge length used.
#[test]
fn adaptive_tessellation_keeps_to_its_bound_and_says_so() {
    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    scene.settings.bump.method = BumpMethod::Displacement;
    scene.settings.bump.displacement_texels = 0.25;
    scene.settings.bump.edge_pixels = 0.5;
    scene.settings.sphere_segments = 192;
    scene.camera.width = 1920;
    scene.camera.height = 1440;
    displacement::displace(&mut scene);
    let (pass, _) = tessellated_on_the_gpu(&scene);
    let report = pass.report.clone().expect("a report");
    eprintln!("{}", report.summary());
    assert!(report.triangles <= tessellation::MAX_TRIANGLES && report.triangles > tessellation::MAX_TRIANGLES / 3);
    assert!(report.edge_pixels > 1.0 && report.summary().contains("forced longer edges"), "{}", report.summary());
}

/// What `bump.method = "normal"` does to a scene: nothing; and the summary says what was made.
#[test]
fn bump_mapping_leaves_the_scene_alone_and_displacement_says_what_it_made() {
    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    let before = (scene.objects.len(), scene.meshes.len(), scene.materials.len());
    assert_eq!(displacement::displace(&mut scene), Default::default());
    assert_eq!(before, (scene.objects.len(), scene.meshes.len(), scene.materials.len()));
    scene.settings.bump.method = BumpMethod::Displacement;
    let made = displacement::displace(&mut scene);
    assert_eq!(made.objects.len(), 1);
    assert!(made.triangles > 10_000, "{made:?}");
    let summary = made.summary().expect("a summary");
    assert!(summary.starts_with("displacement: 1 objects,") && !summary.contains("forced"), "{summary}");
    // The displaced material has no height field left: the geometry carries the relief.
    let material = &scene.materials[scene.objects[0].material.0];
    assert!(material.height_map.is_none() && material.height_field.is_none());
}

/// Bad input: a scale of 10³⁰ moves the surface off to where f32 ends, and the offsets that
/// are not finite stay unmoved: both renderers draw something, nothing panics. A tessellation
/// finer than the bound is made at the level the bound allows, and the summary says so.
#[test]
fn a_huge_scale_and_a_level_past_the_bound_are_handled() {
    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    scene.settings.bump.method = BumpMethod::Displacement;
    scene.settings.bump.scale = 1e30;
    displacement::displace(&mut scene);
    assert!(scene.meshes.iter().all(|m| m.positions.iter().all(|p| p.is_finite())));
    let _ = common::raster(&scene, &scene.settings);
    let _ = mirador::trace::render_image(&scene, &scene.settings);

    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    scene.settings.bump.method = BumpMethod::Displacement;
    scene.settings.bump.displacement_texels = 0.25;
    scene.settings.sphere_segments = 192;
    let made = displacement::displace(&mut scene);
    assert!(made.triangles <= MAX_TRIANGLES, "{made:?}");
    let summary = made.summary().expect("a summary");
    assert!(summary.contains("forced `ball` at level"), "{summary}");
}

/// The tessellation view (`bump.view = "tessellation"`) draws the displaced triangles' edges over
/// the ball, finer at a finer level; the bump-mapped ball, which is no mesh, gets none.
#[test]
fn the_tessellation_view_shows_the_displaced_triangles() {
    use mirador::settings::BumpView;
    let edge_pixels = |method: BumpMethod, texels: f32| {
        let mut scene = common::load("scenes/course/displacement-sphere.toml");
        scene.settings.bump.method = method;
        scene.settings.bump.displacement_texels = texels;
        displacement::displace(&mut scene);
        let mut settings = scene.settings.clone();
        settings.bump.view = BumpView::Tessellation;
        let image = common::raster(&scene, &settings);
        // The edges' colour: green well above red and blue (neither the ball nor the sky is).
        image.pixels().filter(|p| p.0[1] > 200 && p.0[0] < 200 && p.0[2] < 200).count()
    };
    let (coarse, fine, bumped) = (
        edge_pixels(BumpMethod::Displacement, 8.0),
        edge_pixels(BumpMethod::Displacement, 2.0),
        edge_pixels(BumpMethod::Normal, 2.0),
    );
    eprintln!("edge pixels: level 1 {coarse}, level 3 {fine}, bump-mapped {bumped}");
    assert_eq!(bumped, 0, "no mesh, no edges");
    assert!(coarse > 2_000 && fine > coarse, "{coarse} then {fine}");
}

/// What bump and parallax mapping cost, in the error budget: against the displaced surface they
/// stand for (the reference is traced on it), swapping them for it removes nearly all of the
/// difference on the grazing-lit plane, and with every approximation swapped nothing is left.
#[test]
fn the_budget_measures_bump_and_parallax_mapping_against_the_displaced_surface() {
    let gpu = common::gpu();
    for (method, least) in [(BumpMethod::Normal, 0.1), (BumpMethod::Parallax, 0.08)] {
        let mut scene = common::load("scenes/course/displacement-plane.toml");
        scene.settings.bump.method = method;
        let settings = scene.settings.clone();
        let reference = mirador::budget::reference_scene(&scene, &settings);
        let traced = mirador::trace::render_image(&reference, &settings);
        let budget = mirador::budget::budget(gpu, (&scene, &reference), &settings, traced);
        let relief = budget.items.iter().find(|i| i.name == "bump and parallax mapping").expect("the relief's row");
        eprintln!("{method:?}: whole {:.4}, relief alone {:.4}, floor {:.4}", budget.whole, relief.alone, budget.floor);
        assert!(relief.alone > least && relief.alone > 0.8 * budget.whole, "{method:?}: {}", budget.report());
        assert!(budget.floor < 0.005, "{method:?}: {}", budget.report());
    }
    // The other side: displaced already, the scene makes no such approximation.
    let mut scene = common::load("scenes/course/displacement-plane.toml");
    scene.settings.bump.method = BumpMethod::Displacement;
    let used = mirador::settings::Traced::Relief.row().in_use;
    assert!(!used(&scene.facts(), &scene.settings));
}

/// `mirador explain` on a bump-mapped ball says what the relief would change at the pixel: at
/// the outline, the relief standing out of the smooth circle; inside it, how much nearer the
/// displaced surface is met. Displaced already, or with no height field, it says nothing.
#[test]
fn explain_names_what_bump_mapping_leaves_out() {
    let gpu = common::gpu();
    let scene = common::load("scenes/course/displacement-sphere.toml");
    let explained = |scene: &Scene, pixel| {
        mirador::explain::explain(gpu, scene, &scene.settings, pixel).expect("the pixel is explained").relief
    };
    // Where the displaced ball covers the sky the bump-mapped one leaves (found on row 150).
    let traced = mirador::trace::render_image(&displacement::displaced(&scene), &scene.settings);
    let bumped = mirador::trace::render_image(&scene, &scene.settings);
    let sky = *bumped.get_pixel(0, 0);
    let is_sky = |p: &image::Rgba<u8>| p.0.iter().zip(sky.0).take(3).all(|(a, b)| a.abs_diff(b) <= 2);
    let outline = (0..scene.camera.width)
        .find(|&x| is_sky(bumped.get_pixel(x, 150)) && !is_sky(traced.get_pixel(x, 150)))
        .expect("a pixel of relief outside the circle");
    let said = explained(&scene, (outline, 150)).expect("the relief is named at the outline");
    assert!(said.contains("the relief stands out of the smooth outline"), "{said}");
    let said = explained(&scene, (230, 230)).expect("the relief is named inside");
    assert!(said.contains("nearer than the smooth one"), "{said}");
    // The other side: displaced already, and a scene without height fields.
    let displaced = with_method("scenes/course/displacement-sphere.toml", BumpMethod::Displacement);
    assert_eq!(explained(&displaced, (230, 230)), None);
    let plain = common::load("scenes/seed-simple.toml");
    assert_eq!(explained(&plain, (100, 100)), None);
}

/// Bad input on the GPU's path: a mesh with no texture coordinates or normals, a triangle with two
/// corners at one point and an index out of range is tessellated without a panic, every position
/// and normal a number (no coordinates: one height everywhere, the normals the faces'); a
/// displacement of 10³⁰ is left to the uniform mesh, said, and the frame drawn.
#[test]
fn adaptive_tessellation_takes_bad_input() {
    use mirador::scene::{Mesh, Shape};
    let mut scene = common::load("scenes/course/displacement-plane.toml");
    scene.meshes.push(Mesh {
        name: "bare".into(),
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::Z, Vec3::new(1.0, 0.0, 1.0)],
        normals: Vec::new(),
        uvs: Vec::new(),
        tangents: Vec::new(),
        indices: vec![0, 2, 1, 0, 2, 3, 1, 2, 4, 0, 1, 9],
    });
    scene.objects[0].shape = Shape::Mesh(scene.meshes.len() - 1);
    scene.settings.bump.method = BumpMethod::Displacement;
    displacement::displace(&mut scene);
    let (pass, _) = tessellated_on_the_gpu(&scene);
    let made = pass.read_back(common::gpu());
    let (vertices, indices) = &made[0];
    assert!(!indices.is_empty() && indices.iter().all(|&i| (i as usize) < vertices.len()));
    assert!(vertices.iter().all(|v| v.position.iter().chain(&v.normal).all(|x| x.is_finite())));

    let mut scene = common::load("scenes/course/displacement-sphere.toml");
    scene.settings.bump.method = BumpMethod::Displacement;
    scene.settings.bump.scale = 1e30;
    displacement::displace(&mut scene);
    let gpu = common::gpu();
    let mut pass = TessellationPass::default();
    pass.load(gpu, &scene);
    let mut geometry = SceneGeometry::new(&scene, &[], &[]);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    assert!(pass.prepare(gpu, &mut encoder, &scene, &scene.settings, &mut geometry).is_none());
    assert!(!geometry.has_displaced());
    let _ = common::raster(&scene, &scene.settings);
}
