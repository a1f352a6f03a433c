// The z-buffer forward pass: every opaque surface, shaded per fragment by the illumination model
// for all lights, into the linear HDR target.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> material: Material;
@group(1) @binding(1) var color_texture: texture_2d<f32>;
@group(1) @binding(2) var color_sampler: sampler;
@group(2) @binding(0) var<uniform> object: Object;

struct VertexIn {
    @location(0) position: vec3f,
    @location(1) normal: vec3f,
    @location(2) uv: vec2f,
}

struct VertexOut {
    @builtin(position) clip: vec4f,
    @location(0) world: vec3f,
    @location(1) normal: vec3f,
    @location(2) uv: vec2f,
}

@vertex
fn vs_opaque(in: VertexIn) -> VertexOut {
    let world = object.world_from_local * vec4f(in.position, 1.0);
    var out: VertexOut;
    out.clip = frame.clip_from_world * world;
    out.world = world.xyz;
    out.normal = (object.normal_from_local * vec4f(in.normal, 0.0)).xyz;
    out.uv = in.uv;
    return out;
}

// The unit vector from p towards the viewer, for either projection.
fn view_vector(p: vec3f) -> vec3f {
    if frame.orthographic != 0u {
        return frame.view_axis;
    }
    return normalize(frame.eye - p);
}

@fragment
fn fs_opaque(in: VertexOut) -> @location(0) vec4f {
    var color = material.color;
    if material.has_texture != 0u {
        color *= textureSample(color_texture, color_sampler, in.uv).rgb;
    }
    let surface = Surface(
        color, material.ka, material.kd, material.ks,
        material.specular_color, material.shininess, material.emission,
    );
    let v = view_vector(in.world);
    let n = facing_viewer(normalize(in.normal), v);
    var radiance = emitted_and_ambient(surface, frame.ambient, frame.terms);
    for (var i = 0u; i < min(frame.light_count, MAX_LIGHTS); i++) {
        let incidence = light_incidence(frame.lights[i], in.world);
        if incidence.valid {
            radiance += direct(surface, n, v, incidence, frame.terms);
        }
    }
    return vec4f(radiance, 1.0);
}
