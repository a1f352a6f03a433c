//! The scene's geometry as the rasterizer draws it: each distinct mesh once, every object an
//! instance of one, and the draw list of instanced calls.
//!
//! - **Shared meshes.** Spheres are instances of one unit sphere per tessellation, placed by
//!   `world_from_local · translate(center) · scale(radius)`; other shapes share a mesh with every
//!   object of identical shape; a file's mesh is shared by every node that uses it. Two thousand
//!   spheres are one mesh in memory, not two thousand.
//! - **Tessellation by size on screen.** A polygon with `n` sides inscribed in a circle of `R`
//!   pixels departs from it by at most `R·(1 − cos(π/n)) ≈ R·π²/2n²`; keeping that under a
//!   sixteenth of a pixel needs `n ≥ π·√(8R)`. (A quarter pixel was not enough: silhouettes held,
//!   but the facets' flat shading positions cost seed-simple 20 dB of PSNR against the tracer.) Curved analytic shapes get the smallest level of
//!   [`SEGMENT_LEVELS`] that does, at most `sphere_segments`, so a far sphere costs tens of
//!   triangles and a near one what the setting allows.
//! - **Instanced draws.** Objects are sorted by (transparency, material, mesh), and each run of
//!   equal keys is one `draw_indexed` over a range of the instance buffer. Transparent objects
//!   are also listed one by one, in the scene's order: their drawing order is the transparency
//!   technique's to choose.

use std::collections::HashMap;
use std::ops::Range;

use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

use super::uniforms::{ENV_LAYER_NONE, ENV_LAYER_WORLD, GpuInstance, Vertex};
use crate::scene::{Camera, Mesh, Object, Projection, Scene, Shape};
use crate::texture::tangents::tangents_or_generate;

/// The tessellations curved shapes choose from.
pub const SEGMENT_LEVELS: [u32; 10] = [8, 12, 16, 24, 32, 48, 64, 96, 128, 192];

/// What makes two objects' meshes the same.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MeshKey {
    /// The unit sphere at the origin, with this many slices.
    Sphere(u32),
    /// Shapes that have no unit form share a mesh with identical shapes: their parameters' bits.
    Cuboid([u32; 6]),
    Plane([u32; 4]),
    Torus([u32; 2], u32),
    RoundedBox([u32; 4], u32),
    /// `Scene::meshes[i]`.
    File(usize),
    /// The displaced surface of object `i`, tessellated on the GPU for this frame's view, in
    /// world coordinates (`crate::raster::tessellation`).
    Displaced(usize),
}

/// The mesh an object is an instance of, at `segments`, and the transform from that mesh to the
/// world.
pub fn instance_of(object: &Object, segments: u32) -> (MeshKey, Mat4) {
    let bits = |v: &[f32]| -> Vec<u32> { v.iter().map(|x| x.to_bits()).collect() };
    let key = match object.shape {
        Shape::Sphere { center, radius } => {
            let placed =
                object.world_from_local * Mat4::from_translation(center) * Mat4::from_scale(Vec3::splat(radius));
            return (MeshKey::Sphere(segments), placed);
        }
        Shape::Cuboid { min, max } => {
            MeshKey::Cuboid(bits(&[min.x, min.y, min.z, max.x, max.y, max.z]).try_into().expect("six values"))
        }
        Shape::Plane { size, uv_scale } => {
            MeshKey::Plane(bits(&[size.x, size.y, uv_scale.x, uv_scale.y]).try_into().expect("four values"))
        }
        Shape::Torus { major, minor } => MeshKey::Torus(bits(&[major, minor]).try_into().expect("two"), segments),
        Shape::RoundedBox { half, radius } => {
            MeshKey::RoundedBox(bits(&[half.x, half.y, half.z, radius]).try_into().expect("four"), segments)
        }
        Shape::Mesh(index) => MeshKey::File(index),
    };
    (key, object.world_from_local)
}

