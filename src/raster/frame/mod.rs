//! The frame: [`Renderer::render`] plans what to draw ([`plan`]), fills the shadow maps, then
//! draws every view with the same phases ([`record_view`]): the cube faces due, the mirrored
//! cameras deepest first, the main camera; then the teaching overlays and the output transform.
//!
//! ```text
//! plan ──► shadow maps (pass 1 of §4; layers kept while their light and the casters stay)
//!      ──► every view's group (group 2: maps, environment maps, the view's own images)
//!      ──► per view: [depth prepass → projected polygons into the view's mask]
//!                    → opaque + mirrors + world
//!                    → isosurfaces → refracting glass
//!                    → transparent surfaces and composited volumes, in order
//!          cube faces (copied into their cube) · mirrored cameras, deepest first · main camera
//!      ──► teaching overlays ──► present (output transform, upscale)
//! ```
//!
//! A technique draws in every view by being one of the phases of [`record_view`]; what it keeps
//! per scene and per target lives in its pass.

pub mod plan;

use glam::Vec3;

use super::context::{Figure, FrameContext, FrameEncoder, FrameReport};
use super::environment::pass::EnvironmentPass;
use super::inspect::{Inspector, RasterPixel, RecordKind};
use super::mirror::MirrorPlane;
use super::mirror::pass::{MirrorNode, MirrorPass, volumes as mirror_volumes};
use super::overlays::{FRUSTUM_COLOUR, Overlays, TESSELLATION_COLOUR, WIREFRAME_COLOUR, box_edges, mesh_edges};
use super::present::PresentPass;
use super::refraction::{PreparedRefraction, RefractionPass};
use super::scene_gpu::{DrawnAlone, SceneGpu, SceneLayouts, SurfaceLayout};
use super::scene_pass::{MirrorImages, PreparedScene, ScenePass};
use super::shadow::projected::ProjectedPass;
use super::shadow::views::ShadowLayout;
use super::shadow::{ShadowMaps, ShadowPass};
use super::targets::{FrameTargets, ViewImage, drawn_size};
use super::tessellation::pass::TessellationPass;
use super::traced::{self, KeptTraced, PreparedTraced, TracedAt};
use super::transparency::{PreparedTransparency, TransparencyPass};
use super::view::{ViewKind, ViewTargets};
use super::view_group::{FrameInputs, ViewGroups};
use super::volume::{PreparedVolumes, RaySpan, VolumePass, VolumeSet};
use crate::gpu::Gpu;
use crate::gpu::mipmap::MipmapGenerator;
use crate::output::OutputTransform;
use crate::scene::Scene;
use crate::settings::{BumpView, MirrorView, RenderSettings};
use crate::shaders::{Profile, Wgsl};
use crate::volume::WIREFRAME_CELLS;
use plan::{FramePlan, plan};

/// What the inspected frame decided before it drew, as its passes used it: the explainer reads
/// these instead of deciding them again, so what it says is about the frame that was drawn.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameFacts {
    /// Every shadowed light's views, as the shadow uniform described them (the shadow maps'
    /// layers, or the channels of the projected mask).
    pub lights: ShadowLayout,
    /// The planar mirrors the main view drew with a mirrored camera: each one's object and the
    /// plane its camera was reflected about.
    pub mirrors: Vec<(usize, MirrorPlane)>,
    /// The dynamic environment cubes: each one's object and the point its faces were drawn from.
    pub cubes: Vec<(usize, Vec3)>,
    /// The box around the drawn geometry (the shadow fit's and the parallax proxies' bounds).
    pub bounds: Option<(Vec3, Vec3)>,
    /// Transparent surfaces were blended by a lab's blend by hand (`BLEND_BY_HAND`): what each
    /// lets through is its record's `blend_factor`, not the material's.
    pub blend_by_hand: bool,
}

