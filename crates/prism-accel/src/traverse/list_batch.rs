//! The batched queries through the root's list: each group of rays against the list on
//! lanes, then the rest of the tree for the rays that enter it (as a packet, in pairs, or
//! one by one), compiled for AVX-512 and AVX2.

use prism_math::Ray;

use super::packet::{self, Query};
use super::root_list::{self, Lanes};
use crate::hit::Hit;
use crate::layout::root_list::RootList;
use crate::layout::{Bvh, Start};
use crate::simd::kernel::{Avx, Kernel, Wide};
use crate::simd::{Avx2, Avx512, Simd};

impl Bvh {
    /// [`Bvh::intersect_batch`] through the root's list ([`RootList`]): `width` rays at a time
    /// against the list on lanes (`closest`), then the rest of the tree for the rays that
    /// enter it: as a packet (`packet`) when the group is coherent and a quarter of its
    /// rays or more enter, else ray by ray. Inlined into each compiled variant.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) fn intersect_batch_list<K: Kernel>(
        &self,
        rays: &[Ray],
        (tmin, tmax): (f32, f32),
        hits: &mut [Option<Hit>],
        (flat, width): (&RootList, usize),
        closest: impl Fn(&[Ray], &mut [Option<Hit>]) -> Lanes,
        packet: impl Fn(&Query, &mut [Option<Hit>]) -> u16,
    ) {
        // The tree walks still to make, over the whole batch: each ray, its end, where its
        // walk starts, and whether it is over the whole tree.
        let mut jobs: Vec<(usize, f32, Start)> = vec![];
        let mut whole: Vec<bool> = vec![];
        let groups = rays.chunks(width).zip(hits.chunks_mut(width));
        for (g, (rays, hits)) in groups.enumerate() {
            let lanes = closest(rays, hits);
            let tree = lanes.need & !lanes.defer;
            if 2 * tree.count_ones() as usize >= width && packet::coherent(rays, width) {
                self.list_packet::<K>(rays, (tmin, tmax), hits, (flat, lanes), &packet);
                continue;
            }
            // The list's hits stand, but in the lanes that must consult the tree.
            let mut rest = u32::from(lanes.defer | lanes.need) & ((1 << rays.len()) - 1);
            while rest != 0 {
                let lane = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                let all = lanes.defer & (1 << lane) != 0;
                // The rest of the tree, for a hit no farther than the list's.
                let end = hits[lane].map_or(tmax, |h| h.t.next_up());
                jobs.push(if all {
                    (g * width + lane, tmax, Start::ROOT)
                } else {
                    (g * width + lane, end, flat.start(lanes.inner[lane]))
                });
                whole.push(all);
            }
        }
        let mut found = vec![None; jobs.len()];
        self.walk_pairs::<K>(rays, tmin, (jobs.len(), |k| jobs[k]), &mut found);
        for ((&(i, ..), all), h) in jobs.iter().zip(whole).zip(found) {
            hits[i] = match h {
                _ if all => h,
                // Two primitives at one distance: the walk over the whole tree decides, by
                // primitive number.
                Some(h) if hits[i].is_some_and(|n| n.t == h.t) => {
                    self.intersect_with::<K>(&rays[i], tmin, tmax, Start::ROOT)
                }
                Some(h) => Some(h),
                None => hits[i],
            };
        }
    }

    /// The tree part of [`Bvh::intersect_batch_list`] for a coherent group, as a packet:
    /// the lanes that enter the rest of the tree walk it together, each up to just past
    /// its list hit; the lanes the list or the packet defers, and those where the tree and
    /// the list meet one distance, take the one-ray walk over the whole tree.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) fn list_packet<K: Kernel>(
        &self,
        rays: &[Ray],
        (tmin, tmax): (f32, f32),
        hits: &mut [Option<Hit>],
        (flat, lanes): (&RootList, Lanes),
        packet: &impl Fn(&Query, &mut [Option<Hit>]) -> u16,
    ) {
        let tree = lanes.need & !lanes.defer;
        let mut list = [None; 16];
        list[..hits.len()].copy_from_slice(hits);
        let mut ends = [tmax; 16];
        for (end, hit) in ends.iter_mut().zip(&list) {
            *end = hit.map_or(tmax, |h| h.t.next_up());
        }
        let query = Query {
            rays,
            tmin,
            ends,
            lanes: tree,
            skip: flat.skip,
        };
        let mut found = [None; 16];
        let deferred = packet(&query, &mut found[..hits.len()]);
        for (lane, hit) in hits.iter_mut().enumerate() {
            let bit = 1 << lane;
            let whole = lanes.defer & bit != 0
                || deferred & bit != 0
                || (tree & bit != 0
                    && found[lane].is_some_and(|h| list[lane].is_some_and(|n| n.t == h.t)));
            if whole {
                *hit = self.intersect_with::<K>(&rays[lane], tmin, tmax, Start::ROOT);
            } else if tree & bit != 0 && found[lane].is_some() {
                *hit = found[lane];
            }
        }
    }

    /// [`Bvh::intersect_batch_list`] on sixteen lanes of AVX-512.
    ///
    /// # Safety
    /// The processor must support AVX-512F and AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl")]
    pub(crate) unsafe fn intersect_batch_flat(
        &self,
        flat: &RootList,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.intersect_batch_list::<Wide>(
            rays,
            (tmin, tmax),
            hits,
            (flat, Avx512::W),
            // SAFETY (both): the processor has AVX-512F.
            |r, h| unsafe { root_list::closest_avx512(flat, r, (tmin, tmax), h) },
            |q, h| unsafe { packet::closest_avx512(self, q, h) },
        );
    }

    /// [`Bvh::intersect_batch_list`] on eight lanes of AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub(crate) unsafe fn intersect_batch_flat8(
        &self,
        flat: &RootList,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) {
        self.intersect_batch_list::<Avx>(
            rays,
            (tmin, tmax),
            hits,
            (flat, Avx2::W),
            // SAFETY (both): the processor has AVX2.
            |r, h| unsafe { root_list::closest_avx2(flat, r, (tmin, tmax), h) },
            |q, h| unsafe { packet::closest_avx2(self, q, h) },
        );
    }

    /// [`Bvh::occluded_batch`] through the root's list, as [`Bvh::intersect_batch_list`].
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) fn occluded_batch_list<K: Kernel>(
        &self,
        rays: &[Ray],
        (tmin, tmax): (f32, &[f32]),
        blocked: &mut [bool],
        (flat, width): (&RootList, usize),
        occluded: impl Fn(&[Ray], &[f32]) -> Lanes,
    ) {
        let groups = rays.chunks(width).zip(tmax.chunks(width));
        for ((rays, ends), blocked) in groups.zip(blocked.chunks_mut(width)) {
            let lanes = occluded(rays, ends);
            for (lane, b) in blocked.iter_mut().enumerate() {
                let bit = 1 << lane;
                let (ray, end) = (&rays[lane], ends[lane]);
                *b = if lanes.blocked & bit != 0 {
                    true
                } else if lanes.defer & bit != 0 {
                    self.occluded_with::<K>(ray, tmin, end, Start::ROOT)
                } else if lanes.need & bit != 0 {
                    self.occluded_with::<K>(ray, tmin, end, flat.start(lanes.inner[lane]))
                } else {
                    false
                };
            }
        }
    }

    /// [`Bvh::occluded_batch_list`] on sixteen lanes of AVX-512.
    ///
    /// # Safety
    /// The processor must support AVX-512F and AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl")]
    pub(crate) unsafe fn occluded_batch_flat(
        &self,
        flat: &RootList,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        self.occluded_batch_list::<Wide>(rays, (tmin, tmax), blocked, (flat, Avx512::W), |r, e| {
            // SAFETY: the processor has AVX-512F.
            unsafe { root_list::occluded_avx512(flat, r, tmin, e) }
        });
    }

    /// [`Bvh::occluded_batch_list`] on eight lanes of AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub(crate) unsafe fn occluded_batch_flat8(
        &self,
        flat: &RootList,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
        blocked: &mut [bool],
    ) {
        self.occluded_batch_list::<Avx>(rays, (tmin, tmax), blocked, (flat, Avx2::W), |r, e| {
            // SAFETY: the processor has AVX2.
            unsafe { root_list::occluded_avx2(flat, r, tmin, e) }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::super::root_list;
    use crate::{BuildOptions, Bvh, Hit};
    use prism_math::{Pcg32, Ray, Vec3};

    /// Oracle: the one-ray calls, which start at the root. In a room (ten wall triangles,
    /// set apart into the root's list) around a cluster the root holds in several children,
    /// rays aimed at the cluster walk on from one child or from the root, as the lanes'
    /// gate decides (both occur here), and every hit and occlusion is the one-ray call's,
    /// bit for bit, with ends infinite and finite.
    #[test]
    fn walks_past_the_list_start_at_the_child_entered() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut rng = Pcg32::new(9, 10);
            let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
            // Five faces of a cube of half-size 10 (all but +z), two triangles each.
            let mut tris = vec![];
            for (axis, side) in [(0, -1.0), (0, 1.0), (1, -1.0), (1, 1.0), (2, -1.0)] {
                let corner = |a: f32, b: f32| {
                    let mut p = [0.0f32; 3];
                    p[axis] = side * 10.0;
                    p[(axis + 1) % 3] = a * 10.0;
                    p[(axis + 2) % 3] = b * 10.0;
                    Vec3::from(p)
                };
                let [p, q, t, u] =
                    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(a, b)| corner(a, b));
                tris.push([p, q, t]);
                tris.push([p, t, u]);
            }
            for _ in 0..600 {
                let a = r() * 3.0;
                tris.push([a, a + r() * 0.3, a + r() * 0.3]);
            }
            let bvh = Bvh::build(&tris, &[], &BuildOptions::default());
            let flat = bvh.root_list.as_ref().expect("the walls make a list");
            assert!(
                flat.inner_nodes.len() >= 2,
                "the cluster under several children"
            );
            let rays: Vec<Ray> = (0..4000)
                .map(|_| {
                    let o = r() * 9.0;
                    Ray::new(o, r() * 3.0 - o)
                })
                .collect();
            // How the gate starts the walks of the lanes that go on into the tree.
            let (mut one, mut several) = (0, 0);
            for group in rays.chunks(8) {
                let mut out = [None; 8];
                // SAFETY: the processor has AVX2.
                let lanes = unsafe {
                    root_list::closest_avx2(flat, group, (1e-3, f32::INFINITY), &mut out)
                };
                for lane in (0..group.len()).filter(|&l| lanes.need & (1 << l) != 0) {
                    if lanes.inner[lane] == root_list::SEVERAL {
                        several += 1;
                    } else {
                        one += 1;
                    }
                }
            }
            assert!(one > 0 && several > 0, "one child {one}, several {several}");
            let bits =
                |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.prim, h.b1.to_bits(), h.b2.to_bits()));
            for tmax in [f32::INFINITY, 9.0] {
                let ends: Vec<f32> = (0..rays.len()).map(|i| 2.0 + (i % 13) as f32).collect();
                let mut hits = vec![None; rays.len()];
                bvh.intersect_batch(&rays, 1e-3, tmax, &mut hits);
                let mut blocked = vec![false; rays.len()];
                bvh.occluded_batch(&rays, 1e-3, &ends, &mut blocked);
                for (i, ray) in rays.iter().enumerate() {
                    assert_eq!(
                        bits(hits[i]),
                        bits(bvh.intersect(ray, 1e-3, tmax)),
                        "ray {i}"
                    );
                    assert_eq!(blocked[i], bvh.occluded(ray, 1e-3, ends[i]), "ray {i}");
                }
            }
        }
    }
}
