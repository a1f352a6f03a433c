// Light crossing a smooth interface (docs/course/06-transparency.md): Snell's law and Fresnel's
// equations, the WGSL twin of src/scene/optics.rs. tests/refraction.rs runs both on the same
// cases. `v` is the unit view vector (away from the surface), `geometric` the outward normal,
// `n` the shading normal turned to face `v`.

// η = n_i/n_t: 1/ior entering (v on the outside), ior leaving.
fn relative_index(v: vec3f, geometric: vec3f, ior: f32) -> f32 {
    return select(ior, 1.0 / ior, dot(v, geometric) > 0.0);
}

// What Snell's law gives: the refracted direction, or none on total internal reflection.
struct Refracted {
    direction: vec3f,
    valid: bool,
}

fn refract_view(v: vec3f, geometric: vec3f, n: vec3f, ior: f32) -> Refracted {
    let eta = relative_index(v, geometric, ior);
    let cos_i = clamp(dot(n, v), 0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t > 1.0 {
        return Refracted(vec3f(0.0), false);
    }
    let cos_t = sqrt(1.0 - sin2_t);
    return Refracted(normalize(-eta * v + (eta * cos_i - cos_t) * n), true);
}

// Fresnel's reflectance for unpolarized light, exact: the mean of r_s² and r_p²; 1 on total
// internal reflection, 0 for η = 1.
fn fresnel(cos_i_in: f32, eta: f32) -> f32 {
    if eta == 1.0 {
        return 0.0;
    }
    let cos_i = clamp(cos_i_in, 0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let r_s = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_p = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (r_s * r_s + r_p * r_p);
}

// A planar mirror (docs/course/07-planar-mirrors.md): the reflection about the plane
// n·p + d = 0 (`plane` = (n, d), n of unit length), world to world: p' = p − 2(n·p + d)·n. Its
// own inverse, with determinant −1. The WGSL twin of `reflection` in src/raster/mirror/mod.rs.
fn mirror_reflection(plane: vec4f) -> mat4x4f {
    let n = plane.xyz;
    let linear = mat3x3f(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0) - 2.0 * mat3x3f(n * n.x, n * n.y, n * n.z);
    return mat4x4f(vec4f(linear[0], 0.0), vec4f(linear[1], 0.0), vec4f(linear[2], 0.0), vec4f(-2.0 * plane.w * n, 1.0));
}

// Light through a volume (docs/course/11-volumes.md), the WGSL twin of src/volume/march.rs.

// A transfer function's opacity α is that of a slab one voxel thick; a sample standing for a
// slab `length` voxels thick lets (1 − α)^length through, so its opacity is 1 − (1 − α)^length.
fn corrected_opacity(alpha: f32, length: f32) -> f32 {
    return 1.0 - pow(1.0 - alpha, length);
}

// Front-to-back compositing of one sample (colour C_v, opacity α_v in `sample`) behind what the
// ray has gathered so far (premultiplied colour C_in, opacity α_in in `accumulated`):
// C_out = C_in + (1 − α_in)·α_v·C_v and α_out = α_in + (1 − α_in)·α_v.
fn composite_front_to_back(accumulated: vec4f, sample: vec4f) -> vec4f {
    let seen = (1.0 - accumulated.a) * sample.a;
    return vec4f(accumulated.rgb + seen * sample.rgb, accumulated.a + seen);
}
