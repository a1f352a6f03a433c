//! Displacement mapping (docs/course/04-bump-mapping.md, seed 004's "texturas de deslocamentos"):
//! the height field that bump mapping reads only for its slope moves the surface itself,
//! `p' = p + k·f(u, v)·n`, so the silhouette, the self-shadows and what hides what are the
//! displaced surface's.
//!
//! What it teaches, and how it is built (by hand: this is the technique):
//!
//! - **The same `k` as bump mapping.** Bump mapping perturbs the normal as if the surface were
//!   `p + k·f·n` with true-length tangents `∂p/∂u`, `∂p/∂v` in world units; the displacement is
//!   that surface, moved in world units too (`k` is `bump_scale × bump.scale`), so the two differ
//!   only in what bump mapping leaves out.
//! - **Pre-tessellation** (pbrt's way): each triangle of the object's mesh is split into `n²`
//!   triangles, `n` chosen so that no new edge spans more than `bump.displacement_texels` steps
//!   of the height field (a texel of a height map), at most [`MAX_TRIANGLES`] in all (the level
//!   that bound forces is reported). Both renderers draw the same triangles, so the rasterizer and
//!   the tracer meet on one displaced surface, and shadows, mirrors, cubes and the hybrid see it
//!   as any mesh.
//! - **No cracks.** A point on an edge is computed from the edge's two ends in one order (the
//!   end with the smaller position first), so the two triangles that share the edge, and the two
//!   sides of a texture seam, make it bit for bit. Points at one position (a seam, a pole, a
//!   cube's corner) are moved together: by their mean height, along their mean normal. Where a
//!   height map does not tile, that mean is the seam's documented fallback.
//! - **The displaced surface's normals**: each vertex's is the area-weighted mean of the normals
//!   of the displaced triangles around it (around every vertex at its position with its original
//!   normal: a cube's faces keep their edges).

use std::collections::HashMap;

use glam::{Mat4, Vec2, Vec3};

use super::height::{HeightField, TextureHeight, with_material_field};
use crate::scene::{DisplacedSurface, Material, Mesh, Scene, Shape};
use crate::settings::{BumpMethod, RenderSettings};

/// The most triangles the displaced meshes of one scene may have together: about 100 MB of
/// vertices and indices on the GPU, and a BVH the tracer builds in seconds.
pub const MAX_TRIANGLES: usize = 2_000_000;

/// The largest subdivision of one triangle (`n`: `n²` triangles from one).
pub const MAX_LEVEL: u32 = 64;

/// What [`displace`] did to a scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Displaced {
    /// Per displaced object: its name, the subdivision `n` it was given and the one its height
    /// field asked for (they differ where [`MAX_TRIANGLES`] forced a coarser level).
    pub objects: Vec<(String, u32, u32)>,
    /// The displaced meshes' triangles, all together.
    pub triangles: usize,
}

impl Displaced {
    /// A line for `--stats` and the viewer: what was displaced, and any level the bound forced.
    pub fn summary(&self) -> Option<String> {
        if self.objects.is_empty() {
            return None;
        }
        let forced: Vec<String> = self
            .objects
            .iter()
            .filter(|(_, level, wanted)| level < wanted)
            .map(|(name, level, wanted)| format!("`{name}` at level {level} (its height field asks {wanted})"))
            .collect();
        let mut line = format!("displacement: {} objects, {} triangles", self.objects.len(), thousands(self.triangles));
        if !forced.is_empty() {
            line.push_str(&format!(
                "; the bound of {} triangles forced {}",
                thousands(MAX_TRIANGLES),
                forced.join(", ")
            ));
        }
        Some(line)
    }
}

fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Whether `settings` ask for displaced geometry: `bump.method = "displacement"`, or the hybrid's
/// relief swapped for it (`hybrid.relief`, the approximations table's row).
pub fn wanted(settings: &RenderSettings) -> bool {
    settings.bump.enabled && (settings.bump.method == BumpMethod::Displacement || settings.hybrid.relief)
}

/// `scene` with its height fields displaced whatever its settings say: the surface bump and
/// parallax mapping stand for, which the error budget's reference is traced on.
pub fn displaced(scene: &Scene) -> Scene {
    let mut displaced = scene.clone();
    displaced.settings.bump.method = BumpMethod::Displacement;
    displace(&mut displaced);
    displaced.settings = scene.settings.clone();
    displaced
}

