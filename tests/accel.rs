//! The ray tracer's geometry and accelerators.
//!
//! - The wide BVH returns the binary BVH's hits (the same primitive at the same `t`, or a tie:
//!   another primitive hit within 8 ulps), through its AVX tests and its two halves of four,
//!   including rays parallel to a box's planes from on them and rays through triangle edges and
//!   vertices; and its two ways return exactly the same hits as each other.
//! - Every accelerator (BVHs, grid, octree) returns the nearest hit brute force returns, on
//!   thousands of seeded random rays through a triangle soup, a tessellated height field, a
//!   sphere mesh, a scene of every analytic shape under rotations and non-uniform scales, and the
//!   built-in scene files; `occluded` agrees with `closest`.
//! - Known answers: sphere roots, box slabs, triangle barycentrics, torus and rounded-box
//!   distances, degenerate input.
//! - Watertightness: rays aimed exactly at the shared edges and vertices of closed and open
//!   meshes always hit, through every accelerator.
//! - Texture coordinates and tangents of analytic shapes agree with the rasterizer's
//!   tessellation of the same shape (`src/scene/mesh.rs`).

use std::f32::consts::PI;

use glam::{EulerRot, Mat4, Quat, Vec2, Vec3};
use mirador::Scene;
use mirador::base::{MaterialId, Ray};
use mirador::scene::{Mesh, Object, Shape};
use mirador::trace::accel::bvh::Bvh;
use mirador::trace::accel::wide::Wide;
use mirador::trace::accel::{AccelKind, Accelerator, Hit, build};
use mirador::trace::geometry::{Aabb, Primitive, Triangle, scene_primitives};

/// PCG32 (O'Neill): a few lines of seeded randomness, the same on every machine.
struct Pcg(u64);

impl Pcg {
    fn new(seed: u64) -> Pcg {
        let mut rng = Pcg(seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407));
        rng.next_u32();
        rng
    }

    fn next_u32(&mut self) -> u32 {
        let old = self.0;
        self.0 = old.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// Uniform in [0, 1).
    fn f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 / (1u32 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }

    fn in_box(&mut self, b: &Aabb) -> Vec3 {
        Vec3::new(self.range(b.min.x, b.max.x), self.range(b.min.y, b.max.y), self.range(b.min.z, b.max.z))
    }

    fn unit_vector(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, 2.0 * PI);
        let s = (1.0 - z * z).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

fn ray(origin: Vec3, direction: Vec3) -> Ray {
    Ray { origin, direction: direction.normalize() }
}

const KINDS: [AccelKind; 4] = [AccelKind::Wide, AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree];

fn bounds_of(prims: &[Primitive]) -> Aabb {
    prims.iter().fold(Aabb::EMPTY, |b, p| b.union(&p.bounds()))
}

/// Rays of three kinds: from outside the scene's box aimed at a point inside it, from inside in
/// random directions, and short segments (`t_max` finite, `t_min` > 0) like shadow and
/// secondary rays.
fn random_queries(rng: &mut Pcg, bounds: &Aabb, count: usize) -> Vec<(Ray, f32, f32)> {
    let size = bounds.extent().max_element().max(1e-3);
    let outer = bounds.padded(0.5 * size);
    (0..count)
        .map(|i| match i % 3 {
            0 => {
                let origin = rng.in_box(&outer);
                let target = rng.in_box(bounds);
                (ray(origin, target - origin), 0.0, f32::INFINITY)
            }
            1 => (ray(rng.in_box(bounds), rng.unit_vector()), 1e-4 * size, f32::INFINITY),
            _ => (ray(rng.in_box(&outer), rng.unit_vector()), 1e-4 * size, rng.range(0.0, 1.5) * size),
        })
        .collect()
}

/// Every accelerator against brute force: the same nearest hit (same primitive, or a tie in t),
/// and `occluded` exactly when `closest` finds something. Returns how many rays hit.
fn assert_accelerators_agree(name: &str, prims: &[Primitive], queries: &[(Ray, f32, f32)]) -> usize {
    let reference = build(AccelKind::None, prims);
    let expected: Vec<_> = queries.iter().map(|(r, t0, t1)| reference.closest(prims, r, *t0, *t1)).collect();
    for kind in KINDS {
        let accel = build(kind, prims);
        for ((r, t0, t1), want) in queries.iter().zip(&expected) {
            let got = accel.closest(prims, r, *t0, *t1);
            match (got, want) {
                (None, None) => {}
                (Some(g), Some(w)) => {
                    let tolerance = 1e-4 * w.t.abs() + 1e-6;
                    assert!(
                        (g.t - w.t).abs() <= tolerance,
                        "{name}, {kind:?}: {r:?} in ({t0}, {t1}) hits primitive {} at t = {}, \
                         brute force primitive {} at t = {}",
                        g.primitive,
                        g.t,
                        w.primitive,
                        w.t
                    );
                    if g.primitive != w.primitive {
                        // A tie: the other primitive is really hit there too.
                        let t = prims[g.primitive as usize].intersect(r, *t0, *t1);
                        assert!(
                            t.is_some_and(|t| (t - w.t).abs() <= tolerance),
                            "{name}, {kind:?}: bad tie {g:?} {w:?}"
                        );
                    }
                }
                _ => panic!("{name}, {kind:?}: {r:?} in ({t0}, {t1}): got {got:?}, brute force {want:?}"),
            }
            assert_eq!(
                accel.occluded(prims, r, *t0, *t1),
                want.is_some(),
                "{name}, {kind:?}: occluded disagrees with closest for {r:?} in ({t0}, {t1})"
            );
        }
    }
    expected.iter().filter(|h| h.is_some()).count()
}

fn triangle(positions: [Vec3; 3]) -> Primitive {
    let n = (positions[1] - positions[0]).cross(positions[2] - positions[0]).normalize();
    Primitive::Triangle(Triangle {
        positions,
        normals: [n; 3],
        uvs: [Vec2::ZERO, Vec2::X, Vec2::Y],
        object: 0,
        material: MaterialId(0),
    })
}

/// A scene to put objects in: the built-in simple scene with its objects removed.
fn empty_scene() -> Scene {
    let mut scene = Scene::load(&mirador::scene::builtin_path("seed-simple.toml")).expect("the built-in scene loads");
    scene.objects.clear();
    scene.meshes.clear();
    scene
}

fn object(shape: Shape, world_from_local: Mat4) -> Object {
    Object { name: "test".into(), shape, material: MaterialId(0), world_from_local }
}

fn mesh_primitives(mesh: Mesh, world_from_local: Mat4) -> Vec<Primitive> {
    let mut scene = empty_scene();
    scene.meshes.push(mesh);
    scene.objects.push(object(Shape::Mesh(0), world_from_local));
    scene_primitives(&scene)
}

/// An `n × n` quad height field over [−1, 1]² with shared vertices, gently bumpy.
fn height_field(n: u32) -> Mesh {
    let mut mesh = Mesh { name: "height field".into(), ..Mesh::default() };
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (2.0 * i as f32 / n as f32 - 1.0, 2.0 * j as f32 / n as f32 - 1.0);
            mesh.positions.push(Vec3::new(x, 0.1 * (3.0 * x).sin() * (2.0 * z).cos(), z));
            mesh.normals.push(Vec3::Y);
            mesh.uvs.push(Vec2::new(x, z));
        }
    }
    let row = n + 1;
    for j in 0..n {
        for i in 0..n {
            let a = j * row + i;
            mesh.indices.extend_from_slice(&[a, a + row, a + 1, a + 1, a + row, a + row + 1]);
        }
    }
    mesh
}