/// The passes, built once per device and output format, and the scene they draw.
pub struct Renderer {
    pub layouts: SceneLayouts,
    pub mipmaps: MipmapGenerator,
    surface: SurfaceLayout,
    scene_gpu: SceneGpu,
    shadow: ShadowPass,
    projected: ProjectedPass,
    scene: ScenePass,
    refraction: RefractionPass,
    transparency: TransparencyPass,
    volumes: VolumePass,
    mirrors: MirrorPass,
    environment: EnvironmentPass,
    overlays: Overlays,
    present: PresentPass,
    /// Displacement tessellated on the GPU, adaptively; `None` where the device has no compute
    /// shaders (WebGL2), which draws the uniform mesh.
    tessellation: Option<TessellationPass>,
    /// Every view's group 2 (what its shading reads), kept while the images it reads are the
    /// same ones.
    view_groups: ViewGroups,
    /// Where an inspecting renderer records what its shaders computed at one pixel.
    inspector: Option<Inspector>,
    /// Inspect the pixel as the mirrored camera of a planar mirror saw it rather than as the
    /// main camera does: the mirror's object and a point of the mirror at the pixel (which face,
    /// for a box of mirrors). See [`Self::inspect_through`].
    through: Option<(usize, Vec3)>,
    /// The mirrored camera the last inspected frame was inspected through (its node), if any.
    inspected_through: Option<usize>,
    /// What the last inspected frame decided before it drew.
    facts: FrameFacts,
    /// Submit and time each pass on its own (`render --stats`): slower, but it says where the
    /// frame's time goes.
    pub profile: bool,
    /// The hybrid's traced terms are traced at one pixel in each block of this many pixels on a
    /// side, the block given its terms: the viewer's coarse frames, refined while the camera
    /// rests (1, the default: every pixel).
    pub traced_stride: u32,
    /// Where they are traced: here (the default), or elsewhere, by whoever takes the views asked
    /// for from [`Self::traced`] and hands their terms back (the page's Web Workers).
    pub traced_at: TracedAt,
    /// The last frame's traced terms, kept while nothing they depend on changes; the views asked
    /// for elsewhere.
    pub traced: KeptTraced,
}

/// The phases every view draws, prepared for one frame.
struct Phases<'p> {
    scene: PreparedScene<'p>,
    projected: &'p ProjectedPass,
    volumes: PreparedVolumes<'p>,
    /// `None`: no glass is refracted.
    refraction: Option<PreparedRefraction<'p>>,
    /// `None`: transparent surfaces are drawn with the opaque ones (or there are none).
    transparency: Option<PreparedTransparency<'p>>,
    /// The hybrid's traced terms of every view; `None`: none is traced.
    traced: Option<PreparedTraced>,
}

impl Renderer {
    /// The passes, with `scene` loaded.
    pub fn new(gpu: &Gpu, scene: &Scene, output_format: wgpu::TextureFormat) -> Renderer {
        Renderer::build(gpu, scene, output_format, Wgsl::builtin(), false)
    }

    /// The passes, with `scene` loaded, their surface modules compiled from `wgsl` (a lab's
    /// student functions in place of Mirador's: src/lab). `inspect` as [`Self::inspecting`].
    pub fn with_wgsl(
        gpu: &Gpu,
        scene: &Scene,
        output_format: wgpu::TextureFormat,
        wgsl: Wgsl,
        inspect: bool,
    ) -> Renderer {
        Renderer::build(gpu, scene, output_format, wgsl, inspect)
    }

    /// A renderer that can inspect a pixel ([`Self::inspect`]): its view groups carry the
    /// inspection buffer, which needs storage buffers written by fragment shaders (every Vulkan
    /// device; not WebGL).
    pub fn inspecting(gpu: &Gpu, scene: &Scene, output_format: wgpu::TextureFormat) -> Renderer {
        Renderer::build(gpu, scene, output_format, Wgsl::builtin(), true)
    }

