//! Repairs made when a mesh is loaded, as OpenMesh does: a face that would use an edge
//! already used in the same direction (a non-manifold edge, or a face turned the other way)
//! gets vertices of its own, and a vertex where separate fans of faces touch (a non-manifold
//! vertex) is split into one vertex per fan.

use crate::PolyMesh;

/// A vertex that was split: the original index and the indices of its new copies, one per
/// fan after the first (which keeps the original index). Indices count from 0.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SplitVertex {
    /// The vertex as the file numbered it.
    pub vertex: u32,
    /// The copies appended for its other fans.
    pub copies: Vec<u32>,
}

/// Union-find root with path halving.
fn root(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let p = parent[parent[i as usize] as usize];
        parent[i as usize] = p;
        i = p;
    }
    i
}

impl PolyMesh {
    /// Gives each face that uses a directed edge an earlier face already used its own copies
    /// of its vertices (appended, attributes copied), so that it stands apart instead of
    /// making a non-manifold edge; OpenMesh's readers do the same with faces they cannot
    /// add. Faces are taken in order, so the earlier face keeps the shared vertices.
    /// Malformed faces are left alone for the halfedge build to report. Returns the
    /// detached faces (counted from 0); a mesh with none is unchanged.
    pub fn detach_faces_on_used_edges(&mut self) -> Vec<usize> {
        let nv = self.vertex_count();
        let mut used = std::collections::HashSet::new();
        let mut detached = Vec::new();
        let mut rows: Vec<Vec<u32>> = Vec::with_capacity(self.face_count());
        for (f, face) in self.faces().enumerate() {
            let sound = face.len() >= 3
                && face.iter().all(|&v| (v as usize) < nv)
                && face.iter().enumerate().all(|(k, v)| !face[..k].contains(v));
            let edges = || (0..face.len()).map(|k| (face[k], face[(k + 1) % face.len()]));
            if sound && edges().any(|e| used.contains(&e)) {
                detached.push(f);
            } else if sound {
                used.extend(edges());
            }
            rows.push(face.to_vec());
        }
        if detached.is_empty() {
            return detached;
        }
        for &f in &detached {
            for v in &mut rows[f] {
                let copy = self.positions.len() as u32;
                let i = *v as usize;
                self.positions.push(self.positions[i]);
                if let Some(n) = &mut self.normals {
                    n.push(n[i]);
                }
                if let Some(t) = &mut self.uvs {
                    t.push(t[i]);
                }
                *v = copy;
            }
        }
        let (positions, normals, uvs) = (
            std::mem::take(&mut self.positions),
            self.normals.take(),
            self.uvs.take(),
        );
        *self = PolyMesh::new(positions, &rows);
        self.normals = normals;
        self.uvs = uvs;
        detached
    }