/// A closed UV sphere whose seam and poles are welded (each point is one vertex), unlike
/// `Mesh::sphere`, whose duplicated seam vertices differ by sin(2π) in f32.
fn welded_sphere(slices: u32, stacks: u32) -> Mesh {
    let mut mesh = Mesh { name: "welded sphere".into(), ..Mesh::default() };
    let push = |p: Vec3, mesh: &mut Mesh| {
        mesh.positions.push(p);
        mesh.normals.push(p.normalize());
        mesh.uvs.push(Vec2::ZERO);
    };
    push(Vec3::Y, &mut mesh);
    for j in 1..stacks {
        let theta = PI * j as f32 / stacks as f32;
        for i in 0..slices {
            let phi = 2.0 * PI * i as f32 / slices as f32;
            push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin()), &mut mesh);
        }
    }
    push(Vec3::NEG_Y, &mut mesh);
    let south = mesh.positions.len() as u32 - 1;
    let ring = |j: u32, i: u32| 1 + (j - 1) * slices + i % slices;
    for i in 0..slices {
        mesh.indices.extend_from_slice(&[0, ring(1, i), ring(1, i + 1)]);
        mesh.indices.extend_from_slice(&[south, ring(stacks - 1, i + 1), ring(stacks - 1, i)]);
        for j in 1..stacks - 1 {
            let (a, b, c, d) = (ring(j, i), ring(j, i + 1), ring(j + 1, i), ring(j + 1, i + 1));
            mesh.indices.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    mesh
}

/// One object of every analytic shape, rotated, translated and (non-uniformly) scaled.
fn analytic_scene() -> Scene {
    let mut scene = empty_scene();
    let place = |s: Vec3, r: Vec3, t: Vec3| {
        Mat4::from_scale_rotation_translation(s, Quat::from_euler(EulerRot::XYZ, r.x, r.y, r.z), t)
    };
    let shapes = [
        (
            Shape::Sphere { center: Vec3::new(0.2, 0.0, 0.0), radius: 0.8 },
            place(Vec3::new(1.0, 1.5, 0.7), Vec3::new(0.3, 0.2, 0.1), Vec3::ZERO),
        ),
        (Shape::Sphere { center: Vec3::ZERO, radius: 0.5 }, place(Vec3::ONE, Vec3::ZERO, Vec3::new(2.0, 0.5, -1.0))),
        (
            Shape::Cuboid { min: Vec3::new(-0.5, -0.2, -0.3), max: Vec3::new(0.4, 0.6, 0.3) },
            place(Vec3::new(1.0, 2.0, 1.0), Vec3::new(0.0, 0.7, 0.2), Vec3::new(-2.0, 0.0, 1.0)),
        ),
        (
            Shape::Plane { size: Vec2::new(8.0, 6.0), uv_scale: Vec2::new(4.0, 3.0) },
            place(Vec3::ONE, Vec3::new(0.05, 0.0, 0.0), Vec3::new(0.0, -1.5, 0.0)),
        ),
        (
            Shape::Plane { size: Vec2::new(1.0, 2.0), uv_scale: Vec2::ONE },
            place(Vec3::ONE, Vec3::new(0.0, 0.0, -PI / 2.0), Vec3::new(-3.0, 0.0, -1.0)),
        ),
        (
            Shape::Torus { major: 0.7, minor: 0.2 },
            place(Vec3::splat(1.2), Vec3::new(1.0, 0.3, 0.0), Vec3::new(0.5, 1.0, 2.0)),
        ),
        (
            Shape::Torus { major: 0.5, minor: 0.25 },
            place(Vec3::new(1.0, 0.5, 1.5), Vec3::ZERO, Vec3::new(-1.0, 1.5, -1.5)),
        ),
        (
            Shape::RoundedBox { half: Vec3::new(0.4, 0.2, 0.3), radius: 0.1 },
            place(Vec3::ONE, Vec3::new(0.2, 0.9, 0.4), Vec3::new(2.0, -0.5, 1.5)),
        ),
        (
            Shape::RoundedBox { half: Vec3::new(0.3, 0.0, 0.3), radius: 0.15 },
            place(Vec3::new(2.0, 1.0, 1.0), Vec3::ZERO, Vec3::new(-2.0, -1.0, -2.5)),
        ),
    ];
    for (shape, m) in shapes {
        scene.objects.push(object(shape, m));
    }
    scene
}

/// `n` triangles of random sizes (mostly small) and orientations in the cube `[-1, 1]³`.
fn triangle_soup(rng: &mut Pcg, n: usize) -> Vec<Primitive> {
    let cube = Aabb::new(Vec3::splat(-1.0), Vec3::ONE);
    (0..n)
        .map(|_| {
            let a = rng.in_box(&cube);
            let size = 0.02 + 0.2 * rng.f32().powi(3);
            triangle([a, a + size * rng.unit_vector(), a + size * rng.unit_vector()])
        })
        .collect()
}

#[test]
fn accelerators_agree_with_brute_force_on_a_triangle_soup() {
    let mut rng = Pcg::new(1);
    let prims = triangle_soup(&mut rng, 3000);
    let queries = random_queries(&mut rng, &bounds_of(&prims), 6000);
    let hits = assert_accelerators_agree("triangle soup", &prims, &queries);
    assert!(hits > 1000, "the rays should hit the soup often, got {hits} hits");
}

#[test]
fn accelerators_agree_with_brute_force_on_meshes_with_shared_edges() {
    let mut rng = Pcg::new(2);
    let field = mesh_primitives(height_field(40), Mat4::from_rotation_x(0.3));
    let queries = random_queries(&mut rng, &bounds_of(&field), 4000);
    assert!(assert_accelerators_agree("height field", &field, &queries) > 1000);
    let sphere = mesh_primitives(welded_sphere(48, 24), Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0)));
    let queries = random_queries(&mut rng, &bounds_of(&sphere), 4000);
    assert!(assert_accelerators_agree("sphere mesh", &sphere, &queries) > 1000);
}

