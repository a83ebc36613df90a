//! Procedural test and demo meshes: the icosahedron.

use prism_math::glam::DVec3;

use crate::PolyMesh;

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
    use crate::{HalfedgeMesh, VertexId};

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
}
