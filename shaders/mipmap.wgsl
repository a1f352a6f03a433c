// Mip generation (docs/course/03-mipmaps.md): one fullscreen triangle per level, each
// fragment the box average of its footprint in the level above. src/gpu/mipmap.rs draws it and
// its header states the rule; the CPU twin is src/texture/mipmap.rs (box_taps). The source is
// read with textureLoad, so an sRGB texture is decoded to linear before averaging; the result is
// written twice: to the texture's level (an sRGB target encodes it again) and, unrounded, to a
// 16-bit float scratch level that the next level reads, so 8-bit rounding never accumulates.
//
// A cube's face is first drawn, texel for texel, into a plain 2D image that level 1 reads
// (fs_mipmap_face_*): GL samples a cube only through a view of the whole cube, and textureLoad
// has no cube form (src/gpu/texture.rs, Layers).

@group(0) @binding(0) var mip_source: texture_2d<f32>;
// The cube whose face is copied, its mip level 0, read with a nearest sampler.
@group(0) @binding(1) var face_sampler: sampler;
@group(0) @binding(2) var face_cube: texture_cube<f32>;
@group(0) @binding(3) var face_cubes: CubeArray;

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

struct FaceOut {
    @builtin(position) position: vec4f,
    // The layer copied: face layer % 6 of cube layer / 6.
    @location(0) @interpolate(flat) layer: u32,
}

@vertex
fn vs_mipmap_face(@builtin(vertex_index) index: u32, @builtin(instance_index) layer: u32) -> FaceOut {
    return FaceOut(fullscreen_position(index), layer);
}

// The direction through the centre of the target's texel at `position` on `face` of a cube of
// `size` texels a side. Nearest sampling there reads exactly that texel: the centre lies half a
// texel from every edge, far beyond the rounding of the cube lookup's projection.
fn face_texel_direction(position: vec4f, face: u32, size: u32) -> vec3f {
    return cube_direction(face, position.xy / f32(size));
}

@fragment
fn fs_mipmap_face_cube(in: FaceOut) -> @location(0) vec4f {
    let d = face_texel_direction(in.position, in.layer, textureDimensions(face_cube).x);
    return textureSampleLevel(face_cube, face_sampler, d, 0.0);
}

@fragment
fn fs_mipmap_face_cubes(in: FaceOut) -> @location(0) vec4f {
    return cube_array_face_texel(face_cubes, face_sampler, in.position.xy, in.layer);
}
