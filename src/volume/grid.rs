//! The scalar field on a Cartesian grid (docs/course/11-volumes.md#reconstruction): voxel
//! values at grid points, reconstructed between them by nearest-neighbour or trilinear
//! interpolation, and the gradient by first- or second-order differences ("Estimativa do vetor
//! normal").
//!
//! Coordinates. Voxel `(i, j, k)` sits at grid coordinates `g = (i, j, k)`; the grid spans
//! `[0, n − 1]` on each axis, `spacing` apart in the volume's local space, centred on the local
//! origin: local `p = (g − (n − 1)/2)·spacing`. A 3D texture of the same values, addressed at
//! `u = (g + 0.5)/n` with clamp-to-edge, reads exactly these samples, so the rasterizer's
//! hardware filtering and [`Grid::sample`] reconstruct the same field.

use glam::{UVec3, Vec3};

/// Values at grid points, x fastest, then y, then z.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub dims: UVec3,
    /// Distance between neighbouring grid points on each axis, in local units.
    pub spacing: Vec3,
    pub values: Vec<f32>,
}

/// How values between grid points are reconstructed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reconstruction {
    /// The value of the nearest grid point (`floor(g + 0.5)`, as a texture's nearest filter).
    Nearest,
    /// The notes' `v(x, y, z)`: the eight surrounding grid points weighted by `(1 − x)`, `x`, …
    Trilinear,
}

/// How the gradient is estimated from the reconstructed field, one voxel either side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Differences {
    /// First order: `(f(g + e) − f(g)) / Δ`, error O(Δ).
    Forward,
    /// Second order, the notes' formula: `(f(g + e) − f(g − e)) / 2Δ`, error O(Δ²).
    Central,
}

/// The largest grid Mirador accepts: 2³⁰ voxels (4 GiB of `f32`), and per axis the 2048 of
/// wgpu's default 3D texture limit.
pub const MAX_VOXELS: u64 = 1 << 30;
pub const MAX_DIM: u32 = 2048;

impl Grid {
    /// A grid with its sizes checked: at least 2 points on every axis (a grid of 1 has no extent),
    /// at most [`MAX_DIM`] per axis and [`MAX_VOXELS`] in all, positive finite spacing, one
    /// finite value per point. The error says which rule is broken.
    pub fn new(dims: UVec3, spacing: Vec3, values: Vec<f32>) -> Result<Grid, String> {
        check_dims(dims)?;
        if !(spacing.is_finite() && spacing.min_element() > 0.0) {
            return Err(format!("spacing must be positive and finite on every axis, got {spacing}"));
        }
        let count = voxel_count(dims);
        if values.len() as u64 != count {
            return Err(format!("{dims} grid needs {count} values, got {}", values.len()));
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            let (x, y, z) = unflatten(dims, index);
            return Err(format!("voxel ({x}, {y}, {z}) is {} (values must be finite)", values[index]));
        }
        Ok(Grid { dims, spacing, values })
    }

    /// A grid of `dims` points filling the cube `[−1, 1]³`, sampling `f` at its points.
    pub fn from_function(dims: UVec3, f: impl Fn(Vec3) -> f32 + Sync) -> Result<Grid, String> {
        use rayon::prelude::*;
        check_dims(dims)?;
        let spacing = 2.0 / (dims - 1).as_vec3();
        let values = (0..voxel_count(dims) as usize)
            .into_par_iter()
            .map(|index| {
                let (x, y, z) = unflatten(dims, index);
                f(Vec3::new(x as f32, y as f32, z as f32) * spacing - 1.0)
            })
            .collect();
        Grid::new(dims, spacing, values)
    }

