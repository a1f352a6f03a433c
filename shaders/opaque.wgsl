// The z-buffer forward pass: every opaque surface, shaded per fragment by the illumination model
// for all lights, into the linear HDR target.

@group(0) @binding(0) var<uniform> frame: Frame;
// Bilinear, for height and normal maps (read on level 0).
@group(0) @binding(1) var height_sampler: sampler;
@group(1) @binding(0) var<uniform> material: Material;
// sRGB, with its whole mip chain: the sampler decodes to linear before it filters.
@group(1) @binding(1) var color_texture: texture_2d<f32>;
// Linear grey levels f_h(u, v); the red channel is the height.
@group(1) @binding(2) var height_texture: texture_2d<f32>;
// Tangent-space normals (glTF's normalTexture), linear.
@group(1) @binding(3) var normal_texture: texture_2d<f32>;
// The chosen texture filter (TECHNIQUES.md §2) with the material's wrap modes.
@group(1) @binding(4) var color_sampler: sampler;
@group(2) @binding(0) var<uniform> object: Object;
// Group 3: the shadow maps of this frame (pass 1's output) and how to read them.
@group(3) @binding(0) var<uniform> shadows: Shadows;
@group(3) @binding(1) var shadow_maps: texture_depth_2d_array;
@group(3) @binding(2) var shadow_linear: sampler_comparison;
@group(3) @binding(3) var shadow_nearest: sampler_comparison;
@group(3) @binding(4) var transmission_maps: texture_2d_array<f32>;
@group(3) @binding(5) var projected_mask: texture_2d<f32>;

const SHADOW_METHOD_MAP: u32 = 0u;
const SHADOW_VIEW_TEXELS: u32 = 2u;

struct VertexIn {
    @location(0) position: vec3f,
    @location(1) normal: vec3f,
    @location(2) uv: vec2f,
    @location(3) tangent: vec4f,
}

struct VertexOut {
    @builtin(position) clip: vec4f,
    @location(0) world: vec3f,
    @location(1) normal: vec3f,
    @location(2) uv: vec2f,
    // World-space tangent, and the bitangent's sign in w.
    @location(3) tangent: vec4f,
}

@vertex
fn vs_opaque(in: VertexIn) -> VertexOut {
    let world = object.world_from_local * vec4f(in.position, 1.0);
    var out: VertexOut;
    out.clip = frame.clip_from_world * world;
    out.world = world.xyz;
    out.normal = (object.normal_from_local * vec4f(in.normal, 0.0)).xyz;
    out.uv = in.uv;
    out.tangent = vec4f((object.world_from_local * vec4f(in.tangent.xyz, 0.0)).xyz, in.tangent.w);
    return out;
}

// The unit vector from p towards the viewer, for either projection.
fn view_vector(p: vec3f) -> vec3f {
    if frame.orthographic != 0u {
        return frame.view_axis;
    }
    return normalize(frame.eye - p);
}

