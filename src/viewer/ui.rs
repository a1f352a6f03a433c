//! The window's layout, drawn with egui each frame: the side panel (view mode, camera, one
//! section per technique, lights, the picked material, the scene), and the 3D view, which shows
//! the raster image, the traced one, both split by a draggable divider, or their difference, and
//! turns mouse and keys over it into camera input. Nothing here changes the scene or the
//! settings directly except the editors of `scene_panel`; the rest is returned as [`UiOutput`]
//! and applied by the frame.

use egui::{Color32, Pos2, Rect, Sense};
use glam::{Vec2, Vec3};

use super::camera_control::{CameraInput, Navigation};
use super::hud::{self, FrameStats};
use super::lab::{LabPanel, LabShown};
use super::panel;
use super::picking::SeenDirection;
use super::scene_panel;
use super::scene_state::SceneState;
use super::traced::TracedView;
use super::view_mode::{ViewMode, ViewState};
use super::volume_probe;
use crate::RenderSettings;

/// What the frame reads from and edits through the UI.
pub struct UiModel<'a> {
    pub settings: &'a RenderSettings,
    pub scene: &'a mut SceneState,
    pub view: &'a mut ViewState,
    pub navigation: &'a mut Navigation,
    /// The raster image as an egui texture, when egui draws it (`screen::Composition::Textured`);
    /// otherwise the image is already in the window under the UI.
    pub raster: Option<egui::TextureId>,
    pub traced: &'a TracedView,
    /// The key of the request the current view shows (to tell stale traced images).
    pub key: u64,
    pub stats: &'a FrameStats,
    /// The rasterizer's passes in the last frame: their times (when timed) and figures.
    pub passes: &'a [crate::raster::PassReport],
    pub camera_error: &'a mut Option<String>,
    /// Messages for the user (settings refused, screenshots written), newest last.
    pub notices: &'a [String],
    /// The inspected pixel, its explanation drawn over the view.
    pub inspection: Option<&'a super::inspect::Inspection>,
    /// The volume ray under the cursor, made by the frame before the layout.
    pub probe: Option<&'a volume_probe::Shown>,
    /// The environment's direction under the cursor and its pixel, for the lat–long marker.
    pub seen: Option<&'a (Vec2, SeenDirection)>,
    /// Lab mode: the lab, what the view shows of it, the student's file's problems.
    pub lab: Option<LabPanel<'a>>,
    /// The settings changed from the scene file's own, as `key = value`.
    pub changed_settings: &'a [String],
    /// The last error budget measured (`crate::budget`), as its report.
    pub error_budget: Option<&'a str>,
    /// The page's lab: the student's file in an editor beside the view.
    pub lab_editor: Option<super::lab::LabEditor<'a>>,
}

/// Requests the UI makes of the frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    Frame,
    Reset,
    Screenshot,
    DismissError,
    /// Every setting back to the scene file's own.
    ResetSettings,
    /// Measure the error budget of the view as it is.
    Budget,
}

/// What the UI gathered this frame.
#[derive(Clone, Debug, Default)]
pub struct UiOutput {
    /// The 3D view, in points, rounded to whole pixels.
    pub view_rect: Option<Rect>,
    pub camera: CameraInput,
    /// `key=value` assignments for `RenderSettings::set`.
    pub settings: Vec<String>,
    /// A click in the 3D view, in pixels of the full-resolution image.
    pub pick: Option<Vec2>,
    /// A click in inspect mode: the pixel to explain.
    pub inspect: Option<Vec2>,
    /// The inspection's window was closed.
    pub inspection_closed: bool,
    pub actions: Vec<Action>,
    /// The camera, a light or a material was edited in place.
    pub camera_edited: bool,
    pub lights_edited: bool,
    pub material_edited: bool,
    /// The pixel of the 3D view under the mouse (or a script's cursor), where the next frame
    /// probes the volume ray.
    pub cursor: Option<Vec2>,
    /// Lab mode: show the student's image, the reference or their difference.
    pub lab_shown: Option<LabShown>,
    /// The page's lab editor changed the student's text.
    pub lab_edited: bool,
    /// The lab panel's Check button was pressed.
    pub lab_check: bool,
}

