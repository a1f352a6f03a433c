//! BVH benchmark: Mirador's two BVHs, the wide one (the tracer's default, with and without its
//! AVX tests) and the binary one the course builds, against the `bvh` (0.13) and `obvhs` (0.4)
//! crates. Ratios are given against the binary BVH, which was the default until the wide one.
//!
//! Scene: a displaced UV sphere of 1024 × 512 quads (1 046 528 triangles after the pole fans).
//! Rays: 512 × 512 primary rays from a pinhole camera that sees the whole sphere, and one shadow
//! ray toward a point light from every primary hit (the same rays, from Mirador's hits, for
//! every library). Each throughput is the best of [`repeats`] passes, on one thread and on all
//! of rayon's threads; builds are single-threaded for all three (obvhs without its `parallel`
//! feature, `bvh` with `Bvh::build`). Single-threaded work (builds, 1T passes) is timed by the
//! thread's CPU time where the system has that clock, so that other programs sharing the cores
//! count less; multi-threaded passes by the wall clock. Run with `cargo bench --bench trace` (about
//! 30 s on two cores); `cargo bench --bench trace -- obvhs` runs Mirador and the named peers only,
//! `-- none` Mirador alone, and `--repeats=9` takes the best of nine passes rather than three (runs
//! of three vary by about 10 % on the project's machine). `--half-angle=9` narrows the camera until
//! every primary ray hits the sphere; `--dump=FOLDER` writes the mesh and the primary rays for
//! `benches/embree.py`, which runs Embree 4 on the same work.
//!
//! The row `wide, packets` traces the same primary rays in packets of 16 (4 × 4 pixels,
//! `mirador::trace::accel::wide::packets`), as the tracer does for centre-sampled images. A
//! table after the rows sets packets against single rays on the wide BVH for the three kinds of
//! ray: primary, shadow (each to its light's distance) and reflected, from the same hits in the
//! blocks' order (`-- packets` prints it alone with Mirador's rows).
//!
//! The peers use their own idioms: obvhs its two-sided Möller–Trumbore `Triangle::intersect`
//! with the triangles reordered into leaf order (as its examples recommend) and its
//! `medium_build` preset, for its binary BVH (Bvh2) and its 8-wide compressed BVH (CWBVH);
//! `bvh` its distance-ordered iterator (stopping once the next leaf starts beyond the nearest
//! hit) with the same two-sided Möller–Trumbore test, since its own triangle test culls back
//! faces. Mirador uses its watertight test (Woop et al.), which does a little more work per
//! triangle.

use std::time::{Duration, Instant};

use glam::{Vec3, Vec3A};
use mirador::base::Ray;
use mirador::trace::accel::Accelerator;
use mirador::trace::accel::bvh::Bvh;
use mirador::trace::accel::wide::Wide;
use mirador::trace::geometry::Primitive;
use rayon::prelude::*;

const SLICES: u32 = 1024;
const STACKS: u32 = 512;
const WIDTH: u32 = 512;
const HEIGHT: u32 = 512;
/// Passes per figure unless `--repeats=N` says otherwise.
const REPEATS: usize = 3;
const SHADOW_T_MIN: f32 = 1e-4;

/// A ray as every library is handed it.
#[derive(Clone, Copy)]
struct Query {
    origin: Vec3,
    direction: Vec3,
    t_min: f32,
    t_max: f32,
}

/// A sphere with bumps of ±4 %: sums of sines in longitude and latitude.
fn displaced_sphere() -> Vec<[Vec3; 3]> {
    let point = |i: u32, j: u32| {
        let (theta, phi) =
            (std::f32::consts::PI * j as f32 / STACKS as f32, std::f32::consts::TAU * i as f32 / SLICES as f32);
        let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin());
        let bumps =
            0.025 * (7.0 * phi).sin() * (5.0 * theta).sin() + 0.015 * (23.0 * phi + 3.0).sin() * (19.0 * theta).cos();
        n * (1.0 + bumps * theta.sin())
    };
    let mut tris = Vec::with_capacity((2 * SLICES * STACKS) as usize);
    for j in 0..STACKS {
        for i in 0..SLICES {
            // The seam's vertices are the same points (index i wraps), so the mesh is closed.
            let (a, b, c, d) =
                (point(i, j), point((i + 1) % SLICES, j), point(i, j + 1), point((i + 1) % SLICES, j + 1));
            if j != 0 {
                tris.push([a, c, b]);
            }
            if j != STACKS - 1 {
                tris.push([b, c, d]);
            }
        }
    }
    tris
}

