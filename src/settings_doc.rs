//! What every render setting means, as the viewer's panel and the documentation show it.
//!
//! Nothing here is written by hand: each setting's meaning, accepted values and unit are declared
//! once beside its field (`src/settings/`, see [`crate::settings::field`]), and this module turns
//! them into the panel's tooltips, choices and slider ranges ([`describe`], keyed by the dotted
//! path `--set` uses) and into the settings table of docs/scene-format.md
//! ([`scene_format_table`]; `tests/settings_docs.rs` fails when the file's table differs, and
//! rewrites it with `MIRADOR_BLESS=1`).

use crate::RenderSettings;
use crate::settings::field::{self, Field, Kind};

pub use crate::settings::field::{Choice, choices_of};

/// What the panel needs to know about one setting or section.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldDoc {
    /// One line of plain text: what the setting changes, in the formula's or the course's terms,
    /// then the values it accepts.
    pub tooltip: String,
    /// For enum settings, every value they accept (empty otherwise).
    pub choices: Vec<Choice>,
    /// For numbers, the inclusive range the panel's control allows: the accepted range, or the
    /// slider stated for a number whose range is open.
    pub range: Option<(f64, f64)>,
}

/// The description of the setting or section at the dotted path `key`, `None` for unknown keys.
pub fn describe(key: &str) -> Option<FieldDoc> {
    let field = RenderSettings::field(key)?;
    let mut tooltip = plain(&field.meaning());
    if let Some(values) = field.values.summary() {
        tooltip.push_str(&format!(" ({values})"));
    }
    let choices = match field.kind {
        Kind::Choice(choices) => {
            choices().into_iter().map(|c| Choice { help: c.help.as_deref().map(plain), ..c }).collect()
        }
        _ => Vec::new(),
    };
    Some(FieldDoc { tooltip, choices, range: field.values.slider_range() })
}

/// Markdown as plain text for a tooltip: code spans lose their backticks.
fn plain(markdown: &str) -> String {
    markdown.replace('`', "")
}

/// The table of every setting in docs/scene-format.md: key, type with the accepted values, default
/// (`RenderSettings::default()`) and meaning, each enum's choices with their help.
pub fn scene_format_table() -> String {
    let mut table = String::from("| Key | Type | Default | Meaning |\n|-----|------|---------|---------|\n");
    let defaults = RenderSettings::default();
    field::walk(RenderSettings::FIELDS, &defaults, "", &mut |key, field, value| {
        if !matches!(field.kind, Kind::Section(_)) {
            let row = [format!("`{key}`"), type_of(field), format!("`{}`", value.toml()), meaning_of(field)];
            table.push_str(&format!("| {} |\n", row.map(|cell| cell.replace('|', "\\|")).join(" | ")));
        }
        Ok::<(), ()>(())
    })
    .expect("the visitor never fails");
    table
}

/// `integer, 3 to 4096`, `number, above 0, at most 64 texels`, `string`.
fn type_of(field: &Field) -> String {
    let name = match field.kind {
        Kind::Switch => "boolean",
        Kind::Integer { signed: false } if field.values.accepts == field::Accepts::Any => "integer ≥ 0",
        Kind::Integer { .. } => "integer",
        Kind::Number => "number",
        Kind::Choice(_) => "string",
        Kind::Section(_) => "table",
    };
    match field.values.summary() {
        Some(values) => format!("{name}, {values}"),
        None => name.to_string(),
    }
}

