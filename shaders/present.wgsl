// The output transform shared with the ray tracer (src/output.rs): exposure, clamp to [0, 1],
// then sRGB encoding, done by the Rgba8UnormSrgb target the pass writes to.

struct Present {
    exposure: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var<uniform> present: Present;

@vertex
fn vs_present(@builtin(vertex_index) index: u32) -> @builtin(position) vec4f {
    return fullscreen_position(index);
}

@fragment
fn fs_present(@builtin(position) pixel: vec4f) -> @location(0) vec4f {
    // textureLoad, not a sampler: the HDR target is read texel for texel, and float
    // filtering is missing on some backends.
    let radiance = textureLoad(hdr, vec2i(pixel.xy), 0).rgb;
    return vec4f(clamp(radiance * present.exposure, vec3f(0.0), vec3f(1.0)), 1.0);
}
