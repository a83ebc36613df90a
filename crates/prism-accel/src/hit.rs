//! [`Hit`], what a query returns, and [`Limit`], the order in which the walks keep hits
//! (by distance, then primitive number).

/// The closest (or any) hit along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// The primitive: triangles are numbered first, then spheres.
    pub prim: u32,
    /// Barycentric weight of the triangle's second vertex (0 for spheres).
    pub b1: f32,
    /// Barycentric weight of the triangle's third vertex (0 for spheres).
    pub b2: f32,
}

/// Where a closest-hit walk stands: a hit counts only if it comes before `(t, prim)` in the
/// order of distance, then primitive number. The walks keep the first hit in that order,
/// so two primitives at one distance are decided by their numbers, not by the order the
/// walk happens to meet them in: a ray's hit does not depend on the hierarchy's shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Limit {
    pub(crate) t: f32,
    pub(crate) prim: u32,
}

impl Limit {
    /// A query's own end: hits before `tmax` count, none at it.
    #[inline(always)]
    pub(crate) fn end(tmax: f32) -> Limit {
        Limit { t: tmax, prim: 0 }
    }

    /// True if a hit at `t` on primitive `prim` comes before this limit.
    #[inline(always)]
    pub(crate) fn admits(&self, t: f32, prim: u32) -> bool {
        t < self.t || (t == self.t && prim < self.prim)
    }
}