    fn build(gpu: &Gpu, scene: &Scene, output_format: wgpu::TextureFormat, wgsl: Wgsl, inspect: bool) -> Renderer {
        let device = &gpu.device;
        let layouts = SceneLayouts::new(device, inspect);
        let surface = SurfaceLayout::new(device, &layouts, wgsl);
        let mipmaps = MipmapGenerator::new(device);
        let mut mirrors = MirrorPass::default();
        let mut environment = EnvironmentPass::new(device);
        let mut volumes = VolumePass::new(device, &layouts, &surface);
        let scene_gpu = load(gpu, scene, (&layouts, &mipmaps), (&mut mirrors, &mut environment, &mut volumes));
        Renderer {
            shadow: ShadowPass::new(device, &layouts),
            projected: ProjectedPass::new(device, &layouts),
            scene: ScenePass::new(device, &layouts, &surface),
            refraction: RefractionPass::new(device, &layouts, &surface),
            transparency: TransparencyPass::new(device, &layouts, &surface),
            overlays: Overlays::new(device, &layouts),
            present: PresentPass::new(device, output_format),
            tessellation: (gpu.profile() == Profile::Standard).then(|| {
                let mut pass = TessellationPass::default();
                pass.load(gpu, scene);
                pass
            }),
            scene_gpu,
            volumes,
            mirrors,
            environment,
            mipmaps,
            surface,
            layouts,
            view_groups: ViewGroups::default(),
            inspector: inspect.then(|| Inspector::new(device)),
            through: None,
            inspected_through: None,
            facts: FrameFacts::default(),
            profile: false,
            traced_stride: 1,
            traced_at: TracedAt::Here,
            traced: KeptTraced::default(),
        }
    }

    /// Inspects `pixel` (of the drawn image) in the next frames, or nothing. Only a renderer made
    /// by [`Self::inspecting`] can.
    pub fn inspect(&mut self, pixel: Option<(u32, u32)>) {
        if let Some(inspector) = &mut self.inspector {
            inspector.pixel = pixel;
        }
    }

    /// Inspects the next frames' pixel through a planar mirror: the mirrored camera of the mirror
    /// of `object` whose plane holds `point` (one level deep) records what it saw at that pixel
    /// (its image is pixel-aligned with the view's), and the main view records nothing. `None`:
    /// the main view, as usual.
    pub fn inspect_through(&mut self, mirror: Option<(usize, Vec3)>) {
        self.through = mirror;
    }

    /// Whether the last inspected frame was inspected through a mirror: `false` also when
    /// [`Self::inspect_through`] named a mirror that drew no camera (then nothing was recorded).
    pub fn inspected_through(&self) -> bool {
        self.inspected_through.is_some()
    }

    /// What the last frame computed at the inspected pixel, read back from the GPU; `targets` are
    /// the frame's. Through a mirror, the pixel of its mirrored camera's image.
    pub fn inspection(&self, gpu: &Gpu, targets: &FrameTargets) -> Option<RasterPixel> {
        let image = match self.inspected_through {
            Some(node) => &self.mirrors.targets(node).hdr.texture,
            None => &targets.hdr.texture,
        };
        self.inspector.as_ref()?.read(gpu, image)
    }

    /// What the last inspected frame decided before it drew: what the explainer reads instead of
    /// deciding it again.
    pub fn facts(&self) -> &FrameFacts {
        &self.facts
    }

    /// Loads `scene` in place of the last one: uploads it, and every pass forgets what it kept of
    /// the last (a kept shadow map or sorted list is named by the draw list it was made from).
    pub fn load(&mut self, gpu: &Gpu, scene: &Scene) {
        let passes = (&mut self.mirrors, &mut self.environment, &mut self.volumes);
        self.scene_gpu = load(gpu, scene, (&self.layouts, &self.mipmaps), passes);
        if let Some(tessellation) = &mut self.tessellation {
            tessellation.load(gpu, scene);
        }
        self.traced.forget();
    }

    /// What the last frame's adaptive displacement made (`None` where nothing was tessellated
    /// on the GPU).
    pub fn tessellation_report(&self) -> Option<&super::tessellation::pass::TessellationReport> {
        self.tessellation.as_ref()?.report.as_ref()
    }

