//! Known answers for the illumination model (docs/course/02-illumination.md): cases computed by hand, evaluated
//! by the Rust model (`src/scene/shading.rs`, the ray tracer's) and by the WGSL model
//! (`shaders/common/lighting.wgsl`, the rasterizer's) through a tiny compute pass.

mod common;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use mirador::raster::uniforms::GpuLight;
use mirador::scene::shading::{SurfaceSample, Terms, local_illumination};
use mirador::scene::{Attenuation, Light, LightKind};

#[derive(Clone)]
struct Case {
    name: &'static str,
    surface: SurfaceSample,
    normal: Vec3,
    view: Vec3,
    point: Vec3,
    ambient: Vec3,
    light: Light,
    terms: Terms,
    /// Worked out by hand, where given.
    expected: Option<Vec3>,
}

fn surface() -> SurfaceSample {
    SurfaceSample {
        color: Vec3::new(0.5, 0.25, 1.0),
        ka: 0.1,
        kd: 0.6,
        ks: 0.4,
        specular_color: Vec3::ONE,
        shininess: 2.0,
        emission: Vec3::new(0.01, 0.02, 0.03),
    }
}

fn light(kind: LightKind, color: Vec3, intensity: f32, attenuation: Attenuation) -> Light {
    Light { name: "probe".into(), kind, color, intensity, attenuation }
}

