//! [`HalfedgeMesh::validate`], the check of every invariant of the halfedge mesh, and
//! [`ValidationError`], one variant per invariant.

use super::mesh::{EdgeId, FaceId, HalfedgeId, HalfedgeMesh, VertexId, NONE};

/// The first broken invariant [`HalfedgeMesh::validate`] finds, naming the element that
/// breaks it.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ValidationError {
    /// The halfedge arrays (next, prev, origin, face) differ in length, or hold an odd
    /// number of halfedges.
    #[error("halfedge arrays differ in length")]
    ArrayLengths,
    /// A halfedge's `next` or `prev` is not a halfedge of the mesh.
    #[error("halfedge {}: next/prev out of range", .halfedge.0)]
    LinkOutOfRange {
        /// The halfedge.
        halfedge: HalfedgeId,
    },
    /// `next` and `prev` are not inverse at a halfedge.
    #[error("halfedge {}: next and prev are not inverse", .halfedge.0)]
    NotInverse {
        /// The halfedge whose `next` does not come back to it by `prev`, or whose `prev`
        /// does not come back by `next`.
        halfedge: HalfedgeId,
    },
    /// A halfedge's `next` starts somewhere other than where the halfedge ends.
    #[error("halfedge {}: its next does not start where it ends", .halfedge.0)]
    Disconnected {
        /// The halfedge.
        halfedge: HalfedgeId,
    },
    /// A halfedge and its `next` lie in different faces (or one on a boundary loop).
    #[error("halfedge {}: its next lies in another face", .halfedge.0)]
    NextInOtherFace {
        /// The halfedge.
        halfedge: HalfedgeId,
    },
    /// A halfedge starts and ends at the same vertex.
    #[error("halfedge {}: starts and ends at the same vertex", .halfedge.0)]
    SelfLoop {
        /// The halfedge.
        halfedge: HalfedgeId,
    },
    /// Neither halfedge of an edge has a face.
    #[error("edge {}: has no face on either side", .edge.0)]
    FacelessEdge {
        /// The edge.
        edge: EdgeId,
    },
    /// A halfedge starts at a vertex the mesh does not have.
    #[error("halfedge {}: origin out of range", .halfedge.0)]
    OriginOutOfRange {
        /// The halfedge.
        halfedge: HalfedgeId,
    },
    /// Following `next` from a face's first halfedge does not close a loop of three or more.
    #[error("face {}: its halfedges do not form a loop of 3 or more", .face.0)]
    FaceLoop {
        /// The face.
        face: FaceId,
    },
    /// A halfedge in a face's loop names another face.
    #[error("face {}: a halfedge of its loop belongs to another face", .face.0)]
    FaceLoopMixed {
        /// The face.
        face: FaceId,
    },
    /// A vertex's stored outgoing halfedge starts at another vertex.
    #[error("vertex {}: its halfedge starts elsewhere", .vertex.0)]
    VertexHalfedge {
        /// The vertex.
        vertex: VertexId,
    },
    /// Rotating around a vertex reaches a halfedge that does not start at it.
    #[error("vertex {}: rotation leaves the vertex", .vertex.0)]
    Rotation {
        /// The vertex.
        vertex: VertexId,
    },
    /// A boundary vertex stores an interior halfedge: its boundary halfedge comes later in
    /// the rotation.
    #[error("vertex {}: its stored halfedge is not its boundary halfedge", .vertex.0)]
    NotBoundaryHalfedge {
        /// The vertex.
        vertex: VertexId,
    },
    /// A vertex's outgoing halfedges do not all lie in the one fan its rotation visits.
    #[error("vertex {}: {outgoing} outgoing halfedges but a fan of {fan}", .vertex.0)]
    NotOneFan {
        /// The vertex.
        vertex: VertexId,
        /// How many halfedges start at the vertex.
        outgoing: usize,
        /// How many of them the rotation from its stored halfedge visits.
        fan: usize,
    },
}

