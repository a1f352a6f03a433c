//! Ray–scene intersection: which primitive a ray meets first, and whether it meets any.
//!
//! Seed 000 §2.2: testing every primitive ("fuerza bruta") costs O(n) per ray; spatial indexing
//! discards whole parts of the scene whose bounding volume the ray misses, for O(log n). Seed 003
//! names three ways to index space, all implemented here behind one [`Accelerator`] trait, the
//! first in two layouts:
//!
//! - [`bvh`]: a bounding volume hierarchy, binary, as the course builds it;
//! - [`wide`]: the same hierarchy collapsed into eight-wide nodes tested with SIMD (the
//!   default, and the fastest: not one of the notes' structures, but how tracers run a BVH);
//! - [`grid`]: a uniform grid of voxels walked by 3D-DDA;
//! - [`octree`]: an adaptive octree;
//! - [`BruteForce`]: every primitive, every ray: the reference the others are tested against.
//!
//! All five return the same nearest hit (the same primitive, or one at the same `t` when two
//! tie), which `tests/accel.rs` checks on thousands of random rays. Each is built once per scene
//! from the primitives of [`crate::trace::geometry::scene_primitives`] and must then be queried
//! with that same slice.

pub mod bvh;
pub mod grid;
pub mod octree;
pub mod wide;

use std::fmt;
use std::time::Duration;

use web_time::Instant;

use crate::base::Ray;
use crate::trace::geometry::{PreparedRay, Primitive};

/// The nearest hit: its distance along the ray and the index of the primitive in the slice the
/// accelerator was built from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub primitive: u32,
}

/// Offers a hit found during traversal: it becomes the best if it is nearer, or equally near with
/// a lower primitive index. That tie-break (coplanar surfaces give exact ties) is shared by every
/// accelerator, so all of them draw the same image. Returns whether the hit was taken; the caller
/// then narrows its far bound to `t.next_up()`, one step past the hit, so that equally near
/// candidates are still tested.
pub(crate) fn offer(best: &mut Option<Hit>, t: f32, primitive: u32) -> bool {
    let better = best.is_none_or(|b| t < b.t || (t == b.t && primitive < b.primitive));
    if better {
        *best = Some(Hit { t, primitive });
    }
    better
}

/// What an accelerator looks like once built, for logs and teaching views.
#[derive(Clone, Debug, PartialEq)]
pub struct AccelStats {
    pub name: &'static str,
    pub primitives: usize,
    /// Tree nodes, or grid cells.
    pub nodes: usize,
    /// Leaves (non-empty cells for the grid).
    pub leaves: usize,
    /// Deepest leaf (the grid: 0).
    pub depth: usize,
    /// Primitive references stored in leaves or cells: more than `primitives` where a primitive
    /// is listed in every cell it overlaps.
    pub references: usize,
    pub memory_bytes: usize,
    pub build_time: Duration,
}

impl fmt::Display for AccelStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: {} primitives, {} nodes, {} leaves, depth {}, {} references, {:.1} MiB, built in {:.1} ms",
            self.name,
            self.primitives,
            self.nodes,
            self.leaves,
            self.depth,
            self.references,
            self.memory_bytes as f64 / (1024.0 * 1024.0),
            self.build_time.as_secs_f64() * 1e3
        )
    }
}

