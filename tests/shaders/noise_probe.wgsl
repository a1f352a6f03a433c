// Test-only compute pass: the WGSL value noise (shaders/common/bump.wgsl) at many points, so
// tests/height_fields.rs can compare it with src/texture/height.rs's ValueNoise.

struct NoiseCase {
    uv: vec2f,
    amplitude: f32,
    seed: u32,
    cells: u32,
    octaves: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<storage, read> cases: array<NoiseCase>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4f>;

@compute @workgroup_size(1)
fn cs_noise_probe(@builtin(global_invocation_id) id: vec3u) {
    let c = cases[id.x];
    results[id.x] = vec4f(value_noise(c.uv, c.seed, c.cells, c.octaves, c.amplitude), 0.0);
}