#[test]
fn accelerators_agree_with_brute_force_on_analytic_shapes() {
    let mut rng = Pcg::new(3);
    let prims = scene_primitives(&analytic_scene());
    assert_eq!(prims.len(), 9);
    let queries = random_queries(&mut rng, &bounds_of(&prims), 6000);
    assert!(assert_accelerators_agree("analytic shapes", &prims, &queries) > 2000);
}

#[test]
fn accelerators_agree_with_brute_force_on_the_built_in_scenes() {
    let mut rng = Pcg::new(4);
    for name in ["showcase.toml", "seed-simple.toml"] {
        let scene = Scene::load(&mirador::scene::builtin_path(name)).expect("built-in scenes load");
        let prims = scene_primitives(&scene);
        assert!(!prims.is_empty());
        let camera = &scene.camera;
        let mut queries: Vec<(Ray, f32, f32)> = (0..2000)
            .map(|_| {
                let (x, y) = (rng.range(0.0, camera.width as f32), rng.range(0.0, camera.height as f32));
                (camera.ray_through(x, y), 0.0, f32::INFINITY)
            })
            .collect();
        // The showcase's 400 m floor would swallow every random ray; aim near the camera's target.
        let focus = Aabb::new(camera.center - Vec3::splat(5.0), camera.center + Vec3::splat(5.0));
        queries.extend(random_queries(&mut rng, &focus, 2000));
        assert!(assert_accelerators_agree(name, &prims, &queries) > 1000);
    }
}

/// The wide BVH, both ways of testing its boxes and triangles, against the binary BVH: identical
/// hits; and the two ways against each other: exactly the same answers, since every lane does the
/// same operations in the same order either way.
fn assert_wide_matches_binary(name: &str, prims: &[Primitive], queries: &[(Ray, f32, f32)]) {
    let binary = Bvh::build(prims);
    let (avx, halves) = (Wide::build(prims), Wide::build_without_avx(prims));
    for (r, t0, t1) in queries {
        assert_eq!(
            avx.closest(prims, r, *t0, *t1),
            halves.closest(prims, r, *t0, *t1),
            "{name}: the wide BVH's two ways differ on {r:?} in ({t0}, {t1})"
        );
        assert_eq!(
            avx.occluded(prims, r, *t0, *t1),
            halves.occluded(prims, r, *t0, *t1),
            "{name}: the wide BVH's two ways differ on occlusion for {r:?} in ({t0}, {t1})"
        );
    }
    for (way, wide) in
        [("AVX where present", Wide::build(prims)), ("two halves of four lanes", Wide::build_without_avx(prims))]
    {
        for (r, t0, t1) in queries {
            let (got, want) = (wide.closest(prims, r, *t0, *t1), binary.closest(prims, r, *t0, *t1));
            // Two primitives hit at the same distance (a shared vertex or edge), or a few units in
            // the last place apart, may be found in either order: both BVHs skip a box whose entry
            // rounds past the nearest hit so far. Such a tie is real: each primitive is hit at the
            // distance given, and the two distances are that close.
            let close = match (got, want) {
                (Some(g), Some(w)) => (g.t - w.t).abs() <= 8.0 * f32::EPSILON * w.t.abs(),
                (g, w) => g == w,
            };
            let tie =
                |h: Hit| prims[h.primitive as usize].intersect(r, *t0, *t1).map(f32::to_bits) == Some(h.t.to_bits());
            assert!(
                got == want || close && got.is_some_and(tie) && want.is_some_and(tie),
                "{name}, wide ({way}): {r:?} in ({t0}, {t1}) hits {got:?}, the binary BVH {want:?}"
            );
            assert_eq!(
                wide.occluded(prims, r, *t0, *t1),
                binary.occluded(prims, r, *t0, *t1),
                "{name}, wide ({way}): occluded differs for {r:?} in ({t0}, {t1})"
            );
        }
    }
}

/// Rays along the axes (direction components exactly zero) from the primitives' own vertex
/// coordinates, so that origins lie on box planes: the box test's 0·∞ case.
fn axis_rays(prims: &[Primitive], rng: &mut Pcg, count: usize) -> Vec<(Ray, f32, f32)> {
    let corners: Vec<Vec3> = prims.iter().flat_map(|p| [p.bounds().min, p.bounds().max]).collect();
    let axes = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];
    (0..count)
        .map(|_| {
            let (a, b) =
                (corners[rng.next_u32() as usize % corners.len()], corners[rng.next_u32() as usize % corners.len()]);
            // Two coordinates from one corner, one from another: on three planes at once, often.
            let origin = Vec3::new(a.x, a.y, b.z);
            (ray(origin, axes[rng.next_u32() as usize % 6]), 0.0, f32::INFINITY)
        })
        .collect()
}

