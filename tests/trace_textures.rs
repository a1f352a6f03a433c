//! The ray tracer's textures (docs/course/03-mipmaps.md, docs/course/04-bump-mapping.md): mip-mapped lookups at the level a ray cone
//! picks, the level-colour view, and bump mapping with its teaching views. Every scene here is
//! lit so that a pixel's radiance is a known function of the texture: `ambient = 1`, `kd = 1`,
//! no lights gives `L = C` exactly.

use std::path::Path;

use glam::{Vec2, Vec3};
use mirador::RenderSettings;
use mirador::base::Ray;
use mirador::scene::Scene;
use mirador::scene::file::parse;
use mirador::settings::{AntiAliasing, BumpView, TextureFilter};
use mirador::texture::mipmap::level_colour;
use mirador::texture::{HeightField, LEVEL_PALETTE, MipChain, TextureHeight};
use mirador::trace::whitted::RayCounts;
use mirador::trace::{RadianceImage, RenderControl, Tracer};

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

/// The level of detail the tracer reads the texture at through image point `(x, y)`.
fn lod_at(tracer: &Tracer, scene: &Scene, x: f32, y: f32) -> Option<f32> {
    tracer.whitted.texture_lod(&scene.camera.ray_through(x, y), tracer.primary_cone)
}

fn mean(values: &[Vec3]) -> Vec3 {
    values.iter().sum::<Vec3>() / values.len().max(1) as f32
}

fn variance(values: &[Vec3]) -> f32 {
    let m = mean(values);
    values.iter().map(|v| (*v - m).length_squared()).sum::<f32>() / values.len().max(1) as f32
}

/// Pearson's correlation of two equally long series.
fn correlation(a: &[f32], b: &[f32]) -> f32 {
    let n = a.len() as f32;
    let (ma, mb) = (a.iter().sum::<f32>() / n, b.iter().sum::<f32>() / n);
    let cov: f32 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let (va, vb): (f32, f32) = (a.iter().map(|x| (x - ma).powi(2)).sum(), b.iter().map(|y| (y - mb).powi(2)).sum());
    cov / (va * vb).sqrt()
}

#[test]
fn one_texel_per_pixel_reads_level_0_so_trilinear_is_bilinear() {
    // Orthographic: the cone is one pixel = one texel wide everywhere, so λ = log2 1 = 0 exactly
    // and trilinear reads level 0 alone: the images are identical.
    let ortho = scene(&head_on_text("orthographic"));
    let tracer = Tracer::new(&ortho, &ortho.settings);
    for (x, y) in [(0.5, 0.5), (64.5, 64.5), (127.5, 3.5)] {
        assert_eq!(lod_at(&tracer, &ortho, x, y), Some(0.0), "pixel ({x}, {y})");
    }
    let trilinear = render(&ortho, &settings_with(&ortho, TextureFilter::Trilinear));
    let bilinear = render(&ortho, &settings_with(&ortho, TextureFilter::Bilinear));
    assert_eq!(trilinear, bilinear);
    // The plane is really textured: both checker colours show.
    let chain = checker_chain(&ortho);
    let spread = variance(&bilinear.pixels);
    assert!(spread > 0.1, "the image is not the checker: variance {spread}");
    assert!(bilinear.pixels.iter().any(|p| p.abs_diff_eq(chain.levels[0].texels[0].truncate(), 1e-6)));

    // Perspective: one texel per pixel at the centre (λ ≈ 0); off axis the cone grows slowly
    // (λ ≤ 0.1 at the corners), and trilinear may differ from bilinear by at most λ times the
    // largest difference between levels 0 and 1 (1 for colours in [0, 1]).
    let persp = scene(&head_on_text("perspective"));
    let tracer = Tracer::new(&persp, &persp.settings);
    let centre = lod_at(&tracer, &persp, 64.0, 64.0).expect("the centre ray hits the plane");
    assert!(centre.abs() < 1e-3, "centre λ = {centre}");
    let trilinear = render(&persp, &settings_with(&persp, TextureFilter::Trilinear));
    let bilinear = render(&persp, &settings_with(&persp, TextureFilter::Bilinear));
    let mut total = 0.0;
    for j in 0..128 {
        for i in 0..128 {
            let lod = lod_at(&tracer, &persp, i as f32 + 0.5, j as f32 + 0.5).expect("every ray hits the plane");
            assert!((-1e-3..0.1).contains(&lod), "pixel ({i}, {j}): λ = {lod}");
            let difference = (pixel(&trilinear, i, j) - pixel(&bilinear, i, j)).abs().max_element();
            assert!(difference <= lod.max(0.0) + 1e-6, "pixel ({i}, {j}): λ = {lod}, difference {difference}");
            total += difference;
        }
    }
    let mean_difference = total / (128.0 * 128.0);
    assert!(mean_difference < 5e-3, "mean difference {mean_difference}");
}