/// Makes every object whose material has a height field (a `height_map` or a `height_field`)
/// a mesh of its displaced surface, when the scene's settings ask for displacement
/// (`bump.method = "displacement"`); its material, a copy without the height field (the normals
/// are the geometry's now). Nothing changes otherwise. Both renderers then draw the same
/// triangles.
pub fn displace(scene: &mut Scene) -> Displaced {
    let settings = scene.settings.bump;
    let mut report = Displaced::default();
    if !wanted(&scene.settings) {
        return report;
    }
    let displaced: Vec<usize> =
        (0..scene.objects.len()).filter(|&i| has_height(&scene.materials[scene.objects[i].material.0])).collect();
    // Each object's mesh and the level its field asks for, then the levels the bound allows.
    let planned: Vec<(Mesh, u32)> = displaced
        .iter()
        .map(|&i| {
            let object = &scene.objects[i];
            let mesh = scene.tessellate(object).into_owned();
            let material = &scene.materials[object.material.0];
            let level = with_field(scene, material, |field| level_for(&mesh, field, settings.displacement_texels));
            (mesh, level.unwrap_or(1))
        })
        .collect();
    let levels = bounded_levels(&planned);
    let mut plain_material: HashMap<usize, usize> = HashMap::new();
    for ((&index, (mesh, wanted_level)), level) in displaced.iter().zip(&planned).zip(levels) {
        let object = &scene.objects[index];
        let material = &scene.materials[object.material.0];
        let k = material.bump_scale * settings.scale;
        let world_from_local = object.world_from_local;
        let moved = with_field(scene, material, |field| displaced_mesh(mesh, field, k, world_from_local, level));
        let Some(moved) = moved else { continue };
        report.triangles += moved.indices.len() / 3;
        report.objects.push((object.name.clone(), level, *wanted_level));
        let old_material = object.material.0;
        let new_material = *plain_material.entry(old_material).or_insert_with(|| {
            let mut plain: Material = scene.materials[old_material].clone();
            plain.height_map = None;
            plain.height_field = None;
            scene.materials.push(plain);
            scene.materials.len() - 1
        });
        scene.meshes.push(moved);
        scene.displaced.push(DisplacedSurface { object: index, material: old_material, base: mesh.clone(), k });
        let object = &mut scene.objects[index];
        object.shape = Shape::Mesh(scene.meshes.len() - 1);
        object.material = crate::base::MaterialId(new_material);
    }
    report
}

/// Whether `material` has a height field for bump mapping (or displacement).
fn has_height(material: &Material) -> bool {
    material.height_field.is_some() || material.height_map.is_some()
}

/// `f` of `material`'s height field: its procedural one, or its height map read as the tracer
/// reads it (level 0, bilinear, repeat).
pub(crate) fn with_field<T>(scene: &Scene, material: &Material, f: impl FnOnce(&dyn HeightField) -> T) -> Option<T> {
    let map = material.height_map.and_then(|id| scene.textures.get(id.0)).map(TextureHeight::new);
    with_material_field(material, map.as_ref(), f)
}

/// The subdivision `n` that keeps every new edge within `texels` steps of `field` (its
/// `default_delta`, a texel of a height map) in texture coordinates, at most [`MAX_LEVEL`].
pub fn level_for(mesh: &Mesh, field: &dyn HeightField, texels: f32) -> u32 {
    let step = field.default_delta() * texels.max(1e-3);
    let mut longest: f32 = 0.0;
    for t in mesh.indices.chunks_exact(3) {
        let uv = |i: u32| mesh.uvs.get(i as usize).copied().unwrap_or(Vec2::ZERO);
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let d = ((uv(a) - uv(b)) / step).abs();
            longest = longest.max(d.x.max(d.y));
        }
    }
    if !longest.is_finite() {
        return 1;
    }
    (longest.ceil() as u32).clamp(1, MAX_LEVEL)
}

