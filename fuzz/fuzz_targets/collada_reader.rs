//! Fuzz the COLLADA reader and what follows it: any input must give a document or an error
//! naming the file, never a panic. A document's meshes must flatten and build or refuse
//! cleanly; a document that makes a scene is path-traced at 4x3 pixels, 1 sample, and every
//! pixel must be finite and non-negative.
#![no_main]

use libfuzzer_sys::fuzz_target;
use prism_mesh::HalfedgeMesh;
use prism_scene::{parse_collada, Scene, SceneOptions};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match parse_collada(text, "fuzz.dae") {
        Ok(doc) => {
            match doc.world_mesh(true) {
                Ok(mesh) => {
                    if let Ok(h) = HalfedgeMesh::from_polymesh(&mesh) {
                        h.validate().expect("a built mesh validates");
                    }
                }
                Err(e) => assert!(e.to_string().starts_with("fuzz.dae"), "{e}"),
            }
            match Scene::from_collada(&doc, &SceneOptions::default(), "fuzz.dae") {
                Ok(scene) => {
                    let triangles: usize = scene.meshes.iter().map(|m| m.triangles.len()).sum();
                    if triangles <= 4096 {
                        let prepared = prism_render::render_scene::RenderScene::new(&scene);
                        let opts = prism_render::render::RenderOptions {
                            film: prism_render::film::FilmSettings {
                                width: 4,
                                height: 3,
                                spp: 1,
                                ..prism_render::film::FilmSettings::default()
                            },
                            ..prism_render::render::RenderOptions::default()
                        };
                        let out = prism_render::render::render(&prepared, &opts, &|_| {});
                        for p in out.image.pixels() {
                            assert!(p.is_finite() && p.r >= 0.0 && p.g >= 0.0 && p.b >= 0.0, "{p:?}");
                        }
                    }
                }
                Err(e) => assert!(e.to_string().starts_with("fuzz.dae"), "{e}"),
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.dae"), "{e}"),
    }
});
