//! Coherent rays traced together: a packet of up to [`RAYS`] rays walks the wide BVH as one.
//!
//! Primary rays through neighbouring pixels, and shadow rays from them towards one light, visit
//! nearly the same nodes in nearly the same order. Walked one by one, each ray pays alone for
//! what they share: loading a node, choosing which children to enter, sorting and keeping them
//! on a stack, and the branches a CPU mispredicts on the way. A packet walks once
//! (Wald et al., "Interactive Rendering with Coherent Ray Tracing", 2001; Embree's packet
//! kernels): at each node every ray still active is tested against the node's eight boxes, as
//! one ray is ([`enter`]), and a child is entered by the rays that enter its box; the packet
//! visits the children nearest first, by the nearest of those rays' entry distances, with one
//! stack for all. In a leaf each of the child's rays tests the triangles as one ray does.
//!
//! **The same hits.** Every ray keeps its own far bound, and a ray leaves a pending child once
//! its nearest hit is nearer than the packet's entry into that child, which is never farther
//! than its own. A child whose box holds a ray's nearest hit is entered before that hit, so the
//! ray tests it, with the single ray's arithmetic, and takes the nearest by the same rule
//! ([`super::super::offer`]: the smaller distance, then the smaller index): the hits, and the
//! image, are the single-ray walk's to the bit. One freedom is left, in both walks: a box's entry
//! and a hit's distance are rounded by different arithmetic, so where a triangle lies on its box's
//! face the box can be entered an ulp past the hit. Two primitives at exactly one distance (a
//! duplicated face) in different boxes may then be chosen between in the order a walk meets them,
//! which differs between the walks. Likewise a shape found by sphere tracing (a torus) stops its
//! march at the far bound it is handed, and its polished hit may lie up to its ε before the step
//! that passed that bound: within ε of a nearer hit, the far bound of the moment decides. No
//! scene of `assets/` shows either: its 28 scenes trace to the same PNGs both ways.
//!
//! A ray it could not walk the fast way (one that runs exactly along an axis, whose slab test
//! needs [`enter`]'s careful variant) is walked alone.
//!
//! **Shadow rays** ([`Wide::occluded_in_packets`]) walk the same way, each to its own far bound
//! (its light's distance), and a ray leaves the packet at its first hit: whether anything is hit
//! is the single ray's answer, since a ray enters every box the single-ray walk enters until then.
//!
//! **The packet as one interval** (Boulos et al., "Geometric and Arithmetic Culling Methods for
//! Entire Ray Packets", 2006). Where every ray of the packet points the same way along each
//! axis, they enter each slab through the same plane, and the packet's rays are bounded by
//! intervals: of their origins, per axis, and of their inverse directions ([`Bounds`]). At a node
//! the slab test run on those intervals ([`enter_together`]) bounds every ray's entry and exit
//! distances at once, for the eight boxes: a box whose lowest entry lies beyond its highest exit
//! is entered by no ray, a box whose highest entry comes before its lowest exit by all of them.
//! Where each of the eight boxes is one or the other, the node is settled for the whole packet by
//! one test instead of one a ray. Near the root, where a 4 × 4 block of pixels is small beside the
//! boxes, that is most nodes; where a box's edge falls between the rays, the node is tested ray
//! by ray as above, and so is everything under it (on the benchmark's sphere, 29 % of the nodes
//! a packet visits are settled whole: docs/performance.md).
//!
//! The bounds are exact, not padded: each ray's `(plane − origin)·(1/d)` is rounded from a
//! difference and a product, and rounding keeps order, so it lies between the same expression at
//! the corners of the intervals. So the packet never leaves out a box a ray enters, and the hits
//! stay the single-ray walk's: a ray the interval test takes into a box it does not enter only
//! tests triangles it misses.
//!
//! **One ray alone on a path walks it as a single ray** (Benthin et al., "Combining Single and
//! Packet-Ray Tracing for Arbitrary Ray Distributions on the Intel MIC Architecture", 2012). Near
//! the leaves the packet's rays part: on a mesh whose triangles are smaller than a pixel, each
//! ray of a 4 × 4 block ends in leaves of its own. A child entered by one ray only is handed to
//! the single-ray walk ([`Wide::traverse_from`]) with that ray's nearest hit so far, and the
//! packet goes on with its other pending children; the packet's bookkeeping (the rays' masks, one
//! entry per child for all of them) is spent only where it is shared.
//!
//! What a packet costs instead: rays that left each other's path are carried along, masked,
//! while two or more share it. Incoherent rays (reflections off curved surfaces, refraction) gain
//! nothing, and are traced one by one.

