// Inspecting one pixel (`mirador explain`, the viewer's inspect mode; src/raster/inspect.rs):
// composed into every surface module before surface.wgsl; each pass's file has its own
// `*_inspect` entry points. Under INSPECT the shading functions of scene.wgsl,
// transparency.wgsl and volume.wgsl also fill `probe`, a private record of what they computed
// (each term, each light's visibility and shadow-map lookup, the texture's level, the bumped
// normal, the reflections); the `*_inspect` entry points, drawn only in the main view of an
// inspected frame, append the record of every fragment that lands on the inspected pixel to a
// storage buffer, in the order they are drawn (the order they are blended in). Normal frames
// use the plain entry points with INSPECT off, which never touch `probe`.

override INSPECT: bool = false;

struct InspectLight {
    // Each part of S·L_dir, before the visibility.
    ambient: vec3f,
    // The shadow-map layer looked up, −1 for none (the light casts none, or projected shadows).
    layer: i32,
    diffuse: vec3f,
    // The filter's lit fraction (projected shadows: 1 − the mask).
    lit: f32,
    specular: vec3f,
    // The depth stored in the texel the lookup lands in.
    stored_depth: f32,
    // V: the lit fraction times the transmission maps' tint.
    visibility: vec3f,
    // The receiver's depth as the light sees it (after the normal offset).
    receiver_depth: f32,
    texel: vec2f,
    _pad0: f32,
    _pad1: f32,
}

struct InspectFragment {
    kind: u32,
    // Material index, object index (u32 max: unknown), and the fragment's depth.
    material: u32,
    object: u32,
    depth: f32,
    world: vec3f,
    // The colour texture's mip level (−1: no texture).
    lod: f32,
    normal: vec3f,
    // Coverage α (transparent and blended fragments), the march's accumulated opacity (volumes).
    alpha: f32,
    geometric: vec3f,
    // Volumes: samples taken.
    samples: f32,
    uv: vec2f,
    // Texels the pixel spans along x and y: the footprint the level comes from.
    footprint: vec2f,
    colour: vec3f,
    // Bump mapping's k, and its slopes (du, dv); Δ in uv.
    bump_k: f32,
    bump: vec2f,
    bump_delta: vec2f,
    emission: vec3f,
    env_layer: i32,
    global_ambient: vec3f,
    // Fresnel's F where the surface is glass with Fresnel on (at the entry, for refraction).
    fresnel: f32,
    // kps·MPS·L(r) looked up in an environment map (and glass's F·kt·Mt·L(r)), and r.
    environment: vec3f,
    _pad1: f32,
    env_direction: vec3f,
    _pad2: f32,
    // kps·MPS times the mirrored camera's image.
    mirror: vec3f,
    _pad3: f32,
    // What the fragment returns: the radiance it shades (premultiplied by α where it blends).
    radiance: vec3f,
    _pad4: f32,
    // Refraction (refraction.wgsl): the exit point p2 and whether the march found it (1), the
    // direction t2 leaving the glass and F at the exit, the transmitted term and where L(t2)
    // came from (1: the environment, 2: the opaque image).
    refraction_exit: vec3f,
    refraction_found: f32,
    refracted_direction: vec3f,
    fresnel_exit: f32,
    refracted: vec3f,
    refraction_source: f32,
    // The transparency lab's blend by hand (BLEND_BY_HAND): b, what the pixel behind the fragment
    // is multiplied by, from the student's blend.
    blend_factor: vec3f,
    _pad5: f32,
    lights: array<InspectLight, MAX_LIGHTS>,
}

struct Inspection {
    // The pixel inspected, written by the CPU.
    pixel: vec2u,
    count: atomic<u32>,
    _pad: u32,
    fragments: array<InspectFragment, MAX_INSPECTED>,
}

@group(2) @binding(11) var<storage, read_write> inspection: Inspection;
// The shadow maps again, as floats: the stored depth of each light's lookup is read here, in the
// `*_inspect` entry points alone, because GLSL has no texelFetch of a depth texture and
// `visibility` is part of every plain entry point too (src/gpu/layout.rs, depth_texels).
@group(2) @binding(12) var shadow_texels: texture_2d_array<f32>;

var<private> probe: InspectFragment;
// The light `visibility` is evaluated for, so it can fill that light's record.
var<private> probe_light: u32;

// Appends the record of a fragment of `kind` at `clip` with `radiance` when it lands on the
// inspected pixel.
fn inspect_record(kind: u32, clip: vec4f, radiance: vec3f) {
    if any(vec2u(clip.xy) != inspection.pixel) {
        return;
    }
    let index = atomicAdd(&inspection.count, 1u);
    if index < MAX_INSPECTED {
        for (var i = 0u; i < min(frame.light_count, MAX_LIGHTS); i++) {
            let light = probe.lights[i];
            if light.layer >= 0 {
                probe.lights[i].stored_depth = textureLoad(shadow_texels, vec2u(light.texel), light.layer, 0).x;
            }
        }
        probe.kind = kind;
        probe.depth = clip.z;
        probe.material = material.index;
        probe.radiance = radiance;
        inspection.fragments[index] = probe;
    }
}

