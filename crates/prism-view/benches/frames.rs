//! Frame times of `prism view`'s modes, headless (the window adds one copy of the pixels):
//! a course SVG at 1024x1024 and 16 samples per pixel, one progressive pass of the Cornell
//! box at 512x384, a 50x50 cloth simulated and shaded at 1024x800, and a mesh of over 100k
//! triangles (the course's beetle, Loop-subdivided twice) orbited at 960x720, with and
//! without its wireframe (and the time to pick what the cursor hovers), and the Whitted ray tracer orbiting the Cornell box at 800x800
//! (its previews, and the full frame it refines to). Median and spread of 15 frames each, after 3 to warm up.

use std::time::Instant;

use prism_raster::{read_svg, Dialect};
use prism_view::{ClothMode, Input, Key, MeshMode, PathMode, SvgMode, Viewer, WhittedMode};

fn measure(name: &str, viewer: &mut Viewer, next: &mut dyn FnMut(&mut Viewer)) {
    let mut times = Vec::new();
    for i in 0..18 {
        next(viewer);
        let t = Instant::now();
        let frame = viewer.frame();
        std::hint::black_box(&frame);
        if i >= 3 {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    times.sort_by(f64::total_cmp);
    println!(
        "{name}: median {:.1} ms a frame ({:.0} frames/s), fastest {:.1}, slowest {:.1}",
        times[times.len() / 2],
        1e3 / times[times.len() / 2],
        times[0],
        times[times.len() - 1]
    );
}

fn main() {
    let assets = prism_testkit::shared_assets();
    let svg = assets.join("rasterizer/svg/illustration/05_lion.svg");
    let doc = read_svg(&svg, Dialect::Cs184).expect("the course's lion");
    let here = std::env::temp_dir();
    let mut v = Viewer::new(
        Box::new(SvgMode::new(doc, &svg, Dialect::Cs184, &here)),
        1024,
        1024,
    );
    for _ in 0..3 {
        v.input(Input::Key {
            key: Key::Char('='),
            ctrl: false,
        });
    }
    assert!(v.mode().status().starts_with("16 spp"));
    // Each frame pans by one pixel, so that every frame is drawn anew.
    let mut x = 500.0;
    v.input(Input::Cursor { x, y: 500.0 });
    v.input(Input::Button(true));
    measure("svg 05_lion.svg, 1024x1024, 16 spp", &mut v, &mut |v| {
        x += 1.0;
        v.input(Input::Cursor { x, y: 500.0 });
    });

    let dae = assets.join("pathtracer/dae/sky/CBspheres_lambertian.dae");
    let scene = prism_scene::load(&dae, &prism_scene::SceneOptions::default()).expect("scene");
    let mut v = Viewer::new(Box::new(PathMode::new(&scene, &dae, 0)), 512, 384);
    measure(
        "path CBspheres_lambertian.dae, 512x384, one pass",
        &mut v,
        &mut |_| {},
    );

    let json = assets.join("clothsim/scene/pinned2.json");
    let cloth = prism_cloth::read_scene(&json, &[]).expect("cloth");
    let mut v = Viewer::new(Box::new(ClothMode::new(cloth, &json)), 1024, 800);
    measure(
        "cloth pinned2.json (50x50), 1024x800, one frame simulated and shaded",
        &mut v,
        &mut |_| {},
    );

    let dae = assets.join("meshedit/dae/beetle.dae");
    let (poly, _) = prism_scene::read_mesh(&dae).expect("beetle");
    let mut mesh = prism_mesh::HalfedgeMesh::from_polymesh(&poly).expect("manifold");
    while mesh.face_count() < 100_000 {
        let next =
            prism_mesh::loop_subdivide(&mesh, prism_mesh::LoopWeights::Warren).expect("subdivides");
        mesh = prism_mesh::HalfedgeMesh::from_polymesh(&next).expect("manifold");
    }
    let faces = mesh.face_count();
    let mut v = Viewer::new(Box::new(MeshMode::new(mesh, &dae)), 960, 720);
    // Hovering: each cursor move picks the element under it (the first builds the BVH).
    let mut picks = Vec::new();
    let mut found = 0;
    let mut first = 0.0;
    for i in 0..40 {
        let t = Instant::now();
        v.input(Input::Cursor {
            x: 300.0 + 9.0 * f64::from(i),
            y: 200.0 + 7.0 * f64::from(i),
        });
        let ms = t.elapsed().as_secs_f64() * 1e3;
        if i > 0 {
            picks.push(ms);
        } else {
            first = ms;
        }
        if !v.mode().status().ends_with("under the cursor: -") {
            found += 1;
        }
    }
    picks.sort_by(f64::total_cmp);
    println!(
        "mesh beetle.dae subdivided ({faces} triangles), hover: median {:.3} ms a pick ({found} of 40 on the mesh), slowest {:.3}, the first (building the BVH) {first:.1}",
        picks[picks.len() / 2],
        picks[picks.len() - 1]
    );
    let mut x = 100.0;
    v.input(Input::Cursor { x, y: 100.0 });
    v.input(Input::Button(true));
    for wireframe in ["wireframe", "no wireframe"] {
        measure(
            &format!(
                "mesh beetle.dae subdivided ({faces} triangles), 960x720, orbiting, {wireframe}"
            ),
            &mut v,
            &mut |v| {
                x += 2.0;
                v.input(Input::Cursor { x, y: 100.0 });
            },
        );
        v.input(Input::Key {
            key: Key::Char('w'),
            ctrl: false,
        });
    }

    // The Whitted ray tracer orbiting the mirror Cornell box: previews while the camera
    // moves, and the full-resolution frame it refines to once it rests.
    let scene = prism_scene::Preset::CornellBox
        .load(&[assets.join("delft-raytracer/data")])
        .expect("the Cornell box");
    let whitted = |rest| {
        let mode = WhittedMode::new(
            scene.clone(),
            "cornell-box",
            prism_scene::OrbitCamera::default(),
            prism_scene::Features::prism_defaults(),
        )
        .with_rest(rest);
        Viewer::new(Box::new(mode), 800, 800)
    };
    let mut v = whitted(std::time::Duration::from_secs(86_400));
    let mut x = 100.0;
    v.input(Input::Cursor { x, y: 100.0 });
    v.input(Input::Button(true));
    measure(
        "whitted cornell-box, 800x800, orbiting (half-resolution previews)",
        &mut v,
        &mut |v| {
            x += 2.0;
            v.input(Input::Cursor { x, y: 100.0 });
        },
    );
    let mut v = whitted(std::time::Duration::ZERO);
    v.input(Input::Cursor { x, y: 100.0 });
    v.input(Input::Button(true));
    measure(
        "whitted cornell-box, 800x800, the full-resolution frame after a move",
        &mut v,
        &mut |v| {
            x += 2.0;
            v.input(Input::Cursor { x, y: 100.0 });
            // The preview, then (no rest to wait for) the refined frame is measured.
            v.frame();
        },
    );
}
