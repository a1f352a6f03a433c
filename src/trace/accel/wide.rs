//! Wide BVH: the teaching BVH collapsed into nodes of eight children, each tested with SIMD.
//!
//! Seed 003 builds the BVH of the notes, and [`super::bvh`] is that one, binary, as the course
//! describes it (chapter 9). This one finds the same hits
//! faster, the way production tracers (Embree, tinybvh) do, and is the tracer's default. A CPU's
//! vector registers hold 4 numbers (SSE, WebAssembly's `simd128`) or 8 (AVX), and one
//! instruction works on all of them: testing eight boxes costs about what testing one does, if
//! the boxes are laid out for it.
//!
//! - **Collapse.** The binary tree, built by the same binned SAH, is flattened into nodes of up
//!   to [`WIDTH`] children: starting from a node's two children, the child of largest surface
//!   area (the one a ray most likely enters) is replaced by its own two, until there are eight
//!   or none left to open. The tree is about a third as deep, and a ray visits about a third as
//!   many nodes, each one SIMD box test of eight boxes.
//! - **Layout.** A node stores its children's boxes plane by plane (structure of arrays): the
//!   eight `min.x`, then the eight `min.y`, and so on, so that one load reads one plane of every
//!   box. A ray enters a box through the planes its direction faces, chosen once per ray, so the
//!   slab test needs no `min`/`max` per plane.
//! - **Leaves as packets.** A subtree of at most eight triangles becomes one leaf (a binary leaf
//!   made at the depth limit may hold more; an analytic primitive keeps a leaf of its own), and a
//!   leaf's triangles are stored as one packet of eight, coordinates lane by lane, tested
//!   together by the watertight test (Woop et al.) that the binary BVH runs on one. Every lane
//!   does the same operations in the same order, so each hit distance is the same to the last
//!   bit.
//! - **Nearest first.** The children a ray enters are sorted by entry distance, the nearest
//!   visited next and the others pushed, so the first hits found are near ones and shrink the
//!   ray's far bound early. Shadow rays (`occluded`) stop at any hit and skip the sort.
//! - **Dispatch at run time.** Both tests are written once, over eight lanes (`wide/lanes.rs`): one
//!   AVX register a step on a CPU that has AVX (checked once, when the tree is built), else two
//!   four-wide halves (SSE2 on every x86-64, `simd128` in the page, NEON on ARM).
//! - **Short steps from node to node.** A ray's walk is a chain: each node's address comes from
//!   the last node's test. So an inner child is stored as its node's byte offset (no
//!   multiplication before the next load), and the exit distances' safety factor is folded into
//!   the ray's constants (one multiplication fewer a node).
//!
//! Both BVHs return the nearest hit, and their box tests are conservative (Ize's bound), so they
//! draw the same image; `tests/accel.rs` checks their hits on random rays and `tests/trace.rs`
//! their images of every scene. One freedom remains: two primitives hit at the same distance (a
//! vertex shared by two triangles), or within a few units in the last place, may be found in
//! either order, since both trees skip a box whose entry distance rounds past the nearest hit so
//! far, and they meet the boxes in different orders.
//!
//! Limits: analytic primitives (spheres, tori, SDFs) are never grouped into packets; a leaf the
//! binary tree made at its depth limit becomes a leaf of as many packets as it needs.
//!
//! **What it buys** (`cargo bench --bench trace`, a million triangles, one thread): primary rays
//! about 2.1× and shadow rays about 3× as fast as the binary BVH. The walk from the root to a
//! leaf shortens from 24 levels to 9. Each node costs more than a binary one, and not in
//! arithmetic: the AVX box test gains little on primary rays over two four-lane halves. AVX pays
//! in the leaves, where eight triangles are tested at once (docs/performance.md has the
//! experiments).

mod lanes;
pub mod packets;

use std::mem::MaybeUninit;

use glam::{Vec3A, Vec4};
use web_time::Instant;

#[cfg(target_arch = "x86_64")]
use self::lanes::Octet;
use self::lanes::{Halves, LANES, Lanes};
use super::bvh::{ANALYTIC, Bvh, ROBUST_EXIT};
use super::{AccelStats, Accelerator, Hit, offer};
use crate::base::Ray;
use crate::trace::geometry::{PreparedRay, Primitive, intersect_triangle};

