//! The `[[volumes]]` tables of a scene file: a voxel grid from a file or a procedural field, its
//! range, transfer function, rendering and placement (`docs/scene-format.md` § Volumes).

use std::ops::Range;
use std::sync::Arc;

use glam::{UVec3, Vec3};
use serde::Deserialize;
use toml::Spanned;

use super::{Builder, Finite, Scale, V3, transform};
use crate::scene::SceneError;
use crate::scene::nrrd::{Endian, RawDesc, ScalarType, read_nrrd, read_raw};
use crate::volume::grid::{MAX_VOXELS, voxel_count};
use crate::volume::{ControlPoint, Grid, Preset, Rendering, TransferFunction, Volume, fields};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct VolumeDesc {
    name: Option<String>,
    /// A NRRD file.
    path: Option<String>,
    /// Headerless bytes.
    raw: Option<Spanned<RawFileDesc>>,
    /// A procedural field.
    field: Option<Spanned<FieldDesc>>,
    /// Data values mapped to 0 and 1 (default: the grid's smallest and largest).
    range: Option<[Finite; 2]>,
    preset: Option<Spanned<String>>,
    transfer: Option<Vec<Spanned<ControlPointDesc>>>,
    mode: Option<ModeName>,
    /// The isosurface's value, in data units.
    iso: Option<Finite>,
    material: Option<Spanned<String>>,
    translate: Option<V3>,
    rotate: Option<V3>,
    scale: Option<Scale>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFileDesc {
    path: String,
    dims: [i64; 3],
    #[serde(rename = "type")]
    scalar: String,
    spacing: Option<V3>,
    endian: Option<String>,
    header_bytes: Option<u64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FieldDesc {
    #[serde(rename = "type")]
    kind: FieldType,
    /// Grid points per axis: one number for a cube, or three.
    resolution: Option<Resolution>,
    radius: Option<Finite>,
    major_radius: Option<Finite>,
    minor_radius: Option<Finite>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
enum FieldType {
    MarschnerLobb,
    Sphere,
    Torus,
    Phantom,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Resolution {
    Cube(i64),
    Axes([i64; 3]),
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum ModeName {
    Composite,
    Isosurface,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ControlPointDesc {
    /// In data units.
    value: Finite,
    colour: V3,
    alpha: Finite,
}

impl Builder<'_> {
    pub(super) fn volume(&mut self, d: VolumeDesc, span: Range<usize>) -> Result<(), SceneError> {
        let fail = |message: String| self.error(message, span.clone());
        let name = d.name.clone().unwrap_or_else(|| format!("volume {}", self.scene.volumes.len()));
        let sources = [d.path.is_some(), d.raw.is_some(), d.field.is_some()];
        if sources.iter().filter(|&&s| s).count() != 1 {
            return Err(fail("a volume needs exactly one of `path` (NRRD), `raw` or `field`".into()));
        }
        let (grid, default_iso) = self.volume_grid(&d, span.clone())?;
        let (lo, hi) = match d.range {
            Some([Finite(lo), Finite(hi)]) if lo < hi => (lo, hi),
            Some([Finite(lo), Finite(hi)]) => return Err(fail(format!("range needs low < high, got [{lo}, {hi}]"))),
            None => grid.range(),
        };
        let normalize = |v: f32| crate::volume::grid::normalize(v, (lo, hi));
        let transfer = match (d.preset, d.transfer) {
            (Some(_), Some(_)) => return Err(fail("give a volume either a `preset` or a `transfer`, not both".into())),
            (Some(preset), None) => Preset::by_name(preset.get_ref())
                .ok_or_else(|| {
                    let known: Vec<&str> = Preset::NAMES.iter().map(|(n, _)| *n).collect();
                    self.error(format!("no preset `{}` (known: {})", preset.get_ref(), known.join(", ")), preset.span())
                })?
                .transfer_function(),
            (None, Some(points)) => self.transfer_function(points, (lo, hi), normalize)?,
            (None, None) => Preset::Grey.transfer_function(),
        };
        let iso = d.iso.map_or(default_iso.unwrap_or(0.5 * (lo + hi)), |Finite(v)| v);
        if !(lo..=hi).contains(&iso) {
            return Err(fail(format!("iso {iso} lies outside the volume's range [{lo}, {hi}]")));
        }
        let iso = normalize(iso);
        let material = match d.material {
            Some(m) => self.named_material(m)?,
            None => self.default_material(),
        };
        let table = transfer.table();
        self.scene.volumes.push(Volume {
            name,
            grid: Arc::new(grid.normalized((lo, hi))),
            range: (lo, hi),
            world_from_local: transform(d.translate, d.rotate, d.scale),
            transfer,
            table,
            rendering: match d.mode {
                Some(ModeName::Isosurface) => Rendering::Isosurface,
                Some(ModeName::Composite) | None => Rendering::Composite,
            },
            iso,
            material,
        });
        Ok(())
    }

    /// The grid in data units, and the iso value its kind suggests (0 for distance fields).
    fn volume_grid(&self, d: &VolumeDesc, span: Range<usize>) -> Result<(Grid, Option<f32>), SceneError> {
        // The scene's volumes together stay within one grid's limit, checked before a grid whose
        // size the scene alone sets is made: a few lines asking for many 1024³ fields must not
        // take 4 GiB each.
        let held: u64 = self.scene.volumes.iter().map(|v| v.grid.values.len() as u64).sum();
        let room = MAX_VOXELS.saturating_sub(held);
        let too_many = |voxels: u64| {
            format!(
                "the scene's volumes would hold {} points in all, more than the {MAX_VOXELS} Mirador reads \
                 ({held} before this one)",
                held + voxels
            )
        };
        if let Some(field) = &d.field {
            let span = field.span();
            let fail = |message: String| self.error(message, span.clone());
            return procedural(field.get_ref(), room, too_many).map_err(fail);
        }
        if let Some(raw) = &d.raw {
            let span = raw.span();
            let fail = |message: String| self.error(format!("raw: {message}"), span.clone());
            let r = raw.get_ref();
            let dims = UVec3::new(
                checked_dim(r.dims[0]).map_err(&fail)?,
                checked_dim(r.dims[1]).map_err(&fail)?,
                checked_dim(r.dims[2]).map_err(&fail)?,
            );
            let desc = RawDesc {
                dims,
                scalar: r.scalar.parse::<ScalarType>().map_err(&fail)?,
                spacing: r.spacing.map_or(Vec3::ONE, |V3(s)| s),
                endian: r.endian.as_deref().unwrap_or("little").parse::<Endian>().map_err(&fail)?,
                header_bytes: r.header_bytes.unwrap_or(0),
            };
            if voxel_count(dims) <= MAX_VOXELS && voxel_count(dims) > room {
                return Err(fail(too_many(voxel_count(dims))));
            }
            let (file, looked) = super::locate::locate(&self.dir, &r.path);
            let grid = read_raw(&file, &desc)
                .map_err(|e| fail(super::locate::with_places(format!("{}: {e}", file.display()), &looked)))?;
            return Ok((grid, None));
        }
        let relative = d.path.as_ref().expect("one source is present");
        let (file, looked) = super::locate::locate(&self.dir, relative);
        let grid = read_nrrd(&file).map_err(|e| {
            self.error(super::locate::with_places(format!("{}: NRRD: {e}", file.display()), &looked), span.clone())
        })?;
        // A NRRD file's size bounds what reading it took; the sum is checked after.
        if grid.values.len() as u64 > room {
            return Err(self.error(too_many(grid.values.len() as u64), span));
        }
        Ok((grid, None))
    }

    fn transfer_function(
        &self,
        points: Vec<Spanned<ControlPointDesc>>,
        (lo, hi): (f32, f32),
        normalize: impl Fn(f32) -> f32,
    ) -> Result<TransferFunction, SceneError> {
        let spans: Vec<Range<usize>> = points.iter().map(Spanned::span).collect();
        let mut converted = Vec::with_capacity(points.len());
        for (point, span) in points.into_iter().zip(&spans) {
            let ControlPointDesc { value: Finite(value), colour: V3(colour), alpha: Finite(alpha) } =
                point.into_inner();
            if !(lo..=hi).contains(&value) {
                let message = format!("control point value {value} lies outside the volume's range [{lo}, {hi}]");
                return Err(self.error(message, span.clone()));
            }
            converted.push(ControlPoint { value: normalize(value), colour, alpha });
        }
        TransferFunction::new(converted).map_err(|message| {
            // "control point N: …" names the point; report it at that point's line.
            let n = message
                .strip_prefix("control point ")
                .and_then(|rest| rest.split(':').next())
                .and_then(|n| n.parse::<usize>().ok());
            let span = n.and_then(|n| spans.get(n - 1)).cloned().unwrap_or_default();
            self.error(format!("transfer: {message}"), span)
        })
    }
}

/// A procedural field sampled onto its grid over `[−1, 1]³`. Distance fields are negated
/// (positive inside), so that in every field the values rise inwards. `too_many` is the message
/// for a grid of more points than the scene has `room` for, which is refused before sampling.
fn procedural(d: &FieldDesc, room: u64, too_many: impl Fn(u64) -> String) -> Result<(Grid, Option<f32>), String> {
    let default = match d.kind {
        // 41 points: Marschner and Lobb's 40 intervals over [−1, 1].
        FieldType::MarschnerLobb => 41,
        FieldType::Sphere | FieldType::Torus | FieldType::Phantom => 64,
    };
    let dims = match d.resolution {
        None => UVec3::splat(default),
        Some(Resolution::Cube(n)) => UVec3::splat(checked_dim(n)?),
        Some(Resolution::Axes([x, y, z])) => UVec3::new(checked_dim(x)?, checked_dim(y)?, checked_dim(z)?),
    };
    // A grid over the limit on its own is refused by `Grid::from_function`, with the limits.
    let points = voxel_count(dims);
    if points <= MAX_VOXELS && points > room {
        return Err(too_many(points));
    }
    let applies = |field: &str, present: bool, allowed: &[FieldType]| {
        if present && !allowed.contains(&d.kind) {
            Err(format!("`{field}` does not apply to this field"))
        } else {
            Ok(())
        }
    };
    applies("radius", d.radius.is_some(), &[FieldType::Sphere])?;
    applies("major_radius", d.major_radius.is_some(), &[FieldType::Torus])?;
    applies("minor_radius", d.minor_radius.is_some(), &[FieldType::Torus])?;
    let positive = |value: Option<Finite>, default: f32, name: &str| match value {
        None => Ok(default),
        Some(Finite(v)) if v > 0.0 => Ok(v),
        Some(Finite(v)) => Err(format!("{name} must be > 0, got {v}")),
    };
    match d.kind {
        FieldType::MarschnerLobb => Ok((Grid::from_function(dims, fields::marschner_lobb)?, None)),
        FieldType::Sphere => {
            let radius = positive(d.radius, 0.6, "radius")?;
            Ok((Grid::from_function(dims, |p| -fields::sphere_distance(p, radius))?, Some(0.0)))
        }
        FieldType::Torus => {
            let major = positive(d.major_radius, 0.55, "major_radius")?;
            let minor = positive(d.minor_radius, 0.25, "minor_radius")?;
            if minor >= major {
                return Err(format!("a torus needs minor_radius < major_radius, got {minor} and {major}"));
            }
            Ok((Grid::from_function(dims, |p| -fields::torus_distance(p, major, minor))?, Some(0.0)))
        }
        FieldType::Phantom => {
            // Edges about 2.5 voxels wide: sharper ones terrace along the grid's planes.
            let blur = 2.5 * 2.0 / (dims.max_element() - 1) as f32;
            Ok((Grid::from_function(dims, |p| fields::phantom(p, blur))?, None))
        }
    }
}

fn checked_dim(n: i64) -> Result<u32, String> {
    u32::try_from(n).ok().filter(|&n| n >= 2).ok_or_else(|| format!("resolution must be at least 2, got {n}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_larger_than_the_scene_has_room_for_is_refused_before_sampling() {
        let field = FieldDesc {
            kind: FieldType::Sphere,
            resolution: Some(Resolution::Cube(16)),
            radius: None,
            major_radius: None,
            minor_radius: None,
        };
        let message = procedural(&field, 4095, |points| format!("{points} points")).expect_err("4096 > 4095");
        assert_eq!(message, "4096 points");
        assert!(procedural(&field, 4096, |_| unreachable!()).is_ok());
    }
}
