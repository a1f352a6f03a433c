// The output transform shared with the ray tracer (src/output.rs): exposure, a tone curve into
// [0, 1], then sRGB encoding, done by the Rgba8UnormSrgb target the pass writes to. When the frame was
// drawn at a render scale below 1, the HDR image is also upscaled here, bilinearly.

struct Present {
    exposure: f32,
    tone_map: u32,
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
    return vec4f(tone_map(max(radiance * present.exposure, vec3f(0.0)), present.tone_map), 1.0);
}

fn tone_map(c: vec3f, curve: u32) -> vec3f {
    var mapped = c;
    switch curve {
        case TONE_MAP_REINHARD: {
            mapped = c / (1.0 + c);
        }
        case TONE_MAP_ACES: {
            // Narkowicz's fit of the ACES filmic curve.
            mapped = (c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14);
        }
        case TONE_MAP_PBR_NEUTRAL: {
            mapped = pbr_neutral(c);
        }
        default: {}
    }
    return clamp(mapped, vec3f(0.0), vec3f(1.0));
}

// Khronos PBR Neutral: a toe offset, identity up to 0.76, then a shoulder that desaturates.
fn pbr_neutral(color: vec3f) -> vec3f {
    let start_compression = 0.8 - 0.04;
    let desaturation = 0.15;
    let x = min(color.r, min(color.g, color.b));
    let offset = select(0.04, x - 6.25 * x * x, x < 0.08);
    let c = color - offset;
    let peak = max(c.r, max(c.g, c.b));
    if peak < start_compression {
        return c;
    }
    let d = 1.0 - start_compression;
    let new_peak = 1.0 - d * d / (peak + d - start_compression);
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(c * (new_peak / peak), vec3f(new_peak), g);
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
