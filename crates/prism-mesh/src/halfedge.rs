//! A halfedge mesh with typed index handles. Halfedges come in pairs: the opposite of
//! halfedge `h` is `h ^ 1`, and edge `e` owns halfedges `2e` and `2e + 1`. Boundary
//! halfedges have no face and are linked into boundary loops, so every halfedge has a
//! `next` and a `prev`.

use prism_math::glam::DVec3;

use crate::{MeshError, PolyMesh};

const NONE: u32 = u32::MAX;

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
    positions: Vec<DVec3>,
    he_next: Vec<u32>,
    he_prev: Vec<u32>,
    he_origin: Vec<u32>,
    he_face: Vec<u32>,
    v_out: Vec<u32>,
    f_he: Vec<u32>,
}

impl HalfedgeMesh {
    /// Builds the halfedge structure of a polygon soup.
    ///
    /// # Errors
    /// [`MeshError::Topology`] naming the face for an index out of range, a face with fewer
    /// than three distinct vertices, or an edge used twice in the same direction (a
    /// non-manifold edge or inconsistent orientation); [`MeshError::NonManifoldVertex`] for
    /// a vertex whose faces form more than one fan.
    pub fn from_polymesh(mesh: &PolyMesh) -> Result<HalfedgeMesh, MeshError> {
        let nv = mesh.vertex_count();
        let starts = mesh.face_starts();
        let corners = mesh.corners();
        let nc = corners.len();
        if nc >= (NONE / 2) as usize {
            return Err(MeshError::Topology {
                face: 0,
                message: format!("{nc} face corners are more than this mesh type holds"),
            });
        }
        // Faces: sizes, index ranges, repeated vertices.
        for (fi, face) in mesh.faces().enumerate() {
            let err = |message: String| MeshError::Topology { face: fi, message };
            if face.len() < 3 {
                return Err(err(format!(
                    "has {} vertices; a face needs at least 3",
                    face.len()
                )));
            }
            for (k, &v) in face.iter().enumerate() {
                if v as usize >= nv {
                    return Err(err(format!(
                        "vertex index {v} is out of range (mesh has {nv} vertices)"
                    )));
                }
                if face[..k].contains(&v) {
                    return Err(err(format!(
                        "vertex {v} appears twice: the face is degenerate"
                    )));
                }
            }
        }
        // Each corner c starts the directed edge corners[c] -> corners[next[c]].
        let mut next = vec![0u32; nc];
        let mut face_of = vec![0u32; nc];
        for f in 0..mesh.face_count() {
            let (s, e) = (starts[f] as usize, starts[f + 1] as usize);
            for c in s..e {
                next[c] = if c + 1 == e { s as u32 } else { c as u32 + 1 };
                face_of[c] = f as u32;
            }
        }
        let dest = |c: usize| corners[next[c] as usize];
        // Directed edges grouped by origin (a counting sort), each group sorted by
        // destination, so twins are found by binary search and repeats are neighbours.
        let mut offset = vec![0u32; nv + 1];
        for &v in corners {
            offset[v as usize + 1] += 1;
        }
        for v in 0..nv {
            offset[v + 1] += offset[v];
        }
        let mut by_origin = vec![0u32; nc];
        {
            let mut fill = offset.clone();
            for (c, &v) in corners.iter().enumerate() {
                by_origin[fill[v as usize] as usize] = c as u32;
                fill[v as usize] += 1;
            }
        }
        let mut out_count: Vec<u32> = (0..nv).map(|v| offset[v + 1] - offset[v]).collect();
        for v in 0..nv {
            let group = &mut by_origin[offset[v] as usize..offset[v + 1] as usize];
            group.sort_unstable_by_key(|&c| (dest(c as usize), c));
            // The same directed edge twice: report the later face, as reading in order would.
            for w in 1..group.len() {
                let (c0, c1) = (group[w - 1] as usize, group[w] as usize);
                if dest(c0) == dest(c1) {
                    return Err(MeshError::Topology {
                        face: face_of[c1] as usize,
                        message: format!(
                            "edge {v}-{} is already used in this direction: non-manifold edge or inconsistent orientation",
                            dest(c1)
                        ),
                    });
                }
            }
        }
        let twin_corner = |c: usize| -> Option<usize> {
            let (a, b) = (corners[c], dest(c));
            let group = &by_origin[offset[b as usize] as usize..offset[b as usize + 1] as usize];
            group
                .binary_search_by_key(&a, |&d| dest(d as usize))
                .ok()
                .map(|i| group[i] as usize)
        };
        // Halfedge ids: edges numbered in order of first use, (a, b) even where first seen.
        let mut hid = vec![NONE; nc];
        let mut edges = 0u32;
        for c in 0..nc {
            if hid[c] != NONE {
                continue;
            }
            let h = 2 * edges;
            edges += 1;
            hid[c] = h;
            if let Some(t) = twin_corner(c) {
                hid[t] = h + 1;
            }
        }
        let nh = 2 * edges as usize;
        let mut m = HalfedgeMesh {
            positions: mesh.positions.clone(),
            v_out: vec![NONE; nv],
            he_next: vec![NONE; nh],
            he_prev: vec![NONE; nh],
            he_origin: vec![NONE; nh],
            he_face: vec![NONE; nh],
            f_he: starts[..mesh.face_count()]
                .iter()
                .map(|&s| hid[s as usize])
                .collect(),
        };
        for c in 0..nc {
            let h = hid[c] as usize;
            let n = hid[next[c] as usize] as usize;
            m.he_origin[h] = corners[c];
            m.he_origin[h ^ 1] = dest(c);
            m.he_face[h] = face_of[c];
            m.he_next[h] = n as u32;
            m.he_prev[n] = h as u32;
        }
        drop((next, face_of, by_origin, hid));
        // Link boundary halfedges into loops.
        let mut boundary_out: Vec<u32> = vec![NONE; nv];
        for h in 0..m.he_next.len() as u32 {
            if m.he_face[h as usize] == NONE {
                let o = m.he_origin[h as usize] as usize;
                out_count[o] += 1;
                if boundary_out[o] != NONE {
                    return Err(MeshError::NonManifoldVertex {
                        vertex: o,
                        message: "two boundary loops meet here".into(),
                    });
                }
                boundary_out[o] = h;
            }
        }
        for h in 0..m.he_next.len() as u32 {
            if m.he_face[h as usize] == NONE {
                let dest = m.he_origin[(h ^ 1) as usize] as usize;
                let n = boundary_out[dest];
                m.he_next[h as usize] = n;
                m.he_prev[n as usize] = h;
            }
        }
        // Outgoing halfedges: the boundary one where there is one.
        for h in 0..m.he_next.len() as u32 {
            let o = m.he_origin[h as usize] as usize;
            if m.v_out[o] == NONE {
                m.v_out[o] = h;
            }
        }
        for (v, &b) in boundary_out.iter().enumerate() {
            if b != NONE {
                m.v_out[v] = b;
            }
        }
        // Every vertex must be a single fan.
        for (v, &count) in out_count.iter().enumerate() {
            if m.v_out[v] == NONE {
                continue;
            }
            let fan = m.outgoing(VertexId(v as u32)).count() as u32;
            if fan != count {
                return Err(MeshError::NonManifoldVertex {
                    vertex: v,
                    message: format!("its {count} outgoing halfedges form more than one fan"),
                });
            }
        }
        Ok(m)
    }

