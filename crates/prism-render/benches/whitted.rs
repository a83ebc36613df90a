//! `cargo bench -p prism-render --bench whitted`: the Whitted ray tracer's rays per second
//! against the BVH's own rate on the very same rays. Each scene (the staged teapot and the
//! mirror Cornell box, 1024x1024, prism's default features) is rendered whole; then every
//! ray the render cast (camera, reflection, shadow, area sample), recorded pixel by pixel,
//! is traced again with traversal alone (closest hit, or occlusion for shadow rays). The
//! ratio of the two rates is what shading, sampling and bookkeeping leave of traversal's
//! speed. Threads: all cores (rayon). Figures are medians of 3 runs.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use prism_math::Ray;
use prism_render::whitted::film::{raytrace, trace_pixel, RaytraceOptions};
use prism_render::whitted::scene::WhittedScene;
use prism_render::whitted::tracer::{RayKind, WhittedSettings};
use prism_scene::{Features, OrbitCamera, Preset};
use rayon::prelude::*;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// A recorded ray: closest hit, or occlusion up to a distance.
enum Query {
    Closest(Ray),
    Occluded(Ray, f32),
}

fn main() {
    let size: u32 = std::env::var("PRISM_WHITTED_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1024);
    let data = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/assets/delft-raytracer/data");
    for preset in [Preset::Teapot, Preset::CornellBox] {
        let scene = preset
            .load(std::slice::from_ref(&data))
            .expect("the staged scene loads");
        let ws = WhittedScene::new(&scene, true);
        let bvh = ws.bvh().expect("built");
        let opts = RaytraceOptions {
            width: size,
            height: size,
            settings: WhittedSettings {
                features: Features::prism_defaults(),
                light_samples: 16,
                max_depth: 3,
                extras: prism_scene::Extras::default(),
            },
            spp: 1,
            bloom: prism_image::Bloom::default(),
            seed: 0,
        };
        let cam = OrbitCamera::default();
        let mut total = 0;
        let render = median(
            (0..3)
                .map(|_| {
                    let t = Instant::now();
                    let out = raytrace(&ws, &cam, &opts, &|_| {});
                    total = out.counts.total();
                    t.elapsed()
                })
                .collect(),
        );
        // Every ray of the render, by row, as traversal queries.
        let rows: Vec<Vec<Query>> = (0..size)
            .into_par_iter()
            .map(|row| {
                let mut q = Vec::new();
                for x in 0..size {
                    for r in trace_pixel(&ws, &cam, &opts, x, row).rays {
                        let d = r.end - r.origin;
                        match r.kind {
                            RayKind::Camera | RayKind::Reflection | RayKind::Transmission => {
                                q.push(Query::Closest(Ray::new(r.origin, d.normalize())));
                            }
                            RayKind::Shadow | RayKind::AreaSample if r.blocked.is_some() => {
                                let dist = d.length();
                                let l = d / dist;
                                q.push(Query::Occluded(
                                    Ray::new(
                                        r.origin + prism_render::whitted::tracer::RAY_EPSILON * l,
                                        l,
                                    ),
                                    dist - prism_render::whitted::tracer::RAY_EPSILON,
                                ));
                            }
                            _ => {}
                        }
                    }
                }
                q
            })
            .collect();
        let replayed: usize = rows.iter().map(Vec::len).sum();
        let traverse = median(
            (0..3)
                .map(|_| {
                    let t = Instant::now();
                    let hits: usize = rows
                        .par_iter()
                        .map(|row| {
                            row.iter()
                                .filter(|q| match q {
                                    Query::Closest(r) => {
                                        bvh.intersect(r, 0.0, f32::INFINITY).is_some()
                                    }
                                    Query::Occluded(r, d) => bvh.occluded(r, 0.0, *d),
                                })
                                .count()
                        })
                        .sum();
                    std::hint::black_box(hits);
                    t.elapsed()
                })
                .collect(),
        );
        let render_rate = total as f64 / render.as_secs_f64();
        let traverse_rate = replayed as f64 / traverse.as_secs_f64();
        println!(
            "{}: {size}x{size}, {} triangles, {total} rays; render {:.1} ms = {:.2} Mrays/s; \
             traversal alone {:.1} ms = {:.2} Mrays/s ({replayed} rays); ratio {:.2}",
            preset.name(),
            ws.triangle_count(),
            render.as_secs_f64() * 1e3,
            render_rate / 1e6,
            traverse.as_secs_f64() * 1e3,
            traverse_rate / 1e6,
            render_rate / traverse_rate
        );
    }
}
