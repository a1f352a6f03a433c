//! World-space primitives for the ray tracer, their ray intersections and hit records.
//!
//! A [`Scene`] becomes a flat list of [`Primitive`]s ([`scene_primitives`]): every triangle of
//! every mesh in world space, and every analytic object (sphere, box, plane quad, torus, rounded
//! box) kept exact in its local space with its `world_from_local` transform. Seed 000 §2.2
//! ("intersecciones rayo-objeto"): the hit is the smallest root `t > 0` of `F(o + t·v) = 0` that
//! meets the object's extra conditions `C`, found by a direct formula or iteratively.
//!
//! - **Slabs** (Kay–Kajiya; docs/course/09-ray-tracing.md#intersections): a box is the intersection of three slabs; per axis
//!   `t₁ = (min − o)/d`, `t₂ = (max − o)/d`, and the ray is inside the box for
//!   `max(t_near) ≤ t ≤ min(t_far)`. With a precomputed inverse direction a zero component gives
//!   `±∞`, which is exactly right, except for `0·∞ = NaN` when the origin lies on the slab's
//!   plane: the bounds are picked by the direction's sign bit and compared so that a NaN
//!   leaves the interval unchanged, i.e. a ray lying in a face counts as inside the closed box.
//! - **Sphere** (direct, a quadric): `|o + t·d − c|² = r²`. The discriminant is taken in the form
//!   of Haines et al. (Ray Tracing Gems, ch. 7), `b² − ac = a·(r² − |oc − (b/a)·d|²)`, and the
//!   roots as `q = −(b + sign(b)·√Δ)`, `t = c/q, q/a`, which keeps both roots accurate far from the
//!   sphere. A tangent ray (Δ = 0) hits once; a ray starting inside hits the far side.
//! - **Triangle**: the watertight test of Woop, Benthin and Wald (JCGT 2013) instead of seed
//!   004's barycentric linear system solved with Cramer's rule. The ray is made the +z axis by a
//!   per-ray permutation and shear; each vertex is transformed once, the same way in every
//!   triangle that shares it, and the 2D edge functions `U, V, W` of the sheared vertices are
//!   exactly antisymmetric across a shared edge (recomputed in f64 when one rounds to 0), so a ray
//!   through an edge or vertex of a closed mesh always hits one of its triangles.
//! - **Analytic objects** are intersected in local space: `o_l = L·o`, `d_l = L·d` with
//!   `L = local_from_world`, and `d_l` is *not* renormalized, so `o_l + t·d_l` is the local image
//!   of `o + t·d` and `t` stays in world units for every affine transform (non-uniform scale too).
//! - **Torus and rounded box** by sphere tracing of their exact signed distance functions (seed
//!   000 §2.2): start where the ray enters the local bounding box, step `t += sdf(p)/|d_l|` (the
//!   SDF is a distance in local units; dividing by `|d_l|` turns it into a safe step in `t`), stop
//!   with a hit when `sdf < ε = SDF_EPSILON·(size + t·|d_l|)` (relative to the object's size and
//!   to how far the ray has gone, which is where f32 positions lose precision), then refine the
//!   hit with up to [`SDF_POLISH_STEPS`] safeguarded Newton steps; or miss after the box's exit
//!   or [`SDF_MAX_STEPS`] steps. A ray starting inside marches on `−sdf` to the far side; one
//!   starting on the surface (a secondary ray) marches away from it first. Limit: rays that
//!   graze the surface converge slowly and may run out of steps, eroding silhouettes by a
//!   fraction of a pixel.
//!
//! Hit records ([`SurfaceHit`]) are computed once, for the nearest hit only. Their texture
//! coordinates follow the rasterizer's tessellation in `src/scene/mesh.rs` exactly, so textures
//! and bump maps land on the same places in both renderers; `dpdu`, `dpdv` are `∂p/∂u`, `∂p/∂v`
//! of that same parametrization (docs/course/04-bump-mapping.md).

use std::f32::consts::{FRAC_PI_2, PI, TAU};

use glam::{Affine3A, Mat3, Vec2, Vec3, Vec3A};

use crate::base::{MaterialId, Ray};
use crate::scene::{Object, Scene, Shape};

/// Relative tolerance of sphere tracing: a hit is declared `SDF_EPSILON·(size + distance)`
/// from the surface, in local units.
pub const SDF_EPSILON: f32 = 1e-5;

/// The most steps sphere tracing takes before it declares a miss.
pub const SDF_MAX_STEPS: u32 = 512;

/// Newton steps taken after convergence to bring the hit onto the true surface.
pub const SDF_POLISH_STEPS: u32 = 3;

