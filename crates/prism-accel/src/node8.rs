//! The 8-wide BVH node and the ray-box test of its eight children: with 256-bit AVX
//! instructions when the processor has them, else as two 4-wide SSE halves. Both compute the
//! same operations in the same order, so they enter the same children with the same
//! distances and traversal is identical either way.

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
    bounds: [[Vec4; 2]; 6],
    pub(crate) child: [u32; 8],
    /// Bit i is set when slot i holds a child.
    used: u32,
    _pad: [u32; 7],
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
/// `inv_far`, `inv_dir` widened by [`FAR_WIDEN`].
pub(crate) struct SlabRay {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    inv_far: [f32; 3],
    /// The row of [`PLANES`] for the ray's direction signs.
    planes: &'static [usize; 6],
    /// The origin and `inv_dir` are finite and no `inv_dir` is zero: no slab distance is
    /// NaN.
    plain: bool,
}

/// For each set of axes a ray runs down (bit `axis` set), the byte offsets of the near
/// planes' rows of `Node8::bounds` on x, y and z, then the far planes'. Looked up rather
/// than computed per ray: a walk keeps a reference to its row.
static PLANES: [[usize; 6]; 8] = {
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
    #[inline(always)]
    pub(crate) fn new(r: &RayPre) -> SlabRay {
        // SIMD tests rather than glam's `Vec3` ones, which test component by component with
        // branches.
        let down = r.inv_dir.is_negative_bitmask() as usize & 7;
        let (o, inv) = (Vec3A::from(r.origin).abs(), Vec3A::from(r.inv_dir).abs());
        SlabRay {
            origin: r.origin.to_array(),
            inv_dir: r.inv_dir.to_array(),
            inv_far: (r.inv_dir * FAR_WIDEN).to_array(),
            planes: &PLANES[down],
            plain: (o.cmplt(Vec3A::INFINITY) & inv.cmplt(Vec3A::INFINITY) & inv.cmpgt(Vec3A::ZERO))
                .all(),
        }
    }

    /// The byte offset of the row of the plane on `axis` the ray meets first.
    #[inline(always)]
    fn near(&self, axis: usize) -> usize {
        self.planes[axis]
    }

    /// The byte offset of the row of the other plane on `axis`.
    #[inline(always)]
    fn far(&self, axis: usize) -> usize {
        self.planes[3 + axis]
    }
}

/// Bytes in one plane's row of `Node8::bounds`.
const PLANE_BYTES: usize = std::mem::size_of::<[Vec4; 2]>();

impl Node8 {
    /// The row of `bounds` at byte offset `offset`, without a bounds check.
    ///
    /// # Safety
    /// `offset` must be a multiple of [`PLANE_BYTES`] below `6 * PLANE_BYTES`, as
    /// [`SlabRay::new`] makes them.
    #[inline(always)]
    unsafe fn plane(&self, offset: usize) -> &[Vec4; 2] {
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

/// [`hit_sse`] with 256-bit AVX instructions: the same operations in the same order (the
/// comparison "not greater than" is `_CMP_NGT_UQ`, true for NaN).
/// Inlined into the callers compiled for AVX (a `target_feature` function could not be
/// inlined always, and a call per node costs a tenth of the traversal).
///
/// # Safety
/// The processor must support AVX.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn hit_avx(n: &Node8, r: &SlabRay, tmin: f32, tmax: f32) -> ([f32; 8], u32) {
    use std::arch::x86_64::{
        _mm256_and_ps, _mm256_cmp_ps, _mm256_load_ps, _mm256_max_ps, _mm256_movemask_ps,
        _mm256_mul_ps, _mm256_set1_ps, _mm256_storeu_ps, _mm256_sub_ps, _CMP_LE_OQ, _CMP_NGT_UQ,
    };
    // SAFETY: `SlabRay::new` makes every plane offset that of one of the node's rows: 32
    // bytes at a 32-byte aligned offset of a 64-byte aligned node, as `_mm256_load_ps`
    // requires; the store writes eight floats into an array of eight.
    unsafe {
        macro_rules! t {
            ($plane:expr, $axis:expr) => {
                t!($plane, $axis, inv_dir)
            };
            ($plane:expr, $axis:expr, $inv:ident) => {
                _mm256_mul_ps(
                    _mm256_sub_ps(
                        _mm256_load_ps(n.plane($plane).as_ptr().cast::<f32>()),
                        _mm256_set1_ps(r.origin[$axis]),
                    ),
                    _mm256_set1_ps(r.$inv[$axis]),
                )
            };
        }
        let near = if r.plain {
            _mm256_max_ps(
                _mm256_max_ps(t!(r.near(0), 0), t!(r.near(1), 1)),
                _mm256_max_ps(t!(r.near(2), 2), _mm256_set1_ps(tmin)),
            )
        } else {
            _mm256_max_ps(
                t!(r.near(2), 2),
                _mm256_max_ps(
                    t!(r.near(1), 1),
                    _mm256_max_ps(t!(r.near(0), 0), _mm256_set1_ps(tmin)),
                ),
            )
        };
        macro_rules! before {
            ($plane:expr, $axis:expr) => {
                _mm256_cmp_ps::<_CMP_NGT_UQ>(near, t!($plane, $axis, inv_far))
            };
        }
        let m = _mm256_and_ps(
            _mm256_and_ps(before!(r.far(0), 0), before!(r.far(1), 1)),
            _mm256_and_ps(
                before!(r.far(2), 2),
                _mm256_cmp_ps::<_CMP_LE_OQ>(near, _mm256_set1_ps(tmax)),
            ),
        );
        let mask = _mm256_movemask_ps(m) as u32;
        let mut near_out = [0f32; 8];
        _mm256_storeu_ps(near_out.as_mut_ptr(), near);
        (near_out, mask & n.used)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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

    /// Property: the SSE and AVX tests enter exactly the children the scalar interval test
    /// enters, with the same entry distances, on boxes with corners on a small integer grid
    /// and rays from grid points along axes (slab distances of 0 * inf = NaN), on box faces,
    /// and in random directions (with no NaN distance, whose entries are combined in
    /// another order).
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
            if std::arch::is_x86_feature_detected!("avx") {
                // SAFETY: AVX was detected.
                let avx = unsafe { hit_avx(&n, &slab, 0.0, tmax) };
                assert_eq!(avx.1, sse.1, "case {k}");
                assert_eq!(avx.0.map(f32::to_bits), sse.0.map(f32::to_bits), "case {k}");
            }
            entered += want.1.count_ones();
        }
        assert!(entered > 10_000, "{entered} children entered");
        assert!(
            (5000..15_000).contains(&plain),
            "{plain} rays with no NaN distance"
        );
    }
}
