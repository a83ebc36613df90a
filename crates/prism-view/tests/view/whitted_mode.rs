//! The Whitted mode driven headlessly: its picture against the batch ray tracer, a click's
//! ray tree against `trace_pixel`, and what drags, feature keys and BVH keys do.

use prism_render::whitted::film::{raytrace, trace_pixel, RaytraceOptions};
use prism_render::whitted::scene::WhittedScene;
use prism_render::whitted::tracer::WhittedSettings;
use prism_scene::{Features, OrbitCamera, Preset};
use prism_view::{Input, Key, Viewer, WhittedMode};

fn key(c: char) -> Input {
    Input::Key {
        key: Key::Char(c),
        ctrl: false,
    }
}

fn viewer() -> (Viewer, prism_scene::Scene) {
    let scene = Preset::from_name("cornell-box").unwrap().load(&[]).unwrap();
    let mode = WhittedMode::new(
        scene.clone(),
        "cornell-box",
        OrbitCamera::default(),
        Features::prism_defaults(),
    );
    (Viewer::new(Box::new(mode), 80, 60), scene)
}

fn options() -> RaytraceOptions {
    RaytraceOptions {
        width: 80,
        height: 60,
        settings: WhittedSettings {
            features: Features::prism_defaults(),
            light_samples: 16,
            max_depth: 3,
            extras: prism_scene::Extras::default(),
        },
        spp: 16,
        bloom: prism_image::Bloom::default(),
        seed: 0,
    }
}

/// Oracle: the batch ray tracer (`prism raytrace`'s image) and `trace_pixel`. The picture is
/// the ray tracer's; a click traces the pixel under the cursor and draws its rays over the
/// dimmed picture; `X` clears them.
#[test]
fn picture_and_click_are_the_ray_tracers() {
    let (mut v, scene) = viewer();
    let ws = WhittedScene::new(&scene, true);
    let batch = raytrace(&ws, &OrbitCamera::default(), &options(), &|_| {});
    let plain = v.picture().clone();
    assert_eq!(plain, batch.image.to_rgb8_truncated());
    v.input(Input::Cursor { x: 40.5, y: 30.5 });
    v.input(Input::Button(true));
    assert!(v.input(Input::Button(false)));
    let expected = trace_pixel(&ws, &OrbitCamera::default(), &options(), 40, 30);
    let m = v.message().unwrap().to_string();
    assert_eq!(m, format!("pixel (40, 30): {} rays", expected.rays.len()));
    assert!(expected.rays.len() > 2);
    assert_ne!(v.picture(), &plain);
    v.input(key('x'));
    assert_eq!(v.picture(), &plain);
}

/// A drag orbits the camera and is not a click; `1` turns shading off (the picture
/// changes) and says so; `]` and `[` step the BVH level, `.` the leaf; with the BVH off
/// they say so.
#[test]
fn drags_features_and_bvh_keys() {
    let (mut v, _) = viewer();
    let before = v.picture().clone();
    v.input(Input::Cursor { x: 10.0, y: 10.0 });
    v.input(Input::Button(true));
    assert!(v.input(Input::Cursor { x: 30.0, y: 10.0 }));
    v.input(Input::Button(false));
    assert_eq!(v.message(), None, "a drag is not a click");
    assert_ne!(v.picture(), &before);
    v.input(key('r'));
    assert_eq!(v.picture(), &before);
    v.input(key('1'));
    assert_eq!(v.message(), Some("shading off"));
    assert!(!v.mode().status().starts_with("shading"));
    assert_ne!(v.picture(), &before);
    v.input(key('1'));
    v.input(key(']'));
    v.input(key(']'));
    assert!(v.mode().status().ends_with("BVH level 1 leaf -"));
    v.input(key('.'));
    assert!(v.mode().status().ends_with("BVH level 1 leaf 0"));
    assert_ne!(v.picture(), &before);
    for _ in 0..3 {
        v.input(key('['));
    }
    assert!(v.mode().status().ends_with("BVH level - leaf 0"));
    v.input(key('8'));
    v.input(key(']'));
    assert_eq!(v.message(), Some("the BVH is off (8 turns it on)"));
}
