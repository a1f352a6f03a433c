//! The settings panel, generated from `RenderSettings` itself.
//!
//! The settings are serialized to a TOML table and walked: each nested table is one collapsible
//! section (a technique), its `enabled` switch drawn in the section's header; a boolean becomes
//! a checkbox, a number a drag value (its range from `settings_doc`), a string a combo box of the
//! enum's choices. A change is written back as `key=value` through `RenderSettings::set`, the
//! mechanism behind `--set`, so the panel can set nothing the command line could not, and a new
//! technique's section appears here with no change to the viewer. Tooltips, choices and ranges
//! come from each setting's one description beside its field (`src/settings/`), through
//! `settings_doc`.

use egui::collapsing_header::CollapsingState;

use crate::RenderSettings;
use crate::settings::HybridSettings;
use crate::settings_doc::{FieldDoc, describe};

/// The name a key shows: its last part, words separated (`shadows.map_size` → "map size").
fn label(key: &str) -> String {
    key.rsplit('.').next().unwrap_or(key).replace('_', " ")
}

fn tooltip(key: &str) -> FieldDoc {
    describe(key).unwrap_or(FieldDoc { tooltip: "(no description)".into(), choices: Vec::new(), range: None })
}

/// Draws the settings, one section per technique; returns the assignments (`key=value`) the user
/// made this frame, to be applied with `RenderSettings::set`.
pub(in crate::viewer) fn settings_ui(ui: &mut egui::Ui, settings: &RenderSettings) -> Vec<String> {
    let mut changes = Vec::new();
    let Ok(table) = toml::Table::try_from(settings) else {
        ui.colored_label(ui.visuals().error_fg_color, "the settings cannot be shown");
        return changes;
    };
    // Top-level numbers and switches (exposure, tessellation) share one "general" section.
    let general: Vec<(&String, &toml::Value)> = table.iter().filter(|(_, v)| !v.is_table()).collect();
    if !general.is_empty() {
        egui::CollapsingHeader::new("general").id_salt("settings.general").default_open(true).show(ui, |ui| {
            for (name, value) in general {
                field(ui, name, value, &mut changes);
            }
        });
    }
    for (name, value) in &table {
        if let toml::Value::Table(section) = value {
            let traced = HybridSettings::choice_of(name);
            let traced = traced.and_then(|switch| Some((switch, table.get("hybrid")?.get(switch)?.as_bool()?)));
            section_ui(ui, name, section, traced, &mut changes);
        }
    }
    changes
}

/// A technique's traced choice: the hybrid's switch that replaces its approximation by the
/// tracer's term (docs/course/12-error-budget.md), shown in the technique's own section.
fn traced_choice(ui: &mut egui::Ui, (switch, on): (&str, bool), changes: &mut Vec<String>) {
    let key = format!("hybrid.{switch}");
    let mut on = on;
    if ui.checkbox(&mut on, format!("traced ({key})")).on_hover_text(tooltip(&key).tooltip).changed() {
        changes.push(format!("{key}={on}"));
    }
}

/// One technique: a collapsible section with its switch in the header, and its traced choice
/// first where the hybrid has one.
fn section_ui(
    ui: &mut egui::Ui,
    key: &str,
    section: &toml::Table,
    traced: Option<(&str, bool)>,
    changes: &mut Vec<String>,
) {
    let id = ui.make_persistent_id(("settings", key));
    let doc = tooltip(key);
    CollapsingState::load_with_default_open(ui.ctx(), id, false)
        .show_header(ui, |ui| match section.get("enabled") {
            Some(toml::Value::Boolean(enabled)) => {
                let mut on = *enabled;
                if ui.checkbox(&mut on, egui::RichText::new(label(key)).strong()).on_hover_text(&doc.tooltip).changed()
                {
                    changes.push(format!("{key}.enabled={on}"));
                }
            }
            _ => {
                ui.label(egui::RichText::new(label(key)).strong()).on_hover_text(&doc.tooltip);
            }
        })
        .body(|ui| {
            if let Some(traced) = traced {
                traced_choice(ui, traced, changes);
            }
            for (name, value) in section {
                let child = format!("{key}.{name}");
                match value {
                    toml::Value::Table(inner) => section_ui(ui, &child, inner, None, changes),
                    _ if name == "enabled" => {}
                    _ => field(ui, &child, value, changes),
                }
            }
        });
}

/// One setting's control; pushes `key=value` when the user changes it.
fn field(ui: &mut egui::Ui, key: &str, value: &toml::Value, changes: &mut Vec<String>) {
    let doc = tooltip(key);
    let name = label(key);
    ui.horizontal(|ui| {
        let changed: Option<toml::Value> = match value {
            toml::Value::Boolean(on) => {
                let mut on = *on;
                ui.checkbox(&mut on, name.as_str())
                    .on_hover_text(&doc.tooltip)
                    .changed()
                    .then_some(toml::Value::Boolean(on))
            }
            toml::Value::Integer(n) => {
                let mut n = *n;
                let (low, high) = doc.range.unwrap_or((i64::MIN as f64, i64::MAX as f64));
                let speed = ((high - low) / 400.0).clamp(0.05, 16.0);
                let response = ui.add(egui::DragValue::new(&mut n).range(low as i64..=high as i64).speed(speed));
                ui.label(name.as_str()).on_hover_text(&doc.tooltip);
                response.on_hover_text(&doc.tooltip).changed().then_some(toml::Value::Integer(n))
            }
            toml::Value::Float(x) => {
                let mut x = *x;
                let (low, high) = doc.range.unwrap_or((-1e6, 1e6));
                let speed = ((high - low) / 1000.0).clamp(1e-3, 10.0);
                let response = ui.add(egui::DragValue::new(&mut x).range(low..=high).speed(speed).max_decimals(3));
                ui.label(name.as_str()).on_hover_text(&doc.tooltip);
                response.on_hover_text(&doc.tooltip).changed().then_some(toml::Value::Float(x))
            }
            toml::Value::String(current) => {
                let mut chosen = None;
                egui::ComboBox::from_id_salt(key)
                    .selected_text(current.replace('_', " "))
                    .show_ui(ui, |ui| {
                        for choice in &doc.choices {
                            let mut item =
                                ui.selectable_label(*current == choice.value, choice.value.replace('_', " "));
                            if let Some(help) = &choice.help {
                                item = item.on_hover_text(help);
                            }
                            if item.clicked() && *current != choice.value {
                                chosen = Some(toml::Value::String(choice.value.clone()));
                            }
                        }
                    })
                    .response
                    .on_hover_text(&doc.tooltip);
                ui.label(name.as_str()).on_hover_text(&doc.tooltip);
                chosen
            }
            other => {
                ui.label(format!("{name}: {other}")).on_hover_text(&doc.tooltip);
                None
            }
        };
        if let Some(value) = changed {
            changes.push(format!("{key}={value}"));
        }
    });
}