/// Each planned mesh's level, lowered evenly (the finest first) until all of them together have
/// at most [`MAX_TRIANGLES`] triangles.
fn bounded_levels(planned: &[(Mesh, u32)]) -> Vec<u32> {
    let mut levels: Vec<u32> = planned.iter().map(|(_, level)| *level).collect();
    let triangles = |levels: &[u32]| -> usize {
        planned.iter().zip(levels).map(|((mesh, _), &n)| mesh.indices.len() / 3 * (n as usize).pow(2)).sum()
    };
    while triangles(&levels) > MAX_TRIANGLES {
        let Some(finest) = levels.iter_mut().filter(|n| **n > 1).max_by_key(|n| **n) else { break };
        *finest -= 1;
    }
    levels
}

/// `mesh` (in its object's coordinates, placed by `world_from_local`) split `n × n` per triangle
/// and displaced by `k·f(u, v)` along its normals, in world units; its normals the displaced
/// surface's.
pub fn displaced_mesh(mesh: &Mesh, field: &dyn HeightField, k: f32, world_from_local: Mat4, n: u32) -> Mesh {
    let mut split = subdivided(mesh, n.max(1));
    let local_from_world = world_from_local.inverse();
    let normal_from_local = glam::Mat3::from_mat4(world_from_local).inverse().transpose();
    // Every vertex at one position moves alike: by the mean height, along the mean normal.
    for members in welded(&split.positions) {
        let Some((height, normal)) = welded_mean(&members, (&split.normals, &split.uvs), field) else { continue };
        let world_normal = (normal_from_local * normal).normalize_or_zero();
        let offset = local_from_world.transform_vector3(k * height * world_normal);
        let moved = split.positions[members[0]] + if offset.is_finite() { offset } else { Vec3::ZERO };
        for &i in &members {
            split.positions[i] = moved;
        }
    }
    split.normals = displaced_normals(&split);
    split.tangents.clear();
    split
}

/// The mean height of the vertices `members` (at one point: a seam's, a pole's, a box's corner's)
/// and the unit mean of their normals, along which they move together; `None` where the normals
/// cancel. A height that is not a number counts as 0.
pub(crate) fn welded_mean(
    members: &[usize],
    (normals, uvs): (&[Vec3], &[Vec2]),
    field: &dyn HeightField,
) -> Option<(f32, Vec3)> {
    let (mut height, mut normal) = (0.0, Vec3::ZERO);
    for &i in members {
        let f = field.height(uvs[i]);
        height += if f.is_finite() { f } else { 0.0 };
        normal += normals[i];
    }
    Some((height / members.len() as f32, normal.try_normalize()?))
}

/// The vertices at one point, as groups of indices: within a millionth of the mesh's size of
/// each other (a sphere's seam is computed at `φ = 0` and `φ = 2π`, whose sines differ by 10⁻⁷),
/// found through a grid of cells of that size and their neighbours.
pub(crate) fn welded(positions: &[Vec3]) -> Vec<Vec<usize>> {
    let (low, high) = positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| (l.min(*p), h.max(*p)));
    let extent = (high - low).max_element();
    let epsilon = if extent.is_finite() && extent > 0.0 { extent * 1e-6 } else { f32::MIN_POSITIVE };
    let cell = |p: Vec3| ((p - low) / (4.0 * epsilon)).floor().as_ivec3();
    let mut cells: HashMap<glam::IVec3, Vec<usize>> = HashMap::new();
    let mut group_of = vec![usize::MAX; positions.len()];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, &p) in positions.iter().enumerate() {
        let home = cell(p);
        let mut found = None;
        'search: for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(near) = cells.get(&(home + glam::IVec3::new(dx, dy, dz))) else { continue };
                    if let Some(&j) = near.iter().find(|&&j| positions[j].distance(p) <= epsilon) {
                        found = Some(group_of[j]);
                        break 'search;
                    }
                }
            }
        }
        let group = found.unwrap_or_else(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[group].push(i);
        group_of[i] = group;
        cells.entry(home).or_default().push(i);
    }
    groups
}

/// The bits of a position: equal for the same point computed the same way.
fn position_key(p: Vec3) -> [u32; 3] {
    // -0.0 and 0.0 are one point.
    (p + Vec3::ZERO).to_array().map(f32::to_bits)
}

/// The vertices grouped by `key`, each group in index order.
fn groups_by<K: std::hash::Hash + Eq>(items: &[Vec3], key: impl Fn(&Vec3) -> K) -> HashMap<K, Vec<usize>> {
    let mut groups: HashMap<K, Vec<usize>> = HashMap::new();
    for (i, item) in items.iter().enumerate() {
        groups.entry(key(item)).or_default().push(i);
    }
    groups
}