/// The triangles of a mesh key, in the mesh's own coordinates.
pub fn build_mesh(scene: &Scene, key: MeshKey) -> std::borrow::Cow<'_, Mesh> {
    use std::borrow::Cow;
    let f = f32::from_bits;
    match key {
        MeshKey::Sphere(segments) => Cow::Owned(Mesh::sphere(Vec3::ZERO, 1.0, segments)),
        MeshKey::Cuboid(b) => {
            Cow::Owned(Mesh::cuboid(Vec3::new(f(b[0]), f(b[1]), f(b[2])), Vec3::new(f(b[3]), f(b[4]), f(b[5]))))
        }
        MeshKey::Plane(b) => {
            Cow::Owned(Mesh::plane(glam::Vec2::new(f(b[0]), f(b[1])), glam::Vec2::new(f(b[2]), f(b[3]))))
        }
        MeshKey::Torus(b, segments) => Cow::Owned(Mesh::torus(f(b[0]), f(b[1]), segments)),
        MeshKey::RoundedBox(b, segments) => {
            Cow::Owned(Mesh::rounded_box(Vec3::new(f(b[0]), f(b[1]), f(b[2])), f(b[3]), segments))
        }
        MeshKey::File(index) => Cow::Borrowed(&scene.meshes[index]),
        // Made by the GPU; its uniform mesh where asked for here.
        MeshKey::Displaced(object) => scene.tessellate(&scene.objects[object]),
    }
}

/// The radius, in pixels, that a world-space sphere of `radius` at `center` covers on screen; a
/// very large number when the eye is inside it.
fn screen_radius(camera: &Camera, center: Vec3, radius: f32) -> f32 {
    let pixels_per_unit_at_one = camera.height as f32 / camera.window().1;
    match camera.projection {
        Projection::Orthographic => radius * pixels_per_unit_at_one,
        Projection::Perspective => {
            // window() is the window at the near plane; scale it to unit distance.
            let depth = (center - camera.eye).dot(-camera.frame().ze);
            if depth <= radius {
                return f32::MAX;
            }
            radius * pixels_per_unit_at_one * camera.near / depth
        }
    }
}

/// Segments for a curved shape whose bounding sphere covers `pixels` on screen: the smallest level
/// whose polygon stays within a sixteenth of a pixel of the circle, at most `max`.
pub fn segments_for_pixels(pixels: f32, max: u32) -> u32 {
    let needed = std::f32::consts::PI * (8.0 * pixels.max(0.0)).sqrt();
    SEGMENT_LEVELS.iter().copied().find(|&n| n as f32 >= needed).unwrap_or(u32::MAX).min(max)
}

/// The world-space bounding sphere of an object's shape: exact for a sphere, around its local box
/// for other shapes.
fn bounding_sphere(object: &Object, local: (Vec3, Vec3)) -> (Vec3, f32) {
    let scale = object.world_from_local.to_scale_rotation_translation().0.max_element();
    let (center, radius) = match object.shape {
        Shape::Sphere { center, radius } => (center, radius),
        _ => ((local.0 + local.1) / 2.0, (local.1 - local.0).length() / 2.0),
    };
    (object.world_from_local.transform_point3(center), radius * scale)
}

/// A mesh on the GPU.
pub struct GpuMesh {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub index_count: u32,
    /// The centre of the mesh's bounding box, in its own coordinates.
    pub centre: Vec3,
}

impl GpuMesh {
    fn upload(device: &wgpu::Device, label: &str, mesh: &Mesh) -> GpuMesh {
        // The file's tangents where it has them, MikkTSpace's otherwise (docs/course/04-bump-mapping.md's
        // per-vertex source).
        let existing = (!mesh.tangents.is_empty()).then_some(mesh.tangents.as_slice());
        let tangents = tangents_or_generate(mesh, existing);
        let vertices: Vec<Vertex> = (0..mesh.positions.len())
            .map(|i| Vertex {
                position: mesh.positions[i].to_array(),
                normal: mesh.normals[i].to_array(),
                uv: mesh.uvs[i].to_array(),
                tangent: tangents[i].to_array(),
            })
            .collect();
        GpuMesh {
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("geometry::vertices {label}")),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("geometry::indices {label}")),
                contents: bytemuck::cast_slice(&mesh.indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
            index_count: mesh.indices.len() as u32,
            centre: mesh_centre(mesh),
        }
    }
}

/// One instanced draw: objects of one material that share one mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    pub mesh: MeshKey,
    pub material: usize,
    /// The material lets light through (kt > 0): it tints shadows rather than casting them.
    pub transparent: bool,
    /// An object drawn alone (its index): a planar mirror, which shows its own reflection, or an
    /// object with its own environment cube, which is left out of its cube's views.
    pub alone: Option<usize>,
    /// The object drawn alone is a planar mirror.
    pub mirror: bool,
    pub instances: Range<u32>,
}

