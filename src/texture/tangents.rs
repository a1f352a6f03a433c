//! Tangent frames for bump and normal mapping (docs/course/04-bump-mapping.md): the vectors
//! `t_u = ∂p/∂u`, `t_v = ∂p/∂v` of the surface as a function of its texture coordinates.
//! The seed lists three ways to get them, all here:
//!
//! - **Analytic**, for simple objects: the ray tracer's `SurfaceHit::dpdu`, `dpdv` are exactly
//!   these (nothing to compute here; pass them to [`super::bump::perturbed_normal`]).
//! - **Constant per polygon** from the texture coordinates ([`triangle_tangents`]): inside a
//!   triangle `p` and `uv` are both affine, so with edges `e₁ = p₁ − p₀`, `e₂ = p₂ − p₀` and
//!   `Δuv₁ = uv₁ − uv₀`, `Δuv₂ = uv₂ − uv₀`, `e₁ = t_u·Δu₁ + t_v·Δv₁` and `e₂ = t_u·Δu₂ + t_v·Δv₂`;
//!   solving the 2×2 system gives `t_u = (e₁·Δv₂ − e₂·Δv₁)/det`, `t_v = (e₂·Δu₁ − e₁·Δu₂)/det`,
//!   `det = Δu₁·Δv₂ − Δu₂·Δv₁`. The rasterizer can solve the same system per pixel from the screen
//!   derivatives `dpdx(p)`, `dpdy(p)`, `dpdx(uv)`, `dpdy(uv)` (WGSL: `tangents_from_derivatives`),
//!   which for flat triangles is the same constant.
//! - **Per vertex, interpolated** ([`mesh_tangents`]): MikkTSpace (Mikkelsen 2008), the
//!   convention of glTF and of the tools that bake normal maps: a unit tangent along `+u` per
//!   vertex and in `w` the sign of the bitangent, `b = w·(n × t)`, which carries the frame's
//!   handedness so that mirrored texture coordinates still decode normal maps correctly.
//!
//! And glTF normal maps ([`normal_map_normal`]): the texel is a direction in the frame
//! `(t, b, n)`: `m = normalize((2·rgb − 1) ⊙ (scale, scale, 1))`, `n' = normalize(m.x·t + m.y·b + m.z·n)`.
//!
//! Limits: MikkTSpace tangents are unit length, so bump mapping with them measures heights per
//! unit of texture coordinate along a unit tangent, not per world unit (see the hand-off notes in
//! `src/texture/mod.rs` for matching the ray tracer); a vertex shared by triangles that
//! MikkTSpace gives different tangents (a mirrored seam welded into one vertex) keeps the
//! tangent of its first corner: meshes should split such seams, as glTF exporters do.

use glam::{Vec2, Vec3, Vec4};

use crate::scene::mesh::Mesh;

/// `(t_u, t_v)` of a triangle from the edges `dp1 = p₁ − p₀`, `dp2 = p₂ − p₀` and the texture
/// coordinate edges `duv1`, `duv2`; `None` where the texture coordinates are degenerate (the
/// triangle's texture image has no area) or the result is not finite. The WGSL twin
/// `tangents_from_derivatives` takes screen derivatives in their place.
pub fn tangents_from_edges(dp1: Vec3, dp2: Vec3, duv1: Vec2, duv2: Vec2) -> Option<(Vec3, Vec3)> {
    let det = duv1.x * duv2.y - duv2.x * duv1.y;
    // Relative to the products it comes from, so that tiny but valid texture coordinates pass.
    if det.abs() <= f32::EPSILON * ((duv1.x * duv2.y).abs() + (duv2.x * duv1.y).abs()) || det == 0.0 {
        return None;
    }
    let r = 1.0 / det;
    let tu = (dp1 * duv2.y - dp2 * duv1.y) * r;
    let tv = (dp2 * duv1.x - dp1 * duv2.x) * r;
    (tu.is_finite() && tv.is_finite()).then_some((tu, tv))
}

