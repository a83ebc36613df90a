//! Four triangles tested against one ray at once: the watertight test of `shapes` on SIMD
//! lanes.

use prism_math::glam::Vec4;
use prism_math::Vec3;

use crate::hit::Limit;
use crate::shapes::{intersect_triangle, RayPre};

/// A lane test met an edge function of exactly zero, which only the scalar test decides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct EdgeOnZero;

/// Four triangles in structure-of-arrays form: `v[i][axis]` holds coordinate `axis` of
/// vertex `i` of the four triangles. Unused lanes hold NaN vertices, which fail every
/// comparison of the test, so they never hit.
/// Aligned to 32 bytes, a pack's 160 bytes always span exactly three cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(crate) struct Tri4 {
    pub(crate) v: [[Vec4; 3]; 3],
    /// Primitive numbers (`u32::MAX` in unused lanes).
    pub(crate) prim: [u32; 4],
}

impl Tri4 {
    /// Packs up to four triangles with their primitive numbers.
    pub(crate) fn new(tris: &[([Vec3; 3], u32)]) -> Tri4 {
        debug_assert!(tris.len() <= 4);
        let mut v = [[Vec4::NAN; 3]; 3];
        let mut prim = [u32::MAX; 4];
        for (lane, (t, p)) in tris.iter().enumerate() {
            for (i, vertex) in t.iter().enumerate() {
                for axis in 0..3 {
                    v[i][axis][lane] = vertex[axis];
                }
            }
            prim[lane] = *p;
        }
        Tri4 { v, prim }
    }

    /// Vertex `i` of the triangle in `lane`, padded to four floats (`x, y, z, 0`).
    pub(crate) fn corner(&self, lane: usize, i: usize) -> [f32; 4] {
        let [x, y, z] = self.coords(lane, i);
        [x, y, z, 0.0]
    }

    pub(crate) fn vertex(&self, lane: usize, i: usize) -> Vec3 {
        Vec3::from_array(self.coords(lane, i))
    }

    /// The coordinates of vertex `i` of the triangle in `lane`, read as array elements
    /// (indexing a `Vec4` itself is a branch on the index).
    #[inline(always)]
    pub(crate) fn coords(&self, lane: usize, i: usize) -> [f32; 3] {
        let [x, y, z] = &self.v[i];
        [x.as_ref()[lane], y.as_ref()[lane], z.as_ref()[lane]]
    }

    /// The first hit among the four with `tmin < t` that `end` admits, by distance, then
    /// primitive number: `(t, lane, b1, b2)`.
    #[inline(always)]
    pub(crate) fn intersect(
        &self,
        r: &RayPre,
        tmin: f32,
        end: Limit,
    ) -> Option<(f32, usize, f32, f32)> {
        self.intersect_fast(r, tmin, end)
            .unwrap_or_else(|EdgeOnZero| self.scalar(r, tmin, end))
    }