/// Children per node.
pub const WIDTH: usize = 8;
/// Triangles tested together: a packet's lanes, one per triangle.
pub const PACKET: usize = LANES;
/// The most primitives a subtree may hold to become one leaf: one packet. For the benchmark's
/// million triangles, leaves of up to four made a tree of 92 000 nodes and up to eight 53 000,
/// with shadow rays 7 % faster (primary rays the same); up to sixteen (34 000 nodes) gained
/// nothing more.
pub const LEAF_SIZE: usize = PACKET;
/// Marks a child that is a leaf: the rest of the `u32` is its first packet.
const LEAF: u32 = 1 << 31;
/// An inner child is stored as its node's byte offset in the tree's nodes, so that the walk
/// finds the next node's address by one addition, without a multiplication by the node's size
/// on the path from one node's test to the next node's load. It caps a tree at
/// `LEAF / NODE_BYTES`, 9.6 million nodes (about 190 million triangles).
const NODE_BYTES: usize = size_of::<Node>();
/// Traversal stacks: the small one serves every tree whose traversal can hold at most this many
/// entries ([`stack_bound`]; the million-triangle benchmark mesh needs 68); deeper trees use
/// [`LARGE_STACK`].
const SMALL_STACK: usize = 96;
/// Enough for any tree: the binary tree is at most 64 deep, so a path visits at most 63 inner
/// nodes, each leaving at most seven entries pushed.
const LARGE_STACK: usize = 64 * (WIDTH - 1);

/// Eight children's boxes, plane by plane, and what each child is. 224 bytes.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node {
    /// `min.x, min.y, min.z, max.x, max.y, max.z` of the eight boxes, as two halves of four.
    /// An unused slot has an empty box (min +∞, max −∞), which no ray enters.
    planes: [[Vec4; 2]; 6],
    /// An inner child's byte offset in the tree's nodes ([`NODE_BYTES`] times its index), or
    /// [`LEAF`] and the leaf's first packet.
    child: [u32; WIDTH],
}

/// Up to eight primitives of one leaf; triangles are tested eight at a time. 352 bytes.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Packet {
    /// `vertices[i][axis]`: vertex `i` of the eight triangles, one per lane, as two halves of
    /// four; NaN in lanes that hold no triangle (their `t` is NaN and fails the test's range
    /// comparisons, and the `triangles` mask drops them besides).
    vertices: [[[Vec4; 2]; 3]; 3],
    /// The primitives' indices in the scene's slice.
    primitives: [u32; PACKET],
    /// Bit `i`: lane `i` holds a triangle.
    triangles: u8,
    /// Bit `i`: lane `i` holds an analytic primitive, tested by its own code.
    analytic: u8,
    /// Whether the leaf's next packet follows this one.
    more: bool,
}

/// The box test's per-ray constants.
struct BoxRay {
    origin: [f32; 3],
    inv_direction: [f32; 3],
    /// `inv_direction` times Ize's `1 + 2γ₃` ([`ROBUST_EXIT`]), for the exit distances: one
    /// multiplication a plane fewer between a node's load and its answer than scaling each exit
    /// (the same four roundings, so the same bound; the exits are not the binary BVH's bits,
    /// but both are conservative, so the hits are the same).
    exit_inv_direction: [f32; 3],
    /// Per axis, the plane the ray enters a slab through (`0..3`: min, `3..6`: max) and the
    /// plane it leaves through.
    near: [usize; 3],
    far: [usize; 3],
}

impl BoxRay {
    fn new(ray: &PreparedRay) -> BoxRay {
        let axis = |k: usize| ray.inv_direction[k].is_sign_negative() as usize * 3 + k;
        let near = [axis(0), axis(1), axis(2)];
        BoxRay {
            origin: ray.origin.to_array(),
            inv_direction: ray.inv_direction.to_array(),
            exit_inv_direction: (ray.inv_direction * ROBUST_EXIT).to_array(),
            near,
            far: near.map(|p| (p + 3) % 6),
        }
    }
}

/// Which of a node's eight boxes a ray enters within `(t_min, t_max)`: bit `i` set where it
/// enters child `i`'s box, and the entry distances.
///
/// # Safety
/// The CPU must have the instructions `L` uses.
#[inline(always)]
unsafe fn enter<L: Lanes, const CAREFUL: bool>(
    node: &Node,
    ray: &BoxRay,
    t_min: f32,
    t_max: f32,
) -> (u32, [f32; WIDTH]) {
    // SAFETY: the caller's promise about `L`.
    unsafe {
        let (mut enter, mut exit) = (L::splat(t_min), L::splat(t_max));
        for k in 0..3 {
            let origin = L::splat(ray.origin[k]);
            let mut near = (L::load(&node.planes[ray.near[k]]) - origin) * L::splat(ray.inv_direction[k]);
            let mut far = (L::load(&node.planes[ray.far[k]]) - origin) * L::splat(ray.exit_inv_direction[k]);
            if CAREFUL {
                // 0·∞ where the origin lies on the plane of a slab the ray runs along: that
                // slab does not bound the ray (the binary BVH's rule too).
                near = near.nan_to(f32::NEG_INFINITY);
                far = far.nan_to(f32::INFINITY);
            }
            enter = enter.max(near);
            exit = exit.min(far);
        }
        (enter.le(exit), enter.to_array())
    }
}

