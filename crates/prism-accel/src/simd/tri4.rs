//! The triangle-pack tests on wide lanes: two packs on eight AVX lanes, four packs on
//! sixteen AVX-512 lanes, each lane computing [`Tri4::intersect`]'s operations.

use crate::hit::Limit;
use crate::layout::tri4::{nearest_lane, EdgeOnZero, Tri4};
use crate::shapes::RayPre;
use crate::simd::{Avx2, Avx512, Simd};

impl Tri4 {
    /// The first hit among the eight triangles of packs `a` and `b` with `tmin < t` that
    /// `end` admits, `(t, lane, b1, b2)` with lanes 0..4 in `a` and 4..8 in `b`:
    /// [`Tri4::intersect`]'s operations on 256-bit AVX lanes, so the same hit as testing `a`
    /// and then `b` up to `a`'s hit, at about the cost of one pack.
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) unsafe fn intersect_pair_avx(
        a: &Tri4,
        b: &Tri4,
        r: &RayPre,
        tmin: f32,
        end: Limit,
    ) -> Option<(f32, usize, f32, f32)> {
        // SAFETY: the caller ensures AVX2.
        unsafe { Tri4::intersect_pair_fast(a, b, r, tmin, end) }.unwrap_or_else(|EdgeOnZero| {
            // The packs one by one, as they decide it.
            let first = a.intersect(r, tmin, end);
            let below = first.map_or(end, |h| Limit {
                t: h.0,
                prim: a.prim[h.1],
            });
            match b.intersect(r, tmin, below) {
                Some((t, lane, b1, b2)) => Some((t, 4 + lane, b1, b2)),
                None => first,
            }
        })
    }

    /// [`Tri4::intersect_pair_avx`] when no edge function of a lane is exactly zero; else
    /// [`EdgeOnZero`]. It calls no function.
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) unsafe fn intersect_pair_fast(
        a: &Tri4,
        b: &Tri4,
        r: &RayPre,
        tmin: f32,
        end: Limit,
    ) -> Result<Option<(f32, usize, f32, f32)>, EdgeOnZero> {
        use std::arch::x86_64::{_mm256_set1_ps, _mm256_set_m128, _mm256_sub_ps, _mm_load_ps};
        let axes = r.axes();
        let o = r.origin_k;
        // SAFETY: the caller ensures AVX2; each load reads one aligned `Vec4` of a pack (a
        // pack is 32-byte aligned and its vectors sit at multiples of 16 bytes).
        unsafe {
            // Macros, not closures: a closure is compiled apart, without AVX.
            // Vertex `$i`'s coordinate on sheared axis `$k`, less the origin's.
            macro_rules! rel {
                ($i:expr, $k:expr) => {
                    _mm256_sub_ps(
                        _mm256_set_m128(
                            _mm_load_ps(b.v[$i][axes[$k]].as_ref().as_ptr()),
                            _mm_load_ps(a.v[$i][axes[$k]].as_ref().as_ptr()),
                        ),
                        _mm256_set1_ps(o[$k]),
                    )
                };
            }
            let rel = [
                [rel!(0, 0), rel!(0, 1), rel!(0, 2)],
                [rel!(1, 0), rel!(1, 1), rel!(1, 2)],
                [rel!(2, 0), rel!(2, 1), rel!(2, 2)],
            ];
            let prim = |lane: usize| {
                if lane < 4 {
                    a.prim[lane]
                } else {
                    b.prim[lane - 4]
                }
            };
            lanes_fast::<Avx2>(rel, r, 0xff, (tmin, end), prim)
        }
    }

    /// [`Tri4::intersect_pair_fast`] over the sixteen lanes of four packs at once with
    /// 512-bit AVX-512 vectors: lanes `4k..4k + 4` are pack `k`'s, and only the lanes of
    /// `valid` may hit (a leaf of three packs names its third again as the fourth). The same
    /// operations lane by lane, so the same hit as testing the packs one after another.
    ///
    /// # Safety
    /// The processor must support AVX-512F.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) unsafe fn intersect_four_fast(
        packs: [&Tri4; 4],
        valid: u16,
        r: &RayPre,
        tmin: f32,
        end: Limit,
    ) -> Result<Option<(f32, usize, f32, f32)>, EdgeOnZero> {
        use std::arch::x86_64::{
            _mm512_castps128_ps512, _mm512_insertf32x4, _mm512_set1_ps, _mm512_sub_ps, _mm_load_ps,
        };
        let axes = r.axes();
        let o = r.origin_k;
        // SAFETY: the caller ensures AVX-512F; each load reads one aligned `Vec4` of a pack.
        unsafe {
            // Vertex `$i`'s coordinate on sheared axis `$k`, less the origin's (a macro, as
            // in `intersect_pair_fast`).
            macro_rules! rel {
                ($i:expr, $k:expr) => {{
                    let axis = axes[$k];
                    macro_rules! quarter {
                        ($p:expr) => {
                            _mm_load_ps(packs[$p].v[$i][axis].as_ref().as_ptr())
                        };
                    }
                    let mut x = _mm512_castps128_ps512(quarter!(0));
                    x = _mm512_insertf32x4::<1>(x, quarter!(1));
                    x = _mm512_insertf32x4::<2>(x, quarter!(2));
                    x = _mm512_insertf32x4::<3>(x, quarter!(3));
                    _mm512_sub_ps(x, _mm512_set1_ps(o[$k]))
                }};
            }
            let rel = [
                [rel!(0, 0), rel!(0, 1), rel!(0, 2)],
                [rel!(1, 0), rel!(1, 1), rel!(1, 2)],
                [rel!(2, 0), rel!(2, 1), rel!(2, 2)],
            ];
            let prim = |lane: usize| packs[lane / 4].prim[lane % 4];
            lanes_fast::<Avx512>(rel, r, valid, (tmin, end), prim)
        }
    }
}