/// An axis-aligned bounding box; `min > max` on some axis means empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    /// The box containing nothing: the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    pub fn new(min: Vec3, max: Vec3) -> Aabb {
        Aabb { min, max }
    }

    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Aabb {
        points.into_iter().fold(Aabb::EMPTY, |b, p| b.including(p))
    }

    pub fn is_empty(&self) -> bool {
        !self.min.cmple(self.max).all()
    }

    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    pub fn including(&self, p: Vec3) -> Aabb {
        Aabb { min: self.min.min(p), max: self.max.max(p) }
    }

    /// `max − min`, zero for an empty box.
    pub fn extent(&self) -> Vec3 {
        if self.is_empty() { Vec3::ZERO } else { self.max - self.min }
    }

    /// `2(xy + yz + zx)`: the SAH's measure of how likely a random ray is to hit the box.
    pub fn surface_area(&self) -> f32 {
        let d = self.extent();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// The axis (0, 1, 2 for x, y, z) along which the box is longest.
    pub fn longest_axis(&self) -> usize {
        let d = self.extent();
        if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        }
    }

    /// Whether the closed boxes share a point.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    pub fn contains(&self, p: Vec3) -> bool {
        self.min.cmple(p).all() && p.cmple(self.max).all()
    }

    /// The box grown by `margin` on every side.
    pub fn padded(&self, margin: f32) -> Aabb {
        Aabb { min: self.min - Vec3::splat(margin), max: self.max + Vec3::splat(margin) }
    }

    /// The world box around this local box carried by `world_from_local` (its eight corners).
    pub fn transformed(&self, world_from_local: &Affine3A) -> Aabb {
        if self.is_empty() {
            return Aabb::EMPTY;
        }
        Aabb::from_points((0..8).map(|i| {
            let corner = Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            world_from_local.transform_point3(corner)
        }))
    }

    /// Kay–Kajiya slabs: the part `[t_enter, t_exit]` of `[t_min, t_max]` where the ray is inside
    /// the closed box, or `None`.
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<(f32, f32)> {
        self.intersect_inv(ray.origin, ray.direction.recip(), t_min, t_max)
    }

    /// [`Aabb::intersect`] with a precomputed `1/direction` (components may be `±∞`).
    #[inline]
    pub fn intersect_inv(&self, origin: Vec3, inv_direction: Vec3, t_min: f32, t_max: f32) -> Option<(f32, f32)> {
        let (mut enter, mut exit) = (t_min, t_max);
        for axis in 0..3 {
            let inv = inv_direction[axis];
            // The near plane is picked by the sign bit, so that −0.0 (inverse −∞) is handled
            // like any other negative direction.
            let (near, far) = if inv.is_sign_negative() {
                (self.max[axis], self.min[axis])
            } else {
                (self.min[axis], self.max[axis])
            };
            let t_near = (near - origin[axis]) * inv;
            let t_far = (far - origin[axis]) * inv;
            // NaN (0·∞: the origin on this slab's plane, the ray parallel to it) compares false
            // and so leaves the interval unchanged: the line lies in the closed slab.
            if t_near > enter {
                enter = t_near;
            }
            if t_far < exit {
                exit = t_far;
            }
        }
        (enter <= exit).then_some((enter, exit))
    }
}

/// A ray with what every intersection test of it needs, computed once per ray: the inverse
/// direction for slabs and the permutation and shear of the watertight triangle test.
#[derive(Clone, Copy, Debug)]
pub struct PreparedRay {
    pub origin: Vec3A,
    pub direction: Vec3A,
    pub inv_direction: Vec3A,
    /// The watertight test's frame: `kx, ky, kz`, with `kz` the direction's largest axis.
    pub(crate) axes: [usize; 3],
    /// Its shear `Sx, Sy, Sz`, which maps `A = v − origin` to the ray's frame: `x = A[kx] − Sx·A[kz]`,
    /// `y = A[ky] − Sy·A[kz]` across the ray (sheared so that the ray is the z axis), `z = Sz·A[kz]`
    /// the distance along it divided by the largest direction component.
    pub(crate) shear: Vec3A,
}

impl PreparedRay {
    /// `None` for a ray that cannot hit anything: a NaN or infinite origin or direction, or a
    /// zero direction.
    pub fn new(ray: &Ray) -> Option<PreparedRay> {
        let (origin, direction) = (load_apart(&ray.origin), load_apart(&ray.direction));
        if !origin.is_finite() || !direction.is_finite() || direction == Vec3A::ZERO {
            return None;
        }
        // Woop et al.: z is the direction's largest axis; x, y are swapped when it is negative to
        // keep the triangles' winding (and so the sign of the edge functions) unchanged.
        let abs = direction.abs();
        let kz = if abs.x >= abs.y && abs.x >= abs.z {
            0
        } else if abs.y >= abs.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let shear = Vec3A::new(direction[kx] / direction[kz], direction[ky] / direction[kz], 1.0 / direction[kz]);
        Some(PreparedRay { origin, direction, inv_direction: direction.recip(), axes: [kx, ky, kz], shear })
    }

    /// `v` in the ray's sheared frame.
    #[inline(always)]
    fn local(&self, v: Vec3A) -> Vec3A {
        let a = v - self.origin;
        let [kx, ky, kz] = self.axes;
        Vec3A::new(a[kx] - self.shear.x * a[kz], a[ky] - self.shear.y * a[kz], self.shear.z * a[kz])
    }
}

/// `v`, read one coordinate at a time.
///
/// A caller usually has just written the ray, a coordinate or two at a time. Left to itself the
/// compiler reads `origin` as one 16-byte load that spans three of those writes (and `direction`
/// across two), and a CPU cannot forward a load from several pending writes: it waits until they
/// reach the cache, about 20 cycles, once for every ray. Volatile reads are never merged; nothing
/// depends on them for correctness, only the code the compiler makes.
/// (`cargo bench --bench trace`: a ray that misses the mesh's box took 29.5 ns, now 23.0; primary
/// rays 12 % faster through the wide BVH, 4 % through the binary one.)
#[inline(always)]
fn load_apart(v: &Vec3) -> Vec3A {
    // SAFETY: each pointer comes from a reference to an `f32`, valid and aligned for the read.
    let read = |x: &f32| unsafe { std::ptr::read_volatile(x) };
    Vec3A::new(read(&v.x), read(&v.y), read(&v.z))
}