/// The triangle test's per-ray constants: the watertight test's axes and shear.
struct PacketRay {
    origin: [f32; 3],
    axes: [usize; 3],
    shear: [f32; 3],
}

impl PacketRay {
    fn new(ray: &PreparedRay) -> PacketRay {
        PacketRay { origin: ray.origin.to_array(), axes: ray.axes, shear: ray.shear.to_array() }
    }

    /// Eight vertices in the ray's sheared frame: `A[kx] − Sx·A[kz]`, `A[ky] − Sy·A[kz]`,
    /// `Sz·A[kz]`, with `A = v − origin`. (No closures here: a closure is compiled without AVX and
    /// its [`Octet`] operations would not inline.)
    ///
    /// # Safety
    /// The CPU must have the instructions `L` uses.
    #[inline(always)]
    unsafe fn local<L: Lanes>(&self, vertex: &[[Vec4; 2]; 3]) -> (L, L, L) {
        let [kx, ky, kz] = self.axes;
        // SAFETY: the caller's promise about `L`.
        unsafe {
            let dx = L::load(&vertex[kx]) - L::splat(self.origin[kx]);
            let dy = L::load(&vertex[ky]) - L::splat(self.origin[ky]);
            let dz = L::load(&vertex[kz]) - L::splat(self.origin[kz]);
            (dx - L::splat(self.shear[0]) * dz, dy - L::splat(self.shear[1]) * dz, L::splat(self.shear[2]) * dz)
        }
    }
}

impl Packet {
    const EMPTY: Packet = Packet {
        vertices: [[[Vec4::NAN; 2]; 3]; 3],
        primitives: [u32::MAX; PACKET],
        triangles: 0,
        analytic: 0,
        more: false,
    };

    /// Lane `lane`'s hit at `t`: with `ANY` the answer, else offered as the nearest (narrowing
    /// `t_max` past it when taken).
    #[inline(always)]
    fn offer<const ANY: bool>(&self, lane: usize, t: f32, best: &mut Option<Hit>, t_max: &mut f32) -> Option<Hit> {
        let primitive = self.primitives[lane];
        if ANY {
            return Some(Hit { t, primitive });
        }
        if offer(best, t, primitive) {
            *t_max = t.next_up();
        }
        None
    }

    /// Lane `lane`'s triangle.
    fn triangle(&self, lane: usize) -> [Vec3A; 3] {
        self.vertices.map(|v| Vec3A::new(v[0][lane / 4][lane % 4], v[1][lane / 4][lane % 4], v[2][lane / 4][lane % 4]))
    }

    /// The watertight test on the eight lanes at once: the lanes hit in `(t_min, t_max)` and
    /// their distances, and the lanes whose edge functions round to zero, which the scalar test
    /// settles in double precision.
    ///
    /// Each line is [`crate::trace::geometry`]'s `watertight` with a lane per triangle: the
    /// sheared frame `A[kx] − Sx·A[kz]`, the three edge functions, their signs, `det` and `T`,
    /// each computed in the same order.
    ///
    /// # Safety
    /// The CPU must have the instructions `L` uses.
    #[inline(always)]
    unsafe fn hits<L: Lanes>(&self, ray: &PacketRay, t_min: f32, t_max: f32) -> (u32, [f32; PACKET], u32) {
        // SAFETY: the caller's promise about `L`.
        unsafe {
            let (a, b, c) =
                (ray.local::<L>(&self.vertices[0]), ray.local(&self.vertices[1]), ray.local(&self.vertices[2]));
            let u = c.0 * b.1 - c.1 * b.0;
            let v = a.0 * c.1 - a.1 * c.0;
            let w = b.0 * a.1 - b.1 * a.0;
            let zero = L::splat(0.0);
            let rounded_to_zero = u.eq(zero) | v.eq(zero) | w.eq(zero);
            let mixed_signs = (u.lt(zero) | v.lt(zero) | w.lt(zero)) & (u.gt(zero) | v.gt(zero) | w.gt(zero));
            let det = u + v + w;
            let t = (u * a.2 + v * b.2 + w * c.2) / det;
            let inside = t.gt(L::splat(t_min)) & t.lt(L::splat(t_max)) & det.ne(zero);
            let triangles = self.triangles as u32;
            let hit = inside & !mixed_signs & triangles & !rounded_to_zero;
            (hit, t.to_array(), rounded_to_zero & triangles)
        }
    }
}

