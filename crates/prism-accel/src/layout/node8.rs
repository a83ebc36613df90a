//! The 8-wide BVH node and the ray-box test of its eight children: with 256-bit AVX2 and FMA
//! instructions when the processor has them, else as two 4-wide SSE halves. The two measure
//! slab distances in different roundings (the AVX2 test fuses a multiply and an add), both
//! never shorter than the exact interval, so each enters every child the ray meets; the
//! walks' hits do not depend on which children they enter or in what order (the closest
//! hit is the first by distance, then primitive number), so they are the same either way.

use prism_math::glam::{Vec3A, Vec4};
use prism_math::{Aabb, Vec3};

use crate::shapes::RayPre;

/// A flattened 8-wide node: 256 bytes (four whole cache lines). `bounds[plane]` holds one
/// plane of the eight child boxes (planes: x, y, z minima, then x, y, z maxima) as two
/// halves of four lanes. A child reference is a node index or a leaf reference; unused
/// slots hold empty boxes and are left out of `used`.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Node8 {
    pub(crate) bounds: [[Vec4; 2]; 6],
    pub(crate) child: [u32; 8],
    /// Bit i is set when slot i holds a child.
    pub(crate) used: u32,
    pub(crate) _pad: [u32; 7],
}

impl Node8 {
    /// A node with no children.
    pub(crate) fn empty() -> Node8 {
        let inf = [Vec4::INFINITY; 2];
        let neg = [Vec4::NEG_INFINITY; 2];
        Node8 {
            bounds: [inf, inf, inf, neg, neg, neg],
            child: [u32::MAX; 8],
            used: 0,
            _pad: [0; 7],
        }
    }

    /// Puts a child with box `b` in `slot`.
    pub(crate) fn set(&mut self, slot: usize, b: Aabb, child: u32) {
        let (half, lane) = (slot / 4, slot % 4);
        for axis in 0..3 {
            self.bounds[axis][half][lane] = b.min[axis];
            self.bounds[3 + axis][half][lane] = b.max[axis];
        }
        self.child[slot] = child;
        self.used |= 1 << slot;
    }

    /// Bit i is set when slot i holds a child.
    pub(crate) fn used(&self) -> u32 {
        self.used
    }

    /// True if `slot` holds a child.
    pub(crate) fn slot_used(&self, slot: usize) -> bool {
        self.used & (1 << slot) != 0
    }

    /// The box of the child in `slot` (the empty box for an unused slot).
    pub(crate) fn child_box(&self, slot: usize) -> Aabb {
        let (half, lane) = (slot / 4, slot % 4);
        // Array elements: indexing a `Vec4` itself is a branch on the index.
        let plane = |p: usize| self.bounds[p][half].as_ref()[lane];
        Aabb {
            min: Vec3::new(plane(0), plane(1), plane(2)),
            max: Vec3::new(plane(3), plane(4), plane(5)),
        }
    }
}

/// A ray prepared for slab tests, `t = (p - origin) * inv_dir`: for each axis, the plane of
/// a box the ray meets first and the other one, as byte offsets of their rows in
/// `Node8::bounds` ([`SlabRay::near`], [`SlabRay::far`]). Far slabs are measured with
/// `inv_far`, `inv_dir` widened by [`FAR_WIDEN`]. The fused test ([`hit_fused`]) measures
/// `t = p * inv_dir + off_near` (far: `p * inv_far + off_far`) in one rounding instead.
pub(crate) struct SlabRay {
    pub(crate) origin: [f32; 3],
    pub(crate) inv_dir: [f32; 3],
    pub(crate) inv_far: [f32; 3],
    /// `-origin * inv_dir`, moved down past its rounding (see [`SlabRay::new`]).
    pub(crate) off_near: [f32; 3],
    /// `-origin * inv_far`, moved up past its rounding.
    pub(crate) off_far: [f32; 3],
    /// The row of [`PLANES`] for the ray's direction signs.
    pub(crate) planes: &'static [usize; 6],
    /// The origin and `inv_dir` are finite and no `inv_dir` is zero: no slab distance is
    /// NaN.
    pub(crate) plain: bool,
    /// `plain`, and the offsets are finite: the fused test applies.
    pub(crate) fused: bool,
}

