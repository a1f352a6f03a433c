//! What a tracer worker of the page needs to rebuild the page's scene and trace it as the page
//! would (`super::pool`, `crate::web::tracer`): the scene file and the overrides set over it, and
//! what the viewer changes in place (the camera, the lights, the materials, the ambient and
//! background radiance), with the settings of the request. Sent as JSON; a unit test below checks
//! that the scene it rebuilds traces to the same image.

use std::path::PathBuf;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::scene::{Camera, Light, Material};
use crate::{RenderSettings, Scene};

/// The page's scene, as a worker rebuilds it.
#[derive(Serialize, Deserialize)]
pub(crate) struct SceneRecipe {
    source: Option<PathBuf>,
    overrides: Vec<String>,
    camera: Camera,
    ambient: Vec3,
    background: Vec3,
    lights: Vec<Light>,
    materials: Vec<Material>,
    settings: RenderSettings,
}

impl SceneRecipe {
    pub(crate) fn of(scene: &Scene, overrides: &[String], settings: &RenderSettings) -> SceneRecipe {
        SceneRecipe {
            source: scene.source.clone(),
            overrides: overrides.to_vec(),
            camera: scene.camera.clone(),
            ambient: scene.ambient,
            background: scene.background,
            lights: scene.lights.clone(),
            materials: scene.materials.clone(),
            settings: settings.clone(),
        }
    }

    pub(crate) fn scene(self) -> Result<(Scene, RenderSettings), String> {
        let scene =
            crate::viewer::scene_state::load(self.source.as_deref(), &self.overrides).map_err(|e| e.to_string())?;
        // Displaced as the viewer's was, so its objects and materials are the viewer's.
        let mut scene = crate::viewer::scene_state::displaced(scene, &self.settings);
        if scene.materials.len() != self.materials.len() || scene.lights.len() != self.lights.len() {
            return Err("the scene file changed since the page read it".into());
        }
        scene.camera = self.camera;
        scene.ambient = self.ambient;
        scene.background = self.background;
        scene.lights = self.lights;
        scene.materials = self.materials;
        Ok((scene, self.settings))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The viewer's request: the showcase with an override, then a camera moved, a material
    /// and a light edited in the panel, and a setting changed.
    fn edited() -> (Scene, Vec<String>, RenderSettings) {
        let overrides = vec!["camera.fovy=35".to_owned()];
        let path = crate::scene::builtin_path("showcase.toml");
        let mut scene = crate::viewer::scene_state::load(Some(&path), &overrides).unwrap();
        (scene.camera.width, scene.camera.height) = (64, 36);
        scene.camera.eye += Vec3::new(1.0, 0.5, 0.0);
        scene.materials[0].kd = 0.2;
        scene.materials[0].color = Vec3::new(0.9, 0.2, 0.1);
        scene.lights[0].intensity *= 0.5;
        let mut settings = scene.settings.clone();
        settings.trace.max_depth = 2;
        (scene, overrides, settings)
    }

    #[test]
    fn a_worker_rebuilds_the_scene_the_page_traces() {
        let (scene, overrides, settings) = edited();
        let json = serde_json::to_string(&SceneRecipe::of(&scene, &overrides, &settings)).unwrap();
        let (rebuilt, rebuilt_settings) = serde_json::from_str::<SceneRecipe>(&json).unwrap().scene().unwrap();
        let page = crate::trace::render_image(&scene, &settings);
        assert!(page == crate::trace::render_image(&rebuilt, &rebuilt_settings), "the worker's image differs");
        // The edits show: the scene file alone, with the same camera, traces another image.
        let path = crate::scene::builtin_path("showcase.toml");
        let mut unedited = crate::viewer::scene_state::load(Some(&path), &overrides).unwrap();
        unedited.camera = scene.camera.clone();
        assert!(page != crate::trace::render_image(&unedited, &settings), "the edits change nothing");
    }

    #[test]
    fn a_scene_file_changed_since_is_refused() {
        let (mut scene, overrides, settings) = edited();
        scene.materials.push(scene.materials[0].clone());
        let recipe = SceneRecipe::of(&scene, &overrides, &settings);
        assert!(recipe.scene().is_err());
    }
}