/// A BVH of eight-wide nodes collapsed from the binary one.
pub struct Wide {
    nodes: Vec<Node>,
    packets: Vec<Packet>,
    /// The most entries a traversal can push on its stack.
    stack_bound: usize,
    /// Whether the box and triangle tests may use AVX (the CPU has it); always false off x86-64.
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    avx: bool,
    stats: AccelStats,
}

/// What collapsing the binary tree reads of it: its nodes, and each node's primitives.
struct Collapse<'a> {
    bvh: &'a Bvh,
    /// Each binary node's primitives in leaf order: a subtree's are contiguous.
    ranges: Vec<(u32, u32)>,
    /// How many analytic primitives come before each position of the leaf order.
    analytic_before: Vec<u32>,
}

impl Collapse<'_> {
    /// Whether binary node `index` becomes a wide leaf: a leaf, or a subtree of at most
    /// [`LEAF_SIZE`] triangles. Analytic primitives are not gathered: each is tested on its own,
    /// and a torus or a rounded box (sphere-traced) costs far more than a box test that skips it.
    fn is_leaf(&self, index: usize) -> bool {
        let (start, end) = self.ranges[index];
        let analytic = self.analytic_before[end as usize] - self.analytic_before[start as usize];
        self.bvh.nodes[index].count() > 0 || (end - start <= LEAF_SIZE as u32 && analytic == 0)
    }

    fn half_area(&self, index: usize) -> f32 {
        let (min, max) = self.bvh.nodes[index].bounds();
        let d = (max - min).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    /// The up to [`WIDTH`] binary nodes that become the children of the wide node made from
    /// binary inner node `index`.
    fn children(&self, index: usize) -> Vec<usize> {
        let left = self.bvh.nodes[index].first() as usize;
        let mut children = vec![left, left + 1];
        while children.len() < WIDTH {
            let open = (0..children.len())
                .filter(|&i| !self.is_leaf(children[i]))
                .max_by(|&i, &j| self.half_area(children[i]).total_cmp(&self.half_area(children[j])));
            let Some(i) = open else { break };
            let left = self.bvh.nodes[children[i]].first() as usize;
            children[i] = left;
            children.push(left + 1);
        }
        children
    }
}

impl Wide {
    /// Builds the tree; its boxes and triangles are tested with AVX where the CPU has it.
    pub fn build(prims: &[Primitive]) -> Wide {
        Wide::build_with(prims, true)
    }

    /// The same tree with its boxes and triangles always tested as two halves of four, as on a CPU
    /// without
    /// AVX (for tests and benchmarks of that path).
    pub fn build_without_avx(prims: &[Primitive]) -> Wide {
        Wide::build_with(prims, false)
    }

