//! The public queries ([`Bvh::intersect`], [`Bvh::occluded`] and their batches) and their
//! dispatch to the walks compiled for the processor's instruction set. The walks live in
//! the rooms below: `single` (one ray), `leaf` (leaf tests), `pairs` (two incoherent rays
//! in turn), `packet` and `packet_batch` (coherent groups on lanes), `root_list` and
//! `list_batch` (the root's list on lanes), over the stack of `stack`.

mod leaf;
#[cfg(target_arch = "x86_64")]
mod list_batch;
#[cfg(target_arch = "x86_64")]
mod packet;
#[cfg(target_arch = "x86_64")]
mod packet_batch;
mod pairs;
#[cfg(target_arch = "x86_64")]
mod root_list;
mod single;
mod stack;

use prism_math::{Isa, Ray};

use crate::hit::Hit;
use crate::layout::{Bvh, Start};
#[cfg(target_arch = "x86_64")]
use crate::simd::kernel::{Avx, Wide};
use crate::simd::kernel::{Kernel, Sse};

impl Bvh {
    /// The closest hit with `tmin < t < tmax`; of primitives at one distance, the one with the
    /// lowest number (so the hit does not depend on the hierarchy's shape).
    #[must_use]
    pub fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        #[cfg(target_arch = "x86_64")]
        {
            if Isa::avx512() {
                // SAFETY: the processor has AVX-512VL.
                return unsafe { self.intersect_avx512(ray, tmin, tmax) };
            }
            if Isa::avx2() {
                // SAFETY: the processor has AVX2 and FMA.
                return unsafe { self.intersect_avx(ray, tmin, tmax) };
            }
        }
        self.intersect_sse(ray, tmin, tmax)
    }

    /// [`Bvh::intersect`] without AVX. Never inlined: inlined, its walk's frame (a traversal
    /// stack of kilobytes) would be set up at every call, whichever walk the call takes.
    #[inline(never)]
    pub(crate) fn intersect_sse(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        self.intersect_with::<Sse>(ray, tmin, tmax, Start::ROOT)
    }

    /// [`Bvh::intersect`] compiled for AVX-512VL: the same 256-bit operations, with twice
    /// the registers, and leaves of three or four packs tested on sixteen lanes
    /// (the [`Wide`] kernel).
    ///
    /// # Safety
    /// The processor must support AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512vl")]
    pub(crate) unsafe fn intersect_avx512(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        self.intersect_with::<Wide>(ray, tmin, tmax, Start::ROOT)
    }

    /// [`Bvh::intersect`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub(crate) unsafe fn intersect_avx(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        self.intersect_with::<Avx>(ray, tmin, tmax, Start::ROOT)
    }

    /// [`Bvh::intersect`] for each ray of `rays` (`hits[i]` for `rays[i]`), in one call:
    /// the same hits, with the per-call work done once for the whole batch.
    ///
    /// # Panics
    /// If `hits` is not as long as `rays`.
    pub fn intersect_batch(&self, rays: &[Ray], tmin: f32, tmax: f32, hits: &mut [Option<Hit>]) {
        self.intersect_batch_on(Isa::get(), rays, tmin, tmax, hits);
    }

    /// [`Bvh::intersect_batch`] on the code paths of instruction set `isa` (or of the
    /// processor, if it has less): the same hits on every level.
    ///
    /// # Panics
    /// If `hits` is not as long as `rays`.
    pub fn intersect_batch_on(
        &self,
        isa: Isa,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        assert_eq!(rays.len(), hits.len());
        if self.nodes.is_empty() {
            hits.fill(None);
            return;
        }
        let isa = isa.min(Isa::get());
        #[cfg(target_arch = "x86_64")]
        {
            if isa >= Isa::Avx512 {
                if let Some(flat) = &self.root_list {
                    // SAFETY: the processor has AVX-512VL, hence AVX-512F.
                    return unsafe { self.intersect_batch_flat(flat, rays, tmin, tmax, hits) };
                }
                // SAFETY: the processor has AVX-512VL.
                return unsafe { self.intersect_batch_avx512(rays, tmin, tmax, hits) };
            }
            if isa >= Isa::Avx2 {
                if let Some(flat) = &self.root_list {
                    // SAFETY: the processor has AVX2 and FMA.
                    return unsafe { self.intersect_batch_flat8(flat, rays, tmin, tmax, hits) };
                }
                // SAFETY: the processor has AVX2 and FMA.
                return unsafe { self.intersect_batch_avx2(rays, tmin, tmax, hits) };
            }
        }
        // Older processors: ray by ray.
        let _ = isa;
        for (ray, hit) in rays.iter().zip(hits) {
            *hit = self.intersect(ray, tmin, tmax);
        }
    }

    /// [`Bvh::occluded`] for each ray of `rays` with its own end (`blocked[i]` for `rays[i]`
    /// and `tmax[i]`), in one call.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn occluded_batch(&self, rays: &[Ray], tmin: f32, tmax: &[f32], blocked: &mut [bool]) {
        self.occluded_batch_on(Isa::get(), rays, tmin, tmax, blocked);
    }

    /// [`Bvh::occluded_batch`] on the code paths of instruction set `isa` (or of the
    /// processor, if it has less): the same answers on every level.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn occluded_batch_on(
        &self,
        isa: Isa,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        assert!(rays.len() == tmax.len() && rays.len() == blocked.len());
        if self.nodes.is_empty() {
            blocked.fill(false);
            return;
        }
        let isa = isa.min(Isa::get());
        #[cfg(target_arch = "x86_64")]
        {
            if isa >= Isa::Avx512 {
                if let Some(flat) = &self.root_list {
                    // SAFETY: the processor has AVX-512VL, hence AVX-512F.
                    return unsafe { self.occluded_batch_flat(flat, rays, tmin, tmax, blocked) };
                }
                // SAFETY: the processor has AVX-512VL.
                return unsafe { self.occluded_batch_avx512(rays, tmin, tmax, blocked) };
            }
            if isa >= Isa::Avx2 {
                if let Some(flat) = &self.root_list {
                    // SAFETY: the processor has AVX2 and FMA.
                    return unsafe { self.occluded_batch_flat8(flat, rays, tmin, tmax, blocked) };
                }
                // SAFETY: the processor has AVX2 and FMA.
                return unsafe { self.occluded_batch_avx2(rays, tmin, tmax, blocked) };
            }
        }
        // Older processors: ray by ray.
        let _ = isa;
        for ((ray, &t), b) in rays.iter().zip(tmax).zip(blocked) {
            *b = self.occluded(ray, tmin, t);
        }
    }

    /// The loop of [`Bvh::occluded_batch`], inlined into each compiled variant.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) fn occluded_batch_with<K: Kernel>(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        for ((ray, &t), b) in rays.iter().zip(tmax).zip(blocked) {
            *b = self.occluded_with::<K>(ray, tmin, t, Start::ROOT);
        }
    }

    /// [`Bvh::occluded_batch`] compiled for AVX-512VL (leaves of three or four packs on
    /// sixteen lanes).
    ///
    /// # Safety
    /// The processor must support AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512vl")]
    pub(crate) unsafe fn occluded_batch_avx512(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        self.occluded_batch_with::<Wide>(rays, tmin, tmax, blocked);
    }

    /// [`Bvh::occluded_batch`] compiled for AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub(crate) unsafe fn occluded_batch_avx2(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        self.occluded_batch_with::<Avx>(rays, tmin, tmax, blocked);
    }

    /// True if anything lies along the ray with `tmin < t < tmax` (for shadow rays).
    #[must_use]
    pub fn occluded(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        #[cfg(target_arch = "x86_64")]
        {
            if Isa::avx512() {
                // SAFETY: the processor has AVX-512VL.
                return unsafe { self.occluded_avx512(ray, tmin, tmax) };
            }
            if Isa::avx2() {
                // SAFETY: the processor has AVX2 and FMA.
                return unsafe { self.occluded_avx(ray, tmin, tmax) };
            }
        }
        self.occluded_sse(ray, tmin, tmax)
    }

    /// [`Bvh::occluded`] without AVX, never inlined (as [`Bvh::intersect_sse`]).
    #[inline(never)]
    pub(crate) fn occluded_sse(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        self.occluded_with::<Sse>(ray, tmin, tmax, Start::ROOT)
    }

    /// [`Bvh::occluded`] compiled for AVX-512VL (leaves of three or four packs on sixteen
    /// lanes).
    ///
    /// # Safety
    /// The processor must support AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512vl")]
    pub(crate) unsafe fn occluded_avx512(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        self.occluded_with::<Wide>(ray, tmin, tmax, Start::ROOT)
    }

    /// [`Bvh::occluded`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub(crate) unsafe fn occluded_avx(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        self.occluded_with::<Avx>(ray, tmin, tmax, Start::ROOT)
    }
}