    /// The scene as uploaded.
    pub fn scene_gpu(&self) -> &SceneGpu {
        &self.scene_gpu
    }

    /// The number of scene-pass shader variants compiled so far.
    pub fn shader_variants(&self) -> usize {
        self.scene.variant_count()
    }

    /// Forgets the kept shadow maps, so the next frame draws them all.
    pub fn invalidate_shadows(&mut self) {
        self.shadow.invalidate();
    }

    /// Records and submits one frame of `scene` (the one loaded, whose camera may have moved)
    /// into `output`. `targets` are remade when the output's size times the render scale no
    /// longer matches them.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &Scene,
        settings: &RenderSettings,
        targets: &mut FrameTargets,
        output: &wgpu::TextureView,
    ) -> FrameReport {
        // Where the hybrid traces a term, the passes draw without what it replaces.
        // What each traced term replaces left out (each row of the approximations table says what).
        let raster_settings = settings.hybrid.raster_settings(settings);
        let settings = raster_settings.as_ref().unwrap_or(settings);
        let wanted = traced::wanted(settings);
        let out = output.texture().size();
        let size = drawn_size((out.width, out.height), settings.raster.render_scale);
        if targets.size != size {
            *targets = FrameTargets::new(&gpu.device, size);
        }
        if wanted.is_some() {
            targets.images.ensure(&gpu.device, ViewImage::Traced, size);
        }
        let targets = &*targets;
        let mut frame = FrameEncoder::new(gpu, self.profile);
        let mut plan = self.plan(gpu, scene, settings, size, &mut frame);
        self.begin_inspection(gpu, &mut plan);
        if wanted.is_some() {
            self.mirrors.ensure_images(&gpu.device, ViewImage::Traced);
            self.environment.ensure_images(&gpu.device, ViewImage::Traced);
        }
        let layers = (&plan.maps, plan.first_shadow_slot);
        self.shadow.record(gpu, &mut frame, &self.scene_gpu, layers, &settings.shadows);
        let maps = self.shadow.maps();
        let (mirrors, environment) = (&self.mirrors, &self.environment);
        let views: Vec<ViewTargets<'_>> = plan
            .views()
            .map(|view| match view.kind {
                ViewKind::Main => (view, targets),
                ViewKind::Mirror(k) => (view, mirrors.targets(k)),
                ViewKind::CubeFace { .. } => (view, environment.capture_targets()),
            })
            .collect();
        let traced = wanted.map(|terms| {
            let inputs = (&gpu.device, scene, settings);
            self.traced.prepare(inputs, &mut frame, (terms, self.traced_stride, self.traced_at), &plan.lights, &views)
        });
        if traced.is_none() {
            self.traced.release();
        }
        let inspection = self.inspector.as_ref().map(|i| &i.buffer);
        let inputs = frame_inputs(&maps, environment, inspection);
        self.view_groups.prepare(&gpu.device, &self.layouts.view, &inputs, &views);
        let ctx = FrameContext {
            gpu,
            scene,
            scene_gpu: &self.scene_gpu,
            settings,
            surface: &self.surface,
            view_groups: &self.view_groups,
        };
        let phases = Phases {
            scene: self.scene.prepare(&ctx, &views, !plan.mirror_nodes.is_empty()),
            projected: &self.projected,
            volumes: self.volumes.prepare(&ctx, &views),
            refraction: plan.transparency.then(|| self.refraction.prepare(&ctx, &views)).flatten(),
            transparency: plan.transparency.then(|| self.transparency.prepare(&ctx, &mut frame, &views)),
            traced,
        };
        // Cube faces first (a mirror may reflect a curved mirror), each copied into its cube;
        // then the mirrored cameras deepest first, so every view's mirrors find their images.
        for view in &plan.cube_views {
            record_view(&ctx, &mut frame, &phases, (view, environment.capture_targets()), &MirrorImages::default());
            if let ViewKind::CubeFace { cube, face } = view.kind {
                environment.store_face(&mut frame, cube, face);
            }
        }
        if !plan.cube_views.is_empty() {
            let faces = plan.cube_views.len();
            frame.group("cubes' mip chains", |frame| environment.finish_faces(gpu, &self.mipmaps, frame, faces));
        }
        for (k, view) in plan.mirror_views.iter().enumerate().rev() {
            let images = mirrors.images(&plan.mirror_nodes, Some(k));
            record_view(&ctx, &mut frame, &phases, (view, mirrors.targets(k)), &images);
        }
        let images = mirrors.images(&plan.mirror_nodes, None);
        record_view(&ctx, &mut frame, &phases, (&plan.main, targets), &images);
        frame.group("overlays", |frame| self.record_overlays(&ctx, frame, &plan, (targets, &maps)));
        // The first mirrored camera's own image, in place of the frame.
        let shown = match plan.mirror_views.first() {
            Some(_) if settings.mirrors.view == MirrorView::Image => &mirrors.targets(0).hdr.view,
            _ => &targets.hdr.view,
        };
        self.present.record(gpu, &mut frame, shown, output, OutputTransform::of(settings));
        frame.report.drawn_size = size;
        frame.report.triangles = self.scene_gpu.geometry.triangles();
        frame.finish()
    }

    /// Where an inspecting renderer has a pixel to inspect: clears its record, chooses the view
    /// that records (the main one, or the mirrored camera [`Self::inspect_through`] names) and
    /// keeps what the frame decided ([`FrameFacts`]).
    fn begin_inspection(&mut self, gpu: &Gpu, plan: &mut FramePlan) {
        let Some(inspector) = self.inspector.as_mut() else { return };
        let Some(pixel) = inspector.pixel else { return };
        inspector.begin(&gpu.queue, pixel);
        self.inspected_through = self.through.and_then(|(object, point)| {
            let mirrors = &self.mirrors.mirrors;
            let distance = |node: &MirrorNode| mirrors[node.mirror].plane.distance(point).abs();
            (0..plan.mirror_nodes.len())
                .filter(|&k| plan.mirror_nodes[k].level == 1 && mirrors[plan.mirror_nodes[k].mirror].object == object)
                .min_by(|&a, &b| distance(&plan.mirror_nodes[a]).total_cmp(&distance(&plan.mirror_nodes[b])))
        });
        match self.inspected_through {
            Some(node) => plan.mirror_views[node].key.inspect = true,
            None if self.through.is_some() => {}
            None => plan.main.key.inspect = true,
        }
        self.facts = facts(plan, &self.mirrors, &self.environment, self.scene_gpu.geometry.bounds);
        self.facts.blend_by_hand = self.surface.wgsl.routes("BLEND_BY_HAND");
    }

    /// Prepares what the plan depends on (materials for the texture filter, tessellations, the
    /// environment maps) and plans the frame; writes every view's slot and the frame uniform.
    fn plan(
        &mut self,
        gpu: &Gpu,
        scene: &Scene,
        settings: &RenderSettings,
        size: (u32, u32),
        frame: &mut FrameEncoder,
    ) -> FramePlan {
        let scene_gpu = &mut self.scene_gpu;
        scene_gpu.prepare_materials(&gpu.device, &self.layouts, &settings.textures);
        if let Some(tessellation) = &mut self.tessellation {
            let report = tessellation.prepare(gpu, &mut frame.encoder, scene, settings, &mut scene_gpu.geometry);
            if let Some(report) = report.cloned() {
                let count = |n: u64| Figure::Count(n);
                let figures = [
                    ("triangles", count(report.triangles)),
                    ("vertices", count(report.vertices)),
                    ("finest split", count(u64::from(report.finest))),
                    ("bound forced", Figure::Flag(report.edge_pixels > report.asked)),
                    ("made", Figure::Flag(report.made)),
                ];
                frame.end("tessellation", &figures);
            }
        }
        let (segments, adaptive) = (scene.sphere_segments(), settings.raster.adaptive_tessellation);
        scene_gpu.geometry.prepare(&gpu.device, scene, &scene.camera, segments, adaptive);
        let bounds = scene_gpu.geometry.bounds;
        // The faces are drawn again with finer terms, or with those traced elsewhere.
        let traced = traced::wanted(settings).map_or(0, |_| self.traced.faces_key(self.traced_stride));
        let faces = self.environment.prepare(gpu, (&self.mipmaps, frame), scene, settings, (bounds, traced));
        let plan = plan(scene, &scene_gpu.geometry, settings, (size, &self.mirrors.mirrors), faces);
        for view in plan.views() {
            scene_gpu.views.write(&gpu.queue, view.slot, &view.view);
        }
        scene_gpu.update_frame(&gpu.queue, scene, &plan.lights.first_layer, settings);
        self.mirrors.prepare(&gpu.device, &self.scene, plan.mirror_nodes.len(), size);
        if plan.projected {
            let recomputed = self.projected.prepare(&gpu.device, scene, scene_gpu.geometry.draw_list(), &plan.lights);
            frame.end("projected shadows", &[("recomputed", Figure::Flag(recomputed))]);
        }
        let views = Figure::Count(plan.mirror_views.len() as u64);
        frame.end("mirror views", &[("views", views)]);
        plan
    }

    /// The teaching views over the main view's image: shadow maps and light frusta, the volumes'
    /// grids, the mirrored cameras' view volumes, the environment maps.
    fn record_overlays(
        &self,
        ctx: &FrameContext,
        frame: &mut FrameEncoder,
        plan: &FramePlan,
        (targets, maps): (&FrameTargets, &ShadowMaps),
    ) {
        let settings = ctx.settings;
        let main = (&plan.main, targets);
        self.overlays.record_shadows(ctx, frame, main, (&plan.maps, maps));
        if settings.volume.enabled && settings.volume.wireframe {
            let lines: Vec<[Vec3; 2]> =
                ctx.scene.volumes.iter().flat_map(|v| v.wireframe_lines(WIREFRAME_CELLS)).collect();
            self.overlays.record_lines(ctx, frame, main, lines.as_flattened(), WIREFRAME_COLOUR);
        }
        if settings.bump.view == BumpView::Tessellation {
            let adaptive = match &self.tessellation {
                Some(tessellation) if tessellation.report.is_some() => tessellation.cpu_meshes(ctx.scene),
                _ => Vec::new(),
            };
            self.overlays.record_lines(ctx, frame, main, &mesh_edges(ctx.scene, &adaptive), TESSELLATION_COLOUR);
        }
        if settings.mirrors.view == MirrorView::Camera {
            let edges = box_edges(&mirror_volumes(&plan.mirror_nodes));
            self.overlays.record_lines(ctx, frame, main, &edges, FRUSTUM_COLOUR);
        }
        self.environment.record_view(frame, settings, targets);
    }
}

