//! What the viewer does to its scene and settings: a setting changed (the panel, `--set`, a
//! step), every setting reset, a scene opened or its file changed on disk, the displaced geometry
//! made again, and what the configuration remembers of each scene's changed settings.

use std::collections::BTreeMap;
use std::path::Path;

use web_time::Instant;

use super::config::{ViewerConfig, scene_key};
use super::frame::Viewer;
use super::lab::LabMode;
use super::scene_state::SceneState;
use crate::RenderSettings;
use crate::scene::Camera;

impl Viewer {
    /// Reloads the scene when its file changed on disk (polled between frames, without drawing
    /// one); returns whether it did, so the window is drawn again.
    pub(in crate::viewer) fn poll_file(&mut self) -> bool {
        let reloaded = self.scene.reload_if_changed(&self.settings);
        if reloaded {
            let what = if self.scene.error.is_some() { "it does not load; the last scene is kept" } else { "reloaded" };
            self.notice(format!("scene file changed on disk: {what}"));
        }
        let lab = self.lab.as_mut().is_some_and(LabMode::poll);
        reloaded || lab
    }

    /// When the scene file, or the lab's file, is next due a look.
    pub fn next_poll(&self) -> Option<Instant> {
        [self.scene.next_poll(), self.lab.as_ref().map(LabMode::next_poll)].into_iter().flatten().min()
    }

    /// What the configuration file should remember now.
    pub fn remembered(&self, window: [u32; 2]) -> ViewerConfig {
        ViewerConfig {
            window,
            mode: self.view.mode,
            split: self.view.split,
            motion_fps: self.view.motion_fps,
            motion_scale: self.view.motion_scale,
            scenes: self.remembered_scenes(),
        }
    }

    /// The settings changed in every scene, this one's as they are now.
    pub(super) fn remembered_scenes(&self) -> BTreeMap<String, toml::Table> {
        let mut scenes = self.remembered.scenes.clone();
        let key = scene_key(self.scene.scene.source.as_deref());
        let changes = self.changed_settings();
        if changes.is_empty() {
            scenes.remove(&key);
        } else {
            scenes.insert(key, changes);
        }
        scenes
    }

    /// The settings that differ from the scene file's own.
    pub(in crate::viewer) fn changed_settings(&self) -> toml::Table {
        super::config::changed_settings(&self.settings, &self.scene.seed_settings)
    }

    /// Opens a scene file (dropped, or from a script) with its own settings and what was changed
    /// in it before: nothing set in the scene left behind comes along.
    pub fn open(&mut self, path: &Path) {
        self.remembered.scenes = self.remembered_scenes();
        // Overrides belong to the scene they were set in.
        let overrides = std::mem::take(&mut self.scene.overrides);
        if self.scene.load(path, None) {
            self.notices.camera_error = None;
            let changes = self.remembered.scenes.get(&scene_key(Some(path))).cloned().unwrap_or_default();
            let (settings, warnings) = super::config::apply_settings(&self.scene.seed_settings, &changes);
            self.settings = settings;
            self.scene.scene.settings = self.settings.clone();
            for warning in warnings {
                self.notice(warning);
            }
            let kept = if changes.is_empty() {
                String::new()
            } else {
                format!(" ({} settings as you left them)", changes.len())
            };
            self.notice(format!("opened {}{kept}", path.display()));
        } else {
            self.scene.overrides = overrides;
        }
    }

    /// Every setting back to the scene file's own.
    pub(super) fn reset_settings(&mut self) {
        if self.settings.sphere_segments != self.scene.seed_settings.sphere_segments {
            self.scene.touch();
        }
        let before = std::mem::replace(&mut self.settings, self.scene.seed_settings.clone());
        self.redisplace(&before);
        self.scene.scene.settings = self.settings.clone();
        self.notice("settings reset to the scene's own".into());
    }

    /// Makes the scene again from its file when the settings changed from `before` in what the
    /// displaced geometry is made of (`bump.method = "displacement"`, its scale and tessellation).
    pub(super) fn redisplace(&mut self, before: &RenderSettings) {
        if !SceneState::displacement_changed(before, &self.settings) {
            return;
        }
        let size = (self.scene.scene.camera.width, self.scene.scene.camera.height);
        let camera = self.scene.scene.camera.clone();
        match self.scene.scene.source.clone() {
            Some(path) if self.scene.load(&path, Some(&self.settings)) => {
                self.scene.scene.camera = Camera { width: size.0, height: size.1, ..camera };
            }
            Some(_) => self.notice("the scene could not be made again for displacement".into()),
            None => self.notice("displacement is made from the scene's file, and this scene has none".into()),
        }
    }

    /// Applies render settings given on the command line (checked already).
    pub(in crate::viewer) fn apply_settings(&mut self, assignments: &[String]) {
        for assignment in assignments {
            self.set(assignment);
        }
    }

    pub(super) fn set(&mut self, assignment: &str) {
        if crate::scene::file::overrides::is_scene_override(assignment) {
            // The camera keeps the view's size, which the file does not know.
            let size = (self.scene.scene.camera.width, self.scene.scene.camera.height);
            if self.scene.set_value(assignment, &self.settings) {
                (self.scene.scene.camera.width, self.scene.scene.camera.height) = size;
                self.notice(format!("scene value set: {assignment}"));
            }
            return;
        }
        let before = self.settings.clone();
        match self.settings.set(assignment) {
            Ok(()) => {
                if self.settings.sphere_segments != self.scene.scene.settings.sphere_segments {
                    self.scene.touch();
                }
                self.scene.scene.settings = self.settings.clone();
                self.redisplace(&before);
            }
            Err(e) => self.notice(format!("setting refused: {e}")),
        }
    }
}
