//! The hierarchy's data: [`Bvh`] (8-wide nodes, leaf triangle packs, the leaf table,
//! spheres, the root's list), how a child reference names a node or a leaf, and the
//! accessors the walks use. The rooms below hold the node layout (`node8`), the triangle
//! packs (`tri4`) and the root's list (`root_list`).

pub(crate) mod node8;
pub(crate) mod root_list;
pub(crate) mod tri4;

use prism_math::{prefetch, Aabb};

use crate::shapes::Sphere;
use node8::Node8;
use root_list::RootList;
use tri4::Tri4;

/// A leaf: `packs` triangle packs from `pack_start`, `spheres` spheres from `sphere_start`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LeafRec {
    pub(crate) pack_start: u32,
    pub(crate) sphere_start: u32,
    pub(crate) packs: u16,
    pub(crate) spheres: u16,
}

/// Build statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BvhStats {
    /// Triangles and spheres.
    pub primitives: usize,
    /// All nodes.
    pub nodes: usize,
    /// Leaf nodes.
    pub leaves: usize,
    /// Deepest leaf (the root has depth 0).
    pub depth: usize,
    /// Largest leaf.
    pub max_leaf_size: usize,
    /// The surface area heuristic's expected cost of a random ray (in primitive tests, with
    /// the build's traversal cost): the sum over nodes of their area relative to the root's
    /// times their cost.
    pub sah_cost: f32,
    /// Bytes held: nodes, triangle packs (vertices and primitive numbers), the leaf table,
    /// and spheres.
    pub bytes: usize,
}

pub(crate) const LEAF: u32 = 1 << 31;

/// In a leaf reference, bits 28 to 30 hold the number of triangle packs of a leaf with
/// triangles only (the low bits are then its first pack); zero means the low bits index
/// the leaf table.
pub(crate) const PACKS_SHIFT: u32 = 28;

pub(crate) const LOW_BITS: u32 = (1 << PACKS_SHIFT) - 1;

/// Depth after which splits are by median, so that no tree is deeper than this plus 32
/// and the traversal stacks below cannot overflow.
pub(crate) const MEDIAN_DEPTH: usize = 64;

/// A bounding volume hierarchy over triangles and spheres.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub(crate) nodes: Vec<Node8>,
    /// Triangles in packs of four, leaf by leaf.
    pub(crate) packs: Vec<Tri4>,
    /// Leaves: their packs, and their spheres in `leaf_spheres`.
    pub(crate) leaves: Vec<LeafRec>,
    /// Sphere primitive numbers, leaf by leaf.
    pub(crate) leaf_spheres: Vec<u32>,
    pub(crate) spheres: Vec<Sphere>,
    pub(crate) triangle_count: u32,
    pub(crate) bounds: Aabb,
    pub(crate) stats: BvhStats,
    /// For small hierarchies, the primitives in one list, for the batched queries.
    pub(crate) root_list: Option<RootList>,
}

/// Where a one-ray walk starts: at node `node`, and if that is the root, with the root's
/// children in the slots of `skip` left out.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Start {
    pub(crate) node: u32,
    pub(crate) skip: u32,
}

impl Start {
    /// The whole tree.
    pub(crate) const ROOT: Start = Start { node: 0, skip: 0 };
}

impl Bvh {
    /// Build statistics.
    #[must_use]
    pub fn stats(&self) -> BvhStats {
        self.stats
    }

    /// The bounds of everything in the hierarchy (empty if nothing).
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of triangles the hierarchy was built from (primitive numbers below this are
    /// triangles).
    #[must_use]
    pub fn triangle_count(&self) -> u32 {
        self.triangle_count
    }

    /// The node of reference `r`, which is not a leaf reference, without a bounds check.
    #[inline(always)]
    pub(crate) fn node(&self, r: u32) -> &Node8 {
        debug_assert!((r as usize) < self.nodes.len());
        // SAFETY: the walks start at the root or at one of its children (`Start`), only
        // when there is a root, and follow child references: each is the index of a node
        // pushed before it was stored (`Bvh::collapse`), and nodes are never removed.
        unsafe { self.nodes.get_unchecked(r as usize) }
    }

    /// Starts loading a node, or a leaf's first three packs of triangles, into the cache.
    #[inline(always)]
    pub(crate) fn prefetch(&self, r: u32) {
        let p: *const u8 = if r & LEAF == 0 {
            self.nodes.as_ptr().wrapping_add(r as usize).cast()
        } else if (r >> PACKS_SHIFT) & 7 != 0 {
            self.packs
                .as_ptr()
                .wrapping_add((r & LOW_BITS) as usize)
                .cast()
        } else {
            return;
        };
        prefetch(p);
        prefetch(p.wrapping_add(64));
        prefetch(p.wrapping_add(128));
        if r & LEAF != 0 && (r >> PACKS_SHIFT) & 6 != 0 {
            // The second pack of a leaf of two or more, tested with the first.
            prefetch(p.wrapping_add(192));
            prefetch(p.wrapping_add(256));
            prefetch(p.wrapping_add(319));
            if (r >> PACKS_SHIFT) & 7 >= 3 {
                // The third pack, tested right after the first two.
                prefetch(p.wrapping_add(383));
                prefetch(p.wrapping_add(447));
                prefetch(p.wrapping_add(479));
            }
        }
    }

    /// The packs and spheres of leaf reference `r`.
    #[inline(always)]
    pub(crate) fn leaf_rec(&self, r: u32) -> LeafRec {
        let in_ref = (r >> PACKS_SHIFT) & 7;
        if in_ref != 0 {
            LeafRec {
                pack_start: r & LOW_BITS,
                packs: in_ref as u16,
                ..LeafRec::default()
            }
        } else {
            self.leaves[(r & LOW_BITS) as usize]
        }
    }

    /// The 8-wide nodes, root first (none for an empty hierarchy).
    pub(crate) fn node_array(&self) -> &[Node8] {
        &self.nodes
    }

    /// True if child reference `r` names a leaf rather than a node.
    pub(crate) fn is_leaf_ref(r: u32) -> bool {
        r & LEAF != 0
    }

    /// The primitive numbers of leaf reference `r`: its triangles in pack order, then its
    /// spheres.
    pub(crate) fn leaf_prims(&self, r: u32) -> Vec<u32> {
        let rec = self.leaf_rec(r);
        let p0 = rec.pack_start as usize;
        let s0 = rec.sphere_start as usize;
        self.packs[p0..p0 + rec.packs as usize]
            .iter()
            .flat_map(|pack| pack.prim)
            .filter(|&p| p != u32::MAX)
            .chain(
                self.leaf_spheres[s0..s0 + rec.spheres as usize]
                    .iter()
                    .copied(),
            )
            .collect()
    }
}