fn cases() -> Vec<Case> {
    let base = Case {
        name: "point light, inverse square",
        surface: surface(),
        normal: Vec3::Z,
        view: Vec3::new(0.6, 0.0, 0.8),
        point: Vec3::ZERO,
        ambient: Vec3::splat(0.2),
        light: light(
            LightKind::Point { position: Vec3::new(0.0, 3.0, 4.0) },
            Vec3::new(1.0, 0.5, 0.25),
            2.0,
            Attenuation::InverseSquare,
        ),
        terms: Terms::ALL,
        // d = 5, l = (0, 0.6, 0.8), n·l = 0.8, S = (2, 1, 0.5)/25 = (0.08, 0.04, 0.02).
        // r = 2·0.8·n − l = (0, −0.6, 0.8), r·v = 0.64, ks·0.64² = 0.16384.
        // L_dir = ka·C + kd·C·0.8 + 0.16384 = 0.58·C + 0.16384 = (0.45384, 0.30884, 0.74384).
        // S ⊗ L_dir = (0.0363072, 0.0123536, 0.0148768).
        // ME + A ⊗ kd·C = (0.01, 0.02, 0.03) + 0.12·C = (0.07, 0.05, 0.15).
        expected: Some(Vec3::new(0.1063072, 0.0623536, 0.1648768)),
    };
    vec![
        Case {
            name: "directional light behind the surface: only ka·C and ME + AG",
            light: light(LightKind::Directional { direction: Vec3::Z }, Vec3::ONE, 1.0, Attenuation::None),
            // n·l = −1: ka·C·S = (0.05, 0.025, 0.1), plus (0.07, 0.05, 0.15).
            expected: Some(Vec3::new(0.12, 0.075, 0.25)),
            ..base.clone()
        },
        Case { name: "normal facing away from the viewer is turned round", normal: -Vec3::Z, ..base.clone() },
        Case {
            name: "specular and ambient off",
            terms: Terms { ambient: false, specular: false, ..Terms::ALL },
            // kd·C·0.8·S + ME = 0.48·C·S + ME = (0.0192, 0.0048, 0.0096) + (0.01, 0.02, 0.03).
            expected: Some(Vec3::new(0.0292, 0.0248, 0.0396)),
            ..base.clone()
        },
        Case {
            name: "spot light in its smooth rim",
            light: light(
                LightKind::Spot {
                    position: Vec3::new(0.0, 0.0, 2.0),
                    direction: Vec3::NEG_Z,
                    inner: 10f32.to_radians(),
                    outer: 20f32.to_radians(),
                },
                Vec3::ONE,
                1.0,
                Attenuation::None,
            ),
            point: Vec3::new(2.0 * 15f32.to_radians().tan(), 0.0, 0.0),
            expected: None,
            ..base.clone()
        },
        Case { name: "the hand-computed point light", ..base.clone() },
    ]
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ProbeCase {
    color: [f32; 3],
    ka: f32,
    specular_color: [f32; 3],
    kd: f32,
    emission: [f32; 3],
    ks: f32,
    normal: [f32; 3],
    shininess: f32,
    view: [f32; 3],
    terms: u32,
    point: [f32; 3],
    _pad0: f32,
    ambient: [f32; 3],
    _pad1: f32,
    light: GpuLight,
}

impl From<&Case> for ProbeCase {
    fn from(c: &Case) -> ProbeCase {
        let t = c.terms;
        ProbeCase {
            color: c.surface.color.to_array(),
            ka: c.surface.ka,
            specular_color: c.surface.specular_color.to_array(),
            kd: c.surface.kd,
            emission: c.surface.emission.to_array(),
            ks: c.surface.ks,
            normal: c.normal.to_array(),
            shininess: c.surface.shininess,
            view: c.view.to_array(),
            terms: u32::from(t.ambient)
                | u32::from(t.diffuse) << 1
                | u32::from(t.specular) << 2
                | u32::from(t.emission) << 3,
            point: c.point.to_array(),
            _pad0: 0.0,
            ambient: c.ambient.to_array(),
            _pad1: 0.0,
            light: c.light.to_gpu(),
        }
    }
}

fn rust_model(c: &Case) -> Vec3 {
    let incidence = c.light.incidence(c.point).expect("the point is not at the light");
    local_illumination(&c.surface, c.normal, c.view, c.ambient, [(&incidence, Vec3::ONE)], c.terms)
}

fn wgsl_model(cases: &[Case]) -> Vec<Vec3> {
    let source = mirador::shaders::compose(include_str!("shaders/illumination_probe.wgsl"));
    let inputs: Vec<ProbeCase> = cases.iter().map(ProbeCase::from).collect();
    let bindings = common::ProbeBindings { input: 0, output: 1, extra: &[] };
    let values: Vec<[f32; 4]> =
        common::run_probe("illumination_probe", &source, "cs_illumination_probe", &inputs, bindings);
    values.iter().map(|v| Vec3::new(v[0], v[1], v[2])).collect()
}

#[test]
fn rust_model_matches_the_hand_computed_values() {
    for case in cases() {
        if let Some(expected) = case.expected {
            let got = rust_model(&case);
            assert!(got.abs_diff_eq(expected, 1e-6), "{}: {got} vs {expected}", case.name);
        }
    }
}

#[test]
fn wgsl_model_matches_the_rust_model() {
    let cases = cases();
    let gpu_values = wgsl_model(&cases);
    for (case, gpu) in cases.iter().zip(gpu_values) {
        let cpu = rust_model(case);
        assert!(gpu.abs_diff_eq(cpu, 1e-5 * cpu.max_element().max(1.0)), "{}: WGSL {gpu} vs Rust {cpu}", case.name);
        if let Some(expected) = case.expected {
            assert!(gpu.abs_diff_eq(expected, 1e-5), "{}: WGSL {gpu} vs hand {expected}", case.name);
        }
    }
}

#[test]
fn spot_rim_is_between_dark_and_full() {
    let case = cases().into_iter().find(|c| c.name.starts_with("spot")).unwrap();
    let inside = Case { point: Vec3::ZERO, ..cases().into_iter().find(|c| c.name.starts_with("spot")).unwrap() };
    let rim = rust_model(&case);
    let full = rust_model(&inside);
    let unlit = emitted_and_ambient_only(&case);
    assert!(rim.x > unlit.x && rim.x < full.x, "rim {rim}, unlit {unlit}, full {full}");
}

fn emitted_and_ambient_only(c: &Case) -> Vec3 {
    mirador::scene::shading::emitted_and_ambient(&c.surface, c.ambient, c.terms)
}
