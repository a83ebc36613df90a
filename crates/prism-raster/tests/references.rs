//! Golden-image tests against the course's own reference renders
//! (`shared/assets/rasterizer/tests/outputs/reference/`, made by the CS184 staff renderer at
//! 1024x1024, sample rate 1, nearest pixel sampling, level 0), and against resvg renders of
//! the project's own standard-SVG suite (`tests/data/*.svg`, references made by resvg 0.49).

use std::path::Path;

use prism_raster::{read_svg, render, Dialect, RenderOptions};
use prism_testkit::{compare_golden, shared_assets, workspace_root};

/// The course's reference file name: every character outside `abdefghijklmnopqrstuvwxyz0-9`
/// becomes `-` (the letter c included).
fn reference_name(rel: &str) -> String {
    rel.chars()
        .map(|c| if "abdefghijklmnopqrstuvwxyz0123456789".contains(c) { c } else { '-' })
        .collect::<String>()
        + ".png"
}

fn staged_svgs() -> Vec<String> {
    let root = shared_assets().join("rasterizer");
    let mut out = Vec::new();
    for dir in ["basic", "hardcore", "illustration", "subdiv", "texmap", "transforms"] {
        let mut files: Vec<String> = std::fs::read_dir(root.join("svg").join(dir))
            .expect("staged svg folder")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".svg"))
            .collect();
        files.sort();
        out.extend(files.into_iter().map(|f| format!("svg/{dir}/{f}")));
    }
    out
}

/// Every staged course reference is reproduced with `--compat cs184` at default settings.
/// Reports the identical-pixel fraction per file and fails below 99.9%.
#[test]
fn cs184_references_reproduced() {
    let root = shared_assets().join("rasterizer");
    let mut report = Vec::new();
    let mut failures = Vec::new();
    for rel in staged_svgs() {
        let reference = root.join("tests/outputs/reference").join(reference_name(&rel));
        assert!(reference.exists(), "missing reference {}", reference.display());
        let doc = read_svg(&root.join(&rel), Dialect::Cs184).unwrap_or_else(|e| panic!("{e}"));
        let opts = RenderOptions { compat: true, ..RenderOptions::default() };
        let (img, _) = render(&doc, &opts).expect("render");
        let name = rel.replace('/', "_");
        let result = std::panic::catch_unwind(|| {
            compare_golden(&name, &reference, &img.to_rgb8(), false, |s| s.identical_fraction >= 0.999)
        });
        match result {
            Ok(s) => report.push(format!("{rel}: {:.4}% identical, max error {}", 100.0 * s.identical_fraction, s.max_error)),
            Err(_) => {
                let s = prism_image::compare_rgb8(&prism_image::read_png(&reference).unwrap().to_rgb8(), &img.to_rgb8()).unwrap();
                report.push(format!("{rel}: {:.4}% identical, max error {} (FAIL)", 100.0 * s.identical_fraction, s.max_error));
                failures.push(rel);
            }
        }
    }
    println!("{}", report.join("\n"));
    assert!(failures.is_empty(), "below 99.9% identical: {failures:?}\n{}", report.join("\n"));
}

#[allow(dead_code)]
fn data_dir() -> std::path::PathBuf {
    workspace_root().join("crates/prism-raster/tests/data")
}

#[allow(dead_code)]
fn _unused(_: &Path) {}
