//! The Whitted ray tracer's extras (FORMATS.md §5) against independent truths: the thin
//! lens's circle of confusion, a translating quad's share of the shutter, the Phong lobe's
//! chi-square and its mirror limit, the environment map's texels, ray-cone mip levels and
//! aliasing against supersampling, and the median-split tree against binned SAH.

use std::sync::Arc;

use prism_image::{Image, RgbImage};
use prism_math::warp::{concentric_disk, cosine_power, cosine_power_pdf};
use prism_math::{Pcg32, Rgb, Vec2, Vec3};
use prism_render::whitted::camera::OrbitView;
use prism_render::whitted::film::{raytrace, trace_pixel, RaytraceOptions};
use prism_render::whitted::scene::{Environment, SceneSetup, Split, WhittedScene};
use prism_render::whitted::tracer::{PixelSampler, RayCounts, RayKind, WhittedTracer};
use prism_scene::{Features, Material, MaterialTexture, OrbitCamera, Preset, Scene, Shading};

use super::whitted::{all_on, head_on, options, phong_material, triangles};

/// Texture mapping and the BVH on, shading off: a pixel is its surface's kd or texel.
fn unshaded() -> Features {
    Features {
        texture_mapping: true,
        accel_structure: true,
        ..Features::default()
    }
}

/// An axis-aligned quad at z = 0 over `[x0, x1] x [y0, y1]`, uv (0, 0) at its lower-left
/// corner and (1, 1) at its upper-right, in one material.
fn quad(x0: f32, x1: f32, y0: f32, y1: f32, material: Material) -> Scene {
    let mut s = triangles(&[], material, vec![]);
    let m = &mut s.meshes[0];
    m.positions = vec![
        Vec3::new(x0, y0, 0.0),
        Vec3::new(x1, y0, 0.0),
        Vec3::new(x1, y1, 0.0),
        Vec3::new(x0, y1, 0.0),
    ];
    m.triangles = vec![[0, 1, 2], [0, 2, 3]];
    m.uvs = Some(vec![
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0, 1.0),
    ]);
    s
}

/// A Phong material showing `image` (nearest or bilinear as the features say).
fn textured(image: RgbImage) -> Material {
    Material::Phong {
        kd: Rgb::WHITE,
        ks: Rgb::BLACK,
        shininess: 1.0,
        kd_texture: Some(MaterialTexture {
            path: "t.png".into(),
            image: Arc::new(image),
            sampling: prism_image::PixelSampling::Nearest,
            wrap: prism_image::Wrap::Clamp,
            to_uv: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        }),
        transparency: 1.0,
    }
}

/// A `w x w` checkerboard of `cell`-texel squares.
fn checker(w: u32, cell: u32) -> RgbImage {
    Image::from_fn(w, w, |x, y| {
        if (x / cell + y / cell).is_multiple_of(2) {
            Rgb::WHITE
        } else {
            Rgb::BLACK
        }
    })
}

fn mean_abs_diff(a: &RgbImage, b: &RgbImage) -> f32 {
    let n = a.pixels().len() as f32;
    a.pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| ((p.r - q.r).abs() + (p.g - q.g).abs() + (p.b - q.b).abs()) / 3.0)
        .sum::<f32>()
        / n
}

