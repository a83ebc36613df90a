//! Fuzz sequences of edge flips, splits and collapses on closed and open meshes: every
//! operation either applies or is refused with the mesh unchanged, and after each one the
//! mesh validates and keeps its Euler characteristic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use prism_math::glam::DVec3;
use prism_mesh::{icosahedron, EdgeId, HalfedgeMesh, PolyMesh};

fn base(kind: u8) -> HalfedgeMesh {
    let mesh = match kind % 4 {
        0 => icosahedron(),
        // A tetrahedron: every collapse is refused.
        1 => PolyMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            &[vec![0, 2, 1], vec![0, 1, 3], vec![1, 2, 3], vec![2, 0, 3]],
        ),
        // An open 3x3 grid of squares, each cut into two triangles.
        2 => {
            let n = 4u32;
            let positions = (0..n * n)
                .map(|i| DVec3::new(f64::from(i % n), f64::from(i / n), 0.0))
                .collect();
            let mut faces = Vec::new();
            for y in 0..n - 1 {
                for x in 0..n - 1 {
                    let v = y * n + x;
                    faces.push(vec![v, v + 1, v + n + 1]);
                    faces.push(vec![v, v + n + 1, v + n]);
                }
            }
            PolyMesh::new(positions, &faces)
        }
        // A single triangle.
        _ => PolyMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], &[vec![0, 1, 2]]),
    };
    HalfedgeMesh::from_polymesh(&mesh).expect("base meshes build")
}

fuzz_target!(|data: &[u8]| {
    let Some((&kind, ops)) = data.split_first() else { return };
    let mut m = base(kind);
    let chi = m.euler_characteristic();
    for op in ops.chunks_exact(3).take(2000) {
        if m.edge_count() > 20_000 {
            break;
        }
        let e = EdgeId(u32::from(u16::from_le_bytes([op[1], op[2]])) % m.edge_count() as u32);
        let before = (m.vertex_count(), m.edge_count(), m.face_count());
        let ok = match op[0] % 3 {
            0 => m.flip(e).is_ok(),
            1 => m.split(e).is_ok(),
            _ => m.collapse(e).is_ok(),
        };
        if !ok {
            assert_eq!((m.vertex_count(), m.edge_count(), m.face_count()), before);
        }
        if let Err(msg) = m.validate() {
            panic!("after {:?} of edge {}: {msg}", op[0] % 3, e.0);
        }
        assert_eq!(m.euler_characteristic(), chi);
    }
    let back = HalfedgeMesh::from_polymesh(&m.to_polymesh()).expect("round trip builds");
    back.validate().expect("round trip validates");
});
