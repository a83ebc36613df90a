//! `cargo bench -p prism-mesh`: halfedge construction and one level of Loop subdivision on
//! an icosphere of 327,680 faces (the icosahedron subdivided 7 times), median of 5 runs.

use std::time::{Duration, Instant};

use prism_mesh::{icosahedron, loop_subdivide, HalfedgeMesh, LoopWeights};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn main() {
    let mut p = icosahedron();
    for _ in 0..7 {
        p = loop_subdivide(
            &HalfedgeMesh::from_polymesh(&p).expect("manifold"),
            LoopWeights::Warren,
        )
        .expect("triangles");
    }
    let faces = p.face_count();
    let build = median(
        (0..5)
            .map(|_| {
                let t = Instant::now();
                let m = HalfedgeMesh::from_polymesh(&p).expect("manifold");
                let e = t.elapsed();
                std::hint::black_box(m);
                e
            })
            .collect(),
    );
    let m = HalfedgeMesh::from_polymesh(&p).expect("manifold");
    let sub = median(
        (0..5)
            .map(|_| {
                let t = Instant::now();
                let out = loop_subdivide(&m, LoopWeights::Warren).expect("triangles");
                let e = t.elapsed();
                std::hint::black_box(out);
                e
            })
            .collect(),
    );
    let bytes = m.halfedge_count() * 16 + m.face_count() * 4 + m.vertex_count() * (24 + 4);
    println!("input faces: {faces}");
    println!(
        "halfedge build: {:.1} ms ({:.2} M faces/s)",
        build.as_secs_f64() * 1e3,
        faces as f64 / build.as_secs_f64() / 1e6
    );
    println!(
        "loop subdivide: {:.1} ms ({:.2} M output faces/s)",
        sub.as_secs_f64() * 1e3,
        4.0 * faces as f64 / sub.as_secs_f64() / 1e6
    );
    println!(
        "halfedge mesh: {:.1} bytes per face",
        bytes as f64 / faces as f64
    );
}
