//! The Whitted ray tracer against independent truths: closed forms of its shading rules,
//! properties its sampling must have, brute force against the BVH, thread counts, and owned
//! golden images of every preset and every feature switch.

use std::path::PathBuf;

use prism_image::Bloom;
use prism_math::{Ray, Rgb, Vec3};
use prism_render::whitted::film::{raytrace, trace_pixel, RaytraceOptions};
use prism_render::whitted::scene::WhittedScene;
use prism_render::whitted::shading::{parallelogram_color, phong};
use prism_render::whitted::tracer::{RayKind, WhittedSettings};
use prism_scene::{Features, Light, Material, OrbitCamera, Preset, Scene, Shading, TriangleMesh};

pub(super) fn all_on() -> Features {
    Features::prism_defaults()
}

pub(super) fn options(w: u32, h: u32, features: Features) -> RaytraceOptions {
    RaytraceOptions {
        width: w,
        height: h,
        settings: WhittedSettings {
            features,
            light_samples: 16,
            max_depth: 3,
            extras: prism_scene::Extras::default(),
        },
        spp: 4,
        bloom: Bloom::default(),
        seed: 0,
    }
}

pub(super) fn phong_material(kd: Rgb, ks: Rgb) -> Material {
    Material::Phong {
        kd,
        ks,
        shininess: 1.0,
        kd_texture: None,
        transparency: 1.0,
    }
}

/// A scene of the given triangles (flat normals unless given) with one material.
pub(super) fn triangles(tris: &[[Vec3; 3]], material: Material, lights: Vec<Light>) -> Scene {
    let mut positions = Vec::new();
    let mut idx = Vec::new();
    for t in tris {
        let base = positions.len() as u32;
        positions.extend_from_slice(t);
        idx.push([base, base + 1, base + 2]);
    }
    Scene {
        meshes: vec![TriangleMesh {
            name: "m".into(),
            positions,
            triangles: idx,
            shading: Shading::Flat,
            material: 0,
            uvs: None,
        }],
        spheres: vec![],
        materials: vec![material],
        material_names: vec!["m".into()],
        one_sided: vec![],
        lights,
        camera: OrbitCamera::default().to_camera(1.0),
        warnings: vec![],
    }
}

/// The camera on the -z axis at distance 3, looking along +z at the origin.
pub(super) fn head_on() -> OrbitCamera {
    OrbitCamera {
        rotation: Vec3::ZERO,
        ..OrbitCamera::default()
    }
}

/// A floor at y = 0 spanning [-5, 5]^2, facing up.
pub(super) fn floor() -> [[Vec3; 3]; 2] {
    let p = |x: f32, z: f32| Vec3::new(x, 0.0, z);
    [
        [p(-5.0, -5.0), p(-5.0, 5.0), p(5.0, 5.0)],
        [p(-5.0, -5.0), p(5.0, 5.0), p(5.0, -5.0)],
    ]
}

/// Closed form: with `r = v`, Phong is `c (kd (n.l) + ks)`; light from below gives 0.
#[test]
fn phong_at_a_point_closed_form() {
    let n = Vec3::Z;
    let l = Vec3::new(1.0, 0.0, 1.0).normalize();
    let v = Vec3::new(-1.0, 0.0, 1.0).normalize();
    let (kd, ks, c) = (
        Rgb::new(0.5, 0.2, 0.1),
        Rgb::splat(0.3),
        Rgb::new(1.0, 2.0, 4.0),
    );
    let got = phong(n, l, v, kd, ks, 7.0, c);
    let nl = std::f32::consts::FRAC_1_SQRT_2;
    let want = c * (kd * nl + ks);
    for (g, w) in [(got.r, want.r), (got.g, want.g), (got.b, want.b)] {
        assert!((g - w).abs() < 1e-5, "{got:?} vs {want:?}");
    }
    // Half-way between: r.v = cos(90 deg) = 0, so no highlight.
    let v2 = Vec3::new(0.0, 1.0, 0.0);
    let got = phong(n, l, v2, kd, ks, 7.0, c);
    assert!((got.r - c.r * kd.r * nl).abs() < 1e-6);
    assert_eq!(phong(n, -l, v, kd, ks, 7.0, c), Rgb::BLACK);
}

