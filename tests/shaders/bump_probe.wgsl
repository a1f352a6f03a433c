// Test-only compute pass: evaluates the WGSL bump-mapping and mip helpers
// (shaders/common/bump.wgsl) on a list of cases, so tests/bump.rs can compare them with their
// Rust twins in src/texture/.

struct BumpProbeCase {
    n: vec3f,
    du: f32,
    tu: vec3f,
    dv: f32,
    tv: vec3f,
    k: f32,
    // f(u+Δ, v), f(u−Δ, v), f(u, v+Δ), f(u, v−Δ)
    samples: vec4f,
    uv: vec2f,
    delta: vec2f,
    frequency: vec2f,
    amplitude: f32,
    lod: f32,
    duv_dx: vec2f,
    duv_dy: vec2f,
    size: vec2f,
    bias: f32,
    normal_scale: f32,
    tangent: vec4f,
    rgb: vec3f,
    _pad0: f32,
    dp1: vec3f,
    _pad1: f32,
    dp2: vec3f,
    _pad2: f32,
    duv1: vec2f,
    duv2: vec2f,
}

struct BumpProbeResult {
    perturbed: vec4f,
    // xy: central differences, z: sine height, w: mip_lod.
    differences: vec4f,
    // xy: sine gradient.
    sine_gradient: vec4f,
    level_colour: vec4f,
    normal_mapped: vec4f,
    // w: 1 where the tangents are valid.
    tu: vec4f,
    tv: vec4f,
}

@group(0) @binding(0) var<storage, read> cases: array<BumpProbeCase>;
@group(0) @binding(1) var<storage, read_write> results: array<BumpProbeResult>;

@compute @workgroup_size(1)
fn cs_bump_probe(@builtin(global_invocation_id) id: vec3u) {
    let c = cases[id.x];
    var r: BumpProbeResult;
    r.perturbed = vec4f(perturbed_normal(c.n, c.tu, c.tv, c.du, c.dv), 0.0);
    let d = bump_central_differences(c.samples.x, c.samples.y, c.samples.z, c.samples.w, c.delta, c.k);
    r.differences = vec4f(d, sine_height(c.uv, c.frequency, c.amplitude), mip_lod(c.duv_dx, c.duv_dy, c.size, c.bias));
    r.sine_gradient = vec4f(sine_height_gradient(c.uv, c.frequency, c.amplitude), 0.0, 0.0);
    r.level_colour = vec4f(mip_level_colour(c.lod), 0.0);
    r.normal_mapped = vec4f(normal_map_normal(c.n, c.tangent, c.rgb, c.normal_scale), 0.0);
    let t = tangents_from_derivatives(c.dp1, c.dp2, c.duv1, c.duv2);
    r.tu = vec4f(t.tu, select(0.0, 1.0, t.valid));
    r.tv = vec4f(t.tv, 0.0);
    results[id.x] = r;
}
