//! The packet walk: a group of coherent rays (sixteen with AVX-512, eight with AVX2) walked
//! through the tree together, for rays such as a camera's that share an origin and head the
//! same way. Each node's children are tested against every ray of the packet on lanes, and
//! each leaf's triangles likewise, with the one-ray tests' operations on each lane
//! (`simd::lanes`). A child is entered by the lanes that enter its box no farther than their
//! nearest hit, widened as the one-ray walk widens it, so both walks meet the same nearest
//! hit. A lane whose answer depends on the one-ray walk's choice by primitive number (two
//! primitives at one distance) or on its double-precision edge test (an edge function of
//! exactly zero) is left to that walk.

use prism_math::Ray;

use super::stack::STACK;
use crate::hit::Hit;
use crate::layout::{Bvh, LEAF};
use crate::simd::lanes::{enters, sphere, triangle, widen, Group, Inverse, Nearest};
use crate::simd::{Avx2, Avx512, Simd};

/// True if `rays` are worth walking as one packet: as many as the lanes, one origin (to the
/// bit) and directions in one octant.
pub(crate) fn coherent(rays: &[Ray], width: usize) -> bool {
    let Some(first) = rays.first() else {
        return false;
    };
    let bits = |r: &Ray| r.origin.to_array().map(f32::to_bits);
    let signs = |r: &Ray| r.dir.to_array().map(f32::is_sign_negative);
    let (o, s) = (bits(first), signs(first));
    rays.len() == width && rays.iter().all(|r| bits(r) == o && signs(r) == s)
}

/// The pending children of a packet walk: a node or leaf reference, the lanes that entered
/// it and their entry distances. Entries are written before they are read.
pub(crate) struct Pending<S: Simd> {
    pub(crate) node: [u32; STACK],
    pub(crate) lanes: [u16; STACK],
    pub(crate) near: [std::mem::MaybeUninit<S::F>; STACK],
}

/// A packet walk's query: the rays (at most the lanes), their common start `tmin`, each
/// lane's end, the lanes to answer, and the root's slots to leave out (as the one-ray walk
/// leaves out the list's leaves).
pub(crate) struct Query<'a> {
    pub(crate) rays: &'a [Ray],
    pub(crate) tmin: f32,
    /// Each lane's end (sixteen; past the rays, any value).
    pub(crate) ends: [f32; 16],
    pub(crate) lanes: u16,
    pub(crate) skip: u32,
}