fn primary_rays() -> Vec<Query> {
    let eye = Vec3::new(0.4, 0.8, 3.2);
    let forward = (Vec3::ZERO - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let half = half_angle().to_radians().tan();
    (0..WIDTH * HEIGHT)
        .map(|k| {
            let (x, y) = ((k % WIDTH) as f32 + 0.5, (k / WIDTH) as f32 + 0.5);
            let s = (2.0 * x / WIDTH as f32 - 1.0) * half;
            let t = (1.0 - 2.0 * y / HEIGHT as f32) * half;
            Query {
                origin: eye,
                direction: (forward + s * right + t * up).normalize(),
                t_min: 0.0,
                t_max: f32::INFINITY,
            }
        })
        .collect()
}

/// CPU time this thread has run (`CLOCK_THREAD_CPUTIME_ID`); `None` where there is no such
/// clock. (Linux's `/proc/thread-self/schedstat` counts whole scheduler ticks, 4 ms on the
/// project's machine: a tenth of a primary-ray pass, which made the figures jump by 10 %.)
#[cfg(any(target_os = "linux", target_os = "macos", target_os = "freebsd"))]
fn thread_cpu_time() -> Option<Duration> {
    let mut now = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `now` is a valid `timespec` for the call to write.
    let status = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut now) };
    (status == 0).then(|| Duration::new(now.tv_sec as u64, now.tv_nsec as u32))
}

#[cfg(not(any(target_os = "linux", target_os = "macos", target_os = "freebsd")))]
fn thread_cpu_time() -> Option<Duration> {
    None
}

/// How long `run` takes: by this thread's CPU time if `on_this_thread` and the system reports
/// it, else by the wall clock.
fn timed<R>(on_this_thread: bool, run: impl FnOnce() -> R) -> (Duration, R) {
    let clock = || if on_this_thread { thread_cpu_time() } else { None };
    let (start, wall) = (clock(), Instant::now());
    let result = run();
    let time = match (start, clock()) {
        (Some(a), Some(b)) => b - a,
        _ => wall.elapsed(),
    };
    (time, result)
}

/// Passes per figure: `--repeats=N`, else [`REPEATS`]. Exits with a message for `--repeats`
/// without `=N` (its number would be taken as a peer's name) or with an `N` that is not a whole
/// number from 1.
fn repeats() -> usize {
    static REPEATS_ASKED: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *REPEATS_ASKED.get_or_init(|| {
        let mut asked = REPEATS;
        for arg in std::env::args().skip(1) {
            if arg == "--repeats" {
                eprintln!("trace bench: write --repeats=N (with '='), e.g. --repeats=9");
                std::process::exit(2);
            }
            if let Some(n) = arg.strip_prefix("--repeats=") {
                match n.parse() {
                    Ok(n) if n >= 1 => asked = n,
                    _ => {
                        eprintln!("trace bench: --repeats={n}: expected a whole number from 1");
                        std::process::exit(2);
                    }
                }
            }
        }
        asked
    })
}

/// The camera's half field of view in degrees: `--half-angle=DEG`, else 22°, which sees the whole
/// sphere (about half the rays miss it); 9° sees only the sphere (every ray hits).
fn half_angle() -> f32 {
    let asked = std::env::args().skip(1).find_map(|a| a.strip_prefix("--half-angle=").map(String::from));
    match asked.map(|a| a.parse::<f32>()) {
        None => 22.0,
        Some(Ok(degrees)) if degrees > 0.0 && degrees < 90.0 => degrees,
        Some(_) => {
            eprintln!("trace bench: --half-angle=DEG: expected degrees between 0 and 90");
            std::process::exit(2);
        }
    }
}