/// Draws the whole window.
pub fn draw(ui: &mut egui::Ui, model: &mut UiModel) -> UiOutput {
    let mut output = UiOutput::default();
    keys(ui.ctx(), model, &mut output);
    if model.view.panel_open {
        egui::Panel::left("side_panel").resizable(true).default_size(330.0).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| side_panel(ui, model, &mut output));
        });
    }
    if let Some(editor) = &mut model.lab_editor {
        output.lab_edited = editor.show(ui);
    }
    egui::CentralPanel::no_frame().show(ui, |ui| view(ui, model, &mut output));
    hud::help_window(ui.ctx(), &mut model.view.help_open);
    if let Some(inspection) = model.inspection {
        let mut open = true;
        super::inspect::window(ui.ctx(), inspection, &mut open);
        output.inspection_closed |= !open;
    }
    output
}

/// Keys act only when no text field has the keyboard.
fn keys(ctx: &egui::Context, model: &mut UiModel, output: &mut UiOutput) {
    if ctx.egui_wants_keyboard_input() {
        return;
    }
    ctx.input(|input| {
        use egui::Key;
        let pressed = |key| input.key_pressed(key);
        if pressed(Key::F) {
            output.actions.push(Action::Frame);
        }
        if pressed(Key::R) {
            output.actions.push(Action::Reset);
        }
        if pressed(Key::F12) {
            output.actions.push(Action::Screenshot);
        }
        if pressed(Key::F1) || pressed(Key::H) {
            model.view.help_open = !model.view.help_open;
        }
        if pressed(Key::O) {
            model.view.overlay_open = !model.view.overlay_open;
        }
        if pressed(Key::P) {
            model.view.panel_open = !model.view.panel_open;
        }
        if pressed(Key::I) {
            model.view.inspecting = !model.view.inspecting;
            if !model.view.inspecting {
                output.inspection_closed = true;
            }
        }
        if pressed(Key::L)
            && let Some(lab) = &model.lab
        {
            output.lab_shown = Some(lab.shown.next());
        }
        if pressed(Key::G) {
            *model.navigation = match model.navigation {
                Navigation::Orbit => Navigation::Fly,
                Navigation::Fly => Navigation::Orbit,
            };
        }
        for (key, mode) in [Key::Num1, Key::Num2, Key::Num3, Key::Num4].into_iter().zip(ViewMode::ALL) {
            if pressed(key) {
                model.view.mode = mode;
            }
        }
        if *model.navigation == Navigation::Fly {
            let axis =
                |plus, minus| f32::from(u8::from(input.key_down(plus))) - f32::from(u8::from(input.key_down(minus)));
            output.camera.walk = Vec3::new(axis(Key::D, Key::A), axis(Key::E, Key::Q), axis(Key::W, Key::S));
            output.camera.fast = input.modifiers.shift;
        }
    });
}

