// Shadow-map lookups (docs/course/05-shadows.md, pass 2): project the shaded point into the light's view
// and compare its depth with the stored one. Textures and samplers come in as parameters so this
// shared file names no pass's bindings. The Rust twins of the layout logic live in
// src/raster/shadow/views.rs (cube_face, project).

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
    map_size: u32,
    // The lookup point is pushed along the normal by this many map texels.
    normal_offset: f32,
    _pad0: f32,
    _pad1: f32,
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

// One comparison of pass 2: 1 where the point (at `depth` in the light's view) is lit, no farther
// from the light than what the map stored there; 0 where something nearer hid it.
fn shadow_compare(stored: f32, depth: f32) -> f32 {
    return select(0.0, 1.0, depth <= stored);
}

// Percentage-closer filtering by hand: the comparisons with the (2r+1)² texels around the one uv
// falls in, averaged; r = 0 is the nearest texel alone. Compare first, then average: an average
// of depths compared once is still all lit or all shadowed. Texels beyond the map repeat its edge.
// Mirador's own filters use the sampler's comparisons (shadow_filtered); a lab (src/lab) whose
// student writes these two functions routes shadow_filtered through them. Nothing else calls
// them: WebGL's GLSL cannot load a texel of a depth texture, and a module that only declares
// them still translates, since only what an entry point reaches is kept.
fn shadow_pcf(map: texture_depth_2d_array, uv: vec2f, depth: f32, layer: u32, map_size: u32, r: i32) -> f32 {
    let centre = vec2i(floor(uv * f32(map_size)));
    let last = vec2i(i32(map_size) - 1);
    var lit = 0.0;
    for (var y = -r; y <= r; y++) {
        for (var x = -r; x <= r; x++) {
            let texel = clamp(centre + vec2i(x, y), vec2i(0), last);
            lit += shadow_compare(textureLoad(map, texel, layer, 0), depth);
        }
    }
    let side = f32(2 * r + 1);
    return lit / (side * side);
}

// The fraction of the filter's comparisons that find p lit: 1 lit, 0 in shadow. Each comparison
// is "p's depth ≤ stored depth". PCF filters compare first and average after: the hardware's 2×2
// filter weighs the four texels around the lookup bilinearly, and a (2r+1)² grid of such taps
// one texel apart adds up to one separable kernel over 2r+2 texels a side, with 1-D weights
// (1 − f, 1, …, 1, f)/(2r+1). That kernel is evaluated here from comparison gathers, four texels
// a call: (r+1)² gathers instead of (2r+1)² filtered samples, which on a software GPU is most of
// the cost of a shadow (docs/performance.md). The Poisson disc, whose taps fall between texels,
// keeps filtered samples.
fn shadow_filtered(
    map: texture_depth_2d_array,
    linear: sampler_comparison,
    uv: vec2f,
    depth: f32,
    layer: u32,
    filter_mode: u32,
    map_size: u32,
) -> f32 {
    let size = f32(map_size);
    switch filter_mode {
        case SHADOW_FILTER_NONE: {
            // The nearest texel: the bilinear filter at its very centre weighs it alone.
            let centre = (floor(uv * size) + 0.5) / size;
            return textureSampleCompareLevel(map, linear, centre, layer, depth);
        }
        case SHADOW_FILTER_POISSON: {
            let texel = 1.0 / size;
            var lit = 0.0;
            for (var k = 0u; k < 16u; k++) {
                lit += textureSampleCompareLevel(map, linear, uv + 2.5 * texel * POISSON_DISC[k], layer, depth);
            }
            return lit / 16.0;
        }
        case SHADOW_FILTER_HARDWARE: {
            return shadow_tent(map, linear, uv, depth, layer, map_size, 0);
        }
        case SHADOW_FILTER_PCF3: {
            return shadow_tent(map, linear, uv, depth, layer, map_size, 1);
        }
        default: {
            return shadow_tent(map, linear, uv, depth, layer, map_size, 2);
        }
    }
}

// (2r+1)² bilinear comparison taps one texel apart around uv, as one separable kernel over
// (2r+2)² texels, gathered 2×2 texels at a time (gather_compare's components are the
// texels (0, 1), (1, 1), (1, 0), (0, 0) of its footprint); texels outside the map repeat its
// edge (the sampler clamps to edge).
fn shadow_tent(map: texture_depth_2d_array, cmp: sampler_comparison, uv: vec2f, depth: f32, layer: u32, map_size: u32, r: i32) -> f32 {
    let size = f32(map_size);
    let p = uv * size - 0.5;
    let base = floor(p);
    let f = p - base;
    let first = base - f32(r);
    let n = 2 * r + 2;
    var lit = 0.0;
    for (var by = 0; by < r + 1; by++) {
        for (var bx = 0; bx < r + 1; bx++) {
            // The corner shared by the block's four texels.
            let corner = (first + vec2f(f32(2 * bx + 1), f32(2 * by + 1))) / size;
            let g = gather_compare(map, cmp, corner, layer, depth);
            let i = 2 * bx;
            let j = 2 * by;
            let wx0 = select(select(1.0, f.x, i == n - 1), 1.0 - f.x, i == 0);
            let wx1 = select(1.0, f.x, i + 1 == n - 1);
            let wy0 = select(select(1.0, f.y, j == n - 1), 1.0 - f.y, j == 0);
            let wy1 = select(1.0, f.y, j + 1 == n - 1);
            lit += wy0 * (wx0 * g.w + wx1 * g.z) + wy1 * (wx0 * g.x + wx1 * g.y);
        }
    }
    let side = f32(2 * r + 1);
    return lit / (side * side);
}

// Where p is looked up in a light view: map coordinates and depth, w = 1; w = 0 when p lies outside
// the view, where nothing was drawn into the map and so nothing occludes. `facing` is the normal
// on the light's side: p is pushed along it by `normal_offset` map texels first (an acne cure).
fn shadow_lookup_point(view: ShadowLayer, light_position: vec3f, p: vec3f, facing: vec3f, normal_offset: f32) -> vec4f {
    // The texel's world size where p is: fixed for orthographic views, growing with distance
    // from the light for perspective ones.
    let texel = select(view.texel_size, view.texel_size * distance(p, light_position), view.perspective != 0u);
    let coordinates = shadow_coordinates(view.clip_from_world, p + facing * normal_offset * texel);
    let inside = coordinates.w > 0.0 && all(coordinates.xy >= vec2f(0.0)) && all(coordinates.xy <= vec2f(1.0))
        && coordinates.z <= 1.0;
    return select(vec4f(0.0), coordinates, inside);
}

// The map texel that p's lookup lands in, for the texel-checker teaching view.
fn shadow_texel_checker(uv: vec2f, map_size: u32) -> f32 {
    let texel = vec2i(floor(uv * f32(map_size)));
    return f32((texel.x + texel.y) & 1);
}
