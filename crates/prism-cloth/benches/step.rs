//! `cargo bench -p prism-cloth --bench step`: particle-updates/s of the course's simulation
//! on the 128x128 cloth that `../shared/bench/cloth/warp_spring_bench.py warp_cpu 128` is
//! compared with (pinned2's cloth at 128x128 points: 1x1 m, every spring family, two pinned
//! corners, thickness scaled with the spacing, self-collision and the length limit as the
//! algorithm has them). It runs 20 frames (600 steps) after 10 frames to let the cloth
//! start falling, three times, and prints the best run's rate and per-step times on all
//! cores, then on one thread. `PRISM_CLOTH_SIDE` changes the side.

use std::time::Instant;

use prism_cloth::{parse_scene, Cloth, StepTimes, STEPS_PER_FRAME};

fn scene(side: usize) -> String {
    let thickness = 0.0095 * 49.0 / (side - 1) as f64;
    format!(
        r#"{{"cloth": {{"damping": 0.2, "density": 150.0, "ks": 5000.0,
        "enable_structural": true, "enable_shearing": true, "enable_bending": true,
        "orientation": 0, "width": 1, "height": 1, "num_width_points": {side},
        "num_height_points": {side}, "thickness": {thickness}, "pinned": [[0, 0], [{last}, 0]]}}}}"#,
        last = side - 1
    )
}

fn run(start: &Cloth, frames: usize) -> (f64, StepTimes) {
    let mut cloth = start.clone();
    cloth.times = StepTimes::default();
    let t = Instant::now();
    for _ in 0..frames {
        cloth.frame();
    }
    let secs = t.elapsed().as_secs_f64();
    assert!(cloth.is_finite());
    let updates = (cloth.positions.len() * frames * STEPS_PER_FRAME) as f64;
    (updates / secs, cloth.times)
}

fn main() {
    let side: usize = std::env::var("PRISM_CLOTH_SIDE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(128);
    let scene = parse_scene(&scene(side), "bench.json", &[]).expect("the bench scene reads");
    let mut start = Cloth::new(&scene);
    for _ in 0..10 {
        start.frame();
    }
    let frames = 20;
    let report = |label: &str| {
        let (rate, times) = (0..3)
            .map(|_| run(&start, frames))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .expect("three runs");
        let steps = (frames * STEPS_PER_FRAME) as f64;
        let per_step: Vec<String> = StepTimes::NAMES
            .iter()
            .zip(times.steps)
            .map(|(n, t)| format!("{n} {:.0} us", t.as_secs_f64() * 1e6 / steps))
            .collect();
        println!(
            "cloth {side}x{side} {label}: {:.2} M particle-updates/s (per step: {})",
            rate / 1e6,
            per_step.join(", ")
        );
    };
    report(&format!("{} threads", rayon::current_num_threads()));
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool")
        .install(|| report("1 thread"));
}
