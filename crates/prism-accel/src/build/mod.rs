//! [`Bvh::build`]: the binned-SAH or median-split binary tree (`sah`, over the nodes of
//! `node`), collapsed into 8-wide nodes (`collapse`), its leaves' triangles packed in fours (`leaves`), and the
//! root's leaves listed apart for the batched queries (`root_list`).

mod collapse;
mod leaves;
mod node;
mod options;
mod root_list;
mod sah;

use prism_math::{Aabb, Vec3};
use rayon::prelude::*;

use crate::layout::node8::Node8;
use crate::layout::tri4::Tri4;
use crate::layout::{Bvh, LeafRec};
use crate::shapes::Sphere;
use node::{free, root_bounds, BuildNode, Summary};
pub use options::{BuildOptions, Split};
use options::{MAX_LEAF_REF, SMALL_SCENE};
use sah::{bounds_of, build_node, take_big, Box3A, PrimRef};

impl Bvh {
    /// Builds the hierarchy. Degenerate triangles (zero area or non-finite) and spheres with
    /// a non-positive or non-finite radius are left out: no ray hits them.
    #[must_use]
    pub fn build(triangles: &[[Vec3; 3]], spheres: &[Sphere], opts: &BuildOptions) -> Bvh {
        let nt = triangles.len();
        let tri_ref = |(i, t): (usize, &[Vec3; 3])| {
            let b = Aabb::point(t[0]).extend(t[1]).extend(t[2]);
            let area2 = (t[1] - t[0]).cross(t[2] - t[0]).length_squared();
            (area2 > 0.0 && b.min.is_finite() && b.max.is_finite()).then(|| PrimRef {
                bounds: Box3A::from_aabb(b),
                id: i as u32,
            })
        };
        let mut prims: Vec<PrimRef> = if nt > opts.parallel_threshold {
            // Written in place, in order, those left out marked and then dropped (a
            // filtered parallel collection gathers pieces and copies them again).
            let mut refs = Vec::with_capacity(nt);
            triangles
                .par_iter()
                .enumerate()
                .map(|t| tri_ref(t).unwrap_or(PrimRef::NONE))
                .collect_into_vec(&mut refs);
            refs.retain(|p| p.id != PrimRef::NONE.id);
            refs
        } else {
            triangles.iter().enumerate().filter_map(tri_ref).collect()
        };
        for (i, s) in spheres.iter().enumerate() {
            let b = s.bounds();
            if s.radius > 0.0 && b.min.is_finite() && b.max.is_finite() {
                prims.push(PrimRef {
                    bounds: Box3A::from_aabb(b),
                    id: (nt + i) as u32,
                });
            }
        }
        let root = if prims.is_empty() {
            None
        } else {
            // A few large primitives (a Cornell box) overlap so much that full packs cost more
            // than the leaves the nearest hit lets a ray skip; memory does not matter there.
            let max_leaf = if prims.len() <= SMALL_SCENE {
                opts.max_leaf.min(2)
            } else {
                opts.max_leaf
            };
            let opts = BuildOptions {
                max_leaf: max_leaf.clamp(1, MAX_LEAF_REF),
                ..*opts
            };
            let (b3, cb) = bounds_of(&prims, opts.parallel_threshold);
            // (Setting the large ones apart is a cost heuristic; a median tree has none.)
            let big = match opts.split {
                Split::Sah => take_big(&mut prims, b3, opts.parallel_threshold),
                Split::Median => 0,
            };
            if big == 0 {
                Some(build_node(&mut prims, 0, 0, &opts, b3, cb))
            } else {
                // The large primitives under one child of the root (leaves of two, which the
                // collapse lifts into the root when that saves node area, as their nodes'
                // large boxes usually make it), the others under the other.
                let (l, r) = prims.split_at_mut(big);
                let (lb, lc) = bounds_of(l, opts.parallel_threshold);
                let (rb, rc) = bounds_of(r, opts.parallel_threshold);
                let small_leaves = BuildOptions {
                    max_leaf: 2,
                    ..opts
                };
                let (a, sa) = build_node(l, 0, 1, &small_leaves, lb, lc);
                let (b, sb) = build_node(r, big, 1, &opts, rb, rc);
                let bounds = b3.to_aabb();
                Some((
                    BuildNode::interior(bounds, [a, b]),
                    Summary::interior(&bounds, opts.traversal_cost, sa, sb),
                ))
            }
        };
        let ids: Vec<u32> = if prims.len() > opts.parallel_threshold {
            prims.par_iter().map(|p| p.id).collect()
        } else {
            prims.iter().map(|p| p.id).collect()
        };
        let mut bvh = Bvh {
            spheres: spheres.to_vec(),
            triangle_count: nt as u32,
            ..Bvh::default()
        };
        if let Some((root, summary)) = root {
            let bounds = root_bounds(&root);
            let root_area = bounds.surface_area().max(f32::MIN_POSITIVE);
            bvh.stats.leaves = summary.leaves;
            bvh.stats.depth = summary.depth;
            bvh.stats.max_leaf_size = summary.max_leaf;
            bvh.stats.sah_cost = (summary.sah / f64::from(root_area)) as f32;
            // About one 8-wide node per seven leaves.
            bvh.nodes.reserve(bvh.stats.leaves / 7 + 1);
            bvh.bounds = bounds;
            let mut jobs = Vec::with_capacity(summary.leaves);
            // A lone leaf still sits under a node.
            bvh.collapse(&root, &ids, &mut jobs);
            bvh.pack_leaves(&jobs, triangles, &ids, opts.parallel_threshold);
            free(root, 0);
        }
        bvh.root_list = bvh.root_list(triangles, spheres);
        bvh.stats.primitives = ids.len();
        bvh.stats.nodes = bvh.nodes.len();
        bvh.stats.bytes = bvh.nodes.len() * std::mem::size_of::<Node8>()
            + bvh.packs.len() * std::mem::size_of::<Tri4>()
            + bvh.leaves.len() * std::mem::size_of::<LeafRec>()
            + bvh.leaf_spheres.len() * 4
            + bvh.spheres.len() * std::mem::size_of::<Sphere>()
            + bvh.root_list.as_ref().map_or(0, |f| {
                f.triangles.len() * std::mem::size_of::<([Vec3; 3], u32)>()
                    + f.spheres.len() * std::mem::size_of::<(Sphere, u32)>()
            });
        bvh
    }
}
