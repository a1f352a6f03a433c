//! The scene: pure CPU data read by both renderers. No wgpu here.
//!
//! A [`Scene`] holds a camera, lights, materials, textures, meshes and objects. Objects are
//! analytic shapes (sphere, axis-aligned box, plane) or triangle meshes, each placed by a
//! `world_from_local` transform; glTF models are imported into meshes, materials, lights and
//! cameras, Wavefront OBJ models (with their MTL materials) and PLY meshes into meshes and
//! materials, NRRD and raw volume files ([`nrrd`]) into the voxel grids of [`crate::volume`].
//! Scenes are written in TOML ([`file`], documented in `docs/scene-format.md`).

pub mod camera;
pub mod environment;
pub mod file;
pub mod gltf;
pub mod light;
pub mod material;
pub mod mesh;
pub mod nrrd;
pub mod obj;
pub mod optics;
pub mod ply;
pub mod shading;
pub mod sphereflake;
pub mod texture;

use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Vec2, Vec3};

pub use camera::{Camera, Projection};
pub use environment::{EnvImage, Environment, EnvironmentSource, Sky};
pub use light::{Attenuation, Light, LightKind};
pub use material::{AlphaMode, ColorSpace, Material, ProceduralHeight, Texture, Wrap};
pub use mesh::Mesh;

/// What one model file (glTF, OBJ or PLY) contributes to a scene. glTF's container is the fullest,
/// so it serves all three; OBJ and PLY files leave its lights and cameras empty.
pub type ModelImport = gltf::GltfImport;

use crate::base::MaterialId;
use crate::settings::{RenderSettings, SceneFacts};

/// The geometry of an object, in its local coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// Axis-aligned (in local coordinates) box between two corners.
    Cuboid {
        min: Vec3,
        max: Vec3,
    },
    /// The finite quad `|x| ≤ size.x/2, |z| ≤ size.y/2` in the plane y = 0, facing +y, with
    /// texture coordinates over `[0, uv_scale]`.
    Plane {
        size: Vec2,
        uv_scale: Vec2,
    },
    /// Index into [`Scene::meshes`].
    Mesh(usize),
    /// Signed-distance-field shapes, which the ray tracer finds by sphere tracing (docs/course/09-ray-tracing.md#intersections).
    /// A torus around the local y axis: `major` radius to the tube's centre, `minor` the tube's.
    Torus {
        major: f32,
        minor: f32,
    },
    /// A box of half extents `half` centred at the origin, its edges rounded by `radius`
    /// (the surface lies `radius` outside the inner box `[−half, half]`).
    RoundedBox {
        half: Vec3,
        radius: f32,
    },
}

