// Pass 1 of the shadow-map algorithm (docs/course/05-shadows.md): the scene's depth as each light sees it,
// one array layer per light view; and, for transparent occluders, the product of their kt·MT
// in front of the nearest opaque surface, with the depth of the nearest of them in alpha.
// Each light view is a View of its own (group 0's dynamic slot), as the main camera is.

@group(0) @binding(0) var<uniform> view: View;
@group(1) @binding(0) var<uniform> material: Material;
@group(1) @binding(1) var color_texture: texture_2d<f32>;
@group(1) @binding(4) var color_sampler: sampler;

struct ShadowVertexOut {
    @builtin(position) clip: vec4f,
    @location(0) uv: vec2f,
}

@vertex
fn vs_shadow(@location(0) position: vec3f, @location(2) uv: vec2f, instance: Instance) -> ShadowVertexOut {
    var out: ShadowVertexOut;
    out.clip = view.clip_from_world * instance_world_from_local(instance) * vec4f(position, 1.0);
    out.uv = uv;
    return out;
}

// Coverage α as the scene pass reads it (an untextured material binds a white texture).
fn shadow_coverage(uv: vec2f) -> f32 {
    return material.alpha * textureSample(color_texture, color_sampler, uv).a;
}

// Cut-out casters (ALPHA_MASK) cast only where their surface is.
@fragment
fn fs_shadow_mask(in: ShadowVertexOut) {
    if shadow_coverage(in.uv) < material.alpha_cutoff {
        discard;
    }
}

// Transparent occluders multiply the colour by what they let through (blend: dst × src) and
// keep the nearest depth in alpha (blend: min).
@fragment
fn fs_shadow_transmission(in: ShadowVertexOut) -> @location(0) vec4f {
    let alpha = shadow_coverage(in.uv);
    if material.alpha_mode == ALPHA_MASK && alpha < material.alpha_cutoff {
        discard;
    }
    return vec4f(material_transmittance(material, alpha), in.clip.z);
}
