//! Volumes in the ray tracer (docs/course/11-volumes.md): every ray, primary or secondary, marches the
//! volumes it crosses in front of the nearest surface.
//!
//! - **Composite**: each volume's box is clipped to `[0, t_surface]` and composited front to back
//!   (`crate::volume::march`); volumes are taken in the order the ray enters their boxes (overlapping
//!   boxes are not interleaved sample by sample), and the radiance behind is added as
//!   `C + (1 − α)·L_behind`. Each volume ends its own march at the termination threshold, and
//!   when the accumulated opacity is past it the ray goes no further: the surface behind is not
//!   shaded (what the rasterizer's blend still adds, at most `1 − threshold` of it).
//! - **Samples are shaded** with the notes' voxel illumination `C = C_amb + C_luz·k_dif·(n·L)`:
//!   the illumination model of `scene/shading.rs` for a material with `kd = 1`, `ka = ks = 0` and
//!   the classified colour as `C`, so `C_amb = A ⊗ C` and `C_luz·k_dif = S_i ⊗ C`. The normal is
//!   the gradient carried to world space by the inverse transpose, normalized and turned to the
//!   viewer; where the gradient vanishes a sample gets the ambient term alone. With
//!   `volume.shadows` each sample casts a shadow ray per light (volumes cast none).
//! - **Isosurface**: the first crossing of `f = iso` in front of the nearest surface becomes a hit
//!   like any other, shaded by `Whitted::shade` with the volume's material: lights, shadows,
//!   reflections and refraction. Its outward normal is `−∇f` (values rise inwards; distance
//!   fields are read as positive inside). Textures and bumps do not apply to it.

use glam::{Mat3, Mat4, Vec2, Vec3};

use super::geometry::SurfaceHit;
use crate::base::Ray;
use crate::scene::Scene;
use crate::scene::light::Incidence;
use crate::scene::shading::{SurfaceSample, Terms, direct, emitted_and_ambient, facing_viewer};
use crate::settings::{VolumeSettings, VolumeView};
use crate::volume::march::{self, LocalRay};
use crate::volume::{March, Rendering, Volume};

/// The scene's volumes, prepared for tracing.
pub struct TracedVolumes<'s> {
    volumes: Vec<Prepared<'s>>,
    pub march: March,
    pub shadows: bool,
    pub view: VolumeView,
}

/// One volume, with the matrices its rays and normals need.
pub struct Prepared<'s> {
    volume: &'s Volume,
    local_from_world: Mat4,
    pub normal_from_local: Mat3,
    rendering: Rendering,
}

impl<'s> TracedVolumes<'s> {
    pub fn new(scene: &'s Scene, settings: &VolumeSettings) -> TracedVolumes<'s> {
        let volumes = if settings.enabled { &scene.volumes[..] } else { &[] };
        TracedVolumes {
            volumes: volumes
                .iter()
                .map(|volume| Prepared {
                    volume,
                    local_from_world: volume.local_from_world(),
                    normal_from_local: volume.normal_from_local(),
                    rendering: volume.rendering(settings),
                })
                .collect(),
            march: March::of(settings),
            shadows: settings.shadows,
            view: settings.view,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.volumes.is_empty()
    }
}

impl Prepared<'_> {
    fn local_ray(&self, ray: &Ray) -> LocalRay {
        LocalRay {
            origin: self.local_from_world.transform_point3(ray.origin),
            direction: self.local_from_world.transform_vector3(ray.direction),
        }
    }
}

/// The heat colour of the samples view: black for none, through red and yellow, white at
/// `VOLUME_SAMPLES_WHITE` (`heat_colour` in `shaders/volume.wgsl`).
pub fn heat_colour(samples: u32) -> Vec3 {
    let x = samples as f32 / crate::settings::VOLUME_SAMPLES_WHITE as f32;
    (Vec3::new(3.0 * x, 3.0 * x - 1.0, 3.0 * x - 2.0)).clamp(Vec3::ZERO, Vec3::ONE)
}

impl TracedVolumes<'_> {
    /// The composited volumes `ray` crosses before `t_end`, marched front to back in the order
    /// the ray enters their boxes; `shade` gives a sample's colour from its volume, `t`, local
    /// gradient and classified colour.
    pub fn composite(
        &self,
        ray: &Ray,
        t_end: f32,
        shade: &mut dyn FnMut(&Prepared, f32, Vec3, Vec3) -> Vec3,
    ) -> Crossing {
        let mut segments: Vec<(&Prepared, LocalRay, (f32, f32))> = Vec::new();
        for prepared in &self.volumes {
            if prepared.rendering != Rendering::Composite {
                continue;
            }
            let local = prepared.local_ray(ray);
            if let Some(segment) = prepared.volume.segment(&local, t_end) {
                segments.push((prepared, local, segment));
            }
        }
        segments.sort_by(|a, b| a.2.0.total_cmp(&b.2.0));
        let mut crossing = Crossing { crossed: !segments.is_empty(), ..Crossing::default() };
        for (prepared, local, segment) in segments {
            let grid = &prepared.volume.grid;
            let mut shade = |t: f32, gradient: Vec3, c: Vec3| shade(prepared, t, gradient, c);
            let out = march::composite(grid, &prepared.volume.table, &local, segment, &self.march, &mut shade, None);
            crossing.taken += out.taken;
            crossing.saved += out.planned - out.taken;
            crossing.colour += (1.0 - crossing.alpha) * out.colour;
            crossing.alpha += (1.0 - crossing.alpha) * out.alpha;
        }
        crossing
    }

