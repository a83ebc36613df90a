//! Split renders in the library: shares partition the tiles, part files read back what was
//! written, part data that contradicts its share is refused, and merging equals the whole
//! render whatever the order of the parts.

use std::path::PathBuf;

use prism_image::ExrSamples;
use prism_render::film::{tile_of, tiles, FilmSettings, Share};
use prism_render::parts::{merge, Part, PartError, PartFile, PartIdentity};
use prism_render::render::{render_share, Job, RenderOptions};
use prism_render::render_scene::RenderScene;

fn options() -> RenderOptions {
    RenderOptions {
        film: FilmSettings {
            width: 75,
            height: 40,
            spp: 5,
            seed: 11,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    }
}

fn identity(opts: &RenderOptions) -> Vec<(String, String)> {
    [
        ("kind", "render".to_string()),
        ("width", opts.film.width.to_string()),
        ("height", opts.film.height.to_string()),
        ("spp", opts.film.spp.to_string()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect()
}

/// Property: for every tile count and share count, each tile is in exactly one share, the
/// shares' tile counts differ by at most one, and `tile_of` finds each pixel's tile.
#[test]
fn shares_partition_the_tiles_evenly() {
    for (w, h) in [(1, 1), (31, 33), (100, 70), (512, 384)] {
        let all = tiles(w, h);
        for (k, &(x0, y0)) in all.iter().enumerate() {
            assert_eq!(tile_of(x0, y0, w), k);
            assert_eq!(tile_of((x0 + 31).min(w - 1), (y0 + 31).min(h - 1), w), k);
        }
        for n in 1..=9u32 {
            let counts: Vec<usize> = (0..n)
                .map(|part| {
                    let s = Share {
                        part,
                        parts: n,
                        samples: 0..1,
                    };
                    (0..all.len()).filter(|&k| s.has_tile(k)).count()
                })
                .collect();
            assert_eq!(counts.iter().sum::<usize>(), all.len());
            let (lo, hi) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
            assert!(hi - lo <= 1, "{w}x{h} in {n}: {counts:?}");
        }
    }
}

/// Oracle: the whole render's sums. Three tile shares, each split in two sample ranges,
/// written to part files and read back, merge (in any order) to the whole render's sample
/// counts and exact radiance sums.
#[test]
fn parts_round_trip_and_merge_to_the_whole_render() {
    let scene = RenderScene::new(&prism_scene::cornell_box());
    let opts = options();
    let whole = render_share(
        &scene,
        &opts,
        &Job::share(&Share::whole(opts.film.spp)),
        &|_| {},
    );
    let dir = std::env::temp_dir().join(format!("prism-parts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut parts = Vec::new();
    for part in 0..3 {
        for samples in [0..2, 2..5] {
            let share = Share {
                part,
                parts: 3,
                samples,
            };
            let sums = render_share(&scene, &opts, &Job::share(&share), &|_| {});
            let p = Part::new(identity(&opts), share, sums);
            let file = dir.join(format!("p{part}-{}.exr", p.header.share.samples.start));
            p.write(&file).unwrap();
            let back = Part::read(&file).unwrap();
            assert_eq!(back.header, p.header);
            for (a, b) in back.sums.pixels().iter().zip(p.sums.pixels()) {
                assert_eq!((a.sum, a.n), (b.sum, b.n));
                assert_eq!(a.moment1, f64::from(b.moment1 as f32));
            }
            parts.push(PartFile::open(&file).unwrap());
        }
    }
    let forward = merge(&mut parts, false).unwrap();
    parts.reverse();
    let backward = merge(&mut parts, false).unwrap();
    assert!(forward.holes.is_empty());
    for ((f, b), w) in forward
        .sums
        .pixels()
        .iter()
        .zip(backward.sums.pixels())
        .zip(whole.pixels())
    {
        assert_eq!((f.sum, f.n), (b.sum, b.n), "the order of the parts matters");
        assert_eq!((f.sum, f.n), (w.sum, w.n));
        assert_eq!(f.mean(), w.mean());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A part whose pixel data contradicts its share is refused, naming the pixel: data in a
/// tile outside the share, a pixel of the share with no samples, more samples than its
/// range holds, a sum that is not finite.
#[test]
fn part_data_must_fit_the_share() {
    let scene = RenderScene::new(&prism_scene::cornell_box());
    let opts = options();
    let share = Share {
        part: 1,
        parts: 2,
        samples: 1..3,
    };
    let sums = render_share(&scene, &opts, &Job::share(&share), &|_| {});
    let good = Part::new(identity(&opts), share, sums).to_exr();
    let file = PathBuf::from("p.exr");
    assert!(Part::from_exr(&good, &file).is_ok());
    let set = |name: &str, x: usize, value: f32| {
        let mut l = good.clone();
        for (n, c) in &mut l.channels {
            match c {
                ExrSamples::Float(v) if n == name => v[x] = value,
                ExrSamples::Uint(v) if n == name => v[x] = value as u32,
                _ => {}
            }
        }
        Part::from_exr(&l, &file)
    };
    // Pixel 0 is in tile 0 (share 0); pixel 40 in tile 1 (share 1).
    let cases = [
        (
            "sum.G.w1",
            0,
            5.0,
            "pixel (0, 0) holds data, but its tile is not in share 1/2",
        ),
        (
            "samples",
            40,
            0.0,
            "pixel (40, 0) holds 0 samples; its share takes 1 to 2",
        ),
        ("samples", 40, 3.0, "pixel (40, 0) holds 3 samples"),
        (
            "Y.sum",
            40,
            f32::NAN,
            "pixel (40, 0) holds a moment that is not finite",
        ),
    ];
    for (channel, x, value, message) in cases {
        match set(channel, x, value) {
            Err(e @ PartError::Corrupt { .. }) => {
                assert!(e.to_string().contains(message), "{e}");
            }
            Err(e) => panic!("{channel}[{x}] = {value}: {e}"),
            Ok(_) => panic!("{channel}[{x}] = {value} was accepted"),
        }
    }
    let mut l = good.clone();
    l.attributes.retain(|(k, _)| k != "prism.spp");
    assert!(matches!(
        Part::from_exr(&l, &file),
        Err(PartError::NotAPart { .. })
    ));
    // A sample range past spp, and more shares than the 75x40 image's 6 tiles (a header
    // that would have a merge loop over billions of shares).
    for (key, value) in [("prism.samples", "1..9"), ("prism.part", "1/7")] {
        let mut l = good.clone();
        for (k, v) in &mut l.attributes {
            if k == key {
                *v = value.into();
            }
        }
        assert!(matches!(
            Part::from_exr(&l, &file),
            Err(PartError::BadAttribute { .. })
        ));
    }
}

/// Two crafted parts, each valid alone, whose exact sums overflow 128 bits when added: the
/// merge refuses them, naming the part and the pixel, rather than wrapping to a negative
/// radiance.
#[test]
fn sums_that_overflow_are_refused() {
    let opts = RenderOptions {
        film: FilmSettings {
            width: 2,
            height: 1,
            spp: 2,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    };
    let dir = std::env::temp_dir().join(format!("prism-overflow-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut parts = Vec::new();
    for samples in [0..1, 1..2] {
        let start = samples.start;
        let share = Share {
            part: 0,
            parts: 1,
            samples,
        };
        let mut sums = prism_image::Image::new(2, 1, prism_render::film::PixelSum::default());
        for p in sums.pixels_mut() {
            p.n = 1;
            p.sum = [prism_math::ExactSum(i128::MAX / 2 + 1); 3];
        }
        let file = dir.join(format!("o{start}.exr"));
        Part::new(identity(&opts), share, sums)
            .write(&file)
            .unwrap();
        parts.push(PartFile::open(&file).unwrap());
    }
    let e = merge(&mut parts, false).unwrap_err();
    assert!(
        matches!(&e, PartError::Corrupt { file, x: 0, y: 0, .. } if file.ends_with("o1.exr")),
        "{e}"
    );
    assert!(e.to_string().contains("overflow"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Oracle: the identity given. A render's [`PartIdentity`], written into a part file and
/// merged, reads back as the same value.
#[test]
fn identity_survives_the_part_file() {
    let cornell = prism_scene::cornell_box();
    let scene = RenderScene::new(&cornell);
    let opts = options();
    let id = PartIdentity::path(cornell.fingerprint(), &opts);
    let share = Share::whole(opts.film.spp);
    let sums = render_share(&scene, &opts, &Job::share(&share), &|_| {});
    let dir = std::env::temp_dir().join(format!("prism-identity-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("whole.exr");
    Part::new(id.to_attributes(), share, sums)
        .write(&file)
        .unwrap();
    let merged = merge(&mut [PartFile::open(&file).unwrap()], false).unwrap();
    assert_eq!(PartIdentity::from_attributes(&merged.identity), Ok(id));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Property: a render told to stop before it starts takes no samples; one told to stop after
/// its first tile keeps that tile's samples exactly and leaves the others empty; one never
/// told equals `render`.
#[test]
fn a_stopped_render_ends_early_and_keeps_what_it_took() {
    use prism_render::render::{render, render_until, Controls};
    use std::sync::atomic::{AtomicBool, Ordering};
    let scene = RenderScene::new(&prism_scene::cornell_box());
    let opts = options();
    let stopping = |stop| Controls {
        stop: Some(stop),
        camera: None,
    };
    let (stopped, never) = (AtomicBool::new(true), AtomicBool::new(false));
    let none = render_until(&scene, &opts, stopping(&stopped), &|_| {});
    assert_eq!(none.total_samples, 0);
    let whole = render(&scene, &opts, &|_| {});
    let running = AtomicBool::new(false);
    let early = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| {
            render_until(&scene, &opts, stopping(&running), &|_| {
                running.store(true, Ordering::Relaxed)
            })
        });
    assert!(early.total_samples > 0 && early.total_samples < whole.total_samples);
    for (a, b) in early.samples.pixels().iter().zip(whole.samples.pixels()) {
        assert!(*a == 0 || a == b);
    }
    let same = render_until(&scene, &opts, stopping(&never), &|_| {});
    assert_eq!(same.image.pixels(), whole.image.pixels());
}
