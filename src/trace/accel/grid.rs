//! Uniform grid walked by 3D-DDA.
//!
//! Seed 003 ("Scena divizata în volume încadratoare"): the scene's bounding box is divided into
//! equal voxels, each listing the objects it contains (an object may be listed in several).
//! A ray is tested only against the objects of the voxels it passes through, visited in order
//! from the one where it enters the scene by a 3D DDA, "the extension to 3D of the DDA algorithm
//! for rasterizing lines", and the walk stops at the first voxel that yields a hit.
//!
//! **Resolution.** About `λ·N` cells for `N` primitives (λ = [`CELLS_PER_PRIMITIVE`]), shaped
//! like the scene's box: `n_i = round(d_i·∛(λN/V))` cells along an axis of length `d_i` of a box
//! of volume `V`, each at most [`MAX_RESOLUTION`]. Each primitive is listed in every cell its
//! (slightly padded) bounding box overlaps, in one flat array indexed by cell.
//!
//! **Walk** (Amanatides and Woo, 1987): from the entry point's cell, `t_next[a]` is the distance
//! to the next cell boundary on axis `a` and `Δt[a] = cell_size[a]/|d[a]|`; the walk steps along
//! the axis with the smallest `t_next`. A primitive that spans several cells may be hit outside
//! the cell being visited, so the walk keeps the nearest hit of every primitive tested and
//! stops once that hit lies inside the cells already visited (`t_hit ≤` the current cell's
//! exit), which is exactly when no later cell can hold a nearer one. A small mailbox skips
//! primitives already tested for this ray. Per ray the cost is O(cells crossed + primitives in
//! them): O(∛N) for evenly spread scenes.
//!
//! Limits: one resolution for the whole scene ("teapot in a stadium"): a small detailed object
//! in a large empty scene falls into a few cells, and large primitives are listed many times.

use web_time::Instant;

use glam::{UVec3, Vec3};

use super::{AccelStats, Accelerator, Hit, Mailbox, offer};
use crate::base::Ray;
use crate::trace::geometry::{Aabb, PreparedRay, Primitive};

/// Target cells per primitive (λ).
pub const CELLS_PER_PRIMITIVE: f32 = 3.0;
/// Cells along each axis at most.
pub const MAX_RESOLUTION: u32 = 128;

/// A uniform grid of cells listing the primitives their boxes overlap.
pub struct Grid {
    bounds: Aabb,
    resolution: UVec3,
    cell_size: Vec3,
    /// Cell `c`'s primitives are `cell_prims[cell_start[c]..cell_start[c + 1]]`.
    cell_start: Vec<u32>,
    cell_prims: Vec<u32>,
    stats: AccelStats,
}

