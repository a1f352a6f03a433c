//! The CPU's part of adaptive displacement: an object's mesh welded, placed in the world and
//! written as patches (one per triangle) for the compute shader; every frame, each edge's level
//! for the camera; and the same tessellation made on the CPU.

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Mat4, Vec2, Vec3};

use super::{GridPoint, MAX_LEVEL, MAX_TRIANGLES, MAX_VERTICES, grid_point, grid_triangle, vertex_count, vertex_index};
use crate::scene::{Camera, Mesh, Scene};
use crate::settings::BumpSettings;
use crate::texture::displacement::{face_normals, welded, welded_mean, with_field};
use crate::texture::height::HeightField;

/// One triangle of the object's mesh as the compute shader reads it (`Patch` in
/// `shaders/tessellation.wgsl`), in world coordinates. Corners are welded: vertices at one point
/// have the same bits and the same number (`groups`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuPatch {
    /// The corners on the undisplaced surface.
    pub corners: [[f32; 4]; 3],
    /// The corners moved: by the mean height of every vertex at their point, along the mean of
    /// their normals.
    pub moved: [[f32; 4]; 3],
    /// The corners' unit normals.
    pub normals: [[f32; 4]; 3],
    /// The corners' texture coordinates: `(u0, v0, u1, v1)`, `(u2, v2, 0, 0)`.
    pub uvs: [[f32; 4]; 2],
    /// Per edge (corner `e` to corner `e + 1`), the texture coordinates the neighbour across it
    /// has at those two corners (its own where there is no neighbour): a seam's other side.
    pub twin_uvs: [[f32; 4]; 3],
    /// Per edge, the neighbour's normals at the edge's two corners.
    pub twin_normals: [[f32; 4]; 6],
    /// `∂p/∂u`, `∂p/∂v`, `∂n/∂u`, `∂n/∂v` across the triangle (zero where its texture coordinates
    /// are degenerate).
    pub derivatives: [[f32; 4]; 4],
    /// The corners' welded numbers (an edge's points are computed from its smaller one), and in
    /// the fourth, bit `e` set where the neighbour across edge `e` goes first in the sums of the
    /// two sides' heights and normals.
    pub groups: [u32; 4],
}

/// One edge of the welded mesh.
#[derive(Clone, Debug)]
struct Edge {
    /// Its two ends' welded numbers.
    ends: [usize; 2],
    /// Its length in steps of the height field (a texel of a height map), the longer of its
    /// sides' (the uniform mesh's rule).
    steps: f32,
}

/// A displaced object made ready for adaptive tessellation.
#[derive(Clone, Debug)]
pub struct Patches {
    /// Index into `Scene::objects`.
    pub object: usize,
    /// The material with the height field.
    pub material: usize,
    /// `k`, in world units.
    pub k: f32,
    /// The transform the patches were placed with: they are made again when it changes.
    pub world_from_local: Mat4,
    pub patches: Vec<GpuPatch>,
    /// Each patch's edges, as indices into `edges`.
    patch_edges: Vec<[usize; 3]>,
    edges: Vec<Edge>,
    /// Each welded point moved.
    moved: Vec<Vec3>,
}

/// One frame's tessellation of one object: per patch its edges' levels, its own and where its
/// vertices and triangles begin (`Level` in `shaders/tessellation.wgsl`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Levels {
    /// `[e0, e1, e2, n, first vertex, first triangle, 0, 0]` (the firsts meaningful while the
    /// totals fit in 32 bits, as they do under the bound).
    pub patches: Vec<[u32; 8]>,
    pub vertices: u64,
    pub triangles: u64,
}

