//! Overrides of a scene file's own values, as `--set` gives them: the camera
//! (`camera.fovy=30`), the world (`world.ambient=[0.1, 0.1, 0.1]`), each light by index or name
//! (`lights.0.intensity=0.5`, `lights.key.intensity=0.5`), each material by name
//! (`materials.ball.ks=0.8`), each object by index or name (`objects.2.center=[0, 1, 0]`) and the
//! settings (`settings.shadows.fit="scene"`). So an exercise's "move the light, change ks"
//! needs no edit of the course's file.
//!
//! Each override is written into the scene's TOML before the scene is read, so it is checked as
//! the file is (an unknown field is refused with the names the table accepts); an error names the
//! override, and an unknown light, material or object is answered with the ones the scene has.

use std::path::Path;

use super::{SceneError, parse};
use crate::scene::Scene;

/// The tables of a scene file an override may reach.
pub const ROOTS: [&str; 6] = ["camera", "world", "lights", "materials", "objects", "settings"];

/// Whether `assignment` (`key=value`) overrides the scene file's own values rather than a render
/// setting: its key starts with one of [`ROOTS`].
pub fn is_scene_override(assignment: &str) -> bool {
    let key = assignment.split('=').next().unwrap_or("").trim();
    ROOTS.contains(&key.split('.').next().unwrap_or(""))
}

/// Reads the scene file at `path` with every override of `assignments` applied, in order; a
/// model file (no TOML of its own to change) is refused with what to do instead.
pub fn load(path: &Path, assignments: &[String]) -> Result<Scene, SceneError> {
    if assignments.is_empty() {
        return super::load(path);
    }
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
        return Err(SceneError::Invalid {
            path: path.into(),
            message: format!(
                "`--set {}`: a model file has no scene values to override (camera, lights, materials, \
                 objects, world): write a TOML scene that names the model (docs/scene-format.md)",
                assignments[0]
            ),
        });
    }
    let text = crate::files::read_to_string(path).map_err(|cause| SceneError::Io { path: path.into(), cause })?;
    parse_with(&text, path, assignments)
}

/// Reads the TOML scene `text` (from `path`, which anchors its relative paths) with every
/// override of `assignments` applied, in order.
pub fn parse_with(text: &str, path: &Path, assignments: &[String]) -> Result<Scene, SceneError> {
    let Ok(mut table) = toml::from_str::<toml::Table>(text) else {
        // Not TOML: the plain parse says where and why.
        return parse(text, path);
    };
    let invalid = |assignment: &str, message: String| SceneError::Invalid {
        path: path.into(),
        message: format!("`--set {assignment}`: {message}"),
    };
    for assignment in assignments {
        apply(&mut table, assignment).map_err(|message| invalid(assignment, message))?;
    }
    let overridden = toml::to_string(&table).map_err(|e| invalid(&assignments.join(" "), e.to_string()))?;
    parse(&overridden, path).map_err(|error| {
        // A scene that does not read without the overrides says so itself.
        if let Err(error) = parse(text, path) {
            return error;
        }
        // Name the override that broke the scene: the first after which it no longer reads.
        let culprit = (1..=assignments.len())
            .find(|&n| {
                let mut partial = toml::from_str::<toml::Table>(text).expect("parsed above");
                assignments[..n].iter().all(|a| apply(&mut partial, a).is_ok())
                    && toml::to_string(&partial).is_ok_and(|t| parse(&t, path).is_err())
            })
            .map_or_else(|| assignments.join(" --set "), |n| assignments[n - 1].clone());
        let message = match error {
            SceneError::Syntax { message, .. } | SceneError::Invalid { message, .. } => message,
            other => return other,
        };
        invalid(&culprit, message)
    })
}

/// Writes one `key=value` into the scene's table.
fn apply(table: &mut toml::Table, assignment: &str) -> Result<(), String> {
    let (key, value) = assignment.split_once('=').ok_or("not of the form key=value")?;
    let value = value.trim();
    let value: toml::Value = toml::from_str::<toml::Table>(&format!("v = {value}"))
        .map(|mut t| t.remove("v").expect("parsed from `v = …`"))
        .unwrap_or_else(|_| toml::Value::String(value.into()));
    let parts: Vec<&str> = key.trim().split('.').collect();
    let (root, rest) = parts.split_first().expect("split yields one part");
    if !ROOTS.contains(root) {
        return Err(format!("a scene has no `{root}`; overrides reach {}", ROOTS.join(", ")));
    }
    let (target, path) = match *root {
        "lights" | "objects" => (element(table, root, rest)?, &rest[1..]),
        "materials" => (material(table, rest)?, &rest[1..]),
        _ => (entry_table(table, root)?, rest),
    };
    let (last, within) = path.split_last().ok_or_else(|| format!("name a field of `{}`", key.trim()))?;
    let mut slot = target;
    for part in within {
        slot = entry_table(slot, part)?;
    }
    slot.insert(last.to_string(), value);
    Ok(())
}