fn side_panel(ui: &mut egui::Ui, model: &mut UiModel, output: &mut UiOutput) {
    ui.heading("Mirador");
    if let Some(lab) = &model.lab {
        lab_section(ui, lab, output);
        ui.separator();
    }
    ui.horizontal_wrapped(|ui| {
        for mode in ViewMode::ALL {
            ui.selectable_value(&mut model.view.mode, mode, mode.label()).on_hover_text(match mode {
                ViewMode::Raster => "The z-buffer rasterizer, every frame.",
                ViewMode::Traced => "The Whitted ray tracer, refined in the background.",
                ViewMode::Split => "Raster left, ray traced right of a divider you can drag: the same pixels.",
                ViewMode::Difference => "The FLIP error map between the two (black: identical).",
            });
        }
    });
    ui.horizontal(|ui| {
        ui.selectable_value(model.navigation, Navigation::Orbit, "orbit")
            .on_hover_text("Drag to turn around the target (G).");
        ui.selectable_value(model.navigation, Navigation::Fly, "fly").on_hover_text("WASD to walk, drag to look (G).");
        if ui.button("help").clicked() {
            model.view.help_open = true;
        }
    });
    motion_budget(ui, model.view);
    ui.separator();

    egui::CollapsingHeader::new(egui::RichText::new("camera").strong()).id_salt("camera").show(ui, |ui| {
        output.camera_edited |= scene_panel::camera_ui(ui, &mut model.scene.scene.camera, model.camera_error);
        if let Some(error) = model.camera_error.as_deref() {
            ui.colored_label(ui.visuals().error_fg_color, error);
        }
        ui.horizontal(|ui| {
            if ui.button("frame the scene (F)").clicked() {
                output.actions.push(Action::Frame);
            }
            if ui.button("reset (R)").clicked() {
                output.actions.push(Action::Reset);
            }
        });
    });
    output.settings = panel::settings_ui(ui, model.settings);
    if !model.changed_settings.is_empty() {
        ui.horizontal(|ui| {
            let count = model.changed_settings.len();
            let plural = if count == 1 { "" } else { "s" };
            ui.small(format!("{count} setting{plural} changed from the scene's"))
                .on_hover_text(model.changed_settings.join("\n"));
            if ui.small_button("reset").on_hover_text("Every setting back to what the scene file says.").clicked() {
                output.actions.push(Action::ResetSettings);
            }
        });
    }
    error_budget(ui, model.error_budget, output);
    egui::CollapsingHeader::new(egui::RichText::new("lights").strong()).id_salt("lights").show(ui, |ui| {
        output.lights_edited |= scene_panel::lights_ui(ui, &mut model.scene.scene.lights);
    });
    let picked = model.scene.picked;
    egui::CollapsingHeader::new(egui::RichText::new("material").strong()).id_salt("material").default_open(true).show(
        ui,
        |ui| match picked {
            Some(picked) => {
                let object = model.scene.scene.objects.get(picked.object).map_or("?", |o| o.name.as_str()).to_string();
                if let Some(material) = model.scene.scene.materials.get_mut(picked.material) {
                    ui.label(format!("object `{object}`, material `{}`", material.name));
                    output.material_edited |= scene_panel::material_ui(ui, material);
                }
            }
            None => {
                ui.label("Click an object in the view to edit its material.");
            }
        },
    );
    ui.separator();
    let source = model.scene.scene.source.as_ref().map_or("(built in)".to_string(), |p| p.display().to_string());
    ui.label(format!("scene: {source}")).on_hover_text(
        "Drop a .toml scene or a .gltf/.glb/.obj/.ply model on the window to open it; the file is reloaded when it changes.",
    );
    for notice in model.notices.iter().rev().take(3) {
        ui.small(notice);
    }
}

/// The error budget of the view (docs/course/12-error-budget.md): a button that measures it, and
/// the last one measured.
fn error_budget(ui: &mut egui::Ui, report: Option<&str>, output: &mut UiOutput) {
    egui::CollapsingHeader::new(egui::RichText::new("error budget").strong()).id_salt("error budget").show(ui, |ui| {
        let hint = "What each of the rasterizer's approximations costs, each swapped for its traced term: the \
                    view drawn ten times or so and traced once (seconds; the window waits).";
        if ui.button("measure the view").on_hover_text(hint).clicked() {
            output.actions.push(Action::Budget);
        }
        if let Some(report) = report {
            ui.label(egui::RichText::new(report).monospace().small());
        }
    });
}

