//! Casting one ray through a volume (docs/course/11-volumes.md#compositing):
//! `k` equally spaced samples between where the ray enters the volume's box and where it leaves
//! it (or meets an opaque surface first), each reconstructed, classified, shaded and composited
//! front to back:
//!
//! ```text
//! α_out = α_in + (1 − α_in)·α_v        C_out = C_in + (1 − α_in)·α_v·C_v
//! ```
//!
//! with early ray termination once `α_out` reaches a threshold. The isosurface mode steps the
//! same samples until `f − iso` changes sign and refines the crossing by bisection.
//!
//! **Where the samples are.** A segment of local length `L` is cut into `k = ⌈L / (step·Δ₀)⌉`
//! equal parts (`Δ₀` the grid's smallest spacing, `step` in voxels), sampled at their midpoints:
//! each sample stands for `ℓ = L/k`, the length its opacity is corrected for (`super::transfer`).
//! Cutting the segment exactly, rather than stepping from the entry by a fixed step, makes the
//! composite integrate the whole segment whatever its length, so two step sizes agree.
//! `shaders/volume.wgsl` runs the same arithmetic on the GPU.

use glam::{Vec3, Vec4};

use super::grid::{Differences, Grid, Reconstruction};
use super::transfer::{Table, corrected_alpha};

/// The most samples one ray takes through one volume: a bound on the work whatever the step.
pub const MAX_SAMPLES: u32 = 4096;
/// Halvings of the interval around an isosurface crossing: 2⁻¹⁰ of a step.
pub const BISECTION_STEPS: u32 = 10;

/// How a ray is marched: the teaching toggles of `[settings.volume]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct March {
    pub reconstruction: Reconstruction,
    /// Shade samples with gradient normals; `None`: the classified colour as it is.
    pub gradient: Option<Differences>,
    /// Sample spacing in voxels (of the smallest spacing).
    pub step: f32,
    pub opacity_correction: bool,
    /// Stop once the accumulated opacity reaches this; `None`: march to the end.
    pub termination: Option<f32>,
}

/// A ray in the volume's local coordinates: `origin + t·direction` with the world ray's `t`
/// (`direction` is not unit length where the volume is scaled).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalRay {
    pub origin: Vec3,
    pub direction: Vec3,
}

impl LocalRay {
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }

    /// Where the ray is inside the box `[−half, half]`: `(t_enter, t_exit)`, or `None` if it
    /// misses (the slab method).
    pub fn box_interval(&self, half: Vec3) -> Option<(f32, f32)> {
        let inverse = self.direction.recip();
        let a = (-half - self.origin) * inverse;
        let b = (half - self.origin) * inverse;
        let near = a.min(b).max_element();
        let far = a.max(b).min_element();
        (near <= far).then_some((near, far))
    }
}

/// The samples of a segment: `count` at `t_first + i·dt`, each standing for `length` voxels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Samples {
    pub t_first: f32,
    pub dt: f32,
    pub count: u32,
    pub length: f32,
}

/// Cuts `[t0, t1]` of `ray` into equal parts of at most `step` voxels (see the module header).
pub fn samples(grid: &Grid, ray: &LocalRay, (t0, t1): (f32, f32), step: f32) -> Samples {
    let voxels = (t1 - t0).max(0.0) * ray.direction.length() / grid.voxel_length();
    let count = ((voxels / step).ceil() as u32).clamp(1, MAX_SAMPLES);
    let dt = (t1 - t0) / count as f32;
    Samples { t_first: t0 + 0.5 * dt, dt, count, length: voxels / count as f32 }
}

/// One sample as the compositing sees it, for the shading callback and the viewer's plot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub t: f32,
    /// Normalized value, reconstructed.
    pub value: f32,
    /// Classified colour and opacity, the opacity corrected for the sample's length.
    pub classified: Vec4,
    /// The colour composited: shaded, or the classified colour without gradient shading.
    pub shaded: Vec3,
    /// Accumulated opacity after this sample.
    pub alpha_out: f32,
}

/// What front-to-back compositing of one segment gives: premultiplied colour, opacity, and the
/// samples taken out of those planned (fewer with early termination).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Composite {
    pub colour: Vec3,
    pub alpha: f32,
    pub taken: u32,
    pub planned: u32,
}

