// Pass 1 of the shadow-map algorithm (TECHNIQUES.md §4): the scene's depth as each light sees it,
// one array layer per light view; and, for transparent occluders, the product of their kt·MT
// in front of the nearest opaque surface, with the depth of the nearest of them in alpha.
// Each light view is a View of its own (group 0's dynamic slot), as the main camera is.

@group(0) @binding(0) var<uniform> view: View;
@group(1) @binding(0) var<uniform> material: Material;

struct ShadowVertexOut {
    @builtin(position) clip: vec4f,
}

@vertex
fn vs_shadow(@location(0) position: vec3f, instance: Instance) -> ShadowVertexOut {
    var out: ShadowVertexOut;
    out.clip = view.clip_from_world * instance_world_from_local(instance) * vec4f(position, 1.0);
    return out;
}

// Transparent occluders multiply the colour (blend: dst × src) and keep the nearest depth in
// alpha (blend: min).
@fragment
fn fs_shadow_transmission(in: ShadowVertexOut) -> @location(0) vec4f {
    return vec4f(material.transmission, in.clip.z);
}