    /// The smallest and largest value.
    pub fn range(&self) -> (f32, f32) {
        self.values.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)))
    }

    /// The values mapped by `(v − lo)/(hi − lo)` and clamped to `[0, 1]` (all 0 when `hi == lo`).
    pub fn normalized(&self, (lo, hi): (f32, f32)) -> Grid {
        let values = self.values.iter().map(|&v| normalize(v, (lo, hi))).collect();
        Grid { values, ..self.clone() }
    }

    /// The local box the grid spans: `±(n − 1)·spacing/2`.
    pub fn half_extent(&self) -> Vec3 {
        0.5 * (self.dims - 1).as_vec3() * self.spacing
    }

    /// The smallest spacing: the voxel length the transfer function's opacity is given for and
    /// the unit of the sample step.
    pub fn voxel_length(&self) -> f32 {
        self.spacing.min_element()
    }

    /// Grid coordinates of a local point.
    pub fn grid_coordinates(&self, local: Vec3) -> Vec3 {
        (local + self.half_extent()) / self.spacing
    }

    /// The value at grid point `(x, y, z)`, the indices clamped to the grid (clamp-to-edge).
    pub fn at(&self, x: i64, y: i64, z: i64) -> f32 {
        let clamp = |i: i64, n: u32| i.clamp(0, i64::from(n) - 1) as usize;
        let (x, y, z) = (clamp(x, self.dims.x), clamp(y, self.dims.y), clamp(z, self.dims.z));
        self.values[x + self.dims.x as usize * (y + self.dims.y as usize * z)]
    }

    /// The reconstructed field at grid coordinates `g` (clamped to the grid).
    pub fn sample(&self, g: Vec3, reconstruction: Reconstruction) -> f32 {
        let g = g.clamp(Vec3::ZERO, (self.dims - 1).as_vec3());
        match reconstruction {
            Reconstruction::Nearest => {
                let n = (g + 0.5).floor();
                self.at(n.x as i64, n.y as i64, n.z as i64)
            }
            Reconstruction::Trilinear => {
                let base = g.floor();
                let (x, y, z) = (g - base).into();
                let (i, j, k) = (base.x as i64, base.y as i64, base.z as i64);
                let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
                let row = |j: i64, k: i64| lerp(self.at(i, j, k), self.at(i + 1, j, k), x);
                let plane = |k: i64| lerp(row(j, k), row(j + 1, k), y);
                lerp(plane(k), plane(k + 1), z)
            }
        }
    }

    /// The gradient of the reconstructed field at grid coordinates `g`, in local units (value per
    /// local length), by differences one voxel either side.
    pub fn gradient(&self, g: Vec3, reconstruction: Reconstruction, differences: Differences) -> Vec3 {
        let f = |d: Vec3| self.sample(g + d, reconstruction);
        let axis = |e: Vec3, spacing: f32| match differences {
            Differences::Forward => (f(e) - f(Vec3::ZERO)) / spacing,
            Differences::Central => (f(e) - f(-e)) / (2.0 * spacing),
        };
        Vec3::new(axis(Vec3::X, self.spacing.x), axis(Vec3::Y, self.spacing.y), axis(Vec3::Z, self.spacing.z))
    }

    /// Bytes the grid holds on the CPU (`f32` values).
    pub fn bytes(&self) -> u64 {
        self.values.len() as u64 * 4
    }
}

fn check_dims(dims: UVec3) -> Result<(), String> {
    if dims.min_element() < 2 {
        return Err(format!("a grid needs at least 2 points on every axis, got {} × {} × {}", dims.x, dims.y, dims.z));
    }
    if dims.max_element() > MAX_DIM || voxel_count(dims) > MAX_VOXELS {
        return Err(format!(
            "a {} × {} × {} grid is larger than Mirador reads ({MAX_DIM} points per axis, {MAX_VOXELS} in all)",
            dims.x, dims.y, dims.z
        ));
    }
    Ok(())
}

/// `(v − lo)/(hi − lo)` clamped to `[0, 1]`, 0 when `hi ≤ lo`: a data value as the transfer
/// function reads it. In `f32`, except for a range whose width overflows `f32` (data near
/// ±3.4e38): there `hi − lo` is infinite and `f32` would give ∞/∞ = NaN at `hi`, so the
/// quotient is taken in `f64`, where the width of any two `f32` values is finite.
pub fn normalize(v: f32, (lo, hi): (f32, f32)) -> f32 {
    if !(hi > lo) {
        return 0.0;
    }
    let width = hi - lo;
    let t = if width.is_finite() {
        (v - lo) / width
    } else {
        ((f64::from(v) - f64::from(lo)) / (f64::from(hi) - f64::from(lo))) as f32
    };
    t.clamp(0.0, 1.0)
}

/// The number of points of a grid of `dims`.
pub fn voxel_count(dims: UVec3) -> u64 {
    u64::from(dims.x) * u64::from(dims.y) * u64::from(dims.z)
}

