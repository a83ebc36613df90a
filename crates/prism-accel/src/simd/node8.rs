//! The 8-wide node test on AVX lanes: [`hit_avx`] (the slab test's operations, as the
//! portable `hit_sse`) and [`hit_fused`] (one fused multiply-add a plane), inlined into the
//! walks compiled for AVX2.

use crate::layout::node8::{Node8, SlabRay};

/// [`hit_sse`] with 256-bit AVX instructions: the same operations in the same order (the
/// comparison "not greater than" is `_CMP_NGT_UQ`, true for NaN), for rays that are not
/// [`SlabRay::fused`]. Inlined into the callers compiled for AVX2 and FMA (a
/// `target_feature` function could not be inlined always, and a call per node costs a
/// tenth of the traversal).
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

/// The node test for a ray of [`SlabRay::fused`], on 256-bit AVX lanes: each slab distance
/// one fused multiply-add, `p * inv + off`, one dependent step fewer on the path every
/// node waits on than [`hit_avx`]. Its distances are never shorter than the exact interval
/// (see [`SlabRay::new`]), but may differ from [`hit_avx`]'s by a rounding. No distance is
/// NaN for such a ray, so the near distances are taken in pairs, and the far ones too: the
/// entry is compared once, with the least of the far distances and `tmax` (a NaN `tmax`
/// enters nothing, as in [`hit_avx`]). Inlined as [`hit_avx`].
///
/// An unused slot's empty box (minima `+inf`, maxima `-inf`) is never entered, so the
/// test leaves out the `used` mask (one dependent step fewer): with a finite non-zero
/// `inv` and a finite offset, each of its near distances is `+inf` and each far one `-inf`.
///
/// # Safety
/// The processor must support AVX2 and FMA, and the ray must be [`SlabRay::fused`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn hit_fused(n: &Node8, r: &SlabRay, tmin: f32, tmax: f32) -> ([f32; 8], u32) {
    use std::arch::x86_64::{
        _mm256_cmp_ps, _mm256_fmadd_ps, _mm256_load_ps, _mm256_max_ps, _mm256_min_ps,
        _mm256_movemask_ps, _mm256_set1_ps, _mm256_storeu_ps, _CMP_LE_OQ,
    };
    debug_assert!(r.fused);
    // SAFETY: as in `hit_avx`; the caller ensures FMA.
    unsafe {
        macro_rules! f {
            ($plane:expr, $axis:expr, $inv:ident, $off:ident) => {
                _mm256_fmadd_ps(
                    _mm256_load_ps(n.plane($plane).as_ptr().cast::<f32>()),
                    _mm256_set1_ps(r.$inv[$axis]),
                    _mm256_set1_ps(r.$off[$axis]),
                )
            };
        }
        macro_rules! near {
            ($axis:expr) => {
                f!(r.near($axis), $axis, inv_dir, off_near)
            };
        }
        let near = _mm256_max_ps(
            _mm256_max_ps(near!(0), near!(1)),
            _mm256_max_ps(near!(2), _mm256_set1_ps(tmin)),
        );
        macro_rules! far {
            ($axis:expr) => {
                f!(r.far($axis), $axis, inv_far, off_far)
            };
        }
        // The exit, taken while the entry is computed: one comparison waits on the entry.
        let exit = _mm256_min_ps(
            _mm256_min_ps(far!(0), far!(1)),
            _mm256_min_ps(far!(2), _mm256_set1_ps(tmax)),
        );
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, exit)) as u32;
        let mut near_out = [0f32; 8];
        _mm256_storeu_ps(near_out.as_mut_ptr(), near);
        (near_out, mask)
    }
}
