//! Environment maps (docs/course/08-environment-maps.md): the rasterizer cannot trace the mirror term
//! `kps·MPS·L(r)` of a curved mirror, so it looks `L(r)` up in a map of the radiance arriving from
//! every direction, made beforehand:
//!
//! - a **cube map**: six 90° images around a centre; `r` picks the face by its largest component
//!   and the texel by the other two (the GPU's cube sampling, seamless across faces);
//! - a **sphere map**: one image of a mirror ball seen along −Z, for one view (`r` in that view's
//!   space picks the texel); made here from the cube, again for every frame or kept (then turning
//!   the camera turns the reflections with it);
//! - a **latitude–longitude map** (`α = a·u`, `β = b·v`), sampled with explicit gradients so its
//!   wrap and its poles get the mip level of their neighbours.
//!
//! The world's environment (`[world.environment]`: the procedural sky, or a lat–long, cube or
//! sphere-map image; `src/scene/environment.rs`) is turned into each form by one triangle per
//! target (`shaders/environment.wgsl`), mipmapped by the same generator as the textures, and
//! drawn as the background by the scene pass. **Dynamic cubes** are drawn from each reflective
//! object's centre (six views of the rest of the scene, with the techniques that are on), so
//! the object reflects its neighbours as well as the world; they are drawn again only when
//! something they see changes, or every `refresh` frames.
//!
//! What the map cannot know: the cube holds the radiance arriving at one point, so a reflection
//! of something near the object (parallax) is wrong away from the centre; reflections of the
//! object in itself are missing; and a dynamic cube seen in another object's cube is a frame
//! old (the first frame, it holds the world alone).

use std::hash::{Hash, Hasher};

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

pub mod pass;

use serde::Serialize;

use super::inspect::GpuInspectFragment;
use super::targets::HDR_FORMAT;
use super::uniforms::{
    ENV_CUBE, ENV_LATLONG, ENV_NONE, ENV_SKY, ENV_SPHERE, GpuEnvironment, PARALLAX_BOX, PARALLAX_GROUND,
    PARALLAX_INFINITE, mat3_columns,
};
use super::view::View;
use crate::gpu::layout;
use crate::gpu::mipmap::{MipmapGenerator, mip_level_count};
use crate::gpu::texture::Layers;
use crate::gpu::uniform::UniformBuffer;
use crate::scene::environment::cube_direction;
use crate::scene::{Camera, EnvImage, EnvironmentSource, Scene};
use crate::settings::{EnvironmentMap, EnvironmentView, Parallax, RenderSettings, SphereView};
use crate::shaders;

pub use super::uniforms::MAX_ENV_CUBES;

/// Every environment map's format: linear radiance, filterable, up to 65,504.
pub const ENV_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The largest lat–long and sphere maps made from a cube.
const MAX_MADE_SIZE: u32 = 4096;

/// The objects that get a dynamic cube: curved mirrors (`kps·MPS` non-zero) that are not planar
/// mirrors, and glass that bends light (its refraction and its Fresnel reflection look the cube
/// up), in the scene's order, at most [`MAX_ENV_CUBES`]; and warnings for those left out.
pub fn reflective_objects(scene: &Scene, planar_mirrors: &[usize]) -> (Vec<usize>, Vec<String>) {
    let mut objects: Vec<usize> = (0..scene.objects.len())
        .filter(|&i| {
            let material = &scene.materials[scene.objects[i].material.0];
            (material.reflects() || material.bends_light()) && !planar_mirrors.contains(&i)
        })
        .collect();
    let mut warnings = Vec::new();
    if objects.len() > MAX_ENV_CUBES {
        warnings.push(format!(
            "{} curved mirrors and glass objects: the first {MAX_ENV_CUBES} get dynamic environment cubes, the others reflect the world's",
            objects.len()
        ));
        objects.truncate(MAX_ENV_CUBES);
    }
    (objects, warnings)
}

/// The direction a dynamic cube drawn from `centre` is read along for the ray `p + t·d`, the twin
/// of `parallax_direction` in `shaders/common/environment.wgsl`: `d` itself when the ray is taken
/// to end infinitely far; else from the centre to where the ray meets the proxy, the ground (the
/// plane `y = bounds.min.y`, for rays going down) or the box `bounds` (the wall it leaves by).
pub fn parallax_direction(parallax: Parallax, (min, max): (Vec3, Vec3), p: Vec3, d: Vec3, centre: Vec3) -> Vec3 {
    match parallax {
        Parallax::Infinite => d,
        Parallax::Ground if d.y < 0.0 && p.y > min.y => p + ((min.y - p.y) / d.y) * d - centre,
        Parallax::Ground => d,
        Parallax::Box => {
            let safe = Vec3::select(d.abs().cmplt(Vec3::splat(1e-12)), Vec3::splat(1e-12), d);
            let far = ((min - p) / safe).max((max - p) / safe);
            let t = far.min_element();
            if t > 0.0 { p + t * d - centre } else { d }
        }
    }
}

