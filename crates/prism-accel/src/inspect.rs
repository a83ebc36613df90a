//! Inspection views of a [`Bvh`]'s 8-wide tree, for drawing and checking it: its number of
//! levels, the boxes at each level, and its leaves with their primitives.

use prism_math::Aabb;

use crate::layout::node8::Node8;
use crate::layout::Bvh;

/// A leaf of the 8-wide tree, as [`Bvh::leaf_views`] lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct LeafView {
    /// The leaf's box, as its parent node stores it.
    pub bounds: Aabb,
    /// The leaf's level (see [`Bvh::levels`]): at least 1.
    pub level: usize,
    /// The leaf's primitive numbers, numbered as in [`crate::Hit::prim`]: its triangles,
    /// then its spheres.
    pub prims: Vec<u32>,
}

/// A used child slot met by [`Bvh::walk`].
struct Slot {
    bounds: Aabb,
    child: u32,
    level: usize,
}

/// Pushes the used slots of `n`, at `level`, so that slot 0 is popped first.
fn push_children(n: &Node8, level: usize, stack: &mut Vec<Slot>) {
    for slot in (0..8).rev() {
        if n.slot_used(slot) {
            stack.push(Slot {
                bounds: n.child_box(slot),
                child: n.child[slot],
                level,
            });
        }
    }
}

impl Bvh {
    /// Visits every used child slot at levels up to `max_level`, depth first in slot order
    /// (a slot, then the subtree under it, then the next slot), with an explicit stack.
    fn walk(&self, max_level: usize, mut visit: impl FnMut(&Slot)) {
        let nodes = self.node_array();
        if nodes.is_empty() || max_level == 0 {
            return;
        }
        let mut stack = Vec::new();
        push_children(&nodes[0], 1, &mut stack);
        while let Some(s) = stack.pop() {
            visit(&s);
            if !Bvh::is_leaf_ref(s.child) && s.level < max_level {
                push_children(&nodes[s.child as usize], s.level + 1, &mut stack);
            }
        }
    }

    /// Number of levels of the 8-wide tree. Level 0 is the root box [`Bvh::bounds`];
    /// level 1 holds the boxes of the root node's children; level `L + 1` the boxes of the
    /// children of the nodes at level `L`. The count is one more than the deepest leaf's
    /// level: 0 for an empty hierarchy, else at least 2 (a lone leaf sits under the root
    /// node, at level 1).
    #[must_use]
    pub fn levels(&self) -> usize {
        if self.node_array().is_empty() {
            return 0;
        }
        let mut deepest = 0;
        self.walk(usize::MAX, |s| deepest = deepest.max(s.level));
        deepest + 1
    }

    /// The boxes of all nodes and leaves at `level` (see [`Bvh::levels`]), in depth-first
    /// slot order: `[self.bounds()]` for level 0, none past the last level or for an empty
    /// hierarchy.
    #[must_use]
    pub fn level_boxes(&self, level: usize) -> Vec<Aabb> {
        if self.node_array().is_empty() {
            return Vec::new();
        }
        if level == 0 {
            return vec![self.bounds()];
        }
        let mut boxes = Vec::new();
        self.walk(level, |s| {
            if s.level == level {
                boxes.push(s.bounds);
            }
        });
        boxes
    }

    /// Every leaf of the 8-wide tree, in depth-first slot order (the order of
    /// [`Bvh::level_boxes`] within each level). Each primitive the build kept appears in
    /// exactly one leaf.
    #[must_use]
    pub fn leaf_views(&self) -> Vec<LeafView> {
        let mut views = Vec::new();
        self.walk(usize::MAX, |s| {
            if Bvh::is_leaf_ref(s.child) {
                views.push(LeafView {
                    bounds: s.bounds,
                    level: s.level,
                    prims: self.leaf_prims(s.child),
                });
            }
        });
        views
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BuildOptions, Sphere};
    use prism_math::{Pcg32, Vec3};

