//! The root's list ([`RootList`]): the primitives of the root's leaves gathered apart, with
//! the boxes of its other children, when there are at most [`FLAT_MAX`] of them.

use prism_math::Vec3;

use crate::layout::root_list::{RootList, FLAT_MAX};
use crate::layout::Bvh;
use crate::shapes::Sphere;

impl Bvh {
    /// The primitives of the root's leaves in one list, with the boxes of the root's other
    /// children, if the root has between one and [`FLAT_MAX`] of them.
    pub(crate) fn root_list(
        &self,
        triangles: &[[Vec3; 3]],
        spheres: &[Sphere],
    ) -> Option<RootList> {
        let root = self.nodes.first()?;
        let nt = self.triangle_count;
        let mut flat = RootList {
            first_sphere: nt,
            ..RootList::default()
        };
        // Each primitive with its leaf, whose box gates it as the walk's root test does.
        let mut prims = Vec::new();
        for slot in (0..8).filter(|&k| root.slot_used(k)) {
            let child = root.child[slot];
            if Bvh::is_leaf_ref(child) {
                let leaf = flat.leaf_boxes.len() as u8;
                flat.leaf_boxes.push(root.child_box(slot));
                prims.extend(self.leaf_prims(child).into_iter().map(|p| (p, leaf)));
                flat.skip |= 1 << slot;
            } else {
                flat.inner.push(root.child_box(slot));
                flat.inner_nodes.push(child);
            }
        }
        if !(1..=FLAT_MAX).contains(&prims.len()) {
            return None;
        }
        prims.sort_unstable();
        for (p, leaf) in prims {
            if p < nt {
                flat.push_triangle(triangles[p as usize], p, leaf);
            } else {
                flat.spheres.push((spheres[(p - nt) as usize], p));
                flat.sphere_leaves.push(leaf);
            }
        }
        Some(flat)
    }
}
