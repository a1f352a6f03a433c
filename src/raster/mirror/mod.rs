//! Planar mirrors, the geometry (docs/course/07-planar-mirrors.md): "render the scene with the
//! camera mirrored about the mirror's plane (only what is in front of the plane), and show that
//! image in the mirror". No wgpu here: the mirror pass draws the views this module makes.
//!
//! - **The mirrored camera.** A mirror lies in the plane `n·p + d = 0`, `n` of unit length and
//!   pointing to its reflective side (its front). Reflection about the plane is the affine map
//!
//!   ```text
//!   R(p) = p − 2(n·p + d)·n          R = ⎡ I − 2nnᵀ   −2d·n ⎤
//!                                        ⎣ 0           1     ⎦
//!   ```
//!
//!   its own inverse, with determinant −1. The real eye sees a point `p` in front of the mirror
//!   where the ray from the eye to `p`'s image `R(p)` behind the glass crosses the mirror. So the
//!   mirror shows the real camera's image of the reflected world, which is the image of the world
//!   through the mirrored camera `clip_from_world · R`: its eye is `R(eye)`, and light leaving
//!   `p` for the mirror travels straight away from `R(eye)`, so shading with that eye is right.
//! - **Why winding flips.** `R` turns every triangle over: a triangle counter-clockwise on screen
//!   through the real camera is clockwise through the mirrored one (`clip_from_world · R` has
//!   the opposite determinant). Culling with the usual front face would cull the fronts, so the
//!   pass reads `View::mirrored` and swaps it; a mirror seen in a mirror turns them back.
//! - **The oblique near plane** (E. Lengyel, "Oblique View Frustum Depth Projection and
//!   Clipping", 2005, here for wgpu's clip space `0 ≤ z ≤ w`). Only what is in front of the mirror
//!   may be drawn: an object behind it, between the mirrored eye and the glass, would hide the
//!   reflection. A clip plane does it per fragment (`View::clip_plane`); making the mirror the
//!   frustum's near plane does it in the clipper, for free. Derivation in
//!   [`oblique_near_plane`].
//! - **Which objects are mirrors** ([`find_mirrors`]): a material with `kps > 0` on a surface
//!   that is flat to within [`FLATNESS`] of its size. One mirrored view serves one plane.
//!
//! Limits. Curved mirrors (spheres, tori, rounded boxes, curved meshes) have no single mirrored
//! camera: environment maps (the rest of §6) are their technique. A box is six planar mirrors,
//! one per face, each with its own mirrored view ([`Mirror::indices`] names the face). A mirror
//! seen in a mirror needs a view of a view; [`mirrored_view`] composes (the `mirrored` flag
//! toggles), but a view has one clip plane, so the nested view keeps only the inner mirror's.
//! The oblique near plane spends the depth range between the mirror and the far corner of the
//! frustum, and its far plane tilts, so depth precision is coarser than the main view's, worst
//! when the mirror is seen at a grazing angle.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

use serde::Serialize;

use super::geometry::{build_mesh, instance_of};
use super::inspect::GpuInspectFragment;
use super::view::View;

pub mod pass;
use crate::scene::{Scene, Shape};

/// A surface is flat when every vertex of its triangles lies within `FLATNESS ×` the diagonal of
/// its world-space bounding box of one plane.
pub const FLATNESS: f32 = 1e-4;

/// A surface whose largest triangle has an area of at most `DEGENERATE_AREA ×` its diagonal
/// squared has no area, or no normal worth trusting.
pub const DEGENERATE_AREA: f32 = 1e-10;

/// The plane `normal·p + d = 0` of a mirror; `normal` has unit length and points to the
/// reflective side, the mirror's front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MirrorPlane {
    pub normal: Vec3,
    pub d: f32,
}

impl MirrorPlane {
    /// The plane through `point` facing `normal`, which may have any length but zero.
    pub fn through(point: Vec3, normal: Vec3) -> MirrorPlane {
        let normal = normal.normalize();
        MirrorPlane { normal, d: -normal.dot(point) }
    }

    /// The signed distance of `p` from the plane: positive in front.
    pub fn distance(&self, p: Vec3) -> f32 {
        self.normal.dot(p) + self.d
    }

    /// `(n, d)`, so that `plane·(p, 1)` is the signed distance: the form of `View::clip_plane`.
    pub fn as_vec4(&self) -> Vec4 {
        self.normal.extend(self.d)
    }

    /// The same plane, facing the other way.
    pub fn flipped(&self) -> MirrorPlane {
        MirrorPlane { normal: -self.normal, d: -self.d }
    }
}

/// The reflection about `plane`, world to world: `p' = p − 2(n·p + d)·n`. Its own inverse, with
/// determinant −1.
pub fn reflection(plane: &MirrorPlane) -> Mat4 {
    let n = plane.normal;
    let linear = Mat3::IDENTITY - Mat3::from_cols(n * n.x, n * n.y, n * n.z) * 2.0;
    Mat4::from_cols(
        linear.x_axis.extend(0.0),
        linear.y_axis.extend(0.0),
        linear.z_axis.extend(0.0),
        (-2.0 * plane.d * n).extend(1.0),
    )
}

