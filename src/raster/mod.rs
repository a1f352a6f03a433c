//! The z-buffer renderer. Each technique is one pass (one file here, one WGSL file of the same
//! name in `shaders/`); [`Renderer::render`] records them in order, top to bottom, and each pass
//! returns what it made for the next to read:
//!
//! ```text
//! views (main camera, light views) written to their slots
//! shadow maps (pass 1 of §4, kept while lights and casters stay) ─┐
//!                                                                 ├→ lighting inputs (group 2)
//! depth prepass → projected shadow polygons (object precision) ───┘
//!               → opaque (z-buffer + illumination model + pass 2 of §4)
//!               → transparent surfaces in Z order (§5: I = Im + kt·Mt·I, depth tested, not written)
//!               → teaching overlays → present (output transform, upscale)
//! ```
//!
//! Later techniques slot in where DESIGN.md puts them: environment captures and mirror views
//! (more views, drawn by the same scene pass) before `opaque`; the sky after it.

pub mod environment;
pub mod geometry;
pub mod mirror;
pub mod overlays;
pub mod present;
pub mod scene_gpu;
pub mod scene_pass;
pub mod shadow;
pub mod transparency;
pub mod uniforms;
pub mod view;
pub mod volume;

use std::collections::HashMap;
use std::time::{Duration, Instant};

use glam::Vec3;

use crate::gpu::mipmap::MipmapGenerator;
use crate::gpu::texture::GpuTexture;
use crate::gpu::{Gpu, readback};
use crate::output::OutputTransform;
use crate::scene::Scene;
use crate::settings::{EnvironmentView, MirrorView, Prepass, RenderSettings, ShadowMethod, TransparencySettings};
use crate::volume::WIREFRAME_CELLS;
use environment::{EnvironmentMaps, EnvironmentPass, capture_key, capture_range, cube_face_view, object_centre};
use mirror::pass::{children, plan, volumes};
use overlays::{FRUSTUM_COLOUR, Overlays, WIREFRAME_COLOUR};
use present::{PresentInput, PresentPass};
use scene_gpu::{SceneGpu, SceneLayouts};
use scene_pass::{FrameKey, MirrorImages, SHADOWS_OFF, ScenePass, SceneTargets};
use shadow::projected::{MASK_FORMAT, ProjectedPass};
use shadow::views::{ShadowLayout, shadow_layout_in};
use shadow::{ShadowMaps, ShadowPass};
use transparency::{TransparencyPass, TransparencyReport};
use view::{View, ViewSlot};

/// Linear radiance, before the output transform.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The format of offscreen screenshots.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The passes, built once per device and output format.
pub struct Renderer {
    pub layouts: SceneLayouts,
    pub mipmaps: MipmapGenerator,
    shadow: ShadowPass,
    projected: ProjectedPass,
    scene: ScenePass,
    transparency: TransparencyPass,
    volumes: volume::VolumePass,
    overlays: Overlays,
    present: PresentPass,
    environment: EnvironmentPass,
    /// The target of the dynamic environment cubes' views, one face at a time.
    capture_targets: Option<FrameTargets>,
    /// The targets of the mirrored views (`mirror::pass`), one per view of the largest frame so
    /// far.
    mirror_targets: Vec<MirrorTarget>,
    /// The lighting inputs (group 2), and the (shadow maps, frame targets, environment maps)
    /// generations they were made for.
    lighting: Option<((u64, u64, u64), wgpu::BindGroup)>,
    /// Submit and time each pass on its own (`render --stats`): slower, but it says where the
    /// frame's time goes.
    pub profile: bool,
}

/// The intermediate images of a frame, recreated when the output size or the render scale
/// changes.
pub struct FrameTargets {
    pub size: (u32, u32),
    pub hdr: GpuTexture,
    pub depth: GpuTexture,
    /// Object-precision shadows: one channel per shadowed light.
    pub shadow_mask: GpuTexture,
    present_input: PresentInput,
    generation: u64,
    /// Draw only inside `[x, y, width, height]` (a mirrored view's window); `None`: everywhere.
    pub scissor: Option<[u32; 4]>,
}