    /// Converts back to a polygon mesh: the same vertices in the same order, and each face
    /// starting at the same vertex as when built.
    #[must_use]
    pub fn to_polymesh(&self) -> PolyMesh {
        let mut p = PolyMesh::new(self.positions.clone(), &[]);
        let mut face = Vec::new();
        for f in 0..self.f_he.len() {
            face.clear();
            face.extend(
                self.face_halfedges(FaceId(f as u32))
                    .map(|h| self.origin(h).0),
            );
            p.push_face(&face);
        }
        p
    }

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

    /// The two halfedges of `e` if it exists, is interior, and lies between two triangles;
    /// `boundary_note` is appended to the boundary refusal.
    fn interior_triangle_edge(
        &self,
        e: EdgeId,
        boundary_note: &str,
    ) -> Result<(HalfedgeId, HalfedgeId), String> {
        if e.0 as usize >= self.edge_count() {
            return Err(format!(
                "edge {} does not exist ({} edges)",
                e.0,
                self.edge_count()
            ));
        }
        if self.is_boundary_edge(e) {
            return Err(format!("edge {} is on the boundary{boundary_note}", e.0));
        }
        let h = self.edge_halfedge(e);
        let t = self.twin(h);
        for side in [h, t] {
            let f = self.face(side).expect("interior");
            if self.face_halfedges(f).count() != 3 {
                return Err(format!("edge {}: face {} is not a triangle", e.0, f.0));
            }
        }
        Ok((h, t))
    }

    /// Whether [`HalfedgeMesh::flip`] may flip edge `e`: it must be interior, both its
    /// faces triangles, and the two opposite vertices distinct and not already joined (which
    /// also refuses flips that would leave a vertex of valence 2).
    ///
    /// # Errors
    /// Why the flip is refused.
    pub fn can_flip(&self, e: EdgeId) -> Result<(), String> {
        let (h, t) = self.interior_triangle_edge(e, "")?;
        let c = self.origin(self.prev(h));
        let d = self.origin(self.prev(t));
        if c == d {
            return Err(format!(
                "edge {}: both opposite vertices are vertex {}",
                e.0, c.0
            ));
        }
        if self.find_edge(c, d).is_some() {
            return Err(format!(
                "edge {}: vertices {} and {} are already joined",
                e.0, c.0, d.0
            ));
        }
        Ok(())
    }