/// Woop–Benthin–Wald: `(U, V, W, det, T)` with the hit at `t = T/det` and barycentric weights
/// `U/det, V/det, W/det` of `v0, v1, v2`; `None` if the ray's line misses the triangle.
#[inline(always)]
fn watertight(ray: &PreparedRay, v0: Vec3A, v1: Vec3A, v2: Vec3A) -> Option<(f32, f32, f32, f32, f32)> {
    let (a, b, c) = (ray.local(v0), ray.local(v1), ray.local(v2));
    let mut u = c.x * b.y - c.y * b.x;
    let mut v = a.x * c.y - a.y * c.x;
    let mut w = b.x * a.y - b.y * a.x;
    if u == 0.0 || v == 0.0 || w == 0.0 {
        // An edge function that rounds to zero may have a sign only double precision can see;
        // products of two f32 are exact in f64, so the sign is then right.
        let edge = |p: Vec3A, q: Vec3A| (p.x as f64 * q.y as f64 - p.y as f64 * q.x as f64) as f32;
        u = edge(c, b);
        v = edge(a, c);
        w = edge(b, a);
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let t_scaled = u * a.z + v * b.z + w * c.z;
    Some((u, v, w, det, t_scaled))
}

/// The watertight ray–triangle test: the hit distance in `(t_min, t_max)`, two-sided.
#[inline(always)]
pub fn intersect_triangle(ray: &PreparedRay, v0: Vec3A, v1: Vec3A, v2: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let (_, _, _, det, t_scaled) = watertight(ray, v0, v1, v2)?;
    let t = t_scaled / det;
    (t > t_min && t < t_max).then_some(t)
}

/// The roots of `|o + t·d − c|² = r²` in increasing order, computed stably; `None` if the line
/// misses the sphere.
fn sphere_roots(o: Vec3, d: Vec3, center: Vec3, radius: f32) -> Option<(f32, f32)> {
    if !(radius > 0.0) {
        return None;
    }
    let oc = o - center;
    let a = d.dot(d);
    let b = oc.dot(d);
    let c = oc.dot(oc) - radius * radius;
    // `b² − a·c` loses every digit when |oc| ≫ r; the distance from the centre to the line does not.
    let l = oc - (b / a) * d;
    let discriminant = a * (radius * radius - l.dot(l));
    if !(discriminant >= 0.0) {
        return None;
    }
    let q = -(b + discriminant.sqrt().copysign(b));
    if q == 0.0 {
        // b = 0 and a tangent line: a double root where the origin already is.
        return Some((0.0, 0.0));
    }
    let (t0, t1) = (c / q, q / a);
    Some((t0.min(t1), t0.max(t1)))
}

/// The first of `roots` inside the open interval `(t_min, t_max)`.
fn first_root_in(roots: (f32, f32), t_min: f32, t_max: f32) -> Option<f32> {
    let inside = |t: f32| t > t_min && t < t_max;
    if inside(roots.0) {
        Some(roots.0)
    } else if inside(roots.1) {
        Some(roots.1)
    } else {
        None
    }
}

/// A triangle in world space with its vertex attributes.
#[derive(Clone, Debug, PartialEq)]
pub struct Triangle {
    pub positions: [Vec3; 3],
    /// Unit shading normals, already in world space.
    pub normals: [Vec3; 3],
    pub uvs: [Vec2; 3],
    pub object: usize,
    pub material: MaterialId,
}

/// An analytic shape in its local coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum AnalyticShape {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    Cuboid {
        min: Vec3,
        max: Vec3,
    },
    /// `|x| ≤ size.x/2, |z| ≤ size.y/2` at y = 0.
    Plane {
        size: Vec2,
        uv_scale: Vec2,
    },
    Torus {
        major: f32,
        minor: f32,
    },
    /// `steps`: the rounded rim's tessellation steps in the rasterizer's mesh, which its texture
    /// coordinates follow (see [`Primitive::surface`]).
    RoundedBox {
        half: Vec3,
        radius: f32,
        steps: u32,
    },
}

impl AnalyticShape {
    fn local_bounds(&self) -> Aabb {
        match *self {
            AnalyticShape::Sphere { center, radius } => Aabb::new(center - radius, center + radius),
            AnalyticShape::Cuboid { min, max } => Aabb::new(min, max),
            AnalyticShape::Plane { size, .. } => {
                let half = Vec3::new(size.x / 2.0, 0.0, size.y / 2.0);
                Aabb::new(-half, half)
            }
            AnalyticShape::Torus { major, minor } => {
                let half = Vec3::new(major + minor, minor, major + minor);
                Aabb::new(-half, half)
            }
            AnalyticShape::RoundedBox { half, radius, .. } => Aabb::new(-half - radius, half + radius),
        }
    }

    /// The exact signed distance, for the two shapes that are sphere traced.
    fn sdf(&self, p: Vec3) -> f32 {
        match *self {
            AnalyticShape::Torus { major, minor } => {
                Vec2::new(Vec2::new(p.x, p.z).length() - major, p.y).length() - minor
            }
            AnalyticShape::RoundedBox { half, radius, .. } => {
                let q = p.abs() - half;
                q.max(Vec3::ZERO).length() + q.max_element().min(0.0) - radius
            }
            _ => unreachable!("only tori and rounded boxes are sphere traced"),
        }
    }

    /// The outward unit normal at (or near) a surface point of a torus or rounded box.
    fn sdf_normal(&self, p: Vec3) -> Vec3 {
        match *self {
            AnalyticShape::Torus { major, .. } => {
                let radial = Vec3::new(p.x, 0.0, p.z).try_normalize().unwrap_or(Vec3::X);
                (p - major * radial).try_normalize().unwrap_or(Vec3::Y)
            }
            AnalyticShape::RoundedBox { half, .. } => (p - p.clamp(-half, half))
                .try_normalize()
                .unwrap_or_else(|| dominant_axis(p / half.max(Vec3::splat(f32::MIN_POSITIVE)))),
            _ => unreachable!("only tori and rounded boxes are sphere traced"),
        }
    }
}

/// The signed unit axis along which `v` is largest in magnitude.
fn dominant_axis(v: Vec3) -> Vec3 {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        Vec3::X * v.x.signum()
    } else if a.y >= a.z {
        Vec3::Y * v.y.signum()
    } else {
        Vec3::Z * v.z.signum()
    }
}

/// An analytic object kept in its local space.
#[derive(Clone, Debug, PartialEq)]
pub struct Analytic {
    pub shape: AnalyticShape,
    pub world_from_local: Affine3A,
    pub local_from_world: Affine3A,
    /// Inverse transpose of `world_from_local`'s linear part: carries local normals to world.
    pub normal_from_local: Mat3,
    pub object: usize,
    pub material: MaterialId,
    bounds: Aabb,
    /// Radius of the local bounding sphere around the origin, the scale of the SDF tolerance.
    size: f32,
}

