// Bump mapping (docs/course/04-bump-mapping.md) and mip-level helpers (docs/course/03-mipmaps.md): the
// WGSL twin of src/texture/{bump,height,tangents,lod,mipmap}.rs. Keep the two in step;
// tests/bump.rs runs both on the same inputs. Pure functions only: the pass supplies texture
// samples and screen derivatives (dpdx/dpdy are fragment-only, so they are taken by the caller).

const BUMP_TAU: f32 = 6.28318530717958647692;

// The level-colour view: the palette blended between levels floor(lod) and floor(lod) + 1, as
// trilinear filtering blends texels. Clamp lod to the texture's last level first
// (f32(texture_level_count(t) - 1u)) to show the level actually read.
fn mip_level_colour(lod: f32) -> vec3f {
    let l = clamp(lod, 0.0, f32(MIP_PALETTE_LAST));
    let lo = floor(l);
    let hi = min(lo + 1.0, f32(MIP_PALETTE_LAST));
    // A function-local copy: a const array indexed at run time is not portable.
    var palette = MIP_LEVEL_PALETTE;
    return mix(palette[u32(lo)], palette[u32(hi)], l - lo);
}

// The GPU's level of detail from the screen derivatives of the texture coordinates
// (duv_dx = dpdx(uv), duv_dy = dpdy(uv)) for a texture of `size` texels:
// log2 max(|duv_dx ⊙ size|, |duv_dy ⊙ size|) + bias.
fn mip_lod(duv_dx: vec2f, duv_dy: vec2f, size: vec2f, bias: f32) -> f32 {
    return log2(max(length(duv_dx * size), length(duv_dy * size))) + bias;
}

// Texel (x, y) of level `level`, its coordinates wrapped into the level (the repeat address mode).
// The level's size is level 0's halved `level` times, as WGSL defines it: lavapipe answers
// textureDimensions(t, level) with one fragment's level for a whole group of fragments whose
// levels differ, and a wrap by the wrong size read black (out of range) or the wrong square.
fn texel_repeat(t: texture_2d<f32>, texel: vec2i, level: i32) -> vec4f {
    let size = max(vec2i(textureDimensions(t)) >> vec2u(u32(level)), vec2i(1));
    return textureLoad(t, ((texel % size) + size) % size, level);
}

// Bilinear filtering on one level: the four texels whose centres surround uv, weighed by how
// near uv lies to each. Texel centres sit at half-integers: uv·size − ½ counts from the first.
fn bilinear_level(t: texture_2d<f32>, uv: vec2f, level: i32) -> vec4f {
    let p = uv * vec2f(textureDimensions(t, level)) - 0.5;
    let base = floor(p);
    let f = p - base;
    let i = vec2i(base);
    let below = mix(texel_repeat(t, i, level), texel_repeat(t, i + vec2i(1, 0), level), f.x);
    let above = mix(texel_repeat(t, i + vec2i(0, 1), level), texel_repeat(t, i + vec2i(1, 1), level), f.x);
    return mix(below, above, f.y);
}

// Trilinear filtering by hand: lod clamped to the chain, bilinear on the levels ⌊lod⌋ and
// ⌊lod⌋ + 1, blended by lod's fraction. What the sampler does when a lab routes the colour
// texture through this function (TRILINEAR_BY_HAND in surface.wgsl).
fn trilinear_sample(t: texture_2d<f32>, uv: vec2f, lod: f32) -> vec4f {
    let last = f32(texture_level_count(t) - 1u);
    let l = clamp(lod, 0.0, last);
    let lo = floor(l);
    let hi = min(lo + 1.0, last);
    return mix(bilinear_level(t, uv, i32(lo)), bilinear_level(t, uv, i32(hi)), l - lo);
}

// (d_u, d_v) by central differences from f(u+Δ, v), f(u−Δ, v), f(u, v+Δ), f(u, v−Δ):
// k·(f₊ − f₋)/2Δ per axis.
fn bump_central_differences(u_plus: f32, u_minus: f32, v_plus: f32, v_minus: f32, delta: vec2f, k: f32) -> vec2f {
    return k * vec2f(u_plus - u_minus, v_plus - v_minus) / (2.0 * delta);
}

// n' = normalize((t_u + d_u·n) × (t_v + d_v·n)), turned to the side of n, so that mirrored
// texture coordinates (t_u × t_v along −n) move the bumps but never invert them. n is unit;
// t_u, t_v are ∂p/∂u, ∂p/∂v of any length. Degenerate tangents return n.
fn perturbed_normal(n: vec3f, tu: vec3f, tv: vec3f, du: f32, dv: f32) -> vec3f {
    // The tangents are first laid in the plane of n: a smooth-shaded mesh's interpolated n is
    // not perpendicular to its flat facets' tangents, and t'u × t'v would bring the facets back.
    let su = tu - dot(tu, n) * n;
    let sv = tv - dot(tv, n) * n;
    let m = cross(su + du * n, sv + dv * n);
    let len = length(m);
    if !(len > 0.0) || len > 3.0e38 {
        return n;
    }
    let perturbed = m / len;
    return select(perturbed, -perturbed, dot(perturbed, n) < 0.0);
}

// The sine height field a·sin(2π·f_u·u)·sin(2π·f_v·v) and its analytic gradient.
fn sine_height(uv: vec2f, frequency: vec2f, amplitude: f32) -> f32 {
    let a = BUMP_TAU * frequency * uv;
    return amplitude * sin(a.x) * sin(a.y);
}

fn sine_height_gradient(uv: vec2f, frequency: vec2f, amplitude: f32) -> vec2f {
    let w = BUMP_TAU * frequency;
    let a = w * uv;
    return amplitude * vec2f(w.x * cos(a.x) * sin(a.y), w.y * sin(a.x) * cos(a.y));
}

