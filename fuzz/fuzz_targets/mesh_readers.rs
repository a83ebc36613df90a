//! Fuzz the OBJ and PLY readers and what follows them: any input must give a mesh or a
//! located error, never a panic. A mesh that reads is built as a halfedge mesh; one that
//! builds must validate, survive a round trip and, when small, subdivide. The load-time
//! repairs (detaching faces on used edges, splitting vertices where fans touch) change
//! nothing in a mesh that builds, and a repaired mesh that builds validates.
#![no_main]

use libfuzzer_sys::fuzz_target;
use prism_mesh::{loop_subdivide, parse_obj, parse_ply, HalfedgeMesh, LoopWeights, PolyMesh};

fn exercise(mesh: PolyMesh) {
    let mut repaired = mesh.clone();
    let detached = repaired.detach_faces_on_used_edges();
    let split = repaired.split_nonmanifold_vertices();
    if let Ok(r) = HalfedgeMesh::from_polymesh(&repaired) {
        r.validate().expect("a repaired mesh validates");
    }
    let Ok(h) = HalfedgeMesh::from_polymesh(&mesh) else { return };
    assert!(detached.is_empty() && split.is_empty(), "a mesh that builds needs no repair");
    h.validate().expect("a built mesh validates");
    let back = HalfedgeMesh::from_polymesh(&h.to_polymesh()).expect("round trip builds");
    assert_eq!(back.face_count(), h.face_count());
    let _ = prism_mesh::vertex_normals_area_weighted(&mesh);
    if h.face_count() <= 256 {
        if let Ok(s) = loop_subdivide(&h, LoopWeights::Loop) {
            assert_eq!(s.face_count(), 4 * h.face_count());
        }
    }
}

fuzz_target!(|data: &[u8]| {
    match parse_ply(data, "fuzz.ply") {
        Ok(m) => exercise(m),
        Err(e) => assert!(e.to_string().starts_with("fuzz.ply:"), "{e}"),
    }
    if let Ok(text) = std::str::from_utf8(data) {
        match parse_obj(text, "fuzz.obj") {
            Ok(m) => exercise(m),
            Err(e) => assert!(e.to_string().starts_with("fuzz.obj:"), "{e}"),
        }
    }
});