/// Lab mode's section: the lab, the student's file, what the view shows, the file's problems.
fn lab_section(ui: &mut egui::Ui, lab: &LabPanel, output: &mut UiOutput) {
    ui.label(egui::RichText::new(format!("lab `{}`", lab.name)).strong()).on_hover_text(lab.title);
    ui.small(format!("{}: {}", lab.file.display(), lab.how));
    ui.horizontal(|ui| {
        for &shown in lab.choices {
            let hint = match shown {
                LabShown::Student => "Your functions (the last version that compiled). L switches.",
                LabShown::Reference => "Mirador's own functions: the answer key. L switches.",
                LabShown::Difference => {
                    "The FLIP error map between the reference and yours (black: the same). L switches."
                }
            };
            if ui.selectable_label(lab.shown == shown, shown.label()).on_hover_text(hint).clicked() {
                output.lab_shown = Some(shown);
            }
        }
    });
    if lab.problems.is_empty() {
        ui.small("Compiles.");
    } else {
        ui.colored_label(ui.visuals().error_fg_color, format!("Does not compile: {} drawn.", lab.fallback));
    }
    let running = lab.checking.is_some_and(super::lab::Checking::running);
    let check = ui.add_enabled(!running, egui::Button::new("Check")).on_hover_text(
        "Run the lab's tests on your file as it is now: each function on known inputs, then the lab's \
         scenes drawn with it against Mirador's and the ray tracer's images.",
    );
    output.lab_check |= check.clicked();
    if let Some(checking) = lab.checking {
        checking.show(ui);
    }
}

/// The frame budget while the camera moves: a frame rate to hold and the lowest render scale.
fn motion_budget(ui: &mut egui::Ui, view: &mut ViewState) {
    use super::budget::{DEFAULT_MOTION_FPS, MOTION_FPS, MOTION_SCALES};
    ui.horizontal(|ui| {
        let mut hold = view.motion_fps > 0.0;
        let checkbox = ui.checkbox(&mut hold, "hold").on_hover_text(
            "While the camera moves, lower the render scale as far as needed to hold this frame rate (measured \
             frame times); full resolution again as soon as it stops.",
        );
        if checkbox.changed() {
            view.motion_fps = if hold { DEFAULT_MOTION_FPS } else { 0.0 };
        }
        if hold {
            ui.add(egui::Slider::new(&mut view.motion_fps, MOTION_FPS).step_by(1.0).suffix(" fps"));
        }
        ui.label("while moving");
    });
    ui.horizontal(|ui| {
        ui.add(egui::Slider::new(&mut view.motion_scale, MOTION_SCALES).step_by(0.05)).on_hover_text(
            "The lowest render scale while the camera moves (the scale itself when no frame rate is held): fewer \
             pixels, more frames.",
        );
        ui.label(if view.motion_fps > 0.0 { "lowest scale" } else { "scale when moving" });
    });
}

/// Rounds a rectangle to whole physical pixels, so images drawn into it are pixel-aligned.
fn snap(rect: Rect, pixels_per_point: f32) -> Rect {
    let round =
        |p: Pos2| Pos2::new((p.x * pixels_per_point).round(), (p.y * pixels_per_point).round()) / pixels_per_point;
    Rect::from_min_max(round(rect.min), round(rect.max))
}