impl Patches {
    /// Surface `index` of `scene.displaced`, welded and placed; `None` where its object,
    /// material or height field is gone.
    pub fn new(scene: &Scene, index: usize) -> Option<Patches> {
        let surface = scene.displaced.get(index)?;
        let object = scene.objects.get(surface.object)?;
        let material = scene.materials.get(surface.material)?;
        let world_from_local = object.world_from_local;
        let (mesh, k) = (&surface.base, surface.k);
        let normal_from_local = Mat3::from_mat4(world_from_local).inverse().transpose();
        let local_normals =
            if mesh.normals.len() == mesh.positions.len() { mesh.normals.clone() } else { face_normals(mesh) };
        let mut positions: Vec<Vec3> = mesh.positions.iter().map(|&p| world_from_local.transform_point3(p)).collect();
        let normals: Vec<Vec3> = local_normals.iter().map(|&n| (normal_from_local * n).normalize_or(Vec3::Y)).collect();
        let uvs: Vec<Vec2> = (0..positions.len()).map(|i| mesh.uvs.get(i).copied().unwrap_or(Vec2::ZERO)).collect();
        let groups = welded(&positions);
        let mut group_of = vec![0; positions.len()];
        for (g, members) in groups.iter().enumerate() {
            for &i in members {
                group_of[i] = g;
                positions[i] = positions[members[0]];
            }
        }
        let (moved, step) = with_field(scene, material, |field| {
            let moved = groups.iter().map(|members| moved_point(members, (&positions, &normals, &uvs), field, k));
            (moved.collect::<Vec<Vec3>>(), field.default_delta())
        })?;
        let welded = Welded { positions, normals, uvs, group_of };
        let (patch_edges, edges, twins) = edges_of(mesh, &welded, step);
        let patches =
            patch_edges.iter().zip(&twins).map(|((corners, _), twins)| welded.patch(*corners, twins, &moved)).collect();
        let patch_edges = patch_edges.into_iter().map(|(_, edges)| edges).collect();
        Some(Patches {
            object: surface.object,
            material: surface.material,
            k,
            world_from_local,
            patches,
            patch_edges,
            edges,
            moved,
        })
    }

    /// Each edge's level for `camera`: enough pieces that none spans more than `edge_pixels` on
    /// screen, no more than `bump.displacement_texels` of the field asks for, 1 to [`MAX_LEVEL`].
    fn edge_levels(&self, camera: &Camera, edge_pixels: f32, texels: f32) -> Vec<u32> {
        let projected: Vec<Option<Vec2>> =
            self.moved.iter().map(|&p| camera.project(p).map(|q| q.truncate()).filter(|q| q.is_finite())).collect();
        self.edges
            .iter()
            .map(|edge| {
                let screen = match (projected[edge.ends[0]], projected[edge.ends[1]]) {
                    (Some(a), Some(b)) => (a.distance(b) / edge_pixels).ceil(),
                    // An end behind the eye: as fine as the field allows.
                    _ => f32::INFINITY,
                };
                let field = (edge.steps / texels.max(1e-3)).ceil();
                let level = screen.min(field);
                if level.is_nan() { 1 } else { level.clamp(1.0, MAX_LEVEL as f32) as u32 }
            })
            .collect()
    }

    /// The patches' levels for `camera` with edges of at most `edge_pixels` on screen.
    pub fn levels(&self, camera: &Camera, edge_pixels: f32, texels: f32) -> Levels {
        let edge_levels = self.edge_levels(camera, edge_pixels, texels);
        let mut levels = Levels::default();
        for edges in &self.patch_edges {
            let e = edges.map(|i| edge_levels[i]);
            let n = e[0].max(e[1]).max(e[2]);
            levels.patches.push([e[0], e[1], e[2], n, levels.vertices as u32, levels.triangles as u32, 0, 0]);
            levels.vertices += u64::from(vertex_count(n));
            levels.triangles += u64::from(n * n);
        }
        levels
    }

    /// The triangles the compute shader makes for `levels`, made on the CPU with `field` (the
    /// tracer's reading of the same height field): for the tessellation view, and the GPU's test.
    pub fn tessellate(&self, levels: &Levels, field: &dyn HeightField) -> Mesh {
        let mut mesh = Mesh {
            name: "adaptive displacement".into(),
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            tangents: Vec::new(),
            indices: Vec::new(),
        };
        for (patch, level) in self.patches.iter().zip(&levels.patches) {
            let (n, edges, first) = (level[3], [level[0], level[1], level[2]], mesh.positions.len() as u32);
            for b in 0..=n {
                for a in 0..=(n - b) {
                    let (position, normal, uv) = point(patch, self.k, (n, edges), (a, b), field);
                    mesh.positions.push(position);
                    mesh.normals.push(normal);
                    mesh.uvs.push(uv);
                }
            }
            for t in 0..n * n {
                mesh.indices.extend(grid_triangle(n, t).map(|(a, b)| first + vertex_index(n, a, b)));
            }
        }
        mesh
    }
}