/// [`Tri4::intersect`]'s operations on the lanes of `S`, four lanes per pack: the first
/// hit with `tmin < t` that `end` admits among the lanes of `valid`, `(t, lane, b1, b2)`, or
/// [`EdgeOnZero`] if an edge function of one of those lanes is exactly zero. `rel[i][k]`
/// holds vertex `i`'s coordinates on the ray's sheared axis `k`, less the origin's; `prim`
/// gives a lane's primitive number. It calls no function.
///
/// # Safety
/// The processor must support `S`'s instruction set.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn lanes_fast<S: Simd>(
    rel: [[S::F; 3]; 3],
    r: &RayPre,
    valid: u16,
    (tmin, end): (f32, Limit),
    prim: impl Fn(usize) -> u32,
) -> Result<Option<(f32, usize, f32, f32)>, EdgeOnZero> {
    // SAFETY: the caller ensures `S`'s instruction set.
    unsafe {
        let (sub, mul) = (S::sub, S::mul);
        let (sx, sy, sz) = (
            S::splat(r.shear.x),
            S::splat(r.shear.y),
            S::splat(r.shear.z),
        );
        let [[ax, ay, az], [bx, by, bz], [cx, cy, cz]] = rel;
        let (ax, ay) = (sub(ax, mul(sx, az)), sub(ay, mul(sy, az)));
        let (bx, by) = (sub(bx, mul(sx, bz)), sub(by, mul(sy, bz)));
        let (cx, cy) = (sub(cx, mul(sx, cz)), sub(cy, mul(sy, cz)));
        let u = sub(mul(cx, by), mul(cy, bx));
        let v = sub(mul(ax, cy), mul(ay, cx));
        let w = sub(mul(bx, ay), mul(by, ax));
        let zero = S::splat(0.0);
        let on_zero = S::or(S::or(S::eq(u, zero), S::eq(v, zero)), S::eq(w, zero));
        if S::bits(on_zero) & valid != 0 {
            return Err(EdgeOnZero);
        }
        // No edge function is zero: a lane is inside when the three share a sign bit. Most
        // tests have no such lane and stop before the division. The sum `det` of three
        // numbers of one sign, none zero, is not zero. A lane with a NaN edge function may
        // pass, but then its `t` is NaN and fails both comparisons with the ends.
        let inside = !S::sign_differs(u, v, w) & valid;
        if inside == 0 {
            return Ok(None);
        }
        let det = S::add(S::add(u, v), w);
        let dist = S::add(S::add(mul(u, az), mul(v, bz)), mul(w, cz));
        let t = mul(mul(sz, dist), S::div(S::splat(1.0), det));
        let within = S::and(S::gt(t, S::splat(tmin)), S::le(t, S::splat(end.t)));
        let mask = u32::from(inside & S::bits(within));
        if mask == 0 {
            return Ok(None);
        }
        // Lanes in memory, each array exactly as wide as the vectors, so that the store
        // fills it (a zeroed remainder would cost stores).
        let lanes = |x: S::F| {
            let mut a = S::Floats::default();
            S::store(x, a.as_mut());
            a
        };
        let ta = lanes(t);
        let ta = ta.as_ref();
        let best = nearest_lane(mask, ta, &prim);
        if !end.admits(ta[best], prim(best)) {
            return Ok(None);
        }
        let inv = 1.0 / lanes(det).as_ref()[best];
        Ok(Some((
            ta[best],
            best,
            lanes(v).as_ref()[best] * inv,
            lanes(w).as_ref()[best] * inv,
        )))
    }
}
