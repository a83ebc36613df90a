//! The batched queries on the root's list ([`RootList`]): sixteen rays at once against each
//! primitive with AVX-512 (eight with AVX2: written once, in the operations of
//! [`crate::simd::Simd`]), then against the boxes of the root's other children, to find the
//! rays that must still traverse those. Each lane computes the one-ray tests' operations in
//! their order, so it finds the hit the hierarchy finds; a lane that meets an edge function
//! of exactly zero or two primitives at one nearest distance is left to the hierarchy.

use prism_math::Ray;

use crate::hit::Hit;
use crate::layout::root_list::{RootList, MAX_VERTICES};
use crate::simd::lanes::{enters, sphere, triangle, widen, Group, Inverse, Nearest};
use crate::simd::{Avx2, Avx512, Simd};

/// What a group of up to sixteen rays learnt, lane by lane (the first eight with AVX2), as
/// bit masks.
pub(crate) struct Lanes {
    /// Lanes that met something (occlusion queries).
    pub(crate) blocked: u16,
    /// Lanes whose answer must come from the hierarchy.
    pub(crate) defer: u16,
    /// Lanes that enter one of the root's other children before their nearest hit (or
    /// their end): they must traverse the rest of the hierarchy too.
    pub(crate) need: u16,
    /// Per lane of `need`, the one of those children it enters (an index into
    /// `RootList::inner`), or [`SEVERAL`] if it enters more than one.
    pub(crate) inner: [u32; 16],
}

/// In [`Lanes::inner`], a lane that enters more than one of the root's other children.
pub(crate) const SEVERAL: u32 = u32::MAX;

/// Lanes that enter one of `flat.inner` with an entry in `[tmin, tmax]`, and per lane
/// the one it enters ([`Lanes::inner`]).
#[inline(always)]
pub(crate) unsafe fn need<S: Simd>(
    flat: &RootList,
    g: &Group<S>,
    inv: &Inverse<S>,
    tmin: S::F,
    tmax: S::F,
) -> (u16, [u32; 16]) {
    // SAFETY: the caller runs on `S`'s instruction set.
    unsafe {
        // Lanes that enter a box, lanes that enter more than one, and the last each
        // enters.
        let (mut any, mut more) = (S::none(), S::none());
        let mut last = S::splat_i(0);
        for (k, b) in flat.inner.iter().enumerate() {
            let enter = enters(g, inv, b, tmin, tmax).1;
            more = S::or(more, S::and(any, enter));
            any = S::or(any, enter);
            last = S::select_i(enter, last, S::splat_i(k as i32));
        }
        let mut inner = [SEVERAL; 16];
        S::store_i(
            S::select_i(more, last, S::splat_i(SEVERAL as i32)),
            &mut inner,
        );
        (S::bits(any), inner)
    }
}

/// The root's leaves (bit `k` for `flat.leaf_boxes[k]`) that some lane enters with an
/// entry in `[tmin, tmax]`: the one-ray walk's root test, so the primitives of the
/// others are those the walk would not test on any lane.
#[inline(always)]
pub(crate) unsafe fn live<S: Simd>(
    flat: &RootList,
    g: &Group<S>,
    inv: &Inverse<S>,
    tmin: S::F,
    tmax: S::F,
) -> u32 {
    // SAFETY: the caller runs on `S`'s instruction set.
    unsafe {
        let mut live = 0;
        for (k, b) in flat.leaf_boxes.iter().enumerate() {
            live |= u32::from(S::bits(enters(g, inv, b, tmin, tmax).1) != 0) << k;
        }
        live
    }
}

/// The list's vertices prepared for a group ([`Group::vertex`]), each once.
pub(crate) struct Prepared<S: Simd> {
    pub(crate) items: [std::mem::MaybeUninit<[S::F; 3]>; MAX_VERTICES],
}

impl<S: Simd> Prepared<S> {
    /// Room for the vertices, none prepared.
    #[inline(always)]
    pub(crate) fn new() -> Prepared<S> {
        Prepared {
            items: [const { std::mem::MaybeUninit::uninit() }; MAX_VERTICES],
        }
    }

    /// Prepares the list's vertices for group `g`, in place (returning kilobytes of
    /// vectors by value would copy them).
    #[inline(always)]
    pub(crate) unsafe fn fill(&mut self, flat: &RootList, g: &Group<S>) {
        for (item, v) in self.items.iter_mut().zip(&flat.vertices) {
            // SAFETY: the caller runs on `S`'s instruction set.
            *item = std::mem::MaybeUninit::new(unsafe { g.vertex(v) });
        }
    }

    /// The prepared vertices of a triangle.
    #[inline(always)]
    pub(crate) fn get(&self, corners: &[u16; 3]) -> [&[S::F; 3]; 3] {
        // SAFETY: `fill` wrote the first `flat.vertices.len()` items (at most
        // `MAX_VERTICES`: three per primitive of a list), and every corner indexes one.
        corners.map(|i| unsafe { self.items[usize::from(i)].assume_init_ref() })
    }
}

