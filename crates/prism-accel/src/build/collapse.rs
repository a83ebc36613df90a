//! The collapse of the binary tree into 8-wide nodes: each node's slots hold the
//! descendants that give the least total node area (a dynamic programme over
//! [`BuildNode::interior`]'s slot costs).

use super::leaves::LeafJob;
use super::node::{root_bounds, split_cost, BuildNode};
use crate::layout::node8::Node8;
use crate::layout::Bvh;

impl Bvh {
    /// Flattens a binary node and its subtree into 8-wide nodes: the node's slots hold the
    /// descendants that give the least total node area ([`BuildNode::interior`]). Returns
    /// the node's index.
    pub(crate) fn collapse(
        &mut self,
        n: &BuildNode,
        order: &[u32],
        jobs: &mut Vec<LeafJob>,
    ) -> u32 {
        let mut kids = Vec::with_capacity(8);
        match n {
            BuildNode::Interior { children, .. } => {
                hand_down(&children[0], &children[1], 8, &mut kids);
            }
            BuildNode::Leaf { .. } => kids.push(n),
        }
        let index = self.nodes.len();
        self.nodes.push(Node8::empty());
        for (slot, &k) in kids.iter().enumerate() {
            let r = match k {
                BuildNode::Leaf { .. } => self.plan_leaf(k, order, jobs),
                BuildNode::Interior { .. } => self.collapse(k, order, jobs),
            };
            self.nodes[index].set(slot, root_bounds(k), r);
        }
        index as u32
    }
}

/// Lists in `out`, in order, the subtrees that fill the slots two sibling subtrees `a` and `b`
/// share at least cost ([`BuildNode::interior`]), given `j` >= 2 slots.
pub(crate) fn hand_down<'a>(
    a: &'a BuildNode,
    b: &'a BuildNode,
    j: usize,
    out: &mut Vec<&'a BuildNode>,
) {
    let k = split_cost(&a.slots(), &b.slots(), j).1;
    place(a, k, out);
    place(b, j - k, out);
}

/// Lists in `out` the subtrees that hold subtree `n` in at most `j` slots at least cost: `n`
/// itself, or descendants of it.
pub(crate) fn place<'a>(n: &'a BuildNode, j: usize, out: &mut Vec<&'a BuildNode>) {
    let BuildNode::Interior {
        children, slots, ..
    } = n
    else {
        out.push(n);
        return;
    };
    // The fewest slots that reach the least cost.
    let mut j = j;
    while j > 1 && slots[j - 2] <= slots[j - 1] {
        j -= 1;
    }
    if j == 1 {
        out.push(n);
    } else {
        hand_down(&children[0], &children[1], j, out);
    }
}

#[cfg(test)]
mod tests {
    use super::super::node::{area64, free};
    use super::super::sah::{bounds_of, build_node, take_big, Box3A, PrimRef};
    use super::*;
    use crate::BuildOptions;
    use prism_math::Aabb;
    use prism_math::{Pcg32, Vec3};
    use std::collections::HashMap;

    /// Every set of at most `max` descendants of `n` (itself included) that holds each of
    /// its leaves exactly once: what slots of a node could hold in its place.
    fn frontiers(n: &BuildNode, max: usize) -> Vec<Vec<&BuildNode>> {
        let mut all = vec![vec![n]];
        if let BuildNode::Interior { children, .. } = n {
            if max >= 2 {
                for fa in frontiers(&children[0], max - 1) {
                    for fb in frontiers(&children[1], max - fa.len()) {
                        all.push(fa.iter().chain(&fb).copied().collect());
                    }
                }
            }
        }
        all
    }

    /// The least total area of the 8-wide nodes of subtree `n` made a node, by trying
    /// every set of descendants its slots could hold (a brute force over those sets,
    /// memoised by node, not the slot-cost recurrence).
    fn least_node_area(n: &BuildNode, memo: &mut HashMap<usize, f64>) -> f64 {
        let BuildNode::Interior {
            bounds, children, ..
        } = n
        else {
            return 0.0;
        };
        let key = std::ptr::from_ref(n) as usize;
        if let Some(&c) = memo.get(&key) {
            return c;
        }
        let mut best = f64::INFINITY;
        for fa in frontiers(&children[0], 7) {
            for fb in frontiers(&children[1], 8 - fa.len()) {
                let c: f64 = fa.iter().chain(&fb).map(|f| least_node_area(f, memo)).sum();
                best = best.min(c);
            }
        }
        let c = area64(bounds) + best;
        memo.insert(key, c);
        c
    }

    /// Oracle: brute force. The collapse's 8-wide tree has the least total node area any
    /// collapse of the binary tree has (every set of descendants each node's slots could
    /// hold tried), on random soups of 20 to 58 triangles in leaves of one.
    #[test]
    fn collapse_has_least_node_area() {
        let mut rng = Pcg32::new(11, 4);
        for case in 0..24 {
            let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let n = 20 + case * 40 / 24;
            let tris: Vec<[Vec3; 3]> = (0..n)
                .map(|k| {
                    let a = r() * 8.0;
                    let size = if k % 5 == 0 { 1.5 } else { 0.4 };
                    [a, a + r() * size, a + r() * size]
                })
                .collect();
            let opts = BuildOptions {
                max_leaf: 1,
                ..BuildOptions::default()
            };
            let bvh = Bvh::build(&tris, &[], &opts);
            // The same binary tree, as the build makes it.
            let mut prims: Vec<PrimRef> = tris
                .iter()
                .enumerate()
                .map(|(i, t)| PrimRef {
                    bounds: Box3A::from_aabb(Aabb::point(t[0]).extend(t[1]).extend(t[2])),
                    id: i as u32,
                })
                .collect();
            let (b3, cb) = bounds_of(&prims, opts.parallel_threshold);
            assert_eq!(take_big(&mut prims, b3, opts.parallel_threshold), 0);
            let (root, summary) = build_node(&mut prims, 0, 0, &opts, b3, cb);
            assert_eq!(
                bvh.stats().primitives,
                n,
                "case {case}: no triangle left out"
            );
            assert_eq!(bvh.stats().leaves, summary.leaves, "case {case}");
            let want = least_node_area(&root, &mut HashMap::new());
            // The built tree's node area: the root's box, then each child node's box as
            // its parent holds it.
            let mut got = area64(&bvh.bounds());
            let mut stack = vec![0usize];
            while let Some(i) = stack.pop() {
                let node = &bvh.nodes[i];
                for slot in 0..8 {
                    if node.slot_used(slot) && !Bvh::is_leaf_ref(node.child[slot]) {
                        got += area64(&node.child_box(slot));
                        stack.push(node.child[slot] as usize);
                    }
                }
            }
            assert!(
                (got - want).abs() <= 1e-5 * want,
                "case {case}: collapse area {got}, least {want}"
            );
            free(root, 0);
        }
    }
}
