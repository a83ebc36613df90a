//! `prism demo`: a gallery of the features, drawn from built-in inputs.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result};
use base64::Engine;
use clap::Args;
use prism_image::{encode_png, montage, Image, LevelSampling, PixelSampling};
use prism_raster::{parse_svg, render, Dialect, RasterOptions, Source};
use prism_render::film::FilmSettings;
use prism_render::integrators::PathSettings;
use prism_render::render::RenderOptions;

/// Arguments of `prism demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Folder to write the gallery into (created if missing).
    #[arg(short, long, default_value = "gallery")]
    pub output: PathBuf,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
    /// The course's staged assets, for the pictures that need their files (the bunny); those
    /// pictures are left out when the folder is missing.
    #[arg(long, default_value = "../shared/assets")]
    pub assets: PathBuf,
}

/// Path-traces a scene for the gallery and writes the PNG (and, if asked, the heat map).
fn trace(
    scene: &prism_scene::Scene,
    opts: &RenderOptions,
    out: &std::path::Path,
    heat: Option<&std::path::Path>,
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

/// A fan of thin triangles: aliasing shows at one sample per pixel.
fn fan_svg() -> String {
    let mut s =
        String::from(r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200">"#);
    for k in 0..36 {
        let a0 = (k as f64) * std::f64::consts::TAU / 36.0;
        let a1 = a0 + 0.06;
        let _ = write!(
            s,
            r##"<polygon points="100,100 {:.3},{:.3} {:.3},{:.3}" fill="#{:02x}30{:02x}"/>"##,
            100.0 + 95.0 * a0.cos(),
            100.0 + 95.0 * a0.sin(),
            100.0 + 95.0 * a1.cos(),
            100.0 + 95.0 * a1.sin(),
            (k * 7) as u8,
            255 - (k * 7) as u8
        );
    }
    s.push_str("</svg>");
    s
}

/// A hexagon of barycentric colour triangles.
fn colortri_svg() -> String {
    let mut s =
        String::from(r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200">"#);
    let hue = |k: usize| -> [f64; 3] {
        let t = k as f64 / 6.0 * 3.0;
        let c = |o: f64| (((t - o).rem_euclid(3.0) - 1.0).abs() - 0.0).clamp(0.0, 1.0);
        [1.0 - c(0.0), 1.0 - c(1.0), 1.0 - c(2.0)]
    };
    for k in 0..6 {
        let a0 = k as f64 * std::f64::consts::TAU / 6.0;
        let a1 = a0 + std::f64::consts::TAU / 6.0;
        let (c0, c1) = (hue(k), hue((k + 1) % 6));
        let _ = write!(
            s,
            r#"<colortri points="100 100 {:.3} {:.3} {:.3} {:.3}" colors="1 1 1 1 {} {} {} 1 {} {} {} 1"/>"#,
            100.0 + 90.0 * a0.cos(),
            100.0 + 90.0 * a0.sin(),
            100.0 + 90.0 * a1.cos(),
            100.0 + 90.0 * a1.sin(),
            c0[0],
            c0[1],
            c0[2],
            c1[0],
            c1[1],
            c1[2]
        );
    }
    s.push_str("</svg>");
    s
}

/// A checkerboard floor receding to the horizon, so texels are minified more and more: a
/// grid of small triangles whose uvs follow the floor, so that each is close to a true
/// perspective mapping. Level 0 shows moire in the distance, the nearest level blocks,
/// trilinear a smooth grey.
fn texture_svg() -> Result<String> {
    let tex = Image::from_fn(512, 512, |x, y| {
        if (x / 8 + y / 8) % 2 == 0 {
            [240, 240, 240]
        } else {
            [30, 60, 160]
        }
    });
    let uri = base64::engine::general_purpose::STANDARD.encode(encode_png(&tex)?);
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="300" height="200"><texture texid="c" filename="data:image/png;base64,{uri}"/>"#
    );
    // The floor spans x in [-30, 30] and depth z in [1, 60] (square checks); a point projects
    // to (150 + 150 x / z, 40 + 160 / z). Depths step geometrically, so rows are even on screen.
    let (rows, cols, far) = (48, 48, 60.0f64);
    let z = |j: usize| far.powf(j as f64 / rows as f64);
    let x = |i: usize| -30.0 + 60.0 * i as f64 / cols as f64;
    let screen = |i: usize, j: usize| (150.0 + 150.0 * x(i) / z(j), 40.0 + 160.0 / z(j));
    let uv = |i: usize, j: usize| (i as f64 / cols as f64, (z(j) - 1.0) / (far - 1.0));
    for j in 0..rows {
        for i in 0..cols {
            let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            for tri in [[0, 1, 2], [0, 2, 3]] {
                let (mut pts, mut uvs) = (String::new(), String::new());
                for k in tri {
                    let (ci, cj) = corners[k];
                    let ((px, py), (u, v)) = (screen(ci, cj), uv(ci, cj));
                    let _ = write!(pts, "{px} {py} ");
                    let _ = write!(uvs, "{u} {v} ");
                }
                let _ = write!(
                    s,
                    r#"<textri texid="c" uvs="{}" points="{}"/>"#,
                    uvs.trim_end(),
                    pts.trim_end()
                );
            }
        }
    }
    s.push_str("</svg>");
    Ok(s)
}

/// A small sky for the environment-map demo, in linear radiance: blue overhead fading to a
/// pale horizon, a warm sun above the camera's right shoulder, and a dim brown ground.
fn sky_map() -> prism_image::RgbImage {
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

/// Nested groups with every transform kind.
fn group_svg() -> String {
    let mut s = String::from(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="240" height="240"><g transform="translate(120 120)">"#,
    );
    for k in 0..8 {
        let _ = write!(
            s,
            r##"<g transform="rotate({})"><g transform="translate(60 0) scale(1.2 0.8)"><g transform="skewX(20)"><rect x="-18" y="-12" width="36" height="24" fill="#{:02x}a0{:02x}" stroke="#222" stroke-width="2"/><circle r="6" fill="#fff" fill-opacity="0.7"/></g></g></g>"##,
            k * 45,
            30 * k as u8,
            255 - 30 * k as u8
        );
    }
    s.push_str("</g></svg>");
    s
}

/// Draws a mesh Blinn-Phong shaded with its edges on top, framed from the front and a
/// little above, and writes it to a PNG.
fn write_shaded(mesh: &prism_mesh::PolyMesh, size: u32, out: &std::path::Path) -> Result<()> {
    let mut m = prism_shade::ShadeMesh::from_polymesh(mesh);
    let (lo, hi) = m.bounds().context("the mesh has vertices")?;
    let centre = (lo + hi) * 0.5;
    // A mesh wound inside out (the teapot's patches) is lit from outside all the same.
    let outward: f32 = m
        .positions
        .iter()
        .zip(&m.normals)
        .map(|(p, n)| n.dot(*p - centre))
        .sum();
    if outward < 0.0 {
        m.normals.iter_mut().for_each(|n| *n = -*n);
    }
    let r = (hi - lo).length() * 0.5;
    let dir = prism_math::Vec3::new(0.35, 0.45, 1.0).normalize();
    let view = prism_shade::View::fit(
        centre,
        r,
        dir,
        prism_math::Vec3::Y,
        45.0,
        size,
        size,
        prism_shade::Framing::Vertical { margin: 1.05 },
    );
    let u = prism_shade::Uniforms {
        light_pos: centre + prism_math::Vec3::new(2.0, 3.0, 4.0) * r,
        light_intensity: prism_math::Rgb::splat((29.0f32 * r * r).max(1e-6)),
        ..prism_shade::Uniforms::default()
    };
    let opts = prism_shade::ShadeOptions {
        samples: 4,
        background: prism_math::Rgb::WHITE,
        wireframe: Some(prism_math::Rgb::splat(0.15)),
        // Thinner edges on dense meshes.
        wire_width: if m.triangles.len() > 1000 { 0.3 } else { 0.75 },
    };
    let img = prism_shade::shade(&m, &view, &prism_shade::Shader::Phong, &u, &opts)
        .map_err(|e| crate::error::UserError(e.to_string()))?;
    prism_image::write_png(out, &prism_shade::to_bytes(&img))
        .with_context(|| format!("writing {}", out.display()))
}

struct Entry {
    file: String,
    caption: String,
}

fn draw(svg: &str, dialect: Dialect, opts: &RasterOptions, out: &std::path::Path) -> Result<()> {
    let doc = parse_svg(
        svg,
        dialect,
        &Source {
            name: "<demo>".into(),
            base_dir: PathBuf::new(),
        },
    )?;
    let (img, _) = render(&doc, opts)?;
    let rgb = img.over_background([255, 255, 255]);
    prism_image::write_png(out, &rgb).with_context(|| format!("writing {}", out.display()))
}

/// Runs `prism demo`.
pub fn run(a: &DemoArgs) -> Result<()> {
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("creating {}", a.output.display()))?;
    let mut entries = Vec::new();
    let tex = texture_svg()?;
    let mut jobs: Vec<(String, String, String, Dialect, RasterOptions)> = Vec::new();
    let base = |w, h, samples| RasterOptions {
        width: w,
        height: h,
        samples,
        ..RasterOptions::default()
    };
    for n in [1u32, 4, 16] {
        jobs.push((
            format!("fan_{n}spp.png"),
            format!("Triangle fan, {n} sample(s) per pixel"),
            fan_svg(),
            Dialect::Svg,
            base(200, 200, n),
        ));
    }
    jobs.push((
        "colortri.png".into(),
        "Barycentric colour triangles".into(),
        colortri_svg(),
        Dialect::Svg,
        base(200, 200, 16),
    ));
    for (name, lsm) in [
        ("zero", LevelSampling::Zero),
        ("nearest", LevelSampling::Nearest),
        ("linear", LevelSampling::Linear),
    ] {
        let mut o = base(300, 200, 1);
        o.pixel_sampling = PixelSampling::Bilinear;
        o.level_sampling = lsm;
        jobs.push((
            format!("texture_level_{name}.png"),
            format!("Minified texture, bilinear pixels, level sampling {name}"),
            tex.clone(),
            Dialect::Svg,
            o,
        ));
    }
    jobs.push((
        "transformed_group.png".into(),
        "Nested groups: rotate, translate, scale, skewX; strokes and opacity".into(),
        group_svg(),
        Dialect::Svg,
        base(240, 240, 16),
    ));
    let pb = crate::progress::bar(jobs.len() as u64 + 11, "demo", a.quiet);
    for (file, caption, svg, dialect, opts) in jobs {
        draw(&svg, dialect, &opts, &a.output.join(&file))?;
        entries.push(Entry { file, caption });
        pb.inc(1);
    }
    // Mesh editing: a de Casteljau construction, and Loop subdivision, shaded with edges.
    let curve = [
        prism_math::DVec2::new(0.2, 0.35),
        prism_math::DVec2::new(0.3, 0.6),
        prism_math::DVec2::new(0.5, 0.75),
        prism_math::DVec2::new(0.7, 0.45),
        prism_math::DVec2::new(1.0, 0.9),
    ];
    crate::bezier::write_curve(
        &curve,
        0.5,
        300,
        &a.output.join("bezier_decasteljau.png"),
        crate::output::ImageFormat::Png,
    )?;
    entries.push(Entry {
        file: "bezier_decasteljau.png".into(),
        caption: "Bezier curve with its de Casteljau levels at t = 0.5".into(),
    });
    pb.inc(1);
    let mut mesh = prism_mesh::icosahedron();
    for level in 0..=2 {
        if level > 0 {
            let he = prism_mesh::HalfedgeMesh::from_polymesh(&mesh)?;
            mesh = prism_mesh::loop_subdivide(&he, prism_mesh::LoopWeights::Warren)?;
        }
        let file = format!("loop_level_{level}.png");
        write_shaded(&mesh, 300, &a.output.join(&file))?;
        entries.push(Entry {
            file,
            caption: format!(
                "Icosahedron after {level} level(s) of Loop subdivision ({} faces)",
                mesh.face_count()
            ),
        });
        pb.inc(1);
    }
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
    trace(&cornell, &base, &a.output.join("render_cornell.png"), None)?;
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
        &a.output.join("render_adaptive.png"),
        Some(&a.output.join("render_heatmap.png")),
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
        trace(&cornell, &opts, &a.output.join(&file), None)?;
        entries.push(Entry {
            file,
            caption: format!("Only the {name} (--bounce {m})"),
        });
        pb.inc(1);
    }
    let bunny = a.assets.join("pathtracer/dae/sky/CBbunny.dae");
    if bunny.is_file() {
        let doc = prism_scene::read_collada(&bunny)
            .map_err(|e| crate::error::UserError(e.to_string()))?;
        let scene = prism_scene::Scene::from_collada(
            &doc,
            &prism_scene::SceneOptions::default(),
            &bunny.display().to_string(),
        )
        .map_err(|e| crate::error::UserError(e.to_string()))?;
        trace(&scene, &base, &a.output.join("render_bunny.png"), None)?;
        entries.push(Entry {
            file: "render_bunny.png".into(),
            caption: "CBbunny.dae from the course, 64 samples per pixel".into(),
        });
    }
    // The course's unlit bunny under a procedural sky map (written beside the pictures).
    let sky = sky_map();
    prism_image::write_exr(&a.output.join("sky.exr"), &sky)?;
    let unlit = a.assets.join("pathtracer/dae/sky/bunny_unlit.dae");
    if unlit.is_file() {
        let doc = prism_scene::read_collada(&unlit)
            .map_err(|e| crate::error::UserError(e.to_string()))?;
        let mut scene = prism_scene::Scene::from_collada(
            &doc,
            &prism_scene::SceneOptions::default(),
            &unlit.display().to_string(),
        )
        .map_err(|e| crate::error::UserError(e.to_string()))?;
        scene.lights = vec![prism_scene::Light::EnvironmentMap {
            radiance: std::sync::Arc::new(sky),
        }];
        trace(&scene, &base, &a.output.join("render_envmap.png"), None)?;
        entries.push(Entry {
            file: "render_envmap.png".into(),
            caption: "bunny_unlit.dae lit by a procedural sky map (--envmap sky.exr), 64 \
                      samples per pixel"
                .into(),
        });
    }
    pb.inc(1);
    // The Utah teapot's 32 bicubic patches (Newell, 1975), tessellated and welded; Z up.
    let patches = prism_mesh::parse_bez(include_str!("../data/teapot.bez"), "teapot.bez")?;
    let mut teapot = prism_mesh::tessellate(&patches, 8);
    for p in &mut teapot.positions {
        *p = prism_math::glam::DVec3::new(p.x, p.z, -p.y);
    }
    write_shaded(&teapot, 300, &a.output.join("bezier_teapot.png"))?;
    entries.push(Entry {
        file: "bezier_teapot.png".into(),
        caption: format!(
            "Utah teapot: 32 bicubic patches tessellated at 8x8 and welded ({} vertices, {} triangles)",
            teapot.vertex_count(),
            teapot.face_count()
        ),
    });
    pb.inc(1);
    raytrace_gallery(a, &mut entries)?;
    cloth_gallery(a, &mut entries)?;
    pb.finish_and_clear();
    let mut html = String::from(
        "<!doctype html><meta charset=\"utf-8\"><title>prism gallery</title>\
         <style>body{font-family:sans-serif;background:#eee}figure{display:inline-block;margin:8px;background:#fff;padding:8px}\
         img{max-width:100%}</style><h1>prism gallery</h1>",
    );
    for e in &entries {
        let _ = write!(
            html,
            "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
            e.file, e.caption, e.caption
        );
    }
    prism_image::write_atomic(&a.output.join("index.html"), |w| {
        std::io::Write::write_all(w, html.as_bytes()).map_err(|source| {
            prism_image::ImageError::Io {
                path: a.output.join("index.html"),
                source,
            }
        })
    })?;
    if !a.quiet {
        eprintln!(
            "wrote {} images and index.html to {}",
            entries.len(),
            a.output.display()
        );
    }
    Ok(())
}

/// The Whitted ray tracer's pictures: the presets, feature switches side by side, bloom
/// and its layer, a BVH level and a pixel's ray tree over the mirror Cornell box.
fn raytrace_gallery(a: &DemoArgs, entries: &mut Vec<Entry>) -> Result<()> {
    use prism_render::whitted::camera::OrbitView;
    use prism_render::whitted::film::{raytrace, trace_pixel, RaytraceOptions};
    use prism_render::whitted::overlay::Overlay;
    use prism_render::whitted::scene::WhittedScene;
    use prism_scene::{OrbitCamera, Preset};
    let dirs = vec![a.assets.join("delft-raytracer/data")];
    let on = prism_scene::Features::prism_defaults();
    let opts = |size: u32, features: prism_scene::Features| RaytraceOptions {
        width: size,
        height: size,
        settings: prism_render::whitted::tracer::WhittedSettings {
            features,
            light_samples: 16,
            max_depth: 3,
        },
        spp: 4,
        bloom: prism_image::Bloom::default(),
        seed: 0,
    };
    let cam = OrbitCamera::default();
    let user = |e: prism_scene::SceneError| crate::error::UserError(e.to_string());
    let write = |name: &str, img: &prism_image::RgbImage| {
        prism_image::write_png(&a.output.join(name), &img.to_rgb8_truncated())
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
    write(
        "raytrace_presets.png",
        &montage(&panels, 3, prism_math::Rgb::BLACK),
    )?;
    entries.push(Entry {
        file: "raytrace_presets.png".into(),
        caption: format!("prism raytrace presets: {}", names.join(", ")),
    });
    // Feature switches on the Cornell box with the four-colour parallelogram light.
    let scene = Preset::CornellBoxParallelogramLight
        .load(&dirs)
        .map_err(user)?;
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
            "--disable soft-shadow",
            prism_scene::Features {
                soft_shadow: false,
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
    write(
        "raytrace_toggles.png",
        &montage(&panels, 4, prism_math::Rgb::BLACK),
    )?;
    entries.push(Entry {
        file: "raytrace_toggles.png".into(),
        caption: format!(
            "cornell-box-parallelogram-light, left to right: {}",
            switches.iter().map(|s| s.0).collect::<Vec<_>>().join(", ")
        ),
    });
    // Bloom on the spheres, and the layer it adds.
    let spheres = WhittedScene::new(&Preset::Spheres.load(&dirs).map_err(user)?, true);
    let mut b = opts(300, prism_scene::Features { bloom: true, ..on });
    b.bloom.passes = 2;
    let out = raytrace(&spheres, &cam, &b, &|_| {});
    write("raytrace_bloom.png", &out.image)?;
    write(
        "raytrace_bloom_layer.png",
        out.bloom_layer.as_ref().expect("bloom is on"),
    )?;
    entries.push(Entry {
        file: "raytrace_bloom.png".into(),
        caption: "spheres with bloom (--enable bloom --bloom-passes 2)".into(),
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
                "the ray tree of pixel {},{} on the mirror box, seen from another orbit                  (--debug-pixel {},{} --debug-camera 10,-15,0,3.2)",
                t.pixel.0, t.pixel.1, t.pixel.0, t.pixel.1
            ),
        });
    }
    Ok(())
}

/// The cloth: the course's five scenes, the ks and density series, and a draped sphere with
/// each shader, drawn by prism-shade with the course app's camera.
fn cloth_gallery(a: &DemoArgs, entries: &mut Vec<Entry>) -> Result<()> {
    use prism_shade::Shader;
    let scenes = a.assets.join("clothsim/scene");
    let textures = a.assets.join("clothsim/textures");
    if !scenes.is_dir() || !textures.is_dir() {
        return Ok(());
    }
    let (w, h) = (240u32, 188u32);
    let user = |e: prism_cloth::ClothError| crate::error::UserError(e.to_string());
    let run = |name: &str, set: &[String], frames: u32| -> Result<prism_cloth::Cloth> {
        let scene =
            prism_cloth::read_scene(&scenes.join(format!("{name}.json")), set).map_err(user)?;
        let mut c = prism_cloth::Cloth::new(&scene);
        for _ in 0..frames {
            c.frame();
        }
        Ok(c)
    };
    let draw = |c: &prism_cloth::Cloth,
                view: &prism_shade::View,
                shader: &Shader|
     -> Result<prism_image::RgbImage> {
        let mut mesh = prism_cloth::cloth_mesh(c);
        mesh.append(&prism_cloth::obstacles(&c.scene));
        prism_shade::shade(
            &mesh,
            view,
            shader,
            &prism_shade::Uniforms::default(),
            &prism_shade::ShadeOptions::default(),
        )
        .map_err(|e| crate::error::UserError(e.to_string()).into())
    };
    let frames = 90;
    let save = |name: &str, panels: &[prism_image::RgbImage], cols: usize| -> Result<()> {
        let img = montage(panels, cols, prism_math::Rgb::BLACK);
        prism_image::write_png(&a.output.join(name), &prism_shade::to_bytes(&img))
            .with_context(|| format!("writing {name}"))
    };
    // The five scenes after one simulated second.
    let names = ["pinned2", "pinned4", "sphere", "plane", "selfCollision"];
    let mut panels = Vec::new();
    for n in names {
        let start = run(n, &[], 0)?;
        let view = prism_cloth::course_view(&start, w, h);
        let c = run(n, &[], frames)?;
        panels.push(draw(&c, &view, &Shader::Phong)?);
    }
    save("cloth_scenes.png", &panels, 5)?;
    entries.push(Entry {
        file: "cloth_scenes.png".into(),
        caption: format!(
            "prism cloth: {} after one simulated second",
            names.join(", ")
        ),
    });
    // The report's series on pinned2.
    for (file, key, values) in [
        ("cloth_ks.png", "ks", ["500", "5000", "50000"]),
        ("cloth_density.png", "density", ["15", "150", "1500"]),
    ] {
        let mut panels = Vec::new();
        for v in values {
            let set = vec![format!("{key}={v}")];
            let start = run("pinned2", &set, 0)?;
            let view = prism_cloth::course_view(&start, w, h);
            panels.push(draw(&run("pinned2", &set, frames)?, &view, &Shader::Phong)?);
        }
        save(file, &panels, 3)?;
        entries.push(Entry {
            file: file.into(),
            caption: format!(
                "pinned2 with {key} = {} (--set {key}=...)",
                values.join(", ")
            ),
        });
    }
    // The draped sphere with each shader.
    let load = |f: &str| -> Result<prism_image::RgbImage> {
        Ok(prism_image::read_image(&textures.join(f))?
            .to_rgb8()
            .to_rgb_f32())
    };
    let tex = prism_shade::course_texture(load("texture_1.png")?);
    let cube = prism_image::CubeMap::read(&textures.join("cube"))?;
    let shaders = [
        Shader::Normal,
        Shader::Diffuse,
        Shader::Phong,
        Shader::Texture(tex.clone()),
        Shader::Bump(tex.clone()),
        Shader::Displacement(tex),
        Shader::Mirror(cube),
    ];
    let start = run("sphere", &[], 0)?;
    let view = prism_cloth::course_view(&start, w, h);
    let c = run("sphere", &[], frames)?;
    let panels: Vec<_> = shaders
        .iter()
        .map(|s| draw(&c, &view, s))
        .collect::<Result<_>>()?;
    save("cloth_shaders.png", &panels, 4)?;
    entries.push(Entry {
        file: "cloth_shaders.png".into(),
        caption:
            "the draped sphere with each shader: normal, diffuse, Blinn-Phong, texture, bump, \
                  displacement, mirror (texture_1 as texture and height map)"
                .into(),
    });
    Ok(())
}
