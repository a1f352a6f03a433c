// Uniform layouts shared by every pass. The Rust twins live in src/raster/uniforms.rs; a test
// (tests/layouts.rs) checks that each struct here has the size of its Rust twin.

const MAX_LIGHTS: u32 = 16u;

const LIGHT_POINT: u32 = 0u;
const LIGHT_DIRECTIONAL: u32 = 1u;
const LIGHT_SPOT: u32 = 2u;

const ATTENUATION_NONE: u32 = 0u;
const ATTENUATION_INVERSE_SQUARE: u32 = 1u;

// Frame.texture_filter: how colour textures are sampled (the sampler does the rest).
const TEXTURE_FILTER_LEVEL_COLOUR: u32 = 5u;

// Frame.bump_view: the bump-mapping teaching views.
const BUMP_VIEW_NORMALS: u32 = 1u;
const BUMP_VIEW_TANGENTS: u32 = 2u;

// Frame.bump_tangents.
const BUMP_TANGENTS_PER_VERTEX: u32 = 1u;

// Bits of Frame.terms: which terms of the illumination model are drawn.
const TERM_AMBIENT: u32 = 1u;
const TERM_DIFFUSE: u32 = 2u;
const TERM_SPECULAR: u32 = 4u;
const TERM_EMISSION: u32 = 8u;

struct Light {
    position: vec3f,
    kind: u32,
    // Unit vector the light travels along (directional and spot lights).
    direction: vec3f,
    attenuation: u32,
    // Colour times intensity.
    radiance: vec3f,
    cos_inner: f32,
    cos_outer: f32,
    // First shadow-map layer of this light, −1 when it casts no shadows.
    shadow_layer: i32,
    // Which of the (at most four) shadowed lights this is: its channel in the projected-shadow
    // mask; −1 when it casts no shadows.
    shadow_slot: i32,
    _pad0: f32,
}

// Group 0: changes once per frame.
struct Frame {
    clip_from_world: mat4x4f,
    eye: vec3f,
    // 1 for an orthographic camera: then every view ray runs along -view_axis.
    orthographic: u32,
    // ze of the eye frame: from the scene towards the eye.
    view_axis: vec3f,
    light_count: u32,
    ambient: vec3f,
    terms: u32,
    texture_filter: u32,
    lod_bias: f32,
    bump_enabled: u32,
    // Multiplies every material's bump scale k.
    bump_scale: f32,
    // The finite-difference step Δ in texels of the height map.
    bump_delta_texels: f32,
    bump_view: u32,
    // 0: tangents from screen derivatives; 1: the interpolated per-vertex tangents.
    bump_tangents: u32,
    // 1: procedural height fields use their closed-form derivatives, not finite differences.
    bump_analytic: u32,
    lights: array<Light, MAX_LIGHTS>,
}

// Group 1: changes per material.
struct Material {
    color: vec3f,
    has_texture: u32,
    ka: f32,
    kd: f32,
    ks: f32,
    shininess: f32,
    specular_color: vec3f,
    // 1 when kt > 0: drawn into the transmission maps instead of the depth maps.
    transparent: u32,
    emission: vec3f,
    // k of TECHNIQUES.md §3.
    bump_scale: f32,
    // kt·MT: what a transparent surface lets through.
    transmission: vec3f,
    has_height_map: u32,
    has_normal_map: u32,
    normal_scale: f32,
    // HEIGHT_* below: where the bump heights come from.
    height_kind: u32,
    height_amplitude: f32,
    height_frequency: vec2f,
    noise_seed: u32,
    noise_cells: u32,
    noise_octaves: u32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

const HEIGHT_TEXTURE: u32 = 1u;
const HEIGHT_SINE: u32 = 2u;
const HEIGHT_NOISE: u32 = 3u;

// Group 2: changes per object.
struct Object {
    world_from_local: mat4x4f,
    // Inverse transpose of world_from_local's upper 3×3, stored as a 4×4 for alignment.
    normal_from_local: mat4x4f,
}

// One triangle covering the screen, for passes that work per pixel: vertices at (−1, −1),
// (3, −1), (−1, 3) in clip space, for vertex_index 0, 1, 2.
fn fullscreen_position(index: u32) -> vec4f {
    let uv = vec2f(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4f(uv * 2.0 - 1.0, 0.0, 1.0);
}