/// The meaning, then each choice with its help: `` `"nearest"`: the nearest texel… ``.
fn meaning_of(field: &Field) -> String {
    let mut meaning = field.meaning();
    if let Kind::Choice(choices) = field.kind {
        for choice in choices() {
            meaning.push_str(&format!(" `\"{}\"`", choice.value));
            if let Some(help) = choice.help {
                meaning.push_str(&format!(": {help}."));
            }
        }
    }
    meaning
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::TextureFilter;

    /// Every dotted key of a serialized value: sections and their settings.
    fn keys(prefix: &str, table: &toml::Table, out: &mut Vec<(String, toml::Value)>) {
        for (name, value) in table {
            let key = if prefix.is_empty() { name.clone() } else { format!("{prefix}.{name}") };
            if let toml::Value::Table(inner) = value {
                keys(&key, inner, out);
            }
            out.push((key, value.clone()));
        }
    }

    fn all_keys() -> Vec<(String, toml::Value)> {
        let table = toml::Table::try_from(RenderSettings::default()).expect("settings serialize");
        let mut all = Vec::new();
        keys("", &table, &mut all);
        all
    }

    #[test]
    fn every_setting_has_a_description() {
        let all = all_keys();
        let missing: Vec<&str> = all.iter().filter(|(k, _)| describe(k).is_none()).map(|(k, _)| k.as_str()).collect();
        assert!(missing.is_empty(), "serde writes keys that `section!` does not describe: {missing:?}");
        let mut described = 0;
        let defaults = RenderSettings::default();
        field::walk(RenderSettings::FIELDS, &defaults, "", &mut |_, _, _| {
            described += 1;
            Ok::<(), ()>(())
        })
        .unwrap();
        assert_eq!(described, all.len(), "every description is of a key serde writes");
        for (key, value) in &all {
            let doc = describe(key).expect("checked above");
            assert!(!doc.tooltip.trim().is_empty() && !doc.tooltip.contains('\n'), "{key}: a tooltip is one line");
            match value {
                toml::Value::String(current) => {
                    assert!(!doc.choices.is_empty(), "{key}: a string setting lists its choices");
                    assert!(doc.choices.iter().any(|c| &c.value == current), "{key}: `{current}` is among its choices");
                }
                toml::Value::Integer(_) | toml::Value::Float(_) => {
                    let (low, high) = doc.range.unwrap_or_else(|| panic!("{key}: a number has a slider range"));
                    assert!(low < high, "{key}: the range is not empty");
                }
                _ => {}
            }
        }
    }

    /// The slider offers only accepted values, and only numbers state values.
    #[test]
    fn sliders_lie_within_the_accepted_values() {
        let defaults = RenderSettings::default();
        field::walk(RenderSettings::FIELDS, &defaults, "", &mut |key, field, value| {
            match field.kind {
                Kind::Integer { .. } | Kind::Number => {
                    let (low, high) = field.values.slider_range().expect("checked above");
                    for end in [low, high] {
                        let mut settings = RenderSettings::default();
                        settings.set(&format!("{key}={end}")).unwrap_or_else(|e| panic!("{key}'s slider: {e}"));
                    }
                    value.check(&field.values).unwrap_or_else(|e| panic!("{key}'s default {e}"));
                }
                _ => assert_eq!(field.values, field::Values::ANY, "{key}: only numbers state values"),
            }
            Ok::<(), ()>(())
        })
        .unwrap();
    }

    #[test]
    fn every_choice_is_accepted_by_set() {
        for (key, _) in all_keys().iter().filter(|(_, v)| v.is_str()) {
            for choice in describe(key).expect("described").choices {
                let mut settings = RenderSettings::default();
                settings.set(&format!("{key}=\"{}\"", choice.value)).unwrap_or_else(|e| panic!("{key}: {e}"));
                assert!(choice.help.is_some(), "{key}: `{}` has a doc comment", choice.value);
            }
        }
    }

    #[test]
    fn choices_use_serde_names_and_carry_help() {
        let filters = choices_of::<TextureFilter>();
        let names: Vec<&str> = filters.iter().map(|c| c.value.as_str()).collect();
        assert!(names.contains(&"nearest_mip") && names.contains(&"level_colour"), "{names:?}");
        assert!(filters.iter().all(|c| c.help.is_some()), "every filter has a doc comment");
    }

    #[test]
    fn a_tooltip_is_the_meaning_in_plain_text_with_its_range() {
        let step = describe("volume.step").unwrap();
        assert!(step.tooltip.starts_with("Distance between samples along a ray, in voxels"), "{}", step.tooltip);
        assert!(step.tooltip.ends_with("(0.05 to 8 voxels)"), "{}", step.tooltip);
        assert_eq!(step.range, Some((0.05, 8.0)));
        assert!(!describe("tone_map").unwrap().tooltip.contains('`'));
        assert_eq!(describe("sphere_segments").unwrap().range, Some((3.0, 512.0)), "a stated slider");
        assert!(describe("shadows").unwrap().tooltip.starts_with("Cast shadows"));
        assert!(describe("shadows.nothing").is_none() && describe("exposure.x").is_none());
    }

    #[test]
    fn the_table_has_a_row_per_setting() {
        let table = scene_format_table();
        assert_eq!(table.lines().count(), 2 + all_keys().iter().filter(|(_, v)| !v.is_table()).count());
        assert!(table.contains("| `sphere_segments` | integer, 3 to 4096 | `96` | Slices around"), "{table}");
        assert!(table.contains("| `volume.threshold` | number, above 0, at most 1 | `0.99` |"), "{table}");
        assert!(table.contains("`\"pcf3x3\"`: 3×3 hardware taps."), "{table}");
        assert!(table.contains("`n = ∇f/\\|∇f\\|`"), "a pipe is escaped in a cell");
    }
}