/// [`RootList::closest`] on `S`'s lanes.
#[inline(always)]
pub(crate) unsafe fn closest<S: Simd>(
    flat: &RootList,
    rays: &[Ray],
    (tmin, tmax): (f32, f32),
    out: &mut [Option<Hit>],
) -> Lanes {
    // SAFETY: the caller runs on `S`'s instruction set.
    unsafe {
        let g = Group::<S>::new(rays);
        let (lo, hi) = (S::splat(tmin), S::splat(tmax));
        let zero = S::splat(0.0);
        let mut near = Nearest::<S>::none(hi);
        let mut defer = S::none();
        let inv = Inverse::<S>::new(&g);
        let live = live(flat, &g, &inv, lo, widen::<S>(hi));
        let mut prepared = Prepared::<S>::new();
        prepared.fill(flat, &g);
        let triangles = flat.corners.iter().zip(&flat.triangles);
        for ((corners, (_, prim)), &leaf) in triangles.zip(&flat.triangle_leaves) {
            if live >> leaf & 1 == 0 {
                continue;
            }
            let (t, v, w, det, hit, zeros) = triangle(&g, prepared.get(corners), lo, hi);
            defer = S::or(defer, zeros);
            near.update((t, v, w, det), *prim, hit);
        }
        for ((s, prim), &leaf) in flat.spheres.iter().zip(&flat.sphere_leaves) {
            if live >> leaf & 1 == 0 {
                continue;
            }
            let (t, hit) = sphere(&g, s, lo, hi);
            near.update((t, zero, zero, zero), *prim, hit);
        }
        near.write(flat.first_sphere, u16::MAX, out);
        let defer = S::bits(defer) | S::bits(near.tie);
        // Past the list's hit (or the rays' end, `near.t` where nothing was found), the
        // walk's own margin (`Walk::reach`), far wider than the slab test's rounding.
        let reach = widen::<S>(near.t);
        let (need, inner) = need(flat, &g, &inv, lo, reach);
        Lanes {
            blocked: 0,
            defer,
            need: need & !defer,
            inner,
        }
    }
}

/// [`RootList::occluded`] on `S`'s lanes.
#[inline(always)]
pub(crate) unsafe fn occluded<S: Simd>(
    flat: &RootList,
    rays: &[Ray],
    tmin: f32,
    tmax: &[f32],
) -> Lanes {
    // SAFETY: the caller runs on `S`'s instruction set.
    unsafe {
        let g = Group::<S>::new(rays);
        let lo = S::splat(tmin);
        let hi = if tmax.len() >= S::W {
            S::load(tmax)
        } else {
            let mut ends = [tmax[0]; 16];
            ends[..tmax.len()].copy_from_slice(tmax);
            S::load(&ends)
        };
        let (mut blocked, mut defer) = (S::none(), S::none());
        let inv = Inverse::<S>::new(&g);
        let live = live(flat, &g, &inv, lo, hi);
        let mut prepared = Prepared::<S>::new();
        prepared.fill(flat, &g);
        for (corners, &leaf) in flat.corners.iter().zip(&flat.triangle_leaves) {
            if live >> leaf & 1 == 0 {
                continue;
            }
            let (.., hit, zeros) = triangle(&g, prepared.get(corners), lo, hi);
            blocked = S::or(blocked, hit);
            defer = S::or(defer, zeros);
        }
        for ((s, _), &leaf) in flat.spheres.iter().zip(&flat.sphere_leaves) {
            if live >> leaf & 1 == 0 {
                continue;
            }
            blocked = S::or(blocked, sphere(&g, s, lo, hi).1);
        }
        let (blocked, defer) = (S::bits(blocked), S::bits(defer));
        // A lane blocked by another primitive is blocked whatever the deferred test
        // says.
        let defer = defer & !blocked;
        let reach = widen::<S>(hi);
        let (need, inner) = need(flat, &g, &inv, lo, reach);
        Lanes {
            blocked,
            defer,
            need: need & !blocked & !defer,
            inner,
        }
    }
}

/// The closest hits of `rays` (at most sixteen) with `t.0 < t < t.1`, written to `out`
/// (one per ray) except in the lanes the returned `defer` names.
///
/// # Safety
/// The processor must support AVX-512F.
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn closest_avx512(
    flat: &RootList,
    rays: &[Ray],
    t: (f32, f32),
    out: &mut [Option<Hit>],
) -> Lanes {
    // SAFETY: compiled for AVX-512F, which the caller guarantees.
    unsafe { closest::<Avx512>(flat, rays, t, out) }
}

/// Whether anything lies along each of `rays` (at most sixteen) with `tmin < t <
/// tmax[i]`.
///
/// # Safety
/// The processor must support AVX-512F.
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn occluded_avx512(
    flat: &RootList,
    rays: &[Ray],
    tmin: f32,
    tmax: &[f32],
) -> Lanes {
    // SAFETY: compiled for AVX-512F, which the caller guarantees.
    unsafe { occluded::<Avx512>(flat, rays, tmin, tmax) }
}

/// [`closest_avx512`] for at most eight rays, with AVX2.
///
/// # Safety
/// The processor must support AVX2.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn closest_avx2(
    flat: &RootList,
    rays: &[Ray],
    t: (f32, f32),
    out: &mut [Option<Hit>],
) -> Lanes {
    // SAFETY: compiled for AVX2, which the caller guarantees.
    unsafe { closest::<Avx2>(flat, rays, t, out) }
}

/// [`occluded_avx512`] for at most eight rays, with AVX2.
///
/// # Safety
/// The processor must support AVX2.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn occluded_avx2(
    flat: &RootList,
    rays: &[Ray],
    tmin: f32,
    tmax: &[f32],
) -> Lanes {
    // SAFETY: compiled for AVX2, which the caller guarantees.
    unsafe { occluded::<Avx2>(flat, rays, tmin, tmax) }
}
