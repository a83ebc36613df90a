//! Fuzz the Delft ray tracer's readers: an OBJ with its MTL and texture, or a TOML render
//! config. Any input must give a scene or an error naming the file, never a panic; a scene
//! is ray-traced at 4x4 pixels (an OBJ with every feature and extra on, a config with its
//! own, sample counts capped), and no pixel may be NaN or negative.
//!
//! Input: a first byte choosing the reader (even: OBJ, odd: config), then for an OBJ the
//! OBJ text, a NUL, the MTL text (`m.mtl`), a NUL and the texture's bytes (`t.png`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use prism_math::{Rgb, Vec3};
use prism_render::whitted::film::{raytrace, RaytraceOptions};
use prism_render::whitted::scene::{Environment, SceneSetup, Split, WhittedScene};
use prism_render::whitted::tracer::WhittedSettings;
use prism_scene::{
    parse_obj_scene, parse_render_config, Features, Material, OrbitCamera, Scene, SceneError,
    Shading, TriangleMesh,
};

/// Every feature and extra on.
fn everything() -> Features {
    Features {
        bloom: true,
        multiple_rays_per_pixel: true,
        transparency: true,
        depth_of_field: true,
        motion_blur: true,
        glossy_reflection: true,
        environment_mapping: true,
        mipmap: true,
        ..Features::prism_defaults()
    }
}

fn render(
    scene: &Scene,
    camera: &OrbitCamera,
    features: Features,
    extras: prism_scene::Extras,
    motion: &[(usize, Vec3)],
) {
    let triangles: usize = scene.meshes.iter().map(|m| m.triangles.len()).sum();
    if triangles > 4096 {
        return;
    }
    let extras = prism_scene::Extras {
        dof_samples: extras.dof_samples.min(3),
        motion_samples: extras.motion_samples.min(3),
        glossy_samples: extras.glossy_samples.min(2),
        ..extras
    };
    let opts = RaytraceOptions {
        width: 4,
        height: 4,
        settings: WhittedSettings {
            features,
            light_samples: 4,
            max_depth: 3,
            extras,
        },
        spp: 2,
        bloom: prism_image::Bloom::default(),
        seed: 0,
    };
    for (bvh, split) in [(true, Split::Sah), (true, Split::Median), (false, Split::Sah)] {
        let setup = SceneSetup {
            bvh: bvh.then_some(split),
            motion: motion.to_vec(),
            environment: Some(Environment::new(
                prism_image::Image::from_fn(3, 2, |x, y| Rgb::new(x as f32, y as f32, 0.5)),
                extras.environment_strength,
            )),
        };
        let ws = WhittedScene::prepare(scene, setup);
        let out = raytrace(&ws, camera, &opts, &|_| {});
        for p in out.image.pixels() {
            assert!(
                !p.r.is_nan() && !p.g.is_nan() && !p.b.is_nan() && p.r >= 0.0 && p.g >= 0.0 && p.b >= 0.0,
                "{p:?}"
            );
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else { return };
    if mode % 2 == 0 {
        let mut parts = rest.splitn(3, |&b| b == 0);
        let obj = parts.next().unwrap_or(&[]);
        let mtl = parts.next().unwrap_or(&[]).to_vec();
        let tex = parts.next().unwrap_or(&[]).to_vec();
        let Ok(text) = std::str::from_utf8(obj) else { return };
        let companions = |name: &str| match name {
            "m.mtl" => Ok(mtl.clone()),
            "t.png" => Ok(tex.clone()),
            _ => Err(SceneError::NotAFile { path: name.to_string() }),
        };
        match parse_obj_scene(text, "fuzz.obj", &companions, mode % 4 == 0) {
            Ok(mut scene) => {
                scene.lights = vec![prism_scene::Light::Point {
                    position: Vec3::new(-1.0, 1.0, -1.0),
                    intensity: Rgb::WHITE,
                }];
                let motion = [(0, Vec3::new(0.1, 0.0, 0.2))];
                render(&scene, &OrbitCamera::default(), everything(), Default::default(), &motion);
            }
            Err(e) => {
                let s = e.to_string();
                assert!(s.starts_with("fuzz.obj") || s.starts_with("m.mtl"), "{s}");
            }
        }
    } else {
        let Ok(text) = std::str::from_utf8(rest) else { return };
        match parse_render_config(text, "fuzz.toml", std::path::Path::new("/nonexistent")) {
            Ok(cfg) => {
                // The config's lights and cameras over one triangle.
                let scene = Scene {
                    meshes: vec![TriangleMesh {
                        name: "t".into(),
                        positions: vec![
                            Vec3::new(-1.0, -1.0, 0.0),
                            Vec3::new(1.0, -1.0, 0.0),
                            Vec3::new(0.0, 1.0, 0.0),
                        ],
                        triangles: vec![[0, 1, 2]],
                        shading: Shading::Flat,
                        material: 0,
                        uvs: None,
                    }],
                    spheres: vec![],
                    materials: vec![Material::Phong {
                        kd: Rgb::splat(0.5),
                        ks: Rgb::splat(0.5),
                        shininess: 8.0,
                        kd_texture: None,
                        transparency: 0.5,
                    }],
                    material_names: vec![],
                    one_sided: vec![false],
                    lights: cfg.lights.clone(),
                    camera: OrbitCamera::default().to_camera(1.0),
                    warnings: vec![],
                };
                let mut motion = Vec::new();
                for m in &cfg.extras.motion {
                    motion.extend(m.mesh.resolve(&scene).into_iter().map(|i| (i, m.velocity)));
                }
                for c in cfg.cameras.iter().take(4) {
                    render(&scene, c, cfg.features, cfg.extras.extras, &motion);
                }
            }
            Err(e) => assert!(e.to_string().starts_with("fuzz.toml"), "{e}"),
        }
    }
});