/// Closed form: a triangle facing the camera, lit by a point light at the eye, shows
/// exactly kd x light colour at the image centre (n.l = 1, ks = 0, no falloff).
#[test]
fn head_on_triangle_shows_kd_times_light() {
    let kd = Rgb::new(0.5, 0.25, 1.0);
    let c = Rgb::new(1.0, 2.0, 0.5);
    let scene = triangles(
        &[[
            Vec3::new(-5.0, -5.0, 0.0),
            Vec3::new(5.0, -5.0, 0.0),
            Vec3::new(0.0, 5.0, 0.0),
        ]],
        phong_material(kd, Rgb::BLACK),
        vec![Light::Point {
            position: Vec3::new(0.0, 0.0, -3.0),
            intensity: c,
        }],
    );
    let ws = WhittedScene::new(&scene, true);
    let out = raytrace(&ws, &head_on(), &options(10, 10, all_on()), &|_| {});
    // Pixel x = 5, y = 5 from the bottom goes through ndc (0, 0): row 10 - 1 - 5 = 4.
    assert_eq!(out.image.get(5, 4), kd * c);
}

/// Property: shadow rays start 1e-4 along the light direction, so a lit plane does not
/// shadow itself: with nothing in between, hard shadows change no pixel.
#[test]
fn shadow_ray_offset_on_a_plane() {
    let scene = triangles(
        &floor(),
        phong_material(Rgb::splat(0.7), Rgb::BLACK),
        vec![Light::Point {
            position: Vec3::new(0.3, 2.0, 0.1),
            intensity: Rgb::WHITE,
        }],
    );
    let ws = WhittedScene::new(&scene, true);
    let cam = OrbitCamera {
        rotation: Vec3::new(60.0, 10.0, 0.0),
        ..OrbitCamera::default()
    };
    let with = raytrace(&ws, &cam, &options(48, 48, all_on()), &|_| {});
    let without = raytrace(
        &ws,
        &cam,
        &options(
            48,
            48,
            Features {
                hard_shadow: false,
                ..all_on()
            },
        ),
        &|_| {},
    );
    assert!(with.image.pixels().iter().any(|p| p.r > 0.0));
    assert_eq!(with.image.pixels(), without.image.pixels());
}

/// The pixel in the middle of a floor seen from above, lit from above.
fn floor_pixel_rays(light: Light, samples: u32) -> Vec<Vec3> {
    let scene = triangles(
        &floor(),
        phong_material(Rgb::splat(0.7), Rgb::BLACK),
        vec![light],
    );
    let ws = WhittedScene::new(&scene, true);
    let cam = OrbitCamera {
        rotation: Vec3::new(90.0, 0.0, 0.0),
        ..OrbitCamera::default()
    };
    let mut o = options(8, 8, all_on());
    o.settings.light_samples = samples;
    let tr = trace_pixel(&ws, &cam, &o, 4, 4);
    tr.rays
        .iter()
        .filter(|r| r.kind == RayKind::AreaSample)
        .map(|r| r.end)
        .collect()
}

/// Property of stratified jitter: each of the 16 strata of a segment, and each cell of the
/// 4 x 4 grid of a parallelogram, holds exactly one sample.
#[test]
fn area_light_strata_each_get_one_sample() {
    let ends = floor_pixel_rays(
        Light::Segment {
            endpoints: [Vec3::new(-1.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 0.0)],
            colors: [Rgb::WHITE, Rgb::WHITE],
        },
        16,
    );
    assert_eq!(ends.len(), 16);
    let mut cells: Vec<i32> = ends
        .iter()
        .map(|q| ((q.x + 1.0) / 2.0 * 16.0).floor() as i32)
        .collect();
    cells.sort_unstable();
    assert_eq!(cells, (0..16).collect::<Vec<_>>());

    let ends = floor_pixel_rays(
        Light::Parallelogram {
            corner: Vec3::new(-0.5, 2.0, -0.5),
            edges: [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0)],
            colors: [Rgb::WHITE; 4],
            facing: None,
        },
        16,
    );
    assert_eq!(ends.len(), 16);
    let mut cells: Vec<(i32, i32)> = ends
        .iter()
        .map(|q| {
            (
                ((q.x + 0.5) * 4.0).floor() as i32,
                ((q.z + 0.5) * 4.0).floor() as i32,
            )
        })
        .collect();
    cells.sort_unstable();
    let want: Vec<(i32, i32)> = (0..4).flat_map(|a| (0..4).map(move |b| (a, b))).collect();
    assert_eq!(cells, want);
}

