//! Rays on SIMD lanes: a group of sixteen (AVX-512) or eight (AVX2) rays prepared as the
//! one-ray tests prepare them, and the one-ray tests' operations on each lane (the
//! watertight triangle test, the sphere test, the slab test), in their order, so that every
//! lane computes the bits the one-ray test computes. The root's list (`traverse::root_list`) and the packet
//! walk (`traverse::packet`) are written in these.

use prism_math::{Aabb, Ray};
use std::arch::x86_64::{_CMP_EQ_OQ, _CMP_GT_OQ, _CMP_LT_OQ};

use crate::hit::Hit;
use crate::layout::node8::FAR_WIDEN;
use crate::shapes::Sphere;
use crate::simd::Simd;

/// The rays of a group on lanes, prepared as the one-ray tests prepare them.
pub(crate) struct Group<S: Simd> {
    pub(crate) origin: [S::F; 3],
    pub(crate) dir: [S::F; 3],
    pub(crate) shear: [S::F; 3],
    /// `is[k][a]`: lanes whose sheared axis `k` is source axis `a` (0 or 1; the other
    /// lanes take axis 2).
    pub(crate) is: [[S::M; 2]; 3],
    /// Per lane, the source axis of sheared axis `k` (0, 1 or 2), and the origin's
    /// coordinate on it.
    pub(crate) axis: [S::I; 3],
    pub(crate) origin_on: [S::F; 3],
}