/// The camera of cube face `face` (+X −X +Y −Y +Z −Z) at `centre`: 90° square, its image's
/// columns along the face's `u` and its rows along `v`, as the cube lookup reads them. The
/// faces' frame is left-handed (the cube is seen from inside), so the view is a mirrored one.
pub fn cube_face_view(centre: Vec3, face: usize, near: f32, far: f32) -> View {
    let forward = cube_direction(face, Vec2::splat(0.5));
    // The face's edges, on the plane one unit along `forward`, from its centre.
    let edge = |uv: Vec2| {
        let d = cube_direction(face, uv);
        d / d.dot(forward) - forward
    };
    let right = edge(Vec2::new(1.0, 0.5)).normalize();
    let up = edge(Vec2::new(0.5, 0.0)).normalize();
    let eye_frame = Mat3::from_cols(right, up, -forward);
    let view_from_world = Mat4::from_mat3(eye_frame.transpose()) * Mat4::from_translation(-centre);
    // The scene camera's perspective (src/scene/camera.rs) with a 90° square window: 2n wide.
    let clip_from_view = Mat4::from_cols(
        Vec4::new(1.0, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 1.0, 0.0, 0.0),
        Vec4::new(0.0, 0.0, far / (near - far), -1.0),
        Vec4::new(0.0, 0.0, near * far / (near - far), 0.0),
    );
    let clip_from_world = clip_from_view * view_from_world;
    View {
        clip_from_world,
        eye: centre,
        orthographic: false,
        view_axis: -forward,
        mirrored: eye_frame.determinant() < 0.0,
        clip_plane: None,
        clip_from_reflected: clip_from_world,
    }
}

/// The world-to-view rotation of a camera: the sphere map's view space.
pub fn view_rotation(camera: &Camera) -> Mat3 {
    let frame = camera.frame();
    Mat3::from_cols(frame.xe, frame.ye, frame.ze).transpose()
}

/// Where an object's dynamic cube is drawn from, the centre of its bounding box, and the
/// distance from there to the box's nearest face (what lies nearer is inside the object).
pub fn object_centre(scene: &Scene, object: usize) -> (Vec3, f32) {
    let object = &scene.objects[object];
    let local = object.shape.curved_bounds().unwrap_or_else(|| {
        let mesh = scene.tessellate(object);
        mesh.positions
            .iter()
            .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    });
    let corners = (0..8).map(|k| {
        let pick = |bit: usize, axis: usize| if k & bit == 0 { local.0[axis] } else { local.1[axis] };
        object.world_from_local.transform_point3(Vec3::new(pick(1, 0), pick(2, 1), pick(4, 2)))
    });
    let (lo, hi) = corners
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(p), hi.max(p)));
    if !(lo.is_finite() && hi.is_finite()) {
        return (object.world_from_local.transform_point3(Vec3::ZERO), 0.0);
    }
    ((lo + hi) / 2.0, ((hi - lo) / 2.0).min_element())
}

/// The near and far planes of the cube views from inside an object whose box reaches `inner`
/// from the centre, in a scene within `bounds`: the near plane half way to the object's surface
/// (nothing the cube should see is nearer), the far one past the whole scene.
pub fn capture_range(inner: f32, bounds: Option<(Vec3, Vec3)>) -> (f32, f32) {
    let diagonal = bounds.map_or(1.0, |(lo, hi)| (hi - lo).length()).max(1e-3);
    ((0.5 * inner).max(1e-5 * diagonal), 4.0 * diagonal)
}

/// The pipelines that make maps from the world's source and draw them as teaching views. Built
/// once per device.
pub struct Converter {
    group_layout: wgpu::BindGroupLayout,
    to_cube: wgpu::RenderPipeline,
    to_latlong: wgpu::RenderPipeline,
    to_sphere: wgpu::RenderPipeline,
    view_cross: wgpu::RenderPipeline,
    /// The first dynamic cube unfolded, read from the cube array.
    view_cross_dynamic: wgpu::RenderPipeline,
    /// A sphere or lat–long map shown as an image.
    view_image: wgpu::RenderPipeline,
    /// Trilinear; u repeats (the lat–long map's wrap), v clamps.
    pub sampler: wgpu::Sampler,
}

