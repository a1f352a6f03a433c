//! Bounding volume hierarchy: a binary tree of boxes, each enclosing a group of primitives.
//!
//! Seed 003 ("Ierarhie de volume incadratoare", BVH): the root's box encloses the whole scene,
//! each leaf holds one or a few objects, inner nodes enclose groups; a ray that misses a node's
//! box cannot hit anything below it, so the whole subtree is skipped. Seed 000 §2.2: this turns
//! the O(n) brute force into O(log n) per ray.
//!
//! **Build: binned surface area heuristic.** The chance that a ray through a node's box also
//! hits a child's box is the ratio of their surface areas, so splitting a node `P` into `L` and
//! `R` costs, in expectation,
//!
//! ```text
//! C(split) = C_trav + C_isect·(A(L)·N(L) + A(R)·N(R)) / A(P)      C(leaf) = C_isect·N(P)
//! ```
//!
//! The primitives' centroids are dropped into [`BINS`] equal bins along the longest axis of the
//! centroid bounds; the cost of the `BINS − 1` planes between bins comes from one sweep from each
//! side. A node becomes a leaf when no split is cheaper and it holds at most [`MAX_LEAF`]
//! primitives (more are always split), or at depth [`MAX_DEPTH`]. Build time O(n log n).
//!
//! **Layout.** Nodes are flattened depth first into an array of 32-byte nodes: box, one `u32`
//! and a count. An inner node (count 0) stores the index of its left child; the right child is
//! always the next node, since siblings are allocated as a pair. A leaf stores the first of its
//! `count` primitives in leaf order. The tree keeps its own copy of the triangles' vertices in
//! leaf order, so a leaf's triangles are read from consecutive memory.
//!
//! **Traversal.** Iterative, with a fixed stack of [`MAX_DEPTH`] entries: both children's boxes
//! are tested, the nearer is visited first and the farther pushed with its entry distance; every
//! hit shrinks `t_max`, and a popped node that starts beyond it is skipped. Shadow rays
//! (`occluded`) stop at the first hit, and since any hit will do they skip the ordering. The
//! box test is Kay–Kajiya slabs made conservative as in Ize, "Robust BVH Ray Traversal" (JCGT
//! 2013): the exit distance is scaled by `1 + 2γ₃`, so rounding never lets a ray slip past a box
//! its primitive is hit in, which the watertight triangle test relies on. Only a ray with a zero
//! direction component can meet `0·∞ = NaN`; it is traversed by a copy of the loop that picks
//! each slab's near plane by the direction's sign, the others by the cheaper `min`/`max` of the
//! two plane distances. Cost per ray O(log n) for well-distributed scenes, and on a CPU it is
//! instruction-bound rather than memory-bound for a million triangles: about 37 box tests and 2
//! triangle tests per primary ray (`benches/trace.rs`).
//!
//! Limits: the build is single-threaded and uses object splits only (no spatial splits), so
//! long thin triangles crossing each other's boxes make deeper trees than necessary.

use web_time::Instant;

use glam::{BVec3A, Vec3A, Vec4};

use super::{AccelStats, Accelerator, Hit, offer};
use crate::base::Ray;
use crate::trace::geometry::{Aabb, PreparedRay, Primitive, intersect_triangle};

/// Bins per node along the split axis.
pub const BINS: usize = 16;
/// Leaves hold at most this many primitives (unless the tree is [`MAX_DEPTH`] deep).
pub const MAX_LEAF: usize = 4;
/// The deepest a leaf may be; also the traversal stack's size.
pub const MAX_DEPTH: usize = 64;
/// `C_trav / C_isect` of the SAH: a box test against a triangle test.
const TRAVERSAL_COST: f32 = 1.0;
/// Ize's `1 + 2γ₃`, `γ_n = nε/(1 − nε)` with ε = 2⁻²⁴.
pub(super) const ROBUST_EXIT: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON / 2.0) / (1.0 - 3.0 * f32::EPSILON / 2.0);
/// Marks an analytic primitive in `Bvh::order`.
pub(super) const ANALYTIC: u32 = 1 << 31;