    /// Flips interior edge `e` between triangles (a, b, c) and (b, a, d) to join c and d.
    /// The edge keeps its index; the two faces keep theirs.
    ///
    /// # Errors
    /// As [`HalfedgeMesh::can_flip`]; the mesh is unchanged on error.
    pub fn flip(&mut self, e: EdgeId) -> Result<(), String> {
        self.can_flip(e)?;
        let h = self.edge_halfedge(e).0 as usize;
        let t = h ^ 1;
        let (hn, hp) = (self.he_next[h] as usize, self.he_prev[h] as usize);
        let (tn, tp) = (self.he_next[t] as usize, self.he_prev[t] as usize);
        let (a, b) = (self.he_origin[h], self.he_origin[t]);
        let (c, d) = (self.he_origin[hp], self.he_origin[tp]);
        let (f0, f1) = (self.he_face[h], self.he_face[t]);
        // New loops: h (d->c), hp (c->a), tn (a->d); t (c->d), tp (d->b), hn (b->c).
        self.he_origin[h] = d;
        self.he_origin[t] = c;
        let link = |m: &mut HalfedgeMesh, x: usize, y: usize| {
            m.he_next[x] = y as u32;
            m.he_prev[y] = x as u32;
        };
        link(self, h, hp);
        link(self, hp, tn);
        link(self, tn, h);
        link(self, t, tp);
        link(self, tp, hn);
        link(self, hn, t);
        self.he_face[tn] = f0;
        self.he_face[hn] = f1;
        self.f_he[f0 as usize] = h as u32;
        self.f_he[f1 as usize] = t as u32;
        if self.v_out[a as usize] == h as u32 {
            self.v_out[a as usize] = tn as u32;
        }
        if self.v_out[b as usize] == t as u32 {
            self.v_out[b as usize] = hn as u32;
        }
        Ok(())
    }

    /// Whether [`HalfedgeMesh::split`] may split edge `e`: the edge must exist and its
    /// faces (one on a boundary edge) must be triangles.
    ///
    /// # Errors
    /// Why the split is refused.
    pub fn can_split(&self, e: EdgeId) -> Result<(), String> {
        if e.0 as usize >= self.edge_count() {
            return Err(format!(
                "edge {} does not exist ({} edges)",
                e.0,
                self.edge_count()
            ));
        }
        let h = self.edge_halfedge(e);
        for side in [h, self.twin(h)] {
            if let Some(f) = self.face(side) {
                if self.face_halfedges(f).count() != 3 {
                    return Err(format!("edge {}: face {} is not a triangle", e.0, f.0));
                }
            }
        }
        Ok(())
    }

    fn new_edge(&mut self, a: u32, b: u32) -> (usize, usize) {
        let h = self.he_next.len();
        for o in [a, b] {
            self.he_origin.push(o);
            self.he_face.push(NONE);
            self.he_next.push(NONE);
            self.he_prev.push(NONE);
        }
        (h, h + 1)
    }

    fn link(&mut self, x: usize, y: usize) {
        self.he_next[x] = y as u32;
        self.he_prev[y] = x as u32;
    }

    fn set_face(&mut self, f: u32, hs: [usize; 3]) {
        for k in 0..3 {
            self.link(hs[k], hs[(k + 1) % 3]);
            self.he_face[hs[k]] = f;
        }
        self.f_he[f as usize] = hs[0] as u32;
    }

    /// Splits edge `e` at its midpoint, joining the new vertex to the opposite corner of
    /// each adjacent triangle. An interior edge gains 1 vertex, 3 edges and 2 faces; a
    /// boundary edge 1 vertex, 2 edges and 1 face. Returns the new vertex.
    ///
    /// # Errors
    /// As [`HalfedgeMesh::can_split`]; the mesh is unchanged on error.
    pub fn split(&mut self, e: EdgeId) -> Result<VertexId, String> {
        self.can_split(e)?;
        // Orient so that h has a face.
        let mut h = self.edge_halfedge(e).0 as usize;
        if self.he_face[h] == NONE {
            h ^= 1;
        }
        let t = h ^ 1;
        let (a, b) = (self.he_origin[h], self.he_origin[t]);
        let mid = (self.positions[a as usize] + self.positions[b as usize]) * 0.5;
        let m = self.positions.len() as u32;
        self.positions.push(mid);
        self.v_out.push(NONE);
        let (hn, hp) = (self.he_next[h] as usize, self.he_prev[h] as usize);
        let c = self.he_origin[hp];
        let f0 = self.he_face[h];
        let t_boundary = self.he_face[t] == NONE;
        let (tn, tp) = (self.he_next[t] as usize, self.he_prev[t] as usize);
        // h becomes a -> m, t becomes m -> a.
        self.he_origin[t] = m;
        let (h2, t2) = self.new_edge(m, b);
        let (h3, t3) = self.new_edge(m, c);
        let f2 = self.f_he.len() as u32;
        self.f_he.push(NONE);
        self.set_face(f0, [h, h3, hp]);
        self.set_face(f2, [h2, hn, t3]);
        if t_boundary {
            // Boundary loop: ... -> t2 (b -> m) -> t (m -> a) -> ...
            self.link(tp, t2);
            self.link(t2, t);
            self.link(t, tn);
            if self.v_out[b as usize] == t as u32 {
                self.v_out[b as usize] = t2 as u32;
            }
            self.v_out[m as usize] = t as u32;
        } else {
            let d = self.he_origin[tp];
            let f1 = self.he_face[t];
            let (h4, t4) = self.new_edge(m, d);
            let f3 = self.f_he.len() as u32;
            self.f_he.push(NONE);
            self.set_face(f1, [t, tn, t4]);
            self.set_face(f3, [t2, h4, tp]);
            if self.v_out[b as usize] == t as u32 {
                self.v_out[b as usize] = t2 as u32;
            }
            self.v_out[m as usize] = h2 as u32;
        }
        Ok(VertexId(m))
    }