/// For each set of axes a ray runs down (bit `axis` set), the byte offsets of the near
/// planes' rows of `Node8::bounds` on x, y and z, then the far planes'. Looked up rather
/// than computed per ray: a walk keeps a reference to its row.
pub(crate) static PLANES: [[usize; 6]; 8] = {
    let mut table = [[0; 6]; 8];
    let mut down = 0;
    while down < 8 {
        let mut axis = 0;
        while axis < 3 {
            let neg = (down >> axis) & 1;
            table[down][axis] = (axis + 3 * neg) * PLANE_BYTES;
            table[down][3 + axis] = (axis + 3 * (1 - neg)) * PLANE_BYTES;
            axis += 1;
        }
        down += 1;
    }
    table
};

impl SlabRay {
    /// The slab values of ray `r`.
    ///
    /// The fused test's offsets: `a = origin * inv` is rounded by at most half an ulp (and
    /// an absolute 2^-150 if subnormal), so `a + |a| * OFFSET_SLACK + MIN_POSITIVE`, rounded,
    /// is at least the exact product (the slack, eight times the rounding, covers both
    /// roundings; `MIN_POSITIVE` the subnormal case). Its negation `off_near` is then at
    /// most `-origin * inv` exactly, and `p * inv + off_near` at most the exact
    /// `(p - origin) * inv`: one rounding of that sum is no larger than one rounding of the
    /// exact distance, within Ize's margin ([`FAR_WIDEN`]) as the unfused test is.
    /// Likewise `off_far` is at least `-origin * inv_far`, and far distances are never
    /// shorter.
    #[inline(always)]
    pub(crate) fn new(r: &RayPre) -> SlabRay {
        SlabRay::from_vectors(Vec3A::from(r.origin), Vec3A::from(r.inv_dir))
    }

    /// [`SlabRay::new`] from the ray's origin and `1 / dir` (as [`RayPre`] holds them).
    #[inline(always)]
    pub(crate) fn from_vectors(origin: Vec3A, inv_dir: Vec3A) -> SlabRay {
        // SIMD tests rather than glam's `Vec3` ones, which test component by component with
        // branches.
        let down = inv_dir.is_negative_bitmask() as usize & 7;
        let inv_far = inv_dir * FAR_WIDEN;
        let plain = ((zero_if_finite(origin) + zero_if_finite(inv_dir)).cmpeq(Vec3A::ZERO)
            & inv_dir.cmpne(Vec3A::ZERO))
        .all();
        let slack = |a: Vec3A| a.abs() * OFFSET_SLACK + Vec3A::splat(f32::MIN_POSITIVE);
        let (a, af) = (origin * inv_dir, origin * inv_far);
        let off_near = -(a + slack(a));
        let off_far = slack(af) - af;
        let finite = (zero_if_finite(off_near) + zero_if_finite(off_far))
            .cmpeq(Vec3A::ZERO)
            .all();
        SlabRay {
            origin: Vec3::from(origin).to_array(),
            inv_dir: Vec3::from(inv_dir).to_array(),
            inv_far: inv_far.to_array(),
            off_near: off_near.to_array(),
            off_far: off_far.to_array(),
            planes: &PLANES[down],
            plain,
            fused: plain && finite,
        }
    }

    /// True if the fused test ([`hit_fused`]) applies to the ray.
    #[inline(always)]
    pub(crate) fn fused(&self) -> bool {
        self.fused
    }

    /// The byte offset of the row of the plane on `axis` the ray meets first.
    #[inline(always)]
    pub(crate) fn near(&self, axis: usize) -> usize {
        self.planes[axis]
    }

    /// The byte offset of the row of the other plane on `axis`.
    #[inline(always)]
    pub(crate) fn far(&self, axis: usize) -> usize {
        self.planes[3 + axis]
    }
}

/// `v - v`: zero in each finite lane, NaN in an infinite or NaN one, so a sum of these is
/// zero exactly where every term is finite (one instruction, where comparing absolute
/// values with infinity takes three).
#[inline(always)]
#[allow(clippy::eq_op)]
pub(crate) fn zero_if_finite(v: Vec3A) -> Vec3A {
    v - v
}

/// The fused test's slack on `origin * inv_dir`: eight times its rounding (2^-21).
pub(crate) const OFFSET_SLACK: f32 = 1.0 / 2_097_152.0;

/// Bytes in one plane's row of `Node8::bounds`.
pub(crate) const PLANE_BYTES: usize = std::mem::size_of::<[Vec4; 2]>();

