//! Fuzz the COLLADA reader: any input must give a document or an error naming the file,
//! never a panic; a document's meshes must flatten and build or refuse cleanly.
#![no_main]

use libfuzzer_sys::fuzz_target;
use prism_mesh::HalfedgeMesh;
use prism_scene::parse_collada;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match parse_collada(text, "fuzz.dae") {
        Ok(doc) => {
            let mesh = doc.world_mesh(true);
            if let Ok(h) = HalfedgeMesh::from_polymesh(&mesh) {
                h.validate().expect("a built mesh validates");
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.dae"), "{e}"),
    }
});
