// Teaching overlays drawn over the shaded image (src/raster/overlays.rs): one shadow-map layer as
// grey levels, and lines in the scene (view volumes, the volumes' grid wireframe).

// ---- One layer of the shadow maps, depth as grey.

struct ShownLayer {
    layer: u32,
    width: u32,
    height: u32,
    // near/far of a perspective view, 0 for an orthographic one.
    depth_ratio: f32,
}

// The stored depths themselves, in x: read as floats, since GLSL has no texelFetch of a depth
// texture (src/gpu/layout.rs, depth_texels).
@group(0) @binding(1) var shadow_maps: texture_2d_array<f32>;
@group(0) @binding(2) var<uniform> shown_layer: ShownLayer;

@vertex
fn vs_shadow_map_view(@builtin(vertex_index) index: u32) -> @builtin(position) vec4f {
    return fullscreen_position(index);
}

@fragment
fn fs_shadow_map_view(@builtin(position) pixel: vec4f) -> @location(0) vec4f {
    // The map fills the largest centred square of the image.
    let size = vec2f(f32(shown_layer.width), f32(shown_layer.height));
    let side = min(size.x, size.y);
    let uv = (pixel.xy - 0.5 * (size - side)) / side;
    if any(uv < vec2f(0.0)) || any(uv >= vec2f(1.0)) {
        return vec4f(0.02, 0.02, 0.03, 1.0);
    }
    let map_size = textureDimensions(shadow_maps);
    let depth = textureLoad(shadow_maps, min(vec2u(uv * vec2f(map_size)), map_size - 1u), shown_layer.layer, 0).x;
    // A perspective view's depth crowds towards 1; shown as distance over the far plane instead.
    let r = shown_layer.depth_ratio;
    let distance = select(depth, r / (1.0 - depth * (1.0 - r)), r > 0.0);
    return vec4f(vec3f(distance), 1.0);
}

// ---- Lines in the scene, one colour per draw.

// Group 0 of the scene pass, read at the main view's slot.
@group(0) @binding(0) var<uniform> view: View;

struct LineVertex {
    @builtin(position) position: vec4f,
    @location(0) colour: vec3f,
}

@vertex
fn vs_lines(@location(0) position: vec3f, @location(1) colour: vec3f) -> LineVertex {
    return LineVertex(view.clip_from_world * vec4f(position, 1.0), colour);
}

@fragment
fn fs_lines(line: LineVertex) -> @location(0) vec4f {
    return vec4f(line.colour, 1.0);
}
