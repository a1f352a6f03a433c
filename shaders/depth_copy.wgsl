// A depth image copied by drawing (src/gpu/depth_copy.rs says why): one fullscreen triangle
// whose fragments read the source's depth under them and write it, unchanged, as their own
// depth. The source is bound as unfilterable floats (the depth in `.x`), as every depth image
// read with textureLoad is: GLSL cannot load a depth texture.

@group(0) @binding(0) var depth_source: texture_2d<f32>;

@vertex
fn vs_depth_copy(@builtin(vertex_index) index: u32) -> @builtin(position) vec4f {
    return fullscreen_position(index);
}

@fragment
fn fs_depth_copy(@builtin(position) pixel: vec4f) -> @builtin(frag_depth) f32 {
    return textureLoad(depth_source, vec2i(pixel.xy), 0).x;
}
