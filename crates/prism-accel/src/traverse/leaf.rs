//! Leaf tests: a leaf's triangle packs (one, two or four at a time, by the instruction
//! set) and its spheres, the full test and the call-free one that defers rare cases.

use prism_math::Ray;

use crate::hit::{Hit, Limit};
use crate::layout::tri4::{EdgeOnZero, Tri4};
use crate::layout::{Bvh, LeafRec};
use crate::shapes::{intersect_sphere, RayPre};
#[cfg(target_arch = "x86_64")]
use crate::simd::kernel::Avx;
use crate::simd::kernel::{Kernel, Sse};

/// A leaf that [`Bvh::leaf_fast`] leaves to [`Bvh::leaf`].
pub(crate) struct SlowLeaf;

impl Bvh {
    /// Tests a leaf's primitives, moving `end` to each hit it admits (the first by distance,
    /// then primitive number, is kept); with `any`, stops at the first. With an AVX [`Kernel`], its
    /// packs are tested two at a time ([`Tri4::intersect_pair_avx`]), which finds the same
    /// hits.
    #[inline(always)]
    pub(crate) fn leaf<K: Kernel>(
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
            .leaf_packs::<K>(&rec, pre, tmin, end, any, false)
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
    pub(crate) fn leaf_fast<K: Kernel>(
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
        let weights = self.leaf_packs::<K>(&rec, pre, tmin, end, any, true)?;
        Ok(weights.map(|(b1, b2)| Hit {
            t: end.t,
            prim: end.prim,
            b1,
            b2,
        }))
    }

    /// The triangle packs of leaf `rec`, as [`Bvh::leaf`] tests them: moves `end` to each
    /// hit it admits (with `any`, to the first), and returns the barycentric weights of the
    /// last (none: `end` is as given). With `defer` (a constant where this is inlined), by the lane tests alone, which call no
    /// function, and [`SlowLeaf`] with `end` as given if one meets an edge function of
    /// exactly zero; without, never [`SlowLeaf`]. With a [`Kernel::WIDE`] kernel
    /// and `defer`, a leaf of three or four packs is one test on sixteen lanes
    /// ([`Tri4::intersect_four_fast`]), which finds the same closest hit (and, with `any`,
    /// a hit if there is one).
    #[inline(always)]
    pub(crate) fn leaf_packs<K: Kernel>(
        &self,
        rec: &LeafRec,
        pre: &RayPre,
        tmin: f32,
        end: &mut Limit,
        any: bool,
        defer: bool,
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
        if K::WIDE && defer && (3..=4).contains(&packs.len()) {
            // Four packs, or three with the third named again in the last lanes, which
            // `valid` leaves out: chosen without a branch, which would be mispredicted on
            // incoherent rays. (Leaves of more, which only primitives that cannot be
            // separated make, are tested by the loop below.)
            let n = packs.len();
            let four = [&packs[0], &packs[1], &packs[2], &packs[n - 1]];
            let valid = 0xffff >> (16 - 4 * n);
            // SAFETY: `K::WIDE` is true only in the walks compiled for AVX-512 (F, DQ and VL),
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
                [b, tail @ ..] if K::AVX => {
                    packs = tail;
                    // SAFETY: `K::AVX` is true only in the traversals compiled for AVX, which
                    // their callers enter after detecting it.
                    let found = unsafe {
                        if defer {
                            Tri4::intersect_pair_fast(a, b, pre, tmin, e)
                        } else {
                            Ok(Tri4::intersect_pair_avx(a, b, pre, tmin, e))
                        }
                    };
                    (found, b)
                }
                _ => {
                    packs = rest;
                    let found = if defer {
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
    pub(crate) fn leaf_apart<K: Kernel>(
        &self,
        r: u32,
        pre: &RayPre,
        ray: &Ray,
        tmin: f32,
        end: &mut Limit,
        any: bool,
    ) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        if K::AVX {
            // SAFETY: `K::AVX` is true only in the walks compiled for AVX2 and FMA (or
            // AVX-512, which has them), which their callers enter after detecting them.
            return unsafe { self.leaf_apart_avx2(r, pre, ray, tmin, end, any) };
        }
        self.leaf::<Sse>(r, pre, ray, tmin, end, any)
    }

    /// [`Bvh::leaf_apart`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline(never)]
    #[cold]
    pub(crate) unsafe fn leaf_apart_avx2(
        &self,
        r: u32,
        pre: &RayPre,
        ray: &Ray,
        tmin: f32,
        end: &mut Limit,
        any: bool,
    ) -> Option<Hit> {
        self.leaf::<Avx>(r, pre, ray, tmin, end, any)
    }

    /// [`Bvh::leaf`]'s test of a leaf's spheres: the first hit `end` admits, moving `end` to
    /// it (with `any`, the first hit). Never inlined: inlined, its per-ray values would be
    /// computed at the start of every walk, spheres or not.
    #[inline(never)]
    pub(crate) fn leaf_spheres(
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::LEAF;
    #[cfg(target_arch = "x86_64")]
    use crate::simd::kernel::Wide;
    use crate::{BuildOptions, Sphere};
    use prism_math::{Pcg32, Vec3};

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
                                bvh.leaf::<Avx>(r, &pre, &ray, 0.0, &mut end, any)
                            } else {
                                bvh.leaf::<Sse>(r, &pre, &ray, 0.0, &mut end, any)
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
                    let fast = bvh.leaf_fast::<Sse>(r, &pre, 0.0, &mut end, any);
                    let (s, d, h) = check(fast, end, false);
                    (same, deferred, hits) = (same + s, deferred + d, hits + h);
                    #[cfg(target_arch = "x86_64")]
                    if std::arch::is_x86_feature_detected!("avx2") {
                        // The [`Avx`] code paths, on a processor with AVX2 (detected above).
                        let mut end = end0;
                        let fast = bvh.leaf_fast::<Avx>(r, &pre, 0.0, &mut end, any);
                        check(fast, end, true);
                    }
                    #[cfg(target_arch = "x86_64")]
                    if wide_paths {
                        // The [`Wide`] code paths, which test three or four packs on sixteen
                        // lanes: with `any`, a hit of the leaf's, perhaps not the full
                        // test's first one.
                        let mut end = end0;
                        let fast = bvh.leaf_fast::<Wide>(r, &pre, 0.0, &mut end, any);
                        if any && matches!(fast, Ok(Some(_))) {
                            let mut all = end0;
                            let first = bvh.leaf::<Avx>(r, &pre, &ray, 0.0, &mut all, false);
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
}