    /// [`Tri4::intersect`] when no edge function of a lane is exactly zero; else
    /// [`EdgeOnZero`], and the lanes are for the scalar test to decide. It calls no
    /// function, so a walk's loop that uses it keeps its per-ray values in registers.
    #[inline(always)]
    pub(crate) fn intersect_fast(
        &self,
        r: &RayPre,
        tmin: f32,
        end: Limit,
    ) -> Result<Option<(f32, usize, f32, f32)>, EdgeOnZero> {
        let axes = r.axes();
        let o = r.origin_k;
        // Vertex `i`'s coordinate on sheared axis `k`, less the origin's.
        let rel = |i: usize, k: usize| self.v[i][axes[k]] - Vec4::splat(o[k]);
        let (sx, sy, sz) = (
            Vec4::splat(r.shear.x),
            Vec4::splat(r.shear.y),
            Vec4::splat(r.shear.z),
        );
        let (az, bz, cz) = (rel(0, 2), rel(1, 2), rel(2, 2));
        let ax = rel(0, 0) - sx * az;
        let ay = rel(0, 1) - sy * az;
        let bx = rel(1, 0) - sx * bz;
        let by = rel(1, 1) - sy * bz;
        let cx = rel(2, 0) - sx * cz;
        let cy = rel(2, 1) - sy * cz;
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let any_zero = u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero);
        if any_zero.any() {
            // An edge function is exactly zero in single precision: these lanes are for the
            // scalar test, which recomputes them in double precision.
            return Err(EdgeOnZero);
        }
        // No edge function is zero here, so a lane is inside its triangle when its edge
        // functions are all negative or all positive: when they share a sign bit. Most packs
        // have no such lane and stop before the division. The sum `det` of three numbers of
        // one sign, none zero, is not zero. A lane with a NaN edge function may pass, but
        // then its `t` is NaN and fails both comparisons with the ends.
        let (su, sv, sw) = (
            u.is_negative_bitmask(),
            v.is_negative_bitmask(),
            w.is_negative_bitmask(),
        );
        let inside = !((su ^ sv) | (su ^ sw)) & 0xf;
        if inside == 0 {
            return Ok(None);
        }
        let det = u + v + w;
        let t = sz * (u * az + v * bz + w * cz) * (Vec4::ONE / det);
        let mask = inside & (t.cmpgt(Vec4::splat(tmin)) & t.cmple(Vec4::splat(end.t))).bitmask();
        if mask == 0 {
            return Ok(None);
        }
        let ta = t.to_array();
        let best = nearest_lane(mask, &ta, |lane| self.prim[lane]);
        if !end.admits(ta[best], self.prim[best]) {
            return Ok(None);
        }
        let inv = 1.0 / det.to_array()[best];
        Ok(Some((
            ta[best],
            best,
            v.to_array()[best] * inv,
            w.to_array()[best] * inv,
        )))
    }

    /// [`Tri4::intersect`] lane by lane with the scalar test (`shapes::intersect_triangle`).
    pub(crate) fn scalar(
        &self,
        r: &RayPre,
        tmin: f32,
        mut end: Limit,
    ) -> Option<(f32, usize, f32, f32)> {
        let mut best = None;
        for (lane, &prim) in self.prim.iter().enumerate() {
            if prim == u32::MAX {
                continue;
            }
            let tri = [
                self.vertex(lane, 0),
                self.vertex(lane, 1),
                self.vertex(lane, 2),
            ];
            // Hits up to `end.t` itself, which `end` then judges.
            let found = intersect_triangle(r, &tri, tmin, end.t.next_up());
            if let Some((t, b1, b2)) = found.filter(|h| end.admits(h.0, prim)) {
                end = Limit { t, prim };
                best = Some((t, lane, b1, b2));
            }
        }
        best
    }
}