/// `--dump=FOLDER`: writes the mesh (`triangles.f32`, nine little-endian `f32` a triangle) and
/// the primary rays (`primary.f32`, origin and direction, six a ray) for another library's run
/// on the same work (`benches/embree.py`).
fn dump(tris: &[[Vec3; 3]], primary: &[Query]) {
    let Some(folder) = std::env::args().skip(1).find_map(|a| a.strip_prefix("--dump=").map(String::from)) else {
        return;
    };
    let bytes = |values: &mut dyn Iterator<Item = f32>| values.flat_map(f32::to_le_bytes).collect::<Vec<u8>>();
    let folder = std::path::Path::new(&folder);
    let written = std::fs::create_dir_all(folder)
        .and_then(|_| {
            std::fs::write(folder.join("triangles.f32"), bytes(&mut tris.iter().flatten().flat_map(|v| v.to_array())))
        })
        .and_then(|_| {
            let rays = primary.iter().flat_map(|q| q.origin.to_array().into_iter().chain(q.direction.to_array()));
            std::fs::write(folder.join("primary.f32"), bytes(&mut { rays }))
        });
    if let Err(e) = written {
        eprintln!("trace bench: --dump={}: {e}", folder.display());
        std::process::exit(2);
    }
    println!("wrote the mesh and the primary rays to {}", folder.display());
}

/// The best of [`repeats`] passes of `run`, which returns a count to check.
fn best_of(on_this_thread: bool, run: impl Fn() -> usize) -> (Duration, usize) {
    (0..repeats()).map(|_| timed(on_this_thread, &run)).min_by_key(|(time, _)| *time).expect("at least one pass")
}

/// Rays per second through `hit` on one thread and on all threads, and how many hit.
struct Throughput {
    single: f64,
    parallel: f64,
    hits: usize,
}

fn throughput(queries: &[Query], hit: impl Fn(&Query) -> bool + Sync) -> Throughput {
    // Warm-up: caches, page faults, rayon's threads.
    let _ = queries.par_iter().take(20_000).filter(|q| hit(q)).count();
    let (single_time, hits) = best_of(true, || queries.iter().filter(|q| hit(q)).count());
    let (parallel_time, _) =
        best_of(false, || queries.par_chunks(256).map(|c| c.iter().filter(|q| hit(q)).count()).sum());
    let rate = |t: Duration| queries.len() as f64 / t.as_secs_f64();
    Throughput { single: rate(single_time), parallel: rate(parallel_time), hits }
}

struct Row {
    name: &'static str,
    build: Duration,
    primary: Throughput,
    shadow: Throughput,
}

/// Two-sided Möller–Trumbore, as obvhs writes it, for the `bvh` crate's shapes.
fn moller_trumbore(v: &[Vec3A; 3], origin: Vec3A, direction: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let e1 = v[0] - v[1];
    let e2 = v[2] - v[0];
    let n = e1.cross(e2);
    let c = v[0] - origin;
    let r = direction.cross(c);
    let inv_det = 1.0 / n.dot(direction);
    let u = r.dot(e2) * inv_det;
    let w = r.dot(e1) * inv_det;
    let valid = inv_det != 0.0 && u >= 0.0 && w >= 0.0 && u + w <= 1.0;
    let t = n.dot(c) * inv_det;
    (valid && t > t_min && t < t_max).then_some(t)
}

struct BvhShape {
    v: [Vec3A; 3],
    node: usize,
}

impl bvh::aabb::Bounded<f32, 3> for BvhShape {
    fn aabb(&self) -> bvh::aabb::Aabb<f32, 3> {
        let (lo, hi) = (self.v[0].min(self.v[1]).min(self.v[2]), self.v[0].max(self.v[1]).max(self.v[2]));
        bvh::aabb::Aabb::with_bounds(lo.to_array().into(), hi.to_array().into())
    }
}