use super::*;

/// Rays in one packet: a 4 × 4 block of pixels.
pub const RAYS: usize = 16;

/// One ray of the packet, prepared once.
struct Member<'a> {
    query: Query<'a>,
    box_ray: BoxRay,
    packet_ray: PacketRay,
}

/// The packet's rays as intervals, for the box test on all of them at once: per axis the planes
/// they all enter and leave a slab through, and the least and greatest of their origins, their
/// inverse directions and those scaled for the exits ([`BoxRay`]'s three), as `[least, greatest]`.
struct Bounds {
    /// The packet's near bound, every ray's.
    t_min: f32,
    near: [usize; 3],
    far: [usize; 3],
    origin: [[f32; 3]; 2],
    inv_direction: [[f32; 3]; 2],
    exit_inv_direction: [[f32; 3]; 2],
}

impl Bounds {
    /// The bounds of `members`' rays; `None` for a packet of one ray or none, and where the rays
    /// point different ways along an axis (the interval of their inverse directions would hold
    /// ±∞) or a bound is not finite.
    fn new(members: &[Option<Member>; RAYS], t_min: f32) -> Option<Bounds> {
        let mut rays = members.iter().flatten().map(|m| &m.box_ray);
        let first = rays.next()?;
        let mut bounds = Bounds {
            t_min,
            near: first.near,
            far: first.far,
            origin: [first.origin; 2],
            inv_direction: [first.inv_direction; 2],
            exit_inv_direction: [first.exit_inv_direction; 2],
        };
        let mut count = 1;
        for ray in rays {
            if ray.near != bounds.near {
                return None;
            }
            for k in 0..3 {
                widen(&mut bounds.origin, k, ray.origin[k]);
                widen(&mut bounds.inv_direction, k, ray.inv_direction[k]);
                widen(&mut bounds.exit_inv_direction, k, ray.exit_inv_direction[k]);
            }
            count += 1;
        }
        let finite = [bounds.origin, bounds.inv_direction, bounds.exit_inv_direction]
            .iter()
            .all(|b| b.iter().flatten().all(|x| x.is_finite()));
        (count > 1 && finite).then_some(bounds)
    }
}

/// Widens `[least, greatest]`'s axis `k` to hold `x`.
fn widen(bounds: &mut [[f32; 3]; 2], k: usize, x: f32) {
    bounds[0][k] = bounds[0][k].min(x);
    bounds[1][k] = bounds[1][k].max(x);
}

impl Wide {
    /// The nearest hit of each of `rays` in `(t_min, t_max)`, into `hits` (as long as `rays`),
    /// found [`RAYS`] at a time; the same hits as [`Accelerator::closest`] ray by ray.
    pub(super) fn closest_in_packets(
        &self,
        prims: &[Primitive],
        rays: &[Ray],
        t_min: f32,
        t_max: f32,
        hits: &mut [Option<Hit>],
    ) {
        assert_eq!(rays.len(), hits.len(), "one hit for each ray");
        let t_max = [t_max; RAYS];
        for (rays, hits) in rays.chunks(RAYS).zip(hits.chunks_mut(RAYS)) {
            self.packet::<false>(prims, rays, (t_min, &t_max), hits);
        }
    }

