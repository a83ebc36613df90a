//! Property tests (proptest) of the halfedge operations and Loop subdivision. Each property is
//! its own oracle: invariants that must hold whatever the input.

use prism_math::glam::DVec3;
use prism_mesh::{icosahedron, loop_subdivide, EdgeId, HalfedgeMesh, LoopWeights, PolyMesh};
use proptest::prelude::*;

/// The icosahedron after one level of subdivision: closed, genus 0, 80 faces.
fn closed() -> HalfedgeMesh {
    let p = loop_subdivide(
        &HalfedgeMesh::from_polymesh(&icosahedron()).unwrap(),
        LoopWeights::Warren,
    )
    .unwrap();
    HalfedgeMesh::from_polymesh(&p).unwrap()
}

/// `closed()` without the faces whose centroid has z > 0.3: a disk with one boundary loop,
/// still mirror-symmetric in x.
fn open() -> PolyMesh {
    let m = closed().to_polymesh();
    let faces: Vec<Vec<u32>> = m
        .faces()
        .filter(|f| f.iter().map(|&v| m.positions[v as usize].z).sum::<f64>() / 3.0 <= 0.3)
        .map(<[u32]>::to_vec)
        .collect();
    let mut used = vec![u32::MAX; m.vertex_count()];
    let mut positions = Vec::new();
    let faces: Vec<Vec<u32>> = faces
        .iter()
        .map(|f| {
            f.iter()
                .map(|&v| {
                    if used[v as usize] == u32::MAX {
                        used[v as usize] = positions.len() as u32;
                        positions.push(m.positions[v as usize]);
                    }
                    used[v as usize]
                })
                .collect()
        })
        .collect();
    PolyMesh::new(positions, &faces)
}

fn counts(m: &HalfedgeMesh) -> (i64, i64, i64) {
    (
        m.vertex_count() as i64,
        m.edge_count() as i64,
        m.face_count() as i64,
    )
}

#[derive(Clone, Copy, Debug)]
enum Op {
    Flip,
    Split,
    Collapse,
}

fn ops() -> impl Strategy<Value = Vec<(Op, u32)>> {
    prop::collection::vec(
        (
            prop_oneof![Just(Op::Flip), Just(Op::Split), Just(Op::Collapse)],
            any::<u32>(),
        ),
        1..120,
    )
}

/// Applies the operations (edge numbers taken modulo the edge count), checking after each
/// one that the mesh is valid, the Euler characteristic is kept, and the counts changed as
/// the operation's closed form says. Returns how many operations were applied.
fn apply(m: &mut HalfedgeMesh, ops: &[(Op, u32)]) -> Result<usize, TestCaseError> {
    let chi = m.euler_characteristic();
    let mut applied = 0;
    for &(op, k) in ops {
        let e = EdgeId(k % m.edge_count() as u32);
        let boundary = m.is_boundary_edge(e);
        let before = counts(m);
        let (result, delta) = match op {
            Op::Flip => (m.flip(e).map(|_| ()), (0, 0, 0)),
            Op::Split if boundary => (m.split(e).map(|_| ()), (1, 2, 1)),
            Op::Split => (m.split(e).map(|_| ()), (1, 3, 2)),
            Op::Collapse if boundary => (m.collapse(e).map(|_| ()), (-1, -2, -1)),
            Op::Collapse => (m.collapse(e).map(|_| ()), (-1, -3, -2)),
        };
        let after = counts(m);
        prop_assert!(m.validate().is_ok(), "{op:?} {e:?}: {:?}", m.validate());
        prop_assert_eq!(m.euler_characteristic(), chi);
        match result {
            Ok(()) => {
                applied += 1;
                prop_assert_eq!(
                    after,
                    (before.0 + delta.0, before.1 + delta.1, before.2 + delta.2)
                );
            }
            // A refused operation leaves the mesh exactly as it was.
            Err(_) => prop_assert_eq!(after, before),
        }
    }
    // The result survives a trip through a polygon soup.
    let back = HalfedgeMesh::from_polymesh(&m.to_polymesh());
    prop_assert!(back.is_ok(), "{:?}", back.err());
    prop_assert!(back.unwrap().validate().is_ok());
    Ok(applied)
}

