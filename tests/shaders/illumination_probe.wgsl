// Test-only compute pass: evaluates the WGSL illumination model (shaders/common/lighting.wgsl)
// on a list of cases, so tests/illumination.rs can compare it with the Rust model.

struct ProbeCase {
    color: vec3f,
    ka: f32,
    specular_color: vec3f,
    kd: f32,
    emission: vec3f,
    ks: f32,
    normal: vec3f,
    shininess: f32,
    view: vec3f,
    terms: u32,
    point: vec3f,
    _pad0: f32,
    ambient: vec3f,
    _pad1: f32,
    light: Light,
}

@group(0) @binding(0) var<storage, read> cases: array<ProbeCase>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4f>;

@compute @workgroup_size(1)
fn cs_illumination_probe(@builtin(global_invocation_id) id: vec3u) {
    let c = cases[id.x];
    let surface = Surface(c.color, c.ka, c.kd, c.ks, c.specular_color, c.shininess, c.emission);
    let n = facing_viewer(c.normal, c.view);
    var radiance = emitted_and_ambient(surface, c.ambient, c.terms);
    let incidence = light_incidence(c.light, c.point);
    if incidence.valid {
        radiance += direct(surface, n, c.view, incidence, c.terms);
    }
    results[id.x] = vec4f(radiance, 0.0);
}