/// Closed form: the parallelogram's colour is its corner colour at each corner and the
/// mean of the four at the centre; the segment's blends linearly.
#[test]
fn parallelogram_colour_interpolation_at_the_corners() {
    let c = [
        Rgb::new(1.0, 0.0, 0.0),
        Rgb::new(0.0, 1.0, 0.0),
        Rgb::new(0.0, 0.0, 1.0),
        Rgb::new(0.0, 1.0, 1.0),
    ];
    assert_eq!(parallelogram_color(&c, 0.0, 0.0), c[0]);
    assert_eq!(parallelogram_color(&c, 1.0, 0.0), c[1]);
    assert_eq!(parallelogram_color(&c, 0.0, 1.0), c[2]);
    assert_eq!(parallelogram_color(&c, 1.0, 1.0), c[3]);
    let mid = parallelogram_color(&c, 0.5, 0.5);
    assert_eq!(mid, Rgb::new(0.25, 0.5, 0.5));
}

/// Closed form: interpolated normals equal the (normalised) vertex normals at the
/// vertices, and the geometric normal without interpolation.
#[test]
fn interpolated_normals_equal_vertex_normals_at_the_vertices() {
    let v = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let n = [
        Vec3::new(-0.5, 0.0, -1.0),
        Vec3::new(0.5, 0.2, -2.0),
        Vec3::new(0.0, 0.6, -1.0),
    ];
    let mut scene = triangles(&[v], phong_material(Rgb::WHITE, Rgb::BLACK), vec![]);
    scene.meshes[0].shading = Shading::Smooth(n.to_vec());
    let ws = WhittedScene::new(&scene, true);
    for (i, corner) in v.iter().enumerate() {
        // Aim a hair inside the triangle from the vertex.
        let centroid = (v[0] + v[1] + v[2]) / 3.0;
        let target = *corner + 1e-5 * (centroid - *corner);
        // From the side the geometric normal faces, so that no normal is flipped.
        let ray = Ray::new(target + Vec3::new(0.0, 0.0, 3.0), Vec3::new(0.0, 0.0, -1.0));
        let hit = ws.intersect(&ray, f32::INFINITY, true).expect("hit");
        let want = n[i].normalize();
        assert!(
            (hit.n_s - want).length() < 1e-3,
            "vertex {i}: {} vs {want}",
            hit.n_s
        );
        let flat = ws.intersect(&ray, f32::INFINITY, false).expect("hit");
        assert_eq!(flat.n_s, flat.n_g);
        assert_eq!(flat.n_g, Vec3::Z);
    }
}

/// Brute force: testing every ray against every primitive gives the same bytes as the BVH,
/// also where a ray meets two primitives at one distance (the cube's shared edges at 200 by
/// 200: both keep the lower-numbered primitive).
#[test]
fn bvh_and_brute_force_give_identical_images() {
    for (preset, size) in [
        (Preset::CornellBox, 64),
        (Preset::CornellBoxParallelogramLight, 64),
        (Preset::Spheres, 64),
        (Preset::CubeTextured, 64),
        (Preset::Cube, 200),
        (Preset::Cube, 96),
        (Preset::Custom, 96),
        (Preset::SingleTriangle, 64),
    ] {
        let scene = preset.load(&[]).unwrap();
        let o = options(size, size, all_on());
        let cam = OrbitCamera::default();
        let a = raytrace(&WhittedScene::new(&scene, true), &cam, &o, &|_| {});
        let b = raytrace(&WhittedScene::new(&scene, false), &cam, &o, &|_| {});
        let (pa, pb) = (a.image.pixels(), b.image.pixels());
        let differ = pa.iter().zip(pb).filter(|(x, y)| x != y).count();
        assert_eq!(differ, 0, "{}: {differ} pixels differ", preset.name());
        assert_eq!(a.counts, b.counts, "{}", preset.name());
    }
}

/// Determinism: one and two threads give the same bytes, jitter and area samples included.
#[test]
fn identical_on_one_and_two_threads() {
    let scene = Preset::CornellBoxParallelogramLight.load(&[]).unwrap();
    let ws = WhittedScene::new(&scene, true);
    let o = options(
        48,
        48,
        Features {
            multiple_rays_per_pixel: true,
            bloom: true,
            ..all_on()
        },
    );
    let run = |threads: usize| {
        prism_testkit::on_threads(threads, || {
            raytrace(&ws, &OrbitCamera::default(), &o, &|_| {})
        })
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.image.pixels(), b.image.pixels());
}

