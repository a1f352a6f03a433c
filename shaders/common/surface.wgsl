// The surface code every pass that draws the scene's surfaces shares (src/shaders.rs composes it,
// after view_group.wgsl and inspect.wgsl, into the scene, transparency, refraction and volume
// modules): the frame's and the material's toggles, groups 0 and 1, the vertex stage, and the
// illumination model evaluated at a fragment for all lights, each weighted by its visibility
// from the shadow pass. Each pass's own entry points and private bindings (group 3, numbered
// from 0) are in its own file.
//
// Every module computes the vertex position the same way, and `@invariant` makes it the same
// bits in all of them: the shading pass after a depth prepass and depth peeling test `Equal`
// against depths another module wrote.
//
// Toggles that switch code on or off are pipeline constants, not uniforms: a software GPU such
// as lavapipe runs both sides of a branch on a uniform value, so a shader that merely skips
// switched-off work would still pay for all of it. Each variant is compiled with its code only.

// The frame's toggles (FrameKey, src/raster/keys.rs).
override SHADOW_METHOD: u32 = 0u;
override SHADOW_FILTER: u32 = 0u;
override SHADOW_TRANSMISSION: bool = false;
override SHADOW_TEXELS_VIEW: bool = false;
override LEVEL_COLOUR: bool = false;
override BUMP: bool = false;
override BUMP_VIEW: u32 = 0u;
override TANGENTS_PER_VERTEX: bool = false;
override BUMP_ANALYTIC: bool = false;
// bump.method = "parallax": the relief's point the view ray meets first is shaded.
override PARALLAX: bool = false;
override FLAT_COLOUR: bool = false;
// Whether the frame traces any of the hybrid's terms; which ones, `frame.traced` says. A constant,
// so that a frame tracing none runs none of their code (lavapipe runs both sides of a branch).
override HYBRID: bool = false;
// The material's inputs (MaterialKey).
override COLOR_TEXTURE: bool = false;
override HEIGHT_KIND: u32 = 0u;
override NORMAL_MAP: bool = false;
// ALPHA_* of shaders/common/types.wgsl: whether coverage cuts the surface out or blends it.
override ALPHA_MODE: u32 = 0u;
// ENV_MAP_*: the map curved mirrors look kps·MPS·L(r) up in; 0: none.
override ENVIRONMENT: u32 = 0u;

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> frame: Frame;
// Bilinear, for height and normal maps (read on level 0).
@group(0) @binding(2) var height_sampler: sampler;
@group(1) @binding(0) var<uniform> material: Material;
// sRGB, with its whole mip chain: the sampler decodes to linear before it filters.
@group(1) @binding(1) var color_texture: texture_2d<f32>;
// Linear grey levels f_h(u, v); the red channel is the height.
@group(1) @binding(2) var height_texture: texture_2d<f32>;
// Tangent-space normals (glTF's normalTexture), linear.
@group(1) @binding(3) var normal_texture: texture_2d<f32>;
// The chosen texture filter (docs/course/03-mipmaps.md) with the material's wrap modes.
@group(1) @binding(4) var color_sampler: sampler;
// Group 2, what this view's shading reads: shaders/common/view_group.wgsl.

struct VertexIn {
    @location(0) position: vec3f,
    @location(1) normal: vec3f,
    @location(2) uv: vec2f,
    @location(3) tangent: vec4f,
}

struct VertexOut {
    // Invariant: the shading pass after a depth prepass tests Equal against the prepass's depth,
    // so both must compute exactly the same position.
    @builtin(position) @invariant clip: vec4f,
    @location(0) world: vec3f,
    @location(1) normal: vec3f,
    @location(2) uv: vec2f,
    // World-space tangent, and the bitangent's sign in w.
    @location(3) tangent: vec4f,
    // The object's dynamic environment cube, −1 for the world's.
    @location(4) @interpolate(flat) env_layer: i32,
    @location(5) @interpolate(flat) object: u32,
}

// The planar-mirror lab's route (assets/labs/planar-mirrors): a mirrored camera's reflection
// made at every vertex by `mirror_reflection` (shaders/common/optics.wgsl) instead of in its
// clip_from_world (src/raster/mirror). False in Mirador; the lab's routes set it.
const MIRROR_BY_HAND = false;

