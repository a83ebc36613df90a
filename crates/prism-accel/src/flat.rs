//! [`Flat`], the primitives of the root's leaves in one list, and the batched queries on it:
//! sixteen rays at once against each primitive with AVX-512 (eight with AVX2: the queries
//! are written once, in the operations of [`crate::simd::Simd`]), with no branch that
//! depends on a ray, then the same rays against the boxes of the root's other children, to
//! find the
//! rays that must still traverse those. In a small scene that is every primitive; in a
//! Cornell box, the walls. Each lane computes the one-ray tests' operations in their order,
//! so it finds the hit the hierarchy finds. A lane that meets an edge function of exactly
//! zero (which the one-ray test settles in double precision) or two primitives at the same
//! nearest distance (where the hierarchy's visiting order decides) is left to the hierarchy.

use prism_math::{Aabb, Vec3};

use crate::shapes::Sphere;

/// Roots whose leaves hold at most this many primitives also keep them in a [`Flat`] list.
/// One-ray traversals of a few large primitives spend their time in mispredicted branches
/// and serial latency rather than work; testing each on sixteen lanes costs less.
pub(crate) const FLAT_MAX: usize = 24;

/// The most distinct vertices a list holds.
const MAX_VERTICES: usize = 3 * FLAT_MAX;

/// The primitives of the root's leaves, with their primitive numbers, and the root's other
/// children.
#[derive(Clone, Debug, Default)]
pub(crate) struct Flat {
    pub(crate) triangles: Vec<([Vec3; 3], u32)>,
    /// The triangles' distinct vertices, padded to four floats (`x, y, z, 0`) for lane
    /// permutes: a room's walls share their corners, which are then prepared once.
    pub(crate) vertices: Vec<[f32; 4]>,
    /// Per triangle, its vertices' indices in `vertices`.
    pub(crate) corners: Vec<[u16; 3]>,
    pub(crate) spheres: Vec<(Sphere, u32)>,
    /// Primitive numbers from this one on are spheres.
    pub(crate) first_sphere: u32,
    /// The boxes of the root's children that are not leaves.
    pub(crate) inner: Vec<Aabb>,
    /// The root's slots whose leaves are in the list.
    pub(crate) skip: u32,
}

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
}

