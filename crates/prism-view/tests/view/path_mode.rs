//! The path-tracing mode driven headlessly: its progressive picture against the batch
//! renderer, and what orbiting, bounce keys and the heat map do to its state.

use std::path::Path;

use prism_render::film::FilmSettings;
use prism_render::render::{render, RenderOptions};
use prism_render::render_scene::RenderScene;
use prism_view::{Input, Key, Mode, PathMode, Viewer};

fn key(c: char) -> Input {
    Input::Key {
        key: Key::Char(c),
        ctrl: false,
    }
}

/// Oracle: `prism render -s 4` of the same scene and seed. Four progressive passes add up,
/// exactly, to its image.
#[test]
fn progressive_passes_are_the_batch_render() {
    let scene = prism_scene::cornell_box();
    let mut mode = PathMode::new(&scene, Path::new("cornell"), 7);
    for _ in 0..3 {
        mode.draw(64, 48);
    }
    let picture = mode.draw(64, 48);
    assert_eq!(mode.passes(), 4);
    let opts = RenderOptions {
        film: FilmSettings {
            width: 64,
            height: 48,
            spp: 4,
            seed: 7,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    };
    let batch = render(&RenderScene::new(&scene), &opts, &|_| {});
    assert_eq!(picture, batch.image.linear_to_srgb8());
}

/// Oracle: `prism render --adaptive 0.05 --batch 32 -s 64`. With `A`, 64 progressive passes
/// stop the same pixels after 32 samples and give the same sums, sample counts and picture.
#[test]
fn adaptive_passes_are_the_adaptive_render() {
    let scene = prism_scene::cornell_box();
    let mut mode = PathMode::new(&scene, Path::new("cornell"), 3);
    mode.input(&key('a'), (40, 30));
    mode.input(&key('m'), (40, 30));
    let mut picture = mode.draw(40, 30);
    for _ in 1..64 {
        picture = mode.draw(40, 30);
    }
    let opts = RenderOptions {
        film: FilmSettings {
            width: 40,
            height: 30,
            spp: 64,
            seed: 3,
            adaptive: Some(0.05),
            batch: 32,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    };
    let batch = render(&RenderScene::new(&scene), &opts, &|_| {});
    let counts = mode.sums().unwrap().map(|s| s.n);
    assert_eq!(counts, batch.samples);
    assert!(counts.pixels().contains(&32), "some pixels stopped early");
    assert!(counts.pixels().contains(&64));
    assert_eq!(picture, batch.image.linear_to_srgb8());
    assert!(!mode.busy() || mode.passes() < 4096);
}

/// Dragging orbits the camera about its target (same distance, new eye) and restarts; the
/// wheel moves it closer; `2` keeps the second bounce, `0` all; `A` turns adaptive sampling
/// on and shows its heat map (restarting), `M` the picture again; `R` puts the camera back.
#[test]
fn orbit_bounces_heat_map_and_reset() {
    let scene = prism_scene::cornell_box();
    let base = scene.camera;
    let mut v = Viewer::new(Box::new(PathMode::new(&scene, Path::new("c"), 0)), 48, 32);
    v.picture();
    v.picture();
    assert!(v.mode().status().starts_with("2 spp"));
    assert!(v.busy());
    v.input(Input::Cursor { x: 10.0, y: 10.0 });
    v.input(Input::Button(true));
    assert!(v.input(Input::Cursor { x: 20.0, y: 12.0 }));
    v.input(Input::Button(false));
    v.picture();
    assert!(
        v.mode().status().starts_with("1 spp"),
        "{}",
        v.mode().status()
    );
    v.input(key('2'));
    v.picture();
    assert!(v.mode().status().contains("bounce 2 only"));
    v.input(key('0'));
    v.picture();
    assert!(v.mode().status().contains("all bounces"));
    let plain = v.picture().clone();
    v.input(key('a'));
    let map = v.picture().clone();
    assert!(v.mode().status().contains("adaptive"));
    assert!(v.mode().status().contains("heat map"));
    assert!(
        v.mode().status().starts_with("1 spp"),
        "adaptive sampling restarts"
    );
    assert_ne!(plain, map);
    v.input(key('m'));
    assert!(!v.mode().status().contains("heat map"));

    let mut mode = PathMode::new(&scene, Path::new("c"), 0);
    mode.input(&Input::Cursor { x: 0.0, y: 0.0 }, (48, 32));
    mode.input(&Input::Button(true), (48, 32));
    mode.input(&Input::Cursor { x: 12.0, y: 0.0 }, (48, 32));
    let turned = mode.camera();
    let d0 = (base.eye - base.target).length();
    let d1 = (turned.eye - turned.target).length();
    assert!((d0 - d1).abs() < 1e-4 * d0);
    assert!((turned.eye - base.eye).length() > 1e-3 * d0);
    mode.input(&Input::Wheel(3.0), (48, 32));
    assert!((mode.camera().eye - base.target).length() < d0);
    mode.input(&key('r'), (48, 32));
    assert_eq!(mode.camera(), base);
}
