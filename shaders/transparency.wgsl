// Transparent surfaces (docs/course/06-transparency.md), composed after shaders/scene.wgsl into
// one module. src/raster/transparency.rs draws them after the opaque surfaces, farthest first,
// with the blend I = Im + kt·Mt·I: the fragment returns Im (times the coverage α for alpha
// blending), and the blend state multiplies what the target holds by kt·Mt.

@fragment
fn fs_transparent(in: VertexOut) -> @location(0) vec4f {
    return transparent_fragment(in);
}

fn transparent_fragment(in: VertexOut) -> vec4f {
    if masked_out(in.uv) {
        discard;
    }
    // Alpha blending is the notes' formula with Im scaled by α; for any other material α = 1.
    var alpha = 1.0;
    if ALPHA_MODE == ALPHA_BLEND {
        alpha = coverage(in.uv);
    }
    return vec4f(alpha * shade(in), alpha);
}

// Depth peeling, the exact order (Everitt 2001, here back to front): layer k is the farthest
// transparent surface that is nearer than the opaque surface and strictly nearer than layer
// k − 1. The pass keeps the farthest survivor (depth test Greater); a second pass shades it.
@group(3) @binding(0) var opaque_depth: texture_depth_2d;
@group(3) @binding(1) var peeled_depth: texture_depth_2d;

@fragment
fn fs_peel(in: VertexOut) {
    let pixel = vec2i(in.clip.xy);
    let limit = min(textureLoad(opaque_depth, pixel, 0), textureLoad(peeled_depth, pixel, 0));
    if in.clip.z >= limit || masked_out(in.uv) {
        discard;
    }
}