    /// Splits every vertex whose faces form more than one fan into one vertex per fan.
    ///
    /// Two faces around a vertex belong to the same fan when they share an edge at that
    /// vertex. The fan holding the vertex's first corner (in face order) keeps the vertex;
    /// each other fan gets a copy appended at the same position (with the same normal and
    /// texture coordinate, if the mesh has them). Faces with an index out of range or a
    /// repeated vertex are left alone for the halfedge build to report. Returns the split
    /// vertices, in vertex order; a mesh with none is unchanged.
    pub fn split_nonmanifold_vertices(&mut self) -> Vec<SplitVertex> {
        let nv = self.vertex_count();
        let starts = self.face_starts().to_vec();
        let corners = self.corners().to_vec();
        let nf = self.face_count();
        // The faces that are well formed take part.
        let sound: Vec<bool> = (0..nf)
            .map(|f| {
                let face = &corners[starts[f] as usize..starts[f + 1] as usize];
                face.len() >= 3
                    && face.iter().all(|&v| (v as usize) < nv)
                    && face.iter().enumerate().all(|(k, v)| !face[..k].contains(v))
            })
            .collect();
        // Corners grouped by vertex (a counting sort), in face order.
        let mut offset = vec![0u32; nv + 1];
        for f in (0..nf).filter(|&f| sound[f]) {
            for &v in &corners[starts[f] as usize..starts[f + 1] as usize] {
                offset[v as usize + 1] += 1;
            }
        }
        for v in 0..nv {
            offset[v + 1] += offset[v];
        }
        let mut around = vec![0u32; offset[nv] as usize];
        let mut fill = offset.clone();
        for f in (0..nf).filter(|&f| sound[f]) {
            for c in starts[f]..starts[f + 1] {
                let v = corners[c as usize] as usize;
                around[fill[v] as usize] = c;
                fill[v] += 1;
            }
        }
        // Each corner's neighbours along its face.
        let face_of = |c: u32| starts.partition_point(|&s| s <= c) - 1;
        let neighbours = |c: u32| {
            let f = face_of(c);
            let (s, e) = (starts[f], starts[f + 1]);
            let prev = if c == s { e - 1 } else { c - 1 };
            let next = if c + 1 == e { s } else { c + 1 };
            [corners[prev as usize], corners[next as usize]]
        };
        let mut split = Vec::new();
        let mut new_corner_vertex: Vec<(u32, u32)> = Vec::new();
        let mut parent: Vec<u32> = Vec::new();
        let mut by_neighbour: Vec<(u32, u32)> = Vec::new();
        for v in 0..nv {
            let ring = &around[offset[v] as usize..offset[v + 1] as usize];
            if ring.len() < 2 {
                continue;
            }
            // Corners that share an edge (v, w) join one fan.
            parent.clear();
            parent.extend(0..ring.len() as u32);
            by_neighbour.clear();
            for (i, &c) in ring.iter().enumerate() {
                for w in neighbours(c) {
                    by_neighbour.push((w, i as u32));
                }
            }
            by_neighbour.sort_unstable();
            for pair in by_neighbour.windows(2) {
                if pair[0].0 == pair[1].0 {
                    let (a, b) = (root(&mut parent, pair[0].1), root(&mut parent, pair[1].1));
                    if a != b {
                        parent[a.max(b) as usize] = a.min(b);
                    }
                }
            }
            // Fans in order of their first corner; the first keeps the vertex.
            let first_root = root(&mut parent, 0);
            let mut copies: Vec<(u32, u32)> = Vec::new(); // (fan root, new vertex)
            for i in 0..ring.len() as u32 {
                let r = root(&mut parent, i);
                if r == first_root {
                    continue;
                }
                let copy = match copies.iter().find(|(fan, _)| *fan == r) {
                    Some(&(_, copy)) => copy,
                    None => {
                        let copy = (nv + new_corner_vertex_count(&split)) as u32;
                        copies.push((r, copy));
                        split_push(&mut split, v as u32, copy);
                        copy
                    }
                };
                new_corner_vertex.push((ring[i as usize], copy));
            }
        }
        if split.is_empty() {
            return split;
        }
        // Append the copies and point the other fans' corners at them.
        for s in &split {
            for _ in &s.copies {
                let v = s.vertex as usize;
                self.positions.push(self.positions[v]);
                if let Some(n) = &mut self.normals {
                    n.push(n[v]);
                }
                if let Some(t) = &mut self.uvs {
                    t.push(t[v]);
                }
            }
        }
        let mut faces = corners;
        for (c, copy) in new_corner_vertex {
            faces[c as usize] = copy;
        }
        let mut rebuilt = PolyMesh::from_rows(starts, faces);
        rebuilt.positions = std::mem::take(&mut self.positions);
        rebuilt.normals = self.normals.take();
        rebuilt.uvs = self.uvs.take();
        *self = rebuilt;
        split
    }
}

/// Copies made so far.
fn new_corner_vertex_count(split: &[SplitVertex]) -> usize {
    split.iter().map(|s| s.copies.len()).sum()
}

