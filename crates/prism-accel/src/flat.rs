//! [`Flat`], the primitives of the root's leaves in one list, and the batched queries on it:
//! sixteen rays at once against each primitive with AVX-512 (eight with AVX2, the same
//! operations on half the lanes), with no branch that depends on
//! a ray, then the same rays against the boxes of the root's other children, to find the
//! rays that must still traverse those. In a small scene that is every primitive; in a
//! Cornell box, the walls. Each lane computes the one-ray tests' operations in their order,
//! so it finds the hit the hierarchy finds. A lane that meets an edge function of exactly
//! zero (which the one-ray test settles in double precision) or two primitives at the same
//! nearest distance (where the hierarchy's visiting order decides) is left to the hierarchy.

use prism_math::{Aabb, Ray, Vec3};

use crate::bvh::Hit;
use crate::shapes::Sphere;

/// Roots whose leaves hold at most this many primitives also keep them in a [`Flat`] list.
/// One-ray traversals of a few large primitives spend their time in mispredicted branches
/// and serial latency rather than work; testing each on sixteen lanes costs less.
pub(crate) const FLAT_MAX: usize = 24;

/// The most distinct vertices a list holds.
const MAX_VERTICES: usize = 3 * FLAT_MAX;

/// Lanes of one query with AVX-512.
pub(crate) const WIDTH: usize = 16;

