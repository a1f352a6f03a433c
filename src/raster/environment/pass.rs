//! The environment technique in the frame: what it keeps per scene (which objects have a dynamic
//! cube, the maps), the cube faces due this frame, the target they are drawn into one at a time,
//! and the teaching views. The faces themselves are views of the frame like any other: the frame
//! draws every phase into the capture target, then [`EnvironmentPass::store_face`] copies it
//! into its layer.

use glam::Vec3;

use super::{
    Converter, EnvironmentMaps, capture_key, capture_range, cube_face_view, object_centre, reflective_objects,
    view_rotation,
};
use crate::gpu::Gpu;
use crate::gpu::mipmap::MipmapGenerator;
use crate::raster::context::{Figure, FrameEncoder};
use crate::raster::targets::{FrameTargets, ViewImage};
use crate::raster::view::View;
use crate::scene::Scene;
use crate::settings::{EnvironmentMap, EnvironmentView, Refraction, RenderSettings};

pub struct EnvironmentPass {
    pub converter: Converter,
    /// The objects with a dynamic cube of their own, by cube (found by [`Self::load`]).
    pub objects: Vec<usize>,
    /// Each of those objects and the point its cube is drawn from (set by [`Self::prepare`]).
    centres: Vec<(usize, Vec3)>,
    /// The world's maps and the dynamic cubes: made at the first frame of a scene (their size is
    /// a setting) and again when `environment.cube_size` changes.
    maps: Option<EnvironmentMaps>,
    /// Where a cube face is drawn before it is copied into its layer.
    capture: Option<FrameTargets>,
}

/// One face of a dynamic cube to draw this frame: its cube, face and camera, and the object the
/// cube belongs to (left out of its own cube).
pub struct CubeFace {
    pub cube: usize,
    pub face: usize,
    pub object: usize,
    pub view: View,
}

impl EnvironmentPass {
    pub fn new(device: &wgpu::Device) -> EnvironmentPass {
        EnvironmentPass {
            converter: Converter::new(device),
            objects: Vec::new(),
            centres: Vec::new(),
            maps: None,
            capture: None,
        }
    }

    /// Finds the curved mirrors of `scene` (objects that are not `planar_mirrors`), in place of
    /// the last scene's, and forgets the last scene's maps; returns the objects.
    pub fn load(&mut self, scene: &Scene, planar_mirrors: &[usize]) -> Vec<usize> {
        let (objects, warnings) = reflective_objects(scene, planar_mirrors);
        for warning in warnings {
            log::warn!("{warning}");
        }
        self.objects = objects.clone();
        self.maps = None;
        objects
    }

    /// Makes the maps the settings ask for and writes their uniform; returns the cube faces due
    /// this frame (every face of every dynamic cube, when something they see changed, their
    /// faces' traced terms (`traced`, a key of them) changed, or their refresh came round; none
    /// otherwise).
    pub fn prepare(
        &mut self,
        gpu: &Gpu,
        (mipmaps, frame): (&MipmapGenerator, &mut FrameEncoder),
        scene: &Scene,
        settings: &RenderSettings,
        (bounds, traced): (Option<(Vec3, Vec3)>, u64),
    ) -> Vec<CubeFace> {
        let env = &settings.environment;
        if self.maps.as_ref().is_none_or(|maps| maps.cube_size != env.cube_size) {
            let (device, queue) = (&gpu.device, &gpu.queue);
            let maps =
                EnvironmentMaps::new(device, queue, &self.converter, mipmaps, scene, env.cube_size, self.objects.len());
            self.maps = Some(maps);
        }
        let maps = self.maps.as_mut().expect("made just above");
        let centres: Vec<Vec3> = self.objects.iter().map(|&object| object_centre(scene, object).0).collect();
        maps.set_proxy(env.parallax, bounds, &centres);
        self.centres = self.objects.iter().copied().zip(centres).collect();
        let rotation = view_rotation(&scene.camera);
        let sphere_made = maps.prepare(&gpu.device, &gpu.queue, &self.converter, mipmaps, settings, rotation);
        let drawn = env.enabled && env.dynamic && env.map == EnvironmentMap::Cube;
        let due = (drawn || env.view == EnvironmentView::Cross)
            && !self.objects.is_empty()
            && maps.capture_due(capture_key(scene, settings, traced), env.refresh);
        frame.end("environment maps", &[("sphere map made", Figure::Flag(sphere_made))]);
        if !due {
            return Vec::new();
        }
        let size = (env.cube_size, env.cube_size);
        if self.capture.as_ref().is_none_or(|t| t.size != size) {
            self.capture = Some(FrameTargets::new(&gpu.device, size));
        }
        let mut faces = Vec::new();
        // Glass's cubes only when its refraction or its Fresnel reflection reads them.
        let glass_reads = settings.transparency.refraction != Refraction::None || settings.terms.fresnel;
        let wanted = |object: usize| {
            let material = &scene.materials[scene.objects[object].material.0];
            glass_reads || material.mirror > 0.0 || !material.bends_light()
        };
        for (cube, &object) in self.objects.iter().enumerate().filter(|(_, o)| wanted(**o)) {
            let (centre, inner) = object_centre(scene, object);
            let (near, far) = capture_range(inner, bounds);
            faces.extend((0..6).map(|face| CubeFace {
                cube,
                face,
                object,
                view: cube_face_view(centre, face, near, far),
            }));
        }
        faces
    }

    /// Each curved mirror's object and the point its cube is drawn from, as the last
    /// [`Self::prepare`] set them.
    pub fn centres(&self) -> &[(usize, Vec3)] {
        &self.centres
    }

    /// The maps, once [`Self::prepare`] has made them.
    pub fn maps(&self) -> &EnvironmentMaps {
        self.maps.as_ref().expect("EnvironmentPass::prepare makes the maps before a frame reads them")
    }

    /// Makes `image` at full size in the capture targets, if there are any (an image made on
    /// demand).
    pub fn ensure_images(&mut self, device: &wgpu::Device, image: ViewImage) {
        if let Some(targets) = &mut self.capture {
            targets.images.ensure(device, image, targets.size);
        }
    }

    /// The target a cube face is drawn into (a face is due only after [`Self::prepare`] made it).
    pub fn capture_targets(&self) -> &FrameTargets {
        self.capture.as_ref().expect("made by prepare with the faces due")
    }

    /// Copies the face just drawn into layer `6·cube + face` of the dynamic cubes.
    pub fn store_face(&self, frame: &mut FrameEncoder, cube: usize, face: usize) {
        let layer = (6 * cube + face) as u32;
        self.maps().store_capture(&mut frame.encoder, &self.capture_targets().hdr.texture, layer);
    }

    /// Makes the dynamic cubes' mip chains once their faces are drawn.
    pub fn finish_faces(&self, gpu: &Gpu, mipmaps: &MipmapGenerator, frame: &mut FrameEncoder, faces: usize) {
        let maps = self.maps();
        mipmaps.record_layers(&gpu.device, &mut frame.encoder, &maps.dynamic.texture, maps.dynamic_layers());
        frame.end("environment cubes", &[("faces", Figure::Count(faces as u64))]);
    }

    /// The teaching view the settings ask for, over `targets`' image.
    pub fn record_view(&self, frame: &mut FrameEncoder, settings: &RenderSettings, targets: &FrameTargets) {
        if settings.environment.view != EnvironmentView::Off {
            let target = (&targets.hdr.view, targets.size);
            self.maps().record_view(&mut frame.encoder, &self.converter, &settings.environment, target);
            frame.end("overlays", &[]);
        }
    }
}