/// 32 bytes: `lo = (min, first)`, `hi = (max, count)`, with the two integers stored as f32 bits
/// so that each half loads as one 16-byte vector.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct Node {
    lo: [f32; 4],
    hi: [f32; 4],
}

impl Node {
    fn new(bounds: &Aabb, first: u32, count: u32) -> Node {
        let (min, max) = (bounds.min, bounds.max);
        Node { lo: [min.x, min.y, min.z, f32::from_bits(first)], hi: [max.x, max.y, max.z, f32::from_bits(count)] }
    }

    /// The node's box, as `(min, max)`.
    pub(super) fn bounds(&self) -> (Vec3A, Vec3A) {
        (Vec3A::from_slice(&self.lo[..3]), Vec3A::from_slice(&self.hi[..3]))
    }

    /// Left child (inner node) or first primitive (leaf).
    #[inline(always)]
    pub(super) fn first(&self) -> u32 {
        self.lo[3].to_bits()
    }

    /// 0 for an inner node.
    #[inline(always)]
    pub(super) fn count(&self) -> u32 {
        self.hi[3].to_bits()
    }
}

/// The per-ray constants of the box test.
struct NodeRay {
    origin: Vec3A,
    inv_direction: Vec3A,
    /// Axes along which the ray runs toward −∞: their near plane is the box's max.
    negative: BVec3A,
}

impl NodeRay {
    fn new(ray: &PreparedRay) -> NodeRay {
        let negative = BVec3A::new(
            ray.inv_direction.x.is_sign_negative(),
            ray.inv_direction.y.is_sign_negative(),
            ray.inv_direction.z.is_sign_negative(),
        );
        NodeRay { origin: ray.origin, inv_direction: ray.inv_direction, negative }
    }

    /// Whether a direction component is zero (or so small that its inverse overflows): only
    /// then can `0·∞ = NaN` arise, and only then does the box test need to pick the near plane
    /// by the direction's sign instead of taking the smaller of the two slab distances.
    fn needs_careful_slabs(&self) -> bool {
        !self.inv_direction.is_finite()
    }

    /// The entry distance into the node's box within `[t_min, t_max]`, or ∞ on a miss.
    #[inline(always)]
    fn entry<const CAREFUL: bool>(&self, node: &Node, t_min: f32, t_max: f32) -> f32 {
        let lo = Vec3A::from_vec4(Vec4::from_array(node.lo));
        let hi = Vec3A::from_vec4(Vec4::from_array(node.hi));
        let (near, far) = if CAREFUL {
            let near = (Vec3A::select(self.negative, hi, lo) - self.origin) * self.inv_direction;
            let far = (Vec3A::select(self.negative, lo, hi) - self.origin) * self.inv_direction;
            // 0·∞ = NaN where the origin lies on the plane of a slab the ray runs along: that
            // slab does not bound the ray. Said outright: how `max` and `min` treat a NaN differs
            // between SSE2 (the second operand wins), simd128 (the first) and plain floats.
            (
                Vec3A::select(near.is_nan_mask(), Vec3A::NEG_INFINITY, near),
                Vec3A::select(far.is_nan_mask(), Vec3A::INFINITY, far),
            )
        } else {
            let (a, b) = ((lo - self.origin) * self.inv_direction, (hi - self.origin) * self.inv_direction);
            (a.min(b), a.max(b))
        };
        let enter = near.max(Vec3A::splat(t_min)).max_element();
        let exit = (far * ROBUST_EXIT).min(Vec3A::splat(t_max)).min_element();
        if enter <= exit { enter } else { f32::INFINITY }
    }
}

/// A bounding volume hierarchy built with the binned SAH.
pub struct Bvh {
    /// A node's children come after it, and the two children of a node are adjacent.
    pub(super) nodes: Vec<Node>,
    /// Primitive indices in leaf order; [`ANALYTIC`] marks the non-triangles.
    pub(super) order: Vec<u32>,
    /// The triangles' vertices in leaf order (zeros in the slots of analytic primitives).
    pub(super) triangles: Vec<[Vec3A; 3]>,
    stats: AccelStats,
}