#[test]
fn mipmaps_turn_the_aliased_horizon_into_the_mean_colour() {
    let floor = scene(&floor_text(100));
    let tracer = Tracer::new(&floor, &floor.settings);
    let (width, height) = (floor.camera.width, floor.camera.height);
    // The far rows: every pixel on the floor and read at λ ≥ 6.5. The checker's squares are 32
    // texels, so from level 6 on (64 texels a texel) every texel is the mean of whole squares.
    let far: Vec<u32> = (0..height)
        .filter(|&j| {
            (0..width).all(|i| lod_at(&tracer, &floor, i as f32 + 0.5, j as f32 + 0.5).is_some_and(|l| l >= 6.5))
        })
        .collect();
    assert!(far.len() >= 5, "too few far rows: {far:?}");
    let texture_mean = checker_chain(&floor).levels[0].mean().truncate();
    let region = |image: &RadianceImage| -> (Vec<Vec3>, Vec<Vec3>) {
        let values = far.iter().flat_map(|&j| (0..width).map(move |i| (i, j))).map(|(i, j)| pixel(image, i, j));
        let steps = far.iter().flat_map(|&j| (0..width - 1).map(move |i| (i, j)));
        (values.collect(), steps.map(|(i, j)| pixel(image, i + 1, j) - pixel(image, i, j)).collect())
    };
    let step_energy = |steps: &[Vec3]| steps.iter().map(|d| d.length_squared()).sum::<f32>() / steps.len() as f32;

    // Bilinear, no mipmaps: each pixel is one point of the checker, nearly at random: neighbours
    // differ about as much as the two checker colours (|c₁ − c₂|² ≈ 0.98).
    let (_, steps) = region(&render(&floor, &settings_with(&floor, TextureFilter::Bilinear)));
    let aliased = step_energy(&steps);
    assert!(aliased > 0.2, "bilinear far rows do not alias: mean squared step {aliased}");

    // Trilinear: the far rows are the texture's mean colour, flat.
    let (values, steps) = region(&render(&floor, &settings_with(&floor, TextureFilter::Trilinear)));
    let far_mean = mean(&values);
    let relative = ((far_mean - texture_mean) / texture_mean).abs().max_element();
    assert!(relative < 0.01, "far mean {far_mean} vs texture mean {texture_mean}");
    assert!(variance(&values) < 1e-6, "far variance {}", variance(&values));
    assert!(step_energy(&steps) < 1e-6 * aliased, "far steps {}", step_energy(&steps));
}

/// The palette position closest to `colour`: the inverse of `level_colour` on its path (which
/// does not cross itself), to 1/256 of a level.
fn decode_level(colour: Vec3) -> f32 {
    (0..=7 * 256)
        .map(|k| k as f32 / 256.0)
        .min_by(|a, b| {
            let da = (level_colour(*a) - colour).length_squared();
            let db = (level_colour(*b) - colour).length_squared();
            da.total_cmp(&db)
        })
        .expect("the range is not empty")
}