// V_i for one light at p: 1 lit, 0 in shadow, a colour behind transparent occluders.
// `facing` is the normal on the side the light is on, for the normal offset.
fn visibility(light: Light, p: vec3f, facing: vec3f, pixel: vec2f) -> vec3f {
    if shadows.enabled == 0u || light.shadow_layer < 0 {
        return vec3f(1.0);
    }
    if shadows.method != SHADOW_METHOD_MAP {
        let mask = textureLoad(projected_mask, vec2i(pixel), 0);
        return vec3f(1.0 - mask[light.shadow_slot]);
    }
    var layer = u32(light.shadow_layer);
    if light.kind == LIGHT_POINT {
        layer += cube_face(p - light.position);
    }
    let view = shadows.layers[layer];
    // The texel's world size where p is: fixed for orthographic views, growing with distance
    // from the light for perspective ones.
    let texel = select(view.texel_size, view.texel_size * distance(p, light.position), view.perspective != 0u);
    let q = p + facing * shadows.normal_offset * texel;
    let coordinates = shadow_coordinates(view.clip_from_world, q);
    let inside = coordinates.w > 0.0 && all(coordinates.xy >= vec2f(0.0)) && all(coordinates.xy <= vec2f(1.0))
        && coordinates.z <= 1.0;
    if !inside {
        // Outside the light's view: nothing there was drawn into the map, so nothing occludes.
        return vec3f(1.0);
    }
    var v = vec3f(shadow_filtered(
        shadow_maps, shadow_linear, shadow_nearest, coordinates.xy, coordinates.z, layer, shadows.filter_mode,
        shadows.map_size,
    ));
    // A transparent receiver is not tinted by transparent occluders: in this one-layer
    // approximation it would be tinted by itself.
    if shadows.transmission != 0u && material.transparent == 0u {
        let size = vec2f(textureDimensions(transmission_maps));
        let tint = textureLoad(transmission_maps, vec2i(coordinates.xy * size), layer, 0);
        if coordinates.z > tint.a {
            v *= tint.rgb;
        }
    }
    return v;
}

// f_h(u, v): the height map's red channel (bilinear on level 0), or a procedural field.
fn height_at(uv: vec2f) -> f32 {
    switch material.height_kind {
        case HEIGHT_SINE: {
            return sine_height(uv, material.height_frequency, material.height_amplitude);
        }
        case HEIGHT_NOISE: {
            return value_noise(uv, material.noise_seed, material.noise_cells, material.noise_octaves, material.height_amplitude).x;
        }
        default: {
            return textureSampleLevel(height_texture, height_sampler, uv, 0.0).r;
        }
    }
}

// The finite-difference step Δ: bump_delta_texels texels of the height map, or of a procedural
// field's own step (a 64th of a sine's shortest period, a 16th of the finest noise cell), as
// src/texture/height.rs's default_delta.
fn height_delta() -> vec2f {
    switch material.height_kind {
        case HEIGHT_SINE: {
            return frame.bump_delta_texels / (64.0 * max(abs(material.height_frequency), vec2f(1.0)));
        }
        case HEIGHT_NOISE: {
            let finest = max(material.noise_cells, 1u) << min(max(material.noise_octaves, 1u) - 1u, 20u);
            return vec2f(frame.bump_delta_texels / (16.0 * f32(finest)));
        }
        default: {
            return frame.bump_delta_texels / vec2f(textureDimensions(height_texture));
        }
    }
}

// The slopes (du, dv) = k·∇f_h: central differences (TECHNIQUES.md §3), or for procedural fields
// their closed-form gradient when asked.
fn height_slopes(uv: vec2f, k: f32) -> vec2f {
    if frame.bump_analytic != 0u {
        if material.height_kind == HEIGHT_SINE {
            return k * sine_height_gradient(uv, material.height_frequency, material.height_amplitude);
        }
        if material.height_kind == HEIGHT_NOISE {
            return k * value_noise(uv, material.noise_seed, material.noise_cells, material.noise_octaves, material.height_amplitude).yz;
        }
    }
    let delta = height_delta();
    return bump_central_differences(
        height_at(uv + vec2f(delta.x, 0.0)), height_at(uv - vec2f(delta.x, 0.0)),
        height_at(uv + vec2f(0.0, delta.y)), height_at(uv - vec2f(0.0, delta.y)),
        delta, k,
    );
}

// TECHNIQUES.md §3: perturbed tangents t'u = tu + du·n, t'v = tv + dv·n, and
// n' = normalize(t'u × t'v) turned to n's side.
fn bumped_normal(n: vec3f, uv: vec2f, tangents: SurfaceTangents) -> vec3f {
    let g = height_slopes(uv, material.bump_scale * frame.bump_scale);
    return perturbed_normal(n, tangents.tu, tangents.tv, g.x, g.y);
}