/// The closest hits of the query's rays with `tmin < t < end`, written to `out` (one per
/// ray, in the query's lanes) except in the lanes the returned bits name, whose answer must
/// come from the one-ray walk.
#[inline(always)]
pub(crate) unsafe fn closest<S: Simd>(bvh: &Bvh, q: &Query, out: &mut [Option<Hit>]) -> u16 {
    let n = q.rays.len().min(S::W);
    let real = q.lanes & if n >= 16 { u16::MAX } else { (1u16 << n) - 1 };
    // SAFETY (all below): the caller runs on `S`'s instruction set.
    unsafe {
        let g = Group::<S>::new(q.rays);
        let inv = Inverse::<S>::new(&g);
        let (lo, hi) = (S::splat(q.tmin), S::load(&q.ends));
        let zero = S::splat(0.0);
        let mut best = Nearest::<S>::none(hi);
        let mut reach = widen::<S>(hi);
        let mut defer = S::none();
        let mut stack = Pending::<S> {
            node: [0; STACK],
            lanes: [0; STACK],
            near: [const { std::mem::MaybeUninit::uninit() }; STACK],
        };
        let nodes = bvh.node_array();
        // The root, entered by every real lane at `tmin`.
        let (mut node, mut active) = (0u32, S::from_bits(real));
        let mut sp = 0usize;
        loop {
            if node & LEAF != 0 {
                let rec = bvh.leaf_rec(node);
                let p0 = rec.pack_start as usize;
                for pack in &bvh.packs[p0..p0 + rec.packs as usize] {
                    for (slot, &prim) in pack.prim.iter().enumerate() {
                        if prim == u32::MAX {
                            break;
                        }
                        let a = g.vertex(&pack.corner(slot, 0));
                        let b = g.vertex(&pack.corner(slot, 1));
                        let c = g.vertex(&pack.corner(slot, 2));
                        let (t, v, w, det, hit, zeros) = triangle(&g, [&a, &b, &c], lo, hi);
                        defer = S::or(defer, S::and(zeros, active));
                        best.update((t, v, w, det), prim, S::and(hit, active));
                    }
                }
                let s0 = rec.sphere_start as usize;
                for &prim in &bvh.leaf_spheres[s0..s0 + rec.spheres as usize] {
                    let s = &bvh.spheres[(prim - bvh.triangle_count) as usize];
                    let (t, hit) = sphere(&g, s, lo, hi);
                    best.update((t, zero, zero, zero), prim, S::and(hit, active));
                }
                reach = widen::<S>(best.t);
            } else {
                let n = &nodes[node as usize];
                // The children entered, nearest (by the least entry of their lanes) first.
                let mut entered = [(0u32, 0u16, 0f32, 0usize); 8];
                let mut nears = [zero; 8];
                let mut count = 0;
                let mut used = n.used();
                if node == 0 {
                    used &= !q.skip;
                }
                while used != 0 {
                    let slot = used.trailing_zeros() as usize;
                    used &= used - 1;
                    let (near, enter) = enters(&g, &inv, &n.child_box(slot), lo, reach);
                    let enter = S::and(enter, active);
                    let bits = S::bits(enter);
                    if bits == 0 {
                        continue;
                    }
                    let key = S::min_of(enter, near);
                    let mut j = count;
                    while j > 0 && entered[j - 1].2 > key {
                        entered[j] = entered[j - 1];
                        j -= 1;
                    }
                    entered[j] = (n.child[slot], bits, key, count);
                    nears[count] = near;
                    count += 1;
                }
                if count > 0 {
                    // Push all but the nearest, farthest first; go on to the nearest.
                    for &(child, bits, _, k) in entered[1..count].iter().rev() {
                        stack.node[sp] = child;
                        stack.lanes[sp] = bits;
                        stack.near[sp] = std::mem::MaybeUninit::new(nears[k]);
                        sp += 1;
                    }
                    node = entered[0].0;
                    active = S::from_bits(entered[0].1);
                    continue;
                }
            }
            // Pop the nearest pending child that some lane may still find a nearer hit in.
            loop {
                if sp == 0 {
                    best.write(bvh.triangle_count, real, out);
                    return S::bits(S::or(defer, best.tie)) & real;
                }
                sp -= 1;
                let near = stack.near[sp].assume_init();
                let lanes = S::and(S::from_bits(stack.lanes[sp]), S::le(near, reach));
                if S::bits(lanes) != 0 {
                    node = stack.node[sp];
                    active = lanes;
                    break;
                }
            }
        }
    }
}

/// [`closest`] on sixteen lanes.
///
/// # Safety
/// The processor must support AVX-512F.
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn closest_avx512(bvh: &Bvh, q: &Query, out: &mut [Option<Hit>]) -> u16 {
    // SAFETY: compiled for AVX-512F, which the caller guarantees.
    unsafe { closest::<Avx512>(bvh, q, out) }
}

