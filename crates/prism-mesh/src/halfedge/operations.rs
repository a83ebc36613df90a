//! Edge flips, splits and collapses, each with the predicate that checks it first
//! (`can_flip` then `flip`), and [`TopologyError`], the reason an operation is refused.

use super::mesh::{EdgeId, FaceId, HalfedgeId, HalfedgeMesh, VertexId, NONE};

/// Why an edge flip, split or collapse was refused; the mesh is unchanged when one is
/// returned. Ids are those of the mesh before the operation.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TopologyError {
    /// The edge index is not below the edge count.
    #[error("edge {} does not exist ({edge_count} edges)", .edge.0)]
    NoSuchEdge {
        /// The requested edge.
        edge: EdgeId,
        /// How many edges the mesh has.
        edge_count: usize,
    },
    /// A flip needs an interior edge, and this one has a boundary halfedge.
    #[error("edge {} is on the boundary", .edge.0)]
    BoundaryEdge {
        /// The boundary edge.
        edge: EdgeId,
    },
    /// A face on the edge has more than three sides.
    #[error("edge {}: face {} is not a triangle", .edge.0, .face.0)]
    NotTriangle {
        /// The edge.
        edge: EdgeId,
        /// The first of its faces that is not a triangle.
        face: FaceId,
    },
    /// A flip would join a vertex to itself: both triangles on the edge have the same
    /// opposite vertex.
    #[error("edge {}: both opposite vertices are vertex {}", .edge.0, .vertex.0)]
    SameOppositeVertex {
        /// The edge.
        edge: EdgeId,
        /// The opposite vertex the two triangles share.
        vertex: VertexId,
    },
    /// A flip would make a second edge between the two opposite vertices.
    #[error("edge {}: vertices {} and {} are already joined", .edge.0, .c.0, .d.0)]
    AlreadyJoined {
        /// The edge.
        edge: EdgeId,
        /// The opposite vertex in the face of the edge's first halfedge.
        c: VertexId,
        /// The opposite vertex in the face of the edge's second halfedge.
        d: VertexId,
    },
    /// A boundary edge whose boundary loop has three edges or fewer (a lone triangle's
    /// rim): collapsing it would leave a degenerate loop.
    #[error("edge {}: its boundary loop has only {len} edges", .edge.0)]
    ShortBoundaryLoop {
        /// The boundary edge.
        edge: EdgeId,
        /// The length of its boundary loop, in edges.
        len: usize,
    },
    /// Collapsing an interior edge between two boundary vertices would pinch the surface
    /// into a non-manifold vertex.
    #[error(
        "edge {}: an interior edge between two boundary vertices ({} and {})",
        .edge.0, .a.0, .b.0
    )]
    JoinsBoundaries {
        /// The interior edge.
        edge: EdgeId,
        /// The endpoint the edge's face-side halfedge starts at.
        a: VertexId,
        /// The other endpoint.
        b: VertexId,
    },
    /// The link condition fails: the endpoints share a neighbour other than the vertices
    /// opposite the edge, so a collapse would fold the surface.
    #[error(
        "edge {}: link condition fails (the endpoints share {shared} neighbours, expected {expected})",
        .edge.0
    )]
    LinkCondition {
        /// The edge.
        edge: EdgeId,
        /// How many neighbours the endpoints share.
        shared: usize,
        /// How many they may share: the distinct opposite vertices.
        expected: usize,
    },
    /// A collapse would leave an opposite vertex on the boundary with no face.
    #[error("edge {}: boundary vertex {} would be left with no face", .edge.0, .vertex.0)]
    FacelessVertex {
        /// The edge.
        edge: EdgeId,
        /// The opposite boundary vertex.
        vertex: VertexId,
    },
    /// A collapse would leave an interior opposite vertex with valence 2, so its two faces
    /// would coincide.
    #[error("edge {}: vertex {} would be left with valence 2", .edge.0, .vertex.0)]
    Valence {
        /// The edge.
        edge: EdgeId,
        /// The interior opposite vertex, now of valence 3.
        vertex: VertexId,
    },
}

impl HalfedgeMesh {
    /// [`TopologyError::NoSuchEdge`] unless `e` is an edge of this mesh.
    fn check_edge_exists(&self, e: EdgeId) -> Result<(), TopologyError> {
        if e.0 as usize >= self.edge_count() {
            return Err(TopologyError::NoSuchEdge {
                edge: e,
                edge_count: self.edge_count(),
            });
        }
        Ok(())
    }

