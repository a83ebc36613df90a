//! [`Bvh::intersect_batch`] over the whole tree: coherent groups as packets, the rays
//! between in pairs, compiled for AVX-512 and AVX2.

use prism_math::Ray;

use super::packet::{self, Query};
use crate::hit::Hit;
use crate::layout::{Bvh, Start};
use crate::simd::kernel::{Avx, Kernel, Wide};
use crate::simd::{Avx2, Avx512, Simd};

impl Bvh {
    /// The loop of [`Bvh::intersect_batch`], inlined into each compiled variant: each group
    /// of `width` coherent rays (`packet::coherent`) takes the packet walk (`packet`, which
    /// returns the lanes it leaves to the one-ray walk); the rays between are walked in
    /// pairs.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) fn intersect_batch_with<K: Kernel>(
        &self,
        rays: &[Ray],
        (tmin, tmax): (f32, f32),
        hits: &mut [Option<Hit>],
        width: usize,
        packet: impl Fn(&Query, &mut [Option<Hit>]) -> u16,
    ) {
        // The first ray not yet walked.
        let mut loose = 0;
        let mut i = 0;
        while i + width <= rays.len() {
            let group = &rays[i..i + width];
            if packet::coherent(group, width) {
                self.intersect_pairs::<K>(&rays[loose..i], tmin, tmax, &mut hits[loose..i]);
                let query = Query {
                    rays: group,
                    tmin,
                    ends: [tmax; 16],
                    lanes: u16::MAX,
                    skip: 0,
                };
                let mut defer = packet(&query, &mut hits[i..i + width]);
                while defer != 0 {
                    let lane = defer.trailing_zeros() as usize;
                    defer &= defer - 1;
                    hits[i + lane] =
                        self.intersect_with::<K>(&group[lane], tmin, tmax, Start::ROOT);
                }
                loose = i + width;
            }
            i += width;
        }
        self.intersect_pairs::<K>(&rays[loose..], tmin, tmax, &mut hits[loose..]);
    }

    /// [`Bvh::intersect_batch`] compiled for AVX-512VL: the same 256-bit operations, with
    /// one-instruction broadcasts and twice the registers, and leaves of three or four packs
    /// tested on sixteen lanes.
    ///
    /// # Safety
    /// The processor must support AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512vl")]
    pub(crate) unsafe fn intersect_batch_avx512(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.intersect_batch_with::<Wide>(rays, (tmin, tmax), hits, Avx512::W, |q, h| {
            // SAFETY: the processor has AVX-512VL, hence AVX-512F.
            unsafe { packet::closest_avx512(self, q, h) }
        });
    }

    /// [`Bvh::intersect_batch`] compiled for AVX2 (one-instruction broadcasts).
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub(crate) unsafe fn intersect_batch_avx2(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.intersect_batch_with::<Avx>(rays, (tmin, tmax), hits, Avx2::W, |q, h| {
            // SAFETY: the processor has AVX2.
            unsafe { packet::closest_avx2(self, q, h) }
        });
    }
}