/// What an inspected frame decided before it drew, for the explainer: the lights' views, the
/// planes the main view's mirrored cameras were reflected about, the cubes' centres, the bounds.
fn facts(
    plan: &FramePlan,
    mirrors: &MirrorPass,
    environment: &EnvironmentPass,
    bounds: Option<(Vec3, Vec3)>,
) -> FrameFacts {
    let seen = plan.mirror_nodes.iter().filter(|node| node.parent.is_none());
    FrameFacts {
        lights: plan.lights.clone(),
        mirrors: seen.map(|node| (mirrors.mirrors[node.mirror].object, mirrors.mirrors[node.mirror].plane)).collect(),
        cubes: environment.centres().to_vec(),
        bounds,
        blend_by_hand: false,
    }
}

/// Draws one view's phases into its targets, the same for the main camera, a mirrored camera
/// and a cube face: the opaque surfaces (after a depth prepass and the projected-shadow mask
/// where the view has them), with the reflections `mirrors` show; the isosurfaces; the glass that
/// refracts; then the transparent surfaces and the composited volumes in one order.
fn record_view(
    ctx: &FrameContext,
    frame: &mut FrameEncoder,
    phases: &Phases,
    (view, targets): ViewTargets<'_>,
    mirrors: &MirrorImages,
) {
    frame.group(&view.kind.name(), |frame| {
        let transparent_later = phases.transparency.is_some();
        if let Some(traced) = &phases.traced {
            frame.group("traced terms", |frame| traced.record(frame, view, targets));
        }
        if view.prepass {
            frame.group("depth prepass", |frame| {
                phases.scene.record_prepass(ctx, frame, view, targets, transparent_later)
            });
        }
        if view.projected {
            frame.group("projected shadows", |frame| phases.projected.record(ctx, frame, view, targets));
        }
        let opaque = (transparent_later, mirrors);
        frame.group("opaque", |frame| phases.scene.record_opaque(ctx, frame, view, targets, opaque));
        frame.group("isosurfaces", |frame| phases.volumes.record_isosurfaces(ctx, frame, view, targets));
        if let Some(refraction) = &phases.refraction {
            frame.group("refraction", |frame| refraction.record(ctx, frame, view, targets));
        }
        let mut composite =
            |frame: &mut FrameEncoder, span: RaySpan| phases.volumes.composite(ctx, frame, view, targets, span);
        frame.group("transparency and volumes", |frame| match &phases.transparency {
            Some(transparency) => transparency.record(ctx, frame, (view, targets), &mut composite),
            None => composite(frame, RaySpan { volumes: VolumeSet::All, near: None, far: None }),
        });
    });
}

