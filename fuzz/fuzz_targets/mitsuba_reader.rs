//! Fuzz the Mitsuba 3 scene reader and what follows it: any file must give a scene or an
//! error naming the file, never a panic, strict or lenient. A scene of at most 4096
//! triangles is path-traced at 4x3 pixels, 1 sample, and every pixel must be finite and
//! non-negative. Each input is written to a scratch folder of its own (the reader reads
//! files, and resolves includes and meshes beside them).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("prism-fuzz-mitsuba-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("fuzz.xml");
    std::fs::write(&file, data).unwrap();
    for lenient in [false, true] {
        let options = prism_scene::MitsubaOptions { lenient, sensor: 0 };
        match prism_scene::read_mitsuba_with(&file, &[], options) {
            Ok(m) => {
                let triangles: usize = m.scene.meshes.iter().map(|x| x.triangles.len()).sum();
                if triangles > 4096 {
                    continue;
                }
                let prepared = prism_render::render_scene::RenderScene::new(&m.scene);
                let opts = prism_render::render::RenderOptions {
                    film: prism_render::film::FilmSettings {
                        width: 4,
                        height: 3,
                        spp: 1,
                        filter: m.settings.filter,
                        ..prism_render::film::FilmSettings::default()
                    },
                    path: prism_render::integrators::PathSettings {
                        max_bounces: m.settings.max_bounces.unwrap_or(16).min(16),
                        rr_bounces: m.settings.rr_bounces,
                        hide_emitters: m.settings.hide_emitters,
                        ..prism_render::integrators::PathSettings::default()
                    },
                };
                let out = prism_render::render::render(&prepared, &opts, &|_| {});
                for p in out.image.pixels() {
                    assert!(p.is_finite() && p.r >= 0.0 && p.g >= 0.0 && p.b >= 0.0, "{p:?}");
                }
            }
            Err(e) => assert!(e.to_string().contains("fuzz.xml"), "{e}"),
        }
    }
});