    fn build_with(prims: &[Primitive], avx: bool) -> Wide {
        let start = Instant::now();
        let bvh = Bvh::build(prims);
        let binary = &bvh.nodes;
        let mut ranges = vec![(0u32, 0u32); binary.len()];
        // Children come after their parent, so a backward sweep sees them first.
        for i in (0..binary.len()).rev() {
            let node = &binary[i];
            ranges[i] = if node.count() > 0 {
                (node.first(), node.first() + node.count())
            } else {
                let left = node.first() as usize;
                (ranges[left].0, ranges[left + 1].1)
            };
        }
        let analytic_before = std::iter::once(0)
            .chain(bvh.order.iter().scan(0, |count, &entry| {
                *count += (entry & ANALYTIC != 0) as u32;
                Some(*count)
            }))
            .collect();
        let collapse = Collapse { bvh: &bvh, ranges, analytic_before };

        let mut nodes: Vec<Node> = Vec::new();
        let mut packets: Vec<Packet> = Vec::new();
        let (mut leaves, mut depth) = (0, 0);
        // (wide node, binary node it is made of, level); the root wide node holds the binary root
        // as its only child when that is already a leaf.
        let mut work = Vec::new();
        // How many children each node has.
        let mut used: Vec<usize> = Vec::new();
        if !binary.is_empty() {
            nodes.push(Node::EMPTY);
            used.push(0);
            work.push((0usize, 0usize, 0usize));
        }
        while let Some((wide, index, level)) = work.pop() {
            depth = depth.max(level);
            let children = if wide == 0 && collapse.is_leaf(0) { vec![0] } else { collapse.children(index) };
            let mut node = Node::EMPTY;
            for (slot, &child) in children.iter().enumerate() {
                let (min, max) = binary[child].bounds();
                node.set_box(slot, min, max);
                if collapse.is_leaf(child) {
                    leaves += 1;
                    assert!(packets.len() < LEAF as usize, "a wide BVH of more than {LEAF} packets");
                    node.child[slot] = LEAF | packets.len() as u32;
                    let (first, end) = collapse.ranges[child];
                    push_packets(&mut packets, &bvh, first as usize..end as usize);
                } else {
                    assert!(
                        (nodes.len() + 1) * NODE_BYTES <= LEAF as usize,
                        "a wide BVH of more than {} nodes",
                        LEAF as usize / NODE_BYTES
                    );
                    node.child[slot] = (nodes.len() * NODE_BYTES) as u32;
                    nodes.push(Node::EMPTY);
                    used.push(0);
                    work.push((nodes.len() - 1, child, level + 1));
                }
            }
            nodes[wide] = node;
            used[wide] = children.len();
        }
        let stack_bound = stack_bound(&nodes, &used);
        // A path visits at most 63 inner nodes (the binary tree is at most 64 deep), each leaving
        // at most seven pushed: 442 entries and the one popped.
        assert!(stack_bound <= LARGE_STACK, "a wide BVH whose traversal needs {stack_bound} stack entries");
        let avx = avx && avx_available();
        let stats = AccelStats {
            name: if avx { "wide bvh (8-wide, AVX)" } else { "wide bvh (8-wide, 2 × 4 lanes)" },
            primitives: prims.len(),
            nodes: nodes.len(),
            leaves,
            depth,
            references: bvh.order.len(),
            memory_bytes: nodes.len() * size_of::<Node>() + packets.len() * size_of::<Packet>(),
            build_time: start.elapsed(),
        };
        Wide { nodes, packets, stack_bound, avx, stats }
    }

