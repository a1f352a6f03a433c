// Object-precision shadows (docs/course/05-shadows.md#shadow-maps-image-precision, "algoritmo de fuerza bruta"): the shadow polygons
// that casters project from each light onto planar receivers, computed on the CPU
// (src/raster/shadow/projected.rs) and drawn here as detail polygons into a screen-sized mask:
// channel i is 1 where the receiver is in the shadow of shadowed light i. The mask's blend is
// max, so where polygons overlap the receiver is not darkened twice.

// Group 0 of the scene pass, at the main view's slot.
@group(0) @binding(0) var<uniform> view: View;

struct ProjectedIn {
    @location(0) position: vec3f,
    @location(1) slot: u32,
}

struct ProjectedOut {
    @builtin(position) clip: vec4f,
    @location(0) @interpolate(flat) slot: u32,
}

@vertex
fn vs_shadow_projected(in: ProjectedIn) -> ProjectedOut {
    var out: ProjectedOut;
    out.clip = view.clip_from_world * vec4f(in.position, 1.0);
    out.slot = in.slot;
    return out;
}

@fragment
fn fs_shadow_projected(in: ProjectedOut) -> @location(0) vec4f {
    var mask = vec4f(0.0);
    mask[in.slot] = 1.0;
    return mask;
}