impl Converter {
    pub fn new(device: &wgpu::Device) -> Converter {
        let module = shaders::module(device, "environment::shader", shaders::ENVIRONMENT);
        let filterable = wgpu::TextureSampleType::Float { filterable: true };
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("environment::group_layout"),
            entries: &[
                layout::uniform(0, wgpu::ShaderStages::FRAGMENT),
                layout::sampler(1, wgpu::SamplerBindingType::Filtering),
                layout::texture(2, filterable, wgpu::TextureViewDimension::D2),
                layout::texture(3, filterable, wgpu::TextureViewDimension::Cube),
                layout::texture(
                    4,
                    filterable,
                    shaders::Profile::of(device).view_dimension(wgpu::TextureViewDimension::CubeArray),
                ),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("environment::layout"),
            bind_group_layouts: &[Some(&group_layout)],
            immediate_size: 0,
        });
        let pipeline = |fragment: &str, format: wgpu::TextureFormat| {
            layout::fullscreen_pipeline(
                device,
                "environment::pipeline",
                &pipeline_layout,
                &module,
                ("vs_convert", fragment),
                &[Some(format.into())],
            )
        };
        let hdr = HDR_FORMAT;
        Converter {
            to_cube: pipeline("fs_to_cube", ENV_FORMAT),
            to_latlong: pipeline("fs_to_latlong", ENV_FORMAT),
            to_sphere: pipeline("fs_to_sphere", ENV_FORMAT),
            view_cross: pipeline("fs_view_cross", hdr),
            view_cross_dynamic: pipeline("fs_view_cross_dynamic", hdr),
            view_image: pipeline("fs_view_image", hdr),
            group_layout,
            sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("environment::sampler"),
                address_mode_u: wgpu::AddressMode::Repeat,
                address_mode_v: wgpu::AddressMode::ClampToEdge,
                address_mode_w: wgpu::AddressMode::ClampToEdge,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                mipmap_filter: wgpu::MipmapFilterMode::Linear,
                ..Default::default()
            }),
        }
    }

    /// The group that reads `sources`: a 2D map, a cube and a cube array.
    fn group(
        &self,
        device: &wgpu::Device,
        params: &UniformBuffer<GpuEnvironment>,
        (source_2d, source_cube, source_cubes): (&wgpu::TextureView, &wgpu::TextureView, &wgpu::TextureView),
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("environment::group"),
            layout: &self.group_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params.binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&self.sampler) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(source_2d) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(source_cube) },
                wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(source_cubes) },
            ],
        })
    }

    /// Draws `pipeline` over `target` once per instance in `instances` (a cube's faces).
    fn draw(
        encoder: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::RenderPipeline,
        group: &wgpu::BindGroup,
        target: &wgpu::TextureView,
        instance: u32,
    ) {
        Self::draw_into(encoder, pipeline, group, target, instance, None);
    }

    /// [`Self::draw`], into the rectangle `viewport` (`[x, y, w, h]` in pixels) over what the
    /// target holds, or over the whole target, cleared, when `None`.
    fn draw_into(
        encoder: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::RenderPipeline,
        group: &wgpu::BindGroup,
        target: &wgpu::TextureView,
        instance: u32,
        viewport: Option<[f32; 4]>,
    ) {
        let load = if viewport.is_some() { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(wgpu::Color::BLACK) };
        let mut pass = encoder.begin_render_pass(&layout::pass(
            "environment::pass",
            &[Some(layout::color_attachment(target, load))],
            None,
        ));
        if let Some([x, y, w, h]) = viewport {
            pass.set_viewport(x, y, w, h, 0.0, 1.0);
        }
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, instance..instance + 1);
    }
}

/// Where a teaching view of a map `aspect` times as wide as it is high sits in a frame of
/// `size` pixels, as `[x, y, w, h]` in pixels: with `inset`, in the frame's lower-right corner,
/// 40 % of its width (at most 60 % of its height) and at the map's own aspect, so the scene
/// stays in view around it; otherwise the whole frame (the view letterboxes itself). The viewer
/// marks directions on the lat–long view with the same rectangle.
pub fn view_rect(size: (u32, u32), aspect: f32, inset: bool) -> [f32; 4] {
    let (width, height) = (size.0 as f32, size.1 as f32);
    if !inset {
        return [0.0, 0.0, width, height];
    }
    let margin = (0.02 * width).round();
    let w = (0.4 * width).min(0.6 * height * aspect).round().max(1.0);
    let h = (w / aspect).round().max(1.0);
    [(width - margin - w).max(0.0), (height - margin - h).max(0.0), w, h]
}

/// A map texture and the view the scene pass samples it through.
pub struct MapTexture {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl MapTexture {
    /// A map of `layers` (a 2D map, the world's cube, the dynamic cubes) with a full mip chain,
    /// viewed as what its layers are.
    fn new(device: &wgpu::Device, label: &str, (width, height): (u32, u32), layers: Layers) -> MapTexture {
        let map = layers.texture(
            device,
            &wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: mip_level_count(width, height),
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: ENV_FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_DST
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            },
        );
        MapTexture { texture: map.texture, view: map.view }
    }