impl Node8 {
    /// The row of `bounds` at byte offset `offset`, without a bounds check.
    ///
    /// # Safety
    /// `offset` must be a multiple of [`PLANE_BYTES`] below `6 * PLANE_BYTES`, as
    /// [`SlabRay::new`] makes them.
    #[inline(always)]
    pub(crate) unsafe fn plane(&self, offset: usize) -> &[Vec4; 2] {
        debug_assert!(offset.is_multiple_of(PLANE_BYTES) && offset < 6 * PLANE_BYTES);
        // SAFETY: the caller passes the offset of one of the six rows.
        unsafe {
            &*self
                .bounds
                .as_ptr()
                .cast::<u8>()
                .add(offset)
                .cast::<[Vec4; 2]>()
        }
    }
}

/// Rounding in the slab test may shrink the interval by a few ulps; widening the far end by
/// this factor keeps hits on box faces (Ize, "Robust BVH Ray Traversal", JCGT 2013, asks
/// for `1 + 2 gamma_3`, about `1 + 3 EPSILON`). The tests widen the inverse direction of
/// the far slabs rather than each far distance: `(p - origin) * (inv_dir * FAR_WIDEN)` is
/// three roundings from the exact widened distance, at least `1 + 4 EPSILON` times the
/// exact far distance, still more than Ize's margin.
pub(crate) const FAR_WIDEN: f32 = 1.0 + 2.0 * 3.0 * f32::EPSILON;

/// `t` moved up by 1/1024 of its size and by the smallest normal float: past a distance by
/// far more than the slab and triangle tests' rounding (subnormal distances included).
/// Walks enter every child whose entry is no farther than the nearest hit so widened, so a
/// hit a few ulps short of its box's computed entry is never lost, nor one at the nearest
/// distance itself (which may come first by its primitive number), whatever order the
/// children are visited in: walks in any order find the same nearest hit.
#[inline(always)]
pub(crate) fn widen(t: f32) -> f32 {
    t + t.abs() * (1.0 / 1024.0) + f32::MIN_POSITIVE
}