    /// A soup of triangles and spheres with the primitive numbers the build must keep:
    /// every seventh triangle and every fifth sphere is made degenerate on purpose (zero
    /// area, a NaN vertex, a zero or negative radius) and left out of the list.
    struct Soup {
        tris: Vec<[Vec3; 3]>,
        spheres: Vec<Sphere>,
        valid: Vec<u32>,
    }

    fn soup(seed: u64, nt: usize, ns: usize, spread: f32) -> Soup {
        let mut rng = Pcg32::new(seed, 11);
        let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let mut valid = Vec::new();
        let tris: Vec<[Vec3; 3]> = (0..nt)
            .map(|i| {
                let a = r() * spread;
                let (b, c) = (a + r(), a + r() * 0.5);
                match i % 7 {
                    3 => [a, b, b],
                    5 => [a, b, Vec3::new(f32::NAN, 0.0, 0.0)],
                    _ => {
                        valid.push(i as u32);
                        [a, b, c]
                    }
                }
            })
            .collect();
        let spheres: Vec<Sphere> = (0..ns)
            .map(|i| {
                let center = r() * spread;
                let radius = match i % 5 {
                    2 => 0.0,
                    4 => -1.0,
                    _ => {
                        valid.push((nt + i) as u32);
                        0.05 + r().x
                    }
                };
                Sphere { center, radius }
            })
            .collect();
        Soup {
            tris,
            spheres,
            valid,
        }
    }

    /// Soups over the build's paths: tiny (leaves of at most two), mid-sized and large
    /// (leaves of up to eight, spheres in the leaf table), and one whose primitives share
    /// a centroid (forced leaves, median splits).
    fn soups() -> Vec<(Soup, Bvh)> {
        let mut out: Vec<Soup> = [
            (1, 3, 0, 1.0),
            (2, 40, 6, 5.0),
            (3, 600, 25, 20.0),
            (4, 4000, 40, 30.0),
            (5, 300, 0, 2.0),
        ]
        .into_iter()
        .map(|(seed, nt, ns, spread)| soup(seed, nt, ns, spread))
        .collect();
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let centroid = (tri[0] + tri[1] + tri[2]) / 3.0;
        out.push(Soup {
            tris: vec![tri; 70],
            spheres: vec![
                Sphere {
                    center: centroid,
                    radius: 0.5
                };
                5
            ],
            valid: (0..75).collect(),
        });
        out.into_iter()
            .map(|s| {
                let bvh = Bvh::build(&s.tris, &s.spheres, &BuildOptions::default());
                (s, bvh)
            })
            .collect()
    }

    fn inside(a: &Aabb, b: &Aabb) -> bool {
        a.min.cmpge(b.min).all() && a.max.cmple(b.max).all()
    }

    /// Brute force: the primitive numbers of all leaves, sorted, are exactly the valid
    /// primitives, each once. The soups reach leaves of several packs and leaves holding
    /// both triangles and spheres.
    #[test]
    fn leaves_partition_the_valid_primitives_brute_force() {
        let (mut multi_pack, mut mixed) = (false, false);
        for (s, bvh) in soups() {
            let nt = bvh.triangle_count();
            let leaves = bvh.leaf_views();
            let mut all: Vec<u32> = leaves.iter().flat_map(|l| l.prims.clone()).collect();
            all.sort_unstable();
            assert_eq!(all, s.valid);
            for l in &leaves {
                assert!(!l.prims.is_empty());
                // Triangles first, then spheres.
                assert!(l.prims.windows(2).all(|w| !(w[0] >= nt && w[1] < nt)));
                let tris = l.prims.iter().filter(|&&p| p < nt).count();
                multi_pack |= tris > 4;
                mixed |= tris > 0 && tris < l.prims.len();
            }
        }
        assert!(multi_pack && mixed);
    }

    /// Property: every leaf's box holds its triangles' vertices and its spheres' boxes.
    #[test]
    fn leaf_boxes_contain_their_primitives() {
        for (s, bvh) in soups() {
            let nt = bvh.triangle_count();
            for l in bvh.leaf_views() {
                for &p in &l.prims {
                    let b = if p < nt {
                        let t = s.tris[p as usize];
                        Aabb::point(t[0]).extend(t[1]).extend(t[2])
                    } else {
                        s.spheres[(p - nt) as usize].bounds()
                    };
                    assert!(inside(&b, &l.bounds), "prim {p} outside {:?}", l.bounds);
                }
            }
        }
    }