fn unflatten(dims: UVec3, index: usize) -> (usize, usize, usize) {
    let (nx, ny) = (dims.x as usize, dims.y as usize);
    (index % nx, (index / nx) % ny, index / (nx * ny))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalizing_stays_finite_over_ranges_wider_than_f32_holds() {
        assert_eq!(normalize(2.5, (0.0, 10.0)), 0.25);
        assert_eq!(normalize(-4.0, (0.0, 10.0)), 0.0, "clamped below");
        assert_eq!(normalize(3.0, (1.0, 1.0)), 0.0, "an empty range");
        // hi − lo overflows f32: in f32, ∞/∞ at hi would be NaN.
        let (lo, hi) = (-3.0e38, 3.0e38);
        assert_eq!(normalize(hi, (lo, hi)), 1.0);
        assert_eq!(normalize(0.0, (lo, hi)), 0.5);
        let grid = Grid::new(UVec3::splat(2), Vec3::ONE, vec![lo, hi, 0.0, 1.0, lo, hi, hi, lo]).unwrap();
        let normalized = grid.normalized(grid.range());
        assert!(normalized.values.iter().all(|v| (0.0..=1.0).contains(v)), "{:?}", normalized.values);
        // A range one subnormal wide: its reciprocal overflows, the quotient does not.
        let tiny = f32::from_bits(1);
        assert_eq!(
            Grid::new(UVec3::splat(2), Vec3::ONE, vec![0.0, tiny, 0.0, 0.0, 0.0, 0.0, 0.0, tiny])
                .unwrap()
                .normalized((0.0, tiny))
                .values[..2],
            [0.0, 1.0]
        );
    }

    fn linear_grid() -> Grid {
        // f = 2x − y + 0.5z + 1 at the points of a 5 × 4 × 3 grid with uneven spacing.
        let dims = UVec3::new(5, 4, 3);
        let spacing = Vec3::new(0.5, 1.0, 2.0);
        let mut values = Vec::new();
        for z in 0..3 {
            for y in 0..4 {
                for x in 0..5 {
                    values.push(linear(Vec3::new(x as f32, y as f32, z as f32)));
                }
            }
        }
        Grid::new(dims, spacing, values).unwrap()
    }

    fn linear(g: Vec3) -> f32 {
        2.0 * g.x - g.y + 0.5 * g.z + 1.0
    }

    #[test]
    fn trilinear_interpolation_reproduces_a_linear_field_exactly() {
        let grid = linear_grid();
        for g in [Vec3::new(0.3, 1.7, 0.2), Vec3::new(3.99, 0.01, 1.5), Vec3::new(2.0, 3.0, 2.0), Vec3::splat(1.25)] {
            let v = grid.sample(g, Reconstruction::Trilinear);
            assert!((v - linear(g)).abs() < 1e-5, "at {g}: {v} vs {}", linear(g));
        }
    }

    #[test]
    fn nearest_takes_the_closest_grid_point() {
        let grid = linear_grid();
        assert_eq!(grid.sample(Vec3::new(0.4, 1.6, 0.5), Reconstruction::Nearest), linear(Vec3::new(0.0, 2.0, 1.0)));
        // Outside the grid the edge value is read, as a clamp-to-edge texture does.
        assert_eq!(grid.sample(Vec3::new(-3.0, 9.0, 1.0), Reconstruction::Nearest), linear(Vec3::new(0.0, 3.0, 1.0)));
    }

    #[test]
    fn gradients_of_a_linear_field_are_exact_inside_the_grid() {
        let grid = linear_grid();
        // df/dg = (2, −1, 0.5); per local unit divide by the spacing.
        let expected = Vec3::new(2.0 / 0.5, -1.0, 0.5 / 2.0);
        for differences in [Differences::Forward, Differences::Central] {
            let d = grid.gradient(Vec3::new(1.5, 1.2, 1.0), Reconstruction::Trilinear, differences);
            assert!((d - expected).abs().max_element() < 1e-4, "{differences:?}: {d}");
        }
    }

    #[test]
    fn sizes_spacing_and_values_are_checked() {
        let ok = |d: UVec3| vec![0.0; voxel_count(d) as usize];
        assert!(Grid::new(UVec3::new(1, 4, 4), Vec3::ONE, ok(UVec3::new(1, 4, 4))).unwrap_err().contains("at least 2"));
        assert!(
            Grid::new(UVec3::splat(2), Vec3::new(1.0, 0.0, 1.0), ok(UVec3::splat(2))).unwrap_err().contains("spacing")
        );
        assert!(Grid::new(UVec3::splat(2), Vec3::ONE, vec![0.0; 7]).unwrap_err().contains("needs 8 values, got 7"));
        let mut values = ok(UVec3::splat(2));
        values[5] = f32::NAN;
        assert!(Grid::new(UVec3::splat(2), Vec3::ONE, values).unwrap_err().contains("voxel (1, 0, 1) is NaN"));
    }

    #[test]
    fn a_function_fills_the_unit_cube() {
        let grid = Grid::from_function(UVec3::new(3, 5, 2), |p| p.x + 10.0 * p.y + 100.0 * p.z).unwrap();
        assert_eq!(grid.half_extent(), Vec3::ONE);
        assert_eq!(grid.at(0, 0, 0), -111.0);
        assert_eq!(grid.at(2, 4, 1), 111.0);
        assert_eq!(grid.at(1, 2, 0), -100.0);
    }
}