fn view(ui: &mut egui::Ui, model: &mut UiModel, output: &mut UiOutput) {
    let ppp = ui.ctx().pixels_per_point();
    let rect = snap(ui.max_rect(), ppp);
    if rect.width() < 1.0 || rect.height() < 1.0 {
        return;
    }
    output.view_rect = Some(rect);
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    camera_input(ui, &response, rect, ppp, output);
    if model.view.inspecting {
        output.inspect = output.pick.take();
    }

    let painter = ui.painter_at(rect);
    let full = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
    // The raster image, under everything; dimmed while it stands in for an image still to come.
    let raster_id = model.raster;
    let raster = |dimmed: bool| {
        let grey = Color32::from_gray(90);
        match raster_id {
            Some(id) => {
                painter.image(id, rect, full, if dimmed { grey } else { Color32::WHITE });
            }
            // Already in the window: darken it to the same grey (egui blends the encoded values).
            None if dimmed => {
                painter.rect_filled(rect, 0.0, Color32::from_black_alpha(255 - grey.r()));
            }
            None => {}
        }
    };
    let traced = model.traced.image.as_ref();
    match model.view.mode {
        ViewMode::Raster => match &model.lab {
            Some(lab) if lab.shown == LabShown::Difference => match lab.difference {
                Some((id, _)) => {
                    painter.image(id, rect, full, Color32::WHITE);
                }
                None => raster(true),
            },
            _ => raster(false),
        },
        ViewMode::Traced => match traced {
            Some(shown) => {
                painter.image(shown.texture.id(), rect, full, Color32::WHITE);
            }
            None => raster(true),
        },
        ViewMode::Split => {
            raster(false);
            let x = (rect.min.x + model.view.split * rect.width()) * ppp;
            let x = x.round() / ppp;
            if let Some(shown) = traced {
                let right = Rect::from_min_max(Pos2::new(x, rect.min.y), rect.max);
                painter.with_clip_rect(right).image(shown.texture.id(), rect, full, Color32::WHITE);
            }
            divider(ui, model, rect, x);
        }
        ViewMode::Difference => match &model.traced.difference {
            Some(shown) if shown.key == model.key => {
                painter.image(shown.texture.id(), rect, full, Color32::WHITE);
            }
            _ => raster(true),
        },
    }
    let cursor = response.hover_pos().map(|p| (p - rect.min) * ppp).map(|p| Vec2::new(p.x, p.y));
    let cursor = model.view.scripted_cursor.or(cursor);
    if model.view.mode == ViewMode::Raster
        && cursor.is_some()
        && let Some(&(pixel, seen)) = model.seen
    {
        latlong_marker(&painter, model, (rect, ppp), (pixel, seen));
    }
    if let Some(inspection) = model.inspection {
        super::inspect::draw(&painter, inspection, &model.scene.scene.camera, (rect, ppp));
    }
    output.cursor = cursor;
    if cursor.is_some()
        && let Some(shown) = model.probe
    {
        volume_probe::show(ui.ctx(), shown, model.settings, (rect, ppp));
    }
    if model.view.overlay_open {
        overlay(ui, model, rect);
    }
    error_boxes(ui, model, rect, output);
}

/// The problems over the 3D view, top left: a lab file that does not compile, a scene that does
/// not load (with a dismiss button).
fn error_boxes(ui: &mut egui::Ui, model: &UiModel, rect: Rect, output: &mut UiOutput) {
    if let Some(lab) = model.lab.as_ref().filter(|lab| !lab.problems.is_empty()) {
        let file = lab.file.file_name().map_or(lab.file.display().to_string(), |f| f.to_string_lossy().into_owned());
        error_box(ui, rect, ("mirador::lab_error", LAB_ERROR_FILL), |ui| {
            let text = format!("{file} does not compile; {} drawn.\n{}", lab.fallback, lab.problems.join("\n"));
            ui.label(egui::RichText::new(text).monospace().color(Color32::WHITE));
        });
    }
    if let Some(error) = model.scene.error.clone() {
        error_box(ui, rect, ("mirador::scene_error", Color32::from_rgb(90, 20, 20)), |ui| {
            ui.colored_label(
                Color32::WHITE,
                format!("The scene could not be loaded; the previous one is kept.\n{error}"),
            );
            if ui.button("dismiss").clicked() {
                output.actions.push(Action::DismissError);
            }
        });
    }
}

/// A box of `fill` over the 3D view `rect`, at its top left, with `content`.
fn error_box(ui: &egui::Ui, rect: Rect, (id, fill): (&str, Color32), content: impl FnOnce(&mut egui::Ui)) {
    egui::Area::new(egui::Id::unique(id)).fixed_pos(rect.min + egui::vec2(12.0, 12.0)).show(ui.ctx(), |ui| {
        egui::Frame::popup(ui.style()).fill(fill).show(ui, |ui| {
            ui.set_max_width(rect.width() - 40.0);
            content(ui);
        });
    });
}

/// The fill behind a lab file's compile error over the view (tests/viewer.rs looks for it).
pub const LAB_ERROR_FILL: Color32 = Color32::from_rgb(110, 16, 16);