    /// A 2D map holding `image` times `intensity` (clamped to what half floats hold), or a cube
    /// of six.
    fn upload(device: &wgpu::Device, queue: &wgpu::Queue, label: &str, images: &[&EnvImage], intensity: f32) -> Self {
        let (width, height) = (images[0].width, images[0].height);
        let layers = if images.len() == 6 { Layers::Cube } else { Layers::Single };
        let map = MapTexture::new(device, label, (width, height), layers);
        for (layer, image) in images.iter().enumerate() {
            let halves: Vec<u16> = image
                .texels
                .iter()
                .flat_map(|&c| {
                    let c = (c * intensity).clamp(Vec3::ZERO, Vec3::splat(65_000.0));
                    [c.x, c.y, c.z, 1.0].map(|x| half::f16::from_f32(x).to_bits())
                })
                .collect();
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &map.texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: layer as u32 },
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(&halves),
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(8 * width), rows_per_image: Some(height) },
                wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            );
        }
        map
    }

    /// The view of one layer's level 0, to draw into (never to sample: see [`Layers`]).
    fn layer(&self, layer: u32) -> wgpu::TextureView {
        self.texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("environment::layer"),
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_mip_level: 0,
            mip_level_count: Some(1),
            base_array_layer: layer,
            array_layer_count: Some(1),
            ..Default::default()
        })
    }

    fn size(&self) -> u32 {
        self.texture.width()
    }
}

/// The scene's environment on the GPU: the world as a cube, a sphere map and a lat–long map, and
/// the dynamic cubes of its reflective objects. Made at the first frame, again when
/// `environment.cube_size` changes.
pub struct EnvironmentMaps {
    pub params: UniformBuffer<GpuEnvironment>,
    /// The conversion group that reads the world's source and its cube: the lat–long and sphere
    /// maps are made through it.
    reads_world: wgpu::BindGroup,
    /// The teaching views' groups, made with the maps.
    views: ViewGroups,
    /// The world's fields of the uniform (source, sky, background); the rotations change per frame.
    world: GpuEnvironment,
    pub cube: MapTexture,
    pub sphere: MapTexture,
    pub latlong: MapTexture,
    /// Six layers per object of `SceneGpu::env_objects`, in a cube array of at least two cubes,
    /// or a 2D array of `6n + 1` layers on the WebGL2 profile ([`Layers::count`]; 1×1 texels for
    /// none, unused).
    pub dynamic: MapTexture,
    /// How many of the cube array's cubes belong to objects.
    dynamic_cubes: u32,
    /// `environment.cube_size` when they were made.
    pub cube_size: u32,
    /// The view rotation the sphere map was last made for.
    sphere_made_for: Option<Mat3>,
    /// What the dynamic cubes were drawn from, and the frames since.
    captured: Option<u64>,
    frames_since_capture: u32,
}

