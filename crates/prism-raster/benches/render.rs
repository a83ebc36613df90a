//! `cargo bench -p prism-raster`: render every staged course SVG at 1024x1024 with 1 and 16
//! samples per pixel on all cores, reporting the median of 5 runs per file and the total.

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

fn main() {
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
