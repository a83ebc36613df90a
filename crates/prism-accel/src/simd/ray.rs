//! [`RayPre::new_avx`]: the watertight test's per-ray values computed in AVX registers, the
//! same bits as [`RayPre::new`], with the slab test's origin and inverse direction.

use prism_math::glam::Vec3A;
use prism_math::{Ray, Vec3};

use crate::shapes::{dominant_axis, RayPre, PERMS};

/// [`PERMS`] as lane numbers for a variable permute, the fourth lane repeating `kz`.
#[cfg(target_arch = "x86_64")]
static PERM_LANES: [[i32; 4]; 6] = {
    let mut t = [[0; 4]; 6];
    let mut p = 0;
    while p < 6 {
        let [kx, ky, kz] = PERMS[p];
        t[p] = [kx as i32, ky as i32, kz as i32, kz as i32];
        p += 1;
    }
    t
};

impl RayPre {
    /// [`RayPre::new`] with AVX's in-register permutes instead of indexing arrays by the
    /// ray's axes (which round-trips each value through memory): the same values, bit for
    /// bit, in fewer instructions. Also returns the origin and `inv_dir` as vectors, for the
    /// slab set-up to take from registers rather than reload.
    ///
    /// # Safety
    /// The processor must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[must_use]
    pub(crate) unsafe fn new_avx(ray: &Ray) -> (RayPre, Vec3A, Vec3A) {
        use std::arch::x86_64::{
            __m128, _mm_blend_ps, _mm_loadu_si128, _mm_mul_ps, _mm_permute_ps, _mm_permutevar_ps,
        };
        let (d, o) = (Vec3A::from(ray.dir), Vec3A::from(ray.origin));
        // As in `new`: the dominant axis and the sign of its component (`< 0`, so a
        // negative zero counts as positive).
        let kz = dominant_axis(d.abs().to_array());
        let perm = 2 * kz + ((d.cmplt(Vec3A::ZERO).bitmask() as usize >> kz) & 1);
        let inv = d.recip();
        // SAFETY: the caller ensures AVX (which includes SSE4.1's blend); the load reads
        // one row of `PERM_LANES`.
        unsafe {
            let lanes = _mm_loadu_si128(PERM_LANES[perm].as_ptr().cast());
            let inv_k = _mm_permutevar_ps(__m128::from(inv), lanes);
            let inv_z = _mm_permute_ps::<0b10_10_10_10>(inv_k);
            let d_k = _mm_permutevar_ps(__m128::from(d), lanes);
            // `(d[kx] * inv_z, d[ky] * inv_z, inv_z)`.
            let shear = _mm_blend_ps::<0b0100>(_mm_mul_ps(d_k, inv_z), inv_z);
            let origin_k = _mm_permutevar_ps(__m128::from(o), lanes);
            let pre = RayPre {
                origin: ray.origin,
                inv_dir: Vec3::from(inv),
                perm,
                shear: Vec3::from(Vec3A::from(shear)),
                origin_k: Vec3A::from(origin_k).to_array(),
            };
            (pre, o, inv)
        }
    }
}
