//! Classification (docs/course/11-volumes.md#classification): a transfer function from a voxel's value
//! to a colour and an opacity, and the opacity's correction for the sample step.
//!
//! The function is piecewise linear between control points over the normalized value `x ∈ [0, 1]`
//! (the volume's `range` mapped onto it). Both renderers classify through the same
//! [`TABLE_SIZE`]-entry table, read with linear interpolation between entries ([`Table::lookup`],
//! twinned in `shaders/volume.wgsl`), as volume renderers classify through a lookup table.
//!
//! **Opacity correction.** A control point's opacity `α` is that of a slab one voxel thick (the
//! grid's smallest spacing `Δ₀`). A sample standing for a slab of length `ℓ` lets `(1 − α)^(ℓ/Δ₀)`
//! through, so its opacity is `α' = 1 − (1 − α)^(ℓ/Δ₀)`; with it, halving the step doubles the
//! samples but not the opacity, and the image does not change with the sample count.

use glam::{Vec3, Vec4};

/// Entries of the classification table.
pub const TABLE_SIZE: usize = 256;

/// One control point: at normalized value `value`, this colour (linear RGB) and opacity per voxel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlPoint {
    pub value: f32,
    pub colour: Vec3,
    pub alpha: f32,
}

/// A piecewise-linear transfer function: sorted control points, constant beyond the ends.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    points: Vec<ControlPoint>,
}

/// Built-in transfer functions, over the normalized value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// Grey ramp, opacity rising with the value: every value visible, the densest most.
    Grey,
    /// For CT-like data over −1000..1000 (Hounsfield units): air clear, skin faint, denser
    /// tissue (lesions, 300–500) red, bone white.
    Ct,
    /// A black-body ramp, for smooth fields such as Marschner–Lobb.
    Heat,
}