/// Shading off: every pixel on the object is its kd (the texel with texture mapping).
#[test]
fn shading_off_shows_kd() {
    let kd = Rgb::new(0.3, 0.6, 0.9);
    let scene = triangles(&floor(), phong_material(kd, Rgb::splat(0.5)), vec![]);
    let ws = WhittedScene::new(&scene, true);
    let cam = OrbitCamera {
        rotation: Vec3::new(90.0, 0.0, 0.0),
        ..OrbitCamera::default()
    };
    let f = Features {
        shading: false,
        ..all_on()
    };
    let out = raytrace(&ws, &cam, &options(16, 16, f), &|_| {});
    assert!(out.image.pixels().iter().all(|&p| p == kd));
}

fn golden_dir() -> PathBuf {
    prism_testkit::workspace_root().join("crates/prism-render/tests/golden/raytrace")
}

fn golden(name: &str, preset: Preset, features: Features) {
    let dirs = vec![prism_testkit::shared_asset("delft-raytracer/data")];
    let scene = preset.load(&dirs).unwrap();
    let ws = WhittedScene::new(&scene, features.accel_structure);
    let out = raytrace(
        &ws,
        &OrbitCamera::default(),
        &options(96, 96, features),
        &|_| {},
    );
    let actual = out.image.to_rgb8_truncated();
    prism_testkit::compare_golden(
        name,
        &golden_dir().join(format!("{name}.png")),
        &actual,
        true,
        |s| s.identical_fraction >= 0.995 && s.max_error <= 8,
    );
}

macro_rules! preset_goldens {
    ($($test:ident: $preset:expr;)*) => {$(
        /// Owned golden image of the preset with every default feature on.
        #[test]
        fn $test() {
            golden(stringify!($test), $preset, all_on());
        }
    )*};
}

preset_goldens! {
    preset_single_triangle: Preset::SingleTriangle;
    preset_cube: Preset::Cube;
    preset_cube_textured: Preset::CubeTextured;
    preset_cornell_box: Preset::CornellBox;
    preset_cornell_box_parallelogram_light: Preset::CornellBoxParallelogramLight;
    preset_monkey: Preset::Monkey;
    preset_teapot: Preset::Teapot;
    preset_spheres: Preset::Spheres;
    preset_custom: Preset::Custom;
}

macro_rules! toggle_goldens {
    ($($test:ident: $preset:expr, $field:ident = $value:expr;)*) => {$(
        /// Owned golden image of one feature switch flipped from the defaults.
        #[test]
        fn $test() {
            let mut f = all_on();
            f.$field = $value;
            golden(stringify!($test), $preset, f);
        }
    )*};
}

toggle_goldens! {
    toggle_no_shading: Preset::CornellBox, shading = false;
    toggle_no_recursive: Preset::CornellBox, recursive = false;
    toggle_no_hard_shadow: Preset::CornellBox, hard_shadow = false;
    toggle_no_soft_shadow: Preset::CornellBoxParallelogramLight, soft_shadow = false;
    toggle_no_normal_interp: Preset::Monkey, normal_interp = false;
    toggle_no_texture: Preset::CubeTextured, texture_mapping = false;
    toggle_nearest_texture: Preset::CubeTextured, bilinear = false;
    toggle_no_bvh: Preset::CornellBox, accel_structure = false;
    toggle_bloom: Preset::Spheres, bloom = true;
    toggle_transparency: Preset::Cube, transparency = true;
    toggle_multi_rays: Preset::CornellBoxParallelogramLight, multiple_rays_per_pixel = true;
}

/// The dragon is not shipped: its preset says which file is missing and where it looked.
#[test]
fn dragon_without_its_file_is_a_named_error() {
    let e = Preset::Dragon
        .load(&[PathBuf::from("/nonexistent")])
        .unwrap_err();
    assert!(e.to_string().contains("dragon.obj"), "{e}");
}