impl Analytic {
    /// `None` when the object cannot be hit: a non-finite or singular transform, or a shape of
    /// zero or non-finite size.
    pub fn new(
        shape: AnalyticShape,
        world_from_local: glam::Mat4,
        object: usize,
        material: MaterialId,
    ) -> Option<Analytic> {
        let world_from_local = Affine3A::from_mat4(world_from_local);
        let determinant = world_from_local.matrix3.determinant();
        if !world_from_local.is_finite() || !determinant.is_normal() {
            return None;
        }
        let valid = match shape {
            AnalyticShape::Sphere { center, radius } => center.is_finite() && radius.is_finite() && radius > 0.0,
            AnalyticShape::Cuboid { min, max } => min.is_finite() && max.is_finite() && min.cmplt(max).all(),
            AnalyticShape::Plane { size, uv_scale } => {
                size.is_finite()
                    && size.cmpgt(Vec2::ZERO).all()
                    && uv_scale.is_finite()
                    && uv_scale.cmpgt(Vec2::ZERO).all()
            }
            AnalyticShape::Torus { major, minor } => {
                major.is_finite() && minor.is_finite() && minor > 0.0 && major > 0.0
            }
            AnalyticShape::RoundedBox { half, radius, .. } => {
                half.is_finite() && half.cmpge(Vec3::ZERO).all() && radius.is_finite() && radius > 0.0
            }
        };
        if !valid {
            return None;
        }
        let local = shape.local_bounds();
        let size = local.min.abs().max(local.max.abs()).length();
        let world = local.transformed(&world_from_local);
        // Hit points are computed in local space and mapped back with rounding; a relative margin
        // keeps them inside the box the accelerators test (and gives the flat plane a thickness).
        let margin = 1e-5 * (world.extent().max_element() + world.min.abs().max(world.max.abs()).max_element());
        Some(Analytic {
            shape,
            local_from_world: world_from_local.inverse(),
            normal_from_local: Mat3::from(world_from_local.matrix3).inverse().transpose(),
            world_from_local,
            object,
            material,
            bounds: world.padded(margin),
            size,
        })
    }

    fn local_ray(&self, ray: &Ray) -> (Vec3, Vec3) {
        (self.local_from_world.transform_point3(ray.origin), self.local_from_world.transform_vector3(ray.direction))
    }

    fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<f32> {
        let (o, d) = self.local_ray(ray);
        if !o.is_finite() || !d.is_finite() || d == Vec3::ZERO {
            return None;
        }
        match self.shape {
            AnalyticShape::Sphere { center, radius } => {
                first_root_in(sphere_roots(o, d, center, radius)?, t_min, t_max)
            }
            AnalyticShape::Cuboid { min, max } => {
                let (enter, exit) =
                    Aabb::new(min, max).intersect_inv(o, d.recip(), f32::NEG_INFINITY, f32::INFINITY)?;
                first_root_in((enter, exit), t_min, t_max)
            }
            AnalyticShape::Plane { size, .. } => {
                // A ray parallel to the plane, even one lying in it, misses.
                if d.y == 0.0 {
                    return None;
                }
                let t = -o.y / d.y;
                if !(t > t_min && t < t_max) {
                    return None;
                }
                let p = o + t * d;
                (p.x.abs() <= size.x / 2.0 && p.z.abs() <= size.y / 2.0).then_some(t)
            }
            AnalyticShape::Torus { .. } | AnalyticShape::RoundedBox { .. } => self.sphere_trace(o, d, t_min, t_max),
        }
    }

    /// Sphere tracing (docs/course/09-ray-tracing.md#intersections) in local space with `t` in world units.
    fn sphere_trace(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
        let d_len = d.length();
        let (enter, exit) = self.shape.local_bounds().intersect_inv(o, d.recip(), t_min, t_max)?;
        let epsilon = |t: f32| SDF_EPSILON * (self.size + t.abs() * d_len);
        let mut t = enter;
        // Marching on `side·sdf` finds the surface from outside (side 1) or inside (side −1).
        let (mut side, mut armed) = (1.0, true);
        if enter <= t_min {
            let p = o + t * d;
            let start = self.shape.sdf(p);
            if start.abs() >= epsilon(t) {
                side = start.signum();
            } else {
                // Starting on the surface (a secondary ray): go the way the ray leaves, and do not
                // take the surface just left as a hit until the ray has moved ε away from it.
                side = if self.shape.sdf_normal(p).dot(d) >= 0.0 { 1.0 } else { -1.0 };
                armed = false;
            }
        }
        for _ in 0..SDF_MAX_STEPS {
            if t > exit {
                return None;
            }
            let distance = side * self.shape.sdf(o + t * d);
            let eps = epsilon(t);
            if distance < eps {
                if armed {
                    let hit = self.polish(o, d, t, distance, side);
                    return (hit > t_min && hit < t_max).then_some(hit);
                }
            } else {
                armed = true;
            }
            t += distance.max(eps) / d_len;
        }
        None
    }

    /// Refines a converged sphere-tracing hit. The tolerance alone leaves the hit up to ε early
    /// along the ray, i.e. displaced sideways on the surface by up to ε·tan θ (θ between the ray
    /// and the normal), which shows in the texture coordinates. Newton steps on
    /// `g(t) = side·sdf(o + t·d)`, whose derivative `side·∇sdf·d` is known analytically, remove
    /// nearly all of it; a step is kept only if it shrinks |g|, and near-grazing rays, where
    /// Newton is unreliable, take the always-safe sphere step instead.
    fn polish(&self, o: Vec3, d: Vec3, mut t: f32, mut gap: f32, side: f32) -> f32 {
        let d_len = d.length();
        for _ in 0..SDF_POLISH_STEPS {
            let slope = side * self.shape.sdf_normal(o + t * d).dot(d);
            let step = if slope < -0.1 * d_len { -gap / slope } else { gap.max(0.0) / d_len };
            let next_gap = side * self.shape.sdf(o + (t + step) * d);
            if !(next_gap.abs() < gap.abs()) {
                break;
            }
            t += step;
            gap = next_gap;
        }
        t
    }