/// What a frame did, for `--stats`, the viewer's corner and the tests of the caches.
#[derive(Clone, Debug, Default)]
pub struct FrameReport {
    /// Wall time of each pass, submitted and waited for on its own; empty unless
    /// [`Renderer::profile`] is set.
    pub passes: Vec<(&'static str, Duration)>,
    /// Shadow-map layers drawn this frame (the others were kept).
    pub shadow_layers_drawn: u32,
    /// The projected shadow polygons were computed anew.
    pub projected_recomputed: bool,
    /// Triangles drawn per view.
    pub triangles: u64,
    /// The size the frame was drawn at, before the present pass upscaled it.
    pub drawn_size: (u32, u32),
    /// What the transparency pass drew, and its CPU sort.
    pub transparency: TransparencyReport,
    /// Mirrored cameras drawn (planar mirrors and their reflections in each other).
    pub mirror_views: u32,
    /// Faces of dynamic environment cubes drawn this frame (six per reflective object when they
    /// were due, else none).
    pub environment_faces: u32,
    /// The sphere map was made this frame.
    pub sphere_map_made: bool,
}

/// The frame's command encoder. When profiling, each pass is submitted and waited for on its
/// own, and its wall time recorded; otherwise the whole frame is one submission.
struct FrameEncoder<'g> {
    gpu: &'g Gpu,
    encoder: wgpu::CommandEncoder,
    profile: bool,
    mark: Instant,
    passes: Vec<(&'static str, Duration)>,
}

impl<'g> FrameEncoder<'g> {
    fn new(gpu: &'g Gpu, profile: bool) -> FrameEncoder<'g> {
        FrameEncoder { gpu, encoder: Self::encoder(gpu), profile, mark: Instant::now(), passes: Vec::new() }
    }

    fn encoder(gpu: &Gpu) -> wgpu::CommandEncoder {
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame::encoder") })
    }

    /// Ends the pass called `name`.
    fn end(&mut self, name: &'static str) {
        if self.profile {
            let encoder = std::mem::replace(&mut self.encoder, Self::encoder(self.gpu));
            self.gpu.queue.submit([encoder.finish()]);
            self.gpu.wait();
            self.passes.push((name, self.mark.elapsed()));
            self.mark = Instant::now();
        }
    }

    fn finish(self) -> Vec<(&'static str, Duration)> {
        self.gpu.queue.submit([self.encoder.finish()]);
        self.passes
    }
}

/// The size a frame is drawn at: the output's times the render scale, at least one pixel.
pub fn drawn_size(output: (u32, u32), render_scale: f32) -> (u32, u32) {
    let scaled = |n: u32| ((n as f32 * render_scale).round() as u32).clamp(1, n.max(1));
    (scaled(output.0), scaled(output.1))
}

impl Renderer {
    pub fn new(device: &wgpu::Device, output_format: wgpu::TextureFormat) -> Renderer {
        let layouts = SceneLayouts::new(device);
        Renderer {
            mipmaps: MipmapGenerator::new(device),
            shadow: ShadowPass::new(device, &layouts),
            projected: ProjectedPass::new(device, &layouts),
            scene: ScenePass::new(device, &layouts),
            transparency: TransparencyPass::new(device, &layouts),
            volumes: volume::VolumePass::new(device, &layouts),
            overlays: Overlays::new(device, &layouts),
            present: PresentPass::new(device, output_format),
            environment: EnvironmentPass::new(device),
            capture_targets: None,
            mirror_targets: Vec::new(),
            layouts,
            lighting: None,
            profile: false,
        }
    }

    pub fn upload(&self, gpu: &Gpu, scene: &Scene) -> SceneGpu {
        SceneGpu::upload(gpu, &self.layouts, &self.mipmaps, scene)
    }

    /// Targets for a frame drawn at `size` (the output's size times the render scale).
    pub fn targets(&self, device: &wgpu::Device, size: (u32, u32)) -> FrameTargets {
        static GENERATION: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let hdr = GpuTexture::target(device, "frame::hdr", size, HDR_FORMAT);
        let depth = GpuTexture::target(device, "frame::depth", size, DEPTH_FORMAT);
        let shadow_mask = GpuTexture::target(device, "frame::shadow_mask", size, MASK_FORMAT);
        let present_input = self.present.bind(device, &hdr.view);
        let generation = GENERATION.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        FrameTargets { size, hdr, depth, shadow_mask, present_input, generation, scissor: None }
    }

    /// The number of scene-pass shader variants compiled so far.
    pub fn shader_variants(&self) -> usize {
        self.scene.variant_count()
    }

    /// Forgets the kept shadow maps, so the next frame draws them all.
    pub fn invalidate_shadows(&mut self) {
        self.shadow.invalidate();
    }