impl EnvironmentMaps {
    /// Uploads the world's environment and makes its cube and lat–long forms; the dynamic cubes
    /// start as copies of the world's cube.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        pass: &Converter,
        mipmaps: &MipmapGenerator,
        scene: &Scene,
        cube_size: u32,
        dynamic_cubes: usize,
    ) -> EnvironmentMaps {
        let world = world_uniform(scene);
        let params = UniformBuffer::new(device, "environment::params", &world);
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("environment::encoder") });
        // Bound where no cube array is read, and always where a group is drawn into the dynamic
        // cubes (a texture may not be read and drawn into in one pass).
        let no_cubes = MapTexture::new(device, "environment::no_cubes", (1, 1), Layers::Cubes(1));
        let maker = MapMaker { device, pass, mipmaps, params: &params, no_cubes: &no_cubes };
        let maps = WorldMaps::upload(device, queue, scene, cube_size);
        let reads_world = maker.world_forms(&mut encoder, &maps);
        let sphere = MapTexture::new(device, "environment::sphere", (maps.map_size, maps.map_size), Layers::Single);
        let dynamic_cubes = dynamic_cubes as u32;
        let dynamic = maker.dynamic_cubes(&mut encoder, &maps, dynamic_cubes, cube_size);
        queue.submit([encoder.finish()]);
        let views = maker.view_groups(&maps, &sphere, &dynamic, dynamic_cubes);
        EnvironmentMaps {
            reads_world,
            views,
            params,
            world,
            cube: maps.cube,
            sphere,
            latlong: maps.latlong,
            dynamic,
            dynamic_cubes,
            cube_size,
            sphere_made_for: None,
            captured: None,
            frames_since_capture: 0,
        }
    }

    /// Writes the frame's uniform and makes the sphere map when it is due (submitted ahead of the
    /// frame); returns whether it did.
    /// `rotation` is the main camera's world-to-view rotation.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        pass: &Converter,
        mipmaps: &MipmapGenerator,
        settings: &RenderSettings,
        rotation: Mat3,
    ) -> bool {
        let env = &settings.environment;
        let wants_sphere = (env.enabled && env.map == EnvironmentMap::Sphere) || env.view == EnvironmentView::Sphere;
        let remake = wants_sphere
            && match (self.sphere_made_for, env.sphere_view) {
                (None, _) => true,
                (Some(made), SphereView::Follow) => made != rotation,
                (Some(_), SphereView::Fixed) => false,
            };
        if remake {
            self.sphere_made_for = Some(rotation);
        }
        let made_for = self.sphere_made_for.unwrap_or(rotation);
        self.params.write(
            queue,
            &GpuEnvironment {
                sphere_from_world: mat3_columns(rotation),
                world_from_map: mat3_columns(made_for.transpose()),
                ..self.world
            },
        );
        if remake {
            // The map is made from the world's cube, for the view `made_for`.
            let mut encoder =
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("environment::sphere") });
            Converter::draw(&mut encoder, &pass.to_sphere, &self.reads_world, &self.sphere.layer(0), 0);
            mipmaps.record(device, &mut encoder, &self.sphere.texture);
            queue.submit([encoder.finish()]);
        }
        remake
    }

    /// Sets where the dynamic cubes' lookups take rays to end: `parallax` (`PARALLAX_*`) on the box
    /// `bounds` around the scene, each cube drawn from its entry of `centres`.
    pub fn set_proxy(&mut self, parallax: Parallax, bounds: Option<(Vec3, Vec3)>, centres: &[Vec3]) {
        let (min, max) = bounds.unwrap_or((Vec3::ZERO, Vec3::ZERO));
        self.world.parallax = match (parallax, bounds) {
            (_, None) | (Parallax::Infinite, _) => PARALLAX_INFINITE,
            (Parallax::Ground, Some(_)) => PARALLAX_GROUND,
            (Parallax::Box, Some(_)) => PARALLAX_BOX,
        };
        self.world.proxy_min = min.to_array();
        self.world.proxy_max = max.to_array();
        for (slot, centre) in self.world.cube_centres.iter_mut().zip(centres) {
            *slot = centre.extend(1.0).to_array();
        }
    }

    /// Whether the dynamic cubes are due for drawing, given what they would see (`key`); counts
    /// the frame.
    pub fn capture_due(&mut self, key: u64, refresh: u32) -> bool {
        self.frames_since_capture += 1;
        let due = self.captured != Some(key) || (refresh > 0 && self.frames_since_capture >= refresh);
        if due {
            self.captured = Some(key);
            self.frames_since_capture = 0;
        }
        due
    }

    /// Forgets the dynamic cubes' contents, so the next frame draws them.
    pub fn invalidate_captures(&mut self) {
        self.captured = None;
    }

    /// The layers of the dynamic cubes that objects own (the cube array's padding left out).
    pub fn dynamic_layers(&self) -> std::ops::Range<u32> {
        0..6 * self.dynamic_cubes
    }

    /// Copies `image` (a capture target of the cube size) into layer `layer` of the dynamic cubes.
    pub fn store_capture(&self, encoder: &mut wgpu::CommandEncoder, image: &wgpu::Texture, layer: u32) {
        encoder.copy_texture_to_texture(
            image.as_image_copy(),
            wgpu::TexelCopyTextureInfo {
                texture: &self.dynamic.texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::Extent3d { width: self.dynamic.size(), height: self.dynamic.size(), depth_or_array_layers: 1 },
        );
    }

    /// Draws the teaching view `view` over `target` (a frame of `size` pixels), inset in its
    /// corner or over all of it ([`view_rect`]): the cube unfolded (object 0's dynamic cube when
    /// it has one, else the world's), the sphere map or the lat–long map.
    pub fn record_view(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pass: &Converter,
        settings: &crate::settings::EnvironmentSettings,
        (target, size): (&wgpu::TextureView, (u32, u32)),
    ) {
        let aspect = |map: &MapTexture| map.texture.width() as f32 / map.texture.height() as f32;
        let (pipeline, group, aspect) = match settings.view {
            EnvironmentView::Off => return,
            EnvironmentView::Cross => match &self.views.cross_dynamic {
                Some(group) if settings.dynamic => (&pass.view_cross_dynamic, group, 4.0 / 3.0),
                _ => (&pass.view_cross, &self.views.cross_world, 4.0 / 3.0),
            },
            EnvironmentView::Sphere => (&pass.view_image, &self.views.sphere, aspect(&self.sphere)),
            EnvironmentView::Latlong => (&pass.view_image, &self.views.latlong, aspect(&self.latlong)),
        };
        let viewport = settings.inset.then(|| view_rect(size, aspect, true));
        Converter::draw_into(encoder, pipeline, group, target, 0, viewport);
    }
}