/// Every kind of inspection record the passes write, each declared by its pass.
pub fn record_kinds() -> impl Iterator<Item = &'static RecordKind> {
    let passes: [&'static [RecordKind]; 4] = [
        &super::scene_pass::RECORDS,
        &super::transparency::RECORDS,
        &super::refraction::RECORDS,
        &super::volume::RECORDS,
    ];
    passes.into_iter().flatten()
}

/// Uploads `scene` and lets each pass find what it keeps per scene: the planar mirrors, the
/// curved ones' cubes, the volumes' textures.
fn load(
    gpu: &Gpu,
    scene: &Scene,
    (layouts, mipmaps): (&SceneLayouts, &MipmapGenerator),
    (mirrors, environment, volumes): (&mut MirrorPass, &mut EnvironmentPass, &mut VolumePass),
) -> SceneGpu {
    if scene.lights.len() > super::uniforms::MAX_LIGHTS {
        log::warn!(
            "the scene has {} lights; the rasterizer draws the first {}",
            scene.lights.len(),
            super::uniforms::MAX_LIGHTS
        );
    }
    let planar = mirrors.load(scene);
    let curved = environment.load(scene, &planar);
    volumes.load(gpu, scene);
    SceneGpu::upload(gpu, layouts, mipmaps, scene, DrawnAlone { mirrors: &planar, env_objects: &curved })
}

/// The frame's inputs to every view's group (group 2): the shadow pass's maps and the
/// environment maps.
fn frame_inputs<'a>(
    maps: &ShadowMaps<'a>,
    environment: &'a EnvironmentPass,
    inspection: Option<&'a wgpu::Buffer>,
) -> FrameInputs<'a> {
    let env = environment.maps();
    FrameInputs {
        shadow_uniform: maps.uniform.binding(),
        shadow_maps: maps.depth,
        shadow_sampler: maps.sampler,
        transmission_maps: maps.transmission,
        environment_uniform: env.params.binding(),
        environment_sampler: &environment.converter.sampler,
        environment_cube: &env.cube.view,
        dynamic_cubes: &env.dynamic.view,
        sphere_map: &env.sphere.view,
        latlong_map: &env.latlong.view,
        inspection,
    }
}
