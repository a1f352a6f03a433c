//! Procedural height fields for bump mapping (docs/course/04-bump-mapping.md): named from scene files, the same
//! field in WGSL and Rust, raster against ray traced, and finite differences against the
//! closed-form gradient.

mod common;

use std::path::Path;

use bytemuck::{Pod, Zeroable};
use glam::Vec2;
use mirador::scene::ProceduralHeight;
use mirador::scene::file::parse;
use mirador::texture::ValueNoise;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct NoiseCase {
    uv: [f32; 2],
    amplitude: f32,
    seed: u32,
    cells: u32,
    octaves: u32,
    _pad: [u32; 2],
}

#[test]
fn wgsl_value_noise_matches_rust() {
    let mut cases = Vec::new();
    for (k, (seed, cells, octaves)) in [(0u32, 1u32, 1u32), (7, 4, 3), (123, 5, 4), (9, 16, 2)].into_iter().enumerate()
    {
        for i in 0..64 {
            // Points inside the unit square, on lattice lines, and outside it (the field tiles).
            let uv = Vec2::new(i as f32 * 0.0731 - 1.3 + k as f32 * 0.01, (i * i % 97) as f32 / 41.0 - 0.8);
            cases.push(NoiseCase { uv: uv.to_array(), amplitude: 0.03, seed, cells, octaves, _pad: [0; 2] });
        }
    }
    let source = mirador::shaders::compose(include_str!("shaders/noise_probe.wgsl"));
    let bindings = common::ProbeBindings { input: 0, output: 1, extra: &[] };
    let gpu: Vec<[f32; 4]> = common::run_probe("noise_probe", &source, "cs_noise_probe", &cases, bindings);
    for (c, g) in cases.iter().zip(&gpu) {
        let field = ValueNoise { seed: c.seed, cells: c.cells, octaves: c.octaves, amplitude: c.amplitude };
        let (value, gradient) = field.evaluate(Vec2::from(c.uv));
        let scale = c.amplitude * (c.cells << (c.octaves - 1)) as f32;
        assert!((g[0] - value).abs() < 1e-5, "value at {:?}: WGSL {} vs Rust {value}", c.uv, g[0]);
        assert!(
            Vec2::new(g[1], g[2]).abs_diff_eq(gradient, 1e-4 * scale),
            "gradient at {:?}: WGSL {g:?} vs Rust {gradient}",
            c.uv
        );
    }
}

fn stage(height_field: &str) -> mirador::Scene {
    let text = format!(
        r#"
        [camera]
        eye = [0, 3, 2.2]
        center = [0, 0, 0]
        fovy = 45
        near = 0.1
        far = 20
        width = 200
        height = 150
        [world]
        ambient = [0.05, 0.05, 0.05]
        [materials.bumpy]
        color = [0.8, 0.8, 0.8]
        ks = 0.2
        shininess = 30
        bump_scale = 1
        height_field = {height_field}
        [[lights]]
        type = "directional"
        direction = [0.8, -0.5, -0.3]
        [[objects]]
        type = "plane"
        size = [4, 4]
        material = "bumpy"
        "#
    );
    parse(&text, Path::new("fields.toml")).unwrap_or_else(|e| panic!("{e}"))
}

const SINE: &str = r#"{ type = "sine", frequency = [4, 3], amplitude = 0.01 }"#;
const NOISE: &str = r#"{ type = "noise", seed = 3, cells = 4, octaves = 3, amplitude = 0.01 }"#;

#[test]
fn scene_files_name_procedural_fields() {
    let sine = stage(SINE);
    assert_eq!(
        sine.materials[0].height_field,
        Some(ProceduralHeight::Sine { frequency: Vec2::new(4.0, 3.0), amplitude: 0.01 })
    );
    let noise = stage(NOISE);
    assert_eq!(
        noise.materials[0].height_field,
        Some(ProceduralHeight::Noise { seed: 3, cells: 4, octaves: 3, amplitude: 0.01 })
    );
    let both = r#"
        [materials.m]
        height_map = "nothing.png"
        height_field = { type = "sine" }
    "#;
    let error = parse(both, Path::new("both.toml")).expect_err("one source of heights at most").to_string();
    assert!(error.contains("both.toml:") && (error.contains("not both") || error.contains("nothing.png")), "{error}");
    let bad = "[materials.m]\nheight_field = { type = \"noise\", frequency = [1, 1] }\n";
    let error = parse(bad, Path::new("bad.toml")).expect_err("frequency is the sine's").to_string();
    assert!(error.starts_with("bad.toml:2:") && error.contains("frequency"), "{error}");
}

#[test]
fn procedural_bumps_agree_between_the_renderers() {
    for (name, field) in [("sine", SINE), ("noise", NOISE)] {
        let scene = stage(field);
        let raster = common::raster(&scene, &scene.settings);
        let traced = mirador::trace::render_image(&scene, &scene.settings);
        let flip = common::difference(&traced, &raster).flip_mean;
        assert!(flip < 0.01, "{name}: FLIP mean {flip}");
        let mut flat = scene.settings.clone();
        flat.bump.enabled = false;
        let against_flat = common::flip(&traced, &common::raster(&scene, &flat));
        assert!(
            against_flat > 3.0 * flip,
            "{name}: the bumps matter ({against_flat} against flat, {flip} against bumped)"
        );
    }
}

#[test]
fn finite_differences_draw_what_the_analytic_gradient_draws() {
    for (name, field) in [("sine", SINE), ("noise", NOISE)] {
        let scene = stage(field);
        let mut analytic = scene.settings.clone();
        analytic.bump.analytic = true;
        for (renderer, a, b) in [
            ("raster", common::raster(&scene, &scene.settings), common::raster(&scene, &analytic)),
            (
                "ray traced",
                mirador::trace::render_image(&scene, &scene.settings),
                mirador::trace::render_image(&scene, &analytic),
            ),
        ] {
            let flip = common::difference(&a, &b).flip_mean;
            assert!(flip < 0.003, "{name}, {renderer}: finite differences against analytic, FLIP {flip}");
        }
    }
}