impl bvh::bounding_hierarchy::BHShape<f32, 3> for BvhShape {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node = index;
    }

    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// Mirador's BVH as `build` makes it, binary or wide.
fn mirador_row<A: Accelerator>(
    name: &'static str,
    build: impl Fn(&[Primitive]) -> A,
    tris: &[[Vec3; 3]],
    primary: &[Query],
    shadow: &[Query],
) -> Row {
    let prims: Vec<Primitive> = tris.iter().copied().map(Primitive::flat_triangle).collect();
    let (build_time, accel) = timed(true, || build(&prims));
    println!("{}", accel.stats());
    let ray = |q: &Query| Ray { origin: q.origin, direction: q.direction };
    Row {
        name,
        build: build_time,
        primary: throughput(primary, |q| accel.closest(&prims, &ray(q), q.t_min, q.t_max).is_some()),
        shadow: throughput(shadow, |q| accel.occluded(&prims, &ray(q), q.t_min, q.t_max)),
    }
}

/// The primary rays in blocks of 4 × 4 pixels, as the tracer hands them to packets.
fn in_blocks(primary: &[Query]) -> Vec<Query> {
    let mut blocks = Vec::with_capacity(primary.len());
    for by in (0..HEIGHT).step_by(4) {
        for bx in (0..WIDTH).step_by(4) {
            for y in by..by + 4 {
                blocks.extend((bx..bx + 4).map(|x| primary[(y * WIDTH + x) as usize]));
            }
        }
    }
    blocks
}

/// The wide BVH tracing the primary rays 16 at a time (`closest_packets`); shadow rays one by one,
/// as the row above (measured again).
fn packets_row(tris: &[[Vec3; 3]], primary: &[Query], shadow: &[Query]) -> Row {
    let prims: Vec<Primitive> = tris.iter().copied().map(Primitive::flat_triangle).collect();
    let (build_time, accel) = timed(true, || Wide::build(&prims));
    let blocks = in_blocks(primary);
    let rays: Vec<Ray> = blocks.iter().map(|q| Ray { origin: q.origin, direction: q.direction }).collect();
    let trace = |rays: &[Ray]| {
        let mut hits = vec![None; rays.len()];
        accel.closest_packets(&prims, rays, 0.0, f32::INFINITY, &mut hits);
        hits.iter().filter(|h| h.is_some()).count()
    };
    let _ = rays.par_chunks(256).take(80).map(trace).sum::<usize>();
    let (single_time, hits) = best_of(true, || rays.chunks(256).map(trace).sum());
    let (parallel_time, _) = best_of(false, || rays.par_chunks(256).map(trace).sum());
    let rate = |t: Duration| rays.len() as f64 / t.as_secs_f64();
    let shadow = throughput(shadow, |q| {
        accel.occluded(&prims, &Ray { origin: q.origin, direction: q.direction }, q.t_min, q.t_max)
    });
    Row {
        name: "wide, packets",
        build: build_time,
        primary: Throughput { single: rate(single_time), parallel: rate(parallel_time), hits },
        shadow,
    }
}

