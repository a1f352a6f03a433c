// The viewer's upscale (src/viewer/upscale.rs): the 3D view's image, drawn below the view's size
// while the camera moves, stretched over the view's rectangle with bilinear filtering. It reads
// the image's encoded bytes (a plain view of the sRGB image) and writes them to the window's plain
// 8-bit surface unchanged, so the filtering is between sRGB-encoded values: a moving preview, not
// the image `mirador render` draws (that one arrives, copied, when the camera stops). A triangle and
// a lone texture read are what a software rasterizer (llvmpipe) draws fastest.

@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var image_sampler: sampler;

struct Stretched {
    @builtin(position) position: vec4f,
    @location(0) uv: vec2f,
}

// One triangle over the viewport (`fullscreen_position`, shaders/common/types.wgsl; the scissor
// keeps what lies outside it), with texture coordinates running from (0, 0) at the viewport's
// top left to (1, 1) at its bottom right.
@vertex
fn vs_upscale(@builtin(vertex_index) index: u32) -> Stretched {
    var out: Stretched;
    out.position = fullscreen_position(index);
    out.uv = vec2f(0.5 + 0.5 * out.position.x, 0.5 - 0.5 * out.position.y);
    return out;
}

@fragment
fn fs_upscale(in: Stretched) -> @location(0) vec4f {
    return textureSample(image, image_sampler, in.uv);
}

// The image's own bytes drawn into a plain 8-bit texture, where a copy cannot move them (WebGL2
// copies no sRGB texture into a plain one; src/viewer/upscale.rs, Reencode): each texel is read
// decoded, as an sRGB texture reads, and encoded again by the sRGB curve, which gives back the
// byte it was (the curve is exact to far less than half a step in 32-bit floats).
@fragment
fn fs_reencode(in: Stretched) -> @location(0) vec4f {
    let c = textureLoad(image, vec2i(in.position.xy), 0);
    let encoded = select(1.055 * pow(c.rgb, vec3f(1.0 / 2.4)) - 0.055, 12.92 * c.rgb, c.rgb <= vec3f(0.0031308));
    return vec4f(encoded, c.a);
}
