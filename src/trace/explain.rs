//! One ray-traced pixel, explained: the Whitted recursion reports what it does to an
//! [`Observer`], and [`RayTree`] records it as the tree of rays the pixel's radiance came from.
//! Every ray (primary, shadow, reflected, refracted, continued past a blended surface) is a node
//! with its origin, direction and hit; every node's radiance is the sum of its terms (emission,
//! global ambient, each light's ambient, diffuse and specular parts weighted by its visibility,
//! the mirror term `kps·MPS·L(r)`, the transmitted term `kt·MT·L(t)`, what lies behind a blended
//! surface or a composited volume), and the techniques' state at the hit (texture coordinates and
//! mip level, the bumped normal, the shadow rays' occluders, the volumes' samples).
//!
//! Normal tracing reports to [`Unobserved`], whose methods are empty and whose `RECORDS` is
//! false, so the compiler removes every report and the work done only for it.

use glam::{Vec2, Vec3};
use serde::Serialize;

use super::geometry::SurfaceHit;
use crate::base::Ray;
use crate::scene::Scene;
use crate::scene::shading::DirectTerms;

/// What kind of ray a node of the tree is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RayKind {
    Primary,
    /// Towards a light, for its visibility `V`.
    Shadow,
    Reflected,
    Refracted,
    /// Straight on past a blended surface (`1 − α` of it) or a masked-out one.
    Continued,
}

/// What the recursion tells an observer. Every method has an empty default.
pub trait Observer {
    /// Whether anything is recorded: work done only to be reported is skipped when false.
    const RECORDS: bool = false;
    /// A ray is cast; what follows belongs to it until its [`Self::end`].
    fn begin(&mut self, _kind: RayKind, _ray: &Ray, _depth: u32) {}
    /// The shadow ray just begun goes towards light `light`.
    fn towards(&mut self, _light: usize) {}
    /// The surface the ray found.
    fn hit(&mut self, _hit: &SurfaceHit, _distance: f32) {}
    /// The state of the techniques at the hit.
    fn surface(&mut self, _state: SurfaceState) {}
    /// One term of the ray's radiance, as it adds to the ray's radiance (see [`Self::scale`]).
    fn term(&mut self, _name: String, _radiance: Vec3) {}
    /// Terms reported from now until [`Self::unscale`] are multiplied by `factor` (a blended
    /// surface's `α`, what a volume lets through).
    fn scale(&mut self, _factor: Vec3) {}
    fn unscale(&mut self) {}
    /// A light's contribution: its visibility `V` and the three parts of `S·L_dir`.
    fn light(&mut self, _light: usize, _visibility: Vec3, _terms: DirectTerms) {}
    /// A shadow ray crossed `hit`, which lets `transmittance` through.
    fn occluder(&mut self, _hit: &SurfaceHit, _transmittance: Vec3) {}
    /// The composited volumes the ray crossed.
    fn volumes(&mut self, _state: VolumeState) {}
    /// The ray's radiance (a shadow ray's: its visibility).
    fn end(&mut self, _radiance: Vec3) {}
}

/// The observer of normal tracing: records nothing.
pub struct Unobserved;

impl Observer for Unobserved {}

/// The techniques' state at a hit, as the tracer found it.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SurfaceState {
    pub uv: Vec2,
    /// The colour texture's mip level from the ray cone (`None`: no texture).
    pub lod: Option<f32>,
    /// The cone's width at the hit, in world units.
    pub footprint: f32,
    /// `C(p)`: the material's colour times its texture.
    pub colour: Vec3,
    /// The coverage `α` (1 for opaque surfaces).
    pub alpha: f32,
    pub geometric_normal: Vec3,
    /// The shading normal: bumped where bump mapping applies, turned to the viewer.
    pub normal: Vec3,
    /// Bump mapping's slopes `(du, dv)` = `k·∇f_h`, when it applied.
    pub bump: Option<Vec2>,
}

/// What a ray's march through the composited volumes did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct VolumeState {
    pub samples: u32,
    /// Samples early termination saved.
    pub saved: u32,
    /// Accumulated opacity.
    pub alpha: f32,
    /// Premultiplied colour the volumes added.
    pub colour: Vec3,
    /// Where the march ended: at the surface behind, or earlier where the opacity reached the
    /// threshold.
    pub stopped_early: bool,
}

/// A surface a ray hit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Hit {
    /// The object's name (`None` for a volume's isosurface).
    pub object: Option<String>,
    pub material: String,
    pub point: Vec3,
    /// From the ray's origin.
    pub distance: f32,
    pub normal: Vec3,
}

/// One term of a ray's radiance.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Term {
    pub name: String,
    pub radiance: Vec3,
}

/// A light's part of a ray's radiance.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LightState {
    pub light: usize,
    pub name: String,
    pub visibility: Vec3,
}