#[test]
fn level_colours_rise_monotonically_towards_the_horizon() {
    // 32 texels a unit: the nearest rows are magnified (λ < 0, level 0). The material colour is
    // not white, to show that the level colour replaces C rather than tinting it.
    let text = floor_text(50).replace("color = [1, 1, 1]", "color = [0.2, 0.4, 0.6]");
    let floor = scene(&text);
    let settings = settings_with(&floor, TextureFilter::LevelColour);
    let tracer = Tracer::new(&floor, &settings);
    let image = render(&floor, &settings);
    let (width, height) = (floor.camera.width, floor.camera.height);
    let max_lod = checker_chain(&floor).max_lod();
    for j in 0..height {
        for i in 0..width {
            let got = pixel(&image, i, j);
            match lod_at(&tracer, &floor, i as f32 + 0.5, j as f32 + 0.5) {
                // The palette blended like trilinear, at λ clamped to the chain (as the GPU does).
                Some(lod) => {
                    let expected = level_colour(lod.clamp(0.0, max_lod));
                    assert!(got.abs_diff_eq(expected, 1e-6), "pixel ({i}, {j}): {got} vs {expected} at λ = {lod}");
                }
                None => assert_eq!(got, Vec3::ZERO, "pixel ({i}, {j}) misses the floor"),
            }
        }
    }
    // Up the centre column, from the nearest floor point to the farthest.
    let column = width / 2;
    assert_eq!(pixel(&image, column, height - 1), LEVEL_PALETTE[0], "up close: level 0's colour");
    let levels: Vec<f32> = (0..height)
        .rev()
        .take_while(|&j| lod_at(&tracer, &floor, column as f32 + 0.5, j as f32 + 0.5).is_some())
        .map(|j| decode_level(pixel(&image, column, j)))
        .collect();
    assert!(levels.windows(2).all(|w| w[1] >= w[0] - 1.0 / 256.0), "not monotonic: {levels:?}");
    let farthest = *levels.last().expect("the column sees the floor");
    assert!(farthest >= 6.0, "the horizon reads level {farthest}, expected the small levels");
    let distinct = levels.iter().map(|l| l.floor() as i32).collect::<std::collections::BTreeSet<_>>();
    assert!(distinct.len() >= 7, "levels along the floor: {distinct:?}");
}

#[test]
fn ray_cone_level_grows_like_log2_of_distance() {
    // Rays down at 45° onto the floor (|∂p/∂u| = |∂p/∂v| = 4: 64 texels a unit) from 1/4 to 8
    // units above it: λ = log2(t·γ/cos 45° · 64) with t = h·√2, one level more per doubling.
    let floor = scene(&floor_text(100));
    let tracer = Tracer::new(&floor, &floor.settings);
    let cone = tracer.primary_cone;
    let direction = Vec3::new(0.0, -1.0, -1.0).normalize();
    let mut previous: Option<f32> = None;
    for (k, h) in [0.25f32, 0.5, 1.0, 2.0, 4.0, 8.0].into_iter().enumerate() {
        // A different spot of the floor each time: the level does not depend on where.
        let target = Vec3::new(0.37 * k as f32, 0.0, -1.1 * k as f32);
        let ray = Ray { origin: target - direction * h * 2f32.sqrt(), direction };
        let lod = tracer.whitted.texture_lod(&ray, cone).expect("the ray hits the floor");
        let t = h * 2f32.sqrt();
        let expected = (t * cone.spread / std::f32::consts::FRAC_1_SQRT_2 * 64.0).log2();
        assert!((lod - expected).abs() < 1e-4, "h = {h}: λ = {lod}, expected {expected}");
        if let Some(p) = previous {
            assert!((lod - p - 1.0).abs() < 1e-4, "doubling the distance from h = {h}: Δλ = {}", lod - p);
        }
        previous = Some(lod);
    }
    // An orthographic cone keeps its width: the level does not change with distance.
    let parallel = mirador::texture::RayCone::orthographic(1.0 / 64.0);
    let levels: Vec<f32> = [1.0f32, 3.0, 9.0]
        .iter()
        .map(|&h| {
            let ray = Ray { origin: Vec3::new(0.0, h, 0.0), direction: Vec3::NEG_Y };
            tracer.whitted.texture_lod(&ray, parallel).expect("the ray hits the floor")
        })
        .collect();
    assert!(levels.iter().all(|&l| l.abs() < 1e-5), "{levels:?}");
}

