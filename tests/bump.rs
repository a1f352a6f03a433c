//! Bump mapping (docs/course/04-bump-mapping.md): the WGSL helpers of `shaders/common/bump.wgsl` against their
//! Rust twins in `src/texture/` through a compute probe, the convergence of finite differences
//! to the analytic normal, mirrored texture coordinates, and tangent frames.

mod common;

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3, Vec4};
use mirador::scene::{ColorSpace, Mesh, Texture};
use mirador::texture::bump::{BumpParams, bump_normal, central_differences, finite_difference_gradient};
use mirador::texture::height::{HeightField, SineField, TextureHeight, ValueNoise};
use mirador::texture::lod::lod_from_uv_derivatives;
use mirador::texture::mipmap::level_colour;
use mirador::texture::perturbed_normal;
use mirador::texture::tangents::{mesh_tangents, normal_map_normal, tangents_from_edges, triangle_tangents};

/// xorshift32: reproducible inputs without a dependency.
struct Rng(u32);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }
    fn vec2(&mut self, lo: f32, hi: f32) -> Vec2 {
        Vec2::new(self.range(lo, hi), self.range(lo, hi))
    }
    fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
    fn unit(&mut self) -> Vec3 {
        loop {
            let v = self.vec3(-1.0, 1.0);
            if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ProbeCase {
    n: [f32; 3],
    du: f32,
    tu: [f32; 3],
    dv: f32,
    tv: [f32; 3],
    k: f32,
    samples: [f32; 4],
    uv: [f32; 2],
    delta: [f32; 2],
    frequency: [f32; 2],
    amplitude: f32,
    lod: f32,
    duv_dx: [f32; 2],
    duv_dy: [f32; 2],
    size: [f32; 2],
    bias: f32,
    normal_scale: f32,
    tangent: [f32; 4],
    rgb: [f32; 3],
    _pad0: f32,
    dp1: [f32; 3],
    _pad1: f32,
    dp2: [f32; 3],
    _pad2: f32,
    duv1: [f32; 2],
    duv2: [f32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ProbeResult {
    perturbed: [f32; 4],
    differences: [f32; 4],
    sine_gradient: [f32; 4],
    level_colour: [f32; 4],
    normal_mapped: [f32; 4],
    tu: [f32; 4],
    tv: [f32; 4],
}

fn probe_source() -> String {
    mirador::shaders::compose(include_str!("shaders/bump_probe.wgsl"))
}

fn cases() -> Vec<ProbeCase> {
    let mut rng = Rng(0x9e37_79b9);
    let mut cases: Vec<ProbeCase> = (0..256)
        .map(|i| {
            let n = rng.unit();
            // Tangents of any length and either handedness; every fourth case mirrored.
            let mut tu = rng.vec3(-3.0, 3.0);
            let tv = rng.vec3(-3.0, 3.0);
            if i % 4 == 0 {
                tu = -tu;
            }
            let uv1 = rng.vec2(-1.0, 1.0);
            // Keep the uv edges well conditioned so that validity is never a rounding question.
            let uv2 = Vec2::new(-uv1.y, uv1.x) * rng.range(0.5, 2.0) + rng.vec2(-0.2, 0.2);
            ProbeCase {
                n: n.to_array(),
                du: rng.range(-3.0, 3.0),
                tu: tu.to_array(),
                dv: rng.range(-3.0, 3.0),
                tv: tv.to_array(),
                k: rng.range(-2.0, 2.0),
                samples: [rng.next(), rng.next(), rng.next(), rng.next()],
                uv: rng.vec2(-1.0, 2.0).to_array(),
                delta: rng.vec2(1.0 / 1024.0, 1.0 / 16.0).to_array(),
                frequency: [(1 + i % 8) as f32, (1 + i % 5) as f32],
                amplitude: rng.range(0.01, 1.0),
                lod: rng.range(-1.0, 9.0),
                duv_dx: rng.vec2(-0.01, 0.01).to_array(),
                duv_dy: rng.vec2(-0.01, 0.01).to_array(),
                size: [(1u32 << (i % 13)) as f32, (3 + i * 7 % 1000) as f32],
                bias: rng.range(-1.0, 1.0),
                normal_scale: rng.range(0.0, 2.0),
                tangent: rng.unit().extend(if i % 3 == 0 { -1.0 } else { 1.0 }).to_array(),
                rgb: rng.vec3(0.0, 1.0).to_array(),
                _pad0: 0.0,
                dp1: rng.vec3(-2.0, 2.0).to_array(),
                _pad1: 0.0,
                dp2: rng.vec3(-2.0, 2.0).to_array(),
                _pad2: 0.0,
                duv1: uv1.to_array(),
                duv2: uv2.to_array(),
            }
        })
        .collect();
    // Degenerate inputs: zero tangents, collinear texture coordinates, a flat normal-map texel.
    let mut degenerate = cases[1];
    degenerate.tu = [0.0; 3];
    degenerate.tv = [0.0; 3];
    degenerate.du = 0.0;
    degenerate.dv = 0.0;
    degenerate.duv2 = (Vec2::from(degenerate.duv1) * 2.0).to_array();
    degenerate.rgb = [0.5, 0.5, 1.0];
    cases.push(degenerate);
    cases
}

fn wgsl_results(cases: &[ProbeCase]) -> Vec<ProbeResult> {
    let bindings = common::ProbeBindings { input: 0, output: 1, extra: &[] };
    common::run_probe("bump_probe", &probe_source(), "cs_bump_probe", cases, bindings)
}

fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

#[test]
fn probe_structs_match_their_wgsl_layout() {
    let source = probe_source();
    let module = naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    let size = |name: &str| {
        module
            .types
            .iter()
            .find_map(|(_, ty)| match &ty.inner {
                naga::TypeInner::Struct { span, .. } if ty.name.as_deref() == Some(name) => Some(*span as usize),
                _ => None,
            })
            .unwrap_or_else(|| panic!("no struct {name} in the probe"))
    };
    assert_eq!(size("BumpProbeCase"), std::mem::size_of::<ProbeCase>());
    assert_eq!(size("BumpProbeResult"), std::mem::size_of::<ProbeResult>());
}

#[test]
fn wgsl_bump_helpers_match_rust() {
    let cases = cases();
    let results = wgsl_results(&cases);
    let mut worst = [0f32; 7];
    for (i, (c, r)) in cases.iter().zip(&results).enumerate() {
        let n = Vec3::from(c.n);
        let rust = perturbed_normal(n, c.tu.into(), c.tv.into(), c.du, c.dv);
        let e = (v3(r.perturbed) - rust).abs().max_element();
        worst[0] = worst[0].max(e);
        assert!(e < 2e-5, "case {i}: perturbed_normal WGSL {} vs Rust {rust}", v3(r.perturbed));
        assert!(v3(r.perturbed).dot(n) >= 0.0, "case {i}: WGSL normal not oriented like n");

        let [a, b, cc, d] = c.samples;
        let rust = central_differences(a, b, cc, d, c.delta.into(), c.k);
        let wgsl = Vec2::new(r.differences[0], r.differences[1]);
        let e = ((wgsl - rust).abs() / rust.abs().max(Vec2::ONE)).max_element();
        worst[1] = worst[1].max(e);
        assert!(e < 1e-5, "case {i}: central differences WGSL {wgsl} vs Rust {rust}");

        let field = SineField { amplitude: c.amplitude, frequency: c.frequency.into() };
        let uv = Vec2::from(c.uv);
        // GPU sin/cos lose accuracy with the size of their argument, so the tolerance grows with it.
        let argument = (std::f32::consts::TAU * field.frequency * uv).abs().max_element();
        let e = (r.differences[2] - field.height(uv)).abs() / (c.amplitude * (1.0 + argument));
        worst[2] = worst[2].max(e);
        assert!(e < 1e-5, "case {i}: sine_height WGSL {} vs Rust {}", r.differences[2], field.height(uv));
        let rust = field.gradient(uv).expect("sine has a gradient");
        let wgsl = Vec2::new(r.sine_gradient[0], r.sine_gradient[1]);
        let scale = c.amplitude * std::f32::consts::TAU * field.frequency.max_element() * (1.0 + argument);
        let e = (wgsl - rust).abs().max_element() / scale;
        worst[3] = worst[3].max(e);
        assert!(e < 1e-5, "case {i}: sine_height_gradient WGSL {wgsl} vs Rust {rust}");

        let rust = lod_from_uv_derivatives(c.duv_dx.into(), c.duv_dy.into(), c.size.into(), c.bias);
        let e = (r.differences[3] - rust).abs() / (1.0 + rust.abs());
        worst[4] = worst[4].max(e);
        assert!(e < 1e-5, "case {i}: mip_lod WGSL {} vs Rust {rust}", r.differences[3]);

        let rust = level_colour(c.lod);
        assert!(v3(r.level_colour).abs_diff_eq(rust, 1e-6), "case {i}: level colour {} vs {rust}", v3(r.level_colour));

        let rust = normal_map_normal(n, c.tangent.into(), c.rgb.into(), c.normal_scale);
        let e = (v3(r.normal_mapped) - rust).abs().max_element();
        worst[5] = worst[5].max(e);
        assert!(e < 2e-5, "case {i}: normal_map_normal WGSL {} vs Rust {rust}", v3(r.normal_mapped));

        let rust = tangents_from_edges(c.dp1.into(), c.dp2.into(), c.duv1.into(), c.duv2.into());
        assert_eq!(r.tu[3] == 1.0, rust.is_some(), "case {i}: tangent validity differs");
        if let Some((tu, tv)) = rust {
            let scale = tu.abs().max_element().max(tv.abs().max_element()).max(1.0);
            let e = (v3(r.tu) - tu).abs().max_element().max((v3(r.tv) - tv).abs().max_element()) / scale;
            worst[6] = worst[6].max(e);
            assert!(e < 1e-5, "case {i}: tangents WGSL {} {} vs Rust {tu} {tv}", v3(r.tu), v3(r.tv));
        }
    }
    let last = cases.len() - 1;
    assert_eq!(v3(results[last].perturbed), Vec3::from(cases[last].n), "degenerate tangents must return n");
    assert_eq!(results[last].tu[3], 0.0, "collinear texture coordinates must be invalid");
    println!(
        "worst WGSL−Rust: perturbed {:.1e}, differences {:.1e} (rel), sine {:.1e}, sine gradient {:.1e}, \
         lod {:.1e}, normal map {:.1e}, tangents {:.1e} (rel)",
        worst[0], worst[1], worst[2], worst[3], worst[4], worst[5], worst[6]
    );
}

/// The angle between two unit vectors, accurate for small angles.
fn angle(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    a.cross(b).length().atan2(a.dot(b))
}

/// The worst angle between the finite-difference normal and the analytic one over many points.
fn max_normal_error(field: &dyn HeightField, delta: f32, k: f32) -> f64 {
    let mut rng = Rng(0x1234_5678);
    // A slanted, non-orthogonal, mirrored frame: the comparison must hold for any frame.
    let (n, tu, tv) = (Vec3::Z, Vec3::new(-1.5, 0.2, 0.0), Vec3::new(0.3, 0.8, 0.0));
    (0..2000)
        .map(|_| {
            let uv = rng.vec2(0.0, 1.0);
            let exact = k * field.gradient(uv).expect("procedural fields have gradients");
            let numeric = finite_difference_gradient(field, uv, Vec2::splat(delta), k);
            angle(perturbed_normal(n, tu, tv, numeric.x, numeric.y), perturbed_normal(n, tu, tv, exact.x, exact.y))
        })
        .fold(0.0, f64::max)
}

#[test]
fn finite_differences_converge_quadratically_to_the_analytic_normal() {
    // Each field with its feature size: the shortest period of the sine, the finest cell of the
    // noise. Central differences are O(Δ²) once Δ is small against it; before that (the noise's
    // quintic changes its third derivative from 60 to −30 within half a cell) the error falls
    // more slowly, though still faster than first order.
    let fields: [(&str, &dyn HeightField, f32); 2] = [
        ("sine 3×2, a = 0.05", &SineField { amplitude: 0.05, frequency: Vec2::new(3.0, 2.0) }, 1.0 / 3.0),
        (
            "value noise 2 cells, 2 octaves, a = 0.02",
            &ValueNoise { seed: 11, cells: 2, octaves: 2, amplitude: 0.02 },
            1.0 / 4.0,
        ),
    ];
    let deltas = [1.0 / 16.0, 1.0 / 64.0, 1.0 / 256.0, 1.0 / 1024.0];
    // Truncation error is O(Δ²); f32 rounding of f(u ± Δ) adds an error that grows like 1/Δ and
    // reaches ~2·10⁻⁵ rad at Δ = 1/1024 for these fields. Above QUADRATIC the first dominates.
    const QUADRATIC: f64 = 1e-3;
    const FLOAT_FLOOR: f64 = 1e-4;
    println!("max angle between finite-difference and analytic normals (radians), k = 1, 2000 points:");
    println!("{:<44} {:>10} {:>10} {:>10} {:>10}", "field", "Δ = 1/16", "1/64", "1/256", "1/1024");
    for (name, field, feature) in fields {
        let errors: Vec<f64> = deltas.iter().map(|&d| max_normal_error(field, d, 1.0)).collect();
        println!("{name:<44} {:>10.3e} {:>10.3e} {:>10.3e} {:>10.3e}", errors[0], errors[1], errors[2], errors[3]);
        let ratios: Vec<String> = errors.windows(2).map(|w| format!("{:.1}", w[0] / w[1])).collect();
        println!("{:<44} ratios {}", "", ratios.join(", "));
        assert!(errors[0] > 1e-2, "{name}: the coarsest step should show a real error, got {}", errors[0]);
        for (pair, w) in errors.windows(2).enumerate() {
            let ratio = w[0] / w[1];
            if w[0] <= QUADRATIC {
                // Near f32's floor: still decreasing, and small.
                assert!(w[1] < w[0] && w[1] < FLOAT_FLOOR, "{name}: step {pair}: {:.3e} → {:.3e}", w[0], w[1]);
            } else if deltas[pair] <= feature / 16.0 {
                // Δ/4 divides an O(Δ²) error by 16 (an O(Δ) one by 4).
                assert!(ratio > 12.0, "{name}: step {pair}: {:.3e} → {:.3e} is not quadratic", w[0], w[1]);
            } else {
                assert!(ratio > 6.0, "{name}: step {pair}: {:.3e} → {:.3e} is not better than O(Δ)", w[0], w[1]);
            }
        }
    }
}

#[test]
fn mirrored_texture_coordinates_move_bumps_but_never_invert_them() {
    // The world surface z = k·f(u(x, y), v(x, y)) over the plane z = 0, n = +z, mapped two ways:
    // A: u = x (t_u = +x, t_u × t_v = +n); B: u = 1 − x (t_u = −x, t_u × t_v = −n, mirrored).
    // In both, the bump-mapped normal must be the true normal (−∂z/∂x, −∂z/∂y, 1) of that surface.
    let field = SineField { amplitude: 0.08, frequency: Vec2::new(2.0, 3.0) };
    let k = 1.5;
    let mut rng = Rng(77);
    for _ in 0..200 {
        let (x, y) = (rng.range(0.0, 1.0), rng.range(0.0, 1.0));
        for (tu, u, du_dx) in [(Vec3::X, x, 1.0), (-Vec3::X, 1.0 - x, -1.0)] {
            let uv = Vec2::new(u, y);
            let g = k * field.gradient(uv).expect("sine has a gradient");
            let truth = Vec3::new(-g.x * du_dx, -g.y, 1.0).normalize();
            let bumped = perturbed_normal(Vec3::Z, tu, Vec3::Y, g.x, g.y);
            assert!(bumped.abs_diff_eq(truth, 1e-6), "u = {u}: bump {bumped}, true normal {truth}");
            // Without turning it to the side of n, the mirrored frame's normal points into the surface.
            let raw = (tu + g.x * Vec3::Z).cross(Vec3::Y + g.y * Vec3::Z);
            assert_eq!(raw.z > 0.0, du_dx > 0.0);
        }
    }
}

#[test]
fn a_height_ramp_texture_tilts_by_its_slope() {
    // Red 0, 32, …, 224 over 8 texels: at the centre of texel 3, one-texel central differences
    // read texels 4 and 2: (128 − 64)/255 over 2/8 in u, i.e. d_u = 256/255.
    let rgba8 = (0..8u8).flat_map(|i| [32 * i, 0, 0, 255]).collect();
    let texture = Texture { path: "ramp".into(), width: 8, height: 1, rgba8, color_space: ColorSpace::Linear };
    let field = TextureHeight::new(&texture);
    let uv = Vec2::new(3.5 / 8.0, 0.5);
    let d = finite_difference_gradient(&field, uv, field.default_delta(), 1.0);
    assert!((d.x - 256.0 / 255.0).abs() < 1e-5 && d.y == 0.0, "{d}");
    let n = bump_normal(&field, &BumpParams::default(), uv, Vec3::Z, Vec3::X, Vec3::Y);
    assert!(n.abs_diff_eq(Vec3::new(-256.0 / 255.0, 0.0, 1.0).normalize(), 1e-5), "{n}");
}

#[test]
fn mesh_tangents_follow_u_and_carry_the_handedness() {
    let mesh = Mesh::sphere(Vec3::ZERO, 2.0, 24);
    let tangents = mesh_tangents(&mesh);
    assert_eq!(tangents.len(), mesh.positions.len());
    for (t, n) in tangents.iter().zip(&mesh.normals) {
        assert!((t.truncate().length() - 1.0).abs() < 1e-4 && t.w.abs() == 1.0, "{t}");
        assert!(t.truncate().dot(*n).abs() < 1e-3, "tangent {t} not perpendicular to {n}");
    }
    let mut checked = 0;
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let Some((tu, tv)) = triangle_tangents(
            mesh.positions[a],
            mesh.positions[b],
            mesh.positions[c],
            mesh.uvs[a],
            mesh.uvs[b],
            mesh.uvs[c],
        ) else {
            continue;
        };
        for i in [a, b, c] {
            let (t, n) = (tangents[i], mesh.normals[i]);
            // Away from the poles and the seam, the vertex tangent leans the triangle's way…
            if mesh.uvs[i].y > 0.1 && mesh.uvs[i].y < 0.9 && mesh.uvs[i].x > 0.0 && mesh.uvs[i].x < 1.0 {
                assert!(t.truncate().dot(tu.normalize()) > 0.9, "vertex {i}: {t} vs ∂p/∂u {tu}");
                // …and w says on which side of n × t the v direction lies.
                assert_eq!(t.w > 0.0, n.cross(t.truncate()).dot(tv) > 0.0, "vertex {i}: sign {}", t.w);
                checked += 1;
            }
        }
    }
    assert!(checked > 500, "only {checked} vertices checked");
    // The sphere's v runs from the north pole down, so its frame is mirrored: w = −1.
    assert!(tangents[mesh.positions.len() / 2].w < 0.0);
}

#[test]
fn normal_map_in_a_mirrored_frame_mirrors_with_it() {
    // The same texel in a frame with w = −1 tilts along −b: the green axis follows the bitangent.
    let texel = Vec3::new(0.5, 0.85, 0.85);
    let right = normal_map_normal(Vec3::Z, Vec4::new(1.0, 0.0, 0.0, 1.0), texel, 1.0);
    let mirrored = normal_map_normal(Vec3::Z, Vec4::new(1.0, 0.0, 0.0, -1.0), texel, 1.0);
    assert!(right.y > 0.1 && mirrored.y < -0.1);
    assert!((right.y + mirrored.y).abs() < 1e-6 && (right.z - mirrored.z).abs() < 1e-6);
}