/// Every object's levels for `camera` under the bound: `bump.edge_pixels`, or longer edges where
/// the objects would have more than [`MAX_TRIANGLES`] triangles or [`MAX_VERTICES`] vertices
/// together. Returns the levels and the edge length used.
pub fn bounded_levels(objects: &[&Patches], camera: &Camera, bump: &BumpSettings) -> (Vec<Levels>, f32) {
    let mut edge_pixels = bump.edge_pixels.max(0.5);
    loop {
        let levels: Vec<Levels> =
            objects.iter().map(|o| o.levels(camera, edge_pixels, bump.displacement_texels)).collect();
        let triangles: u64 = levels.iter().map(|l| l.triangles).sum();
        let vertices: u64 = levels.iter().map(|l| l.vertices).sum();
        let coarsest = levels.iter().all(|l| l.patches.iter().all(|p| p[3] == 1));
        if (triangles <= MAX_TRIANGLES && vertices <= MAX_VERTICES) || coarsest || edge_pixels > 1e6 {
            return (levels, edge_pixels);
        }
        edge_pixels *= 1.25;
    }
}

/// The mesh's vertices in the world, welded: the points of one group have the same bits.
struct Welded {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    group_of: Vec<usize>,
}

/// A patch's corners (mesh indices) and its edges (indices into the edges).
type PatchEdges = ([usize; 3], [usize; 3]);

/// Per patch edge, the neighbour's texture coordinates and normals at the edge's two corners, and
/// whether the neighbour goes first in the sums of the two sides (the one with the smaller
/// number does).
type Twins = [([Vec2; 2], [Vec3; 2], bool); 3];

/// The mesh's triangles as patches (those with an index out of range or two corners at one point
/// left out), its edges, and each patch's neighbours across them.
fn edges_of(mesh: &Mesh, welded: &Welded, step: Vec2) -> (Vec<PatchEdges>, Vec<Edge>, Vec<Twins>) {
    let mut ids: HashMap<(usize, usize), usize> = HashMap::new();
    let mut edges: Vec<Edge> = Vec::new();
    let mut sides: Vec<Vec<(usize, usize)>> = Vec::new();
    let mut patches: Vec<PatchEdges> = Vec::new();
    for t in mesh.indices.chunks_exact(3) {
        let corners = [t[0], t[1], t[2]].map(|i| i as usize);
        if corners.iter().any(|&i| i >= welded.positions.len()) {
            continue;
        }
        // A triangle with two corners at one point (a sphere's pole row) covers nothing: left out,
        // so that the edge it would share has only its two true sides.
        let groups = corners.map(|i| welded.group_of[i]);
        if groups[0] == groups[1] || groups[1] == groups[2] || groups[2] == groups[0] {
            continue;
        }
        let mut patch_edges = [0; 3];
        for slot in 0..3 {
            let (a, b) = (corners[slot], corners[(slot + 1) % 3]);
            let (ga, gb) = (welded.group_of[a], welded.group_of[b]);
            let id = *ids.entry((ga.min(gb), ga.max(gb))).or_insert_with(|| {
                edges.push(Edge { ends: [ga.min(gb), ga.max(gb)], steps: 0.0 });
                sides.push(Vec::new());
                edges.len() - 1
            });
            let d = ((welded.uvs[b] - welded.uvs[a]) / step).abs();
            edges[id].steps = edges[id].steps.max(d.x.max(d.y));
            sides[id].push((patches.len(), slot));
            patch_edges[slot] = id;
        }
        patches.push((corners, patch_edges));
    }
    let twins = patches
        .iter()
        .enumerate()
        .map(|(p, (corners, patch_edges))| {
            std::array::from_fn(|slot| {
                let ends = [corners[slot], corners[(slot + 1) % 3]];
                let own = (ends.map(|i| welded.uvs[i]), ends.map(|i| welded.normals[i]), false);
                let side = &sides[patch_edges[slot]];
                // The one other triangle on the edge; an edge of one triangle (the mesh's border)
                // or of three or more keeps its own.
                let other = match side.as_slice() {
                    [x, y] if x.0 == p => Some(*y),
                    [x, y] if y.0 == p => Some(*x),
                    _ => None,
                };
                let Some((q, _)) = other else { return own };
                let theirs = patches[q].0;
                let at = |i: usize| theirs.into_iter().find(|&j| welded.group_of[j] == welded.group_of[i]);
                match (at(ends[0]), at(ends[1])) {
                    (Some(a), Some(b)) => {
                        ([welded.uvs[a], welded.uvs[b]], [welded.normals[a], welded.normals[b]], q < p)
                    }
                    _ => own,
                }
            })
        })
        .collect();
    (patches, edges, twins)
}

