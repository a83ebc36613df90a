//! Loop subdivision of triangle meshes (C. Loop, "Smooth Subdivision Surfaces Based on
//! Triangles", MS thesis, University of Utah, 1987), with the standard boundary rules
//! (Hoppe et al., "Piecewise Smooth Surface Reconstruction", SIGGRAPH 1994): a boundary edge
//! gets its midpoint, a boundary vertex `3/4 v + 1/8 (a + b)` from its two boundary
//! neighbours.

use prism_math::glam::DVec3;

use crate::{FaceId, HalfedgeId, HalfedgeMesh, MeshError, PolyMesh, VertexId};

/// The weight `beta` given to each neighbour of an interior vertex of valence `n`; the vertex
/// keeps `1 - n beta`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LoopWeights {
    /// Warren's simplification, as the CS184 course uses: `3/16` for `n = 3`, else `3/(8n)`
    /// (J. Warren, "Subdivision Methods for Geometric Design", 1995).
    #[default]
    Warren,
    /// Loop's original: `(5/8 - (3/8 + cos(2 pi / n) / 4)^2) / n`.
    Loop,
}

impl LoopWeights {
    /// `beta` for valence `n`.
    #[must_use]
    pub fn beta(self, n: usize) -> f64 {
        let nf = n as f64;
        match self {
            LoopWeights::Warren => {
                if n == 3 {
                    3.0 / 16.0
                } else {
                    3.0 / (8.0 * nf)
                }
            }
            LoopWeights::Loop => {
                let c = 3.0 / 8.0 + (std::f64::consts::TAU / nf).cos() / 4.0;
                (5.0 / 8.0 - c * c) / nf
            }
        }
    }
}

/// Bytes a subdivided triangle mesh takes, a face: as a halfedge mesh, three halfedges of
/// four indices, half a vertex (a position and an index) and the face's index; and, while
/// it is made, as a polygon mesh, its start and three indices and half a position.
pub const BYTES_PER_FACE: u64 = (3 * 16 + (24 + 4) / 2 + 4) + (4 + 12 + 24 / 2);

/// Faces and bytes ([`BYTES_PER_FACE`] a face) of `faces` triangles after `levels` of Loop
/// subdivision, each of which makes four faces of one (saturating).
#[must_use]
pub fn subdivided_size(faces: usize, levels: u32) -> (u64, u64) {
    let out = (faces as u64).saturating_mul(1u64.checked_shl(2 * levels).unwrap_or(u64::MAX));
    (out, out.saturating_mul(BYTES_PER_FACE))
}

/// Checks `levels` of Loop subdivision of `faces` triangles against the memory budget.
///
/// # Errors
/// [`MeshError::OverBudget`] with the faces the result would have.
pub fn check_subdivision(faces: usize, levels: u32) -> Result<(), MeshError> {
    let (faces, bytes) = subdivided_size(faces, levels);
    prism_math::limits::check_memory(bytes)
        .map_err(|source| MeshError::OverBudget { faces, source })
}

