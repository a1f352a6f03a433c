//! Adaptive octree.
//!
//! Seed 003 ("Divizarea adaptiva a scenei"): start from the scene's bounding box and divide it
//! into 8 equal sub-boxes, recursively, stopping where a sub-box holds no object or only one;
//! the scene becomes an octal tree. A ray that misses a node's box misses everything in its
//! subtree. Here a node is divided while it holds more than [`MAX_LEAF`] primitives, is less than
//! [`MAX_DEPTH`] deep, and dividing actually separates its primitives (some child gets fewer
//! than the parent: a primitive overlapping all eight octants would otherwise be copied forever).
//! A primitive is listed in every child its (slightly padded) box overlaps.
//!
//! **Traversal**, front to back: the children of an inner node are tested against the ray and
//! pushed farthest first, so the nearest is visited next. Since a primitive may be listed in
//! several leaves and hit outside the one being visited, the nearest hit of every primitive
//! tested is kept and a node is skipped only when it starts beyond that hit: exact, and the
//! walk ends as soon as the nearest pending node starts after the nearest hit. A mailbox skips
//! primitives already tested for this ray.
//!
//! Limits: the octants split at the box's centre whatever the primitives' distribution, so
//! clustered geometry needs depth a BVH would not; memory grows with primitives that straddle
//! many octants.

use web_time::Instant;

use glam::Vec3;

use super::{AccelStats, Accelerator, Hit, Mailbox, offer};
use crate::base::Ray;
use crate::trace::geometry::{Aabb, PreparedRay, Primitive};

/// Nodes with more primitives than this are divided.
pub const MAX_LEAF: usize = 8;
/// The deepest a node may be.
pub const MAX_DEPTH: usize = 12;
/// Marks a leaf in [`OctNode::children`].
const LEAF: u32 = u32::MAX;

struct OctNode {
    bounds: Aabb,
    /// The first of eight consecutive children, or [`LEAF`].
    children: u32,
    /// A leaf's primitives: `prims[first..first + count]`.
    first: u32,
    count: u32,
}

/// An adaptive octree over the primitives' boxes.
pub struct Octree {
    nodes: Vec<OctNode>,
    prims: Vec<u32>,
    stats: AccelStats,
}

impl Octree {
    pub fn build(prims: &[Primitive]) -> Octree {
        let start = Instant::now();
        let boxes: Vec<Aabb> = prims.iter().map(Primitive::bounds).collect();
        let scene = boxes.iter().filter(|b| !b.is_empty()).fold(Aabb::EMPTY, |s, b| s.union(b));
        let margin = 1e-5 * scene.extent().max_element().max(scene.min.abs().max(scene.max.abs()).max_element());
        let padded: Vec<Aabb> = boxes.iter().map(|b| if b.is_empty() { *b } else { b.padded(margin) }).collect();
        let mut octree = Octree { nodes: Vec::new(), prims: Vec::new(), stats: empty_stats(prims.len()) };
        let mut depth = 0;
        if !scene.is_empty() {
            let all: Vec<u32> = (0..prims.len() as u32).filter(|&i| !padded[i as usize].is_empty()).collect();
            octree.nodes.push(OctNode { bounds: scene.padded(margin), children: LEAF, first: 0, count: 0 });
            // (node, its primitives, depth)
            let mut work = vec![(0usize, all, 0usize)];
            while let Some((node, list, level)) = work.pop() {
                depth = depth.max(level);
                let bounds = octree.nodes[node].bounds;
                let split = (list.len() > MAX_LEAF && level < MAX_DEPTH)
                    .then(|| {
                        let lists: Vec<Vec<u32>> = (0..8)
                            .map(|octant| {
                                let child = octant_bounds(&bounds, octant);
                                list.iter().copied().filter(|&i| padded[i as usize].overlaps(&child)).collect()
                            })
                            .collect();
                        lists.iter().any(|l| l.len() < list.len()).then_some(lists)
                    })
                    .flatten();
                match split {
                    Some(lists) => {
                        let first_child = octree.nodes.len();
                        octree.nodes[node].children = first_child as u32;
                        for (octant, child_list) in lists.into_iter().enumerate() {
                            let bounds = octant_bounds(&bounds, octant);
                            octree.nodes.push(OctNode { bounds, children: LEAF, first: 0, count: 0 });
                            work.push((first_child + octant, child_list, level + 1));
                        }
                    }
                    None => {
                        let n = &mut octree.nodes[node];
                        n.first = octree.prims.len() as u32;
                        n.count = list.len() as u32;
                        octree.prims.extend_from_slice(&list);
                    }
                }
            }
        }
        octree.stats = AccelStats {
            nodes: octree.nodes.len(),
            leaves: octree.nodes.iter().filter(|n| n.children == LEAF).count(),
            depth,
            references: octree.prims.len(),
            memory_bytes: octree.nodes.len() * size_of::<OctNode>() + 4 * octree.prims.len(),
            build_time: start.elapsed(),
            ..empty_stats(prims.len())
        };
        octree
    }

    fn walk<const ANY: bool>(&self, prims: &[Primitive], ray: &Ray, t_min: f32, mut t_max: f32) -> Option<Hit> {
        let prepared = PreparedRay::new(ray)?;
        let (origin, inv) = (ray.origin, Vec3::from(prepared.inv_direction));
        let root = self.nodes.first()?;
        let (root_entry, _) = root.bounds.intersect_inv(origin, inv, t_min, t_max)?;
        let mut stack = [(0u32, 0.0f32); 8 * (MAX_DEPTH + 1)];
        stack[0] = (0, root_entry);
        let mut top = 1;
        let mut mailbox = Mailbox::new();
        let mut best = None;
        while top > 0 {
            top -= 1;
            let (index, entry) = stack[top];
            if entry >= t_max {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.children == LEAF {
                for &p in &self.prims[node.first as usize..(node.first + node.count) as usize] {
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
                continue;
            }
            // Children the ray enters, sorted so that the nearest ends on top of the stack.
            let mut hits = [(0u32, 0.0f32); 8];
            let mut n = 0;
            for c in node.children..node.children + 8 {
                if let Some((t, _)) = self.nodes[c as usize].bounds.intersect_inv(origin, inv, t_min, t_max) {
                    hits[n] = (c, t);
                    n += 1;
                }
            }
            hits[..n].sort_unstable_by(|a, b| b.1.total_cmp(&a.1));
            stack[top..top + n].copy_from_slice(&hits[..n]);
            top += n;
        }
        best
    }
}

fn empty_stats(primitives: usize) -> AccelStats {
    AccelStats {
        name: "adaptive octree",
        primitives,
        nodes: 0,
        leaves: 0,
        depth: 0,
        references: 0,
        memory_bytes: 0,
        build_time: Default::default(),
    }
}

/// Octant `i` of `b`: bit 0 picks the upper half in x, bit 1 in y, bit 2 in z.
fn octant_bounds(b: &Aabb, i: usize) -> Aabb {
    let c = b.centroid();
    let pick = |bit: usize, axis: usize| if i & bit == 0 { (b.min[axis], c[axis]) } else { (c[axis], b.max[axis]) };
    let ((x0, x1), (y0, y1), (z0, z1)) = (pick(1, 0), pick(2, 1), pick(4, 2));
    Aabb::new(Vec3::new(x0, y0, z0), Vec3::new(x1, y1, z1))
}

impl Accelerator for Octree {
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