impl Welded {
    /// The patch of the triangle `corners`.
    fn patch(&self, corners: [usize; 3], twins: &Twins, moved: &[Vec3]) -> GpuPatch {
        let four = |v: Vec3| v.extend(0.0).to_array();
        let [p, n, uv] = [
            corners.map(|i| self.positions[i]).map(|v| v.extend(0.0)),
            corners.map(|i| self.normals[i]).map(|v| v.extend(0.0)),
            corners.map(|i| self.uvs[i].extend(0.0).extend(0.0)),
        ];
        let [uv0, uv1, uv2] = corners.map(|i| self.uvs[i]);
        GpuPatch {
            corners: p.map(|v| v.to_array()),
            moved: corners.map(|i| four(moved[self.group_of[i]])),
            normals: n.map(|v| v.to_array()),
            uvs: [[uv0.x, uv0.y, uv1.x, uv1.y], [uv2.x, uv2.y, 0.0, 0.0]],
            twin_uvs: twins.map(|(uvs, ..)| [uvs[0].x, uvs[0].y, uvs[1].x, uvs[1].y]),
            twin_normals: std::array::from_fn(|i| four(twins[i / 2].1[i % 2])),
            derivatives: derivatives(
                p.map(|v| v.truncate()),
                n.map(|v| v.truncate()),
                uv.map(|v| v.truncate().truncate()),
            )
            .map(four),
            groups: [
                self.group_of[corners[0]] as u32,
                self.group_of[corners[1]] as u32,
                self.group_of[corners[2]] as u32,
                (0..3).map(|e| u32::from(twins[e].2) << e).sum(),
            ],
        }
    }
}

/// `∂p/∂u`, `∂p/∂v`, `∂n/∂u`, `∂n/∂v` across a triangle from its corners' positions, normals and
/// texture coordinates; zero where the coordinates are degenerate.
fn derivatives(p: [Vec3; 3], n: [Vec3; 3], uv: [Vec2; 3]) -> [Vec3; 4] {
    let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = d1.x * d2.y - d1.y * d2.x;
    if !(det.abs() > 1e-12) {
        return [Vec3::ZERO; 4];
    }
    let along = |v: [Vec3; 3]| {
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        ((e1 * d2.y - e2 * d1.y) / det, (e2 * d1.x - e1 * d2.x) / det)
    };
    let ((pu, pv), (nu, nv)) = (along(p), along(n));
    let all = [pu, pv, nu, nv];
    if all.iter().all(|v| v.is_finite()) { all } else { [Vec3::ZERO; 4] }
}

/// The welded point `members` moved by their mean height along their mean normal
/// ([`welded_mean`], the uniform mesh's rule).
fn moved_point(
    members: &[usize],
    (positions, normals, uvs): (&[Vec3], &[Vec3], &[Vec2]),
    field: &dyn HeightField,
    k: f32,
) -> Vec3 {
    let at = positions[members[0]];
    let Some((height, normal)) = welded_mean(members, (normals, uvs), field) else { return at };
    let offset = k * height * normal;
    at + if offset.is_finite() { offset } else { Vec3::ZERO }
}

/// A patch's corners, normals and texture coordinates as vectors.
fn corners_of(patch: &GpuPatch) -> ([Vec3; 3], [Vec3; 3], [Vec2; 3]) {
    let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
    let [a, b] = patch.uvs;
    (
        patch.corners.map(v3),
        patch.normals.map(v3),
        [Vec2::new(a[0], a[1]), Vec2::new(a[2], a[3]), Vec2::new(b[0], b[1])],
    )
}

/// `f` where it is a number, 0 elsewhere (a height map's NaN texel moves nothing).
fn height(field: &dyn HeightField, uv: Vec2) -> f32 {
    let f = field.height(uv);
    if f.is_finite() { f } else { 0.0 }
}

/// Grid point `(a, b)` of `patch` split `n` ways with edge levels `edges`, on the displaced
/// surface: its position, the displaced surface's normal and its texture coordinates (WGSL twin:
/// `surface_point` in `shaders/tessellation.wgsl`).
fn point(
    patch: &GpuPatch,
    k: f32,
    (n, edges): (u32, [u32; 3]),
    (a, b): (u32, u32),
    field: &dyn HeightField,
) -> (Vec3, Vec3, Vec2) {
    let (corners, normals, uvs) = corners_of(patch);
    let mix = |w: Vec3, v: [Vec3; 3]| v[0] * w.x + v[1] * w.y + v[2] * w.z;
    let at = grid_point(n, edges, a, b);
    // The point's own weights of the corners (an edge point's after snapping).
    let weights = match at {
        GridPoint::Corner(c) => Vec3::AXES[c],
        GridPoint::Edge { edge, step: s } => {
            let t = s as f32 / edges[edge] as f32;
            let mut w = Vec3::ZERO;
            w[edge] = 1.0 - t;
            w[(edge + 1) % 3] = t;
            w
        }
        GridPoint::Interior => Vec3::new((n - a - b) as f32, a as f32, b as f32) / n as f32,
    };
    let uv = uvs[0] * weights.x + uvs[1] * weights.y + uvs[2] * weights.z;
    let normal = mix(weights, normals).normalize_or_zero();
    let position = match at {
        GridPoint::Corner(c) => Vec3::from_slice(&patch.moved[c][..3]),
        GridPoint::Edge { edge, step: s } => edge_point(patch, k, edge, (s, edges[edge]), field),
        GridPoint::Interior => mix(weights, corners) + k * height(field, uv) * normal,
    };
    (position, surface_normal(patch, (k, n), (uv, normal), field), uv)
}

