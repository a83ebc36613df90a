//! Golden-image tests, one test per input file: the course's own reference renders
//! (`shared/assets/rasterizer/tests/outputs/reference/`, made by the CS184 staff renderer at
//! 1024x1024, sample rate 1, nearest pixel sampling, level 0), and resvg renders of the
//! project's own standard-SVG suite (`tests/golden/resvg/NAME.svg`, references `NAME.png` made by resvg 0.49).
//! Images are compared in memory; a failure leaves an `expected | diff | actual` triptych
//! under `target/test-diffs/`. Two more tests check that the lists below name every file.

use prism_image::Rgb8Image;
use prism_raster::{read_svg, render, Dialect, RasterOptions};
use prism_testkit::{compare_images, shared_asset, workspace_root};

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

/// The staged course file `rel` (under `rasterizer/`), rendered with `--compat cs184` at
/// default settings, matches the course renderer's image in at least 99.9% of its pixels.
fn course_golden(rel: &str) {
    let svg = shared_asset(&format!("rasterizer/{rel}"));
    let reference = shared_asset(&format!(
        "rasterizer/tests/outputs/reference/{}",
        reference_name(rel)
    ));
    let doc = read_svg(&svg, Dialect::Cs184).unwrap_or_else(|e| panic!("{e}"));
    let opts = RasterOptions {
        compat: true,
        ..RasterOptions::default()
    };
    let (img, _) = render(&doc, &opts).expect("render");
    let expected = prism_image::read_png(&reference)
        .unwrap_or_else(|e| panic!("{e}"))
        .to_rgb8();
    let s = compare_images(&rel.replace('/', "_"), &expected, &img.to_rgb8(), |s| {
        s.identical_fraction >= 0.999
    });
    println!(
        "{rel}: {:.4}% identical, max error {}",
        100.0 * s.identical_fraction,
        s.max_error
    );
}

macro_rules! course_goldens {
    ($($name:ident => $rel:literal,)*) => {
        $(
            #[test]
            fn $name() {
                course_golden($rel);
            }
        )*
        /// Every staged course SVG, as listed above.
        const COURSE_FILES: &[&str] = &[$($rel),*];
    };
}

course_goldens! {
    basic_test1 => "svg/basic/test1.svg",
    basic_test2 => "svg/basic/test2.svg",
    basic_test3 => "svg/basic/test3.svg",
    basic_test4 => "svg/basic/test4.svg",
    basic_test5 => "svg/basic/test5.svg",
    basic_test6 => "svg/basic/test6.svg",
    basic_test7 => "svg/basic/test7.svg",
    basic_test8 => "svg/basic/test8.svg",
    hardcore_01_degenerate_square1 => "svg/hardcore/01_degenerate_square1.svg",
    illustration_01_sketchpad => "svg/illustration/01_sketchpad.svg",
    illustration_02_hexes => "svg/illustration/02_hexes.svg",
    illustration_03_circle => "svg/illustration/03_circle.svg",
    illustration_04_sun => "svg/illustration/04_sun.svg",
    illustration_05_lion => "svg/illustration/05_lion.svg",
    illustration_07_lines => "svg/illustration/07_lines.svg",
    illustration_08_monkeytree => "svg/illustration/08_monkeytree.svg",
    illustration_09_kochcurve => "svg/illustration/09_kochcurve.svg",
    subdiv_triangle1 => "svg/subdiv/triangle1.svg",
    subdiv_triangle2 => "svg/subdiv/triangle2.svg",
    subdiv_triangle3 => "svg/subdiv/triangle3.svg",
    subdiv_triangle4 => "svg/subdiv/triangle4.svg",
    subdiv_triangle5 => "svg/subdiv/triangle5.svg",
    subdiv_triangle6 => "svg/subdiv/triangle6.svg",
    subdiv_triangle7 => "svg/subdiv/triangle7.svg",
    texmap_test1 => "svg/texmap/test1.svg",
    texmap_test2 => "svg/texmap/test2.svg",
    texmap_test5 => "svg/texmap/test5.svg",
    texmap_test6 => "svg/texmap/test6.svg",
    transforms_robot => "svg/transforms/robot.svg",
}

fn data_dir() -> std::path::PathBuf {
    workspace_root().join("crates/prism-raster/tests/golden/resvg")
}

/// The standard SVG `tests/golden/resvg/{stem}.svg` at 16 samples agrees with resvg 0.49's render
/// (the oracle, made by `resvg FILE.svg FILE.png`): mean absolute channel error at most
/// 1/255 and at most 0.5% of pixels off by more than 24/255, both composited over white.
fn resvg_golden(stem: &str) {
    let doc = read_svg(&data_dir().join(format!("{stem}.svg")), Dialect::Svg)
        .unwrap_or_else(|e| panic!("{e}"));
    let reference = data_dir().join(format!("{stem}.png"));
    let expected = prism_image::read_png(&reference).unwrap_or_else(|e| panic!("{e}"));
    let opts = RasterOptions {
        width: expected.width(),
        height: expected.height(),
        samples: 16,
        ..RasterOptions::default()
    };
    let (img, _) = render(&doc, &opts).expect("render");
    let actual: Rgb8Image = img.over_background([255, 255, 255]);
    let expected: Rgb8Image = expected.over_background([255, 255, 255]);
    let s = compare_images(&format!("resvg_{stem}"), &expected, &actual, |s| {
        s.mean_abs_error <= 1.0 && s.over_24_fraction <= 0.005
    });
    println!(
        "{stem}.svg: mean abs {:.3}/255, {:.3}% pixels off by >24, max {}",
        s.mean_abs_error,
        100.0 * s.over_24_fraction,
        s.max_error
    );
}

macro_rules! resvg_goldens {
    ($($name:ident => $stem:literal,)*) => {
        mod resvg {
            $(
                #[test]
                fn $name() {
                    super::resvg_golden($stem);
                }
            )*
        }
        /// Every standard SVG of the suite, as listed above.
        const RESVG_FILES: &[&str] = &[$($stem),*];
    };
}

resvg_goldens! {
    arcs => "arcs",
    curves => "curves",
    dashes => "dashes",
    evenodd => "evenodd",
    gradients => "gradients",
    images => "images",
    joins => "joins",
    opacity => "opacity",
    thin => "thin",
    transforms => "transforms",
}

/// The SVG files in `dir`, as sorted names.
fn svgs_in(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".svg"))
        .collect();
    names.sort();
    names
}

/// The course list names every staged SVG, so that a new file cannot go untested.
#[test]
fn course_list_names_every_staged_file() {
    let mut staged = Vec::new();
    for dir in [
        "basic",
        "hardcore",
        "illustration",
        "subdiv",
        "texmap",
        "transforms",
    ] {
        let folder = shared_asset(&format!("rasterizer/svg/{dir}"));
        staged.extend(
            svgs_in(&folder)
                .into_iter()
                .map(|f| format!("svg/{dir}/{f}")),
        );
    }
    assert_eq!(staged, COURSE_FILES);
}

/// The resvg list names every SVG of the suite.
#[test]
fn resvg_list_names_every_suite_file() {
    let stems: Vec<String> = svgs_in(&data_dir())
        .into_iter()
        .map(|n| n.trim_end_matches(".svg").to_string())
        .collect();
    assert_eq!(stems, RESVG_FILES);
}
