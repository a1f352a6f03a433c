// Direct volume rendering (docs/course/11-volumes.md), with the surface code of
// shaders/common/surface.wgsl (the illumination model, the shadow lookups): the GPU twin of
// src/volume/march.rs, drawn by src/raster/volume.rs over the opaque image.
//
// The volume's box is the proxy geometry: its back faces are drawn (so a camera inside still
// gets fragments), and each fragment casts the camera ray through its pixel centre, as the
// tracer's primary ray, clips it to the box and to the opaque surface there (read from a copy of
// the depth buffer), and marches it:
//   composite   k equal parts, sampled at their midpoints from a 3D texture (hardware nearest or
//               trilinear filtering), classified through the transfer table, the opacity
//               corrected for the part's length, shaded C_amb + Σ V·C_luz·k_dif·(n·L), composited
//               front to back with early termination; the blend adds (1 − α) of what is behind.
//   isosurface  the same samples until f − iso changes sign, refined by bisection, shaded with the
//               volume's material (group 1) like any surface; writes its depth.

override VOLUME_GRADIENT: u32 = 2u;
override VOLUME_SHADOWS: bool = false;
// Rays end at the nearer of the opaque surface and `peeled_depth` (a transparent layer peeled
// before: the volume lies behind it), and start at `near_depth` (the layer being peeled: the
// volume lies behind it, between the two). src/raster/transparency.rs says when.
override VOLUME_FAR_LIMIT: bool = false;
override VOLUME_NEAR_LIMIT: bool = false;

struct Volume {
    world_from_local: mat4x4f,
    local_from_world: mat4x4f,
    // The upper 3 × 3 carries local gradients to world normals (the inverse transpose).
    normal_from_local: mat4x4f,
    half_extent: vec3f,
    // The smallest spacing Δ₀: the unit of the step and of the transfer function's opacity.
    voxel_length: f32,
    spacing: vec3f,
    // Sample spacing in voxels.
    step: f32,
    // Grid points per axis (of the texture).
    dims: vec3f,
    // Normalized iso value.
    iso: f32,
    // Accumulated opacity that ends a ray; above 1: never.
    termination: f32,
    opacity_correction: u32,
    view: u32,
    samples_white: f32,
}

// Group 3: the view's depth (a copy of it for isosurfaces, which write depth), the transparent
// layers that bound the rays (`peeled_depth` behind, `near_depth` in front), and the volume's
// uniform, field, sampler and transfer table. Depth images read with textureLoad are declared as
// float textures, depth in x (src/gpu/layout.rs, depth_texels).
@group(3) @binding(0) var opaque_depth: texture_2d<f32>;
@group(3) @binding(1) var peeled_depth: texture_2d<f32>;
@group(3) @binding(2) var near_depth: texture_2d<f32>;
@group(3) @binding(3) var<uniform> volume: Volume;
@group(3) @binding(4) var volume_texture: texture_3d<f32>;
@group(3) @binding(5) var volume_sampler: sampler;
@group(3) @binding(6) var<uniform> transfer_table: array<vec4f, VOLUME_TABLE_SIZE>;

struct VolumeVertex {
    @builtin(position) clip: vec4f,
}

// The 12 triangles of the box [−1, 1]³, wound counter-clockwise seen from outside.
const BOX_CORNERS = array<vec3f, 8>(
    vec3f(-1.0, -1.0, -1.0), vec3f(1.0, -1.0, -1.0), vec3f(-1.0, 1.0, -1.0), vec3f(1.0, 1.0, -1.0),
    vec3f(-1.0, -1.0, 1.0), vec3f(1.0, -1.0, 1.0), vec3f(-1.0, 1.0, 1.0), vec3f(1.0, 1.0, 1.0),
);
const BOX_INDICES = array<u32, 36>(
    0u, 2u, 1u, 1u, 2u, 3u,  4u, 5u, 6u, 5u, 7u, 6u,
    0u, 1u, 4u, 1u, 5u, 4u,  2u, 6u, 3u, 3u, 6u, 7u,
    0u, 4u, 2u, 2u, 4u, 6u,  1u, 3u, 5u, 3u, 7u, 5u,
);

@vertex
fn vs_volume(@builtin(vertex_index) index: u32) -> VolumeVertex {
    let local = BOX_CORNERS[BOX_INDICES[index]] * volume.half_extent;
    return VolumeVertex(view.clip_from_world * volume.world_from_local * vec4f(local, 1.0));
}

struct VolumeRay {
    origin: vec3f,
    direction: vec3f,
    // Local origin and direction, with the world ray's t.
    local_origin: vec3f,
    local_direction: vec3f,
    t0: f32,
    t1: f32,
}