/// The world's environment as the scene gives it: its source uploaded (a sphere map, a lat–long
/// map or a cube's six faces, times the environment's intensity) and blank images for the forms
/// made from it. No environment gives a small blank cube and lat–long map.
struct WorldMaps<'s> {
    source: Option<&'s EnvironmentSource>,
    /// The sphere map the scene gives (1×1, unused, for other sources).
    sphere_source: MapTexture,
    latlong: MapTexture,
    cube: MapTexture,
    /// The side of the sphere map and the height of the lat–long map made from the source.
    map_size: u32,
}

impl<'s> WorldMaps<'s> {
    fn upload(device: &wgpu::Device, queue: &wgpu::Queue, scene: &'s Scene, cube_size: u32) -> WorldMaps<'s> {
        let intensity = scene.environment.as_ref().map_or(1.0, |e| e.intensity);
        let source = scene.environment.as_ref().map(|e| &e.source);
        let (cube_face, map_size) = match source {
            None => (4, 4),
            Some(EnvironmentSource::Cube(faces)) => (faces[0].width, (2 * faces[0].width).min(MAX_MADE_SIZE / 2)),
            Some(_) => (cube_size, (2 * cube_size).min(MAX_MADE_SIZE / 2)),
        };
        let sphere_source = match source {
            Some(EnvironmentSource::Sphere(image)) => {
                MapTexture::upload(device, queue, "environment::sphere_source", &[image], intensity)
            }
            _ => MapTexture::new(device, "environment::no_sphere_source", (1, 1), Layers::Single),
        };
        let latlong = match source {
            Some(EnvironmentSource::LatLong(image)) => {
                MapTexture::upload(device, queue, "environment::latlong", &[image], intensity)
            }
            _ => MapTexture::new(device, "environment::latlong", (2 * map_size, map_size), Layers::Single),
        };
        let cube = match source {
            Some(EnvironmentSource::Cube(faces)) => {
                let faces: Vec<&EnvImage> = faces.iter().collect();
                MapTexture::upload(device, queue, "environment::cube", &faces, intensity)
            }
            _ => MapTexture::new(device, "environment::cube", (cube_face, cube_face), Layers::Cube),
        };
        WorldMaps { source, sphere_source, latlong, cube, map_size }
    }

    /// The 2D map the world's radiance is read from by direction: the sphere map given, else the
    /// lat–long map.
    fn source_2d(&self) -> &wgpu::TextureView {
        match self.source {
            Some(EnvironmentSource::Sphere(_)) => &self.sphere_source.view,
            _ => &self.latlong.view,
        }
    }
}

/// What the steps of [`EnvironmentMaps::new`] draw with: the conversions, the mip generator, the
/// uniform every group reads and the stand-in cube array.
struct MapMaker<'a> {
    device: &'a wgpu::Device,
    pass: &'a Converter,
    mipmaps: &'a MipmapGenerator,
    params: &'a UniformBuffer<GpuEnvironment>,
    no_cubes: &'a MapTexture,
}