#[test]
fn the_wide_bvh_finds_exactly_the_binary_bvhs_hits() {
    let mut rng = Pcg::new(8);
    let soup = triangle_soup(&mut rng, 2000);
    let field = mesh_primitives(height_field(40), Mat4::IDENTITY);
    let sphere = mesh_primitives(welded_sphere(48, 24), Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0)));
    let analytic = scene_primitives(&analytic_scene());
    let showcase = scene_primitives(&Scene::load(&mirador::scene::builtin_path("showcase.toml")).unwrap());
    // Packets with awkward lanes: triangles of zero area (a point, a segment), exact duplicates
    // (ties in every lane), slivers, and analytic shapes mixed in among them.
    let mut awkward = triangle_soup(&mut rng, 300);
    for _ in 0..100 {
        let a = rng.in_box(&Aabb::new(Vec3::splat(-1.0), Vec3::ONE));
        let d = 0.1 * rng.unit_vector();
        awkward.push(triangle([a, a, a]));
        awkward.push(triangle([a, a + d, a + 2.0 * d]));
        awkward.push(triangle([a, a + d, a + d + 1e-6 * rng.unit_vector()]));
        let copy = awkward[rng.next_u32() as usize % awkward.len()].clone();
        awkward.push(copy);
    }
    awkward.extend(scene_primitives(&analytic_scene()));
    for (name, prims) in [
        ("soup", soup),
        ("awkward triangles", awkward),
        ("height field", field),
        ("sphere mesh", sphere),
        ("analytic", analytic),
        ("showcase", showcase),
    ] {
        let focus = bounds_of(&prims);
        let focus =
            if focus.extent().max_element() > 50.0 { Aabb::new(Vec3::splat(-5.0), Vec3::splat(5.0)) } else { focus };
        let mut queries = random_queries(&mut rng, &focus, 3000);
        queries.extend(axis_rays(&prims, &mut rng, 1000));
        assert_wide_matches_binary(name, &prims, &queries);
    }
    // The height field's vertices and edges, straight down: edge functions that round to zero.
    let n = 16;
    let field = height_field(n);
    let prims = mesh_primitives(field.clone(), Mat4::IDENTITY);
    let queries: Vec<_> = field
        .positions
        .iter()
        .flat_map(|&p| [p, p + Vec3::new(1.0 / n as f32, 0.0, 0.0)])
        .map(|p| (ray(p + Vec3::Y, Vec3::NEG_Y), 0.0, f32::INFINITY))
        .collect();
    assert_wide_matches_binary("height field's vertices", &prims, &queries);
}

#[test]
fn meshes_are_watertight_at_shared_edges_and_vertices() {
    let mut rng = Pcg::new(5);
    let check = |name: &str,
                 mesh: &Mesh,
                 prims: &[Primitive],
                 targets: Vec<Vec3>,
                 origin: &mut dyn FnMut(Vec3) -> Vec3| {
        let accels: Vec<(AccelKind, Box<dyn Accelerator>)> =
            [AccelKind::None, AccelKind::Wide, AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree]
                .map(|k| (k, build(k, prims)))
                .into();
        for target in targets {
            let o = origin(target);
            let r = ray(o, target - o);
            for (kind, accel) in &accels {
                assert!(
                    accel.closest(prims, &r, 0.0, f32::INFINITY).is_some(),
                    "{name}, {kind:?}: the ray from {o} through {target} slips through the mesh"
                );
                assert!(accel.occluded(prims, &r, 0.0, f32::INFINITY), "{name}, {kind:?}: unoccluded through {target}");
            }
        }
        assert!(mesh.indices.len() / 3 == prims.len(), "{name}: no triangle was dropped");
    };
    // Interior vertices and edge midpoints of the height field, seen from above at any angle.
    let n = 24;
    let field = height_field(n);
    let world_from_local = Mat4::from_rotation_z(0.2);
    let prims = mesh_primitives(field.clone(), world_from_local);
    let p = |i: u32, j: u32| world_from_local.transform_point3(field.positions[(j * (n + 1) + i) as usize]);
    let mut targets = Vec::new();
    for j in 1..n {
        for i in 1..n {
            targets.extend([p(i, j), 0.5 * (p(i, j) + p(i + 1, j)), 0.5 * (p(i, j) + p(i, j + 1))]);
            targets.push(0.5 * (p(i, j + 1) + p(i + 1, j)));
        }
    }
    check("height field", &field, &prims, targets, &mut |t| {
        t + Vec3::new(rng.range(-2.0, 2.0), 3.0, rng.range(-2.0, 2.0))
    });
    // Every vertex and edge midpoint of a closed sphere mesh, from outside and from inside.
    let sphere = welded_sphere(32, 16);
    let prims = mesh_primitives(sphere.clone(), Mat4::IDENTITY);
    let mut targets = sphere.positions.clone();
    for t in sphere.indices.chunks_exact(3) {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            targets.push(0.5 * (sphere.positions[a as usize] + sphere.positions[b as usize]));
        }
    }
    let mut rng = Pcg::new(6);
    check("sphere mesh from outside", &sphere, &prims, targets.clone(), &mut |t| t * 3.0 + 0.5 * rng.unit_vector());
    let mut rng = Pcg::new(7);
    check("sphere mesh from inside", &sphere, &prims, targets, &mut |_| 0.3 * rng.unit_vector());
}

fn analytic(shape: Shape, world_from_local: Mat4) -> Primitive {
    let mut scene = empty_scene();
    scene.objects.push(object(shape, world_from_local));
    let mut prims = scene_primitives(&scene);
    assert_eq!(prims.len(), 1, "the shape is valid");
    prims.remove(0)
}

fn assert_t(prim: &Primitive, r: Ray, expected: Option<f32>, what: &str) {
    let got = prim.intersect(&r, 0.0, f32::INFINITY);
    match (got, expected) {
        (Some(g), Some(e)) => assert!((g - e).abs() <= 1e-4 * e.max(1.0), "{what}: t = {g}, expected {e}"),
        (None, None) => {}
        _ => panic!("{what}: got {got:?}, expected {expected:?}"),
    }
}