// The camera ray through the pixel centre `pixel`, clipped to the box, to the opaque surface, to
// the transparent layers that bound this part of it, and to the view's clip plane (a mirrored
// camera sees only what lies beyond its mirror). `t0 >= t1` where nothing of the box is left.
fn volume_ray(pixel: vec2f) -> VolumeRay {
    let size = vec2f(textureDimensions(opaque_depth));
    let ndc = vec2f(2.0 * pixel.x / size.x - 1.0, 1.0 - 2.0 * pixel.y / size.y);
    var ray: VolumeRay;
    if view.orthographic != 0u {
        let near = view.world_from_clip * vec4f(ndc, 0.0, 1.0);
        ray.origin = near.xyz / near.w;
        ray.direction = -view.view_axis;
    } else {
        // Any point on the pixel's ray, unprojected: q.xyz − eye·q.w points away from the eye
        // whatever the sign of q.w (a mirrored view's oblique projection puts some depths
        // behind the eye), as fs_background finds it.
        let q = view.world_from_clip * vec4f(ndc, 0.5, 1.0);
        ray.origin = view.eye;
        ray.direction = normalize(q.xyz - view.eye * q.w);
    }
    var t_end = depth_distance(ray, ndc, textureLoad(opaque_depth, vec2i(pixel), 0).x);
    var t_start = 0.0;
    if VOLUME_FAR_LIMIT {
        t_end = min(t_end, depth_distance(ray, ndc, textureLoad(peeled_depth, vec2i(pixel), 0).x));
    }
    if VOLUME_NEAR_LIMIT {
        // No layer here (the peel is cleared to 0): nothing in front bounds the ray.
        let depth = textureLoad(near_depth, vec2i(pixel), 0).x;
        if depth > 0.0 {
            t_start = depth_distance(ray, ndc, depth);
        }
    }
    let plane = view.clip_plane;
    if any(plane != vec4f(0.0)) {
        let distance = dot(plane.xyz, ray.origin) + plane.w;
        let rate = dot(plane.xyz, ray.direction);
        if distance < 0.0 {
            t_start = max(t_start, select(3.4e38, -distance / rate, rate > 0.0));
        } else if rate < 0.0 {
            t_end = min(t_end, -distance / rate);
        }
    }
    ray.local_origin = (volume.local_from_world * vec4f(ray.origin, 1.0)).xyz;
    ray.local_direction = (volume.local_from_world * vec4f(ray.direction, 0.0)).xyz;
    let inverse = 1.0 / ray.local_direction;
    let a = (-volume.half_extent - ray.local_origin) * inverse;
    let b = (volume.half_extent - ray.local_origin) * inverse;
    let near = max(max(min(a.x, b.x), min(a.y, b.y)), min(a.z, b.z));
    let far_t = min(min(max(a.x, b.x), max(a.y, b.y)), max(a.z, b.z));
    ray.t0 = max(near, t_start);
    ray.t1 = min(far_t, t_end);
    return ray;
}

// The distance along `ray` to the point of the pixel at `ndc` with depth `depth`; beyond every
// volume where the depth is the far plane's (nothing was drawn there).
fn depth_distance(ray: VolumeRay, ndc: vec2f, depth: f32) -> f32 {
    if depth >= 1.0 {
        return 3.4e38;
    }
    let p = view.world_from_clip * vec4f(ndc, depth, 1.0);
    return dot(p.xyz / p.w - ray.origin, ray.direction);
}

// Grid coordinates of a local point, clamped to the grid, as texture coordinates.
fn volume_uv(local: vec3f) -> vec3f {
    let g = clamp((local + volume.half_extent) / volume.spacing, vec3f(0.0), volume.dims - 1.0);
    return (g + 0.5) / volume.dims;
}

fn volume_value(local: vec3f) -> f32 {
    return textureSampleLevel(volume_texture, volume_sampler, volume_uv(local), 0.0).r;
}

// The gradient per local unit, one voxel either side (Grid::gradient).
fn volume_gradient(local: vec3f) -> vec3f {
    let s = volume.spacing;
    let ex = vec3f(s.x, 0.0, 0.0);
    let ey = vec3f(0.0, s.y, 0.0);
    let ez = vec3f(0.0, 0.0, s.z);
    if VOLUME_GRADIENT == VOLUME_GRADIENT_FORWARD {
        let f = volume_value(local);
        return vec3f(volume_value(local + ex) - f, volume_value(local + ey) - f, volume_value(local + ez) - f) / s;
    }
    return vec3f(
        volume_value(local + ex) - volume_value(local - ex),
        volume_value(local + ey) - volume_value(local - ey),
        volume_value(local + ez) - volume_value(local - ez),
    ) / (2.0 * s);
}