    fn surface(&self, ray: &Ray, t: f32) -> SurfaceHit {
        let (o, d) = self.local_ray(ray);
        let mut p = o + t * d;
        let (normal, uv, dpdu, dpdv) = match self.shape {
            AnalyticShape::Sphere { center, radius } => {
                // Back onto the sphere: removes the rounding of `o + t·d` from the hit point.
                let n = (p - center).try_normalize().unwrap_or(Vec3::Y);
                p = center + radius * n;
                let (uv, dpdu, dpdv) = sphere_parametrization(n, radius);
                (n, uv, dpdu, dpdv)
            }
            AnalyticShape::Cuboid { min, max } => cuboid_parametrization(p, min, max),
            AnalyticShape::Plane { size, uv_scale } => {
                let uv = Vec2::new(p.x / size.x + 0.5, p.z / size.y + 0.5) * uv_scale;
                let dpdu = Vec3::X * (size.x / uv_scale.x);
                let dpdv = Vec3::Z * (size.y / uv_scale.y);
                (Vec3::Y, uv, dpdu, dpdv)
            }
            AnalyticShape::Torus { major, minor } => torus_parametrization(p, major, minor),
            AnalyticShape::RoundedBox { half, radius, steps } => {
                let n = self.shape.sdf_normal(p);
                let (uv, dpdu, dpdv) = rounded_box_parametrization(p, n, half, radius, steps);
                (n, uv, dpdu, dpdv)
            }
        };
        let world_normal = (self.normal_from_local * normal).try_normalize().unwrap_or(normal);
        SurfaceHit {
            t,
            point: self.world_from_local.transform_point3(p),
            geometric_normal: world_normal,
            normal: world_normal,
            uv,
            dpdu: self.world_from_local.transform_vector3(dpdu),
            dpdv: self.world_from_local.transform_vector3(dpdv),
            material: self.material,
            object: self.object,
        }
    }
}

/// `Mesh::sphere`'s parametrization of the unit direction `n`:
/// `n = (sin θ cos φ, cos θ, −sin θ sin φ)`, `u = φ/2π`, `v = θ/π`.
fn sphere_parametrization(n: Vec3, radius: f32) -> (Vec2, Vec3, Vec3) {
    let theta = n.y.clamp(-1.0, 1.0).acos();
    let mut phi = (-n.z).atan2(n.x);
    if phi < 0.0 {
        phi += TAU;
    }
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    // At the poles ∂p/∂φ vanishes; a tiny sin θ keeps its direction (the meridian's tangent).
    let sin_t_u = sin_t.max(1e-6);
    let dpdu = TAU * radius * Vec3::new(-sin_t_u * sin_p, 0.0, -sin_t_u * cos_p);
    let dpdv = PI * radius * Vec3::new(cos_t * cos_p, -sin_t, -cos_t * sin_p);
    (Vec2::new(phi / TAU, theta / PI), dpdu, dpdv)
}

/// `Mesh::cuboid`'s faces: the quad `origin + s·edge_u + t·edge_v` with `uv = (s, 1 − t)`, so
/// `∂p/∂u = edge_u`, `∂p/∂v = −edge_v`.
fn cuboid_parametrization(p: Vec3, min: Vec3, max: Vec3) -> (Vec3, Vec2, Vec3, Vec3) {
    let d = max - min;
    let (dx, dy, dz) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
    let faces = [
        (Vec3::X, (p.x - max.x).abs(), Vec3::new(max.x, min.y, max.z), -dz, dy),
        (Vec3::NEG_X, (p.x - min.x).abs(), min, dz, dy),
        (Vec3::Y, (p.y - max.y).abs(), Vec3::new(min.x, max.y, max.z), dx, -dz),
        (Vec3::NEG_Y, (p.y - min.y).abs(), min, dx, dz),
        (Vec3::Z, (p.z - max.z).abs(), Vec3::new(min.x, min.y, max.z), dx, dy),
        (Vec3::NEG_Z, (p.z - min.z).abs(), Vec3::new(max.x, min.y, min.z), -dx, dy),
    ];
    let (normal, _, origin, edge_u, edge_v) =
        faces.into_iter().min_by(|a, b| a.1.total_cmp(&b.1)).expect("a box has six faces");
    let s = (p - origin).dot(edge_u) / edge_u.length_squared();
    let t = (p - origin).dot(edge_v) / edge_v.length_squared();
    (normal, Vec2::new(s, 1.0 - t), edge_u, -edge_v)
}

/// `Mesh::torus`'s parametrization: `radial = (cos a, 0, −sin a)`,
/// `p = R·radial + r·(cos b·radial + sin b·y)`, `u = a/2π`, `v = b/2π`.
fn torus_parametrization(p: Vec3, major: f32, minor: f32) -> (Vec3, Vec2, Vec3, Vec3) {
    let mut a = (-p.z).atan2(p.x);
    if a < 0.0 {
        a += TAU;
    }
    let (sin_a, cos_a) = a.sin_cos();
    let radial = Vec3::new(cos_a, 0.0, -sin_a);
    let q = p - major * radial;
    let mut b = q.y.atan2(q.dot(radial));
    if b < 0.0 {
        b += TAU;
    }
    let (sin_b, cos_b) = b.sin_cos();
    let normal = cos_b * radial + sin_b * Vec3::Y;
    let dpdu = TAU * (major + minor * cos_b) * Vec3::new(-sin_a, 0.0, -cos_a);
    let dpdv = TAU * minor * (-sin_b * radial + cos_b * Vec3::Y);
    (normal, Vec2::new(a / TAU, b / TAU), dpdu, dpdv)
}

