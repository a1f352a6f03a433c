//! The scene the viewer shows: where it came from, the camera it was loaded with (for R), the
//! picked object, and reloading — from a dropped file, from a script, or because the file changed
//! on disk (its modification time is polled twice a second). A scene that fails to load leaves
//! the previous one in place and its error on screen.

use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use web_time::Instant;

use super::picking::{Picked, Picker, SeenDirection};
use crate::scene::Camera;
use crate::{RenderSettings, Scene};

/// How often the scene file's modification time is checked.
pub(super) const WATCH_PERIOD: Duration = Duration::from_millis(500);

pub struct SceneState {
    pub scene: Scene,
    /// The camera the scene file gave: what R returns to.
    pub seed_camera: Camera,
    /// The settings the scene file gave: what remembered changes are relative to.
    pub seed_settings: RenderSettings,
    /// Bumped whenever geometry or materials change, so GPU buffers and the tracer rebuild.
    pub revision: u64,
    /// The last load error, shown in the window until the next successful load.
    pub error: Option<String>,
    pub picked: Option<Picked>,
    /// The scene's bounds, computed once (objects do not move in the viewer).
    pub bounds: Option<(glam::Vec3, glam::Vec3)>,
    picker: Option<Picker>,
    watch: Option<Watch>,
    /// Overrides of the scene file's own values (`--set camera.fovy=30`, the script's `set`),
    /// applied again whenever the file is read.
    pub overrides: Vec<String>,
}

struct Watch {
    path: PathBuf,
    /// The file's modification time and length when last read: a save within one tick of a
    /// coarse clock still changes the length, mostly.
    modified: Option<(SystemTime, u64)>,
    checked: Instant,
}

/// A watched file's modification time and length (the scene file, a lab's file).
pub(super) fn modified(path: &Path) -> Option<(SystemTime, u64)> {
    let metadata = std::fs::metadata(path).ok()?;
    Some((metadata.modified().ok()?, metadata.len()))
}

/// Loads `path`, or the built-in showcase, with `overrides` of its own values applied.
pub fn load(path: Option<&Path>, overrides: &[String]) -> Result<Scene, crate::scene::SceneError> {
    let builtin = crate::scene::builtin_path("showcase.toml");
    crate::scene::file::overrides::load(path.unwrap_or(&builtin), overrides)
}

/// `scene` with its height fields displaced into triangles where `settings` ask for
/// displacement (`crate::texture::displacement`); its own settings kept.
pub fn displaced(mut scene: Scene, settings: &RenderSettings) -> Scene {
    let seed_settings = std::mem::replace(&mut scene.settings, settings.clone());
    if let Some(line) = crate::texture::displacement::displace(&mut scene).summary() {
        log::info!("{line}");
    }
    scene.settings = seed_settings;
    scene
}

impl SceneState {
    pub fn new(scene: Scene) -> SceneState {
        let watch = scene.source.clone().map(|path| Watch { modified: modified(&path), path, checked: Instant::now() });
        let bounds = scene.bounds();
        SceneState {
            seed_camera: scene.camera.clone(),
            seed_settings: scene.settings.clone(),
            scene,
            revision: 0,
            error: None,
            picked: None,
            bounds,
            picker: None,
            watch,
            overrides: Vec::new(),
        }
    }

    /// Replaces the scene with the one at `path` and the window's image size, with `settings`
    /// (the same scene reloaded) or its own (`None`: another scene); on failure keeps the current
    /// scene and records the error. Returns whether the scene changed.
    pub fn load(&mut self, path: &Path, settings: Option<&RenderSettings>) -> bool {
        match crate::scene::file::overrides::load(path, &self.overrides) {
            Ok(scene) => {
                let settings = settings.cloned().unwrap_or_else(|| scene.settings.clone());
                self.replace(scene, &settings);
                true
            }
            Err(e) => {
                log::warn!("{e}");
                self.error = Some(e.to_string());
                if let Some(watch) = &mut self.watch
                    && watch.path == path
                {
                    watch.modified = modified(path);
                }
                false
            }
        }
    }

    /// Replaces the scene with `scene` at the window's image size, drawn with `settings` (its
    /// height fields displaced into triangles where `settings` ask for displacement).
    pub fn replace(&mut self, scene: Scene, settings: &RenderSettings) {
        let (width, height) = (self.scene.camera.width, self.scene.camera.height);
        let revision = self.revision + 1;
        let overrides = std::mem::take(&mut self.overrides);
        *self = SceneState::new(displaced(scene, settings));
        self.overrides = overrides;
        self.revision = revision;
        self.scene.settings = settings.clone();
        self.scene.camera.width = width;
        self.scene.camera.height = height;
    }

    /// Whether going from `before` to `after` changes the displaced geometry: the scene must be
    /// made again from its file (`bump.method = "displacement"` and what it reads).
    pub(in crate::viewer) fn displacement_changed(before: &RenderSettings, after: &RenderSettings) -> bool {
        use crate::texture::displacement::wanted;
        let (b, a) = (&before.bump, &after.bump);
        wanted(before) != wanted(after)
            || (wanted(after) && (b.scale != a.scale || b.displacement_texels != a.displacement_texels))
            || (wanted(after) && before.sphere_segments != after.sphere_segments)
    }