#[test]
fn ray_sphere_known_answers() {
    let unit = analytic(Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, Mat4::IDENTITY);
    assert_t(&unit, ray(Vec3::new(0.0, 0.0, -5.0), Vec3::Z), Some(4.0), "head on");
    assert_t(&unit, ray(Vec3::ZERO, Vec3::Z), Some(1.0), "from the centre: the far side");
    assert_t(&unit, ray(Vec3::new(0.3, 0.2, 0.1), Vec3::NEG_X), Some(0.3 + (1.0f32 - 0.05).sqrt()), "from inside");
    // A tangent ray has a double root: it counts as one hit, where it touches.
    assert_t(&unit, ray(Vec3::new(0.0, 1.0, -5.0), Vec3::Z), Some(5.0), "grazing at y = 1");
    assert_t(&unit, ray(Vec3::new(0.0, 1.001, -5.0), Vec3::Z), None, "passing just above");
    assert_t(&unit, ray(Vec3::new(0.0, 0.0, -5.0), Vec3::NEG_Z), None, "pointing away");
    assert_t(&unit, ray(Vec3::new(0.0, 0.0, 5.0), Vec3::Z), None, "behind the origin");
    // The local ray is not renormalized, so t stays in world units under a non-uniform scale.
    let ellipsoid =
        analytic(Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0)));
    assert_t(&ellipsoid, ray(Vec3::new(-5.0, 0.0, 0.0), Vec3::X), Some(3.0), "ellipsoid along its long axis");
    assert_t(&ellipsoid, ray(Vec3::new(0.0, -5.0, 0.0), Vec3::Y), Some(4.0), "ellipsoid along a short axis");
    let far = analytic(Shape::Sphere { center: Vec3::new(0.0, 0.0, 5000.0), radius: 1.0 }, Mat4::IDENTITY);
    assert_t(&far, ray(Vec3::ZERO, Vec3::Z), Some(4999.0), "far away");
    // Normal, texture coordinates and tangents at the hit.
    let r = ray(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
    let hit = unit.surface(&r, 4.0);
    assert!(hit.point.abs_diff_eq(Vec3::NEG_X, 1e-6) && hit.normal.abs_diff_eq(Vec3::NEG_X, 1e-6));
    // −x is φ = π on the equator: u = 1/2, v = 1/2.
    assert!(hit.uv.abs_diff_eq(Vec2::splat(0.5), 1e-6), "{}", hit.uv);
}

#[test]
fn ray_box_slab_known_answers() {
    let cuboid = analytic(Shape::Cuboid { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) }, Mat4::IDENTITY);
    assert_t(&cuboid, ray(Vec3::new(-3.0, 0.5, 0.5), Vec3::X), Some(2.0), "through the −x face");
    assert_t(&cuboid, ray(Vec3::new(0.5, 0.0, 0.0), Vec3::X), Some(0.5), "from inside: the exit");
    assert_t(&cuboid, ray(Vec3::new(-3.0, 1.5, 0.0), Vec3::X), None, "above the box");
    // Zero direction components (1/0 = ∞) with the origin exactly on a slab boundary (0·∞ = NaN):
    // a ray running along the top face is inside the closed box there.
    let along_face = ray(Vec3::new(-3.0, 1.0, 0.0), Vec3::X);
    assert_t(&cuboid, along_face, Some(2.0), "along the top face");
    let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    assert_eq!(b.intersect(&along_face, 0.0, f32::INFINITY), Some((2.0, 4.0)));
    let along_edge = Ray { origin: Vec3::new(1.0, 1.0, -4.0), direction: Vec3::new(-0.0, 0.0, 1.0) };
    assert_eq!(b.intersect(&along_edge, 0.0, 10.0), Some((3.0, 5.0)));
    let parallel_outside = Ray { origin: Vec3::new(1.0 + 1e-6, 0.0, -4.0), direction: Vec3::Z };
    assert_eq!(b.intersect(&parallel_outside, 0.0, 10.0), None);
    assert_eq!(b.intersect(&along_face, 0.0, 1.5), None, "the box starts after t_max");
    // Box normals and texture coordinates follow Mesh::cuboid: +z face, u along +x, v down.
    let hit = cuboid.surface(&ray(Vec3::new(0.5, 0.5, 3.0), Vec3::NEG_Z), 2.0);
    assert!(hit.normal.abs_diff_eq(Vec3::Z, 1e-6));
    assert!(hit.uv.abs_diff_eq(Vec2::new(0.75, 0.25), 1e-6), "{}", hit.uv);
}

#[test]
fn triangle_barycentrics_interpolate_normals_and_uvs() {
    let tri = Primitive::Triangle(Triangle {
        positions: [Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0)],
        normals: [Vec3::Z, Vec3::X, Vec3::Y],
        uvs: [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)],
        object: 7,
        material: MaterialId(3),
    });
    // (0.5, 0.5, 0) has barycentrics (0.5, 0.25, 0.25).
    let r = ray(Vec3::new(0.5, 0.5, 3.0), Vec3::NEG_Z);
    assert_t(&tri, r, Some(3.0), "front");
    assert_t(&tri, ray(Vec3::new(0.5, 0.5, -3.0), Vec3::Z), Some(3.0), "back: triangles are two-sided");
    assert_t(&tri, ray(Vec3::new(1.5, 1.5, 3.0), Vec3::NEG_Z), None, "beyond the hypotenuse");
    let hit = tri.surface(&r, 3.0);
    assert!(hit.uv.abs_diff_eq(Vec2::new(0.25, 0.25), 1e-6), "{}", hit.uv);
    assert!(hit.normal.abs_diff_eq(Vec3::new(0.25, 0.25, 0.5).normalize(), 1e-6), "{}", hit.normal);
    assert!(hit.geometric_normal.abs_diff_eq(Vec3::Z, 1e-6));
    assert!(
        hit.dpdu.abs_diff_eq(Vec3::new(2.0, 0.0, 0.0), 1e-6) && hit.dpdv.abs_diff_eq(Vec3::new(0.0, 2.0, 0.0), 1e-6)
    );
    assert_eq!((hit.object, hit.material), (7, MaterialId(3)));
    // Degenerate texture coordinates still give a unit tangent frame around the normal.
    let flat_uv = Primitive::Triangle(Triangle {
        uvs: [Vec2::ZERO; 3],
        ..match &tri {
            Primitive::Triangle(t) => t.clone(),
            Primitive::Analytic(_) => unreachable!(),
        }
    });
    let hit = flat_uv.surface(&r, 3.0);
    assert!((hit.dpdu.length() - 1.0).abs() < 1e-5 && hit.dpdu.dot(hit.geometric_normal).abs() < 1e-5);
    assert!(hit.dpdu.cross(hit.dpdv).abs_diff_eq(hit.geometric_normal, 1e-5));
}

