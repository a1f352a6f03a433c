// Environment maps (docs/course/08-environment-maps.md): the radiance arriving from a direction,
// stored three ways. Each mapping here has its Rust twin in src/scene/environment.rs, with the
// tests that pin the conventions; the passes that bind the maps are scene.wgsl (lookups and the
// background) and environment.wgsl (making one form from another).

const PI: f32 = 3.14159265358979;

struct Environment {
    // World to the sphere map's view space, for lookups: the current camera's rotation.
    sphere_from_world: mat3x3f,
    // Sphere-map view space to world, for making the map: the rotation it is made for, inverted.
    world_from_map: mat3x3f,
    zenith: vec3f,
    source: u32,
    horizon: vec3f,
    intensity: f32,
    ground: vec3f,
    sun_cos_outer: f32,
    // Unit vector towards the sun.
    sun_direction: vec3f,
    sun_cos_inner: f32,
    sun_color: vec3f,
    _pad0: f32,
    // Radiance of rays that hit nothing when there is no environment.
    background: vec3f,
    _pad1: f32,
    // The parallax proxy (PARALLAX_*): the box around the scene, its bottom the ground.
    proxy_min: vec3f,
    parallax: u32,
    proxy_max: vec3f,
    _pad2: f32,
    // Each dynamic cube's centre, where its six views were drawn from.
    cube_centres: array<vec4f, MAX_ENV_CUBES>,
}

// The direction to read a cube drawn from `centre` for the ray p + t·d (docs/course/
// 08-environment-maps.md#parallax): d itself when the ray is taken to end infinitely far, else
// the direction from the centre to where the ray meets the proxy: the ground plane (rays going
// down), or the wall of the box it leaves through.
fn parallax_direction(env: Environment, p: vec3f, d: vec3f, centre: vec3f) -> vec3f {
    if env.parallax == PARALLAX_GROUND {
        let ground = env.proxy_min.y;
        if d.y < 0.0 && p.y > ground {
            return p + ((ground - p.y) / d.y) * d - centre;
        }
        return d;
    }
    if env.parallax == PARALLAX_BOX {
        // Slabs: the nearest of the far planes along d (p is inside the box).
        let safe = select(d, vec3f(1e-12), abs(d) < vec3f(1e-12));
        let far = max((env.proxy_min - p) / safe, (env.proxy_max - p) / safe);
        let t = min(min(far.x, far.y), far.z);
        if t > 0.0 {
            return p + t * d - centre;
        }
    }
    return d;
}

// The procedural sky: a gradient from the horizon up to the zenith and down to the ground, and a
// sun disc with a soft rim (so sampled copies of it do not alias).
fn sky_radiance(env: Environment, direction: vec3f) -> vec3f {
    let d = normalize(direction);
    var c: vec3f;
    if d.y >= 0.0 {
        c = env.zenith + (env.horizon - env.zenith) * pow(1.0 - d.y, 3.0);
    } else {
        c = env.ground + (env.horizon - env.ground) * pow(1.0 + d.y, 8.0);
    }
    return c + env.sun_color * smoothstep(env.sun_cos_outer, env.sun_cos_inner, dot(d, env.sun_direction));
}

// Latitude–longitude: α = 2π·u (longitude), β = π·v (from +Y); u = ½ looks along −Z.
fn latlong_uv(d: vec3f) -> vec2f {
    let n = normalize(d);
    var alpha = atan2(-n.x, n.z);
    if alpha < 0.0 {
        alpha += 2.0 * PI;
    }
    return vec2f(alpha / (2.0 * PI), acos(clamp(n.y, -1.0, 1.0)) / PI);
}

fn latlong_direction(uv: vec2f) -> vec3f {
    let alpha = 2.0 * PI * uv.x;
    let beta = PI * uv.y;
    return vec3f(-sin(beta) * sin(alpha), cos(beta), sin(beta) * cos(alpha));
}

// OpenGL's sphere map: r in the map's view space (viewer along −Z), image row 0 at the top.
fn sphere_map_uv(r: vec3f) -> vec2f {
    let n = normalize(r);
    let m = 2.0 * sqrt(n.x * n.x + n.y * n.y + (n.z + 1.0) * (n.z + 1.0));
    // Straight back at the viewer (r = −z): the whole rim, as the tracer's `sphere_map_uv` reads it.
    if m < 1e-12 {
        return vec2f(0.5, 0.0);
    }
    return vec2f(n.x / m + 0.5, 0.5 - n.y / m);
}

// The reflected direction a sphere-map texel holds; outside the disc, the rim's.
fn sphere_map_direction(uv: vec2f) -> vec3f {
    var xy = vec2f(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
    let len = length(xy);
    if len > 1.0 {
        xy /= len;
    }
    let n = vec3f(xy, sqrt(max(1.0 - dot(xy, xy), 0.0)));
    return vec3f(2.0 * n.z * n.x, 2.0 * n.z * n.y, 2.0 * n.z * n.z - 1.0);
}

// The direction through texel coordinates uv of cube face `face` (+X −X +Y −Y +Z −Z), the
// Vulkan/OpenGL face table inverted: what the hardware's cube lookup picks that texel for.
fn cube_direction(face: u32, uv: vec2f) -> vec3f {
    let s = 2.0 * uv.x - 1.0;
    let t = 2.0 * uv.y - 1.0;
    switch face {
        case 0u: { return normalize(vec3f(1.0, -t, -s)); }
        case 1u: { return normalize(vec3f(-1.0, -t, s)); }
        case 2u: { return normalize(vec3f(s, 1.0, t)); }
        case 3u: { return normalize(vec3f(s, -1.0, -t)); }
        case 4u: { return normalize(vec3f(s, -t, 1.0)); }
        default: { return normalize(vec3f(-s, -t, -1.0)); }
    }
}

// Gradients of a lat–long lookup: the screen-space change of uv, with u's jump across the wrap
// (from 1 back to 0) taken the short way round, so the seam gets the same mip level as its
// neighbours.
fn latlong_gradient(duv: vec2f) -> vec2f {
    return vec2f(duv.x - round(duv.x), duv.y);
}
