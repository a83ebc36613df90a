//! Four triangles tested against one ray at once: the watertight test of `shapes` on SIMD
//! lanes.

use prism_math::glam::Vec4;
use prism_math::Vec3;

use crate::shapes::{intersect_triangle, RayPre};

/// Four triangles in structure-of-arrays form: `v[i][axis]` holds coordinate `axis` of
/// vertex `i` of the four triangles. Unused lanes hold NaN vertices, which fail every
/// comparison of the test, so they never hit.
/// Aligned to 32 bytes, a pack's 160 bytes always span exactly three cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(crate) struct Tri4 {
    v: [[Vec4; 3]; 3],
    /// Primitive numbers (`u32::MAX` in unused lanes).
    pub(crate) prim: [u32; 4],
}

impl Tri4 {
    /// Packs up to four triangles with their primitive numbers.
    pub(crate) fn new(tris: &[([Vec3; 3], u32)]) -> Tri4 {
        debug_assert!(tris.len() <= 4);
        let mut v = [[Vec4::NAN; 3]; 3];
        let mut prim = [u32::MAX; 4];
        for (lane, (t, p)) in tris.iter().enumerate() {
            for (i, vertex) in t.iter().enumerate() {
                for axis in 0..3 {
                    v[i][axis][lane] = vertex[axis];
                }
            }
            prim[lane] = *p;
        }
        Tri4 { v, prim }
    }

    /// Vertex `i` of the triangle in `lane`, padded to four floats (`x, y, z, 0`).
    pub(crate) fn corner(&self, lane: usize, i: usize) -> [f32; 4] {
        [
            self.v[i][0][lane],
            self.v[i][1][lane],
            self.v[i][2][lane],
            0.0,
        ]
    }

    fn vertex(&self, lane: usize, i: usize) -> Vec3 {
        Vec3::new(self.v[i][0][lane], self.v[i][1][lane], self.v[i][2][lane])
    }

    /// The nearest hit among the four with `tmin < t < tmax`: `(t, lane, b1, b2)`.
    #[inline(always)]
    pub(crate) fn intersect(
        &self,
        r: &RayPre,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, usize, f32, f32)> {
        let [kx, ky, kz] = crate::shapes::PERMS[r.perm];
        let o = r.origin.to_array();
        let rel = |i: usize, axis: usize| self.v[i][axis] - Vec4::splat(o[axis]);
        let (sx, sy, sz) = (
            Vec4::splat(r.shear.x),
            Vec4::splat(r.shear.y),
            Vec4::splat(r.shear.z),
        );
        let (az, bz, cz) = (rel(0, kz), rel(1, kz), rel(2, kz));
        let ax = rel(0, kx) - sx * az;
        let ay = rel(0, ky) - sy * az;
        let bx = rel(1, kx) - sx * bz;
        let by = rel(1, ky) - sy * bz;
        let cx = rel(2, kx) - sx * cz;
        let cy = rel(2, ky) - sy * cz;
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let any_zero = u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero);
        if any_zero.any() {
            // An edge function is exactly zero in single precision: decide these lanes with
            // the scalar test, which recomputes them in double precision.
            return self.scalar(r, tmin, tmax);
        }
        let neg = u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero);
        let pos = u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero);
        // No edge function is zero here, so a lane is inside its triangle when its edge
        // functions are all negative or all positive: exactly one of `neg` and `pos`. A NaN
        // lane is neither. Most packs have no such lane and stop before the division.
        let inside = neg ^ pos;
        if !inside.any() {
            return None;
        }
        let det = u + v + w;
        let t = sz * (u * az + v * bz + w * cz) * (Vec4::ONE / det);
        let hit =
            inside & det.cmpne(zero) & t.cmpgt(Vec4::splat(tmin)) & t.cmplt(Vec4::splat(tmax));
        let mut mask = hit.bitmask();
        if mask == 0 {
            return None;
        }
        let ta = t.to_array();
        let mut best = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if ta[lane] < ta[best] {
                best = lane;
            }
        }
        let inv = 1.0 / det.to_array()[best];
        Some((
            ta[best],
            best,
            v.to_array()[best] * inv,
            w.to_array()[best] * inv,
        ))
    }

    fn scalar(&self, r: &RayPre, tmin: f32, mut tmax: f32) -> Option<(f32, usize, f32, f32)> {
        let mut best = None;
        for lane in 0..4 {
            if self.prim[lane] == u32::MAX {
                continue;
            }
            let tri = [
                self.vertex(lane, 0),
                self.vertex(lane, 1),
                self.vertex(lane, 2),
            ];
            if let Some((t, b1, b2)) = intersect_triangle(r, &tri, tmin, tmax) {
                tmax = t;
                best = Some((t, lane, b1, b2));
            }
        }
        best
    }
}
