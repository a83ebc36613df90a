//! [`PolyMesh`], the indexed polygon mesh that readers produce and writers consume.

use prism_math::glam::{DVec2, DVec3};

/// An indexed polygon mesh: positions and faces as vertex-index lists (compressed rows).
///
/// Invariant: `face_starts` is non-decreasing, starts at 0 and ends at `face_indices.len()`;
/// face `f` is `face_indices[face_starts[f]..face_starts[f + 1]]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Per-vertex normals, if the source had them.
    pub normals: Option<Vec<DVec3>>,
    /// Per-vertex texture coordinates, if the source had them.
    pub uvs: Option<Vec<DVec2>>,
    face_starts: Vec<u32>,
    face_indices: Vec<u32>,
}

impl PolyMesh {
    /// A mesh from positions and faces.
    #[must_use]
    pub fn new(positions: Vec<DVec3>, faces: &[Vec<u32>]) -> PolyMesh {
        let mut m = PolyMesh {
            positions,
            ..PolyMesh::default()
        };
        m.face_starts.push(0);
        for f in faces {
            m.push_face(f);
        }
        m
    }

    /// Appends a face.
    pub fn push_face(&mut self, face: &[u32]) {
        if self.face_starts.is_empty() {
            self.face_starts.push(0);
        }
        self.face_indices.extend_from_slice(face);
        self.face_starts.push(self.face_indices.len() as u32);
    }

    /// Number of faces.
    #[must_use]
    pub fn face_count(&self) -> usize {
        self.face_starts.len().saturating_sub(1)
    }

    /// Number of vertices.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The vertex indices of face `f`.
    ///
    /// # Panics
    /// If `f >= face_count()`.
    #[must_use]
    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_indices[self.face_starts[f] as usize..self.face_starts[f + 1] as usize]
    }

    /// Iterates over the faces.
    pub fn faces(&self) -> impl Iterator<Item = &[u32]> + '_ {
        (0..self.face_count()).map(|f| self.face(f))
    }

    /// Face start offsets into [`PolyMesh::corners`]: `face_count() + 1` entries.
    pub(crate) fn face_starts(&self) -> &[u32] {
        &self.face_starts
    }

    /// Every face's vertex indices, face after face.
    pub(crate) fn corners(&self) -> &[u32] {
        &self.face_indices
    }

    /// A mesh without attributes from compressed face rows (see the type's invariant).
    pub(crate) fn from_rows(face_starts: Vec<u32>, face_indices: Vec<u32>) -> PolyMesh {
        PolyMesh {
            face_starts,
            face_indices,
            ..PolyMesh::default()
        }
    }

    /// True if every face is a triangle.
    #[must_use]
    pub fn is_triangle_mesh(&self) -> bool {
        self.faces().all(|f| f.len() == 3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_round_trip() {
        let m = PolyMesh::new(vec![DVec3::ZERO; 5], &[vec![0, 1, 2], vec![1, 3, 4, 2]]);
        assert_eq!(m.face_count(), 2);
        assert_eq!(m.face(1), &[1, 3, 4, 2]);
        assert!(!m.is_triangle_mesh());
        assert_eq!(PolyMesh::default().face_count(), 0);
    }
}