/// `(∂p/∂u, ∂p/∂v)` of the triangle `p0 p1 p2` with texture coordinates `uv0 uv1 uv2`: constant
/// over the triangle, not normalized (their lengths are world units per unit of texture
/// coordinate). `None` if the texture coordinates are degenerate.
pub fn triangle_tangents(p0: Vec3, p1: Vec3, p2: Vec3, uv0: Vec2, uv1: Vec2, uv2: Vec2) -> Option<(Vec3, Vec3)> {
    tangents_from_edges(p1 - p0, p2 - p0, uv1 - uv0, uv2 - uv0)
}

struct MikkMesh<'a> {
    mesh: &'a Mesh,
    tangents: Vec<Option<Vec4>>,
}

impl MikkMesh<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.mesh.indices[face * 3 + vert] as usize
    }
}

impl mikktspace::Geometry for MikkMesh<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.indices.len() / 3
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.normals[self.vertex(face, vert)].to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.mesh.uvs[self.vertex(face, vert)].to_array()
    }

    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        let vertex = self.vertex(face, vert);
        let slot = &mut self.tangents[vertex];
        if slot.is_none() {
            *slot = Some(Vec4::from_array(tangent));
        }
    }
}

/// MikkTSpace tangents per vertex of `mesh`: `xyz` a unit tangent along `+u`, `w = ±1` the sign
/// of the bitangent `b = w·(n × t)`. Vertices MikkTSpace cannot give a tangent (no triangle, or
/// degenerate texture coordinates everywhere around them) get an arbitrary unit vector
/// perpendicular to their normal and `w = 1`, so the result always has one finite entry per
/// vertex. The mesh must be valid (`Mesh::validate_and_repair`).
pub fn mesh_tangents(mesh: &Mesh) -> Vec<Vec4> {
    let vertices = mesh.positions.len();
    let usable = mesh.normals.len() == vertices
        && mesh.uvs.len() == vertices
        && mesh.indices.len().is_multiple_of(3)
        && mesh.indices.iter().all(|&i| (i as usize) < vertices);
    let mut geometry = MikkMesh { mesh, tangents: vec![None; vertices] };
    if usable && !mesh.indices.is_empty() {
        // `false` means no usable triangle at all; the fallback below covers it.
        mikktspace::generate_tangents(&mut geometry);
    }
    geometry
        .tangents
        .into_iter()
        .enumerate()
        .map(|(i, tangent)| match tangent {
            Some(t) if t.is_finite() && t.truncate().length_squared() > 0.0 => {
                t.truncate().normalize().extend(if t.w < 0.0 { -1.0 } else { 1.0 })
            }
            _ => {
                let n = mesh.normals.get(i).and_then(|n| n.try_normalize()).unwrap_or(Vec3::Z);
                n.any_orthonormal_vector().extend(1.0)
            }
        })
        .collect()
}

/// The mesh's own tangents where it has a usable set (one finite tangent per vertex, as a glTF
/// file may carry), MikkTSpace's otherwise.
pub fn tangents_or_generate(mesh: &Mesh, existing: Option<&[Vec4]>) -> Vec<Vec4> {
    match existing {
        Some(t) if t.len() == mesh.positions.len() && t.iter().all(|t| t.is_finite()) => t.to_vec(),
        _ => mesh_tangents(mesh),
    }
}

/// The orthonormal frame `(t, b)` of a per-vertex tangent at a point with unit normal `n`: `t`
/// made perpendicular to `n` (interpolation bends it away; Gram–Schmidt), `b = sign(w)·(n × t)`.
/// `None` if the tangent is parallel to `n` or not finite.
pub fn tangent_frame(n: Vec3, tangent: Vec4) -> Option<(Vec3, Vec3)> {
    let t = tangent.truncate();
    let t = (t - t.dot(n) * n).try_normalize()?;
    let sign = if tangent.w < 0.0 { -1.0 } else { 1.0 };
    Some((t, sign * n.cross(t)))
}