    /// Brute force over boxes: level 0 is the root bounds and the union of level 1; every
    /// box at level `L + 1` lies inside some box at level `L`; every level below
    /// `levels()` has at most `8^L` boxes and none after it; each leaf's box is among its
    /// level's boxes, leaves keeping their relative order there.
    #[test]
    fn boxes_nest_level_by_level() {
        for (_, bvh) in soups() {
            let levels = bvh.levels();
            assert_eq!(bvh.level_boxes(0), vec![bvh.bounds()]);
            let union = bvh
                .level_boxes(1)
                .into_iter()
                .fold(Aabb::EMPTY, Aabb::union);
            assert_eq!(union, bvh.bounds());
            for level in 1..levels {
                let (upper, lower) = (bvh.level_boxes(level - 1), bvh.level_boxes(level));
                assert!(!lower.is_empty() && lower.len() <= 8usize.pow(level as u32));
                for b in &lower {
                    assert!(!b.is_empty());
                    assert!(upper.iter().any(|u| inside(b, u)), "level {level}: {b:?}");
                }
            }
            assert!(bvh.level_boxes(levels).is_empty());
            let leaves = bvh.leaf_views();
            for level in 1..levels {
                let boxes = bvh.level_boxes(level);
                let mut at = 0;
                for l in leaves.iter().filter(|l| l.level == level) {
                    let k = boxes[at..].iter().position(|b| *b == l.bounds);
                    at += k.expect("leaf box missing from its level, or out of order") + 1;
                }
            }
        }
    }

    /// Agreement with `stats()`: the binary tree's leaves are exactly the 8-wide tree's
    /// (collapsing only opens interior nodes), so the leaf count, the primitive total and
    /// the largest leaf match; a leaf's level is at most its binary depth (at least 1).
    #[test]
    fn leaf_views_match_stats() {
        for (_, bvh) in soups() {
            let st = bvh.stats();
            let leaves = bvh.leaf_views();
            assert_eq!(leaves.len(), st.leaves);
            let total: usize = leaves.iter().map(|l| l.prims.len()).sum();
            assert_eq!(total, st.primitives);
            let largest = leaves.iter().map(|l| l.prims.len()).max().unwrap_or(0);
            assert_eq!(largest, st.max_leaf_size);
            assert!(bvh.levels() - 1 <= st.depth.max(1));
        }
    }

    /// Closed form on the smallest trees: an empty hierarchy (no primitives, or only
    /// degenerate ones) has 0 levels and no boxes or leaves; one triangle is a lone leaf
    /// under the root node, 2 levels; larger trees have at least 2.
    #[test]
    fn levels_of_empty_lone_leaf_and_larger_trees() {
        let opts = BuildOptions::default();
        let degenerate = [[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]];
        for bvh in [Bvh::default(), Bvh::build(&degenerate, &[], &opts)] {
            assert_eq!(bvh.levels(), 0);
            assert!(bvh.level_boxes(0).is_empty());
            assert!(bvh.level_boxes(1).is_empty());
            assert!(bvh.leaf_views().is_empty());
        }
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let bvh = Bvh::build(&[tri], &[], &opts);
        let b = Aabb::point(tri[0]).extend(tri[1]).extend(tri[2]);
        assert_eq!(bvh.levels(), 2);
        assert_eq!(bvh.level_boxes(1), vec![b]);
        assert_eq!(
            bvh.leaf_views(),
            vec![LeafView {
                bounds: b,
                level: 1,
                prims: vec![0]
            }]
        );
        let sphere = Sphere {
            center: Vec3::ONE,
            radius: 2.0,
        };
        let bvh = Bvh::build(&[], &[sphere], &opts);
        assert_eq!(bvh.levels(), 2);
        assert_eq!(bvh.leaf_views()[0].prims, vec![0]);
        for (_, bvh) in soups() {
            assert!(bvh.levels() >= 2);
        }
    }
}
