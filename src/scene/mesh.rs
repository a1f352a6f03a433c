//! Triangle meshes, and the tessellation the rasterizer draws analytic shapes with.
//!
//! The ray tracer intersects spheres, boxes and planes exactly; the z-buffer needs triangles.
//! Boxes and planes tessellate exactly; a sphere becomes a UV sphere of `segments × segments/2`
//! quads whose vertices lie on the true sphere, so its silhouette is a polygon inscribed in the
//! true one (a raster-vs-trace difference of at most `r·(1 − cos(π/segments))`).

use glam::{Vec2, Vec3, Vec4};

/// An indexed triangle mesh in its local coordinates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    /// Per-vertex tangents (xyz, and w = ±1 the bitangent's sign) when the file gives them, as
    /// glTF's TANGENT does; empty otherwise, and then made with MikkTSpace where needed.
    pub tangents: Vec<Vec4>,
    /// Three indices per triangle, counter-clockwise seen from the front.
    pub indices: Vec<u32>,
}

/// Why a mesh could not be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("mesh `{mesh}`: index {index} at position {at} is out of range ({vertices} vertices)")]
    IndexOutOfRange { mesh: String, index: u32, at: usize, vertices: usize },
    #[error("mesh `{mesh}`: {count} indices is not a whole number of triangles")]
    PartialTriangle { mesh: String, count: usize },
    #[error("mesh `{mesh}`: vertex {vertex} has a NaN or infinite {what}")]
    NotFinite { mesh: String, vertex: usize, what: &'static str },
    #[error("mesh `{mesh}`: {positions} positions but {other} {what}")]
    AttributeCount { mesh: String, positions: usize, other: usize, what: &'static str },
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Checks indices and attribute values, and removes zero-area triangles (they have no normal
    /// and no pixels). Returns how many triangles were removed, so the caller can warn.
    pub fn validate_and_repair(&mut self) -> Result<usize, MeshError> {
        let mesh = self.name.clone();
        let vertices = self.positions.len();
        for (other, what) in [(self.normals.len(), "normals"), (self.uvs.len(), "texture coordinates")] {
            if other != vertices {
                return Err(MeshError::AttributeCount { mesh, positions: vertices, other, what });
            }
        }
        if !self.tangents.is_empty() && self.tangents.len() != vertices {
            return Err(MeshError::AttributeCount {
                mesh,
                positions: vertices,
                other: self.tangents.len(),
                what: "tangents",
            });
        }
        if !self.indices.len().is_multiple_of(3) {
            return Err(MeshError::PartialTriangle { mesh, count: self.indices.len() });
        }
        if let Some((at, &index)) = self.indices.iter().enumerate().find(|&(_, &i)| i as usize >= vertices) {
            return Err(MeshError::IndexOutOfRange { mesh, index, at, vertices });
        }
        let checks: [(&'static str, Option<usize>); 3] = [
            ("position", self.positions.iter().position(|p| !p.is_finite())),
            ("normal", self.normals.iter().position(|n| !n.is_finite())),
            ("texture coordinate", self.uvs.iter().position(|t| !t.is_finite())),
        ];
        if let Some((what, Some(vertex))) = checks.into_iter().find(|(_, at)| at.is_some()) {
            return Err(MeshError::NotFinite { mesh, vertex, what });
        }
        let before = self.indices.len() / 3;
        let positions = &self.positions;
        let kept: Vec<u32> = self
            .indices
            .chunks_exact(3)
            .filter(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
                (b - a).cross(c - a).length_squared() > 0.0
            })
            .flatten()
            .copied()
            .collect();
        self.indices = kept;
        Ok(before - self.indices.len() / 3)
    }

    /// Per-vertex normals as the area-weighted average of the adjacent faces, for meshes that
    /// come without normals.
    pub fn compute_normals(&mut self) {
        let mut normals = vec![Vec3::ZERO; self.positions.len()];
        for t in self.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
            let face = (self.positions[b] - self.positions[a]).cross(self.positions[c] - self.positions[a]);
            for i in [a, b, c] {
                normals[i] += face;
            }
        }
        self.normals = normals.into_iter().map(|n| n.try_normalize().unwrap_or(Vec3::Y)).collect();
    }

    fn push_vertex(&mut self, position: Vec3, normal: Vec3, uv: Vec2) -> u32 {
        self.positions.push(position);
        self.normals.push(normal);
        self.uvs.push(uv);
        (self.positions.len() - 1) as u32
    }

    /// Appends the quad `origin + s·edge_u + t·edge_v`, s, t ∈ [0, 1], facing `edge_u × edge_v`,
    /// with texture coordinates `(s·uv_scale.x, (1 − t)·uv_scale.y)`.
    fn push_quad(&mut self, origin: Vec3, edge_u: Vec3, edge_v: Vec3, uv_scale: Vec2) {
        let normal = edge_u.cross(edge_v).normalize();
        let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let [a, b, c, d] = corners
            .map(|(s, t)| self.push_vertex(origin + s * edge_u + t * edge_v, normal, Vec2::new(s, 1.0 - t) * uv_scale));
        self.indices.extend_from_slice(&[a, b, c, a, c, d]);
    }

    /// The quad `[−sx/2, sx/2] × [−sz/2, sz/2]` in the plane y = 0, facing +y; texture coordinates
    /// run over `[0, uv_scale]`.
    pub fn plane(size: Vec2, uv_scale: Vec2) -> Mesh {
        let mut mesh = Mesh { name: "plane".into(), ..Mesh::default() };
        let origin = Vec3::new(-size.x / 2.0, 0.0, size.y / 2.0);
        mesh.push_quad(origin, Vec3::X * size.x, Vec3::NEG_Z * size.y, uv_scale);
        mesh
    }

    /// The six faces of the axis-aligned box `[min, max]`, each with its own flat normal and
    /// texture coordinates over `[0, 1]²`.
    pub fn cuboid(min: Vec3, max: Vec3) -> Mesh {
        let mut mesh = Mesh { name: "box".into(), ..Mesh::default() };
        let d = max - min;
        let (dx, dy, dz) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
        let faces = [
            (Vec3::new(max.x, min.y, max.z), -dz, dy), // +x
            (min, dz, dy),                             // −x
            (Vec3::new(min.x, max.y, max.z), dx, -dz), // +y
            (min, dx, dz),                             // −y
            (Vec3::new(min.x, min.y, max.z), dx, dy),  // +z
            (Vec3::new(max.x, min.y, min.z), -dx, dy), // −z
        ];
        for (origin, u, v) in faces {
            mesh.push_quad(origin, u, v, Vec2::ONE);
        }
        mesh
    }

    /// A UV sphere with `segments` slices around the y axis and `segments / 2` stacks; texture
    /// coordinates are longitude and latitude (`u = φ/2π`, `v = θ/π` from the north pole).
    pub fn sphere(center: Vec3, radius: f32, segments: u32) -> Mesh {
        let slices = segments.max(3);
        let stacks = (segments / 2).max(2);
        let mut mesh = Mesh { name: "sphere".into(), ..Mesh::default() };
        for j in 0..=stacks {
            let v = j as f32 / stacks as f32;
            let theta = v * std::f32::consts::PI;
            for i in 0..=slices {
                let u = i as f32 / slices as f32;
                let phi = u * std::f32::consts::TAU;
                let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin());
                mesh.push_vertex(center + radius * n, n, Vec2::new(u, v));
            }
        }
        let row = slices + 1;
        for j in 0..stacks {
            for i in 0..slices {
                let (a, b) = (j * row + i, j * row + i + 1);
                let (c, d) = (a + row, b + row);
                // Skip the triangles that collapse to a point at each pole.
                if j != 0 {
                    mesh.indices.extend_from_slice(&[a, c, b]);
                }
                if j != stacks - 1 {
                    mesh.indices.extend_from_slice(&[b, c, d]);
                }
            }
        }
        mesh
    }

    /// A torus around the y axis: `segments` steps around the ring, `segments / 2` around the
    /// tube; `u` runs around the ring, `v` around the tube.
    pub fn torus(major: f32, minor: f32, segments: u32) -> Mesh {
        let (ring, tube) = (segments.max(3), (segments / 2).max(3));
        let mut mesh = Mesh { name: "torus".into(), ..Mesh::default() };
        for j in 0..=tube {
            let v = j as f32 / tube as f32;
            let (sin_b, cos_b) = (v * std::f32::consts::TAU).sin_cos();
            for i in 0..=ring {
                let u = i as f32 / ring as f32;
                let (sin_a, cos_a) = (u * std::f32::consts::TAU).sin_cos();
                let radial = Vec3::new(cos_a, 0.0, -sin_a);
                let n = cos_b * radial + sin_b * Vec3::Y;
                mesh.push_vertex(major * radial + minor * n, n, Vec2::new(u, v));
            }
        }
        mesh.grid_indices(ring, tube);
        mesh
    }

    /// A box of half extents `half` with edges rounded by `radius`: a finely divided cube of half
    /// extent `half + radius` whose every vertex is moved onto the exact rounded surface
    /// `q + radius·normalize(p − q)`, `q` the nearest point of the inner box. Flat faces stay
    /// flat; the rounded edges get `segments / 4` steps.
    pub fn rounded_box(half: Vec3, radius: f32, segments: u32) -> Mesh {
        let steps = (segments / 4).max(2);
        let mut mesh = Mesh { name: "rounded box".into(), ..Mesh::default() };
        let outer = half + Vec3::splat(radius);
        // Along each face axis: the rounded rim, the flat middle, the rim again.
        let ticks = |h: f32| -> Vec<f32> {
            let mut t: Vec<f32> = (0..=steps)
                .map(|k| -h - radius * (std::f32::consts::FRAC_PI_2 * k as f32 / steps as f32).cos())
                .collect();
            t.extend(
                (0..=steps).rev().map(|k| h + radius * (std::f32::consts::FRAC_PI_2 * k as f32 / steps as f32).cos()),
            );
            t
        };
        let faces = [
            (Vec3::X, Vec3::NEG_Z, Vec3::Y),
            (Vec3::NEG_X, Vec3::Z, Vec3::Y),
            (Vec3::Y, Vec3::X, Vec3::NEG_Z),
            (Vec3::NEG_Y, Vec3::X, Vec3::Z),
            (Vec3::Z, Vec3::X, Vec3::Y),
            (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
        ];
        for (normal, u_axis, v_axis) in faces {
            let (us, vs) = (ticks(u_axis.abs().dot(half)), ticks(v_axis.abs().dot(half)));
            let base = mesh.positions.len() as u32;
            for (j, &v) in vs.iter().enumerate() {
                for (i, &u) in us.iter().enumerate() {
                    let p = normal * normal.abs().dot(outer) + u_axis * u + v_axis * v;
                    let q = p.clamp(-half, half);
                    let n = (p - q).try_normalize().unwrap_or(normal);
                    let uv = Vec2::new(i as f32 / (us.len() - 1) as f32, 1.0 - j as f32 / (vs.len() - 1) as f32);
                    mesh.push_vertex(q + radius * n, n, uv);
                }
            }
            let row = us.len() as u32;
            for j in 0..vs.len() as u32 - 1 {
                for i in 0..row - 1 {
                    let (a, b) = (base + j * row + i, base + j * row + i + 1);
                    mesh.indices.extend_from_slice(&[a, b, b + row, a, b + row, a + row]);
                }
            }
        }
        // Rims meet at the edges in coincident vertices, so some rim quads collapse; drop them.
        mesh.validate_and_repair().expect("the rounded box's own indices are in range");
        mesh
    }

    /// Indices of a `(columns + 1) × (rows + 1)` vertex grid, counter-clockwise seen from the
    /// side the normals point to when u runs left to right and v bottom to top.
    fn grid_indices(&mut self, columns: u32, rows: u32) {
        let row = columns + 1;
        for j in 0..rows {
            for i in 0..columns {
                let (a, b) = (j * row + i, j * row + i + 1);
                self.indices.extend_from_slice(&[a, b, b + row, a, b + row, a + row]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_outward_and_ccw(mesh: &Mesh, center: Vec3) {
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
            let face = (b - a).cross(c - a);
            assert!(face.length() > 0.0, "degenerate triangle in {}", mesh.name);
            let centroid = (a + b + c) / 3.0;
            assert!(face.dot(centroid - center) > 0.0, "{} has an inward-facing triangle", mesh.name);
            let n = mesh.normals[t[0] as usize];
            assert!(n.dot(face) > 0.0, "{}: vertex normal disagrees with winding", mesh.name);
        }
    }

    #[test]
    fn analytic_shapes_tessellate_outward_counter_clockwise() {
        let center = Vec3::new(1.0, 2.0, 3.0);
        assert_outward_and_ccw(&Mesh::sphere(center, 2.0, 16), center);
        assert_outward_and_ccw(&Mesh::cuboid(center - 1.0, center + Vec3::new(1.0, 2.0, 3.0)), center);
        assert_outward_and_ccw(&Mesh::plane(Vec2::new(4.0, 2.0), Vec2::ONE), Vec3::NEG_Y);
        assert_outward_and_ccw(&Mesh::rounded_box(Vec3::new(1.0, 2.0, 0.5), 0.25, 32), Vec3::ZERO);
    }

    #[test]
    fn torus_faces_away_from_its_tube_and_lies_on_the_surface() {
        let mesh = Mesh::torus(2.0, 0.5, 32);
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
            let centroid = (a + b + c) / 3.0;
            let ring = Vec3::new(centroid.x, 0.0, centroid.z).normalize() * 2.0;
            assert!((b - a).cross(c - a).dot(centroid - ring) > 0.0, "inward-facing torus triangle");
        }
        for p in &mesh.positions {
            let ring_distance = (Vec2::new(p.x, p.z).length() - 2.0).hypot(p.y);
            assert!((ring_distance - 0.5).abs() < 1e-4);
        }
    }

    #[test]
    fn rounded_box_vertices_lie_on_the_rounded_surface() {
        let (half, radius) = (Vec3::new(1.0, 2.0, 0.5), 0.25);
        for p in &Mesh::rounded_box(half, radius, 32).positions {
            let distance = (p.abs() - half).max(Vec3::ZERO).length();
            assert!((distance - radius).abs() < 1e-4, "{p} is {distance} from the inner box");
        }
    }

    #[test]
    fn sphere_vertices_lie_on_the_sphere() {
        let mesh = Mesh::sphere(Vec3::ZERO, 25.0, 32);
        assert!(mesh.positions.iter().all(|p| (p.length() - 25.0).abs() < 1e-4));
        assert_eq!(mesh.triangle_count(), 32 * 16 * 2 - 2 * 32);
    }

    #[test]
    fn repair_drops_zero_area_triangles_and_rejects_bad_indices() {
        let mut mesh = Mesh {
            name: "t".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X * 2.0],
            normals: vec![Vec3::Z; 4],
            uvs: vec![Vec2::ZERO; 4],
            tangents: Vec::new(),
            indices: vec![0, 1, 2, 0, 1, 3],
        };
        assert_eq!(mesh.validate_and_repair(), Ok(1));
        assert_eq!(mesh.indices, vec![0, 1, 2]);
        mesh.indices.extend_from_slice(&[0, 1, 7]);
        assert!(matches!(mesh.validate_and_repair(), Err(MeshError::IndexOutOfRange { index: 7, .. })));
    }
}
