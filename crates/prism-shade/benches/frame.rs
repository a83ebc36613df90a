//! `cargo bench -p prism-shade --bench frame`: time per frame of the software pipeline, to
//! put beside Mesa llvmpipe's (`../shared/bench/shade/gl_time.py`, which times clear, draw
//! and finish of a bound scene). The headline case is the issue's: the Delft teapot with
//! Blinn-Phong at 1024x800 from (0.6, 0.8, 3.2); the 50x50 cloth with Blinn-Phong at the
//! same size follows. Each case renders 3 frames to warm up, then 20; the median frame is
//! printed (vertex stage to finished 8-bit image, no file I/O), on all cores.
//!
//! `PRISM_SHADE_OBJ=mesh.obj` adds that mesh with Blinn-Phong at 960x720 from
//! `PRISM_SHADE_EYE` (default `1.5,0.5,2.5`) towards the origin, without and with a black
//! wireframe: the beetle Loop-subdivided twice (`prism mesh subdivide -n 2`, 120,928
//! triangles) is the second case, put beside `gl_time.py` with the same camera.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use prism_math::Vec3;
use prism_shade::{shade_rgb8, ShadeMesh, ShadeOptions, Shader, Uniforms, View};

fn median_frame(mesh: &ShadeMesh, view: &View, shader: &Shader) -> Duration {
    median_frame_with(mesh, view, shader, &ShadeOptions::default())
}

fn median_frame_with(
    mesh: &ShadeMesh,
    view: &View,
    shader: &Shader,
    opts: &ShadeOptions,
) -> Duration {
    let u = Uniforms::default();
    let mut times: Vec<Duration> = (0..23)
        .map(|_| {
            let t = Instant::now();
            let img = shade_rgb8(mesh, view, shader, &u, opts).expect("renders");
            std::hint::black_box(img);
            t.elapsed()
        })
        .skip(3)
        .collect();
    times.sort();
    times[times.len() / 2]
}

fn main() {
    let data = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/assets/delft-raytracer/data/teapot.obj");
    let text = std::fs::read_to_string(&data).expect("the staged teapot");
    let teapot = ShadeMesh::from_obj(&text, "teapot.obj").expect("reads");
    let view = View {
        eye: Vec3::new(0.6, 0.8, 3.2),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y: 45.0,
        width: 1024,
        height: 800,
    };
    let t = median_frame(&teapot, &view, &Shader::Phong);
    println!(
        "teapot ({} triangles) phong 1024x800: {:.2} ms per frame ({} threads)",
        teapot.triangles.len(),
        t.as_secs_f64() * 1e3,
        rayon::current_num_threads()
    );
    let side = 50;
    let grid: Vec<Vec3> = (0..side * side)
        .map(|i| {
            let (x, y) = ((i % side) as f32, (i / side) as f32);
            let s = 1.0 / (side - 1) as f32;
            Vec3::new(x * s, 0.3 + 0.05 * (x * s * 6.0).sin(), y * s)
        })
        .collect();
    let cloth = ShadeMesh::grid(&grid, side, side);
    let view = View {
        eye: Vec3::new(0.5, 1.2, 2.2),
        target: Vec3::new(0.5, 0.3, 0.5),
        ..view
    };
    let t = median_frame(&cloth, &view, &Shader::Phong);
    println!(
        "cloth 50x50 phong 1024x800: {:.2} ms per frame",
        t.as_secs_f64() * 1e3
    );
    let Ok(path) = std::env::var("PRISM_SHADE_OBJ") else {
        return;
    };
    let text = std::fs::read_to_string(&path).expect("PRISM_SHADE_OBJ reads");
    let mesh = ShadeMesh::from_obj(&text, &path).expect("PRISM_SHADE_OBJ is a mesh");
    let eye: Vec<f32> = std::env::var("PRISM_SHADE_EYE")
        .unwrap_or_else(|_| "1.5,0.5,2.5".into())
        .split(',')
        .map(|v| v.trim().parse().expect("PRISM_SHADE_EYE is X,Y,Z"))
        .collect();
    let view = View {
        eye: Vec3::new(eye[0], eye[1], eye[2]),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y: 45.0,
        width: 960,
        height: 720,
    };
    for wireframe in [None, Some(prism_math::Rgb::new(0.0, 0.0, 0.0))] {
        let opts = ShadeOptions {
            wireframe,
            ..ShadeOptions::default()
        };
        let t = median_frame_with(&mesh, &view, &Shader::Phong, &opts);
        println!(
            "{path} ({} triangles) phong 960x720{}: {:.2} ms per frame",
            mesh.triangles.len(),
            if wireframe.is_some() {
                ", wireframe"
            } else {
                ""
            },
            t.as_secs_f64() * 1e3
        );
    }
}