/// Closed form: every thin-lens ray of a pixel passes through the pinhole ray's point on
/// the plane in focus (a point there projects sharp), and at depth z the rays from the
/// lens's rim lie R |z - d| / d from the pinhole ray: the circle of confusion.
#[test]
fn lens_rays_meet_in_focus_and_spread_by_the_circle_of_confusion() {
    let view = OrbitView::new(&OrbitCamera::default(), 64, 48);
    let (radius, d) = (0.2f32, 2.5f32);
    let axis = view.ray(32.0, 24.0).dir;
    let eye = view.eye();
    for (x, y) in [(32.0, 24.0), (5.0, 40.0), (60.5, 3.25)] {
        let pin = view.ray(x, y);
        let at_depth = |z: f32| pin.origin + pin.dir * (z / pin.dir.dot(axis));
        let mut widest = [0f32; 2];
        for i in 0..=32 {
            for j in 0..=32 {
                let lens = concentric_disk(Vec2::new(i as f32 / 32.0, j as f32 / 32.0));
                let ray = view.lens_ray(x, y, lens, radius, d);
                let along = |z: f32| {
                    let t = (z - (ray.origin - eye).dot(axis)) / ray.dir.dot(axis);
                    ray.origin + t * ray.dir
                };
                assert!(
                    (along(d) - at_depth(d)).length() < 1e-5 * d,
                    "{x} {y} {lens}"
                );
                for (k, z) in [1.5f32, 4.0].into_iter().enumerate() {
                    let r = (along(z) - at_depth(z)).length();
                    assert!(r <= radius * (z - d).abs() / d * 1.0001 + 1e-6);
                    widest[k] = widest[k].max(r);
                }
            }
        }
        for (k, z) in [1.5f32, 4.0].into_iter().enumerate() {
            let coc = radius * (z - d).abs() / d;
            assert!(
                (widest[k] - coc).abs() < 1e-4,
                "z {z}: {} vs {coc}",
                widest[k]
            );
        }
    }
}

/// Closed form: a textured plane exactly at the focal distance renders as the pinhole
/// camera renders it (every lens ray meets the pinhole ray's point); out of focus it blurs.
#[test]
fn a_plane_in_focus_is_sharp_and_out_of_focus_blurs() {
    let scene = quad(-3.0, 3.0, -3.0, 3.0, textured(checker(64, 4)));
    let ws = WhittedScene::new(&scene, true);
    let pinhole = raytrace(&ws, &head_on(), &options(48, 48, unshaded()), &|_| {}).image;
    let mut o = options(
        48,
        48,
        Features {
            depth_of_field: true,
            ..unshaded()
        },
    );
    o.settings.extras.dof_aperture = 0.2;
    let sharp = raytrace(&ws, &head_on(), &o, &|_| {}).image;
    let same = (pinhole.pixels().iter())
        .zip(sharp.pixels())
        .filter(|(a, b)| a == b)
        .count();
    assert!(
        same * 100 >= 99 * pinhole.pixels().len(),
        "{same} pixels equal"
    );
    o.settings.extras.dof_focal_distance = Some(1.5);
    let blurred = raytrace(&ws, &head_on(), &o, &|_| {}).image;
    assert!(mean_abs_diff(&pinhole, &blurred) > 0.1);
}

/// Closed form: a quad translating across a pixel's ray covers it for the share of the
/// shutter it spends there: `|[0.2 - X, 1.2 - X] n [0, 1]|` for a quad over x in
/// [0.2, 1.2] moving by -1 in x, seen along a ray meeting z = 0 at x = X; the BVH and
/// brute force agree.
#[test]
fn a_moving_quad_covers_a_pixel_for_its_share_of_the_shutter() {
    let scene = quad(0.2, 1.2, -1.0, 1.0, phong_material(Rgb::WHITE, Rgb::BLACK));
    let setup = |bvh: Option<Split>| SceneSetup {
        bvh,
        motion: vec![(0, Vec3::new(-1.0, 0.0, 0.0))],
        environment: None,
    };
    let mut o = options(
        40,
        40,
        Features {
            motion_blur: true,
            ..unshaded()
        },
    );
    o.settings.extras.motion_samples = 128;
    let n = 128.0;
    let ws = WhittedScene::prepare(&scene, setup(Some(Split::Sah)));
    assert!(ws.has_motion());
    let img = raytrace(&ws, &head_on(), &o, &|_| {}).image;
    let brute = WhittedScene::prepare(&scene, setup(None));
    assert_eq!(img, raytrace(&brute, &head_on(), &o, &|_| {}).image);
    let view = OrbitView::new(&head_on(), 40, 40);
    let mut checked = 0;
    for row in [12u32, 20, 27] {
        for x in 0..40 {
            let ray = view.ray(x as f32, (39 - row) as f32);
            let hit = ray.origin + ray.dir * (3.0 / ray.dir.z);
            if hit.y.abs() >= 0.99 {
                continue;
            }
            let share = ((1.2 - hit.x).min(1.0) - (0.2 - hit.x).max(0.0)).max(0.0);
            let got = img.get(x, row).r;
            assert!(
                (got - share).abs() <= 2.0 / n,
                "pixel {x},{row}: {got} vs {share}"
            );
            checked += 1;
        }
    }
    assert!(checked > 60);
    // With motion blur off the quad stands at time 0.
    let still = raytrace(&ws, &head_on(), &options(40, 40, unshaded()), &|_| {}).image;
    let view_hit = |x: u32| {
        let ray = view.ray(x as f32, 19.0);
        ray.origin.x + ray.dir.x * (3.0 / ray.dir.z)
    };
    for x in 0..40 {
        let inside = (0.2..=1.2).contains(&view_hit(x));
        assert_eq!(still.get(x, 20).r, if inside { 1.0 } else { 0.0 });
    }
}