    /// Makes the environment maps `settings` ask for, writes their uniform and decides whether
    /// the dynamic cubes are drawn this frame. Returns (cubes due, sphere map made).
    fn prepare_environment(
        &mut self,
        gpu: &Gpu,
        scene: &Scene,
        scene_gpu: &mut SceneGpu,
        settings: &RenderSettings,
    ) -> (bool, bool) {
        let env = &settings.environment;
        if scene_gpu.environment.as_ref().is_none_or(|maps| maps.cube_size != env.cube_size) {
            scene_gpu.environment = Some(EnvironmentMaps::new(
                &gpu.device,
                &gpu.queue,
                &self.environment,
                &self.mipmaps,
                scene,
                env.cube_size,
                scene_gpu.env_objects.len(),
            ));
        }
        let maps = scene_gpu.environment.as_mut().expect("made just above");
        let rotation = environment::view_rotation(&scene.camera);
        let sphere_made = maps.prepare(&gpu.device, &gpu.queue, &self.environment, &self.mipmaps, settings, rotation);
        let drawn = env.enabled && env.dynamic && env.map == crate::settings::EnvironmentMap::Cube;
        let cubes_due = (drawn || env.view == EnvironmentView::Cross)
            && !scene_gpu.env_objects.is_empty()
            && maps.capture_due(capture_key(scene, settings), env.refresh);
        (cubes_due, sphere_made)
    }