/// The area-weighted mean of the triangles' normals around each vertex, over every vertex at
/// its position that had its original normal (so a cube's faces keep their edges).
fn displaced_normals(mesh: &Mesh) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; mesh.positions.len()];
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        let (pa, pb, pc) = (mesh.positions[a], mesh.positions[b], mesh.positions[c]);
        // Twice the area, along the face normal.
        let face = (pb - pa).cross(pc - pa);
        if face.is_finite() {
            for i in [a, b, c] {
                sums[i] += face;
            }
        }
    }
    // Around one point, the vertices whose original normals agree (within about 8°) share their
    // sums: a seam's two sides do, a cube's faces do not.
    let mut normals = mesh.normals.clone();
    for members in groups_by(&mesh.positions, |p| position_key(*p)).into_values() {
        let mut clusters: Vec<(Vec3, Vec3, Vec<usize>)> = Vec::new();
        for i in members {
            let original = mesh.normals[i];
            match clusters.iter_mut().find(|(first, ..)| first.dot(original) > 0.99) {
                Some((_, sum, indices)) => {
                    *sum += sums[i];
                    indices.push(i);
                }
                None => clusters.push((original, sums[i], vec![i])),
            }
        }
        for (original, sum, indices) in clusters {
            let normal = sum.try_normalize().unwrap_or(original);
            for i in indices {
                normals[i] = normal;
            }
        }
    }
    normals
}

/// `mesh` with each triangle split into `n²`: the points `(a, b)` of a triangular grid, `a + b ≤
/// n`. A point on an edge is made once for the mesh, from the edge's two ends in one order, so
/// the triangles on either side of the edge share it. Its normals and texture coordinates are
/// interpolated; missing normals are the faces'.
pub fn subdivided(mesh: &Mesh, n: u32) -> Mesh {
    let normals = if mesh.normals.len() == mesh.positions.len() { mesh.normals.clone() } else { face_normals(mesh) };
    let uvs: Vec<Vec2> = (0..mesh.positions.len()).map(|i| mesh.uvs.get(i).copied().unwrap_or(Vec2::ZERO)).collect();
    let mut out = Mesh {
        name: format!("{} (displaced)", mesh.name),
        positions: mesh.positions.clone(),
        normals,
        uvs,
        tangents: Vec::new(),
        indices: Vec::new(),
    };
    let mut edges: HashMap<(u32, u32, u32), u32> = HashMap::new();
    for t in mesh.indices.chunks_exact(3) {
        let corners = [t[0], t[1], t[2]];
        if corners.iter().any(|&i| i as usize >= mesh.positions.len()) {
            continue;
        }
        // The grid's vertex indices, row b by column a.
        let mut grid = vec![0u32; ((n + 1) * (n + 2) / 2) as usize];
        let at = |a: u32, b: u32| (b * (n + 1) - b * (b.saturating_sub(1)) / 2 + a) as usize;
        for b in 0..=n {
            for a in 0..=(n - b) {
                grid[at(a, b)] = grid_vertex(&mut out, &mut edges, corners, (a, b), n);
            }
        }
        for b in 0..n {
            for a in 0..(n - b) {
                out.indices.extend([grid[at(a, b)], grid[at(a + 1, b)], grid[at(a, b + 1)]]);
                if a + b + 1 < n {
                    out.indices.extend([grid[at(a + 1, b)], grid[at(a + 1, b + 1)], grid[at(a, b + 1)]]);
                }
            }
        }
    }
    out
}