    /// Whether [`HalfedgeMesh::collapse`] may collapse edge `e`. The edge's faces (two, or
    /// one on a boundary edge) must be triangles, and the result must stay a manifold:
    /// - the link condition: the endpoints share no neighbour but the opposite vertices;
    /// - an interior edge may not join two boundary vertices (that would pinch the surface);
    /// - a boundary edge's boundary loop must have more than three edges;
    /// - no opposite vertex may be left with valence 2 if interior, or with no face if on
    ///   a boundary (so no face or edge degenerates).
    ///
    /// # Errors
    /// Why the collapse is refused.
    pub fn can_collapse(&self, e: EdgeId) -> Result<(), String> {
        if e.0 as usize >= self.edge_count() {
            return Err(format!(
                "edge {} does not exist ({} edges)",
                e.0,
                self.edge_count()
            ));
        }
        let mut h = self.edge_halfedge(e);
        if self.face(h).is_none() {
            h = self.twin(h);
        }
        let t = self.twin(h);
        let (a, b) = (self.origin(h), self.origin(t));
        let mut opposite = Vec::with_capacity(2);
        for side in [h, t] {
            if let Some(f) = self.face(side) {
                if self.face_halfedges(f).count() != 3 {
                    return Err(format!("edge {}: face {} is not a triangle", e.0, f.0));
                }
                opposite.push(self.origin(self.prev(side)));
            }
        }
        let boundary_edge = opposite.len() == 1;
        if boundary_edge {
            let mut len = 1;
            let mut x = self.next(t);
            while x != t && len <= 3 {
                len += 1;
                x = self.next(x);
            }
            if len <= 3 {
                return Err(format!(
                    "edge {}: its boundary loop has only {len} edges",
                    e.0
                ));
            }
        } else if self.is_boundary_vertex(a) && self.is_boundary_vertex(b) {
            return Err(format!(
                "edge {}: an interior edge between two boundary vertices ({} and {})",
                e.0, a.0, b.0
            ));
        }
        let ring = |v: VertexId| -> Vec<u32> { self.outgoing(v).map(|o| self.dest(o).0).collect() };
        let (ra, rb) = (ring(a), ring(b));
        let mut shared: Vec<u32> = ra.iter().copied().filter(|v| rb.contains(v)).collect();
        shared.sort_unstable();
        let mut expect: Vec<u32> = opposite.iter().map(|v| v.0).collect();
        expect.sort_unstable();
        expect.dedup();
        if shared != expect {
            return Err(format!(
                "edge {}: link condition fails (the endpoints share {} neighbours, expected {})",
                e.0,
                shared.len(),
                expect.len()
            ));
        }
        for &v in &opposite {
            let valence = self.outgoing(v).count();
            if self.is_boundary_vertex(v) {
                if valence <= 2 {
                    return Err(format!(
                        "edge {}: boundary vertex {} would be left with no face",
                        e.0, v.0
                    ));
                }
            } else if valence <= 3 {
                return Err(format!(
                    "edge {}: vertex {} would be left with valence 2",
                    e.0, v.0
                ));
            }
        }
        Ok(())
    }

    /// Moves the data of halfedge `from` into slot `to` and points every reference at `to`.
    fn move_halfedge(&mut self, from: usize, to: usize) {
        self.he_origin[to] = self.he_origin[from];
        self.he_face[to] = self.he_face[from];
        let (n, p) = (self.he_next[from], self.he_prev[from]);
        self.he_next[to] = n;
        self.he_prev[to] = p;
        self.he_prev[n as usize] = to as u32;
        self.he_next[p as usize] = to as u32;
        let f = self.he_face[to];
        if f != NONE && self.f_he[f as usize] == from as u32 {
            self.f_he[f as usize] = to as u32;
        }
        let o = self.he_origin[to] as usize;
        if self.v_out[o] == from as u32 {
            self.v_out[o] = to as u32;
        }
    }

    /// Removes an unreferenced edge pair by moving the last pair into its slots.
    fn remove_edge_pair(&mut self, e: usize) {
        let last = self.edge_count() - 1;
        if e != last {
            for k in 0..2 {
                let (from, to) = (2 * last + k, 2 * e + k);
                // A pair may link to itself (next == twin); remap before moving.
                for arr in [0, 1] {
                    let link = if arr == 0 {
                        self.he_next[from]
                    } else {
                        self.he_prev[from]
                    };
                    if link as usize / 2 == last {
                        let mapped = (2 * e + link as usize % 2) as u32;
                        if arr == 0 {
                            self.he_next[from] = mapped;
                        } else {
                            self.he_prev[from] = mapped;
                        }
                    }
                }
                self.move_halfedge(from, to);
            }
        }
        for arr in [
            &mut self.he_next,
            &mut self.he_prev,
            &mut self.he_origin,
            &mut self.he_face,
        ] {
            arr.truncate(2 * last);
        }
    }