    /// Records and submits one frame of `scene` into `output`. `targets` are remade when the
    /// output's size times the render scale no longer matches them.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &Scene,
        scene_gpu: &mut SceneGpu,
        settings: &RenderSettings,
        targets: &mut FrameTargets,
        output: &wgpu::TextureView,
    ) -> FrameReport {
        let (device, queue) = (&gpu.device, &gpu.queue);
        let out = output.texture().size();
        let size = drawn_size((out.width, out.height), settings.raster.render_scale);
        if targets.size != size {
            *targets = self.targets(device, size);
        }

        // Per-scene work, redone only when what it depends on changes.
        scene_gpu.prepare_materials(device, &self.layouts, &settings.textures);
        scene_gpu.geometry.prepare(
            device,
            queue,
            scene,
            &scene.camera,
            settings.sphere_segments,
            settings.raster.adaptive_tessellation,
        );
        let shadows = &settings.shadows;
        let layout = shadow_layout_in(scene, scene_gpu.geometry.bounds, shadows);
        let main_view = View::of_camera(&scene.camera);
        scene_gpu.views.write(queue, ViewSlot::Main, &main_view);
        scene_gpu.update_frame(queue, scene, &layout.first_layer, settings);
        let (cubes_due, sphere_map_made) = self.prepare_environment(gpu, scene, scene_gpu, settings);
        let scene_gpu = &*scene_gpu;
        let world = scene.environment.is_some();

        let projected = shadows.enabled && shadows.method == ShadowMethod::Projected;
        let prepass = projected
            || match settings.raster.depth_prepass {
                Prepass::Always => true,
                Prepass::Never => false,
                Prepass::Auto => scene_gpu.geometry.triangles() * 4 < u64::from(size.0) * u64::from(size.1),
            };
        let transmission = shadows.transmission && scene_gpu.geometry.has_transparent();
        let frame_key = FrameKey::new(settings, !layout.views.is_empty(), transmission);
        // Transparent surfaces are drawn after the opaque ones, or as opaque ones when the
        // technique is off.
        let sorted_transparency = settings.transparency.enabled && scene_gpu.geometry.has_transparent();
        // Planar mirrors: the tree of mirrored cameras, each with its slot and targets.
        let mirrors = &settings.mirrors;
        let (nodes, truncated) =
            if mirrors.enabled { plan(&main_view, &scene_gpu.mirrors, mirrors.depth) } else { (Vec::new(), false) };
        if truncated {
            log::debug!("more than {} mirrored views: the deepest are left out", view::MAX_MIRROR_VIEWS);
        }
        if self.mirror_targets.first().is_some_and(|t| t.targets.size != size) {
            self.mirror_targets.clear();
        }
        while self.mirror_targets.len() < nodes.len() {
            let targets = self.targets(device, size);
            let image = self.scene.mirror_image_group(device, &targets.hdr.view);
            self.mirror_targets.push(MirrorTarget { targets, image });
        }
        for (k, node) in nodes.iter().enumerate() {
            scene_gpu.views.write(queue, ViewSlot::Mirror(k as u32), &node.view);
            self.mirror_targets[k].targets.scissor = Some(mirror::pass::scissor(node.window, size));
        }
        // Object-precision shadows are a mask of the main view's pixels: mirrored views and cube
        // faces go without.
        let mirror_key = if projected { FrameKey { shadow_method: SHADOWS_OFF, ..frame_key } } else { frame_key };
        self.scene.prepare(device, frame_key, scene_gpu, prepass, !nodes.is_empty());
        if !nodes.is_empty() || cubes_due {
            self.scene.prepare(device, mirror_key, scene_gpu, false, !nodes.is_empty());
        }
        let cube_size = settings.environment.cube_size;
        if cubes_due && self.capture_targets.as_ref().is_none_or(|t| t.size != (cube_size, cube_size)) {
            self.capture_targets = Some(self.targets(device, (cube_size, cube_size)));
        }

        // Object precision draws no maps: its light views have no layers to fill.
        let no_maps = ShadowLayout::default();
        let map_layout = if projected { &no_maps } else { &layout };
        let mut frame = FrameEncoder::new(gpu, self.profile);
        let maps = self.shadow.record(device, queue, &mut frame.encoder, scene_gpu, map_layout, shadows);
        let shadow_layers_drawn = maps.layers_drawn;
        frame.end("shadow maps");
        let env_maps = scene_gpu.environment.as_ref().expect("prepare_environment made them");
        let lighting = lighting_group(
            &mut self.lighting,
            device,
            &self.layouts,
            &maps,
            targets,
            env_maps,
            &self.environment.sampler,
        );
        // Every view other than the main camera's draws the opaque surfaces (no prepass) and the
        // transparent ones into its own targets.
        let views = SecondaryViews {
            device,
            queue,
            scene,
            scene_gpu,
            lighting,
            frame: mirror_key,
            transparency: sorted_transparency.then_some(&settings.transparency),
            world,
        };
        // Dynamic environment cubes: six views from each reflective object's centre, the object
        // itself left out, each copied into its layer; then their mip chains.
        let mut environment_faces = 0;
        if cubes_due {
            let capture = self.capture_targets.as_ref().expect("made above when cubes are due");
            for (k, &object) in scene_gpu.env_objects.iter().enumerate() {
                let (centre, inner) = object_centre(scene, object);
                let (near, far) = capture_range(inner, scene_gpu.geometry.bounds);
                let images = MirrorImages { images: HashMap::new(), skip: Some(object) };
                for face in 0..6 {
                    let layer = (6 * k + face) as u32;
                    let slot = ViewSlot::Cube(layer);
                    let view = cube_face_view(centre, face, near, far);
                    scene_gpu.views.write(queue, slot, &view);
                    views.record(
                        &mut frame.encoder,
                        (&self.scene, &mut self.transparency),
                        (slot, &view),
                        capture,
                        &images,
                        Some(object),
                    );
                    env_maps.store_capture(&mut frame.encoder, &capture.hdr.texture, layer);
                    environment_faces += 1;
                }
            }
            self.mipmaps.record(device, &mut frame.encoder, &env_maps.dynamic.texture);
            frame.end("environment cubes");
        }
        // Deepest first: every view's mirrors find their images drawn.
        let images_of = children(&nodes);
        for (k, node) in nodes.iter().enumerate().rev() {
            let mut images = mirror_images(scene_gpu, &self.mirror_targets, images_of.get(&Some(k)));
            images.skip = Some(scene_gpu.mirrors[node.mirror].object);
            let slot = ViewSlot::Mirror(k as u32);
            let node_targets = &self.mirror_targets[k].targets;
            views.record(
                &mut frame.encoder,
                (&self.scene, &mut self.transparency),
                (slot, &node.view),
                node_targets,
                &images,
                None,
            );
        }
        if !nodes.is_empty() {
            frame.end("mirror views");
        }
        if prepass {
            self.scene.record_prepass(
                &mut frame.encoder,
                scene_gpu,
                lighting,
                ViewSlot::Main,
                &targets.depth.view,
                sorted_transparency,
            );
            frame.end("depth prepass");
        }
        let mut projected_recomputed = false;
        if projected {
            projected_recomputed =
                self.projected.record(device, &mut frame.encoder, scene, scene_gpu, &layout, targets);
            frame.end("projected shadows");
        }
        let scene_targets = SceneTargets {
            hdr: &targets.hdr.view,
            depth: &targets.depth.view,
            background: scene.background,
            world,
            scissor: None,
        };
        self.scene.record_opaque(
            &mut frame.encoder,
            scene_gpu,
            lighting,
            ViewSlot::Main,
            frame_key,
            &scene_targets,
            prepass,
            sorted_transparency,
            &mirror_images(scene_gpu, &self.mirror_targets, images_of.get(&None)),
        );
        frame.end("opaque");
        if settings.volume.enabled && !scene.volumes.is_empty() {
            self.volumes.record(
                device,
                queue,
                &mut frame.encoder,
                &self.scene,
                scene,
                scene_gpu,
                lighting,
                frame_key,
                targets,
                &settings.volume,
            );
            frame.end("volumes");
            if settings.volume.wireframe {
                let lines: Vec<[Vec3; 2]> =
                    scene.volumes.iter().flat_map(|v| v.wireframe_lines(WIREFRAME_CELLS)).collect();
                let lines = lines.as_flattened();
                self.overlays.record_lines(device, &mut frame.encoder, scene_gpu, lines, WIREFRAME_COLOUR, targets);
                frame.end("volume wireframe");
            }
        }
        let mut transparency = TransparencyReport::default();
        if sorted_transparency {
            transparency = self.transparency.record(
                device,
                queue,
                &mut frame.encoder,
                &self.scene,
                scene,
                scene_gpu,
                lighting,
                frame_key,
                (ViewSlot::Main, &main_view),
                targets,
                &settings.transparency,
                None,
            );
            frame.end("transparency");
        }
        self.overlays.record(device, queue, &mut frame.encoder, shadows, scene_gpu, map_layout, &maps, targets);
        if mirrors.view == MirrorView::Camera && !nodes.is_empty() {
            let edges = overlays::box_edges(&volumes(&nodes));
            self.overlays.record_lines(device, &mut frame.encoder, scene_gpu, &edges, FRUSTUM_COLOUR, targets);
        }
        // The environment's teaching views, over the frame.
        let env_view = settings.environment.view;
        if env_view != EnvironmentView::Off {
            let env = &settings.environment;
            let size = (targets.hdr.texture.width(), targets.hdr.texture.height());
            env_maps.record_view(
                &mut frame.encoder,
                &self.environment,
                env_view,
                env.dynamic,
                env.inset,
                &targets.hdr.view,
                size,
            );
        }
        // The first mirror camera's own image, in place of the frame.
        let shown = match nodes.first() {
            Some(_) if mirrors.view == MirrorView::Image => &self.mirror_targets[0].targets.present_input,
            _ => &targets.present_input,
        };
        self.present.record(queue, &mut frame.encoder, shown, output, OutputTransform::of(settings));
        frame.end("overlays + present");
        FrameReport {
            passes: frame.finish(),
            shadow_layers_drawn,
            projected_recomputed,
            triangles: scene_gpu.geometry.triangles(),
            drawn_size: size,
            transparency,
            mirror_views: nodes.len() as u32,
            environment_faces,
            sphere_map_made,
        }
    }
}

/// What every view of a frame other than the main camera's (mirrored cameras, cube faces) is
/// drawn with.
struct SecondaryViews<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    scene: &'a Scene,
    scene_gpu: &'a SceneGpu,
    lighting: &'a wgpu::BindGroup,
    frame: FrameKey,
    /// How transparent surfaces are sorted; `None`: they are drawn as opaque ones.
    transparency: Option<&'a TransparencySettings>,
    /// Draw the world's environment where nothing is.
    world: bool,
}