/// One level of Loop subdivision. Old vertices keep their indices (repositioned); the new
/// vertex of edge `e` gets index `V + e`; face `f` becomes faces `4f .. 4f + 3`: the three
/// corner triangles (in the order of the face's vertices), then the middle one.
///
/// # Errors
/// [`MeshError::NotTriangles`] if a face is not a triangle; [`MeshError::OverBudget`] if
/// the result would be larger than the memory budget (checked before it is allocated).
pub fn loop_subdivide(mesh: &HalfedgeMesh, weights: LoopWeights) -> Result<PolyMesh, MeshError> {
    check_subdivision(mesh.face_count(), 1)?;
    for f in 0..mesh.face_count() {
        let sides = mesh.face_halfedges(FaceId(f as u32)).count();
        if sides != 3 {
            return Err(MeshError::NotTriangles { face: f, sides });
        }
    }
    let nv = mesh.vertex_count();
    let ne = mesh.edge_count();
    let mut positions = Vec::with_capacity(nv + ne);
    // Repositioned old vertices.
    for v in 0..nv {
        let v = VertexId(v as u32);
        let p = mesh.position(v);
        let Some(h) = mesh.vertex_halfedge(v) else {
            positions.push(p);
            continue;
        };
        if mesh.is_boundary_halfedge(h) {
            let a = mesh.position(mesh.dest(h));
            let b = mesh.position(mesh.origin(mesh.prev(h)));
            positions.push(p * 0.75 + (a + b) * 0.125);
        } else {
            let (mut sum, mut n) = (DVec3::ZERO, 0usize);
            for o in mesh.outgoing(v) {
                sum += mesh.position(mesh.dest(o));
                n += 1;
            }
            let beta = weights.beta(n);
            positions.push(p * (1.0 - n as f64 * beta) + sum * beta);
        }
    }
    // Edge vertices.
    for e in 0..ne {
        let h = HalfedgeId(2 * e as u32);
        let t = mesh.twin(h);
        let (a, b) = (mesh.position(mesh.origin(h)), mesh.position(mesh.origin(t)));
        if mesh.is_boundary_halfedge(h) || mesh.is_boundary_halfedge(t) {
            positions.push((a + b) * 0.5);
        } else {
            let c = mesh.position(mesh.origin(mesh.prev(h)));
            let d = mesh.position(mesh.origin(mesh.prev(t)));
            positions.push((a + b) * 0.375 + (c + d) * 0.125);
        }
    }
    let mut out = PolyMesh::new(positions, &[]);
    for f in 0..mesh.face_count() {
        let h0 = mesh.face_halfedge(FaceId(f as u32));
        let h1 = mesh.next(h0);
        let h2 = mesh.next(h1);
        let (v0, v1, v2) = (mesh.origin(h0).0, mesh.origin(h1).0, mesh.origin(h2).0);
        let m = |h: HalfedgeId| nv as u32 + mesh.edge(h).0;
        let (m0, m1, m2) = (m(h0), m(h1), m(h2));
        out.push_face(&[v0, m0, m2]);
        out.push_face(&[v1, m1, m0]);
        out.push_face(&[v2, m2, m1]);
        out.push_face(&[m0, m1, m2]);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::icosahedron;

    fn subdivide(p: &PolyMesh, levels: usize, w: LoopWeights) -> PolyMesh {
        let mut p = p.clone();
        for _ in 0..levels {
            let m = HalfedgeMesh::from_polymesh(&p).unwrap();
            p = loop_subdivide(&m, w).unwrap();
        }
        p
    }

    /// Properties: faces multiply by 4, the result is a valid closed manifold (Euler 2), and
    /// the icosahedron's symmetry keeps every vertex at the same distance per generation.
    #[test]
    fn icosahedron_levels() {
        for w in [LoopWeights::Warren, LoopWeights::Loop] {
            let p = subdivide(&icosahedron(), 2, w);
            assert_eq!(p.face_count(), 320);
            let m = HalfedgeMesh::from_polymesh(&p).unwrap();
            m.validate().unwrap();
            assert_eq!(m.euler_characteristic(), 2);
            assert_eq!(m.vertex_count(), 162);
        }
    }

    /// Closed form: one level on the icosahedron. With all neighbours at distance 1, an old
    /// vertex moves to (1 - 5 beta) v + beta * sum(neighbours), and the neighbour sum of a
    /// vertex of the unit icosahedron is sqrt(5) v.
    #[test]
    fn old_vertex_rule_closed_form() {
        let ico = icosahedron();
        for w in [LoopWeights::Warren, LoopWeights::Loop] {
            let p = subdivide(&ico, 1, w);
            let beta = w.beta(5);
            let expect = (1.0 - 5.0 * beta) + beta * 5f64.sqrt();
            for v in 0..12 {
                let got = p.positions[v];
                assert!(
                    (got - ico.positions[v] * expect).length() < 1e-12,
                    "{w:?} vertex {v}"
                );
            }
        }
    }

    /// Property: subdivision is affine invariant, so a planar open grid stays planar and
    /// boundary points stay on the boundary line.
    #[test]
    fn planar_open_mesh_stays_planar() {
        let n = 4;
        let mut pos = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                pos.push(DVec3::new(
                    i as f64,
                    j as f64,
                    0.25 * i as f64 + 0.5 * j as f64,
                ));
            }
        }
        let idx = |i: u32, j: u32| j * (n + 1) + i;
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                faces.push(vec![idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)]);
                faces.push(vec![idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]);
            }
        }
        let p = subdivide(&PolyMesh::new(pos, &faces), 2, LoopWeights::Warren);
        HalfedgeMesh::from_polymesh(&p).unwrap().validate().unwrap();
        for q in &p.positions {
            assert!((q.z - (0.25 * q.x + 0.5 * q.y)).abs() < 1e-12);
            assert!(q.x >= -1e-12 && q.x <= n as f64 + 1e-12);
        }
        // Closed form: the corner follows 3/4 v + 1/8 (a + b) with its boundary neighbours,
        // (1, 0) and (0, 1) at level 0, then the two edge midpoints (1/2, 0), (0, 1/2).
        let l1 = DVec3::new(0.125, 0.125, 0.09375);
        let l2 = l1 * 0.75 + (DVec3::new(0.5, 0.0, 0.125) + DVec3::new(0.0, 0.5, 0.25)) * 0.125;
        assert!((p.positions[0] - l2).length() < 1e-12);
    }

    #[test]
    fn refuses_quads() {
        let quad = PolyMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::ONE, DVec3::Y],
            &[vec![0, 1, 2, 3]],
        );
        let m = HalfedgeMesh::from_polymesh(&quad).unwrap();
        assert!(matches!(
            loop_subdivide(&m, LoopWeights::Warren),
            Err(MeshError::NotTriangles { face: 0, sides: 4 })
        ));
    }

    #[test]
    fn beta_values() {
        assert_eq!(LoopWeights::Warren.beta(3), 3.0 / 16.0);
        assert_eq!(LoopWeights::Warren.beta(6), 1.0 / 16.0);
        // Loop's weights equal 1/16 for the regular valence 6 as well.
        assert!((LoopWeights::Loop.beta(6) - 1.0 / 16.0).abs() < 1e-15);
    }
}

#[cfg(test)]
mod budget_tests {
    use super::*;

    /// Closed form: each level makes four faces of one; a count past 64 bits saturates
    /// rather than wrapping to a small number, and is refused.
    #[test]
    fn subdivision_sizes_are_checked_before_subdividing() {
        assert_eq!(subdivided_size(20, 0), (20, 20 * BYTES_PER_FACE));
        assert_eq!(subdivided_size(20, 3), (20 * 64, 20 * 64 * BYTES_PER_FACE));
        assert_eq!(subdivided_size(5856, 40).0, u64::MAX);
        assert!(check_subdivision(20, 3).is_ok());
        let e = check_subdivision(5856, 9).unwrap_err().to_string();
        assert!(
            e.starts_with("making 1535115264 faces needs 134 GiB of memory"),
            "{e}"
        );
        let ico = HalfedgeMesh::from_polymesh(&crate::icosahedron()).unwrap();
        assert!(loop_subdivide(&ico, LoopWeights::Warren).is_ok());
    }
}