/// One object in the draw list: (transparent, material, drawn alone, mesh, instance, object
/// index, world from mesh).
type Entry = (bool, usize, Option<usize>, MeshKey, GpuInstance, usize, Mat4);

/// A transparent object, as the transparency pass draws it: alone, in an order of its choosing.
#[derive(Clone, Debug, PartialEq)]
pub struct TransparentObject {
    /// Index into `Scene::objects`.
    pub object: usize,
    pub mesh: MeshKey,
    pub material: usize,
    /// Its slot in the instance buffer.
    pub instance: u32,
    pub world_from_mesh: Mat4,
    /// The world-space centre of its bounding box, the key of sorting by object.
    pub centre: Vec3,
    /// Its transform mirrors (negative determinant): its triangles' winding flips.
    pub flipped: bool,
    /// Its material bends light (`Material::bends_light`): the refraction pass draws it when
    /// refraction is on.
    pub bends_light: bool,
}

/// Per object, what does not change while the scene stays: its material, and for curved shapes
/// the local bounds that size it on screen.
struct ObjectInfo {
    material: usize,
    transparent: bool,
    mirror: bool,
    /// Its layer among the dynamic environment cubes.
    env_layer: Option<u32>,
    curved_bounds: Option<(Vec3, Vec3)>,
}

/// The meshes, the instance buffer and the draw list of one scene.
pub struct SceneGeometry {
    objects: Vec<ObjectInfo>,
    meshes: HashMap<MeshKey, GpuMesh>,
    instances: Option<wgpu::Buffer>,
    /// The segments each object was last drawn with (0 for fixed shapes): the draw list is
    /// rebuilt only when one of them changes.
    segments: Vec<u32>,
    pub batches: Vec<Batch>,
    /// The transparent objects in the scene's order.
    pub transparent: Vec<TransparentObject>,
    /// A world-space box around everything, computed once.
    pub bounds: Option<(Vec3, Vec3)>,
    /// The draw list was built at least once.
    prepared: bool,
    /// The objects drawn from the GPU's adaptive tessellation (`MeshKey::Displaced`), and whether
    /// it changed since the draw list was made.
    displaced: Vec<usize>,
    displaced_changed: bool,
}

/// The name of one draw list: its instance buffer, made anew for every list (wgpu's handles
/// compare by identity). A new scene or a new tessellation is a new name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DrawListId(Option<wgpu::Buffer>);

impl SceneGeometry {
    /// The geometry of `scene`, in which the objects listed in `mirrors` are planar mirrors and
    /// `env_objects[k]` has the dynamic environment cube `k`.
    pub fn new(scene: &Scene, mirrors: &[usize], env_objects: &[usize]) -> SceneGeometry {
        let objects = scene
            .objects
            .iter()
            .enumerate()
            .map(|(index, object)| ObjectInfo {
                material: object.material.0,
                transparent: scene.materials[object.material.0].is_transparent(),
                mirror: mirrors.contains(&index),
                env_layer: env_objects.iter().position(|&o| o == index).map(|k| k as u32),
                curved_bounds: object.shape.curved_bounds(),
            })
            .collect();
        SceneGeometry {
            objects,
            meshes: HashMap::new(),
            instances: None,
            segments: Vec::new(),
            batches: Vec::new(),
            transparent: Vec::new(),
            bounds: scene.bounds(),
            prepared: false,
            displaced: Vec::new(),
            displaced_changed: false,
        }
    }

    /// Draws each listed object from its mesh made by the GPU (world coordinates) instead of its
    /// own; an empty list, every object from its own. The next [`Self::prepare`] makes a new draw
    /// list, so what was kept of the last (shadow maps) is made again.
    pub fn set_displaced(&mut self, meshes: Vec<(usize, GpuMesh)>) {
        if meshes.is_empty() && self.displaced.is_empty() {
            return;
        }
        self.displaced = meshes.iter().map(|(object, _)| *object).collect();
        for (object, mesh) in meshes {
            self.meshes.insert(MeshKey::Displaced(object), mesh);
        }
        self.displaced_changed = true;
    }

    /// Whether some object is drawn from the GPU's tessellation.
    pub fn has_displaced(&self) -> bool {
        !self.displaced.is_empty()
    }