    /// Removes an unreferenced face by moving the last face into its slot.
    fn remove_face(&mut self, f: usize) {
        let last = self.f_he.len() - 1;
        if f != last {
            self.f_he[f] = self.f_he[last];
            let hs: Vec<HalfedgeId> = self.face_halfedges(FaceId(f as u32)).collect();
            for h in hs {
                self.he_face[h.0 as usize] = f as u32;
            }
        }
        self.f_he.truncate(last);
    }

    /// Removes an unreferenced vertex by moving the last vertex into its slot.
    fn remove_vertex(&mut self, v: usize) {
        let last = self.positions.len() - 1;
        if v != last {
            self.positions[v] = self.positions[last];
            self.v_out[v] = self.v_out[last];
            let hs: Vec<HalfedgeId> = self.outgoing(VertexId(v as u32)).collect();
            for h in hs {
                self.he_origin[h.0 as usize] = v as u32;
            }
        }
        self.positions.truncate(last);
        self.v_out.truncate(last);
    }

    /// Collapses edge `e` to its midpoint: the edge's endpoints become one vertex, the
    /// triangles on the edge disappear and their other edges merge pairwise. An interior edge
    /// loses 1 vertex, 3 edges and 2 faces; a boundary edge 1 vertex, 2 edges and 1 face.
    /// Elements are removed by moving the last vertex, edges and faces into the freed slots,
    /// so indices above the removed ones may change. Returns the merged vertex.
    ///
    /// # Errors
    /// As [`HalfedgeMesh::can_collapse`]; the mesh is unchanged on error.
    pub fn collapse(&mut self, e: EdgeId) -> Result<VertexId, String> {
        self.can_collapse(e)?;
        // Orient so that h has a face; t may be a boundary halfedge.
        let mut h = self.edge_halfedge(e).0 as usize;
        if self.he_face[h] == NONE {
            h ^= 1;
        }
        let t = h ^ 1;
        let t_boundary = self.he_face[t] == NONE;
        let (hn, hp) = (self.he_next[h] as usize, self.he_prev[h] as usize);
        let (tn, tp) = (self.he_next[t] as usize, self.he_prev[t] as usize);
        let (a, b) = (self.he_origin[h] as usize, self.he_origin[t] as usize);
        let c = self.he_origin[hp] as usize;
        let f0 = self.he_face[h] as usize;
        let mid = (self.positions[a] + self.positions[b]) * 0.5;
        // The merged vertex's boundary halfedge, if it will be on a boundary.
        let boundary_out = if t_boundary {
            Some(tn)
        } else if self.is_boundary_vertex(VertexId(a as u32)) {
            Some(self.v_out[a] as usize)
        } else if self.is_boundary_vertex(VertexId(b as u32)) {
            Some(self.v_out[b] as usize)
        } else {
            None
        };
        // Everything leaving a now leaves b.
        let from_a: Vec<HalfedgeId> = self.outgoing(VertexId(a as u32)).collect();
        for o in from_a {
            self.he_origin[o.0 as usize] = b as u32;
        }
        if let Some(o) = boundary_out {
            self.v_out[b] = o as u32;
        }
        if t_boundary {
            // The boundary loop skips t (before the move below, which may relocate tn).
            self.link(tp, tn);
        }
        // Merge b-c: slot hn takes the outer halfedge of c-a (now b->c).
        self.move_halfedge(hp ^ 1, hn);
        if !t_boundary {
            // Merge b-d: slot tp takes the outer halfedge of a-d (d->a, now d->b).
            self.move_halfedge(tn ^ 1, tp);
        }
        self.positions[b] = mid;
        if boundary_out.is_none() {
            self.v_out[b] = hn as u32;
        }
        if self.v_out[c] == hp as u32 {
            self.v_out[c] = (hn ^ 1) as u32;
        }
        // Remove the dead edges (highest index first), faces, and vertex a.
        let mut dead = vec![h / 2, hp / 2];
        let mut faces = vec![f0];
        if !t_boundary {
            dead.push(tn / 2);
            faces.push(self.he_face[t] as usize);
        }
        dead.sort_unstable_by(|x, y| y.cmp(x));
        for d in dead {
            self.remove_edge_pair(d);
        }
        faces.sort_unstable_by(|x, y| y.cmp(x));
        for f in faces {
            self.remove_face(f);
        }
        let merged = if b == self.positions.len() - 1 { a } else { b };
        self.remove_vertex(a);
        Ok(VertexId(merged as u32))
    }

