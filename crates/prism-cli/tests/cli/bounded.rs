//! Bounded by design: every hostile input of the resource sweep, run under a 1 GiB
//! address-space limit (`ulimit -v`), exits 2 with a located message, writes nothing and
//! leaves its inputs as they were; legitimate inputs of the same shape still work.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Output;

use super::{prism, scratch, stderr};

/// Runs `prism ARGS` under a 1 GiB address-space limit: a command that tried to allocate
/// what a hostile input asks for would abort (exit by signal) instead of exiting 2.
fn bounded<S: AsRef<OsStr>>(dir: &Path, args: &[S]) -> Output {
    std::process::Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1048576 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_prism"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// The case's promise: exit 2, a message holding `expect`, no output written.
fn refused(what: &str, o: &Output, expect: &str, outputs: &[PathBuf]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    assert!(
        err.contains(expect),
        "{what}: expected {expect:?} in {err:?}"
    );
    assert!(!err.contains("panicked"), "{what}: {err}");
    for out in outputs {
        assert!(!out.exists(), "{what}: {} was written", out.display());
    }
}

/// A real 16 x 16 JPEG (about 600 bytes) whose frame header claims 4096 x 65535 pixels.
fn huge_jpeg() -> Vec<u8> {
    jpeg_claiming(4096, 65535)
}

/// A real 16 x 16 JPEG (about 600 bytes) whose frame header claims `width x height` pixels.
fn jpeg_claiming(width: u16, height: u16) -> Vec<u8> {
    let im = prism_image::Image::from_fn(16, 16, |x, y| [(x * 9) as u8, (y * 9) as u8, 77]);
    let mut bytes = prism_image::encode_jpeg(&im).unwrap();
    let sof = bytes.windows(2).position(|w| w == [0xff, 0xc0]).unwrap();
    bytes[sof + 5..sof + 7].copy_from_slice(&height.to_be_bytes());
    bytes[sof + 7..sof + 9].copy_from_slice(&width.to_be_bytes());
    bytes
}

/// A 16384 x 16384 one-bit grey PNG: a few hundred kilobytes, 1 GiB as RGBA.
fn huge_png() -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, 16384, 16384);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::One);
    enc.set_compression(png::Compression::Fast);
    let mut w = enc.write_header().unwrap();
    w.write_image_data(&vec![0u8; 16384 / 8 * 16384]).unwrap();
    w.finish().unwrap();
    out
}

/// A 1 x 1 OpenEXR of `channels` float channels whose data window is widened in place to
/// `width x height`.
fn exr_claiming(channels: &[&str], width: i32, height: i32) -> Vec<u8> {
    let layers = prism_image::ExrLayers {
        width: 1,
        height: 1,
        channels: channels
            .iter()
            .map(|c| (c.to_string(), prism_image::ExrSamples::Float(vec![1.0])))
            .collect(),
        attributes: Vec::new(),
    };
    let mut bytes = prism_image::encode_exr_layers(&layers);
    let at = bytes.windows(10).position(|w| w == b"dataWindow").unwrap() + 21;
    bytes[at + 8..at + 12].copy_from_slice(&(width - 1).to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&(height - 1).to_le_bytes());
    bytes
}

/// A triangle with texture coordinates and one material `m` from `m.mtl`.
const TRIANGLE: &str = "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
                        usemtl m\nf 1/1 2/2 3/3\n";