@vertex
fn vs_scene(in: VertexIn, instance: Instance) -> VertexOut {
    let world_from_local = instance_world_from_local(instance);
    let world = world_from_local * vec4f(in.position, 1.0);
    var out: VertexOut;
    out.clip = view.clip_from_world * world;
    if MIRROR_BY_HAND && any(view.clip_plane != vec4f(0.0)) {
        out.clip = view.clip_from_reflected * (mirror_reflection(view.clip_plane) * world);
    }
    out.world = world.xyz;
    out.normal = instance_normal_from_local(instance) * in.normal;
    out.uv = in.uv;
    out.tangent = vec4f((world_from_local * vec4f(in.tangent.xyz, 0.0)).xyz, in.tangent.w);
    out.env_layer = instance.env_layer;
    out.object = instance.object;
    return out;
}

// The unit vector from p towards the viewer, for either projection.
fn view_vector(p: vec3f) -> vec3f {
    if view.orthographic != 0u {
        return view.view_axis;
    }
    return normalize(view.eye - p);
}

// V_i for one light at p: 1 lit, 0 in shadow, a colour behind transparent occluders.
// `facing` is the normal on the side the light is on, for the normal offset.
fn visibility(light: Light, p: vec3f, facing: vec3f, pixel: vec2f) -> vec3f {
    if SHADOW_METHOD == SHADOWS_OFF || light.shadow_layer < 0 {
        return vec3f(1.0);
    }
    if SHADOW_METHOD == SHADOWS_PROJECTED {
        let mask = textureLoad(drawn_images, vec2i(pixel), PROJECTED_MASK_LAYER, 0);
        if INSPECT {
            probe.lights[probe_light].lit = 1.0 - mask[light.shadow_slot];
        }
        return vec3f(1.0 - mask[light.shadow_slot]);
    }
    var layer = u32(light.shadow_layer);
    if light.kind == LIGHT_POINT {
        layer += cube_face(p - light.position);
    }
    let coordinates = shadow_lookup_point(shadows.layers[layer], light.position, p, facing, shadows.normal_offset);
    if coordinates.w == 0.0 {
        return vec3f(1.0);
    }
    var v = vec3f(shadow_filtered(
        shadow_maps, shadow_sampler, coordinates.xy, coordinates.z, layer, SHADOW_FILTER,
        shadows.map_size,
    ));
    if INSPECT {
        let texel = min(vec2u(coordinates.xy * f32(shadows.map_size)), vec2u(shadows.map_size - 1u));
        probe.lights[probe_light].layer = i32(layer);
        probe.lights[probe_light].texel = vec2f(texel);
        probe.lights[probe_light].receiver_depth = coordinates.z;
        probe.lights[probe_light].lit = v.x;
    }
    // A transparent receiver is not tinted by transparent occluders: the transmission map holds
    // one product over every transparent surface in front of the nearest opaque one, the
    // receiver's own share included, and its nearest depth, with no bias to tell a surface from
    // itself. (Tried: dividing out the receiver's own share darkened sloped walls by self-tinting
    // worse than leaving the tint out.)
    if SHADOW_TRANSMISSION && material.transparent == 0u {
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
    switch HEIGHT_KIND {
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
    switch HEIGHT_KIND {
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

// The slopes (du, dv) = k·∇f_h: central differences (docs/course/04-bump-mapping.md), or for procedural fields
// their closed-form gradient when asked.
fn height_slopes(uv: vec2f, k: f32) -> vec2f {
    if BUMP_ANALYTIC && HEIGHT_KIND == HEIGHT_SINE {
        return k * sine_height_gradient(uv, material.height_frequency, material.height_amplitude);
    }
    if BUMP_ANALYTIC && HEIGHT_KIND == HEIGHT_NOISE {
        return k * value_noise(uv, material.noise_seed, material.noise_cells, material.noise_octaves, material.height_amplitude).yz;
    }
    let delta = height_delta();
    return bump_central_differences(
        height_at(uv + vec2f(delta.x, 0.0)), height_at(uv - vec2f(delta.x, 0.0)),
        height_at(uv + vec2f(0.0, delta.y)), height_at(uv - vec2f(0.0, delta.y)),
        delta, k,
    );
}

// Set by a lab (src/lab) whose student writes trilinear filtering: the colour texture is then
// read by `trilinear_sample` from texel loads at `mip_lod`, not by the sampler.
const TRILINEAR_BY_HAND = false;

// The surface colour C(p): the material's colour times its texture, or the level-colour view.
fn surface_color(uv: vec2f, duv_dx: vec2f, duv_dy: vec2f) -> vec3f {
    if !COLOR_TEXTURE {
        return material.color;
    }
    if TRILINEAR_BY_HAND {
        let lod = mip_lod(duv_dx, duv_dy, vec2f(textureDimensions(color_texture)), frame.lod_bias);
        return material.color * trilinear_sample(color_texture, uv, lod).rgb;
    }
    if LEVEL_COLOUR {
        let size = vec2f(textureDimensions(color_texture));
        let lod = mip_lod(duv_dx, duv_dy, size, frame.lod_bias);
        return mip_level_colour(clamp(lod, 0.0, f32(texture_level_count(color_texture) - 1u)));
    }
    return material.color * textureSampleBias(color_texture, color_sampler, uv, frame.lod_bias).rgb;
}

// The shading normal: the interpolated normal, perturbed by the height field (docs/course/04-bump-mapping.md:
// t'u = tu + du·n, t'v = tv + dv·n, n' = normalize(t'u × t'v)) and by a normal map.
fn shading_normal(in: VertexOut, tangents: SurfaceTangents) -> vec3f {
    var n = normalize(in.normal);
    if !BUMP || !tangents.valid {
        return n;
    }
    if HEIGHT_KIND != HEIGHT_NONE {
        let g = height_slopes(in.uv, material.bump_scale * frame.bump_scale);
        n = perturbed_normal(n, tangents.tu, tangents.tv, g.x, g.y);
        if INSPECT {
            probe.bump = g;
            probe.bump_k = material.bump_scale * frame.bump_scale;
            probe.bump_delta = height_delta();
        }
    }
    if NORMAL_MAP {
        // glTF's frame: t along ∂p/∂u (in n's plane), the bitangent's sign from ∂p/∂v.
        let t = tangents.tu - dot(tangents.tu, n) * n;
        let handedness = select(1.0, -1.0, dot(cross(n, t), tangents.tv) < 0.0);
        let rgb = textureSampleLevel(normal_texture, height_sampler, in.uv, 0.0).rgb;
        n = normal_map_normal(n, vec4f(t, handedness), rgb, material.normal_scale);
    }
    return n;
}

// The tangents ∂p/∂u, ∂p/∂v of the surface: from the change of position and uv across pixels
// (screen-space derivatives: call in uniform control flow), or the interpolated per-vertex
// tangent t and bitangent sign·(n × t), both unit length.
fn surface_tangents(in: VertexOut) -> SurfaceTangents {
    if TANGENTS_PER_VERTEX {
        let t = normalize(in.tangent.xyz);
        return SurfaceTangents(t, sign(in.tangent.w) * cross(normalize(in.normal), t), length(in.tangent.xyz) > 0.0);
    }
    return tangents_from_derivatives(dpdx(in.world), dpdy(in.world), dpdx(in.uv), dpdy(in.uv));
}

// The least and the greatest height the material's field can take: the slab parallax mapping
// marches through (Rust twin: HeightField::range, src/texture/height.rs).
fn height_range() -> vec2f {
    let a = abs(material.height_amplitude);
    switch HEIGHT_KIND {
        case HEIGHT_SINE: {
            return vec2f(-a, a);
        }
        case HEIGHT_NOISE: {
            return vec2f(-2.0 * a, 2.0 * a);
        }
        default: {
            return vec2f(0.0, 1.0);
        }
    }
}

// Parallax occlusion mapping (docs/course/04-bump-mapping.md; src/texture/parallax.rs, the same
// operations in the same order): the texture coordinates where the view ray along d, through
// the flat surface's point at uv, first meets the surface displaced by k·f. A point p + s·d of the
// ray is at height s·(d·n), at uv + s·duv_ds; PARALLAX_STEPS equal steps from the slab's top to
// its bottom find the first under the relief, PARALLAX_REFINEMENTS secant steps the crossing.
fn parallax_uv(uv: vec2f, n: vec3f, tangents: SurfaceTangents, d: vec3f) -> vec2f {
    let k = material.bump_scale * frame.bump_scale;
    let dn = dot(d, n);
    if !(dn < -1e-4) || k == 0.0 || !tangents.valid {
        return uv;
    }
    let range = height_range();
    let h_low = min(k * range.x, k * range.y);
    let h_high = max(k * range.x, k * range.y);
    // Degenerate tangents give no rate: the march stays at uv.
    let duv_ds = parallax_rate(d, n, tangents.tu, tangents.tv);
    let s_top = h_high / dn;
    let s_bottom = h_low / dn;
    var before = vec2f(s_top, parallax_gap(uv, duv_ds, s_top, dn, k));
    for (var step = 1u; step <= PARALLAX_STEPS; step++) {
        let s = s_top + (s_bottom - s_top) * (f32(step) / f32(PARALLAX_STEPS));
        let after = vec2f(s, parallax_gap(uv, duv_ds, s, dn, k));
        if after.y <= 0.0 {
            return uv + parallax_crossing(before, after, uv, duv_ds, dn, k) * duv_ds;
        }
        before = after;
    }
    return uv + s_bottom * duv_ds;
}

// How far the ray's point at s is above the displaced surface there.
fn parallax_gap(uv: vec2f, duv_ds: vec2f, s: f32, dn: f32, k: f32) -> f32 {
    return s * dn - k * height_at(uv + s * duv_ds);
}

// The s where the gap crosses zero between above (gap > 0) and below (gap ≤ 0): secant steps,
// each keeping the pair that brackets the crossing.
fn parallax_crossing(above_start: vec2f, below_start: vec2f, uv: vec2f, duv_ds: vec2f, dn: f32, k: f32) -> f32 {
    var above = above_start;
    var below = below_start;
    for (var i = 0u; i < PARALLAX_REFINEMENTS; i++) {
        let s = secant_crossing(above, below);
        let at = vec2f(s, parallax_gap(uv, duv_ds, s, dn, k));
        if at.y > 0.0 {
            above = at;
        } else {
            below = at;
        }
    }
    return secant_crossing(above, below);
}

// What shading a fragment found: the radiance leaving it towards the viewer, and for the
// passes that add transmission (transparency.wgsl, refraction.wgsl) the shading normal n (turned
// to the viewer), the view vector v and L(r), the environment looked up along the reflected
// direction (zero where the frame has no environment map or the object looks none up).
struct Shaded {
    radiance: vec3f,
    n: vec3f,
    v: vec3f,
    environment: vec3f,
}

// The radiance leaving the surface towards the viewer: ME + AG + Σ_i V_i·S_i·L_dir, plus the
// mirror term kps·MPS·L(r) of a curved mirror.
fn shade(in: VertexOut) -> vec3f {
    return shade_surface(in).radiance;
}

// The illumination model at a fragment, each technique's part in a function of its own, in the
// order the model adds them (the sums' order is the image's bits).
fn shade_surface(in: VertexOut) -> Shaded {
    // Screen-space derivatives first, in uniform control flow: the texture's level of detail and
    // the tangents ∂p/∂u, ∂p/∂v of the surface, from the change of position and uv across pixels.
    let duv_dx = dpdx(in.uv);
    let duv_dy = dpdy(in.uv);
    let tangents = surface_tangents(in);
    // The hybrid's terms hold at this pixel only if they were traced on this fragment's surface.
    let here = HYBRID && frame.traced != 0u && traced_object(in.clip.xy) == in.object + 1u;
    // Parallax mapping shades the point of the relief the view ray meets first.
    var at = in;
    if PARALLAX && HEIGHT_KIND != HEIGHT_NONE {
        at.uv = parallax_uv(in.uv, normalize(in.normal), tangents, -view_vector(in.world));
    }
    var color = surface_color(at.uv, duv_dx, duv_dy);
    if (frame.traced & TRACED_TEXTURES) != 0u && here {
        color = traced_term(in.clip.xy, TRACED_SURFACE_LAYER);
    }
    if INSPECT {
        inspect_texture(in, color, duv_dx, duv_dy);
    }
    if FLAT_COLOUR {
        return Shaded(color, normalize(in.normal), view_vector(in.world), vec3f(0.0));
    }
    let v = view_vector(in.world);
    let n = facing_viewer(shading_normal(at, tangents), v);
    if BUMP_VIEW == BUMP_VIEW_NORMALS {
        return Shaded(0.5 + 0.5 * n, n, v, vec3f(0.0));
    }
    if BUMP_VIEW == BUMP_VIEW_TANGENTS {
        return Shaded(0.5 + 0.5 * normalize(tangents.tu), n, v, vec3f(0.0));
    }
    let surface = Surface(
        color, material.ka, material.kd, material.ks,
        material.specular_color, material.shininess, material.emission,
    );
    var radiance = emitted_and_ambient(surface, frame.ambient, frame.terms);
    if INSPECT {
        probe.normal = n;
        probe.emission = select(vec3f(0.0), surface.emission, (frame.terms & TERM_EMISSION) != 0u);
        probe.global_ambient = select(vec3f(0.0), frame.ambient * surface.kd * surface.color, (frame.terms & TERM_AMBIENT) != 0u);
    }
    radiance = lit_by_lights(radiance, in, surface, n, v, here);
    return with_mirror_term(radiance, in, n, v, here);
}

// What the inspection records of the surface: where, its colour and its texture's level.
fn inspect_texture(in: VertexOut, color: vec3f, duv_dx: vec2f, duv_dy: vec2f) {
    probe.world = in.world;
    probe.uv = in.uv;
    probe.colour = color;
    probe.geometric = normalize(in.normal);
    probe.lod = -1.0;
    if COLOR_TEXTURE {
        let size = vec2f(textureDimensions(color_texture));
        probe.lod = mip_lod(duv_dx, duv_dy, size, frame.lod_bias);
        probe.footprint = vec2f(length(duv_dx * size), length(duv_dy * size));
    }
}

// radiance + Σ_i V_i·S_i·L_dir over the frame's lights, each V_i from its shadow (or the hybrid's
// traced term), in the lights' order; the shadow-map texel view's checker over it.
fn lit_by_lights(ambient: vec3f, in: VertexOut, surface: Surface, n: vec3f, v: vec3f, here: bool) -> vec3f {
    var radiance = ambient;
    var checker = -1.0;
    // The hybrid's traced lights: where traced, the lights without a shadow map are the tracer's.
    let traced_lights = (frame.traced & TRACED_LIGHTS) != 0u && here;
    for (var i = 0u; i < min(frame.light_count, MAX_LIGHTS); i++) {
        let light = frame.lights[i];
        let incidence = light_incidence(light, in.world);
        if incidence.valid && !(traced_lights && light.shadow_slot < 0) {
            let facing = select(-n, n, dot(n, incidence.l) >= 0.0);
            if INSPECT {
                probe_light = i;
                probe.lights[i].layer = -1;
                probe.lights[i].lit = 1.0;
            }
            var visible: vec3f;
            if (frame.traced & TRACED_SHADOWS) != 0u && here && light.shadow_slot >= 0 {
                visible = traced_term(in.clip.xy, TRACED_SHADOWS_LAYER + light.shadow_slot);
            } else {
                visible = visibility(light, in.world, facing, in.clip.xy);
            }
            if INSPECT {
                let parts = direct_terms(surface, n, v, incidence, frame.terms);
                probe.lights[i].ambient = parts[0];
                probe.lights[i].diffuse = parts[1];
                probe.lights[i].specular = parts[2];
                probe.lights[i].visibility = visible;
            }
            radiance += visible * direct(surface, n, v, incidence, frame.terms);
            if SHADOW_TEXELS_VIEW && SHADOW_METHOD == SHADOWS_MAP && light.shadow_layer >= 0 && checker < 0.0 {
                checker = texel_checker(light, in.world);
            }
        }
    }
    if traced_lights {
        radiance += traced_term(in.clip.xy, TRACED_LIGHTS_LAYER);
    }
    if checker >= 0.0 {
        radiance *= mix(0.55, 1.0, checker);
    }
    return radiance;
}

// The shadow-map texel view: which of the map's texels `world` falls in, as a checker.
fn texel_checker(light: Light, world: vec3f) -> f32 {
    var layer = u32(light.shadow_layer);
    if light.kind == LIGHT_POINT {
        layer += cube_face(world - light.position);
    }
    return shadow_texel_checker(shadow_coordinates(shadows.layers[layer].clip_from_world, world).xy, shadows.map_size);
}

// radiance plus the mirror term kps·MPS·L(r) of a curved mirror: L(r) from the environment map,
// or traced by the hybrid; and the environment's L(r), which glass reads.
fn with_mirror_term(lit: vec3f, in: VertexOut, n: vec3f, v: vec3f, here: bool) -> Shaded {
    var radiance = lit;
    var environment_radiance = vec3f(0.0);
    if ENVIRONMENT != 0u {
        // Looked up everywhere (its derivatives need uniform control flow), kept where the
        // object reflects through a map.
        let r = 2.0 * dot(n, v) * n - v;
        environment_radiance = select(vec3f(0.0), environment_lookup(in.world, r, in.env_layer), in.env_layer != ENV_LAYER_NONE);
        // Where the hybrid traced this surface's reflection, that is added below instead (the
        // lookup stays: glass reads it).
        if (frame.traced & TRACED_REFLECTIONS) == 0u || !here {
            radiance += material.reflectance * environment_radiance;
        }
        if INSPECT {
            probe.environment = material.reflectance * environment_radiance;
            probe.env_direction = r;
            probe.env_layer = in.env_layer;
        }
    }
    if (frame.traced & TRACED_REFLECTIONS) != 0u && here {
        // kps·MPS·L(r), L(r) traced: in place of the mirrored camera's image and the environment
        // maps, which the frame leaves out when this is on.
        let traced_reflection = material.reflectance * traced_term(in.clip.xy, TRACED_REFLECTIONS_LAYER);
        radiance += traced_reflection;
        if INSPECT {
            probe.mirror = traced_reflection;
        }
    }
    return Shaded(radiance, n, v, environment_radiance);
}

// The object + 1 whose surface the view's traced terms were traced on at this pixel; 0: none.
fn traced_object(pixel: vec2f) -> u32 {
    return u32(textureLoad(copied_images, vec2i(pixel), TRACED_FIRST_LAYER + TRACED_SURFACE_LAYER, 0).a);
}

// One of the view's traced terms at this pixel.
fn traced_term(pixel: vec2f, layer: i32) -> vec3f {
    return textureLoad(copied_images, vec2i(pixel), TRACED_FIRST_LAYER + layer, 0).rgb;
}

// L(d), the radiance arriving at p from direction d, looked up in the environment map: for the
// mirror term kps·MPS·L(r) of a curved mirror (docs/course/08-environment-maps.md), r = 2(n·v)n − v,
// and for glass's reflection and refraction. An object's own dynamic cube is read along the
// direction the parallax setting gives (parallax_direction). The level of detail comes from the
// direction's change across the pixel, taken here in uniform control flow, so a reflection
// minified on a small sphere is filtered rather than aliased.
fn environment_lookup(p: vec3f, d: vec3f, layer: i32) -> vec3f {
    var lookup = d;
    if ENVIRONMENT == ENV_MAP_DYNAMIC && layer >= 0 {
        lookup = parallax_direction(environment, p, d, environment.cube_centres[layer].xyz);
    }
    let dx = dpdx(lookup);
    let dy = dpdy(lookup);
    if ENVIRONMENT == ENV_MAP_SPHERE {
        let uv = sphere_map_uv(environment.sphere_from_world * d);
        return textureSampleGrad(env_sphere, env_sampler, uv, dpdx(uv), dpdy(uv)).rgb;
    }
    if ENVIRONMENT == ENV_MAP_LATLONG {
        let uv = latlong_uv(d);
        return textureSampleGrad(env_latlong, env_sampler, uv, latlong_gradient(dpdx(uv)), latlong_gradient(dpdy(uv))).rgb;
    }
    if ENVIRONMENT == ENV_MAP_DYNAMIC && layer >= 0 {
        return cube_array_sample_grad(env_cubes, env_sampler, lookup, layer, dx, dy).rgb;
    }
    return textureSampleGrad(env_cube, env_sampler, d, dx, dy).rgb;
}

// Coverage α: the material's alpha times its colour texture's (glTF's base colour alpha).
fn coverage(uv: vec2f) -> f32 {
    if !COLOR_TEXTURE {
        return material.alpha;
    }
    return material.alpha * textureSampleBias(color_texture, color_sampler, uv, frame.lod_bias).a;
}

// Whether a cut-out surface (ALPHA_MASK) is absent at this fragment.
fn masked_out(uv: vec2f) -> bool {
    return ALPHA_MODE == ALPHA_MASK && coverage(uv) < material.alpha_cutoff;
}