// The transfer table at normalized value x, linear between entries (Table::lookup).
fn classify(x: f32) -> vec4f {
    let position = clamp(x, 0.0, 1.0) * f32(VOLUME_TABLE_SIZE - 1u);
    let i = min(u32(floor(position)), VOLUME_TABLE_SIZE - 2u);
    let a = transfer_table[i];
    let b = transfer_table[i + 1u];
    return mix(a, b, position - f32(i));
}

// The world normal of a local gradient; zero where the gradient vanishes.
fn volume_normal(gradient: vec3f) -> vec3f {
    let n = mat3x3f(volume.normal_from_local[0].xyz, volume.normal_from_local[1].xyz, volume.normal_from_local[2].xyz) * gradient;
    if dot(n, n) <= 1e-20 {
        return vec3f(0.0);
    }
    return normalize(n);
}

// One sample's colour: C_amb + Σ V·C_luz·k_dif·(n·L), the classified colour as k_dif.
fn shade_volume_sample(p: vec3f, gradient: vec3f, colour: vec3f, v: vec3f, pixel: vec2f) -> vec3f {
    let surface = Surface(colour, 0.0, 1.0, 0.0, vec3f(0.0), 1.0, vec3f(0.0));
    var radiance = emitted_and_ambient(surface, frame.ambient, frame.terms);
    let normal = volume_normal(gradient);
    if all(normal == vec3f(0.0)) {
        return radiance;
    }
    let n = facing_viewer(normal, v);
    for (var i = 0u; i < min(frame.light_count, MAX_LIGHTS); i++) {
        let light = frame.lights[i];
        let incidence = light_incidence(light, p);
        if incidence.valid && dot(n, incidence.l) > 0.0 {
            var shadowed = vec3f(1.0);
            if VOLUME_SHADOWS && SHADOW_METHOD == SHADOWS_MAP {
                shadowed = visibility(light, p, incidence.l, pixel);
            }
            radiance += shadowed * direct(surface, n, v, incidence, frame.terms);
        }
    }
    return radiance;
}

// The samples of [t0, t1]: count, the first's t, the spacing in t, the length each stands for in
// voxels (march::samples).
struct VolumeSamples {
    count: u32,
    t_first: f32,
    dt: f32,
    length: f32,
}

fn volume_samples(ray: VolumeRay) -> VolumeSamples {
    let voxels = max(ray.t1 - ray.t0, 0.0) * length(ray.local_direction) / volume.voxel_length;
    let count = clamp(u32(ceil(voxels / volume.step)), 1u, VOLUME_MAX_SAMPLES);
    let dt = (ray.t1 - ray.t0) / f32(count);
    return VolumeSamples(count, ray.t0 + 0.5 * dt, dt, voxels / f32(count));
}

// The samples view: black for none, through red and yellow, white at `samples_white`
// (heat_colour in src/trace/volume.rs).
fn heat_colour(samples: u32) -> vec3f {
    let x = f32(samples) / volume.samples_white;
    return clamp(vec3f(3.0 * x, 3.0 * x - 1.0, 3.0 * x - 2.0), vec3f(0.0), vec3f(1.0));
}

// Premultiplied colour and opacity, blended One, OneMinusSrcAlpha over the opaque image.
@fragment
fn fs_volume_composite(in: VolumeVertex) -> @location(0) vec4f {
    return composite_fragment(in);
}

fn composite_fragment(in: VolumeVertex) -> vec4f {
    let ray = volume_ray(in.clip.xy);
    if ray.t0 >= ray.t1 {
        discard;
    }
    let s = volume_samples(ray);
    let v = -ray.direction;
    // Premultiplied colour and opacity so far (shaders/common/optics.wgsl).
    var gathered = vec4f(0.0);
    var taken = 0u;
    for (var i = 0u; i < s.count; i++) {
        if gathered.a >= volume.termination {
            break;
        }
        taken += 1u;
        let t = s.t_first + f32(i) * s.dt;
        let local = ray.local_origin + t * ray.local_direction;
        var classified = classify(volume_value(local));
        if volume.opacity_correction != 0u {
            classified.a = corrected_opacity(classified.a, s.length);
        }
        if classified.a > 0.0 {
            var shaded = classified.rgb;
            if VOLUME_GRADIENT != VOLUME_GRADIENT_OFF {
                shaded = shade_volume_sample(ray.origin + t * ray.direction, volume_gradient(local), shaded, v, in.clip.xy);
            }
            gathered = composite_front_to_back(gathered, vec4f(shaded, classified.a));
        }
    }
    if INSPECT {
        probe.samples = f32(taken);
        probe.world = ray.origin + ray.t0 * ray.direction;
        probe.env_direction = ray.origin + ray.t1 * ray.direction;
    }
    if volume.view == VOLUME_VIEW_SAMPLES {
        return vec4f(heat_colour(taken), 1.0);
    }
    return gathered;
}

