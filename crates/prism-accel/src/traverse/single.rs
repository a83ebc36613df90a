//! The one-ray walks: closest hit ([`Bvh::intersect_with`]) and occlusion
//! ([`Bvh::occluded_with`]), each a loop that keeps its state in registers, with the node
//! test and per-ray set-up of the instruction set it is compiled for, and the ordering of
//! the children a node test enters ([`Bvh::descend`]).

use prism_math::Ray;

use super::leaf::SlowLeaf;
use super::stack::{pop, Stack};
use crate::hit::{Hit, Limit};
use crate::layout::node8::{widen, Node8, SlabRay};
use crate::layout::{Bvh, Start, LEAF};
use crate::shapes::RayPre;
use crate::simd::kernel::Kernel;
use crate::simd::order::Pending;

impl Bvh {
    /// The closest hit with `tmin < t < tmax` (the lowest primitive number of equals), in the
    /// part of the tree `start` names.
    #[inline(always)]
    pub(crate) fn intersect_with<K: Kernel>(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        start: Start,
    ) -> Option<Hit> {
        let (pre, slab) = K::set_up(ray);
        // One loop per node test, so that each keeps only its own per-ray values live.
        if K::AVX && slab.fused() {
            self.walk_one::<K>(ray, (&pre, &slab), tmin, tmax, (start, true))
        } else {
            self.walk_one::<K>(ray, (&pre, &slab), tmin, tmax, (start, false))
        }
    }

    /// [`Bvh::intersect_with`]'s walk with the node test [`Kernel::node_hit`], fused if `fused` (a
    /// constant where the walk is inlined: one loop per node test).
    #[inline(always)]
    pub(crate) fn walk_one<K: Kernel>(
        &self,
        ray: &Ray,
        (pre, slab): (&RayPre, &SlabRay),
        tmin: f32,
        tmax: f32,
        (start, fused): (Start, bool),
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
                    match self.leaf_fast::<K>(node_ref, pre, tmin, &mut end, false) {
                        Ok(Some(h)) => {
                            best = Some(h);
                            reach = widen(end.t);
                        }
                        Ok(None) => {}
                        Err(SlowLeaf) => break node_ref,
                    }
                } else {
                    let n = self.node(node_ref);
                    let (near, mut mask) = K::node_hit(n, slab, tmin, reach, fused);
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
                        node_ref = self.descend::<K>(n, &near, mask, &mut stack, &mut sp, true);
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
            if let Some(h) = self.leaf::<K>(slow, pre, ray, tmin, &mut e, false) {
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
    /// - `lone` (a constant where this is inlined), a lone walk ([`Bvh::intersect_with`]), whose rays are mostly coherent
    ///   and its branches predicted: two children by a branch (primary rays 3.5% faster
    ///   than by selects), three by three branches (primary rays 1.2% faster, random
    ///   rays 0.7%, than one by one), more one by one (a sorting network made them 2.2%
    ///   slower); the next child on the stack is prefetched (random rays 3.7% faster,
    ///   primary rays 1.9% slower than without).
    /// - Else the paired walks of batches ([`Bvh::walk_pairs`]), whose rays are
    ///   incoherent: one or two children are told apart and ordered by selects (one is
    ///   pushed and popped again at once: `*sp` does not move); more, with an AVX
    ///   [`Kernel`], by a sorting network without branches
    ///   ([`crate::simd::order::sort_entered_avx2`], which orders entries less than 8 ulps
    ///   apart by slot; random rays 3.3% faster), else one by one. Nothing is
    ///   prefetched: these walks overlap their misses already, and render 2-7% faster
    ///   without.
    #[inline(always)]
    pub(crate) fn descend<K: Kernel>(
        &self,
        n: &Node8,
        near: &[f32; 8],
        mut mask: u32,
        stack: &mut Stack<Pending>,
        sp: &mut usize,
        lone: bool,
    ) -> u32 {
        // The entered children but the lowest slot's: none when one is entered. (Bit
        // tricks rather than a count: the walks are compiled without `popcnt`.)
        let rest = mask & mask.wrapping_sub(1);
        if rest & rest.wrapping_sub(1) == 0 {
            // Push the farther (when there are two) and go on to the nearer, as the sort
            // below orders them.
            let first = mask.trailing_zeros() as usize;
            let last = 31 - mask.leading_zeros() as usize;
            if lone {
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
        if K::AVX && !lone {
            // SAFETY: `K::AVX` is true only in the walks compiled for AVX2, which their callers
            // enter after detecting it; three or more children are entered, none with a
            // NaN entry (the node tests enter no such child).
            let (nearest, pushed) = unsafe {
                crate::simd::order::sort_entered_avx2(near, &n.child, mask, stack.eight(*sp))
            };
            *sp += pushed;
            return nearest;
        }
        // The entered children but the two lowest slots'.
        let rest2 = rest & rest.wrapping_sub(1);
        if lone && rest2 & rest2.wrapping_sub(1) == 0 {
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
        if lone {
            // The second nearest is likely visited next after the nearest's subtree.
            self.prefetch(hits[1].0);
        }
        hits[0].0
    }

    /// True if anything lies along the ray with `tmin < t < tmax`, in the part of the tree
    /// `start` names.
    #[inline(always)]
    pub(crate) fn occluded_with<K: Kernel>(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        start: Start,
    ) -> bool {
        let (r, slab) = K::set_up(ray);
        if K::AVX && slab.fused() {
            self.occluded_one::<K>(ray, (&r, &slab), tmin, tmax, (start, true))
        } else {
            self.occluded_one::<K>(ray, (&r, &slab), tmin, tmax, (start, false))
        }
    }

    /// [`Bvh::occluded_with`]'s walk with the node test [`Kernel::node_hit`], fused if `fused` (a
    /// constant where the walk is inlined: one loop per node test).
    #[inline(always)]
    pub(crate) fn occluded_one<K: Kernel>(
        &self,
        ray: &Ray,
        (r, slab): (&RayPre, &SlabRay),
        tmin: f32,
        tmax: f32,
        (start, fused): (Start, bool),
    ) -> bool {
        let mut stack = Stack::<u32>::new();
        let mut sp = 0usize;
        let mut node_ref = start.node;
        loop {
            // The walk up to a leaf that needs `Bvh::leaf`, tested after this loop (as in
            // `Bvh::walk_one`).
            let slow = loop {
                if node_ref & LEAF != 0 {
                    match self.leaf_fast::<K>(node_ref, r, tmin, &mut Limit::end(tmax), true) {
                        Ok(Some(_)) => return true,
                        Ok(None) => {}
                        Err(SlowLeaf) => break node_ref,
                    }
                } else {
                    let n = self.node(node_ref);
                    let (_, mut mask) = K::node_hit(n, slab, tmin, tmax, fused);
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
            if self.leaf::<K>(slow, r, ray, tmin, &mut end, true).is_some() {
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