/// The view of `view`'s camera mirrored about `plane`: it sees the world as the mirror shows it,
/// and only what lies in front of the plane (its clip plane, and its near plane made the mirror
/// by [`oblique_near_plane`]). Meant for a camera in front of the mirror ([`camera_side`]
/// `Front`); from anywhere else the near plane stays as it was and only the clip plane holds.
/// Perspective and orthographic views alike.
pub fn mirrored_view(view: &View, plane: &MirrorPlane) -> View {
    let reflected_from_world = reflection(plane);
    let clip_from_world = oblique_near_plane(view.clip_from_world * reflected_from_world, plane.as_vec4());
    View {
        clip_from_world,
        eye: reflected_from_world.transform_point3(view.eye),
        orthographic: view.orthographic,
        view_axis: reflected_from_world.transform_vector3(view.view_axis),
        mirrored: !view.mirrored,
        clip_plane: Some(plane.as_vec4()),
        // A reflection is its own inverse.
        clip_from_reflected: clip_from_world * reflected_from_world,
    }
}

/// `clip_from_world` with its near plane moved onto the world plane `plane_world` (`P`): points
/// with `P·(p, 1) < 0` get a clip `z < 0` and are clipped; `x`, `y` and `w` do not change, so
/// neither does any point's pixel, only its depth.
///
/// Derivation. Let `M = clip_from_world` have rows `m0..m3`. wgpu keeps `0 ≤ z ≤ w`: the near
/// plane is the row `m2·p ≥ 0`, the far plane `(m3 − m2)·p ≥ 0`. Replacing `m2` by `a·P`,
/// `a > 0`, makes the near plane `P·p ≥ 0`, and the far plane `(m3 − a·P)·p ≥ 0`; `a` is chosen
/// for the far plane. In clip space the plane is `C = M⁻ᵀ·P` (so that `C·(M·p) = P·p`), and the
/// new depth of a clip point `c` is `z'/w = a·C·c/w`. Over the old frustum (`|x|, |y| ≤ w`,
/// `0 ≤ z ≤ w`), `C·c/w` is largest at the corner opposite the plane, `Q = (sgn Cx, sgn Cy, 1,
/// 1)`, when `Cz > 0`. With `a = 1/(C·Q)` that largest depth is exactly 1: the new far plane
/// touches the old frustum at `Q` and cuts nothing of it in front of the plane (a larger `a`
/// would cut, a smaller one wastes depth range). Beyond `Q` the tilted far plane lets in a little
/// that the old far plane cut.
///
/// `Cz > 0` says where the eye is: for both projections the eye is the clip-space point
/// `(0, 0, −1, 0)` times a positive number (for an orthographic camera, the point at infinity
/// behind it), so `C·eye` has the sign of `−Cz`. A near plane always has the eye behind it; if
/// the eye is in front of `P` or on it (`Cz ≤ 0`), or the whole frustum is behind it
/// (`C·Q ≤ 0`), the matrix is returned unchanged and the caller decides ([`camera_side`]).
pub fn oblique_near_plane(clip_from_world: Mat4, plane_world: Vec4) -> Mat4 {
    let c = clip_from_world.inverse().transpose() * plane_world;
    if !(c.z > 0.0) {
        return clip_from_world;
    }
    let corner = Vec4::new(c.x.signum(), c.y.signum(), 1.0, 1.0);
    let reach = c.dot(corner);
    if !(reach > 0.0) {
        return clip_from_world;
    }
    let mut rows = clip_from_world.transpose();
    rows.z_axis = plane_world / reach;
    rows.transpose()
}

/// Where a camera is, seen from a mirror.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// In front: the mirror shows [`mirrored_view`].
    Front,
    /// Behind: the camera sees the mirror's back. Read as a one-sided mirror, the back shows its
    /// material and no reflection. Both renderers shade planes two-sided, though (normals turned
    /// to the viewer), and the ray tracer reflects off either side, so a pass that must agree
    /// with it mirrors about `plane.flipped()` instead, from whose front the camera looks.
    Back,
    /// In the plane (an orthographic view: parallel to it): the mirror is seen edge on and
    /// covers no pixels of its own. There is no view to make; draw it as plain material.
    EdgeOn,
}

/// Which side of `plane` the camera of `view` is on: its eye's, or for an orthographic view the
/// side its view axis points to (its rays come from infinitely far along it).
pub fn camera_side(view: &View, plane: &MirrorPlane) -> Side {
    let (signed, tolerance) = if view.orthographic {
        (plane.normal.dot(view.view_axis), 1e-6)
    } else {
        // About the spacing of f32 coordinates near the eye.
        (plane.distance(view.eye), 1e-5 * view.eye.abs().max_element().max(1.0))
    };
    if signed > tolerance {
        Side::Front
    } else if signed < -tolerance {
        Side::Back
    } else {
        Side::EdgeOn
    }
}

