//! `prism bezier`: draw a `.bzc` curve with its de Casteljau construction, or tessellate a
//! `.bez` patch file into a mesh.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use prism_math::{DVec2, Rgb};
use prism_mesh::{bezier_point, de_casteljau_levels, parse_bez, parse_bzc, tessellate};
use prism_raster::path::{LineCap, LineJoin, Path, StrokeStyle};
use prism_raster::{render, Document, FillRule, Item, Mat3, Paint, RenderOptions};

use crate::UserError;

/// Arguments of `prism bezier`.
#[derive(Args, Debug)]
pub struct BezierArgs {
    /// A `.bzc` curve (drawn to PNG) or a `.bez` patch file (tessellated to .obj or .ply).
    pub input: PathBuf,
    /// Output: a .png for curves, a .obj or .ply for patches.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Curve parameter at which the de Casteljau levels are drawn.
    #[arg(long, default_value_t = 0.5)]
    pub t: f64,
    /// Grid cells per patch side when tessellating.
    #[arg(long, default_value_t = 16)]
    pub resolution: usize,
    /// Picture size in pixels for curves.
    #[arg(long, default_value_t = 800)]
    pub size: u32,
}

/// Runs `prism bezier`.
pub fn run(a: &BezierArgs) -> Result<()> {
    let name = a.input.display().to_string();
    let text = std::fs::read_to_string(&a.input).map_err(|e| UserError(format!("{name}: {e}")))?;
    let ext = a
        .input
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "bzc" => {
            if !(0.0..=1.0).contains(&a.t) {
                return Err(
                    UserError(format!("--t: expected a value in [0, 1], found {}", a.t)).into(),
                );
            }
            let pts = parse_bzc(&text, &name).map_err(|e| UserError(e.to_string()))?;
            draw_curve(&pts, a.t, a.size, &a.output)
        }
        "bez" => {
            if a.resolution == 0 || a.resolution > 1024 {
                return Err(UserError(format!(
                    "--resolution: expected 1..=1024, found {}",
                    a.resolution
                ))
                .into());
            }
            let patches = parse_bez(&text, &name).map_err(|e| UserError(e.to_string()))?;
            let mesh = tessellate(&patches, a.resolution);
            crate::mesh::write(&a.output, &mesh)
        }
        _ => Err(UserError(format!("{name}: expected a .bzc or .bez file")).into()),
    }
}

/// Draws the curve, its control polygon and every de Casteljau level at `t` to a PNG.
pub(crate) fn draw_curve(pts: &[DVec2], t: f64, size: u32, output: &std::path::Path) -> Result<()> {
    // Curve files use [0, 1]^2 with y up; the picture has y down.
    let flip = |p: DVec2| DVec2::new(p.x, 1.0 - p.y);
    let mut doc = Document {
        width: 1.0,
        height: 1.0,
        ..Document::default()
    };
    let stroke = |points: Vec<DVec2>, width: f64, color: Rgb| Item::Stroke {
        path: Path::polygon(&points, false),
        transform: Mat3::IDENTITY,
        style: StrokeStyle {
            width,
            join: LineJoin::Round,
            cap: LineCap::Round,
            ..StrokeStyle::default()
        },
        paint: Paint::Solid(color),
        opacity: 1.0,
    };
    let dot = |p: DVec2, r: f64, color: Rgb| Item::Fill {
        path: Path::ellipse(p, r, r),
        transform: Mat3::IDENTITY,
        rule: FillRule::NonZero,
        paint: Paint::Solid(color),
        opacity: 1.0,
    };
    doc.items.push(Item::Fill {
        path: Path::polygon(&[DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y], true),
        transform: Mat3::IDENTITY,
        rule: FillRule::NonZero,
        paint: Paint::Solid(Rgb::WHITE),
        opacity: 1.0,
    });
    let curve: Vec<DVec2> = (0..=400)
        .map(|k| flip(bezier_point(pts, k as f64 / 400.0)))
        .collect();
    doc.items
        .push(stroke(curve, 0.006, Rgb::new(0.1, 0.1, 0.1)));
    let levels = de_casteljau_levels(pts, t);
    let n = levels.len().max(2) as f32;
    for (k, level) in levels.iter().enumerate() {
        let hue = k as f32 / (n - 1.0);
        let color = Rgb::new(0.15 + 0.8 * hue, 0.35, 0.9 - 0.7 * hue);
        let level: Vec<DVec2> = level.iter().map(|&p| flip(p)).collect();
        if level.len() > 1 {
            doc.items.push(stroke(level.clone(), 0.003, color));
        }
        for &p in &level {
            doc.items
                .push(dot(p, if level.len() == 1 { 0.012 } else { 0.008 }, color));
        }
    }
    let opts = RenderOptions {
        width: size,
        height: size,
        samples: 16,
        ..RenderOptions::default()
    };
    let (img, _) = render(&doc, &opts).map_err(|e| UserError(e.to_string()))?;
    prism_image::write_png(output, &img.over_background([255, 255, 255]))
        .with_context(|| format!("writing {}", output.display()))
}
