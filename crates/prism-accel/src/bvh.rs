//! [`Bvh`], the bounding volume hierarchy over triangles and spheres: binned-SAH build,
//! collapse into 8-wide nodes, statistics, and closest-hit and occlusion traversal.

use std::mem::MaybeUninit;

use prism_math::glam::Vec3A;
use prism_math::{prefetch, Aabb, Isa, Ray, Vec3};
use rayon::prelude::*;

use crate::flat::{Flat, Lanes, FLAT_MAX};
use crate::node8::{self, widen, Node8, SlabRay};
use crate::order::Pending;
#[cfg(target_arch = "x86_64")]
use crate::packet::Query;
use crate::shapes::{intersect_sphere, Limit, RayPre, Sphere};
#[cfg(target_arch = "x86_64")]
use crate::simd::{Avx2, Avx512, Simd};
use crate::tri4::{EdgeOnZero, Tri4};

/// A leaf: `packs` triangle packs from `pack_start`, `spheres` spheres from `sphere_start`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LeafRec {
    pub(crate) pack_start: u32,
    pub(crate) sphere_start: u32,
    pub(crate) packs: u16,
    pub(crate) spheres: u16,
}

/// Build parameters.
#[derive(Clone, Copy, Debug)]
pub struct BuildOptions {
    /// Leaf size: every subtree of at most this many primitives is one leaf (larger
    /// leaves are forced only when primitives cannot be separated); at most two for
    /// hierarchies over 64 primitives or fewer.
    pub max_leaf: usize,
    /// Cost of a traversal step relative to one primitive test, for the reported SAH cost.
    pub traversal_cost: f32,
    /// Subtrees with more primitives than this are built in parallel.
    pub parallel_threshold: usize,
}

impl Default for BuildOptions {
    fn default() -> BuildOptions {
        BuildOptions {
            // Four packs, the most a leaf reference holds. Split further, a subtree of
            // sixteen takes more slots or a node of the 8-wide tree to save at most two pack
            // tests, which with AVX are one test of eight lanes: on the 56k-triangle bunny,
            // leaves of sixteen rather than twelve make the tree about 30% smaller and the
            // build 7-12% faster, and trace as fast or faster.
            max_leaf: MAX_LEAF_REF,
            // One 8-wide node test replaces about three binary ones and costs about one
            // triangle pack test.
            traversal_cost: 0.5,
            parallel_threshold: 4096,
        }
    }
}

/// The closest (or any) hit along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// The primitive: triangles are numbered first, then spheres.
    pub prim: u32,
    /// Barycentric weight of the triangle's second vertex (0 for spheres).
    pub b1: f32,
    /// Barycentric weight of the triangle's third vertex (0 for spheres).
    pub b2: f32,
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
const PACKS_SHIFT: u32 = 28;
const LOW_BITS: u32 = (1 << PACKS_SHIFT) - 1;
/// Hierarchies over at most this many primitives keep leaves of at most two (on the
/// course's Cornell box, 17% fewer instructions per sample than full packs).
const SMALL_SCENE: usize = 64;
/// Largest leaf the build makes, even when primitives cannot be separated.
const MAX_LEAF_REF: usize = 16;

/// A bounding volume hierarchy over triangles and spheres.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub(crate) nodes: Vec<Node8>,
    /// Triangles in packs of four, leaf by leaf.
    pub(crate) packs: Vec<Tri4>,
    /// Leaves: their packs, and their spheres in `leaf_spheres`.
    leaves: Vec<LeafRec>,
    /// Sphere primitive numbers, leaf by leaf.
    pub(crate) leaf_spheres: Vec<u32>,
    pub(crate) spheres: Vec<Sphere>,
    pub(crate) triangle_count: u32,
    bounds: Aabb,
    stats: BvhStats,
    /// For small hierarchies, the primitives in one list, for the batched queries.
    flat: Option<Flat>,
}

enum BuildNode {
    Leaf {
        bounds: Aabb,
        start: usize,
        count: usize,
    },
    Interior {
        bounds: Aabb,
        children: Box<[BuildNode; 2]>,
        /// `slots[j - 1]`: the least total area of the 8-wide nodes of the subtree held in
        /// at most `j` slots of the node above it ([`BuildNode::interior`]), in `f64`, which
        /// no sum of areas of finite `f32` boxes overflows.
        slots: [f64; 8],
    },
}

impl BuildNode {
    /// An interior node over `children`, its slot costs computed from theirs.
    ///
    /// The 8-wide tree keeps the binary tree's leaves, so collapses differ only in their
    /// nodes, which a random ray visits with a chance proportional to their surface area:
    /// the collapse minimises the nodes' total area. A subtree given `j` slots of the node
    /// above it takes one, as a node of its own (its area, plus its children's cost in
    /// that node's eight slots), or, for `j` of two or more, hands `k` and `j - k` down to
    /// its two children: its cost in `j` slots is the least of these (a dynamic programme,
    /// as in Ylitie, Karras and Laine, "Efficient Incoherent Ray Traversal on GPUs Through
    /// Compressed Wide BVHs", 2017). A leaf's is zero.
    fn interior(bounds: Aabb, children: [BuildNode; 2]) -> BuildNode {
        let (a, b) = (children[0].slots(), children[1].slots());
        let mut slots = [0f64; 8];
        for (j, slot) in slots.iter_mut().enumerate().skip(1) {
            *slot = split_cost(&a, &b, j + 1).0;
        }
        slots[0] = area64(&bounds) + slots[7];
        for j in 1..8 {
            slots[j] = slots[j].min(slots[j - 1]);
        }
        BuildNode::Interior {
            bounds,
            children: Box::new(children),
            slots,
        }
    }

    /// The subtree's cost in at most `j` slots at `j - 1`.
    fn slots(&self) -> [f64; 8] {
        match self {
            BuildNode::Leaf { .. } => [0.0; 8],
            BuildNode::Interior { slots, .. } => *slots,
        }
    }
}

/// The surface area of `b`, in `f64`.
fn area64(b: &Aabb) -> f64 {
    let e = (b.max - b.min).as_dvec3();
    2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
}

/// The least cost of two subtrees with slot costs `a` and `b` sharing `j` >= 2 slots, and
/// the slots the first takes (the fewest of equals).
fn split_cost(a: &[f64; 8], b: &[f64; 8], j: usize) -> (f64, usize) {
    let mut best = (f64::INFINITY, 1);
    for k in 1..j {
        let c = a[k - 1] + b[j - k - 1];
        if c < best.0 {
            best = (c, k);
        }
    }
    best
}

/// What the build learns of a subtree on its way back up, so that no pass over the binary
/// tree is needed for the statistics.
#[derive(Clone, Copy, Default)]
struct Summary {
    leaves: usize,
    /// Deepest leaf, counted from the root of the whole tree.
    depth: usize,
    max_leaf: usize,
    /// Sum over the subtree's nodes of surface area times cost (in primitive tests).
    sah: f64,
}

impl Summary {
    fn leaf(bounds: &Aabb, count: usize, depth: usize) -> Summary {
        Summary {
            leaves: 1,
            depth,
            max_leaf: count,
            sah: f64::from(bounds.surface_area()) * count as f64,
        }
    }

    /// An interior node over subtrees `a` and `b`.
    fn interior(bounds: &Aabb, traversal_cost: f32, a: Summary, b: Summary) -> Summary {
        Summary {
            leaves: a.leaves + b.leaves,
            depth: a.depth.max(b.depth),
            max_leaf: a.max_leaf.max(b.max_leaf),
            sah: f64::from(bounds.surface_area() * traversal_cost) + (a.sah + b.sah),
        }
    }
}

/// A leaf placed by the collapse, whose triangles are packed afterwards (in parallel): its
/// range in the build order and its first pack.
struct LeafJob {
    start: usize,
    count: usize,
    pack_start: usize,
    packs: usize,
}

/// A primitive while building: its box and number. The build moves these, not indices, so
/// each pass over a node reads memory in order.
#[derive(Clone, Copy)]
struct PrimRef {
    bounds: B3,
    id: u32,
}

impl PrimRef {
    /// A placeholder for a primitive left out (no primitive has its number).
    const NONE: PrimRef = PrimRef {
        bounds: B3::EMPTY,
        id: u32::MAX,
    };

    /// Twice the box centre: the split position, without a multiply.
    #[inline(always)]
    fn centroid2(&self) -> Vec3A {
        self.bounds.min + self.bounds.max
    }
}

/// A box in SIMD registers, for the build's many unions.
#[derive(Clone, Copy, Debug)]
struct B3 {
    min: Vec3A,
    max: Vec3A,
}

impl B3 {
    const EMPTY: B3 = B3 {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
    };

    fn from_aabb(b: Aabb) -> B3 {
        B3 {
            min: b.min.into(),
            max: b.max.into(),
        }
    }

    fn to_aabb(self) -> Aabb {
        Aabb {
            min: self.min.into(),
            max: self.max.into(),
        }
    }

