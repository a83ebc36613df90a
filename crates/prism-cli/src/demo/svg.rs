//! The gallery's rasterizer pictures: a triangle fan at 1, 4 and 16 samples per pixel,
//! barycentric colour triangles and a minified texture at each level sampling (the course
//! dialect), nested transformed groups, all from SVG made here, and the standard-SVG
//! feature picture of `docs/examples/svg/features.svg`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use base64::Engine;
use indicatif::ProgressBar;
use prism_image::{encode_png, Image, LevelSampling, PixelSampling};
use prism_raster::{parse_svg, render, Dialect, RasterOptions, Source};

use super::index::Entry;

/// One picture to draw: its file, caption, SVG text, dialect and raster options.
pub type Job = (String, String, String, Dialect, RasterOptions);

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

/// Rasterizes `svg` and writes it over white to the PNG `out`.
fn draw(svg: &str, dialect: Dialect, opts: &RasterOptions, out: &Path) -> Result<()> {
    let doc = parse_svg(
        svg,
        dialect,
        &Source {
            name: "<demo>".into(),
            base_dir: PathBuf::new(),
            ..Source::default()
        },
    )?;
    let (img, _) = render(&doc, opts)?;
    let rgb = img.over_background([255, 255, 255]);
    prism_image::write_png(out, &rgb).with_context(|| format!("writing {}", out.display()))
}

/// The pictures to draw, in gallery order.
pub fn jobs() -> Result<Vec<Job>> {
    let tex = texture_svg()?;
    let mut jobs: Vec<Job> = Vec::new();
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
        Dialect::Cs184,
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
            Dialect::Cs184,
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
    jobs.push((
        "svg_features.png".into(),
        "Standard SVG: a drop shadow, turbulence lit as paper, a masked pattern, a clip path, \
         multiply blending, text on a path with a glow (docs/examples/svg/features.svg)"
            .into(),
        include_str!("../../../../docs/examples/svg/features.svg").into(),
        Dialect::Svg,
        base(480, 240, 16),
    ));
    Ok(jobs)
}

/// Draws each job into `output`, adding its entry and one step of `pb`.
pub fn draw_jobs(
    jobs: Vec<Job>,
    output: &Path,
    entries: &mut Vec<Entry>,
    pb: &ProgressBar,
) -> Result<()> {
    for (file, caption, svg, dialect, opts) in jobs {
        draw(&svg, dialect, &opts, &output.join(&file))?;
        entries.push(Entry { file, caption });
        pb.inc(1);
    }
    Ok(())
}