#[test]
fn sphere_traced_torus_and_rounded_box_hit_at_their_analytic_distances() {
    let (major, minor) = (1.0, 0.25);
    let torus = analytic(Shape::Torus { major, minor }, Mat4::IDENTITY);
    assert_t(&torus, ray(Vec3::new(5.0, 0.0, 0.0), Vec3::NEG_X), Some(5.0 - major - minor), "along x");
    assert_t(&torus, ray(Vec3::new(0.0, 5.0, 0.0), Vec3::NEG_Y), None, "down the axis, through the hole");
    assert_t(&torus, ray(Vec3::new(0.0, 5.0, -1.0), Vec3::NEG_Y), Some(5.0 - minor), "onto the top of the tube");
    assert_t(&torus, ray(Vec3::new(0.0, 0.0, 0.0), Vec3::Z), Some(major - minor), "from the centre, the inner wall");
    assert_t(&torus, ray(Vec3::new(0.0, 0.0, 1.0), Vec3::Z), Some(minor), "from inside the tube");
    // Under a rotation, uniform scale and translation, t is still in world units.
    let placed = analytic(
        Shape::Torus { major, minor },
        Mat4::from_scale_rotation_translation(
            Vec3::splat(2.0),
            Quat::from_rotation_z(PI / 2.0),
            Vec3::new(0.0, 0.0, 3.0),
        ),
    );
    assert_t(&placed, ray(Vec3::new(0.0, 10.0, 3.0), Vec3::NEG_Y), Some(10.0 - 2.0 * (major + minor)), "placed torus");
    let torus_hit = torus.surface(&ray(Vec3::new(5.0, 0.0, 0.0), Vec3::NEG_X), 3.75);
    assert!(torus_hit.normal.abs_diff_eq(Vec3::X, 1e-4), "{}", torus_hit.normal);

    let (half, radius) = (Vec3::new(0.5, 0.3, 0.2), 0.1);
    let rounded = analytic(Shape::RoundedBox { half, radius }, Mat4::IDENTITY);
    assert_t(&rounded, ray(Vec3::new(5.0, 0.1, 0.1), Vec3::NEG_X), Some(5.0 - half.x - radius), "onto a flat face");
    // Toward the rounded corner along the diagonal through the inner box's corner.
    let o = half + 4.0 * Vec3::ONE.normalize();
    assert_t(&rounded, ray(o, -Vec3::ONE), Some(4.0 - radius), "onto a rounded corner");
    assert_t(&rounded, ray(Vec3::new(0.0, 0.0, 0.0), Vec3::Y), Some(half.y + radius), "from inside");
    assert_t(&rounded, ray(Vec3::new(5.0, half.y + radius + 1e-3, 0.0), Vec3::NEG_X), None, "just above the top face");
}

#[test]
fn degenerate_input_neither_panics_nor_hits() {
    let mut scene = analytic_scene();
    scene.objects.push(object(Shape::Sphere { center: Vec3::ZERO, radius: 0.0 }, Mat4::IDENTITY));
    scene
        .objects
        .push(object(Shape::Cuboid { min: Vec3::ZERO, max: Vec3::ONE }, Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))));
    scene.objects.push(object(Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, Mat4::from_translation(Vec3::NAN)));
    let prims = scene_primitives(&scene);
    assert_eq!(prims.len(), 9, "a zero radius, a flattening scale and a NaN transform are left out");
    let nan = Ray { origin: Vec3::ZERO, direction: Vec3::new(f32::NAN, 0.0, 1.0) };
    let zero = Ray { origin: Vec3::ZERO, direction: Vec3::ZERO };
    let infinite = Ray { origin: Vec3::new(f32::INFINITY, 0.0, 0.0), direction: Vec3::NEG_X };
    for kind in [AccelKind::None, AccelKind::Wide, AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree] {
        let accel = build(kind, &prims);
        for r in [nan, zero, infinite] {
            assert_eq!(accel.closest(&prims, &r, 0.0, f32::INFINITY), None, "{kind:?}: {r:?}");
            assert!(!accel.occluded(&prims, &r, 0.0, f32::INFINITY), "{kind:?}: {r:?}");
        }
        let empty = build(kind, &[]);
        assert_eq!(empty.closest(&[], &ray(Vec3::ZERO, Vec3::Z), 0.0, f32::INFINITY), None);
        assert!(!empty.occluded(&[], &ray(Vec3::ZERO, Vec3::Z), 0.0, f32::INFINITY));
        assert_eq!(empty.stats().primitives, 0);
    }
    for prim in &prims {
        assert_eq!(prim.intersect(&nan, 0.0, f32::INFINITY), None);
    }
}

