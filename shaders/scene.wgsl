// The scene pass (src/raster/scene_pass.rs): every opaque surface of the scene drawn from one
// view with the surface code of shaders/common/surface.wgsl: the depth prepass (fs_mask for
// cut-out materials), the shaded surfaces (fs_scene), planar mirrors with their reflection
// (fs_mirror), and the world where nothing was drawn (fs_background); each with its inspecting
// twin (`*_inspect`, shaders/common/inspect.wgsl).

// Group 3 (mirror variants only): the reflection, drawn by the camera mirrored about this mirror's
// plane at the same size as this view, so the mirror's own pixel is where its reflection is
// (the projective lookup of docs/course/07-planar-mirrors.md reduces to the fragment's pixel).
@group(3) @binding(0) var mirror_image: texture_2d<f32>;

fn scene_fragment(in: VertexOut) -> vec4f {
    if masked_out(in.uv) {
        discard;
    }
    // The hybrid's traced transmission (src/raster/traced/mod.rs): the frame draws transparent
    // surfaces here, each its own α·Im and, where traced on it, what it lets through.
    if HYBRID && (frame.traced & TRACED_TRANSMISSION) != 0u && material.transparent != 0u && !FLAT_COLOUR && BUMP_VIEW == 0u {
        var alpha = 1.0;
        if ALPHA_MODE == ALPHA_BLEND {
            alpha = coverage(in.uv);
        }
        var radiance = alpha * shade(in);
        if traced_object(in.clip.xy) == in.object + 1u {
            radiance += traced_term(in.clip.xy, TRACED_TRANSMISSION_LAYER);
        }
        return vec4f(radiance, 1.0);
    }
    return vec4f(shade(in), 1.0);
}

@fragment
fn fs_scene(in: VertexOut) -> @location(0) vec4f {
    return scene_fragment(in);
}

// A planar mirror drawn with its reflection (src/raster/mirror): its model plus the mirror term
// kps·MPS·L(r), as the tracer adds its reflected ray, L(r) read from the mirrored camera's image.
fn mirror_fragment(in: VertexOut) -> vec4f {
    if masked_out(in.uv) {
        discard;
    }
    var radiance = shade(in);
    if !FLAT_COLOUR && BUMP_VIEW == 0u {
        let reflected = material.reflectance * textureLoad(mirror_image, vec2i(in.clip.xy), 0).rgb;
        radiance += reflected;
        if INSPECT {
            probe.mirror = reflected;
        }
    }
    return vec4f(radiance, 1.0);
}

@fragment
fn fs_mirror(in: VertexOut) -> @location(0) vec4f {
    return mirror_fragment(in);
}

// The depth prepass of a cut-out material: depth only where the surface is.
@fragment
fn fs_mask(in: VertexOut) {
    if masked_out(in.uv) {
        discard;
    }
}

// The world where nothing is drawn (docs/course/08-environment-maps.md): one triangle over the screen at the far
// plane, drawn after the opaque surfaces with the depth test LessEqual, so only the pixels no
// surface covered run it. Each pixel looks along the camera ray through its centre, the same ray
// the tracer sends, and returns the environment's radiance there (the tracer's rays that hit
// nothing return the same function: src/scene/environment.rs).
struct BackgroundOut {
    @builtin(position) clip: vec4f,
    // The pixel's normalized device coordinates (interpolated exactly: they are linear).
    @location(0) ndc: vec2f,
}

@vertex
fn vs_background(@builtin(vertex_index) index: u32) -> BackgroundOut {
    let p = fullscreen_position(index).xy;
    return BackgroundOut(vec4f(p, 1.0, 1.0), p);
}

@fragment
fn fs_background(in: BackgroundOut) -> @location(0) vec4f {
    return background_fragment(in);
}

fn background_fragment(in: BackgroundOut) -> vec4f {
    // Any point on the pixel's ray, unprojected; q.xyz − eye·q.w points away from the eye along
    // the ray whatever the sign of q.w (oblique projections of mirrored views included).
    let q = view.world_from_clip * vec4f(in.ndc, 0.5, 1.0);
    var d = q.xyz - view.eye * q.w;
    if view.orthographic != 0u {
        d = -view.view_axis;
    }
    return vec4f(world_radiance(d), 1.0);
}

// The world's radiance along d: the procedural sky evaluated, an image source sampled (the
// lat–long image with explicit gradients, seamless across its wrap), or the plain background.
fn world_radiance(d: vec3f) -> vec3f {
    // Every derivative first, in uniform control flow.
    let uv = latlong_uv(d);
    let duv_dx = latlong_gradient(dpdx(uv));
    let duv_dy = latlong_gradient(dpdy(uv));
    let dd_dx = dpdx(d);
    let dd_dy = dpdy(d);
    let source = environment.source;
    if source == ENV_SKY {
        return environment.intensity * sky_radiance(environment, d);
    }
    if source == ENV_LATLONG {
        return textureSampleGrad(env_latlong, env_sampler, uv, duv_dx, duv_dy).rgb;
    }
    if source == ENV_CUBE || source == ENV_SPHERE {
        return textureSampleGrad(env_cube, env_sampler, d, dd_dx, dd_dy).rgb;
    }
    return environment.background;
}

// The inspecting twins (shaders/common/inspect.wgsl).
@fragment
fn fs_scene_inspect(in: VertexOut) -> @location(0) vec4f {
    probe.object = in.object;
    let out = scene_fragment(in);
    inspect_record(INSPECT_OPAQUE, in.clip, out.rgb);
    return out;
}

@fragment
fn fs_mirror_inspect(in: VertexOut) -> @location(0) vec4f {
    probe.object = in.object;
    let out = mirror_fragment(in);
    inspect_record(INSPECT_MIRROR, in.clip, out.rgb);
    return out;
}

@fragment
fn fs_background_inspect(in: BackgroundOut) -> @location(0) vec4f {
    let out = background_fragment(in);
    probe.object = 0xffffffffu;
    if all(vec2u(in.clip.xy) == inspection.pixel) {
        let index = atomicAdd(&inspection.count, 1u);
        if index < MAX_INSPECTED {
            probe.kind = INSPECT_BACKGROUND;
            probe.depth = 1.0;
            probe.material = 0xffffffffu;
            probe.radiance = out.rgb;
            inspection.fragments[index] = probe;
        }
    }
    return out;
}

