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

/// Oracle: the batch ray tracer at half and at full resolution. While the camera moves the
/// picture is the half-width, half-height render with each pixel drawn as a 2 x 2 block,
/// and the mode stays busy; once the camera has rested, the next frame is the full render
/// from the new camera and the mode is idle. Keys draw at full resolution at once.
#[test]
fn orbiting_previews_at_half_resolution_then_refines() {
    let scene = Preset::from_name("cornell-box").unwrap().load(&[]).unwrap();
    let camera = OrbitCamera::default();
    let mode = WhittedMode::new(
        scene.clone(),
        "cornell-box",
        camera,
        Features::prism_defaults(),
    );
    // A rest of a whole day: the preview stays until asked.
    let mode = mode.with_rest(std::time::Duration::from_secs(86_400));
    let mut v = Viewer::new(Box::new(mode), 80, 60);
    let ws = WhittedScene::new(&scene, true);
    v.picture();
    v.input(Input::Cursor { x: 10.0, y: 10.0 });
    v.input(Input::Button(true));
    v.input(Input::Cursor { x: 30.0, y: 14.0 });
    // The drag's camera: 180 degrees across the window's width.
    let per_pixel = 180.0 / 80.0;
    let moved = OrbitCamera {
        rotation: prism_math::Vec3::new(
            camera.rotation.x + 4.0 * per_pixel,
            camera.rotation.y - 20.0 * per_pixel,
            0.0,
        ),
        ..camera
    };
    let half = RaytraceOptions {
        width: 40,
        height: 30,
        ..options()
    };
    let small = raytrace(&ws, &moved, &half, &|_| {})
        .image
        .to_rgb8_truncated();
    let preview = v.picture().clone();
    assert_eq!((preview.width(), preview.height()), (80, 60));
    for y in 0..60 {
        for x in 0..80 {
            assert_eq!(preview.get(x, y), small.get(x / 2, y / 2), "pixel {x},{y}");
        }
    }
    assert!(v.busy());
    // Still moving: the preview holds.
    assert_eq!(v.picture(), &preview);
    v.input(Input::Button(false));
    // A key draws at full resolution at once.
    v.input(key('1'));
    v.input(key('1'));
    let full = raytrace(&ws, &moved, &options(), &|_| {})
        .image
        .to_rgb8_truncated();
    assert_eq!(v.picture(), &full);
    assert!(!v.busy());
    // With no rest to wait for, the first frame after the motion is refined.
    let mode = WhittedMode::new(scene, "cornell-box", camera, Features::prism_defaults())
        .with_rest(std::time::Duration::ZERO);
    let mut v = Viewer::new(Box::new(mode), 80, 60);
    v.input(Input::Cursor { x: 10.0, y: 10.0 });
    v.input(Input::Button(true));
    v.input(Input::Cursor { x: 30.0, y: 14.0 });
    assert_eq!(v.picture(), &preview);
    assert!(v.busy());
    assert_eq!(v.picture(), &full);
    assert!(!v.busy());
}

/// Oracle: the batch ray tracer on the same scene setup. A config's extras reach the window:
/// with environment mapping on, misses show the map; with the tall box moving and motion
/// blur on, the picture is the motion-blurred render.
#[test]
fn a_configs_extras_reach_the_window() {
    use prism_render::whitted::scene::{Environment, SceneSetup, Split};
    let scene = Preset::from_name("cornell-box").unwrap().load(&[]).unwrap();
    let sky = prism_image::Image::from_fn(8, 4, |x, y| {
        prism_math::Rgb::new(x as f32 / 8.0, y as f32 / 4.0, 0.7)
    });
    let features = Features {
        environment_mapping: true,
        motion_blur: true,
        ..Features::prism_defaults()
    };
    let extras = prism_scene::Extras {
        motion_samples: 3,
        environment_strength: 0.5,
        ..prism_scene::Extras::default()
    };
    let motion = vec![(6, prism_math::Vec3::new(0.3, 0.0, 0.0))];
    let mode = WhittedMode::new(
        scene.clone(),
        "cornell-box",
        OrbitCamera::default(),
        features,
    )
    .with_extras(
        extras,
        motion.clone(),
        Some(std::sync::Arc::new(sky.clone())),
    );
    let mut v = Viewer::new(Box::new(mode), 80, 60);
    let ws = WhittedScene::prepare(
        &scene,
        SceneSetup {
            bvh: Some(Split::Sah),
            motion,
            environment: Some(Environment::new(sky, 0.5)),
        },
    );
    let mut o = options();
    o.settings.features = features;
    o.settings.extras = extras;
    let want = raytrace(&ws, &OrbitCamera::default(), &o, &|_| {});
    assert_eq!(v.picture(), &want.image.to_rgb8_truncated());
    // The corners look past the box at the map.
    assert_ne!(v.picture().get(0, 0), [0, 0, 0]);
    // E turns the map off: misses are black; E again brings it back.
    v.input(key('e'));
    assert_eq!(v.message(), Some("env-map off"));
    assert_eq!(v.picture().get(0, 0), [0, 0, 0]);
    v.input(key('e'));
    assert_eq!(v.picture(), &want.image.to_rgb8_truncated());
    // B stops the motion: the picture is the still render's.
    v.input(key('b'));
    assert_eq!(v.message(), Some("motion-blur off"));
    let still = WhittedScene::prepare(
        &scene,
        SceneSetup {
            bvh: Some(Split::Sah),
            motion: Vec::new(),
            environment: Some(Environment::new(
                prism_image::Image::from_fn(8, 4, |x, y| {
                    prism_math::Rgb::new(x as f32 / 8.0, y as f32 / 4.0, 0.7)
                }),
                0.5,
            )),
        },
    );
    o.settings.features.motion_blur = false;
    let want = raytrace(&still, &OrbitCamera::default(), &o, &|_| {});
    assert_eq!(v.picture(), &want.image.to_rgb8_truncated());
    // G, D, P and A switch the other extras, each saying so.
    for (k, name) in [('g', "glossy"), ('d', "dof"), ('p', "mipmap"), ('a', "sah")] {
        v.input(key(k));
        let on = if name == "sah" { "off" } else { "on" };
        assert_eq!(v.message(), Some(format!("{name} {on}").as_str()));
    }
    assert!(v.mode().status().contains("glossy"));
}