    /// Chooses each curved shape's tessellation for `camera` (or `max_segments` everywhere when
    /// `adaptive` is off), uploads meshes not seen before, and rebuilds the draw list if anything
    /// changed. Returns whether it did.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        scene: &Scene,
        camera: &Camera,
        max_segments: u32,
        adaptive: bool,
    ) -> bool {
        let segments = self.segments_for(scene, camera, max_segments, adaptive);
        if segments == self.segments && self.prepared && !self.displaced_changed {
            return false;
        }
        self.displaced_changed = false;
        let entries = self.entries(scene, &segments);
        for (_, _, _, key, ..) in &entries {
            if !self.meshes.contains_key(key) {
                let mesh = build_mesh(scene, *key);
                self.meshes.insert(*key, GpuMesh::upload(device, &format!("{key:?}"), &mesh));
            }
        }
        self.batches = self.batches_of(&entries);
        self.transparent = self.transparent_of(scene, &entries);
        // A new buffer for every new list, never rewritten: the buffer names the list
        // ([`Self::draw_list`]).
        let data: Vec<GpuInstance> = entries.iter().map(|e| e.4).collect();
        self.instances = (!data.is_empty()).then(|| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("geometry::instances"),
                contents: bytemuck::cast_slice(&data),
                usage: wgpu::BufferUsages::VERTEX,
            })
        });
        self.segments = segments;
        self.prepared = true;
        true
    }

    /// The segments each object is tessellated with for `camera`: 0 for shapes that are not
    /// curved, `max_segments` when `adaptive` is off, else by the size of its bounding sphere on
    /// screen.
    fn segments_for(&self, scene: &Scene, camera: &Camera, max_segments: u32, adaptive: bool) -> Vec<u32> {
        scene
            .objects
            .iter()
            .zip(&self.objects)
            .map(|(object, info)| match info.curved_bounds {
                None => 0,
                Some(_) if !adaptive => max_segments,
                Some(local) => {
                    let (center, radius) = bounding_sphere(object, local);
                    segments_for_pixels(screen_radius(camera, center, radius), max_segments)
                }
            })
            .collect()
    }

    /// The draw list's entries, one per object tessellated with `segments`, sorted opaque first,
    /// then by material, object drawn alone and mesh: runs of equal keys become one draw.
    fn entries(&self, scene: &Scene, segments: &[u32]) -> Vec<Entry> {
        let mut entries: Vec<Entry> = scene
            .objects
            .iter()
            .zip(&self.objects)
            .zip(segments)
            .enumerate()
            .map(|(index, ((object, info), &n))| {
                let (key, world_from_mesh) = match self.displaced.contains(&index) {
                    true => (MeshKey::Displaced(index), Mat4::IDENTITY),
                    false => instance_of(object, n),
                };
                let alone = (info.mirror || info.env_layer.is_some()).then_some(index);
                (
                    info.transparent,
                    info.material,
                    alone,
                    key,
                    GpuInstance::new(world_from_mesh, env_layer(info), index as u32),
                    index,
                    world_from_mesh,
                )
            })
            .collect();
        entries.sort_by(|a, b| {
            (a.0, a.1, a.2).cmp(&(b.0, b.1, b.2)).then_with(|| mesh_order(&a.3).cmp(&mesh_order(&b.3)))
        });
        entries
    }

    /// The sorted `entries` as instanced draws: each run of one transparency, material, object
    /// drawn alone and mesh is one batch over its instances.
    fn batches_of(&self, entries: &[Entry]) -> Vec<Batch> {
        let mut batches: Vec<Batch> = Vec::new();
        for (index, (transparent, material, alone, key, ..)) in entries.iter().enumerate() {
            let index = index as u32;
            match batches.last_mut() {
                Some(b)
                    if b.transparent == *transparent
                        && b.material == *material
                        && b.alone == *alone
                        && b.mesh == *key =>
                {
                    b.instances.end = index + 1;
                }
                _ => batches.push(Batch {
                    mesh: *key,
                    material: *material,
                    transparent: *transparent,
                    alone: *alone,
                    mirror: alone.is_some_and(|o| self.objects[o].mirror),
                    instances: index..index + 1,
                }),
            }
        }
        batches
    }

    /// The transparent entries as the transparency pass draws them, in the scene's order (their
    /// meshes uploaded).
    fn transparent_of(&self, scene: &Scene, entries: &[Entry]) -> Vec<TransparentObject> {
        let mut transparent = Vec::new();
        for (instance, &(_, material, _, mesh, _, object, world_from_mesh)) in entries.iter().enumerate() {
            if entries[instance].0 {
                transparent.push(TransparentObject {
                    object,
                    mesh,
                    material,
                    instance: instance as u32,
                    world_from_mesh,
                    centre: world_from_mesh.transform_point3(self.meshes[&mesh].centre),
                    flipped: world_from_mesh.determinant() < 0.0,
                    bends_light: scene.materials[material].bends_light(),
                });
            }
        }
        transparent.sort_by_key(|t| t.object);
        transparent
    }

    /// Names the current draw list: what is drawn from it (shadow maps, projected polygons,
    /// sorted triangles) is kept while the name stays the same.
    pub fn draw_list(&self) -> DrawListId {
        DrawListId(self.instances.clone())
    }

    /// Records `batch`: binds its mesh and instances and draws them (the pipeline and material
    /// group are the caller's).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, batch: &Batch) {
        self.draw_instances(pass, batch.mesh, batch.instances.clone());
    }

    /// Records `instances` of `mesh` (the pipeline and material group are the caller's).
    pub fn draw_instances(&self, pass: &mut wgpu::RenderPass<'_>, mesh: MeshKey, instances: Range<u32>) {
        let count = self.meshes[&mesh].index_count;
        self.draw_part(pass, mesh, 0..count, instances);
    }

    /// Records the triangles `indices` of `mesh` (a face of a box, say) for `instances`.
    pub fn draw_part(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        mesh: MeshKey,
        indices: Range<u32>,
        instances: Range<u32>,
    ) {
        let mesh = &self.meshes[&mesh];
        let buffer = self.instances.as_ref().expect("prepare() made the instance buffer for these instances");
        let stride = std::mem::size_of::<GpuInstance>() as u64;
        pass.set_vertex_buffer(0, mesh.vertices.slice(..));
        pass.set_vertex_buffer(1, buffer.slice(u64::from(instances.start) * stride..));
        pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(indices, 0, 0..instances.len() as u32);
    }

    /// The number of indices of `mesh`.
    pub fn index_count(&self, mesh: MeshKey) -> u32 {
        self.meshes[&mesh].index_count
    }

    /// Triangles drawn per view with the current draw list.
    pub fn triangles(&self) -> u64 {
        self.batches.iter().map(|b| u64::from(self.meshes[&b.mesh].index_count / 3) * b.instances.len() as u64).sum()
    }

    /// Transparent triangles drawn per view.
    pub fn transparent_triangles(&self) -> u64 {
        self.transparent.iter().map(|t| u64::from(self.meshes[&t.mesh].index_count / 3)).sum()
    }

    pub fn mesh_count(&self) -> usize {
        self.meshes.len()
    }

    pub fn has_transparent(&self) -> bool {
        self.objects.iter().any(|o| o.transparent)
    }
}

