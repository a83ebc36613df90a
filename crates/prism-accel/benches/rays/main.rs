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
//! `valgrind --tool=callgrind`. `PRISM_RAYS_SETS` (a comma-separated list such as
//! `primary,random-batch`) traces only the sets named.
//!
//! `PRISM_EMBREE=<path to libembree4.so>` instead traces the one-ray sets with prism and
//! with that Embree library side by side in this process (`side_by_side`: chunks of the
//! two alternating on each thread, three passes, on 1 and 2 threads), and prints prism's
//! speed over Embree's by the CPU time each spent, and how their hits compare. Embree's
//! scene is built with its defaults, as `embree_rays.py` builds it through `embreex`, and
//! is traced with `rtcIntersect1` directly: no binding's per-ray copying counts against
//! it, as it does in the script's figures.

mod embree;

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
    // An empty value is no value, as for `PRISM_RAYS_SETS` (`dlopen("")` would open this
    // program itself).
    if let Some(lib) = std::env::var("PRISM_EMBREE")
        .ok()
        .filter(|l| !l.trim().is_empty())
    {
        let Some(emb) = embree::Embree::new(&lib, &tris) else {
            std::process::exit(2);
        };
        for (kind, rays, batch) in sets {
            if batch
                || only
                    .as_deref()
                    .is_some_and(|o| !o.split(',').any(|k| k == kind))
            {
                continue;
            }
            for &threads in thread_counts {
                side_by_side(&bvh, &emb, kind, rays, threads, if quick { 1 } else { 3 });
            }
        }
        return;
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

/// What one side-by-side chunk or run measured: each side's thread CPU time, and how the
/// hits compare (rays both hit, rays one side alone hits, rays both hit at distances more
/// than 1e-4 apart relative to prism's).
#[derive(Clone, Copy, Default)]
struct Tally {
    prism: f64,
    embree: f64,
    both: usize,
    prism_only: usize,
    embree_only: usize,
    apart: usize,
}

impl Tally {
    fn add(self, o: Tally) -> Tally {
        Tally {
            prism: self.prism + o.prism,
            embree: self.embree + o.embree,
            both: self.both + o.both,
            prism_only: self.prism_only + o.prism_only,
            embree_only: self.embree_only + o.embree_only,
            apart: self.apart + o.apart,
        }
    }
}

/// Traces `rays` with prism and with Embree in chunks of 1024, each chunk by the two back
/// to back on one thread (which first alternates from chunk to chunk and pass to pass),
/// `passes` times over on `threads` threads, and prints prism's speed divided by Embree's:
/// the ratio of the thread CPU time each spent, whole and per pass. Load on the machine
/// slows both alike, so the ratio holds to a percent or two where separate runs differ by
/// tens of percent.
fn side_by_side(
    bvh: &Bvh,
    emb: &embree::Embree,
    kind: &str,
    rays: &[Ray],
    threads: usize,
    passes: usize,
) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let chunk = |i: usize, c: &[Ray], pass: usize| {
        let prism = || {
            let t0 = thread_cpu();
            let hits: Vec<Option<f32>> = c
                .iter()
                .map(|r| bvh.intersect(r, 0.0, f32::INFINITY).map(|h| h.t))
                .collect();
            ((thread_cpu() - t0).as_secs_f64(), hits)
        };
        let embree = || {
            let t0 = thread_cpu();
            let hits: Vec<Option<f32>> = c.iter().map(|r| emb.intersect(r)).collect();
            ((thread_cpu() - t0).as_secs_f64(), hits)
        };
        let ((tp, hp), (te, he)) = if (i + pass).is_multiple_of(2) {
            let p = prism();
            (p, embree())
        } else {
            let e = embree();
            (prism(), e)
        };
        let mut t = Tally {
            prism: tp,
            embree: te,
            ..Tally::default()
        };
        for (p, e) in hp.iter().zip(&he) {
            match (p, e) {
                (Some(p), Some(e)) => {
                    t.both += 1;
                    t.apart += usize::from((p - e).abs() > 1e-4 * p.abs());
                }
                (Some(_), None) => t.prism_only += 1,
                (None, Some(_)) => t.embree_only += 1,
                (None, None) => {}
            }
        }
        t
    };
    let runs: Vec<Tally> = (0..passes)
        .map(|pass| {
            pool.install(|| {
                rays.par_chunks(1024)
                    .enumerate()
                    .map(|(i, c)| chunk(i, c, pass))
                    .reduce(Tally::default, Tally::add)
            })
        })
        .collect();
    let mut ratios: Vec<f64> = runs.iter().map(|t| t.embree / t.prism).collect();
    ratios.sort_by(f64::total_cmp);
    let all = runs.iter().copied().fold(Tally::default(), Tally::add);
    let n = (rays.len() * passes) as f64;
    let last = runs[runs.len() - 1];
    println!(
        "{kind:13} threads={threads} prism/Embree speed {:.3} (passes {:.3}-{:.3}); \
         prism {:.2} Embree {:.2} Mrays/cpu-s; hits: both {} (apart {}), prism only {}, Embree only {}",
        all.embree / all.prism,
        ratios[0],
        ratios[ratios.len() - 1],
        n / all.prism / 1e6,
        n / all.embree / 1e6,
        last.both,
        last.apart,
        last.prism_only,
        last.embree_only
    );
}
