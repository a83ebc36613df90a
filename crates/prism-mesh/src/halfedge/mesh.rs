//! The halfedge mesh type: typed index handles, the mesh's arrays, accessors and traversal.
//! Halfedges come in pairs: the opposite of halfedge `h` is `h ^ 1`, and edge `e` owns
//! halfedges `2e` and `2e + 1`. Boundary halfedges have no face and are linked into boundary
//! loops, so every halfedge has a `next` and a `prev`.

use prism_math::glam::DVec3;

/// The "no element" marker in the index arrays.
pub(super) const NONE: u32 = u32::MAX;

/// Index of a halfedge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct HalfedgeId(pub u32);
/// Index of a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VertexId(pub u32);
/// Index of a face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FaceId(pub u32);
/// Index of an edge (a pair of opposite halfedges).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EdgeId(pub u32);

/// A manifold polygon mesh, possibly with boundaries, in halfedge form.
///
/// Invariants (checked by [`HalfedgeMesh::validate`]): `next` and `prev` are inverse
/// permutations; a halfedge ends where its `next` starts; the halfedges of a face loop back
/// to the face's first halfedge; a vertex's outgoing halfedge starts at it, and is a
/// boundary halfedge when the vertex is on a boundary; the faces around every vertex form a
/// single fan.
#[derive(Clone, Debug, Default)]
pub struct HalfedgeMesh {
    pub(super) positions: Vec<DVec3>,
    pub(super) he_next: Vec<u32>,
    pub(super) he_prev: Vec<u32>,
    pub(super) he_origin: Vec<u32>,
    pub(super) he_face: Vec<u32>,
    pub(super) v_out: Vec<u32>,
    pub(super) f_he: Vec<u32>,
}

impl HalfedgeMesh {
    /// Vertex count.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    /// Edge count.
    #[must_use]
    pub fn edge_count(&self) -> usize {
        self.he_next.len() / 2
    }
    /// Face count.
    #[must_use]
    pub fn face_count(&self) -> usize {
        self.f_he.len()
    }
    /// Halfedge count.
    #[must_use]
    pub fn halfedge_count(&self) -> usize {
        self.he_next.len()
    }
    /// V - E + F.
    #[must_use]
    pub fn euler_characteristic(&self) -> i64 {
        self.vertex_count() as i64 - self.edge_count() as i64 + self.face_count() as i64
    }
    /// Position of a vertex.
    #[must_use]
    pub fn position(&self, v: VertexId) -> DVec3 {
        self.positions[v.0 as usize]
    }
    /// All positions.
    #[must_use]
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }
    /// The next halfedge around its face or boundary loop.
    #[must_use]
    pub fn next(&self, h: HalfedgeId) -> HalfedgeId {
        HalfedgeId(self.he_next[h.0 as usize])
    }
    /// The previous halfedge around its face or boundary loop.
    #[must_use]
    pub fn prev(&self, h: HalfedgeId) -> HalfedgeId {
        HalfedgeId(self.he_prev[h.0 as usize])
    }
    /// The opposite halfedge.
    #[must_use]
    pub fn twin(&self, h: HalfedgeId) -> HalfedgeId {
        HalfedgeId(h.0 ^ 1)
    }
    /// The edge a halfedge belongs to.
    #[must_use]
    pub fn edge(&self, h: HalfedgeId) -> EdgeId {
        EdgeId(h.0 >> 1)
    }
    /// The first halfedge of an edge.
    #[must_use]
    pub fn edge_halfedge(&self, e: EdgeId) -> HalfedgeId {
        HalfedgeId(e.0 << 1)
    }
    /// The vertex a halfedge starts at.
    #[must_use]
    pub fn origin(&self, h: HalfedgeId) -> VertexId {
        VertexId(self.he_origin[h.0 as usize])
    }
    /// The vertex a halfedge ends at.
    #[must_use]
    pub fn dest(&self, h: HalfedgeId) -> VertexId {
        VertexId(self.he_origin[(h.0 ^ 1) as usize])
    }
    /// The face of a halfedge; `None` on the boundary.
    #[must_use]
    pub fn face(&self, h: HalfedgeId) -> Option<FaceId> {
        let f = self.he_face[h.0 as usize];
        (f != NONE).then_some(FaceId(f))
    }
    /// True for a halfedge without a face.
    #[must_use]
    pub fn is_boundary_halfedge(&self, h: HalfedgeId) -> bool {
        self.he_face[h.0 as usize] == NONE
    }
    /// True for an edge with a boundary halfedge.
    #[must_use]
    pub fn is_boundary_edge(&self, e: EdgeId) -> bool {
        let h = self.edge_halfedge(e);
        self.is_boundary_halfedge(h) || self.is_boundary_halfedge(self.twin(h))
    }
    /// An outgoing halfedge of a vertex (the boundary one on a boundary); `None` if isolated.
    #[must_use]
    pub fn vertex_halfedge(&self, v: VertexId) -> Option<HalfedgeId> {
        let h = self.v_out[v.0 as usize];
        (h != NONE).then_some(HalfedgeId(h))
    }
    /// True for a vertex on a boundary.
    #[must_use]
    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        self.vertex_halfedge(v)
            .is_some_and(|h| self.is_boundary_halfedge(h))
    }
    /// The first halfedge of a face.
    #[must_use]
    pub fn face_halfedge(&self, f: FaceId) -> HalfedgeId {
        HalfedgeId(self.f_he[f.0 as usize])
    }

    /// The halfedges of a face, in order.
    pub fn face_halfedges(&self, f: FaceId) -> impl Iterator<Item = HalfedgeId> + '_ {
        let start = self.face_halfedge(f);
        let mut cur = Some(start);
        let limit = self.he_next.len();
        let mut steps = 0;
        std::iter::from_fn(move || {
            let h = cur?;
            steps += 1;
            let n = self.next(h);
            cur = (n != start && steps < limit).then_some(n);
            Some(h)
        })
    }

    /// The outgoing halfedges of a vertex, rotating from its stored halfedge.
    pub fn outgoing(&self, v: VertexId) -> impl Iterator<Item = HalfedgeId> + '_ {
        let start = self.vertex_halfedge(v);
        let mut cur = start;
        let limit = self.he_next.len();
        let mut steps = 0;
        std::iter::from_fn(move || {
            let h = cur?;
            steps += 1;
            let n = self.twin(self.prev(h));
            cur = (Some(n) != start && steps < limit).then_some(n);
            Some(h)
        })
    }

    /// The edge between two vertices, if there is one.
    #[must_use]
    pub fn find_edge(&self, a: VertexId, b: VertexId) -> Option<EdgeId> {
        self.outgoing(a)
            .find(|&h| self.dest(h) == b)
            .map(|h| self.edge(h))
    }
}