/// Mouse over the 3D view: drags, wheel and clicks, in pixels of the full-resolution image.
fn camera_input(ui: &egui::Ui, response: &egui::Response, rect: Rect, ppp: f32, output: &mut UiOutput) {
    let delta = response.drag_delta() * ppp;
    let delta = Vec2::new(delta.x, delta.y);
    if response.dragged_by(egui::PointerButton::Primary) {
        output.camera.rotate = delta;
    }
    if response.dragged_by(egui::PointerButton::Secondary) || response.dragged_by(egui::PointerButton::Middle) {
        output.camera.pan = delta;
    }
    if response.hovered() {
        // egui gives a wheel notch as 50 points of scroll.
        output.camera.zoom = ui.input(|i| i.smooth_scroll_delta.y) / 50.0;
    }
    output.camera.dt = ui.input(|i| i.stable_dt).min(0.1);
    if response.clicked()
        && let Some(pos) = response.interact_pointer_pos()
    {
        let p = (pos - rect.min) * ppp;
        output.pick = Some(Vec2::new(p.x, p.y));
    }
}

/// The colour of the lat–long view's marker: no sky, ground or environment map is magenta.
pub(in crate::viewer) const MARKER_COLOUR: Color32 = Color32::from_rgb(255, 0, 255);

/// On the inset lat–long view (`environment.view = "latlong"`, `environment.inset`), marks `seen`,
/// the direction the environment is seen in at view pixel `pixel` (found before the layout,
/// `super::seen`): the reflected direction of the surface there, or the view ray over the
/// background. The map is the world's, in world coordinates, so the mark lands where the mirror
/// reads it (a dynamic cube reads the same direction from its own images).
fn latlong_marker(
    painter: &egui::Painter,
    model: &UiModel,
    (rect, ppp): (Rect, f32),
    (pixel, seen): (Vec2, SeenDirection),
) {
    let size = ((rect.width() * ppp).round() as u32, (rect.height() * ppp).round() as u32);
    let [x, y, w, h] = crate::raster::environment::view_rect(size, 2.0, true);
    let map = Rect::from_min_size(rect.min + egui::vec2(x, y) / ppp, egui::vec2(w, h) / ppp);
    let at = rect.min + egui::vec2(pixel.x, pixel.y) / ppp;
    if map.contains(at) {
        return;
    }
    let uv = crate::scene::environment::latlong_uv(seen.direction);
    let mark = map.min + egui::vec2(uv.x * map.width(), uv.y * map.height());
    let stroke = |width: f32, colour: Color32| egui::Stroke::new(width, colour);
    for (width, colour) in [(4.0, Color32::BLACK), (2.0, MARKER_COLOUR)] {
        painter.circle_stroke(mark, 7.0, stroke(width, colour));
        painter.line_segment([mark - egui::vec2(12.0, 0.0), mark - egui::vec2(4.0, 0.0)], stroke(width, colour));
        painter.line_segment([mark + egui::vec2(4.0, 0.0), mark + egui::vec2(12.0, 0.0)], stroke(width, colour));
    }
    painter.circle_stroke(at, 4.0, stroke(2.0, MARKER_COLOUR));
    let d = seen.direction;
    let what = match seen.object.and_then(|o| model.scene.scene.objects.get(o)) {
        Some(object) => format!("r reflected by `{}`", object.name),
        None => "the view ray (background)".to_string(),
    };
    let text = format!("{what}\n({:+.2}, {:+.2}, {:+.2})", d.x, d.y, d.z);
    let font = egui::FontId::proportional(12.0);
    let anchor = Pos2::new(map.min.x + 4.0, map.min.y - 4.0);
    painter.text(anchor + egui::vec2(1.0, 1.0), egui::Align2::LEFT_BOTTOM, &text, font.clone(), Color32::BLACK);
    painter.text(anchor, egui::Align2::LEFT_BOTTOM, &text, font, Color32::WHITE);
}