#[cfg(test)]
mod tests {
    use crate::layout::Start;
    use crate::simd::kernel::Sse;
    use crate::{BuildOptions, Bvh, Sphere};
    use prism_math::{Pcg32, Ray, Vec3};

    /// Property: the AVX2 walk (fused slab distances) and the SSE walk (unfused) enter
    /// boxes by distances a rounding apart, and still return bit-identical hits: both enter
    /// every box the ray meets, and the closest hit is the first by distance, then
    /// primitive number, whatever the order (checked on random rays, and on axis-aligned
    /// rays, whose slab distances include NaN).
    #[test]
    fn avx_and_sse_traversals_agree() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            let mut rng = Pcg32::new(5, 6);
            let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let tris: Vec<[Vec3; 3]> = (0..3000)
                .map(|_| {
                    let a = r() * 8.0;
                    [a, a + r() * 0.5, a + r() * 0.5]
                })
                .collect();
            let spheres = [Sphere {
                center: Vec3::splat(4.0),
                radius: 0.7,
            }];
            let bvh = Bvh::build(&tris, &spheres, &BuildOptions::default());
            let mut hits = 0;
            for k in 0..20_000 {
                let o = r() * 10.0 - 1.0;
                let d = if k % 4 == 0 {
                    [Vec3::X, -Vec3::Y, Vec3::Z][k % 3]
                } else {
                    r() - 0.5
                };
                let ray = Ray::new(o.floor(), d);
                // SAFETY: AVX2 and FMA were detected above.
                let avx = unsafe { bvh.intersect_avx(&ray, 0.0, f32::INFINITY) };
                assert_eq!(
                    avx,
                    bvh.intersect_with::<Sse>(&ray, 0.0, f32::INFINITY, Start::ROOT)
                );
                // SAFETY: as above.
                let occ = unsafe { bvh.occluded_avx(&ray, 0.0, 5.0) };
                assert_eq!(occ, bvh.occluded_with::<Sse>(&ray, 0.0, 5.0, Start::ROOT));
                hits += usize::from(avx.is_some());
            }
            assert!(hits > 2000, "{hits} hits");
        }
    }
}