/// A planar mirror of the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Mirror {
    /// Index into `Scene::objects`.
    pub object: usize,
    pub plane: MirrorPlane,
    /// The smallest rectangle in the plane around the mirror's triangles, counter-clockwise seen
    /// from the front, with sides along an edge of its largest triangle: a `plane` shape's own
    /// quad. What the mirror pass bounds its view's scissor by.
    pub corners: [Vec3; 4],
    /// The area of its triangles, in world units squared.
    pub area: f32,
    /// The part of the object's mesh that is this mirror, as a range of its indices: one face of
    /// a box. `None`: the whole mesh.
    pub indices: Option<std::ops::Range<u32>>,
}

/// The scene's planar mirrors, and a warning for every object with a mirror material (`kps > 0`)
/// that is not one.
///
/// The rule: an object is a planar mirror when its material has `kps > 0` and its world-space
/// triangles are flat. Flat means that every vertex lies within [`FLATNESS`] × the diagonal of
/// its bounding box of the plane through the triangles' centroid (area-weighted) with the normal
/// of its largest triangle. That normal is turned to the front the triangles' winding gives
/// ("counter-clockwise seen from the front", with the winding read in the object's own
/// coordinates, so a mirroring transform does not turn it over), or, where front- and
/// back-facing triangles cancel, to the side of the vertex normals. `plane` shapes always
/// qualify, and so does a flat mesh.
///
/// A box with `kps > 0` is six planar mirrors, one per face (its `indices`).
///
/// Skipped: curved shapes (spheres, tori, rounded boxes), for which environment maps are the
/// technique (`super::environment`); warned about and skipped: meshes that are not flat (they
/// reflect through environment maps too) and mirrors with no area ([`DEGENERATE_AREA`]).
pub fn find_mirrors(scene: &Scene) -> (Vec<Mirror>, Vec<String>) {
    let mut mirrors = Vec::new();
    let mut warnings = Vec::new();
    for (index, object) in scene.objects.iter().enumerate() {
        let Some(material) = scene.materials.get(object.material.0) else { continue };
        let kps = material.mirror;
        if kps <= 0.0 {
            continue;
        }
        let name = &object.name;
        let curved = "it reflects through an environment map instead";
        match object.shape {
            // Curved mirrors have no single mirrored camera: environment maps reflect for them
            // (`super::environment`).
            Shape::Sphere { .. } | Shape::Torus { .. } | Shape::RoundedBox { .. } => {}
            // Each face of a box is a planar mirror of its own (`Mesh::cuboid` draws face `f` with
            // indices 6f..6f + 6).
            Shape::Cuboid { .. } => {
                for face in 0..6u32 {
                    let indices = 6 * face..6 * face + 6;
                    match planar(scene, index, Some(indices.clone())) {
                        Ok(fit) => mirrors.push(Mirror {
                            object: index,
                            plane: fit.plane,
                            corners: fit.corners,
                            area: fit.area,
                            indices: Some(indices),
                        }),
                        Err(_) => warnings.push(format!("object `{name}`: face {face} has no area; skipped")),
                    }
                }
            }
            Shape::Mesh(mesh) if mesh >= scene.meshes.len() => {
                warnings.push(format!("object `{name}`: mesh {mesh} does not exist; skipped"));
            }
            Shape::Plane { .. } | Shape::Mesh(_) => match planar(scene, index, None) {
                Ok(fit) => mirrors.push(Mirror {
                    object: index,
                    plane: fit.plane,
                    corners: fit.corners,
                    area: fit.area,
                    indices: None,
                }),
                Err(NotPlanar::Degenerate) => {
                    warnings.push(format!("object `{name}`: a mirror with no area; skipped"));
                }
                Err(NotPlanar::Curved { offset, tolerance }) => warnings.push(format!(
                    "object `{name}`: a mirror (kps = {kps}) that is not flat: a vertex lies {offset:.2e} from \
                     its plane, more than the {tolerance:.2e} allowed; {curved}"
                )),
            },
        }
    }
    (mirrors, warnings)
}

/// A flat surface's plane, bounding rectangle and area.
#[derive(Clone, Debug, PartialEq)]
struct PlaneFit {
    plane: MirrorPlane,
    corners: [Vec3; 4],
    area: f32,
}

/// Why a surface is not a planar mirror.
#[derive(Clone, Debug, PartialEq)]
enum NotPlanar {
    Degenerate,
    /// The farthest vertex lies `offset` from the plane, more than `tolerance`.
    Curved {
        offset: f32,
        tolerance: f32,
    },
}

/// The plane of object `index` (a plane shape, a mesh, or the triangles of `indices` of its
/// mesh), from its world-space triangles.
fn planar(scene: &Scene, index: usize, indices: Option<std::ops::Range<u32>>) -> Result<PlaneFit, NotPlanar> {
    let object = &scene.objects[index];
    let (key, world_from_mesh) = instance_of(object, scene.sphere_segments());
    let mesh = build_mesh(scene, key);
    // A mirroring transform reverses the winding in the world; undo it so the winding still
    // names the front.
    let turned = world_from_mesh.determinant() < 0.0;
    let world = |i: u32| world_from_mesh.transform_point3(mesh.positions[i as usize]);
    let part = match indices {
        Some(range) => &mesh.indices[range.start as usize..range.end as usize],
        None => &mesh.indices[..],
    };
    let triangles: Vec<[Vec3; 3]> = part
        .chunks_exact(3)
        .map(|t| if turned { [world(t[0]), world(t[2]), world(t[1])] } else { [world(t[0]), world(t[1]), world(t[2])] })
        .collect();
    let normal_from_mesh = Mat3::from_mat4(world_from_mesh).inverse().transpose();
    let normals: Vec3 = part.iter().map(|&i| normal_from_mesh * mesh.normals[i as usize]).sum();
    fit_plane(&triangles, normals)
}