    /// Whether anything is hit along each of `rays` in `(t_min, t_max[i])`, into `occluded`,
    /// [`RAYS`] at a time (shadow rays, each to its own light distance); the same answers as
    /// [`Accelerator::occluded`] ray by ray. A ray leaves the packet at its first hit.
    pub(super) fn occluded_in_packets(
        &self,
        prims: &[Primitive],
        rays: &[Ray],
        (t_min, t_max): (f32, &[f32]),
        occluded: &mut [bool],
    ) {
        assert!(rays.len() == t_max.len() && rays.len() == occluded.len(), "one bound and one answer for each ray");
        let mut hits = [None; RAYS];
        for ((rays, t_max), occluded) in rays.chunks(RAYS).zip(t_max.chunks(RAYS)).zip(occluded.chunks_mut(RAYS)) {
            let hits = &mut hits[..rays.len()];
            self.packet::<true>(prims, rays, (t_min, t_max), hits);
            for (answer, hit) in occluded.iter_mut().zip(hits.iter()) {
                *answer = hit.is_some();
            }
        }
    }

    /// One packet: with `ANY`, each ray's first hit found (whether it is occluded); without, its
    /// nearest.
    fn packet<const ANY: bool>(
        &self,
        prims: &[Primitive],
        rays: &[Ray],
        (t_min, t_max): (f32, &[f32]),
        hits: &mut [Option<Hit>],
    ) {
        let mut prepared: [Option<PreparedRay>; RAYS] = [None; RAYS];
        for (i, ray) in rays.iter().enumerate() {
            hits[i] = None;
            prepared[i] = PreparedRay::new(ray);
            // A ray along an axis needs the careful slab test: walked alone.
            if prepared[i].is_some_and(|p| !p.inv_direction.is_finite()) {
                hits[i] = self.query::<ANY>(prims, ray, t_min, t_max[i]);
                prepared[i] = None;
            }
        }
        if self.nodes.is_empty() {
            return;
        }
        let members: [Option<Member>; RAYS] = std::array::from_fn(|i| {
            let p = prepared[i].as_ref()?;
            let query = Query { prims, ray: &rays[i], prepared: p, t_min, t_max: t_max[i] };
            Some(Member { query, box_ray: BoxRay::new(p), packet_ray: PacketRay::new(p) })
        });
        let active = (0..RAYS).filter(|&i| members[i].is_some()).fold(0u32, |m, i| m | 1 << i);
        if active == 0 {
            return;
        }
        let bounds = Bounds::new(&members, t_min);
        let packet = (&members, bounds.as_ref());
        let small = self.stack_bound <= SMALL_STACK;
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is set only where the CPU reports AVX.
            unsafe { self.packet_avx::<ANY>(packet, active, small, hits) };
            return;
        }
        // SAFETY: `Halves` uses what every target has (SSE2 on x86-64).
        unsafe {
            if small {
                self.walk::<Halves, ANY, SMALL_STACK>(packet, active, hits)
            } else {
                self.walk::<Halves, ANY, LARGE_STACK>(packet, active, hits)
            }
        }
    }

    /// The packet's walk compiled with AVX enabled ([`Wide::run_avx`]'s reason).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn packet_avx<const ANY: bool>(
        &self,
        packet: (&[Option<Member>; RAYS], Option<&Bounds>),
        active: u32,
        small: bool,
        hits: &mut [Option<Hit>],
    ) {
        // SAFETY: this function runs only where the CPU has AVX (its caller checks).
        unsafe {
            if small {
                self.walk::<Octet, ANY, SMALL_STACK>(packet, active, hits)
            } else {
                self.walk::<Octet, ANY, LARGE_STACK>(packet, active, hits)
            }
        }
    }

    /// The packet's nearest-first walk: the rays of `active` (those `members` holds), each with
    /// its own far bound. With `ANY`, a ray's first hit ends its walk: its far bound becomes
    /// −∞, so it enters no more boxes and leaves every pending child. Nodes are tested on the
    /// rays' `bounds` where there are bounds, until a node needs its rays tested one by one;
    /// under that node they all are.
    ///
    /// # Safety
    /// The CPU must have the instructions `L` uses.
    #[inline(always)]
    unsafe fn walk<L: Lanes, const ANY: bool, const STACK: usize>(
        &self,
        (members, bounds): (&[Option<Member>; RAYS], Option<&Bounds>),
        active: u32,
        hits: &mut [Option<Hit>],
    ) {
        let mut t_max = [f32::INFINITY; RAYS];
        for (i, member) in members.iter().enumerate() {
            if let Some(member) = member {
                t_max[i] = member.query.t_max;
            }
        }
        // Each pending child with its rays, their nearest entry, and whether they are together.
        let mut stack = Stack::<(u32, u32, f32, bool), STACK>::new();
        let (mut current, mut rays) = (0u32, active);
        let mut together = bounds.is_some();
        let mut done = 0u32;
        loop {
            if rays & (rays - 1) == 0 {
                // One ray left on this path: it walks the subtree alone, as it would on its own.
                let i = rays.trailing_zeros() as usize;
                if let Some(member) = &members[i] {
                    // SAFETY: the caller's promise about `L`; `current` is 0 or a child's entry.
                    let first = unsafe {
                        self.traverse_from::<L, ANY, false, STACK>(&member.query, current, &mut hits[i], &mut t_max[i])
                    };
                    if ANY && first.is_some() {
                        hits[i] = first;
                        t_max[i] = f32::NEG_INFINITY;
                        done |= 1 << i;
                        if done == active {
                            return;
                        }
                    }
                }
            } else if current & LEAF == 0 {
                // SAFETY: `current` is 0 or an inner child's entry of a node.
                let node = unsafe { self.node(current) };
                let settled = match bounds {
                    // SAFETY: the caller's promise about `L`.
                    Some(bounds) if together => unsafe { enter_together::<L>(node, bounds, rays, &t_max) },
                    _ => None,
                };
                together = settled.is_some();
                // SAFETY: the caller's promise about `L`.
                let entered = settled.unwrap_or_else(|| unsafe { enter_each::<L>(node, members, rays, &t_max) });
                if let Some((child, next)) = entered.nearest_pushing_others(node, together, &mut stack) {
                    (current, rays) = (child, next);
                    continue;
                }
            } else {
                for i in bits(rays) {
                    let Some(member) = &members[i] else { continue };
                    // SAFETY: the caller's promise about `L`.
                    let first = unsafe {
                        self.leaf::<L, ANY>(
                            current & !LEAF,
                            &member.query,
                            &member.packet_ray,
                            &mut hits[i],
                            &mut t_max[i],
                        )
                    };
                    debug_assert!(ANY || first.is_none(), "a nearest-hit walk returns from its leaves only at the end");
                    if ANY && first.is_some() {
                        hits[i] = first;
                        t_max[i] = f32::NEG_INFINITY;
                        done |= 1 << i;
                    }
                }
                if ANY && done == active {
                    return;
                }
            }
            // Next: the nearest pending child, with the rays whose nearest hit is not nearer.
            loop {
                let Some((child, pending, entry, with_bounds)) = stack.pop() else { return };
                let still = bits(pending).filter(|&i| entry < t_max[i]).fold(0, |m, i| m | 1 << i);
                if still != 0 {
                    (current, rays, together) = (child, still, with_bounds);
                    break;
                }
            }
        }
    }
}