    /// Checks every invariant listed on the type.
    ///
    /// # Errors
    /// A message naming the first element that breaks an invariant.
    pub fn validate(&self) -> Result<(), String> {
        let nh = self.he_next.len();
        if !nh.is_multiple_of(2)
            || self.he_prev.len() != nh
            || self.he_origin.len() != nh
            || self.he_face.len() != nh
        {
            return Err("halfedge arrays differ in length".into());
        }
        for h in 0..nh {
            let (n, p) = (self.he_next[h] as usize, self.he_prev[h] as usize);
            if n >= nh || p >= nh {
                return Err(format!("halfedge {h}: next/prev out of range"));
            }
            if self.he_prev[n] as usize != h || self.he_next[p] as usize != h {
                return Err(format!("halfedge {h}: next and prev are not inverse"));
            }
            if self.he_origin[n] != self.he_origin[h ^ 1] {
                return Err(format!(
                    "halfedge {h}: its next does not start where it ends"
                ));
            }
            if self.he_face[n] != self.he_face[h] {
                return Err(format!("halfedge {h}: its next lies in another face"));
            }
            if self.he_origin[h] == self.he_origin[h ^ 1] {
                return Err(format!("halfedge {h}: starts and ends at the same vertex"));
            }
            if self.he_face[h] == NONE && self.he_face[h ^ 1] == NONE {
                return Err(format!("edge {}: has no face on either side", h / 2));
            }
            if self.he_origin[h] as usize >= self.positions.len() {
                return Err(format!("halfedge {h}: origin out of range"));
            }
        }
        for f in 0..self.f_he.len() {
            let hs: Vec<HalfedgeId> = self.face_halfedges(FaceId(f as u32)).collect();
            if hs.len() < 3 || self.next(*hs.last().expect("non-empty")) != hs[0] {
                return Err(format!(
                    "face {f}: its halfedges do not form a loop of 3 or more"
                ));
            }
            if hs.iter().any(|h| self.he_face[h.0 as usize] != f as u32) {
                return Err(format!(
                    "face {f}: a halfedge of its loop belongs to another face"
                ));
            }
        }
        for v in 0..self.positions.len() {
            let Some(h) = self.vertex_halfedge(VertexId(v as u32)) else {
                continue;
            };
            if self.he_origin[h.0 as usize] as usize != v {
                return Err(format!("vertex {v}: its halfedge starts elsewhere"));
            }
            let out: Vec<HalfedgeId> = self.outgoing(VertexId(v as u32)).collect();
            if out.iter().any(|o| self.origin(*o).0 as usize != v) {
                return Err(format!("vertex {v}: rotation leaves the vertex"));
            }
            if out.iter().skip(1).any(|o| self.is_boundary_halfedge(*o)) {
                return Err(format!(
                    "vertex {v}: its stored halfedge is not its boundary halfedge"
                ));
            }
        }
        // Each vertex's outgoing halfedges are all in its one fan.
        let mut count = vec![0usize; self.positions.len()];
        for h in 0..nh {
            count[self.he_origin[h] as usize] += 1;
        }
        for (v, &c) in count.iter().enumerate() {
            let fan = self.outgoing(VertexId(v as u32)).count();
            if fan != c {
                return Err(format!(
                    "vertex {v}: {c} outgoing halfedges but a fan of {fan}"
                ));
            }
        }
        Ok(())
    }
}

