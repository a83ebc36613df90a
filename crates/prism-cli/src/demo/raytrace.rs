//! The gallery's Whitted ray-tracer pictures: the presets, feature switches side by side,
//! the template's extras, bloom and its layer, a BVH level, and a pixel's ray tree.

use std::path::Path;

use anyhow::{Context, Result};
use prism_image::montage;

use super::index::Entry;

/// The luminance above which the gallery's bloom picture blooms.
const BLOOM_THRESHOLD: f32 = 0.8;

/// The Whitted ray tracer's pictures: the presets, feature switches side by side, bloom
/// and its layer, a BVH level and a pixel's ray tree over the mirror Cornell box.
pub fn pictures(output: &Path, assets: Option<&Path>, entries: &mut Vec<Entry>) -> Result<()> {
    use prism_render::whitted::camera::OrbitView;
    use prism_render::whitted::film::{raytrace, trace_pixel, RaytraceOptions};
    use prism_render::whitted::overlay::Overlay;
    use prism_render::whitted::scene::WhittedScene;
    use prism_scene::{OrbitCamera, Preset};
    let dirs: Vec<_> = assets
        .map(|a| a.join("delft-raytracer/data"))
        .into_iter()
        .collect();
    let on = prism_scene::Features::prism_defaults();
    let opts = |size: u32, features: prism_scene::Features| RaytraceOptions {
        width: size,
        height: size,
        settings: prism_render::whitted::tracer::WhittedSettings {
            features,
            light_samples: 16,
            max_depth: 3,
            extras: prism_scene::Extras::default(),
        },
        spp: 4,
        bloom: prism_image::Bloom::default(),
        seed: 0,
    };
    let cam = OrbitCamera::default();
    let user = |e: prism_scene::SceneError| crate::error::UserError::input(e);
    let write = |name: &str, img: &prism_image::RgbImage| {
        prism_image::write_png(&output.join(name), &img.to_rgb8_truncated())
            .with_context(|| format!("writing {name}"))
    };
    // A grid of `cols` columns of `size`-pixel panels, each labelled.
    let write_grid =
        |name: &str, panels: &[prism_image::RgbImage], cols: usize, size: u32, labels: &[&str]| {
            let mut img = montage(panels, cols, prism_math::Rgb::BLACK).to_rgb8_truncated();
            super::labels::label_panels(&mut img, size, size, cols, labels);
            prism_image::write_png(&output.join(name), &img)
                .with_context(|| format!("writing {name}"))
        };
    // Every preset whose file is here (the dragon is never shipped).
    let mut panels = Vec::new();
    let mut names = Vec::new();
    for p in Preset::ALL {
        let Ok(scene) = p.load(&dirs) else { continue };
        let ws = WhittedScene::new(&scene, true);
        panels.push(raytrace(&ws, &cam, &opts(200, on), &|_| {}).image);
        names.push(p.name());
    }
    write_grid("raytrace_presets.png", &panels, 3, 200, &names)?;
    entries.push(Entry {
        file: "raytrace_presets.png".into(),
        caption: format!("prism raytrace presets: {}", names.join(", ")),
    });
    // Feature switches on the mirror Cornell box with its point light.
    let scene = Preset::CornellBox.load(&dirs).map_err(user)?;
    let ws = WhittedScene::new(&scene, true);
    let switches: [(&str, prism_scene::Features); 4] = [
        ("everything on", on),
        (
            "--disable shading",
            prism_scene::Features {
                shading: false,
                ..on
            },
        ),
        (
            "--disable hard-shadow",
            prism_scene::Features {
                hard_shadow: false,
                ..on
            },
        ),
        (
            "--disable recursive",
            prism_scene::Features {
                recursive: false,
                ..on
            },
        ),
    ];
    let panels: Vec<_> = switches
        .iter()
        .map(|(_, f)| raytrace(&ws, &cam, &opts(200, *f), &|_| {}).image)
        .collect();
    let labels: Vec<&str> = switches.iter().map(|s| s.0).collect();
    write_grid("raytrace_toggles.png", &panels, 4, 200, &labels)?;
    entries.push(Entry {
        file: "raytrace_toggles.png".into(),
        caption: format!(
            "cornell-box, left to right: {}",
            switches.iter().map(|s| s.0).collect::<Vec<_>>().join(", ")
        ),
    });
    // The template's extras, each beside the plain picture.
    extras(&dirs, &cam, &opts, &write_grid, entries)?;
    // Bloom on the teapot, and the layer it adds.
    // The teapot's highlight blooms; without the course's files, the built-in spheres.
    let (bloomed, scene) = match Preset::Teapot.load(&dirs) {
        Ok(s) => ("the teapot", s),
        Err(_) => ("spheres", Preset::Spheres.load(&dirs).map_err(user)?),
    };
    let teapot = WhittedScene::new(&scene, true);
    let mut b = opts(300, prism_scene::Features { bloom: true, ..on });
    b.bloom.passes = 2;
    // Only what is brighter than this blooms: the highlights, not the whole picture.
    b.bloom.threshold = BLOOM_THRESHOLD;
    let out = raytrace(&teapot, &cam, &b, &|_| {});
    write("raytrace_bloom.png", &out.image)?;
    write(
        "raytrace_bloom_layer.png",
        out.bloom_layer.as_ref().expect("bloom is on"),
    )?;
    entries.push(Entry {
        file: "raytrace_bloom.png".into(),
        caption: format!(
            "{bloomed} with bloom: what passes the threshold glows (--enable bloom \
             --bloom-passes 2 --bloom-threshold {BLOOM_THRESHOLD})"
        ),
    });
    entries.push(Entry {
        file: "raytrace_bloom_layer.png".into(),
        caption: "its bloom layer alone (--bloom-debug)".into(),
    });
    // The mirror Cornell box: a BVH level, and the ray tree of a pixel on the mirror.
    let scene = Preset::CornellBox.load(&dirs).map_err(user)?;
    let ws = WhittedScene::new(&scene, true);
    let o = opts(300, on);
    let img = raytrace(&ws, &cam, &o, &|_| {}).image;
    let mut ov = Overlay::new(img.clone(), OrbitView::new(&cam, 300, 300), &ws);
    let bvh = ws.bvh().expect("built");
    for (i, bx) in bvh.level_boxes(1).iter().enumerate() {
        ov.aabb(bx, prism_render::whitted::overlay::palette(i));
    }
    write("raytrace_bvh_level.png", &ov.image)?;
    entries.push(Entry {
        file: "raytrace_bvh_level.png".into(),
        caption: "the BVH's level 1 over the mirror Cornell box (--bvh-level 1)".into(),
    });
    // The middle one of the pixels of row 120 whose camera rays meet the mirror box.
    let on_mirror: Vec<_> = (0..300)
        .map(|x| trace_pixel(&ws, &cam, &o, x, 120))
        .filter(|t| {
            t.rays
                .first()
                .and_then(|r| r.hit.as_ref())
                .is_some_and(|h| h.0 == "tallBox")
        })
        .collect();
    if let Some(t) = on_mirror.get(on_mirror.len() / 2) {
        let debug_cam = OrbitCamera {
            rotation: prism_math::Vec3::new(10.0, -15.0, 0.0),
            distance: 3.2,
            ..cam
        };
        let base = raytrace(&ws, &debug_cam, &o, &|_| {})
            .image
            .map(|p| *p * 0.5);
        let mut ov = Overlay::new(base, OrbitView::new(&debug_cam, 300, 300), &ws);
        for r in &t.rays {
            let on_top = matches!(
                r.kind,
                prism_render::whitted::tracer::RayKind::Normal
                    | prism_render::whitted::tracer::RayKind::InterpolatedNormal
            );
            ov.segment(r.origin, r.end, r.color, !on_top);
        }
        for r in &t.rays {
            if let Some(p) = r.blocked_at {
                ov.marker(p, prism_math::Rgb::new(1.0, 0.0, 0.0));
            }
        }
        write("raytrace_debug_pixel.png", &ov.image)?;
        entries.push(Entry {
            file: "raytrace_debug_pixel.png".into(),
            caption: format!(
                "the ray tree of pixel {},{} on the mirror box, seen from another orbit \
                 (--debug-pixel {},{} --debug-camera 10,-15,0,3.2)",
                t.pixel.0, t.pixel.1, t.pixel.0, t.pixel.1
            ),
        });
    }
    Ok(())
}