/// The map taking each vertex to its mirror image in x, found by brute force.
fn mirror_map(positions: &[DVec3]) -> Vec<usize> {
    positions
        .iter()
        .map(|p| {
            let q = DVec3::new(-p.x, p.y, p.z);
            let (i, d) = positions
                .iter()
                .enumerate()
                .map(|(i, r)| (i, (*r - q).length()))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(d < 1e-12, "not mirror-symmetric");
            i
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Random flips, splits and collapses on a closed mesh keep every invariant.
    #[test]
    fn operations_keep_invariants_on_a_closed_mesh(ops in ops()) {
        let mut m = closed();
        apply(&mut m, &ops)?;
        prop_assert_eq!(m.euler_characteristic(), 2);
    }

    /// The same on an open mesh, where boundary splits and collapses come into play.
    #[test]
    fn operations_keep_invariants_on_an_open_mesh(ops in ops()) {
        let mut m = HalfedgeMesh::from_polymesh(&open()).unwrap();
        prop_assert_eq!(m.euler_characteristic(), 1);
        apply(&mut m, &ops)?;
    }

    /// Subdivision of any (edited) triangle mesh: F' = 4F, V' = V + E, E' = 2E + 3F, the
    /// Euler characteristic is kept and the result is a valid mesh.
    #[test]
    fn subdivision_quadruples_faces(ops in ops(), open_mesh in any::<bool>(), loop_w in any::<bool>()) {
        let mut m = if open_mesh {
            HalfedgeMesh::from_polymesh(&open()).unwrap()
        } else {
            closed()
        };
        apply(&mut m, &ops)?;
        let w = if loop_w { LoopWeights::Loop } else { LoopWeights::Warren };
        let (v, e, f) = counts(&m);
        let s = HalfedgeMesh::from_polymesh(&loop_subdivide(&m, w).unwrap()).unwrap();
        prop_assert!(s.validate().is_ok());
        prop_assert_eq!(counts(&s), (v + e, 2 * e + 3 * f, 4 * f));
        prop_assert_eq!(s.euler_characteristic(), m.euler_characteristic());
    }

    /// A mirror-symmetric mesh, randomly perturbed in a mirror-symmetric way, stays
    /// symmetric after two levels of subdivision (both weights, closed and open).
    #[test]
    fn subdivision_keeps_mirror_symmetry(
        offsets in prop::collection::vec((-0.2f64..0.2, -0.2f64..0.2, -0.2f64..0.2), 42),
        open_mesh in any::<bool>(),
        loop_w in any::<bool>(),
    ) {
        let mut p = if open_mesh { open() } else { closed().to_polymesh() };
        let mirror = mirror_map(&p.positions);
        let mut k = 0;
        for (i, &j) in mirror.iter().enumerate() {
            if j < i {
                continue;
            }
            let (x, y, z) = offsets[k % offsets.len()];
            k += 1;
            if i == j {
                p.positions[i] += DVec3::new(0.0, y, z);
            } else {
                p.positions[i] += DVec3::new(x, y, z);
                p.positions[j] += DVec3::new(-x, y, z);
            }
        }
        mirror_map(&p.positions);
        let w = if loop_w { LoopWeights::Loop } else { LoopWeights::Warren };
        let once = loop_subdivide(&HalfedgeMesh::from_polymesh(&p).unwrap(), w).unwrap();
        let twice = loop_subdivide(&HalfedgeMesh::from_polymesh(&once).unwrap(), w).unwrap();
        let map = mirror_map(&twice.positions);
        // The mirror map is a bijection that takes faces to (reversed) faces.
        let mut faces: Vec<Vec<usize>> = twice
            .faces()
            .map(|f| {
                let mut k: Vec<usize> = f.iter().map(|&v| v as usize).collect();
                k.sort_unstable();
                k
            })
            .collect();
        faces.sort();
        let mut mirrored: Vec<Vec<usize>> = twice
            .faces()
            .map(|f| {
                let mut k: Vec<usize> = f.iter().map(|&v| map[v as usize]).collect();
                k.sort_unstable();
                k
            })
            .collect();
        mirrored.sort();
        prop_assert_eq!(faces, mirrored);
    }
}