impl Flat {
    /// Adds triangle `tri`, primitive `prim`, sharing the vertices already listed.
    pub(crate) fn push_triangle(&mut self, tri: [Vec3; 3], prim: u32) {
        let corners = tri.map(|v| {
            let padded = [v.x, v.y, v.z, 0.0];
            let bits = padded.map(f32::to_bits);
            let at = self
                .vertices
                .iter()
                .position(|w| w.map(f32::to_bits) == bits)
                .unwrap_or_else(|| {
                    self.vertices.push(padded);
                    self.vertices.len() - 1
                });
            at as u16
        });
        self.triangles.push((tri, prim));
        self.corners.push(corners);
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use queries::{closest_avx2, closest_avx512, occluded_avx2, occluded_avx512};

/// The queries on the lanes of one width `S`, and their entry points compiled for each.
#[cfg(target_arch = "x86_64")]
mod queries {
    use super::{Flat, Lanes, MAX_VERTICES};
    use crate::bvh::Hit;
    use crate::node8::FAR_WIDEN;
    use crate::shapes::Sphere;
    use crate::simd::{Avx2, Avx512, Simd};
    use prism_math::{Aabb, Ray};

    /// The rays of a group on lanes, prepared as the one-ray tests prepare them.
    struct Group<S: Simd> {
        origin: [S::F; 3],
        dir: [S::F; 3],
        shear: [S::F; 3],
        /// `is[k][a]`: lanes whose sheared axis `k` is source axis `a` (0 or 1; the other
        /// lanes take axis 2).
        is: [[S::M; 2]; 3],
        /// Per lane, the source axis of sheared axis `k` (0, 1 or 2), and the origin's
        /// coordinate on it.
        axis: [S::I; 3],
        origin_on: [S::F; 3],
    }

    impl<S: Simd> Group<S> {
        /// Lanes `i < rays.len()` take `rays[i]`; the others repeat the first ray. The shear
        /// and the axis permutation are `RayPre::new`'s, computed on lanes with the same
        /// operations.
        #[inline(always)]
        unsafe fn new(rays: &[Ray]) -> Group<S> {
            let mut padded = [rays[0]; 16];
            let n = rays.len().min(S::W);
            padded[..n].copy_from_slice(&rays[..n]);
            let (o, d) = (
                std::mem::offset_of!(Ray, origin) / 4,
                std::mem::offset_of!(Ray, dir) / 4,
            );
            // SAFETY (all below): the caller runs on `S`'s instruction set.
            unsafe {
                // No closures here: a closure is not compiled for `S`'s instruction set, and
                // the operations it calls would not be inlined into it.
                let origin = [
                    S::ray_field(&padded, o),
                    S::ray_field(&padded, o + 1),
                    S::ray_field(&padded, o + 2),
                ];
                let dir = [
                    S::ray_field(&padded, d),
                    S::ray_field(&padded, d + 1),
                    S::ray_field(&padded, d + 2),
                ];
                let abs = [S::abs(dir[0]), S::abs(dir[1]), S::abs(dir[2])];
                // The dominant axis kz (ties to the lower axis), and whether the ray runs
                // down it.
                let kz0 = S::and(S::ge(abs[0], abs[1]), S::ge(abs[0], abs[2]));
                let kz1 = S::and_not(S::ge(abs[1], abs[2]), kz0);
                let kz2 = S::and_not(S::and_not(S::all(), kz0), kz1);
                let dz = S::select(kz0, S::select(kz1, dir[2], dir[1]), dir[0]);
                let down = S::lt(dz, S::splat(0.0));
                let up = S::and_not(S::all(), down);
                // The permutations of `PERMS`, by (kz, down): kx and ky per lane.
                let (p0, p1, p2) = (S::and(kz0, up), S::and(kz0, down), S::and(kz1, up));
                let (p3, p4, p5) = (S::and(kz1, down), S::and(kz2, up), S::and(kz2, down));
                let is = [
                    [S::or(p3, p4), S::or(p0, p5)],
                    [S::or(p2, p5), S::or(p1, p4)],
                    [kz0, kz1],
                ];
                let mut axis = [S::splat_i(0); 3];
                for (axis, [a0, a1]) in axis.iter_mut().zip(is) {
                    let one_or_two = S::select_i(a1, S::splat_i(2), S::splat_i(1));
                    *axis = S::select_i(a0, one_or_two, S::splat_i(0));
                }
                let zero = S::splat(0.0);
                let mut g = Group {
                    origin,
                    dir,
                    shear: [zero; 3],
                    is,
                    axis,
                    origin_on: [zero; 3],
                };
                let inv_z = S::div(S::splat(1.0), dz);
                g.shear = [
                    S::mul(g.pick(0, &dir), inv_z),
                    S::mul(g.pick(1, &dir), inv_z),
                    inv_z,
                ];
                g.origin_on = [g.pick(0, &origin), g.pick(1, &origin), g.pick(2, &origin)];
                g
            }
        }

        /// Per lane, the component of `v` on the lane's sheared axis `k`.
        #[inline(always)]
        unsafe fn pick(&self, k: usize, v: &[S::F; 3]) -> S::F {
            // SAFETY: the caller runs on `S`'s instruction set.
            unsafe { S::select(self.is[k][0], S::select(self.is[k][1], v[2], v[1]), v[0]) }
        }

        /// A vertex as every lane's triangle test takes it: its coordinates on the lane's
        /// sheared axes, less the origin's (`v[k] - o[k]`, the one-ray test's values after
        /// reordering `v - o`), the first two sheared.
        #[inline(always)]
        unsafe fn vertex(&self, p: &[f32; 4]) -> [S::F; 3] {
            // SAFETY: the caller runs on `S`'s instruction set.
            unsafe {
                let v = S::broadcast4(p);
                let x = S::sub(S::permute(self.axis[0], v), self.origin_on[0]);
                let y = S::sub(S::permute(self.axis[1], v), self.origin_on[1]);
                let z = S::sub(S::permute(self.axis[2], v), self.origin_on[2]);
                let [sx, sy, _] = self.shear;
                [S::sub(x, S::mul(sx, z)), S::sub(y, S::mul(sy, z)), z]
            }
        }
    }

    /// One triangle's hit on every lane from its prepared vertices, as a pack of the
    /// hierarchy tests it: `(t, v, w, det, hit, zero)`. `hit` holds the lanes hit with
    /// `tmin < t < tmax`, `zero` those with an edge function of exactly zero.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    unsafe fn triangle<S: Simd>(
        g: &Group<S>,
        [a, b, c]: [&[S::F; 3]; 3],
        tmin: S::F,
        tmax: S::F,
    ) -> (S::F, S::F, S::F, S::F, S::M, S::M) {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let [ax, ay, az] = *a;
            let [bx, by, bz] = *b;
            let [cx, cy, cz] = *c;
            let sz = g.shear[2];
            let u = S::sub(S::mul(cx, by), S::mul(cy, bx));
            let v = S::sub(S::mul(ax, cy), S::mul(ay, cx));
            let w = S::sub(S::mul(bx, ay), S::mul(by, ax));
            let zero = S::splat(0.0);
            let zeros = S::or(S::or(S::eq(u, zero), S::eq(v, zero)), S::eq(w, zero));
            let neg = S::or(S::or(S::lt(u, zero), S::lt(v, zero)), S::lt(w, zero));
            let pos = S::or(S::or(S::gt(u, zero), S::gt(v, zero)), S::gt(w, zero));
            let det = S::add(S::add(u, v), w);
            let sum = S::add(S::add(S::mul(u, az), S::mul(v, bz)), S::mul(w, cz));
            let t = S::mul(S::mul(sz, sum), S::div(S::splat(1.0), det));
            let hit = S::and(
                S::and(
                    S::and_not(S::ne(det, zero), S::and(neg, pos)),
                    S::gt(t, tmin),
                ),
                S::lt(t, tmax),
            );
            (t, v, w, det, hit, zeros)
        }
    }

