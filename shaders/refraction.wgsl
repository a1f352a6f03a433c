// Refraction (docs/course/06-transparency.md#refraction; src/raster/refraction.rs): glass whose
// ior ≠ 1, drawn after the opaque surfaces and before the other transparent ones, with the
// surface code of shaders/common/surface.wgsl.
//
// A z-buffer sees one surface per pixel, so the ray's path through the glass is found in screen
// space. For a fragment of the glass's front face at p1:
//   1. t1 = the view ray refracted into the glass by Snell's law (shaders/common/optics.wgsl);
//   2. the exit point p2: where p1 + s·t1 first passes behind the glass's back faces, drawn
//      beforehand into back_depth and back_normal (a march along the ray's image, refined by
//      bisection): right wherever the path leaves through a back face, so exact for a sphere up
//      to the depth image's pixels;
//   3. t2 = t1 refracted out of the glass at p2 (on total internal reflection, t1 reflected);
//   4. L(t2), the radiance arriving along it: looked up in the object's environment cube
//      (REFRACTION_ENVIRONMENT), or found in the opaque image where p2 + s·t2 first passes
//      behind the opaque depth (REFRACTION_SCREEN; the cube where it leaves the screen).
// The fragment returns, as the tracer's two interfaces do (F1, F2 = 0 without Fresnel),
//   Im + kps·MPS·L(r) + F1·kt·Mt·L(r) + (1 − F1)·kt·Mt·(Im2 + (1 − F2)·kt·Mt·L(t2))
// with Im2 the glass's model at the exit (lit through its own surface); the rays reflected
// inside the glass are left out.

// REFRACTION_*: where L(t2) comes from.
override REFRACTION: u32 = 1u;

// Steps of the march along a ray's image, and the bisection after it.
const MARCH_STEPS: u32 = 96u;
const BISECTION_STEPS: u32 = 6u;

// Group 3: a copy of the view's depth before the glass is drawn; the glass's nearest back faces;
// a copy of the opaque image. Depth images read with textureLoad are declared as float
// textures, depth in x (src/gpu/layout.rs, depth_texels).
@group(3) @binding(0) var opaque_depth: texture_2d<f32>;
@group(3) @binding(1) var back_depth: texture_2d<f32>;
@group(3) @binding(2) var back_normal: texture_2d<f32>;
@group(3) @binding(3) var opaque_image: texture_2d<f32>;

// The back-face pass: the glass's outward normal where its nearest back face is.
@fragment
fn fs_refraction_back(in: VertexOut) -> @location(0) vec4f {
    if masked_out(in.uv) {
        discard;
    }
    return vec4f(normalize(in.normal), 1.0);
}

// Where a ray p + s·d first passes behind a depth image of this view.
struct ScreenHit {
    found: bool,
    pixel: vec2i,
    point: vec3f,
}

// A point's position in the view's image: pixel coordinates of an image of `size`, the depth
// the z-buffer stores, and clip w (1/w interpolates linearly along a projected segment).
struct Projected {
    pixel: vec2f,
    depth: f32,
    inverse_w: f32,
}

fn project(p: vec3f, size: vec2f) -> Projected {
    let c = view.clip_from_world * vec4f(p, 1.0);
    let ndc = c.xyz / c.w;
    return Projected(vec2f(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y) * size, ndc.z, 1.0 / c.w);
}

// How far the ray p + s·d (p inside the scene's box) runs before it leaves the box.
fn box_exit(p: vec3f, d: vec3f) -> f32 {
    let safe = select(d, vec3f(1e-12), abs(d) < vec3f(1e-12));
    let far = max((environment.proxy_min - p) / safe, (environment.proxy_max - p) / safe);
    return max(min(min(far.x, far.y), far.z), 0.0);
}

// Marches the segment p → p + distance·d in the image of `depth`, pixel by pixel along its
// projection (up to MARCH_STEPS steps), until the segment's depth passes the image's; then
// bisects the last step. The depth along a projected segment is linear in the image, so each
// step compares exactly what the z-buffer would.
fn screen_march(depth: texture_2d<f32>, p: vec3f, d: vec3f, distance: f32) -> ScreenHit {
    let size = vec2f(textureDimensions(depth));
    // A little past `distance`, so a surface right at its end (the scene's box) is crossed;
    // and in front of the near plane (clip z ≥ 0, linear along the segment).
    var reach = max(1.05 * distance, 1e-6);
    let z0 = (view.clip_from_world * vec4f(p, 1.0)).z;
    let z1 = (view.clip_from_world * vec4f(p + reach * d, 1.0)).z;
    if z1 < 0.0 && z0 > 0.0 {
        reach *= 0.999 * z0 / (z0 - z1);
    }
    let a = project(p, size);
    let b = project(p + reach * d, size);
    // The part of the segment inside the image (Liang–Barsky on its projection).
    let delta = b.pixel - a.pixel;
    var end = 1.0;
    for (var axis = 0; axis < 2; axis++) {
        if delta[axis] > 0.0 {
            end = min(end, (size[axis] - 0.5 - a.pixel[axis]) / delta[axis]);
        } else if delta[axis] < 0.0 {
            end = min(end, (0.5 - a.pixel[axis]) / delta[axis]);
        }
    }
    var miss: ScreenHit;
    miss.found = false;
    if end <= 0.0 {
        return miss;
    }
    let steps = u32(clamp(ceil(length(delta) * end), 1.0, f32(MARCH_STEPS)));
    var before = 0.0;
    var after = -1.0;
    for (var i = 1u; i <= steps; i++) {
        let t = end * f32(i) / f32(steps);
        let pixel = vec2i(mix(a.pixel, b.pixel, t));
        if mix(a.depth, b.depth, t) > textureLoad(depth, pixel, 0).x {
            after = t;
            break;
        }
        before = t;
    }
    if after < 0.0 {
        return miss;
    }
    for (var i = 0u; i < BISECTION_STEPS; i++) {
        let t = 0.5 * (before + after);
        if mix(a.depth, b.depth, t) > textureLoad(depth, vec2i(mix(a.pixel, b.pixel, t)), 0).x {
            after = t;
        } else {
            before = t;
        }
    }
    // Back from the image to the world: p·(1/w) and 1/w interpolate linearly.
    let inverse_w = mix(a.inverse_w, b.inverse_w, after);
    let s = reach * (after * b.inverse_w) / inverse_w;
    return ScreenHit(true, vec2i(mix(a.pixel, b.pixel, after)), p + s * d);
}