/// The vertex at grid point `(a, b)` of the triangle `corners` split `n` ways: a corner, a point
/// of an edge (made once per edge), or a new interior point.
fn grid_vertex(
    out: &mut Mesh,
    edges: &mut HashMap<(u32, u32, u32), u32>,
    [i0, i1, i2]: [u32; 3],
    (a, b): (u32, u32),
    n: u32,
) -> u32 {
    let c = n - a - b;
    // On an edge: the two ends and the steps from the first.
    let edge = match (a, b, c) {
        (_, 0, 0) => return i1,
        (0, _, 0) => return i2,
        (0, 0, _) => return i0,
        (_, 0, _) => Some((i0, i1, a)),
        (0, _, _) => Some((i0, i2, b)),
        (_, _, 0) => Some((i1, i2, b)),
        _ => None,
    };
    if let Some((p, q, steps)) = edge {
        let (first, second, steps) = if p < q { (p, q, steps) } else { (q, p, n - steps) };
        if let Some(&vertex) = edges.get(&(first, second, steps)) {
            return vertex;
        }
        let vertex = push_on_edge(out, (first, second), steps, n);
        edges.insert((first, second, steps), vertex);
        return vertex;
    }
    let w = Vec3::new(c as f32, a as f32, b as f32) / n as f32;
    let mix3 = |v: [Vec3; 3]| v[0] * w.x + v[1] * w.y + v[2] * w.z;
    let [p, q, r] = [i0, i1, i2].map(|i| i as usize);
    let position = mix3([out.positions[p], out.positions[q], out.positions[r]]);
    let normal = mix3([out.normals[p], out.normals[q], out.normals[r]]).normalize_or_zero();
    let uv = out.uvs[p] * w.x + out.uvs[q] * w.y + out.uvs[r] * w.z;
    push(out, position, normal, uv)
}

/// A point `steps` of `n` along the edge `(p, q)`, computed from the end with the smaller
/// position: the same bits wherever two vertices at those positions meet (a seam).
fn push_on_edge(out: &mut Mesh, (p, q): (u32, u32), steps: u32, n: u32) -> u32 {
    let (p, q) = (p as usize, q as usize);
    let smaller = |x: Vec3, y: Vec3| x.to_array() <= y.to_array();
    let (from, to, t) = if smaller(out.positions[p], out.positions[q]) {
        (p, q, steps as f32 / n as f32)
    } else {
        (q, p, (n - steps) as f32 / n as f32)
    };
    let position = out.positions[from].lerp(out.positions[to], t);
    let normal = out.normals[from].lerp(out.normals[to], t).normalize_or_zero();
    let uv = out.uvs[from].lerp(out.uvs[to], t);
    push(out, position, normal, uv)
}

fn push(out: &mut Mesh, position: Vec3, normal: Vec3, uv: Vec2) -> u32 {
    out.positions.push(position);
    out.normals.push(normal);
    out.uvs.push(uv);
    (out.positions.len() - 1) as u32
}

