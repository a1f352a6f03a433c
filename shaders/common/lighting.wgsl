// The local illumination model (docs/course/02-illumination.md): the WGSL twin of
// src/scene/shading.rs and src/scene/light.rs. Keep the two in step; tests/illumination.rs runs
// both on the same inputs.
//
//   L = ME + AG + Σ_i V_i · S_i ⊗ ( ka·C + [n·l > 0]·( kd·C·(n·l) + ks·Sc·max(0, r·v)^e ) )
//   r = 2(n·l)n − l,   AG = A ⊗ kd·C

struct Surface {
    color: vec3f,
    ka: f32,
    kd: f32,
    ks: f32,
    specular_color: vec3f,
    shininess: f32,
    emission: vec3f,
}

struct Incidence {
    // Unit vector towards the light.
    l: vec3f,
    // Distance to the light; a very large number for directional lights.
    distance: f32,
    // S_i: colour · intensity · attenuation · spot falloff.
    radiance: vec3f,
    // false when the point is at the light's own position.
    valid: bool,
}

fn attenuation_factor(kind: u32, distance: f32) -> f32 {
    if kind == ATTENUATION_INVERSE_SQUARE {
        return 1.0 / max(distance * distance, 1.17549435e-38);
    }
    return 1.0;
}

fn light_incidence(light: Light, p: vec3f) -> Incidence {
    if light.kind == LIGHT_DIRECTIONAL {
        return Incidence(-light.direction, 3.4e38, light.radiance, true);
    }
    let to_light = light.position - p;
    let distance = length(to_light);
    if distance <= 0.0 {
        return Incidence(vec3f(0.0), 0.0, vec3f(0.0), false);
    }
    let l = to_light / distance;
    var radiance = light.radiance * attenuation_factor(light.attenuation, distance);
    if light.kind == LIGHT_SPOT {
        radiance *= cone_falloff(light.cos_outer, light.cos_inner, dot(-l, light.direction));
    }
    return Incidence(l, distance, radiance, true);
}

// smoothstep with equal edges read as a hard step (WGSL leaves that case undefined).
fn cone_falloff(edge0: f32, edge1: f32, x: f32) -> f32 {
    if edge1 <= edge0 {
        return select(0.0, 1.0, x >= edge0);
    }
    return smoothstep(edge0, edge1, x);
}

fn facing_viewer(n: vec3f, v: vec3f) -> vec3f {
    return select(n, -n, dot(n, v) < 0.0);
}

// L_dir(p, v, l) times S_i: one visible light. n faces the viewer.
fn direct(s: Surface, n: vec3f, v: vec3f, light: Incidence, terms: u32) -> vec3f {
    var rad = vec3f(0.0);
    if (terms & TERM_AMBIENT) != 0u {
        rad += s.ka * s.color;
    }
    let n_dot_l = dot(n, light.l);
    if n_dot_l > 0.0 {
        if (terms & TERM_DIFFUSE) != 0u {
            rad += s.kd * s.color * n_dot_l;
        }
        if (terms & TERM_SPECULAR) != 0u && s.ks > 0.0 {
            let r = 2.0 * n_dot_l * n - light.l;
            rad += s.ks * s.specular_color * pow(max(dot(r, v), 0.0), s.shininess);
        }
    }
    return light.radiance * rad;
}

// direct()'s three parts, each times S_i: ka·C, kd·C·(n·l), ks·Sc·max(0, r·v)^e (for inspecting
// a pixel; src/scene/shading.rs's direct_terms).
fn direct_terms(s: Surface, n: vec3f, v: vec3f, light: Incidence, terms: u32) -> array<vec3f, 3> {
    var parts = array<vec3f, 3>(vec3f(0.0), vec3f(0.0), vec3f(0.0));
    if (terms & TERM_AMBIENT) != 0u {
        parts[0] = light.radiance * s.ka * s.color;
    }
    let n_dot_l = dot(n, light.l);
    if n_dot_l > 0.0 {
        if (terms & TERM_DIFFUSE) != 0u {
            parts[1] = light.radiance * s.kd * s.color * n_dot_l;
        }
        if (terms & TERM_SPECULAR) != 0u && s.ks > 0.0 {
            let r = 2.0 * n_dot_l * n - light.l;
            parts[2] = light.radiance * s.ks * s.specular_color * pow(max(dot(r, v), 0.0), s.shininess);
        }
    }
    return parts;
}

// ME + AG(p).
fn emitted_and_ambient(s: Surface, ambient: vec3f, terms: u32) -> vec3f {
    var rad = vec3f(0.0);
    if (terms & TERM_EMISSION) != 0u {
        rad += s.emission;
    }
    if (terms & TERM_AMBIENT) != 0u {
        rad += ambient * s.kd * s.color;
    }
    return rad;
}