/// Chi-square against the lobe's own density integrated in closed form: the Phong lobe
/// sampler's directions fall in (theta, phi) cells as `(n + 1) / 2 pi cos^n` says, and that
/// density integrates to 1 over the hemisphere (midpoint rule).
#[test]
fn phong_lobe_sampler_follows_its_density() {
    for n in [1.0f32, 10.0, 100.0, 1e4] {
        // 24 theta cells up to where the lobe keeps 1e-4 of its mass, and the rest.
        let theta_max = (1e-4f64).powf(1.0 / (f64::from(n) + 1.0)).acos();
        let (nt, np) = (24usize, 8usize);
        let mass = |theta: f64| theta.cos().powf(f64::from(n) + 1.0);
        let mut expected = vec![0.0; (nt + 1) * np];
        let count = 400_000;
        for i in 0..=nt {
            let (a, b) = if i < nt {
                (
                    theta_max * i as f64 / nt as f64,
                    theta_max * (i + 1) as f64 / nt as f64,
                )
            } else {
                (theta_max, std::f64::consts::FRAC_PI_2)
            };
            for j in 0..np {
                expected[i * np + j] = count as f64 * (mass(a) - mass(b)) / np as f64;
            }
        }
        let mut observed = vec![0.0; (nt + 1) * np];
        let mut rng = Pcg32::new(11, n as u64);
        for _ in 0..count {
            let d = cosine_power(Vec2::new(rng.next_f32(), rng.next_f32()), n);
            let theta = f64::from(d.z.clamp(-1.0, 1.0)).acos();
            let phi = f64::from(d.y)
                .atan2(f64::from(d.x))
                .rem_euclid(std::f64::consts::TAU);
            let i = ((theta / theta_max * nt as f64) as usize).min(nt);
            let j = ((phi / std::f64::consts::TAU * np as f64) as usize).min(np - 1);
            observed[i * np + j] += 1.0;
        }
        let (stat, critical) = prism_testkit::chi_square(&observed, &expected);
        assert!(stat < critical, "n {n}: chi-square {stat} over {critical}");
        let steps = 200_000;
        let h = std::f64::consts::FRAC_PI_2 / steps as f64;
        let integral: f64 = (0..steps)
            .map(|k| {
                let t = (k as f64 + 0.5) * h;
                f64::from(cosine_power_pdf(t.cos() as f32, n)) * t.sin() * std::f64::consts::TAU * h
            })
            .sum();
        assert!((integral - 1.0).abs() < 2e-3, "n {n}: {integral}");
    }
}