/// Packets against single rays on the wide BVH, for the three kinds of ray the tracer casts: the
/// primary rays in 4 × 4 blocks; from each hit, in the same order, a shadow ray to the light
/// (to its own distance) and the mirror reflection about the triangle's normal. Each kind is
/// traced one by one and in packets of 16, finding as many hits (checked); one thread and all.
fn packet_table(tris: &[[Vec3; 3]], primary: &[Query], light: Vec3) {
    let prims: Vec<Primitive> = tris.iter().copied().map(Primitive::flat_triangle).collect();
    let accel = Wide::build(&prims);
    let ray = |q: &Query| Ray { origin: q.origin, direction: q.direction };
    let blocks = in_blocks(primary);
    let mut hits = vec![None; blocks.len()];
    accel.closest_packets(&prims, &blocks.iter().map(ray).collect::<Vec<_>>(), 0.0, f32::INFINITY, &mut hits);
    let (mut shadow, mut reflected) = (Vec::new(), Vec::new());
    for (q, hit) in blocks.iter().zip(&hits) {
        let Some(hit) = hit else { continue };
        let p = ray(q).at(hit.t);
        let [a, b, c] = tris[hit.primitive as usize];
        let n = (b - a).cross(c - a).normalize();
        let to_light = light - p;
        shadow.push(Query {
            origin: p,
            direction: to_light.normalize(),
            t_min: SHADOW_T_MIN,
            t_max: to_light.length(),
        });
        let d = q.direction;
        reflected.push(Query {
            origin: p,
            direction: d - 2.0 * d.dot(n) * n,
            t_min: SHADOW_T_MIN,
            t_max: f32::INFINITY,
        });
    }
    println!();
    println!("packets against single rays (the wide BVH; the rays in 4 × 4 blocks of pixels, in that order):");
    println!(
        "{:<10} {:>9} {:>12} {:>12} {:>7} {:>12} {:>12} {:>7}",
        "", "rays", "single 1T", "packets 1T", "ratio", "single all", "packets all", "ratio"
    );
    // Each kind's rays and far bounds made once, outside the timed passes.
    let arrays = |queries: &[Query]| -> (Vec<Ray>, Vec<f32>) {
        (queries.iter().map(ray).collect(), queries.iter().map(|q| q.t_max).collect())
    };
    let (blocks_rays, shadow_rays, reflected_rays) = (arrays(&blocks), arrays(&shadow), arrays(&reflected));
    // The primary rays start at the eye (t_min 0), the others off a surface (SHADOW_T_MIN).
    let (accel, prims) = (&accel, &prims);
    let closest = |t_min: f32| {
        move |(rays, _): (&[Ray], &[f32])| -> usize {
            let mut hits = [None; 256];
            let hits = &mut hits[..rays.len()];
            accel.closest_packets(prims, rays, t_min, f32::INFINITY, hits);
            hits.iter().filter(|h| h.is_some()).count()
        }
    };
    let occluded = |(rays, t_max): (&[Ray], &[f32])| -> usize {
        let mut occluded = [false; 256];
        let occluded = &mut occluded[..rays.len()];
        accel.occluded_packets(prims, rays, (SHADOW_T_MIN, t_max), occluded);
        occluded.iter().filter(|&&o| o).count()
    };
    let (primary_closest, reflected_closest) = (closest(0.0), closest(SHADOW_T_MIN));
    type Packets<'a> = &'a (dyn Fn((&[Ray], &[f32])) -> usize + Sync);
    /// A kind of ray: its name, its queries, their rays and far bounds, and its packets' walk.
    type Kind<'a> = (&'a str, &'a [Query], &'a (Vec<Ray>, Vec<f32>), Packets<'a>);
    let kinds: [Kind; 3] = [
        ("primary", &blocks, &blocks_rays, &primary_closest),
        ("shadow", &shadow, &shadow_rays, &occluded),
        ("reflected", &reflected, &reflected_rays, &reflected_closest),
    ];
    for (name, queries, (rays, t_max), packets) in kinds {
        let one = |q: &Query| match name {
            "shadow" => accel.occluded(prims, &ray(q), q.t_min, q.t_max),
            _ => accel.closest(prims, &ray(q), q.t_min, q.t_max).is_some(),
        };
        let single = throughput(queries, one);
        let chunks = || rays.chunks(256).zip(t_max.chunks(256));
        let parallel_chunks = || rays.par_chunks(256).zip(t_max.par_chunks(256));
        let _ = parallel_chunks().take(80).map(|(r, t)| packets((r, t))).sum::<usize>();
        let (packet_time, packet_hits) = best_of(true, || chunks().map(|(r, t)| packets((r, t))).sum());
        let (parallel_time, _) = best_of(false, || parallel_chunks().map(|(r, t)| packets((r, t))).sum());
        assert_eq!(packet_hits, single.hits, "{name}: packets and single rays find as many hits");
        let rate = |t: Duration| queries.len() as f64 / t.as_secs_f64() / 1e6;
        let (packet, parallel) = (rate(packet_time), rate(parallel_time));
        println!(
            "{:<10} {:>9} {:>7.2} Mr/s {:>7.2} Mr/s {:>6.2}× {:>7.2} Mr/s {:>7.2} Mr/s {:>6.2}×",
            name,
            queries.len(),
            single.single / 1e6,
            packet,
            packet / (single.single / 1e6),
            single.parallel / 1e6,
            parallel,
            parallel / (single.parallel / 1e6)
        );
    }
}

