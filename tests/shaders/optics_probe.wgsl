// Test-only compute pass: evaluates the WGSL optics (shaders/common/optics.wgsl) on a list of
// cases, so tests/refraction.rs can compare them with the Rust twins and the hand-computed values.

struct OpticsCase {
    // The view vector (unit, away from the surface) and the cosine of its angle to the normal.
    v: vec3f,
    cos_i: f32,
    // The outward geometric normal and the index of refraction.
    geometric: vec3f,
    ior: f32,
    // The shading normal, facing v; and η for fresnel().
    n: vec3f,
    eta: f32,
}

@group(0) @binding(0) var<storage, read> cases: array<OpticsCase>;
// Per case: F in x; then the refracted direction and 1 where there is one (else 0).
@group(0) @binding(1) var<storage, read_write> results: array<vec4f>;

@compute @workgroup_size(1)
fn cs_optics_probe(@builtin(global_invocation_id) id: vec3u) {
    let c = cases[id.x];
    let refracted = refract_view(c.v, c.geometric, c.n, c.ior);
    results[2u * id.x] = vec4f(fresnel(c.cos_i, c.eta), relative_index(c.v, c.geometric, c.ior), 0.0, 0.0);
    results[2u * id.x + 1u] = vec4f(refracted.direction, select(0.0, 1.0, refracted.valid));
}