/// `Mesh::rounded_box`'s faces: (normal, u axis, v axis), in the mesh's order.
const ROUNDED_BOX_FACES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Z, Vec3::Y),
    (Vec3::NEG_X, Vec3::Z, Vec3::Y),
    (Vec3::Y, Vec3::X, Vec3::NEG_Z),
    (Vec3::NEG_Y, Vec3::X, Vec3::Z),
    (Vec3::Z, Vec3::X, Vec3::Y),
    (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
];

/// Tick `i` (0..=2·steps + 1) of `Mesh::rounded_box`'s grid along a face axis of half extent
/// `h`: `−h − r·cos(π/2·i/steps)` over the rim, the flat middle, then the rim mirrored. The
/// mesh gives tick `i` the texture coordinate `i/(2·steps + 1)`.
fn rounded_box_tick_at(i: u32, h: f32, radius: f32, steps: u32) -> f32 {
    if i <= steps {
        -h - radius * (FRAC_PI_2 * i as f32 / steps as f32).cos()
    } else {
        h + radius * (FRAC_PI_2 * (2 * steps + 1 - i) as f32 / steps as f32).cos()
    }
}

/// The (fractional) tick index of face coordinate `c`, linear between ticks as it is across
/// the mesh's triangles.
fn rounded_box_tick_index(c: f32, h: f32, radius: f32, steps: u32) -> f32 {
    let tick = |i: u32| rounded_box_tick_at(i, h, radius, steps);
    let last = 2 * steps + 1;
    if c <= tick(0) {
        return 0.0;
    }
    if c >= tick(last) {
        return last as f32;
    }
    let (mut lo, mut hi) = (0, last);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if tick(mid) <= c { lo = mid } else { hi = mid }
    }
    let (a, b) = (tick(lo), tick(hi));
    lo as f32 + if b > a { (c - a) / (b - a) } else { 0.5 }
}

/// The rounded box's texture coordinates as `Mesh::rounded_box` lays them out. The mesh's
/// vertices are points of the outer cube face moved onto the surface along `q → p` (`q` the
/// nearest point of the inner box), so the hit is moved back: onto the face the normal leans
/// towards most, along the same line, and its grid coordinates there give `uv` (linear between
/// grid ticks, as across the mesh's triangles). `∂p/∂u`, `∂p/∂v` follow by the chain rule.
fn rounded_box_parametrization(p: Vec3, n: Vec3, half: Vec3, radius: f32, steps: u32) -> (Vec2, Vec3, Vec3) {
    let (normal, u_axis, v_axis) =
        ROUNDED_BOX_FACES.into_iter().max_by(|a, b| n.dot(a.0).total_cmp(&n.dot(b.0))).expect("a box has six faces");
    let last = (2 * steps + 1) as f32;
    let (hu, hv) = (u_axis.abs().dot(half), v_axis.abs().dot(half));
    let q = p.clamp(-half, half);
    let on_face = q + radius * n / n.dot(normal).max(f32::MIN_POSITIVE);
    let iu = rounded_box_tick_index(on_face.dot(u_axis), hu, radius, steps);
    let iv = rounded_box_tick_index(on_face.dot(v_axis), hv, radius, steps);
    let uv = Vec2::new(iu / last, 1.0 - iv / last);
    // Chain rule through uv → tick index → face coordinate c → outer face point o → surface
    // S = q + r·(o − q)/|o − q|. Along an axis where o lies over the flat part (o = q there)
    // ∂S/∂o is that axis; where it overhangs the inner box, ∂S/∂o = r·(I − n·nᵀ)/|o − q|.
    let slope = |index: f32, h: f32| {
        let i = (index.floor().max(0.0) as u32).min(2 * steps);
        rounded_box_tick_at(i + 1, h, radius, steps) - rounded_box_tick_at(i, h, radius, steps)
    };
    let overhang = (on_face - q).length();
    let d_surface = |axis: Vec3, dc: f32| {
        if (on_face - q).dot(axis).abs() > 0.0 { radius * (axis - n * n.dot(axis)) / overhang * dc } else { axis * dc }
    };
    let dpdu = d_surface(u_axis, slope(iu, hu) * last);
    let dpdv = d_surface(v_axis, -slope(iv, hv) * last);
    (uv, dpdu, dpdv)
}

/// Something a ray can hit: a world-space triangle, or an analytic object in its local space
/// (boxed, so that the triangles of large meshes stay small and dense).
#[derive(Clone, Debug, PartialEq)]
pub enum Primitive {
    Triangle(Triangle),
    Analytic(Box<Analytic>),
}

/// Everything the shader needs about the nearest hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub t: f32,
    pub point: Vec3,
    /// Unit; outward for closed shapes, the face normal (counter-clockwise winding, or +y of a
    /// plane) for triangles and planes. Not flipped toward the viewer.
    pub geometric_normal: Vec3,
    /// Unit shading normal: interpolated for triangles, analytic otherwise. Not flipped toward
    /// the viewer (the shader does that).
    pub normal: Vec3,
    pub uv: Vec2,
    /// `∂p/∂u`, `∂p/∂v` in world space. For the rasterizer's image-like texture coordinates (v
    /// down the image) `dpdu × dpdv` points along −n on spheres, boxes and planes and along +n on
    /// tori; bump mapping orients the perturbed normal like `n` (docs/course/04-bump-mapping.md).
    pub dpdu: Vec3,
    pub dpdv: Vec3,
    pub material: MaterialId,
    pub object: usize,
}

impl Primitive {
    /// A triangle alone: its face normal at every corner, no texture coordinates, object 0 and
    /// material 0 (the accelerators' tests and benchmarks, which look at hits only).
    pub fn flat_triangle(positions: [Vec3; 3]) -> Primitive {
        let n = (positions[1] - positions[0]).cross(positions[2] - positions[0]).normalize_or_zero();
        Primitive::Triangle(Triangle {
            positions,
            normals: [n; 3],
            uvs: [Vec2::ZERO; 3],
            object: 0,
            material: MaterialId(0),
        })
    }