impl Grid {
    pub fn build(prims: &[Primitive]) -> Grid {
        let start = Instant::now();
        let boxes: Vec<Aabb> = prims.iter().map(Primitive::bounds).collect();
        let scene = boxes.iter().filter(|b| !b.is_empty()).fold(Aabb::EMPTY, |s, b| s.union(b));
        let valid = boxes.iter().filter(|b| !b.is_empty()).count();
        // A margin keeps flat scenes (a single plane) three-dimensional and puts hit points that
        // rounding moved off a primitive's box into a cell that lists it.
        let margin = 1e-5 * scene.extent().max_element().max(scene.min.abs().max(scene.max.abs()).max_element());
        let bounds = if scene.is_empty() { Aabb::new(Vec3::ZERO, Vec3::ONE) } else { scene.padded(margin.max(1e-6)) };
        let extent = bounds.extent();
        let density = (CELLS_PER_PRIMITIVE * valid.max(1) as f32 / (extent.x * extent.y * extent.z)).cbrt();
        let resolution = (extent * density).round().clamp(Vec3::ONE, Vec3::splat(MAX_RESOLUTION as f32)).as_uvec3();
        let cell_size = extent / resolution.as_vec3();
        let cells = (resolution.x * resolution.y * resolution.z) as usize;

        let mut grid = Grid {
            bounds,
            resolution,
            cell_size,
            cell_start: vec![0; cells + 1],
            cell_prims: Vec::new(),
            stats: AccelStats {
                name: "uniform grid (3D-DDA)",
                primitives: prims.len(),
                nodes: cells,
                leaves: 0,
                depth: 0,
                references: 0,
                memory_bytes: 0,
                build_time: Default::default(),
            },
        };
        // Two passes: count each cell's primitives, then fill the flat array.
        let ranges: Vec<Option<(UVec3, UVec3)>> = boxes
            .iter()
            .map(|b| (!b.is_empty()).then(|| (grid.cell_of(b.min - margin), grid.cell_of(b.max + margin))))
            .collect();
        for (lo, hi) in ranges.iter().flatten() {
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        let c = grid.cell_index(UVec3::new(x, y, z));
                        grid.cell_start[c + 1] += 1;
                    }
                }
            }
        }
        for c in 0..cells {
            grid.cell_start[c + 1] += grid.cell_start[c];
        }
        let mut fill = grid.cell_start.clone();
        grid.cell_prims = vec![0; grid.cell_start[cells] as usize];
        for (i, range) in ranges.iter().enumerate() {
            let Some((lo, hi)) = range else { continue };
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        let c = grid.cell_index(UVec3::new(x, y, z));
                        grid.cell_prims[fill[c] as usize] = i as u32;
                        fill[c] += 1;
                    }
                }
            }
        }
        grid.stats.leaves = grid.cell_start.windows(2).filter(|w| w[1] > w[0]).count();
        grid.stats.references = grid.cell_prims.len();
        grid.stats.memory_bytes = 4 * (grid.cell_start.len() + grid.cell_prims.len());
        grid.stats.build_time = start.elapsed();
        grid
    }

    /// The cell containing `p`, clamped into the grid.
    fn cell_of(&self, p: Vec3) -> UVec3 {
        let c = ((p - self.bounds.min) / self.cell_size).floor();
        c.clamp(Vec3::ZERO, (self.resolution - 1).as_vec3()).as_uvec3()
    }

    fn cell_index(&self, c: UVec3) -> usize {
        (c.x + self.resolution.x * (c.y + self.resolution.y * c.z)) as usize
    }

    fn walk<const ANY: bool>(&self, prims: &[Primitive], ray: &Ray, t_min: f32, mut t_max: f32) -> Option<Hit> {
        let prepared = PreparedRay::new(ray)?;
        let (origin, inv) = (ray.origin, Vec3::from(prepared.inv_direction));
        let (t_enter, t_exit) = self.bounds.intersect_inv(origin, inv, t_min, t_max)?;
        let mut cell = self.cell_of(ray.at(t_enter)).as_ivec3();
        let resolution = self.resolution.as_ivec3();
        let mut step = [0i32; 3];
        let mut t_next = [f32::INFINITY; 3];
        let next_boundary = |axis: usize, cell: i32, step: i32| {
            let boundary = self.bounds.min[axis] + (cell + (step > 0) as i32) as f32 * self.cell_size[axis];
            (boundary - origin[axis]) * inv[axis]
        };
        for axis in 0..3 {
            // A zero direction component never crosses a boundary on that axis (and would give
            // 0·∞ = NaN for an origin on one).
            if ray.direction[axis] != 0.0 {
                step[axis] = if ray.direction[axis] > 0.0 { 1 } else { -1 };
                t_next[axis] = next_boundary(axis, cell[axis], step[axis]);
            }
        }
        let mut mailbox = Mailbox::new();
        let mut best = None;
        // A straight walk crosses each axis's cells at most once; the bound guards the loop
        // against directions so small that their inverse overflows.
        for _ in 0..resolution.element_sum() {
            let c = self.cell_index(cell.as_uvec3());
            for &p in &self.cell_prims[self.cell_start[c] as usize..self.cell_start[c + 1] as usize] {
                if !mailbox.first_visit(p) {
                    continue;
                }
                if let Some(t) = prims[p as usize].intersect_prepared(ray, &prepared, t_min, t_max)
                    && offer(&mut best, t, p)
                {
                    if ANY {
                        return best;
                    }
                    t_max = t.next_up();
                }
            }
            let axis = if t_next[0] <= t_next[1] && t_next[0] <= t_next[2] {
                0
            } else if t_next[1] <= t_next[2] {
                1
            } else {
                2
            };
            let cell_exit = t_next[axis];
            // Every point before the nearest hit has been covered by the cells visited so far.
            if t_max <= cell_exit || cell_exit > t_exit {
                return best;
            }
            cell[axis] += step[axis];
            if cell[axis] < 0 || cell[axis] >= resolution[axis] {
                return best;
            }
            t_next[axis] = next_boundary(axis, cell[axis], step[axis]);
        }
        best
    }
}

impl Accelerator for Grid {
    fn closest(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        self.walk::<false>(prims, ray, t_min, t_max)
    }

    fn occluded(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> bool {
        self.walk::<true>(prims, ray, t_min, t_max).is_some()
    }

    fn stats(&self) -> AccelStats {
        self.stats.clone()
    }
}