/// The table `name` inside `table`, made when the file has none (`[settings.shadows]`).
fn entry_table<'t>(table: &'t mut toml::Table, name: &str) -> Result<&'t mut toml::Table, String> {
    match table.entry(name.to_string()).or_insert_with(|| toml::Value::Table(toml::Table::new())) {
        toml::Value::Table(inner) => Ok(inner),
        other => Err(format!("`{name}` is a {}, not a table", other.type_str())),
    }
}

/// Light or object `rest[0]` of the array `root`: by index, or by its `name`.
fn element<'t>(table: &'t mut toml::Table, root: &str, rest: &[&str]) -> Result<&'t mut toml::Table, String> {
    let which = rest.first().ok_or_else(|| format!("name one of the {root} by index or name: `{root}.0.…`"))?;
    let Some(toml::Value::Array(elements)) = table.get_mut(root) else {
        return Err(format!("the scene has no {root}"));
    };
    let names: Vec<String> = elements
        .iter()
        .enumerate()
        .map(|(k, e)| e.get("name").and_then(|n| n.as_str()).map_or(format!("{k}"), |n| format!("{k} (`{n}`)")))
        .collect();
    let index = match which.parse::<usize>() {
        Ok(index) => Some(index).filter(|&i| i < elements.len()),
        Err(_) => elements.iter().position(|e| e.get("name").and_then(|n| n.as_str()) == Some(which)),
    };
    let Some(index) = index else {
        return Err(format!("the scene has no {root} `{which}`; it has {}", names.join(", ")));
    };
    elements[index].as_table_mut().ok_or_else(|| format!("{root} {index} is not a table"))
}

/// Material `rest[0]`, by its name.
fn material<'t>(table: &'t mut toml::Table, rest: &[&str]) -> Result<&'t mut toml::Table, String> {
    let name = rest.first().ok_or("name a material: `materials.NAME.…`")?;
    let materials = entry_table(table, "materials")?;
    let known: Vec<String> = materials.keys().map(|k| format!("`{k}`")).collect();
    match materials.get_mut(*name) {
        Some(toml::Value::Table(material)) => Ok(material),
        _ => Err(format!("the scene has no material `{name}`; it has {}", known.join(", "))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"
        [camera]
        eye = [0, 1, 5]
        center = [0, 0, 0]
        fovy = 45
        [materials.red]
        color = [0.8, 0.1, 0.1]
        [[lights]]
        name = "key"
        type = "point"
        position = [0, 4, 0]
        [[objects]]
        name = "ball"
        type = "sphere"
        radius = 1
        material = "red"
    "#;

    fn overridden(assignments: &[&str]) -> Result<Scene, SceneError> {
        let assignments: Vec<String> = assignments.iter().map(|a| a.to_string()).collect();
        parse_with(TEXT, Path::new("inline.toml"), &assignments)
    }

    #[test]
    fn overrides_reach_the_camera_lights_materials_objects_and_settings() {
        let scene = overridden(&[
            "camera.fovy=30",
            "lights.0.intensity=0.5",
            "lights.key.position=[1, 5, 0]",
            "materials.red.ks=0.8",
            "objects.ball.radius=2",
            "settings.shadows.enabled=false",
        ])
        .unwrap();
        assert_eq!(scene.camera.fovy_degrees, 30.0);
        assert_eq!(scene.lights[0].intensity, 0.5);
        assert_eq!(scene.lights[0].position(), Some(glam::Vec3::new(1.0, 5.0, 0.0)));
        assert_eq!(scene.materials[0].ks, 0.8);
        assert!(matches!(scene.objects[0].shape, crate::scene::Shape::Sphere { radius, .. } if radius == 2.0));
        assert!(!scene.settings.shadows.enabled);
    }

    #[test]
    fn a_bad_override_is_named_with_what_the_scene_has() {
        let message = |assignments: &[&str]| overridden(assignments).unwrap_err().to_string();
        let unknown = message(&["camera.fovyy=30"]);
        assert!(unknown.contains("`--set camera.fovyy=30`") && unknown.contains("fovy"), "{unknown}");
        let light = message(&["lights.fill.intensity=1"]);
        assert!(light.contains("no lights `fill`") && light.contains("0 (`key`)"), "{light}");
        let material = message(&["materials.blue.ks=1"]);
        assert!(material.contains("no material `blue`") && material.contains("`red`"), "{material}");
        let root = message(&["camera2.fovy=1"]);
        assert!(root.contains("camera, world, lights"), "{root}");
        let range = message(&["lights.3.intensity=1"]);
        assert!(range.contains("no lights `3`"), "{range}");
        // Checked as the file is: a nan, a wrong type; the culprit among several is named.
        let nan = message(&["camera.fovy=45", "camera.fovy=nan"]);
        assert!(nan.contains("`--set camera.fovy=nan`"), "{nan}");
        let typed = message(&["materials.red.ks=\"shiny\""]);
        assert!(typed.contains("ks") || typed.contains("shiny"), "{typed}");
    }
}
