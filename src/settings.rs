//! `RenderSettings`: every toggle in one serde struct. The CLI's `--set key=value`, the scene
//! file's `[settings]` table, the viewer's panel and the tests all read and write this one type,
//! so a toggle means the same thing everywhere. Later techniques add their sections here.

use serde::{Deserialize, Serialize};

use crate::scene::shading::Terms;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderSettings {
    /// Which terms of the illumination model are drawn (teaching toggles).
    pub terms: TermSettings,
    /// Exposure applied to linear radiance before the output transform.
    pub exposure: f32,
    /// Slices around a tessellated sphere (the rasterizer's; the tracer's spheres are exact).
    pub sphere_segments: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TermSettings {
    pub ambient: bool,
    pub diffuse: bool,
    pub specular: bool,
    pub emission: bool,
}

impl Default for TermSettings {
    fn default() -> Self {
        TermSettings { ambient: true, diffuse: true, specular: true, emission: true }
    }
}

impl From<TermSettings> for Terms {
    fn from(t: TermSettings) -> Terms {
        Terms { ambient: t.ambient, diffuse: t.diffuse, specular: t.specular, emission: t.emission }
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings { terms: TermSettings::default(), exposure: 1.0, sphere_segments: 96 }
    }
}

/// Why a `--set key=value` could not be applied.
#[derive(Debug, thiserror::Error)]
pub enum SettingsError {
    #[error("`{0}` is not of the form key=value")]
    NotAnAssignment(String),
    #[error("`{key}`: {message}")]
    Rejected { key: String, message: String },
    #[error("{0}")]
    Invalid(String),
}

impl RenderSettings {
    /// Applies `key=value` where `key` is a dotted path (`terms.specular`, `exposure`) and `value`
    /// is a TOML value (`true`, `1.5`, `"text"`). Unknown keys and ill-typed values are rejected.
    pub fn set(&mut self, assignment: &str) -> Result<(), SettingsError> {
        let (key, value) =
            assignment.split_once('=').ok_or_else(|| SettingsError::NotAnAssignment(assignment.into()))?;
        let key = key.trim();
        let rejected = |message: String| SettingsError::Rejected { key: key.into(), message };
        let value: toml::Value = toml::from_str::<toml::Table>(&format!("v = {}", value.trim()))
            .map(|mut t| t.remove("v").expect("the table was parsed from `v = …`"))
            .unwrap_or_else(|_| toml::Value::String(value.trim().into()));
        let mut table = toml::Table::try_from(&*self).map_err(|e| rejected(e.to_string()))?;
        let mut slot = &mut table;
        let parts: Vec<&str> = key.split('.').collect();
        let (last, path) = parts.split_last().expect("split always yields one part");
        for part in path {
            slot = match slot.get_mut(*part) {
                Some(toml::Value::Table(inner)) => inner,
                _ => return Err(rejected("no such settings section".into())),
            };
        }
        if !slot.contains_key(*last) {
            return Err(rejected("no such setting".into()));
        }
        slot.insert(last.to_string(), value);
        let updated: RenderSettings = table.try_into().map_err(|e: toml::de::Error| rejected(e.message().into()))?;
        updated.validate().map_err(|e| rejected(e.to_string()))?;
        *self = updated;
        Ok(())
    }

    pub fn validate(&self) -> Result<(), SettingsError> {
        if !(self.exposure.is_finite() && self.exposure > 0.0) {
            return Err(SettingsError::Invalid(format!("exposure must be positive, got {}", self.exposure)));
        }
        if !(3..=4096).contains(&self.sphere_segments) {
            return Err(SettingsError::Invalid(format!(
                "sphere_segments must lie in 3..=4096, got {}",
                self.sphere_segments
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_reaches_nested_keys_and_rejects_unknown_ones() {
        let mut s = RenderSettings::default();
        s.set("terms.specular=false").unwrap();
        s.set("exposure = 2.5").unwrap();
        assert!(!s.terms.specular);
        assert_eq!(s.exposure, 2.5);
        assert!(s.set("terms.glow=true").is_err());
        assert!(s.set("exposure=bright").is_err());
        assert!(s.set("exposure=-1").is_err());
        assert!(s.set("exposure").is_err());
        assert_eq!(s.exposure, 2.5, "a rejected assignment leaves the settings unchanged");
    }
}
