//! The gallery's path-traced pictures: the Cornell box, adaptive sampling and its heat map,
//! single bounces, a Mitsuba 3 scene, and the course's bunnies (one under a procedural sky
//! map) when staged.

use std::path::Path;

use anyhow::{Context, Result};
use indicatif::ProgressBar;
use prism_image::Image;
use prism_render::film::FilmSettings;
use prism_render::integrators::PathSettings;
use prism_render::render::RenderOptions;

use super::index::Entry;

/// Path-traces a scene for the gallery and writes the PNG (and, if asked, the heat map).
fn trace(
    scene: &prism_scene::Scene,
    opts: &RenderOptions,
    out: &Path,
    heat: Option<&Path>,
) -> Result<()> {
    let prepared = prism_render::render_scene::RenderScene::new(scene);
    let r = prism_render::render::render(&prepared, opts, &|_| {});
    prism_image::write_png(out, &r.image.linear_to_srgb8())
        .with_context(|| format!("writing {}", out.display()))?;
    if let Some(h) = heat {
        prism_image::write_png(h, &prism_image::heatmap(&r.samples))
            .with_context(|| format!("writing {}", h.display()))?;
    }
    Ok(())
}

/// A small sky for the environment-map demo, in linear radiance: blue overhead fading to a
/// pale horizon, a warm sun above the camera's right shoulder, and a dim brown ground.
pub(super) fn sky_map() -> prism_image::RgbImage {
    let sun = prism_math::Vec3::new(0.5, 0.7, 0.6).normalize();
    Image::from_fn(128, 64, |x, y| {
        let uv = prism_math::Vec2::new((x as f32 + 0.5) / 128.0, (y as f32 + 0.5) / 64.0);
        let d = prism_render::lights::envmap::uv_to_direction(uv);
        if d.y < 0.0 {
            return prism_math::Rgb::new(0.25, 0.18, 0.12);
        }
        let t = d.y.sqrt();
        let sky = prism_math::Rgb::new(0.9, 0.95, 1.0) * (1.0 - t)
            + prism_math::Rgb::new(0.25, 0.45, 1.0) * t;
        if d.dot(sun) > 0.995 {
            prism_math::Rgb::new(60.0, 50.0, 35.0)
        } else {
            sky
        }
    })
}

/// The Mitsuba 3 scene the gallery renders (built-in shapes only, so it stands alone).
const SHOWCASE: &str = include_str!("../../../../docs/examples/mitsuba/showcase.xml");

/// The path-traced pictures, eight steps of `pb`; the bunnies only when `assets` holds them.
/// Writes the sky map, sky.exr, and the Mitsuba scene, showcase.xml, beside the pictures.
pub fn pictures(
    output: &Path,
    assets: Option<&Path>,
    entries: &mut Vec<Entry>,
    pb: &ProgressBar,
) -> Result<()> {
    // Path tracing: the Cornell box, its sample-rate heat map and its bounce decomposition.
    let cornell = prism_scene::cornell_box();
    let base = RenderOptions {
        film: FilmSettings {
            width: 256,
            height: 192,
            spp: 64,
            ..FilmSettings::default()
        },
        ..RenderOptions::default()
    };
    trace(&cornell, &base, &output.join("render_cornell.png"), None)?;
    entries.push(Entry {
        file: "render_cornell.png".into(),
        caption: "Cornell box path-traced: 64 samples per pixel, next-event estimation with MIS"
            .into(),
    });
    pb.inc(1);
    // The course's adaptive-sampling settings (2048 samples at most, checked every 64), at
    // a small size, so the map shows where the samples went.
    let adaptive = RenderOptions {
        film: FilmSettings {
            width: 128,
            height: 96,
            spp: 2048,
            batch: 64,
            adaptive: Some(0.05),
            ..base.film
        },
        ..base
    };
    trace(
        &cornell,
        &adaptive,
        &output.join("render_adaptive.png"),
        Some(&output.join("render_heatmap.png")),
    )?;
    entries.push(Entry {
        file: "render_adaptive.png".into(),
        caption: "Cornell box with adaptive sampling (tolerance 0.05, at most 2048 samples, \
                  checked every 64)"
            .into(),
    });
    entries.push(Entry {
        file: "render_heatmap.png".into(),
        caption: "Adaptive sampling (tolerance 0.05, at most 2048 samples, checked every 64): \
                  samples per pixel, blue few, red many"
            .into(),
    });
    pb.inc(1);
    for (m, name) in [
        (1, "direct light"),
        (2, "second bounce"),
        (3, "third bounce"),
    ] {
        let file = format!("render_bounce_{m}.png");
        let opts = RenderOptions {
            path: PathSettings {
                only_bounce: Some(m),
                ..base.path
            },
            ..base
        };
        trace(&cornell, &opts, &output.join(&file), None)?;
        entries.push(Entry {
            file,
            caption: format!("Only the {name} (--bounce {m})"),
        });
        pb.inc(1);
    }
    // A Mitsuba 3 scene file, rendered with its own film, sampler and depth.
    let showcase = output.join("showcase.xml");
    std::fs::write(&showcase, SHOWCASE)
        .with_context(|| format!("writing {}", showcase.display()))?;
    let m = prism_scene::read_mitsuba(&showcase, &[]).map_err(crate::error::UserError::input)?;
    let opts = RenderOptions::mitsuba(&m.settings, base);
    trace(&m.scene, &opts, &output.join("render_mitsuba.png"), None)?;
    entries.push(Entry {
        file: "render_mitsuba.png".into(),
        caption: "A Mitsuba 3 scene file (showcase.xml): rough glass, GGX gold, rough plastic, \
                  a checkerboard texture and instances"
            .into(),
    });
    pb.inc(1);
    let course = |rel: &str| assets.map(|a| a.join(rel)).filter(|p| p.is_file());
    if let Some(bunny) = course("pathtracer/dae/sky/CBbunny.dae") {
        let doc = prism_scene::read_collada(&bunny).map_err(crate::error::UserError::input)?;
        let scene = prism_scene::Scene::from_collada(
            &doc,
            &prism_scene::SceneOptions::default(),
            &bunny.display().to_string(),
        )
        .map_err(crate::error::UserError::input)?;
        trace(&scene, &base, &output.join("render_bunny.png"), None)?;
        entries.push(Entry {
            file: "render_bunny.png".into(),
            caption: "CBbunny.dae from the course, 64 samples per pixel".into(),
        });
    }
    // The course's unlit bunny under a procedural sky map (written beside the pictures).
    let sky = sky_map();
    prism_image::write_exr(&output.join("sky.exr"), &sky)?;
    if let Some(unlit) = course("pathtracer/dae/sky/bunny_unlit.dae") {
        let doc = prism_scene::read_collada(&unlit).map_err(crate::error::UserError::input)?;
        let mut scene = prism_scene::Scene::from_collada(
            &doc,
            &prism_scene::SceneOptions::default(),
            &unlit.display().to_string(),
        )
        .map_err(crate::error::UserError::input)?;
        scene.lights = vec![prism_scene::Light::EnvironmentMap {
            radiance: std::sync::Arc::new(sky),
            mapping: prism_scene::EnvMapping::Course,
        }];
        trace(&scene, &base, &output.join("render_envmap.png"), None)?;
        entries.push(Entry {
            file: "render_envmap.png".into(),
            caption: "bunny_unlit.dae lit by a procedural sky map (--envmap sky.exr), 64 \
                      samples per pixel"
                .into(),
        });
    }
    pb.inc(1);
    Ok(())
}