/// [`closest`] on eight lanes of AVX2.
///
/// # Safety
/// The processor must support AVX2.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn closest_avx2(bvh: &Bvh, q: &Query, out: &mut [Option<Hit>]) -> u16 {
    // SAFETY: compiled for AVX2, which the caller guarantees.
    unsafe { closest::<Avx2>(bvh, q, out) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::BuildOptions;
    use prism_math::{Isa, Pcg32, Vec3};

    /// A bumpy closed sphere of `n` by `n / 2` quads split on their diagonals, an
    /// axis-aligned grid of unit squares at `z = -5` (split on their diagonals too), a few
    /// of the grid's triangles twice and a large triangle over half the grid: shared edges
    /// and vertices that rays through grid points meet exactly, and pairs of primitives at
    /// one distance.
    fn scene(n: usize) -> Vec<[Vec3; 3]> {
        let mut tris = vec![];
        let at = |i: usize, j: usize| {
            let (th, ph) = (
                std::f32::consts::PI * j as f32 / (n / 2) as f32,
                std::f32::consts::TAU * i as f32 / n as f32,
            );
            let r = 3.0 + 0.2 * (5.0 * ph).sin() * (3.0 * th).cos();
            Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * r
        };
        for j in 0..n / 2 {
            for i in 0..n {
                let (a, b) = (at(i, j), at((i + 1) % n, j));
                let (c, d) = (at(i, j + 1), at((i + 1) % n, j + 1));
                tris.push([a, b, d]);
                tris.push([a, d, c]);
            }
        }
        for y in -8..8 {
            for x in -8..8 {
                let p = |dx: i32, dy: i32| Vec3::new((x + dx) as f32, (y + dy) as f32, -5.0);
                tris.push([p(0, 0), p(1, 0), p(1, 1)]);
                tris.push([p(0, 0), p(1, 1), p(0, 1)]);
                if (x + y) % 5 == 0 {
                    tris.push([p(0, 0), p(1, 0), p(1, 1)]);
                }
            }
        }
        // A large triangle in the grid's plane, over half of it: hits at the grid's
        // distances from a primitive in another part of the tree.
        let p = |x: f32, y: f32| Vec3::new(x, y, -5.0);
        tris.push([p(-8.0, -8.0), p(8.0, -8.0), p(8.0, 8.0)]);
        tris
    }

    /// Oracle: the one-ray walk. Walks `rays` as packets of sixteen and of eight lanes (on
    /// the instruction sets the processor has) with `tmin < t < tmax`, asserts that every
    /// lane a packet answers has the one-ray walk's hit, bit for bit, and returns how many
    /// lanes were walked and how many were left to the one-ray walk.
    fn check(bvh: &Bvh, rays: &[Ray], (tmin, tmax): (f32, f32), what: &str) -> (usize, usize) {
        let (mut lanes, mut deferred) = (0, 0);
        for (width, isa) in [(16, Isa::Avx512), (8, Isa::Avx2)] {
            if Isa::get() < isa {
                continue;
            }
            for rays in rays.chunks(width) {
                let q = Query {
                    rays,
                    tmin,
                    ends: [tmax; 16],
                    lanes: u16::MAX,
                    skip: 0,
                };
                let mut out = vec![None; width];
                // SAFETY: the processor has the instruction set (checked above).
                let defer = unsafe {
                    if width == 16 {
                        closest_avx512(bvh, &q, &mut out)
                    } else {
                        closest_avx2(bvh, &q, &mut out)
                    }
                };
                for (lane, ray) in rays.iter().enumerate() {
                    lanes += 1;
                    if defer & (1 << lane) != 0 {
                        deferred += 1;
                        continue;
                    }
                    let want = bvh.intersect(ray, tmin, tmax);
                    assert_eq!(
                        bits(out[lane]),
                        bits(want),
                        "{what}, width {width}, lane {lane}"
                    );
                }
            }
        }
        (lanes, deferred)
    }

    /// A hit's bits, for exact comparison.
    fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
        h.map(|h| (h.t.to_bits(), h.prim, h.b1.to_bits(), h.b2.to_bits()))
    }

    /// Oracle: the one-ray walk. Packets of coherent rays (a pinhole camera's, from inside
    /// and outside the sphere, and from grid points towards grid points), and packets of
    /// hostile directions (along an axis, tiny, subnormal, zero, NaN, infinite), get the
    /// one-ray walk's hit, bit for bit, in every lane they answer; they leave few lanes to
    /// it.
    #[test]
    fn packets_equal_the_one_ray_walk() {
        let bvh = Bvh::build(&scene(48), &[], &BuildOptions::default());
        let mut rng = Pcg32::new(11, 3);
        let mut r = || rng.next_f32();
        let (mut lanes, mut deferred) = (0, 0);
        for group in 0..600 {
            let origin = match group % 4 {
                0 => Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5),
                1 => Vec3::new(r() * 20.0 - 10.0, r() * 20.0 - 10.0, 9.0),
                _ => Vec3::new((group % 7) as f32 - 3.0, (group % 5) as f32 - 2.0, 1.0),
            };
            let aim = Vec3::new(r() * 8.0 - 4.0, r() * 8.0 - 4.0, -5.0);
            let rays: Vec<Ray> = (0..16)
                .map(|k| {
                    let step = Vec3::new((k % 4) as f32, (k / 4) as f32, 0.0);
                    let target = match group % 4 {
                        // Grid points: shared vertices of the grid's triangles.
                        2 => aim.round() + step,
                        // Points inside the grid's squares, computed exactly in floats: the
                        // square's triangle and the large one meet them at one distance.
                        3 => aim.round() + step + Vec3::new(0.75, 0.25, 0.0),
                        _ => aim + step * 0.05,
                    };
                    Ray::new(origin, target - origin)
                })
                .collect();
            let tmax = if group % 4 == 0 { 8.0 } else { f32::INFINITY };
            let (n, d) = check(&bvh, &rays, (1e-3, tmax), &format!("group {group}"));
            lanes += n;
            deferred += d;
        }
        // Hostile lanes: directions along an axis (slab planes the ray lies in), tiny,
        // subnormal, zero and NaN components, from a grid point and from the sphere's
        // centre.
        let odd = [
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(0.0, 1e-30, -1.0),
            Vec3::new(1e-40, 0.0, -1.0),
            Vec3::new(0.0, 0.0, -1e-30),
            Vec3::new(0.5, 0.5, -1e-38),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(f32::NAN, 0.0, -1.0),
            Vec3::new(0.0, f32::INFINITY, -1.0),
        ];
        for origin in [
            Vec3::new(1.0, 2.0, 1.0),
            Vec3::ZERO,
            Vec3::new(0.5, 0.5, -5.0),
        ] {
            let rays: Vec<Ray> = odd
                .iter()
                .chain(&odd)
                .map(|&d| Ray::new(origin, d))
                .collect();
            check(&bvh, &rays, (0.0, f32::INFINITY), &format!("from {origin}"));
        }
        // Grid-point packets meet edges exactly and duplicated triangles: some lanes are
        // left to the one-ray walk, but few.
        assert!(
            deferred > 0 && deferred * 10 < lanes,
            "{deferred} of {lanes}"
        );
    }

    /// Property: only groups of one origin and one direction octant, as long as the lanes,
    /// are packets.
    #[test]
    fn coherence_needs_one_origin_and_one_octant() {
        let o = Vec3::new(1.0, 2.0, 3.0);
        let rays: Vec<Ray> = (0..8)
            .map(|k| Ray::new(o, Vec3::new(0.1 * k as f32 + 0.1, -1.0, 0.5)))
            .collect();
        assert!(coherent(&rays, 8));
        assert!(!coherent(&rays[..7], 8));
        assert!(!coherent(&[], 8));
        let mut moved = rays.clone();
        moved[5].origin.x = f32::from_bits(moved[5].origin.x.to_bits() + 1);
        assert!(!coherent(&moved, 8));
        let mut turned = rays.clone();
        turned[3].dir.y = 1.0;
        assert!(!coherent(&turned, 8));
    }
}