/// An icosahedron with unit circumradius, counter-clockwise faces seen from outside.
#[must_use]
pub fn icosahedron() -> PolyMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let raw = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let positions = raw
        .iter()
        .map(|p| DVec3::from_array(*p).normalize())
        .collect();
    let faces: Vec<Vec<u32>> = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ]
    .iter()
    .map(|f| f.to_vec())
    .collect();
    PolyMesh::new(positions, &faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosahedron_is_closed_and_valid() {
        let m = HalfedgeMesh::from_polymesh(&icosahedron()).unwrap();
        m.validate().unwrap();
        assert_eq!(
            (m.vertex_count(), m.edge_count(), m.face_count()),
            (12, 30, 20)
        );
        assert_eq!(m.euler_characteristic(), 2);
        assert!((0..12)
            .all(|v| !m.is_boundary_vertex(VertexId(v)) && m.outgoing(VertexId(v)).count() == 5));
    }

    #[test]
    fn round_trip_is_lossless() {
        let p = icosahedron();
        let m = HalfedgeMesh::from_polymesh(&p).unwrap();
        assert_eq!(m.to_polymesh(), p);
    }

    /// An open fan: boundary loop linked, boundary vertices store boundary halfedges.
    #[test]
    fn open_mesh_has_boundary_loop() {
        let p = PolyMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::NEG_X, DVec3::NEG_Y],
            &[vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 4], vec![0, 4, 1]],
        );
        let m = HalfedgeMesh::from_polymesh(&p).unwrap();
        m.validate().unwrap();
        assert!(!m.is_boundary_vertex(VertexId(0)));
        assert!((1..5).all(|v| m.is_boundary_vertex(VertexId(v))));
        assert_eq!(m.euler_characteristic(), 1);
        let quad = PolyMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::ONE, DVec3::Y],
            &[vec![0, 1, 2, 3]],
        );
        HalfedgeMesh::from_polymesh(&quad)
            .unwrap()
            .validate()
            .unwrap();
    }

    /// Property: any sequence of flips keeps every invariant, the counts and the Euler
    /// characteristic, and a flip twice in a row restores the connectivity.
    #[test]
    fn random_flips_keep_invariants() {
        let p = crate::loop_subdivide(
            &HalfedgeMesh::from_polymesh(&icosahedron()).unwrap(),
            crate::LoopWeights::Warren,
        )
        .unwrap();
        let mut m = HalfedgeMesh::from_polymesh(&p).unwrap();
        let mut seed = 12345u64;
        let (mut flipped, mut refused) = (0, 0);
        for _ in 0..2000 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let e = EdgeId(((seed >> 33) % m.edge_count() as u64) as u32);
            match m.flip(e) {
                Ok(()) => flipped += 1,
                Err(_) => refused += 1,
            }
            m.validate().unwrap();
        }
        assert!(flipped > 100 && refused > 0, "{flipped} {refused}");
        assert_eq!(
            (m.vertex_count(), m.edge_count(), m.face_count()),
            (42, 120, 80)
        );
        assert_eq!(m.euler_characteristic(), 2);
        // Double flip: the faces come back as the same vertex sets.
        let before = m.to_polymesh();
        let e = (0..m.edge_count() as u32)
            .map(EdgeId)
            .find(|&e| m.can_flip(e).is_ok())
            .unwrap();
        m.flip(e).unwrap();
        m.flip(e).unwrap();
        let after = m.to_polymesh();
        let sorted = |p: &PolyMesh| {
            let mut f: Vec<Vec<u32>> = p
                .faces()
                .map(|f| {
                    let mut v = f.to_vec();
                    v.sort();
                    v
                })
                .collect();
            f.sort();
            f
        };
        assert_eq!(sorted(&before), sorted(&after));
    }

    /// Closed-form counts: an interior split adds 1 vertex, 3 edges, 2 faces; a boundary
    /// split 1 vertex, 2 edges, 1 face. Property: random flips and splits keep every
    /// invariant and the Euler characteristic.
    #[test]
    fn splits_and_flips_keep_invariants() {
        let mut m = HalfedgeMesh::from_polymesh(&icosahedron()).unwrap();
        let v = m.split(EdgeId(0)).unwrap();
        m.validate().unwrap();
        assert_eq!(
            (m.vertex_count(), m.edge_count(), m.face_count()),
            (13, 33, 22)
        );
        assert_eq!(m.outgoing(v).count(), 4);
        let p = PolyMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], &[vec![0, 1, 2]]);
        let mut open = HalfedgeMesh::from_polymesh(&p).unwrap();
        let v = open.split(EdgeId(0)).unwrap();
        open.validate().unwrap();
        assert_eq!(
            (open.vertex_count(), open.edge_count(), open.face_count()),
            (4, 5, 2)
        );
        assert!(open.is_boundary_vertex(v));
        assert_eq!(open.position(v), DVec3::new(0.5, 0.0, 0.0));
        // Random sequences on a closed and an open mesh.
        let fan = PolyMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::NEG_X, DVec3::NEG_Y],
            &[vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 4], vec![0, 4, 1]],
        );
        for start in [icosahedron(), fan] {
            let mut m = HalfedgeMesh::from_polymesh(&start).unwrap();
            let chi = m.euler_characteristic();
            let mut seed = 99u64;
            for _ in 0..600 {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let e = EdgeId(((seed >> 33) % m.edge_count() as u64) as u32);
                if (seed >> 20).is_multiple_of(3) {
                    m.split(e).unwrap();
                } else {
                    let _ = m.flip(e);
                }
                m.validate().unwrap();
                assert_eq!(m.euler_characteristic(), chi);
            }
            let back = HalfedgeMesh::from_polymesh(&m.to_polymesh()).unwrap();
            back.validate().unwrap();
        }
    }

    /// Closed-form counts: a collapse removes 1 vertex, 3 edges and 2 faces. Property:
    /// random sequences of flips, splits and collapses keep every invariant and the Euler
    /// characteristic.
    #[test]
    fn collapses_keep_invariants() {
        let p = crate::loop_subdivide(
            &HalfedgeMesh::from_polymesh(&icosahedron()).unwrap(),
            crate::LoopWeights::Warren,
        )
        .unwrap();
        let mut m = HalfedgeMesh::from_polymesh(&p).unwrap();
        let (v, e, f) = (m.vertex_count(), m.edge_count(), m.face_count());
        let edge = (0..e as u32)
            .map(EdgeId)
            .find(|&x| m.can_collapse(x).is_ok())
            .unwrap();
        let merged = m.collapse(edge).unwrap();
        m.validate().unwrap();
        assert_eq!(
            (m.vertex_count(), m.edge_count(), m.face_count()),
            (v - 1, e - 3, f - 2)
        );
        assert!((merged.0 as usize) < m.vertex_count());
        let mut seed = 7u64;
        let (mut done, mut refused) = (0, 0);
        for _ in 0..1500 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let e = EdgeId(((seed >> 33) % m.edge_count() as u64) as u32);
            match (seed >> 20) % 4 {
                0 => {
                    m.split(e).unwrap();
                }
                1 => {
                    let _ = m.flip(e);
                }
                _ => match m.collapse(e) {
                    Ok(_) => done += 1,
                    Err(_) => refused += 1,
                },
            }
            m.validate().unwrap();
            assert_eq!(m.euler_characteristic(), 2);
        }
        assert!(
            done > 50 && refused > 0,
            "{done} collapses, {refused} refused"
        );
        HalfedgeMesh::from_polymesh(&m.to_polymesh())
            .unwrap()
            .validate()
            .unwrap();
        // The tetrahedron cannot lose an edge: every opposite vertex has valence 3.
        let tet = PolyMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            &[vec![0, 2, 1], vec![0, 1, 3], vec![1, 2, 3], vec![2, 0, 3]],
        );
        let mut t = HalfedgeMesh::from_polymesh(&tet).unwrap();
        assert!(t.collapse(EdgeId(0)).is_err());
        t.validate().unwrap();
    }

    /// Closed-form counts of boundary collapses: a boundary edge loses 1 vertex, 2 edges and
    /// 1 face; an interior edge with one boundary endpoint the usual 1, 3 and 2. Refusals: a
    /// lone triangle (its boundary loop has 3 edges) and an interior edge joining two
    /// boundary vertices.
    #[test]
    fn boundary_collapses() {
        // A fan of 6 triangles around vertex 0, whose rim is the boundary.
        let mut positions = vec![DVec3::ZERO];
        for k in 0..6 {
            let a = f64::from(k) * std::f64::consts::PI / 3.0;
            positions.push(DVec3::new(a.cos(), a.sin(), 0.0));
        }
        let faces: Vec<Vec<u32>> = (0..6).map(|k| vec![0, 1 + k, 1 + (k + 1) % 6]).collect();
        let fan = HalfedgeMesh::from_polymesh(&PolyMesh::new(positions, &faces)).unwrap();
        let (v, e, f) = (fan.vertex_count(), fan.edge_count(), fan.face_count());

        let mut m = fan.clone();
        let rim = m.find_edge(VertexId(1), VertexId(2)).unwrap();
        let merged = m.collapse(rim).unwrap();
        m.validate().unwrap();
        assert_eq!(
            (m.vertex_count(), m.edge_count(), m.face_count()),
            (v - 1, e - 2, f - 1)
        );
        assert!(m.is_boundary_vertex(merged));
        assert!((m.position(merged) - DVec3::new(0.75, 3f64.sqrt() / 4.0, 0.0)).length() < 1e-15);

        let mut m = fan.clone();
        let spoke = m.find_edge(VertexId(0), VertexId(1)).unwrap();
        let merged = m.collapse(spoke).unwrap();
        m.validate().unwrap();
        assert_eq!(
            (m.vertex_count(), m.edge_count(), m.face_count()),
            (v - 1, e - 3, f - 2)
        );
        assert!(m.is_boundary_vertex(merged));

        // After a spoke collapse every vertex is on the rim, so an interior edge (a chord)
        // joins two boundary vertices.
        let mut m = fan.clone();
        m.collapse(m.find_edge(VertexId(0), VertexId(1)).unwrap())
            .unwrap();
        let chord = (0..m.edge_count() as u32)
            .map(EdgeId)
            .find(|&x| {
                let h = m.edge_halfedge(x);
                !m.is_boundary_edge(x)
                    && m.is_boundary_vertex(m.origin(h))
                    && m.is_boundary_vertex(m.dest(h))
            })
            .unwrap();
        assert!(m
            .can_collapse(chord)
            .unwrap_err()
            .contains("two boundary vertices"));

        let tri = PolyMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], &[vec![0, 1, 2]]);
        let mut t = HalfedgeMesh::from_polymesh(&tri).unwrap();
        assert!(t.collapse(EdgeId(0)).unwrap_err().contains("only 3 edges"));
        t.validate().unwrap();
    }

    #[test]
    fn flip_refusals() {
        let p = PolyMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::NEG_X, DVec3::NEG_Y],
            &[vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 4], vec![0, 4, 1]],
        );
        let mut m = HalfedgeMesh::from_polymesh(&p).unwrap();
        let boundary = m.find_edge(VertexId(1), VertexId(2)).unwrap();
        assert!(m.flip(boundary).unwrap_err().contains("boundary"));
        // The centre has valence 4 here: flipping a spoke is allowed once.
        let spoke = m.find_edge(VertexId(0), VertexId(1)).unwrap();
        m.flip(spoke).unwrap();
        m.validate().unwrap();
        assert!(m.find_edge(VertexId(2), VertexId(4)).is_some());
        assert!(m.flip(EdgeId(999)).is_err());
    }

    #[test]
    fn refuses_bad_soups_with_located_errors() {
        let pts = vec![DVec3::ZERO; 6];
        // Three faces on one edge.
        let e = HalfedgeMesh::from_polymesh(&PolyMesh::new(
            pts.clone(),
            &[vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]],
        ))
        .unwrap_err();
        assert!(matches!(e, MeshError::Topology { face: 2, .. }), "{e}");
        // Bowtie: two fans meeting at vertex 0.
        let e = HalfedgeMesh::from_polymesh(&PolyMesh::new(
            pts.clone(),
            &[vec![0, 1, 2], vec![0, 3, 4]],
        ))
        .unwrap_err();
        assert!(
            matches!(e, MeshError::NonManifoldVertex { vertex: 0, .. }),
            "{e}"
        );
        let e =
            HalfedgeMesh::from_polymesh(&PolyMesh::new(pts.clone(), &[vec![0, 1, 9]])).unwrap_err();
        assert_eq!(
            e.to_string(),
            "face 0: vertex index 9 is out of range (mesh has 6 vertices)"
        );
        let e = HalfedgeMesh::from_polymesh(&PolyMesh::new(pts, &[vec![0, 1, 1]])).unwrap_err();
        assert!(e.to_string().contains("degenerate"));
    }
}
