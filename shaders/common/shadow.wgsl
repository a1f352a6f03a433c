// Shadow-map lookups (TECHNIQUES.md §4, pass 2): project the shaded point into the light's view
// and compare its depth with the stored one. Textures and samplers come in as parameters so this
// shared file names no pass's bindings. The Rust twins of the layout logic live in
// src/raster/shadow/views.rs (cube_face, project).

const SHADOW_FILTER_NONE: u32 = 0u;
const SHADOW_FILTER_HARDWARE: u32 = 1u;
const SHADOW_FILTER_PCF3: u32 = 2u;
const SHADOW_FILTER_PCF5: u32 = 3u;
const SHADOW_FILTER_POISSON: u32 = 4u;

const MAX_SHADOW_LAYERS: u32 = 24u;

struct ShadowLayer {
    clip_from_world: mat4x4f,
    // World size of a texel (at unit distance from the light for perspective views).
    texel_size: f32,
    perspective: u32,
    _pad0: f32,
    _pad1: f32,
}

struct Shadows {
    layers: array<ShadowLayer, MAX_SHADOW_LAYERS>,
    enabled: u32,
    method: u32,
    filter_mode: u32,
    map_size: u32,
    normal_offset: f32,
    transmission: u32,
    view: u32,
    view_layer: u32,
}

// Sixteen points of a Poisson disc in the unit circle.
const POISSON_DISC = array<vec2f, 16>(
    vec2f(-0.94201624, -0.39906216), vec2f(0.94558609, -0.76890725),
    vec2f(-0.09418410, -0.92938870), vec2f(0.34495938, 0.29387760),
    vec2f(-0.91588581, 0.45771432), vec2f(-0.81544232, -0.87912464),
    vec2f(-0.38277543, 0.27676845), vec2f(0.97484398, 0.75648379),
    vec2f(0.44323325, -0.97511554), vec2f(0.53742981, -0.47373420),
    vec2f(-0.26496911, -0.41893023), vec2f(0.79197514, 0.19090188),
    vec2f(-0.24188840, 0.99706507), vec2f(-0.81409955, 0.91437590),
    vec2f(0.19984126, 0.78641367), vec2f(0.14383161, -0.14100790),
);

// The cube face a direction from a point light falls in: the axis of its largest component,
// in the order +x, −x, +y, −y, +z, −z.
fn cube_face(d: vec3f) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, d.x >= 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z >= 0.0);
}

// Map coordinates (v down) and depth of p in a light's view; w = 0 behind a perspective light.
fn shadow_coordinates(clip_from_world: mat4x4f, p: vec3f) -> vec4f {
    let clip = clip_from_world * vec4f(p, 1.0);
    if clip.w <= 0.0 {
        return vec4f(0.0);
    }
    let ndc = clip.xyz / clip.w;
    return vec4f(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y, ndc.z, 1.0);
}

// The fraction of hardware comparisons that find p lit: 1 lit, 0 in shadow. Each comparison is
// "stored depth ≥ p's depth" (the sampler's compare function is greater-equal on the reference).
fn shadow_filtered(
    map: texture_depth_2d_array,
    linear: sampler_comparison,
    nearest: sampler_comparison,
    uv: vec2f,
    depth: f32,
    layer: u32,
    filter_mode: u32,
    map_size: u32,
) -> f32 {
    let texel = 1.0 / f32(map_size);
    switch filter_mode {
        case SHADOW_FILTER_NONE: {
            return textureSampleCompareLevel(map, nearest, uv, layer, depth);
        }
        case SHADOW_FILTER_HARDWARE: {
            return textureSampleCompareLevel(map, linear, uv, layer, depth);
        }
        case SHADOW_FILTER_POISSON: {
            var lit = 0.0;
            for (var k = 0u; k < 16u; k++) {
                lit += textureSampleCompareLevel(map, linear, uv + 2.5 * texel * POISSON_DISC[k], layer, depth);
            }
            return lit / 16.0;
        }
        default: {
            let reach = select(1, 2, filter_mode == SHADOW_FILTER_PCF5);
            var lit = 0.0;
            for (var j = -reach; j <= reach; j++) {
                for (var i = -reach; i <= reach; i++) {
                    lit += textureSampleCompareLevel(map, linear, uv + texel * vec2f(f32(i), f32(j)), layer, depth);
                }
            }
            let side = f32(2 * reach + 1);
            return lit / (side * side);
        }
    }
}

// The map texel that p's lookup lands in, for the texel-checker teaching view.
fn shadow_texel_checker(uv: vec2f, map_size: u32) -> f32 {
    let texel = vec2i(floor(uv * f32(map_size)));
    return f32((texel.x + texel.y) & 1);
}