    /// [`TopologyError::NotTriangle`] if the face of halfedge `side` of edge `e` is not a
    /// triangle; a boundary halfedge passes.
    fn check_triangle(&self, e: EdgeId, side: HalfedgeId) -> Result<(), TopologyError> {
        match self.face(side) {
            Some(f) if self.face_halfedges(f).count() != 3 => {
                Err(TopologyError::NotTriangle { edge: e, face: f })
            }
            _ => Ok(()),
        }
    }

    /// The two halfedges of `e` if it exists, is interior, and lies between two triangles.
    fn interior_triangle_edge(&self, e: EdgeId) -> Result<(HalfedgeId, HalfedgeId), TopologyError> {
        self.check_edge_exists(e)?;
        if self.is_boundary_edge(e) {
            return Err(TopologyError::BoundaryEdge { edge: e });
        }
        let h = self.edge_halfedge(e);
        let t = self.twin(h);
        for side in [h, t] {
            self.check_triangle(e, side)?;
        }
        Ok((h, t))
    }

    /// Whether [`HalfedgeMesh::flip`] may flip edge `e`: it must be interior, both its
    /// faces triangles, and the two opposite vertices distinct and not already joined (which
    /// also refuses flips that would leave a vertex of valence 2).
    ///
    /// # Errors
    /// Why the flip is refused: [`TopologyError::NoSuchEdge`], [`TopologyError::BoundaryEdge`],
    /// [`TopologyError::NotTriangle`], [`TopologyError::SameOppositeVertex`] or
    /// [`TopologyError::AlreadyJoined`].
    pub fn can_flip(&self, e: EdgeId) -> Result<(), TopologyError> {
        let (h, t) = self.interior_triangle_edge(e)?;
        let c = self.origin(self.prev(h));
        let d = self.origin(self.prev(t));
        if c == d {
            return Err(TopologyError::SameOppositeVertex { edge: e, vertex: c });
        }
        if self.find_edge(c, d).is_some() {
            return Err(TopologyError::AlreadyJoined { edge: e, c, d });
        }
        Ok(())
    }

