// Mip generation (docs/course/03-mipmaps.md): one fullscreen triangle per level, each
// fragment the box average of its footprint in the level above. src/gpu/mipmap.rs draws it and
// its header states the rule; the CPU twin is src/texture/mipmap.rs (box_taps). The source is
// read with textureLoad, so an sRGB texture is decoded to linear before averaging; the result is
// written twice: to the texture's level (an sRGB target encodes it again) and, unrounded, to a
// 16-bit float scratch level that the next level reads, so 8-bit rounding never accumulates.

@group(0) @binding(0) var mip_source: texture_2d<f32>;

// The source texels one output texel averages along an axis of n texels: `count` texels from
// `first` with `weights`. Even n: 2j, 2j+1 at ½ each; odd n = 2h + 1: 2j, 2j+1, 2j+2 at
// (h−j)/n, h/n, (j+1)/n (the footprint [j·n/h, (j+1)·n/h) is 2 + 2/(n−1) texels wide); n = 1:
// the texel itself.
struct MipTaps {
    first: i32,
    count: i32,
    weights: vec3f,
}

fn mip_box_taps(j: i32, n: i32) -> MipTaps {
    if n <= 1 {
        return MipTaps(0, 1, vec3f(1.0, 0.0, 0.0));
    }
    if n % 2 == 0 {
        return MipTaps(2 * j, 2, vec3f(0.5, 0.5, 0.0));
    }
    let h = n / 2;
    let nf = f32(n);
    return MipTaps(2 * j, 3, vec3f(f32(h - j) / nf, f32(h) / nf, f32(j + 1) / nf));
}

@vertex
fn vs_mipmap(@builtin(vertex_index) index: u32) -> @builtin(position) vec4f {
    return fullscreen_position(index);
}

struct MipmapOut {
    // The scratch level the next level is computed from.
    @location(0) linear: vec4f,
    // The texture's own level.
    @location(1) stored: vec4f,
}

@fragment
fn fs_mipmap(@builtin(position) pixel: vec4f) -> MipmapOut {
    let size = vec2i(textureDimensions(mip_source));
    let out = vec2i(pixel.xy);
    let tx = mip_box_taps(out.x, size.x);
    let ty = mip_box_taps(out.y, size.y);
    // y outer, x inner, as on the CPU: power-of-two levels are ((¼a + ¼b) + ¼c) + ¼d.
    var sum = vec4f(0.0);
    for (var b = 0; b < ty.count; b++) {
        for (var a = 0; a < tx.count; a++) {
            let texel = textureLoad(mip_source, vec2i(tx.first + a, ty.first + b), 0);
            sum += texel * (tx.weights[a] * ty.weights[b]);
        }
    }
    return MipmapOut(sum, sum);
}