#[test]
fn a_mirror_continues_the_cone_over_the_whole_path() {
    // Straight down onto a horizontal mirror 2 units below the eye; the reflected ray goes back up
    // past the eye to a textured ceiling 3 units above it: 7 units in all. The ceiling's level is
    // that of a 7-unit path, log2(7·γ·64), not of the 5-unit second leg.
    let text = format!(
        r#"
        [camera]
        eye = [0, 2, 0]
        center = [0, 0, 0]
        up = [0, 0, -1]
        fovy = 30
        near = 0.1
        far = 100
        width = 65
        height = 65
        [world]
        ambient = [1, 1, 1]
        background = [0, 0, 0]
        [materials.mirror]
        kd = 0
        mirror = 1
        [materials.checker]
        texture = "{checker}"
        kd = 1
        [[objects]]
        type = "plane"
        size = [4, 4]
        material = "mirror"
        [[objects]]
        type = "plane"
        size = [400, 400]
        uv_scale = [100, 100]
        translate = [0, 5, 0]
        material = "checker"
        "#,
        checker = texture_path("checker.png"),
    );
    let room = scene(&text);
    let settings = settings_with(&room, TextureFilter::LevelColour);
    let tracer = Tracer::new(&room, &settings);
    let got = tracer.primary(Vec2::new(32.5, 32.5), &mut RayCounts::default());
    let expected_lod = (7.0 * tracer.primary_cone.spread * 64.0).log2();
    let expected = level_colour(expected_lod);
    // To 1e-4: the reflected ray starts 1e-4 off the mirror, so the path is that much shorter.
    assert!(got.abs_diff_eq(expected, 1e-4), "{got} vs level_colour({expected_lod}) = {expected}");
    let second_leg_only = level_colour((5.0 * tracer.primary_cone.spread * 64.0).log2());
    assert!(!got.abs_diff_eq(second_leg_only, 1e-2), "the cone restarted at the mirror");
}

/// The texture coordinates the centre of pixel `(i, j)` sees on the plane of [`bump_text`]: the
/// camera's x is the world's x, its rows run along +z, and `uv = (x/2 + ½, z/2 + ½)`.
fn bump_uv(i: u32, j: u32) -> Vec2 {
    let x = (i as f32 + 0.5) / 128.0 - 0.5;
    let z = (j as f32 + 0.5) / 128.0 - 0.5;
    Vec2::new(x / 2.0 + 0.5, z / 2.0 + 0.5)
}

fn bump_render(bump_scale: f32, enabled: bool, view: BumpView) -> RadianceImage {
    let plane = scene(&bump_text(bump_scale));
    let mut settings = plane.settings.clone();
    settings.bump.enabled = enabled;
    settings.bump.view = view;
    render(&plane, &settings)
}