/// The lane of `mask` (not empty) first by `t`, then by primitive number `prim`.
#[inline(always)]
pub(crate) fn nearest_lane(mut mask: u32, t: &[f32], prim: impl Fn(usize) -> u32) -> usize {
    let mut best = mask.trailing_zeros() as usize;
    mask &= mask - 1;
    while mask != 0 {
        let lane = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if t[lane] < t[best] || (t[lane] == t[best] && prim(lane) < prim(best)) {
            best = lane;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::{Pcg32, Ray};

    /// A ray from and along small integer coordinates (the origin's scaled by 1.5), moved off
    /// the grid for odd `k` so that most lane tests there take the vector path; `None` for a
    /// zero direction.
    fn grid_ray(rng: &mut Pcg32, k: usize) -> Option<RayPre> {
        let coord = |rng: &mut Pcg32| (rng.next_u32() % 5) as f32 - 2.0;
        let jitter = if k.is_multiple_of(2) { 0.0 } else { 0.173 };
        let o = Vec3::new(coord(rng) + jitter, coord(rng), coord(rng)) * 1.5;
        let d = Vec3::new(coord(rng), coord(rng) - jitter, coord(rng));
        (d != Vec3::ZERO).then(|| RayPre::new(&Ray::new(o, d)))
    }

    /// Oracle: the scalar watertight test lane by lane ([`Tri4::scalar`], which calls
    /// `shapes::intersect_triangle`). The lane test finds the same hit, on small integer
    /// coordinates (edge functions exactly zero, ties, triangles of zero area) and with
    /// unused lanes; primitive numbers run against the lanes, so that ties are decided by
    /// number, not lane; and with limits at a hit's own distance.
    #[test]
    fn pack_test_equals_the_scalar_test_lane_by_lane() {
        let mut rng = Pcg32::new(5, 7);
        let coord = |rng: &mut Pcg32| (rng.next_u32() % 5) as f32 - 2.0;
        let (mut hits, mut vector, mut at_limit) = (0, 0, 0);
        for k in 0..40_000 {
            let tris: Vec<_> = (0..1 + k % 4)
                .map(|p| {
                    let mut v = || Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng));
                    ([v(), v(), v()], 10 - 3 * p as u32)
                })
                .collect();
            let pack = Tri4::new(&tris);
            let Some(pre) = grid_ray(&mut rng, k) else {
                continue;
            };
            let jitter = k % 2;
            let tmax = if k % 3 == 0 { 2.0 } else { f32::INFINITY };
            let end = Limit::end(tmax);
            let want = pack.scalar(&pre, 0.0, end);
            assert_eq!(pack.intersect(&pre, 0.0, end), want, "case {k}");
            hits += usize::from(want.is_some());
            vector += usize::from(jitter != 0 && want.is_some());
            // A limit at the hit's own distance admits the hits there on lower numbers.
            if let Some((t, lane, ..)) = want {
                for prim in [0, 1, pack.prim[lane], pack.prim[lane] + 1, 11] {
                    let end = Limit { t, prim };
                    let want = pack.scalar(&pre, 0.0, end);
                    assert_eq!(pack.intersect(&pre, 0.0, end), want, "case {k} {prim}");
                    assert!(want.is_none_or(|h| h.0 == t && pack.prim[h.1] < prim));
                    at_limit += usize::from(want.is_some());
                }
            }
        }
        assert!(
            hits > 1500 && vector > 800 && at_limit > 1000,
            "{hits} hits, {vector} off the grid, {at_limit} at a limit"
        );
    }

    /// Property: the sixteen-lane test of three or four packs returns exactly what testing
    /// the packs one after the other returns (each by [`Tri4::intersect`], whose oracle is
    /// the scalar test), or defers only where a lane's edge function is exactly zero;
    /// including rays through shared edges and vertices (small integer coordinates),
    /// distances that tie across packs (decided by interleaved primitive numbers), and
    /// packs with unused lanes.
    #[test]
    fn four_pack_test_equals_the_packs_one_by_one() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            let mut rng = Pcg32::new(17, 9);
            let coord = |rng: &mut Pcg32| (rng.next_u32() % 5) as f32 - 2.0;
            let (mut hits, mut ties, mut deferred) = (0, 0, 0);
            for k in 0..40_000 {
                let n = 3 + k % 2;
                let mut tris: Vec<Vec<_>> = (0..n)
                    .map(|q| {
                        (0..1 + (k / 2 + q) % 4)
                            .map(|p| {
                                let mut v =
                                    || Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng));
                                ([v(), v(), v()], (20 - 4 * p + q) as u32)
                            })
                            .collect()
                    })
                    .collect();
                if k % 4 < 2 {
                    // The first pack's first triangle again in the last pack, under another
                    // number: hits at one distance in two packs.
                    tris[n - 1][0].0 = tris[0][0].0;
                }
                let packs: Vec<Tri4> = tris.iter().map(|t| Tri4::new(t)).collect();
                let Some(pre) = grid_ray(&mut rng, k) else {
                    continue;
                };
                let end = Limit::end(if k % 3 == 0 { 2.0 } else { f32::INFINITY });
                let mut seq = None;
                let mut below = end;
                let mut firsts = vec![];
                for (q, pack) in packs.iter().enumerate() {
                    if let Some((t, lane, b1, b2)) = pack.intersect(&pre, 0.0, below) {
                        below = Limit {
                            t,
                            prim: pack.prim[lane],
                        };
                        seq = Some((t, 4 * q + lane, b1, b2));
                    }
                    firsts.push(pack.intersect(&pre, 0.0, end).map(|h| h.0));
                }
                let four = [&packs[0], &packs[1], &packs[2], &packs[n - 1]];
                let valid = 0xffff >> (16 - 4 * n);
                // SAFETY: AVX-512F was detected above.
                match unsafe { Tri4::intersect_four_fast(four, valid, &pre, 0.0, end) } {
                    Ok(found) => {
                        assert_eq!(found, seq, "case {k}");
                        hits += usize::from(seq.is_some());
                        let mut ts: Vec<f32> = firsts.into_iter().flatten().collect();
                        ts.sort_by(f32::total_cmp);
                        ties += usize::from(ts.windows(2).any(|w| w[0] == w[1]));
                    }
                    Err(EdgeOnZero) => {
                        assert!(
                            packs
                                .iter()
                                .any(|p| p.intersect_fast(&pre, 0.0, end).is_err()),
                            "case {k}"
                        );
                        deferred += 1;
                    }
                }
            }
            assert!(
                hits > 1500 && ties > 100 && deferred > 1000,
                "{hits} hits, {ties} ties, {deferred} deferred"
            );
        }
    }

    /// Property: the 8-wide pair test returns exactly what testing the two packs one after
    /// the other returns, including rays through shared edges and vertices (small integer
    /// coordinates make edge functions exactly zero and distances tie, decided by primitive
    /// numbers that interleave the packs') and packs with unused lanes.
    #[test]
    fn pair_test_equals_the_packs_one_by_one() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut rng = Pcg32::new(11, 3);
            let coord = |rng: &mut Pcg32| (rng.next_u32() % 5) as f32 - 2.0;
            let (mut hits, mut ties) = (0, 0);
            for k in 0..40_000 {
                let tri = |rng: &mut Pcg32, p: u32| {
                    let mut v = || Vec3::new(coord(rng), coord(rng), coord(rng));
                    ([v(), v(), v()], p)
                };
                let na = 1 + k % 4;
                let nb = 1 + (k / 4) % 4;
                let a: Vec<_> = (0..na).map(|p| tri(&mut rng, 8 - 2 * p as u32)).collect();
                let b: Vec<_> = (0..nb).map(|p| tri(&mut rng, 7 - 2 * p as u32)).collect();
                let (a, b) = (Tri4::new(&a), Tri4::new(&b));
                let o = Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng)) * 1.5;
                let d = Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng));
                if d == Vec3::ZERO {
                    continue;
                }
                let pre = RayPre::new(&Ray::new(o, d));
                let end = Limit::end(if k % 3 == 0 { 2.0 } else { f32::INFINITY });
                let first = a.intersect(&pre, 0.0, end);
                let below = first.map_or(end, |h| Limit {
                    t: h.0,
                    prim: a.prim[h.1],
                });
                let seq = match b.intersect(&pre, 0.0, below) {
                    Some((t, lane, b1, b2)) => Some((t, 4 + lane, b1, b2)),
                    None => first,
                };
                // SAFETY: AVX2 was detected above.
                let pair = unsafe { Tri4::intersect_pair_avx(&a, &b, &pre, 0.0, end) };
                assert_eq!(pair, seq, "case {k}");
                hits += usize::from(seq.is_some());
                ties += usize::from(first.is_some_and(|f| seq.is_some_and(|s| s.0 == f.0)));
            }
            assert!(hits > 2000 && ties > 100, "{hits} hits, {ties} ties");
        }
    }
}
