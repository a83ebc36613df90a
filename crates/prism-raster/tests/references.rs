//! Golden-image tests against the course's own reference renders
//! (`shared/assets/rasterizer/tests/outputs/reference/`, made by the CS184 staff renderer at
//! 1024x1024, sample rate 1, nearest pixel sampling, level 0), and against resvg renders of
//! the project's own standard-SVG suite (`tests/data/*.svg`, references made by resvg 0.49).

use prism_raster::{read_svg, render, Dialect, RenderOptions};
use prism_testkit::{compare_golden, shared_assets, workspace_root};

/// The course's reference file name: every character outside `abdefghijklmnopqrstuvwxyz0-9`
/// becomes `-` (the letter c included).
fn reference_name(rel: &str) -> String {
    rel.chars()
        .map(|c| {
            if "abdefghijklmnopqrstuvwxyz0123456789".contains(c) {
                c
            } else {
                '-'
            }
        })
        .collect::<String>()
        + ".png"
}

fn staged_svgs() -> Vec<String> {
    let root = shared_assets().join("rasterizer");
    let mut out = Vec::new();
    for dir in [
        "basic",
        "hardcore",
        "illustration",
        "subdiv",
        "texmap",
        "transforms",
    ] {
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
        let reference = root
            .join("tests/outputs/reference")
            .join(reference_name(&rel));
        assert!(
            reference.exists(),
            "missing reference {}",
            reference.display()
        );
        let doc = read_svg(&root.join(&rel), Dialect::Cs184).unwrap_or_else(|e| panic!("{e}"));
        let opts = RenderOptions {
            compat: true,
            ..RenderOptions::default()
        };
        let (img, _) = render(&doc, &opts).expect("render");
        let name = rel.replace('/', "_");
        let result = std::panic::catch_unwind(|| {
            compare_golden(&name, &reference, &img.to_rgb8(), false, |s| {
                s.identical_fraction >= 0.999
            })
        });
        match result {
            Ok(s) => report.push(format!(
                "{rel}: {:.4}% identical, max error {}",
                100.0 * s.identical_fraction,
                s.max_error
            )),
            Err(_) => {
                let s = prism_image::compare_rgb8(
                    &prism_image::read_png(&reference).unwrap().to_rgb8(),
                    &img.to_rgb8(),
                )
                .unwrap();
                report.push(format!(
                    "{rel}: {:.4}% identical, max error {} (FAIL)",
                    100.0 * s.identical_fraction,
                    s.max_error
                ));
                failures.push(rel);
            }
        }
    }
    println!("{}", report.join("\n"));
    assert!(
        failures.is_empty(),
        "below 99.9% identical: {failures:?}\n{}",
        report.join("\n")
    );
}

fn data_dir() -> std::path::PathBuf {
    workspace_root().join("crates/prism-raster/tests/data")
}

/// The standard-SVG suite at 16 samples agrees with resvg 0.49's renders (the oracle, made by
/// `resvg FILE.svg resvg/FILE.png`): mean absolute channel error at most 1/255 and at most
/// 0.5% of pixels off by more than 24/255, both composited over white.
#[test]
fn standard_svgs_agree_with_resvg() {
    let mut names: Vec<String> = std::fs::read_dir(data_dir())
        .expect("tests/data")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".svg"))
        .collect();
    names.sort();
    assert!(names.len() >= 8, "suite is missing files");
    let mut report = Vec::new();
    for n in &names {
        let stem = n.trim_end_matches(".svg");
        let doc = read_svg(&data_dir().join(n), Dialect::Svg).unwrap_or_else(|e| panic!("{e}"));
        let reference = data_dir().join("resvg").join(format!("{stem}.png"));
        let expected = prism_image::read_png(&reference).expect("resvg reference");
        let opts = RenderOptions {
            width: expected.width(),
            height: expected.height(),
            samples: 16,
            ..RenderOptions::default()
        };
        let (img, _) = render(&doc, &opts).expect("render");
        let actual = img.over_background([255, 255, 255]);
        let expected_rgb = expected.over_background([255, 255, 255]);
        let tmp =
            std::env::temp_dir().join(format!("prism-resvg-{stem}-{}.png", std::process::id()));
        prism_image::write_png(&tmp, &expected_rgb).expect("write");
        let s = compare_golden(&format!("resvg_{stem}"), &tmp, &actual, false, |s| {
            s.mean_abs_error <= 1.0 && s.over_24_fraction <= 0.005
        });
        let _ = std::fs::remove_file(&tmp);
        report.push(format!(
            "{n}: mean abs {:.3}/255, {:.3}% pixels off by >24, max {}",
            s.mean_abs_error,
            100.0 * s.over_24_fraction,
            s.max_error
        ));
    }
    println!("{}", report.join("\n"));
}
