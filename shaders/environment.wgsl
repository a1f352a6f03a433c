// Making environment maps (docs/course/08-environment-maps.md): one triangle over a target texture, each texel
// finding the direction it stores and asking the source for the radiance there. So any source
// (the procedural sky, a lat–long image, six cube faces, a sphere-map image) becomes any lookup
// form: a cube (each face a draw, the face index passed as the instance), a lat–long map, or a
// sphere map made from a cube for one view. src/raster/environment/mod.rs draws them; the
// mappings are shaders/common/environment.wgsl. Each source is read with implicit gradients, so
// a big source feeding a small target is read at the mip level of the target's texels.
//
// The teaching views (`environment.view`) are here too: the cube unfolded as a cross, the sphere
// map and the lat–long map drawn over the frame.

@group(0) @binding(0) var<uniform> environment: Environment;
@group(0) @binding(1) var env_sampler: sampler;
// The lat–long or sphere-map source image.
@group(0) @binding(2) var source_2d: texture_2d<f32>;
// The cube source: the world's cube.
@group(0) @binding(3) var source_cube: texture_cube<f32>;
// The reflective objects' dynamic cubes, for the cross view of the first. A cube of the array
// cannot be viewed as a cube of its own on GL (src/gpu/texture.rs, Layers).
@group(0) @binding(4) var source_cubes: CubeArray;

struct ConvertOut {
    @builtin(position) clip: vec4f,
    // Texture coordinates of the target, row 0 at the top.
    @location(0) uv: vec2f,
    @location(1) @interpolate(flat) face: u32,
}

@vertex
fn vs_convert(@builtin(vertex_index) index: u32, @builtin(instance_index) face: u32) -> ConvertOut {
    let p = fullscreen_position(index);
    return ConvertOut(p, vec2f(0.5 + 0.5 * p.x, 0.5 - 0.5 * p.y), face);
}

// The source's radiance along d.
fn source_radiance(d: vec3f) -> vec3f {
    let uv = latlong_uv(d);
    let duv_dx = latlong_gradient(dpdx(uv));
    let duv_dy = latlong_gradient(dpdy(uv));
    switch environment.source {
        case ENV_SKY: {
            return environment.intensity * sky_radiance(environment, d);
        }
        case ENV_LATLONG: {
            return textureSampleGrad(source_2d, env_sampler, uv, duv_dx, duv_dy).rgb;
        }
        case ENV_SPHERE: {
            // A sphere-map source is made for a camera looking along world −Z: view = world.
            return textureSample(source_2d, env_sampler, sphere_map_uv(d)).rgb;
        }
        case ENV_CUBE: {
            return textureSample(source_cube, env_sampler, d).rgb;
        }
        default: {
            return environment.background;
        }
    }
}

@fragment
fn fs_to_cube(in: ConvertOut) -> @location(0) vec4f {
    return vec4f(source_radiance(cube_direction(in.face, in.uv)), 1.0);
}

@fragment
fn fs_to_latlong(in: ConvertOut) -> @location(0) vec4f {
    return vec4f(source_radiance(latlong_direction(in.uv)), 1.0);
}

// The sphere map for the view `world_from_map` inverts, from the cube: what a mirror ball seen
// along −Z reflects at each texel (outside the ball, the rim's direction, straight behind).
@fragment
fn fs_to_sphere(in: ConvertOut) -> @location(0) vec4f {
    let d = environment.world_from_map * sphere_map_direction(in.uv);
    return vec4f(textureSample(source_cube, env_sampler, d).rgb, 1.0);
}

// The teaching views fill the frame, letterboxed to the map's aspect (the frame's size read from
// the change of uv across a pixel). Outside the map: a dark grey.
fn letterbox(uv: vec2f, aspect: f32) -> vec2f {
    let size = 1.0 / vec2f(abs(dpdx(uv.x)), abs(dpdy(uv.y)));
    let frame_aspect = size.x / size.y;
    if frame_aspect > aspect {
        return vec2f(0.5 + (uv.x - 0.5) * frame_aspect / aspect, uv.y);
    }
    return vec2f(uv.x, 0.5 + (uv.y - 0.5) * aspect / frame_aspect);
}

const OUTSIDE: vec4f = vec4f(0.02, 0.02, 0.02, 1.0);

// Where a point of the cross view falls: whether on a face, and the direction the face shows
// there.
struct CrossPoint {
    inside: bool,
    direction: vec3f,
}

// The cube's faces unfolded as a horizontal cross (src/scene/environment.rs, unfold_cross):
// +Y above +Z; −X, +Z, +X, −Z in a row; −Y below.
fn cross_point(uv: vec2f) -> CrossPoint {
    let p = letterbox(uv, 4.0 / 3.0);
    let cell = vec2i(floor(p * vec2f(4.0, 3.0)));
    let local = fract(p * vec2f(4.0, 3.0));
    var face = 6u;
    if cell.y == 1 && cell.x >= 0 && cell.x < 4 {
        face = array<u32, 4>(1u, 4u, 0u, 5u)[cell.x];
    } else if cell.x == 1 && cell.y == 0 {
        face = 2u;
    } else if cell.x == 1 && cell.y == 2 {
        face = 3u;
    }
    let inside = face != 6u && all(p >= vec2f(0.0)) && all(p <= vec2f(1.0));
    return CrossPoint(inside, cube_direction(min(face, 5u), local));
}

// The world's cube as a cross.
@fragment
fn fs_view_cross(in: ConvertOut) -> @location(0) vec4f {
    let at = cross_point(in.uv);
    let radiance = textureSampleLevel(source_cube, env_sampler, at.direction, 0.0).rgb;
    return select(OUTSIDE, vec4f(radiance, 1.0), at.inside);
}

// The first dynamic cube as a cross.
@fragment
fn fs_view_cross_dynamic(in: ConvertOut) -> @location(0) vec4f {
    let at = cross_point(in.uv);
    let radiance = cube_array_sample_level(source_cubes, env_sampler, at.direction, 0, 0.0).rgb;
    return select(OUTSIDE, vec4f(radiance, 1.0), at.inside);
}

// A 2D map (the sphere map, the lat–long map) as it is, at its own aspect.
@fragment
fn fs_view_image(in: ConvertOut) -> @location(0) vec4f {
    let size = vec2f(textureDimensions(source_2d));
    let p = letterbox(in.uv, size.x / size.y);
    let radiance = textureSampleLevel(source_2d, env_sampler, p, 0.0).rgb;
    if any(p < vec2f(0.0)) || any(p > vec2f(1.0)) {
        return OUTSIDE;
    }
    return vec4f(radiance, 1.0);
}
