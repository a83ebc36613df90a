//! `cargo bench -p prism-accel`: BVH build time and closest-hit ray throughput, set up as
//! `../shared/bench/pathtrace/embree_rays.py` sets up Embree, so the figures compare:
//! - primary: 1024x1024 pinhole rays looking down -z at the mesh (45 degree field of view,
//!   eye at 1.6 half-diagonals from the centre), in scanline order;
//! - random: 2,000,000 rays with origins uniform in the mesh's box and directions uniform
//!   on the sphere.
//!
//!
//! Each set is traced one ray per call (`Bvh::intersect`, as the Embree script calls
//! `rtcIntersect1`), then a chunk per call (`primary-batch`, `random-batch`:
//! `Bvh::intersect_batch`, which walks groups of sixteen primary rays as packets, and
//! random rays two at a time).
//!
//! The mesh is `PRISM_RAYS_MESH` (.obj, .ply or .dae), by default the staged bunny
//! (`pathtracer/dae/sky/bunny.dae`). Threads: 1 and 2 (rayon, rays in chunks of 4096).
//! Each figure is the median of 5 runs. `Mrays/cpu-s` divides the rays by the CPU time the
//! tracing threads spent in their chunks (as the Embree script's figure of that name does):
//! per-core speed, less hurt than `Mrays/s` by other work on a busy machine.
//! `PRISM_RAYS_QUICK=1` traces each set once on one thread, for instruction counts under
//! `valgrind --tool=callgrind`. `PRISM_RAYS_SETS` (a
//! comma-separated list such as `primary,random-batch`) traces only the sets named.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use prism_accel::{BuildOptions, Bvh};
use prism_math::{Pcg32, Ray, Vec3};
use rayon::prelude::*;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn load(path: &Path) -> Vec<[Vec3; 3]> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let mesh = match ext {
        "obj" => prism_mesh::read_obj(path).expect("mesh reads"),
        "ply" => prism_mesh::read_ply(path).expect("mesh reads"),
        _ => prism_scene::read_collada(path)
            .expect("mesh reads")
            .world_mesh(true)
            .expect("mesh places"),
    };
    let p = |i: u32| mesh.positions[i as usize].as_vec3();
    mesh.faces()
        .flat_map(|f| (1..f.len() - 1).map(move |k| [p(f[0]), p(f[k]), p(f[k + 1])]))
        .collect()
}

/// CPU time the calling thread has used so far (zero where the platform has no such clock).
fn thread_cpu() -> Duration {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `ts` is a valid `timespec` for the call to fill.
        if unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) } == 0 {
            return Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32);
        }
    }
    Duration::ZERO
}

/// One timed trace: wall time, the CPU time the tracing threads spent in their chunks, and
/// the fraction of rays that hit.
struct Run {
    wall: Duration,
    cpu: Duration,
    hit: f64,
}

/// Traces `rays` on `threads` threads in chunks of 4096: one ray per call
/// ([`Bvh::intersect`]), or, with `batch`, a chunk per call ([`Bvh::intersect_batch`]).
fn trace(bvh: &Bvh, rays: &[Ray], threads: usize, batch: bool) -> Run {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let t = Instant::now();
        let (hits, cpu) = rays
            .par_chunks(4096)
            .map(|c| {
                let cpu = thread_cpu();
                let hits = if batch {
                    let mut hits = vec![None; c.len()];
                    bvh.intersect_batch(c, 0.0, f32::INFINITY, &mut hits);
                    hits.iter().filter(|h| h.is_some()).count()
                } else {
                    c.iter()
                        .filter(|r| bvh.intersect(r, 0.0, f32::INFINITY).is_some())
                        .count()
                };
                (hits, thread_cpu().saturating_sub(cpu))
            })
            .reduce(|| (0, Duration::ZERO), |a, b| (a.0 + b.0, a.1 + b.1));
        Run {
            wall: t.elapsed(),
            cpu,
            hit: hits as f64 / rays.len() as f64,
        }
    })
}