impl SecondaryViews<'_> {
    /// Draws the scene from `view` (in `slot`) into `targets`: opaque surfaces with the
    /// reflections in `images` (no prepass), then the transparent ones, `skip` left out of them.
    fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (scene_pass, transparency): (&ScenePass, &mut TransparencyPass),
        (slot, view): (ViewSlot, &View),
        targets: &FrameTargets,
        images: &MirrorImages,
        skip: Option<usize>,
    ) {
        let scene_targets = SceneTargets {
            hdr: &targets.hdr.view,
            depth: &targets.depth.view,
            background: self.scene.background,
            world: self.world,
            scissor: targets.scissor,
        };
        let sorted = self.transparency.is_some();
        let (scene_gpu, lighting) = (self.scene_gpu, self.lighting);
        scene_pass.record_opaque(encoder, scene_gpu, lighting, slot, self.frame, &scene_targets, false, sorted, images);
        if let Some(settings) = self.transparency {
            let scene = self.scene;
            transparency.record(
                self.device,
                self.queue,
                encoder,
                scene_pass,
                scene,
                scene_gpu,
                lighting,
                self.frame,
                (slot, view),
                targets,
                settings,
                skip,
            );
        }
    }
}

/// One mirrored view's targets, and the group 3 through which its mirror reads its image (made
/// once with the targets).
struct MirrorTarget {
    targets: FrameTargets,
    image: wgpu::BindGroup,
}