/// The plane of `triangles` if they are flat (see [`find_mirrors`] for the rule), facing the
/// side their winding gives, or `normals` (summed vertex normals) where windings cancel.
fn fit_plane(triangles: &[[Vec3; 3]], normals: Vec3) -> Result<PlaneFit, NotPlanar> {
    let cross = |[a, b, c]: &[Vec3; 3]| (b - a).cross(c - a);
    let (min, max) = triangles
        .iter()
        .flatten()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let diagonal = (max - min).length();
    // The largest triangle's cross product is the best conditioned normal.
    let Some(largest) =
        triangles.iter().reduce(|best, t| if cross(t).length() > cross(best).length() { t } else { best })
    else {
        return Err(NotPlanar::Degenerate);
    };
    let twice_largest = cross(largest).length();
    if !(twice_largest / 2.0 > DEGENERATE_AREA * diagonal * diagonal) {
        return Err(NotPlanar::Degenerate);
    }
    let mut normal = cross(largest) / twice_largest;
    let winding: f32 = triangles.iter().map(|t| cross(t).dot(normal)).sum();
    let twice_area: f32 = triangles.iter().map(|t| cross(t).length()).sum();
    let facing = if winding.abs() > 1e-3 * twice_area { winding } else { normals.dot(normal) };
    if facing < 0.0 {
        normal = -normal;
    }
    let centroid = triangles.iter().map(|t| cross(t).length() * (t[0] + t[1] + t[2]) / 3.0).sum::<Vec3>() / twice_area;
    let plane = MirrorPlane::through(centroid, normal);
    let offset = triangles.iter().flatten().map(|&p| plane.distance(p).abs()).fold(0.0, f32::max);
    let tolerance = FLATNESS * diagonal;
    if offset > tolerance {
        return Err(NotPlanar::Curved { offset, tolerance });
    }
    // Along the shortest edge of the largest triangle: for a quad's half, one of its sides.
    let [a, b, c] = *largest;
    let edge = [b - a, c - b, a - c].into_iter().min_by(|e, f| e.length().total_cmp(&f.length())).expect("three edges");
    let u = (edge - normal * normal.dot(edge)).normalize();
    let v = normal.cross(u);
    let (lo, hi) = triangles.iter().flatten().fold(
        (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| {
            let q = Vec2::new((p - centroid).dot(u), (p - centroid).dot(v));
            (lo.min(q), hi.max(q))
        },
    );
    let at = |s: f32, t: f32| centroid + s * u + t * v;
    Ok(PlaneFit {
        plane,
        corners: [at(lo.x, lo.y), at(hi.x, lo.y), at(hi.x, hi.y), at(lo.x, hi.y)],
        area: twice_area / 2.0,
    })
}

/// A planar mirror's lookup.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MirrorLookup {
    /// The mirrored camera's eye: the camera reflected about the mirror's plane.
    pub mirrored_eye: Vec3,
    /// The texel of the mirrored camera's image read: the pixel itself.
    pub texel: [u32; 2],
    /// `kps·MPS` times that texel.
    pub radiance: Vec3,
}