fn main() {
    let path = std::env::var_os("PRISM_RAYS_MESH").map_or_else(
        || {
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../../shared/assets/pathtracer/dae/sky/bunny.dae")
        },
        PathBuf::from,
    );
    let tris = load(&path);
    let build = median(
        (0..if std::env::var_os("PRISM_RAYS_QUICK").is_some() {
            1
        } else {
            3
        })
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(Bvh::build(&tris, &[], &BuildOptions::default()));
                t.elapsed()
            })
            .collect(),
    );
    let bvh = Bvh::build(&tris, &[], &BuildOptions::default());
    let s = bvh.stats();
    println!("mesh: {} ({} triangles)", path.display(), tris.len());
    println!(
        "build: {:.1} ms  nodes {}  leaves {}  depth {}  max leaf {}  SAH cost {:.1}  {:.1} bytes/triangle",
        build.as_secs_f64() * 1e3,
        s.nodes,
        s.leaves,
        s.depth,
        s.max_leaf_size,
        s.sah_cost,
        s.bytes as f64 / tris.len() as f64
    );

    let b = bvh.bounds();
    let (c, ext) = (b.centroid(), b.extent().length() / 2.0);
    let eye = c + Vec3::new(0.0, 0.0, 1.6 * ext);
    let res = 1024;
    let tan = (std::f32::consts::PI / 8.0).tan();
    let primary: Vec<Ray> = (0..res * res)
        .map(|i| {
            let x = ((i % res) as f32 + 0.5) / res as f32 * 2.0 - 1.0;
            let y = -(((i / res) as f32 + 0.5) / res as f32 * 2.0 - 1.0);
            Ray::new(eye, Vec3::new(x * tan, y * tan, -1.0).normalize())
        })
        .collect();
    let mut rng = Pcg32::new(2, 0);
    let random: Vec<Ray> = (0..2_000_000)
        .map(|_| {
            let o = b.min + b.extent() * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let z = 1.0 - 2.0 * rng.next_f32();
            let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
            let r = (1.0 - z * z).max(0.0).sqrt();
            Ray::new(o, Vec3::new(r * phi.cos(), r * phi.sin(), z))
        })
        .collect();
    let quick = std::env::var_os("PRISM_RAYS_QUICK").is_some();
    let (thread_counts, n_runs): (&[usize], usize) = if quick { (&[1], 1) } else { (&[1, 2], 5) };
    let sets = [
        ("primary", &primary, false),
        ("random", &random, false),
        ("primary-batch", &primary, true),
        ("random-batch", &random, true),
    ];
    let only = std::env::var("PRISM_RAYS_SETS")
        .ok()
        .filter(|o| !o.trim().is_empty());
    if let Some(o) = &only {
        let known: Vec<&str> = sets.iter().map(|s| s.0).collect();
        if let Some(bad) = o.split(',').map(str::trim).find(|k| !known.contains(k)) {
            eprintln!(
                "PRISM_RAYS_SETS: no ray set {bad:?}; the sets are {}",
                known.join(", ")
            );
            std::process::exit(2);
        }
    }
    for (kind, rays, batch) in sets {
        if only
            .as_deref()
            .is_some_and(|o| !o.split(',').any(|k| k == kind))
        {
            continue;
        }
        for &threads in thread_counts {
            if !quick {
                trace(&bvh, &rays[..10_000], threads, batch);
            }
            let runs: Vec<Run> = (0..n_runs)
                .map(|_| trace(&bvh, rays, threads, batch))
                .collect();
            let hit = runs[0].hit;
            let med = median(runs.iter().map(|r| r.wall).collect());
            let cpu = median(runs.iter().map(|r| r.cpu).collect());
            let per_cpu = if cpu.is_zero() {
                "-".to_string()
            } else {
                format!("{:.2}", rays.len() as f64 / cpu.as_secs_f64() / 1e6)
            };
            println!(
                "{kind:13} threads={threads} rays={} hit={hit:.3} median={:.1} ms Mrays/s={:.2} Mrays/cpu-s={per_cpu}",
                rays.len(),
                med.as_secs_f64() * 1e3,
                rays.len() as f64 / med.as_secs_f64() / 1e6
            );
        }
    }
}