    #[inline(always)]
    fn union(self, o: B3) -> B3 {
        B3 {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    #[inline(always)]
    fn grow(self, p: Vec3A) -> B3 {
        B3 {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    #[inline(always)]
    fn area(self) -> f32 {
        let e = (self.max - self.min).max(Vec3A::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

const BINS: usize = 16;

/// Depth after which splits are by median, so that no tree is deeper than this plus 32
/// and the traversal stacks below cannot overflow.
const MEDIAN_DEPTH: usize = 64;
pub(crate) const STACK: usize = 7 * (MEDIAN_DEPTH + 34) + 8;

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
                bounds: B3::from_aabb(b),
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
                    bounds: B3::from_aabb(b),
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
            let big = take_big(&mut prims, b3, opts.parallel_threshold);
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
        bvh.flat = bvh.root_list(triangles, spheres);
        bvh.stats.primitives = ids.len();
        bvh.stats.nodes = bvh.nodes.len();
        bvh.stats.bytes = bvh.nodes.len() * std::mem::size_of::<Node8>()
            + bvh.packs.len() * std::mem::size_of::<Tri4>()
            + bvh.leaves.len() * std::mem::size_of::<LeafRec>()
            + bvh.leaf_spheres.len() * 4
            + bvh.spheres.len() * std::mem::size_of::<Sphere>()
            + bvh.flat.as_ref().map_or(0, |f| {
                f.triangles.len() * std::mem::size_of::<([Vec3; 3], u32)>()
                    + f.spheres.len() * std::mem::size_of::<(Sphere, u32)>()
            });
        bvh
    }

    /// Flattens a binary node and its subtree into 8-wide nodes: the node's slots hold the
    /// descendants that give the least total node area ([`BuildNode::interior`]). Returns
    /// the node's index.
    fn collapse(&mut self, n: &BuildNode, order: &[u32], jobs: &mut Vec<LeafJob>) -> u32 {
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

    /// Places a leaf: its packs of four triangles (filled by [`Bvh::pack_leaves`]) and its
    /// spheres. Returns its reference.
    fn plan_leaf(&mut self, n: &BuildNode, order: &[u32], jobs: &mut Vec<LeafJob>) -> u32 {
        let BuildNode::Leaf { start, count, .. } = *n else {
            unreachable!("only leaves are stored as leaves")
        };
        let nt = self.triangle_count;
        let prims = &order[start..start + count];
        let nt_leaf = prims.iter().filter(|&&p| p < nt).count();
        let pack_start = jobs.last().map_or(0, |j| j.pack_start + j.packs);
        let rec = LeafRec {
            pack_start: pack_start as u32,
            sphere_start: self.leaf_spheres.len() as u32,
            packs: nt_leaf.div_ceil(4) as u16,
            spheres: (count - nt_leaf) as u16,
        };
        jobs.push(LeafJob {
            start,
            count,
            pack_start,
            packs: usize::from(rec.packs),
        });
        assert!(
            pack_start + usize::from(rec.packs) <= LOW_BITS as usize
                && self.leaves.len() < LOW_BITS as usize,
            "BVH over 2^30 triangles"
        );
        if rec.spheres == 0 && rec.packs < 8 {
            return LEAF | u32::from(rec.packs) << PACKS_SHIFT | rec.pack_start;
        }
        self.leaf_spheres
            .extend(prims.iter().copied().filter(|&p| p >= nt));
        self.leaves.push(rec);
        LEAF | (self.leaves.len() - 1) as u32
    }

    /// Fills the triangle packs of the leaves the collapse placed, in parallel for large
    /// hierarchies (each leaf writes only its own packs, so the result is the same).
    fn pack_leaves(
        &mut self,
        jobs: &[LeafJob],
        triangles: &[[Vec3; 3]],
        order: &[u32],
        parallel_threshold: usize,
    ) {
        let total = jobs.last().map_or(0, |j| j.pack_start + j.packs);
        // Each pack is written once, by its leaf's job (in parallel, so that the first
        // touch of the memory is shared too).
        let mut packs: Vec<Tri4> = Vec::with_capacity(total);
        let nt = self.triangle_count;
        let fill = |job: &LeafJob, out: &mut [MaybeUninit<Tri4>]| {
            let mut tris = [([Vec3::ZERO; 3], 0u32); MAX_LEAF_REF];
            // The build order visits triangles out of the mesh's order: start loading those
            // a few leaves ahead, so that the misses overlap.
            let ahead = (job.start + PACK_AHEAD).min(order.len());
            for &p in &order[ahead..(ahead + job.count).min(order.len())] {
                prefetch(triangles.as_ptr().wrapping_add(p as usize));
            }
            let mut n = 0;
            for &p in order[job.start..job.start + job.count]
                .iter()
                .filter(|&&p| p < nt)
            {
                tris[n] = (triangles[p as usize], p);
                n += 1;
            }
            assert_eq!(
                n.div_ceil(4),
                out.len(),
                "a leaf's packs hold its triangles"
            );
            for (pack, four) in out.iter_mut().zip(tris[..n].chunks(4)) {
                pack.write(Tri4::new(four));
            }
        };
        let mut rest = &mut packs.spare_capacity_mut()[..total];
        let mut outs = Vec::with_capacity(jobs.len());
        for job in jobs {
            let (out, tail) = std::mem::take(&mut rest).split_at_mut(job.packs);
            outs.push(out);
            rest = tail;
        }
        if order.len() > parallel_threshold {
            jobs.par_iter()
                .zip(outs)
                .with_min_len(256)
                .for_each(|(job, out)| fill(job, out));
        } else {
            for (job, out) in jobs.iter().zip(outs) {
                fill(job, out);
            }
        }
        // SAFETY: the jobs' ranges tile `0..total` (each starts where the last ended) and
        // each job wrote every pack of its range (asserted above).
        unsafe { packs.set_len(total) };
        self.packs = packs;
    }

    /// The primitives of the root's leaves in one list, with the boxes of the root's other
    /// children, if the root has between one and [`FLAT_MAX`] of them.
    fn root_list(&self, triangles: &[[Vec3; 3]], spheres: &[Sphere]) -> Option<Flat> {
        let root = self.nodes.first()?;
        let nt = self.triangle_count;
        let mut flat = Flat {
            first_sphere: nt,
            ..Flat::default()
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

    /// Entry distances of the ray into a node's eight child boxes, and which it enters: with
    /// `AVX`, by the fused test if `FUSED` (which the caller sets only for a
    /// [`SlabRay::fused`] ray), else by the unfused one.
    #[inline(always)]
    fn node_hit<const AVX: bool, const FUSED: bool>(
        n: &Node8,
        r: &SlabRay,
        tmin: f32,
        tmax: f32,
    ) -> ([f32; 8], u32) {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: `AVX` is true only in the traversals compiled for AVX2 and FMA, which
            // their callers enter after detecting them; `FUSED` only for a fused ray.
            return unsafe {
                if FUSED {
                    node8::hit_fused(n, r, tmin, tmax)
                } else {
                    node8::hit_avx(n, r, tmin, tmax)
                }
            };
        }
        node8::hit_sse(n, r, tmin, tmax)
    }

    /// The node of reference `r`, which is not a leaf reference, without a bounds check.
    #[inline(always)]
    fn node(&self, r: u32) -> &Node8 {
        debug_assert!((r as usize) < self.nodes.len());
        // SAFETY: the walks start at the root or at one of its children (`Start`), only
        // when there is a root, and follow child references: each is the index of a node
        // pushed before it was stored (`Bvh::collapse`), and nodes are never removed.
        unsafe { self.nodes.get_unchecked(r as usize) }
    }

    /// Starts loading a node, or a leaf's first three packs of triangles, into the cache.
    #[inline(always)]
    fn prefetch(&self, r: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let p: *const i8 = if r & LEAF == 0 {
                self.nodes.as_ptr().wrapping_add(r as usize).cast()
            } else if (r >> PACKS_SHIFT) & 7 != 0 {
                self.packs
                    .as_ptr()
                    .wrapping_add((r & LOW_BITS) as usize)
                    .cast()
            } else {
                return;
            };
            // SAFETY: prefetching is only a hint; it never faults, whatever the address.
            unsafe {
                _mm_prefetch::<_MM_HINT_T0>(p);
                _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64));
                _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(128));
                if r & LEAF != 0 && (r >> PACKS_SHIFT) & 6 != 0 {
                    // The second pack of a leaf of two or more, tested with the first.
                    _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(192));
                    _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(256));
                    _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(319));
                    if (r >> PACKS_SHIFT) & 7 >= 3 {
                        // The third pack, tested right after the first two.
                        _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(383));
                        _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(447));
                        _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(479));
                    }
                }
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

    /// Tests a leaf's primitives, moving `end` to each hit it admits (the first by distance,
    /// then primitive number, is kept); with `any`, stops at the first. With `AVX`, its
    /// packs are tested two at a time ([`Tri4::intersect_pair_avx`]), which finds the same
    /// hits.
    #[inline(always)]
    fn leaf<const AVX: bool>(
        &self,
        r: u32,
        pre: &RayPre,
        ray: &Ray,
        tmin: f32,
        end: &mut Limit,
        any: bool,
    ) -> Option<Hit> {
        let rec = self.leaf_rec(r);
        let weights = self
            .leaf_packs::<AVX, false, false>(&rec, pre, tmin, end, any)
            .unwrap_or_else(|SlowLeaf| unreachable!("only the deferring test defers a leaf"));
        if rec.spheres != 0 && !(any && weights.is_some()) {
            if let Some(h) = self.leaf_spheres(&rec, ray, tmin, end, any) {
                return Some(h);
            }
        }
        weights.map(|(b1, b2)| Hit {
            t: end.t,
            prim: end.prim,
            b1,
            b2,
        })
    }

    /// [`Bvh::leaf`] without calling any function, so that a walk's loop around it keeps
    /// its per-ray values in registers (a call would clobber them): the leaf's packs by the
    /// lane tests alone. [`SlowLeaf`] if the leaf holds spheres or a lane test met an edge
    /// function of exactly zero; `end` is then as given, for [`Bvh::leaf`] to decide the
    /// leaf.
    #[inline(always)]
    fn leaf_fast<const AVX: bool, const WIDE: bool>(
        &self,
        r: u32,
        pre: &RayPre,
        tmin: f32,
        end: &mut Limit,
        any: bool,
    ) -> Result<Option<Hit>, SlowLeaf> {
        let rec = self.leaf_rec(r);
        if rec.spheres != 0 {
            return Err(SlowLeaf);
        }
        let weights = self.leaf_packs::<AVX, WIDE, true>(&rec, pre, tmin, end, any)?;
        Ok(weights.map(|(b1, b2)| Hit {
            t: end.t,
            prim: end.prim,
            b1,
            b2,
        }))
    }

    /// The triangle packs of leaf `rec`, as [`Bvh::leaf`] tests them: moves `end` to each
    /// hit it admits (with `any`, to the first), and returns the barycentric weights of the
    /// last (none: `end` is as given). With `DEFER`, by the lane tests alone, which call no
    /// function, and [`SlowLeaf`] with `end` as given if one meets an edge function of
    /// exactly zero; without, never [`SlowLeaf`]. With `WIDE` (walks compiled for
    /// AVX-512) and `DEFER`, a leaf of three or four packs is one test on sixteen lanes
    /// ([`Tri4::intersect_four_fast`]), which finds the same closest hit (and, with `any`,
    /// a hit if there is one).
    #[inline(always)]
    fn leaf_packs<const AVX: bool, const WIDE: bool, const DEFER: bool>(
        &self,
        rec: &LeafRec,
        pre: &RayPre,
        tmin: f32,
        end: &mut Limit,
        any: bool,
    ) -> Result<Option<(f32, f32)>, SlowLeaf> {
        let mut e = *end;
        let mut weights = None;
        let p0 = rec.pack_start as usize;
        let range = p0..p0 + rec.packs as usize;
        debug_assert!(range.end <= self.packs.len());
        // SAFETY: `rec` is the record of a leaf reference the tree holds: its packs were
        // placed by `Bvh::plan_leaf` and every placed pack is filled by
        // `Bvh::pack_leaves`; packs are never removed.
        let mut packs = unsafe { self.packs.get_unchecked(range) };
        #[cfg(target_arch = "x86_64")]
        if WIDE && DEFER && (3..=4).contains(&packs.len()) {
            // Four packs, or three with the third named again in the last lanes, which
            // `valid` leaves out: chosen without a branch, which would be mispredicted on
            // incoherent rays. (Leaves of more, which only primitives that cannot be
            // separated make, are tested by the loop below.)
            let n = packs.len();
            let four = [&packs[0], &packs[1], &packs[2], &packs[n - 1]];
            let valid = 0xffff >> (16 - 4 * n);
            // SAFETY: `WIDE` is true only in the walks compiled for AVX-512 (F, DQ and VL),
            // which their callers enter after detecting it.
            let found = unsafe { Tri4::intersect_four_fast(four, valid, pre, tmin, e) }
                .map_err(|EdgeOnZero| SlowLeaf)?;
            let Some((t, lane, b1, b2)) = found else {
                return Ok(None);
            };
            *end = Limit {
                t,
                prim: four[lane / 4].prim[lane % 4],
            };
            return Ok(Some((b1, b2)));
        }
        while let [a, rest @ ..] = packs {
            // The pack of lanes 4..8 (the first again when tested alone).
            let (found, second) = match rest {
                #[cfg(target_arch = "x86_64")]
                [b, tail @ ..] if AVX => {
                    packs = tail;
                    // SAFETY: `AVX` is true only in the traversals compiled for AVX, which
                    // their callers enter after detecting it.
                    let found = unsafe {
                        if DEFER {
                            Tri4::intersect_pair_fast(a, b, pre, tmin, e)
                        } else {
                            Ok(Tri4::intersect_pair_avx(a, b, pre, tmin, e))
                        }
                    };
                    (found, b)
                }
                _ => {
                    packs = rest;
                    let found = if DEFER {
                        a.intersect_fast(pre, tmin, e)
                    } else {
                        Ok(a.intersect(pre, tmin, e))
                    };
                    (found, a)
                }
            };
            let found = found.map_err(|EdgeOnZero| SlowLeaf)?;
            if let Some((t, lane, b1, b2)) = found {
                let pack = if lane < 4 { a } else { second };
                e = Limit {
                    t,
                    prim: pack.prim[lane % 4],
                };
                weights = Some((b1, b2));
                if any {
                    break;
                }
            }
        }
        *end = e;
        Ok(weights)
    }