impl MapMaker<'_> {
    fn group(&self, sources: (&wgpu::TextureView, &wgpu::TextureView, &wgpu::TextureView)) -> wgpu::BindGroup {
        self.pass.group(self.device, self.params, sources)
    }

    /// Records the sources' mip chains, then the world's cube and lat–long map made from the
    /// source where the scene gave neither; returns the group that reads the source, or the
    /// world's cube made from it (what the sphere map is made from).
    fn world_forms(&self, encoder: &mut wgpu::CommandEncoder, maps: &WorldMaps) -> wgpu::BindGroup {
        let (device, mipmaps) = (self.device, self.mipmaps);
        // Sources first: their mip chains are what the conversions read.
        mipmaps.record(device, encoder, &maps.sphere_source.texture);
        match maps.source {
            Some(EnvironmentSource::LatLong(_)) => mipmaps.record(device, encoder, &maps.latlong.texture),
            Some(EnvironmentSource::Cube(_)) => mipmaps.record(device, encoder, &maps.cube.texture),
            _ => {}
        }
        if !matches!(maps.source, Some(EnvironmentSource::Cube(_))) {
            let no_cube = MapTexture::new(device, "environment::no_cube", (1, 1), Layers::Cube);
            let group = self.group((maps.source_2d(), &no_cube.view, &self.no_cubes.view));
            for face in 0..6 {
                Converter::draw(encoder, &self.pass.to_cube, &group, &maps.cube.layer(face), face);
            }
            mipmaps.record(device, encoder, &maps.cube.texture);
        }
        let reads_world = self.group((&maps.sphere_source.view, &maps.cube.view, &self.no_cubes.view));
        if !matches!(maps.source, Some(EnvironmentSource::LatLong(_))) {
            Converter::draw(encoder, &self.pass.to_latlong, &reads_world, &maps.latlong.layer(0), 0);
            mipmaps.record(device, encoder, &maps.latlong.texture);
        }
        reads_world
    }

    /// The cube array of `count` dynamic cubes of `size` texels a side (1×1 for none). Until it is
    /// drawn, each dynamic cube shows the world (a neighbour's cube seen in the first frame's
    /// captures is the world alone, not black).
    fn dynamic_cubes(&self, encoder: &mut wgpu::CommandEncoder, maps: &WorldMaps, count: u32, size: u32) -> MapTexture {
        let size = if count == 0 { 1 } else { size };
        let dynamic = MapTexture::new(self.device, "environment::dynamic", (size, size), Layers::Cubes(count));
        if count > 0 {
            let group = self.group((maps.source_2d(), &maps.cube.view, &self.no_cubes.view));
            for layer in 0..6 * count {
                // The world's radiance at the dynamic cube's texels.
                Converter::draw(encoder, &self.pass.to_cube, &group, &dynamic.layer(layer), layer % 6);
            }
            self.mipmaps.record_layers(self.device, encoder, &dynamic.texture, 0..6 * count);
        }
        dynamic
    }

    /// The teaching views' groups over the finished maps.
    fn view_groups(
        &self,
        maps: &WorldMaps,
        sphere: &MapTexture,
        dynamic: &MapTexture,
        dynamic_cubes: u32,
    ) -> ViewGroups {
        let reads = |source_2d, source_cubes| self.group((source_2d, &maps.cube.view, source_cubes));
        ViewGroups {
            cross_world: reads(&maps.latlong.view, &self.no_cubes.view),
            cross_dynamic: (dynamic_cubes > 0).then(|| reads(&maps.latlong.view, &dynamic.view)),
            sphere: reads(&sphere.view, &self.no_cubes.view),
            latlong: reads(&maps.latlong.view, &self.no_cubes.view),
        }
    }
}

/// What each teaching view reads: the cube unfolded (the world's, or the first reflective
/// object's when there is one), the sphere map, the lat–long map.
struct ViewGroups {
    cross_world: wgpu::BindGroup,
    cross_dynamic: Option<wgpu::BindGroup>,
    sphere: wgpu::BindGroup,
    latlong: wgpu::BindGroup,
}

/// The world's part of the environment uniform.
fn world_uniform(scene: &Scene) -> GpuEnvironment {
    let identity = mat3_columns(Mat3::IDENTITY);
    let mut gpu = GpuEnvironment {
        sphere_from_world: identity,
        world_from_map: identity,
        zenith: [0.0; 3],
        source: ENV_NONE,
        horizon: [0.0; 3],
        intensity: 1.0,
        ground: [0.0; 3],
        sun_cos_outer: 1.0,
        sun_direction: [0.0, 1.0, 0.0],
        sun_cos_inner: 1.0,
        sun_color: [0.0; 3],
        _pad0: 0.0,
        background: scene.background.to_array(),
        _pad1: 0.0,
        proxy_min: [0.0; 3],
        parallax: PARALLAX_INFINITE,
        proxy_max: [0.0; 3],
        _pad2: 0.0,
        cube_centres: [[0.0; 4]; MAX_ENV_CUBES],
    };
    let Some(environment) = &scene.environment else { return gpu };
    gpu.intensity = environment.intensity;
    gpu.source = match &environment.source {
        EnvironmentSource::Sky(sky) => {
            gpu.zenith = sky.zenith.to_array();
            gpu.horizon = sky.horizon.to_array();
            gpu.ground = sky.ground.to_array();
            gpu.sun_direction = sky.sun_direction.normalize().to_array();
            gpu.sun_color = sky.sun_color.to_array();
            gpu.sun_cos_inner = sky.sun_radius.cos();
            gpu.sun_cos_outer = (1.5 * sky.sun_radius).cos();
            ENV_SKY
        }
        EnvironmentSource::LatLong(_) => ENV_LATLONG,
        EnvironmentSource::Cube(_) => ENV_CUBE,
        EnvironmentSource::Sphere(_) => ENV_SPHERE,
    };
    gpu
}

