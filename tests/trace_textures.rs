//! The ray tracer's textures (TECHNIQUES.md §2, §3): mip-mapped lookups at the level a ray cone
//! picks, the level-colour view, and bump mapping with its teaching views. Every scene here is
//! lit so that a pixel's radiance is a known function of the texture: `ambient = 1`, `kd = 1`,
//! no lights gives `L = C` exactly.

use std::path::Path;

use glam::{Vec2, Vec3};
use mirador::scene::file::parse;
use mirador::scene::{Ray, Scene};
use mirador::settings::{AntiAliasing, BumpView, TextureFilter};
use mirador::texture::mipmap::level_colour;
use mirador::texture::{HeightField, LEVEL_PALETTE, MipChain, TextureHeight};
use mirador::trace::whitted::RayCounts;
use mirador::trace::{RadianceImage, RenderControl, Tracer};
use mirador::RenderSettings;

fn texture_path(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets").join("textures").join(name).display().to_string()
}

fn scene(text: &str) -> Scene {
    parse(text, Path::new("t.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn render(scene: &Scene, settings: &RenderSettings) -> RadianceImage {
    let tracer = Tracer::new(scene, settings);
    tracer.render(&RenderControl::default()).expect("nothing cancels this render").0
}

fn settings_with(scene: &Scene, filter: TextureFilter) -> RenderSettings {
    let mut settings = scene.settings.clone();
    settings.textures.filter = filter;
    settings
}

fn pixel(image: &RadianceImage, i: u32, j: u32) -> Vec3 {
    image.pixels[(j * image.width + i) as usize]
}

/// A 2×2 plane with the cobbles height map (once), seen straight down by an orthographic camera
/// at one texel per pixel over its middle half (128 × 128 pixels), lit by a white directional
/// light at 45° from +x: a flat plane has `L = kd·(n·l) = cos 45°`.
fn bump_text(bump_scale: f32) -> String {
    format!(
        r#"
        [camera]
        eye = [0, 5, 0]
        center = [0, 0, 0]
        up = [0, 0, -1]
        near = 0.1
        far = 100
        width = 128
        height = 128
        projection = "orthographic"
        ortho_height = 1
        [world]
        ambient = [0, 0, 0]
        background = [0, 0, 0]
        [materials.cobbles]
        color = [1, 1, 1]
        kd = 1
        height_map = "{height}"
        bump_scale = {bump_scale}
        [[lights]]
        type = "directional"
        direction = [-1, -1, 0]
        intensity = 1
        [[objects]]
        type = "plane"
        size = [2, 2]
        material = "cobbles"
        "#,
        height = texture_path("cobbles-height.png"),
    )
}

/// The checker texture's level 0 in linear values, and its mean.
fn checker_chain(scene: &Scene) -> MipChain {
    MipChain::build(&scene.textures[0])
}

/// A camera straight down the y axis onto a 2×2 plane textured once with the 256² checker.
/// Perspective: fovy 20°, 128×128 pixels, at the height where one pixel's cone covers one texel
/// at the centre: h·γ = 2/256, γ = atan(2·tan 10°/128). The image then spans 1 unit = 128 texels.
fn head_on_text(projection: &str) -> String {
    let gamma = (2.0 * 10f32.to_radians().tan() / 128.0).atan();
    let height = (2.0 / 256.0) / gamma;
    format!(
        r#"
        [camera]
        eye = [0, {height}, 0]
        center = [0, 0, 0]
        up = [0, 0, -1]
        fovy = 20
        near = 0.1
        far = 100
        width = 128
        height = 128
        projection = "{projection}"
        ortho_height = 1
        [world]
        ambient = [1, 1, 1]
        background = [0, 0, 0]
        [materials.checker]
        color = [1, 1, 1]
        texture = "{checker}"
        kd = 1
        [[objects]]
        type = "plane"
        size = [2, 2]
        material = "checker"
        "#,
        checker = texture_path("checker.png"),
    )
}

/// A checker floor 400 × 400 units, the texture repeated every `400/repeats` units, seen from 1
/// unit above, looking down by 12°, out to the horizon.
fn floor_text(repeats: u32) -> String {
    format!(
        r#"
        [camera]
        eye = [0, 1, 0]
        center = [0, 0.7874, -1]
        fovy = 40
        near = 0.05
        far = 1000
        width = 160
        height = 120
        [world]
        ambient = [1, 1, 1]
        background = [0, 0, 0]
        [materials.checker]
        color = [1, 1, 1]
        texture = "{checker}"
        kd = 1
        [[objects]]
        type = "plane"
        size = [400, 400]
        uv_scale = [{repeats}, {repeats}]
        material = "checker"
        "#,
        checker = texture_path("checker.png"),
    )
}


#[test]
fn explore() {
    let s = scene(&floor_text(100));
    let tracer = Tracer::new(&s, &s.settings);
    let far: Vec<u32> = (0..120).filter(|&j| (0..160).all(|i| tracer.whitted.texture_lod(&s.camera.ray_through(i as f32 + 0.5, j as f32 + 0.5), tracer.primary_cone).is_some_and(|l| l >= 6.5))).collect();
    eprintln!("far rows {far:?}");
    for filter in [TextureFilter::Bilinear, TextureFilter::Trilinear, TextureFilter::NearestMip, TextureFilter::Nearest] {
        let img = render(&s, &settings_with(&s, filter));
        let vals: Vec<Vec3> = far.iter().flat_map(|&j| (0..160).map(move |i| (i, j))).map(|(i, j)| pixel(&img, i, j)).collect();
        let mean = vals.iter().sum::<Vec3>() / vals.len() as f32;
        let var = vals.iter().map(|v| (*v - mean).length_squared()).sum::<f32>() / vals.len() as f32;
        let diffs: Vec<Vec3> = far.iter().flat_map(|&j| (0..159).map(move |i| (i, j))).map(|(i, j)| pixel(&img, i + 1, j) - pixel(&img, i, j)).collect();
        let dvar = diffs.iter().map(|d| d.length_squared()).sum::<f32>() / diffs.len() as f32;
        eprintln!("{filter:?}: mean {mean} var {var} diffvar {dvar}");
    }
    let h = scene(&bump_text(1.0));
    let field = TextureHeight::new(&h.textures[0]);
    let g: Vec<f32> = (0..256 * 256).map(|k| { let uv = Vec2::new((k % 256) as f32 + 0.5, (k / 256) as f32 + 0.5) / 256.0; let d = 1.0 / 256.0; (field.height(uv + Vec2::X * d) - field.height(uv - Vec2::X * d)) / (2.0 * d) }).collect();
    let rms = (g.iter().map(|x| x * x).sum::<f32>() / g.len() as f32).sqrt();
    eprintln!("height mean {} rms du {}", field.level.mean(), rms);
}
