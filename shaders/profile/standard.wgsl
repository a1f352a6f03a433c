// What a WebGPU, Vulkan or desktop-GL device offers, used as it is (src/shaders.rs, Profile).
// shaders/profile/webgl2.wgsl declares the same names for a device that lacks these: each pass
// calls them, so a pass's code is the same on both.

// The dynamic environment cubes, one per reflective object.
alias CubeArray = texture_cube_array<f32>;

// Cube `cube` of `cubes` looked up along d, its level of detail from the lookup direction's
// screen derivatives dx and dy.
fn cube_array_sample_grad(cubes: CubeArray, s: sampler, d: vec3f, cube: i32, dx: vec3f, dy: vec3f) -> vec4f {
    return textureSampleGrad(cubes, s, d, cube, dx, dy);
}

// Cube `cube` of `cubes` looked up along d at mip level `level`.
fn cube_array_sample_level(cubes: CubeArray, s: sampler, d: vec3f, cube: i32, level: f32) -> vec4f {
    return textureSampleLevel(cubes, s, d, cube, level);
}

// The depth comparisons of the 2×2 texels around `corner` (a point where four texels meet), in
// textureGatherCompare's order: texels (0, 1), (1, 1), (1, 0), (0, 0) of the footprint.
fn gather_compare(map: texture_depth_2d_array, cmp: sampler_comparison, corner: vec2f, layer: u32, depth: f32) -> vec4f {
    return textureGatherCompare(map, cmp, corner, layer, depth);
}

// How many mip levels the texture t has.
fn texture_level_count(t: texture_2d<f32>) -> u32 {
    return textureNumLevels(t);
}

// Texel `position` of layer `layer` (cube layer / 6's face layer % 6) at level 0, for the mip
// chain's face copy: looked up along that texel's centre direction (GL samples a cube only
// through a view of the whole cube, and textureLoad has no cube form), where a nearest lookup
// reads exactly that texel.
fn cube_array_face_texel(cubes: CubeArray, s: sampler, position: vec2f, layer: u32) -> vec4f {
    let d = cube_direction(layer % 6u, position / f32(textureDimensions(cubes).x));
    return textureSampleLevel(cubes, s, d, i32(layer / 6u), 0.0);
}
