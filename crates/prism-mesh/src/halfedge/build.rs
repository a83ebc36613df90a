//! Building a [`HalfedgeMesh`] from a polygon soup ([`PolyMesh`]), with located errors for
//! soups that cannot be a manifold, and converting back.

use super::mesh::{FaceId, HalfedgeMesh, VertexId, NONE};
use crate::{MeshError, PolyMesh};

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
}

#[cfg(test)]
mod tests {
    use prism_math::glam::DVec3;

    use super::*;
    use crate::icosahedron;

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