#[test]
fn bumps_redistribute_light_towards_the_side_facing_it() {
    let flat_value = std::f32::consts::FRAC_1_SQRT_2;
    let flat = bump_render(0.04, false, BumpView::Off);
    assert!(flat.pixels.iter().all(|p| p.abs_diff_eq(Vec3::splat(flat_value), 1e-5)), "bump off is the flat plane");

    // k = 0.01: slopes of about 8° on average (steeper at the cobbles' edges).
    let bumped = bump_render(0.01, true, BumpView::Off);
    let dented = bump_render(-0.01, true, BumpView::Off);
    for image in [&bumped, &dented] {
        let largest = image.pixels.iter().map(|p| (p.x - flat_value).abs()).fold(0.0, f32::max);
        assert!(largest > 0.15, "bumps change the shading: largest change {largest}");
        // Tilting normals moves light around: what one side of a cobble gains the other loses, to
        // first order in the slope; the mean loses only the second-order cos of the tilt.
        let m = mean(&image.pixels).x;
        assert!((m - flat_value).abs() < 0.01 * flat_value, "mean {m} vs flat {flat_value}");
        assert!(variance(&image.pixels) > 3e-3, "variance {}", variance(&image.pixels));
    }
    let plane = scene(&bump_text(0.01));
    let field = TextureHeight::new(&plane.textures[0]);
    let d = 1.0 / 256.0;
    let (mut slope, mut up, mut down) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..128 {
        for i in 0..128 {
            let uv = bump_uv(i, j);
            slope.push(-(field.height(uv + Vec2::new(d, 0.0)) - field.height(uv - Vec2::new(d, 0.0))) / (2.0 * d));
            up.push(pixel(&bumped, i, j).x);
            down.push(pixel(&dented, i, j).x);
        }
    }
    let lit_side = correlation(&up, &slope);
    let dent_side = correlation(&down, &slope);
    let mirrored = correlation(&up, &down);
    assert!(lit_side > 0.95, "bumps: correlation with −∂f/∂u {lit_side}");
    assert!(dent_side < -0.95, "dents: correlation with −∂f/∂u {dent_side}");
    assert!(mirrored < -0.95, "flipping k does not mirror the shading: correlation {mirrored}");
}

#[test]
fn normal_and_tangent_views() {
    // A flat plane facing +y, bump off: n = +y everywhere, shown as (0.5, 1, 0.5); its tangent
    // ∂p/∂u is +x: (1, 0.5, 0.5). No lighting is applied (the light would give 0.707).
    let normals = bump_render(0.04, false, BumpView::Normals);
    assert!(normals.pixels.iter().all(|&p| p == Vec3::new(0.5, 1.0, 0.5)), "{:?}", &normals.pixels[..3]);
    let tangents = bump_render(0.04, true, BumpView::Tangents);
    assert!(tangents.pixels.iter().all(|&p| p == Vec3::new(1.0, 0.5, 0.5)), "{:?}", &tangents.pixels[..3]);

    // Seen from below, the normal turned to the viewer is −y: (0.5, 0, 0.5).
    let below = scene(&bump_text(0.04).replace("eye = [0, 5, 0]", "eye = [0, -5, 0]"));
    let mut settings = below.settings.clone();
    settings.bump = mirador::settings::BumpSettings { enabled: false, view: BumpView::Normals, ..settings.bump };
    let image = render(&below, &settings);
    assert!(image.pixels.iter().all(|&p| p == Vec3::new(0.5, 0.0, 0.5)), "{:?}", &image.pixels[..3]);

    // Bumped, from below: the same relief, one surface seen from its other side (a bump from
    // above is a dent from below), so the normal is the one seen from above, negated. The camera
    // below sees x mirrored: its pixel (127 − i, j) looks at the point pixel (i, j) sees above.
    settings.bump.enabled = true;
    let from_below = render(&below, &settings);
    let from_above = bump_render(0.04, true, BumpView::Normals);
    for j in 0..128 {
        for i in 0..128 {
            let (up, down) = (pixel(&from_above, i, j), pixel(&from_below, 127 - i, j));
            assert!(down.abs_diff_eq(1.0 - up, 1e-6), "pixel ({i}, {j}): {down} from below, {up} from above");
        }
    }

    // With bumps, the view shows the very normal the shading uses: the lit image is
    // max(0, n'·l) with n' = 2·view − 1.
    let view = bump_render(0.04, true, BumpView::Normals);
    let lit = bump_render(0.04, true, BumpView::Off);
    let l = Vec3::new(1.0, 1.0, 0.0).normalize();
    let mut tilted = 0;
    for (shown, radiance) in view.pixels.iter().zip(&lit.pixels) {
        let n = 2.0 * *shown - 1.0;
        assert!((n.length() - 1.0).abs() < 1e-5, "not a unit normal: {n}");
        assert!((radiance.x - n.dot(l).max(0.0)).abs() < 1e-5, "{radiance} vs n'·l for n' = {n}");
        tilted += usize::from(n.y < 0.99);
    }
    assert!(tilted > 1000, "only {tilted} pixels have a bumped normal");
}