/// Entry distances of the ray into the eight child boxes, and which it enters (with an entry
/// in `[tmin, tmax]`), by 4-wide SSE halves.
///
/// The entry is the largest near-slab distance (and `tmin`); a child is entered when the
/// entry is at most each far-slab distance (measured with the widened inverse direction,
/// [`FAR_WIDEN`]), and at most `tmax`. Comparing with each far distance, rather than with
/// their minimum, gives the same answer in fewer dependent steps: the test waits on the
/// entry alone.
///
/// A slab distance is NaN (0 * inf) for a ray lying in a slab's plane, and that slab does not
/// cut the interval: SSE and AVX max return their second operand when either is NaN, so with
/// the slab value first a NaN drops out of the entry, and a far slab counts as passed when
/// the entry is not greater than it (true when it is NaN). For a [`SlabRay`] with no NaN
/// distance (`plain`: every ray but those parallel to an axis plane), the near distances
/// are instead taken in pairs, `max(max(x, y), max(z, tmin))`: the same value (max of
/// numbers picks the same number in any order, up to the sign of a zero, which no
/// comparison sees), two dependent steps rather than three on the path every node waits on.
#[inline(always)]
pub(crate) fn hit_sse(n: &Node8, r: &SlabRay, tmin: f32, tmax: f32) -> ([f32; 8], u32) {
    let mut near_out = [0f32; 8];
    let mut mask = 0;
    for half in 0..2 {
        let slab = |plane: usize, axis: usize, inv: &[f32; 3]| {
            // SAFETY: `SlabRay::new` makes every plane offset one of a row.
            let b = unsafe { n.plane(plane) };
            (b[half] - Vec4::splat(r.origin[axis])) * Vec4::splat(inv[axis])
        };
        let t = |plane: usize, axis: usize| slab(plane, axis, &r.inv_dir);
        let near = if r.plain {
            t(r.near(0), 0)
                .max(t(r.near(1), 1))
                .max(t(r.near(2), 2).max(Vec4::splat(tmin)))
        } else {
            t(r.near(2), 2).max(t(r.near(1), 1).max(t(r.near(0), 0).max(Vec4::splat(tmin))))
        };
        let before = |plane: usize, axis: usize| !near.cmpgt(slab(plane, axis, &r.inv_far));
        let enters = (before(r.far(0), 0) & before(r.far(1), 1))
            & (before(r.far(2), 2) & near.cmple(Vec4::splat(tmax)));
        near_out[4 * half..4 * half + 4].copy_from_slice(&near.to_array());
        mask |= enters.bitmask() << (4 * half);
    }
    (near_out, mask & n.used)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[cfg(target_arch = "x86_64")]
    use crate::simd::node8::{hit_avx, hit_fused};
    use prism_math::{Pcg32, Ray};

    /// The slab test written out per child in scalar arithmetic, as the interval
    /// `[max(near slabs, tmin), min(far slabs, tmax)]`, far slabs measured with the inverse
    /// direction times `FAR_WIDEN`, NaN slabs left out: the reference the vector tests must
    /// match child for child.
    fn reference(n: &Node8, ray: &Ray, tmin: f32, tmax: f32) -> ([f32; 8], u32) {
        let inv = ray.dir.recip();
        let inv_far = inv * FAR_WIDEN;
        let (mut near_out, mut mask) = ([0f32; 8], 0);
        for (slot, out) in near_out.iter_mut().enumerate() {
            let b = n.child_box(slot);
            let (mut near, mut far) = (tmin, f32::INFINITY);
            for axis in 0..3 {
                let (lo, hi) = if inv[axis].is_sign_negative() {
                    (b.max[axis], b.min[axis])
                } else {
                    (b.min[axis], b.max[axis])
                };
                let tn = (lo - ray.origin[axis]) * inv[axis];
                let tf = (hi - ray.origin[axis]) * inv_far[axis];
                if !tn.is_nan() {
                    near = near.max(tn);
                }
                if !tf.is_nan() {
                    far = far.min(tf);
                }
            }
            *out = near;
            if near <= far.min(tmax) && n.slot_used(slot) {
                mask |= 1 << slot;
            }
        }
        (near_out, mask)
    }

    /// The AVX test the walks take for `slab` ([`hit_fused`] or [`hit_avx`]) where the
    /// processor has AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    fn avx_test(n: &Node8, slab: &SlabRay, tmax: f32) -> Option<([f32; 8], u32)> {
        #[target_feature(enable = "avx2,fma")]
        unsafe fn run(n: &Node8, slab: &SlabRay, tmax: f32) -> ([f32; 8], u32) {
            // SAFETY: compiled for AVX2 and FMA, which the caller detected; the fused test
            // only for a fused ray.
            unsafe {
                if slab.fused() {
                    hit_fused(n, slab, 0.0, tmax)
                } else {
                    hit_avx(n, slab, 0.0, tmax)
                }
            }
        }
        let has = std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
        // SAFETY: AVX2 and FMA were detected.
        has.then(|| unsafe { run(n, slab, tmax) })
    }

    /// The interval test in double precision, with `1 / dir` exact to its rounding: the
    /// children a ray meets, and its entry distance into each.
    fn exact(n: &Node8, ray: &Ray, tmax: f32) -> ([f64; 8], u32) {
        let (mut near_out, mut mask) = ([0f64; 8], 0);
        for (slot, out) in near_out.iter_mut().enumerate() {
            let b = n.child_box(slot);
            let (mut near, mut far) = (0f64, f64::from(tmax));
            for axis in 0..3 {
                let (o, d) = (f64::from(ray.origin[axis]), f64::from(ray.dir[axis]));
                let (lo, hi) = (f64::from(b.min[axis]), f64::from(b.max[axis]));
                if d == 0.0 {
                    if o < lo || o > hi {
                        far = -1.0;
                    }
                    continue;
                }
                let (t1, t2) = ((lo - o) / d, (hi - o) / d);
                near = near.max(t1.min(t2));
                far = far.min(t1.max(t2));
            }
            *out = near;
            if near <= far && n.slot_used(slot) {
                mask |= 1 << slot;
            }
        }
        (near_out, mask)
    }

    /// The fused test against the exact one: it enters every child the ray meets, with an
    /// entry no later than the exact one (up to `1 / dir`'s rounding), and it enters
    /// children the ray misses only when it passes within a rounding of them (checked by
    /// counting, in the callers).
    fn fused_checks(
        n: &Node8,
        ray: &Ray,
        tmax: f32,
        got: ([f32; 8], u32),
        want: &([f32; 8], u32),
        k: usize,
    ) {
        let (exact_near, exact_mask) = exact(n, ray, tmax);
        assert_eq!(
            exact_mask & !got.1,
            0,
            "case {k}: a child met is not entered"
        );
        for slot in (0..8).filter(|s| got.1 & exact_mask & (1 << s) != 0) {
            let (e, g) = (exact_near[slot], f64::from(got.0[slot]));
            assert!(
                g <= e + e.abs() * 1e-6 + 1e-30,
                "case {k} slot {slot}: {g} after {e}"
            );
            let w = f64::from(want.0[slot]);
            assert!(
                (g - w).abs() <= w.abs() * 1e-5 + 1e-5,
                "case {k} slot {slot}: {g} vs {w}"
            );
        }
    }

    /// Property: the SSE test (and the AVX one, unfused) enters exactly the children the
    /// scalar interval test enters, with the same entry distances, on boxes with corners on
    /// a small integer grid and rays from grid points along axes (slab distances of
    /// 0 * inf = NaN), on box faces, and in random directions (with no NaN distance, whose
    /// entries are combined in another order). The fused AVX test enters every child the
    /// double-precision interval test enters ([`fused_checks`]).
    #[test]
    fn node_tests_match_the_scalar_interval_test() {
        let mut rng = Pcg32::new(3, 9);
        let (mut entered, mut plain) = (0, 0);
        for k in 0..20_000 {
            let mut grid = || (rng.next_u32() % 7) as f32 - 3.0;
            let mut n = Node8::empty();
            for slot in 0..8 {
                if slot == 0 || grid() > -2.0 {
                    let a = Vec3::new(grid(), grid(), grid());
                    let b = Vec3::new(grid(), grid(), grid());
                    n.set(
                        slot,
                        Aabb {
                            min: a.min(b),
                            max: a.max(b),
                        },
                        slot as u32,
                    );
                }
            }
            let origin = Vec3::new(grid(), grid(), grid());
            let dir = match k % 3 {
                0 => [Vec3::X, -Vec3::Y, Vec3::Z, -Vec3::X][k % 4],
                1 => Vec3::new(grid(), grid(), grid()),
                _ => Vec3::new(grid() + 0.37, grid() - 0.21, grid() + 0.05),
            };
            if dir == Vec3::ZERO {
                continue;
            }
            let ray = Ray::new(origin, dir);
            let slab = SlabRay::new(&RayPre::new(&ray));
            plain += usize::from(slab.plain);
            let tmax = if k % 5 == 0 { 2.5 } else { f32::INFINITY };
            let want = reference(&n, &ray, 0.0, tmax);
            let sse = hit_sse(&n, &slab, 0.0, tmax);
            assert_eq!(sse.1, want.1, "case {k}");
            for slot in 0..8 {
                if want.1 & (1 << slot) != 0 {
                    assert_eq!(sse.0[slot], want.0[slot], "case {k} slot {slot}");
                }
            }
            #[cfg(target_arch = "x86_64")]
            if let Some(avx) = avx_test(&n, &slab, tmax) {
                if slab.fused {
                    fused_checks(&n, &ray, tmax, avx, &want, k);
                } else {
                    assert_eq!(avx.1, sse.1, "case {k}");
                    assert_eq!(avx.0.map(f32::to_bits), sse.0.map(f32::to_bits), "case {k}");
                }
            }
            entered += want.1.count_ones();
        }
        assert!(entered > 10_000, "{entered} children entered");
        assert!(
            (5000..15_000).contains(&plain),
            "{plain} rays with no NaN distance"
        );
    }

    /// Property: the fused test, which skips the `used` mask, enters no unused slot, for
    /// every fused ray (origins and directions from tiny to huge, every sign) and every
    /// query interval, whatever the used slots hold.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn fused_test_never_enters_an_unused_slot() {
        #[target_feature(enable = "avx2,fma")]
        unsafe fn run(n: &Node8, s: &SlabRay, tmin: f32, tmax: f32) -> u32 {
            // SAFETY: compiled for AVX2 and FMA, which the caller detected; the ray is fused.
            unsafe { hit_fused(n, s, tmin, tmax).1 }
        }
        if !(std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma"))
        {
            return;
        }
        let mut rng = Pcg32::new(23, 5);
        let mut fused = 0;
        for k in 0..20_000 {
            let mut f = |s: f32| (rng.next_f32() * 2.0 - 1.0) * s;
            let mut n = Node8::empty();
            let used = (k as u32 * 37) % 255;
            for slot in (0..8).filter(|s| used & (1 << s) != 0) {
                let c = Vec3::new(f(4.0), f(4.0), f(4.0));
                n.set(
                    slot,
                    Aabb {
                        min: c - Vec3::ONE,
                        max: c + Vec3::ONE,
                    },
                    slot as u32,
                );
            }
            let scale = [1e-30, 1e-3, 1.0, 1e6, 1e30][k % 5];
            let dir_scale = [1e-20, 1.0, 1e20][k % 3];
            let origin = Vec3::new(f(scale), f(scale), f(scale));
            let dir = Vec3::new(f(dir_scale), f(dir_scale), f(dir_scale));
            let ray = Ray::new(origin, dir);
            let slab = SlabRay::new(&RayPre::new(&ray));
            if !slab.fused {
                continue;
            }
            fused += 1;
            for (tmin, tmax) in [(0.0, f32::INFINITY), (-f32::MAX, f32::MAX), (0.0, 1.0)] {
                // SAFETY: AVX2 and FMA were detected; the ray is fused.
                let mask = unsafe { run(&n, &slab, tmin, tmax) };
                assert_eq!(mask & !used, 0, "case {k}: unused slot entered ({ray:?})");
            }
        }
        assert!(fused > 15_000, "{fused} fused rays");
    }

    /// Property: the fused test enters every child the double-precision interval test
    /// enters, on boxes and rays of random floats (no grid), with origins near the boxes
    /// and far from them (where `origin * inv` is large against the distances, so its
    /// rounding matters), and enters few others.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn fused_test_enters_every_child_the_ray_meets() {
        let mut rng = Pcg32::new(17, 2);
        // Per distance of the origins: children met, entered but not met, by the unfused test.
        let (mut met, mut extra, mut sse_extra) = ([0usize; 3], [0usize; 3], [0usize; 3]);
        let mut fused = 0;
        for k in 0..30_000 {
            let mut f = |s: f32| (rng.next_f32() * 2.0 - 1.0) * s;
            let mut n = Node8::empty();
            for slot in 0..8 {
                let c = Vec3::new(f(4.0), f(4.0), f(4.0));
                let e = Vec3::new(f(1.0).abs(), f(1.0).abs(), f(1.0).abs());
                n.set(
                    slot,
                    Aabb {
                        min: c - e,
                        max: c + e,
                    },
                    slot as u32,
                );
            }
            let far = [1.0, 1e3, 1e6][k % 3];
            let origin = Vec3::new(f(far), f(far), f(far));
            // Aimed at a box's centre, offset by up to a box's size.
            let target = n.child_box(k % 8).centroid() + Vec3::new(f(1.5), f(1.5), f(1.5));
            let ray = Ray::new(origin, target - origin);
            let slab = SlabRay::new(&RayPre::new(&ray));
            let tmax = if k % 4 == 0 {
                (target - origin).length() / ray.dir.length()
            } else {
                f32::INFINITY
            };
            let Some(got) = avx_test(&n, &slab, tmax) else {
                return;
            };
            if !slab.fused {
                continue;
            }
            fused += 1;
            let want = hit_sse(&n, &slab, 0.0, tmax);
            fused_checks(&n, &ray, tmax, got, &want, k);
            let exact_mask = exact(&n, &ray, tmax).1;
            let class = k % 3;
            met[class] += exact_mask.count_ones() as usize;
            extra[class] += (got.1 & !exact_mask).count_ones() as usize;
            sse_extra[class] += (want.1 & !exact_mask).count_ones() as usize;
        }
        assert!(
            fused > 29_000 && met.iter().all(|&m| m > 1000),
            "{fused} fused rays, {met:?} children met"
        );
        // Near the boxes, next to no extra child; a million box sizes away (where the
        // origin's own rounding is a sixteenth of a box), a few times the unfused test's.
        assert!(
            (extra[0] + extra[1]) * 100 <= met[0] + met[1] && extra[2] <= 4 * sse_extra[2],
            "{extra:?} children entered but not met, of {met:?} (unfused {sse_extra:?})"
        );
    }
}
