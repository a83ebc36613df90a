//! The paired walks of a batch: two closest-hit walks of incoherent rays stepped in turn,
//! so that each one's memory waits overlap the other's work.

use prism_math::Ray;

use super::leaf::SlowLeaf;
use super::stack::{pop, Stack};
use crate::hit::{Hit, Limit};
use crate::layout::node8::{widen, SlabRay};
use crate::layout::{Bvh, Start, LEAF};
use crate::shapes::RayPre;
use crate::simd::kernel::Kernel;
use crate::simd::order::Pending;

/// A slot of [`Bvh::walk_pairs`]: the walk of query `query`, of ray `ray` with the root's
/// slots `skip` left out.
pub(crate) struct Slot {
    pub(crate) walk: Walk,
    pub(crate) stack: Stack<Pending>,
    pub(crate) ray: usize,
    pub(crate) skip: u32,
    pub(crate) query: usize,
}

impl Slot {
    /// The slot walking query `k` of `job`.
    #[inline(always)]
    pub(crate) fn start<K: Kernel>(
        rays: &[Ray],
        job: &impl Fn(usize) -> (usize, f32, Start),
        k: usize,
    ) -> Slot {
        let (ray, tmax, start) = job(k);
        Slot {
            walk: Walk::new::<K>(&rays[ray], tmax, start.node),
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
pub(crate) struct Walk {
    pub(crate) pre: RayPre,
    pub(crate) slab: SlabRay,
    pub(crate) best: Option<Hit>,
    pub(crate) end: Limit,
    /// `widen(end.t)`: children entered no farther than this are visited.
    pub(crate) reach: f32,
    pub(crate) sp: usize,
    /// The node or leaf the next step visits.
    pub(crate) node: u32,
}

impl Walk {
    /// A walk of `ray` up to `tmax`, starting at node `start`.
    #[inline(always)]
    pub(crate) fn new<K: Kernel>(ray: &Ray, tmax: f32, start: u32) -> Walk {
        let (pre, slab) = K::set_up(ray);
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
    pub(crate) fn reset<K: Kernel>(&mut self, ray: &Ray, tmax: f32, start: u32) {
        (self.pre, self.slab) = K::set_up(ray);
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
    pub(crate) fn step<K: Kernel>(
        &mut self,
        bvh: &Bvh,
        ray: &Ray,
        tmin: f32,
        skip: u32,
        stack: &mut Stack<Pending>,
    ) -> bool {
        let node_ref = self.node;
        if node_ref & LEAF != 0 {
            let found = match bvh.leaf_fast::<K>(node_ref, &self.pre, tmin, &mut self.end, false) {
                Ok(found) => found,
                Err(SlowLeaf) => {
                    bvh.leaf_apart::<K>(node_ref, &self.pre, ray, tmin, &mut self.end, false)
                }
            };
            if let Some(h) = found {
                self.best = Some(h);
                self.reach = widen(self.end.t);
            }
        } else {
            let n = bvh.node(node_ref);
            let (near, mut mask) = if K::AVX && self.slab.fused() {
                K::node_hit(n, &self.slab, tmin, self.reach, true)
            } else {
                K::node_hit(n, &self.slab, tmin, self.reach, false)
            };
            if node_ref == 0 {
                mask &= !skip;
            }
            if mask != 0 {
                self.node = bvh.descend::<K>(n, &near, mask, stack, &mut self.sp, false);
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

impl Bvh {
    /// [`Bvh::intersect_with`] for each ray of `rays` over the whole tree, two rays walked
    /// at once ([`Bvh::walk_pairs`]).
    #[inline(always)]
    pub(crate) fn intersect_pairs<K: Kernel>(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.walk_pairs::<K>(rays, tmin, (rays.len(), |k| (k, tmax, Start::ROOT)), hits);
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
    pub(crate) fn walk_pairs<K: Kernel>(
        &self,
        rays: &[Ray],
        tmin: f32,
        (n, job): (usize, impl Fn(usize) -> (usize, f32, Start)),
        hits: &mut [Option<Hit>],
    ) {
        if n < 2 {
            for (k, hit) in hits.iter_mut().enumerate().take(n) {
                let (i, tmax, start) = job(k);
                *hit = self.intersect_with::<K>(&rays[i], tmin, tmax, start);
            }
            return;
        }
        let mut a = Slot::start::<K>(rays, &job, 0);
        let mut b = Slot::start::<K>(rays, &job, 1);
        let mut next = 2;
        let (walks, out) = ((rays, tmin, (n, &job)), hits);
        while self.pair_step::<K>(walks, out, &mut a, &mut b, &mut next)
            && self.pair_step::<K>(walks, out, &mut b, &mut a, &mut next)
        {}
    }

    /// A step of [`Bvh::walk_pairs`]' walk in slot `slot`. When its walk ends, its hit is
    /// stored and the slot takes query `next`; with no query left, the `other` slot's walk
    /// is finished, and the answer is false: all are done.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    pub(crate) fn pair_step<K: Kernel>(
        &self,
        (rays, tmin, (n, job)): (&[Ray], f32, (usize, &impl Fn(usize) -> (usize, f32, Start))),
        hits: &mut [Option<Hit>],
        slot: &mut Slot,
        other: &mut Slot,
        next: &mut usize,
    ) -> bool {
        if slot
            .walk
            .step::<K>(self, &rays[slot.ray], tmin, slot.skip, &mut slot.stack)
        {
            return true;
        }
        hits[slot.query] = slot.walk.best;
        if *next == n {
            while other
                .walk
                .step::<K>(self, &rays[other.ray], tmin, other.skip, &mut other.stack)
            {}
            hits[other.query] = other.walk.best;
            return false;
        }
        let (ray, tmax, start) = job(*next);
        slot.walk.reset::<K>(&rays[ray], tmax, start.node);
        (slot.ray, slot.skip, slot.query) = (ray, start.skip, *next);
        *next += 1;
        true
    }
}
