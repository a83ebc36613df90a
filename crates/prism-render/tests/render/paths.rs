//! End-to-end rendering tests, each against an independent truth.

use prism_math::{Rgb, Vec3};
use prism_render::film::FilmSettings;
use prism_render::integrators::{Integrator, PathSettings};
use prism_render::render::{render, RenderOptions};
use prism_render::render_scene::RenderScene;
use prism_scene::{Camera, Light, Material, Scene, SceneSphere};

fn furnace(material: Material) -> Scene {
    Scene {
        meshes: vec![],
        spheres: vec![SceneSphere {
            center: Vec3::ZERO,
            radius: 1.0,
            material: 0,
            inward: false,
            to_local: None,
        }],
        materials: vec![material],
        material_names: vec![],
        one_sided: vec![],
        lights: vec![Light::Environment {
            radiance: Rgb::WHITE,
        }],
        camera: Camera {
            eye: Vec3::new(0.0, 0.0, 4.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            hfov: 30.0,
            vfov: 30.0,
            near: 0.01,
            far: 100.0,
            lens: None,
            orthographic: None,
            crop: None,
        },
        warnings: vec![],
    }
}

/// The image's bits, channel by channel, for exact comparisons.
fn bits(r: &prism_render::render::Rendered) -> Vec<u32> {
    r.image
        .pixels()
        .iter()
        .flat_map(|p| [p.r.to_bits(), p.g.to_bits(), p.b.to_bits()])
        .collect()
}

fn mean(img: &prism_image::Image<Rgb>) -> Rgb {
    let n = img.pixels().len() as f32;
    img.pixels().iter().fold(Rgb::BLACK, |a, &p| a + p) * (1.0 / n)
}

/// Oracle: the white furnace. A convex object inside a unit-radiance environment reflects
/// exactly its albedo times 1 (it never sees itself), so an albedo-1 diffuse sphere renders
/// 1 everywhere and an albedo-0.5 sphere 0.5 on its pixels; a lossless glass sphere
/// conserves energy, so it renders 1 everywhere as well.
#[test]
fn white_furnace() {
    let opts = RenderOptions {
        film: FilmSettings {
            width: 48,
            height: 48,
            spp: 64,
            ..FilmSettings::default()
        },
        path: PathSettings {
            max_bounces: 64,
            rr_bounces: 64,
            ..PathSettings::default()
        },
    };
    for (material, expect) in [
        (
            Material::Diffuse {
                reflectance: Rgb::WHITE,
                texture: None,
            },
            1.0,
        ),
        (
            Material::Glass {
                reflectance: Rgb::WHITE,
                transmittance: Rgb::WHITE,
                roughness: 0.0,
                ior: 1.5,
            },
            1.0,
        ),
    ] {
        let scene = RenderScene::new(&furnace(material.clone()));
        let out = render(&scene, &opts, &|_| {});
        let m = mean(&out.image);
        for c in [m.r, m.g, m.b] {
            assert!((c - expect).abs() < 0.01, "{material:?}: mean {m:?}");
        }
        // Every pixel within noise of 1 (the diffuse case is exact up to shading noise).
        let worst = out
            .image
            .pixels()
            .iter()
            .map(|p| (p.g - expect).abs())
            .fold(0.0f32, f32::max);
        assert!(worst < 0.35, "{material:?}: worst pixel off by {worst}");
    }
    // Half albedo: the sphere's pixels are 0.5, the background 1.
    let scene = RenderScene::new(&furnace(Material::Diffuse {
        reflectance: Rgb::splat(0.5),
        texture: None,
    }));
    let out = render(&scene, &opts, &|_| {});
    let centre = out.image.get(24, 24);
    assert!((centre.g - 0.5).abs() < 0.02, "{centre:?}");
    assert!((out.image.get(0, 0).g - 1.0).abs() < 1e-6);
}

/// Property: the image is a pure function of the inputs: identical bytes with 1 and 2
/// threads, for the path and direct integrators and with adaptive sampling.
#[test]
fn deterministic_across_thread_counts() {
    let scene = RenderScene::new(&prism_scene::cornell_box());
    for integrator in [Integrator::Path, Integrator::Direct { hemisphere: true }] {
        let opts = RenderOptions {
            film: FilmSettings {
                width: 40,
                height: 30,
                spp: 8,
                adaptive: Some(0.2),
                batch: 4,
                ..FilmSettings::default()
            },
            path: PathSettings {
                integrator,
                ..PathSettings::default()
            },
        };
        let run =
            |threads: usize| prism_testkit::on_threads(threads, || render(&scene, &opts, &|_| {}));
        let (a, b) = (run(1), run(2));
        assert_eq!(bits(&a), bits(&b));
        assert_eq!(a.samples.pixels(), b.samples.pixels());
        assert!(
            a.samples.pixels().iter().any(|&n| n < 8),
            "adaptive sampling stopped no pixel"
        );
    }
}

/// Oracle: Mitsuba 3's converged render of the same scene, pixel by pixel. The reference
/// (`tests/golden/mitsuba/CBspheres_lambertian.exr`) holds the half floats of
/// `../shared/bench/pathtrace/refs/CBspheres_lambertian_4096spp.exr` (512x384, the course's
/// `-m 7` as Mitsuba's `max_depth 8`, 4,096 samples), stored ZIP- instead of PIZ-compressed;
/// `CBspheres_lambertian_variance.exr` holds the variance of one sample's luminance in each
/// pixel, from the spread of 256 Mitsuba renders of 16 samples. A per-pixel Z-test of the
/// luminance, as Mitsuba's own `test_renders.py` tests its renders: prism's 64-sample mean
/// (the variance of that mean from the larger of its own second moment, which the film keeps,
/// and the reference's variance) against the reference's mean (its variance over 4,096
/// samples, plus its half-float rounding). No pixel may reject one mean at significance 0.01
/// over all pixels tested (Bonferroni); pixels that vary on neither side must agree to 1e-3.
#[test]
fn cornell_box_agrees_with_mitsuba_pixel_by_pixel() {
    let golden = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/mitsuba");
    let reference = prism_image::read_exr(&golden.join("CBspheres_lambertian.exr"))
        .expect("the Mitsuba reference reads");
    let variance = prism_image::read_exr(&golden.join("CBspheres_lambertian_variance.exr"))
        .expect("the Mitsuba variance reads");
    let scene = RenderScene::new(&prism_scene::cornell_box());
    let opts = RenderOptions {
        film: FilmSettings {
            width: reference.width(),
            height: reference.height(),
            spp: 64,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    };
    let share = prism_render::film::Share::whole(opts.film.spp);
    let job = prism_render::render::Job::share(&share);
    let sums = prism_render::render::render_share(&scene, &opts, &job, &|_| {});
    let mut ours = Vec::new();
    let mut theirs = Vec::new();
    let pixels = sums.pixels().iter().zip(reference.pixels());
    for ((p, r), v) in pixels.zip(variance.pixels()) {
        let n = f64::from(p.n);
        let mean = p.moment1 / n;
        let own = ((p.moment2 - p.moment1 * mean) / (n - 1.0)).max(0.0);
        let reference_var = f64::from(v.r);
        let reference_mean = f64::from(r.luminance());
        // Half floats keep 11 significant bits: a rounding error uniform over one unit.
        let unit = reference_mean.abs() * 2f64.powi(-10);
        ours.push(prism_testkit::Estimate {
            mean,
            variance: own.max(reference_var) / n,
        });
        theirs.push(prism_testkit::Estimate {
            mean: reference_mean,
            variance: reference_var / 4096.0 + unit * unit / 12.0,
        });
    }
    let z = prism_testkit::z_test(&ours, &theirs, 0.01, 1e-3);
    let width = reference.width() as usize;
    let (x, y) = (z.worst_pixel % width, z.worst_pixel / width);
    assert!(
        z.passed(),
        "{z:?}: pixel ({x}, {y}) prism {:?} vs Mitsuba {:?}",
        ours[z.worst_pixel],
        theirs[z.worst_pixel]
    );
    assert!(z.tested > 60_000, "{} pixels vary", z.tested);
}

/// Oracle: Mitsuba 3's converged render of the same scene (`../shared/bench/pathtrace/refs/
/// CBspheres_lambertian_4096spp.exr`, per-channel means 0.12176, 0.10751, 0.12159 as listed
/// in that folder's README). prism's built-in Cornell box is that scene; at 16 spp its mean
/// must be within 1% per channel. The direct-only render (`-m 1`) and the sum of the
/// bounce-by-bounce renders must agree with the full one the same way.
#[test]
fn cornell_box_agrees_with_mitsuba() {
    let scene = RenderScene::new(&prism_scene::cornell_box());
    let opts = RenderOptions {
        film: FilmSettings {
            width: 256,
            height: 192,
            spp: 16,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    };
    let full = mean(&render(&scene, &opts, &|_| {}).image);
    let reference = [0.12176f32, 0.10751, 0.12159];
    for (c, r) in [full.r, full.g, full.b].into_iter().zip(reference) {
        assert!(
            (c / r - 1.0).abs() < 0.01,
            "mean {full:?} vs Mitsuba {reference:?}"
        );
    }
    // Bounces 0..=7 rendered one at a time add up to the full render.
    let mut sum = Rgb::BLACK;
    for m in 0..=7 {
        let o = RenderOptions {
            film: FilmSettings {
                spp: 8,
                ..opts.film
            },
            path: PathSettings {
                only_bounce: Some(m),
                ..opts.path
            },
        };
        sum += mean(&render(&scene, &o, &|_| {}).image);
    }
    assert!((sum.g / full.g - 1.0).abs() < 0.02, "{sum:?} vs {full:?}");
    // The emitter seen directly is 0.0519 of each channel's mean in Mitsuba's max_depth 1.
    let zero = mean(
        &render(
            &scene,
            &RenderOptions {
                film: FilmSettings {
                    spp: 4,
                    ..opts.film
                },
                path: PathSettings {
                    max_bounces: 0,
                    ..opts.path
                },
            },
            &|_| {},
        )
        .image,
    );
    assert!((zero.g / 0.0519 - 1.0).abs() < 0.03, "{zero:?}");
}

/// Oracle: the white furnace again, lit by a constant environment *map*. Its importance
/// sampling (by sin theta) differs from the constant light's, but the answer must not: an
/// albedo-1 diffuse sphere renders 1, the background is the map's exact value, and the mean
/// matches the constant environment's render.
#[test]
fn constant_map_renders_as_the_constant_environment() {
    let opts = RenderOptions {
        film: FilmSettings {
            width: 32,
            height: 32,
            spp: 32,
            ..FilmSettings::default()
        },
        path: PathSettings {
            max_bounces: 64,
            rr_bounces: 64,
            ..PathSettings::default()
        },
    };
    let white = Material::Diffuse {
        reflectance: Rgb::WHITE,
        texture: None,
    };
    let mut scene = furnace(white.clone());
    scene.lights = vec![Light::EnvironmentMap {
        radiance: std::sync::Arc::new(prism_image::Image::new(64, 32, Rgb::WHITE)),
        mapping: prism_scene::EnvMapping::Course,
    }];
    let map = render(&RenderScene::new(&scene), &opts, &|_| {});
    let constant = render(&RenderScene::new(&furnace(white)), &opts, &|_| {});
    let (m, c) = (mean(&map.image), mean(&constant.image));
    assert!(
        (m.g - 1.0).abs() < 0.01 && (m.g - c.g).abs() < 0.01,
        "{m:?} vs {c:?}"
    );
    assert_eq!(map.image.get(0, 0), Rgb::WHITE);
}

/// Oracle: the course's `bunny.dae` under its hemisphere light (radiance 1 from every
/// direction above the horizon) and the same scene under a map that is 1 above the horizon
/// and 0 below light the bunny and floor alike: the mean over the pixels that see geometry
/// agrees within noise. (Camera rays see the map but not the hidden hemisphere light, so the
/// background is left out, found with the normals integrator.)
#[test]
fn sky_map_lights_like_the_hemisphere_light() {
    let path = prism_testkit::shared_asset("pathtracer/dae/sky/bunny.dae");
    let doc = prism_scene::read_collada(&path).unwrap();
    let scene =
        Scene::from_collada(&doc, &prism_scene::SceneOptions::default(), "bunny.dae").unwrap();
    assert!(matches!(scene.lights[..], [Light::Hemisphere { .. }]));
    let opts = RenderOptions {
        film: FilmSettings {
            width: 48,
            height: 36,
            spp: 64,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    };
    let geometry: Vec<bool> = render(
        &RenderScene::new(&scene),
        &RenderOptions {
            film: FilmSettings {
                spp: 1,
                ..opts.film
            },
            path: PathSettings {
                integrator: Integrator::Normals,
                ..opts.path
            },
        },
        &|_| {},
    )
    .image
    .pixels()
    .iter()
    .map(|p| p.max_channel() > 0.0)
    .collect();
    let covered = geometry.iter().filter(|&&g| g).count();
    assert!(covered > 100, "{covered}");
    let mean_over = |img: &prism_image::Image<Rgb>| {
        let sum: f64 = img
            .pixels()
            .iter()
            .zip(&geometry)
            .filter(|(_, &g)| g)
            .map(|(p, _)| f64::from(p.g))
            .sum();
        sum / covered as f64
    };
    let hemi = mean_over(&render(&RenderScene::new(&scene), &opts, &|_| {}).image);
    let mut sky = scene.clone();
    sky.lights = vec![Light::EnvironmentMap {
        radiance: std::sync::Arc::new(prism_image::Image::from_fn(256, 128, |_, y| {
            if y < 64 {
                Rgb::WHITE
            } else {
                Rgb::BLACK
            }
        })),
        mapping: prism_scene::EnvMapping::Course,
    }];
    let map = mean_over(&render(&RenderScene::new(&sky), &opts, &|_| {}).image);
    assert!(
        (map / hemi - 1.0).abs() < 0.03,
        "map {map} vs hemisphere {hemi}"
    );
}

/// Oracle: the irradiance under the centre of a rectangle parallel to the floor, in closed
/// form (the form factor of a rectangle to a parallel element, summed over the four
/// quarters). The rectangle is an emissive *mesh* (two triangles, radiance 10), the only
/// light: light sampling of the direct integrator, the hemisphere estimator and the path
/// integrator (next-event estimation on the mesh, MIS with BSDF hits on it) must all give
/// `albedo L F` at a floor point seen through a tiny field of view.
#[test]
fn emissive_mesh_lights_the_floor_as_the_form_factor_says() {
    let (a, b, h, radiance, albedo) = (0.6f32, 0.8f32, 1.0f32, 10.0f32, 0.5f32);
    let quad = |y: f32, hx: f32, hz: f32| {
        vec![
            Vec3::new(-hx, y, -hz),
            Vec3::new(hx, y, -hz),
            Vec3::new(hx, y, hz),
            Vec3::new(-hx, y, hz),
        ]
    };
    let mesh = |positions: Vec<Vec3>, material: usize| prism_scene::TriangleMesh {
        name: String::new(),
        positions,
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        shading: prism_scene::Shading::Flat,
        material,
        uvs: None,
    };
    let scene = Scene {
        meshes: vec![
            mesh(quad(0.0, 20.0, 20.0), 0),
            mesh(quad(h, a / 2.0, b / 2.0), 1),
        ],
        spheres: vec![],
        materials: vec![
            Material::Diffuse {
                reflectance: Rgb::splat(albedo),
                texture: None,
            },
            Material::Emission {
                radiance: Rgb::splat(radiance),
            },
        ],
        material_names: vec![],
        one_sided: vec![],
        lights: vec![],
        camera: Camera {
            eye: Vec3::new(0.0, 0.5, 0.0),
            target: Vec3::ZERO,
            up: Vec3::Z,
            hfov: 0.2,
            vfov: 0.2,
            near: 0.01,
            far: 100.0,
            lens: None,
            orthographic: None,
            crop: None,
        },
        warnings: vec![],
    };
    let corner = |x: f64, y: f64| {
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
    };
    let f = 4.0 * corner(f64::from(a / 2.0 / h), f64::from(b / 2.0 / h));
    let want = (f64::from(albedo * radiance) * f) as f32;
    let scene = RenderScene::new(&scene);
    for (integrator, spp) in [
        (Integrator::Direct { hemisphere: false }, 64),
        (Integrator::Direct { hemisphere: true }, 8192),
        (Integrator::Path, 256),
    ] {
        let opts = RenderOptions {
            film: FilmSettings {
                width: 8,
                height: 8,
                spp,
                ..FilmSettings::default()
            },
            path: PathSettings {
                max_bounces: 1,
                integrator,
                ..PathSettings::default()
            },
        };
        let got = mean(&render(&scene, &opts, &|_| {}).image).g;
        assert!(
            (got / want - 1.0).abs() < 0.01,
            "{integrator:?}: {got} vs the closed form {want}"
        );
    }
}

/// A COLLADA file whose effect's diffuse is a `<texture>` of `image` (a PNG beside it), on a
/// unit square in z = 0 with uvs equal to its x and y; loaded from disk.
fn textured_square(image: &prism_image::Rgb8Image, name: &str) -> Scene {
    let dir = std::env::temp_dir().join(format!("prism-textured-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    prism_image::write_png(&dir.join("tex.png"), image).unwrap();
    let dae = r##"<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><up_axis>Y_UP</up_axis></asset>
  <library_images><image id="img"><init_from>tex.png</init_from></image></library_images>
  <library_effects><effect id="fx"><profile_COMMON>
    <newparam sid="surf"><surface type="2D"><init_from>img</init_from></surface></newparam>
    <newparam sid="samp"><sampler2D><source>surf</source></sampler2D></newparam>
    <technique sid="common"><lambert><diffuse><texture texture="samp" texcoord="UVMap"/></diffuse></lambert></technique>
  </profile_COMMON></effect></library_effects>
  <library_materials><material id="m"><instance_effect url="#fx"/></material></library_materials>
  <library_geometries><geometry id="sq"><mesh>
    <source id="p"><float_array id="pa" count="12">0 0 0 1 0 0 1 1 0 0 1 0</float_array>
      <technique_common><accessor source="#pa" count="4" stride="3"/></technique_common></source>
    <source id="t"><float_array id="ta" count="8">0 0 1 0 1 1 0 1</float_array>
      <technique_common><accessor source="#ta" count="4" stride="2"/></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles material="paint" count="2">
      <input semantic="VERTEX" source="#v" offset="0"/>
      <input semantic="TEXCOORD" source="#t" offset="1" set="0"/>
      <p>0 0 1 1 2 2  0 0 2 2 3 3</p>
    </triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n" name="N"><instance_geometry url="#sq">
    <bind_material><technique_common><instance_material symbol="paint" target="#m"/></technique_common></bind_material>
  </instance_geometry></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##;
    let path = dir.join("square.dae");
    std::fs::write(&path, dae).unwrap();
    let mut scene = prism_scene::load(&path, &prism_scene::SceneOptions::default()).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    scene.lights = vec![Light::Environment {
        radiance: Rgb::WHITE,
    }];
    scene.camera = Camera {
        eye: Vec3::new(0.5, 0.5, 2.0),
        target: Vec3::new(0.5, 0.5, 0.0),
        up: Vec3::Y,
        hfov: 20.0,
        vfov: 20.0,
        near: 0.01,
        far: 100.0,
        lens: None,
        orthographic: None,
        crop: None,
    };
    scene
}

/// Oracles for textured diffuse: a flat surface under a unit environment reflects exactly
/// its albedo (the white furnace), so the picture is the texture, sRGB-decoded, with v up
/// the image (a texture red in its top half and blue in its bottom half renders red above
/// and blue below); and a constant texture renders as the untextured diffuse of its
/// colour.
#[test]
fn textured_diffuse_shows_its_texture_the_right_way_up() {
    let halves =
        prism_image::Image::from_fn(4, 4, |_, y| if y < 2 { [255, 0, 0] } else { [0, 0, 255] });
    let scene = RenderScene::new(&textured_square(&halves, "halves"));
    let opts = RenderOptions {
        film: FilmSettings {
            width: 16,
            height: 16,
            spp: 16,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    };
    let img = render(
        &scene,
        &RenderOptions {
            film: FilmSettings {
                spp: 64,
                ..opts.film
            },
            ..opts
        },
        &|_| {},
    )
    .image;
    // The mean of rows 1..4 (a quarter up from the top) and 12..15 (from the bottom).
    let band = |rows: std::ops::Range<u32>| {
        let n = (rows.len() * 16) as f32;
        rows.flat_map(|y| (0..16).map(move |x| (x, y)))
            .fold(Rgb::BLACK, |a, (x, y)| a + img.get(x, y))
            * (1.0 / n)
    };
    let (top, bottom) = (band(1..4), band(12..15));
    assert!(
        (top.r - 1.0).abs() < 0.02 && top.b == 0.0,
        "top {top:?} should be red"
    );
    assert!(
        (bottom.b - 1.0).abs() < 0.02 && bottom.r == 0.0,
        "bottom {bottom:?} should be blue"
    );
    let grey = prism_image::Image::from_fn(3, 3, |_, _| [128u8, 128, 128]);
    let textured = mean(
        &render(
            &RenderScene::new(&textured_square(&grey, "grey")),
            &opts,
            &|_| {},
        )
        .image,
    );
    let mut plain = textured_square(&grey, "plain");
    let linear = prism_image::srgb_to_linear(128.0 / 255.0);
    plain.materials[0] = Material::Diffuse {
        reflectance: Rgb::splat(linear),
        texture: None,
    };
    let untextured = mean(&render(&RenderScene::new(&plain), &opts, &|_| {}).image);
    assert!(
        (textured.g / untextured.g - 1.0).abs() < 1e-5 && (textured.g / linear - 1.0).abs() < 0.02,
        "{textured:?} vs {untextured:?} (albedo {linear})"
    );
}

/// Oracle: the one-path-at-a-time integrator. The wavefront integrator (the default `path`)
/// draws the same random numbers and adds the same terms in the same order, so it must give
/// the same bytes: on every staged scene with a light (diffuse and rough conductor surfaces
/// run sixteen at a time, mirrors and glass one by one), on the furnace's environment
/// light, under point and directional lights alone and beside an area light, under an
/// emissive mesh and an environment map (which the lanes sample lane by lane), and with the
/// options that change which paths take which step (one bounce kept, several light samples,
/// adaptive sampling, a thin lens, short paths, early roulette).
#[test]
fn wavefront_equals_path_scalar_bit_for_bit() {
    let same = |scene: &RenderScene, opts: RenderOptions, what: &str| {
        let a = render(scene, &opts, &|_| {});
        let b = render(
            scene,
            &RenderOptions {
                path: PathSettings {
                    integrator: Integrator::PathScalar,
                    ..opts.path
                },
                ..opts
            },
            &|_| {},
        );
        assert!(bits(&a) == bits(&b), "{what}: the images differ");
        assert_eq!(a.samples.pixels(), b.samples.pixels(), "{what}");
    };
    let small = RenderOptions {
        film: FilmSettings {
            width: 32,
            height: 24,
            spp: 4,
            seed: 11,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    };
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/assets/pathtracer/dae/sky");
    let mut staged = 0;
    for entry in std::fs::read_dir(&dir).expect("the staged scenes") {
        let path = entry.unwrap().path();
        let scene = prism_scene::load(&path, &prism_scene::SceneOptions::default()).expect("loads");
        if scene.lights.is_empty() {
            continue;
        }
        same(
            &RenderScene::new(&scene),
            small,
            &path.display().to_string(),
        );
        staged += 1;
    }
    assert!(staged >= 8, "{staged} staged scenes");
    for material in [
        Material::Diffuse {
            reflectance: Rgb::splat(0.7),
            texture: None,
        },
        Material::Glass {
            reflectance: Rgb::WHITE,
            transmittance: Rgb::WHITE,
            ior: 1.5,
            roughness: 0.0,
        },
    ] {
        same(&RenderScene::new(&furnace(material)), small, "furnace");
    }
    let cornell = RenderScene::new(&prism_scene::cornell_box());
    let variants = [
        (
            "one bounce kept",
            RenderOptions {
                path: PathSettings {
                    only_bounce: Some(2),
                    ..small.path
                },
                ..small
            },
        ),
        (
            "three light samples",
            RenderOptions {
                path: PathSettings {
                    light_samples: 3,
                    ..small.path
                },
                ..small
            },
        ),
        (
            "adaptive",
            RenderOptions {
                film: FilmSettings {
                    spp: 16,
                    adaptive: Some(0.3),
                    batch: 4,
                    ..small.film
                },
                ..small
            },
        ),
        (
            "two bounces",
            RenderOptions {
                path: PathSettings {
                    max_bounces: 2,
                    ..small.path
                },
                ..small
            },
        ),
        (
            "early roulette",
            RenderOptions {
                path: PathSettings {
                    rr_bounces: 1,
                    ..small.path
                },
                ..small
            },
        ),
    ];
    for (what, opts) in variants {
        same(&cornell, opts, what);
    }
    // Point and directional lights (one sample each, unweighted), alone and beside the
    // area light with several samples of its own.
    let point = Light::Point {
        position: Vec3::new(0.3, 1.2, 0.2),
        intensity: Rgb::new(2.0, 1.5, 1.0),
    };
    let sun = Light::Directional {
        direction: Vec3::new(0.3, -1.0, -0.2).normalize(),
        irradiance: Rgb::new(0.5, 0.6, 0.7),
    };
    for (what, lights, samples) in [
        ("point light", vec![point.clone()], 1),
        ("directional light", vec![sun.clone()], 1),
        (
            "area, point and directional lights",
            vec![point.clone(), sun.clone()],
            3,
        ),
    ] {
        let mut lit = prism_scene::cornell_box();
        if what.starts_with("area") {
            lit.lights.extend(lights);
        } else {
            lit.lights = lights;
        }
        let opts = RenderOptions {
            path: PathSettings {
                light_samples: samples,
                ..small.path
            },
            ..small
        };
        same(&RenderScene::new(&lit), opts, what);
    }
    // An emissive mesh (a tilted triangle pair under the ceiling) beside the area light,
    // and a map of varying radiance around an open scene: lights the lanes sample lane by
    // lane with their own code.
    let mut glowing = prism_scene::cornell_box();
    glowing.materials.push(Material::Emission {
        radiance: Rgb::new(4.0, 3.0, 2.0),
    });
    glowing.meshes.push(prism_scene::TriangleMesh {
        name: "glow".into(),
        positions: vec![
            Vec3::new(-0.6, 1.2, -0.3),
            Vec3::new(-0.2, 1.3, -0.3),
            Vec3::new(-0.2, 1.1, 0.2),
            Vec3::new(-0.6, 1.0, 0.2),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        shading: prism_scene::Shading::Flat,
        material: glowing.materials.len() - 1,
        uvs: None,
    });
    let opts = RenderOptions {
        path: PathSettings {
            light_samples: 2,
            ..small.path
        },
        ..small
    };
    same(&RenderScene::new(&glowing), opts, "emissive mesh");
    // One light picked per light sample (Mitsuba's estimator) among the area light, the
    // emissive mesh, a point and a directional light and an emitting sphere: the lanes of a
    // group pick different lights.
    let mut four = glowing.clone();
    four.lights.extend([point.clone(), sun.clone()]);
    // And a sphere under an area emitter (sampled by its cone, lane by lane).
    four.materials.push(Material::AreaEmitter {
        radiance: Rgb::new(2.0, 2.5, 3.0),
        texture: None,
        surface: None,
    });
    four.spheres.push(SceneSphere {
        center: Vec3::new(0.5, 1.2, 0.3),
        radius: 0.15,
        material: four.materials.len() - 1,
        inward: false,
        to_local: None,
    });
    let four = RenderScene::new(&four);
    for (samples, one_light) in [(1, true), (3, true), (2, false)] {
        let opts = RenderOptions {
            path: PathSettings {
                light_samples: samples,
                one_light,
                ..small.path
            },
            ..small
        };
        let what = format!("five lights, one picked: {one_light}, {samples} samples");
        same(&four, opts, &what);
    }
    let mut mapped = furnace(Material::Diffuse {
        reflectance: Rgb::splat(0.6),
        texture: None,
    });
    mapped.lights = vec![Light::EnvironmentMap {
        radiance: std::sync::Arc::new(prism_image::Image::from_fn(16, 8, |x, y| {
            Rgb::new(0.2 + x as f32 * 0.1, 1.0 / (1.0 + y as f32), 0.5)
        })),
        mapping: prism_scene::EnvMapping::Course,
    }];
    same(&RenderScene::new(&mapped), small, "environment map");
    // The same map laid as Mitsuba lays one, turned: its lookups are made for a whole pass
    // at once on lanes.
    if let Some(Light::EnvironmentMap { mapping, .. }) = mapped.lights.first_mut() {
        *mapping = prism_scene::EnvMapping::Mitsuba {
            to_local: prism_math::glam::Mat3::from_rotation_y(0.7)
                * prism_math::glam::Mat3::from_rotation_x(-0.3),
        };
    }
    same(
        &RenderScene::new(&mapped),
        small,
        "Mitsuba's environment map",
    );
    let mut lens = prism_scene::cornell_box();
    lens.camera.lens = Some(prism_scene::ThinLens {
        radius: 0.05,
        focal_distance: 3.0,
    });
    same(&RenderScene::new(&lens), small, "thin lens");
}