/// Closed form of the template's camera: the default orbit (20, 20, 0) at distance 3 puts
/// the eye at `R (0, 0, -3) = (-3 cos20 sin20, 3 sin20, -3 cos^2 20)`; the ray through the
/// image centre points at `look_at`; pixel (0, 0), the bottom-left corner, looks along
/// `R normalize(hw, -hh, 1)` (screen-right is camera -x); projecting a point of a pixel's
/// ray gives that pixel back (row 0 at the top).
#[test]
fn orbit_camera_closed_form() {
    let cam = OrbitCamera::default();
    let (s, c) = 20f32.to_radians().sin_cos();
    let want = Vec3::new(-3.0 * c * s, 3.0 * s, -3.0 * c * c);
    assert!((cam.eye() - want).length() < 1e-5, "{}", cam.eye());
    let view = prism_render::whitted::camera::OrbitView::new(&cam, 200, 100);
    let centre = view.ray(100.0, 50.0);
    assert!((centre.dir - (-cam.eye()).normalize()).length() < 1e-5);
    let head = prism_render::whitted::camera::OrbitView::new(&head_on(), 200, 100);
    let hh = 25f32.to_radians().tan();
    let corner = head.ray(0.0, 0.0).dir;
    let want = Vec3::new(2.0 * hh, -hh, 1.0).normalize();
    assert!((corner - want).length() < 1e-6, "{corner} vs {want}");
    for (x, y) in [(10.5f32, 20.5f32), (150.25, 90.75)] {
        let r = view.ray(x, y);
        let (px, py, _) = view.project(r.origin + 4.0 * r.dir).unwrap();
        assert!(
            (px - x).abs() < 1e-3 && (py - (100.0 - y)).abs() < 1e-3,
            "{px} {py}"
        );
    }
}

/// Property of the one light description: a parallelogram that faces away from a surface
/// (the course's one-sided area light) gives it nothing; facing it, or with no facing side
/// (the Delft light), it lights it, and the same amount either way.
#[test]
fn one_sided_parallelograms_light_only_their_side() {
    let light = |facing| Light::Parallelogram {
        corner: Vec3::new(-0.5, 2.0, -0.5),
        edges: [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0)],
        colors: [Rgb::WHITE; 4],
        facing,
    };
    let mean = |facing| {
        let scene = triangles(
            &floor(),
            phong_material(Rgb::splat(0.7), Rgb::BLACK),
            vec![light(facing)],
        );
        let ws = WhittedScene::new(&scene, true);
        let cam = OrbitCamera {
            rotation: Vec3::new(90.0, 0.0, 0.0),
            ..OrbitCamera::default()
        };
        let out = raytrace(&ws, &cam, &options(16, 16, all_on()), &|_| {});
        out.image.pixels().iter().map(|p| p.r).sum::<f32>()
    };
    assert_eq!(mean(Some(Vec3::Y)), 0.0);
    let down = mean(Some(Vec3::NEG_Y));
    assert!(down > 0.0);
    assert_eq!(down, mean(None));
}

/// Property: the row-at-a-time camera directions are bit for bit those of one ray at a
/// time, for cameras at odd angles and odd image sizes.
#[test]
fn row_directions_equal_single_rays_bit_for_bit() {
    for (rot, w, h) in [
        (Vec3::new(20.0, 20.0, 0.0), 37, 23),
        (Vec3::new(-73.5, 191.0, 12.25), 64, 64),
        (Vec3::ZERO, 10, 10),
    ] {
        let cam = OrbitCamera {
            rotation: rot,
            fov_y: 61.0,
            ..OrbitCamera::default()
        };
        let view = prism_render::whitted::camera::OrbitView::new(&cam, w, h);
        let mut rays = Vec::new();
        for y in 0..h {
            view.corner_rays(y, &mut rays);
            assert_eq!(rays.len(), w as usize);
            for (x, d) in rays.iter().enumerate() {
                let r = view.ray(x as f32, y as f32);
                assert_eq!(d.origin, r.origin);
                assert_eq!(
                    d.dir.to_array().map(f32::to_bits),
                    r.dir.to_array().map(f32::to_bits)
                );
            }
        }
    }
}

/// Property: a Whitted render told to stop before it starts leaves every pixel black and
/// casts no ray; one never told equals `raytrace`.
#[test]
fn a_stopped_whitted_render_ends_early() {
    use prism_render::whitted::film::raytrace_until;
    use std::sync::atomic::AtomicBool;
    let ws = WhittedScene::new(&Preset::CornellBox.load(&[]).unwrap(), true);
    let cam = OrbitCamera::default();
    let o = options(16, 16, all_on());
    let stopped = raytrace_until(&ws, &cam, &o, Some(&AtomicBool::new(true)), &|_| {});
    assert!(stopped.image.pixels().iter().all(|p| *p == Rgb::BLACK));
    assert_eq!(stopped.counts.total(), 0);
    let whole = raytrace(&ws, &cam, &o, &|_| {});
    let same = raytrace_until(&ws, &cam, &o, Some(&AtomicBool::new(false)), &|_| {});
    assert_eq!(same.image.pixels(), whole.image.pixels());
}