/// What a mirror record read, for `mirador explain`: the texel of its mirrored camera's image
/// (the pixel itself) and that camera's eye, reflected about the plane the frame used (`planes`,
/// the main view's mirrors by object).
pub fn lookup(
    record: &GpuInspectFragment,
    planes: &[(usize, MirrorPlane)],
    eye: Vec3,
    pixel: (u32, u32),
) -> MirrorLookup {
    let plane = planes.iter().find(|(object, _)| *object as u32 == record.object).map(|(_, plane)| plane);
    let mirrored_eye = plane.map_or(eye, |p| eye - 2.0 * p.distance(eye) * p.normal);
    MirrorLookup { mirrored_eye, texel: [pixel.0, pixel.1], radiance: record.mirror }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use glam::{Vec3Swizzles, Vec4Swizzles};

    use super::*;
    use crate::scene::{Camera, Mesh, Object, Projection};

    fn camera(projection: Projection) -> Camera {
        Camera {
            eye: Vec3::new(0.5, 1.0, 6.0),
            center: Vec3::new(0.0, 0.8, 0.0),
            up: Vec3::Y,
            fovy_degrees: 50.0,
            near: 0.1,
            far: 100.0,
            width: 64,
            height: 48,
            projection,
            ortho_height: 6.0,
        }
    }

    /// A tilted mirror behind the origin, facing the cameras of [`camera`].
    fn tilted() -> MirrorPlane {
        MirrorPlane::through(Vec3::new(0.0, 0.0, -3.0), Vec3::new(0.3, 0.2, 1.0))
    }

    fn assert_close(actual: Vec3, expected: Vec3, tolerance: f32, what: &str) {
        assert!(actual.abs_diff_eq(expected, tolerance), "{what}: {actual} ≠ {expected}");
    }

    /// Normalized device coordinates `x/w, y/w` and depth `z/w` of `p` under `clip_from_world`.
    fn ndc(clip_from_world: Mat4, p: Vec3) -> Vec3 {
        let clip = clip_from_world * p.extend(1.0);
        assert!(clip.w > 0.0, "{p} is behind the eye");
        clip.xyz() / clip.w
    }

    /// The pixel `Camera::project` would give for normalized device coordinates `ndc`.
    fn pixel(camera: &Camera, ndc: Vec3) -> Vec2 {
        Vec2::new((ndc.x + 1.0) / 2.0 * camera.width as f32, (1.0 - ndc.y) / 2.0 * camera.height as f32)
    }

    // --- reflection

    #[test]
    fn reflection_about_x_equals_two_maps_5_1_1_to_minus_1_1_1() {
        // The plane x = 2 facing −x: n = (−1, 0, 0), d = 2.
        let plane = MirrorPlane { normal: Vec3::NEG_X, d: 2.0 };
        assert_close(
            reflection(&plane).transform_point3(Vec3::new(5.0, 1.0, 1.0)),
            Vec3::new(-1.0, 1.0, 1.0),
            0.0,
            "R",
        );
        // The same plane from a point and a normal of another length.
        let through = MirrorPlane::through(Vec3::new(2.0, 7.0, -3.0), Vec3::new(-3.0, 0.0, 0.0));
        assert_eq!(through, plane);
        assert_eq!(plane.distance(Vec3::new(5.0, 1.0, 1.0)), -3.0);
        assert_eq!(plane.as_vec4(), Vec4::new(-1.0, 0.0, 0.0, 2.0));
    }

    #[test]
    fn reflection_is_its_own_inverse_with_determinant_minus_one() {
        let plane = tilted();
        let r = reflection(&plane);
        assert!((r * r).abs_diff_eq(Mat4::IDENTITY, 1e-6), "R·R = {:?}", r * r);
        assert!((r.determinant() + 1.0).abs() < 1e-6, "det R = {}", r.determinant());
        // Points of the plane stay; the normal turns over; distances change sign.
        let on = Vec3::new(0.0, 0.0, -3.0) + plane.normal.any_orthonormal_vector() * 2.5;
        assert_close(r.transform_point3(on), on, 1e-5, "a point of the plane");
        assert_close(r.transform_vector3(plane.normal), -plane.normal, 1e-6, "the normal");
        let p = Vec3::new(1.0, 2.0, 0.5);
        assert!((plane.distance(r.transform_point3(p)) + plane.distance(p)).abs() < 1e-5);
        assert_eq!(plane.flipped().flipped(), plane);
        assert_eq!(reflection(&plane.flipped()), r);
    }

    // --- the mirrored view

    /// Points in front of the mirror, whose images behind it the cameras of [`camera`] see.
    const IN_FRONT: [Vec3; 4] =
        [Vec3::new(0.5, 1.0, 0.0), Vec3::new(-1.0, 0.5, 2.0), Vec3::new(1.0, 2.0, -1.0), Vec3::new(0.2, 0.1, -2.5)];

    #[test]
    fn the_mirrored_view_sees_a_point_where_the_camera_sees_its_image() {
        for projection in [Projection::Perspective, Projection::Orthographic] {
            let camera = camera(projection);
            let view = View::of_camera(&camera);
            let plane = tilted();
            let mirrored = mirrored_view(&view, &plane);
            let r = reflection(&plane);
            for p in IN_FRONT {
                assert!(plane.distance(p) > 0.0);
                let image = r.transform_point3(p);
                let seen = pixel(&camera, ndc(mirrored.clip_from_world, p));
                let expected = camera.project(image).expect("the image is in front of the camera").xy();
                assert!(seen.abs_diff_eq(expected, 1e-3), "{projection:?}, {p}: {seen} ≠ {expected}");
                // That pixel is where the camera looks at the mirror itself: the ray from the eye
                // (or along the orthographic axis) to the image crosses the mirror there.
                let towards = if view.orthographic { -view.view_axis } else { image - camera.eye };
                let from = if view.orthographic { image - 20.0 * towards } else { camera.eye };
                let t = -plane.distance(from) / plane.normal.dot(towards);
                let on_mirror = camera.project(from + t * towards).expect("the mirror is in view").xy();
                assert!(on_mirror.abs_diff_eq(expected, 1e-3), "{projection:?}, {p}: {on_mirror} ≠ {expected}");
            }
        }
    }

    #[test]
    fn the_mirrored_view_reflects_the_eye_flips_winding_and_clips_at_the_mirror() {
        for projection in [Projection::Perspective, Projection::Orthographic] {
            let view = View::of_camera(&camera(projection));
            let plane = tilted();
            let mirrored = mirrored_view(&view, &plane);
            let r = reflection(&plane);
            assert_close(mirrored.eye, r.transform_point3(view.eye), 1e-5, "eye");
            assert_close(mirrored.view_axis, r.transform_vector3(view.view_axis), 1e-6, "view axis");
            assert_eq!(mirrored.orthographic, view.orthographic);
            assert!(mirrored.mirrored && !view.mirrored);
            assert_eq!(mirrored.clip_plane, Some(plane.as_vec4()));
            // The determinant's sign is the screen's winding.
            let before = view.clip_from_world.determinant();
            assert!(before * mirrored.clip_from_world.determinant() < 0.0, "winding did not flip");
            // A mirror seen in the mirror turns it back.
            let second = MirrorPlane::through(Vec3::new(4.0, 0.0, 0.0), Vec3::NEG_X);
            assert!(!mirrored_view(&mirrored, &second).mirrored);
        }
    }

    // --- the oblique near plane

    /// Points spread through the frustum of `clip_from_world`, from near to far.
    fn frustum_points(clip_from_world: Mat4) -> Vec<Vec3> {
        let world_from_clip = clip_from_world.inverse();
        let steps = [-0.95, -0.5, 0.0, 0.4, 0.95];
        let depths = [0.0, 0.01, 0.2, 0.5, 0.9, 0.99, 0.999, 1.0];
        let mut points = Vec::new();
        for x in steps {
            for y in steps {
                for z in depths {
                    points.push(world_from_clip.project_point3(Vec3::new(x, y, z)));
                }
            }
        }
        points
    }

    #[test]
    fn the_oblique_near_plane_clips_behind_the_mirror_and_keeps_pixels_in_front() {
        for projection in [Projection::Perspective, Projection::Orthographic] {
            let plane = tilted();
            let camera = camera(projection);
            let clip_from_world = camera.clip_from_world() * reflection(&plane);
            let oblique = oblique_near_plane(clip_from_world, plane.as_vec4());
            let (mut behind, mut in_front) = (0, 0);
            for p in frustum_points(clip_from_world) {
                let clip = oblique * p.extend(1.0);
                let distance = plane.distance(p);
                if distance < -1e-3 {
                    behind += 1;
                    assert!(clip.z < 0.0, "{projection:?}: {p} behind the mirror has clip {clip}");
                } else if distance > 1e-3 {
                    in_front += 1;
                    let before = clip_from_world * p.extend(1.0);
                    assert!(clip.z >= 0.0 && clip.z <= clip.w * (1.0 + 1e-5), "{projection:?}: {p} has clip {clip}");
                    assert!((clip.w - before.w).abs() <= 1e-5 * before.w, "{projection:?}: w changed at {p}");
                    let (now, was) = (clip.xy() / clip.w, before.xy() / before.w);
                    assert!(now.abs_diff_eq(was, 1e-5), "{projection:?}: {p} moved from {was} to {now}");
                }
            }
            assert!(behind > 20 && in_front > 20, "{projection:?}: {behind} behind, {in_front} in front");
        }
    }

    #[test]
    fn the_oblique_far_plane_touches_the_frustum_at_the_corner_opposite_the_mirror() {
        for projection in [Projection::Perspective, Projection::Orthographic] {
            let plane = tilted();
            let clip_from_world = camera(projection).clip_from_world() * reflection(&plane);
            let oblique = oblique_near_plane(clip_from_world, plane.as_vec4());
            let world_from_clip = clip_from_world.inverse();
            let deepest = [-1.0, 1.0]
                .into_iter()
                .flat_map(|x| [-1.0, 1.0].into_iter().flat_map(move |y| [0.0, 1.0].map(|z| Vec3::new(x, y, z))))
                .map(|corner| ndc(oblique, world_from_clip.project_point3(corner)).z)
                .fold(f32::NEG_INFINITY, f32::max);
            assert!((deepest - 1.0).abs() < 1e-4, "{projection:?}: the deepest corner has depth {deepest}");
        }
    }

    #[test]
    fn the_oblique_depth_grows_along_every_ray_of_the_mirrored_view() {
        for projection in [Projection::Perspective, Projection::Orthographic] {
            let plane = tilted();
            let mirrored = mirrored_view(&View::of_camera(&camera(projection)), &plane);
            for p in IN_FRONT {
                let along = if mirrored.orthographic { -mirrored.view_axis } else { (p - mirrored.eye).normalize() };
                let (near, far) = (ndc(mirrored.clip_from_world, p), ndc(mirrored.clip_from_world, p + 0.5 * along));
                assert!(near.z < far.z, "{projection:?}: depth {} at {p}, {} beyond it", near.z, far.z);
                assert!(near.xy().abs_diff_eq(far.xy(), 1e-4), "{projection:?}: not one ray");
            }
        }
    }

    #[test]
    fn a_plane_the_eye_is_in_front_of_cannot_be_a_near_plane() {
        for projection in [Projection::Perspective, Projection::Orthographic] {
            // The real camera is in front of the mirror: a near plane on the mirror would have to
            // keep the eye's side.
            let clip_from_world = camera(projection).clip_from_world();
            assert_eq!(oblique_near_plane(clip_from_world, tilted().as_vec4()), clip_from_world);
            // Also when the far corner opposite the plane is in front of it: a plane along the
            // view direction, to the side.
            let side = MirrorPlane::through(Vec3::new(-1.0, 0.0, 0.0), Vec3::X);
            assert_eq!(oblique_near_plane(clip_from_world, side.as_vec4()), clip_from_world);
            // A plane the whole frustum lies behind.
            let beyond = MirrorPlane::through(Vec3::new(0.0, 0.0, -500.0), Vec3::NEG_Z);
            assert_eq!(oblique_near_plane(clip_from_world, beyond.as_vec4()), clip_from_world);
        }
    }

    // --- the camera's side

    #[test]
    fn the_camera_side_is_the_eyes_or_for_orthographic_views_the_view_axis() {
        let plane = tilted();
        let mut view = View::of_camera(&camera(Projection::Perspective));
        assert_eq!(camera_side(&view, &plane), Side::Front);
        assert_eq!(camera_side(&view, &plane.flipped()), Side::Back);
        view.eye = Vec3::new(0.0, 0.0, -3.0) + plane.normal.any_orthonormal_vector();
        assert_eq!(camera_side(&view, &plane), Side::EdgeOn);

        let mut view = View::of_camera(&camera(Projection::Orthographic));
        // Wherever the eye is, orthographic rays come from infinitely far along the view axis.
        view.eye = Vec3::new(0.0, 0.0, -10.0);
        assert_eq!(camera_side(&view, &plane), Side::Front);
        assert_eq!(camera_side(&view, &plane.flipped()), Side::Back);
        view.view_axis = plane.normal.any_orthonormal_vector();
        assert_eq!(camera_side(&view, &plane), Side::EdgeOn);
    }

    // --- finding the mirrors

    fn scene(objects: &str) -> Scene {
        let text = format!(
            r#"
            [camera]
            eye = [0, 0, 10]
            center = [0, 0, 0]
            [materials.silver]
            mirror = 0.9
            [materials.matte]
            kd = 0.8
            {objects}
            "#
        );
        crate::scene::file::parse(&text, Path::new("x.toml")).unwrap_or_else(|e| panic!("{e}\n{text}"))
    }

    #[test]
    fn a_rotated_plane_and_a_boxs_faces_are_mirrors_and_curved_shapes_are_not() {
        let scene = scene(
            r#"
            [[objects]]
            type = "plane"
            name = "tilted"
            size = [2, 4]
            rotate = [45, 0, 90]
            translate = [1, 2, 3]
            material = "silver"
            [[objects]]
            type = "plane"
            name = "floor"
            material = "matte"
            [[objects]]
            type = "sphere"
            name = "ball"
            material = "silver"
            [[objects]]
            type = "box"
            name = "crate"
            min = [0, 0, 0]
            max = [1, 1, 1]
            material = "silver"
            [[objects]]
            type = "torus"
            name = "ring"
            material = "silver"
            "#,
        );
        let (mirrors, warnings) = find_mirrors(&scene);
        assert_eq!(mirrors.len(), 7, "the plane and the box's six faces: {mirrors:?}");
        // The box [0, 1]³: each face is a unit square facing out, named by its indices.
        for (face, (normal, d)) in [
            (Vec3::X, -1.0),
            (Vec3::NEG_X, 0.0),
            (Vec3::Y, -1.0),
            (Vec3::NEG_Y, 0.0),
            (Vec3::Z, -1.0),
            (Vec3::NEG_Z, 0.0),
        ]
        .into_iter()
        .enumerate()
        {
            let m = &mirrors[1 + face];
            assert_eq!((m.object, m.indices.clone()), (3, Some(6 * face as u32..6 * face as u32 + 6)));
            assert_close(m.plane.normal, normal, 1e-6, "a face's normal");
            assert!((m.plane.d - d).abs() < 1e-6 && (m.area - 1.0).abs() < 1e-5, "face {face}: {m:?}");
        }
        let mirror = &mirrors[0];
        assert_eq!(mirror.object, 0);
        // +y turned 45° about x is (0, √½, √½); then 90° about z, (−√½, 0, √½). Through (1, 2, 3):
        // d = −(−1 + 3)·√½ = −√2.
        let half = 0.5f32.sqrt();
        assert_close(mirror.plane.normal, Vec3::new(-half, 0.0, half), 1e-6, "normal");
        assert!((mirror.plane.d + 2.0f32.sqrt()).abs() < 1e-5, "d = {}", mirror.plane.d);
        assert!((mirror.area - 8.0).abs() < 1e-4, "area {}", mirror.area);
        // The corners are the quad's: the local (±1, 0, ±2), counter-clockwise from the front.
        let world_from_local = scene.objects[0].world_from_local;
        for corner in mirror.corners {
            let local = world_from_local.inverse().transform_point3(corner);
            assert_close(local.abs(), Vec3::new(1.0, 0.0, 2.0), 1e-5, "a corner");
        }
        let [a, b, c, _] = mirror.corners;
        assert!((b - a).cross(c - b).dot(mirror.plane.normal) > 0.0, "corners clockwise");

        // The ball and the ring are no planar mirrors, and no mistake: environment maps reflect
        // for them.
        assert!(warnings.is_empty(), "{warnings:#?}");
        assert!(mirrors.iter().all(|m| m.object != 2 && m.object != 4));
    }

    #[test]
    fn a_plane_without_area_is_skipped_with_a_warning() {
        // Sizes must be positive in a file; a scale of 1e-30 across leaves no area in f32.
        let mut scene = scene(
            r#"
            [[objects]]
            type = "plane"
            name = "sliver"
            scale = [1, 1, 1e-30]
            material = "silver"
            [[objects]]
            type = "plane"
            name = "point"
            material = "silver"
            "#,
        );
        scene.objects[1].shape = Shape::Plane { size: Vec2::ZERO, uv_scale: Vec2::ONE };
        let (mirrors, warnings) = find_mirrors(&scene);
        assert!(mirrors.is_empty(), "{mirrors:?}");
        assert_eq!(warnings.len(), 2, "{warnings:#?}");
        assert!(warnings[0].contains("`sliver`") && warnings[0].contains("no area"), "{}", warnings[0]);
        assert!(warnings[1].contains("`point`") && warnings[1].contains("no area"), "{}", warnings[1]);
    }

    /// A hexagon fan around the origin in the plane z = 0, counter-clockwise seen from +z, its
    /// vertex normals `normal`.
    fn hexagon(normal: Vec3) -> Mesh {
        let mut positions = vec![Vec3::ZERO];
        positions.extend((0..6).map(|k| {
            let angle = k as f32 * std::f32::consts::TAU / 6.0;
            Vec3::new(angle.cos(), angle.sin(), 0.0)
        }));
        let indices = (0..6u32).flat_map(|k| [0, 1 + k, 1 + (k + 1) % 6]).collect();
        Mesh {
            name: "hexagon".into(),
            normals: vec![normal; positions.len()],
            uvs: vec![Vec2::ZERO; positions.len()],
            positions,
            indices,
            ..Mesh::default()
        }
    }

    /// The scene of [`scene`] with `mesh` placed by `world_from_local`, of material silver.
    fn with_mesh(mesh: Mesh, world_from_local: Mat4) -> Scene {
        let mut scene = scene("");
        let material =
            crate::base::MaterialId(scene.materials.iter().position(|m| m.name == "silver").expect("silver"));
        scene.meshes.push(mesh);
        let shape = Shape::Mesh(scene.meshes.len() - 1);
        scene.objects.push(Object { name: "model".into(), shape, material, world_from_local });
        scene
    }

    #[test]
    fn a_flat_mesh_is_a_mirror_facing_its_winding() {
        let place = Mat4::from_translation(Vec3::new(0.0, 1.0, -2.0)) * Mat4::from_rotation_y(0.6);
        let front = place.transform_vector3(Vec3::Z);
        let (mirrors, warnings) = find_mirrors(&with_mesh(hexagon(Vec3::Z), place));
        assert!(warnings.is_empty(), "{warnings:#?}");
        assert_close(mirrors[0].plane.normal, front, 1e-6, "normal");
        assert!(mirrors[0].plane.distance(Vec3::new(0.0, 1.0, -2.0)).abs() < 1e-6);
        let area = 6.0 * 3.0f32.sqrt() / 4.0;
        assert!((mirrors[0].area - area).abs() < 1e-5, "area {} ≠ {area}", mirrors[0].area);

        // Wound the other way, it faces the other way.
        let mut backwards = hexagon(Vec3::Z);
        backwards.indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
        let (mirrors, _) = find_mirrors(&with_mesh(backwards, place));
        assert_close(mirrors[0].plane.normal, -front, 1e-6, "reversed winding");

        // A mirroring transform does not turn the front over: the local +z side is still the front.
        let mirroring = place * Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let (mirrors, _) = find_mirrors(&with_mesh(hexagon(Vec3::Z), mirroring));
        assert_close(mirrors[0].plane.normal, front, 1e-6, "mirrored transform");

        // Both windings at once: the vertex normals decide.
        let mut both = hexagon(-Vec3::Z);
        let reversed: Vec<u32> = both.indices.chunks_exact(3).flat_map(|t| [t[0], t[2], t[1]]).collect();
        both.indices.extend(reversed);
        let (mirrors, _) = find_mirrors(&with_mesh(both, place));
        assert_close(mirrors[0].plane.normal, -front, 1e-6, "double-sided, normals towards −z");
    }

    #[test]
    fn a_mesh_that_is_not_flat_warns() {
        let mut bent = hexagon(Vec3::Z);
        bent.positions[3].z = 0.01;
        let (mirrors, warnings) = find_mirrors(&with_mesh(bent, Mat4::IDENTITY));
        assert!(mirrors.is_empty(), "{mirrors:?}");
        assert_eq!(warnings.len(), 1, "{warnings:#?}");
        assert!(warnings[0].contains("`model`") && warnings[0].contains("not flat"), "{}", warnings[0]);

        // Within the tolerance (1e-4 of the 2.6 diagonal), it is flat.
        let mut nearly = hexagon(Vec3::Z);
        nearly.positions[3].z = 1e-5;
        let (mirrors, warnings) = find_mirrors(&with_mesh(nearly, Mat4::IDENTITY));
        assert!(warnings.is_empty() && mirrors.len() == 1, "{warnings:#?}");
    }
}
