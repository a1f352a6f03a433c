//! What the shading reads belongs to the view (`src/raster/view_group.rs`): an image that a
//! view's earlier phases make for its shading, the projected-shadow mask today, is made and read
//! by every view, so object-precision shadows (docs/course/05-shadows.md) show inside a planar
//! mirror (a mirrored camera's view) and inside a curved mirror's dynamic cube (six cube-face
//! views) as the tracer's shadow rays show them there.
//!
//! Each test compares the rasterizer with the tracer over the mirror's pixels only, and is
//! two-sided: the same pixels without any shadow (what a view without its own mask draws, as
//! mirrored views did before the view group) must be far from the tracer, and the shadow maps'
//! image (which every view always had) must agree as well as the projected one.

mod common;

use glam::Vec3;
use mirador::scene::LightKind;
use mirador::scene::file::parse;
use mirador::settings::{Parallax, ShadowMethod};
use mirador::{RenderSettings, Scene};

/// What both scenes share (a grey floor, a red material, the mirror's material
/// `mirror_material`), with `rest`: the camera, the light, the shadow's caster and the mirror.
fn scene(rest: &str, mirror_material: &str) -> Scene {
    let text = format!(
        r#"
        [world]
        ambient = [0.15, 0.15, 0.15]
        background = [0.3, 0.4, 0.55]
        [settings.shadows]
        fit = "scene"
        [settings.trace]
        max_depth = 2
        [materials.floor]
        color = [0.8, 0.8, 0.78]
        [materials.red]
        color = [0.8, 0.12, 0.08]
        [materials.mirror]
        {mirror_material}
        [[objects]]
        name = "floor"
        type = "plane"
        size = [14, 14]
        material = "floor"
        {rest}
        "#
    );
    parse(&text, &common::asset("scenes/shadows.toml")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// A pure mirror: nothing but `kps = 1`.
const CHROME: &str = "ka = 0\nkd = 0\nks = 0\nmirror = 1";
/// The same object as a flat magenta, to find its pixels in a traced image.
const MAGENTA: &str = "color = [1, 0, 1]\nka = 1\nkd = 1\nks = 0";

/// A planar mirror standing on the floor on the left, and a red block whose shadow falls towards
/// it from a light on the right: the mirror shows the block and its shadow on the floor.
fn planar(mirror_material: &str) -> Scene {
    let rest = r#"
        [camera]
        eye = [1.6, 1.5, 2.6]
        center = [-2.5, 0.6, -1.0]
        fovy = 50
        width = 240
        height = 160
        [[lights]]
        type = "point"
        position = [2.5, 3.0, -0.5]
        [[objects]]
        name = "block"
        type = "box"
        min = [-0.8, 0, -1.2]
        max = [0, 1.0, -0.4]
        material = "red"
        [[objects]]
        name = "mirror"
        type = "plane"
        size = [2.2, 3.4]
        rotate = [0, 0, -90]
        translate = [-2.5, 1.1, -0.8]
        material = "mirror"
    "#;
    scene(rest, mirror_material)
}

/// A chrome ball (a curved mirror: a dynamic cube) under a slab held above it, out of view, that
/// shades the floor all round the ball from a light overhead: the ball's lower half reflects the
/// shadowed floor.
fn ball(mirror_material: &str) -> Scene {
    let rest = r#"
        [camera]
        eye = [0.8, 1.7, 4.2]
        center = [0, 0.6, 0]
        fovy = 40
        width = 240
        height = 160
        [[lights]]
        type = "point"
        position = [0.3, 6.0, 0.2]
        [[objects]]
        name = "slab"
        type = "box"
        min = [-1.2, 2.4, -1.2]
        max = [1.2, 2.5, 1.2]
        material = "red"
        [[objects]]
        name = "ball"
        type = "sphere"
        center = [0, 0.6, 0]
        radius = 0.6
        material = "mirror"
    "#;
    scene(rest, mirror_material)
}

/// The pixels of the mirror object: magenta in the tracer's image of the scene with a magenta
/// mirror.
fn mirror_pixels(scene: fn(&str) -> Scene) -> Vec<bool> {
    let scene = scene(MAGENTA);
    let traced = mirador::trace::render_image(&scene, &scene.settings);
    traced.pixels().map(|p| p[0] > 60 && p[2] > 60 && p[1] < 20).collect()
}

/// The mean FLIP error of the rasterizer against the tracer over the pixels `inside`.
fn error_inside(scene: &Scene, settings: &RenderSettings, inside: &[bool]) -> f32 {
    let raster = common::raster(scene, settings);
    let traced = mirador::trace::render_image(scene, settings);
    let difference = common::difference(&traced, &raster);
    let (sum, count) = difference
        .flip_errors
        .iter()
        .zip(inside)
        .filter(|(_, inside)| **inside)
        .fold((0.0, 0), |(sum, count), (e, _)| (sum + e, count + 1));
    sum / count as f32
}

/// The rasterizer's error inside the mirror with projected shadows, with shadow maps, and
/// without shadows (against the tracer with its shadows).
fn errors(scene: fn(&str) -> Scene, settings: impl Fn(&mut RenderSettings)) -> (f32, f32, f32) {
    let inside = mirror_pixels(scene);
    let share = inside.iter().filter(|&&i| i).count() as f32 / inside.len() as f32;
    assert!(share > 0.05, "the mirror covers {share} of the image");
    let scene = scene(CHROME);
    let mut base = scene.settings.clone();
    settings(&mut base);
    let with = |method: ShadowMethod| {
        let mut s = base.clone();
        s.shadows.method = method;
        error_inside(&scene, &s, &inside)
    };
    let (projected, maps) = (with(ShadowMethod::Projected), with(ShadowMethod::Map));
    // No shadow drawn in the raster image, against the tracer's shadowed one.
    let raster_off = {
        let mut s = base.clone();
        s.shadows.enabled = false;
        common::raster(&scene, &s)
    };
    let traced = mirador::trace::render_image(&scene, &base);
    let errors = common::difference(&traced, &raster_off).flip_errors;
    let off = errors.iter().zip(&inside).filter(|(_, i)| **i).map(|(e, _)| e).sum::<f32>()
        / inside.iter().filter(|&&i| i).count() as f32;
    eprintln!("inside the mirror: projected {projected:.4}, shadow maps {maps:.4}, no shadows {off:.4}");
    (projected, maps, off)
}

#[test]
fn a_planar_mirror_shows_projected_shadows_as_the_tracer_does() {
    let (projected, maps, off) = errors(planar, |_| {});
    // Measured 0.006 (shadow maps 0.003): the ring of the polygons' edges against the rays'.
    assert!(projected < 0.02, "projected shadows in the mirror vs traced: FLIP {projected}");
    assert!(projected < maps + 0.01, "projected {projected} vs shadow maps {maps} in the mirror");
    assert!(off > 2.0 * projected && off > projected + 0.02, "no shadows in the mirror {off}, projected {projected}");
}

#[test]
fn a_dynamic_cube_shows_projected_shadows_as_the_tracer_does() {
    let (projected, maps, off) = errors(ball, |s| {
        s.environment.dynamic = true;
        s.environment.parallax = Parallax::Ground;
    });
    // Measured 0.12: the cube's own approximation (what it sees from the ball's centre), the same
    // with shadow maps.
    assert!(projected < 0.18, "projected shadows in the ball vs traced: FLIP {projected}");
    assert!(projected < maps + 0.01, "projected {projected} vs shadow maps {maps} in the ball");
    assert!(off > 1.5 * projected && off > projected + 0.02, "no shadows in the ball {off}, projected {projected}");
}

/// The rasterizer's error inside the mirror with shadow maps made to fail (no bias: acne over
/// every lit surface), with and without the hybrid's traced visibility (`hybrid.shadows`),
/// against the tracer; `light` moves the light.
fn traced_visibility_errors(
    scene: fn(&str) -> Scene,
    light: Option<Vec3>,
    settings: impl Fn(&mut RenderSettings),
) -> (f32, f32) {
    let inside = mirror_pixels(scene);
    let share = inside.iter().filter(|&&i| i).count() as f32 / inside.len() as f32;
    assert!(share > 0.05, "the mirror covers {share} of the image");
    let mut scene = scene(CHROME);
    if let (Some(position), LightKind::Point { position: p, .. }) = (light, &mut scene.lights[0].kind) {
        *p = position;
    }
    let mut acne = scene.settings.clone();
    settings(&mut acne);
    (acne.shadows.depth_bias, acne.shadows.slope_bias, acne.shadows.normal_offset) = (0, 0.0, 0.0);
    let mut traced = acne.clone();
    traced.hybrid.shadows = true;
    let (with, without) = (error_inside(&scene, &traced, &inside), error_inside(&scene, &acne, &inside));
    eprintln!("inside the mirror: traced visibility {with:.4}, shadow maps with acne {without:.4}");
    (with, without)
}

#[test]
fn a_planar_mirror_shows_the_hybrids_traced_shadows() {
    // The mirrored camera's own traced image: without it, the floor in the mirror keeps its acne.
    let (with, without) = traced_visibility_errors(planar, None, |_| {});
    // Measured 0.0003 (acne: 0.13).
    assert!(with < 0.01, "traced visibility in the mirror vs the tracer: FLIP {with}");
    assert!(without > with + 0.02, "acne in the mirror {without}, traced {with}");
}

#[test]
fn a_dynamic_cube_shows_the_hybrids_traced_shadows() {
    // Each cube face's own traced image (the faces share one set of targets, each copied in just
    // before the face draws). The light low and to the side, so the ball reflects lit floor.
    let (with, without) = traced_visibility_errors(ball, Some(Vec3::new(5.0, 2.0, 3.0)), |s| {
        s.environment.dynamic = true;
        s.environment.parallax = Parallax::Ground;
    });
    // Measured 0.094 (acne: 0.25): the cube's own approximation (what it sees from the ball's
    // centre) stays.
    assert!(with < 0.13, "traced visibility in the ball vs the tracer: FLIP {with}");
    assert!(without > with + 0.02, "acne in the ball {without}, traced {with}");
}

/// [`planar`] through an orthographic camera: the mirrored camera is orthographic too, its rays
/// parallel, each starting on the mirror.
fn planar_orthographic(mirror_material: &str) -> Scene {
    let mut scene = planar(mirror_material);
    let camera = &mut scene.camera;
    (camera.projection, camera.ortho_height, camera.near) = (mirador::scene::Projection::Orthographic, 5.0, 0.01);
    scene
}

#[test]
fn an_orthographic_mirrored_camera_shows_the_hybrids_traced_shadows() {
    let (with, without) = traced_visibility_errors(planar_orthographic, None, |_| {});
    // Measured 0.0000 (acne: 0.24).
    assert!(with < 0.01, "traced visibility in the mirror vs the tracer: FLIP {with}");
    assert!(without > with + 0.02, "acne in the mirror {without}, traced {with}");
}