    /// The nearest hit, or with `ANY` the first found, choosing the stack's size and the tests'
    /// instructions for this tree and CPU.
    #[inline(always)]
    fn query<const ANY: bool>(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        let prepared = PreparedRay::new(ray)?;
        if self.nodes.is_empty() {
            return None;
        }
        let query = Query { prims, ray, prepared: &prepared, t_min, t_max };
        let careful = !prepared.inv_direction.is_finite();
        let small = self.stack_bound <= SMALL_STACK;
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is set only where the CPU reports AVX.
            return unsafe { self.run_avx::<ANY>(&query, careful, small) };
        }
        // SAFETY: `Halves` uses what every target has (SSE2 on x86-64).
        unsafe {
            match (careful, small) {
                (false, true) => self.traverse::<Halves, ANY, false, SMALL_STACK>(&query),
                (true, true) => self.traverse::<Halves, ANY, true, SMALL_STACK>(&query),
                (false, false) => self.traverse::<Halves, ANY, false, LARGE_STACK>(&query),
                (true, false) => self.traverse::<Halves, ANY, true, LARGE_STACK>(&query),
            }
        }
    }

    /// The traversal compiled with AVX enabled, so that [`Octet`]'s operations inline into it.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn run_avx<const ANY: bool>(&self, query: &Query, careful: bool, small: bool) -> Option<Hit> {
        // SAFETY: this function runs only where the CPU has AVX (its callers check).
        unsafe {
            match (careful, small) {
                (false, true) => self.traverse::<Octet, ANY, false, SMALL_STACK>(query),
                (true, true) => self.traverse::<Octet, ANY, true, SMALL_STACK>(query),
                (false, false) => self.traverse::<Octet, ANY, false, LARGE_STACK>(query),
                (true, false) => self.traverse::<Octet, ANY, true, LARGE_STACK>(query),
            }
        }
    }

    /// Nearest-first traversal with an explicit stack of (child, entry distance).
    ///
    /// # Safety
    /// The CPU must have the instructions `L` uses.
    #[inline(always)]
    unsafe fn traverse<L: Lanes, const ANY: bool, const CAREFUL: bool, const STACK: usize>(
        &self,
        query: &Query,
    ) -> Option<Hit> {
        let (mut best, mut t_max) = (None, query.t_max);
        // SAFETY: the caller's promise about `L`; 0 is the root, and the walk runs only in a
        // tree with nodes.
        let first = unsafe { self.traverse_from::<L, ANY, CAREFUL, STACK>(query, 0, &mut best, &mut t_max) };
        first.or(best)
    }

    /// [`Wide::traverse`] from the node or leaf `start` down, with the nearest hit found so far
    /// `best` at `t_max` (both updated): returns the first hit with `ANY`, else `None`. A packet
    /// hands a subtree that only one of its rays enters to this walk ([`packets`]).
    ///
    /// # Safety
    /// The CPU must have the instructions `L` uses, and `start` must be 0 in a tree with nodes or
    /// a child's entry of one of its nodes.
    #[inline(always)]
    unsafe fn traverse_from<L: Lanes, const ANY: bool, const CAREFUL: bool, const STACK: usize>(
        &self,
        query: &Query,
        start: u32,
        best: &mut Option<Hit>,
        t_max: &mut f32,
    ) -> Option<Hit> {
        let t_min = query.t_min;
        let box_ray = BoxRay::new(query.prepared);
        let packet_ray = PacketRay::new(query.prepared);
        let mut stack = Stack::<(u32, f32), STACK>::new();
        let mut current = start;
        loop {
            if current & LEAF == 0 {
                // SAFETY: `current` is `start` (the caller's promise) or an inner child's entry of
                // a node.
                let node = unsafe { self.node(current) };
                // SAFETY: the caller's promise about `L`.
                let (mut mask, entries) = unsafe { enter::<L, CAREFUL>(node, &box_ray, t_min, *t_max) };
                let child = |i: usize| (node.child[i], entries[i]);
                if mask != 0 {
                    let first = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if mask == 0 {
                        current = node.child[first];
                        continue;
                    }
                    let second = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if mask == 0 {
                        // Two, the commonest case after one: visit the nearer, push the other.
                        let (near, far) =
                            if !ANY && entries[second] < entries[first] { (second, first) } else { (first, second) };
                        stack.push(child(far));
                        current = node.child[near];
                        continue;
                    }
                    // More: push them all, the nearest last, and take it.
                    let base = stack.len();
                    stack.push(child(first));
                    stack.push_sorted::<ANY>(base, child(second));
                    while mask != 0 {
                        let i = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        stack.push_sorted::<ANY>(base, child(i));
                    }
                    current = stack.pop().expect("three children were just pushed").0;
                    continue;
                }
            } else if let Some(hit) =
                // SAFETY: the caller's promise about `L`.
                unsafe { self.leaf::<L, ANY>(current & !LEAF, query, &packet_ray, best, t_max) }
            {
                return Some(hit);
            }
            // Next: the nearest pending child that still starts before the nearest hit.
            loop {
                let (child, entry) = stack.pop()?;
                if entry < *t_max {
                    current = child;
                    break;
                }
            }
        }
    }

    /// The inner node at byte offset `offset` ([`Node::child`]).
    ///
    /// # Safety
    /// `offset` must be an inner child's entry of one of this tree's nodes, or 0 in a tree with
    /// nodes: `NODE_BYTES` times the index of a node.
    #[inline(always)]
    unsafe fn node(&self, offset: u32) -> &Node {
        let offset = offset as usize;
        debug_assert!(offset.is_multiple_of(NODE_BYTES) && offset / NODE_BYTES < self.nodes.len());
        // SAFETY: the caller's promise. `build_with` makes each inner child's entry
        // `NODE_BYTES` times the index of a node it pushed, and an unused slot holds 0, the root
        // (an empty box, which no ray enters).
        unsafe { &*self.nodes.as_ptr().byte_add(offset) }
    }

    /// Tests the leaf's packets, offering each hit; with `ANY`, returns the first.
    ///
    /// # Safety
    /// The CPU must have the instructions `L` uses.
    #[inline(always)]
    unsafe fn leaf<L: Lanes, const ANY: bool>(
        &self,
        first: u32,
        query: &Query,
        packet_ray: &PacketRay,
        best: &mut Option<Hit>,
        t_max: &mut f32,
    ) -> Option<Hit> {
        let Query { prims, ray, prepared, t_min, .. } = *query;
        for packet in self.packets[first as usize..].iter() {
            let (mut hits, t, mut one_by_one) = if packet.triangles != 0 {
                // SAFETY: the caller's promise about `L`.
                unsafe { packet.hits::<L>(packet_ray, t_min, *t_max) }
            } else {
                (0, [0.0; PACKET], 0)
            };
            // Edge functions that rounded to zero (bits 0–7), then analytic primitives (8–15).
            one_by_one |= (packet.analytic as u32) << PACKET;
            while hits != 0 {
                let lane = hits.trailing_zeros() as usize;
                hits &= hits - 1;
                if let Some(hit) = packet.offer::<ANY>(lane, t[lane], best, t_max) {
                    return Some(hit);
                }
            }
            while one_by_one != 0 {
                let bit = one_by_one.trailing_zeros() as usize;
                one_by_one &= one_by_one - 1;
                let lane = bit % PACKET;
                let hit = if bit < PACKET {
                    let [a, b, c] = packet.triangle(lane);
                    intersect_triangle(prepared, a, b, c, t_min, *t_max)
                } else {
                    prims[packet.primitives[lane] as usize].intersect_prepared(ray, prepared, t_min, *t_max)
                };
                if let Some(hit) = hit.and_then(|t| packet.offer::<ANY>(lane, t, best, t_max)) {
                    return Some(hit);
                }
            }
            if !packet.more {
                break;
            }
        }
        None
    }
}

