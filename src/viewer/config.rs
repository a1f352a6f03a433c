//! What the viewer remembers between runs: the window's size, the view mode and divider, the
//! frame budget while moving, and the render settings the user changed, scene by scene. Kept as
//! TOML in the
//! user's configuration directory (`$XDG_CONFIG_HOME/mirador/viewer.toml`, else
//! `~/.config/mirador/viewer.toml`).
//!
//! The frame budget (a target frame rate and the lowest render scale) is the viewer's alone:
//! `render` and `trace` never move a camera, so it is kept here and in the panel's view section,
//! not in `RenderSettings`, whose every key the headless commands and the scene files share.
//!
//! Settings are remembered per scene (its file's path), as the leaves that differ from the
//! scene's own and are put back one by one through `RenderSettings::set` (the mechanism behind
//! `--set`), so a setting that was renamed or removed since is dropped with a warning instead of
//! discarding the rest. A scene opens with its own settings and what was changed in it before,
//! never with another scene's: shadows turned off in one chapter's scene stay on in the next. A
//! file that cannot be read or parsed is ignored with a warning: the viewer starts from defaults.

use std::collections::BTreeMap;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::budget::{DEFAULT_MOTION_FPS, DEFAULT_MOTION_SCALE, MOTION_FPS, MOTION_SCALES};
use super::view_mode::ViewMode;
use crate::RenderSettings;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ViewerConfig {
    /// Inner size of the window in logical pixels.
    pub window: [u32; 2],
    pub mode: ViewMode,
    /// Where the split view's divider sits, as a fraction of the view's width.
    pub split: f32,
    /// The frame rate the render scale holds while the camera moves (0: no target, the scale
    /// is `motion_scale`).
    pub motion_fps: f32,
    /// The lowest render scale while the camera moves (1 = always full resolution).
    pub motion_scale: f32,
    /// Render settings changed from each scene's own, as dotted keys, by [`scene_key`].
    pub scenes: BTreeMap<String, toml::Table>,
}

impl Default for ViewerConfig {
    fn default() -> Self {
        ViewerConfig {
            window: [1280, 720],
            mode: ViewMode::Raster,
            split: 0.5,
            motion_fps: DEFAULT_MOTION_FPS,
            motion_scale: DEFAULT_MOTION_SCALE,
            scenes: BTreeMap::new(),
        }
    }
}

/// `$XDG_CONFIG_HOME/mirador/viewer.toml`, else `$HOME/.config/mirador/viewer.toml`.
pub(in crate::viewer) fn config_path() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").filter(|v| !v.is_empty()).map(|home| Path::new(&home).join(".config")))?;
    Some(base.join("mirador").join("viewer.toml"))
}

/// The key a scene's remembered settings are kept under: its file's full path, or
/// `(built in)` for the showcase.
pub(in crate::viewer) fn scene_key(source: Option<&Path>) -> String {
    match source {
        Some(path) => std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()).display().to_string(),
        None => "(built in)".to_string(),
    }
}

/// Reads the configuration; a missing file gives the defaults silently, an unreadable or corrupt
/// one gives the defaults and a warning naming the file.
pub fn load(path: &Path) -> (ViewerConfig, Option<String>) {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return (ViewerConfig::default(), None),
        Err(e) => return (ViewerConfig::default(), Some(format!("{}: cannot read it ({e}); ignored", path.display()))),
    };
    match toml::from_str::<ViewerConfig>(&text) {
        Ok(mut config) => {
            config.sanitize();
            (config, None)
        }
        Err(e) => {
            let message = e.message().trim().to_string();
            (
                ViewerConfig::default(),
                Some(format!("{}: not a valid viewer configuration ({message}); ignored", path.display())),
            )
        }
    }
}

/// Writes the configuration atomically, creating its directory.
pub fn save(path: &Path, config: &ViewerConfig) -> anyhow::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let text = toml::to_string(config)?;
    crate::output::write_atomically(text.as_bytes(), path)?;
    Ok(())
}

impl ViewerConfig {
    /// Brings remembered numbers back into the ranges the viewer uses.
    fn sanitize(&mut self) {
        self.window = self.window.map(|side| side.clamp(320, 8192));
        if !(self.split.is_finite() && (0.0..=1.0).contains(&self.split)) {
            self.split = 0.5;
        }
        if !(self.motion_scale.is_finite() && MOTION_SCALES.contains(&self.motion_scale)) {
            self.motion_scale = DEFAULT_MOTION_SCALE;
        }
        if !(self.motion_fps == 0.0 || MOTION_FPS.contains(&self.motion_fps)) {
            self.motion_fps = DEFAULT_MOTION_FPS;
        }
    }
}