impl Shape {
    /// A box around a curved analytic shape in its local coordinates; `None` for flat shapes and
    /// meshes, whose vertices are their bounds.
    pub fn curved_bounds(&self) -> Option<(Vec3, Vec3)> {
        match *self {
            Shape::Sphere { center, radius } => Some((center - Vec3::splat(radius), center + Vec3::splat(radius))),
            Shape::Torus { major, minor } => {
                let half = Vec3::new(major + minor, minor, major + minor);
                Some((-half, half))
            }
            Shape::RoundedBox { half, radius } => Some((-half - Vec3::splat(radius), half + Vec3::splat(radius))),
            Shape::Cuboid { .. } | Shape::Plane { .. } | Shape::Mesh(_) => None,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    pub shape: Shape,
    pub material: MaterialId,
    pub world_from_local: Mat4,
}

impl Object {
    /// The matrix that carries local normals to world normals (inverse transpose).
    pub fn normal_from_local(&self) -> Mat3 {
        Mat3::from_mat4(self.world_from_local).inverse().transpose()
    }
}

/// Everything both renderers draw.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The file the scene came from, for messages; `None` for scenes built in code.
    pub source: Option<PathBuf>,
    pub camera: Camera,
    /// `A`: global ambient radiance (see `shading.rs` for how it is reflected).
    pub ambient: Vec3,
    /// Radiance of rays that hit nothing, where there is no `environment`.
    pub background: Vec3,
    /// The radiance of rays that hit nothing, by direction ([`environment`]); `None` for a plain
    /// `background` (and for scenes built in code and bare glTF models).
    pub environment: Option<Environment>,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub meshes: Vec<Mesh>,
    pub objects: Vec<Object>,
    /// Voxel grids, drawn by ray casting (`crate::volume`).
    pub volumes: Vec<crate::volume::Volume>,
    /// The objects displacement made into triangles (`bump.method = "displacement"`), each with
    /// the surface it was made from: what the rasterizer tessellates again, adaptively, on the
    /// GPU (`crate::raster::tessellation`). Empty unless [`crate::texture::displacement::displace`]
    /// displaced something.
    pub displaced: Vec<DisplacedSurface>,
    /// The scene file's defaults for the toggles; the CLI and the viewer start from these.
    pub settings: RenderSettings,
}

/// An object displacement made into triangles (`crate::texture::displacement::displace`), and
/// what it was made from: the surface the rasterizer tessellates again on the GPU, adaptively
/// (`crate::raster::tessellation`).
#[derive(Clone, Debug, PartialEq)]
pub struct DisplacedSurface {
    /// Index into `Scene::objects`: the object, now a mesh of the uniformly displaced surface.
    pub object: usize,
    /// The material with the height field (the object's own is now a copy without it).
    pub material: usize,
    /// The undisplaced mesh, in the object's coordinates.
    pub base: Mesh,
    /// The displacement `k` in world units: the material's `bump_scale` times `bump.scale`.
    pub k: f32,
}

/// Why a scene could not be loaded. Every variant names the file it is about.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The cause is part of the message (and so not a `source` as well: error chains would print
    /// it twice).
    #[error("{path}: cannot read the file: {cause}")]
    Io { path: PathBuf, cause: std::io::Error },
    #[error("{path}:{line}:{column}: {message}")]
    Syntax { path: PathBuf, line: usize, column: usize, message: String },
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
    #[error("{path}: glTF: {message}")]
    Gltf { path: PathBuf, message: String },
    #[error("{path}: OBJ: {message}")]
    Obj { path: PathBuf, message: String },
    #[error("{path}: PLY: {message}")]
    Ply { path: PathBuf, message: String },
    #[error("{path}: texture: {message}")]
    Texture { path: PathBuf, message: String },
}

impl SceneError {
    pub fn path(&self) -> &Path {
        match self {
            SceneError::Io { path, .. }
            | SceneError::Syntax { path, .. }
            | SceneError::Invalid { path, .. }
            | SceneError::Gltf { path, .. }
            | SceneError::Obj { path, .. }
            | SceneError::Ply { path, .. }
            | SceneError::Texture { path, .. } => path,
        }
    }
}