    /// One sphere's hit on every lane, as `intersect_sphere` finds it: `(t, hit)`, the
    /// nearest root with `tmin < t < tmax`.
    #[inline(always)]
    unsafe fn sphere<S: Simd>(g: &Group<S>, s: &Sphere, tmin: S::F, tmax: S::F) -> (S::F, S::M) {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let o = [
                S::sub(g.origin[0], S::splat(s.center.x)),
                S::sub(g.origin[1], S::splat(s.center.y)),
                S::sub(g.origin[2], S::splat(s.center.z)),
            ];
            let d = g.dir;
            let r = S::splat(s.radius);
            let a = dot::<S>(&d, &d);
            let b = S::mul(S::splat(2.0), dot::<S>(&o, &d));
            let c = S::sub(dot::<S>(&o, &o), S::splat(s.radius * s.radius));
            let k = S::div(b, S::mul(S::splat(2.0), a));
            let l = [
                S::sub(o[0], S::mul(k, d[0])),
                S::sub(o[1], S::mul(k, d[1])),
                S::sub(o[2], S::mul(k, d[2])),
            ];
            let l = S::sqrt(dot::<S>(&l, &l));
            let disc = S::mul(S::mul(S::mul(S::splat(4.0), a), S::add(r, l)), S::sub(r, l));
            let zero = S::splat(0.0);
            let miss = S::lt(disc, zero);
            let root = S::sqrt(disc);
            let b_neg = S::lt(b, zero);
            let q = S::mul(
                S::splat(-0.5),
                S::select(b_neg, S::add(b, root), S::sub(b, root)),
            );
            let t0 = S::div(q, a);
            let t1 = S::div(c, q);
            let swap = S::gt(t0, t1);
            let near = S::select(swap, t0, t1);
            let far = S::select(swap, t1, t0);
            let in_near = S::and(S::gt(near, tmin), S::lt(near, tmax));
            let in_far = S::and(S::gt(far, tmin), S::lt(far, tmax));
            (
                S::select(in_near, far, near),
                S::and_not(S::or(in_near, in_far), miss),
            )
        }
    }

    /// `a . b`, in glam's order.
    #[inline(always)]
    unsafe fn dot<S: Simd>(a: &[S::F; 3], b: &[S::F; 3]) -> S::F {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            S::add(
                S::add(S::mul(a[0], b[0]), S::mul(a[1], b[1])),
                S::mul(a[2], b[2]),
            )
        }
    }

    /// Lanes entering `b` with an entry in `[tmin, tmax]`: the slab test of the tree's nodes
    /// (`node8`), on lanes.
    #[inline(always)]
    unsafe fn enters<S: Simd>(
        g: &Group<S>,
        inv: &[S::F; 3],
        b: &Aabb,
        tmin: S::F,
        tmax: S::F,
    ) -> S::M {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let mut near = tmin;
            let mut far = S::splat(f32::INFINITY);
            for (a, &inv) in inv.iter().enumerate() {
                // Lanes whose direction is negative on this axis meet the upper plane first.
                let (lo, hi) = (S::splat(b.min[a]), S::splat(b.max[a]));
                let first = S::mul(S::sub(S::select_sign(inv, lo, hi), g.origin[a]), inv);
                let last = S::mul(S::sub(S::select_sign(inv, hi, lo), g.origin[a]), inv);
                // The slab value first: a NaN (a ray in the slab's plane) drops out.
                near = S::max(first, near);
                far = S::min(last, far);
            }
            let far = S::min(S::mul(far, S::splat(FAR_WIDEN)), tmax);
            S::le(near, far)
        }
    }

    /// `t` moved up by 1/1024 of its size and by the smallest normal float: past a distance
    /// by far more than the slab test's rounding (subnormal distances included), so that
    /// the gate below never drops a child the tree would enter.
    #[inline(always)]
    unsafe fn widen<S: Simd>(t: S::F) -> S::F {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            S::add(
                S::add(t, S::mul(S::abs(t), S::splat(1.0 / 1024.0))),
                S::splat(f32::MIN_POSITIVE),
            )
        }
    }

    /// Lanes that enter one of `flat.inner` with an entry in `[tmin, tmax]`.
    #[inline(always)]
    unsafe fn need<S: Simd>(flat: &Flat, g: &Group<S>, tmin: S::F, tmax: S::F) -> u16 {
        if flat.inner.is_empty() {
            return 0;
        }
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let one = S::splat(1.0);
            let inv = [
                S::div(one, g.dir[0]),
                S::div(one, g.dir[1]),
                S::div(one, g.dir[2]),
            ];
            let mut need = S::none();
            for b in &flat.inner {
                need = S::or(need, enters(g, &inv, b, tmin, tmax));
            }
            S::bits(need)
        }
    }

    /// The list's vertices prepared for a group ([`Group::vertex`]), each once.
    struct Prepared<S: Simd> {
        items: [std::mem::MaybeUninit<[S::F; 3]>; MAX_VERTICES],
    }

    impl<S: Simd> Prepared<S> {
        /// Room for the vertices, none prepared.
        #[inline(always)]
        fn new() -> Prepared<S> {
            Prepared {
                items: [const { std::mem::MaybeUninit::uninit() }; MAX_VERTICES],
            }
        }

        /// Prepares the list's vertices for group `g`, in place (returning kilobytes of
        /// vectors by value would copy them).
        #[inline(always)]
        unsafe fn fill(&mut self, flat: &Flat, g: &Group<S>) {
            for (item, v) in self.items.iter_mut().zip(&flat.vertices) {
                // SAFETY: the caller runs on `S`'s instruction set.
                *item = std::mem::MaybeUninit::new(unsafe { g.vertex(v) });
            }
        }

        /// The prepared vertices of a triangle.
        #[inline(always)]
        fn get(&self, corners: &[u16; 3]) -> [&[S::F; 3]; 3] {
            // SAFETY: `fill` wrote the first `flat.vertices.len()` items (at most
            // `MAX_VERTICES`: three per primitive of a list), and every corner indexes one.
            corners.map(|i| unsafe { self.items[usize::from(i)].assume_init_ref() })
        }
    }

    /// The running nearest hit of a group's lanes.
    struct Nearest<S: Simd> {
        t: S::F,
        v: S::F,
        w: S::F,
        det: S::F,
        prim: S::I,
        found: S::M,
        /// Lanes where a primitive met the nearest distance found so far exactly.
        tie: S::M,
    }

    impl<S: Simd> Nearest<S> {
        /// Takes a primitive's hits (`hit` lanes at `t`) where they are nearer.
        #[inline(always)]
        unsafe fn update(
            &mut self,
            (t, v, w, det): (S::F, S::F, S::F, S::F),
            prim: u32,
            hit: S::M,
        ) {
            // SAFETY: the caller runs on `S`'s instruction set.
            unsafe {
                let nearer = S::and(hit, S::lt(t, self.t));
                let equal = S::and(hit, S::eq(t, self.t));
                self.tie = S::or(S::and_not(self.tie, nearer), equal);
                self.t = S::select(nearer, self.t, t);
                self.v = S::select(nearer, self.v, v);
                self.w = S::select(nearer, self.w, w);
                self.det = S::select(nearer, self.det, det);
                self.prim = S::select_i(nearer, self.prim, S::splat_i(prim as i32));
                self.found = S::or(self.found, nearer);
            }
        }
    }

    /// [`Flat::closest`] on `S`'s lanes.
    #[inline(always)]
    unsafe fn closest<S: Simd>(
        flat: &Flat,
        rays: &[Ray],
        (tmin, tmax): (f32, f32),
        out: &mut [Option<Hit>],
    ) -> Lanes {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let g = Group::<S>::new(rays);
            let (lo, hi) = (S::splat(tmin), S::splat(tmax));
            let zero = S::splat(0.0);
            let mut near = Nearest::<S> {
                t: hi,
                v: zero,
                w: zero,
                det: zero,
                prim: S::splat_i(-1),
                found: S::none(),
                tie: S::none(),
            };
            let mut defer = S::none();
            let mut prepared = Prepared::<S>::new();
            prepared.fill(flat, &g);
            for (corners, (_, prim)) in flat.corners.iter().zip(&flat.triangles) {
                let (t, v, w, det, hit, zeros) = triangle(&g, prepared.get(corners), lo, hi);
                defer = S::or(defer, zeros);
                near.update((t, v, w, det), *prim, hit);
            }
            for (s, prim) in &flat.spheres {
                let (t, hit) = sphere(&g, s, lo, hi);
                near.update((t, zero, zero, zero), *prim, hit);
            }
            // The barycentric weights `v / det` and `w / det` (the one-ray test's
            // operations), zero for spheres.
            let inv = S::div(S::splat(1.0), near.det);
            let sphere = S::ge_u32(near.prim, S::splat_i(flat.first_sphere as i32));
            let b1 = S::select(sphere, S::mul(near.v, inv), zero);
            let b2 = S::select(sphere, S::mul(near.w, inv), zero);
            let mut t = [0f32; 16];
            let mut b = [[0f32; 16]; 2];
            let mut prim = [0u32; 16];
            S::store(near.t, &mut t);
            S::store(b1, &mut b[0]);
            S::store(b2, &mut b[1]);
            S::store_i(near.prim, &mut prim);
            let found = S::bits(near.found);
            let defer = S::bits(defer) | S::bits(near.tie);
            // Past a hit the list found, a margin far wider than the slab test's rounding.
            let reach = S::select(near.found, hi, widen::<S>(near.t));
            let need = need(flat, &g, lo, reach) & !defer;
            for (lane, hit) in out.iter_mut().enumerate().take(S::W) {
                *hit = (found & (1 << lane) != 0).then(|| Hit {
                    t: t[lane],
                    prim: prim[lane],
                    b1: b[0][lane],
                    b2: b[1][lane],
                });
            }
            Lanes {
                blocked: 0,
                defer,
                need,
            }
        }
    }

    /// [`Flat::occluded`] on `S`'s lanes.
    #[inline(always)]
    unsafe fn occluded<S: Simd>(flat: &Flat, rays: &[Ray], tmin: f32, tmax: &[f32]) -> Lanes {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let g = Group::<S>::new(rays);
            let mut ends = [tmax[0]; 16];
            let n = tmax.len().min(S::W);
            ends[..n].copy_from_slice(&tmax[..n]);
            let lo = S::splat(tmin);
            let hi = S::load(&ends);
            let (mut blocked, mut defer) = (S::none(), S::none());
            let mut prepared = Prepared::<S>::new();
            prepared.fill(flat, &g);
            for corners in &flat.corners {
                let (.., hit, zeros) = triangle(&g, prepared.get(corners), lo, hi);
                blocked = S::or(blocked, hit);
                defer = S::or(defer, zeros);
            }
            for (s, _) in &flat.spheres {
                blocked = S::or(blocked, sphere(&g, s, lo, hi).1);
            }
            let (blocked, defer) = (S::bits(blocked), S::bits(defer));
            // A lane blocked by another primitive is blocked whatever the deferred test
            // says.
            let defer = defer & !blocked;
            let reach = widen::<S>(hi);
            Lanes {
                blocked,
                defer,
                need: need(flat, &g, lo, reach) & !blocked & !defer,
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
        flat: &Flat,
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
        flat: &Flat,
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
        flat: &Flat,
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
        flat: &Flat,
        rays: &[Ray],
        tmin: f32,
        tmax: &[f32],
    ) -> Lanes {
        // SAFETY: compiled for AVX2, which the caller guarantees.
        unsafe { occluded::<Avx2>(flat, rays, tmin, tmax) }
    }
}