    /// [`Bvh::leaf`], compiled apart and marked cold: the paired walks' test of a leaf
    /// [`Bvh::leaf_fast`] leaves to it. Inlined, the calls it makes would sit in their loop
    /// and clobber the registers it keeps (on the 56k-triangle bunny, random rays in
    /// batches trace 5% faster by `leaf_fast` and this than by `leaf` inlined).
    #[inline(never)]
    #[cold]
    fn leaf_apart<const AVX: bool>(
        &self,
        r: u32,
        pre: &RayPre,
        ray: &Ray,
        tmin: f32,
        end: &mut Limit,
        any: bool,
    ) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: `AVX` is true only in the walks compiled for AVX2 and FMA (or
            // AVX-512, which has them), which their callers enter after detecting them.
            return unsafe { self.leaf_apart_avx2(r, pre, ray, tmin, end, any) };
        }
        self.leaf::<false>(r, pre, ray, tmin, end, any)
    }

    /// [`Bvh::leaf_apart`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline(never)]
    #[cold]
    unsafe fn leaf_apart_avx2(
        &self,
        r: u32,
        pre: &RayPre,
        ray: &Ray,
        tmin: f32,
        end: &mut Limit,
        any: bool,
    ) -> Option<Hit> {
        self.leaf::<true>(r, pre, ray, tmin, end, any)
    }

    /// [`Bvh::leaf`]'s test of a leaf's spheres: the first hit `end` admits, moving `end` to
    /// it (with `any`, the first hit). Never inlined: inlined, its per-ray values would be
    /// computed at the start of every walk, spheres or not.
    #[inline(never)]
    fn leaf_spheres(
        &self,
        rec: &LeafRec,
        ray: &Ray,
        tmin: f32,
        end: &mut Limit,
        any: bool,
    ) -> Option<Hit> {
        let mut best = None;
        let s0 = rec.sphere_start as usize;
        for &p in &self.leaf_spheres[s0..s0 + rec.spheres as usize] {
            let s = &self.spheres[(p - self.triangle_count) as usize];
            // Hits up to `end.t` itself, which `end` then judges.
            let found = intersect_sphere(ray, s, tmin, end.t.next_up());
            if let Some(t) = found.filter(|&t| end.admits(t, p)) {
                *end = Limit { t, prim: p };
                best = Some(Hit {
                    t,
                    prim: p,
                    b1: 0.0,
                    b2: 0.0,
                });
                if any {
                    return best;
                }
            }
        }
        best
    }

    /// The closest hit with `tmin < t < tmax`; of primitives at one distance, the one with the
    /// lowest number (so the hit does not depend on the hierarchy's shape).
    #[must_use]
    pub fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        #[cfg(target_arch = "x86_64")]
        {
            if Isa::avx512() {
                // SAFETY: the processor has AVX-512VL.
                return unsafe { self.intersect_avx512(ray, tmin, tmax) };
            }
            if Isa::avx2() {
                // SAFETY: the processor has AVX2 and FMA.
                return unsafe { self.intersect_avx(ray, tmin, tmax) };
            }
        }
        self.intersect_sse(ray, tmin, tmax)
    }

    /// [`Bvh::intersect`] without AVX. Never inlined: inlined, its walk's frame (a traversal
    /// stack of kilobytes) would be set up at every call, whichever walk the call takes.
    #[inline(never)]
    fn intersect_sse(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        self.intersect_with::<false, false>(ray, tmin, tmax, Start::ROOT)
    }

    /// [`Bvh::intersect`] compiled for AVX-512VL: the same 256-bit operations, with twice
    /// the registers, and leaves of three or four packs tested on sixteen lanes
    /// (`leaf_packs`' `WIDE`).
    ///
    /// # Safety
    /// The processor must support AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512vl")]
    unsafe fn intersect_avx512(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        self.intersect_with::<true, true>(ray, tmin, tmax, Start::ROOT)
    }

    /// [`Bvh::intersect`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn intersect_avx(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        self.intersect_with::<true, false>(ray, tmin, tmax, Start::ROOT)
    }

    /// The closest hit with `tmin < t < tmax` (the lowest primitive number of equals), in the
    /// part of the tree `start` names.
    #[inline(always)]
    fn intersect_with<const AVX: bool, const WIDE: bool>(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        start: Start,
    ) -> Option<Hit> {
        let (pre, slab) = set_up::<AVX>(ray);
        // One loop per node test, so that each keeps only its own per-ray values live.
        if AVX && slab.fused() {
            self.walk_one::<AVX, WIDE, true>(ray, (&pre, &slab), tmin, tmax, start)
        } else {
            self.walk_one::<AVX, WIDE, false>(ray, (&pre, &slab), tmin, tmax, start)
        }
    }

    /// [`Bvh::intersect_with`]'s walk with node test `node_hit::<AVX, FUSED>`.
    #[inline(always)]
    fn walk_one<const AVX: bool, const WIDE: bool, const FUSED: bool>(
        &self,
        ray: &Ray,
        (pre, slab): (&RayPre, &SlabRay),
        tmin: f32,
        tmax: f32,
        start: Start,
    ) -> Option<Hit> {
        // `Walk::step`'s walk, written as one loop over local variables, so that its state
        // stays in registers (a `Walk`, stepped from outside, lives in memory).
        let (mut end, mut reach, mut best) = (Limit::end(tmax), widen(tmax), None);
        let mut stack = Stack::new();
        let mut sp = 0;
        let mut node_ref = start.node;
        loop {
            // The walk up to a leaf that needs `Bvh::leaf`, which calls functions: tested
            // after this loop, so that no call clobbers the registers it keeps.
            let slow = loop {
                if node_ref & LEAF != 0 {
                    match self.leaf_fast::<AVX, WIDE>(node_ref, pre, tmin, &mut end, false) {
                        Ok(Some(h)) => {
                            best = Some(h);
                            reach = widen(end.t);
                        }
                        Ok(None) => {}
                        Err(SlowLeaf) => break node_ref,
                    }
                } else {
                    let n = self.node(node_ref);
                    let (near, mut mask) = Bvh::node_hit::<AVX, FUSED>(n, slab, tmin, reach);
                    if node_ref == 0 {
                        mask &= !start.skip;
                    }
                    if mask != 0 && mask & mask.wrapping_sub(1) == 0 {
                        // One child entered: go on to it without the stack (its loads follow
                        // at once, so it is not prefetched).
                        node_ref = n.child[mask.trailing_zeros() as usize];
                        continue;
                    }
                    if mask != 0 {
                        node_ref = self.descend::<true, AVX>(n, &near, mask, &mut stack, &mut sp);
                        continue;
                    }
                }
                match pop(&stack, &mut sp, reach) {
                    Some(next) => node_ref = next,
                    None => return best,
                }
            };
            // A copy of the end for the full test, which takes it by reference: the end
            // itself is never borrowed past the call-free test, so it stays in registers.
            let mut e = end;
            if let Some(h) = self.leaf::<AVX>(slow, pre, ray, tmin, &mut e, false) {
                best = Some(h);
                reach = widen(e.t);
            }
            end = e;
            match pop(&stack, &mut sp, reach) {
                Some(next) => node_ref = next,
                None => return best,
            }
        }
    }

    /// Orders the children of `n` entered (`mask`, not empty) by their entries `near`,
    /// nearest first (the lower slot first of equals), pushes all but the nearest onto
    /// `stack` at `*sp`, farthest first, and returns the nearest. Any order finds the same
    /// hit (see [`widen`]); the two kinds of walk order children in the ways that are
    /// fastest for their rays (in-process A/B on the 56k-triangle bunny, 5 passes):
    /// - `LONE`, a lone walk ([`Bvh::intersect_with`]), whose rays are mostly coherent
    ///   and its branches predicted: two children by a branch (primary rays 3.5% faster
    ///   than by selects), three by three branches (primary rays 1.2% faster, random
    ///   rays 0.7%, than one by one), more one by one (a sorting network made them 2.2%
    ///   slower); the next child on the stack is prefetched (random rays 3.7% faster,
    ///   primary rays 1.9% slower than without).
    /// - Else the paired walks of batches ([`Bvh::walk_pairs`]), whose rays are
    ///   incoherent: one or two children are told apart and ordered by selects (one is
    ///   pushed and popped again at once: `*sp` does not move); more, with `AVX` (walks
    ///   compiled for AVX2), by a sorting network without branches
    ///   ([`crate::order::sort_entered_avx2`], which orders entries less than 8 ulps
    ///   apart by slot; random rays 3.3% faster), else one by one. Nothing is
    ///   prefetched: these walks overlap their misses already, and render 2-7% faster
    ///   without.
    #[inline(always)]
    fn descend<const LONE: bool, const AVX: bool>(
        &self,
        n: &Node8,
        near: &[f32; 8],
        mut mask: u32,
        stack: &mut Stack<Pending>,
        sp: &mut usize,
    ) -> u32 {
        // The entered children but the lowest slot's: none when one is entered. (Bit
        // tricks rather than a count: the walks are compiled without `popcnt`.)
        let rest = mask & mask.wrapping_sub(1);
        if rest & rest.wrapping_sub(1) == 0 {
            // Push the farther (when there are two) and go on to the nearer, as the sort
            // below orders them.
            let first = mask.trailing_zeros() as usize;
            let last = 31 - mask.leading_zeros() as usize;
            if LONE {
                debug_assert!(rest != 0, "a lone walk goes on to a lone child itself");
                let (a, b) = (n.child[first], n.child[last]);
                let (ta, tb) = (near[first], near[last]);
                // Each arm pushes and returns, so that this stays a branch.
                if tb < ta {
                    stack.push(
                        *sp,
                        Pending {
                            node: a,
                            t_near: ta,
                        },
                    );
                    *sp += 1;
                    self.prefetch(a);
                    return b;
                }
                stack.push(
                    *sp,
                    Pending {
                        node: b,
                        t_near: tb,
                    },
                );
                *sp += 1;
                self.prefetch(b);
                return a;
            }
            let swap = near[last] < near[first];
            let (a, b) = if swap { (last, first) } else { (first, last) };
            stack.push(
                *sp,
                Pending {
                    node: n.child[b],
                    t_near: near[b],
                },
            );
            *sp += usize::from(rest != 0);
            return n.child[a];
        }
        #[cfg(target_arch = "x86_64")]
        if AVX && !LONE {
            // SAFETY: `AVX` is true only in the walks compiled for AVX2, which their callers
            // enter after detecting it; three or more children are entered, none with a
            // NaN entry (the node tests enter no such child).
            let (nearest, pushed) =
                unsafe { crate::order::sort_entered_avx2(near, &n.child, mask, stack.eight(*sp)) };
            *sp += pushed;
            return nearest;
        }
        // The entered children but the two lowest slots'.
        let rest2 = rest & rest.wrapping_sub(1);
        if LONE && rest2 & rest2.wrapping_sub(1) == 0 {
            // Three children, the most common case past two: sorted by three predicted
            // branches, in the order of the sort below (strict comparisons keep the lower
            // slot first of equals).
            let at = |m: u32| {
                let i = m.trailing_zeros() as usize;
                Pending {
                    node: n.child[i],
                    t_near: near[i],
                }
            };
            let (mut a, mut b, mut c) = (at(mask), at(rest), at(rest2));
            if b.t_near < a.t_near {
                std::mem::swap(&mut a, &mut b);
            }
            if c.t_near < b.t_near {
                std::mem::swap(&mut b, &mut c);
                if b.t_near < a.t_near {
                    std::mem::swap(&mut a, &mut b);
                }
            }
            stack.push(*sp, c);
            stack.push(*sp + 1, b);
            *sp += 2;
            self.prefetch(b.node);
            return a.node;
        }
        let i = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        let mut hits = [(0u32, 0f32); 8];
        hits[0] = (n.child[i], near[i]);
        let mut count = 1;
        while mask != 0 {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let mut j = count;
            while j > 0 && hits[j - 1].1 > near[i] {
                hits[j] = hits[j - 1];
                j -= 1;
            }
            hits[j] = (n.child[i], near[i]);
            count += 1;
        }
        for k in (1..count).rev() {
            let (node, t_near) = hits[k];
            stack.push(*sp, Pending { node, t_near });
            *sp += 1;
        }
        if LONE {
            // The second nearest is likely visited next after the nearest's subtree.
            self.prefetch(hits[1].0);
        }
        hits[0].0
    }

    /// [`Bvh::intersect_with`] for each ray of `rays` over the whole tree, two rays walked
    /// at once ([`Bvh::walk_pairs`]).
    #[inline(always)]
    fn intersect_pairs<const AVX: bool, const WIDE: bool>(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.walk_pairs::<AVX, WIDE>(rays, tmin, (rays.len(), |k| (k, tmax, Start::ROOT)), hits);
    }

    /// Walks `jobs.0` closest-hit queries, `jobs.1(k)` giving query k's ray (an index into
    /// `rays`), its end and where its walk starts, and writes query k's hit to
    /// `hits[k]`. Two walks go on at once, a step of one then a step of the other: each
    /// step waits on memory (a node, a leaf's triangles) that the other's step is computed
    /// under. Each walk is the one [`Bvh::intersect_with`] takes (but for the order of
    /// children entered less than 8 ulps apart, see [`Bvh::descend`]), so the hits are the
    /// same; its children are chosen by selects (`Walk::step`) and sorted without branches
    /// on AVX2, as the rays of a batch are mostly incoherent.
    #[inline(always)]
    fn walk_pairs<const AVX: bool, const WIDE: bool>(
        &self,
        rays: &[Ray],
        tmin: f32,
        (n, job): (usize, impl Fn(usize) -> (usize, f32, Start)),
        hits: &mut [Option<Hit>],
    ) {
        if n < 2 {
            for (k, hit) in hits.iter_mut().enumerate().take(n) {
                let (i, tmax, start) = job(k);
                *hit = self.intersect_with::<AVX, WIDE>(&rays[i], tmin, tmax, start);
            }
            return;
        }
        let mut a = Slot::start::<AVX>(rays, &job, 0);
        let mut b = Slot::start::<AVX>(rays, &job, 1);
        let mut next = 2;
        let (walks, out) = ((rays, tmin, (n, &job)), hits);
        while self.pair_step::<AVX, WIDE>(walks, out, &mut a, &mut b, &mut next)
            && self.pair_step::<AVX, WIDE>(walks, out, &mut b, &mut a, &mut next)
        {}
    }

    /// A step of [`Bvh::walk_pairs`]' walk in slot `slot`. When its walk ends, its hit is
    /// stored and the slot takes query `next`; with no query left, the `other` slot's walk
    /// is finished, and the answer is false: all are done.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn pair_step<const AVX: bool, const WIDE: bool>(
        &self,
        (rays, tmin, (n, job)): (&[Ray], f32, (usize, &impl Fn(usize) -> (usize, f32, Start))),
        hits: &mut [Option<Hit>],
        slot: &mut Slot,
        other: &mut Slot,
        next: &mut usize,
    ) -> bool {
        if slot
            .walk
            .step::<AVX, WIDE>(self, &rays[slot.ray], tmin, slot.skip, &mut slot.stack)
        {
            return true;
        }
        hits[slot.query] = slot.walk.best;
        if *next == n {
            while other.walk.step::<AVX, WIDE>(
                self,
                &rays[other.ray],
                tmin,
                other.skip,
                &mut other.stack,
            ) {}
            hits[other.query] = other.walk.best;
            return false;
        }
        let (ray, tmax, start) = job(*next);
        slot.walk.reset::<AVX>(&rays[ray], tmax, start.node);
        (slot.ray, slot.skip, slot.query) = (ray, start.skip, *next);
        *next += 1;
        true
    }

    /// [`Bvh::intersect`] for each ray of `rays` (`hits[i]` for `rays[i]`), in one call:
    /// the same hits, with the per-call work done once for the whole batch.
    ///
    /// # Panics
    /// If `hits` is not as long as `rays`.
    pub fn intersect_batch(&self, rays: &[Ray], tmin: f32, tmax: f32, hits: &mut [Option<Hit>]) {
        self.intersect_batch_on(Isa::get(), rays, tmin, tmax, hits);
    }

    /// [`Bvh::intersect_batch`] on the code paths of instruction set `isa` (or of the
    /// processor, if it has less): the same hits on every level.
    ///
    /// # Panics
    /// If `hits` is not as long as `rays`.
    pub fn intersect_batch_on(
        &self,
        isa: Isa,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        assert_eq!(rays.len(), hits.len());
        if self.nodes.is_empty() {
            hits.fill(None);
            return;
        }
        let isa = isa.min(Isa::get());
        #[cfg(target_arch = "x86_64")]
        {
            if isa >= Isa::Avx512 {
                if let Some(flat) = &self.flat {
                    // SAFETY: the processor has AVX-512VL, hence AVX-512F.
                    return unsafe { self.intersect_batch_flat(flat, rays, tmin, tmax, hits) };
                }
                // SAFETY: the processor has AVX-512VL.
                return unsafe { self.intersect_batch_avx512(rays, tmin, tmax, hits) };
            }
            if isa >= Isa::Avx2 {
                if let Some(flat) = &self.flat {
                    // SAFETY: the processor has AVX2 and FMA.
                    return unsafe { self.intersect_batch_flat8(flat, rays, tmin, tmax, hits) };
                }
                // SAFETY: the processor has AVX2 and FMA.
                return unsafe { self.intersect_batch_avx2(rays, tmin, tmax, hits) };
            }
        }
        // Older processors: ray by ray.
        let _ = isa;
        for (ray, hit) in rays.iter().zip(hits) {
            *hit = self.intersect(ray, tmin, tmax);
        }
    }

    /// The loop of [`Bvh::intersect_batch`], inlined into each compiled variant: each group
    /// of `width` coherent rays (`packet::coherent`) takes the packet walk (`packet`, which
    /// returns the lanes it leaves to the one-ray walk); the rays between are walked in
    /// pairs.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_batch_with<const WIDE: bool>(
        &self,
        rays: &[Ray],
        (tmin, tmax): (f32, f32),
        hits: &mut [Option<Hit>],
        width: usize,
        packet: impl Fn(&Query, &mut [Option<Hit>]) -> u16,
    ) {
        // The first ray not yet walked.
        let mut loose = 0;
        let mut i = 0;
        while i + width <= rays.len() {
            let group = &rays[i..i + width];
            if crate::packet::coherent(group, width) {
                self.intersect_pairs::<true, WIDE>(
                    &rays[loose..i],
                    tmin,
                    tmax,
                    &mut hits[loose..i],
                );
                let query = Query {
                    rays: group,
                    tmin,
                    ends: [tmax; 16],
                    lanes: u16::MAX,
                    skip: 0,
                };
                let mut defer = packet(&query, &mut hits[i..i + width]);
                while defer != 0 {
                    let lane = defer.trailing_zeros() as usize;
                    defer &= defer - 1;
                    hits[i + lane] =
                        self.intersect_with::<true, WIDE>(&group[lane], tmin, tmax, Start::ROOT);
                }
                loose = i + width;
            }
            i += width;
        }
        self.intersect_pairs::<true, WIDE>(&rays[loose..], tmin, tmax, &mut hits[loose..]);
    }

    /// [`Bvh::intersect_batch`] through the root's list ([`Flat`]): `width` rays at a time
    /// against the list on lanes (`closest`), then the rest of the tree for the rays that
    /// enter it: as a packet (`packet`) when the group is coherent and a quarter of its
    /// rays or more enter, else ray by ray. Inlined into each compiled variant.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_batch_list<const WIDE: bool>(
        &self,
        rays: &[Ray],
        (tmin, tmax): (f32, f32),
        hits: &mut [Option<Hit>],
        (flat, width): (&Flat, usize),
        closest: impl Fn(&[Ray], &mut [Option<Hit>]) -> Lanes,
        packet: impl Fn(&Query, &mut [Option<Hit>]) -> u16,
    ) {
        // The tree walks still to make, over the whole batch: each ray, its end, where its
        // walk starts, and whether it is over the whole tree.
        let mut jobs: Vec<(usize, f32, Start)> = vec![];
        let mut whole: Vec<bool> = vec![];
        let groups = rays.chunks(width).zip(hits.chunks_mut(width));
        for (g, (rays, hits)) in groups.enumerate() {
            let lanes = closest(rays, hits);
            let tree = lanes.need & !lanes.defer;
            if 2 * tree.count_ones() as usize >= width && crate::packet::coherent(rays, width) {
                self.list_packet::<WIDE>(rays, (tmin, tmax), hits, (flat, lanes), &packet);
                continue;
            }
            // The list's hits stand, but in the lanes that must consult the tree.
            let mut rest = u32::from(lanes.defer | lanes.need) & ((1 << rays.len()) - 1);
            while rest != 0 {
                let lane = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                let all = lanes.defer & (1 << lane) != 0;
                // The rest of the tree, for a hit no farther than the list's.
                let end = hits[lane].map_or(tmax, |h| h.t.next_up());
                jobs.push(if all {
                    (g * width + lane, tmax, Start::ROOT)
                } else {
                    (g * width + lane, end, flat.start(lanes.inner[lane]))
                });
                whole.push(all);
            }
        }
        let mut found = vec![None; jobs.len()];
        self.walk_pairs::<true, WIDE>(rays, tmin, (jobs.len(), |k| jobs[k]), &mut found);
        for ((&(i, ..), all), h) in jobs.iter().zip(whole).zip(found) {
            hits[i] = match h {
                _ if all => h,
                // Two primitives at one distance: the walk over the whole tree decides, by
                // primitive number.
                Some(h) if hits[i].is_some_and(|n| n.t == h.t) => {
                    self.intersect_with::<true, WIDE>(&rays[i], tmin, tmax, Start::ROOT)
                }
                Some(h) => Some(h),
                None => hits[i],
            };
        }
    }

    /// The tree part of [`Bvh::intersect_batch_list`] for a coherent group, as a packet:
    /// the lanes that enter the rest of the tree walk it together, each up to just past
    /// its list hit; the lanes the list or the packet defers, and those where the tree and
    /// the list meet one distance, take the one-ray walk over the whole tree.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn list_packet<const WIDE: bool>(
        &self,
        rays: &[Ray],
        (tmin, tmax): (f32, f32),
        hits: &mut [Option<Hit>],
        (flat, lanes): (&Flat, Lanes),
        packet: &impl Fn(&Query, &mut [Option<Hit>]) -> u16,
    ) {
        let tree = lanes.need & !lanes.defer;
        let mut list = [None; 16];
        list[..hits.len()].copy_from_slice(hits);
        let mut ends = [tmax; 16];
        for (end, hit) in ends.iter_mut().zip(&list) {
            *end = hit.map_or(tmax, |h| h.t.next_up());
        }
        let query = Query {
            rays,
            tmin,
            ends,
            lanes: tree,
            skip: flat.skip,
        };
        let mut found = [None; 16];
        let deferred = packet(&query, &mut found[..hits.len()]);
        for (lane, hit) in hits.iter_mut().enumerate() {
            let bit = 1 << lane;
            let whole = lanes.defer & bit != 0
                || deferred & bit != 0
                || (tree & bit != 0
                    && found[lane].is_some_and(|h| list[lane].is_some_and(|n| n.t == h.t)));
            if whole {
                *hit = self.intersect_with::<true, WIDE>(&rays[lane], tmin, tmax, Start::ROOT);
            } else if tree & bit != 0 && found[lane].is_some() {
                *hit = found[lane];
            }
        }
    }

    /// [`Bvh::intersect_batch_list`] on sixteen lanes of AVX-512.
    ///
    /// # Safety
    /// The processor must support AVX-512F and AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn intersect_batch_flat(
        &self,
        flat: &Flat,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.intersect_batch_list::<true>(
            rays,
            (tmin, tmax),
            hits,
            (flat, Avx512::W),
            // SAFETY (both): the processor has AVX-512F.
            |r, h| unsafe { crate::flat::closest_avx512(flat, r, (tmin, tmax), h) },
            |q, h| unsafe { crate::packet::closest_avx512(self, q, h) },
        );
    }

    /// [`Bvh::intersect_batch_list`] on eight lanes of AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn intersect_batch_flat8(
        &self,
        flat: &Flat,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.intersect_batch_list::<false>(
            rays,
            (tmin, tmax),
            hits,
            (flat, Avx2::W),
            // SAFETY (both): the processor has AVX2.
            |r, h| unsafe { crate::flat::closest_avx2(flat, r, (tmin, tmax), h) },
            |q, h| unsafe { crate::packet::closest_avx2(self, q, h) },
        );
    }

    /// [`Bvh::occluded_batch`] through the root's list, as [`Bvh::intersect_batch_list`].
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn occluded_batch_list<const WIDE: bool>(
        &self,
        rays: &[Ray],
        (tmin, tmax): (f32, &[f32]),
        blocked: &mut [bool],
        (flat, width): (&Flat, usize),
        occluded: impl Fn(&[Ray], &[f32]) -> Lanes,
    ) {
        let groups = rays.chunks(width).zip(tmax.chunks(width));
        for ((rays, ends), blocked) in groups.zip(blocked.chunks_mut(width)) {
            let lanes = occluded(rays, ends);
            for (lane, b) in blocked.iter_mut().enumerate() {
                let bit = 1 << lane;
                let (ray, end) = (&rays[lane], ends[lane]);
                *b = if lanes.blocked & bit != 0 {
                    true
                } else if lanes.defer & bit != 0 {
                    self.occluded_with::<true, WIDE>(ray, tmin, end, Start::ROOT)
                } else if lanes.need & bit != 0 {
                    self.occluded_with::<true, WIDE>(ray, tmin, end, flat.start(lanes.inner[lane]))
                } else {
                    false
                };
            }
        }
    }

    /// [`Bvh::occluded_batch_list`] on sixteen lanes of AVX-512.
    ///
    /// # Safety
    /// The processor must support AVX-512F and AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn occluded_batch_flat(
        &self,
        flat: &Flat,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        self.occluded_batch_list::<true>(rays, (tmin, tmax), blocked, (flat, Avx512::W), |r, e| {
            // SAFETY: the processor has AVX-512F.
            unsafe { crate::flat::occluded_avx512(flat, r, tmin, e) }
        });
    }

    /// [`Bvh::occluded_batch_list`] on eight lanes of AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn occluded_batch_flat8(
        &self,
        flat: &Flat,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        self.occluded_batch_list::<false>(rays, (tmin, tmax), blocked, (flat, Avx2::W), |r, e| {
            // SAFETY: the processor has AVX2.
            unsafe { crate::flat::occluded_avx2(flat, r, tmin, e) }
        });
    }

    /// [`Bvh::intersect_batch`] compiled for AVX-512VL: the same 256-bit operations, with
    /// one-instruction broadcasts and twice the registers, and leaves of three or four packs
    /// tested on sixteen lanes.
    ///
    /// # Safety
    /// The processor must support AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512vl")]
    unsafe fn intersect_batch_avx512(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.intersect_batch_with::<true>(rays, (tmin, tmax), hits, Avx512::W, |q, h| {
            // SAFETY: the processor has AVX-512VL, hence AVX-512F.
            unsafe { crate::packet::closest_avx512(self, q, h) }
        });
    }

    /// [`Bvh::intersect_batch`] compiled for AVX2 (one-instruction broadcasts).
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn intersect_batch_avx2(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.intersect_batch_with::<false>(rays, (tmin, tmax), hits, Avx2::W, |q, h| {
            // SAFETY: the processor has AVX2.
            unsafe { crate::packet::closest_avx2(self, q, h) }
        });
    }

    /// [`Bvh::occluded`] for each ray of `rays` with its own end (`blocked[i]` for `rays[i]`
    /// and `tmax[i]`), in one call.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn occluded_batch(&self, rays: &[Ray], tmin: f32, tmax: &[f32], blocked: &mut [bool]) {
        self.occluded_batch_on(Isa::get(), rays, tmin, tmax, blocked);
    }

    /// [`Bvh::occluded_batch`] on the code paths of instruction set `isa` (or of the
    /// processor, if it has less): the same answers on every level.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn occluded_batch_on(
        &self,
        isa: Isa,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        assert!(rays.len() == tmax.len() && rays.len() == blocked.len());
        if self.nodes.is_empty() {
            blocked.fill(false);
            return;
        }
        let isa = isa.min(Isa::get());
        #[cfg(target_arch = "x86_64")]
        {
            if isa >= Isa::Avx512 {
                if let Some(flat) = &self.flat {
                    // SAFETY: the processor has AVX-512VL, hence AVX-512F.
                    return unsafe { self.occluded_batch_flat(flat, rays, tmin, tmax, blocked) };
                }
                // SAFETY: the processor has AVX-512VL.
                return unsafe { self.occluded_batch_avx512(rays, tmin, tmax, blocked) };
            }
            if isa >= Isa::Avx2 {
                if let Some(flat) = &self.flat {
                    // SAFETY: the processor has AVX2 and FMA.
                    return unsafe { self.occluded_batch_flat8(flat, rays, tmin, tmax, blocked) };
                }
                // SAFETY: the processor has AVX2 and FMA.
                return unsafe { self.occluded_batch_avx2(rays, tmin, tmax, blocked) };
            }
        }
        // Older processors: ray by ray.
        let _ = isa;
        for ((ray, &t), b) in rays.iter().zip(tmax).zip(blocked) {
            *b = self.occluded(ray, tmin, t);
        }
    }

    /// The loop of [`Bvh::occluded_batch`], inlined into each compiled variant.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn occluded_batch_with<const WIDE: bool>(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        for ((ray, &t), b) in rays.iter().zip(tmax).zip(blocked) {
            *b = self.occluded_with::<true, WIDE>(ray, tmin, t, Start::ROOT);
        }
    }

    /// [`Bvh::occluded_batch`] compiled for AVX-512VL (leaves of three or four packs on
    /// sixteen lanes).
    ///
    /// # Safety
    /// The processor must support AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512vl")]
    unsafe fn occluded_batch_avx512(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        self.occluded_batch_with::<true>(rays, tmin, tmax, blocked);
    }

    /// [`Bvh::occluded_batch`] compiled for AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn occluded_batch_avx2(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        self.occluded_batch_with::<false>(rays, tmin, tmax, blocked);
    }

    /// True if anything lies along the ray with `tmin < t < tmax` (for shadow rays).
    #[must_use]
    pub fn occluded(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        #[cfg(target_arch = "x86_64")]
        {
            if Isa::avx512() {
                // SAFETY: the processor has AVX-512VL.
                return unsafe { self.occluded_avx512(ray, tmin, tmax) };
            }
            if Isa::avx2() {
                // SAFETY: the processor has AVX2 and FMA.
                return unsafe { self.occluded_avx(ray, tmin, tmax) };
            }
        }
        self.occluded_sse(ray, tmin, tmax)
    }

    /// [`Bvh::occluded`] without AVX, never inlined (as [`Bvh::intersect_sse`]).
    #[inline(never)]
    fn occluded_sse(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        self.occluded_with::<false, false>(ray, tmin, tmax, Start::ROOT)
    }

    /// [`Bvh::occluded`] compiled for AVX-512VL (leaves of three or four packs on sixteen
    /// lanes).
    ///
    /// # Safety
    /// The processor must support AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512vl")]
    unsafe fn occluded_avx512(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        self.occluded_with::<true, true>(ray, tmin, tmax, Start::ROOT)
    }

    /// [`Bvh::occluded`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn occluded_avx(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        self.occluded_with::<true, false>(ray, tmin, tmax, Start::ROOT)
    }

    /// True if anything lies along the ray with `tmin < t < tmax`, in the part of the tree
    /// `start` names.
    #[inline(always)]
    fn occluded_with<const AVX: bool, const WIDE: bool>(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        start: Start,
    ) -> bool {
        let (r, slab) = set_up::<AVX>(ray);
        if AVX && slab.fused() {
            self.occluded_one::<AVX, WIDE, true>(ray, (&r, &slab), tmin, tmax, start)
        } else {
            self.occluded_one::<AVX, WIDE, false>(ray, (&r, &slab), tmin, tmax, start)
        }
    }

    /// [`Bvh::occluded_with`]'s walk with node test `node_hit::<AVX, FUSED>`.
    #[inline(always)]
    fn occluded_one<const AVX: bool, const WIDE: bool, const FUSED: bool>(
        &self,
        ray: &Ray,
        (r, slab): (&RayPre, &SlabRay),
        tmin: f32,
        tmax: f32,
        start: Start,
    ) -> bool {
        let mut stack = Stack::<u32>::new();
        let mut sp = 0usize;
        let mut node_ref = start.node;
        loop {
            // The walk up to a leaf that needs `Bvh::leaf`, tested after this loop (as in
            // `Bvh::walk_one`).
            let slow = loop {
                if node_ref & LEAF != 0 {
                    match self.leaf_fast::<AVX, WIDE>(
                        node_ref,
                        r,
                        tmin,
                        &mut Limit::end(tmax),
                        true,
                    ) {
                        Ok(Some(_)) => return true,
                        Ok(None) => {}
                        Err(SlowLeaf) => break node_ref,
                    }
                } else {
                    let n = self.node(node_ref);
                    let (_, mut mask) = Self::node_hit::<AVX, FUSED>(n, slab, tmin, tmax);
                    if node_ref == 0 {
                        mask &= !start.skip;
                    }
                    if mask != 0 {
                        // No prefetch of the next child on the stack: shadow rays come in
                        // batches, whose walks render faster without it.
                        let i = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        while mask != 0 {
                            let k = mask.trailing_zeros() as usize;
                            mask &= mask - 1;
                            stack.push(sp, n.child[k]);
                            sp += 1;
                        }
                        node_ref = n.child[i];
                        continue;
                    }
                }
                if sp == 0 {
                    return false;
                }
                sp -= 1;
                node_ref = stack.get(sp);
            };
            let mut end = Limit::end(tmax);
            if self
                .leaf::<AVX>(slow, r, ray, tmin, &mut end, true)
                .is_some()
            {
                return true;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node_ref = stack.get(sp);
        }
    }
}

