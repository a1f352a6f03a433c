// Uniform layouts shared by every pass. The Rust twins live in src/raster/uniforms.rs; a test
// (tests/layouts.rs) checks that each struct here has the size and field offsets of its Rust twin.

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

// Group 0, binding 0: one camera as one pass sees it (the main camera, a light's view for pass 1
// of the shadow maps, later mirrored cameras and cube faces). Each view has its own slot in one
// buffer, chosen by a dynamic offset, so a frame can draw from many cameras.
struct View {
    clip_from_world: mat4x4f,
    // Its inverse: the world-space ray through a pixel, for the background.
    world_from_clip: mat4x4f,
    eye: vec3f,
    // 1 for an orthographic camera: then every view ray runs along -view_axis.
    orthographic: u32,
    // ze of the eye frame: from the scene towards the eye.
    view_axis: vec3f,
    // 1 when the view is mirrored (its triangles' winding flips).
    mirrored: u32,
    // Points p with dot(clip_plane.xyz, p) + clip_plane.w < 0 are not drawn; all zero: no plane.
    clip_plane: vec4f,
    // A mirrored camera's clip_from_world before its last reflection, the one about its
    // clip_plane: clip_from_world = clip_from_reflected · R(clip_plane). clip_from_world itself
    // in a view that no mirror made. The planar-mirror lab reflects with the student's R.
    clip_from_reflected: mat4x4f,
}

// Group 0, binding 1: what every view of the frame shares: lights and numeric settings. The
// toggles that switch code on and off are pipeline constants instead (shaders/scene.wgsl).
struct Frame {
    ambient: vec3f,
    light_count: u32,
    terms: u32,
    lod_bias: f32,
    // Multiplies every material's bump scale k.
    bump_scale: f32,
    // The finite-difference step Δ in texels of the height map.
    bump_delta_texels: f32,
    // TRACED_* bits: the hybrid's terms read from the view's traced image (src/raster/traced/mod.rs).
    // A field, not a pipeline constant, though it switches code: swapping a term (mirador budget
    // swaps each in turn, the viewer's panel) then draws with the variants already made. The
    // constant HYBRID (shaders/common/surface.wgsl) leaves the code out where none is traced.
    traced: u32,
    lights: array<Light, MAX_LIGHTS>,
}

// Group 1: changes per material. Which textures and height field a material has are pipeline
// constants of its variant (shaders/scene.wgsl), not fields here.
struct Material {
    color: vec3f,
    ka: f32,
    kd: f32,
    ks: f32,
    shininess: f32,
    // 1 when kt > 0: drawn into the transmission maps instead of the depth maps.
    transparent: u32,
    specular_color: vec3f,
    // k of docs/course/04-bump-mapping.md.
    bump_scale: f32,
    emission: vec3f,
    normal_scale: f32,
    // kt·MT: what a transparent surface lets through (see material_transmittance).
    transmission: vec3f,
    height_amplitude: f32,
    height_frequency: vec2f,
    noise_seed: u32,
    noise_cells: u32,
    noise_octaves: u32,
    // Coverage α before the colour texture's alpha, and the cut-off of ALPHA_MASK.
    alpha: f32,
    alpha_cutoff: f32,
    alpha_mode: u32,
    // kps·MPS: what a mirror reflects.
    reflectance: vec3f,
    // The material's index in the scene (for inspecting a pixel).
    index: u32,
    // The index of refraction, for Fresnel and refraction.
    ior: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

// What a transparent surface lets through, the factor of I = Im + kt·Mt·I (docs/course/06-transparency.md):
// kt·Mt, and for alpha blending α·kt·Mt + (1 − α), with α the coverage at the fragment.
fn material_transmittance(m: Material, alpha: f32) -> vec3f {
    if m.alpha_mode == ALPHA_BLEND {
        return alpha * m.transmission + vec3f(1.0 - alpha);
    }
    return m.transmission;
}

// The blend of docs/course/06-transparency.md: a transparent surface's own light Im, plus what it
// lets through, kt·Mt, of what the pixel held behind it: I = Im + kt·Mt·I. The GPU's blend state
// computes it in Mirador (src/raster/transparency.rs); the transparency lab routes it through
// here (BLEND_BY_HAND in shaders/transparency.wgsl).
fn transparent_blend(im: vec3f, transmittance: vec3f, behind: vec3f) -> vec3f {
    return im + transmittance * behind;
}

// Per object, as instance attributes (vertex buffer 1): objects that share a mesh are drawn in one
// instanced call.
struct Instance {
    @location(4) world_from_local_0: vec4f,
    @location(5) world_from_local_1: vec4f,
    @location(6) world_from_local_2: vec4f,
    @location(7) world_from_local_3: vec4f,
    // Inverse transpose of world_from_local's upper 3×3, by columns.
    @location(8) normal_from_local_0: vec3f,
    @location(9) normal_from_local_1: vec3f,
    @location(10) normal_from_local_2: vec3f,
    // Layer of the object's own cube among the dynamic environment cubes; ENV_LAYER_WORLD: the
    // world's; ENV_LAYER_NONE: no lookup (planar mirrors reflect through their mirrored camera).
    @location(11) env_layer: i32,
    // The object's index in the scene (for inspecting a pixel); u32 max where unknown.
    @location(12) object: u32,
}

fn instance_world_from_local(i: Instance) -> mat4x4f {
    return mat4x4f(i.world_from_local_0, i.world_from_local_1, i.world_from_local_2, i.world_from_local_3);
}

fn instance_normal_from_local(i: Instance) -> mat3x3f {
    return mat3x3f(i.normal_from_local_0, i.normal_from_local_1, i.normal_from_local_2);
}

// One triangle covering the screen, for passes that work per pixel: vertices at (−1, −1),
// (3, −1), (−1, 3) in clip space, for vertex_index 0, 1, 2.
fn fullscreen_position(index: u32) -> vec4f {
    let uv = vec2f(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4f(uv * 2.0 - 1.0, 0.0, 1.0);
}