/// Small files that claim gigabytes: each decoder refuses them before allocating (the
/// sweep measured 8.5 GB, 5.4 GB, 6.4 GB, 10.5 GB and 2.4 GB for these).
#[test]
fn small_files_claiming_gigabytes_are_refused() {
    let dir = scratch("bounded-decode");
    std::fs::write(dir.join("huge.jpg"), huge_jpeg()).unwrap();
    std::fs::write(dir.join("huge.png"), huge_png()).unwrap();
    assert!(std::fs::metadata(dir.join("huge.png")).unwrap().len() < 1 << 20);
    std::fs::write(
        dir.join("sky.exr"),
        exr_claiming(&["B", "G", "R"], 16384, 8192),
    )
    .unwrap();
    let many: Vec<String> = (0..2000).map(|i| format!("c{i:04}")).collect();
    let many: Vec<&str> = many.iter().map(String::as_str).collect();
    std::fs::write(dir.join("many.exr"), exr_claiming(&many, 256, 512)).unwrap();
    std::fs::write(dir.join("scene.obj"), TRIANGLE).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl m\nKd 1 1 1\nmap_Kd huge.jpg\n").unwrap();
    let data = base64_png(&huge_png());
    std::fs::write(
        dir.join("image.svg"),
        format!(
            "<svg xmlns='http://www.w3.org/2000/svg' width='10' height='10'>\n\
             <image width='10' height='10' href='data:image/png;base64,{data}'/></svg>"
        ),
    )
    .unwrap();
    let out = dir.join("out.png");
    // Each command line, and what it says.
    let cases = [
        (
            "raytrace scene.obj -r 16 16 -o out.png",
            "m.mtl:3: material m: map_Kd huge.jpg: huge.jpg: a 4096x65535 image needs 2 GiB",
        ),
        (
            "shade scene.obj --shader texture --texture huge.jpg -o out.png",
            "huge.jpg: a 4096x65535 image needs",
        ),
        (
            "shade scene.obj --shader texture --texture huge.png -o out.png",
            "huge.png: a 16384x16384 image needs 2 GiB of memory, over the budget of 512 MiB",
        ),
        ("svg image.svg -o out.png", "a 16384x16384 image needs"),
        (
            "render -r 16 16 -s 1 --envmap sky.exr -o out.png",
            "sky.exr: a 16384x8192 image needs 1.5 GiB",
        ),
        (
            "render -r 16 16 -s 1 --envmap many.exr -o out.png",
            "many.exr: a 256x512 image needs 1000 MiB",
        ),
    ];
    for (line, expect) in cases {
        let args: Vec<&str> = line.split_whitespace().collect();
        let o = bounded(&dir, &args);
        refused(line, &o, expect, std::slice::from_ref(&out));
    }
    // The budget is a setting: a 2048 x 2048 texture (32 MiB as the decoder counts it)
    // draws under the default budget and is refused under a budget of 64 MiB (16 MiB an
    // image).
    let t = prism_image::Image::from_fn(2048, 2048, |x, y| [(x / 8) as u8, (y / 8) as u8, 99]);
    std::fs::write(dir.join("t.png"), prism_image::encode_png(&t).unwrap()).unwrap();
    let shade = [
        "shade",
        "scene.obj",
        "--shader",
        "texture",
        "--texture",
        "t.png",
    ];
    let o = bounded(
        &dir,
        &[&["--max-memory", "64M"], &shade[..], &["-o", "out.png"]].concat(),
    );
    refused(
        "--max-memory 64M",
        &o,
        "t.png: a 2048x2048 image needs 32 MiB of memory, over the budget of 16 MiB",
        std::slice::from_ref(&out),
    );
    let o = bounded(
        &dir,
        &[&shade[..], &["-o", "out.png", "-r", "32", "32"]].concat(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(out.exists());
}

fn base64_png(bytes: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// Devices and FIFOs are refused without reading (the sweep saw /dev/zero read to 2 GB and
/// 19 GB, and a FIFO hang every reader).
#[test]
fn only_regular_files_are_read() {
    let dir = scratch("bounded-files");
    for fifo in ["pipe.obj", "pipe.svg"] {
        let made = std::process::Command::new("mkfifo")
            .arg(dir.join(fifo))
            .status();
        assert!(made.unwrap().success());
    }
    let cases: [&[&str]; 7] = [
        &["merge", "-o", "x.png", "/dev/zero"],
        &["shade", "/dev/zero", "-o", "x.png"],
        &["svg", "/dev/zero", "-o", "x.png"],
        &["mesh", "info", "pipe.obj"],
        &["shade", "pipe.obj", "-o", "x.png"],
        &["svg", "pipe.svg", "-o", "x.png"],
        &["raytrace", "pipe.obj", "-o", "x.png"],
    ];
    for args in cases {
        let what = args.join(" ");
        let o = bounded(&dir, args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        assert!(
            err.contains("not a regular file") || err.contains("expected a"),
            "{what}: {err}"
        );
        assert!(!dir.join("x.png").exists(), "{what}: written");
    }
}

/// Flags that asked for terabytes or hung: refused, or clamped with a warning.
#[test]
fn flags_are_bounded() {
    let dir = scratch("bounded-flags");
    let out = dir.join("out.png");
    std::fs::write(dir.join("scene.obj"), TRIANGLE).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl m\nKd 1 0 0\n").unwrap();
    let cloth = prism_testkit::shared_asset("clothsim/scene/pinned2.json");
    let cloth = cloth.to_str().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (
            &["render", "-l", "4294967295"],
            "--light-samples: expected 1 to 65536, found 4294967295",
        ),
        (
            &["raytrace", "-r", "16384", "16384"],
            "--resolution 16384 16384: the image needs 29 GiB of memory, over the budget of \
             2 GiB (--max-memory raises it)",
        ),
        (
            &["render", "-r", "8192", "8192"],
            "--resolution 8192 8192: the image needs",
        ),
        (
            &[
                "--max-memory",
                "512M",
                "shade",
                "scene.obj",
                "-r",
                "16384",
                "16384",
            ],
            // 768 MiB of picture and one band a worker thread (a figure by machine).
            "--resolution 16384 16384: the image needs",
        ),
        (
            &[
                "--max-memory",
                "1G",
                "cloth",
                cloth,
                "--frames",
                "1",
                "-r",
                "16384",
                "16384",
            ],
            "--resolution 16384 16384: the image needs",
        ),
    ];
    for (args, expect) in cases {
        let o = bounded(&dir, &[args, &["-o", "out.png"]].concat());
        refused(&args.join(" "), &o, expect, std::slice::from_ref(&out));
    }
    let o = prism()
        .current_dir(&*dir)
        .args([
            "raytrace", "-r", "16", "16", "-t", "100000", "-o", "out.png",
        ])
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("--threads 100000: more than four a core; using"),
        "{err}"
    );
    assert!(out.exists());
}

/// An OBJ naming its MTL 10,000 times (the sweep: 7 GB and an abort) reads it once and
/// renders.
#[test]
fn a_library_named_many_times_is_read_once() {
    let dir = scratch("bounded-mtllib");
    let obj = TRIANGLE.replacen(
        "mtllib m.mtl",
        &format!("mtllib {}", ["m.mtl"; 10_000].join(" ")),
        1,
    );
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl m\nKd 1 0 0\n").unwrap();
    let o = bounded(
        &dir,
        &["raytrace", "scene.obj", "-r", "16", "16", "-o", "out.png"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(dir.join("out.png").exists());
}

/// No output replaces an input or another output (the sweep: each replaced silently,
/// exit 0): exit 2 before any work, the inputs byte for byte as they were.
#[test]
fn outputs_never_replace_inputs() {
    let dir = scratch("bounded-outputs");
    let run = |args: &[&str]| prism().current_dir(&*dir).args(args).output().unwrap();
    // Two real parts and an env map, a texture and a mesh to name.
    for i in 0..2 {
        let tile = format!("{i}/2");
        let part = format!("rt{i}.exr");
        let o = run(&["raytrace", "-r", "40", "40", "--tile", &tile, "-o", &part]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    std::fs::write(dir.join("env.exr"), exr_claiming(&["B", "G", "R"], 1, 1)).unwrap();
    let t = prism_image::Image::from_fn(4, 4, |x, y| [(x * 60) as u8, (y * 60) as u8, 9]);
    std::fs::write(dir.join("t.png"), prism_image::encode_png(&t).unwrap()).unwrap();
    std::fs::write(dir.join("scene.obj"), TRIANGLE).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl m\nKd 1 0 0\n").unwrap();
    std::fs::create_dir(dir.join("sub")).unwrap();
    let snapshot = || -> Vec<(String, Vec<u8>)> {
        ["rt0.exr", "rt1.exr", "env.exr", "t.png", "scene.obj"]
            .iter()
            .map(|f| (f.to_string(), std::fs::read(dir.join(f)).unwrap()))
            .collect()
    };
    std::os::unix::fs::symlink(dir.join("t.png"), dir.join("link.png")).unwrap();
    let before = snapshot();
    // Each command line, and what it says.
    let cases = [
        (
            "shade scene.obj --shader texture --texture t.png -o link.png",
            "--output link.png: it names --texture t.png, an input",
        ),
        (
            "merge -o rt0.exr rt0.exr rt1.exr",
            "--output rt0.exr: it names the part rt0.exr, an input",
        ),
        (
            "merge -o ./sub/../rt1.exr rt0.exr rt1.exr",
            "it names the part rt1.exr, an input",
        ),
        (
            "render -r 8 8 -e env.exr -o env.exr",
            "--output env.exr: it names --envmap env.exr, an input",
        ),
        (
            "shade scene.obj --shader texture --texture t.png -o t.png",
            "--output t.png: it names --texture t.png, an input",
        ),
        (
            "render -r 8 8 --adaptive 0.05 -o a.png --heatmap a.png",
            "--heatmap a.png: it names the same file as --output",
        ),
        (
            "raytrace scene.obj -r 8 8 -o a.exr --exr ./a.exr",
            "--exr ./a.exr: it names the same file as --output",
        ),
        (
            "mesh convert scene.obj -o scene.obj",
            "--output scene.obj: it names the mesh scene.obj, an input",
        ),
    ];
    for (line, expect) in cases {
        let args: Vec<&str> = line.split_whitespace().collect();
        let o = run(&args);
        refused(line, &o, expect, &[dir.join("a.png"), dir.join("a.exr")]);
        assert_eq!(snapshot(), before, "{line}: an input changed");
    }
}

/// Silently wrong pictures, now refused or right: env-map radiance of 2^55 or more (the sky
/// rendered black) is refused by texel; a luminance-only EXR env map lights the scene as
/// grey (it rendered black).
#[test]
fn env_maps_beyond_the_sums_or_grey_are_read_right() {
    let dir = scratch("bounded-envmap");
    let bright = prism_image::ExrLayers {
        width: 2,
        height: 1,
        channels: ["B", "G", "R"]
            .iter()
            .map(|c| {
                (
                    c.to_string(),
                    prism_image::ExrSamples::Float(vec![1.0, 2f32.powi(56)]),
                )
            })
            .collect(),
        attributes: Vec::new(),
    };
    std::fs::write(
        dir.join("bright.exr"),
        prism_image::encode_exr_layers(&bright),
    )
    .unwrap();
    let o = bounded(
        &dir,
        &[
            "render",
            "-r",
            "8",
            "8",
            "-s",
            "1",
            "-e",
            "bright.exr",
            "-o",
            "out.png",
        ],
    );
    refused(
        "2^56",
        &o,
        "--envmap bright.exr: texel (1, 0) is",
        &[dir.join("out.png")],
    );
    assert!(stderr(&o).contains("below 2^55"), "{}", stderr(&o));
    let grey = prism_image::ExrLayers {
        width: 4,
        height: 2,
        channels: vec![("Y".into(), prism_image::ExrSamples::Float(vec![0.5; 8]))],
        attributes: Vec::new(),
    };
    std::fs::write(dir.join("grey.exr"), prism_image::encode_exr_layers(&grey)).unwrap();
    let rgb = prism_image::ExrLayers {
        channels: ["B", "G", "R"]
            .iter()
            .map(|c| (c.to_string(), prism_image::ExrSamples::Float(vec![0.5; 8])))
            .collect(),
        ..grey.clone()
    };
    std::fs::write(dir.join("rgb.exr"), prism_image::encode_exr_layers(&rgb)).unwrap();
    // Oracle: the same map written as R = G = B renders the same bytes; both are lit.
    let scene = prism_testkit::shared_assets().join("meshedit/dae/teapot.dae");
    let mut pictures = Vec::new();
    for map in ["grey.exr", "rgb.exr"] {
        let out = dir.join(format!("{map}.png"));
        let o = prism()
            .current_dir(&*dir)
            .arg("render")
            .arg(&scene)
            .args(["-r", "24", "16", "-s", "2", "-e", map, "-o"])
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        pictures.push(prism_image::read_png(&out).unwrap());
    }
    assert_eq!(pictures[0], pictures[1]);
    assert!(
        pictures[0].pixels().iter().any(|p| p[0] > 0),
        "the grey sky renders black"
    );
}

/// Interrupted work leaves no hidden temporary: a cloth animation streaming into
/// `.anim.gif.PID.tmp` is stopped by SIGINT (exit 130) and by SIGTERM (exit 143), and
/// neither the temporary nor the animation remains.
#[test]
fn interrupted_writes_leave_no_temporaries() {
    let dir = scratch("bounded-signals");
    let scene = prism_testkit::shared_asset("clothsim/scene/pinned2.json");
    for (signal, code) in [("INT", 130), ("TERM", 143)] {
        let mut child = prism()
            .current_dir(&*dir)
            .arg("cloth")
            .arg(&scene)
            .args(["--frames", "5000", "-r", "64", "64", "-o", "anim.gif", "-q"])
            .spawn()
            .unwrap();
        let hidden = || {
            std::fs::read_dir(&*dir)
                .unwrap()
                .filter_map(|e| e.ok())
                .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
                .count()
        };
        let started = std::time::Instant::now();
        while hidden() == 0 {
            assert!(started.elapsed().as_secs() < 60, "no temporary appeared");
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let killed = std::process::Command::new("kill")
            .arg(format!("-{signal}"))
            .arg(child.id().to_string())
            .status()
            .unwrap();
        assert!(killed.success());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(code), "SIG{signal}");
        assert_eq!(hidden(), 0, "SIG{signal}: a temporary remains");
        assert!(!dir.join("anim.gif").exists());
    }
}

/// A frame folder shows one run: a shorter run removes the higher-numbered frames of a
/// longer one, and leaves every other file alone.
#[test]
fn frame_folders_hold_one_run() {
    let dir = scratch("bounded-frames");
    let scene = prism_testkit::shared_asset("clothsim/scene/pinned2.json");
    let run = |frames: &str| {
        let o = prism()
            .current_dir(&*dir)
            .arg("cloth")
            .arg(&scene)
            .args(["--frames", frames, "-r", "16", "16", "-o", "./", "-q"])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    };
    let frames = || {
        let mut names: Vec<String> = std::fs::read_dir(&*dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    run("6");
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    std::fs::write(dir.join("frame_12.png"), "not a frame of prism's").unwrap();
    run("3");
    assert_eq!(
        frames(),
        [
            "frame_0001.png",
            "frame_0002.png",
            "frame_0003.png",
            "frame_12.png",
            "notes.txt"
        ]
    );
}

/// A part file whose header claims 16384 x 16384 pixels (the sweep's crafted part took
/// 5.2 GB before it was refused) is refused as it is opened: the file is too short for the
/// tile table such an image has.
#[test]
fn crafted_parts_are_refused_before_merging() {
    let dir = scratch("bounded-parts");
    let o = prism()
        .current_dir(&*dir)
        .args(["raytrace", "-r", "16", "16", "--tile", "0/1", "-o", "p.exr"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mut bytes = std::fs::read(dir.join("p.exr")).unwrap();
    let at = bytes.windows(10).position(|w| w == b"dataWindow").unwrap() + 21;
    bytes[at + 8..at + 12].copy_from_slice(&16383i32.to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&16383i32.to_le_bytes());
    std::fs::write(dir.join("big.exr"), bytes).unwrap();
    let o = bounded(&dir, &["merge", "-o", "out.png", "big.exr"]);
    refused(
        "crafted part",
        &o,
        "big.exr: the file ends before its offset table",
        &[dir.join("out.png")],
    );
}

/// Six faces of a cube map are counted together: a 4096 x 4096 first face (decodable on
/// its own) means 2.3 GiB for six, refused before the other five are read; a face of
/// another size is refused naming it.
#[test]
fn cube_maps_are_counted_whole() {
    let dir = scratch("bounded-cube");
    std::fs::create_dir(dir.join("cube")).unwrap();
    let mut png = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut png, 4096, 4096);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::One);
        let mut w = enc.write_header().unwrap();
        w.write_image_data(&vec![0u8; 4096 / 8 * 4096]).unwrap();
    }
    std::fs::write(dir.join("cube/posx.png"), png).unwrap();
    std::fs::write(dir.join("scene.obj"), TRIANGLE).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl m\nKd 1 0 0\n").unwrap();
    let args = [
        "shade",
        "scene.obj",
        "--shader",
        "mirror",
        "--cubemap",
        "cube",
        "-o",
        "out.png",
    ];
    let o = bounded(&dir, &args);
    refused(
        "cube map",
        &o,
        "--cubemap: cube: the cube map of six 4096x4096 faces needs 2.3 GiB of memory",
        &[dir.join("out.png")],
    );
}

/// The extras' settings, from flags and from a config: out-of-range numbers, NaN
/// velocities, absurd sample counts, a switched-on environment without a map, missing and
/// huge maps, unknown meshes: each refused before rendering, exit 2, located, nothing
/// written.
#[test]
fn extras_settings_are_bounded() {
    let dir = scratch("bounded-extras");
    std::fs::write(dir.join("huge.png"), huge_png()).unwrap();
    let config = |name: &str, body: &str| {
        std::fs::write(
            dir.join(name),
            format!("scene = \"cornell_box\"\nwindow_size = [16, 16]\n{body}"),
        )
        .unwrap();
    };
    config("aperture.toml", "[extras]\ndof_aperture = -0.5\n");
    config("nan.toml", "[[motion]]\nmesh = 6\nvelocity = [nan, 0, 0]\n");
    config("samples.toml", "[extras]\nglossy_samples = 1000000\n");
    config("sky.toml", "[extras]\nenvironment_map = \"huge.png\"\n");
    config(
        "nomesh.toml",
        "[[motion]]\nmesh = \"nothing\"\nvelocity = [1, 0, 0]\n",
    );
    let out = dir.join("out.png");
    let cases: [(&[&str], &str); 12] = [
        (
            &["--dof-aperture", "-1"],
            "--dof-aperture: expected a number from 0",
        ),
        (
            &["--dof-focal-distance", "0"],
            "--dof-focal-distance: expected a number above 0",
        ),
        (
            &["--dof-samples", "0"],
            "--dof-samples: expected 1 to 4096 samples, found 0",
        ),
        (
            &["--glossy-samples", "99999999"],
            "--glossy-samples: expected 1 to 4096 samples",
        ),
        (
            &["--motion", "6=nan,0,0"],
            "--motion 6=nan,0,0: expected MESH=VX,VY,VZ",
        ),
        (
            &["--motion", "chair=1,0,0"],
            "--motion chair=1,0,0: no such mesh (the scene's meshes: 0 \"floor\"",
        ),
        (
            &["--enable", "env-map"],
            "env-map is on, but no environment map is given",
        ),
        (&["--environment-map", "missing.exr"], "missing.exr"),
        (
            &["--environment-map", "huge.png"],
            "huge.png: a 16384x16384 image needs",
        ),
        (
            &["aperture.toml"],
            "aperture.toml:4: dof_aperture: expected a number from 0",
        ),
        (
            &["nan.toml"],
            "nan.toml:5: velocity: expected a finite number",
        ),
        (
            &["samples.toml"],
            "samples.toml:4: glossy_samples: expected 1 to 4096 samples",
        ),
    ];
    for (args, expect) in cases {
        let scene: &[&str] = if args[0].ends_with(".toml") {
            &[]
        } else {
            &["cornell-box", "-r", "16", "16"]
        };
        let line = [&["raytrace"], scene, args, &["-o", "out.png"]].concat();
        let o = bounded(&dir, &line);
        refused(&line.join(" "), &o, expect, std::slice::from_ref(&out));
    }
    for (file, expect) in [
        ("sky.toml", "sky.toml:4: environment_map: "),
        (
            "nomesh.toml",
            "nomesh.toml:3: [[motion]] mesh \"nothing\": no such mesh",
        ),
    ] {
        let o = bounded(&dir, &["raytrace", file, "-o", "out.png"]);
        refused(file, &o, expect, std::slice::from_ref(&out));
    }
    let o = bounded(&dir, &["raytrace", "sky.toml", "-o", "out.png"]);
    assert!(
        stderr(&o).contains("a 16384x16384 image needs"),
        "{}",
        stderr(&o)
    );
    // A 600-byte JPEG claiming 60000 x 60000 pixels, /dev/zero and a FIFO as the map:
    // refused before reading or allocating.
    std::fs::write(dir.join("claims.jpg"), jpeg_claiming(60000, 60000)).unwrap();
    let fifo = dir.join("fifo.png");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    let mut maps = vec![
        ("claims.jpg", "claims.jpg: a 60000x60000 image needs"),
        ("/dev/zero", "/dev/zero: not a regular file"),
    ];
    if made.is_ok_and(|s| s.success()) {
        maps.push(("fifo.png", "fifo.png: not a regular file"));
    }
    for (map, expect) in maps {
        let line = [
            "raytrace",
            "cornell-box",
            "-r",
            "16",
            "16",
            "--environment-map",
            map,
        ];
        let o = bounded(&dir, &[&line[..], &["-o", "out.png"]].concat());
        refused(map, &o, expect, std::slice::from_ref(&out));
    }
    // The picture never replaces the environment map, named by a flag or by the config.
    let sky = prism_image::Image::from_fn(4, 2, |x, _| [(x * 60) as u8, 90, 200]);
    prism_image::write_png(&dir.join("sky.png"), &sky).unwrap();
    let before = std::fs::read(dir.join("sky.png")).unwrap();
    config("mapped.toml", "[extras]\nenvironment_map = \"sky.png\"\n");
    for line in [
        "raytrace cornell-box -r 16 16 --environment-map sky.png -o sky.png",
        "raytrace mapped.toml -o sky.png",
    ] {
        let args: Vec<&str> = line.split_whitespace().collect();
        let o = bounded(&dir, &args);
        refused(
            line,
            &o,
            "--output sky.png: it names the environment map",
            &[],
        );
        assert_eq!(
            std::fs::read(dir.join("sky.png")).unwrap(),
            before,
            "{line}"
        );
    }
}