impl<S: Simd> Group<S> {
    /// Lanes `i < rays.len()` take `rays[i]`; the others repeat the first ray. The shear
    /// and the axis permutation are `RayPre::new`'s, computed on lanes with the same
    /// operations.
    #[inline(always)]
    pub(crate) unsafe fn new(rays: &[Ray]) -> Group<S> {
        // A full group is read in place; a short one is padded, in a copy.
        let padded: [Ray; 16];
        let rays = if rays.len() >= S::W {
            rays
        } else {
            let mut copy = [rays[0]; 16];
            copy[..rays.len()].copy_from_slice(rays);
            padded = copy;
            &padded[..]
        };
        let (o, d) = (
            std::mem::offset_of!(Ray, origin) / 4,
            std::mem::offset_of!(Ray, dir) / 4,
        );
        // SAFETY (all below): the caller runs on `S`'s instruction set.
        unsafe {
            // No closures here: a closure is not compiled for `S`'s instruction set, and
            // the operations it calls would not be inlined into it.
            let origin = [
                S::ray_field(rays, o),
                S::ray_field(rays, o + 1),
                S::ray_field(rays, o + 2),
            ];
            let dir = [
                S::ray_field(rays, d),
                S::ray_field(rays, d + 1),
                S::ray_field(rays, d + 2),
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
    pub(crate) unsafe fn pick(&self, k: usize, v: &[S::F; 3]) -> S::F {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe { S::select(self.is[k][0], S::select(self.is[k][1], v[2], v[1]), v[0]) }
    }

    /// A vertex as every lane's triangle test takes it: its coordinates on the lane's
    /// sheared axes, less the origin's (`v[k] - o[k]`, the one-ray test's values after
    /// reordering `v - o`), the first two sheared.
    #[inline(always)]
    pub(crate) unsafe fn vertex(&self, p: &[f32; 4]) -> [S::F; 3] {
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
/// hierarchy tests it: `(t, v, w, det, hit, zero)`. `zero` holds the lanes with an edge
/// function of exactly zero, which the one-ray test decides in double precision: the
/// caller must decide those lanes by it. `hit` holds the other lanes hit with
/// `tmin < t < tmax`.
#[inline(always)]
#[allow(clippy::type_complexity)]
pub(crate) unsafe fn triangle<S: Simd>(
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
        let det = S::add(S::add(u, v), w);
        let sum = S::add(S::add(S::mul(u, az), S::mul(v, bz)), S::mul(w, cz));
        let t = S::mul(S::mul(sz, sum), S::div(S::splat(1.0), det));
        // With no edge function zero, the one-ray test's `!(neg && pos)` is a shared sign
        // bit, and then `det`, a sum of three numbers of one sign, is not zero. A NaN edge
        // function makes `t` NaN, which no comparison below passes, in both tests alike.
        let inside = S::same_sign(S::and_not(S::all(), zeros), u, v, w);
        let hit = S::cmp_and::<_CMP_LT_OQ>(S::cmp_and::<_CMP_GT_OQ>(inside, t, tmin), t, tmax);
        (t, v, w, det, hit, zeros)
    }
}

/// One sphere's hit on every lane, as `intersect_sphere` finds it: `(t, hit)`, the
/// nearest root with `tmin < t < tmax`.
#[inline(always)]
pub(crate) unsafe fn sphere<S: Simd>(
    g: &Group<S>,
    s: &Sphere,
    tmin: S::F,
    tmax: S::F,
) -> (S::F, S::M) {
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

/// `1 / dir` of a group's rays as the slab tests take it, as `node8::SlabRay` holds it:
/// for the near slabs, and widened by [`FAR_WIDEN`] for the far ones.
pub(crate) struct Inverse<S: Simd> {
    near: [S::F; 3],
    far: [S::F; 3],
}

impl<S: Simd> Inverse<S> {
    /// The inverse directions of group `g`.
    #[inline(always)]
    pub(crate) unsafe fn new(g: &Group<S>) -> Inverse<S> {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let one = S::splat(1.0);
            let near = [
                S::div(one, g.dir[0]),
                S::div(one, g.dir[1]),
                S::div(one, g.dir[2]),
            ];
            let widen = S::splat(FAR_WIDEN);
            let far = [
                S::mul(near[0], widen),
                S::mul(near[1], widen),
                S::mul(near[2], widen),
            ];
            Inverse { near, far }
        }
    }
}

/// The unfused slab test of the tree's nodes (`node8::hit_sse`) on lanes: each lane's entry
/// distance into `b`, and the lanes entering it with an entry in `[tmin, tmax]`. The same
/// distances as that test's, and the same answer (it compares the entry with each far
/// distance that is not NaN and with `tmax`, this test with their minimum): never shorter
/// than the exact interval, so no lane skips a box it meets.
#[inline(always)]
pub(crate) unsafe fn enters<S: Simd>(
    g: &Group<S>,
    inv: &Inverse<S>,
    b: &Aabb,
    tmin: S::F,
    tmax: S::F,
) -> (S::F, S::M) {
    // SAFETY: the caller runs on `S`'s instruction set.
    unsafe {
        let mut near = tmin;
        let mut far = tmax;
        for a in 0..3 {
            // Lanes whose direction is negative on this axis meet the upper plane first.
            let (lo, hi) = (S::splat(b.min[a]), S::splat(b.max[a]));
            let first = S::sub(S::select_sign(inv.near[a], lo, hi), g.origin[a]);
            let last = S::sub(S::select_sign(inv.near[a], hi, lo), g.origin[a]);
            // The slab value first: a NaN (a ray in the slab's plane) drops out.
            near = S::max(S::mul(first, inv.near[a]), near);
            far = S::min(S::mul(last, inv.far[a]), far);
        }
        (near, S::le(near, far))
    }
}

/// `node8::widen` on lanes: `t` moved up past a distance by far more than the tests'
/// rounding, so that no walk or gate drops a child the one-ray walk would enter.
#[inline(always)]
pub(crate) unsafe fn widen<S: Simd>(t: S::F) -> S::F {
    // SAFETY: the caller runs on `S`'s instruction set.
    unsafe {
        S::add(
            S::add(t, S::mul(S::abs(t), S::splat(1.0 / 1024.0))),
            S::splat(f32::MIN_POSITIVE),
        )
    }
}

/// The running nearest hit of a group's lanes.
pub(crate) struct Nearest<S: Simd> {
    pub(crate) t: S::F,
    pub(crate) v: S::F,
    pub(crate) w: S::F,
    pub(crate) det: S::F,
    pub(crate) prim: S::I,
    pub(crate) found: S::M,
    /// Lanes where a primitive met the nearest distance found so far exactly.
    pub(crate) tie: S::M,
}

impl<S: Simd> Nearest<S> {
    /// Nothing found yet on any lane, up to `tmax`.
    #[inline(always)]
    pub(crate) unsafe fn none(tmax: S::F) -> Nearest<S> {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let zero = S::splat(0.0);
            Nearest {
                t: tmax,
                v: zero,
                w: zero,
                det: zero,
                prim: S::splat_i(-1),
                found: S::none(),
                tie: S::none(),
            }
        }
    }

    /// Writes each lane's hit in `lanes` to `out` (none where nothing was found), with the
    /// barycentric weights `v / det` and `w / det` as the one-ray test divides them (zero
    /// for spheres, the primitives from `first_sphere` on).
    #[inline(always)]
    pub(crate) unsafe fn write(&self, first_sphere: u32, lanes: u16, out: &mut [Option<Hit>]) {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let zero = S::splat(0.0);
            let inv = S::div(S::splat(1.0), self.det);
            let sphere = S::ge_u32(self.prim, S::splat_i(first_sphere as i32));
            let b1 = S::select(sphere, S::mul(self.v, inv), zero);
            let b2 = S::select(sphere, S::mul(self.w, inv), zero);
            let mut t = [0f32; 16];
            let mut b = [[0f32; 16]; 2];
            let mut prim = [0u32; 16];
            S::store(self.t, &mut t);
            S::store(b1, &mut b[0]);
            S::store(b2, &mut b[1]);
            S::store_i(self.prim, &mut prim);
            let found = S::bits(self.found);
            for (lane, hit) in out.iter_mut().enumerate().take(S::W) {
                if lanes & (1 << lane) != 0 {
                    *hit = (found & (1 << lane) != 0).then(|| Hit {
                        t: t[lane],
                        prim: prim[lane],
                        b1: b[0][lane],
                        b2: b[1][lane],
                    });
                }
            }
        }
    }

    /// Takes a primitive's hits (`hit` lanes at `t`) where they are nearer.
    #[inline(always)]
    pub(crate) unsafe fn update(
        &mut self,
        (t, v, w, det): (S::F, S::F, S::F, S::F),
        prim: u32,
        hit: S::M,
    ) {
        // SAFETY: the caller runs on `S`'s instruction set.
        unsafe {
            let nearer = S::cmp_and::<_CMP_LT_OQ>(hit, t, self.t);
            let equal = S::cmp_and::<_CMP_EQ_OQ>(hit, t, self.t);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::node8::{hit_sse, Node8, SlabRay};
    use crate::shapes::RayPre;
    use crate::simd::Avx2;
    use prism_math::{Pcg32, Vec3};

    /// [`enters`] for up to eight rays and one box on AVX2: each lane's entry, and the
    /// lanes entering.
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn enters_avx2(rays: &[Ray], b: &Aabb, tmax: f32) -> ([f32; 16], u16) {
        // SAFETY: compiled for AVX2, which the caller guarantees.
        unsafe {
            let g = Group::<Avx2>::new(rays);
            let inv = Inverse::new(&g);
            let (near, enter) = enters(&g, &inv, b, Avx2::splat(0.0), Avx2::splat(tmax));
            let mut out = [0.0; 16];
            Avx2::store(near, &mut out);
            (out, Avx2::bits(enter))
        }
    }

    /// Property: the lanes' slab test enters exactly the children the unfused node test
    /// (`node8::hit_sse`, which the one-ray walks run without AVX2) enters, with entries equal to its
    /// own, on boxes with corners on a small integer grid and rays from grid points along
    /// axes (slab distances of 0 * inf = NaN), through box faces, and in random directions.
    #[test]
    fn lane_slab_test_equals_the_node_test() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let mut rng = Pcg32::new(8, 1);
        let mut entered = 0;
        for k in 0..4000 {
            let mut grid = || (rng.next_u32() % 7) as f32 - 3.0;
            let mut n = Node8::empty();
            let boxes: Vec<Aabb> = (0..8)
                .map(|_| {
                    let a = Vec3::new(grid(), grid(), grid());
                    let b = Vec3::new(grid(), grid(), grid());
                    Aabb {
                        min: a.min(b),
                        max: a.max(b),
                    }
                })
                .collect();
            for (slot, b) in boxes.iter().enumerate() {
                n.set(slot, *b, slot as u32);
            }
            let rays: Vec<Ray> = (0..8)
                .map(|i| {
                    let origin = Vec3::new(grid(), grid(), grid());
                    let dir = match (k + i) % 4 {
                        0 => [Vec3::X, -Vec3::Y, Vec3::Z, -Vec3::X][i % 4],
                        1 => Vec3::new(grid(), grid(), grid() + 0.5),
                        2 => Vec3::new(grid() + 0.37, grid() - 0.21, grid() + 0.05),
                        // At a box's corner, missed or met by a few ulps: where the far
                        // slabs' rounding decides.
                        _ => {
                            let b = &boxes[i];
                            let corner = Vec3::new(b.max.x, b.min.y, b.max.z);
                            let ulps = (grid() * 2.0) * f32::EPSILON;
                            (corner - origin) * (1.0 + ulps) + Vec3::new(0.0, ulps, 0.0)
                        }
                    };
                    Ray::new(origin + Vec3::splat(0.123), dir)
                })
                .collect();
            let tmax = if k % 5 == 0 { 2.5 } else { f32::INFINITY };
            let lanes: Vec<_> = boxes
                .iter()
                // SAFETY: AVX2 was detected above.
                .map(|b| unsafe { enters_avx2(&rays, b, tmax) })
                .collect();
            for (i, ray) in rays.iter().enumerate() {
                let (near, mask) = hit_sse(&n, &SlabRay::new(&RayPre::new(ray)), 0.0, tmax);
                for (slot, (lane_near, lane_mask)) in lanes.iter().enumerate() {
                    let enters = lane_mask >> i & 1 == 1;
                    assert_eq!(
                        enters,
                        mask >> slot & 1 == 1,
                        "case {k} ray {i} slot {slot}"
                    );
                    if enters {
                        assert_eq!(lane_near[i], near[slot], "case {k} ray {i} slot {slot}");
                        entered += 1;
                    }
                }
            }
        }
        assert!(entered > 20_000, "{entered} children entered");
    }
}