/// The analytic hit's texture coordinates and tangents against those of the rasterizer's
/// tessellation of the same object, hit by the same ray; and `∂p/∂u`, `∂p/∂v` against the
/// change of uv along them.
/// `wraps`: u and v are periodic (compared modulo 1). Hits with `v` within `v_margin` of 0 or 1
/// are skipped: near a UV sphere's poles the mesh's triangle fans interpolate `u` poorly.
/// `mesh_tangents`: compare with the triangles' tangents (not for the rounded box, whose mesh
/// has sliver triangles where its rims meet).
fn assert_uv_matches_tessellation(
    name: &str,
    shape: Shape,
    uv_tolerance: f32,
    wraps: bool,
    v_margin: f32,
    mesh_tangents: bool,
) {
    let mut scene = empty_scene();
    scene.settings.sphere_segments = 128;
    let world_from_local = Mat4::from_scale_rotation_translation(
        Vec3::new(1.5, 1.0, 0.8),
        Quat::from_rotation_y(0.4),
        Vec3::new(0.3, 0.2, 0.1),
    );
    let exact = object(shape, world_from_local);
    let mesh = scene.tessellate(&exact).into_owned();
    scene.objects.push(exact);
    scene.meshes.push(mesh);
    scene.objects.push(object(Shape::Mesh(0), world_from_local));
    let prims = scene_primitives(&scene);
    let (analytic, triangles) = prims.split_first().expect("the analytic object comes first");
    let mesh_bvh = build(AccelKind::Bvh, triangles);
    let bounds = analytic.bounds();
    let mut rng = Pcg::new(8);
    let mut compared = 0;
    for _ in 0..5000 {
        let target = rng.in_box(&bounds);
        let origin = target + 3.0 * bounds.extent().max_element() * rng.unit_vector();
        let r = ray(origin, target - origin);
        let Some(t) = analytic.intersect(&r, 0.0, f32::INFINITY) else { continue };
        let exact_hit = analytic.surface(&r, t);
        // Away from silhouettes, where the polygon and the true surface part ways.
        if exact_hit.normal.dot(r.direction).abs() < 0.3 || !(v_margin..=1.0 - v_margin).contains(&exact_hit.uv.y) {
            continue;
        }
        let Some(mesh) = mesh_bvh.closest(triangles, &r, 0.0, f32::INFINITY) else { continue };
        let mesh_hit = triangles[mesh.primitive as usize].surface(&r, mesh.t);
        if (mesh_hit.point - exact_hit.point).length() > 0.01 {
            continue;
        }
        let mut d = (exact_hit.uv - mesh_hit.uv).abs();
        if wraps {
            d = d.min(Vec2::ONE - d);
        }
        assert!(
            d.max_element() <= uv_tolerance,
            "{name}: at {} the exact uv is {}, the tessellation's {}",
            exact_hit.point,
            exact_hit.uv,
            mesh_hit.uv
        );
        for tangent in [exact_hit.dpdu, exact_hit.dpdv] {
            let off_plane = tangent.dot(exact_hit.normal) / tangent.length();
            assert!(
                off_plane.abs() <= 1e-3,
                "{name}: tangent {tangent} leaves the surface ({off_plane}) at uv {}",
                exact_hit.uv
            );
        }
        // A small step along ∂p/∂u moves the texture coordinates by that step in u alone. The
        // rounded box's uv is piecewise linear (as its mesh's), so a step may cross a tick where
        // the slope changes; no point is within one step of two ticks, so one of the steps
        // forward and backward stays within one piece.
        let delta = 2e-4;
        for (tangent, expected) in [(exact_hit.dpdu, Vec2::new(delta, 0.0)), (exact_hit.dpdv, Vec2::new(0.0, delta))] {
            let moved = |sign: f32| {
                let target = exact_hit.point + sign * delta * tangent;
                let probe = ray(target + 1e-2 * exact_hit.normal, -exact_hit.normal);
                let t = analytic.intersect(&probe, 0.0, f32::INFINITY)?;
                let mut moved = sign * (analytic.surface(&probe, t).uv - exact_hit.uv);
                if wraps {
                    moved -= moved.round();
                }
                Some(moved)
            };
            let (forward, backward) = (moved(1.0), moved(-1.0));
            let fits = |m: Option<Vec2>| m.is_some_and(|m| (m - expected).length() <= 0.05 * delta);
            assert!(
                fits(forward) || fits(backward),
                "{name}: steps of ±{delta} along {tangent} at uv {} move uv by {forward:?}, {backward:?}",
                exact_hit.uv
            );
        }
        // The mesh's tangents are constant per triangle: they match up to how much the exact ones
        // turn and grow across one triangle (most near a sphere's poles). A convention error
        // (a swapped, mirrored or mis-scaled u or v) is off by 100 % or more.
        let pairs = [(exact_hit.dpdu, mesh_hit.dpdu), (exact_hit.dpdv, mesh_hit.dpdv)];
        for (exact, mesh) in pairs.into_iter().filter(|_| mesh_tangents) {
            assert!(
                (exact - mesh).length() <= 0.2 * exact.length().max(mesh.length()),
                "{name}: tangent {exact} against the tessellation's {mesh} at {}",
                exact_hit.point
            );
        }
        compared += 1;
    }
    assert!(compared > 300, "{name}: only {compared} hits compared");
}

#[test]
fn analytic_texture_coordinates_follow_the_rasterizer_tessellation() {
    let plane = Shape::Plane { size: Vec2::new(3.0, 2.0), uv_scale: Vec2::new(6.0, 4.0) };
    assert_uv_matches_tessellation("plane", plane, 1e-4, false, 0.0, true);
    let cuboid = Shape::Cuboid { min: Vec3::new(-1.0, -0.5, -0.7), max: Vec3::new(0.8, 0.6, 0.7) };
    assert_uv_matches_tessellation("box", cuboid, 1e-4, false, 0.0, true);
    let sphere = Shape::Sphere { center: Vec3::new(0.1, 0.0, 0.2), radius: 0.9 };
    assert_uv_matches_tessellation("sphere", sphere, 2e-3, true, 0.1, true);
    assert_uv_matches_tessellation("torus", Shape::Torus { major: 0.8, minor: 0.3 }, 2e-3, true, 0.0, true);
    let rounded = Shape::RoundedBox { half: Vec3::new(0.6, 0.4, 0.5), radius: 0.2 };
    assert_uv_matches_tessellation("rounded box", rounded, 1e-2, false, 0.0, false);
}

/// A `side × side` grid of points on a square `size` wide around `centre`, facing along
/// `forward`, in blocks of 4 × 4 as the tracer hands a packet its pixels.
fn block_grid(centre: Vec3, forward: Vec3, size: f32, side: usize) -> Vec<Vec3> {
    let right = forward.cross(Vec3::Y).try_normalize().unwrap_or(Vec3::X);
    let up = right.cross(forward);
    let mut points = Vec::new();
    for by in (0..side).step_by(4) {
        for bx in (0..side).step_by(4) {
            for y in by..(by + 4).min(side) {
                for x in bx..(bx + 4).min(side) {
                    let (s, t) = ((x as f32 + 0.5) / side as f32 - 0.5, (y as f32 + 0.5) / side as f32 - 0.5);
                    points.push(centre + size * (s * right + t * up));
                }
            }
        }
    }
    points
}