/// What the build needs of a primitive: its box and where it came from.
#[derive(Clone, Copy)]
struct BuildPrim {
    bounds: Bounds,
    index: u32,
}

/// A box in SIMD registers, for the build's inner loops.
#[derive(Clone, Copy)]
struct Bounds {
    min: Vec3A,
    max: Vec3A,
}

impl Bounds {
    const EMPTY: Bounds = Bounds { min: Vec3A::INFINITY, max: Vec3A::NEG_INFINITY };

    #[inline(always)]
    fn union(self, other: Bounds) -> Bounds {
        Bounds { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    #[inline(always)]
    fn including(self, p: Vec3A) -> Bounds {
        Bounds { min: self.min.min(p), max: self.max.max(p) }
    }

    #[inline(always)]
    fn centroid(&self) -> Vec3A {
        0.5 * (self.min + self.max)
    }

    /// Half the surface area (the SAH only compares ratios); 0 for an empty box.
    #[inline(always)]
    fn half_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    fn to_aabb(self) -> Aabb {
        Aabb::new(self.min.into(), self.max.into())
    }
}

/// Primitives gathered in a bin, or on one side of a split: their boxes' union, their
/// centroids' box and how many there are.
#[derive(Clone, Copy)]
struct Group {
    bounds: Bounds,
    centroids: Bounds,
    count: usize,
}

impl Group {
    const EMPTY: Group = Group { bounds: Bounds::EMPTY, centroids: Bounds::EMPTY, count: 0 };

    fn of(prims: &[BuildPrim]) -> Group {
        prims.iter().fold(Group::EMPTY, |g, p| g.with(p))
    }

    #[inline(always)]
    fn with(self, p: &BuildPrim) -> Group {
        Group {
            bounds: self.bounds.union(p.bounds),
            centroids: self.centroids.including(p.bounds.centroid()),
            count: self.count + 1,
        }
    }

    #[inline(always)]
    fn union(self, other: &Group) -> Group {
        Group {
            bounds: self.bounds.union(other.bounds),
            centroids: self.centroids.union(other.centroids),
            count: self.count + other.count,
        }
    }

    /// `A·N`, the SAH's weight of this side of a split.
    fn cost(&self) -> f32 {
        self.bounds.half_area() * self.count as f32
    }
}

/// A chosen split: bins `0..=bin` along `axis` go left.
struct Split {
    axis: usize,
    lo: f32,
    scale: f32,
    bin: usize,
    /// `(A(L)·N(L) + A(R)·N(R)) / A(P)`.
    cost: f32,
    left: Group,
    right: Group,
}

/// The bin of a primitive whose centroid is `c`, along `axis`.
#[inline(always)]
fn bin_index(c: Vec3A, axis: usize, lo: f32, scale: f32) -> usize {
    let x = match axis {
        0 => c.x,
        1 => c.y,
        _ => c.z,
    };
    ((x - lo) * scale).min((BINS - 1) as f32) as usize
}

/// The best SAH split of `prims` (whose union is `node`) between bins along the longest axis of
/// their centroids' box, or `None` if the centroids coincide.
fn best_split(prims: &[BuildPrim], node: &Group) -> Option<Split> {
    let extent = node.centroids.max - node.centroids.min;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    if !(extent[axis] > 0.0) {
        return None;
    }
    let (lo, scale) = (node.centroids.min[axis], BINS as f32 / extent[axis]);
    let mut bins = [Group::EMPTY; BINS];
    for p in prims {
        let b = bin_index(p.bounds.centroid(), axis, lo, scale);
        bins[b] = bins[b].with(p);
    }
    // right[i]: bins i+1.., the right side of the plane after bin i.
    let mut right = [Group::EMPTY; BINS];
    for i in (0..BINS - 1).rev() {
        right[i] = right[i + 1].union(&bins[i + 1]);
    }
    let mut left = Group::EMPTY;
    let mut best: Option<Split> = None;
    let area = node.bounds.half_area().max(f32::MIN_POSITIVE);
    for i in 0..BINS - 1 {
        left = left.union(&bins[i]);
        if left.count == 0 || right[i].count == 0 {
            continue;
        }
        let cost = (left.cost() + right[i].cost()) / area;
        if best.as_ref().is_none_or(|b| cost < b.cost) {
            best = Some(Split { axis, lo, scale, bin: i, cost, left, right: right[i] });
        }
    }
    best
}

/// Reorders `prims` so that those with `left(p)` come first; returns how many did.
fn partition(prims: &mut [BuildPrim], left: impl Fn(&BuildPrim) -> bool) -> usize {
    let (mut i, mut j) = (0, prims.len());
    while i < j {
        if left(&prims[i]) {
            i += 1;
        } else {
            j -= 1;
            prims.swap(i, j);
        }
    }
    i
}

impl Bvh {
    pub fn build(prims: &[Primitive]) -> Bvh {
        let start = Instant::now();
        let mut build: Vec<BuildPrim> = prims
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let b = p.bounds();
                BuildPrim { bounds: Bounds { min: b.min.into(), max: b.max.into() }, index: i as u32 }
            })
            .filter(|p| p.bounds.min.cmple(p.bounds.max).all())
            .collect();
        let mut nodes: Vec<Node> = Vec::with_capacity(2 * build.len() / MAX_LEAF + 1);
        let (mut depth, mut leaves) = (0, 0);
        if !build.is_empty() {
            let root = Group::of(&build);
            nodes.push(Node::new(&root.bounds.to_aabb(), 0, 0));
            // (node, its primitives' range, depth, their group): the node's box is already written.
            let mut work = vec![(0usize, 0usize, build.len(), 0usize, root)];
            while let Some((node, first, end, level, group)) = work.pop() {
                depth = depth.max(level);
                let range = &mut build[first..end];
                let count = range.len();
                let children = if level >= MAX_DEPTH - 1 || count == 1 {
                    None
                } else {
                    match best_split(range, &group) {
                        Some(split) if TRAVERSAL_COST + split.cost < count as f32 || count > MAX_LEAF => {
                            let Split { axis, lo, scale, bin, .. } = split;
                            let mid = partition(range, |p| bin_index(p.bounds.centroid(), axis, lo, scale) <= bin);
                            Some((mid, split.left, split.right))
                        }
                        // All centroids coincide: halve by count to keep leaves small.
                        None if count > MAX_LEAF => {
                            let mid = count / 2;
                            Some((mid, Group::of(&range[..mid]), Group::of(&range[mid..])))
                        }
                        _ => None,
                    }
                };
                match children {
                    Some((mid, left_group, right_group)) => {
                        let left = nodes.len();
                        nodes.push(Node::new(&left_group.bounds.to_aabb(), 0, 0));
                        nodes.push(Node::new(&right_group.bounds.to_aabb(), 0, 0));
                        nodes[node] = Node::new(&group.bounds.to_aabb(), left as u32, 0);
                        work.push((left + 1, first + mid, end, level + 1, right_group));
                        work.push((left, first, first + mid, level + 1, left_group));
                    }
                    None => {
                        leaves += 1;
                        nodes[node] = Node::new(&group.bounds.to_aabb(), first as u32, count as u32);
                    }
                }
            }
        }
        let order: Vec<u32> = build
            .iter()
            .map(|p| match prims[p.index as usize] {
                Primitive::Triangle(_) => p.index,
                Primitive::Analytic(_) => p.index | ANALYTIC,
            })
            .collect();
        let triangles = build
            .iter()
            .map(|p| match &prims[p.index as usize] {
                Primitive::Triangle(tri) => tri.positions.map(Vec3A::from),
                Primitive::Analytic(_) => [Vec3A::ZERO; 3],
            })
            .collect();
        let stats = AccelStats {
            name: "bvh (binned SAH)",
            primitives: prims.len(),
            nodes: nodes.len(),
            leaves,
            depth,
            references: build.len(),
            memory_bytes: nodes.len() * size_of::<Node>() + build.len() * (4 + size_of::<[Vec3A; 3]>()),
            build_time: start.elapsed(),
        };
        Bvh { nodes, order, triangles, stats }
    }