/// For each of a node's children, the rays that enter its box and the nearest of their entries.
struct Entered {
    rays: [u32; WIDTH],
    entry: [f32; WIDTH],
}

/// The node's eight boxes tested once for all of `rays`, on the packet's `bounds` (the module's
/// "packet as one interval"): `Some` where each box is entered by every ray or by none, with the
/// nearest entry any ray can have; `None` where a box may be entered by some rays only.
///
/// # Safety
/// The CPU must have the instructions `L` uses.
#[inline(always)]
unsafe fn enter_together<L: Lanes>(node: &Node, bounds: &Bounds, rays: u32, t_max: &[f32; RAYS]) -> Option<Entered> {
    let (mut least_far, mut greatest_far) = (f32::INFINITY, f32::NEG_INFINITY);
    for i in bits(rays) {
        (least_far, greatest_far) = (least_far.min(t_max[i]), greatest_far.max(t_max[i]));
    }
    // SAFETY: the caller's promise about `L`.
    let (all, none, entry) = unsafe {
        let (mut enter_least, mut enter_greatest) = (L::splat(bounds.t_min), L::splat(bounds.t_min));
        let (mut exit_least, mut exit_greatest) = (L::splat(least_far), L::splat(greatest_far));
        for k in 0..3 {
            let near = L::load(&node.planes[bounds.near[k]]);
            let (near_least, near_greatest) = corners(near, bounds.origin, bounds.inv_direction, k);
            let far = L::load(&node.planes[bounds.far[k]]);
            let (far_least, far_greatest) = corners(far, bounds.origin, bounds.exit_inv_direction, k);
            (enter_least, enter_greatest) = (enter_least.max(near_least), enter_greatest.max(near_greatest));
            (exit_least, exit_greatest) = (exit_least.min(far_least), exit_greatest.min(far_greatest));
        }
        (enter_greatest.le(exit_least), enter_least.gt(exit_greatest), enter_least.to_array())
    };
    if (all | none) != (1 << WIDTH) - 1 {
        return None;
    }
    let mut entered = Entered { rays: [0; WIDTH], entry: [f32::INFINITY; WIDTH] };
    for child in bits(all) {
        (entered.rays[child], entered.entry[child]) = (rays, entry[child]);
    }
    Some(entered)
}