    pub fn bounds(&self) -> Aabb {
        match self {
            Primitive::Triangle(tri) => Aabb::from_points(tri.positions),
            Primitive::Analytic(a) => a.bounds,
        }
    }

    pub fn material(&self) -> MaterialId {
        match self {
            Primitive::Triangle(tri) => tri.material,
            Primitive::Analytic(a) => a.material,
        }
    }

    /// Index of the object in [`Scene::objects`] this primitive came from.
    pub fn object(&self) -> usize {
        match self {
            Primitive::Triangle(tri) => tri.object,
            Primitive::Analytic(a) => a.object,
        }
    }

    /// The hit distance in the open interval `(t_min, t_max)`, if any.
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<f32> {
        let prepared = PreparedRay::new(ray)?;
        self.intersect_prepared(ray, &prepared, t_min, t_max)
    }

    /// [`Primitive::intersect`] with the per-ray precomputation done once by the caller.
    #[inline]
    pub fn intersect_prepared(&self, ray: &Ray, prepared: &PreparedRay, t_min: f32, t_max: f32) -> Option<f32> {
        match self {
            Primitive::Triangle(tri) => {
                let [a, b, c] = tri.positions.map(Vec3A::from);
                intersect_triangle(prepared, a, b, c, t_min, t_max)
            }
            Primitive::Analytic(a) => a.intersect(ray, t_min, t_max),
        }
    }

    /// The full hit record at `t`, a distance [`Primitive::intersect`] returned for this ray.
    pub fn surface(&self, ray: &Ray, t: f32) -> SurfaceHit {
        match self {
            Primitive::Triangle(tri) => triangle_surface(tri, ray, t),
            Primitive::Analytic(a) => a.surface(ray, t),
        }
    }
}

fn triangle_surface(tri: &Triangle, ray: &Ray, t: f32) -> SurfaceHit {
    let [p0, p1, p2] = tri.positions;
    let point = ray.at(t);
    let face = (p1 - p0).cross(p2 - p0);
    let geometric_normal = face.try_normalize().unwrap_or(Vec3::Y);
    let barycentric = PreparedRay::new(ray)
        .and_then(|r| watertight(&r, p0.into(), p1.into(), p2.into()))
        .map(|(u, v, w, det, _)| Vec3::new(u, v, w) / det)
        .unwrap_or_else(|| barycentric_of_point(point, tri.positions, face));
    let normal = (barycentric.x * tri.normals[0] + barycentric.y * tri.normals[1] + barycentric.z * tri.normals[2])
        .try_normalize()
        .unwrap_or(geometric_normal);
    let [uv0, uv1, uv2] = tri.uvs;
    let uv = barycentric.x * uv0 + barycentric.y * uv1 + barycentric.z * uv2;
    // p − p0 = (u − u0)·∂p/∂u + (v − v0)·∂p/∂v over the triangle: a 2×2 system in the edges.
    let (dp1, dp2, duv1, duv2) = (p1 - p0, p2 - p0, uv1 - uv0, uv2 - uv0);
    let det = duv1.x * duv2.y - duv1.y * duv2.x;
    let (dpdu, dpdv) = if det.abs() > 1e-12 * duv1.length_squared().max(duv2.length_squared()) && det.is_finite() {
        ((duv2.y * dp1 - duv1.y * dp2) / det, (duv1.x * dp2 - duv2.x * dp1) / det)
    } else {
        orthonormal_basis(geometric_normal)
    };
    SurfaceHit { t, point, geometric_normal, normal, uv, dpdu, dpdv, material: tri.material, object: tri.object }
}

/// Barycentric weights of `p` projected onto the triangle's plane, clamped to the triangle; the
/// fallback when the ray given to [`Primitive::surface`] no longer meets the triangle.
fn barycentric_of_point(p: Vec3, [p0, p1, p2]: [Vec3; 3], face: Vec3) -> Vec3 {
    let area = face.length_squared();
    if !(area > 0.0) {
        return Vec3::new(1.0, 0.0, 0.0);
    }
    let b1 = (p - p0).cross(p2 - p0).dot(face) / area;
    let b2 = (p1 - p0).cross(p - p0).dot(face) / area;
    let b = Vec3::new(1.0 - b1 - b2, b1, b2).max(Vec3::ZERO);
    b / b.element_sum().max(f32::MIN_POSITIVE)
}

/// Two unit tangents `t, b` with `t × b = n` (Duff et al. 2017), for triangles whose texture
/// coordinates do not span a plane.
fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0_f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// Everything in `scene` a ray can hit. Analytic objects stay exact (not tessellated); meshes
/// become world-space triangles (positions by `world_from_local`, normals by
/// [`Object::normal_from_local`]). Degenerate triangles and objects that cannot be hit (a
/// singular transform, a zero radius) are left out.
pub fn scene_primitives(scene: &Scene) -> Vec<Primitive> {
    let mut primitives = Vec::new();
    for (index, object) in scene.objects.iter().enumerate() {
        let analytic = match object.shape {
            Shape::Mesh(mesh) => {
                match scene.meshes.get(mesh) {
                    Some(mesh) => push_mesh_triangles(&mut primitives, mesh, object, index),
                    None => log::warn!("object `{}`: mesh {mesh} does not exist; skipped", object.name),
                }
                continue;
            }
            Shape::Sphere { center, radius } => AnalyticShape::Sphere { center, radius },
            Shape::Cuboid { min, max } => AnalyticShape::Cuboid { min, max },
            Shape::Plane { size, uv_scale } => AnalyticShape::Plane { size, uv_scale },
            Shape::Torus { major, minor } => AnalyticShape::Torus { major, minor },
            Shape::RoundedBox { half, radius } => {
                AnalyticShape::RoundedBox { half, radius, steps: (scene.sphere_segments() / 4).max(2) }
            }
        };
        match Analytic::new(analytic, object.world_from_local, index, object.material) {
            Some(a) => primitives.push(Primitive::Analytic(Box::new(a))),
            None => log::warn!("object `{}` has a singular transform or a degenerate shape; skipped", object.name),
        }
    }
    primitives
}