/// A bumped horizontal mirror seen at 45° by an orthographic camera, reflecting a wall 10 units
/// away split at height 10 into red (above) and green (below), so that a flat mirror shows the
/// split on one image row.
fn bumped_mirror_text(bump_scale: f32) -> String {
    format!(
        r#"
        [camera]
        eye = [0, 5, 5]
        center = [0, 0, 0]
        near = 0.1
        far = 100
        width = 96
        height = 96
        projection = "orthographic"
        ortho_height = 1.5
        [world]
        ambient = [0, 0, 0]
        background = [0, 0, 0]
        [materials.mirror]
        kd = 0
        mirror = 1
        height_map = "{height}"
        bump_scale = {bump_scale}
        [materials.red]
        kd = 0
        emission = [1, 0, 0]
        [materials.green]
        kd = 0
        emission = [0, 1, 0]
        [[objects]]
        type = "plane"
        size = [4, 4]
        material = "mirror"
        [[objects]]
        type = "plane"
        size = [40, 10]
        rotate = [90, 0, 0]
        translate = [0, 15, -10]
        material = "red"
        [[objects]]
        type = "plane"
        size = [40, 10]
        rotate = [90, 0, 0]
        translate = [0, 5, -10]
        material = "green"
        "#,
        height = texture_path("cobbles-height.png"),
    )
}

#[test]
fn a_bumped_mirror_reflects_about_the_bumped_normal() {
    let mirror = scene(&bumped_mirror_text(0.02));
    let mut settings = mirror.settings.clone();
    let lit = render(&mirror, &settings);
    settings.bump.view = BumpView::Normals;
    let view = render(&mirror, &settings);
    let (mut checked, mut moved) = (0, 0);
    for j in 0..96 {
        for i in 0..96 {
            let ray = mirror.camera.ray_through(i as f32 + 0.5, j as f32 + 0.5);
            let p = ray.at(-ray.origin.y / ray.direction.y);
            assert!(p.x.abs() < 2.0 && p.z.abs() < 2.0, "pixel ({i}, {j}) misses the mirror");
            // Where the reflection about the shown normal meets the wall, and about the flat one.
            let n = 2.0 * pixel(&view, i, j) - 1.0;
            let v = -ray.direction;
            let wall_height = |n: Vec3| {
                let r = 2.0 * n.dot(v) * n - v;
                p.y + r.y * (-10.0 - p.z) / r.z
            };
            let (y, flat_y) = (wall_height(n), wall_height(Vec3::Y));
            if (y - 10.0).abs() < 0.05 || !(0.0..20.0).contains(&y) {
                continue; // on the split, or off the wall
            }
            let expected = if y > 10.0 { Vec3::X } else { Vec3::Y };
            let got = pixel(&lit, i, j);
            assert!(got.abs_diff_eq(expected, 1e-6), "pixel ({i}, {j}): {got}, reflection meets the wall at {y}");
            checked += 1;
            moved += usize::from((y > 10.0) != (flat_y > 10.0));
        }
    }
    assert!(checked > 8000, "only {checked} pixels checked");
    assert!(moved > 50, "only {moved} pixels changed side because of the bumps");
}

#[test]
fn renders_are_deterministic() {
    let floor = scene(&floor_text(100));
    let mut settings = settings_with(&floor, TextureFilter::Trilinear);
    settings.trace.anti_aliasing = AntiAliasing::Jittered;
    assert_eq!(render(&floor, &settings), render(&floor, &settings));
    let plane = scene(&bump_text(0.04));
    assert_eq!(render(&plane, &plane.settings), render(&plane, &plane.settings));
}
