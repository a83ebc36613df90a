//! `cargo bench -p prism-raster`: render every staged course SVG at 1024x1024 with 1 and 16
//! samples per pixel on all cores, reporting the median of 5 runs per file and the total.
//! With `PRISM_RASTER_SVG=folder` it renders that folder's standard SVGs instead, at
//! 960x640 with 16 samples per pixel (the raster bench's setting), reporting the median
//! of 41 runs per file and the stage times of the median run.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use prism_raster::{read_svg, render, Dialect, RasterOptions};

fn svgs(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            svgs(&p, out);
        } else if p.extension().is_some_and(|e| e == "svg") {
            out.push(p);
        }
    }
}

/// Renders each standard SVG under `dir` at 960x640, 16 samples per pixel.
fn standard(dir: &Path) {
    let mut files = Vec::new();
    svgs(dir, &mut files);
    println!("threads: {}", rayon::current_num_threads());
    for f in &files {
        let doc = read_svg(f, Dialect::Svg).expect("svg parses");
        let opts = RasterOptions {
            width: 960,
            height: 640,
            samples: 16,
            ..RasterOptions::default()
        };
        let mut runs: Vec<(Duration, prism_raster::RasterStats)> = (0..41)
            .map(|_| {
                let t = Instant::now();
                let (_, stats) = render(&doc, &opts).expect("render");
                (t.elapsed(), stats)
            })
            .collect();
        runs.sort_by_key(|r| r.0);
        let (t, s) = runs[20];
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        println!(
            "{:<16} {:>7.2} ms  (prepare {:.2}, raster {:.2}, resolve {:.2})",
            f.file_name().unwrap_or_default().to_string_lossy(),
            ms(t),
            ms(s.prepare),
            ms(s.raster),
            ms(s.resolve)
        );
    }
}

fn main() {
    if let Some(dir) = std::env::var_os("PRISM_RASTER_SVG") {
        standard(Path::new(&dir));
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/assets/rasterizer/svg");
    let mut files = Vec::new();
    svgs(&root, &mut files);
    if files.is_empty() {
        eprintln!("no staged SVGs under {}", root.display());
        return;
    }
    println!("threads: {}", rayon::current_num_threads());
    for samples in [1u32, 16] {
        let mut total = Duration::ZERO;
        for f in &files {
            let doc = read_svg(f, Dialect::Cs184).expect("staged svg parses");
            let opts = RasterOptions {
                samples,
                compat: true,
                ..RasterOptions::default()
            };
            let mut times: Vec<Duration> = (0..5)
                .map(|_| {
                    let t = Instant::now();
                    let _ = render(&doc, &opts).expect("render");
                    t.elapsed()
                })
                .collect();
            times.sort();
            total += times[2];
            let name = f.strip_prefix(&root).unwrap_or(f).display();
            println!(
                "{samples:>2} spp  {name:<40} {:>8.2} ms",
                times[2].as_secs_f64() * 1e3
            );
        }
        println!(
            "{samples:>2} spp  total over {} files: {:.1} ms",
            files.len(),
            total.as_secs_f64() * 1e3
        );
    }
}