/// Step `s` of `level` along `patch`'s edge `edge` (from its own first corner), displaced:
/// computed from the end with the smaller welded number, by the mean of both sides' heights along
/// the mean of both sides' normals, the side of the smaller patch first: the neighbour computes
/// the same sums of the same numbers in the same order, and makes the same bits.
fn edge_point(patch: &GpuPatch, k: f32, edge: usize, (s, level): (u32, u32), field: &dyn HeightField) -> Vec3 {
    let (corners, normals, uvs) = corners_of(patch);
    let ends = [edge, (edge + 1) % 3];
    let twin_uvs = [edge].map(|e| patch.twin_uvs[e]).map(|v| [Vec2::new(v[0], v[1]), Vec2::new(v[2], v[3])])[0];
    let twin_normals = [2 * edge, 2 * edge + 1].map(|i| Vec3::from_slice(&patch.twin_normals[i][..3]));
    let (from, to, steps) = if patch.groups[ends[0]] <= patch.groups[ends[1]] { (0, 1, s) } else { (1, 0, level - s) };
    if steps == 0 || steps == level {
        let corner = if steps == 0 { ends[from] } else { ends[to] };
        return Vec3::from_slice(&patch.moved[corner][..3]);
    }
    let t = steps as f32 / level as f32;
    let (p, q) = (ends[from], ends[to]);
    let own = (uvs[p].lerp(uvs[q], t), normals[p].lerp(normals[q], t));
    let theirs = (twin_uvs[from].lerp(twin_uvs[to], t), twin_normals[from].lerp(twin_normals[to], t));
    let sides = if patch.groups[3] >> edge & 1 == 1 { [theirs, own] } else { [own, theirs] };
    let (mut sum, mut normal) = (0.0, Vec3::ZERO);
    for (uv, n) in sides {
        sum += height(field, uv);
        normal += n;
    }
    corners[p].lerp(corners[q], t) + k * (sum * 0.5) * normal.normalize_or_zero()
}

/// The displaced surface's unit normal at `uv`, where the undisplaced surface's is `normal`, as
/// the mesh's own normals are made: the area-weighted normal of the six grid triangles around the
/// point, the grid (spacing: the triangle's split `n` ways) laid on the smooth surface's tangent
/// plane (the triangle's `t_u`, `t_v` made tangent to it, else the undisplaced mesh's facets would
/// show), each neighbour moved by `k·f` along the normal, which turns as `∂n/∂u`, `∂n/∂v` say;
/// the undisplaced normal where the patch has no tangents.
fn surface_normal(patch: &GpuPatch, (k, n): (f32, u32), (uv, normal): (Vec2, Vec3), field: &dyn HeightField) -> Vec3 {
    let [flat_u, flat_v, nu, nv] = patch.derivatives.map(|v| Vec3::from_slice(&v[..3]));
    if flat_u == Vec3::ZERO && flat_v == Vec3::ZERO {
        return normal;
    }
    let (tu, tv) = (flat_u - flat_u.dot(normal) * normal, flat_v - flat_v.dot(normal) * normal);
    let (_, _, uvs) = corners_of(patch);
    let (along_a, along_b) = ((uvs[1] - uvs[0]) / n as f32, (uvs[2] - uvs[0]) / n as f32);
    let centre = k * height(field, uv) * normal;
    let around = [(1.0, 0.0), (0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0), (0.0, -1.0), (1.0, -1.0), (1.0, 0.0)];
    let moved: Vec<Vec3> = around
        .iter()
        .map(|&(a, b)| {
            let d = a * along_a + b * along_b;
            tu * d.x + tv * d.y + k * height(field, uv + d) * (normal + nu * d.x + nv * d.y) - centre
        })
        .collect();
    let sum: Vec3 = moved.windows(2).map(|w| w[0].cross(w[1])).sum();
    let oriented = if sum.dot(normal) < 0.0 { -sum } else { sum };
    oriented.try_normalize().unwrap_or(normal)
}