/// A leaf that [`Bvh::leaf_fast`] leaves to [`Bvh::leaf`].
struct SlowLeaf;

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

/// A traversal stack that is not cleared before use (clearing a few kilobytes per ray
/// costs more than a small BVH's whole traversal). Entries are written before they are read:
/// `get(i)` is only called for `i` below the highest index pushed.
struct Stack<T: Copy> {
    items: [std::mem::MaybeUninit<T>; STACK],
}

impl<T: Copy> Stack<T> {
    #[inline(always)]
    fn new() -> Stack<T> {
        Stack {
            items: [const { std::mem::MaybeUninit::uninit() }; STACK],
        }
    }

    #[inline(always)]
    fn push(&mut self, i: usize, v: T) {
        self.items[i] = std::mem::MaybeUninit::new(v);
    }

    /// Slots `i..i + 8`, to be written at once. A walk's stack holds at most seven
    /// children per level above the node it is at, so past the deepest node's pushes it
    /// has room for these eight ([`STACK`]).
    #[inline(always)]
    fn eight(&mut self, i: usize) -> &mut [std::mem::MaybeUninit<T>; 8] {
        (&mut self.items[i..i + 8]).try_into().expect("eight slots")
    }

    #[inline(always)]
    fn get(&self, i: usize) -> T {
        debug_assert!(i < STACK);
        // SAFETY: the traversals read slot i only after pushing it (the stack pointer never
        // passes the highest slot written), so it lies in the stack (`push` and `eight`
        // check their slots) and holds an initialized value.
        unsafe { self.items.get_unchecked(i).assume_init() }
    }
}