/// glTF's normal map: the texel `sample_rgb` (linear values in `[0, 1]`, i.e. the texture read
/// as data, not sRGB) decodes to `m = normalize((2·rgb − 1) ⊙ (scale, scale, 1))` in the frame
/// `(t, b, n)` of [`tangent_frame`]; returns `normalize(m.x·t + m.y·b + m.z·n)`. Falls back to `n`
/// where the frame or the texel is degenerate. WGSL twin: `normal_map_normal`.
pub fn normal_map_normal(n: Vec3, tangent: Vec4, sample_rgb: Vec3, scale: f32) -> Vec3 {
    let Some((t, b)) = tangent_frame(n, tangent) else {
        return n;
    };
    let Some(m) = ((2.0 * sample_rgb - 1.0) * Vec3::new(scale, scale, 1.0)).try_normalize() else {
        return n;
    };
    (m.x * t + m.y * b + m.z * n).try_normalize().unwrap_or(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_tangents_are_the_parametrization_derivatives() {
        // p = (2u, 0, 3v) + offset: ∂p/∂u = (2, 0, 0), ∂p/∂v = (0, 0, 3).
        let p = |uv: Vec2| Vec3::new(2.0 * uv.x, 0.0, 3.0 * uv.y) + Vec3::ONE;
        let uvs = [Vec2::new(0.1, 0.2), Vec2::new(0.7, 0.3), Vec2::new(0.4, 0.9)];
        let (tu, tv) = triangle_tangents(p(uvs[0]), p(uvs[1]), p(uvs[2]), uvs[0], uvs[1], uvs[2]).expect("valid");
        assert!(tu.abs_diff_eq(Vec3::new(2.0, 0.0, 0.0), 1e-5), "{tu}");
        assert!(tv.abs_diff_eq(Vec3::new(0.0, 0.0, 3.0), 1e-5), "{tv}");
        let same = Vec2::splat(0.5);
        assert_eq!(triangle_tangents(Vec3::ZERO, Vec3::X, Vec3::Y, same, same, Vec2::ONE), None);
    }

    #[test]
    fn plane_tangents_run_along_u_with_a_negative_bitangent_sign() {
        // Mesh::plane: u along +x, v along +z, normal +y. n × t = y × x = −z, but ∂p/∂v = +z, so
        // the bitangent sign is −1.
        let plane = Mesh::plane(Vec2::new(2.0, 2.0), Vec2::ONE);
        for t in mesh_tangents(&plane) {
            assert!(t.abs_diff_eq(Vec4::new(1.0, 0.0, 0.0, -1.0), 1e-6), "{t}");
        }
        let (t, b) = tangent_frame(Vec3::Y, Vec4::new(1.0, 0.0, 0.0, -1.0)).expect("valid");
        assert_eq!((t, b), (Vec3::X, Vec3::Z));
    }

    #[test]
    fn flat_normal_map_texel_keeps_the_normal() {
        let tangent = Vec4::new(1.0, 0.0, 0.0, 1.0);
        let flat = Vec3::new(0.5, 0.5, 1.0);
        assert!(normal_map_normal(Vec3::Z, tangent, flat, 1.0).abs_diff_eq(Vec3::Z, 1e-6));
        // (1, 0.5, 0.5) is a normal tilted fully towards +t: m = (1, 0, 0).
        assert!(normal_map_normal(Vec3::Z, tangent, Vec3::new(1.0, 0.5, 0.5), 1.0).abs_diff_eq(Vec3::X, 1e-6));
        // scale = 0 flattens any texel back to n.
        assert!(normal_map_normal(Vec3::Z, tangent, Vec3::new(0.9, 0.2, 0.8), 0.0).abs_diff_eq(Vec3::Z, 1e-6));
        // The bitangent sign flips the green axis.
        let up = Vec3::new(0.5, 1.0, 0.5);
        assert!(normal_map_normal(Vec3::Z, tangent, up, 1.0).abs_diff_eq(Vec3::Y, 1e-6));
        assert!(normal_map_normal(Vec3::Z, tangent.with_w(-1.0), up, 1.0).abs_diff_eq(-Vec3::Y, 1e-6));
    }
}