/// Writes a labelled grid: file name, panels, columns, panel size, labels.
type GridWriter<'a> =
    dyn Fn(&str, &[prism_image::RgbImage], usize, u32, &[&str]) -> Result<()> + 'a;

/// The extras' panel: the Cornell box plain, with depth of field, with the tall box moving,
/// with glossy reflection and under the demo's sky; and the textured cube's mip-mapping.
fn extras(
    dirs: &[std::path::PathBuf],
    cam: &prism_scene::OrbitCamera,
    opts: &dyn Fn(u32, prism_scene::Features) -> prism_render::whitted::film::RaytraceOptions,
    write_grid: &GridWriter<'_>,
    entries: &mut Vec<Entry>,
) -> Result<()> {
    use prism_render::whitted::film::raytrace;
    use prism_render::whitted::scene::{Environment, SceneSetup, Split, WhittedScene};
    use prism_scene::{Features, Preset};
    let user = |e: prism_scene::SceneError| crate::error::UserError::input(e);
    let on = Features::prism_defaults();
    let scene = Preset::CornellBox.load(dirs).map_err(user)?;
    let tall = (scene.meshes.iter())
        .position(|m| m.name == "tallBox")
        .unwrap_or(0);
    let ws = WhittedScene::prepare(
        &scene,
        SceneSetup {
            bvh: Some(Split::Sah),
            motion: vec![(tall, prism_math::Vec3::new(0.3, 0.0, 0.0))],
            environment: Some(Environment::new(super::render::sky_map(), 1.0)),
        },
    );
    let size = 200;
    let mut panels = Vec::new();
    let with = |f: Features| {
        let mut o = opts(size, f);
        o.settings.extras.dof_aperture = 0.1;
        o.settings.extras.dof_focal_distance = Some(2.2);
        raytrace(&ws, cam, &o, &|_| {}).image
    };
    panels.push(with(on));
    for f in [
        Features {
            depth_of_field: true,
            ..on
        },
        Features {
            motion_blur: true,
            ..on
        },
        Features {
            glossy_reflection: true,
            ..on
        },
        Features {
            environment_mapping: true,
            ..on
        },
    ] {
        panels.push(with(f));
    }
    let cube = Preset::CubeTextured.load(dirs).map_err(user)?;
    let cube = WhittedScene::new(&cube, true);
    let far = prism_scene::OrbitCamera {
        distance: 6.0,
        ..*cam
    };
    let mip = Features { mipmap: true, ..on };
    panels.push(raytrace(&cube, &far, &opts(size, mip), &|_| {}).image);
    let labels = [
        "plain",
        "depth of field",
        "motion blur",
        "glossy",
        "environment map",
        "mip-mapped",
    ];
    let flags = [
        "everything on",
        "--dof-aperture 0.1 --dof-focal-distance 2.2",
        "--motion tallBox=0.3,0,0",
        "--enable glossy",
        "--environment-map sky.exr",
        "cube-textured at distance 6, --enable mipmap",
    ];
    write_grid("raytrace_extras.png", &panels, 3, size, &labels)?;
    entries.push(Entry {
        file: "raytrace_extras.png".into(),
        caption: format!(
            "the template's extras on cornell-box, left to right and down: {}",
            flags.join("; ")
        ),
    });
    Ok(())
}
