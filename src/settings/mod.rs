//! `RenderSettings`: every toggle in one serde struct. The CLI's `--set key=value`, the scene
//! file's `[settings]` table, the viewer's panel and the tests all read and write this one type,
//! so a toggle means the same thing everywhere.
//!
//! **One source per setting.** Each technique's section lives in its own file here and is
//! declared with `field::section!`: beside each field sit its meaning (its doc comment), the
//! values it accepts and their unit (`#[values(…)]`), and its default. Everything else is derived
//! from that: [`RenderSettings::validate`] walks the descriptions, `settings_doc` makes the
//! viewer's tooltips and sliders from them and generates the settings table of
//! docs/scene-format.md (`tests/settings_docs.rs` fails when the file's table differs). Adding a
//! setting is adding a field to its section; adding a technique is adding its section's file and
//! one field of `RenderSettings` below.
//!
//! This module depends on nothing else of Mirador: the scene holds its file's settings, and the
//! renderers read both, so the layers stay one-way (settings ← scene ← renderers).

pub mod field;

mod bump;
mod environment;
pub mod hybrid;
mod mirrors;
mod raster;
mod shadows;
mod terms;
mod textures;
mod trace;
mod transparency;
mod volume;

pub use bump::{BumpMethod, BumpSettings, BumpView, TangentSource, Tessellation};
pub use environment::{EnvironmentMap, EnvironmentSettings, EnvironmentView, Parallax, SphereView};
pub use hybrid::{APPROXIMATIONS, Approximation, HybridSettings, SceneFacts, Traced, TracedSet};
pub use mirrors::{MAX_MIRROR_DEPTH, MirrorSettings, MirrorView};
pub use raster::{Prepass, RasterSettings};
pub use shadows::{MAX_SHADOWED_LIGHTS, ShadowFilter, ShadowFit, ShadowMethod, ShadowSettings, ShadowView};
pub use terms::TermSettings;
pub use textures::{TextureFilter, TextureSettings, TracerLod};
pub use trace::{AccelKind, AntiAliasing, TraceSettings};
pub use transparency::{MAX_PEEL_LAYERS, Refraction, TransparencySettings, TransparencySort};
pub use volume::{VOLUME_SAMPLES_WHITE, VolumeGradient, VolumeMode, VolumeReconstruction, VolumeSettings, VolumeView};

use field::{choices, section};

section! {
    /// Every render setting, one section per technique; the top-level numbers are the output
    /// transform's and the tessellation's.
    pub struct RenderSettings {
        /// Which terms of the illumination model
        /// `L = ME + AG + Σ V_i·S_i ⊗ (ka·C + kd·C·max(0, n·l) + ks·Sc·max(0, r·v)^e)` are drawn:
        /// teaching toggles (docs/course/02-illumination.md).
        terms: TermSettings = TermSettings::default(),
        /// Multiplies linear radiance before the tone curve and the sRGB encoding (the output
        /// transform both renderers share). For a model with physical lights, 1 is Blender's
        /// Standard view at exposure 0; Blender's exposure `x` (in stops) is `2^x` here.
        #[values(above(0.0).slider(0.01, 16.0))]
        exposure: f32 = 1.0,
        /// The output transform's curve from exposed radiance `c` to the display's [0, 1], per
        /// channel, before the sRGB encoding: clamp (the course's), Reinhard, a fit of ACES or
        /// Khronos PBR Neutral. Both renderers run the same curve (`src/output.rs`,
        /// `shaders/present.wgsl`).
        tone_map: ToneMap = ToneMap::Clamp,
        /// Slices around the rasterizer's tessellated spheres, tori and rounded boxes (its
        /// triangles); the ray tracer's analytic shapes are exact, so few slices show as
        /// polygonal silhouettes in the difference view.
        #[values(closed(3.0, 4096.0).slider(3.0, 512.0))]
        sphere_segments: u32 = 96,
        /// Texture filtering (docs/course/03-mipmaps.md): the mip level from the footprint on the surface
        /// (the notes' `log(distance)`), trilinear blending between the two nearest levels.
        textures: TextureSettings = TextureSettings::default(),
        /// Bump mapping (docs/course/04-bump-mapping.md): `n' = normalize((t_u + du·n) × (t_v + dv·n))` from a
        /// height field's differences, and normal maps.
        bump: BumpSettings = BumpSettings::default(),
        /// Cast shadows (docs/course/05-shadows.md): the visibility `V_i` of each light, by shadow maps or
        /// projected polygons in the rasterizer, by shadow rays in the tracer.
        shadows: ShadowSettings = ShadowSettings::default(),
        /// Transparent surfaces in the rasterizer (docs/course/06-transparency.md): drawn after the opaque
        /// ones, farthest first, each pixel updated as `I = Im + kt·Mt·I`.
        transparency: TransparencySettings = TransparencySettings::default(),
        /// Planar mirrors (docs/course/07-planar-mirrors.md): the scene rendered by the camera mirrored about each
        /// mirror's plane, shown in the mirror as `kps·MPS·L(r)`.
        mirrors: MirrorSettings = MirrorSettings::default(),
        /// Environment maps (docs/course/08-environment-maps.md): curved mirrors look `kps·MPS·L(r)` up in a cube,
        /// sphere or latitude–longitude map; the world's environment is the background.
        environment: EnvironmentSettings = EnvironmentSettings::default(),
        /// Direct volume rendering of voxel grids (docs/course/11-volumes.md): rays march the grid,
        /// classify each sample by the transfer function, shade it
        /// `C = C_amb + C_luz·k_dif·(n·L)` and composite front to back; or find the isosurface
        /// `f = iso`.
        volume: VolumeSettings = VolumeSettings::default(),
        /// The hybrid (docs/course/12-error-budget.md): approximations of the rasterizer swapped
        /// for their traced counterparts inside its frame.
        hybrid: HybridSettings = HybridSettings::default(),
        /// How the rasterizer spends its time: prepass, tessellation, render scale. None of these
        /// changes what a technique computes; each trades time for a measured difference
        /// (docs/performance.md).
        raster: RasterSettings = RasterSettings::default(),
        /// The Whitted ray tracer's own settings (docs/course/09-ray-tracing.md): recursion, anti-aliasing,
        /// acceleration.
        trace: TraceSettings = TraceSettings::default(),
    }
}