/// The reflections the mirrors of one view show: for each `(mirror, node)` child of the view,
/// the group 3 reading that node's image.
fn mirror_images(
    scene_gpu: &SceneGpu,
    mirror_targets: &[MirrorTarget],
    children: Option<&Vec<(usize, usize)>>,
) -> MirrorImages {
    let mut images: HashMap<usize, Vec<_>> = HashMap::new();
    for &(mirror, node) in children.into_iter().flatten() {
        let mirror = &scene_gpu.mirrors[mirror];
        images.entry(mirror.object).or_default().push((mirror.indices.clone(), mirror_targets[node].image.clone()));
    }
    MirrorImages { images, skip: None }
}

/// Group 2 of the scene pass, built from the shadow pass's outputs and the frame's projected
/// shadow mask; remade only when either is recreated.
fn lighting_group<'c>(
    cache: &'c mut Option<((u64, u64, u64), wgpu::BindGroup)>,
    device: &wgpu::Device,
    layouts: &SceneLayouts,
    maps: &ShadowMaps,
    targets: &FrameTargets,
    environment: &EnvironmentMaps,
    env_sampler: &wgpu::Sampler,
) -> &'c wgpu::BindGroup {
    let key = (maps.generation, targets.generation, environment.generation);
    if cache.as_ref().is_none_or(|(k, _)| *k != key) {
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("frame::lighting_group"),
            layout: &layouts.lighting,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: maps.uniform.binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(maps.depth) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(maps.sampler) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(maps.transmission) },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(&targets.shadow_mask.view),
                },
                wgpu::BindGroupEntry { binding: 5, resource: environment.params.binding() },
                wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::Sampler(env_sampler) },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: wgpu::BindingResource::TextureView(&environment.cube.view),
                },
                wgpu::BindGroupEntry {
                    binding: 8,
                    resource: wgpu::BindingResource::TextureView(&environment.dynamic.view),
                },
                wgpu::BindGroupEntry {
                    binding: 9,
                    resource: wgpu::BindingResource::TextureView(&environment.sphere.view),
                },
                wgpu::BindGroupEntry {
                    binding: 10,
                    resource: wgpu::BindingResource::TextureView(&environment.latlong.view),
                },
            ],
        });
        *cache = Some((key, group));
    }
    &cache.as_ref().expect("made just above").1
}

/// A headless frame: renders `scene` at its camera's size and reads it back as sRGB RGBA8.
/// The same passes the viewer runs, drawn into an offscreen texture.
pub struct Headless {
    pub renderer: Renderer,
    pub scene_gpu: SceneGpu,
    pub targets: FrameTargets,
    pub output: GpuTexture,
    /// What the last frame did.
    pub report: FrameReport,
}

impl Headless {
    pub fn new(gpu: &Gpu, scene: &Scene) -> Headless {
        let renderer = Renderer::new(&gpu.device, OUTPUT_FORMAT);
        let scene_gpu = renderer.upload(gpu, scene);
        let size = (scene.camera.width, scene.camera.height);
        let targets = renderer.targets(&gpu.device, drawn_size(size, scene.settings.raster.render_scale));
        let output = GpuTexture::target(&gpu.device, "frame::output", size, OUTPUT_FORMAT);
        Headless { renderer, scene_gpu, targets, output, report: FrameReport::default() }
    }

    pub fn render(&mut self, gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
        self.report =
            self.renderer.render(gpu, scene, &mut self.scene_gpu, settings, &mut self.targets, &self.output.view);
        let size = self.output.texture.size();
        let (width, height) = (size.width, size.height);
        let pixels =
            readback::read_rgba8(&gpu.device, &gpu.queue, &self.output.texture).expect("reading the frame back");
        image::RgbaImage::from_raw(width, height, pixels).expect("readback returns width × height RGBA8 pixels")
    }
}

/// Renders `scene` once, headless, with `settings`.
pub fn render_image(gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    Headless::new(gpu, scene).render(gpu, scene, settings)
}
