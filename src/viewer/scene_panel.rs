//! The scene's own editors: the seed camera (eye, center, up, fovy, near, far), the lights
//! (type, position, direction, colour, intensity) and the picked object's material (the
//! illumination model's coefficients and colours). Edits are checked before they are kept: a
//! camera that cannot form an image is shown with its error and not applied.

use glam::Vec3;

use crate::scene::{Camera, Light, LightKind, Material};

fn vec3_ui(ui: &mut egui::Ui, name: &str, v: &mut Vec3, speed: f32, tip: &str) -> bool {
    ui.horizontal(|ui| {
        let mut changed = false;
        for c in 0..3 {
            changed |=
                ui.add(egui::DragValue::new(&mut v[c]).speed(speed).max_decimals(3)).on_hover_text(tip).changed();
        }
        ui.label(name).on_hover_text(tip);
        changed
    })
    .inner
}

fn number_ui(ui: &mut egui::Ui, name: &str, x: &mut f32, range: std::ops::RangeInclusive<f32>, tip: &str) -> bool {
    ui.horizontal(|ui| {
        let speed = ((range.end() - range.start()) / 500.0).clamp(1e-3, 1.0);
        let changed =
            ui.add(egui::DragValue::new(x).range(range).speed(speed).max_decimals(3)).on_hover_text(tip).changed();
        ui.label(name).on_hover_text(tip);
        changed
    })
    .inner
}

fn colour_ui(ui: &mut egui::Ui, name: &str, c: &mut Vec3, tip: &str) -> bool {
    ui.horizontal(|ui| {
        let mut rgb = c.to_array();
        // Colours above 1 (bright emitters) keep their size; the picker edits the hue.
        let scale = rgb.iter().copied().fold(1.0_f32, f32::max);
        let mut unit = rgb.map(|x| x / scale);
        let mut changed = ui.color_edit_button_rgb(&mut unit).on_hover_text(tip).changed();
        if changed {
            rgb = unit.map(|x| x * scale);
        }
        for x in &mut rgb {
            changed |= ui.add(egui::DragValue::new(x).range(0.0..=100.0).speed(0.01).max_decimals(3)).changed();
        }
        ui.label(name).on_hover_text(tip);
        *c = Vec3::from(rgb);
        changed
    })
    .inner
}

/// The camera's parameters; returns whether a valid change was made. `error` keeps the reason an
/// edit was refused.
pub(in crate::viewer) fn camera_ui(ui: &mut egui::Ui, camera: &mut Camera, error: &mut Option<String>) -> bool {
    let mut edited = camera.clone();
    let mut changed = false;
    changed |= vec3_ui(ui, "eye", &mut edited.eye, 0.05, "Where the eye is: the origin of the primary rays.");
    changed |= vec3_ui(ui, "center", &mut edited.center, 0.05, "The point looked at: ze = normalize(eye − center).");
    changed |= vec3_ui(ui, "up", &mut edited.up, 0.01, "Which way is up: xe = normalize(up × ze), ye = ze × xe.");
    changed |= number_ui(
        ui,
        "fovy",
        &mut edited.fovy_degrees,
        1.0..=179.0,
        "Vertical field of view in degrees: h = 2·near·tan(fovy/2).",
    );
    changed |=
        number_ui(ui, "near", &mut edited.near, 1e-4..=1e4, "Distance of the near plane, where the view window lies.");
    changed |= number_ui(
        ui,
        "far",
        &mut edited.far,
        1e-3..=1e6,
        "Distance of the far clipping plane (the z-buffer's depth range).",
    );
    if !changed {
        return false;
    }
    match edited.validate() {
        Ok(()) => {
            *camera = edited;
            *error = None;
            true
        }
        Err(e) => {
            *error = Some(e.to_string());
            false
        }
    }
}

fn kind_name(kind: &LightKind) -> &'static str {
    match kind {
        LightKind::Point { .. } => "point",
        LightKind::Directional { .. } => "directional",
        LightKind::Spot { .. } => "spot",
    }
}

/// The same light as another type, keeping what the two share.
fn with_kind(kind: &LightKind, name: &str) -> LightKind {
    let (position, direction) = match *kind {
        LightKind::Point { position } => (position, Vec3::NEG_Y),
        LightKind::Directional { direction } => (-direction * 10.0, direction),
        LightKind::Spot { position, direction, .. } => (position, direction),
    };
    match name {
        "point" => LightKind::Point { position },
        "directional" => LightKind::Directional { direction },
        _ => LightKind::Spot { position, direction, inner: 0.3, outer: 0.5 },
    }
}