choices! {
    /// The output transform's curve from exposed linear radiance `c` to the display's [0, 1], per
    /// channel unless said otherwise; the sRGB encoding follows. Both renderers run the same curve
    /// (`src/output.rs`, `shaders/present.wgsl`).
    pub enum ToneMap {
        /// `min(max(c, 0), 1)`: the course's output (and Blender's Standard view); everything
        /// above 1 is white.
        Clamp,
        /// `c/(1 + c)` (Reinhard's global operator): nothing is ever white, highlights keep
        /// detail, mid-tones darken (0.18 shows as 0.15).
        Reinhard,
        /// Narkowicz's fit of the ACES filmic curve, `c(2.51c + 0.03)/(c(2.43c + 0.59) + 0.14)`:
        /// contrast in the mid-tones, a soft shoulder, white near c = 10.
        Aces,
        /// Khronos PBR Neutral: base colours up to 0.76 pass unchanged (a colour-accurate product
        /// shot), brighter values compress towards white and desaturate.
        PbrNeutral,
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
        // An unknown name is answered with the name it most likely misspells, and the names the
        // section has.
        let unknown = |what: &str, has: &str, table: &toml::Table, name: &str| {
            let names = table.keys().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", ");
            let nearest = table.keys().map(|k| (strsim::damerau_levenshtein(k, name), k)).min();
            let guess = match nearest {
                Some((distance, k)) if distance <= 2 => format!(" (did you mean `{k}`?)"),
                _ => String::new(),
            };
            rejected(format!("no such {what}{guess}; {has} {names}"))
        };
        for part in path {
            if !matches!(slot.get(*part), Some(toml::Value::Table(_))) {
                return Err(unknown("settings section", "the sections are", slot, part));
            }
            slot = slot.get_mut(*part).and_then(toml::Value::as_table_mut).expect("a section, checked just above");
        }
        if !slot.contains_key(*last) {
            return Err(unknown("setting", "this section has", slot, last));
        }
        slot.insert(last.to_string(), value);
        let updated: RenderSettings = table.try_into().map_err(|e: toml::de::Error| rejected(e.message().into()))?;
        updated.validate().map_err(|e| rejected(e.to_string()))?;
        *self = updated;
        Ok(())
    }

    /// Checks every setting against the values its section says it accepts; the error names the
    /// first setting that is out of range, the range and the value
    /// (`sphere_segments must lie in 3..=4096, got 2`).
    pub fn validate(&self) -> Result<(), SettingsError> {
        field::walk(RenderSettings::FIELDS, self, "", &mut |key, field, value| {
            value.check(&field.values).map_err(|broken| SettingsError::Invalid(format!("{key} {broken}")))
        })
    }

    /// The description of the setting or section at the dotted path `key` (`shadows.map_size`).
    pub fn field(key: &str) -> Option<&'static field::Field> {
        field::find(RenderSettings::FIELDS, key)
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
        let unknown = s.set("terms.glow=true").unwrap_err().to_string();
        assert!(unknown.contains("`specular`"), "an unknown setting is answered with its section's: {unknown}");
        let section = s.set("shadow.enabled=true").unwrap_err().to_string();
        assert!(section.contains("`shadows`"), "an unknown section is answered with the sections: {section}");
        // A misspelling gets the name it most likely means; a name far from every one gets none.
        assert!(section.contains("did you mean `shadows`?"), "{section}");
        let setting = s.set("shadows.enable=true").unwrap_err().to_string();
        assert!(setting.contains("did you mean `enabled`?"), "{setting}");
        assert!(!s.set("lighting.x=1").unwrap_err().to_string().contains("did you mean"));
        assert!(s.set("exposure=bright").is_err());
        assert!(s.set("exposure=-1").is_err());
        assert!(s.set("exposure").is_err());
        assert_eq!(s.exposure, 2.5, "a rejected assignment leaves the settings unchanged");
    }

    #[test]
    fn the_defaults_are_accepted() {
        RenderSettings::default().validate().unwrap();
    }

    #[test]
    fn a_rejected_value_is_named_with_its_key_range_and_value() {
        let message = |assignment: &str| RenderSettings::default().set(assignment).unwrap_err().to_string();
        assert_eq!(message("sphere_segments=2"), "`sphere_segments`: sphere_segments must lie in 3..=4096, got 2");
        assert_eq!(message("exposure=-1"), "`exposure`: exposure must be positive, got -1");
        assert_eq!(message("exposure=nan"), "`exposure`: exposure must be positive, got NaN");
        assert_eq!(message("volume.step=0.01"), "`volume.step`: volume.step must lie in 0.05..=8 voxels, got 0.01");
        assert_eq!(
            message("bump.delta_texels=0"),
            "`bump.delta_texels`: bump.delta_texels must lie in (0, 64] texels, got 0"
        );
        assert_eq!(
            message("shadows.slope_bias=-1"),
            "`shadows.slope_bias`: shadows.slope_bias must be a finite number ≥ 0, got -1"
        );
        assert_eq!(message("bump.scale=inf"), "`bump.scale`: bump.scale must be finite, got inf");
    }

    /// Every bounded number is accepted at its bounds and rejected just outside them, through
    /// `set` as the command line and the viewer use it: the descriptions are what is checked.
    #[test]
    fn every_bound_is_checked() {
        use field::{Accepts, Kind};
        let mut checked = 0;
        let defaults = RenderSettings::default();
        field::walk(RenderSettings::FIELDS, &defaults, "", &mut |key, field, _| {
            let integer = matches!(field.kind, Kind::Integer { .. });
            let step = |x: f64| if integer { 1.0 } else { (x.abs() * 1e-3).max(1e-3) };
            let (inside, outside) = match field.values.accepts {
                Accepts::Any => return Ok::<(), ()>(()),
                Accepts::Closed(low, high) => (vec![low, high], vec![low - step(low), high + step(high)]),
                Accepts::OpenClosed(low, high) => (vec![low + step(low), high], vec![low, high + step(high)]),
                Accepts::AtLeast(low) => (vec![low], vec![low - step(low)]),
                Accepts::Above(low) => (vec![low + step(low)], vec![low]),
            };
            for x in inside {
                let mut settings = RenderSettings::default();
                settings.set(&format!("{key}={x}")).unwrap_or_else(|e| panic!("{key}={x}: {e}"));
            }
            for x in outside {
                if integer && x < 0.0 && !matches!(field.kind, Kind::Integer { signed: true }) {
                    continue;
                }
                let error = RenderSettings::default().set(&format!("{key}={x}")).expect_err(&format!("{key}={x}"));
                assert!(error.to_string().contains(&format!("{key} must")), "{key}={x}: {error}");
            }
            checked += 1;
            Ok(())
        })
        .unwrap();
        assert!(checked >= 20, "{checked} bounded settings");
    }
}