/// The least and the greatest of `(plane − origin)·inv` along axis `k` over the intervals
/// `[least, greatest]` of `origin` and `inv`: among its values at the intervals' corners, since
/// rounding keeps order (of the difference, then of the product in each factor).
///
/// # Safety
/// The CPU must have the instructions `L` uses.
#[inline(always)]
unsafe fn corners<L: Lanes>(plane: L, origin: [[f32; 3]; 2], inv: [[f32; 3]; 2], k: usize) -> (L, L) {
    // SAFETY: the caller's promise about `L`.
    unsafe {
        let (from_greatest, from_least) = (plane - L::splat(origin[1][k]), plane - L::splat(origin[0][k]));
        let (least_inv, greatest_inv) = (L::splat(inv[0][k]), L::splat(inv[1][k]));
        let (a, b) = (from_greatest * least_inv, from_greatest * greatest_inv);
        let (c, d) = (from_least * least_inv, from_least * greatest_inv);
        (a.min(b).min(c.min(d)), a.max(b).max(c.max(d)))
    }
}

/// Tests every ray of `rays` against the node's eight boxes.
///
/// # Safety
/// The CPU must have the instructions `L` uses.
#[inline(always)]
unsafe fn enter_each<L: Lanes>(
    node: &Node,
    members: &[Option<Member>; RAYS],
    rays: u32,
    t_max: &[f32; RAYS],
) -> Entered {
    let mut entered = Entered { rays: [0; WIDTH], entry: [f32::INFINITY; WIDTH] };
    for i in bits(rays) {
        let Some(member) = &members[i] else { continue };
        // SAFETY: the caller's promise about `L`.
        let (mask, entries) = unsafe { enter::<L, false>(node, &member.box_ray, member.query.t_min, t_max[i]) };
        for child in bits(mask) {
            entered.rays[child] |= 1 << i;
            entered.entry[child] = entered.entry[child].min(entries[child]);
        }
    }
    entered
}

impl Entered {
    /// Pushes every entered child but the nearest, farthest first (each marked `together` or not),
    /// and returns the nearest with its rays; `None` when no ray enters any.
    #[inline(always)]
    fn nearest_pushing_others<const N: usize>(
        &self,
        node: &Node,
        together: bool,
        stack: &mut Stack<(u32, u32, f32, bool), N>,
    ) -> Option<(u32, u32)> {
        let mut order = [0usize; WIDTH];
        let mut count = 0;
        for child in (0..WIDTH).filter(|&c| self.rays[c] != 0) {
            // Insertion, farthest first.
            let mut j = count;
            while j > 0 && self.entry[order[j - 1]] < self.entry[child] {
                order[j] = order[j - 1];
                j -= 1;
            }
            order[j] = child;
            count += 1;
        }
        let (&nearest, others) = order[..count].split_last()?;
        for &child in others {
            stack.push((node.child[child], self.rays[child], self.entry[child], together));
        }
        Some((node.child[nearest], self.rays[nearest]))
    }
}

/// The set bits of `mask`, lowest first.
#[inline(always)]
fn bits(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        let i = mask.trailing_zeros() as usize;
        mask &= mask.wrapping_sub(1);
        (i < 32).then_some(i)
    })
}