/// Every leaf of `table` as `(dotted key, value)`.
fn leaves(prefix: &str, table: &toml::Table, out: &mut Vec<(String, toml::Value)>) {
    for (name, value) in table {
        let key = if prefix.is_empty() { name.clone() } else { format!("{prefix}.{name}") };
        match value {
            toml::Value::Table(inner) => leaves(&key, inner, out),
            _ => out.push((key, value.clone())),
        }
    }
}

fn flatten(settings: &RenderSettings) -> Vec<(String, toml::Value)> {
    let table = toml::Table::try_from(settings).expect("render settings serialize to a table");
    let mut out = Vec::new();
    leaves("", &table, &mut out);
    out
}

/// The settings that differ from `defaults`, as a flat table of dotted keys.
pub(in crate::viewer) fn changed_settings(settings: &RenderSettings, defaults: &RenderSettings) -> toml::Table {
    let before = flatten(defaults);
    flatten(settings)
        .into_iter()
        .filter(|(key, value)| before.iter().find(|(k, _)| k == key).is_none_or(|(_, v)| v != value))
        .collect()
}

/// `defaults` with the remembered `changes` applied one by one through `RenderSettings::set`;
/// returns a warning for each change that no longer applies.
pub(in crate::viewer) fn apply_settings(
    defaults: &RenderSettings,
    changes: &toml::Table,
) -> (RenderSettings, Vec<String>) {
    let mut settings = defaults.clone();
    let mut warnings = Vec::new();
    let mut flat = Vec::new();
    leaves("", changes, &mut flat);
    for (key, value) in flat {
        if let Err(e) = settings.set(&format!("{key}={value}")) {
            warnings.push(format!("remembered setting {e}; ignored"));
        }
    }
    (settings, warnings)
}

/// What the viewer remembers of the settings: those changed in each scene opened before, by scene
/// key, and the settings and the scene's own the panel's list of changed settings was made from,
/// with the list.
#[derive(Clone, Debug, Default)]
pub(in crate::viewer) struct Remembered {
    pub scenes: BTreeMap<String, toml::Table>,
    pub changed: (RenderSettings, RenderSettings, Vec<String>),
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temporary(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("mirador-config-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir.join("mirador").join("viewer.toml")
    }

    #[test]
    fn settings_round_trip_as_changes_from_the_defaults() {
        let defaults = RenderSettings::default();
        let mut settings = defaults.clone();
        settings.set("shadows.enabled=false").unwrap();
        settings.set("textures.filter=\"nearest\"").unwrap();
        settings.set("exposure=1.5").unwrap();
        let changes = changed_settings(&settings, &defaults);
        assert_eq!(changes.len(), 3, "{changes:?}");
        let scenes = BTreeMap::from([("/course/a.toml".to_string(), changes)]);
        let config = ViewerConfig { scenes, mode: ViewMode::Split, ..Default::default() };
        let path = temporary("round-trip");
        save(&path, &config).unwrap();
        let (loaded, warning) = load(&path);
        assert_eq!(warning, None);
        assert_eq!(loaded, config);
        let (restored, warnings) = apply_settings(&defaults, &loaded.scenes["/course/a.toml"]);
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(restored, settings);
    }

    #[test]
    fn a_corrupt_or_stale_file_is_ignored_with_a_warning() {
        let path = temporary("corrupt");
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, "window = [1, 2, \nmode = 7").unwrap();
        let (config, warning) = load(&path);
        assert_eq!(config, ViewerConfig::default());
        assert!(warning.unwrap().contains("viewer.toml"));
        std::fs::write(&path, "mode = \"sideways\"").unwrap();
        assert!(load(&path).1.is_some(), "an unknown view mode is reported");
        let missing = temporary("missing");
        assert_eq!(load(&missing), (ViewerConfig::default(), None));

        let mut stale = toml::Table::new();
        stale.insert("shadows.glow".into(), toml::Value::Boolean(true));
        stale.insert("exposure".into(), toml::Value::Float(2.0));
        let (settings, warnings) = apply_settings(&RenderSettings::default(), &stale);
        assert_eq!(settings.exposure, 2.0, "the valid change still applies");
        assert_eq!(warnings.len(), 1, "{warnings:?}");
    }
}