/// Lanes of one query with AVX2.
pub(crate) const WIDTH8: usize = 8;

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

    /// The closest hits of `rays` (at most sixteen) with `tmin < t < tmax`, written to
    /// `hits` (one per ray) except in the lanes the returned `defer` names.
    ///
    /// # Safety
    /// The processor must support AVX-512F.
    #[cfg(target_arch = "x86_64")]
    pub(crate) unsafe fn closest(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) -> Lanes {
        // SAFETY: the caller guarantees AVX-512F.
        unsafe { avx512::closest(self, rays, (tmin, tmax), hits) }
    }

    /// Whether anything lies along each of `rays` (at most sixteen) with `tmin < t <
    /// tmax[i]`.
    ///
    /// # Safety
    /// The processor must support AVX-512F.
    #[cfg(target_arch = "x86_64")]
    pub(crate) unsafe fn occluded(&self, rays: &[Ray], tmin: f32, tmax: &[f32]) -> Lanes {
        // SAFETY: the caller guarantees AVX-512F.
        unsafe { avx512::occluded(self, rays, tmin, tmax) }
    }

    /// [`Flat::closest`] for at most eight rays, with AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[cfg(target_arch = "x86_64")]
    pub(crate) unsafe fn closest8(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: f32,
        hits: &mut [Option<Hit>],
    ) -> Lanes {
        // SAFETY: the caller guarantees AVX2.
        unsafe { avx2::closest(self, rays, (tmin, tmax), hits) }
    }

    /// [`Flat::occluded`] for at most eight rays, with AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[cfg(target_arch = "x86_64")]
    pub(crate) unsafe fn occluded8(&self, rays: &[Ray], tmin: f32, tmax: &[f32]) -> Lanes {
        // SAFETY: the caller guarantees AVX2.
        unsafe { avx2::occluded(self, rays, tmin, tmax) }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::{Flat, Lanes, MAX_VERTICES, WIDTH};
    use crate::bvh::Hit;
    use crate::node8::FAR_WIDEN;
    use crate::shapes::Sphere;
    use prism_math::{Aabb, Ray};

    /// The rays of a group on lanes, prepared as the one-ray tests prepare them.
    struct Group {
        origin: [__m512; 3],
        dir: [__m512; 3],
        shear: [__m512; 3],
        /// `is[k][a]`: lanes whose sheared axis `k` is source axis `a` (0 or 1; the other
        /// lanes take axis 2).
        is: [[__mmask16; 2]; 3],
        /// Per lane, the source axis of sheared axis `k` (0, 1 or 2), and the origin's
        /// coordinate on it.
        axis: [__m512i; 3],
        origin_on: [__m512; 3],
    }

    /// Lanes `i < rays.len()` take `rays[i]`; the others repeat the first ray. The shear and
    /// the axis permutation are `RayPre::new`'s, computed on lanes with the same operations.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn group(rays: &[Ray]) -> Group {
        let mut padded = [rays[0]; WIDTH];
        let n = rays.len().min(WIDTH);
        padded[..n].copy_from_slice(&rays[..n]);
        const _: () = assert!(std::mem::size_of::<Ray>() == 24);
        let base = padded.as_ptr().cast::<f32>();
        let index = _mm512_mullo_epi32(
            _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
            _mm512_set1_epi32(6),
        );
        let (o, d) = (
            std::mem::offset_of!(Ray, origin) / 4,
            std::mem::offset_of!(Ray, dir) / 4,
        );
        // SAFETY: `Ray` is six floats (two `Vec3`, three floats each, at the offsets taken
        // above), so lane i reads floats 6i to 6i + 5: the ray of `padded` it takes.
        let field = |k: usize| unsafe { _mm512_i32gather_ps::<4>(index, base.add(k)) };
        let origin = [field(o), field(o + 1), field(o + 2)];
        let dir = [field(d), field(d + 1), field(d + 2)];
        let abs = dir.map(|d| _mm512_abs_ps(d));
        let ge = |a: __m512, b: __m512| _mm512_cmp_ps_mask::<_CMP_GE_OQ>(a, b);
        // The dominant axis kz (ties to the lower axis), and whether the ray runs down it.
        let kz0 = ge(abs[0], abs[1]) & ge(abs[0], abs[2]);
        let kz1 = !kz0 & ge(abs[1], abs[2]);
        let kz2 = !kz0 & !kz1;
        let dz = _mm512_mask_blend_ps(kz0, _mm512_mask_blend_ps(kz1, dir[2], dir[1]), dir[0]);
        let down = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(dz, _mm512_setzero_ps());
        let up = !down;
        // The permutations of `PERMS`, by (kz, down): kx and ky per lane.
        let (p0, p1, p2) = (kz0 & up, kz0 & down, kz1 & up);
        let (p3, p4, p5) = (kz1 & down, kz2 & up, kz2 & down);
        let is = [[p3 | p4, p0 | p5], [p2 | p5, p1 | p4], [kz0, kz1]];
        let axis = is.map(|[a0, a1]| {
            _mm512_mask_blend_epi32(
                a0,
                _mm512_mask_blend_epi32(a1, _mm512_set1_epi32(2), _mm512_set1_epi32(1)),
                _mm512_setzero_si512(),
            )
        });
        let zero = _mm512_setzero_ps();
        let mut g = Group {
            origin,
            dir,
            shear: [zero; 3],
            is,
            axis,
            origin_on: [zero; 3],
        };
        let inv_z = _mm512_div_ps(_mm512_set1_ps(1.0), dz);
        g.shear = [
            _mm512_mul_ps(pick(&g, 0, &dir), inv_z),
            _mm512_mul_ps(pick(&g, 1, &dir), inv_z),
            inv_z,
        ];
        g.origin_on = [
            pick(&g, 0, &origin),
            pick(&g, 1, &origin),
            pick(&g, 2, &origin),
        ];
        g
    }

    /// Per lane, the component of `v` on the lane's sheared axis `k`.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn pick(g: &Group, k: usize, v: &[__m512; 3]) -> __m512 {
        _mm512_mask_blend_ps(
            g.is[k][0],
            _mm512_mask_blend_ps(g.is[k][1], v[2], v[1]),
            v[0],
        )
    }

    /// A vertex as every lane's triangle test takes it: its coordinates on the lane's
    /// sheared axes, less the origin's (`v[k] - o[k]`, the one-ray test's values after
    /// reordering `v - o`), the first two sheared.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn vertex(g: &Group, p: &[f32; 4]) -> [__m512; 3] {
        // SAFETY: a padded vertex is four floats.
        let v = _mm512_broadcast_f32x4(unsafe { _mm_loadu_ps(p.as_ptr()) });
        let on = |k: usize| _mm512_sub_ps(_mm512_permutexvar_ps(g.axis[k], v), g.origin_on[k]);
        let (x, y, z) = (on(0), on(1), on(2));
        let [sx, sy, _] = g.shear;
        [
            _mm512_sub_ps(x, _mm512_mul_ps(sx, z)),
            _mm512_sub_ps(y, _mm512_mul_ps(sy, z)),
            z,
        ]
    }

    /// One triangle's hit on every lane from its prepared vertices ([`vertex`]), as a pack
    /// of the hierarchy tests it: `(t, v, w, det, hit, zero)`. `hit` holds the lanes hit
    /// with `tmin < t < tmax`, `zero` those with an edge function of exactly zero.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn triangle(
        g: &Group,
        [a, b, c]: [&[__m512; 3]; 3],
        tmin: __m512,
        tmax: __m512,
    ) -> (__m512, __m512, __m512, __m512, __mmask16, __mmask16) {
        let [ax, ay, az] = *a;
        let [bx, by, bz] = *b;
        let [cx, cy, cz] = *c;
        let sz = g.shear[2];
        let edge = |a: __m512, b: __m512, c: __m512, d: __m512| {
            _mm512_sub_ps(_mm512_mul_ps(a, b), _mm512_mul_ps(c, d))
        };
        let u = edge(cx, by, cy, bx);
        let v = edge(ax, cy, ay, cx);
        let w = edge(bx, ay, by, ax);
        let zero = _mm512_setzero_ps();
        let eq0 = |x: __m512| _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(x, zero);
        let lt0 = |x: __m512| _mm512_cmp_ps_mask::<_CMP_LT_OQ>(x, zero);
        let gt0 = |x: __m512| _mm512_cmp_ps_mask::<_CMP_GT_OQ>(x, zero);
        let zeros = eq0(u) | eq0(v) | eq0(w);
        let neg = lt0(u) | lt0(v) | lt0(w);
        let pos = gt0(u) | gt0(v) | gt0(w);
        let det = _mm512_add_ps(_mm512_add_ps(u, v), w);
        let sum = _mm512_add_ps(
            _mm512_add_ps(_mm512_mul_ps(u, az), _mm512_mul_ps(v, bz)),
            _mm512_mul_ps(w, cz),
        );
        let t = _mm512_mul_ps(
            _mm512_mul_ps(sz, sum),
            _mm512_div_ps(_mm512_set1_ps(1.0), det),
        );
        let hit = !(neg & pos)
            & _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(det, zero)
            & _mm512_cmp_ps_mask::<_CMP_GT_OQ>(t, tmin)
            & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, tmax);
        (t, v, w, det, hit, zeros)
    }

    /// One sphere's hit on every lane, as `intersect_sphere` finds it: `(t, hit)`, the
    /// nearest root with `tmin < t < tmax`.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn sphere(g: &Group, s: &Sphere, tmin: __m512, tmax: __m512) -> (__m512, __mmask16) {
        let o = [
            _mm512_sub_ps(g.origin[0], _mm512_set1_ps(s.center.x)),
            _mm512_sub_ps(g.origin[1], _mm512_set1_ps(s.center.y)),
            _mm512_sub_ps(g.origin[2], _mm512_set1_ps(s.center.z)),
        ];
        let d = g.dir;
        let dot = |a: &[__m512; 3], b: &[__m512; 3]| {
            _mm512_add_ps(
                _mm512_add_ps(_mm512_mul_ps(a[0], b[0]), _mm512_mul_ps(a[1], b[1])),
                _mm512_mul_ps(a[2], b[2]),
            )
        };
        let r = _mm512_set1_ps(s.radius);
        let a = dot(&d, &d);
        let b = _mm512_mul_ps(_mm512_set1_ps(2.0), dot(&o, &d));
        let c = _mm512_sub_ps(dot(&o, &o), _mm512_set1_ps(s.radius * s.radius));
        let k = _mm512_div_ps(b, _mm512_mul_ps(_mm512_set1_ps(2.0), a));
        let l = [0, 1, 2].map(|i| _mm512_sub_ps(o[i], _mm512_mul_ps(k, d[i])));
        let l = _mm512_sqrt_ps(dot(&l, &l));
        let disc = _mm512_mul_ps(
            _mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(4.0), a), _mm512_add_ps(r, l)),
            _mm512_sub_ps(r, l),
        );
        let zero = _mm512_setzero_ps();
        let miss = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(disc, zero);
        let root = _mm512_sqrt_ps(disc);
        let b_neg = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(b, zero);
        let q = _mm512_mul_ps(
            _mm512_set1_ps(-0.5),
            _mm512_mask_blend_ps(b_neg, _mm512_add_ps(b, root), _mm512_sub_ps(b, root)),
        );
        let t0 = _mm512_div_ps(q, a);
        let t1 = _mm512_div_ps(c, q);
        let swap = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(t0, t1);
        let near = _mm512_mask_blend_ps(swap, t0, t1);
        let far = _mm512_mask_blend_ps(swap, t1, t0);
        let inside = |t: __m512| {
            _mm512_cmp_ps_mask::<_CMP_GT_OQ>(t, tmin) & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, tmax)
        };
        let (in_near, in_far) = (inside(near), inside(far));
        (
            _mm512_mask_blend_ps(in_near, far, near),
            !miss & (in_near | in_far),
        )
    }

    /// Lanes entering `b` with an entry in `[tmin, tmax]`: the slab test of the tree's nodes
    /// (`node8`), on lanes.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn enters(g: &Group, inv: &[__m512; 3], b: &Aabb, tmin: __m512, tmax: __m512) -> __mmask16 {
        let mut near = tmin;
        let mut far = _mm512_set1_ps(f32::INFINITY);
        for (a, &inv) in inv.iter().enumerate() {
            // Lanes whose direction is negative on this axis meet the upper plane first.
            let neg = _mm512_cmplt_epi32_mask(_mm512_castps_si512(inv), _mm512_setzero_si512());
            let (lo, hi) = (_mm512_set1_ps(b.min[a]), _mm512_set1_ps(b.max[a]));
            let t = |plane: __m512| _mm512_mul_ps(_mm512_sub_ps(plane, g.origin[a]), inv);
            // The slab value first: a NaN (a ray in the slab's plane) drops out.
            near = _mm512_max_ps(t(_mm512_mask_blend_ps(neg, lo, hi)), near);
            far = _mm512_min_ps(t(_mm512_mask_blend_ps(neg, hi, lo)), far);
        }
        let far = _mm512_min_ps(_mm512_mul_ps(far, _mm512_set1_ps(FAR_WIDEN)), tmax);
        _mm512_cmp_ps_mask::<_CMP_LE_OQ>(near, far)
    }

    /// `t` moved up by 1/1024 of its size and by the smallest normal float: past a distance
    /// by far more than the slab test's rounding (subnormal distances included), so that the
    /// gate below never drops a child the tree would enter.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn widen(t: __m512) -> __m512 {
        _mm512_add_ps(
            _mm512_add_ps(
                t,
                _mm512_mul_ps(_mm512_abs_ps(t), _mm512_set1_ps(1.0 / 1024.0)),
            ),
            _mm512_set1_ps(f32::MIN_POSITIVE),
        )
    }

    /// Lanes that enter one of `flat.inner` with an entry in `[tmin, tmax]`.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn need(flat: &Flat, g: &Group, tmin: __m512, tmax: __m512) -> __mmask16 {
        if flat.inner.is_empty() {
            return 0;
        }
        let one = _mm512_set1_ps(1.0);
        let inv = [
            _mm512_div_ps(one, g.dir[0]),
            _mm512_div_ps(one, g.dir[1]),
            _mm512_div_ps(one, g.dir[2]),
        ];
        let mut need = 0;
        for b in &flat.inner {
            need |= enters(g, &inv, b, tmin, tmax);
        }
        need
    }

    /// The list's vertices prepared for a group ([`vertex`]), each once.
    struct Prepared {
        items: [std::mem::MaybeUninit<[__m512; 3]>; MAX_VERTICES],
    }

    impl Prepared {
        /// Room for the vertices, none prepared.
        #[inline(always)]
        fn new() -> Prepared {
            Prepared {
                items: [const { std::mem::MaybeUninit::uninit() }; MAX_VERTICES],
            }
        }

        /// Prepares the list's vertices for group `g`, in place (returning kilobytes of
        /// vectors by value would copy them).
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn fill(&mut self, flat: &Flat, g: &Group) {
            for (item, v) in self.items.iter_mut().zip(&flat.vertices) {
                *item = std::mem::MaybeUninit::new(vertex(g, v));
            }
        }

        /// The prepared vertices of a triangle.
        #[inline(always)]
        fn get(&self, corners: &[u16; 3]) -> [&[__m512; 3]; 3] {
            // SAFETY: `fill` wrote the first `flat.vertices.len()` items (at most
            // `MAX_VERTICES`: three per primitive of a list), and every corner indexes one.
            corners.map(|i| unsafe { self.items[usize::from(i)].assume_init_ref() })
        }
    }

    /// The running nearest hit of a group's lanes.
    struct Nearest {
        t: __m512,
        v: __m512,
        w: __m512,
        det: __m512,
        prim: __m512i,
        found: __mmask16,
        /// Lanes where a primitive met the nearest distance found so far exactly.
        tie: __mmask16,
    }

    impl Nearest {
        /// Takes a primitive's hits (`hit` lanes at `t`) where they are nearer.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn update(&mut self, t: __m512, v: __m512, w: __m512, det: __m512, prim: u32, hit: u16) {
            let nearer = hit & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, self.t);
            let equal = hit & _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(t, self.t);
            self.tie = (self.tie & !nearer) | equal;
            self.t = _mm512_mask_blend_ps(nearer, self.t, t);
            self.v = _mm512_mask_blend_ps(nearer, self.v, v);
            self.w = _mm512_mask_blend_ps(nearer, self.w, w);
            self.det = _mm512_mask_blend_ps(nearer, self.det, det);
            self.prim = _mm512_mask_blend_epi32(nearer, self.prim, _mm512_set1_epi32(prim as i32));
            self.found |= nearer;
        }
    }

    /// [`Flat::closest`].
    #[target_feature(enable = "avx512f")]
    pub(super) fn closest(
        flat: &Flat,
        rays: &[Ray],
        (tmin, tmax): (f32, f32),
        out: &mut [Option<Hit>],
    ) -> Lanes {
        let g = group(rays);
        let (lo, hi) = (_mm512_set1_ps(tmin), _mm512_set1_ps(tmax));
        let zero = _mm512_setzero_ps();
        let mut near = Nearest {
            t: hi,
            v: zero,
            w: zero,
            det: zero,
            prim: _mm512_set1_epi32(-1),
            found: 0,
            tie: 0,
        };
        let mut defer = 0u16;
        let mut prepared = Prepared::new();
        prepared.fill(flat, &g);
        for (corners, (_, prim)) in flat.corners.iter().zip(&flat.triangles) {
            let (t, v, w, det, hit, zeros) = triangle(&g, prepared.get(corners), lo, hi);
            defer |= zeros;
            near.update(t, v, w, det, *prim, hit);
        }
        for (s, prim) in &flat.spheres {
            let (t, hit) = sphere(&g, s, lo, hi);
            near.update(t, zero, zero, zero, *prim, hit);
        }
        // The barycentric weights `v / det` and `w / det` (the one-ray test's operations),
        // zero for spheres.
        let inv = _mm512_div_ps(_mm512_set1_ps(1.0), near.det);
        let sphere =
            _mm512_cmpge_epu32_mask(near.prim, _mm512_set1_epi32(flat.first_sphere as i32));
        let b1 = _mm512_mask_blend_ps(sphere, _mm512_mul_ps(near.v, inv), zero);
        let b2 = _mm512_mask_blend_ps(sphere, _mm512_mul_ps(near.w, inv), zero);
        let mut t = [0f32; WIDTH];
        let mut b = [[0f32; WIDTH]; 2];
        let mut prim = [0u32; WIDTH];
        // SAFETY: each store writes sixteen lanes into an array of sixteen.
        unsafe {
            _mm512_storeu_ps(t.as_mut_ptr(), near.t);
            _mm512_storeu_ps(b[0].as_mut_ptr(), b1);
            _mm512_storeu_ps(b[1].as_mut_ptr(), b2);
            _mm512_storeu_si512(prim.as_mut_ptr().cast(), near.prim);
        }
        let defer = defer | near.tie;
        // Past a hit the list found, a margin far wider than the slab test's rounding.
        let reach = _mm512_mask_blend_ps(near.found, hi, widen(near.t));
        let need = need(flat, &g, lo, reach) & !defer;
        for (lane, hit) in out.iter_mut().enumerate().take(WIDTH) {
            *hit = (near.found & (1 << lane) != 0).then(|| Hit {
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

    /// [`Flat::occluded`].
    #[target_feature(enable = "avx512f")]
    pub(super) fn occluded(flat: &Flat, rays: &[Ray], tmin: f32, tmax: &[f32]) -> Lanes {
        let g = group(rays);
        let mut ends = [tmax[0]; WIDTH];
        ends[..tmax.len().min(WIDTH)].copy_from_slice(&tmax[..tmax.len().min(WIDTH)]);
        let lo = _mm512_set1_ps(tmin);
        // SAFETY: sixteen floats are read from an array of sixteen.
        let hi = unsafe { _mm512_loadu_ps(ends.as_ptr()) };
        let (mut blocked, mut defer) = (0u16, 0u16);
        let mut prepared = Prepared::new();
        prepared.fill(flat, &g);
        for corners in &flat.corners {
            let (.., hit, zeros) = triangle(&g, prepared.get(corners), lo, hi);
            blocked |= hit;
            defer |= zeros;
        }
        for (s, _) in &flat.spheres {
            blocked |= sphere(&g, s, lo, hi).1;
        }
        // A lane blocked by another primitive is blocked whatever the deferred test says.
        let defer = defer & !blocked;
        let reach = widen(hi);
        Lanes {
            blocked,
            defer,
            need: need(flat, &g, lo, reach) & !blocked & !defer,
        }
    }
}

/// The queries of `avx512` on eight lanes of 256-bit AVX2 vectors: the same operations in the
/// same order, with vector masks (all bits set in a lane that is in) for AVX-512's mask
/// registers, and `blendv` (which takes the second operand where the mask's sign is set) for
/// masked blends.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::{Flat, Lanes, MAX_VERTICES, WIDTH8 as WIDTH};
    use crate::bvh::Hit;
    use crate::node8::FAR_WIDEN;
    use crate::shapes::Sphere;
    use prism_math::{Aabb, Ray};

    /// A lane mask: every bit of a lane set where it is in, none where it is out.
    type M = __m256;

    #[inline]
    #[target_feature(enable = "avx2")]
    fn and(a: M, b: M) -> M {
        _mm256_and_ps(a, b)
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn or(a: M, b: M) -> M {
        _mm256_or_ps(a, b)
    }

    /// `a & !b`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn and_not(a: M, b: M) -> M {
        _mm256_andnot_ps(b, a)
    }

    /// `b` in the lanes of `m`, `a` in the others.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn blend(m: M, a: __m256, b: __m256) -> __m256 {
        _mm256_blendv_ps(a, b, m)
    }

    /// The lanes of `m` as bits.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn bits(m: M) -> u16 {
        _mm256_movemask_ps(m) as u16
    }

    /// The rays of a group on lanes, prepared as the one-ray tests prepare them.
    struct Group {
        origin: [__m256; 3],
        dir: [__m256; 3],
        shear: [__m256; 3],
        /// `is[k][a]`: lanes whose sheared axis `k` is source axis `a` (0 or 1; the other
        /// lanes take axis 2).
        is: [[M; 2]; 3],
        /// Per lane, the source axis of sheared axis `k` (0, 1 or 2), and the origin's
        /// coordinate on it.
        axis: [__m256i; 3],
        origin_on: [__m256; 3],
    }

    /// Lanes `i < rays.len()` take `rays[i]`; the others repeat the first ray. The shear and
    /// the axis permutation are `RayPre::new`'s, computed on lanes with the same operations.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn group(rays: &[Ray]) -> Group {
        let mut padded = [rays[0]; WIDTH];
        let n = rays.len().min(WIDTH);
        padded[..n].copy_from_slice(&rays[..n]);
        const _: () = assert!(std::mem::size_of::<Ray>() == 24);
        let base = padded.as_ptr().cast::<f32>();
        let index = _mm256_setr_epi32(0, 6, 12, 18, 24, 30, 36, 42);
        let (o, d) = (
            std::mem::offset_of!(Ray, origin) / 4,
            std::mem::offset_of!(Ray, dir) / 4,
        );
        // SAFETY: `Ray` is six floats (two `Vec3`, three floats each, at the offsets taken
        // above), so lane i reads floats 6i to 6i + 5: the ray of `padded` it takes.
        let field = |k: usize| unsafe { _mm256_i32gather_ps::<4>(base.add(k), index) };
        let origin = [field(o), field(o + 1), field(o + 2)];
        let dir = [field(d), field(d + 1), field(d + 2)];
        let magnitude = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
        let abs = dir.map(|d| _mm256_and_ps(d, magnitude));
        let ge = |a: __m256, b: __m256| _mm256_cmp_ps::<_CMP_GE_OQ>(a, b);
        let all = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
        // The dominant axis kz (ties to the lower axis), and whether the ray runs down it.
        let kz0 = and(ge(abs[0], abs[1]), ge(abs[0], abs[2]));
        let kz1 = and_not(ge(abs[1], abs[2]), kz0);
        let kz2 = and_not(and_not(all, kz0), kz1);
        let dz = blend(kz0, blend(kz1, dir[2], dir[1]), dir[0]);
        let down = _mm256_cmp_ps::<_CMP_LT_OQ>(dz, _mm256_setzero_ps());
        let up = and_not(all, down);
        // The permutations of `PERMS`, by (kz, down): kx and ky per lane.
        let (p0, p1, p2) = (and(kz0, up), and(kz0, down), and(kz1, up));
        let (p3, p4, p5) = (and(kz1, down), and(kz2, up), and(kz2, down));
        let is = [
            [or(p3, p4), or(p0, p5)],
            [or(p2, p5), or(p1, p4)],
            [kz0, kz1],
        ];
        let axis = is.map(|[a0, a1]| {
            let two = _mm256_castsi256_ps(_mm256_set1_epi32(2));
            let one = _mm256_castsi256_ps(_mm256_set1_epi32(1));
            _mm256_castps_si256(blend(a0, blend(a1, two, one), _mm256_setzero_ps()))
        });
        let zero = _mm256_setzero_ps();
        let mut g = Group {
            origin,
            dir,
            shear: [zero; 3],
            is,
            axis,
            origin_on: [zero; 3],
        };
        let inv_z = _mm256_div_ps(_mm256_set1_ps(1.0), dz);
        g.shear = [
            _mm256_mul_ps(pick(&g, 0, &dir), inv_z),
            _mm256_mul_ps(pick(&g, 1, &dir), inv_z),
            inv_z,
        ];
        g.origin_on = [
            pick(&g, 0, &origin),
            pick(&g, 1, &origin),
            pick(&g, 2, &origin),
        ];
        g
    }

    /// Per lane, the component of `v` on the lane's sheared axis `k`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn pick(g: &Group, k: usize, v: &[__m256; 3]) -> __m256 {
        blend(g.is[k][0], blend(g.is[k][1], v[2], v[1]), v[0])
    }

    /// A vertex as every lane's triangle test takes it: its coordinates on the lane's
    /// sheared axes, less the origin's (`v[k] - o[k]`, the one-ray test's values after
    /// reordering `v - o`), the first two sheared.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn vertex(g: &Group, p: &[f32; 4]) -> [__m256; 3] {
        // SAFETY: a padded vertex is four floats.
        let v = _mm256_broadcast_ps(&unsafe { _mm_loadu_ps(p.as_ptr()) });
        let on = |k: usize| _mm256_sub_ps(_mm256_permutevar8x32_ps(v, g.axis[k]), g.origin_on[k]);
        let (x, y, z) = (on(0), on(1), on(2));
        let [sx, sy, _] = g.shear;
        [
            _mm256_sub_ps(x, _mm256_mul_ps(sx, z)),
            _mm256_sub_ps(y, _mm256_mul_ps(sy, z)),
            z,
        ]
    }

    /// One triangle's hit on every lane from its prepared vertices ([`vertex`]), as a pack
    /// of the hierarchy tests it: `(t, v, w, det, hit, zero)`. `hit` holds the lanes hit
    /// with `tmin < t < tmax`, `zero` those with an edge function of exactly zero.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn triangle(
        g: &Group,
        [a, b, c]: [&[__m256; 3]; 3],
        tmin: __m256,
        tmax: __m256,
    ) -> (__m256, __m256, __m256, __m256, M, M) {
        let [ax, ay, az] = *a;
        let [bx, by, bz] = *b;
        let [cx, cy, cz] = *c;
        let sz = g.shear[2];
        let edge = |a: __m256, b: __m256, c: __m256, d: __m256| {
            _mm256_sub_ps(_mm256_mul_ps(a, b), _mm256_mul_ps(c, d))
        };
        let u = edge(cx, by, cy, bx);
        let v = edge(ax, cy, ay, cx);
        let w = edge(bx, ay, by, ax);
        let zero = _mm256_setzero_ps();
        let eq0 = |x: __m256| _mm256_cmp_ps::<_CMP_EQ_OQ>(x, zero);
        let lt0 = |x: __m256| _mm256_cmp_ps::<_CMP_LT_OQ>(x, zero);
        let gt0 = |x: __m256| _mm256_cmp_ps::<_CMP_GT_OQ>(x, zero);
        let zeros = or(or(eq0(u), eq0(v)), eq0(w));
        let neg = or(or(lt0(u), lt0(v)), lt0(w));
        let pos = or(or(gt0(u), gt0(v)), gt0(w));
        let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
        let sum = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(u, az), _mm256_mul_ps(v, bz)),
            _mm256_mul_ps(w, cz),
        );
        let t = _mm256_mul_ps(
            _mm256_mul_ps(sz, sum),
            _mm256_div_ps(_mm256_set1_ps(1.0), det),
        );
        let hit = and(
            and(
                and_not(_mm256_cmp_ps::<_CMP_NEQ_UQ>(det, zero), and(neg, pos)),
                _mm256_cmp_ps::<_CMP_GT_OQ>(t, tmin),
            ),
            _mm256_cmp_ps::<_CMP_LT_OQ>(t, tmax),
        );
        (t, v, w, det, hit, zeros)
    }

    /// One sphere's hit on every lane, as `intersect_sphere` finds it: `(t, hit)`, the
    /// nearest root with `tmin < t < tmax`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn sphere(g: &Group, s: &Sphere, tmin: __m256, tmax: __m256) -> (__m256, M) {
        let o = [
            _mm256_sub_ps(g.origin[0], _mm256_set1_ps(s.center.x)),
            _mm256_sub_ps(g.origin[1], _mm256_set1_ps(s.center.y)),
            _mm256_sub_ps(g.origin[2], _mm256_set1_ps(s.center.z)),
        ];
        let d = g.dir;
        let dot = |a: &[__m256; 3], b: &[__m256; 3]| {
            _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(a[0], b[0]), _mm256_mul_ps(a[1], b[1])),
                _mm256_mul_ps(a[2], b[2]),
            )
        };
        let r = _mm256_set1_ps(s.radius);
        let a = dot(&d, &d);
        let b = _mm256_mul_ps(_mm256_set1_ps(2.0), dot(&o, &d));
        let c = _mm256_sub_ps(dot(&o, &o), _mm256_set1_ps(s.radius * s.radius));
        let k = _mm256_div_ps(b, _mm256_mul_ps(_mm256_set1_ps(2.0), a));
        let l = [0, 1, 2].map(|i| _mm256_sub_ps(o[i], _mm256_mul_ps(k, d[i])));
        let l = _mm256_sqrt_ps(dot(&l, &l));
        let disc = _mm256_mul_ps(
            _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(4.0), a), _mm256_add_ps(r, l)),
            _mm256_sub_ps(r, l),
        );
        let zero = _mm256_setzero_ps();
        let miss = _mm256_cmp_ps::<_CMP_LT_OQ>(disc, zero);
        let root = _mm256_sqrt_ps(disc);
        let b_neg = _mm256_cmp_ps::<_CMP_LT_OQ>(b, zero);
        let q = _mm256_mul_ps(
            _mm256_set1_ps(-0.5),
            blend(b_neg, _mm256_add_ps(b, root), _mm256_sub_ps(b, root)),
        );
        let t0 = _mm256_div_ps(q, a);
        let t1 = _mm256_div_ps(c, q);
        let swap = _mm256_cmp_ps::<_CMP_GT_OQ>(t0, t1);
        let near = blend(swap, t0, t1);
        let far = blend(swap, t1, t0);
        let inside = |t: __m256| {
            and(
                _mm256_cmp_ps::<_CMP_GT_OQ>(t, tmin),
                _mm256_cmp_ps::<_CMP_LT_OQ>(t, tmax),
            )
        };
        let (in_near, in_far) = (inside(near), inside(far));
        (
            blend(in_near, far, near),
            and_not(or(in_near, in_far), miss),
        )
    }

    /// Lanes entering `b` with an entry in `[tmin, tmax]`: the slab test of the tree's nodes
    /// (`node8`), on lanes.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn enters(g: &Group, inv: &[__m256; 3], b: &Aabb, tmin: __m256, tmax: __m256) -> M {
        let mut near = tmin;
        let mut far = _mm256_set1_ps(f32::INFINITY);
        for (a, &inv) in inv.iter().enumerate() {
            // Lanes whose direction is negative on this axis (sign set: `inv` is the
            // blend's mask) meet the upper plane first.
            let (lo, hi) = (_mm256_set1_ps(b.min[a]), _mm256_set1_ps(b.max[a]));
            let t = |plane: __m256| _mm256_mul_ps(_mm256_sub_ps(plane, g.origin[a]), inv);
            // The slab value first: a NaN (a ray in the slab's plane) drops out.
            near = _mm256_max_ps(t(_mm256_blendv_ps(lo, hi, inv)), near);
            far = _mm256_min_ps(t(_mm256_blendv_ps(hi, lo, inv)), far);
        }
        let far = _mm256_min_ps(_mm256_mul_ps(far, _mm256_set1_ps(FAR_WIDEN)), tmax);
        _mm256_cmp_ps::<_CMP_LE_OQ>(near, far)
    }

    /// `avx512::widen`: `t` moved up by 1/1024 of its size and by the smallest normal float.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn widen(t: __m256) -> __m256 {
        let magnitude = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
        _mm256_add_ps(
            _mm256_add_ps(
                t,
                _mm256_mul_ps(_mm256_and_ps(t, magnitude), _mm256_set1_ps(1.0 / 1024.0)),
            ),
            _mm256_set1_ps(f32::MIN_POSITIVE),
        )
    }

    /// Lanes that enter one of `flat.inner` with an entry in `[tmin, tmax]`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn need(flat: &Flat, g: &Group, tmin: __m256, tmax: __m256) -> u16 {
        if flat.inner.is_empty() {
            return 0;
        }
        let one = _mm256_set1_ps(1.0);
        let inv = [
            _mm256_div_ps(one, g.dir[0]),
            _mm256_div_ps(one, g.dir[1]),
            _mm256_div_ps(one, g.dir[2]),
        ];
        let mut need = _mm256_setzero_ps();
        for b in &flat.inner {
            need = or(need, enters(g, &inv, b, tmin, tmax));
        }
        bits(need)
    }

    /// The list's vertices prepared for a group ([`vertex`]), each once.
    struct Prepared {
        items: [std::mem::MaybeUninit<[__m256; 3]>; MAX_VERTICES],
    }

    impl Prepared {
        /// Room for the vertices, none prepared.
        #[inline(always)]
        fn new() -> Prepared {
            Prepared {
                items: [const { std::mem::MaybeUninit::uninit() }; MAX_VERTICES],
            }
        }

        /// Prepares the list's vertices for group `g`, in place (returning kilobytes of
        /// vectors by value would copy them).
        #[inline]
        #[target_feature(enable = "avx2")]
        fn fill(&mut self, flat: &Flat, g: &Group) {
            for (item, v) in self.items.iter_mut().zip(&flat.vertices) {
                *item = std::mem::MaybeUninit::new(vertex(g, v));
            }
        }

        /// The prepared vertices of a triangle.
        #[inline(always)]
        fn get(&self, corners: &[u16; 3]) -> [&[__m256; 3]; 3] {
            // SAFETY: `fill` wrote the first `flat.vertices.len()` items (at most
            // `MAX_VERTICES`: three per primitive of a list), and every corner indexes one.
            corners.map(|i| unsafe { self.items[usize::from(i)].assume_init_ref() })
        }
    }

    /// The running nearest hit of a group's lanes.
    struct Nearest {
        t: __m256,
        v: __m256,
        w: __m256,
        det: __m256,
        prim: __m256,
        found: M,
        /// Lanes where a primitive met the nearest distance found so far exactly.
        tie: M,
    }

    impl Nearest {
        /// Takes a primitive's hits (`hit` lanes at `t`) where they are nearer.
        #[inline]
        #[target_feature(enable = "avx2")]
        fn update(&mut self, t: __m256, v: __m256, w: __m256, det: __m256, prim: u32, hit: M) {
            let nearer = and(hit, _mm256_cmp_ps::<_CMP_LT_OQ>(t, self.t));
            let equal = and(hit, _mm256_cmp_ps::<_CMP_EQ_OQ>(t, self.t));
            self.tie = or(and_not(self.tie, nearer), equal);
            self.t = blend(nearer, self.t, t);
            self.v = blend(nearer, self.v, v);
            self.w = blend(nearer, self.w, w);
            self.det = blend(nearer, self.det, det);
            // The primitive number's bits ride in a float vector (a blend moves bits only).
            let p = _mm256_castsi256_ps(_mm256_set1_epi32(prim as i32));
            self.prim = blend(nearer, self.prim, p);
            self.found = or(self.found, nearer);
        }
    }

    /// [`Flat::closest8`].
    #[target_feature(enable = "avx2")]
    pub(super) fn closest(
        flat: &Flat,
        rays: &[Ray],
        (tmin, tmax): (f32, f32),
        out: &mut [Option<Hit>],
    ) -> Lanes {
        let g = group(rays);
        let (lo, hi) = (_mm256_set1_ps(tmin), _mm256_set1_ps(tmax));
        let zero = _mm256_setzero_ps();
        let mut near = Nearest {
            t: hi,
            v: zero,
            w: zero,
            det: zero,
            prim: _mm256_castsi256_ps(_mm256_set1_epi32(-1)),
            found: zero,
            tie: zero,
        };
        let mut defer = zero;
        let mut prepared = Prepared::new();
        prepared.fill(flat, &g);
        for (corners, (_, prim)) in flat.corners.iter().zip(&flat.triangles) {
            let (t, v, w, det, hit, zeros) = triangle(&g, prepared.get(corners), lo, hi);
            defer = or(defer, zeros);
            near.update(t, v, w, det, *prim, hit);
        }
        for (s, prim) in &flat.spheres {
            let (t, hit) = sphere(&g, s, lo, hi);
            near.update(t, zero, zero, zero, *prim, hit);
        }
        let mut t = [0f32; WIDTH];
        let mut v = [0f32; WIDTH];
        let mut w = [0f32; WIDTH];
        let mut det = [0f32; WIDTH];
        let mut prim = [0u32; WIDTH];
        // SAFETY: each store writes eight lanes into an array of eight.
        unsafe {
            _mm256_storeu_ps(t.as_mut_ptr(), near.t);
            _mm256_storeu_ps(v.as_mut_ptr(), near.v);
            _mm256_storeu_ps(w.as_mut_ptr(), near.w);
            _mm256_storeu_ps(det.as_mut_ptr(), near.det);
            _mm256_storeu_ps(prim.as_mut_ptr().cast(), near.prim);
        }
        let found = bits(near.found);
        let defer = bits(defer) | bits(near.tie);
        // Past a hit the list found, a margin far wider than the slab test's rounding.
        let reach = blend(near.found, hi, widen(near.t));
        let need = need(flat, &g, lo, reach) & !defer;
        for (lane, hit) in out.iter_mut().enumerate().take(WIDTH) {
            *hit = (found & (1 << lane) != 0).then(|| {
                // The barycentric weights `v / det` and `w / det`, zero for spheres.
                let (b1, b2) = if prim[lane] >= flat.first_sphere {
                    (0.0, 0.0)
                } else {
                    let inv = 1.0 / det[lane];
                    (v[lane] * inv, w[lane] * inv)
                };
                Hit {
                    t: t[lane],
                    prim: prim[lane],
                    b1,
                    b2,
                }
            });
        }
        Lanes {
            blocked: 0,
            defer,
            need,
        }
    }

    /// [`Flat::occluded8`].
    #[target_feature(enable = "avx2")]
    pub(super) fn occluded(flat: &Flat, rays: &[Ray], tmin: f32, tmax: &[f32]) -> Lanes {
        let g = group(rays);
        let mut ends = [tmax[0]; WIDTH];
        ends[..tmax.len().min(WIDTH)].copy_from_slice(&tmax[..tmax.len().min(WIDTH)]);
        let lo = _mm256_set1_ps(tmin);
        // SAFETY: eight floats are read from an array of eight.
        let hi = unsafe { _mm256_loadu_ps(ends.as_ptr()) };
        let zero = _mm256_setzero_ps();
        let (mut blocked, mut defer) = (zero, zero);
        let mut prepared = Prepared::new();
        prepared.fill(flat, &g);
        for corners in &flat.corners {
            let (.., hit, zeros) = triangle(&g, prepared.get(corners), lo, hi);
            blocked = or(blocked, hit);
            defer = or(defer, zeros);
        }
        for (s, _) in &flat.spheres {
            blocked = or(blocked, sphere(&g, s, lo, hi).1);
        }
        let (blocked, defer) = (bits(blocked), bits(defer));
        // A lane blocked by another primitive is blocked whatever the deferred test says.
        let defer = defer & !blocked;
        let reach = widen(hi);
        Lanes {
            blocked,
            defer,
            need: need(flat, &g, lo, reach) & !blocked & !defer,
        }
    }
}