// L(d) at p from the environment, for the refracted rays: the object's dynamic cube (along the
// parallax setting's direction) or the world's, at level 0 (these lookups follow the march, out
// of uniform control flow, where screen derivatives are undefined).
fn refracted_environment(p: vec3f, d: vec3f, layer: i32) -> vec3f {
    if ENVIRONMENT == ENV_MAP_DYNAMIC && layer >= 0 {
        let lookup = parallax_direction(environment, p, d, environment.cube_centres[layer].xyz);
        return cube_array_sample_level(env_cubes, env_sampler, lookup, layer, 0.0).rgb;
    }
    return textureSampleLevel(env_cube, env_sampler, d, 0.0).rgb;
}

// The glass's illumination model at the exit point p (untextured), seen from inside along v
// with n the inner normal: each light reaches it through the glass's own surface (kt·Mt, as the
// tracer's shadow ray from inside a closed object crosses it once); no shadow maps.
fn exit_radiance(p: vec3f, n: vec3f, v: vec3f) -> vec3f {
    let surface = Surface(
        material.color, material.ka, material.kd, material.ks,
        material.specular_color, material.shininess, material.emission,
    );
    var radiance = emitted_and_ambient(surface, frame.ambient, frame.terms);
    for (var i = 0u; i < min(frame.light_count, MAX_LIGHTS); i++) {
        let incidence = light_incidence(frame.lights[i], p);
        if incidence.valid {
            radiance += material.transmission * direct(surface, n, v, incidence, frame.terms);
        }
    }
    return radiance;
}

@fragment
fn fs_refraction(in: VertexOut) -> @location(0) vec4f {
    return refraction_fragment(in);
}

fn refraction_fragment(in: VertexOut) -> vec4f {
    if masked_out(in.uv) {
        discard;
    }
    let shaded = shade_surface(in);
    let n = shaded.n;
    let v = shaded.v;
    let fresnel_on = (frame.terms & TERM_FRESNEL) != 0u;
    let geometric = normalize(in.normal);
    let kt = material.transmission;
    // 1. Into the glass.
    let f_in = select(0.0, fresnel(dot(n, v), relative_index(v, geometric, material.ior)), fresnel_on);
    let entering = refract_view(v, geometric, n, material.ior);
    let t1 = select(-v, entering.direction, entering.valid);
    // 2. The exit point, on the back faces.
    let exit = screen_march(back_depth, in.world, t1, box_exit(in.world, t1));
    var p2 = in.world;
    var t2 = t1;
    var f_out = 0.0;
    var at_exit = vec3f(0.0);
    if exit.found {
        p2 = exit.point;
        // 3. Out of the glass: the view vector there is −t1, on the inside of the outward n2.
        let n2 = normalize(textureLoad(back_normal, exit.pixel, 0).xyz);
        at_exit = exit_radiance(p2, -n2, -t1);
        let leaving = refract_view(-t1, n2, -n2, material.ior);
        if leaving.valid {
            t2 = leaving.direction;
            f_out = select(0.0, fresnel(dot(n2, t1), material.ior), fresnel_on);
        } else {
            t2 = t1 - 2.0 * dot(t1, n2) * n2;
        }
    }
    // 4. What arrives along t2.
    var behind = vec3f(0.0);
    var found_on_screen = false;
    if REFRACTION == REFRACTION_SCREEN {
        let hit = screen_march(opaque_depth, p2, t2, box_exit(p2, t2));
        if hit.found {
            behind = textureLoad(opaque_image, hit.pixel, 0).rgb;
            found_on_screen = true;
        }
    }
    if !found_on_screen {
        behind = refracted_environment(p2, t2, in.env_layer);
    }
    let reflected = f_in * kt * shaded.environment;
    let through = (1.0 - f_in) * kt * (at_exit + (1.0 - f_out) * kt * behind);
    if INSPECT {
        probe.fresnel = f_in;
        probe.environment += reflected;
        probe.refraction_exit = p2;
        probe.refraction_found = select(0.0, 1.0, exit.found);
        probe.refracted_direction = t2;
        probe.fresnel_exit = f_out;
        probe.refracted = through;
        probe.refraction_source = select(1.0, 2.0, found_on_screen);
    }
    return vec4f(shaded.radiance + reflected + through, 1.0);
}

// The inspecting twins (shaders/common/inspect.wgsl).
@fragment
fn fs_refraction_inspect(in: VertexOut) -> @location(0) vec4f {
    probe.object = in.object;
    let out = refraction_fragment(in);
    inspect_record(INSPECT_REFRACTION, in.clip, out.rgb);
    return out;
}