impl HalfedgeMesh {
    /// Checks every invariant listed on the type.
    ///
    /// # Errors
    /// The first broken invariant, naming the element that breaks it.
    pub fn validate(&self) -> Result<(), ValidationError> {
        let nh = self.he_next.len();
        if !nh.is_multiple_of(2)
            || self.he_prev.len() != nh
            || self.he_origin.len() != nh
            || self.he_face.len() != nh
        {
            return Err(ValidationError::ArrayLengths);
        }
        for h in 0..nh {
            let halfedge = HalfedgeId(h as u32);
            let (n, p) = (self.he_next[h] as usize, self.he_prev[h] as usize);
            if n >= nh || p >= nh {
                return Err(ValidationError::LinkOutOfRange { halfedge });
            }
            if self.he_prev[n] as usize != h || self.he_next[p] as usize != h {
                return Err(ValidationError::NotInverse { halfedge });
            }
            if self.he_origin[n] != self.he_origin[h ^ 1] {
                return Err(ValidationError::Disconnected { halfedge });
            }
            if self.he_face[n] != self.he_face[h] {
                return Err(ValidationError::NextInOtherFace { halfedge });
            }
            if self.he_origin[h] == self.he_origin[h ^ 1] {
                return Err(ValidationError::SelfLoop { halfedge });
            }
            if self.he_face[h] == NONE && self.he_face[h ^ 1] == NONE {
                return Err(ValidationError::FacelessEdge {
                    edge: self.edge(halfedge),
                });
            }
            if self.he_origin[h] as usize >= self.positions.len() {
                return Err(ValidationError::OriginOutOfRange { halfedge });
            }
        }
        for f in 0..self.f_he.len() {
            let face = FaceId(f as u32);
            let hs: Vec<HalfedgeId> = self.face_halfedges(face).collect();
            if hs.len() < 3 || self.next(*hs.last().expect("non-empty")) != hs[0] {
                return Err(ValidationError::FaceLoop { face });
            }
            if hs.iter().any(|h| self.he_face[h.0 as usize] != f as u32) {
                return Err(ValidationError::FaceLoopMixed { face });
            }
        }
        for v in 0..self.positions.len() {
            let vertex = VertexId(v as u32);
            let Some(h) = self.vertex_halfedge(vertex) else {
                continue;
            };
            if self.he_origin[h.0 as usize] as usize != v {
                return Err(ValidationError::VertexHalfedge { vertex });
            }
            let out: Vec<HalfedgeId> = self.outgoing(vertex).collect();
            if out.iter().any(|o| self.origin(*o) != vertex) {
                return Err(ValidationError::Rotation { vertex });
            }
            if out.iter().skip(1).any(|o| self.is_boundary_halfedge(*o)) {
                return Err(ValidationError::NotBoundaryHalfedge { vertex });
            }
        }
        // Each vertex's outgoing halfedges are all in its one fan.
        let mut count = vec![0usize; self.positions.len()];
        for h in 0..nh {
            count[self.he_origin[h] as usize] += 1;
        }
        for (v, &outgoing) in count.iter().enumerate() {
            let vertex = VertexId(v as u32);
            let fan = self.outgoing(vertex).count();
            if fan != outgoing {
                return Err(ValidationError::NotOneFan {
                    vertex,
                    outgoing,
                    fan,
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::icosahedron;

    fn mesh() -> HalfedgeMesh {
        HalfedgeMesh::from_polymesh(&icosahedron()).unwrap()
    }

    /// Each kind of corruption is reported as the invariant it breaks, naming the element.
    #[test]
    fn corruptions_name_the_broken_invariant() {
        let mut m = mesh();
        m.he_origin.pop();
        assert_eq!(m.validate(), Err(ValidationError::ArrayLengths));
        assert_eq!(
            m.validate().unwrap_err().to_string(),
            "halfedge arrays differ in length"
        );

        let mut m = mesh();
        m.he_next[0] = u32::MAX - 1;
        let err = m.validate().unwrap_err();
        assert_eq!(
            err,
            ValidationError::LinkOutOfRange {
                halfedge: HalfedgeId(0)
            }
        );
        assert_eq!(err.to_string(), "halfedge 0: next/prev out of range");

        // Two halfedges of face 0 swap their `next`: the first one out of order breaks the
        // inverse relation.
        let mut m = mesh();
        let h = m.face_halfedge(FaceId(0));
        let n = m.next(h);
        m.he_next.swap(h.0 as usize, n.0 as usize);
        assert!(matches!(
            m.validate(),
            Err(ValidationError::NotInverse { .. })
        ));

        let mut m = mesh();
        m.f_he.push(0);
        let err = m.validate().unwrap_err();
        assert_eq!(
            err,
            ValidationError::FaceLoopMixed {
                face: FaceId(m.face_count() as u32 - 1)
            }
        );
        assert_eq!(
            err.to_string(),
            "face 20: a halfedge of its loop belongs to another face"
        );

        let mut m = mesh();
        let v = m.origin(HalfedgeId(0));
        let elsewhere = m.next(HalfedgeId(0));
        m.v_out[v.0 as usize] = elsewhere.0;
        assert_eq!(
            m.validate(),
            Err(ValidationError::VertexHalfedge { vertex: v })
        );
        assert_eq!(
            m.validate().unwrap_err().to_string(),
            format!("vertex {}: its halfedge starts elsewhere", v.0)
        );
    }

    #[test]
    fn fan_message_gives_both_counts() {
        let err = ValidationError::NotOneFan {
            vertex: VertexId(5),
            outgoing: 6,
            fan: 3,
        };
        assert_eq!(
            err.to_string(),
            "vertex 5: 6 outgoing halfedges but a fan of 3"
        );
    }
}