/// Composites the segment `[t0, t1]` of `ray` front to back. `shade(t, local_gradient, colour)`
/// returns a sample's shaded colour (called only with gradient shading on, and only for samples
/// with opacity). `record` receives every sample taken.
pub fn composite(
    grid: &Grid,
    table: &Table,
    ray: &LocalRay,
    segment: (f32, f32),
    march: &March,
    shade: &mut dyn FnMut(f32, Vec3, Vec3) -> Vec3,
    mut record: Option<&mut Vec<Sample>>,
) -> Composite {
    let s = samples(grid, ray, segment, march.step);
    let mut out = Composite { planned: s.count, ..Composite::default() };
    for i in 0..s.count {
        if march.termination.is_some_and(|threshold| out.alpha >= threshold) {
            break;
        }
        out.taken += 1;
        let t = s.t_first + i as f32 * s.dt;
        let g = grid.grid_coordinates(ray.at(t));
        let value = grid.sample(g, march.reconstruction);
        let mut classified = table.lookup(value);
        if march.opacity_correction {
            classified.w = corrected_alpha(classified.w, s.length);
        }
        let mut shaded = classified.truncate();
        if classified.w > 0.0 {
            if let Some(differences) = march.gradient {
                shaded = shade(t, grid.gradient(g, march.reconstruction, differences), shaded);
            }
            out.colour += (1.0 - out.alpha) * classified.w * shaded;
            out.alpha += (1.0 - out.alpha) * classified.w;
        }
        if let Some(record) = record.as_deref_mut() {
            record.push(Sample { t, value, classified, shaded, alpha_out: out.alpha });
        }
    }
    out
}

/// The first crossing of `f = iso` along `[t0, t1]`: the field read at the entry and at the same
/// samples [`composite`] takes (and the exit), the first sign change of `f − iso` refined by
/// [`BISECTION_STEPS`] bisections. Returns `t` of the crossing, or `None`.
pub fn isosurface(grid: &Grid, ray: &LocalRay, segment: (f32, f32), iso: f32, march: &March) -> Option<f32> {
    let f = |t: f32| grid.sample(grid.grid_coordinates(ray.at(t)), march.reconstruction) - iso;
    let s = samples(grid, ray, segment, march.step);
    let (mut t_before, mut f_before) = (segment.0, f(segment.0));
    for i in 0..=s.count {
        let t = if i == s.count { segment.1 } else { s.t_first + i as f32 * s.dt };
        let f_here = f(t);
        if (f_here >= 0.0) != (f_before >= 0.0) {
            let (mut a, mut b) = (t_before, t);
            for _ in 0..BISECTION_STEPS {
                let middle = 0.5 * (a + b);
                if (f(middle) >= 0.0) == (f_before >= 0.0) {
                    a = middle;
                } else {
                    b = middle;
                }
            }
            return Some(0.5 * (a + b));
        }
        (t_before, f_before) = (t, f_here);
    }
    None
}

#[cfg(test)]
mod tests {
    use glam::UVec3;

    use super::*;
    use crate::volume::transfer::{ControlPoint, TransferFunction};

    /// A field that is 0 for x < 0 and 1 for x ≥ 0 on [−1, 1]³, 21 points a side (spacing 0.1).
    fn two_values() -> Grid {
        Grid::from_function(UVec3::splat(21), |p| if p.x < -1e-6 { 0.0 } else { 1.0 }).unwrap()
    }

    fn march() -> March {
        March {
            reconstruction: Reconstruction::Nearest,
            gradient: None,
            step: 0.5,
            opacity_correction: true,
            termination: None,
        }
    }