/// One ray of the tree.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RayNode {
    pub kind: RayKind,
    pub origin: Vec3,
    pub direction: Vec3,
    pub depth: u32,
    /// A shadow ray's light.
    pub light: Option<String>,
    /// The nearest surface (for a shadow ray, the first occluder, if any).
    pub hit: Option<Hit>,
    /// The radiance the ray brings back; for a shadow ray, its visibility `V`.
    pub radiance: Vec3,
    /// What the radiance is made of; the terms add up to it.
    pub terms: Vec<Term>,
    pub lights: Vec<LightState>,
    pub surface: Option<SurfaceState>,
    /// A shadow ray's occluders and what each lets through.
    pub occluders: Vec<(Hit, Vec3)>,
    pub volumes: Option<VolumeState>,
    pub children: Vec<RayNode>,
}

/// Records what the tracer reports as a tree of rays.
pub struct RayTree<'s> {
    scene: &'s Scene,
    /// The rays begun and not yet ended, outermost first, each with its scale stack.
    open: Vec<(RayNode, Vec<Vec3>)>,
    /// The primary ray, once it ended.
    pub root: Option<RayNode>,
}

impl<'s> RayTree<'s> {
    pub fn new(scene: &'s Scene) -> RayTree<'s> {
        RayTree { scene, open: Vec::new(), root: None }
    }

    fn hit_record(&self, hit: &SurfaceHit, distance: f32) -> Hit {
        let object = self.scene.objects.get(hit.object).map(|o| o.name.clone());
        let material = self.scene.materials.get(hit.material.0).map_or_else(String::new, |m| m.name.clone());
        Hit { object, material, point: hit.point, distance, normal: hit.normal }
    }

    fn current(&mut self) -> Option<&mut (RayNode, Vec<Vec3>)> {
        self.open.last_mut()
    }

    fn light_name(&self, light: usize) -> String {
        self.scene.lights.get(light).map_or_else(|| format!("light {light}"), |l| l.name.clone())
    }
}

impl Observer for RayTree<'_> {
    const RECORDS: bool = true;

    fn begin(&mut self, kind: RayKind, ray: &Ray, depth: u32) {
        let node = RayNode {
            kind,
            origin: ray.origin,
            direction: ray.direction,
            depth,
            light: None,
            hit: None,
            radiance: Vec3::ZERO,
            terms: Vec::new(),
            lights: Vec::new(),
            surface: None,
            occluders: Vec::new(),
            volumes: None,
            children: Vec::new(),
        };
        self.open.push((node, Vec::new()));
    }

    fn towards(&mut self, light: usize) {
        let name = self.light_name(light);
        if let Some((node, _)) = self.current() {
            node.light = Some(name);
        }
    }

    fn hit(&mut self, hit: &SurfaceHit, distance: f32) {
        let record = self.hit_record(hit, distance);
        if let Some((node, _)) = self.current() {
            node.hit = Some(record);
        }
    }

    fn surface(&mut self, state: SurfaceState) {
        if let Some((node, _)) = self.current() {
            node.surface = Some(state);
        }
    }

    fn term(&mut self, name: String, radiance: Vec3) {
        if let Some((node, scales)) = self.current() {
            let radiance = scales.iter().fold(radiance, |r, s| r * *s);
            node.terms.push(Term { name, radiance });
        }
    }

    fn scale(&mut self, factor: Vec3) {
        if let Some((_, scales)) = self.current() {
            scales.push(factor);
        }
    }

    fn unscale(&mut self) {
        if let Some((_, scales)) = self.current() {
            scales.pop();
        }
    }

    fn light(&mut self, light: usize, visibility: Vec3, terms: DirectTerms) {
        let name = self.light_name(light);
        for (part, radiance) in [
            ("ambient ka·C", terms.ambient),
            ("diffuse kd·C·(n·l)", terms.diffuse),
            ("specular ks·S·(r·v)^e", terms.specular),
        ] {
            self.term(format!("light `{name}`: {part} × V"), visibility * radiance);
        }
        if let Some((node, _)) = self.current() {
            node.lights.push(LightState { light, name, visibility });
        }
    }

    fn occluder(&mut self, hit: &SurfaceHit, transmittance: Vec3) {
        let record = self.hit_record(hit, hit.t);
        if let Some((node, _)) = self.current() {
            if node.hit.is_none() {
                node.hit = Some(record.clone());
            }
            node.occluders.push((record, transmittance));
        }
    }

    fn volumes(&mut self, state: VolumeState) {
        if let Some((node, _)) = self.current() {
            node.volumes = Some(state);
        }
    }

    fn end(&mut self, radiance: Vec3) {
        let Some((mut node, _)) = self.open.pop() else { return };
        node.radiance = radiance;
        match self.open.last_mut() {
            Some((parent, _)) => parent.children.push(node),
            None => self.root = Some(node),
        }
    }
}