/// What the dynamic cubes see, hashed: every object's transform, every material, light and
/// setting, and `traced`, what their faces' traced terms are (the hybrid's; the camera is left out:
/// the cubes do not depend on it).
pub fn capture_key(scene: &Scene, settings: &RenderSettings, traced: u64) -> u64 {
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    traced.hash(&mut hasher);
    for object in &scene.objects {
        object.world_from_local.to_cols_array().map(f32::to_bits).hash(&mut hasher);
        object.material.0.hash(&mut hasher);
    }
    for material in &scene.materials {
        bytemuck::bytes_of(&material.to_gpu()).hash(&mut hasher);
    }
    for light in &scene.lights {
        bytemuck::bytes_of(&light.to_gpu()).hash(&mut hasher);
    }
    scene.ambient.to_array().map(f32::to_bits).hash(&mut hasher);
    let settings = RenderSettings {
        environment: crate::settings::EnvironmentSettings { view: EnvironmentView::Off, ..settings.environment },
        ..settings.clone()
    };
    format!("{settings:?}").hash(&mut hasher);
    hasher.finish()
}

/// A curved mirror's environment lookup.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnvironmentLookup {
    /// `r = 2(n·v)n − v`, the direction looked up.
    pub direction: Vec3,
    /// `cube (dynamic, object's centre)`, `cube (world)`, `sphere` or `latlong`.
    pub map: String,
    /// Where a dynamic cube was captured (its object's centre).
    pub centre: Option<Vec3>,
    /// The direction the map was read along: `r`, or for a dynamic cube with a local proxy
    /// (`environment.parallax`) the direction from its centre to where `r` meets the proxy.
    pub read_along: Vec3,
    /// The cube face and texel (for cubes), or the map's texel coordinates.
    pub texel: String,
    /// `kps·MPS·L(r)`.
    pub radiance: Vec3,
}

/// What a curved mirror's record looked up, for `mirador explain`: the direction, the map and its
/// texel, and for a dynamic cube where the frame drew it from (`cubes`, by object) and the
/// direction read along through the parallax proxy (around `bounds`).
pub fn lookup(
    record: &GpuInspectFragment,
    settings: &RenderSettings,
    cubes: &[(usize, Vec3)],
    bounds: Option<(Vec3, Vec3)>,
) -> EnvironmentLookup {
    let r = record.env_direction.normalize_or_zero();
    let env = &settings.environment;
    let dynamic = env.map == EnvironmentMap::Cube && env.dynamic && record.env_layer >= 0;
    // The point the frame drew the object's cube from, and the bounds of its parallax proxy.
    let centre = dynamic
        .then(|| cubes.iter().find(|(object, _)| *object as u32 == record.object).map(|(_, centre)| *centre))
        .flatten();
    let read_along = match (centre, bounds) {
        (Some(centre), Some(bounds)) => parallax_direction(env.parallax, bounds, record.world, r, centre).normalize(),
        _ => r,
    };
    let (map, texel) = match env.map {
        EnvironmentMap::Cube => {
            let size = env.cube_size as f32;
            let (face, uv) = crate::scene::environment::cube_face_uv(read_along);
            let faces = ["+X", "−X", "+Y", "−Y", "+Z", "−Z"];
            let name = if dynamic { "cube (dynamic, captured at the object's centre)" } else { "cube (the world's)" };
            (
                name.to_string(),
                format!("face {} texel ({}, {})", faces[face], (uv.x * size) as u32, (uv.y * size) as u32),
            )
        }
        EnvironmentMap::Sphere => ("sphere map".to_string(), "in view space".to_string()),
        EnvironmentMap::Latlong => {
            let uv = crate::scene::environment::latlong_uv(r);
            ("lat–long map".to_string(), format!("(u, v) = ({:.3}, {:.3})", uv.x, uv.y))
        }
    };
    EnvironmentLookup { direction: r, map, centre, read_along, texel, radiance: record.environment }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallax_reads_the_cube_where_the_ray_meets_the_proxy() {
        let bounds = (Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 2.0, 5.0));
        let centre = Vec3::new(0.0, 1.0, 0.0);
        // From a point on a ball's underside, 45° down: the floor at (1, 0, 0), seen from the
        // centre along (1, −1, 0).
        let (p, d) = (Vec3::new(0.5, 0.5, 0.0), Vec3::new(1.0, -1.0, 0.0).normalize());
        let ground = parallax_direction(Parallax::Ground, bounds, p, d, centre);
        assert!(ground.normalize().abs_diff_eq(Vec3::new(1.0, -1.0, 0.0).normalize(), 1e-6), "{ground}");
        assert_eq!(parallax_direction(Parallax::Infinite, bounds, p, d, centre), d);
        // Going up, the ground proxy is infinitely far; the box's ceiling is at y = 2, reached
        // at (0.5, 2, 1.5).
        let up = Vec3::new(0.0, 1.0, 1.0).normalize();
        assert_eq!(parallax_direction(Parallax::Ground, bounds, p, up, centre), up);
        let boxed = parallax_direction(Parallax::Box, bounds, p, up, centre);
        assert!(boxed.normalize().abs_diff_eq(Vec3::new(0.5, 1.0, 1.5).normalize(), 1e-6), "{boxed}");
    }
}