fn obvhs_rows(tris: &[[Vec3; 3]], primary: &[Query], shadow: &[Query]) -> Vec<Row> {
    use obvhs::ray::{Ray as ORay, RayHit};
    let triangles: Vec<obvhs::triangle::Triangle> =
        tris.iter().map(|t| obvhs::triangle::Triangle { v0: t[0].into(), v1: t[1].into(), v2: t[2].into() }).collect();
    let oray = |q: &Query| ORay::new(q.origin.into(), q.direction.into(), q.t_min, q.t_max);
    let mut rows = Vec::new();

    let params = obvhs::BvhBuildParams::medium_build();
    let (build, bvh2) =
        timed(true, || obvhs::bvh2::builder::build_bvh2_from_tris(&triangles, params, &mut Duration::default()));
    let ordered: Vec<_> = bvh2.primitive_indices.iter().map(|&i| triangles[i as usize]).collect();
    rows.push(Row {
        name: "obvhs 0.4 bvh2",
        build,
        primary: throughput(primary, |q| {
            let mut hit = RayHit::none();
            bvh2.ray_traverse(oray(q), &mut hit, |r, id| ordered[id].intersect(r))
        }),
        shadow: throughput(shadow, |q| !bvh2.ray_traverse_miss(oray(q), |r, id| ordered[id].intersect(r))),
    });
    drop((bvh2, ordered));

    let (build, cwbvh) =
        timed(true, || obvhs::cwbvh::builder::build_cwbvh_from_tris(&triangles, params, &mut Duration::default()));
    let ordered: Vec<_> = cwbvh.primitive_indices.iter().map(|&i| triangles[i as usize]).collect();
    rows.push(Row {
        name: "obvhs 0.4 cwbvh",
        build,
        primary: throughput(primary, |q| {
            let mut hit = RayHit::none();
            cwbvh.ray_traverse(oray(q), &mut hit, |r, id| ordered[id].intersect(r))
        }),
        shadow: throughput(shadow, |q| !cwbvh.ray_traverse_miss(oray(q), |r, id| ordered[id].intersect(r))),
    });
    rows
}

fn bvh_crate_row(tris: &[[Vec3; 3]], primary: &[Query], shadow: &[Query]) -> Row {
    let mut shapes: Vec<BvhShape> = tris.iter().map(|t| BvhShape { v: t.map(Vec3A::from), node: 0 }).collect();
    let (build, tree) = timed(true, || bvh::bvh::Bvh::build(&mut shapes));
    let bray = |q: &Query| bvh::ray::Ray::new(q.origin.to_array().into(), q.direction.to_array().into());
    let closest = |q: &Query| {
        let ray = bray(q);
        let mut best = q.t_max;
        for shape in tree.nearest_traverse_iterator(&ray, &shapes) {
            // Leaves come out by the distance at which the ray enters their box.
            let entry =
                ray.intersection_slice_for_aabb(&bvh::aabb::Bounded::aabb(shape)).map_or(f32::INFINITY, |s| s.0);
            if entry > best {
                break;
            }
            if let Some(t) = moller_trumbore(&shape.v, q.origin.into(), q.direction.into(), q.t_min, best) {
                best = t;
            }
        }
        best < q.t_max
    };
    let occluded = |q: &Query| {
        let ray = bray(q);
        tree.traverse_iterator(&ray, &shapes)
            .any(|shape| moller_trumbore(&shape.v, q.origin.into(), q.direction.into(), q.t_min, q.t_max).is_some())
    };
    Row { name: "bvh 0.13", build, primary: throughput(primary, closest), shadow: throughput(shadow, occluded) }
}