/// A structure that finds ray–primitive hits faster than testing every primitive.
pub trait Accelerator: Send + Sync {
    /// The nearest hit with `t` in the open interval `(t_min, t_max)`.
    fn closest(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit>;
    /// Whether anything is hit in `(t_min, t_max)`: stops at the first hit found (shadow rays).
    fn occluded(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> bool;
    fn stats(&self) -> AccelStats;

    /// The nearest hit of each of `rays` into `hits`: [`Self::closest`] for each. Coherent rays
    /// (neighbouring pixels' primary rays, in blocks of 16) are traced together where the
    /// accelerator can ([`wide::packets`]), with the same hits.
    fn closest_packets(&self, prims: &[Primitive], rays: &[Ray], t_min: f32, t_max: f32, hits: &mut [Option<Hit>]) {
        for (ray, hit) in rays.iter().zip(hits) {
            *hit = self.closest(prims, ray, t_min, t_max);
        }
    }

    /// Whether anything is hit along each of `rays` in `(t_min, t_max[i])`, into `occluded`:
    /// [`Self::occluded`] for each, or 16 at a time where the accelerator can
    /// ([`wide::packets`]), with the same answers. The tracer casts its shadow rays one by one:
    /// packets of them measured slower (docs/performance.md); `benches/trace.rs` keeps the
    /// comparison.
    fn occluded_packets(
        &self,
        prims: &[Primitive],
        rays: &[Ray],
        (t_min, t_max): (f32, &[f32]),
        occluded: &mut [bool],
    ) {
        for ((ray, &t_max), answer) in rays.iter().zip(t_max).zip(occluded) {
            *answer = self.occluded(prims, ray, t_min, t_max);
        }
    }
}

pub use crate::settings::AccelKind;

/// Builds the accelerator `kind` over `prims`; query it with the same slice.
pub fn build(kind: AccelKind, prims: &[Primitive]) -> Box<dyn Accelerator> {
    match kind {
        AccelKind::Wide => Box::new(wide::Wide::build(prims)),
        AccelKind::Bvh => Box::new(bvh::Bvh::build(prims)),
        AccelKind::Grid => Box::new(grid::Grid::build(prims)),
        AccelKind::Octree => Box::new(octree::Octree::build(prims)),
        AccelKind::None => Box::new(BruteForce::build(prims)),
    }
}

/// Every primitive for every ray: O(n) per ray, and the reference for the others.
pub struct BruteForce {
    stats: AccelStats,
}

impl BruteForce {
    pub fn build(prims: &[Primitive]) -> BruteForce {
        let start = Instant::now();
        let stats = AccelStats {
            name: "none (brute force)",
            primitives: prims.len(),
            nodes: 0,
            leaves: 0,
            depth: 0,
            references: prims.len(),
            memory_bytes: 0,
            build_time: start.elapsed(),
        };
        BruteForce { stats }
    }
}

impl Accelerator for BruteForce {
    fn closest(&self, prims: &[Primitive], ray: &Ray, t_min: f32, mut t_max: f32) -> Option<Hit> {
        let prepared = PreparedRay::new(ray)?;
        let mut best = None;
        for (i, prim) in prims.iter().enumerate() {
            if let Some(t) = prim.intersect_prepared(ray, &prepared, t_min, t_max) {
                t_max = t;
                best = Some(Hit { t, primitive: i as u32 });
            }
        }
        best
    }

    fn occluded(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> bool {
        let Some(prepared) = PreparedRay::new(ray) else {
            return false;
        };
        prims.iter().any(|prim| prim.intersect_prepared(ray, &prepared, t_min, t_max).is_some())
    }

    fn stats(&self) -> AccelStats {
        self.stats.clone()
    }
}

/// A tiny direct-mapped cache of the primitives a ray has already been tested against, for the
/// grid and the octree, which list a primitive in every cell it overlaps ("mailboxing"). A
/// forgotten entry only costs a repeated test, never a wrong answer.
pub(crate) struct Mailbox {
    slots: [u32; 16],
}

impl Mailbox {
    pub(crate) fn new() -> Mailbox {
        Mailbox { slots: [u32::MAX; 16] }
    }

    /// True the first time `primitive` is seen (as far as the cache remembers).
    #[inline]
    pub(crate) fn first_visit(&mut self, primitive: u32) -> bool {
        let slot = &mut self.slots[primitive as usize & 15];
        if *slot == primitive {
            false
        } else {
            *slot = primitive;
            true
        }
    }
}
