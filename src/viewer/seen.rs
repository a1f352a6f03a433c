//! The direction the environment is seen in under the cursor, for the lat–long view's marker
//! (`environment.view = "latlong"` with its inset): one primary ray cast by the picker, made
//! before the UI is laid out, so that the layout only draws it. Kept while the pixel, the view's
//! size, the camera and the scene are the same.

use glam::Vec2;

use super::kept::Kept;
use super::picking::SeenDirection;
use super::scene_state::SceneState;
use crate::scene::Camera;
use crate::settings::{EnvironmentView, RenderSettings};

/// What the marker was made from.
#[derive(Clone, Debug, PartialEq)]
struct Inputs {
    pixel: Vec2,
    size: (u32, u32),
    camera: Camera,
    revision: u64,
}

/// The marker's direction, with the pixel it was found at.
#[derive(Default)]
pub(in crate::viewer) struct CursorDirection {
    kept: Kept<Inputs, (Vec2, SeenDirection)>,
}

impl CursorDirection {
    /// Casts the ray at `at` (a pixel of a view of that size) for the current scene, unless the
    /// one kept was cast for the same inputs.
    pub fn update(&mut self, scene: &mut SceneState, settings: &RenderSettings, at: Option<(Vec2, (u32, u32))>) {
        let inputs = inputs(scene, settings, at);
        self.kept.update(inputs, |i| (i.pixel, scene.seen_direction(i.pixel, i.size)));
    }

    /// Whether the kept direction is the one [`Self::update`] would find now.
    pub(in crate::viewer) fn is_current(
        &self,
        scene: &SceneState,
        settings: &RenderSettings,
        at: Option<(Vec2, (u32, u32))>,
    ) -> bool {
        self.kept.is_current(&inputs(scene, settings, at))
    }

    /// The direction and its pixel; `None` when the marker is not shown.
    pub fn shown(&self) -> Option<&(Vec2, SeenDirection)> {
        self.kept.get()
    }
}

/// `None` where no marker is drawn: the view is not the lat–long inset, or the pixel lies
/// outside the view.
fn inputs(scene: &SceneState, settings: &RenderSettings, at: Option<(Vec2, (u32, u32))>) -> Option<Inputs> {
    let env = &settings.environment;
    let (pixel, size) = at?;
    let inside = pixel.x >= 0.0 && pixel.y >= 0.0 && pixel.x < size.0 as f32 && pixel.y < size.1 as f32;
    if env.view != EnvironmentView::Latlong || !env.inset || !inside {
        return None;
    }
    Some(Inputs { pixel, size, camera: scene.scene.camera.clone(), revision: scene.revision })
}