/// A slot of [`Bvh::walk_pairs`]: the walk of query `query`, of ray `ray` with the root's
/// slots `skip` left out.
struct Slot {
    walk: Walk,
    stack: Stack<Pending>,
    ray: usize,
    skip: u32,
    query: usize,
}

impl Slot {
    /// The slot walking query `k` of `job`.
    #[inline(always)]
    fn start<const AVX: bool>(
        rays: &[Ray],
        job: &impl Fn(usize) -> (usize, f32, Start),
        k: usize,
    ) -> Slot {
        let (ray, tmax, start) = job(k);
        Slot {
            walk: Walk::new::<AVX>(&rays[ray], tmax, start.node),
            stack: Stack::new(),
            ray,
            skip: start.skip,
            query: k,
        }
    }
}

/// One ray's closest-hit walk through the tree, a node or leaf per [`Walk::step`], for
/// [`Bvh::walk_pairs`], which alternates two; its traversal stack is kept apart. A lone walk
/// is [`Bvh::intersect_with`]'s loop, the same steps (see [`Bvh::walk_pairs`]).
struct Walk {
    pre: RayPre,
    slab: SlabRay,
    best: Option<Hit>,
    end: Limit,
    /// `widen(end.t)`: children entered no farther than this are visited.
    reach: f32,
    sp: usize,
    /// The node or leaf the next step visits.
    node: u32,
}

