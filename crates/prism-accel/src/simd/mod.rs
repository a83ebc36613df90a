//! The only room that touches `std::arch`: the instruction-set [`kernel::Kernel`] a walk is
//! compiled for, chosen by type (`kernel`), the vector operations the lane code is written
//! in ([`Simd`], for AVX2 and AVX-512: `vector`), rays on lanes (`lanes`), and the
//! instruction-set kernels of the walks: the 8-wide node tests (`node8`), the triangle-pack
//! tests on 8 and 16 lanes (`tri4`), the per-ray set-up (`ray`) and the sorting network of
//! the children entered (`order`). Each kernel computes the bits of the portable code it
//! stands for.

pub(crate) mod kernel;
#[cfg(target_arch = "x86_64")]
pub(crate) mod lanes;
#[cfg(target_arch = "x86_64")]
pub(crate) mod node8;
pub(crate) mod order;
#[cfg(target_arch = "x86_64")]
mod ray;
#[cfg(target_arch = "x86_64")]
mod tri4;
#[cfg(target_arch = "x86_64")]
mod vector;

use prism_math::glam::Vec3A;

#[cfg(target_arch = "x86_64")]
pub(crate) use vector::{Avx2, Avx512, Simd};

/// The integer parts of `b`'s three lanes, each in `[0, 2^31)` (the SAH build's bins).
#[inline(always)]
pub(crate) fn bin_indices(b: Vec3A) -> [usize; 3] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128i, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of x86_64; the caller's lanes are in [0, 2^31), so truncation
        // is exact and the i32 lanes are non-negative.
        let i: [i32; 4] =
            unsafe { std::mem::transmute::<__m128i, [i32; 4]>(_mm_cvttps_epi32(b.into())) };
        [i[0] as usize, i[1] as usize, i[2] as usize]
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        [b.x as usize, b.y as usize, b.z as usize]
    }
}