fn push_mesh_triangles(primitives: &mut Vec<Primitive>, mesh: &crate::scene::Mesh, object: &Object, index: usize) {
    let normal_from_local = object.normal_from_local();
    let positions: Vec<Vec3> = mesh.positions.iter().map(|&p| object.world_from_local.transform_point3(p)).collect();
    for t in mesh.indices.chunks_exact(3) {
        let ids = [t[0], t[1], t[2]].map(|i| i as usize);
        let Some(p) = ids.iter().map(|&i| positions.get(i).copied()).collect::<Option<Vec<Vec3>>>() else {
            continue;
        };
        let [p0, p1, p2] = [p[0], p[1], p[2]];
        let face = (p1 - p0).cross(p2 - p0);
        if !(face.length_squared() > 0.0) || !face.is_finite() {
            continue;
        }
        let face_normal = face.normalize();
        let normals = ids.map(|i| {
            mesh.normals.get(i).map(|&n| normal_from_local * n).and_then(Vec3::try_normalize).unwrap_or(face_normal)
        });
        let uvs = ids.map(|i| mesh.uvs.get(i).copied().unwrap_or(Vec2::ZERO));
        primitives.push(Primitive::Triangle(Triangle {
            positions: [p0, p1, p2],
            normals,
            uvs,
            object: index,
            material: object.material,
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(origin: Vec3, direction: Vec3) -> Ray {
        Ray { origin, direction: direction.normalize() }
    }

    #[test]
    fn slabs_accept_a_ray_lying_in_a_face_and_reject_one_just_outside() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        // Direction (1, 0, 0): 1/0 = ∞ on y and z, and the origin lies on the y = 0 plane.
        let along_face = Ray { origin: Vec3::new(-1.0, 0.0, 0.5), direction: Vec3::X };
        assert_eq!(b.intersect(&along_face, 0.0, f32::INFINITY), Some((1.0, 2.0)));
        let negative_zero = Ray { origin: Vec3::new(2.0, 1.0, 0.5), direction: Vec3::new(-1.0, -0.0, 0.0) };
        assert_eq!(b.intersect(&negative_zero, 0.0, f32::INFINITY), Some((1.0, 2.0)));
        let outside = Ray { origin: Vec3::new(-1.0, -1e-6, 0.5), direction: Vec3::X };
        assert_eq!(b.intersect(&outside, 0.0, f32::INFINITY), None);
    }

    #[test]
    fn sphere_roots_are_accurate_far_away() {
        // 1e4 radii away, the textbook b² − ac loses the tangent distance; the stable form does not.
        let (t0, t1) = sphere_roots(Vec3::new(0.0, 0.0, -1e4), Vec3::Z, Vec3::ZERO, 1.0).expect("hits");
        assert!((t0 - 9999.0).abs() <= 1e-3 && (t1 - 10001.0).abs() <= 1e-3, "{t0} {t1}");
        assert_eq!(sphere_roots(Vec3::new(0.0, 1.0 + 1e-6, -5.0), Vec3::Z, Vec3::ZERO, 1.0), None);
    }

    #[test]
    fn sphere_uv_matches_the_mesh_convention() {
        // u = φ/2π, v = θ/π with n = (sin θ cos φ, cos θ, −sin θ sin φ).
        let (theta, phi) = (1.0_f32, 4.0_f32);
        let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin());
        let (uv, dpdu, dpdv) = sphere_parametrization(n, 2.0);
        assert!(uv.abs_diff_eq(Vec2::new(phi / TAU, theta / PI), 1e-5), "{uv}");
        assert!(dpdu.dot(n).abs() < 1e-4 && dpdv.dot(n).abs() < 1e-4);
        assert!(dpdu.cross(dpdv).dot(n) < 0.0, "v runs southward, so ∂p/∂u × ∂p/∂v points inward");
    }

    #[test]
    fn rounded_box_ticks_invert() {
        let tick = |index: f32| {
            let i = index.floor() as u32;
            let a = rounded_box_tick_at(i, 0.7, 0.2, 3);
            a + (rounded_box_tick_at(i + 1, 0.7, 0.2, 3) - a) * (index - i as f32)
        };
        assert_eq!(rounded_box_tick_index(-1.0, 0.7, 0.2, 3), 0.0);
        assert_eq!(rounded_box_tick_index(1.0, 0.7, 0.2, 3), 7.0);
        for i in 0..9 {
            let index = i as f32 * 6.9 / 9.0;
            let c = tick(index);
            assert!((rounded_box_tick_index(c, 0.7, 0.2, 3) - index).abs() < 1e-3, "{index}");
        }
    }

    #[test]
    fn sphere_tracing_leaves_the_surface_it_starts_on() {
        let shape = AnalyticShape::Torus { major: 1.0, minor: 0.25 };
        let torus = Analytic::new(shape, glam::Mat4::IDENTITY, 0, MaterialId(0)).expect("valid torus");
        // From the outer equator straight back in: the far wall of the tube at x = 0.75.
        let inward = ray(Vec3::new(1.25, 0.0, 0.0), Vec3::NEG_X);
        let t = torus.intersect(&inward, 0.0, f32::INFINITY).expect("exits through the tube's inner wall");
        assert!((t - 0.5).abs() < 1e-4, "{t}");
        // Outward from the same point: nothing beyond.
        assert_eq!(torus.intersect(&ray(Vec3::new(1.25, 0.0, 0.0), Vec3::X), 0.0, f32::INFINITY), None);
    }
}