/// Limit: with exponents of 2 x 10^4 the glossy lobe is a mirror: the Cornell box's glossy
/// image equals its mirror image within noise.
#[test]
fn glossy_at_huge_exponents_equals_the_mirror() {
    let mut scene = Preset::CornellBox.load(&[]).unwrap();
    for m in &mut scene.materials {
        if let Material::Phong { shininess, .. } = m {
            *shininess = 2e4;
        }
    }
    let ws = WhittedScene::new(&scene, true);
    let cam = OrbitCamera::default();
    let mut o = options(40, 40, all_on());
    o.settings.extras.glossy_samples = 4;
    let mirror = raytrace(&ws, &cam, &o, &|_| {}).image;
    o.settings.features.glossy_reflection = true;
    let glossy = raytrace(&ws, &cam, &o, &|_| {});
    assert!(
        glossy.counts.reflection
            > 3 * raytrace(&ws, &cam, &options(40, 40, all_on()), &|_| {})
                .counts
                .reflection
    );
    let diff = mean_abs_diff(&mirror, &glossy.image);
    assert!(diff < 2e-3, "mean difference {diff}");
    // A low exponent blurs the reflections: the images differ.
    for m in &mut scene.materials {
        if let Material::Phong { shininess, .. } = m {
            *shininess = 2.0;
        }
    }
    let ws = WhittedScene::new(&scene, true);
    let rough = raytrace(&ws, &cam, &o, &|_| {}).image;
    assert!(mean_abs_diff(&mirror, &rough) > 5.0 * diff.max(1e-4));
}

/// Closed form: a constant map returns its value times the strength on every miss.
#[test]
fn a_constant_environment_is_seen_on_every_miss() {
    let c = Rgb::new(0.3, 0.6, 0.9);
    let scene = triangles(&[], phong_material(Rgb::WHITE, Rgb::BLACK), vec![]);
    let setup = SceneSetup {
        bvh: Some(Split::Sah),
        environment: Some(Environment::new(Image::new(4, 2, c), 2.0)),
        ..SceneSetup::default()
    };
    let ws = WhittedScene::prepare(&scene, setup);
    let f = Features {
        environment_mapping: true,
        ..all_on()
    };
    let img = raytrace(&ws, &OrbitCamera::default(), &options(16, 12, f), &|_| {}).image;
    assert!(img.pixels().iter().all(|&p| p == c * 2.0));
    // Off, misses are black.
    let off = raytrace(
        &ws,
        &OrbitCamera::default(),
        &options(16, 12, all_on()),
        &|_| {},
    )
    .image;
    assert!(off.pixels().iter().all(|&p| p == Rgb::BLACK));
}

/// Oracle: the written mapping with a bilinear lookup of its own. Each pixel of a wide view
/// of an empty scene shows the map at u = 0.5 + atan2(d.x, -d.z) / 2 pi, v = acos(d.y) / pi
/// of its ray, wrapping in u and clamped in v.
#[test]
fn each_pixel_shows_the_map_texel_it_looks_at() {
    let (w, h) = (16u32, 8u32);
    let mut rng = Pcg32::new(5, 5);
    let map = Image::from_fn(w, h, |_, _| {
        Rgb::new(rng.next_f32(), rng.next_f32(), rng.next_f32())
    });
    let scene = triangles(&[], phong_material(Rgb::WHITE, Rgb::BLACK), vec![]);
    let ws = WhittedScene::prepare(
        &scene,
        SceneSetup {
            bvh: Some(Split::Sah),
            environment: Some(Environment::new(map.clone(), 1.0)),
            ..SceneSetup::default()
        },
    );
    let cam = OrbitCamera {
        fov_y: 150.0,
        rotation: Vec3::new(-30.0, 70.0, 0.0),
        ..OrbitCamera::default()
    };
    let f = Features {
        environment_mapping: true,
        ..all_on()
    };
    let img = raytrace(&ws, &cam, &options(24, 20, f), &|_| {}).image;
    let view = OrbitView::new(&cam, 24, 20);
    let texel = |x: i64, y: i64| {
        map.get(
            x.rem_euclid(i64::from(w)) as u32,
            y.clamp(0, i64::from(h) - 1) as u32,
        )
    };
    for row in 0..20 {
        for x in 0..24 {
            let d = view.ray(x as f32, (19 - row) as f32).dir;
            let u = 0.5 + f64::from(d.x).atan2(-f64::from(d.z)) / std::f64::consts::TAU;
            let v = f64::from(d.y).acos() / std::f64::consts::PI;
            let (gx, gy) = (u * f64::from(w) - 0.5, v * f64::from(h) - 0.5);
            let (x0, y0) = (gx.floor(), gy.floor());
            let (tx, ty) = ((gx - x0) as f32, (gy - y0) as f32);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let top = texel(x0, y0) * (1.0 - tx) + texel(x0 + 1, y0) * tx;
            let bottom = texel(x0, y0 + 1) * (1.0 - tx) + texel(x0 + 1, y0 + 1) * tx;
            let want = top * (1.0 - ty) + bottom * ty;
            let got = img.get(x, row);
            let err = (got.r - want.r)
                .abs()
                .max((got.g - want.g).abs())
                .max((got.b - want.b).abs());
            assert!(err < 2e-3, "pixel {x},{row}: {got:?} vs {want:?}");
        }
    }
}