impl Walk {
    /// A walk of `ray` up to `tmax`, starting at node `start`.
    #[inline(always)]
    fn new<const AVX: bool>(ray: &Ray, tmax: f32, start: u32) -> Walk {
        let (pre, slab) = set_up::<AVX>(ray);
        Walk {
            slab,
            pre,
            best: None,
            end: Limit::end(tmax),
            reach: widen(tmax),
            sp: 0,
            node: start,
        }
    }

    /// Starts the walk over, for `ray` up to `tmax` from node `start` (the stack's memory
    /// is kept).
    #[inline(always)]
    fn reset<const AVX: bool>(&mut self, ray: &Ray, tmax: f32, start: u32) {
        (self.pre, self.slab) = set_up::<AVX>(ray);
        self.best = None;
        self.end = Limit::end(tmax);
        self.reach = widen(tmax);
        self.sp = 0;
        self.node = start;
    }

    /// Visits the next node or leaf (the root's children in the slots of `skip` left out)
    /// and chooses the one after it: the nearest child entered, else the nearest pending
    /// child that may still hold a closer hit. False when none is left: the walk is over
    /// and `best` is the closest hit.
    ///
    /// One or two children entered are told apart and ordered by selects instead of
    /// branches ([`Bvh::descend`]): for incoherent rays, whose branches the processor cannot
    /// predict, that is faster (the one-ray walk, mostly coherent, branches on one child).
    /// The children visited are the same either way, in the same order but for children
    /// entered less than 8 ulps apart ([`Bvh::descend`]).
    #[inline(always)]
    fn step<const AVX: bool, const WIDE: bool>(
        &mut self,
        bvh: &Bvh,
        ray: &Ray,
        tmin: f32,
        skip: u32,
        stack: &mut Stack<Pending>,
    ) -> bool {
        let node_ref = self.node;
        if node_ref & LEAF != 0 {
            let found =
                match bvh.leaf_fast::<AVX, WIDE>(node_ref, &self.pre, tmin, &mut self.end, false) {
                    Ok(found) => found,
                    Err(SlowLeaf) => {
                        bvh.leaf_apart::<AVX>(node_ref, &self.pre, ray, tmin, &mut self.end, false)
                    }
                };
            if let Some(h) = found {
                self.best = Some(h);
                self.reach = widen(self.end.t);
            }
        } else {
            let n = bvh.node(node_ref);
            let (near, mut mask) = if AVX && self.slab.fused() {
                Bvh::node_hit::<AVX, true>(n, &self.slab, tmin, self.reach)
            } else {
                Bvh::node_hit::<AVX, false>(n, &self.slab, tmin, self.reach)
            };
            if node_ref == 0 {
                mask &= !skip;
            }
            if mask != 0 {
                self.node = bvh.descend::<false, AVX>(n, &near, mask, stack, &mut self.sp);
                return true;
            }
        }
        match pop(stack, &mut self.sp, self.reach) {
            Some(next) => {
                self.node = next;
                true
            }
            None => false,
        }
    }
}

/// The ray's per-ray values for the leaves and the node tests: with `AVX` (in walks
/// compiled for AVX2), by [`RayPre::new_avx`], which gives the same values as
/// [`RayPre::new`], and the slab values from its registers.
#[inline(always)]
fn set_up<const AVX: bool>(ray: &Ray) -> (RayPre, SlabRay) {
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: `AVX` is true only in the walks compiled for AVX2, which their callers
        // enter after detecting it.
        let (pre, origin, inv_dir) = unsafe { RayPre::new_avx(ray) };
        return (pre, SlabRay::from_vectors(origin, inv_dir));
    }
    let pre = RayPre::new(ray);
    let slab = SlabRay::new(&pre);
    (pre, slab)
}

/// Pops the nearest pending child that may still hold a closer hit (one entered no farther
/// than `reach`), dropping those that cannot.
#[inline(always)]
fn pop(stack: &Stack<Pending>, sp: &mut usize, reach: f32) -> Option<u32> {
    while *sp > 0 {
        *sp -= 1;
        let p = stack.get(*sp);
        if p.t_near <= reach {
            return Some(p.node);
        }
    }
    None
}