    /// Iterative traversal: nearer child first for the closest hit; with `ANY` in tree order,
    /// returning at the first hit found.
    #[inline(always)]
    fn traverse<const ANY: bool, const CAREFUL: bool>(
        &self,
        prims: &[Primitive],
        ray: &Ray,
        prepared: &PreparedRay,
        node_ray: &NodeRay,
        t_min: f32,
        mut t_max: f32,
    ) -> Option<Hit> {
        let root = self.nodes.first()?;
        if node_ray.entry::<CAREFUL>(root, t_min, t_max) == f32::INFINITY {
            return None;
        }
        let mut best = None;
        let mut stack = [(0u32, 0.0f32); MAX_DEPTH];
        let mut top = 0;
        let mut node = root;
        loop {
            let count = node.count();
            if count > 0 {
                let first = node.first() as usize;
                for k in first..first + count as usize {
                    let entry = self.order[k];
                    let hit = if entry & ANALYTIC == 0 {
                        let [a, b, c] = self.triangles[k];
                        intersect_triangle(prepared, a, b, c, t_min, t_max)
                    } else {
                        prims[(entry & !ANALYTIC) as usize].intersect_prepared(ray, prepared, t_min, t_max)
                    };
                    if let Some(t) = hit
                        && offer(&mut best, t, entry & !ANALYTIC)
                    {
                        if ANY {
                            return best;
                        }
                        t_max = t.next_up();
                    }
                }
            } else {
                let left = node.first() as usize;
                let (t_left, t_right) = (
                    node_ray.entry::<CAREFUL>(&self.nodes[left], t_min, t_max),
                    node_ray.entry::<CAREFUL>(&self.nodes[left + 1], t_min, t_max),
                );
                // Any hit ends a shadow ray, so it need not look nearest first.
                let (near, far, t_near, t_far) = if !ANY && t_right < t_left {
                    (left + 1, left, t_right, t_left)
                } else {
                    (left, left + 1, t_left, t_right)
                };
                match (t_near != f32::INFINITY, t_far != f32::INFINITY) {
                    (true, far_hit) => {
                        if far_hit {
                            stack[top] = (far as u32, t_far);
                            top += 1;
                        }
                        node = &self.nodes[near];
                        continue;
                    }
                    (false, true) => {
                        node = &self.nodes[far];
                        continue;
                    }
                    (false, false) => {}
                }
            }
            // Next: the nearest pending node that still starts before the nearest hit.
            loop {
                if top == 0 {
                    return best;
                }
                top -= 1;
                let (index, entry) = stack[top];
                if entry < t_max {
                    node = &self.nodes[index as usize];
                    break;
                }
            }
        }
    }
}

impl Accelerator for Bvh {
    fn closest(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        let prepared = PreparedRay::new(ray)?;
        let node_ray = NodeRay::new(&prepared);
        if node_ray.needs_careful_slabs() {
            self.traverse::<false, true>(prims, ray, &prepared, &node_ray, t_min, t_max)
        } else {
            self.traverse::<false, false>(prims, ray, &prepared, &node_ray, t_min, t_max)
        }
    }

    fn occluded(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> bool {
        let Some(prepared) = PreparedRay::new(ray) else {
            return false;
        };
        let node_ray = NodeRay::new(&prepared);
        if node_ray.needs_careful_slabs() {
            self.traverse::<true, true>(prims, ray, &prepared, &node_ray, t_min, t_max).is_some()
        } else {
            self.traverse::<true, false>(prims, ray, &prepared, &node_ray, t_min, t_max).is_some()
        }
    }

    fn stats(&self) -> AccelStats {
        self.stats.clone()
    }
}