    #[test]
    fn two_slabs_composite_as_computed_by_hand() {
        // Value 0: red, α = 0.2 per voxel; value 1: blue, α = 0.5 per voxel. Read by nearest
        // neighbour, the field changes halfway between the grid points x = −0.1 and x = 0, at
        // x = −0.05: a ray along +x crosses 0.95 units (9.5 voxels) of red, then 10.5 voxels of blue.
        // By hand: the red slab lets 0.8^9.5 through and keeps 1 − 0.8^9.5 of its colour; the blue
        // one adds 0.8^9.5·(1 − 0.5^10.5). The samples (every 0.05, at midpoints) fall 19 before
        // and 21 after the change, so the sum is exact up to rounding.
        let tf = TransferFunction::new(vec![
            ControlPoint { value: 0.0, colour: Vec3::X, alpha: 0.2 },
            ControlPoint { value: 1.0, colour: Vec3::Z, alpha: 0.5 },
        ])
        .unwrap();
        let grid = two_values();
        let ray = LocalRay { origin: Vec3::new(-2.0, 0.03, 0.02), direction: Vec3::X };
        let (t0, t1) = ray.box_interval(grid.half_extent()).unwrap();
        assert_eq!((t0, t1), (1.0, 3.0));
        let out = composite(&grid, &tf.table(), &ray, (t0, t1), &march(), &mut |_, _, c| c, None);
        let first = 1.0 - 0.8f32.powf(9.5);
        let second = 0.8f32.powf(9.5) * (1.0 - 0.5f32.powf(10.5));
        assert!((out.colour - Vec3::new(first, 0.0, second)).abs().max_element() < 1e-5, "{}", out.colour);
        assert!((out.alpha - (first + second)).abs() < 1e-5);
        assert_eq!(out.planned, 40);
        assert_eq!(out.taken, 40);
    }

    #[test]
    fn opacity_correction_makes_the_step_irrelevant_for_a_uniform_slab() {
        let grid = Grid::from_function(UVec3::splat(11), |_| 0.5).unwrap();
        let tf = TransferFunction::new(vec![ControlPoint { value: 0.0, colour: Vec3::ONE, alpha: 0.1 }]).unwrap();
        let ray = LocalRay { origin: Vec3::new(0.1, -5.0, 0.3), direction: Vec3::Y };
        let segment = ray.box_interval(grid.half_extent()).unwrap();
        let at = |step: f32, correction: bool| {
            let march = March { step, opacity_correction: correction, ..march() };
            composite(&grid, &tf.table(), &ray, segment, &march, &mut |_, _, c| c, None).alpha
        };
        // 2 units = 10 voxels of α = 0.1 per voxel.
        let expected = 1.0 - 0.9f32.powi(10);
        for step in [0.13, 0.5, 1.0, 3.0] {
            assert!((at(step, true) - expected).abs() < 1e-4, "step {step}: {}", at(step, true));
        }
        assert!((at(0.25, false) - at(1.0, false)).abs() > 0.2, "without correction the step shows");
    }

    #[test]
    fn early_termination_stops_once_opaque_enough() {
        let grid = Grid::from_function(UVec3::splat(11), |_| 1.0).unwrap();
        let tf = TransferFunction::new(vec![ControlPoint { value: 0.0, colour: Vec3::ONE, alpha: 0.5 }]).unwrap();
        let ray = LocalRay { origin: Vec3::new(0.0, 0.0, -5.0), direction: Vec3::Z };
        let segment = ray.box_interval(grid.half_extent()).unwrap();
        let stop = March { step: 1.0, termination: Some(0.99), ..march() };
        let mut samples = Vec::new();
        let out = composite(&grid, &tf.table(), &ray, segment, &stop, &mut |_, _, c| c, Some(&mut samples));
        // 1 − 0.5^k ≥ 0.99 first at k = 7.
        assert_eq!((out.taken, out.planned), (7, 10));
        assert_eq!(samples.len(), 7);
        assert!(out.alpha >= 0.99);
    }

    #[test]
    fn the_isosurface_of_a_distance_field_is_found_on_the_sphere() {
        let grid = Grid::from_function(UVec3::splat(33), |p| p.length() - 0.6).unwrap();
        let march = March { reconstruction: Reconstruction::Trilinear, ..march() };
        let ray = LocalRay { origin: Vec3::new(0.1, 0.2, -4.0), direction: Vec3::Z };
        let segment = ray.box_interval(grid.half_extent()).unwrap();
        let t = isosurface(&grid, &ray, segment, 0.0, &march).unwrap();
        let exact = 4.0 - (0.36f32 - 0.05).sqrt();
        // Trilinear reconstruction of |p| is within a fraction of a voxel (1/16) of the sphere.
        assert!((t - exact).abs() < 0.01, "{t} vs {exact}");
        let miss = LocalRay { origin: Vec3::new(0.7, 0.0, -4.0), direction: Vec3::Z };
        assert_eq!(isosurface(&grid, &miss, miss.box_interval(grid.half_extent()).unwrap(), 0.0, &march), None);
    }
}