/// The traversal's stack of `(child, entry distance)` (a packet's: of `(child, its rays, their
/// nearest entry)`), left uninitialized: zeroing its [`SMALL_STACK`] entries for every ray cost
/// 7 % of a primary ray's time.
struct Stack<T, const N: usize> {
    items: [MaybeUninit<T>; N],
    /// `items[..len]` are written.
    len: usize,
}

impl<T: Copy, const N: usize> Stack<T, N> {
    #[inline(always)]
    fn new() -> Self {
        Stack { items: [const { MaybeUninit::uninit() }; N], len: 0 }
    }

    #[inline(always)]
    fn len(&self) -> usize {
        self.len
    }

    /// Panics past `N` entries, which [`stack_bound`] rules out.
    #[inline(always)]
    fn push(&mut self, item: T) {
        self.items[self.len].write(item);
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<T> {
        self.len = self.len.checked_sub(1)?;
        // SAFETY: the entry was below `len`, so it is written.
        Some(unsafe { self.items[self.len].assume_init() })
    }
}

impl<const N: usize> Stack<(u32, f32), N> {
    /// Pushes `item` into the run pushed since `base`, keeping the run farthest first (unless
    /// `ANY`, when order does not matter).
    #[inline(always)]
    fn push_sorted<const ANY: bool>(&mut self, base: usize, item: (u32, f32)) {
        let mut j = self.len;
        self.push(item);
        if !ANY {
            // SAFETY: `base <= j - 1 < len`, so the entry read is written.
            while j > base && unsafe { self.items[j - 1].assume_init() }.1 < item.1 {
                self.items[j] = self.items[j - 1];
                j -= 1;
            }
            self.items[j].write(item);
        }
    }
}

/// One query's inputs, passed whole to the traversal's variants.
#[derive(Clone, Copy)]
struct Query<'a> {
    prims: &'a [Primitive],
    ray: &'a Ray,
    prepared: &'a PreparedRay,
    t_min: f32,
    t_max: f32,
}

impl Node {
    const EMPTY: Node = Node {
        planes: [
            [Vec4::INFINITY; 2],
            [Vec4::INFINITY; 2],
            [Vec4::INFINITY; 2],
            [Vec4::NEG_INFINITY; 2],
            [Vec4::NEG_INFINITY; 2],
            [Vec4::NEG_INFINITY; 2],
        ],
        child: [0; WIDTH],
    };

    fn set_box(&mut self, slot: usize, min: Vec3A, max: Vec3A) {
        for k in 0..3 {
            self.planes[k][slot / 4][slot % 4] = min[k];
            self.planes[k + 3][slot / 4][slot % 4] = max[k];
        }
    }
}

/// Appends the packets of the leaf holding the binary tree's primitives `range` (leaf order).
fn push_packets(packets: &mut Vec<Packet>, bvh: &Bvh, range: std::ops::Range<usize>) {
    let first = packets.len();
    for start in range.clone().step_by(PACKET) {
        let mut packet = Packet { more: true, ..Packet::EMPTY };
        for (lane, k) in (start..(start + PACKET).min(range.end)).enumerate() {
            let entry = bvh.order[k];
            packet.primitives[lane] = entry & !ANALYTIC;
            if entry & ANALYTIC != 0 {
                packet.analytic |= 1 << lane;
            } else {
                packet.triangles |= 1 << lane;
                for (i, vertex) in bvh.triangles[k].iter().enumerate() {
                    for axis in 0..3 {
                        packet.vertices[i][axis][lane / 4][lane % 4] = vertex[axis];
                    }
                }
            }
        }
        packets.push(packet);
    }
    if let Some(last) = packets[first..].last_mut() {
        last.more = false;
    }
}

