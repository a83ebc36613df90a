//! [`RootList`], the primitives of the root's leaves in one list (in a small scene every
//! primitive; in a Cornell box, the walls), with the boxes of the root's other children:
//! the data the batched queries test on lanes before the tree.

use prism_math::{Aabb, Vec3};

use crate::shapes::Sphere;

/// Roots whose leaves hold at most this many primitives also keep them in a [`RootList`].
/// One-ray traversals of a few large primitives spend their time in mispredicted branches
/// and serial latency rather than work; testing each on sixteen lanes costs less.
pub(crate) const FLAT_MAX: usize = 24;

/// The most distinct vertices a list holds.
pub(crate) const MAX_VERTICES: usize = 3 * FLAT_MAX;

/// The primitives of the root's leaves, with their primitive numbers, and the root's other
/// children.
#[derive(Clone, Debug, Default)]
pub(crate) struct RootList {
    pub(crate) triangles: Vec<([Vec3; 3], u32)>,
    /// The triangles' distinct vertices, padded to four floats (`x, y, z, 0`) for lane
    /// permutes: a room's walls share their corners, which are then prepared once.
    pub(crate) vertices: Vec<[f32; 4]>,
    /// Per triangle, its vertices' indices in `vertices`.
    pub(crate) corners: Vec<[u16; 3]>,
    pub(crate) spheres: Vec<(Sphere, u32)>,
    /// Primitive numbers from this one on are spheres.
    pub(crate) first_sphere: u32,
    /// Per triangle, its leaf: an index into `leaf_boxes`.
    pub(crate) triangle_leaves: Vec<u8>,
    /// Per sphere, its leaf.
    pub(crate) sphere_leaves: Vec<u8>,
    /// The boxes of the root's children that are leaves (at most eight).
    pub(crate) leaf_boxes: Vec<Aabb>,
    /// The boxes of the root's children that are not leaves.
    pub(crate) inner: Vec<Aabb>,
    /// Those children's node references.
    pub(crate) inner_nodes: Vec<u32>,
    /// The root's slots whose leaves are in the list.
    pub(crate) skip: u32,
}

impl RootList {
    /// Where the walk of a lane of `Lanes::need` starts, given its `Lanes::inner`: at
    /// the one child of the root it enters, else at the root, leaving out the list's
    /// leaves. Both walks find the same hit. The gate computes the root's slab test (its
    /// operations, in order) up to the list's hit or the ray's end, widened as the walk
    /// widens it; the children it does not enter start beyond that, hold no hit the walk
    /// would take, and the walk from the root visits the one it enters as it would from
    /// there. A shadow ray the root's own test (up to the unwidened end) sends nowhere
    /// finds nothing in the child either: the boxes below it start no nearer.
    pub(crate) fn start(&self, inner: u32) -> crate::layout::Start {
        match self.inner_nodes.get(inner as usize) {
            Some(&node) => crate::layout::Start { node, skip: 0 },
            None => crate::layout::Start {
                node: 0,
                skip: self.skip,
            },
        }
    }

    /// Adds triangle `tri`, primitive `prim`, of leaf `leaf`, sharing the vertices already
    /// listed.
    pub(crate) fn push_triangle(&mut self, tri: [Vec3; 3], prim: u32, leaf: u8) {
        let corners = tri.map(|v| {
            let padded = [v.x, v.y, v.z, 0.0];
            let bits = padded.map(f32::to_bits);
            let at = self
                .vertices
                .iter()
                .position(|w| w.map(f32::to_bits) == bits)
                .unwrap_or_else(|| {
                    self.vertices.push(padded);
                    self.vertices.len() - 1
                });
            at as u16
        });
        self.triangles.push((tri, prim));
        self.corners.push(corners);
        self.triangle_leaves.push(leaf);
    }
}
