//! Displacement tessellated on the GPU, adaptively (docs/course/04-bump-mapping.md,
//! "Displacement mapping"; `bump.tessellation = "adaptive"`): the surface `p + k·f(u, v)·n` made
//! every frame the view changes, in a compute shader (`shaders/tessellation.wgsl`), as finely as
//! the screen needs and no finer.
//!
//! What it teaches, and how it is built (by hand: this is the technique):
//!
//! - **A level per edge, from the screen.** Each edge of the object's own mesh is split into `e`
//!   pieces: enough that none spans more than `bump.edge_pixels` on screen, never more than the
//!   height field has detail for (`bump.displacement_texels`, the uniform mesh's rule), at most
//!   [`MAX_LEVEL`]. The level is the edge's, computed from the edge alone (its two ends, both
//!   sides' texture coordinates), so the two triangles that share it agree on it.
//! - **A triangle split `n` ways, its edges snapped.** A triangle is split into the `n²`
//!   triangles of a grid, `n` the largest of its edges' levels. A grid point on an edge of level
//!   `e < n` is moved to the nearest of the edge's own `e + 1` points ([`snap`]): the triangle's
//!   side is then made of the very pieces its neighbour's side is made of, and a few of its
//!   triangles fold to nothing (zero area, never drawn). That is how neighbours of different
//!   levels meet without cracks or T-junctions, the compute-shader way (Khoury, Dupuy and
//!   Riccio); hardware tessellators do the same with fractional spacing.
//! - **One point, one computation.** A point on an edge is computed from the edge's ends in one
//!   order (the welded corner with the smaller number first), with the height the mean of the two
//!   sides' (a texture seam's two `u`s), along the mean of their normals: the same operations on
//!   the same numbers, so the same bits on either side. Corners are moved once, on the CPU, by the
//!   mean of every vertex at their point ([`crate::texture::displacement`]'s rule).
//! - **The displaced surface's normal**: `N = ∂P/∂u × ∂P/∂v` of `P = p + k·f·n`, with
//!   `∂P/∂u = t_u + k·f_u·n + k·f·∂n/∂u`: bump mapping's perturbed normal, plus the curvature
//!   term bump mapping leaves out (the surface is moved, so its tangents stretch). The mesh's
//!   `t_u` is constant across a triangle; it is first made tangent to the smooth surface (whose
//!   normal is the corners' interpolated one), or the facets of the mesh would show through.
//! - **A bound.** All displaced objects together get at most [`MAX_TRIANGLES`] triangles: past
//!   that, the edges are allowed longer on screen until they fit, and the length used is said
//!   (`--stats`, the viewer's notice).
//!
//! [`Patches`] is the CPU's part (the mesh welded and made ready, the levels each frame);
//! [`pass::TessellationPass`] the GPU's. [`Patches::tessellate`] makes the same triangles on the
//! CPU, for the tessellation teaching view and for the tests that check the GPU's against it.

pub mod pass;
mod patches;

pub use patches::{GpuPatch, Levels, Patches, bounded_levels};

/// The most pieces one edge is split into, and so the finest split of a triangle (`n²` from one).
pub const MAX_LEVEL: u32 = 64;

/// The most triangles adaptive tessellation makes for all displaced objects together, the uniform
/// mesh's bound: 24 MB of indices.
pub const MAX_TRIANGLES: u64 = crate::texture::displacement::MAX_TRIANGLES as u64;

/// The most vertices it makes: 96 MB, under the storage binding every WebGPU device allows
/// (128 MiB).
pub const MAX_VERTICES: u64 = 2_000_000;

/// Where grid point `(a, b)` of a triangle split `n` ways lies (weights `(n − a − b, a, b)/n` of
/// corners 0, 1, 2), once its edges' points are snapped to their levels `edges` (edge 0 runs
/// from corner 0 to 1, edge 1 from 1 to 2, edge 2 from 2 to 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridPoint {
    Corner(usize),
    /// `step` of the edge's `edges[edge]` steps from the edge's first end (its own order).
    Edge {
        edge: usize,
        step: u32,
    },
    Interior,
}

/// Grid point `(a, b)` of a triangle split `n` ways with edge levels `edges` (WGSL twin:
/// `grid_point` in `shaders/tessellation.wgsl`).
pub fn grid_point(n: u32, edges: [u32; 3], a: u32, b: u32) -> GridPoint {
    let c = n - a - b;
    match (a, b, c) {
        (0, 0, _) => GridPoint::Corner(0),
        (_, 0, 0) => GridPoint::Corner(1),
        (0, _, 0) => GridPoint::Corner(2),
        (_, 0, _) => GridPoint::Edge { edge: 0, step: snap(a, n, edges[0]) },
        (_, _, 0) => GridPoint::Edge { edge: 1, step: snap(b, n, edges[1]) },
        (0, _, _) => GridPoint::Edge { edge: 2, step: snap(c, n, edges[2]) },
        _ => GridPoint::Interior,
    }
}

/// Step `s` of `n` along an edge of level `e ≤ n`, moved to the nearest of the edge's own points:
/// `round(s·e/n)`, halves up. Consecutive steps move by at most one point, so every one of the
/// edge's points is met, and the pieces between them are the neighbour's.
pub fn snap(s: u32, n: u32, e: u32) -> u32 {
    (2 * s * e + n) / (2 * n)
}

/// The vertices of a triangle split `n` ways: `(n + 1)(n + 2)/2`.
pub fn vertex_count(n: u32) -> u32 {
    (n + 1) * (n + 2) / 2
}

/// The index of grid point `(a, b)` among a split triangle's vertices, row `b` after row `b − 1`.
pub fn vertex_index(n: u32, a: u32, b: u32) -> u32 {
    b * (n + 1) - b * b.saturating_sub(1) / 2 + a
}

/// The `t`-th of the `n²` triangles of a triangle split `n` ways, as three grid points: row by
/// row, in a row the upright triangle at `a` then the one upside down beside it.
pub fn grid_triangle(n: u32, t: u32) -> [(u32, u32); 3] {
    let (mut b, mut first) = (0, 0);
    while first + 2 * (n - b) - 1 <= t {
        first += 2 * (n - b) - 1;
        b += 1;
    }
    let r = t - first;
    let a = r / 2;
    if r.is_multiple_of(2) { [(a, b), (a + 1, b), (a, b + 1)] } else { [(a + 1, b), (a + 1, b + 1), (a, b + 1)] }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_edge_point_is_met_and_the_grid_is_listed_once() {
        for n in 1..=12 {
            for e in 1..=n {
                let steps: Vec<u32> = (0..=n).map(|s| snap(s, n, e)).collect();
                assert_eq!((steps[0], steps[n as usize]), (0, e));
                assert!(steps.windows(2).all(|w| w[1] == w[0] || w[1] == w[0] + 1), "n {n} e {e}: {steps:?}");
            }
            let mut seen = std::collections::HashSet::new();
            for b in 0..=n {
                for a in 0..=(n - b) {
                    assert!(seen.insert(vertex_index(n, a, b)));
                }
            }
            assert_eq!(seen.len() as u32, vertex_count(n));
            assert!(seen.iter().all(|&i| i < vertex_count(n)));
            // The triangles: n² of them, each once, the CPU's split (displacement::subdivided) order.
            let triangles: std::collections::HashSet<_> = (0..n * n).map(|t| grid_triangle(n, t)).collect();
            assert_eq!(triangles.len() as u32, n * n);
        }
    }
}
