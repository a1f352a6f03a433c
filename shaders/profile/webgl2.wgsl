// What WebGL2 (OpenGL ES 3.0) lacks, done with what it has (src/shaders.rs, Profile): the names
// of shaders/profile/standard.wgsl, for the same calls.
//
// No cube-map arrays: each dynamic cube is six layers of a 2D array (cube k's face f is layer
// 6k + f), and the lookup picks the face itself, by the Vulkan/OpenGL face table that
// cube_direction inverts (src/scene/environment.rs, cube_face_uv). What the hardware does for a
// cube and this does not: filter across a face's edge. Each face is clamped half a texel inside
// its edge at every level, so a lookup there reads its own face's edge texels where a cube blends
// the two faces' (docs/course/08-environment-maps.md).
//
// No textureGather (GLSL ES 3.00 has none): the four comparisons are four lookups, each at a
// texel's centre, where the comparison sampler's bilinear weights are 1 for that texel alone.

alias CubeArray = texture_2d_array<f32>;

// Where a direction meets the cube: the face, and the selectors that give its coordinates,
// sc = S·d, tc = T·d, ma = M·d > 0, so that uv = ((sc, tc) / ma + 1) / 2.
struct CubeFace {
    face: i32,
    s: vec3f,
    t: vec3f,
    m: vec3f,
}

fn cube_face_of(d: vec3f) -> CubeFace {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        if d.x >= 0.0 {
            return CubeFace(0, vec3f(0.0, 0.0, -1.0), vec3f(0.0, -1.0, 0.0), vec3f(1.0, 0.0, 0.0));
        }
        return CubeFace(1, vec3f(0.0, 0.0, 1.0), vec3f(0.0, -1.0, 0.0), vec3f(-1.0, 0.0, 0.0));
    }
    if a.y >= a.z {
        if d.y >= 0.0 {
            return CubeFace(2, vec3f(1.0, 0.0, 0.0), vec3f(0.0, 0.0, 1.0), vec3f(0.0, 1.0, 0.0));
        }
        return CubeFace(3, vec3f(1.0, 0.0, 0.0), vec3f(0.0, 0.0, -1.0), vec3f(0.0, -1.0, 0.0));
    }
    if d.z >= 0.0 {
        return CubeFace(4, vec3f(1.0, 0.0, 0.0), vec3f(0.0, -1.0, 0.0), vec3f(0.0, 0.0, 1.0));
    }
    return CubeFace(5, vec3f(-1.0, 0.0, 0.0), vec3f(0.0, -1.0, 0.0), vec3f(0.0, 0.0, -1.0));
}

// The face's uv of direction d.
fn cube_face_uv_of(f: CubeFace, d: vec3f) -> vec2f {
    return (vec2f(dot(f.s, d), dot(f.t, d)) / dot(f.m, d) + 1.0) * 0.5;
}

// The change of the face's uv when the direction d changes by dd (the quotient rule).
fn cube_face_duv(f: CubeFace, d: vec3f, dd: vec3f) -> vec2f {
    let ma = dot(f.m, d);
    let st = vec2f(dot(f.s, d), dot(f.t, d));
    let dst = vec2f(dot(f.s, dd), dot(f.t, dd));
    return 0.5 * (dst * ma - st * dot(f.m, dd)) / (ma * ma);
}

// One mip level of one face, bilinear, uv kept half a texel inside the face's edge.
fn cube_face_sample(cubes: CubeArray, s: sampler, uv: vec2f, layer: i32, level: f32) -> vec4f {
    // A level's size is rounded down (a 300-texel face has 2 texels at level 7, not 2.34).
    let texels = max(floor(f32(textureDimensions(cubes).x) / exp2(level)), 1.0);
    let margin = 0.5 / texels;
    return textureSampleLevel(cubes, s, clamp(uv, vec2f(margin), vec2f(1.0 - margin)), layer, level);
}

fn cube_array_sample_level(cubes: CubeArray, s: sampler, d: vec3f, cube: i32, level: f32) -> vec4f {
    return cube_face_trilinear(cubes, s, cube_face_of(d), d, cube, level);
}

// Direction d on face f of cube `cube`, at mip level `level`: the two levels around it, blended.
fn cube_face_trilinear(cubes: CubeArray, s: sampler, f: CubeFace, d: vec3f, cube: i32, level: f32) -> vec4f {
    let uv = cube_face_uv_of(f, d);
    let layer = 6 * cube + f.face;
    let below = floor(level);
    let a = cube_face_sample(cubes, s, uv, layer, below);
    if level == below {
        return a;
    }
    return mix(a, cube_face_sample(cubes, s, uv, layer, below + 1.0), level - below);
}

// The level of detail a cube lookup takes: log2 of the longer screen step in face texels. Past
// the last level, the lookup clamps to it (textureSampleLevel does).
fn cube_array_sample_grad(cubes: CubeArray, s: sampler, d: vec3f, cube: i32, dx: vec3f, dy: vec3f) -> vec4f {
    let f = cube_face_of(d);
    let size = f32(textureDimensions(cubes).x);
    let step = max(length(cube_face_duv(f, d, dx)), length(cube_face_duv(f, d, dy))) * size;
    let level = max(log2(max(step, 1e-8)), 0.0);
    return cube_face_trilinear(cubes, s, f, d, cube, level);
}

fn gather_compare(map: texture_depth_2d_array, cmp: sampler_comparison, corner: vec2f, layer: u32, depth: f32) -> vec4f {
    let half = 0.5 / vec2f(textureDimensions(map));
    return vec4f(
        textureSampleCompareLevel(map, cmp, corner + vec2f(-half.x, half.y), layer, depth),
        textureSampleCompareLevel(map, cmp, corner + half, layer, depth),
        textureSampleCompareLevel(map, cmp, corner + vec2f(half.x, -half.y), layer, depth),
        textureSampleCompareLevel(map, cmp, corner - half, layer, depth),
    );
}

// No textureNumLevels (GLSL ES 3.00 has no textureQueryLevels, nor findMSB): the count of a full chain,
// ⌊log2 max(w, h)⌋ + 1, which is what every texture the surface code asks about has (the scene's
// textures get their whole chain, src/gpu/mipmap.rs).
fn texture_level_count(t: texture_2d<f32>) -> u32 {
    // log2 of half a texel more: a power of two is not rounded down by an inexact log2.
    let size = textureDimensions(t);
    return u32(floor(log2(f32(max(size.x, size.y)) + 0.5))) + 1u;
}

// Texel `position` of layer `layer` (cube layer / 6's face layer % 6) at level 0, for the mip
// chain's face copy: the layer read directly, not through the face table above, so that a
// mistake in the table shows at every level rather than being undone by the chain.
fn cube_array_face_texel(cubes: CubeArray, s: sampler, position: vec2f, layer: u32) -> vec4f {
    let uv = position / vec2f(textureDimensions(cubes));
    return textureSampleLevel(cubes, s, uv, i32(layer), 0.0);
}