    /// The nearest crossing of an isosurface volume before `t_max`, as a surface hit.
    pub fn nearest_isosurface(&self, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        let mut nearest: Option<SurfaceHit> = None;
        for prepared in &self.volumes {
            if prepared.rendering != Rendering::Isosurface {
                continue;
            }
            let iso = prepared.volume.iso;
            let limit = nearest.as_ref().map_or(t_max, |hit| hit.t);
            let local = prepared.local_ray(ray);
            let Some(segment) = prepared.volume.segment(&local, limit) else { continue };
            let grid = &prepared.volume.grid;
            let Some(t) = march::isosurface(grid, &local, segment, iso, &self.march) else { continue };
            let g = grid.grid_coordinates(local.at(t));
            let differences = self.march.gradient.unwrap_or(crate::volume::Differences::Central);
            let gradient = grid.gradient(g, self.march.reconstruction, differences);
            // Outward is where values fall; a vanishing gradient faces the ray.
            let normal = world_normal(prepared.normal_from_local, -gradient).unwrap_or(-ray.direction);
            nearest = Some(SurfaceHit {
                t,
                point: ray.at(t),
                geometric_normal: normal,
                normal,
                uv: Vec2::ZERO,
                dpdu: Vec3::ZERO,
                dpdv: Vec3::ZERO,
                material: prepared.volume.material,
                object: usize::MAX,
            });
        }
        nearest
    }
}

/// What a ray gathered crossing the composited volumes: premultiplied colour, opacity, and the
/// samples taken and saved by early termination.
#[derive(Clone, Copy, Debug, Default)]
pub struct Crossing {
    pub crossed: bool,
    pub colour: Vec3,
    pub alpha: f32,
    pub taken: u32,
    pub saved: u32,
}

/// The world-space unit normal of a local gradient (`normal_from_local`: the inverse transpose),
/// `None` where it vanishes.
pub fn world_normal(normal_from_local: Mat3, gradient: Vec3) -> Option<Vec3> {
    let n = normal_from_local * gradient;
    (n.length_squared() > 1e-20).then(|| n.normalize())
}

/// One composited sample's colour, the notes' voxel illumination `C_amb + Σ V·C_luz·k_dif·(n·L)`
/// with the classified colour `colour`, at `p` seen from direction `v` (unit, towards the viewer):
/// `normal` is turned to the viewer, `None` gives the ambient term alone; `visibility` is each
/// light's `V`.
pub fn voxel_illumination(
    scene: &Scene,
    terms: Terms,
    colour: Vec3,
    normal: Option<Vec3>,
    v: Vec3,
    p: Vec3,
    visibility: &mut dyn FnMut(&Incidence) -> Vec3,
) -> Vec3 {
    let sample = SurfaceSample {
        color: colour,
        ka: 0.0,
        kd: 1.0,
        ks: 0.0,
        specular_color: Vec3::ZERO,
        shininess: 1.0,
        emission: Vec3::ZERO,
    };
    let mut rad = emitted_and_ambient(&sample, scene.ambient, terms);
    let Some(n) = normal else { return rad };
    let n = facing_viewer(n, v);
    for light in &scene.lights {
        let Some(incidence) = light.incidence(p) else { continue };
        if incidence.l.dot(n) <= 0.0 {
            continue;
        }
        rad += visibility(&incidence) * direct(&sample, n, v, &incidence, terms);
    }
    rad
}