fn main() {
    // Read `--repeats` first, so that a mistyped flag stops the run before the mesh is made.
    let _ = repeats();
    let total = Instant::now();
    let tris = displaced_sphere();
    let primary = primary_rays();
    dump(&tris, &primary);
    // Shadow rays from Mirador's primary hits toward a point light.
    let light = Vec3::new(3.0, 4.0, 2.0);
    let shadow: Vec<Query> = {
        let prims: Vec<Primitive> = tris.iter().copied().map(Primitive::flat_triangle).collect();
        let accel = Bvh::build(&prims);
        primary
            .par_iter()
            .filter_map(|q| {
                let ray = Ray { origin: q.origin, direction: q.direction };
                let hit = accel.closest(&prims, &ray, q.t_min, q.t_max)?;
                let p = ray.at(hit.t);
                let to_light = light - p;
                Some(Query {
                    origin: p,
                    direction: to_light.normalize(),
                    t_min: SHADOW_T_MIN,
                    t_max: to_light.length(),
                })
            })
            .collect()
    };
    let threads = rayon::current_num_threads();
    println!(
        "mesh: displaced sphere, {} triangles; {} primary rays ({WIDTH}×{HEIGHT}), {} shadow rays; \
         best of {}; {threads} threads",
        tris.len(),
        primary.len(),
        shadow.len(),
        repeats()
    );

    // `cargo bench --bench trace -- obvhs` runs Mirador and the peers whose names contain "obvhs".
    let filters: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let wanted = |name: &str| filters.is_empty() || filters.iter().any(|f| name.contains(f.as_str()));
    let mut rows = vec![
        mirador_row("mirador wide", Wide::build, &tris, &primary, &shadow),
        packets_row(&tris, &primary, &shadow),
        mirador_row("wide without AVX", Wide::build_without_avx, &tris, &primary, &shadow),
        mirador_row("mirador bvh", Bvh::build, &tris, &primary, &shadow),
    ];
    if wanted("obvhs") {
        rows.extend(obvhs_rows(&tris, &primary, &shadow));
    }
    if wanted("bvh 0.13") {
        rows.push(bvh_crate_row(&tris, &primary, &shadow));
    }

    println!();
    println!(
        "{:<18} {:>9} {:>12} {:>12} {:>12} {:>12} {:>9} {:>9}",
        "",
        "build",
        "primary 1T",
        "shadow 1T",
        format!("primary {threads}T"),
        format!("shadow {threads}T"),
        "hits",
        "occluded"
    );
    for r in &rows {
        println!(
            "{:<18} {:>7.2} s {:>7.2} Mr/s {:>7.2} Mr/s {:>7.2} Mr/s {:>7.2} Mr/s {:>9} {:>9}",
            r.name,
            r.build.as_secs_f64(),
            r.primary.single / 1e6,
            r.shadow.single / 1e6,
            r.primary.parallel / 1e6,
            r.shadow.parallel / 1e6,
            r.primary.hits,
            r.shadow.hits
        );
    }
    println!();
    println!(
        "ratios: the wide BVH's throughput over each other's (> 1: wide faster), their build time over its (> 1: wide builds faster)"
    );
    let ours = &rows[0];
    for peer in &rows[1..] {
        println!(
            "vs {:<15} {:>7.2}× {:>11.2}× {:>11.2}× {:>11.2}× {:>11.2}×",
            peer.name,
            peer.build.as_secs_f64() / ours.build.as_secs_f64(),
            ours.primary.single / peer.primary.single,
            ours.shadow.single / peer.shadow.single,
            ours.primary.parallel / peer.primary.parallel,
            ours.shadow.parallel / peer.shadow.parallel
        );
    }
    if wanted("packets") {
        packet_table(&tris, &primary, light);
    }
    println!();
    println!("total {:.1} s", total.elapsed().as_secs_f64());
}