// Parallax mapping's two pure steps (the march itself is parallax_uv in surface.wgsl; Rust twins
// in src/texture/parallax.rs). How fast the texture coordinates change along the view ray d over
// the surface of normal n and tangents t_u = ∂p/∂u, t_v = ∂p/∂v: the part of d in the surface's
// plane, d − (d·n)·n, written as du/ds·t_u + dv/ds·t_v by the 2×2 normal equations (the tangents
// need not be orthogonal or unit). Zero where they are degenerate.
fn parallax_rate(d: vec3f, n: vec3f, tu: vec3f, tv: vec3f) -> vec2f {
    let a = dot(tu, tu);
    let b = dot(tu, tv);
    let c = dot(tv, tv);
    let det = a * c - b * b;
    if !(abs(det) > 1e-12) {
        return vec2f(0.0);
    }
    let along = d - dot(d, n) * n;
    let x = dot(along, tu);
    let y = dot(along, tv);
    return vec2f(c * x - b * y, a * y - b * x) / det;
}

// The secant step between two points (s, gap) of the march, the gap > 0 above the relief and ≤ 0
// below it: where the line through them crosses zero.
fn secant_crossing(above: vec2f, below: vec2f) -> f32 {
    return above.x + (below.x - above.x) * (above.y / (above.y - below.y));
}

struct SurfaceTangents {
    tu: vec3f,
    tv: vec3f,
    valid: bool,
}

// (∂p/∂u, ∂p/∂v) from two position differences and the matching texture-coordinate
// differences: triangle edges, or screen derivatives in a fragment shader
// (tangents_from_derivatives(dpdx(p), dpdy(p), dpdx(uv), dpdy(uv))), which is the per-triangle
// constant for flat triangles. Invalid where the texture coordinates are degenerate.
fn tangents_from_derivatives(dp1: vec3f, dp2: vec3f, duv1: vec2f, duv2: vec2f) -> SurfaceTangents {
    let det = duv1.x * duv2.y - duv2.x * duv1.y;
    if abs(det) <= 1.1920929e-7 * (abs(duv1.x * duv2.y) + abs(duv2.x * duv1.y)) || det == 0.0 {
        return SurfaceTangents(vec3f(0.0), vec3f(0.0), false);
    }
    let r = 1.0 / det;
    return SurfaceTangents((dp1 * duv2.y - dp2 * duv1.y) * r, (dp2 * duv1.x - dp1 * duv2.x) * r, true);
}

// glTF normal map: the texel rgb (linear, data) is m = normalize((2·rgb − 1) ⊙ (scale, scale, 1))
// in the frame (t, b = sign(w)·(n × t), n), t made perpendicular to n. Degenerate input returns n.
fn normal_map_normal(n: vec3f, tangent: vec4f, sample_rgb: vec3f, scale: f32) -> vec3f {
    let t_raw = tangent.xyz - dot(tangent.xyz, n) * n;
    let m_raw = (2.0 * sample_rgb - 1.0) * vec3f(scale, scale, 1.0);
    if !(length(t_raw) > 0.0) || !(length(m_raw) > 0.0) {
        return n;
    }
    let t = normalize(t_raw);
    let b = select(1.0, -1.0, tangent.w < 0.0) * cross(n, t);
    let m = normalize(m_raw);
    return normalize(m.x * t + m.y * b + m.z * n);
}

// Seeded, tileable value noise with quintic interpolation (src/texture/height.rs's ValueNoise):
// the field and its gradient, as (value, ∂/∂u, ∂/∂v).
fn noise_hash(x_in: u32) -> u32 {
    var x = x_in;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    return x ^ (x >> 16u);
}

fn noise_lattice(seed: u32, i: u32, j: u32, octave: u32) -> f32 {
    let h = noise_hash(i + noise_hash(j + noise_hash(octave + noise_hash(seed))));
    return f32(h >> 8u) / 8388608.0 - 1.0;
}

fn quintic(t: f32) -> f32 {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

fn quintic_derivative(t: f32) -> f32 {
    return 30.0 * t * t * (t * (t - 2.0) + 1.0);
}

fn value_noise(uv: vec2f, seed: u32, cells: u32, octaves: u32, amplitude_in: f32) -> vec3f {
    var result = vec3f(0.0);
    var amplitude = amplitude_in;
    for (var octave = 0u; octave < max(octaves, 1u); octave++) {
        let n = max(cells, 1u) << min(octave, 20u);
        let p = uv * f32(n);
        let cell = floor(p);
        let f = p - cell;
        let ni = i32(n);
        let i0 = u32(((i32(cell.x) % ni) + ni) % ni);
        let j0 = u32(((i32(cell.y) % ni) + ni) % ni);
        let i1 = (i0 + 1u) % n;
        let j1 = (j0 + 1u) % n;
        let a = noise_lattice(seed, i0, j0, octave);
        let b = noise_lattice(seed, i1, j0, octave);
        let c = noise_lattice(seed, i0, j1, octave);
        let d = noise_lattice(seed, i1, j1, octave);
        let s = vec2f(quintic(f.x), quintic(f.y));
        let cross = a - b - c + d;
        result.x += amplitude * (a + (b - a) * s.x + (c - a) * s.y + cross * s.x * s.y);
        let scale = amplitude * f32(n);
        result.y += scale * ((b - a) + cross * s.y) * quintic_derivative(f.x);
        result.z += scale * ((c - a) + cross * s.x) * quintic_derivative(f.y);
        amplitude *= 0.5;
    }
    return result;
}