fn root_bounds(n: &BuildNode) -> Aabb {
    match n {
        BuildNode::Leaf { bounds, .. } | BuildNode::Interior { bounds, .. } => *bounds,
    }
}

/// Primitives whose box has at least this fraction of the scene's surface area are large.
const BIG_AREA: f32 = 1.0 / 16.0;
/// At most this many large primitives are set apart.
const BIG_MAX: usize = 12;

/// Sets apart the large primitives of a scene with more than [`FLAT_MAX`] (walls and floors
/// of a room, among small ones): moves up to [`BIG_MAX`] of them (largest first) to the
/// front of `prims`, in primitive order, and returns how many (none if there are no small
/// ones to keep apart from). `b3` bounds the scene; over `parallel_threshold` primitives,
/// the search runs in parallel.
fn take_big(prims: &mut [PrimRef], b3: B3, parallel_threshold: usize) -> usize {
    if prims.len() <= FLAT_MAX {
        return 0;
    }
    let least = b3.area() * BIG_AREA;
    let big_one = |p: &PrimRef| {
        let area = p.bounds.area();
        (area >= least).then_some((area, p.id))
    };
    let mut big: Vec<(f32, u32)> = if prims.len() > parallel_threshold {
        prims.par_iter().filter_map(big_one).collect()
    } else {
        prims.iter().filter_map(big_one).collect()
    };
    if big.is_empty() || big.len() == prims.len() {
        return 0;
    }
    big.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    big.truncate(BIG_MAX);
    let mut ids: Vec<u32> = big.iter().map(|b| b.1).collect();
    ids.sort_unstable();
    // A stable partition: the large ones first, each side in its old order.
    let (mut front, mut back): (Vec<PrimRef>, Vec<PrimRef>) = (Vec::new(), Vec::new());
    for p in prims.iter() {
        if ids.binary_search(&p.id).is_ok() {
            front.push(*p);
        } else {
            back.push(*p);
        }
    }
    let n = front.len();
    prims[..n].copy_from_slice(&front);
    prims[n..].copy_from_slice(&back);
    n
}

/// The union of the boxes of `prims` and the bounds of their doubled centroids (min and max
/// are exact, so the parallel reduction gives the same boxes as a sequential one).
fn bounds_of(prims: &[PrimRef], parallel_threshold: usize) -> (B3, B3) {
    let add = |(b, c): (B3, B3), p: &PrimRef| (b.union(p.bounds), c.grow(p.centroid2()));
    if prims.len() > parallel_threshold {
        prims
            .par_chunks(parallel_threshold)
            .map(|c| c.iter().fold((B3::EMPTY, B3::EMPTY), add))
            .reduce(
                || (B3::EMPTY, B3::EMPTY),
                |(a, b), (c, d)| (a.union(c), b.union(d)),
            )
    } else {
        prims.iter().fold((B3::EMPTY, B3::EMPTY), add)
    }
}

/// How far ahead, in primitives, leaf packing prefetches triangles.
const PACK_AHEAD: usize = 16;

/// Frees a binary tree, the top levels' halves in parallel.
fn free(n: BuildNode, depth: usize) {
    if let BuildNode::Interior { children, .. } = n {
        let [a, b] = *children;
        if depth < 4 {
            rayon::join(|| free(a, depth + 1), || free(b, depth + 1));
        }
    }
}

/// Per-axis bin counts and boxes of a set of primitives.
#[derive(Clone, Copy)]
struct Bins {
    counts: [[u32; BINS]; 3],
    boxes: [[B3; BINS]; 3],
}

impl Bins {
    const EMPTY: Bins = Bins {
        counts: [[0; BINS]; 3],
        boxes: [[B3::EMPTY; BINS]; 3],
    };

    #[inline(always)]
    fn add(&mut self, bin: [usize; 3], b: B3) {
        for (axis, &k) in bin.iter().enumerate() {
            let k = k % BINS;
            self.counts[axis][k] += 1;
            self.boxes[axis][k] = self.boxes[axis][k].union(b);
        }
    }

    /// The bins of both sets (counts add exactly and boxes unite exactly, so the order of
    /// merging does not matter).
    fn merge(mut self, o: &Bins) -> Bins {
        for axis in 0..3 {
            for k in 0..BINS {
                self.counts[axis][k] += o.counts[axis][k];
                self.boxes[axis][k] = self.boxes[axis][k].union(o.boxes[axis][k]);
            }
        }
        self
    }
}

/// Builds the subtree over `prims`, which start at `offset` in the final order; `b3` bounds
/// their boxes and `cb` their doubled centroids.
fn build_node(
    prims: &mut [PrimRef],
    offset: usize,
    depth: usize,
    opts: &BuildOptions,
    b3: B3,
    cb: B3,
) -> (BuildNode, Summary) {
    let bounds = b3.to_aabb();
    let n = prims.len();
    let leaf = || {
        (
            BuildNode::Leaf {
                bounds,
                start: offset,
                count: n,
            },
            Summary::leaf(&bounds, n, depth),
        )
    };
    // A subtree small enough for one leaf is one (see `BuildOptions::default`).
    if n <= opts.max_leaf {
        return leaf();
    }
    // Binned SAH on every axis with a non-degenerate centroid extent, all three axes binned
    // in one pass.
    let extent = cb.max - cb.min;
    let scale = Vec3A::select(
        extent.cmpgt(Vec3A::ZERO),
        Vec3A::splat(BINS as f32) / extent,
        Vec3A::ZERO,
    );
    let bin_of = |p: &PrimRef| bins((p.centroid2() - cb.min) * scale);
    let bin_all = |bins: &mut Bins, ps: &[PrimRef]| {
        for p in ps {
            bins.add(bin_of(p), p.bounds);
        }
    };
    let mut bins = Bins::EMPTY;
    if n > 4 * opts.parallel_threshold {
        bins = prims
            .par_chunks(opts.parallel_threshold)
            .map(|ps| {
                let mut b = Bins::EMPTY;
                bin_all(&mut b, ps);
                b
            })
            .reduce(|| Bins::EMPTY, |a, b| a.merge(&b));
    } else {
        bin_all(&mut bins, prims);
    }
    let Bins { counts, boxes } = &bins;
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, split bin)
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        // Only non-empty bins matter: every split between two of them gives the same
        // sides, and the first such split is kept, as a sweep over all bins would.
        let mut full = [0usize; BINS];
        let mut m = 0;
        for (b, &count) in counts[axis].iter().enumerate() {
            if count > 0 {
                full[m] = b;
                m += 1;
            }
        }
        // Sweep from the right, then from the left.
        let mut right_area = [0f32; BINS];
        let mut right_count = [0u32; BINS];
        let (mut acc, mut c) = (B3::EMPTY, 0);
        for i in (1..m).rev() {
            acc = acc.union(boxes[axis][full[i]]);
            c += counts[axis][full[i]];
            right_area[i] = acc.area();
            right_count[i] = c;
        }
        let (mut acc, mut c) = (B3::EMPTY, 0);
        for i in 1..m {
            acc = acc.union(boxes[axis][full[i - 1]]);
            c += counts[axis][full[i - 1]];
            let cost = acc.area() * packs(c) + right_area[i] * packs(right_count[i]);
            if best.is_none_or(|(bc, _, _)| cost < bc) {
                best = Some((cost, axis, full[i - 1] + 1));
            }
        }
    }
    let split = match best {
        // Past this depth, median splits bound the remaining depth by log2(n).
        Some(_) if depth >= MEDIAN_DEPTH => None,
        Some((_, axis, split)) => Some((axis, split)),
        // Every centroid coincides: nothing separates them.
        None if n <= MAX_LEAF_REF => return leaf(),
        None => None,
    };
    // Partition, gathering each side's bounds on the way.
    let mut mid = 0;
    let mut sides = [(B3::EMPTY, B3::EMPTY); 2];
    if let Some((axis, split)) = split {
        // The four boxes stay in registers: one branch per primitive, no indexed stores.
        let [(mut lb, mut lc), (mut rb, mut rc)] = sides;
        for j in 0..n {
            let p = prims[j];
            if bin_of(&p)[axis] < split {
                lb = lb.union(p.bounds);
                lc = lc.grow(p.centroid2());
                prims.swap(mid, j);
                mid += 1;
            } else {
                rb = rb.union(p.bounds);
                rc = rc.grow(p.centroid2());
            }
        }
        sides = [(lb, lc), (rb, rc)];
    }
    if mid == 0 || mid == n {
        mid = n / 2;
        sides = [(B3::EMPTY, B3::EMPTY); 2];
        for (j, p) in prims.iter().enumerate() {
            let side = &mut sides[usize::from(j >= mid)];
            side.0 = side.0.union(p.bounds);
            side.1 = side.1.grow(p.centroid2());
        }
    }
    let (l, r) = prims.split_at_mut(mid);
    let [(lb, lc), (rb, rc)] = sides;
    let ((a, sa), (b, sb)) = if n > opts.parallel_threshold {
        rayon::join(
            || build_node(l, offset, depth + 1, opts, lb, lc),
            || build_node(r, offset + mid, depth + 1, opts, rb, rc),
        )
    } else {
        (
            build_node(l, offset, depth + 1, opts, lb, lc),
            build_node(r, offset + mid, depth + 1, opts, rb, rc),
        )
    };
    (
        BuildNode::interior(bounds, [a, b]),
        Summary::interior(&bounds, opts.traversal_cost, sa, sb),
    )
}

/// The bins (`0..BINS`) of scaled centroid offsets on the three axes: the integer parts,
/// with NaN taken as 0 and anything past the last bin put in it.
#[inline(always)]
fn bins(scaled: Vec3A) -> [usize; 3] {
    let b = scaled.max(Vec3A::ZERO).min(Vec3A::splat((BINS - 1) as f32));
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128i, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of x86_64; the lanes are in [0, BINS - 1], so truncation is
        // exact and the i32 lanes are non-negative.
        let i: [i32; 4] =
            unsafe { std::mem::transmute::<__m128i, [i32; 4]>(_mm_cvttps_epi32(b.into())) };
        [i[0] as usize, i[1] as usize, i[2] as usize]
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        [b.x as usize, b.y as usize, b.z as usize]
    }
}

/// Lists in `out`, in order, the subtrees that fill the slots two sibling subtrees `a` and `b`
/// share at least cost ([`BuildNode::interior`]), given `j` >= 2 slots.
fn hand_down<'a>(a: &'a BuildNode, b: &'a BuildNode, j: usize, out: &mut Vec<&'a BuildNode>) {
    let k = split_cost(&a.slots(), &b.slots(), j).1;
    place(a, k, out);
    place(b, j - k, out);
}

/// Lists in `out` the subtrees that hold subtree `n` in at most `j` slots at least cost: `n`
/// itself, or descendants of it.
fn place<'a>(n: &'a BuildNode, j: usize, out: &mut Vec<&'a BuildNode>) {
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