/// Each vertex's normal from the faces around it, for a mesh that has none.
pub(crate) fn face_normals(mesh: &Mesh) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; mesh.positions.len()];
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        if [a, b, c].iter().any(|&i| i >= mesh.positions.len()) {
            continue;
        }
        let face = (mesh.positions[b] - mesh.positions[a]).cross(mesh.positions[c] - mesh.positions[a]);
        for i in [a, b, c] {
            sums[i] += face;
        }
    }
    sums.into_iter().map(|s| s.try_normalize().unwrap_or(Vec3::Y)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::height::SineField;

    fn flat(amplitude: f32) -> SineField {
        SineField { amplitude, frequency: Vec2::new(2.0, 2.0) }
    }

    /// `f = u`: a field that does not tile.
    struct Ramp;
    impl HeightField for Ramp {
        fn height(&self, uv: Vec2) -> f32 {
            uv.x
        }
        fn default_delta(&self) -> Vec2 {
            Vec2::splat(0.01)
        }
        fn range(&self) -> (f32, f32) {
            (0.0, 1.0)
        }
    }

    /// The edges of `mesh` (by their ends' positions) not met by exactly two triangles; a pole's
    /// degenerate triangles left out.
    fn open_edges(mesh: &Mesh) -> usize {
        let mut edges: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
        for t in mesh.indices.chunks_exact(3) {
            let p = [t[0], t[1], t[2]].map(|i| position_key(mesh.positions[i as usize]));
            if p[0] == p[1] || p[1] == p[2] || p[0] == p[2] {
                continue;
            }
            for (a, b) in [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])] {
                *edges.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
            }
        }
        edges.values().filter(|&&count| count != 2).count()
    }

    #[test]
    fn a_split_triangle_has_n_squared_triangles_and_shares_its_edges() {
        let mesh = Mesh::plane(Vec2::new(2.0, 2.0), Vec2::ONE);
        let split = subdivided(&mesh, 4);
        assert_eq!(split.indices.len() / 3, 2 * 16);
        // Two triangles of 15 grid points each share their diagonal's 5: 25 vertices.
        assert_eq!(split.positions.len(), 25, "{}", split.positions.len());
        // Every triangle keeps the original winding: its normal is the plane's.
        for t in split.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| split.positions[i as usize]);
            assert!((b - a).cross(c - a).normalize().dot(mesh.normals[0]) > 0.999);
        }
    }

    #[test]
    fn a_displaced_sphere_is_closed_and_moved_by_k_f() {
        let sphere = Mesh::sphere(Vec3::ZERO, 1.0, 16);
        let field = flat(1.0);
        let moved = displaced_mesh(&sphere, &field, 0.1, Mat4::IDENTITY, 3);
        let split = subdivided(&sphere, 3);
        assert_eq!(moved.positions.len(), split.positions.len());
        // Every point is moved 0.1·f(u, v) along its normal (f averaged where several meet: the
        // seam, and the poles' edges, one per slice, all from the one pole point).
        let mut shared = vec![1; split.positions.len()];
        for group in welded(&split.positions) {
            for &i in &group {
                shared[i] = group.len();
            }
        }
        for (i, &uv) in split.uvs.iter().enumerate() {
            if shared[i] > 1 {
                continue;
            }
            let expected = split.positions[i] + 0.1 * field.height(uv) * split.normals[i];
            assert!(moved.positions[i].distance(expected) < 1e-5, "{i}: {} against {expected}", moved.positions[i]);
        }
        assert_eq!(open_edges(&moved), 0, "the displaced sphere is closed");
        // A height field that does not tile (f = u: 0 on one side of the seam, 1 on the other):
        // the seam's two sides move by their mean, and the sphere stays closed.
        let moved = displaced_mesh(&sphere, &Ramp, 0.1, Mat4::IDENTITY, 3);
        assert_eq!(open_edges(&moved), 0, "a seam of a field that does not tile is closed");
    }

    /// Bad input: a mesh without texture coordinates or normals, with a degenerate triangle and
    /// an index out of range: displaced without a panic, every position and normal finite (no
    /// coordinates: a constant height, the mesh moved along its faces' normals).
    #[test]
    fn a_mesh_without_uvs_or_normals_and_with_degenerate_triangles_is_displaced() {
        let mesh = Mesh {
            name: "bare".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Y, Vec3::new(2.0, 0.0, 0.0)],
            normals: Vec::new(),
            uvs: Vec::new(),
            tangents: Vec::new(),
            // A good triangle, one with two corners at one point, one on a line, one out of range.
            indices: vec![0, 1, 2, 0, 2, 3, 0, 1, 4, 0, 1, 9],
        };
        let moved = displaced_mesh(&mesh, &flat(1.0), 0.1, Mat4::IDENTITY, 3);
        assert!(moved.positions.iter().chain(&moved.normals).all(|v| v.is_finite()));
        assert_eq!(moved.positions.len(), moved.normals.len());
        assert!(moved.indices.iter().all(|&i| (i as usize) < moved.positions.len()));
        // The out-of-range triangle is left out; the other three are split 9 ways each.
        assert_eq!(moved.indices.len() / 3, 3 * 9);
    }

    #[test]
    fn the_level_follows_the_height_fields_step_and_the_bound() {
        let plane = Mesh::plane(Vec2::new(2.0, 2.0), Vec2::new(4.0, 4.0));
        // A sine of frequency 2 steps a 64th of its period: 1/128 of texture coordinate; plane's
        // uv edges are 4 long (the diagonal's too, per axis): 4·128/8 = 64 at 8 steps an edge.
        assert_eq!(level_for(&plane, &flat(1.0), 8.0), 64);
        assert_eq!(level_for(&plane, &flat(1.0), 16.0), 32);
        let levels = bounded_levels(&[(plane.clone(), 64), (plane, 8)]);
        let total: usize = levels.iter().map(|&n| 2 * (n as usize).pow(2)).sum();
        assert!(total <= MAX_TRIANGLES && levels == [64, 8], "{levels:?}");
        let many = Mesh::sphere(Vec3::ZERO, 1.0, 192);
        let levels = bounded_levels(&[(many, 64)]);
        assert!(levels[0] < 64 && levels[0] >= 1, "{levels:?}");
    }
}