/// Rays from `eye` through [`block_grid`]'s points around `target`: coherent rays.
fn fan(eye: Vec3, target: Vec3, size: f32, side: usize) -> Vec<Ray> {
    let points = block_grid(target, (target - eye).normalize(), size, side);
    points.into_iter().map(|p| ray(eye, p - eye)).collect()
}

/// Rays from [`block_grid`]'s points around `from`: towards `to` if `converging` (as shadow rays
/// towards a light), else all along `to − from` (an orthographic camera). Each packet's rays start
/// at different points.
fn grid_rays(from: Vec3, to: Vec3, size: f32, side: usize, converging: bool) -> Vec<Ray> {
    let points = block_grid(from, (to - from).normalize(), size, side);
    points.into_iter().map(|p| ray(p, if converging { to - p } else { to - from })).collect()
}

/// The scenes and rays the packet tests trace: a sphere mesh, the showcase, and a triangle soup
/// with analytic shapes; for each, a fan of coherent rays, rays from a grid of points (parallel,
/// and converging on a point beyond the scene), random rays, rays along the axes
/// (walked alone inside a packet) and a ray that misses, so that the last packet is short. Each
/// with its reach, the size of what the rays aim at.
fn packet_cases(rng: &mut Pcg) -> Vec<(&'static str, Vec<Primitive>, Vec<Ray>, f32)> {
    let sphere = mesh_primitives(welded_sphere(96, 48), Mat4::IDENTITY);
    let showcase = scene_primitives(&Scene::load(&mirador::scene::builtin_path("showcase.toml")).unwrap());
    let mut awkward = triangle_soup(rng, 300);
    awkward.extend(scene_primitives(&analytic_scene()));
    let scenes = [("sphere mesh", sphere), ("showcase", showcase), ("soup and analytic", awkward)];
    scenes
        .into_iter()
        .map(|(name, prims)| {
            let focus = bounds_of(&prims);
            let focus = if focus.extent().max_element() > 50.0 {
                Aabb::new(Vec3::splat(-5.0), Vec3::splat(5.0))
            } else {
                focus
            };
            let centre = (focus.min + focus.max) / 2.0;
            let reach = focus.extent().max_element();
            let eye = centre + Vec3::new(0.3, 0.4, 1.6) * reach;
            let mut rays = fan(eye, centre, reach, 37);
            rays.extend(grid_rays(eye, centre, reach, 29, false));
            rays.extend(grid_rays(centre - Vec3::new(0.2, 1.0, 0.5) * reach, eye, reach, 29, true));
            rays.extend(random_queries(rng, &focus, 500).into_iter().map(|(r, _, _)| r));
            rays.extend(axis_rays(&prims, rng, 60).into_iter().map(|(r, _, _)| r));
            rays.push(ray(centre + Vec3::splat(10.0 * reach), Vec3::ONE));
            (name, prims, rays, reach)
        })
        .collect()
}

/// Packets of coherent rays (`Accelerator::closest_packets`) against the same rays one by one:
/// the same hits, ties at shared vertices and edges aside as between the two BVHs (equally near,
/// both real); and on AVX and two halves of four alike, on [`packet_cases`].
#[test]
fn packets_find_the_single_ray_walks_hits() {
    let mut rng = Pcg::new(16);
    let mut packets_tested = 0;
    for (name, prims, rays, reach) in packet_cases(&mut rng) {
        for t_max in [f32::INFINITY, 1.2 * reach] {
            for (way, wide) in
                [("AVX where present", Wide::build(&prims)), ("two halves", Wide::build_without_avx(&prims))]
            {
                let mut hits = vec![None; rays.len()];
                wide.closest_packets(&prims, &rays, 0.0, t_max, &mut hits);
                for (r, got) in rays.iter().zip(&hits) {
                    let want = wide.closest(&prims, r, 0.0, t_max);
                    let tie = |h: &Hit| {
                        prims[h.primitive as usize].intersect(r, 0.0, t_max).map(f32::to_bits) == Some(h.t.to_bits())
                    };
                    let same_distance = matches!((got, want), (Some(g), Some(w)) if g.t == w.t);
                    assert!(
                        *got == want
                            || same_distance && got.as_ref().is_some_and(tie) && want.as_ref().is_some_and(tie),
                        "{name} ({way}, t_max {t_max}): {r:?} in a packet hits {got:?}, alone {want:?}"
                    );
                }
                packets_tested += rays.len().div_ceil(16);
            }
        }
    }
    assert!(packets_tested > 300);
}

/// Shadow rays in packets (`Accelerator::occluded_packets`), each to its own far bound, against
/// the same rays one by one: the same answer for every ray, on AVX and two halves of four alike.
/// The bounds range from nothing (no ray can be occluded) to beyond the scene; the rays are the
/// packets test's, coherent and not.
#[test]
fn shadow_packets_answer_as_single_rays() {
    let mut rng = Pcg::new(17);
    let (mut occluded_seen, mut clear_seen) = (0, 0);
    for (name, prims, rays, reach) in packet_cases(&mut rng) {
        let t_max: Vec<f32> = (0..rays.len())
            .map(|i| match i % 4 {
                0 => f32::INFINITY,
                1 => 0.0,
                _ => rng.range(0.0, 2.0 * reach),
            })
            .collect();
        for (way, wide) in [("AVX where present", Wide::build(&prims)), ("two halves", Wide::build_without_avx(&prims))]
        {
            let mut occluded = vec![false; rays.len()];
            wide.occluded_packets(&prims, &rays, (1e-4, &t_max), &mut occluded);
            for ((r, &t_max), &got) in rays.iter().zip(&t_max).zip(&occluded) {
                let want = wide.occluded(&prims, r, 1e-4, t_max);
                assert_eq!(got, want, "{name} ({way}): {r:?} to {t_max} in a packet occluded {got}, alone {want}");
                if got {
                    occluded_seen += 1;
                } else {
                    clear_seen += 1;
                }
            }
        }
    }
    assert!(occluded_seen > 300 && clear_seen > 300, "{occluded_seen} occluded, {clear_seen} not");
}
