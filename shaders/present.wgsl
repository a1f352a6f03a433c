// The output transform shared with the ray tracer (src/output.rs): exposure, clamp to [0, 1],
// then sRGB encoding, done by the Rgba8UnormSrgb target the pass writes to. When the frame was
// drawn at a render scale below 1, the HDR image is also upscaled here, bilinearly.

struct Present {
    exposure: f32,
    _pad0: f32,
    // The HDR image's size over the output's.
    scale: vec2f,
}

@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var<uniform> present: Present;

@vertex
fn vs_present(@builtin(vertex_index) index: u32) -> @builtin(position) vec4f {
    return fullscreen_position(index);
}

@fragment
fn fs_present(@builtin(position) pixel: vec4f) -> @location(0) vec4f {
    // textureLoad, not a sampler: float filtering is missing on some backends. At scale 1 the
    // output pixel centre lands on its texel's centre, so the four weights pick that texel alone.
    let last = vec2i(textureDimensions(hdr)) - 1;
    let p = pixel.xy * present.scale - 0.5;
    let base = floor(p);
    let f = p - base;
    let i = vec2i(base);
    let radiance = upscaled(i, f, last);
    return vec4f(clamp(radiance * present.exposure, vec3f(0.0), vec3f(1.0)), 1.0);
}

// The HDR radiance at texel position i + f (f in [0, 1)²), bilinear between its four texels,
// clamped to the image.
fn upscaled(i: vec2i, f: vec2f, last: vec2i) -> vec3f {
    let a = textureLoad(hdr, clamp(i, vec2i(0), last), 0).rgb;
    let b = textureLoad(hdr, clamp(i + vec2i(1, 0), vec2i(0), last), 0).rgb;
    let c = textureLoad(hdr, clamp(i + vec2i(0, 1), vec2i(0), last), 0).rgb;
    let d = textureLoad(hdr, clamp(i + vec2i(1, 1), vec2i(0), last), 0).rgb;
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}