/// What an object's environment lookups read (`GpuInstance::env_layer`).
fn env_layer(info: &ObjectInfo) -> i32 {
    match (info.mirror, info.env_layer) {
        (true, _) => ENV_LAYER_NONE,
        (false, Some(layer)) => layer as i32,
        (false, None) => ENV_LAYER_WORLD,
    }
}

/// The centre of a mesh's bounding box.
fn mesh_centre(mesh: &Mesh) -> Vec3 {
    let (min, max) = mesh
        .positions
        .iter()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    if mesh.positions.is_empty() { Vec3::ZERO } else { (min + max) / 2.0 }
}

/// A total order on mesh keys for sorting (their parameters are bit patterns, so any order will
/// do as long as equal keys end up side by side).
fn mesh_order(key: &MeshKey) -> (u8, [u32; 6], u32) {
    match *key {
        MeshKey::Sphere(n) => (0, [0; 6], n),
        MeshKey::Cuboid(b) => (1, b, 0),
        MeshKey::Plane(b) => (2, [b[0], b[1], b[2], b[3], 0, 0], 0),
        MeshKey::Torus(b, n) => (3, [b[0], b[1], 0, 0, 0, 0], n),
        MeshKey::RoundedBox(b, n) => (4, [b[0], b[1], b[2], b[3], 0, 0], n),
        MeshKey::File(i) => (5, [0; 6], i as u32),
        MeshKey::Displaced(i) => (6, [0; 6], i as u32),
    }
}