/// Records `copy` as a copy of `vertex`.
fn split_push(split: &mut Vec<SplitVertex>, vertex: u32, copy: u32) {
    match split.last_mut() {
        Some(s) if s.vertex == vertex => s.copies.push(copy),
        _ => split.push(SplitVertex {
            vertex,
            copies: vec![copy],
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HalfedgeMesh;
    use prism_math::glam::DVec3;

    /// Two triangles touching at one vertex (a bowtie): the shared vertex has two fans.
    fn bowtie() -> PolyMesh {
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        PolyMesh::new(
            vec![
                p(0.0, 0.0),
                p(1.0, 1.0),
                p(-1.0, 1.0),
                p(1.0, -1.0),
                p(-1.0, -1.0),
            ],
            &[vec![0, 1, 2], vec![0, 4, 3]],
        )
    }

    /// Oracle: the bowtie is refused as built, and after the split it builds, validates and
    /// has 6 vertices (one copy at the same position) and 2 boundary loops of 3 edges.
    #[test]
    fn bowtie_vertex_splits_into_two() {
        let mut m = bowtie();
        assert!(HalfedgeMesh::from_polymesh(&m).is_err());
        let split = m.split_nonmanifold_vertices();
        assert_eq!(
            split,
            vec![SplitVertex {
                vertex: 0,
                copies: vec![5]
            }]
        );
        assert_eq!(m.vertex_count(), 6);
        assert_eq!(m.positions[5], m.positions[0]);
        assert_eq!(m.face(0), &[0, 1, 2]);
        assert_eq!(m.face(1), &[5, 4, 3]);
        let h = HalfedgeMesh::from_polymesh(&m).unwrap();
        h.validate().unwrap();
        assert_eq!(h.euler_characteristic(), 2);
    }

    /// Property: a manifold mesh (a closed cube of quads, and an open fan) is unchanged.
    #[test]
    fn manifold_meshes_are_unchanged() {
        let cube = PolyMesh::new(
            (0..8)
                .map(|i| DVec3::new(f64::from(i & 1), f64::from(i >> 1 & 1), f64::from(i >> 2)))
                .collect(),
            &[
                vec![0, 2, 3, 1],
                vec![4, 5, 7, 6],
                vec![0, 1, 5, 4],
                vec![2, 6, 7, 3],
                vec![0, 4, 6, 2],
                vec![1, 3, 7, 5],
            ],
        );
        let mut m = cube.clone();
        assert!(m.split_nonmanifold_vertices().is_empty());
        assert_eq!(m, cube);
        let fan = PolyMesh::new(
            vec![DVec3::ZERO; 5],
            &[vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 4]],
        );
        let mut m = fan.clone();
        assert!(m.split_nonmanifold_vertices().is_empty());
        assert_eq!(m, fan);
    }

    /// Three fans at one vertex make two copies; attributes are copied with the position.
    #[test]
    fn three_fans_make_two_copies_with_attributes() {
        let mut m = PolyMesh::new(
            vec![DVec3::ZERO; 7],
            &[vec![0, 1, 2], vec![0, 3, 4], vec![0, 5, 6]],
        );
        m.uvs = Some(
            (0..7)
                .map(|i| prism_math::glam::DVec2::splat(f64::from(i)))
                .collect(),
        );
        let split = m.split_nonmanifold_vertices();
        assert_eq!(split[0].copies, vec![7, 8]);
        assert_eq!(m.uvs.as_ref().unwrap()[8], m.uvs.as_ref().unwrap()[0]);
        assert_eq!((m.face(1)[0], m.face(2)[0]), (7, 8));
    }

    /// Oracle: three triangles on one edge (a non-manifold edge, as in the Delft
    /// `monkey.obj`) are refused as built; after detaching the third it builds and
    /// validates, with its own three vertices.
    #[test]
    fn faces_on_used_edges_are_detached() {
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let mut m = PolyMesh::new(
            vec![
                p(0.0, 0.0, 0.0),
                p(1.0, 0.0, 0.0),
                p(0.0, 1.0, 0.0),
                p(0.0, -1.0, 0.0),
                p(0.0, 0.0, 1.0),
            ],
            &[vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]],
        );
        assert!(HalfedgeMesh::from_polymesh(&m).is_err());
        assert_eq!(m.detach_faces_on_used_edges(), vec![2]);
        assert_eq!(m.face(2), &[5, 6, 7]);
        assert_eq!(m.positions[7], m.positions[4]);
        HalfedgeMesh::from_polymesh(&m).unwrap().validate().unwrap();
        assert!(m.detach_faces_on_used_edges().is_empty());
    }
}