impl Scene {
    /// Loads a TOML scene file (or a bare `.gltf` / `.glb` / `.obj` / `.ply` model, framed by a
    /// default camera and light).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        file::load(path)
    }

    /// The built-in default scene, `assets/scenes/showcase.toml`.
    pub fn showcase() -> Result<Scene, SceneError> {
        Scene::load(&builtin_path("showcase.toml"))
    }

    /// The radiance arriving from `direction` (need not be unit) along a ray that hits nothing:
    /// the environment's, or the plain background where there is none.
    pub fn environment_radiance(&self, direction: Vec3) -> Vec3 {
        match &self.environment {
            Some(environment) => environment.radiance(direction),
            None => self.background,
        }
    }

    /// Slices around the rasterizer's spheres, tori and rounded boxes (the setting
    /// `sphere_segments`, at most this many where tessellation adapts to the screen). Read here
    /// only, from the scene's own settings: the frame's geometry, its mirrors, projected shadows
    /// and cubes, displacement and the tracer's rounded boxes all make a shape from one count.
    pub fn sphere_segments(&self) -> u32 {
        self.settings.sphere_segments
    }

    /// The triangles the rasterizer draws for `object`, in its local coordinates.
    pub fn tessellate(&self, object: &Object) -> std::borrow::Cow<'_, Mesh> {
        use std::borrow::Cow;
        match object.shape {
            Shape::Sphere { center, radius } => Cow::Owned(Mesh::sphere(center, radius, self.sphere_segments())),
            Shape::Cuboid { min, max } => Cow::Owned(Mesh::cuboid(min, max)),
            Shape::Plane { size, uv_scale } => Cow::Owned(Mesh::plane(size, uv_scale)),
            Shape::Mesh(index) => Cow::Borrowed(&self.meshes[index]),
            Shape::Torus { major, minor } => Cow::Owned(Mesh::torus(major, minor, self.sphere_segments())),
            Shape::RoundedBox { half, radius } => Cow::Owned(Mesh::rounded_box(half, radius, self.sphere_segments())),
        }
    }

    /// What the approximations table asks of the scene to say which approximations it makes
    /// (`crate::settings::hybrid`).
    pub fn facts(&self) -> SceneFacts {
        let material = |o: &Object| &self.materials[o.material.0];
        SceneFacts {
            lights: self.lights.len(),
            reflective: self.objects.iter().any(|o| material(o).reflects()),
            transparent: self.objects.iter().any(|o| material(o).is_transparent()),
            textured: self.objects.iter().any(|o| material(o).texture.is_some()),
            heights: self
                .objects
                .iter()
                .any(|o| material(o).height_map.is_some() || material(o).height_field.is_some()),
        }
    }

    /// A world-space bounding box of everything in the scene, `None` for an empty scene: the box
    /// around the rasterizer's triangles, except that a sphere's is exact (`r·‖row_i‖` of its
    /// transform about its centre), so thousands of spheres need no tessellation.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut bounds: Option<(Vec3, Vec3)> = None;
        let mut add = |lo: Vec3, hi: Vec3| {
            bounds = Some(match bounds {
                None => (lo, hi),
                Some((a, b)) => (a.min(lo), b.max(hi)),
            });
        };
        for volume in &self.volumes {
            for corner in volume.world_corners() {
                add(corner, corner);
            }
        }
        for object in &self.objects {
            let m = object.world_from_local;
            if let Shape::Sphere { center, radius } = object.shape {
                let c = m.transform_point3(center);
                let rows = Mat3::from_mat4(m).transpose();
                let half = radius * Vec3::new(rows.x_axis.length(), rows.y_axis.length(), rows.z_axis.length());
                add(c - half, c + half);
                continue;
            }
            for p in self.tessellate(object).positions.iter() {
                let w = m.transform_point3(*p);
                add(w, w);
            }
        }
        bounds
    }
}

/// The words of the message [`without_panics`] gives for a caught panic. A file that gets this
/// message found a check the readers miss: the fuzz harness (`fuzz/src/lib.rs`) counts it as a
/// crash, as libFuzzer does the panic itself.
pub const PANIC_CAUGHT: &str = "the reader stopped on an internal check";

/// Runs a model reader, turning a panic inside a third-party parser into an error message. The
/// readers check what they can before handing bytes to a parser; this is only the last net that
/// keeps a malformed file the parser trips over from taking the whole program down.
fn without_panics<T>(read: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(read)) {
        Ok(result) => result,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "no details".into());
            Err(format!("malformed file ({PANIC_CAUGHT}: {what})"))
        }
    }
}

/// Reads a whole file that a scene or model names (a model, a glTF buffer or image, an MTL
/// library): a regular file (see [`crate::files`]).
fn read_file(path: &Path) -> std::io::Result<Vec<u8>> {
    crate::files::read(path)
}

/// An error unless `path` is a regular file (or a link to one); see [`crate::files`].
pub(crate) fn check_regular_file(path: &Path) -> std::io::Result<()> {
    crate::files::check_regular(path)
}

/// Where the built-in scenes live: `assets/scenes/` of the source tree this binary was built from
/// (in the browser, of the assets built into the page: [`crate::files`]).
pub fn builtin_path(name: &str) -> PathBuf {
    let root = if cfg!(target_arch = "wasm32") { "" } else { env!("CARGO_MANIFEST_DIR") };
    Path::new(root).join("assets").join("scenes").join(name)
}