/// The split view's divider: a line you can drag.
fn divider(ui: &mut egui::Ui, model: &mut UiModel, rect: Rect, x: f32) {
    let handle = Rect::from_min_max(Pos2::new(x - 5.0, rect.min.y), Pos2::new(x + 5.0, rect.max.y));
    let response = ui
        .interact(handle, ui.scope_id().with("split_divider"), Sense::drag())
        .on_hover_cursor(egui::CursorIcon::ResizeHorizontal);
    if response.dragged()
        && let Some(pointer) = response.interact_pointer_pos()
    {
        model.view.split = ((pointer.x - rect.min.x) / rect.width()).clamp(0.0, 1.0);
    }
    let painter = ui.painter_at(rect);
    let stroke = egui::Stroke::new(if response.hovered() || response.dragged() { 3.0 } else { 1.0 }, Color32::WHITE);
    painter.vline(x, rect.y_range(), stroke);
    let font = egui::FontId::proportional(13.0);
    let shadowed = |pos: Pos2, align, text: &str| {
        painter.text(pos + egui::vec2(1.0, 1.0), align, text, font.clone(), Color32::BLACK);
        painter.text(pos, align, text, font.clone(), Color32::WHITE);
    };
    shadowed(Pos2::new(x - 8.0, rect.max.y - 8.0), egui::Align2::RIGHT_BOTTOM, "raster");
    shadowed(Pos2::new(x + 8.0, rect.max.y - 8.0), egui::Align2::LEFT_BOTTOM, "ray traced");
}

/// Frame times, the traced image's progress and the difference's mean, in the view's top-right
/// corner: what the last frame cost. It asks for no frame itself: frames come only when something
/// changes.
fn overlay(ui: &egui::Ui, model: &UiModel, rect: Rect) {
    let mut text = model.stats.overlay_text();
    for pass in model.passes {
        text += &format!("\n  {}", pass.name);
        if let Some(time) = pass.time {
            text += &format!(" {:.1} ms", time.as_secs_f64() * 1e3);
        }
        for (figure, value) in &pass.figures {
            text += &format!(", {figure} {value}");
        }
    }
    text += &format!(
        "\nview: {}  ({})",
        model.view.mode.label(),
        match model.navigation {
            Navigation::Orbit => "orbit",
            Navigation::Fly => "fly",
        }
    );
    if model.view.mode.needs_traced() {
        text += &match model.traced.image.as_ref() {
            Some(shown) if shown.key == model.key && shown.complete => {
                format!("\ntraced: complete in {:.2} s", shown.elapsed.as_secs_f64())
            }
            Some(shown) if shown.key == model.key => {
                format!("\ntraced: 1 ray per {0}×{0} pixels, {1:.2} s", shown.block, shown.elapsed.as_secs_f64())
            }
            _ => "\ntraced: starting…".to_string(),
        };
    }
    if let Some(lab) = &model.lab {
        text += &format!("\nlab: {}", lab.shown.label());
        if lab.shown == LabShown::Difference {
            text += &match lab.difference {
                Some((_, mean)) => format!(", {} mean {mean:.4} against the reference", crate::compare::METRIC),
                None => ", waiting for the image at full scale".to_string(),
            };
        }
    }
    if model.view.mode == ViewMode::Difference {
        text += &match &model.traced.difference {
            Some(d) if d.key == model.key => format!("\n{} mean {:.4}", crate::compare::METRIC, d.flip_mean),
            _ => format!("\n{}: waiting for the complete traced image", crate::compare::METRIC),
        };
    }
    // Shadowed text, no panel behind it: a filled panel costs egui about 3 ms a frame on a
    // software GPU, every frame the view changes under it (docs/performance.md).
    let painter = ui.painter_at(rect);
    let galley = painter.layout_no_wrap(text, egui::FontId::monospace(12.0), Color32::WHITE);
    let at = Pos2::new(rect.max.x - 10.0 - galley.size().x, rect.min.y + 10.0);
    painter.galley_with_override_text_color(at + egui::vec2(1.0, 1.0), galley.clone(), Color32::BLACK);
    painter.galley(at, galley, Color32::WHITE);
}