struct IsosurfaceOut {
    @location(0) colour: vec4f,
    @builtin(frag_depth) depth: f32,
}

// The first crossing of f = iso, shaded with the volume's material like any surface.
@fragment
fn fs_volume_isosurface(in: VolumeVertex) -> IsosurfaceOut {
    return isosurface_fragment(in);
}

fn isosurface_fragment(in: VolumeVertex) -> IsosurfaceOut {
    let ray = volume_ray(in.clip.xy);
    if ray.t0 >= ray.t1 {
        discard;
    }
    let s = volume_samples(ray);
    var t_before = ray.t0;
    var f_before = volume_value(ray.local_origin + ray.t0 * ray.local_direction) - volume.iso;
    var found = false;
    var t_hit = 0.0;
    for (var i = 0u; i <= s.count; i++) {
        let t = select(s.t_first + f32(i) * s.dt, ray.t1, i == s.count);
        let f = volume_value(ray.local_origin + t * ray.local_direction) - volume.iso;
        if (f >= 0.0) != (f_before >= 0.0) {
            var a = t_before;
            var b = t;
            for (var k = 0u; k < VOLUME_BISECTION_STEPS; k++) {
                let middle = 0.5 * (a + b);
                let f_middle = volume_value(ray.local_origin + middle * ray.local_direction) - volume.iso;
                if (f_middle >= 0.0) == (f_before >= 0.0) {
                    a = middle;
                } else {
                    b = middle;
                }
            }
            t_hit = 0.5 * (a + b);
            found = true;
            break;
        }
        t_before = t;
        f_before = f;
    }
    if !found {
        discard;
    }
    let p = ray.origin + t_hit * ray.direction;
    let local = ray.local_origin + t_hit * ray.local_direction;
    // Outward is where values fall (src/trace/volume.rs).
    var normal = volume_normal(-volume_gradient(local));
    if all(normal == vec3f(0.0)) {
        normal = -ray.direction;
    }
    let v = -ray.direction;
    let n = facing_viewer(normal, v);
    let surface = Surface(
        material.color, material.ka, material.kd, material.ks,
        material.specular_color, material.shininess, material.emission,
    );
    var radiance = emitted_and_ambient(surface, frame.ambient, frame.terms);
    if INSPECT {
        probe.world = p;
        probe.normal = n;
        probe.geometric = normal;
        probe.colour = material.color;
        probe.lod = -1.0;
        probe.emission = select(vec3f(0.0), surface.emission, (frame.terms & TERM_EMISSION) != 0u);
        probe.global_ambient = select(vec3f(0.0), frame.ambient * surface.kd * surface.color, (frame.terms & TERM_AMBIENT) != 0u);
    }
    for (var i = 0u; i < min(frame.light_count, MAX_LIGHTS); i++) {
        let light = frame.lights[i];
        let incidence = light_incidence(light, p);
        if incidence.valid {
            let facing = select(-n, n, dot(n, incidence.l) >= 0.0);
            if INSPECT {
                probe_light = i;
                probe.lights[i].layer = -1;
                probe.lights[i].lit = 1.0;
            }
            var shadowed = vec3f(1.0);
            if SHADOW_METHOD == SHADOWS_MAP {
                shadowed = visibility(light, p, facing, in.clip.xy);
            }
            if INSPECT {
                let parts = direct_terms(surface, n, v, incidence, frame.terms);
                probe.lights[i].ambient = parts[0];
                probe.lights[i].diffuse = parts[1];
                probe.lights[i].specular = parts[2];
                probe.lights[i].visibility = shadowed;
            }
            radiance += shadowed * direct(surface, n, v, incidence, frame.terms);
        }
    }
    let clip = view.clip_from_world * vec4f(p, 1.0);
    return IsosurfaceOut(vec4f(radiance, 1.0), clip.z / clip.w);
}

// The inspecting twins (shaders/common/inspect.wgsl).
@fragment
fn fs_volume_composite_inspect(in: VolumeVertex) -> @location(0) vec4f {
    probe.object = 0xffffffffu;
    let out = composite_fragment(in);
    probe.alpha = out.a;
    inspect_record(INSPECT_VOLUME, in.clip, out.rgb);
    return out;
}

@fragment
fn fs_volume_isosurface_inspect(in: VolumeVertex) -> IsosurfaceOut {
    probe.object = 0xffffffffu;
    let out = isosurface_fragment(in);
    inspect_record(INSPECT_ISOSURFACE, vec4f(in.clip.xy, out.depth, 1.0), out.colour.rgb);
    return out;
}
