//! End-to-end tests of the `prism` command: bad input gives a located error and exit code 2,
//! never a panic and never a partial output file; good input renders.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod bounded;
mod readme;
mod split;

fn prism() -> Command {
    Command::new(env!("CARGO_BIN_EXE_prism"))
}

fn scratch(name: &str) -> prism_testkit::Scratch {
    prism_testkit::scratch("prism-cli", name)
}

fn run_svg(dir: &Path, svg: &str, extra: &[&str]) -> (Output, PathBuf) {
    let input = dir.join("in.svg");
    std::fs::write(&input, svg).unwrap();
    let out = dir.join("out.png");
    let o = prism()
        .arg("svg")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(extra)
        .output()
        .unwrap();
    (o, out)
}

/// Exit codes of `prism mesh OP MESH -o OUT --edge E` for edges 0..40.
fn edge_op_codes(op: &str, mesh: &Path, out: &Path) -> Vec<Option<i32>> {
    (0..40)
        .map(|e| {
            prism()
                .args(["mesh", op])
                .arg(mesh)
                .arg("-o")
                .arg(out)
                .args(["--edge", &e.to_string()])
                .output()
                .unwrap()
                .status
                .code()
        })
        .collect()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Each bad input: exit 2, a `file:line: element:` message, and no output file. Bad
/// attribute values are errors in the course dialect (standard SVG reads past them, see
/// `standard_svg_is_lenient_as_browsers_are`).
#[test]
fn bad_inputs_are_located_errors() {
    let dir = scratch("bad");
    let deep = format!(
        "<svg xmlns='http://www.w3.org/2000/svg' width='10' height='10'>{}{}</svg>",
        "<g>".repeat(5000),
        "</g>".repeat(5000)
    );
    let course = &["--compat", "cs184"][..];
    let cases: Vec<(&str, String, &str, &[&str])> = vec![
        ("malformed xml", "<svg width='10' height='10'><rect></svg>".into(), ":1: xml: malformed XML", &[]),
        ("bad number", "<svg width='10' height='10'>\n<rect x='1' y='zz' width='3' height='3'/></svg>".into(), ":2: rect: y: expected a number", course),
        ("nan coordinate", "<svg width='10' height='10'>\n\n<polygon points='0,0 NaN,1 2,2'/></svg>".into(), ":3: polygon: points: expected a number", course),
        ("inf coordinate", "<svg width='10' height='10'><line x1='1e999' y1='0' x2='1' y2='1' stroke='red'/></svg>".into(), "line: x1", course),
        ("missing texture", "<svg width='10' height='10'><texture texid='t' filename='nope.png'/></svg>".into(), "texture: texture \"nope.png\"", course),
        ("not svg", "<html/>".into(), "html: expected the root element to be <svg>", &[]),
        ("too deep", deep, "elements nest deeper than the limit of 256", &[]),
    ];
    for (what, svg, expect, extra) in cases {
        let (o, out) = run_svg(&dir, &svg, extra);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        assert!(
            err.contains(expect),
            "{what}: expected {expect:?} in {err:?}"
        );
        assert!(err.contains("in.svg:"), "{what}: no file name in {err:?}");
        assert!(!out.exists(), "{what}: output written");
    }
    // A corrupt texture file.
    std::fs::write(dir.join("bad.png"), b"\x89PNG\r\n\x1a\nthis is not a png").unwrap();
    let (o, out) = run_svg(
        &dir,
        "<svg width='10' height='10'><texture texid='t' filename='bad.png'/></svg>",
        course,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("bad.png"));
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_options_exit_2_and_keep_old_output() {
    let dir = scratch("opts");
    let svg = "<svg xmlns='http://www.w3.org/2000/svg' width='10' height='10'><rect width='5' height='5'/></svg>";
    std::fs::write(dir.join("out.png"), b"precious").unwrap();
    for extra in [
        &["--samples", "8"][..],
        &["--width", "100000"],
        &["--view", "1,2"],
        &["--view", "0,0,-1"],
    ] {
        let (o, out) = run_svg(&dir, svg, extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert_eq!(std::fs::read(&out).unwrap(), b"precious", "{extra:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Unknown elements are skipped and the rest drawn, as browsers and resvg do; `--stats`
/// prints a line per stage.
#[test]
fn unknown_elements_are_skipped_and_stats_print() {
    let dir = scratch("warn");
    let svg = "<svg xmlns='http://www.w3.org/2000/svg' width='10' height='10'><blink/><blink/><rect width='10' height='10' fill='#00f'/></svg>";
    let (o, out) = run_svg(&dir, svg, &["--width", "10", "--height", "10", "--stats"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    for stage in ["parse: ", "raster: ", "resolve: ", "encode: "] {
        assert!(
            err.lines()
                .any(|l| l.starts_with(stage) && l.ends_with(" ms")),
            "{stage} in {err}"
        );
    }
    let img = prism_image::read_png(&out).unwrap();
    assert_eq!(img.get(5, 5), [0, 0, 255, 255]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A directory in gives a directory out with the same tree, written into a folder that
/// exists (a missing one, or a file name, is refused and not created); output is identical
/// whatever the thread count.
#[test]
fn batch_directory_and_determinism() {
    let dir = scratch("batch");
    let input = dir.join("in");
    std::fs::create_dir_all(input.join("sub")).unwrap();
    let svg = "<svg xmlns='http://www.w3.org/2000/svg' width='64' height='64'><circle cx='32' cy='32' r='20' fill='red' opacity='0.5'/></svg>";
    std::fs::write(input.join("a.svg"), svg).unwrap();
    std::fs::write(input.join("sub/b.svg"), svg).unwrap();
    let out = dir.join("out");
    for missing in [dir.join("single.png"), out.clone(), dir.join("nodir/")] {
        let o = prism()
            .arg("svg")
            .arg(&input)
            .arg("-o")
            .arg(&missing)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(": no such folder"), "{}", stderr(&o));
        assert!(!missing.exists(), "{} was created", missing.display());
    }
    std::fs::create_dir(&out).unwrap();
    let o = prism()
        .args(["svg"])
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(["--samples", "16"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let a = std::fs::read(out.join("a.png")).unwrap();
    let b = std::fs::read(out.join("sub/b.png")).unwrap();
    assert_eq!(a, b);
    let one = dir.join("one.png");
    let o = prism()
        .env("RAYON_NUM_THREADS", "1")
        .args(["svg"])
        .arg(input.join("a.svg"))
        .arg("-o")
        .arg(&one)
        .args(["--samples", "16"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(
        std::fs::read(&one).unwrap(),
        a,
        "thread count changed the bytes"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn demo_writes_gallery() {
    let dir = scratch("demo");
    let o = prism()
        .args(["demo", "-q", "-o"])
        .arg(&dir)
        .arg("--assets")
        .arg(prism_testkit::shared_assets())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let mut written: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png"))
        .collect();
    written.sort();
    for f in &written {
        assert!(html.contains(f.as_str()), "{f} not in index");
        assert!(prism_image::read_png(&dir.join(f)).is_ok(), "{f}");
    }
    // Each feature at its best: the page shows pictures at their own size; the mip-level
    // modes differ visibly (level 0 aliases in the distance, trilinear blurs); the heat map
    // of the course's adaptive settings has many levels, not two colours.
    assert!(!html.contains("pixelated"));
    let png = |f: &str| prism_image::read_png(&dir.join(f)).unwrap().to_rgb8();
    let (zero, linear) = (
        png("texture_level_zero.png"),
        png("texture_level_linear.png"),
    );
    let differ = prism_image::compare_rgb8(&zero, &linear).unwrap();
    assert!(differ.identical_fraction < 0.9, "{differ:?}");
    let heat = png("render_heatmap.png");
    let colours: std::collections::BTreeSet<[u8; 3]> = heat.pixels().iter().copied().collect();
    assert!(
        colours.len() > 16,
        "{} colours in the heat map",
        colours.len()
    );
    // The committed sky map is the one the demo generates.
    let committed =
        prism_image::read_exr(&prism_testkit::workspace_root().join("docs/envmap/sky.exr"))
            .unwrap();
    let fresh = prism_image::read_exr(&dir.join("sky.exr")).unwrap();
    assert_eq!(
        (committed.width(), committed.height()),
        (fresh.width(), fresh.height())
    );
    for (a, b) in committed.pixels().iter().zip(fresh.pixels()) {
        assert!(
            (a.r - b.r).abs() <= 1e-5 * a.r.abs().max(1.0),
            "{a:?} vs {b:?}"
        );
    }
    // The README's gallery is exactly what the demo writes, and the committed pictures are
    // the demo's (allowing for the last-bit differences another processor or libm can make
    // in a Monte Carlo render).
    let root = prism_testkit::workspace_root();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let gallery = &readme[readme.find("## Gallery").expect("a gallery section")..];
    let mut shown: Vec<String> = gallery
        .split("docs/gallery/")
        .skip(1)
        .filter_map(|rest| rest.split(')').next())
        .filter(|n| n.ends_with(".png"))
        .map(str::to_string)
        .collect();
    shown.sort();
    shown.dedup();
    assert_eq!(shown, written, "README gallery and demo output differ");
    let mut committed: Vec<String> = std::fs::read_dir(root.join("docs/gallery"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    committed.sort();
    assert_eq!(committed, written, "docs/gallery and demo output differ");
    for f in &written {
        let committed = prism_image::read_png(&root.join("docs/gallery").join(f))
            .unwrap()
            .to_rgb8();
        let fresh = prism_image::read_png(&dir.join(f)).unwrap().to_rgb8();
        let name = format!("gallery_{}", f.trim_end_matches(".png"));
        prism_testkit::compare_images(&name, &committed, &fresh, |s| {
            s.identical_fraction >= 0.98 && s.mean_abs_error <= 1.0
        });
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `prism mesh subdivide` multiplies faces by 4 per level and `info` reports the counts;
/// a non-manifold input is a located error with exit code 2 and no output.
#[test]
fn mesh_subdivide_and_errors() {
    let dir = scratch("mesh");
    let tet = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
    std::fs::write(dir.join("tet.obj"), tet).unwrap();
    let out = dir.join("sub.obj");
    let o = prism()
        .args(["mesh", "subdivide"])
        .arg(dir.join("tet.obj"))
        .arg("-o")
        .arg(&out)
        .args(["-n", "2", "--weights", "loop", "--stats"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o)
        .lines()
        .any(|l| l.starts_with("subdivide: ") && l.ends_with(" ms")));
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(
        text.lines().filter(|l| l.starts_with("f ")).count(),
        4 * 4 * 4
    );
    // Through PLY and back: the same mesh.
    let ply = dir.join("sub.ply");
    let o = prism()
        .args(["mesh", "convert"])
        .arg(&out)
        .arg("-o")
        .arg(&ply)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let back = dir.join("back.obj");
    let o = prism()
        .args(["mesh", "convert"])
        .arg(&ply)
        .arg("-o")
        .arg(&back)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&back).unwrap(), text);
    let o = prism().args(["mesh", "info"]).arg(&out).output().unwrap();
    let info = String::from_utf8_lossy(&o.stdout);
    assert!(
        info.contains("faces: 64") && info.contains("euler characteristic: 2"),
        "{info}"
    );
    // Three faces on one edge.
    let bad = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
    std::fs::write(dir.join("bad.obj"), bad).unwrap();
    let out2 = dir.join("bad_out.obj");
    // Repaired on load by default (the third face gets its own vertices), with a warning.
    let o = prism()
        .args(["mesh", "subdivide"])
        .arg(dir.join("bad.obj"))
        .arg("-o")
        .arg(&out2)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("warning: ") && stderr(&o).contains("face 2 uses an edge"));
    std::fs::remove_file(&out2).unwrap();
    // Refused with --strict.
    let o = prism()
        .args(["mesh", "subdivide", "--strict"])
        .arg(dir.join("bad.obj"))
        .arg("-o")
        .arg(&out2)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    // Face and vertex numbers in topology errors count from 0.
    assert!(
        stderr(&o).contains("bad.obj: face 2: edge 0-1"),
        "{}",
        stderr(&o)
    );
    assert!(!out2.exists());
    // Flip: an interior edge of the tetrahedron's subdivision flips; a tetrahedron edge
    // cannot (its opposite vertices are already joined).
    let flipped = dir.join("flip.obj");
    let codes = edge_op_codes("flip", &out, &flipped);
    assert!(
        codes.contains(&Some(0)) && codes.contains(&Some(2)),
        "{codes:?}"
    );
    for op in ["split", "collapse"] {
        let codes = edge_op_codes(op, &out, &flipped);
        assert!(codes.contains(&Some(0)), "{op}: {codes:?}");
    }
    let o = prism()
        .args(["mesh", "flip"])
        .arg(dir.join("tet.obj"))
        .arg("-o")
        .arg(&flipped)
        .args(["--vertices", "1,2"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("cannot flip: edge 2: vertices"),
        "{}",
        stderr(&o)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `prism bezier` draws a curve file to PNG and tessellates a patch file to a mesh; a
/// malformed file is a located error.
#[test]
fn bezier_curve_and_patches() {
    let dir = scratch("bezier");
    std::fs::write(dir.join("c.bzc"), "4\n0.2 0.35 0.3 0.6 0.8 0.75 0.9 0.45\n").unwrap();
    let png = dir.join("c.png");
    let o = prism()
        .args(["bezier"])
        .arg(dir.join("c.bzc"))
        .arg("-o")
        .arg(&png)
        .args(["--parameter", "0.3", "--size", "200"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let img = prism_image::read_png(&png).unwrap();
    assert_eq!((img.width(), img.height()), (200, 200));
    assert!(img.pixels().iter().any(|p| p[0] < 100), "nothing drawn");
    // One flat patch: 4 x 4 cells, 32 triangles, 25 welded vertices.
    let mut bez = String::from("1\n");
    for i in 0..4 {
        for j in 0..4 {
            bez += &format!("{i} {j} 0\n");
        }
    }
    std::fs::write(dir.join("p.bez"), bez).unwrap();
    let obj = dir.join("p.obj");
    let o = prism()
        .args(["bezier"])
        .arg(dir.join("p.bez"))
        .arg("-o")
        .arg(&obj)
        .args(["--resolution", "4"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&obj).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 32);
    assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), 25);
    std::fs::write(dir.join("bad.bzc"), "3\n0 0\n1 x\n").unwrap();
    let o = prism()
        .args(["bezier"])
        .arg(dir.join("bad.bzc"))
        .arg("-o")
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("bad.bzc:3: expected a finite number"),
        "{}",
        stderr(&o)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `prism mesh` reads the staged COLLADA files and writes COLLADA that reads back as the same
/// mesh; a broken file is a located error with exit code 2.
#[test]
fn mesh_collada_in_and_out() {
    let dir = scratch("dae");
    let cow = prism_testkit::shared_assets().join("meshedit/dae/cow.dae");
    let o = prism().args(["mesh", "info"]).arg(&cow).output().unwrap();
    let info = String::from_utf8_lossy(&o.stdout);
    assert!(
        info.contains("faces: 5856") && info.contains("euler characteristic: 2"),
        "{info}"
    );
    let dae = dir.join("cow1.dae");
    let o = prism()
        .args(["mesh", "subdivide"])
        .arg(&cow)
        .arg("-o")
        .arg(&dae)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (obj_a, obj_b) = (dir.join("a.obj"), dir.join("b.obj"));
    for (input, output) in [(&dae, &obj_a), (&obj_a, &obj_b)] {
        let o = prism()
            .args(["mesh", "convert"])
            .arg(input)
            .arg("-o")
            .arg(output)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let a = std::fs::read_to_string(&obj_a).unwrap();
    assert_eq!(a.lines().filter(|l| l.starts_with("f ")).count(), 4 * 5856);
    assert_eq!(a, std::fs::read_to_string(&obj_b).unwrap());

    // Nine levels would make 1.5 billion faces: refused up front, nothing written.
    let o = prism()
        .args(["mesh", "subdivide", "-n", "9"])
        .arg(&cow)
        .arg("-o")
        .arg(&obj_a)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("9 levels of 5856 faces: making 1535115264 faces needs 134 GiB of memory, over the budget of 2 GiB"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read_to_string(&obj_a).unwrap(), a);

    let text = std::fs::read_to_string(&cow).unwrap();
    let broken = dir.join("broken.dae");
    std::fs::write(&broken, text.replacen("<vcount>3 ", "<vcount>2 ", 1)).unwrap();
    let o = prism()
        .args(["mesh", "convert"])
        .arg(&broken)
        .arg("-o")
        .arg(&obj_a)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("broken.dae:"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&obj_a).unwrap(), a);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `prism render` renders the built-in Cornell box and a staged scene; every kind of broken
/// scene is a located error with exit code 2 that leaves the previous output untouched.
#[test]
fn render_scenes_and_errors() {
    let dir = scratch("render");
    let out = dir.join("cb.png");
    let exr = dir.join("cb.exr");
    let heat = dir.join("heat.png");
    let o = prism()
        .args([
            "render",
            "-q",
            "-s",
            "4",
            "-r",
            "64",
            "48",
            "--adaptive",
            "0.5",
            "--batch",
            "2",
            "--stats",
            "-t",
            "1",
            "-o",
        ])
        .arg(&out)
        .arg("--exr")
        .arg(&exr)
        .arg("--heatmap")
        .arg(&heat)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let img = prism_image::read_png(&out).unwrap();
    assert_eq!((img.width(), img.height()), (64, 48));
    assert!(prism_image::read_png(&heat).is_ok());
    assert!(std::fs::metadata(&exr).unwrap().len() > 64 * 48 * 12);
    let err = stderr(&o);
    for stage in [
        "bvh: ",
        "read: ",
        "build: ",
        "render: ",
        "write: ",
        "samples/s: ",
        "stages: ",
    ] {
        assert!(
            err.lines().any(|l| l.starts_with(stage)),
            "{stage} missing: {err}"
        );
    }
    // Property: the path integrator's stages share the whole of its time.
    let stages = err
        .lines()
        .find_map(|l| l.strip_prefix("stages: "))
        .unwrap();
    let shares: Vec<f64> = stages
        .split(", ")
        .map(|s| {
            s.rsplit(' ')
                .next()
                .unwrap()
                .trim_end_matches('%')
                .parse()
                .unwrap()
        })
        .collect();
    assert_eq!(shares.len(), 8, "{stages}");
    assert!((shares.iter().sum::<f64>() - 100.0).abs() < 0.5, "{stages}");
    assert!(stages.starts_with("camera rays ") && stages.contains(", shadow rays "));
    // Property: on one thread, the stages' times add up to no more than the render's time.
    let ms = |prefix: &str| -> Vec<f64> {
        let body = err.lines().find_map(|l| l.strip_prefix(prefix)).unwrap();
        body.split(", ")
            .map(|s| {
                let v = s.trim_end_matches(" ms");
                v.rsplit(' ').next().unwrap().parse().unwrap()
            })
            .collect()
    };
    let times = ms("stage times: ");
    let render = ms("render: ")[0];
    assert_eq!(times.len(), 8, "{err}");
    let sum: f64 = times.iter().sum();
    assert!(
        sum > 0.0 && sum <= render + 0.5,
        "stages {sum} ms, render {render} ms: {err}"
    );
    let bunny = prism_testkit::shared_assets().join("pathtracer/dae/sky/CBbunny.dae");
    let o = prism()
        .args([
            "render",
            "-q",
            "-s",
            "1",
            "-r",
            "32",
            "24",
            "--integrator",
            "normals",
            "-o",
        ])
        .arg(dir.join("bunny.png"))
        .arg(&bunny)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let good = std::fs::read_to_string(
        prism_testkit::shared_assets().join("pathtracer/dae/sky/CBspheres_lambertian.dae"),
    )
    .unwrap();
    let before = std::fs::read(&out).unwrap();
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "broken XML",
            good.replacen("</library_lights>", "", 1),
            "bad.dae: ",
        ),
        (
            "dangling material",
            good.replacen("target=\"#lambertian\"", "target=\"#nothing\"", 1),
            "no <material> with id \"nothing\"",
        ),
        (
            "dangling geometry",
            good.replacen("url=\"#Sphere1-data\"", "url=\"#Sphere9-data\"", 1),
            "no <geometry> with id \"Sphere9-data\"",
        ),
        (
            "zero-area light",
            good.replacen(
                "<matrix sid=\"transform\">0.6 0 0 0 0 0.8 0 0 0 0 1 1.49 0 0 0 1</matrix>",
                "<matrix sid=\"transform\">0 0 0 0 0 0.8 0 0 0 0 1 1.49 0 0 0 1</matrix>",
                1,
            ),
            "zero area",
        ),
        (
            "NaN matrix",
            good.replacen(
                "0.6 0 0 0 0 0.8 0 0 0 0 1 1.49 0 0 0 1",
                "0.6 0 0 0 0 NaN 0 0 0 0 1 1.49 0 0 0 1",
                1,
            ),
            "expected a finite value",
        ),
        (
            "camera without fov",
            good.replacen("<xfov sid=\"xfov\">49.13434</xfov>", "", 1),
            "expected an <xfov> or a <yfov>",
        ),
    ];
    for (what, text, want) in cases {
        assert_ne!(text, good, "{what}: the edit did not apply");
        let bad = dir.join("bad.dae");
        std::fs::write(&bad, text).unwrap();
        let o = prism()
            .args(["render", "-q", "-s", "1", "-r", "16", "12", "-o"])
            .arg(&out)
            .arg(&bad)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{what}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{what}: {}", stderr(&o));
        assert_eq!(
            std::fs::read(&out).unwrap(),
            before,
            "{what}: output changed"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The hostile inputs of the hardening work, through the command a user runs: 100,000 levels
/// of nesting (SVG in both dialects, COLLADA for `render` and `mesh info`), `use` and
/// `instance_node` fan-out to 2^29 copies, and reference cycles. Each ends in exit 2 with a
/// located message, and leaves no output file.
#[test]
fn hostile_inputs_are_located_errors() {
    let dir = scratch("hostile");
    let levels = 100_000;
    let svg_ns = "xmlns='http://www.w3.org/2000/svg' xmlns:xlink='http://www.w3.org/1999/xlink'";
    let deep_svg = format!(
        "<svg {svg_ns} width='8' height='8'>\n{}<rect width='4' height='4'/>{}</svg>",
        "<g>".repeat(levels),
        "</g>".repeat(levels)
    );
    let mut fan_svg = format!(
        "<svg {svg_ns} width='8' height='8'><defs><g id='g0'><rect width='1' height='1'/></g>\n"
    );
    for i in 1..30 {
        fan_svg += &format!(
            "<g id='g{i}'><use xlink:href='#g{p}'/><use xlink:href='#g{p}'/></g>\n",
            p = i - 1
        );
    }
    fan_svg += "</defs><use xlink:href='#g29'/></svg>";
    let cycle_svg = format!(
        "<svg {svg_ns} width='8' height='8'>\n<g id='a'><use href='#b'/></g>\n<g id='b'><use href='#a'/></g></svg>"
    );
    let dae = |scene: &str, library: &str| {
        format!(
            "<?xml version='1.0'?>\n<COLLADA xmlns='http://www.collada.org/2005/11/COLLADASchema' \
             version='1.4.1'>{library}\n<library_visual_scenes><visual_scene id='s'>\n{scene}\
             </visual_scene></library_visual_scenes><scene><instance_visual_scene url='#s'/>\
             </scene></COLLADA>"
        )
    };
    let deep_dae = dae(
        &format!("{}{}", "<node>".repeat(levels), "</node>".repeat(levels)),
        "",
    );
    let mut library = String::from("<library_nodes><node id='n0'/>");
    for i in 1..30 {
        library += &format!(
            "<node id='n{i}'><instance_node url='#n{p}'/><instance_node url='#n{p}'/></node>",
            p = i - 1
        );
    }
    library += "<node id='c'><instance_node url='#c'/></node></library_nodes>";
    let fan_dae = dae("<node><instance_node url='#n29'/></node>", &library);
    let cycle_dae = dae("<node><instance_node url='#c'/></node>", &library);
    let svg_cases = [
        (
            &deep_svg,
            &[][..],
            "in.svg:2: g: elements nest deeper than the limit of 256",
        ),
        (
            &deep_svg,
            &["--compat", "cs184"][..],
            "in.svg:2: g: elements nest deeper",
        ),
        (
            &fan_svg,
            &[][..],
            "in.svg:19: g: use references would expand to more than 1000000 elements",
        ),
        (
            &cycle_svg,
            &[][..],
            "in.svg: SVG data parsing failed cause nodes limit reached",
        ),
    ];
    for (text, extra, want) in svg_cases {
        let (o, out) = run_svg(&dir, text, extra);
        assert_eq!(o.status.code(), Some(2), "{want}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(want),
            "expected {want:?} in {}",
            stderr(&o)
        );
        assert!(!out.exists(), "{want}: output written");
    }
    let dae_cases = [
        (
            "deep.dae",
            &deep_dae,
            "deep.dae:4: <node>: nodes nest deeper than 64",
        ),
        (
            "fan.dae",
            &fan_dae,
            ": <node>: the node expands to more than 1000000 nodes",
        ),
        (
            "cycle.dae",
            &cycle_dae,
            "the node instances a node that contains it",
        ),
    ];
    for (name, text, want) in dae_cases {
        let input = dir.join(name);
        std::fs::write(&input, text).unwrap();
        let out = dir.join("out.png");
        for command in [
            &["render", "-q", "-s", "1", "-r", "8", "6", "-o"][..],
            &["mesh", "info"][..],
        ] {
            let mut c = prism();
            c.args(command);
            if command[0] == "render" {
                c.arg(&out);
            }
            let o = c.arg(&input).output().unwrap();
            assert_eq!(
                o.status.code(),
                Some(2),
                "{name} {command:?}: {}",
                stderr(&o)
            );
            assert!(
                stderr(&o).contains(want),
                "{name}: expected {want:?} in {}",
                stderr(&o)
            );
            assert!(!out.exists(), "{name}: output written");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A course Cornell box whose camera `<matrix>` lacks its final number renders, with a
/// warning naming file, line and element, to the same bytes as the intact file (the oracle);
/// under `--camera file`, which uses that matrix, it is an error that writes nothing.
#[test]
fn course_file_with_a_short_camera_matrix_renders_as_the_intact_one() {
    let dir = scratch("short-matrix");
    let intact = prism_testkit::shared_asset("pathtracer/dae/sky/CBspheres_lambertian.dae");
    let text = std::fs::read_to_string(&intact).unwrap();
    let full = "<matrix sid=\"transform\">-1 0 0 0 0 0 1 3 0 1 0 0 0 0 0 1</matrix>";
    assert!(text.contains(full), "the staged camera matrix changed");
    let short = dir.join("short.dae");
    std::fs::write(
        &short,
        text.replacen(full, &full.replace(" 0 1</", " 0</"), 1),
    )
    .unwrap();
    let line = 1 + text[..text.find(full).unwrap()].matches('\n').count();
    let render = |scene: &Path, out: &Path, extra: &[&str]| {
        prism()
            .args(["render", "-q", "-s", "2", "-r", "32", "24", "-o"])
            .arg(out)
            .arg(scene)
            .args(extra)
            .output()
            .unwrap()
    };
    let (a, b) = (dir.join("intact.png"), dir.join("short.png"));
    assert_eq!(render(&intact, &a, &[]).status.code(), Some(0));
    let o = render(&short, &b, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let want = format!("short.dae:{line}: <matrix>: expected 16 numbers, found 15");
    assert!(
        stderr(&o).contains(&want),
        "expected {want:?} in {}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let c = dir.join("file-camera.png");
    let o = render(&short, &c, &["--camera", "file"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&want.replace(", found 15", "")),
        "{}",
        stderr(&o)
    );
    assert!(!c.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `prism ARGS` and returns the output.
fn run(args: &[&std::ffi::OsStr]) -> Output {
    prism().args(args).output().unwrap()
}

/// The output's extension picks the format (PNG, JPEG or EXR bytes, checked by their magic
/// numbers); an extension a command cannot write, or a missing folder, is refused with exit
/// 2 before the input is even read (a missing input is not what is reported), naming the
/// user's path once and never a temporary file.
#[test]
fn outputs_are_chosen_by_extension_and_checked_first() {
    let dir = scratch("outputs");
    let s = |x: &str| std::ffi::OsString::from(x);
    let p = |x: &Path| x.as_os_str().to_owned();
    let magic = |path: &Path| std::fs::read(path).unwrap()[..4].to_vec();
    let small = ["-q", "-s", "1", "-r", "8", "6"];
    for (name, want) in [
        ("r.png", vec![0x89, b'P', b'N', b'G']),
        ("r.JPG", vec![0xff, 0xd8, 0xff]),
        ("r.exr", vec![0x76, 0x2f, 0x31, 0x01]),
    ] {
        let out = dir.join(name);
        let mut args = vec![s("render"), s("-o"), p(&out)];
        args.extend(small.iter().map(|a| s(a)));
        let o = run(&args.iter().map(|a| a.as_os_str()).collect::<Vec<_>>());
        assert_eq!(o.status.code(), Some(0), "{name}: {}", stderr(&o));
        assert_eq!(magic(&out)[..want.len()], want[..], "{name}");
    }
    let svg = dir.join("in.svg");
    std::fs::write(
        &svg,
        "<svg xmlns='http://www.w3.org/2000/svg' width='4' height='4'/>",
    )
    .unwrap();
    let o = run(&[&s("svg"), &p(&svg), &s("-o"), &p(&dir.join("s.jpeg"))]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(magic(&dir.join("s.jpeg"))[..2], [0xff, 0xd8]);

    std::fs::create_dir_all(dir.join("folder.png")).unwrap();
    let curve = prism_testkit::shared_asset("meshedit/bzc/curve1.bzc");
    let patches = prism_testkit::shared_asset("meshedit/bez/wavy_cube.bez");
    let cube = prism_testkit::shared_asset("meshedit/dae/cube.dae");
    let missing = dir.join("no-such-input.dae");
    let cases: Vec<(Vec<std::ffi::OsString>, &str)> = vec![
        (
            vec![s("render"), p(&missing), s("-o"), p(&dir.join("r.tif"))],
            "--output",
        ),
        (
            vec![s("render"), p(&missing), s("--exr"), p(&dir.join("r.png"))],
            "--exr",
        ),
        (
            vec![
                s("render"),
                p(&missing),
                s("--heatmap"),
                p(&dir.join("h.exr")),
            ],
            "--heatmap",
        ),
        (
            vec![s("svg"), p(&svg), s("-o"), p(&dir.join("s.exr"))],
            "expected a .png or .jpg file",
        ),
        (
            vec![s("bezier"), p(&curve), s("-o"), p(&dir.join("c.obj"))],
            "expected a .png or .jpg file",
        ),
        (
            vec![s("bezier"), p(&patches), s("-o"), p(&dir.join("t.png"))],
            "expected an .obj, .ply or .dae file",
        ),
        (
            vec![
                s("mesh"),
                s("convert"),
                p(&cube),
                s("-o"),
                p(&dir.join("m.png")),
            ],
            "expected an .obj, .ply or .dae file",
        ),
        (
            vec![
                s("mesh"),
                s("subdivide"),
                p(&missing),
                s("-o"),
                p(&dir.join("nope/m.obj")),
            ],
            "(prism does not create it)",
        ),
        (
            vec![
                s("render"),
                p(&missing),
                s("-o"),
                p(&dir.join("nope/r.png")),
            ],
            "no such folder",
        ),
        (
            vec![s("svg"), p(&svg), s("-o"), p(&dir.join("folder.png"))],
            "expected a file name, not a folder",
        ),
    ];
    for (args, want) in cases {
        let o = run(&args.iter().map(|a| a.as_os_str()).collect::<Vec<_>>());
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: expected {want:?} in {err}");
        // The output is checked first: a missing input is never what is reported.
        assert!(!err.contains("no such file"), "{err}");
        assert!(!err.contains(".tmp"), "{err}");
    }
    for left in ["r.tif", "h.exr", "s.exr", "c.obj", "t.png", "m.png"] {
        assert!(!dir.join(left).exists(), "{left} written");
    }
    assert!(!dir.join("nope").exists(), "a folder was created");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `prism mesh info` lists vertices, edges and faces (limited), and each edge operation says
/// what it changed and the counts that result.
#[test]
fn mesh_listing_and_operation_reports() {
    let dir = scratch("mesh-report");
    let tet = dir.join("tet.obj");
    std::fs::write(
        &tet,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n",
    )
    .unwrap();
    let o = prism()
        .args([
            "mesh",
            "info",
            "--vertices",
            "--edges",
            "--faces",
            "--limit",
            "2",
        ])
        .arg(&tet)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for want in [
        "vertex 1: 0 0 0",
        "vertex 2: 1 0 0",
        "... 2 more vertices (--limit 4 lists them all)",
        "edge 0: vertices 1,3, from 0 0 0 to 0 1 0",
        "... 4 more edges",
        "face 0: vertices 1,3,2",
        "... 2 more faces",
    ] {
        assert!(text.contains(want), "{want:?} not in {text}");
    }
    assert!(!text.contains("vertex 3:"), "{text}");
    let out = dir.join("out.obj");
    for (op, want) in [
        ("split", "edge 0 (vertices 1,3): split at new vertex 5 (0 0.5 0)\nnow 5 vertices, 9 edges, 6 faces"),
        ("flip", "edge 0 (vertices 1,3): flipped; it now joins vertices"),
        ("collapse", "edge 0 (vertices 1,3): "),
    ] {
        let o = prism()
            .args(["mesh", op])
            .arg(&tet)
            .arg("-o")
            .arg(&out)
            .args(["--edge", "0"])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout);
        if o.status.code() == Some(0) {
            assert!(text.contains(want), "{op}: {want:?} not in {text}");
            assert!(text.contains("now "), "{op}: {text}");
        } else {
            // A tetrahedron's edges cannot flip or collapse and stay a manifold: a reason.
            assert_eq!(o.status.code(), Some(2), "{op}: {}", stderr(&o));
            assert!(stderr(&o).contains(&format!("cannot {op}")), "{}", stderr(&o));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Impossible flag combinations are errors; ineffective ones are warnings naming the flag;
/// a scene whose only light gives off nothing says so, and what would show it.
#[test]
fn render_flags_are_never_silent_no_ops() {
    let dir = scratch("flags");
    let out = dir.join("r.png");
    let render = |extra: &[&str]| {
        prism()
            .args(["render", "-q", "-s", "1", "-r", "8", "6", "-o"])
            .arg(&out)
            .args(extra)
            .output()
            .unwrap()
    };
    for (extra, want) in [
        (
            &["--bounce", "3", "-m", "1"][..],
            "--bounce 3: no path gets that far (--max-bounces is 1)",
        ),
        (
            &["--bounce", "2", "--integrator", "direct"][..],
            "--integrator direct stops after 1",
        ),
        (
            &["--bounce", "1", "--integrator", "normals"][..],
            "the normals integrator does not bounce",
        ),
    ] {
        let o = render(extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{extra:?}: {}", stderr(&o));
        assert!(!out.exists());
    }
    let heat = dir.join("h.png");
    let o = render(&[
        "--hemisphere",
        "--batch",
        "8",
        "--heatmap",
        heat.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for want in [
        "warning: --hemisphere has no effect",
        "warning: --batch has no effect",
        "warning: --heatmap without --adaptive",
    ] {
        assert!(stderr(&o).contains(want), "{want}: {}", stderr(&o));
    }
    let o = render(&[
        "--integrator",
        "direct",
        "--hemisphere",
        "--adaptive",
        "0.1",
        "--batch",
        "8",
    ]);
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let unlit = prism_testkit::shared_asset("pathtracer/dae/sky/bunny_unlit.dae");
    let o = render(&[unlit.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("renders black (`--envmap FILE.exr` lights it, `--integrator normals` shows its shapes)"),
        "{}",
        stderr(&o)
    );
    let help = prism().arg("--help").output().unwrap();
    let first = String::from_utf8_lossy(&help.stdout)
        .lines()
        .next()
        .unwrap_or("")
        .to_string();
    assert!(
        first.contains("mesh editing") && first.contains("path tracing"),
        "{first}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Meshes prism wrote itself load: the welded Bezier teapot (a vertex where the handle
/// touches the body has two fans) and the Delft `monkey.obj` (a face on an edge already used
/// in its direction) are repaired on load with a warning naming the vertex or face, subdivide,
/// and the result builds and validates (prism-mesh's `validate` is the oracle); `--strict`
/// keeps the refusal.
#[test]
fn meshes_prism_wrote_load_repaired() {
    let dir = scratch("repair");
    let teapot = dir.join("teapot.obj");
    let o = prism()
        .arg("bezier")
        .arg(prism_testkit::shared_asset("meshedit/bez/teapot.bez"))
        .arg("-o")
        .arg(&teapot)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let monkey = prism_testkit::shared_asset("delft-raytracer/data/monkey.obj");
    for (input, want) in [
        (
            &teapot,
            "joins 2 fans of faces that touch only there; split into 2 vertices",
        ),
        (
            &monkey,
            "face 143 uses an edge an earlier face already uses in that direction",
        ),
    ] {
        let out = dir.join("smooth.obj");
        let o = prism()
            .args(["mesh", "subdivide"])
            .arg(input)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert!(stderr(&o).contains(want), "{want:?} not in {}", stderr(&o));
        let smooth = prism_mesh::read_obj(&out).unwrap();
        prism_mesh::HalfedgeMesh::from_polymesh(&smooth)
            .unwrap()
            .validate()
            .unwrap();
        let o = prism()
            .args(["mesh", "info", "--strict"])
            .arg(input)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Standard SVG is read as resvg reads it: an invalid transform or opacity is treated as
/// absent, an invalid fill colour as black (usvg's fallback), and path data is drawn up to
/// its first error, each with a warning. Oracle: the same file with the bad part removed
/// (or replaced by the fallback) gives the same bytes.
#[test]
fn standard_svg_is_lenient_as_browsers_are() {
    let dir = scratch("lenient");
    let head = "<svg xmlns='http://www.w3.org/2000/svg' width='16' height='16'>";
    let cases = [
        (
            "<path d='M0 0 L16 0 L16 16 Z L5' fill='red'/>",
            "<path d='M0 0 L16 0 L16 16 Z' fill='red'/>",
            "Error during path parsing",
        ),
        (
            "<g fill='blue'><rect width='9' height='9' fill='#12' stroke='red'/></g>",
            "<g fill='blue'><rect width='9' height='9' fill='black' stroke='red'/></g>",
            "Failed to parse fill value: '#12'. Fallback to black.",
        ),
        (
            "<rect width='9' height='9' transform='rotate(' style='opacity: lots'/>",
            "<rect width='9' height='9'/>",
            "Failed to parse transform value: 'rotate('",
        ),
    ];
    for (bad, good, want) in cases {
        let (o, out) = run_svg(&dir, &format!("{head}{bad}</svg>"), &[]);
        assert_eq!(o.status.code(), Some(0), "{bad}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{want:?} not in {}", stderr(&o));
        assert!(stderr(&o).contains("warning"), "{}", stderr(&o));
        let got = std::fs::read(&out).unwrap();
        let (o, out) = run_svg(&dir, &format!("{head}{good}</svg>"), &[]);
        assert_eq!(o.status.code(), Some(0), "{good}: {}", stderr(&o));
        assert_eq!(
            got,
            std::fs::read(&out).unwrap(),
            "{bad} differs from {good}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The course's own flags work as typed, and mean what the long forms mean (oracle: the
/// same bytes): `-f` output, `-a BATCH TOL`, `-H`; the thin lens (`-b`, `-d`) changes the
/// picture, a lens of radius 0 does not; typos get a suggestion.
#[test]
fn course_flags_work_as_typed() {
    let dir = scratch("course-flags");
    let render = |out: &Path, extra: &[&str]| {
        let o = prism()
            .args(["render", "-q", "-s", "8", "-r", "24", "18"])
            .args(extra)
            .arg("-o")
            .arg(out)
            .output()
            .unwrap();
        (
            o.status.code(),
            std::fs::read(out).unwrap_or_default(),
            stderr(&o),
        )
    };
    let bytes = |name: &str, extra: &[&str]| render(&dir.join(name), extra).1;
    let long = bytes(
        "long.png",
        &[
            "--batch",
            "4",
            "--adaptive",
            "0.2",
            "--integrator",
            "direct",
            "--hemisphere",
        ],
    );
    let short = bytes(
        "short.png",
        &["-a", "4", "0.2", "--integrator", "direct", "-H"],
    );
    assert!(!long.is_empty());
    assert_eq!(long, short);
    let o = prism()
        .args(["render", "-q", "-s", "1", "-r", "8", "6", "-f"])
        .arg(dir.join("f.png"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(dir.join("f.png").exists());
    let pinhole = bytes("pinhole.png", &[]);
    assert_eq!(bytes("zero-lens.png", &["-b", "0", "-d", "3"]), pinhole);
    let lens = bytes("lens.png", &["-b", "0.2", "-d", "2"]);
    assert!(!lens.is_empty() && lens != pinhole);
    let (code, _, err) = render(&dir.join("bad.png"), &["--lens-radius=-1"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--lens-radius: expected a radius of 0 or more"),
        "{err}"
    );
    let (code, _, err) = render(&dir.join("a.png"), &["-a", "4", "x"]);
    assert_eq!(code, Some(2), "{err}");
    let o = prism().args(["render", "--sp", "4"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("similar argument exists: '--spp'"),
        "{}",
        stderr(&o)
    );
    let o = prism().args(["render", "--help"]).output().unwrap();
    assert!(String::from_utf8_lossy(&o.stdout).contains("[SCENE]"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--envmap` (`-e`) lights the course's unlit bunny with an OpenEXR map: the picture is no
/// longer black, the darkness warning is gone, and a map that is not `.exr` or does not read
/// is a located error with exit 2 and no output.
#[test]
fn envmap_lights_the_unlit_bunny() {
    let dir = scratch("envmap");
    let unlit = prism_testkit::shared_asset("pathtracer/dae/sky/bunny_unlit.dae");
    let sky = prism_testkit::workspace_root().join("docs/envmap/sky.exr");
    let out = dir.join("lit.png");
    let render = |extra: &[&std::ffi::OsStr]| {
        prism()
            .args(["render", "-q", "-s", "4", "-r", "32", "24", "-o"])
            .arg(&out)
            .arg(&unlit)
            .args(extra)
            .output()
            .unwrap()
    };
    let o = render(&["-e".as_ref(), sky.as_os_str()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stderr(&o).contains("renders black"), "{}", stderr(&o));
    let img = prism_image::read_png(&out).unwrap().to_rgb8();
    let lit = img
        .pixels()
        .iter()
        .filter(|p| p.iter().any(|&c| c > 20))
        .count();
    assert!(lit > img.pixels().len() / 2, "{lit} lit pixels");
    std::fs::remove_file(&out).unwrap();
    let bad = dir.join("bad.exr");
    std::fs::write(&bad, b"v/1\x01 not really").unwrap();
    // A 2x1 map whose second texel is NaN.
    let nan = dir.join("nan.exr");
    let map = prism_image::Image::from_fn(2, 1, |x, _| {
        prism_math::Rgb::splat(if x == 1 { f32::NAN } else { 1.0 })
    });
    prism_image::write_exr(&nan, &map).unwrap();
    for (map, want) in [
        (
            sky.with_extension("png"),
            "expected an OpenEXR (.exr) or Radiance (.hdr) map",
        ),
        (bad.clone(), "bad.exr"),
        (nan.clone(), "nan.exr: texel (1, 0) is"),
    ] {
        let o = render(&["--envmap".as_ref(), map.as_os_str()]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(want), "{want}: {}", stderr(&o));
        assert!(!out.exists());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The template's extras from a config: every one on, the settings read, both trees in
/// `--stats`, the extras' rays in the ray tree with their shutter times; the environment map
/// path is the config's folder's.
#[test]
fn raytrace_extras_from_a_config() {
    let dir = scratch("raytrace-extras");
    let sky = prism_image::Image::from_fn(8, 4, |x, y| [(x * 30) as u8, (y * 60) as u8, 200]);
    prism_image::write_png(&dir.join("sky.png"), &sky).unwrap();
    std::fs::write(
        dir.join("extras.toml"),
        "scene = \"cornell_box\"\nwindow_size = [24, 24]\n\
         [features]\nenable_shading = true\nenable_recursive = true\nenable_accel_structure = true\n\
         [features.extra]\nenable_depth_of_field = true\nenable_motion_blur = true\n\
         enable_glossy_reflection = true\nenable_environment_mapping = true\n\
         enable_mipmap_texture_filtering = true\n\
         [[motion]]\nmesh = \"tallBox\"\nvelocity = [0.2, 0, 0]\n\
         [extras]\ndof_aperture = 0.1\ndof_samples = 4\nmotion_samples = 4\nglossy_samples = 4\n\
         environment_map = \"sky.png\"\nenvironment_strength = 0.5\n",
    )
    .unwrap();
    let out = dir.join("x.png");
    let o = prism()
        .arg("raytrace")
        .arg(dir.join("extras.toml"))
        .args(["-q", "--stats", "--debug-pixel", "12,12", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(!err.contains("warning"), "{err}");
    for line in [
        "bvh: ",
        "tree by binned SAH: SAH cost ",
        "tree by median split: SAH cost ",
    ] {
        assert!(
            err.lines().any(|l| l.starts_with(line)),
            "{line} missing: {err}"
        );
    }
    assert!(err.contains("(median split)"), "{err}");
    let json = std::fs::read_to_string(dir.join("x.rays.json")).unwrap();
    for kind in ["lens", "glossy", "environment"] {
        assert!(
            json.contains(&format!("\"kind\":\"{kind}\"")),
            "{kind}: {json}"
        );
    }
    assert!(json.contains("\"time\":"), "{json}");
    let img = prism_image::read_png(&out).unwrap();
    // The corners look past the box at the sky (blue 200 x 0.5 / 255).
    assert!(img.pixels()[0][2] > 80, "{:?}", img.pixels()[0]);
}

/// `prism raytrace`: presets, configs with several cameras, the debug outputs, and every
/// kind of bad OBJ, MTL or config input as a located error with exit 2 and no output.
#[test]
fn raytrace_scenes_debugging_and_errors() {
    let dir = scratch("raytrace");
    let out = dir.join("cb.png");
    let ply = dir.join("rays.ply");
    let o = prism()
        .args(["raytrace", "cornell-box", "-q", "-r", "40", "30", "--stats"])
        .arg("-o")
        .arg(&out)
        .args(["--debug-pixel", "20,15", "--debug-camera", "30,-40,0,3.5"])
        .arg("--debug-ply")
        .arg(&ply)
        .args(["--bvh-level", "1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let img = prism_image::read_png(&out).unwrap();
    assert_eq!((img.width(), img.height()), (40, 30));
    assert!(prism_image::read_png(&dir.join("cb.debug.png")).is_ok());
    let json = std::fs::read_to_string(dir.join("cb.rays.json")).unwrap();
    assert!(json.starts_with("{\"pixel\":[20,15],\"color\":["), "{json}");
    assert!(json.contains("\"kind\":\"camera\""), "{json}");
    assert!(json.contains("\"kind\":\"shadow\""), "{json}");
    assert!(std::fs::read_to_string(&ply).unwrap().starts_with("ply\n"));
    let err = stderr(&o);
    for stage in [
        "bvh: ", "rays: ", "read: ", "render: ", "write: ", "rays/s: ",
    ] {
        assert!(
            err.lines().any(|l| l.starts_with(stage)),
            "{stage} missing: {err}"
        );
    }

    // A config: two cameras make two images; the OBJ path is relative to data_path.
    std::fs::write(
        dir.join("tri.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("scene.toml"),
        "window_size = [16, 12]\ndata_path = \".\"\nscene = \"tri.obj\"\n\
         [features]\nenable_shading = true\n[[cameras]]\nrotation = [0, 0, 0]\n[[cameras]]\n\
         [[lights]]\ntype = \"point\"\nposition = [0, 0, -3]\ncolor = [1, 1, 1]\n",
    )
    .unwrap();
    let o = prism()
        .args(["raytrace", "-q"])
        .arg(dir.join("scene.toml"))
        .arg("-o")
        .arg(dir.join("cfg.png"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for i in 0..2 {
        let img = prism_image::read_png(&dir.join(format!("cfg-{i}.png"))).unwrap();
        assert_eq!((img.width(), img.height()), (16, 12));
    }

    // The template's own output format: a 24-bit bitmap of the same bytes as the PNG.
    let o = prism()
        .args(["raytrace", "cube", "-q", "-r", "8", "6", "-o"])
        .arg(dir.join("cube.bmp"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let bmp = std::fs::read(dir.join("cube.bmp")).unwrap();
    assert_eq!((&bmp[..2], bmp.len()), (&b"BM"[..], 54 + 6 * 24));

    // Bad inputs: each a located error, exit 2, no output file, within seconds.
    let cases: Vec<(&str, &str, &str)> = vec![
        ("bad-index.obj", "v 0 0 0\nf 1 2 3\n", "bad-index.obj:2: f: vertex index 2 is out of range"),
        ("nan.obj", "v 0 nan 0\n", "nan.obj:1: v: expected a finite number"),
        ("no-mtl.obj", "mtllib gone.mtl\n", "no-mtl.obj:1: mtllib: cannot read the material library"),
        ("bad-number.obj", "v 0 0 x\n", "bad-number.obj:1: v: expected a finite number, found \"x\""),
        ("bad.toml", "scene = \"kitchen\"\n", "bad.toml:1: scene: expected a preset"),
        ("types.toml", "[[cameras]]\nfield_of_view = \"wide\"\n", "types.toml:2: field_of_view: expected a number"),
        ("fov.toml", "[[cameras]]\nfield_of_view = 0\n", "fov.toml:2: field_of_view: expected degrees strictly between 0 and 180"),
        ("light.toml", "[[lights]]\ntype = \"parallelogram\"\ncorner = [0,0,0]\nedges = [[1,0,0],[1,0,0]]\ncolors = [[1,1,1],[1,1,1],[1,1,1],[1,1,1]]\n", "light.toml:4: edges: a parallelogram light needs an area above 0"),
        ("window.toml", "window_size = [100000, 2]\n", "window.toml:1: window_size: expected sides from 1 to 16384"),
        ("truncated.toml", "[features\n", "truncated.toml:1: expected TOML"),
        ("missing.toml", "data_path = \".\"\nscene = \"nowhere.obj\"\n", "nowhere.obj"),
    ];
    for (name, text, want) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        let target = dir.join(format!("{name}.png"));
        let t = std::time::Instant::now();
        let o = prism()
            .args(["raytrace", "-q"])
            .arg(dir.join(name))
            .arg("-o")
            .arg(&target)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{name}: {}", stderr(&o));
        assert!(!target.exists(), "{name}: wrote an output");
        assert!(t.elapsed().as_secs() < 20, "{name}: too slow");
    }
    // A texture that is missing, a huge face, an unknown preset, a bad flag value.
    std::fs::write(dir.join("t.mtl"), "newmtl a\nmap_Kd gone.png\n").unwrap();
    std::fs::write(
        dir.join("tex.obj"),
        "mtllib t.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let huge = format!("v 0 0 0\nf {}\n", "1 ".repeat(100_000));
    std::fs::write(dir.join("huge.obj"), huge).unwrap();
    for (args, want) in [
        (
            vec![dir.join("tex.obj").display().to_string()],
            "t.mtl:2: material a: map_Kd gone.png: cannot read the texture".to_string(),
        ),
        (
            vec![dir.join("huge.obj").display().to_string()],
            "f: more than 65536 corners".to_string(),
        ),
        (
            vec!["kitchen".into()],
            "kitchen: no such file or preset; presets: single-triangle".to_string(),
        ),
        (
            vec!["cube".into(), "--enable".into(), "shiny".into()],
            "--enable shiny: expected one of".to_string(),
        ),
        (
            vec!["cube".into(), "--debug-pixel".into(), "900,1".into()],
            "--debug-pixel 900,1: outside".to_string(),
        ),
    ] {
        let target = dir.join("x.png");
        let o = prism()
            .args(["raytrace", "-q", "-r", "8", "8"])
            .args(&args)
            .arg("-o")
            .arg(&target)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(&want), "{args:?}: {}", stderr(&o));
        assert!(!target.exists());
    }
}

/// `prism shade`: a mesh of each format drawn with every shader, `--flag=VALUE` for values
/// that start with `-`, per-stage times; bad input is a located error with exit 2 and no
/// output.
#[test]
fn shade_meshes_and_errors() {
    let dir = scratch("shade");
    let monkey = prism_testkit::shared_asset("delft-raytracer/data/monkey.obj");
    let textures = prism_testkit::shared_asset("clothsim/textures");
    for (shader, extra) in [
        ("normal", vec![]),
        ("wireframe", vec![]),
        ("diffuse", vec![]),
        (
            "phong",
            vec!["--wireframe".to_string(), "0,0,0".to_string()],
        ),
        (
            "texture",
            vec![
                "--texture".into(),
                textures.join("texture_1.png").display().to_string(),
            ],
        ),
        (
            "bump",
            vec![
                "--height-map".into(),
                textures.join("texture_1.png").display().to_string(),
            ],
        ),
        (
            "displacement",
            vec![
                "--height-map".into(),
                textures.join("texture_1.png").display().to_string(),
            ],
        ),
        (
            "mirror",
            vec![
                "--cubemap".into(),
                textures.join("cube").display().to_string(),
            ],
        ),
    ] {
        let out = dir.join(format!("{shader}.png"));
        let o = prism()
            .arg("shade")
            .arg(&monkey)
            .args([
                "--shader",
                shader,
                "-r",
                "64",
                "48",
                "--eye=-1,0.5,-3",
                "--stats",
                "-o",
            ])
            .arg(&out)
            .args(&extra)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{shader}: {}", stderr(&o));
        let img = prism_image::read_png(&out).unwrap();
        assert_eq!((img.width(), img.height()), (64, 48));
        let err = stderr(&o);
        for stage in ["read: ", "render: ", "write: "] {
            assert!(err.lines().any(|l| l.starts_with(stage)), "{stage}: {err}");
        }
    }
    // PLY and COLLADA too, framed automatically.
    for mesh in ["meshedit/dae/cow.dae", "meshedit/dae/teapot.dae"] {
        let out = dir.join("auto.png");
        let o = prism()
            .arg("shade")
            .arg(prism_testkit::shared_asset(mesh))
            .args(["-r", "32", "32", "-o"])
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{mesh}: {}", stderr(&o));
    }
    std::fs::write(dir.join("bad.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap();
    for (args, want) in [
        (
            vec![dir.join("bad.obj").display().to_string()],
            "bad.obj:3: f: vertex index 3 is out of range",
        ),
        (
            vec![
                monkey.display().to_string(),
                "--shader".into(),
                "bump".into(),
                "--data".into(),
                "/nonexistent-prism-data".into(),
            ],
            "--height-map not given, and --data /nonexistent-prism-data: no such folder",
        ),
        (
            vec![monkey.display().to_string(), "--eye".into(), "1,2".into()],
            "--eye: expected three finite numbers",
        ),
        (
            vec![monkey.display().to_string(), "--samples".into(), "3".into()],
            "expected a square number of samples",
        ),
        (
            vec![
                monkey.display().to_string(),
                "-r".into(),
                "16384".into(),
                "16384".into(),
                "--samples".into(),
                "16".into(),
            ],
            "is over the limit of 2^28",
        ),
        (
            vec![
                monkey.display().to_string(),
                "--eye=0,0,0".into(),
                "--target=0,0,0".into(),
            ],
            "camera: the eye is the target",
        ),
    ] {
        let out = dir.join("x.png");
        let o = prism()
            .arg("shade")
            .args(&args)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{args:?}: {}", stderr(&o));
        assert!(!out.exists());
    }
}

/// `prism cloth`: a staged scene simulated, written as OBJ (masses first, row-major) and
/// drawn; `--set` overrides; bad scenes are located errors with exit 2 and nothing written.
#[test]
fn cloth_runs_and_errors() {
    let dir = scratch("cloth");
    let scene = prism_testkit::shared_asset("clothsim/scene/pinned2.json");
    let obj = dir.join("state.obj");
    let png = dir.join("last.png");
    let o = prism()
        .arg("cloth")
        .arg(&scene)
        .args([
            "--frames", "3", "-r", "64", "50", "--stats", "--set", "ks=500", "--obj",
        ])
        .arg(&obj)
        .arg("-o")
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&obj).unwrap();
    let v: Vec<&str> = text.lines().filter(|l| l.starts_with("v ")).collect();
    assert_eq!(v.len(), 2500);
    // Mass (49, 0) is pinned at (1, 1, 0).
    let p: Vec<f64> = v[49][2..].split(' ').map(|x| x.parse().unwrap()).collect();
    assert_eq!(p, [1.0, 1.0, 0.0]);
    assert!(text.lines().any(|l| l.starts_with("f ")));
    // An animated PNG of the three frames.
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.windows(4).any(|w| w == b"acTL"), "not animated");
    assert_eq!(bytes.windows(4).filter(|w| *w == b"fcTL").count(), 3);
    assert_eq!(prism_image::read_png(&png).unwrap().width(), 64);
    let err = stderr(&o);
    assert!(
        err.lines().any(|l| l.starts_with("particle-updates/s: ")),
        "{err}"
    );
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let o = prism()
        .arg("cloth")
        .arg(&scene)
        .args(["--frames", "2", "-r", "32", "24", "-o"])
        .arg(&frames)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(frames.join("frame_0002.png").is_file());
    // A GIF of the two frames, at GIF's shortest honoured frame time.
    let gif = dir.join("run.gif");
    let o = prism()
        .arg("cloth")
        .arg(&scene)
        .args(["--frames", "2", "-r", "32", "24", "-o"])
        .arg(&gif)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mut dec = gif::DecodeOptions::new()
        .read_info(std::fs::File::open(&gif).unwrap())
        .unwrap();
    assert_eq!((dec.width(), dec.height()), (32, 24));
    for _ in 0..2 {
        assert_eq!(dec.read_next_frame().unwrap().unwrap().delay, 2);
    }
    assert!(dec.read_next_frame().unwrap().is_none());

    let text = std::fs::read_to_string(&scene).unwrap();
    for (name, bad, want) in [
        (
            "types.json",
            text.replace("\"ks\": 5000.0", "\"ks\": \"x\""),
            "types.json:5: ks: expected a number, found a string",
        ),
        (
            "unknown.json",
            text.replace("\"damping\"", "\"dampng\""),
            "unknown.json:3: cloth: unknown key \"dampng\"",
        ),
        (
            "missing.json",
            text.replace("\"density\": 150.0,", ""),
            "cloth: missing required key \"density\"",
        ),
        (
            "nan.json",
            text.replace("\"width\": 1", "\"width\": -1"),
            "width: expected a number above 0",
        ),
        (
            "grid.json",
            text.replace("\"num_width_points\": 50", "\"num_width_points\": 1"),
            "num_width_points: expected 2 to 4096 masses",
        ),
        (
            "huge.json",
            text.replace("\"num_width_points\": 50", "\"num_width_points\": 99999999"),
            "num_width_points: expected 2 to 4096 masses",
        ),
        (
            "pins.json",
            text.replace("[49, 0]", "[49, 50]"),
            "pinned: [49, 50] is outside the 50 x 50 grid",
        ),
        (
            "broken.json",
            text[..text.len() / 2].to_string(),
            "broken.json:",
        ),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, bad).unwrap();
        let out = dir.join(format!("{name}.obj"));
        let o = prism()
            .arg("cloth")
            .arg(&path)
            .args(["--frames", "1", "--obj"])
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{name}: {}", stderr(&o));
        assert!(!out.exists());
    }
    let o = prism()
        .arg("cloth")
        .arg(&scene)
        .args(["--set", "sphere.radius=0"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("the scene has no \"sphere\""),
        "{}",
        stderr(&o)
    );
}

/// `prism view` refuses before opening anything: a file whose extension names no mode, a
/// missing file, and no display (exit 2 with a message naming what to do).
#[test]
fn view_refuses_without_a_display_or_a_mode() {
    let dir = scratch("view");
    let svg = dir.join("t.svg");
    std::fs::write(
        &svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="4" height="4"/>"#,
    )
    .unwrap();
    let txt = dir.join("t.txt");
    std::fs::write(&txt, "x").unwrap();
    let view = |file: &Path| {
        prism()
            .arg("view")
            .arg(file)
            .env_remove("DISPLAY")
            .output()
            .unwrap()
    };
    let o = view(&svg);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("prism view needs an X11 display, and DISPLAY is not set"));
    let o = view(&txt);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("cannot tell what to view from the extension `.txt`"));
    let o = view(&dir.join("missing.svg"));
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("missing.svg"));
}

/// Property: every SIMD kernel does its scalar code's operations in its order, so capping the
/// instruction set (`PRISM_ISA`) changes no byte of a path-traced render (the Cornell box
/// with the bunny and the one with spheres: the list queries on sixteen lanes, eight, or
/// none), a shaded mesh, or a cloth run.
#[test]
fn outputs_are_the_same_bytes_on_every_instruction_set() {
    let dir = scratch("isa");
    // Each argument list ends with the option that names the output.
    let args = |words: &[&str], file: &str| -> Vec<std::ffi::OsString> {
        words
            .iter()
            .map(|&w| {
                if w == "{}" {
                    prism_testkit::shared_asset(file).into()
                } else {
                    w.into()
                }
            })
            .collect()
    };
    let render = ["render", "{}", "-q", "-s", "2", "-r", "96", "72", "-o"];
    let runs = [
        ("bunny.exr", args(&render, "pathtracer/dae/sky/CBbunny.dae")),
        (
            "spheres.exr",
            args(&render, "pathtracer/dae/sky/CBspheres_lambertian.dae"),
        ),
        (
            "monkey.png",
            args(
                &["shade", "{}", "--shader", "phong", "-r", "96", "72", "-o"],
                "delft-raytracer/data/monkey.obj",
            ),
        ),
        (
            "cloth.obj",
            args(
                &["cloth", "{}", "--frames", "2", "-q", "--obj"],
                "clothsim/scene/pinned2.json",
            ),
        ),
    ];
    for (out, args) in &runs {
        let mut outputs = Vec::new();
        for isa in ["avx512", "avx2", "avx", "sse"] {
            let path = dir.join(format!("{isa}-{out}"));
            let o = prism()
                .env("PRISM_ISA", isa)
                .args(args)
                .arg(&path)
                .output()
                .unwrap();
            assert_eq!(o.status.code(), Some(0), "{out} on {isa}: {}", stderr(&o));
            outputs.push((isa, std::fs::read(&path).unwrap()));
        }
        for (isa, bytes) in &outputs[1..] {
            assert!(bytes == &outputs[0].1, "{out}: {isa} differs from avx512");
        }
    }
    // The cap is in force: `--stats` names the level the kernels ran on (never above the
    // cap, and the cap itself where the processor has it).
    let level = |cap: &str| {
        let o = prism()
            .env("PRISM_ISA", cap)
            .args(args(&render, "pathtracer/dae/sky/CBspheres_lambertian.dae"))
            .arg(dir.join("level.exr"))
            .arg("--stats")
            .output()
            .unwrap();
        let text = stderr(&o);
        let line = text.lines().find(|l| l.starts_with("simd: ")).unwrap_or("");
        line.trim_start_matches("simd: ").to_string()
    };
    assert_eq!(level("sse"), "sse");
    let native = level("avx512");
    assert!(
        ["sse", "avx", "avx2", "avx512"].contains(&native.as_str()),
        "{native}"
    );
    if native == "avx512" || native == "avx2" {
        assert_eq!(level("avx2"), "avx2");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The course's files are found at run time: a copy of the binary outside the checkout (as
/// `cargo install` puts it), run from another folder with `PRISM_DATA`, writes the demo's
/// pictures made from them (the bunny, the Delft presets, the cloth) and traces a Delft
/// preset from their data; `PRISM_DATA` naming no folder is refused, naming it.
#[test]
fn an_installed_binary_finds_the_course_files_by_prism_data() {
    let dir = scratch("installed");
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let exe = bin.join("prism");
    std::fs::copy(env!("CARGO_BIN_EXE_prism"), &exe).unwrap();
    let work = dir.join("work");
    std::fs::create_dir_all(&work).unwrap();
    let run = |args: &[&str], data: &std::path::Path| {
        Command::new(&exe)
            .args(args)
            .current_dir(&work)
            .env("PRISM_DATA", data)
            .output()
            .unwrap()
    };
    let assets = prism_testkit::shared_assets();
    let o = run(&["demo", "-q", "-o", "gallery"], &assets);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for f in [
        "render_bunny.png",
        "raytrace_presets.png",
        "cloth_scenes.png",
        "cloth_shaders.png",
    ] {
        assert!(work.join("gallery").join(f).is_file(), "{f} missing");
    }
    let o = run(
        &["raytrace", "teapot", "-r", "32", "32", "-o", "t.png", "-q"],
        &assets,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let gone = dir.join("gone");
    let o = run(&["demo", "-q", "-o", "g2"], &gone);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("PRISM_DATA {}: no such folder", gone.display())),
        "{}",
        stderr(&o)
    );
    assert!(
        !work.join("g2").exists(),
        "the demo made its folder before refusing"
    );
    // A file is no folder either, for the demo and for the Delft presets' data.
    for args in [
        &["demo", "-q", "-o", "g3"][..],
        &["raytrace", "teapot", "-o", "t3.png"],
    ] {
        let o = run(args, &exe);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let want = format!("PRISM_DATA {}: not a folder", exe.display());
        assert!(stderr(&o).contains(&want), "{args:?}: {}", stderr(&o));
    }
    assert!(!work.join("g3").exists() && !work.join("t3.png").exists());
}

/// The README's examples in `docs/examples` run as it shows them: the render config writes
/// one non-black picture per camera, the cloth scene an animation.
#[test]
fn docs_examples_run() {
    let dir = scratch("examples");
    let examples = prism_testkit::workspace_root().join("docs/examples");
    let o = prism()
        .arg("raytrace")
        .arg(examples.join("teapot.toml"))
        .args(["-r", "64", "64", "-q", "-o"])
        .arg(dir.join("teapot.png"))
        .env("PRISM_DATA", prism_testkit::shared_assets())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for camera in 0..2 {
        let img = prism_image::read_png(&dir.join(format!("teapot-{camera}.png"))).unwrap();
        let lit = img
            .to_rgb8()
            .pixels()
            .iter()
            .filter(|p| p.iter().any(|&c| c > 32))
            .count();
        assert!(lit > 100, "camera {camera}: {lit} lit pixels");
    }
    let o = prism()
        .arg("cloth")
        .arg(examples.join("drape.json"))
        .args(["--frames", "20", "-r", "64", "48", "-q", "-o"])
        .arg(dir.join("drape.gif"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(std::fs::metadata(dir.join("drape.gif")).unwrap().len() > 1000);
}

/// The subcommands a `--help` page lists under `Commands:` (without `help`).
fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter(|l| !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect()
}

/// One set of habits, walked through every subcommand's `--help` (found from `prism --help`
/// and `prism mesh --help`, so a new one is walked too): each page opens, every command takes
/// `-q, --quiet`, and every command that writes files names them with `-o, --output`. The
/// window (`view`) writes nothing and has no quiet mode; `mesh info` prints a report.
#[test]
fn every_subcommand_has_the_common_flags() {
    let help = |args: &[&str]| {
        let o = prism().args(args).arg("--help").output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        String::from_utf8(o.stdout).unwrap()
    };
    let top = subcommands(&help(&[]));
    assert!(top.len() >= 10, "{top:?}");
    let mut walked = 0;
    for cmd in &top {
        let page = help(&[cmd]);
        let nested = subcommands(&page);
        let pages: Vec<(String, String)> = if nested.is_empty() {
            vec![(cmd.clone(), page)]
        } else {
            nested
                .iter()
                .map(|sub| (format!("{cmd} {sub}"), help(&[cmd, sub])))
                .collect()
        };
        for (name, page) in pages {
            walked += 1;
            let has = |flag: &str| page.contains(flag);
            // Samples per pixel, threads, the course's files and another renderer's
            // behaviour, where the subcommand has them, under one spelling.
            let spp = ["svg", "render", "raytrace", "shade", "cloth"];
            let threads = [
                "svg", "render", "raytrace", "shade", "cloth", "view", "demo",
            ];
            let data = ["raytrace", "shade", "cloth", "view", "demo"];
            let compat = ["svg", "view"];
            let base = name.as_str();
            if spp.contains(&base) {
                assert!(has("-s, --spp <"), "prism {name}: no -s, --spp");
            }
            if threads.contains(&base) {
                assert!(has("-t, --threads <"), "prism {name}: no -t, --threads");
            }
            if data.contains(&base) {
                assert!(has("--data <DIR>"), "prism {name}: no --data DIR");
            }
            if compat.contains(&base) {
                assert!(has("--compat <COMPAT>"), "prism {name}: no --compat VALUE");
            }
            if name == "bezier" {
                // The course's -t (the curve parameter) wins, and the help says so.
                assert!(has("-t, --parameter") && has("not threads"), "{page}");
            }
            if name == "view" {
                continue;
            }
            assert!(has("-q, --quiet"), "prism {name}: no -q, --quiet");
            assert!(has("--stats"), "prism {name}: no --stats");
            if name != "mesh info" {
                assert!(has("-o, --output"), "prism {name}: no -o, --output");
            }
        }
    }
    assert!(walked >= 16, "{walked} pages walked");
}

/// The share of a picture's pixels that are not black.
fn lit_share(img: &prism_image::Rgb8Image) -> f64 {
    let lit = img
        .pixels()
        .iter()
        .filter(|p| p.iter().any(|&c| c > 8))
        .count();
    lit as f64 / img.pixels().len() as f64
}

/// `prism cloth` draws every course shader with the course's files (texture, bump,
/// displacement, mirror with its cube map), each picture lit; its wireframe is lines (a
/// property: far fewer lit pixels than the filled shading's silhouette, but some); and a run
/// that writes nothing says so.
#[test]
fn cloth_draws_every_course_shader_and_wireframe_lines() {
    let dir = scratch("cloth-shaders");
    let scene = prism_testkit::shared_asset("clothsim/scene/sphere.json");
    let data = prism_testkit::shared_assets();
    let mut share = std::collections::BTreeMap::new();
    for shader in [
        "normal",
        "wireframe",
        "diffuse",
        "phong",
        "texture",
        "bump",
        "displacement",
        "mirror",
    ] {
        let frames = dir.join(shader);
        std::fs::create_dir_all(&frames).unwrap();
        // Lines and silhouettes are compared where lines are thin beside the mesh's cells.
        let size = if matches!(shader, "normal" | "wireframe") {
            ["800", "640"]
        } else {
            ["200", "160"]
        };
        let o = prism()
            .arg("cloth")
            .arg(&scene)
            .args(["--frames", "30", "-r", size[0], size[1], "--shader", shader])
            .arg("--data")
            .arg(&data)
            .arg("-o")
            .arg(&frames)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{shader}: {}", stderr(&o));
        let img = prism_image::read_png(&frames.join("frame_0030.png")).unwrap();
        share.insert(shader, lit_share(&img.to_rgb8()));
    }
    for (shader, s) in &share {
        assert!(*s > 0.005, "{shader}: {s}");
    }
    assert!(share["wireframe"] < 0.8 * share["normal"], "{share:?}");
    let o = prism()
        .arg("cloth")
        .arg(&scene)
        .args(["--frames", "1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("nothing will be written"),
        "{}",
        stderr(&o)
    );
}

/// `prism shade` lights a mesh far larger than the course's as the course lights its own: a
/// property checked on the Delft teapot (tens of units across), whose Blinn-Phong picture
/// must be more than ambient where the mesh is.
#[test]
fn shade_places_the_default_light_by_the_mesh() {
    let dir = scratch("shade-light");
    let teapot = prism_testkit::shared_asset("delft-raytracer/data/teapot.obj");
    let out = dir.join("teapot.png");
    let o = prism()
        .arg("shade")
        .arg(&teapot)
        .args(["--shader", "phong", "-r", "160", "120", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let img = prism_image::read_png(&out).unwrap().to_rgb8();
    // Ambient alone is 0.1 (26 of 255); the lit side must pass twice that.
    let brightest = img.pixels().iter().map(|p| p[0]).max().unwrap();
    assert!(brightest > 52, "brightest {brightest}");
}

/// Every subcommand words each class of user mistake the same way and exits 2 without
/// writing: a missing file, a folder given as a file, a wrong extension, a missing output
/// folder, a bad value, a mistyped subcommand or preset (with the name meant).
#[test]
fn every_error_class_has_one_wording_on_every_subcommand() {
    let dir = scratch("error-classes");
    let folder = dir.join("a-folder.obj");
    std::fs::create_dir_all(&folder).unwrap();
    let missing = dir.join("missing.obj");
    let bez = dir.join("missing.bez");
    let out = dir.join("no-such-folder/out.png");
    let svg = prism_testkit::shared_asset("rasterizer/svg/basic/test1.svg");
    let monkey = prism_testkit::shared_asset("delft-raytracer/data/monkey.obj");
    let dae = prism_testkit::shared_asset("meshedit/dae/cube.dae");
    let json = prism_testkit::shared_asset("clothsim/scene/pinned2.json");
    let bzc = prism_testkit::shared_asset("meshedit/bzc/curve1.bzc");
    let s = |p: &Path| p.display().to_string();
    let cases: Vec<(Vec<String>, String)> = vec![
        // A missing file.
        (
            vec!["svg".into(), s(&missing), "-o".into(), "x.png".into()],
            format!("{}: no such file", s(&missing)),
        ),
        (
            vec!["mesh".into(), "info".into(), s(&missing)],
            format!("{}: no such file", s(&missing)),
        ),
        (
            vec!["bezier".into(), s(&bez), "-o".into(), "x.obj".into()],
            format!("{}: no such file", s(&bez)),
        ),
        (
            vec!["render".into(), s(&missing)],
            format!("{}: no such file", s(&missing)),
        ),
        (
            vec!["raytrace".into(), s(&missing)],
            format!("{}: no such file", s(&missing)),
        ),
        (
            vec!["shade".into(), s(&missing)],
            format!("{}: no such file", s(&missing)),
        ),
        (
            vec!["cloth".into(), s(&missing), "--obj".into(), "x.obj".into()],
            format!("{}: no such file", s(&missing)),
        ),
        (
            vec!["merge".into(), s(&missing), "-o".into(), "x.png".into()],
            format!("{}: no such file", s(&missing)),
        ),
        (
            vec!["view".into(), s(&missing)],
            format!("{}: no such file", s(&missing)),
        ),
        (
            vec![
                "render".into(),
                "--envmap".into(),
                s(&missing).replace(".obj", ".exr"),
            ],
            format!(
                "--envmap {}: no such file",
                s(&missing).replace(".obj", ".exr")
            ),
        ),
        (
            vec![
                "shade".into(),
                s(&monkey),
                "--shader".into(),
                "texture".into(),
                "--texture".into(),
                s(&missing),
            ],
            format!("--texture {}: no such file", s(&missing)),
        ),
        // Not a file.
        (
            vec!["mesh".into(), "info".into(), s(&folder)],
            format!("{}: not a regular file", s(&folder)),
        ),
        (
            vec!["shade".into(), s(&folder)],
            format!("{}: not a regular file", s(&folder)),
        ),
        (
            vec!["render".into(), s(&folder)],
            format!("{}: not a regular file", s(&folder)),
        ),
        (
            vec!["cloth".into(), s(&folder)],
            format!("{}: not a regular file", s(&folder)),
        ),
        // A wrong extension (or kind).
        (
            vec!["svg".into(), s(&svg), "-o".into(), "x.txt".into()],
            "--output x.txt: expected a .png or .jpg file".into(),
        ),
        (
            vec![
                "mesh".into(),
                "convert".into(),
                s(&monkey),
                "-o".into(),
                "x.png".into(),
            ],
            "--output x.png: expected an .obj, .ply or .dae file".into(),
        ),
        (
            vec!["bezier".into(), s(&monkey), "-o".into(), "x.obj".into()],
            format!("{}: expected a .bzc or .bez file", s(&monkey)),
        ),
        (
            vec!["shade".into(), s(&monkey), "-o".into(), "x.exr".into()],
            "--output x.exr: expected a ".into(),
        ),
        (
            vec!["cloth".into(), s(&json), "--obj".into(), "x.ply".into()],
            "--obj x.ply: expected an .obj file".into(),
        ),
        (
            vec![
                "svg".into(),
                s(&prism_testkit::shared_asset(
                    "clothsim/textures/texture_1.png",
                )),
                "-o".into(),
                "x.png".into(),
            ],
            "expected an SVG file, and this is a PNG image".into(),
        ),
        // A missing output folder.
        (
            vec!["svg".into(), s(&svg), "-o".into(), s(&out)],
            format!("--output {}: no such folder", s(&out)),
        ),
        (
            vec!["bezier".into(), s(&bzc), "-o".into(), s(&out)],
            format!("--output {}: no such folder", s(&out)),
        ),
        (
            vec!["render".into(), "-o".into(), s(&out)],
            format!("--output {}: no such folder", s(&out)),
        ),
        (
            vec!["raytrace".into(), "cube".into(), "-o".into(), s(&out)],
            format!("--output {}: no such folder", s(&out)),
        ),
        (
            vec!["shade".into(), s(&monkey), "-o".into(), s(&out)],
            format!("--output {}: no such folder", s(&out)),
        ),
        (
            vec![
                "mesh".into(),
                "convert".into(),
                s(&dae),
                "-o".into(),
                s(&out).replace(".png", ".obj"),
            ],
            "no such folder".into(),
        ),
        (
            vec!["demo".into(), "--data".into(), s(&missing)],
            format!("--data {}: no such folder", s(&missing)),
        ),
        // A bad value, from the parser or from the command's own checks.
        (
            vec!["render".into(), "-s".into(), "abc".into()],
            "--spp: expected a whole number, found \"abc\"".into(),
        ),
        (
            vec!["render".into(), "--integrator".into(), "pth".into()],
            "--integrator: expected one of path,".into(),
        ),
        (
            vec![
                "svg".into(),
                s(&svg),
                "-o".into(),
                "x.png".into(),
                "-s".into(),
                "8".into(),
            ],
            "--spp: expected a perfect square".into(),
        ),
        (
            vec!["raytrace".into(), "cube".into(), "-s".into(), "0".into()],
            "--spp: expected 1 to".into(),
        ),
        (
            vec![
                "shade".into(),
                s(&monkey),
                "-r".into(),
                "0".into(),
                "10".into(),
            ],
            "--resolution: expected 1 to 16384".into(),
        ),
        (
            vec!["cloth".into(), s(&json), "--frames".into(), "0".into()],
            "--frames: expected 1 to".into(),
        ),
        // A mistyped name.
        (
            vec!["sgv".into()],
            "sgv: no such subcommand (did you mean svg?)".into(),
        ),
        (
            vec!["raytrace".into(), "cornel-box".into()],
            "cornel-box: no such file or preset (did you mean cornell-box?)".into(),
        ),
    ];
    for (args, wording) in &cases {
        let o = prism().current_dir(&dir).args(args).output().unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.lines()
                .any(|l| l.starts_with("prism: error: ") && l.contains(wording.as_str())),
            "{args:?}: expected {wording:?} in {err}"
        );
    }
    // Nothing was written, and no folder was made.
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, [std::ffi::OsString::from("a-folder.obj")], "{left:?}");
}

/// A Mitsuba scene renders from the command line with its own film and sample count, `-D`
/// sets its parameters, and a plugin prism does not render, a malformed `-D` or a split of a
/// Gaussian-filtered scene is refused with exit 2 and nothing written.
#[test]
fn mitsuba_scenes_render_and_refuse_what_they_cannot() {
    let dir = scratch("mitsuba");
    let scene = prism_testkit::workspace_root().join("docs/examples/cbox.xml");
    let out = dir.join("cbox.png");
    let o = prism()
        .arg("render")
        .arg(&scene)
        .args(["-D", "spp=4", "-D", "res=64", "-q", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let img = prism_image::read_png(&out).unwrap();
    assert_eq!((img.width(), img.height()), (64, 96));
    // No output replaces a file the scene reads: here, a texture beside it.
    let textured = prism_testkit::workspace_root()
        .join("crates/prism-render/tests/golden/mitsuba/xml/textures.xml");
    let texture = textured.with_file_name("pattern.png");
    let before = std::fs::read(&texture).unwrap();
    let o = prism()
        .arg("render")
        .arg(&textured)
        .args(["-s", "1", "-q", "-o"])
        .arg(&texture)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("a file the scene reads"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&texture).unwrap(), before);
    let bad = dir.join("bad.xml");
    std::fs::write(
        &bad,
        "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/></sensor>\n<shape type=\"sphere\">\n<bsdf type=\"hair\"/>\n</shape>\n</scene>\n",
    )
    .unwrap();
    for (args, want) in [
        (
            vec![bad.display().to_string()],
            format!(
                "{}:4: <bsdf>: type=\"hair\": not supported by prism",
                bad.display()
            ),
        ),
        (
            vec![scene.display().to_string(), "-D".into(), "spp".into()],
            "--define: expected NAME=VALUE, found \"spp\"".to_string(),
        ),
    ] {
        let o = prism()
            .arg("render")
            .args(&args)
            .arg("-q")
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(&want), "{args:?}: {}", stderr(&o));
    }
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "{left:?}");
}

/// A Mitsuba scene with two sensors renders one image for each, `_0` and `_1` before the
/// extension, each the same bytes as `--sensor N` renders alone; a sensor the scene does
/// not have is refused with exit 2, naming the file, and nothing written.
#[test]
fn each_sensor_of_a_mitsuba_scene_renders_its_own_image() {
    let dir = scratch("sensors");
    let scene = dir.join("two.xml");
    std::fs::write(
        &scene,
        r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/><rfilter type="box"/></film>
    </sensor>
    <sensor type="orthographic">
        <transform name="to_world"><lookat origin="3, 1, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="10"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="sphere"><bsdf type="diffuse"/></shape>
</scene>"#,
    )
    .unwrap();
    let render = |extra: &[&str], out: &std::path::Path| {
        prism()
            .arg("render")
            .arg(&scene)
            .args(["-s", "2", "-q", "-o"])
            .arg(out)
            .args(extra)
            .output()
            .unwrap()
    };
    let o = render(&[], &dir.join("img.png"));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (first, second) = (dir.join("img_0.png"), dir.join("img_1.png"));
    assert_eq!(prism_image::read_png(&first).unwrap().width(), 16);
    assert_eq!(prism_image::read_png(&second).unwrap().width(), 10);
    assert!(!dir.join("img.png").exists());
    let alone = dir.join("alone.png");
    let o = render(&["--sensor", "1"], &alone);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&alone).unwrap(),
        std::fs::read(&second).unwrap()
    );
    let missing = dir.join("missing.png");
    let o = render(&["--sensor", "2"], &missing);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!(
            "{}:1: <scene>: sensor 2: the scene has 2 (0 to 1)",
            scene.display()
        )),
        "{}",
        stderr(&o)
    );
    assert!(!missing.exists());
}
