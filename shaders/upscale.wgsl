// The viewer's upscale (src/viewer/upscale.rs): the 3D view's image, drawn below the view's size
// while the camera moves, stretched over the view's rectangle with bilinear filtering. It reads
// the image's encoded bytes (a plain view of the sRGB image) and writes them to the window's plain
// 8-bit surface unchanged, so the filtering is between sRGB-encoded values: a moving preview, not
// the image `mirador render` draws (that one arrives, copied, when the camera stops). A quad and a
// lone texture read are what a software rasterizer (llvmpipe) draws fastest.

@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var image_sampler: sampler;

struct Stretched {
    @builtin(position) position: vec4f,
    @location(0) uv: vec2f,
}

// The viewport's four corners as a triangle strip: (0, 0), (1, 0), (0, 1), (1, 1) in texture
// coordinates.
@vertex
fn vs_upscale(@builtin(vertex_index) index: u32) -> Stretched {
    let corner = vec2f(f32(index & 1u), f32(index >> 1u));
    var out: Stretched;
    out.position = vec4f(corner.x * 2.0 - 1.0, 1.0 - corner.y * 2.0, 0.0, 1.0);
    out.uv = corner;
    return out;
}

@fragment
fn fs_upscale(in: Stretched) -> @location(0) vec4f {
    return textureSample(image, image_sampler, in.uv);
}
