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
//! than its own. So each ray tests at least every triangle the single-ray walk tests, each with
//! the same arithmetic, and takes the nearest by the same rule ([`super::super::offer`]: the
//! smaller distance, then the smaller index): the hits, and the image, are the single-ray walk's
//! to the bit. A ray it could not walk the fast way (one that runs exactly along an axis, whose
//! slab test needs [`enter`]'s careful variant) is walked alone.
//!
//! **Shadow rays** ([`Wide::occluded_in_packets`]) walk the same way, each to its own far bound
//! (its light's distance), and a ray leaves the packet at its first hit: whether anything is hit
//! is the single ray's answer, since a ray enters every box the single-ray walk enters until then.
//!
//! What a packet costs instead: a ray that left the others' path is carried along, masked, until
//! the nodes it enters run out. Incoherent rays (reflections off curved surfaces, refraction)
//! gain nothing, and are traced one by one.

use super::*;

/// Rays in one packet: a 4 × 4 block of pixels.
pub const RAYS: usize = 16;

/// One ray of the packet, prepared once.
struct Member<'a> {
    query: Query<'a>,
    box_ray: BoxRay,
    packet_ray: PacketRay,
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
        let members = &members;
        let small = self.stack_bound <= SMALL_STACK;
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is set only where the CPU reports AVX.
            unsafe { self.packet_avx::<ANY>(members, active, small, hits) };
            return;
        }
        // SAFETY: `Halves` uses what every target has (SSE2 on x86-64).
        unsafe {
            if small {
                self.walk::<Halves, ANY, SMALL_STACK>(members, active, hits)
            } else {
                self.walk::<Halves, ANY, LARGE_STACK>(members, active, hits)
            }
        }
    }

    /// The packet's walk compiled with AVX enabled ([`Wide::run_avx`]'s reason).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn packet_avx<const ANY: bool>(
        &self,
        members: &[Option<Member>; RAYS],
        active: u32,
        small: bool,
        hits: &mut [Option<Hit>],
    ) {
        // SAFETY: this function runs only where the CPU has AVX (its caller checks).
        unsafe {
            if small {
                self.walk::<Octet, ANY, SMALL_STACK>(members, active, hits)
            } else {
                self.walk::<Octet, ANY, LARGE_STACK>(members, active, hits)
            }
        }
    }

    /// The packet's nearest-first walk: the rays of `active` (those `members` holds), each with
    /// its own far bound. With `ANY`, a ray's first hit ends its walk: its far bound becomes
    /// −∞, so it enters no more boxes and leaves every pending child.
    ///
    /// # Safety
    /// The CPU must have the instructions `L` uses.
    #[inline(always)]
    unsafe fn walk<L: Lanes, const ANY: bool, const STACK: usize>(
        &self,
        members: &[Option<Member>; RAYS],
        active: u32,
        hits: &mut [Option<Hit>],
    ) {
        let mut t_max = [f32::INFINITY; RAYS];
        for (i, member) in members.iter().enumerate() {
            if let Some(member) = member {
                t_max[i] = member.query.t_max;
            }
        }
        let mut stack = Stack::<(u32, u32, f32), STACK>::new();
        let (mut current, mut rays) = (0u32, active);
        let mut done = 0u32;
        loop {
            if current & LEAF == 0 {
                // SAFETY: `current` is 0 or an inner child's entry of a node.
                let node = unsafe { self.node(current) };
                // SAFETY: the caller's promise about `L`.
                let entered = unsafe { enter_all::<L>(node, members, rays, &t_max) };
                if let Some((child, next)) = entered.nearest_pushing_others(node, &mut stack) {
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
                let Some((child, pending, entry)) = stack.pop() else { return };
                let still = bits(pending).filter(|&i| entry < t_max[i]).fold(0, |m, i| m | 1 << i);
                if still != 0 {
                    (current, rays) = (child, still);
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

/// Tests every ray of `rays` against the node's eight boxes.
///
/// # Safety
/// The CPU must have the instructions `L` uses.
#[inline(always)]
unsafe fn enter_all<L: Lanes>(
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
    /// Pushes every entered child but the nearest, farthest first, and returns the nearest with
    /// its rays; `None` when no ray enters any.
    #[inline(always)]
    fn nearest_pushing_others<const N: usize>(
        &self,
        node: &Node,
        stack: &mut Stack<(u32, u32, f32), N>,
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
            stack.push((node.child[child], self.rays[child], self.entry[child]));
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