/// Every light's type, position, direction, colour and intensity; returns whether any changed.
pub(in crate::viewer) fn lights_ui(ui: &mut egui::Ui, lights: &mut [Light]) -> bool {
    let mut changed = false;
    for (index, light) in lights.iter_mut().enumerate() {
        let title = if light.name.is_empty() { format!("light {index}") } else { light.name.clone() };
        egui::CollapsingHeader::new(title).id_salt(("light", index)).show(ui, |ui| {
            let current = kind_name(&light.kind);
            egui::ComboBox::from_id_salt(("light kind", index)).selected_text(current).show_ui(ui, |ui| {
                for name in ["point", "directional", "spot"] {
                    if ui.selectable_label(current == name, name).clicked() && current != name {
                        light.kind = with_kind(&light.kind, name);
                        changed = true;
                    }
                }
            });
            let direction_tip = "The direction the light travels (unit); l = −direction at every point.";
            match &mut light.kind {
                LightKind::Point { position } => {
                    changed |=
                        vec3_ui(ui, "position", position, 0.05, "Where the light is; l = normalize(position − p).");
                }
                LightKind::Directional { direction } => {
                    changed |= direction_ui(ui, direction, direction_tip);
                }
                LightKind::Spot { position, direction, inner, outer } => {
                    changed |=
                        vec3_ui(ui, "position", position, 0.05, "Where the light is; l = normalize(position − p).");
                    changed |= direction_ui(ui, direction, "The spot's axis (unit).");
                    let (mut inner_deg, mut outer_deg) = (inner.to_degrees(), outer.to_degrees());
                    let cone = "Full strength within `inner` of the axis, none beyond `outer`, smoothstep between.";
                    if number_ui(ui, "inner (°)", &mut inner_deg, 0.0..=89.0, cone)
                        | number_ui(ui, "outer (°)", &mut outer_deg, 0.1..=90.0, cone)
                    {
                        *inner = inner_deg.min(outer_deg).to_radians();
                        *outer = outer_deg.to_radians();
                        changed = true;
                    }
                }
            }
            changed |= colour_ui(
                ui,
                "colour",
                &mut light.color,
                "The light's linear RGB colour, multiplied by intensity: S_i.",
            );
            changed |= number_ui(
                ui,
                "intensity",
                &mut light.intensity,
                0.0..=1e4,
                "Multiplies the colour: S_i = colour · intensity · fat.",
            );
        });
    }
    changed
}

fn direction_ui(ui: &mut egui::Ui, direction: &mut Vec3, tip: &str) -> bool {
    let mut edited = *direction;
    if vec3_ui(ui, "direction", &mut edited, 0.01, tip)
        && let Some(unit) = edited.try_normalize()
    {
        *direction = unit;
        return true;
    }
    false
}

/// The illumination model's coefficients and colours of one material; returns whether any
/// changed.
pub(in crate::viewer) fn material_ui(ui: &mut egui::Ui, material: &mut Material) -> bool {
    let mut changed = false;
    changed |=
        colour_ui(ui, "colour C", &mut material.color, "C: the surface colour (times its texture) in ka·C and kd·C.");
    changed |= number_ui(ui, "ka", &mut material.ka, 0.0..=1.0, "Ambient coefficient: ka·C per visible light.");
    changed |= number_ui(ui, "kd", &mut material.kd, 0.0..=1.0, "Diffuse coefficient: kd·C·max(0, n·l), Lambert.");
    changed |= number_ui(ui, "ks", &mut material.ks, 0.0..=1.0, "Specular coefficient: ks·S·max(0, r·v)^e, Phong.");
    changed |= colour_ui(
        ui,
        "specular S",
        &mut material.specular_color,
        "S: the highlight's colour (white for plastics, the base colour for metals).",
    );
    changed |= number_ui(
        ui,
        "shininess e",
        &mut material.shininess,
        0.0..=10000.0,
        "Phong exponent e: larger gives a smaller, sharper highlight.",
    );
    changed |= colour_ui(ui, "emission ME", &mut material.emission, "ME: radiance the surface emits by itself.");
    changed |= number_ui(
        ui,
        "mirror kps",
        &mut material.mirror,
        0.0..=1.0,
        "kps·MPS·L(r): perfect mirror reflection (traced; the rasterizer's planar mirrors later).",
    );
    changed |= colour_ui(ui, "mirror MPS", &mut material.mirror_color, "MPS: the colour of the mirror reflection.");
    changed |= number_ui(
        ui,
        "transmission kt",
        &mut material.transmission,
        0.0..=1.0,
        "kt·MT·L(t): light through the surface; kt > 0 also tints shadows.",
    );
    changed |=
        colour_ui(ui, "transmission MT", &mut material.transmission_color, "MT: the colour of the transmitted light.");
    changed |=
        number_ui(ui, "ior", &mut material.ior, 1.0..=4.0, "Index of refraction: Snell's n_i sin θ_i = n_t sin θ_t.");
    changed |= number_ui(
        ui,
        "bump k",
        &mut material.bump_scale,
        -16.0..=16.0,
        "The bump scale k of du = k·∂f/∂u (with a height map or field).",
    );
    changed
}

/// Applies `key=value` to a material, for scripts (`material kd=0.2`). Colours are `[r, g, b]`.
pub(in crate::viewer) fn set_material(material: &mut Material, assignment: &str) -> Result<(), String> {
    let (key, value) = assignment.split_once('=').ok_or("expected key=value")?;
    let (key, value) = (key.trim(), value.trim());
    let number =
        || value.parse::<f32>().ok().filter(|x| x.is_finite()).ok_or(format!("{key}: `{value}` is not a number"));
    let colour = || -> Result<Vec3, String> {
        let parts: Vec<f32> = value
            .trim_matches(|c| c == '[' || c == ']')
            .split(',')
            .map(|p| p.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("{key}: `{value}` is not [r, g, b]"))?;
        match parts[..] {
            [r, g, b] if parts.iter().all(|x| x.is_finite() && *x >= 0.0) => Ok(Vec3::new(r, g, b)),
            _ => Err(format!("{key}: `{value}` is not [r, g, b] with r, g, b ≥ 0")),
        }
    };
    match key {
        "ka" => material.ka = number()?,
        "kd" => material.kd = number()?,
        "ks" => material.ks = number()?,
        "shininess" => material.shininess = number()?,
        "mirror" => material.mirror = number()?,
        "transmission" => material.transmission = number()?,
        "ior" => material.ior = number()?,
        "bump_scale" => material.bump_scale = number()?,
        "color" => material.color = colour()?,
        "specular_color" => material.specular_color = colour()?,
        "emission" => material.emission = colour()?,
        "mirror_color" => material.mirror_color = colour()?,
        "transmission_color" => material.transmission_color = colour()?,
        _ => return Err(format!("`{key}` is not a material field")),
    }
    Ok(())
}