/// Closed form: a plane seen head-on at one texel per pixel takes mip level 0, at four
/// texels per pixel level 2 (within 0.05), at the centre of the image.
#[test]
fn ray_cone_levels_follow_texels_per_pixel() {
    let height = 100u32;
    let pixel = 2.0 * 3.0 * 25f32.to_radians().tan() / height as f32;
    for (side, want) in [(64u32, 0.0f32), (256, 2.0)] {
        // 64 texels across 64 pixels' width of plane.
        let half = 64.0 * pixel / 2.0;
        let scene = quad(-half, half, -half, half, textured(checker(side, 1)));
        let ws = WhittedScene::new(&scene, true);
        let view = OrbitView::new(&head_on(), height, height);
        let ray = view.ray(50.0, 50.0);
        let hit = ws.intersect(&ray, f32::INFINITY, false).unwrap();
        let mut o = options(height, height, unshaded());
        o.settings.features.mipmap = true;
        let tracer = WhittedTracer {
            scene: &ws,
            settings: &o.settings,
            sampler: PixelSampler::new(0, 0, 0),
            counts: &mut RayCounts::default(),
            record: None,
            time: 0.0,
            spread: view.cone_spread(),
            blocked: &[],
        };
        let tex = ws.materials[0].texture.as_ref().unwrap();
        let level = tracer
            .texture_level(tex, &hit, ray.dir, view.cone_spread() * hit.t)
            .unwrap();
        assert!((level - want).abs() < 0.05, "{side} texels: level {level}");
    }
}

/// Oracle: a 256-ray supersampled render. A checkerboard floor receding to the horizon
/// aliases (moire) far off with one ray per pixel at level 0; with mip-mapping, where the
/// supersampled floor is an even grey, the one-ray image is too (within its noise).
#[test]
fn mip_mapping_stops_a_receding_checkerboard_aliasing() {
    let mut scene = quad(-40.0, 40.0, -40.0, 40.0, textured(checker(1024, 4)));
    // The quad laid down as a floor at y = -0.5.
    for p in &mut scene.meshes[0].positions {
        *p = Vec3::new(p.x, -0.5, p.y);
    }
    scene.meshes[0].shading = Shading::Flat;
    let ws = WhittedScene::new(&scene, true);
    let cam = OrbitCamera {
        rotation: Vec3::new(8.0, 0.0, 0.0),
        ..OrbitCamera::default()
    };
    let f = Features {
        bilinear: true,
        ..unshaded()
    };
    let render = |f: Features, spp: u32| {
        let mut o: RaytraceOptions = options(64, 64, f);
        o.spp = spp;
        raytrace(&ws, &cam, &o, &|_| {}).image
    };
    let reference = render(
        Features {
            multiple_rays_per_pixel: true,
            ..f
        },
        256,
    );
    let plain = render(f, 1);
    let mipped = render(Features { mipmap: true, ..f }, 1);
    // Where the floor's checks are finer than a pixel: the rows of the floor on which the
    // supersampled image is an even grey (its deviation within a row under 0.1).
    let grey: Vec<u32> = (0..64)
        .filter(|&r| {
            let v: Vec<f32> = (0..64).map(|x| reference.get(x, r).r).collect();
            let mean = v.iter().sum::<f32>() / 64.0;
            let dev = (v.iter().map(|a| (a - mean).powi(2)).sum::<f32>() / 64.0).sqrt();
            mean > 0.2 && dev < 0.1
        })
        .collect();
    assert!(grey.len() >= 5, "{grey:?}");
    let rmse = |a: &RgbImage| {
        let mut s = 0.0;
        for &r in &grey {
            for x in 0..64 {
                s += (a.get(x, r).r - reference.get(x, r).r).powi(2);
            }
        }
        (s / (grey.len() * 64) as f32).sqrt()
    };
    let (e_plain, e_mip) = (rmse(&plain), rmse(&mipped));
    assert!(
        e_mip < 0.08,
        "mip-mapped {e_mip}, level 0 {e_plain}, rows {grey:?}"
    );
    assert!(e_plain > 0.25, "level 0 {e_plain}: the scene should alias");
}