    /// Flips interior edge `e` between triangles (a, b, c) and (b, a, d) to join c and d.
    /// The edge keeps its index; the two faces keep theirs.
    ///
    /// # Errors
    /// As [`HalfedgeMesh::can_flip`]; the mesh is unchanged on error.
    pub fn flip(&mut self, e: EdgeId) -> Result<(), TopologyError> {
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
    /// Why the split is refused: [`TopologyError::NoSuchEdge`] or
    /// [`TopologyError::NotTriangle`].
    pub fn can_split(&self, e: EdgeId) -> Result<(), TopologyError> {
        self.check_edge_exists(e)?;
        let h = self.edge_halfedge(e);
        for side in [h, self.twin(h)] {
            self.check_triangle(e, side)?;
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
    pub fn split(&mut self, e: EdgeId) -> Result<VertexId, TopologyError> {
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
    /// Why the collapse is refused: [`TopologyError::NoSuchEdge`],
    /// [`TopologyError::NotTriangle`], [`TopologyError::ShortBoundaryLoop`],
    /// [`TopologyError::JoinsBoundaries`], [`TopologyError::LinkCondition`],
    /// [`TopologyError::FacelessVertex`] or [`TopologyError::Valence`].
    pub fn can_collapse(&self, e: EdgeId) -> Result<(), TopologyError> {
        self.check_edge_exists(e)?;
        let mut h = self.edge_halfedge(e);
        if self.face(h).is_none() {
            h = self.twin(h);
        }
        let t = self.twin(h);
        let (a, b) = (self.origin(h), self.origin(t));
        let mut opposite = Vec::with_capacity(2);
        for side in [h, t] {
            self.check_triangle(e, side)?;
            if self.face(side).is_some() {
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
                return Err(TopologyError::ShortBoundaryLoop { edge: e, len });
            }
        } else if self.is_boundary_vertex(a) && self.is_boundary_vertex(b) {
            return Err(TopologyError::JoinsBoundaries { edge: e, a, b });
        }
        let ring = |v: VertexId| -> Vec<u32> { self.outgoing(v).map(|o| self.dest(o).0).collect() };
        let (ra, rb) = (ring(a), ring(b));
        let mut shared: Vec<u32> = ra.iter().copied().filter(|v| rb.contains(v)).collect();
        shared.sort_unstable();
        let mut expect: Vec<u32> = opposite.iter().map(|v| v.0).collect();
        expect.sort_unstable();
        expect.dedup();
        if shared != expect {
            return Err(TopologyError::LinkCondition {
                edge: e,
                shared: shared.len(),
                expected: expect.len(),
            });
        }
        for &v in &opposite {
            let valence = self.outgoing(v).count();
            if self.is_boundary_vertex(v) {
                if valence <= 2 {
                    return Err(TopologyError::FacelessVertex { edge: e, vertex: v });
                }
            } else if valence <= 3 {
                return Err(TopologyError::Valence { edge: e, vertex: v });
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
    pub fn collapse(&mut self, e: EdgeId) -> Result<VertexId, TopologyError> {
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
}

#[cfg(test)]
mod tests {
    use prism_math::glam::DVec3;

    use super::*;
    use crate::{icosahedron, PolyMesh};

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
        assert!(matches!(
            t.collapse(EdgeId(0)),
            Err(TopologyError::Valence { .. })
        ));
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
        let err = m.can_collapse(chord).unwrap_err();
        assert!(
            matches!(err, TopologyError::JoinsBoundaries { edge, .. } if edge == chord),
            "{err}"
        );
        assert!(err.to_string().contains("two boundary vertices"), "{err}");

        let tri = PolyMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], &[vec![0, 1, 2]]);
        let mut t = HalfedgeMesh::from_polymesh(&tri).unwrap();
        let err = t.collapse(EdgeId(0)).unwrap_err();
        assert_eq!(
            err,
            TopologyError::ShortBoundaryLoop {
                edge: EdgeId(0),
                len: 3
            }
        );
        assert_eq!(
            err.to_string(),
            "edge 0: its boundary loop has only 3 edges"
        );
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
        let err = m.flip(boundary).unwrap_err();
        assert_eq!(err, TopologyError::BoundaryEdge { edge: boundary });
        assert_eq!(
            err.to_string(),
            format!("edge {} is on the boundary", boundary.0)
        );
        // The centre has valence 4 here: flipping a spoke is allowed once.
        let spoke = m.find_edge(VertexId(0), VertexId(1)).unwrap();
        m.flip(spoke).unwrap();
        m.validate().unwrap();
        assert!(m.find_edge(VertexId(2), VertexId(4)).is_some());
        let err = m.flip(EdgeId(999)).unwrap_err();
        assert_eq!(err.to_string(), "edge 999 does not exist (8 edges)");
    }

    /// The messages name the edge and the elements involved, as the CLI prints them after
    /// `cannot flip: ` (and the like).
    #[test]
    fn messages_name_the_elements() {
        let (e, f) = (EdgeId(7), FaceId(3));
        let (a, b) = (VertexId(1), VertexId(2));
        let cases = [
            (
                TopologyError::NotTriangle { edge: e, face: f },
                "edge 7: face 3 is not a triangle",
            ),
            (
                TopologyError::SameOppositeVertex { edge: e, vertex: a },
                "edge 7: both opposite vertices are vertex 1",
            ),
            (
                TopologyError::AlreadyJoined {
                    edge: e,
                    c: a,
                    d: b,
                },
                "edge 7: vertices 1 and 2 are already joined",
            ),
            (
                TopologyError::JoinsBoundaries { edge: e, a, b },
                "edge 7: an interior edge between two boundary vertices (1 and 2)",
            ),
            (
                TopologyError::LinkCondition {
                    edge: e,
                    shared: 3,
                    expected: 2,
                },
                "edge 7: link condition fails (the endpoints share 3 neighbours, expected 2)",
            ),
            (
                TopologyError::FacelessVertex { edge: e, vertex: b },
                "edge 7: boundary vertex 2 would be left with no face",
            ),
            (
                TopologyError::Valence { edge: e, vertex: b },
                "edge 7: vertex 2 would be left with valence 2",
            ),
        ];
        for (err, text) in cases {
            assert_eq!(err.to_string(), text);
        }
    }
}