    /// Reloads the scene when its file changed on disk since it was loaded (polled, cheap);
    /// returns whether the window changes: the scene, or the error of a file saved broken.
    pub(in crate::viewer) fn reload_if_changed(&mut self, settings: &RenderSettings) -> bool {
        let Some(watch) = &mut self.watch else { return false };
        if watch.checked.elapsed() < WATCH_PERIOD {
            return false;
        }
        watch.checked = Instant::now();
        let now = modified(&watch.path);
        if now == watch.modified {
            return false;
        }
        watch.modified = now;
        let path = watch.path.clone();
        log::info!("{} changed on disk; reloading", path.display());
        let loaded = self.load(&path, Some(settings));
        // A failed reload changes the window too: its error shows at once, not at the next input.
        loaded || self.error.is_some()
    }

    /// When the scene file's modification time is next due a look (`None`: no file).
    pub fn next_poll(&self) -> Option<Instant> {
        self.watch.as_ref().map(|watch| watch.checked + WATCH_PERIOD)
    }

    /// Overrides one of the scene file's own values (`camera.fovy=30`, `lights.key.intensity=0.5`)
    /// and reads the file again with it, keeping `settings`; an override the file refuses is
    /// dropped and its error shown, the scene as it was.
    pub(in crate::viewer) fn set_value(&mut self, assignment: &str, settings: &RenderSettings) -> bool {
        let Some(path) = self.scene.source.clone() else {
            self.error = Some(format!("`{assignment}`: this scene has no file to override"));
            return false;
        };
        self.overrides.push(assignment.to_owned());
        let loaded = self.load(&path, Some(settings));
        if !loaded {
            self.overrides.pop();
        }
        loaded
    }

    /// Marks geometry or materials as changed.
    pub fn touch(&mut self) {
        self.revision += 1;
    }

    /// Picks the object under `pixel` of an image of `size` pixels taken by the current camera.
    pub fn pick(&mut self, pixel: glam::Vec2, size: (u32, u32)) -> Option<Picked> {
        let picked = self.with_picker(size, |picker, scene| picker.pick(scene, pixel));
        self.picked = picked;
        picked
    }

    /// The direction the environment is seen in at `pixel` of an image of `size` pixels taken
    /// by the current camera.
    pub(in crate::viewer) fn seen_direction(&mut self, pixel: glam::Vec2, size: (u32, u32)) -> SeenDirection {
        self.with_picker(size, |picker, scene| picker.seen_direction(scene, pixel))
    }

    /// Runs `f` with the picker (built once per scene) and the scene, its camera taking images
    /// of `size` pixels (the view's, not the render size the camera was loaded with).
    pub(in crate::viewer) fn with_picker<T>(&mut self, size: (u32, u32), f: impl FnOnce(&Picker, &Scene) -> T) -> T {
        let picker = self.picker.get_or_insert_with(|| Picker::new(&self.scene));
        let (width, height) = (self.scene.camera.width, self.scene.camera.height);
        (self.scene.camera.width, self.scene.camera.height) = size;
        let result = f(picker, &self.scene);
        (self.scene.camera.width, self.scene.camera.height) = (width, height);
        result
    }

    /// The diagonal of the scene's bounds (1 for an empty scene): the scale of fly speeds.
    pub fn size(&self) -> f32 {
        self.bounds.map_or(1.0, |(lo, hi)| (hi - lo).length().max(1e-3))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene file saved broken is news for the window at once (its error is drawn), not only
    /// at the next input; the last scene stays.
    #[test]
    fn a_scene_file_saved_broken_asks_for_a_frame_and_keeps_the_last_scene() {
        let dir = std::env::temp_dir().join(format!("mirador-scene-state-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("scene.toml");
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/seed-simple.toml"))
            .expect("the seed scene");
        std::fs::write(&path, &text).unwrap();
        let scene = Scene::load(&path).expect("the scene loads");
        let objects = scene.objects.len();
        let mut state = SceneState::new(scene);
        let settings = state.scene.settings.clone();
        std::thread::sleep(WATCH_PERIOD + Duration::from_millis(100));
        assert!(!state.reload_if_changed(&settings), "nothing changed yet");
        std::fs::write(&path, format!("{text}\n[camera\n")).unwrap();
        std::thread::sleep(WATCH_PERIOD + Duration::from_millis(100));
        assert!(state.reload_if_changed(&settings), "a broken save must ask for a frame");
        assert!(state.error.as_deref().is_some_and(|e| e.contains("scene.toml")), "{:?}", state.error);
        assert_eq!(state.scene.objects.len(), objects, "the last scene stays");
        std::thread::sleep(WATCH_PERIOD + Duration::from_millis(100));
        assert!(!state.reload_if_changed(&settings), "an unchanged broken file is not news twice");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