@fragment
fn fs_opaque(in: VertexOut) -> @location(0) vec4f {
    // Screen-space derivatives first, in uniform control flow: the texture's level of detail and
    // the tangents ∂p/∂u, ∂p/∂v of the surface, from the change of position and uv across pixels.
    let duv_dx = dpdx(in.uv);
    let duv_dy = dpdy(in.uv);
    var tangents = tangents_from_derivatives(dpdx(in.world), dpdy(in.world), duv_dx, duv_dy);
    var color = material.color;
    if material.has_texture != 0u {
        if frame.texture_filter == TEXTURE_FILTER_LEVEL_COLOUR {
            let size = vec2f(textureDimensions(color_texture));
            let lod = mip_lod(duv_dx, duv_dy, size, frame.lod_bias);
            color = mip_level_colour(clamp(lod, 0.0, f32(textureNumLevels(color_texture) - 1u)));
        } else {
            color *= textureSampleBias(color_texture, color_sampler, in.uv, frame.lod_bias).rgb;
        }
    }
    let surface = Surface(
        color, material.ka, material.kd, material.ks,
        material.specular_color, material.shininess, material.emission,
    );
    let v = view_vector(in.world);
    var shading_normal = normalize(in.normal);
    if frame.bump_tangents == BUMP_TANGENTS_PER_VERTEX {
        // Interpolated per-vertex tangent t and bitangent sign·(n × t), both unit length.
        let t = normalize(in.tangent.xyz);
        tangents = SurfaceTangents(t, sign(in.tangent.w) * cross(shading_normal, t), length(in.tangent.xyz) > 0.0);
    }
    if frame.bump_enabled != 0u && material.has_height_map != 0u && tangents.valid {
        shading_normal = bumped_normal(shading_normal, in.uv, tangents);
    }
    if frame.bump_enabled != 0u && material.has_normal_map != 0u && tangents.valid {
        // glTF's frame: t along ∂p/∂u (in n's plane), the bitangent's sign from ∂p/∂v.
        let t = tangents.tu - dot(tangents.tu, shading_normal) * shading_normal;
        let handedness = select(1.0, -1.0, dot(cross(shading_normal, t), tangents.tv) < 0.0);
        let rgb = textureSampleLevel(normal_texture, height_sampler, in.uv, 0.0).rgb;
        shading_normal = normal_map_normal(shading_normal, vec4f(t, handedness), rgb, material.normal_scale);
    }
    let n = facing_viewer(shading_normal, v);
    if frame.bump_view == BUMP_VIEW_NORMALS {
        return vec4f(0.5 + 0.5 * n, 1.0);
    }
    if frame.bump_view == BUMP_VIEW_TANGENTS {
        return vec4f(0.5 + 0.5 * normalize(tangents.tu), 1.0);
    }
    var radiance = emitted_and_ambient(surface, frame.ambient, frame.terms);
    var checker = -1.0;
    for (var i = 0u; i < min(frame.light_count, MAX_LIGHTS); i++) {
        let light = frame.lights[i];
        let incidence = light_incidence(light, in.world);
        if incidence.valid {
            let facing = select(-n, n, dot(n, incidence.l) >= 0.0);
            radiance += visibility(light, in.world, facing, in.clip.xy) * direct(surface, n, v, incidence, frame.terms);
            if shadows.view == SHADOW_VIEW_TEXELS && light.shadow_layer >= 0 && checker < 0.0 {
                var layer = u32(light.shadow_layer);
                if light.kind == LIGHT_POINT {
                    layer += cube_face(in.world - light.position);
                }
                checker = shadow_texel_checker(shadow_coordinates(shadows.layers[layer].clip_from_world, in.world).xy, shadows.map_size);
            }
        }
    }
    if checker >= 0.0 {
        radiance *= mix(0.55, 1.0, checker);
    }
    return vec4f(radiance, 1.0);
}
