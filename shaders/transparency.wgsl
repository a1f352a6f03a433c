// Transparent surfaces (docs/course/06-transparency.md), with the surface code of
// shaders/common/surface.wgsl. src/raster/transparency.rs draws them after the opaque surfaces,
// farthest first, with the blend I = Im + kt·Mt·I: the fragment returns Im (times the coverage α for alpha
// blending), and the blend state multiplies what the target holds by kt·Mt.

@fragment
fn fs_transparent(in: VertexOut) -> @location(0) vec4f {
    return transparent_fragment(in);
}

fn transparent_fragment(in: VertexOut) -> vec4f {
    if masked_out(in.uv) {
        discard;
    }
    // Alpha blending is the notes' formula with Im scaled by α; for any other material α = 1.
    var alpha = 1.0;
    if ALPHA_MODE == ALPHA_BLEND {
        alpha = coverage(in.uv);
    }
    return vec4f(alpha * shade(in), alpha);
}

// The transparency lab's route (assets/labs/transparency): the blend made by `transparent_blend`
// (shaders/common/types.wgsl) instead of the GPU's blend state. False in Mirador; the lab's
// routes set it, and src/raster/transparency.rs then draws every transparent triangle twice, both
// draws before the next triangle. A fragment cannot read the pixel behind it, but any blend of
// the notes' form is affine in it, channel by channel, I' = a + b·I, so two draws make it
// exactly: the first multiplies what the pixel holds by b = blend(Im, t, 1) − blend(Im, t, 0)
// (the blend computes dst·src), the second adds a = blend(Im, t, 0) (src + dst). Triangle by
// triangle, because a draw that covered a pixel twice would multiply twice, then add twice.
const BLEND_BY_HAND = false;

// Im and kt·Mt at a fragment, as the GPU's blend state takes them: kt·Mt is the material's
// (alpha blending's α·kt·Mt + (1 − α)), or 1 − α alone where α varies per pixel.
struct BlendInputs {
    im: vec3f,
    transmittance: vec3f,
}

fn blend_inputs(in: VertexOut) -> BlendInputs {
    let out = transparent_fragment(in);
    if ALPHA_MODE == ALPHA_BLEND && COLOR_TEXTURE {
        return BlendInputs(out.rgb, vec3f(1.0 - out.a));
    }
    return BlendInputs(out.rgb, material_transmittance(material, out.a));
}

@fragment
fn fs_blend_factor(in: VertexOut) -> @location(0) vec4f {
    let b = blend_inputs(in);
    return vec4f(transparent_blend(b.im, b.transmittance, vec3f(1.0)) - transparent_blend(b.im, b.transmittance, vec3f(0.0)), 1.0);
}

@fragment
fn fs_blend_term(in: VertexOut) -> @location(0) vec4f {
    return blend_term(in);
}

fn blend_term(in: VertexOut) -> vec4f {
    let b = blend_inputs(in);
    return vec4f(transparent_blend(b.im, b.transmittance, vec3f(0.0)), 1.0);
}

// Glass that bends light, with Fresnel (terms.fresnel): kt·Mt splits into F·kt·Mt reflected and
// (1 − F)·kt·Mt let through, and F changes across the surface, so one blend constant cannot
// carry it. src/raster/transparency.rs draws such glass twice: fs_transparent_transmit
// multiplies what the pixel holds by (1 − F)·kt·Mt (the blend computes dst·src), then
// fs_transparent_fresnel adds the surface's own radiance and its reflected share,
// Im + F·kt·Mt·L(r) (src + dst). Together: I = Im + F·kt·Mt·L(r) + (1 − F)·kt·Mt·I.

// F at a fragment of glass. The rays go straight through here, so a far wall is met at the
// angle the near one was: F is taken as entering at that angle, 1/ior, on both walls (by
// reciprocity the exit at the refracted angle reflects as much: exact for a slab and a sphere,
// where a bent ray leaves at the angle it entered). Taking the far wall as leaving at the
// unbent angle would reflect everything past the critical angle: a dark ring no glass shows.
fn glass_reflectance(n: vec3f, v: vec3f) -> f32 {
    return fresnel(dot(n, v), 1.0 / material.ior);
}

@fragment
fn fs_transparent_fresnel(in: VertexOut) -> @location(0) vec4f {
    return transparent_fresnel_fragment(in);
}

fn transparent_fresnel_fragment(in: VertexOut) -> vec4f {
    if masked_out(in.uv) {
        discard;
    }
    let shaded = shade_surface(in);
    let f = glass_reflectance(shaded.n, shaded.v);
    if INSPECT {
        probe.fresnel = f;
        probe.environment += f * material.transmission * shaded.environment;
    }
    return vec4f(shaded.radiance + f * material.transmission * shaded.environment, 1.0);
}

@fragment
fn fs_transparent_transmit(in: VertexOut) -> @location(0) vec4f {
    if masked_out(in.uv) {
        discard;
    }
    let v = view_vector(in.world);
    let n = facing_viewer(shading_normal(in, surface_tangents(in)), v);
    return vec4f((1.0 - glass_reflectance(n, v)) * material.transmission, 1.0);
}

// Depth peeling, the exact order (Everitt 2001, here back to front): layer k is the farthest
// transparent surface that is nearer than the opaque surface and strictly nearer than layer
// k − 1. The pass keeps the farthest survivor (depth test Greater); a second pass shades it.
// Depth images read with textureLoad are declared as float textures, depth in x: GLSL has no
// texelFetch of a depth texture (src/gpu/layout.rs, depth_texels).
@group(3) @binding(0) var opaque_depth: texture_2d<f32>;
@group(3) @binding(1) var peeled_depth: texture_2d<f32>;

@fragment
fn fs_peel(in: VertexOut) {
    let pixel = vec2i(in.clip.xy);
    let limit = min(textureLoad(opaque_depth, pixel, 0).x, textureLoad(peeled_depth, pixel, 0).x);
    // The mask is sampled before the depth test, not behind `||`: a texture sampled with implicit
    // derivatives must be in uniform control flow, and WebGPU compilers (Tint) refuse the module
    // otherwise.
    let masked = masked_out(in.uv);
    if in.clip.z >= limit || masked {
        discard;
    }
}

// The inspecting twins (shaders/common/inspect.wgsl).
@fragment
fn fs_transparent_inspect(in: VertexOut) -> @location(0) vec4f {
    probe.object = in.object;
    let out = transparent_fragment(in);
    probe.alpha = out.a;
    inspect_record(INSPECT_TRANSPARENT, in.clip, out.rgb);
    return out;
}

@fragment
fn fs_blend_term_inspect(in: VertexOut) -> @location(0) vec4f {
    probe.object = in.object;
    let b = blend_inputs(in);
    probe.blend_factor =
        transparent_blend(b.im, b.transmittance, vec3f(1.0)) - transparent_blend(b.im, b.transmittance, vec3f(0.0));
    let out = blend_term(in);
    probe.alpha = transparent_fragment(in).a;
    inspect_record(INSPECT_TRANSPARENT, in.clip, out.rgb);
    return out;
}

@fragment
fn fs_transparent_fresnel_inspect(in: VertexOut) -> @location(0) vec4f {
    probe.object = in.object;
    let out = transparent_fresnel_fragment(in);
    probe.alpha = 1.0;
    inspect_record(INSPECT_TRANSPARENT, in.clip, out.rgb);
    return out;
}