/// The most entries a traversal's stack can hold, from each node's number of children (`used`).
/// A node that enters `k` children pushes all of them and pops the nearest: `k` at once, and
/// `k − 1` left while the walk is below it. So a node needs `max(k, k − 1 + its deepest child's
/// need)`, at worst with every child entered. (The traversal pushes one fewer for one or two
/// children entered; the bound does not count that saving.) Children come after their parent, so
/// a backward sweep sees them first.
fn stack_bound(nodes: &[Node], used: &[usize]) -> usize {
    let mut need = vec![0usize; nodes.len()];
    for i in (0..nodes.len()).rev() {
        let node = &nodes[i];
        let deepest = (0..used[i])
            .filter(|&s| node.child[s] & LEAF == 0)
            .map(|s| need[node.child[s] as usize / NODE_BYTES])
            .max();
        need[i] = used[i].saturating_sub(1) + deepest.unwrap_or(0).max(1);
    }
    need.first().copied().unwrap_or(0)
}

fn avx_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

impl Accelerator for Wide {
    fn closest(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        self.query::<false>(prims, ray, t_min, t_max)
    }

    fn occluded(&self, prims: &[Primitive], ray: &Ray, t_min: f32, t_max: f32) -> bool {
        self.query::<true>(prims, ray, t_min, t_max).is_some()
    }

    fn stats(&self) -> AccelStats {
        self.stats.clone()
    }

    fn closest_packets(&self, prims: &[Primitive], rays: &[Ray], t_min: f32, t_max: f32, hits: &mut [Option<Hit>]) {
        self.closest_in_packets(prims, rays, t_min, t_max, hits);
    }

    fn occluded_packets(&self, prims: &[Primitive], rays: &[Ray], bounds: (f32, &[f32]), occluded: &mut [bool]) {
        self.occluded_in_packets(prims, rays, bounds, occluded);
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn triangles(corners: impl Iterator<Item = [Vec3; 3]>) -> Vec<Primitive> {
        corners.map(Primitive::flat_triangle).collect()
    }

    /// The stack's highest over walks that enter every child of every node, pushing and popping
    /// as [`Wide::traverse`] does, each walk visiting the children in a random order (which is
    /// nearest depends on the ray).
    fn every_child_entered(wide: &Wide, walks: u32) -> usize {
        let used = |node: &Node| (0..WIDTH).filter(|&s| node.planes[0][s / 4][s % 4] != f32::INFINITY).count();
        let mut seed = 1u64;
        let mut random = move |n: usize| {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 33) as usize % n
        };
        let mut peak = 0;
        for _ in 0..walks {
            let (mut stack, mut current) = (Vec::new(), Some(0u32));
            while let Some(child) = current {
                current = stack.pop();
                if child & LEAF != 0 {
                    continue;
                }
                if let Some(popped) = current {
                    stack.push(popped);
                }
                // SAFETY: `child` is 0 (the tree has nodes) or an inner child's entry.
                let node = unsafe { wide.node(child) };
                let mut children = node.child[..used(node)].to_vec();
                for i in (1..children.len()).rev() {
                    children.swap(i, random(i + 1));
                }
                stack.extend_from_slice(&children);
                peak = peak.max(stack.len());
                current = stack.pop();
            }
        }
        peak
    }

    #[test]
    fn the_stack_bound_covers_a_walk_that_enters_every_child() {
        let grid = triangles((0..40 * 40).map(|i| {
            let p = Vec3::new((i % 40) as f32, (i / 40) as f32, ((i * 7) % 5) as f32);
            [p, p + Vec3::X, p + Vec3::Y]
        }));
        // Each triangle half the size of the last, nested toward the origin: a deep, lopsided tree.
        let nested = triangles((0..60).map(|i| {
            let s = 0.5f32.powi(i);
            [Vec3::new(s, 0.0, 0.0), Vec3::new(0.0, s, 0.0), Vec3::new(s, s, s)]
        }));
        for (name, prims) in [("grid", grid), ("nested", nested)] {
            let wide = Wide::build(&prims);
            let peak = every_child_entered(&wide, 20_000);
            // Never above the bound, and the bound is reached: it is exact.
            assert_eq!(peak, wide.stack_bound, "{name}: the walks' peak against the bound");
        }
    }
}