/// Same picture whichever way the tree is split, the SAH tree's expected cost the lower.
#[test]
fn median_split_and_sah_trees_give_the_same_image() {
    let scene = Preset::CornellBox.load(&[]).unwrap();
    let sah = WhittedScene::prepare(
        &scene,
        SceneSetup {
            bvh: Some(Split::Sah),
            ..SceneSetup::default()
        },
    );
    let median = WhittedScene::prepare(
        &scene,
        SceneSetup {
            bvh: Some(Split::Median),
            ..SceneSetup::default()
        },
    );
    let cam = OrbitCamera::default();
    let o = options(48, 48, all_on());
    assert_eq!(
        raytrace(&sah, &cam, &o, &|_| {}).image,
        raytrace(&median, &cam, &o, &|_| {}).image
    );
    assert!(sah.bvh_stats(Split::Sah).sah_cost < sah.bvh_stats(Split::Median).sah_cost);
}

/// Property: the ray tree records the extras' rays by kind (lens, glossy, environment), each
/// with its shutter time; and the render does not depend on the thread count.
#[test]
fn extras_rays_are_recorded_and_renders_do_not_depend_on_threads() {
    let scene = Preset::CornellBox.load(&[]).unwrap();
    let setup = SceneSetup {
        bvh: Some(Split::Sah),
        motion: vec![(6, Vec3::new(0.2, 0.0, 0.0))],
        environment: Some(Environment::new(
            Image::new(2, 1, Rgb::new(0.1, 0.2, 0.3)),
            1.0,
        )),
    };
    let ws = WhittedScene::prepare(&scene, setup);
    let f = Features {
        depth_of_field: true,
        motion_blur: true,
        glossy_reflection: true,
        environment_mapping: true,
        mipmap: true,
        ..all_on()
    };
    let mut o = options(24, 24, f);
    o.settings.extras.dof_samples = 4;
    o.settings.extras.motion_samples = 4;
    o.settings.extras.glossy_samples = 4;
    let cam = OrbitCamera::default();
    let tr = trace_pixel(&ws, &cam, &o, 12, 12);
    for kind in [RayKind::Lens, RayKind::Glossy, RayKind::Environment] {
        assert!(tr.rays.iter().any(|r| r.kind == kind), "no {kind:?} ray");
    }
    assert!(tr
        .rays
        .iter()
        .all(|r| r.time.is_some_and(|t| (0.0..1.0).contains(&t))));
    // A ray that misses returns what its environment segment (recorded next) sees.
    let mut misses = 0;
    for w in tr.rays.windows(2) {
        if w[1].kind == RayKind::Environment {
            assert!(w[0].hit.is_none());
            assert_eq!(w[0].color, w[1].color);
            misses += 1;
        }
    }
    assert!(misses > 0);
    let json = tr.to_json();
    assert!(json.contains("\"kind\":\"lens\"") && json.contains("\"time\":"));
    let one = prism_testkit::on_threads(1, || raytrace(&ws, &cam, &o, &|_| {}).image);
    let two = prism_testkit::on_threads(2, || raytrace(&ws, &cam, &o, &|_| {}).image);
    assert_eq!(one, two);
    // The pixel's trace is the render's pixel.
    assert_eq!(tr.color, one.get(12, 12));
}
