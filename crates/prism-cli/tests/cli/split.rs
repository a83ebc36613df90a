//! Split renders end to end: `prism render --tile` / `--samples-from --samples-to` and
//! `prism raytrace --tile` parts merged by `prism merge` against the single-process render
//! (the oracle), and every way a set of parts can be wrong refused with exit 2 and no output.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn prism() -> Command {
    Command::new(env!("CARGO_BIN_EXE_prism"))
}

fn scratch(name: &str) -> prism_testkit::Scratch {
    prism_testkit::scratch("prism-split", name)
}

fn ok(o: Output) -> Output {
    assert!(
        o.status.success(),
        "exit {:?}: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn run(cmd: &str, args: &[&str], extra: &[&str], out: &Path) -> Output {
    prism()
        .arg(cmd)
        .args(args)
        .args(extra)
        .arg("-o")
        .arg(out)
        .arg("-q")
        .output()
        .unwrap()
}

fn merge(parts: &[PathBuf], out: &Path, extra: &[&str]) -> Output {
    prism()
        .arg("merge")
        .args(parts)
        .arg("-o")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

fn lambertian() -> String {
    prism_testkit::shared_asset("pathtracer/dae/sky/CBspheres_lambertian.dae")
        .display()
        .to_string()
}

/// 100x70 pixels: 4x3 tiles, the last column and row of tiles cut short.
const SMALL: [&str; 3] = ["-r", "100", "70"];

/// Oracle: the single render. A split into 32 shares (of 45 tiles: some shares hold two, one
/// holds the last, cut-short tile), given out of order, merges to its PNG and EXR byte for
/// byte; a part file's bytes do not depend on the thread count, and it holds only its tiles.
#[test]
fn thirty_two_part_merge_equals_the_single_render() {
    let dir = scratch("thirty-two");
    let scene = lambertian();
    let args = [
        "render",
        scene.as_str(),
        "-s",
        "2",
        "--seed",
        "5",
        "-r",
        "260",
        "150",
    ];
    let (whole_png, whole_exr) = (dir.join("whole.png"), dir.join("whole.exr"));
    ok(run(
        args[0],
        &args[1..],
        &["--exr", whole_exr.to_str().unwrap()],
        &whole_png,
    ));
    let n = 32u32;
    let mut parts: Vec<PathBuf> = (0..n)
        .map(|i| {
            let p = dir.join(format!("part-{i}.exr"));
            ok(run(
                args[0],
                &args[1..],
                &["--tile", &format!("{i}/{n}"), "-t", "2"],
                &p,
            ));
            p
        })
        .collect();
    let one_thread = dir.join("one-thread.exr");
    ok(run(
        args[0],
        &args[1..],
        &["--tile", "5/32", "-t", "1"],
        &one_thread,
    ));
    assert!(std::fs::read(&one_thread).unwrap() == std::fs::read(&parts[5]).unwrap());
    let reader = prism_image::TiledExrReader::open(&parts[5]).unwrap();
    let held: Vec<(u32, u32)> = (0..5)
        .flat_map(|ty| (0..9).map(move |tx| (tx, ty)))
        .filter(|&(tx, ty)| reader.has_tile(tx, ty))
        .collect();
    assert_eq!(held, vec![(5, 0), (1, 4)], "part 5 holds tiles 5 and 37");
    parts.rotate_left(11);
    parts.swap(0, 20);
    let (png, exr) = (dir.join("merged.png"), dir.join("merged.exr"));
    ok(merge(&parts, &png, &["--exr", exr.to_str().unwrap()]));
    assert!(std::fs::read(&png).unwrap() == std::fs::read(&whole_png).unwrap());
    assert!(std::fs::read(&exr).unwrap() == std::fs::read(&whole_exr).unwrap());
}

/// Oracle: the single render. Tile splits into N = 1, 2, 3 and 7 shares (7 does not divide
/// the 12 tiles) merge, given in any order, to its PNG and EXR byte for byte, with fixed
/// and adaptive sampling (and to its sample-count heat map).
#[test]
fn tile_splits_merge_to_the_single_render_byte_for_byte() {
    let dir = scratch("tiles");
    let scene = lambertian();
    for adaptive in [&[][..], &["--adaptive", "0.05", "--batch", "4"][..]] {
        let mut args = vec!["render", scene.as_str(), "-s", "8", "--seed", "3"];
        args.extend(SMALL);
        args.extend(adaptive);
        let whole_png = dir.join("whole.png");
        let whole_exr = dir.join("whole.exr");
        let whole_map = dir.join("whole-map.png");
        let mut pictures = vec!["--exr", whole_exr.to_str().unwrap()];
        if !adaptive.is_empty() {
            pictures.extend(["--heatmap", whole_map.to_str().unwrap()]);
        }
        ok(run(args[0], &args[1..], &pictures, &whole_png));
        for n in [1u32, 2, 3, 7] {
            let mut parts = Vec::new();
            for i in (0..n).rev() {
                let p = dir.join(format!("part-{i}-of-{n}.exr"));
                let tile = format!("{i}/{n}");
                ok(run(args[0], &args[1..], &["--tile", &tile], &p));
                parts.push(p);
            }
            let (png, exr) = (dir.join("merged.png"), dir.join("merged.exr"));
            let map = dir.join("merged-map.png");
            let (e, m) = (exr.to_str().unwrap(), map.to_str().unwrap());
            ok(merge(&parts, &png, &["--exr", e, "--heatmap", m]));
            assert!(
                std::fs::read(&png).unwrap() == std::fs::read(&whole_png).unwrap(),
                "{n} tile shares, {adaptive:?}: the PNG differs"
            );
            if !adaptive.is_empty() {
                assert!(
                    std::fs::read(&map).unwrap() == std::fs::read(&whole_map).unwrap(),
                    "{n} tile shares: the heat map differs"
                );
            }
            assert!(
                std::fs::read(&exr).unwrap() == std::fs::read(&whole_exr).unwrap(),
                "{n} tile shares, {adaptive:?}: the EXR differs"
            );
        }
    }
}

/// Oracle: the single render. A Mitsuba scene under its Gaussian and tent filters (each
/// sample's position drawn around its own pixel) split into 3 tile shares crossed with 2
/// sample ranges merges to its EXR byte for byte; the filter is part of the parts'
/// identity, so parts of different filters do not merge.
#[test]
fn filtered_mitsuba_splits_merge_to_the_single_render_byte_for_byte() {
    let dir = scratch("filtered");
    let scene = prism_testkit::workspace_root().join("docs/examples/cbox.xml");
    let scene = scene.to_str().unwrap();
    for filter in ["filter=gaussian", "filter=tent"] {
        let args = ["render", scene, "-D", filter, "-s", "6", "-r", "70", "50"];
        let whole = dir.join("whole.exr");
        ok(run(args[0], &args[1..], &[], &whole));
        let mut parts = Vec::new();
        for t in 0..3 {
            for (from, to) in [("0", "2"), ("2", "6")] {
                let p = dir.join(format!("t{t}-{from}.exr"));
                let tile = format!("{t}/3");
                let extra = ["--tile", &tile, "--samples-from", from, "--samples-to", to];
                ok(run(args[0], &args[1..], &extra, &p));
                parts.push(p);
            }
        }
        let merged = dir.join("merged.exr");
        ok(merge(&parts, &merged, &[]));
        assert!(
            std::fs::read(&merged).unwrap() == std::fs::read(&whole).unwrap(),
            "{filter}: the merged EXR differs"
        );
        // A part rendered under a box filter does not join them.
        let boxed = dir.join("boxed.exr");
        let extra = ["--tile", "0/3", "--samples-from", "0", "--samples-to", "2"];
        let box_args = ["render", scene, "-s", "6", "-r", "70", "50"];
        ok(run(box_args[0], &box_args[1..], &extra, &boxed));
        let mut mixed = parts.clone();
        mixed[0] = boxed;
        let o = merge(&mixed, &dir.join("mixed.exr"), &[]);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{filter}: parts of two filters merged"
        );
    }
}

/// Oracle: the single render. Sample-range splits into N = 1, 2, 3 and 7 ranges (of 13
/// samples, so ranges differ in length), alone and crossed with a 3-way tile split, merge
/// to its PNG and EXR byte for byte: pixel sums are exact, so their order does not matter.
#[test]
fn sample_splits_merge_to_the_single_render_byte_for_byte() {
    let dir = scratch("samples");
    let scene = lambertian();
    let mut args = vec!["render", scene.as_str(), "-s", "13", "--seed", "5"];
    args.extend(SMALL);
    let whole_png = dir.join("whole.png");
    let whole_exr = dir.join("whole.exr");
    ok(run(
        args[0],
        &args[1..],
        &["--exr", whole_exr.to_str().unwrap()],
        &whole_png,
    ));
    for (n, tiles) in [(1u32, 1u32), (2, 1), (3, 1), (7, 1), (2, 3)] {
        let mut parts = Vec::new();
        for t in 0..tiles {
            for k in 0..n {
                let (a, b) = (13 * k / n, 13 * (k + 1) / n);
                let p = dir.join(format!("s{a}-{b}-t{t}.exr"));
                let (from, to, tile) = (a.to_string(), b.to_string(), format!("{t}/{tiles}"));
                let extra = [
                    "--samples-from",
                    &from,
                    "--samples-to",
                    &to,
                    "--tile",
                    &tile,
                ];
                ok(run(args[0], &args[1..], &extra, &p));
                parts.push(p);
            }
        }
        let (png, exr) = (dir.join("merged.png"), dir.join("merged.exr"));
        ok(merge(&parts, &png, &["--exr", exr.to_str().unwrap()]));
        assert!(
            std::fs::read(&png).unwrap() == std::fs::read(&whole_png).unwrap(),
            "{n} sample ranges x {tiles} tile shares: the PNG differs"
        );
        assert!(
            std::fs::read(&exr).unwrap() == std::fs::read(&whole_exr).unwrap(),
            "{n} sample ranges x {tiles} tile shares: the EXR differs"
        );
    }
    // A part's `--stats` include the path integrator's share of time per stage.
    let o = ok(run(
        args[0],
        &args[1..],
        &["--tile", "1/3", "--stats"],
        &dir.join("stats.exr"),
    ));
    let err = String::from_utf8_lossy(&o.stderr);
    let stages = err.lines().find_map(|l| l.strip_prefix("stages: "));
    assert_eq!(stages.map(|s| s.split(", ").count()), Some(8), "{err}");
}

/// Oracle: the single Whitted render, bloom included (merge adds it after assembling, as
/// bloom spreads light across tiles): tile splits into 1, 2, 3 and 7 shares give its bytes.
#[test]
fn whitted_tile_splits_merge_to_the_single_render() {
    let dir = scratch("whitted");
    let args = [
        "cornell-box",
        "-r",
        "90",
        "70",
        "--enable",
        "bloom,multi-rays",
        "--spp",
        "2",
        "--bloom-threshold",
        "0.4",
    ];
    let whole = dir.join("whole.png");
    ok(run("raytrace", &args, &[], &whole));
    for n in [1u32, 2, 3, 7] {
        let parts: Vec<PathBuf> = (0..n)
            .map(|i| {
                let p = dir.join(format!("w{i}.exr"));
                ok(run("raytrace", &args, &["--tile", &format!("{i}/{n}")], &p));
                p
            })
            .collect();
        let out = dir.join("merged.png");
        ok(merge(&parts, &out, &[]));
        assert!(
            std::fs::read(&out).unwrap() == std::fs::read(&whole).unwrap(),
            "{n} Whitted tile shares differ from the single render"
        );
    }
}

/// Each bad set of parts: exit 2, a message naming the culprit, and the output left as it
/// was (absent here, or its old bytes).
#[test]
fn bad_part_sets_exit_2_and_write_nothing() {
    let dir = scratch("bad");
    let scene = lambertian();
    let part = |name: &str, extra: &[&str]| {
        let p = dir.join(name);
        let mut args = vec!["render", scene.as_str(), "-s", "4"];
        args.extend(SMALL);
        ok(run(args[0], &args[1..], extra, &p));
        p
    };
    let a = part("a.exr", &["--tile", "0/2"]);
    let b = part("b.exr", &["--tile", "1/2"]);
    let seed = part("seed.exr", &["--tile", "1/2", "--seed", "9"]);
    let cornell = {
        let p = dir.join("cornell.exr");
        ok(run(
            "render",
            &["-s", "4", "-r", "100", "70", "--tile", "1/2"],
            &[],
            &p,
        ));
        p
    };
    let three = part("three.exr", &["--tile", "1/3"]);
    let low = part("low.exr", &["--tile", "1/2", "--samples-to", "2"]);
    let high = part("high.exr", &["--tile", "1/2", "--samples-from", "1"]);
    let plain = dir.join("plain.exr");
    ok(run(
        "render",
        &["-s", "1", "-r", "100", "70", "--integrator", "normals"],
        &[],
        &plain,
    ));
    let bytes = std::fs::read(&b).unwrap();
    let truncated = dir.join("truncated.exr");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let flipped = dir.join("flipped.exr");
    let mut f = bytes.clone();
    let at = f.len() / 2;
    f[at..at + 16].fill(0xff);
    std::fs::write(&flipped, &f).unwrap();
    // A sample count the share cannot hold, in an otherwise valid file.
    let tampered = dir.join("tampered.exr");
    let mut reader = prism_image::TiledExrReader::open(&b).unwrap();
    let mut copy =
        prism_image::TiledExrWriter::new(std::io::Cursor::new(Vec::new()), &reader.header(), 32)
            .unwrap();
    let (across, down) = reader.tiles();
    for ty in 0..down {
        for tx in 0..across {
            if let Some(mut tile) = reader.read_tile(tx, ty).unwrap() {
                for (name, c) in &mut tile.channels {
                    if let (true, prism_image::ExrSamples::Uint(v)) = (name == "samples", c) {
                        if (tx, ty) == (1, 0) {
                            v[0] = 9;
                        }
                    }
                }
                copy.write_tile(tx, ty, &tile).unwrap();
            }
        }
    }
    std::fs::write(&tampered, copy.finish().unwrap().into_inner()).unwrap();
    let cases: Vec<(Vec<&PathBuf>, &str)> = vec![
        (vec![&a], "missing part: tiles 1/2, samples 0..4"),
        (vec![&a, &b, &b], "b.exr repeats tiles 1/2, samples 0..4 of"),
        (
            vec![&a, &low, &high],
            "high.exr repeats tiles 1/2, samples 1..2 of",
        ),
        (vec![&a, &low], "missing part: tiles 1/2, samples 2..4"),
        (vec![&a, &seed], "seed.exr: seed is 9, but"),
        (vec![&a, &cornell], "cornell.exr: scene is"),
        (
            vec![&a, &three],
            "three.exr: the tile share count is 3, but",
        ),
        (
            vec![&a, &plain],
            "plain.exr: expected a single-part tiled OpenEXR 2 file",
        ),
        (vec![&a, &truncated], "truncated.exr"),
        (vec![&a, &flipped], "flipped.exr"),
        (
            vec![&a, &tampered],
            "tampered.exr: corrupt: pixel (32, 0) holds 9 samples; its share takes 1 to 4",
        ),
    ];
    let out = dir.join("out.png");
    for (parts, message) in &cases {
        let parts: Vec<PathBuf> = parts.iter().map(|p| (*p).clone()).collect();
        let o = merge(&parts, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{parts:?}: {err}");
        assert!(
            err.contains(message),
            "{parts:?}: expected `{message}` in {err}"
        );
        assert!(!out.exists(), "{parts:?} wrote an output");
    }
    // An old output survives a refused merge.
    std::fs::write(&out, b"old").unwrap();
    assert_eq!(
        merge(std::slice::from_ref(&a), &out, &[]).status.code(),
        Some(2)
    );
    assert_eq!(std::fs::read(&out).unwrap(), b"old");
    // --allow-missing paints the holes magenta and says which shares are missing.
    let o = ok(merge(std::slice::from_ref(&a), &out, &["--allow-missing"]));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing tiles 1/2, samples 0..4"));
    let img = prism_image::read_png(&out).unwrap();
    assert_eq!(img.get(40, 0), [255, 0, 255, 255], "tile 1 is a hole");
    assert_ne!(img.get(0, 0), [255, 0, 255, 255], "tile 0 is rendered");
}

/// Split flags that cannot work are refused before rendering, with exit 2.
#[test]
fn impossible_splits_are_refused() {
    let dir = scratch("refused");
    let scene = lambertian();
    let cases: [(&[&str], &str, &str); 7] = [
        (
            &["--samples-to", "2", "--adaptive", "0.1"],
            "p.exr",
            "adaptive sampling decides per pixel",
        ),
        (&["--tile", "0/2"], "p.png", "a part file, an OpenEXR file"),
        (&["--tile", "2/2"], "p.exr", "expected I/N"),
        (
            &["--samples-from", "3", "--samples-to", "3"],
            "p.exr",
            "expected 0 <= FROM < TO",
        ),
        (
            &["--samples-to", "9"],
            "p.exr",
            "expected 0 <= FROM < TO <= --spp (4)",
        ),
        (
            &["--tile", "0/2", "--exr", "x.exr"],
            "p.exr",
            "--exr: a split render",
        ),
        (
            &["--tile", "0/4294967295", "-r", "64", "64"],
            "p.exr",
            "a 64x64 image has only 4 tiles of 32x32",
        ),
    ];
    for (extra, out, message) in cases {
        let out = dir.join(out);
        let o = run("render", &[scene.as_str(), "-s", "4"], extra, &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(
            err.contains(message),
            "{extra:?}: expected `{message}` in {err}"
        );
        assert!(!out.exists());
    }
    let o = run(
        "raytrace",
        &["--tile", "0/2", "--debug-pixel", "1,1"],
        &[],
        &dir.join("w.exr"),
    );
    assert_eq!(o.status.code(), Some(2));
}

/// A set of parts whose (common) identity prism cannot read, here an integrator no render
/// has, is refused with exit 2 naming the file, and writes nothing: it is not merged on
/// guesses about its bloom or encoding.
#[test]
fn parts_with_an_unreadable_identity_are_refused() {
    let dir = scratch("identity");
    let parts: Vec<PathBuf> = (0..2).map(|i| dir.join(format!("p{i}.exr"))).collect();
    for (i, part) in parts.iter().enumerate() {
        let tile = format!("{i}/2");
        ok(run(
            "render",
            &[&lambertian(), "-s", "2"],
            &[&SMALL[..], &["--tile", &tile]].concat(),
            part,
        ));
        let mut bytes = std::fs::read(part).unwrap();
        let key = b"prism.integrator\0string\0";
        let at = bytes
            .windows(key.len())
            .position(|w| w == key)
            .expect("the part records its integrator")
            + key.len()
            + 4;
        assert_eq!(&bytes[at..at + 4], b"path");
        bytes[at..at + 4].copy_from_slice(b"pith");
        std::fs::write(part, bytes).unwrap();
    }
    let out = dir.join("merged.png");
    let o = merge(&parts, &out, &[]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("p0.exr: the part's identity: setting integrator is `pith`"),
        "{err}"
    );
    assert!(!out.exists());
}