impl Preset {
    pub const NAMES: [(&'static str, Preset); 3] = [("grey", Preset::Grey), ("ct", Preset::Ct), ("heat", Preset::Heat)];

    pub fn by_name(name: &str) -> Option<Preset> {
        Preset::NAMES.iter().find(|(n, _)| *n == name).map(|&(_, p)| p)
    }

    pub fn transfer_function(self) -> TransferFunction {
        let p =
            |value: f32, r: f32, g: f32, b: f32, alpha: f32| ControlPoint { value, colour: Vec3::new(r, g, b), alpha };
        let points = match self {
            Preset::Grey => vec![p(0.0, 0.0, 0.0, 0.0, 0.0), p(1.0, 1.0, 1.0, 1.0, 0.25)],
            // x = (HU + 1000)/2000 over −1000..1000: skin ≈ 0.52, lesions 0.7, bone 1.
            Preset::Ct => vec![
                p(0.0, 0.0, 0.0, 0.0, 0.0),
                p(0.44, 0.0, 0.0, 0.0, 0.0),
                p(0.50, 0.80, 0.50, 0.40, 0.03),
                p(0.56, 0.80, 0.50, 0.40, 0.03),
                p(0.62, 0.0, 0.0, 0.0, 0.0),
                p(0.66, 0.90, 0.25, 0.10, 0.25),
                p(0.74, 0.90, 0.25, 0.10, 0.25),
                p(0.80, 0.0, 0.0, 0.0, 0.0),
                p(0.88, 0.95, 0.92, 0.85, 0.3),
                p(1.0, 1.0, 1.0, 0.95, 0.8),
            ],
            Preset::Heat => vec![
                p(0.0, 0.0, 0.0, 0.0, 0.0),
                p(0.3, 0.5, 0.0, 0.0, 0.02),
                p(0.6, 1.0, 0.45, 0.0, 0.08),
                p(0.85, 1.0, 0.9, 0.3, 0.25),
                p(1.0, 1.0, 1.0, 1.0, 0.6),
            ],
        };
        TransferFunction { points }
    }
}

impl TransferFunction {
    /// A transfer function from control points over the normalized value: at least one, values in
    /// `[0, 1]` and non-decreasing (two at the same value make a step), colours and opacities in
    /// `[0, 1]`. The error names the first point (from 1) that breaks a rule.
    pub fn new(points: Vec<ControlPoint>) -> Result<TransferFunction, String> {
        if points.is_empty() {
            return Err("a transfer function needs at least one control point".into());
        }
        let unit = |x: f32| (0.0..=1.0).contains(&x);
        for (i, point) in points.iter().enumerate() {
            let n = i + 1;
            if !unit(point.value) {
                return Err(format!("control point {n}: value {} lies outside the volume's range", point.value));
            }
            if !(point.colour.to_array().iter().all(|&c| unit(c)) && unit(point.alpha)) {
                return Err(format!(
                    "control point {n}: colour {} and opacity {} must lie in [0, 1]",
                    point.colour, point.alpha
                ));
            }
            if i > 0 && point.value < points[i - 1].value {
                return Err(format!(
                    "control point {n}: values must not decrease ({} after {})",
                    point.value,
                    points[i - 1].value
                ));
            }
        }
        Ok(TransferFunction { points })
    }

    pub fn points(&self) -> &[ControlPoint] {
        &self.points
    }

    /// Colour and opacity at normalized value `x`, exactly: linear between the two control points
    /// around `x`, the end points' beyond them.
    pub fn evaluate(&self, x: f32) -> Vec4 {
        let rgba = |p: &ControlPoint| p.colour.extend(p.alpha);
        let first = &self.points[0];
        if x <= first.value {
            return rgba(first);
        }
        for pair in self.points.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            if x <= b.value {
                let t = if b.value > a.value { (x - a.value) / (b.value - a.value) } else { 1.0 };
                return rgba(a).lerp(rgba(b), t);
            }
        }
        rgba(self.points.last().expect("at least one point"))
    }

    /// The classification table both renderers read.
    pub fn table(&self) -> Table {
        Table((0..TABLE_SIZE).map(|i| self.evaluate(i as f32 / (TABLE_SIZE - 1) as f32)).collect())
    }
}

/// [`TABLE_SIZE`] entries of colour and opacity at `x = i / (TABLE_SIZE − 1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Table(pub Vec<Vec4>);

impl Table {
    /// The entry at `x ∈ [0, 1]` (clamped), linear between the two nearest entries.
    pub fn lookup(&self, x: f32) -> Vec4 {
        let position = x.clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f32;
        let i = (position.floor() as usize).min(TABLE_SIZE - 2);
        self.0[i].lerp(self.0[i + 1], position - i as f32)
    }
}

/// The opacity of a sample standing for `length_in_voxels` voxels of material whose opacity per
/// voxel is `alpha`: `1 − (1 − α)^ℓ`.
pub fn corrected_alpha(alpha: f32, length_in_voxels: f32) -> f32 {
    1.0 - (1.0 - alpha.clamp(0.0, 1.0)).powf(length_in_voxels)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(value: f32, alpha: f32) -> ControlPoint {
        ControlPoint { value, colour: Vec3::splat(value), alpha }
    }

    #[test]
    fn evaluation_is_piecewise_linear_and_constant_beyond_the_ends() {
        let tf =
            TransferFunction::new(vec![point(0.2, 0.0), point(0.6, 0.8), point(0.6, 0.1), point(1.0, 0.5)]).unwrap();
        assert_eq!(tf.evaluate(0.0).w, 0.0);
        assert!((tf.evaluate(0.4).w - 0.4).abs() < 1e-6);
        assert!((tf.evaluate(0.8).w - 0.3).abs() < 1e-6);
        assert!((tf.evaluate(0.8).x - 0.8).abs() < 1e-6);
    }

    #[test]
    fn the_table_follows_the_function_within_one_entry() {
        let tf = Preset::Ct.transfer_function();
        let table = tf.table();
        for i in 0..=1000 {
            let x = i as f32 / 1000.0;
            // Between entries the table is linear; the function bends only at control points,
            // where the table can miss by at most the slope times half an entry.
            let error = (table.lookup(x) - tf.evaluate(x)).abs().max_element();
            assert!(error < 0.03, "{error} at {x}");
        }
        assert_eq!(table.lookup(1.0), tf.evaluate(1.0));
    }

    #[test]
    fn opacity_correction_composes_over_a_slab() {
        // Two samples of half a voxel let through what one sample of a voxel does.
        let a = 0.3;
        let half = corrected_alpha(a, 0.5);
        assert!(((1.0 - half) * (1.0 - half) - (1.0 - a)).abs() < 1e-6);
        assert_eq!(corrected_alpha(a, 1.0), a);
    }

    #[test]
    fn bad_control_points_are_named() {
        let unsorted = TransferFunction::new(vec![point(0.5, 0.1), point(0.2, 0.1)]).unwrap_err();
        assert!(unsorted.contains("control point 2") && unsorted.contains("must not decrease"), "{unsorted}");
        let outside = TransferFunction::new(vec![point(1.5, 0.1)]).unwrap_err();
        assert!(outside.contains("outside the volume's range"), "{outside}");
        let opacity = TransferFunction::new(vec![point(0.5, 1.1)]).unwrap_err();
        assert!(opacity.contains("must lie in [0, 1]"), "{opacity}");
        assert!(TransferFunction::new(Vec::new()).is_err());
    }
}