/// Cost of testing `n` primitives: they are tested four at a time.
fn packs(n: u32) -> f32 {
    n.div_ceil(4) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::Pcg32;
    use std::collections::HashMap;

    /// Oracle: the one-ray calls, which start at the root. In a room (ten wall triangles,
    /// set apart into the root's list) around a cluster the root holds in several children,
    /// rays aimed at the cluster walk on from one child or from the root, as the lanes'
    /// gate decides (both occur here), and every hit and occlusion is the one-ray call's,
    /// bit for bit, with ends infinite and finite.
    #[test]
    fn walks_past_the_list_start_at_the_child_entered() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut rng = Pcg32::new(9, 10);
            let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
            // Five faces of a cube of half-size 10 (all but +z), two triangles each.
            let mut tris = vec![];
            for (axis, side) in [(0, -1.0), (0, 1.0), (1, -1.0), (1, 1.0), (2, -1.0)] {
                let corner = |a: f32, b: f32| {
                    let mut p = [0.0f32; 3];
                    p[axis] = side * 10.0;
                    p[(axis + 1) % 3] = a * 10.0;
                    p[(axis + 2) % 3] = b * 10.0;
                    Vec3::from(p)
                };
                let [p, q, t, u] =
                    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(a, b)| corner(a, b));
                tris.push([p, q, t]);
                tris.push([p, t, u]);
            }
            for _ in 0..600 {
                let a = r() * 3.0;
                tris.push([a, a + r() * 0.3, a + r() * 0.3]);
            }
            let bvh = Bvh::build(&tris, &[], &BuildOptions::default());
            let flat = bvh.flat.as_ref().expect("the walls make a list");
            assert!(
                flat.inner_nodes.len() >= 2,
                "the cluster under several children"
            );
            let rays: Vec<Ray> = (0..4000)
                .map(|_| {
                    let o = r() * 9.0;
                    Ray::new(o, r() * 3.0 - o)
                })
                .collect();
            // How the gate starts the walks of the lanes that go on into the tree.
            let (mut one, mut several) = (0, 0);
            for group in rays.chunks(8) {
                let mut out = [None; 8];
                // SAFETY: the processor has AVX2.
                let lanes = unsafe {
                    crate::flat::closest_avx2(flat, group, (1e-3, f32::INFINITY), &mut out)
                };
                for lane in (0..group.len()).filter(|&l| lanes.need & (1 << l) != 0) {
                    if lanes.inner[lane] == crate::flat::SEVERAL {
                        several += 1;
                    } else {
                        one += 1;
                    }
                }
            }
            assert!(one > 0 && several > 0, "one child {one}, several {several}");
            let bits =
                |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.prim, h.b1.to_bits(), h.b2.to_bits()));
            for tmax in [f32::INFINITY, 9.0] {
                let ends: Vec<f32> = (0..rays.len()).map(|i| 2.0 + (i % 13) as f32).collect();
                let mut hits = vec![None; rays.len()];
                bvh.intersect_batch(&rays, 1e-3, tmax, &mut hits);
                let mut blocked = vec![false; rays.len()];
                bvh.occluded_batch(&rays, 1e-3, &ends, &mut blocked);
                for (i, ray) in rays.iter().enumerate() {
                    assert_eq!(
                        bits(hits[i]),
                        bits(bvh.intersect(ray, 1e-3, tmax)),
                        "ray {i}"
                    );
                    assert_eq!(blocked[i], bvh.occluded(ray, 1e-3, ends[i]), "ray {i}");
                }
            }
        }
    }

    /// Property: the AVX2 walk (fused slab distances) and the SSE walk (unfused) enter
    /// boxes by distances a rounding apart, and still return bit-identical hits: both enter
    /// every box the ray meets, and the closest hit is the first by distance, then
    /// primitive number, whatever the order (checked on random rays, and on axis-aligned
    /// rays, whose slab distances include NaN).
    #[test]
    fn avx_and_sse_traversals_agree() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            let mut rng = Pcg32::new(5, 6);
            let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let tris: Vec<[Vec3; 3]> = (0..3000)
                .map(|_| {
                    let a = r() * 8.0;
                    [a, a + r() * 0.5, a + r() * 0.5]
                })
                .collect();
            let spheres = [Sphere {
                center: Vec3::splat(4.0),
                radius: 0.7,
            }];
            let bvh = Bvh::build(&tris, &spheres, &BuildOptions::default());
            let mut hits = 0;
            for k in 0..20_000 {
                let o = r() * 10.0 - 1.0;
                let d = if k % 4 == 0 {
                    [Vec3::X, -Vec3::Y, Vec3::Z][k % 3]
                } else {
                    r() - 0.5
                };
                let ray = Ray::new(o.floor(), d);
                // SAFETY: AVX2 and FMA were detected above.
                let avx = unsafe { bvh.intersect_avx(&ray, 0.0, f32::INFINITY) };
                assert_eq!(
                    avx,
                    bvh.intersect_with::<false, false>(&ray, 0.0, f32::INFINITY, Start::ROOT)
                );
                // SAFETY: as above.
                let occ = unsafe { bvh.occluded_avx(&ray, 0.0, 5.0) };
                assert_eq!(
                    occ,
                    bvh.occluded_with::<false, false>(&ray, 0.0, 5.0, Start::ROOT)
                );
                hits += usize::from(avx.is_some());
            }
            assert!(hits > 2000, "{hits} hits");
        }
    }

    /// Property: the call-free leaf test answers exactly as the full one (hit, and the end
    /// it moves to) or defers the leaf, and defers only a leaf with spheres or one where a
    /// pack's lane test meets an edge function of exactly zero. Small integer coordinates
    /// make such edges common; both occur here, as do hits, for closest and any hits, with
    /// and without AVX, and on AVX-512's sixteen lanes (where, with `any`, the answer may
    /// be another of the leaf's hits than the full test's first).
    #[test]
    fn call_free_leaf_test_equals_the_full_one_or_defers() {
        let mut rng = Pcg32::new(13, 4);
        let mut c = || (rng.next_u32() % 9) as f32 - 4.0;
        let tris: Vec<[Vec3; 3]> = (0..400)
            .map(|_| {
                let a = Vec3::new(c(), c(), c());
                [
                    a,
                    a + Vec3::new(c(), c(), 1.0),
                    a + Vec3::new(1.0, c(), c()),
                ]
            })
            .collect();
        let spheres = [Sphere {
            center: Vec3::new(0.5, 0.5, 0.5),
            radius: 0.75,
        }];
        let bvh = Bvh::build(&tris, &spheres, &BuildOptions::default());
        let leaves: Vec<u32> = bvh
            .nodes
            .iter()
            .flat_map(|n| (0..8).filter(|&s| n.slot_used(s)).map(|s| n.child[s]))
            .filter(|&r| r & LEAF != 0)
            .collect();
        let zero_edge = |r: u32, pre: &RayPre| {
            let rec = bvh.leaf_rec(r);
            let p0 = rec.pack_start as usize;
            bvh.packs[p0..p0 + rec.packs as usize].iter().any(|p| {
                p.intersect_fast(pre, 0.0, Limit::end(f32::INFINITY))
                    .is_err()
            })
        };
        let (mut same, mut deferred, mut hits, mut wide) = (0, 0, 0, 0);
        #[cfg(target_arch = "x86_64")]
        let wide_paths = std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512dq")
            && std::arch::is_x86_feature_detected!("avx512vl");
        for k in 0..3000 {
            let o =
                Vec3::new(c(), c(), c()) * 1.5 + Vec3::splat(if k % 2 == 0 { 0.0 } else { 0.3 });
            let d = Vec3::new(c(), c(), c());
            if d == Vec3::ZERO {
                continue;
            }
            let ray = Ray::new(o, d);
            let pre = RayPre::new(&ray);
            for &r in &leaves {
                for any in [false, true] {
                    let end0 = Limit::end(if k % 3 == 0 { 3.0 } else { f32::INFINITY });
                    // The full test on the same instruction set (with AVX it tests packs in
                    // pairs, which may find another first hit when `any`).
                    let check =
                        |fast: Result<Option<Hit>, SlowLeaf>, end_fast: Limit, avx: bool| {
                            let mut end = end0;
                            let full = if avx {
                                bvh.leaf::<true>(r, &pre, &ray, 0.0, &mut end, any)
                            } else {
                                bvh.leaf::<false>(r, &pre, &ray, 0.0, &mut end, any)
                            };
                            match fast {
                                Ok(h) => {
                                    assert_eq!(h, full, "ray {k} leaf {r:#x}");
                                    assert_eq!((end_fast.t, end_fast.prim), (end.t, end.prim));
                                    (1, 0, usize::from(h.is_some()))
                                }
                                Err(SlowLeaf) => {
                                    assert!(bvh.leaf_rec(r).spheres != 0 || zero_edge(r, &pre));
                                    assert_eq!((end_fast.t, end_fast.prim), (end0.t, end0.prim));
                                    (0, 1, 0)
                                }
                            }
                        };
                    let mut end = end0;
                    let fast = bvh.leaf_fast::<false, false>(r, &pre, 0.0, &mut end, any);
                    let (s, d, h) = check(fast, end, false);
                    (same, deferred, hits) = (same + s, deferred + d, hits + h);
                    #[cfg(target_arch = "x86_64")]
                    if std::arch::is_x86_feature_detected!("avx2") {
                        // The `AVX` code paths, on a processor with AVX2 (detected above).
                        let mut end = end0;
                        let fast = bvh.leaf_fast::<true, false>(r, &pre, 0.0, &mut end, any);
                        check(fast, end, true);
                    }
                    #[cfg(target_arch = "x86_64")]
                    if wide_paths {
                        // The `WIDE` code paths, which test three or four packs on sixteen
                        // lanes: with `any`, a hit of the leaf's, perhaps not the full
                        // test's first one.
                        let mut end = end0;
                        let fast = bvh.leaf_fast::<true, true>(r, &pre, 0.0, &mut end, any);
                        if any && matches!(fast, Ok(Some(_))) {
                            let mut all = end0;
                            let first = bvh.leaf::<true>(r, &pre, &ray, 0.0, &mut all, false);
                            assert!(first.is_some(), "ray {k} leaf {r:#x}");
                            assert!(end.t >= all.t && end.t <= end0.t);
                            wide += 1;
                        } else {
                            let (s, ..) = check(fast, end, true);
                            wide += s;
                        }
                    }
                }
            }
        }
        assert!(
            same > 10_000 && deferred > 1000 && hits > 1000,
            "{same} answered, {deferred} deferred, {hits} hits"
        );
        #[cfg(target_arch = "x86_64")]
        assert!(
            !wide_paths || wide > 10_000,
            "{wide} answered on sixteen lanes"
        );
    }

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
                    bounds: B3::from_aabb(Aabb::point(t[0]).extend(t[1]).extend(t[2])),
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
