//! `cargo bench -p prism-render --bench render`: whole path-traced renders, in samples per
//! second, of the staged Cornell-box scenes at the settings `../shared/bench/pathtrace/`
//! times Mitsuba 3 at: 512x384, 64 spp, `-m 7` (Mitsuba max_depth 8), the course's camera,
//! both cores, with the wavefront integrator (`path`, the default) and its one-path-at-a-time
//! reference (`path-scalar`), alternating. Each scene renders once per integrator to warm up,
//! then 3 times each; the medians are printed, with the spread. `PRISM_RENDER_SPP` changes the sample count, `PRISM_RENDER_SCENES` the list
//! (comma-separated names in `pathtracer/dae/sky/`).

use std::path::PathBuf;
use std::time::Instant;

use prism_render::film::FilmSettings;
use prism_render::integrators::{Integrator, PathSettings};
use prism_render::render::{render, RenderOptions};
use prism_render::render_scene::RenderScene;
use prism_scene::SceneOptions;

fn main() {
    let spp: u32 = std::env::var("PRISM_RENDER_SPP")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(64);
    let names = std::env::var("PRISM_RENDER_SCENES")
        .unwrap_or_else(|_| "CBspheres_lambertian,CBbunny,CBspheres_microfacet_al_ag".to_string());
    let dir =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/assets/pathtracer/dae/sky");
    for name in names.split(',') {
        let scene = prism_scene::load(&dir.join(format!("{name}.dae")), &SceneOptions::default())
            .expect("the staged scene loads");
        let t = Instant::now();
        let prepared = RenderScene::new(&scene);
        let build = t.elapsed();
        let integrators = [Integrator::Path, Integrator::PathScalar];
        let run = |integrator: Integrator| {
            let opts = RenderOptions {
                film: FilmSettings {
                    spp,
                    ..FilmSettings::default()
                },
                path: PathSettings {
                    integrator,
                    ..PathSettings::default()
                },
            };
            let t = Instant::now();
            let out = render(&prepared, &opts, &|_| {});
            out.total_samples as f64 / t.elapsed().as_secs_f64()
        };
        for i in integrators {
            run(i);
        }
        let mut rates = [Vec::new(), Vec::new()];
        for _ in 0..3 {
            for (k, &i) in integrators.iter().enumerate() {
                rates[k].push(run(i));
            }
        }
        for (rates, label) in rates.iter_mut().zip(["path", "path-scalar"]) {
            rates.sort_by(f64::total_cmp);
            println!(
                "{name} {label}: {:.2} M samples/s (median of 3; {:.2} to {:.2}), scene build {:.1} ms, {} threads",
                rates[1] / 1e6,
                rates[0] / 1e6,
                rates[2] / 1e6,
                build.as_secs_f64() * 1e3,
                rayon::current_num_threads()
            );
        }
    }
}
