//! [`Kernel`]: the instruction set a walk is compiled for, chosen by type. A walk generic
//! over `K: Kernel` is one source for every instruction set; [`Sse`] runs anywhere,
//! [`Avx`] and [`Wide`] only inside functions compiled for AVX2 and FMA (AVX-512VL), which
//! their callers enter after detecting it. Every kernel gives the portable code's bits.

use prism_math::Ray;

use crate::layout::node8::{hit_sse, Node8, SlabRay};
use crate::shapes::RayPre;
#[cfg(target_arch = "x86_64")]
use crate::simd::node8::{hit_avx, hit_fused};

/// The kernels a walk calls, by instruction set.
pub(crate) trait Kernel {
    /// AVX code: the per-ray set-up in AVX registers, the AVX node tests, triangle packs two
    /// at a time on eight lanes, and the children entered sorted by a network.
    const AVX: bool;
    /// AVX-512VL: a leaf of three or four packs tested on sixteen lanes at once.
    const WIDE: bool;

    /// The ray's per-ray values for the leaves and the node tests.
    fn set_up(ray: &Ray) -> (RayPre, SlabRay);

    /// Entry distances of the ray into a node's eight child boxes, and which it enters: by
    /// the fused test if `fused` (which the caller sets only for a [`SlabRay::fused`] ray
    /// and an AVX kernel), else by the unfused one.
    fn node_hit(n: &Node8, r: &SlabRay, tmin: f32, tmax: f32, fused: bool) -> ([f32; 8], u32);
}

/// The portable kernels (SSE, part of x86-64, or any processor).
pub(crate) struct Sse;

impl Kernel for Sse {
    const AVX: bool = false;
    const WIDE: bool = false;

    #[inline(always)]
    fn set_up(ray: &Ray) -> (RayPre, SlabRay) {
        let pre = RayPre::new(ray);
        let slab = SlabRay::new(&pre);
        (pre, slab)
    }

    #[inline(always)]
    fn node_hit(n: &Node8, r: &SlabRay, tmin: f32, tmax: f32, _fused: bool) -> ([f32; 8], u32) {
        hit_sse(n, r, tmin, tmax)
    }
}

/// The kernels of walks compiled for AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Avx;

/// The kernels of walks compiled for AVX-512VL: [`Avx`]'s, and sixteen-lane leaves.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Wide;

/// [`Kernel::set_up`] in AVX registers: [`RayPre::new_avx`] gives the same values as
/// [`RayPre::new`], and the slab values from its registers.
///
/// # Safety
/// The processor must support AVX.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn set_up_avx(ray: &Ray) -> (RayPre, SlabRay) {
    // SAFETY: the caller ensures AVX.
    let (pre, origin, inv_dir) = unsafe { RayPre::new_avx(ray) };
    (pre, SlabRay::from_vectors(origin, inv_dir))
}

/// [`Kernel::node_hit`] on AVX lanes.
///
/// # Safety
/// The processor must support AVX2 and FMA, and a `fused` ray must be [`SlabRay::fused`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn node_hit_avx(
    n: &Node8,
    r: &SlabRay,
    tmin: f32,
    tmax: f32,
    fused: bool,
) -> ([f32; 8], u32) {
    // SAFETY: as the caller ensures.
    unsafe {
        if fused {
            hit_fused(n, r, tmin, tmax)
        } else {
            hit_avx(n, r, tmin, tmax)
        }
    }
}

#[cfg(target_arch = "x86_64")]
impl Kernel for Avx {
    const AVX: bool = true;
    const WIDE: bool = false;

    #[inline(always)]
    fn set_up(ray: &Ray) -> (RayPre, SlabRay) {
        // SAFETY: `Avx` and `Wide` are named only in walks compiled for AVX2 and FMA (or
        // AVX-512VL, which implies them), which their callers enter after detecting them.
        unsafe { set_up_avx(ray) }
    }

    #[inline(always)]
    fn node_hit(n: &Node8, r: &SlabRay, tmin: f32, tmax: f32, fused: bool) -> ([f32; 8], u32) {
        // SAFETY: as in `set_up`; the walks set `fused` only for a fused ray.
        unsafe { node_hit_avx(n, r, tmin, tmax, fused) }
    }
}

/// AVX-512VL has AVX2 and FMA: `Wide` walks use [`Avx`]'s set-up and node tests.
#[cfg(target_arch = "x86_64")]
impl Kernel for Wide {
    const AVX: bool = true;
    const WIDE: bool = true;

    #[inline(always)]
    fn set_up(ray: &Ray) -> (RayPre, SlabRay) {
        Avx::set_up(ray)
    }

    #[inline(always)]
    fn node_hit(n: &Node8, r: &SlabRay, tmin: f32, tmax: f32, fused: bool) -> ([f32; 8], u32) {
        Avx::node_hit(n, r, tmin, tmax, fused)
    }
}
