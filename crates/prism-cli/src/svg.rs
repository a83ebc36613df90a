//! `prism svg`: SVG to PNG, one file or a directory tree.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use prism_image::{
    over_background8, AtomicFile, ImageError, LevelSampling, PixelSampling, PngColor, PngRowWriter,
    Rgb8Image,
};
use prism_raster::{
    read_svg_with, Dialect, Document, Fonts, Prepared, RasterOptions, RasterStats, View,
};

use crate::error::UserError;
use crate::output::{image_output, write_rgb8, ImageFormat};

/// Texel lookup within a mip level.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PixelMode {
    /// The nearest texel.
    Nearest,
    /// Bilinear between the four nearest texels.
    Bilinear,
}

/// Mip level selection.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum LevelMode {
    /// Always the full-resolution level.
    Zero,
    /// The nearest level to the pixel footprint.
    Nearest,
    /// Blend the two nearest levels (trilinear with bilinear pixels).
    Linear,
}

/// Behaviour of another renderer to reproduce.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Compat {
    /// The CS184 course renderer: its SVG subset and quirks, its view with a 20% margin and a
    /// canvas outline, `fill="none"` as black, DDA lines and points without antialiasing.
    Cs184,
}

/// Arguments of `prism svg`.
#[derive(Args, Debug)]
pub struct SvgArgs {
    /// An SVG file, or a directory searched recursively for *.svg.
    pub input: PathBuf,
    /// Output image, .png or .jpg by its extension (the folder must exist); or the output
    /// directory, for PNGs, when the input is a directory.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Output width in pixels. Standard SVG (as resvg's command line): the document's own
    /// size by default; with only --width or --height the other follows the aspect ratio;
    /// with both, the document is fitted into that box keeping its aspect ratio. With
    /// --compat cs184 or --view the image is exactly this size (default 1024).
    #[arg(long)]
    pub width: Option<u32>,
    /// Output height in pixels (see --width).
    #[arg(long)]
    pub height: Option<u32>,
    /// Scale the document's own size by this factor (standard SVG; not with --width or
    /// --height).
    #[arg(short = 'z', long, conflicts_with_all = ["width", "height"])]
    pub zoom: Option<f64>,
    /// A folder of font files to load for text, besides the system's (repeatable).
    #[arg(long = "font-dir", value_name = "DIR")]
    pub font_dirs: Vec<PathBuf>,
    /// Load no system fonts: only those of --font-dir.
    #[arg(long)]
    pub skip_system_fonts: bool,
    /// The font family for text that names none (default Times New Roman).
    #[arg(long, value_name = "FAMILY")]
    pub font_family: Option<String>,
    /// The family that `serif` stands for (default Times New Roman).
    #[arg(long, value_name = "FAMILY")]
    pub serif_family: Option<String>,
    /// The family that `sans-serif` stands for (default Arial).
    #[arg(long, value_name = "FAMILY")]
    pub sans_serif_family: Option<String>,
    /// The family that `monospace` stands for (default Courier New).
    #[arg(long, value_name = "FAMILY")]
    pub monospace_family: Option<String>,
    /// The family that `cursive` stands for (default Comic Sans MS).
    #[arg(long, value_name = "FAMILY")]
    pub cursive_family: Option<String>,
    /// The family that `fantasy` stands for (default Impact).
    #[arg(long, value_name = "FAMILY")]
    pub fantasy_family: Option<String>,
    /// Samples per pixel: a perfect square (1, 4, 9, 16, ...; at most 256).
    #[arg(
        short = 's',
        long = "spp",
        visible_alias = "samples",
        default_value_t = 1
    )]
    pub samples: u32,
    /// Texel lookup for textured triangles.
    #[arg(long, value_enum, default_value_t = PixelMode::Nearest)]
    pub pixel_sampling: PixelMode,
    /// Mip level selection for textured triangles.
    #[arg(long, value_enum, default_value_t = LevelMode::Zero)]
    pub level_sampling: LevelMode,
    /// Show the square region centred at CX,CY reaching SPAN user units to each side.
    #[arg(long, value_name = "CX,CY,SPAN")]
    pub view: Option<String>,
    /// Reproduce another renderer's behaviour.
    #[arg(long, value_enum)]
    pub compat: Option<Compat>,
    /// Print per-stage times on stderr (`parse: 1.2 ms`, one line per stage; for a folder,
    /// each file's block opens with its name).
    #[arg(long)]
    pub stats: bool,
    /// Worker threads (default: one per core).
    #[arg(short = 't', long)]
    pub threads: Option<usize>,
    /// No progress bar and no warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

fn parse_view(s: &str) -> Result<View> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            UserError::Refused(format!("--view: expected CX,CY,SPAN numbers, found {s:?}"))
        })?;
    match v[..] {
        [cx, cy, span] if cx.is_finite() && cy.is_finite() && span.is_finite() && span > 0.0 => {
            Ok(View::Region { cx, cy, span })
        }
        _ => Err(UserError::Refused(format!(
            "--view: expected CX,CY,SPAN with a positive span, found {s:?}"
        ))
        .into()),
    }
}

/// The fonts the arguments ask for.
fn fonts(a: &SvgArgs) -> Fonts {
    Fonts {
        dirs: a.font_dirs.clone(),
        skip_system: a.skip_system_fonts,
        family: a.font_family.clone(),
        serif: a.serif_family.clone(),
        sans_serif: a.sans_serif_family.clone(),
        monospace: a.monospace_family.clone(),
        cursive: a.cursive_family.clone(),
        fantasy: a.fantasy_family.clone(),
    }
}

/// Output size for a document under these arguments.
fn output_size(doc: &Document, a: &SvgArgs) -> (u32, u32) {
    if a.compat.is_some() || a.view.is_some() {
        return (a.width.unwrap_or(1024), a.height.unwrap_or(1024));
    }
    doc.output_size(a.width, a.height, a.zoom.unwrap_or(1.0))
}

fn ms(d: std::time::Duration) -> String {
    format!("{:.1} ms", d.as_secs_f64() * 1e3)
}

/// Renders one file; returns the warnings.
fn render_one(
    input: &Path,
    output: &Path,
    format: ImageFormat,
    a: &SvgArgs,
    view: Option<View>,
) -> Result<Vec<prism_math::Warning>> {
    let dialect = if a.compat.is_some() {
        Dialect::Cs184
    } else {
        Dialect::Svg
    };
    let t0 = Instant::now();
    let mut doc = read_svg_with(input, dialect, &fonts(a)).map_err(UserError::input)?;
    let parse = t0.elapsed();
    let (width, height) = output_size(&doc, a);
    let opts = RasterOptions {
        width,
        height,
        samples: a.samples,
        pixel_sampling: match a.pixel_sampling {
            PixelMode::Nearest => PixelSampling::Nearest,
            PixelMode::Bilinear => PixelSampling::Bilinear,
        },
        level_sampling: match a.level_sampling {
            LevelMode::Zero => LevelSampling::Zero,
            LevelMode::Nearest => LevelSampling::Nearest,
            LevelMode::Linear => LevelSampling::Linear,
        },
        view: view.unwrap_or_default(),
        compat: a.compat.is_some(),
    };
    let refused = |e| UserError::input(format!("{}: {e}", input.display()));
    let prepared = Prepared::new(&doc, &opts).map_err(refused)?;
    // Drawing needs only the primitives.
    let warnings = std::mem::take(&mut doc.warnings);
    drop(doc);
    let (stats, encode) = if format == ImageFormat::Png {
        write_png_rows(output, &prepared)?
    } else {
        // JPEG has no alpha: the picture goes over white, as a browser shows it. The
        // encoder takes it whole, gathered as 3 bytes a pixel.
        let mut rgb = Vec::with_capacity(width as usize * height as usize);
        let stats = prepared.render_rows(|rows| {
            rgb.extend(rows.iter().map(|&p| over_background8(p, [255, 255, 255])));
            true
        });
        let t1 = Instant::now();
        write_rgb8(output, format, &Rgb8Image::from_vec(width, height, rgb))?;
        (stats, t1.elapsed())
    };
    if a.stats {
        if a.input.is_dir() {
            eprintln!("{}:", input.display());
        }
        eprintln!("parse: {}", ms(parse));
        eprintln!("prepare: {}", ms(stats.prepare));
        eprintln!("raster: {}", ms(stats.raster));
        eprintln!("resolve: {}", ms(stats.resolve));
        eprintln!("encode: {}", ms(encode));
    }
    Ok(warnings)
}

/// Renders `prepared` straight into the PNG `output`, each band of rows encoded as it is drawn
/// (RGB for the course's opaque pictures, RGBA otherwise); returns the render's stage
/// times and the time spent encoding.
fn write_png_rows(
    output: &Path,
    prepared: &Prepared,
) -> std::result::Result<(RasterStats, Duration), ImageError> {
    let opts = prepared.options();
    let io = |source| ImageError::Io {
        path: output.to_path_buf(),
        source,
    };
    let mut file = AtomicFile::create(output).map_err(io)?;
    let color = if opts.compat {
        PngColor::Rgb
    } else {
        PngColor::Rgba
    };
    let mut png = PngRowWriter::new(file.writer(), opts.width, opts.height, color)?;
    let mut failed = None;
    let mut encode = Duration::ZERO;
    let mut rgb = Vec::new();
    let stats = prepared.render_rows(|rows| {
        let t = Instant::now();
        for row in rows.chunks(opts.width as usize) {
            let bytes = if opts.compat {
                rgb.clear();
                rgb.extend(row.iter().flat_map(|p| [p[0], p[1], p[2]]));
                &rgb[..]
            } else {
                row.as_flattened()
            };
            if let Err(e) = png.write_row(bytes) {
                failed = Some(e);
                return false;
            }
        }
        encode += t.elapsed();
        true
    });
    if let Some(e) = failed {
        return Err(e);
    }
    let t = Instant::now();
    png.finish()?;
    file.commit().map_err(io)?;
    Ok((stats, encode + t.elapsed()))
}

/// The `*.svg` files under `dir`, in path order, walked with a stack of folders (not
/// recursion, so the depth of the tree costs no call stack).
fn find_svgs(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut folders = vec![dir.to_path_buf()];
    while let Some(d) = folders.pop() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(&d)
            .with_context(|| format!("reading directory {}", d.display()))?
            .map(|e| e.map(|e| e.path()))
            .collect::<Result<_, _>>()?;
        entries.sort();
        // Folders are pushed in reverse so that they are walked in path order.
        for p in entries.iter().rev() {
            if p.is_dir() {
                folders.push(p.clone());
            }
        }
        out.extend(entries.into_iter().filter(|p| {
            !p.is_dir() && p.extension().is_some_and(|x| x.eq_ignore_ascii_case("svg"))
        }));
    }
    out.sort();
    Ok(out)
}

/// Runs `prism svg`.
pub fn run(a: &SvgArgs) -> Result<()> {
    crate::resources::pool(a.threads)?.install(|| run_in_pool(a))
}

/// Runs `prism svg` on the current worker pool.
fn run_in_pool(a: &SvgArgs) -> Result<()> {
    let view = a.view.as_deref().map(parse_view).transpose()?;
    if let Some(z) = a.zoom {
        if !(z.is_finite() && z > 0.0) {
            return Err(UserError::Refused(format!(
                "--zoom: expected a positive number, found {z}"
            ))
            .into());
        }
    }
    if prism_raster::sample_rate(a.samples).is_none() {
        return Err(UserError::Refused(format!(
            "--spp: expected a perfect square from 1 to {} (1, 4, 9, 16, ...), found {}",
            prism_raster::MAX_SAMPLES,
            a.samples
        ))
        .into());
    }
    let warn = |ws: Vec<prism_math::Warning>| {
        if !a.quiet {
            for w in ws {
                eprintln!("prism: warning: {w}");
            }
        }
    };
    if !a.input.is_dir() {
        let format = image_output(
            &a.output,
            "--output",
            &[ImageFormat::Png, ImageFormat::Jpeg],
        )?;
        crate::error::check_input(&a.input, None)?;
        if let Some(kind) = crate::output::binary_kind(&a.input) {
            return Err(UserError::WrongKind {
                flag: None,
                path: a.input.clone(),
                expected: format!("an SVG file, and this is {kind}"),
            }
            .into());
        }
        crate::output::check_distinct(&[("the SVG", &a.input)], &[("--output", &a.output)])?;
        return render_one(&a.input, &a.output, format, a, view).map(warn);
    }
    // A folder of drawings is written into a folder that exists (its subfolders mirror the
    // input's); prism does not create the output folder itself.
    // A folder of drawings is written into an existing folder.
    crate::error::check_folder_input(&a.output, "--output")?;
    let files = find_svgs(&a.input)?;
    let pb = crate::progress::bar(files.len() as u64, "svg", a.quiet);
    let mut failed = 0usize;
    for f in &files {
        let rel = f.strip_prefix(&a.input).unwrap_or(f);
        let out = a.output.join(rel).with_extension("png");
        if let Some(parent) = out.parent() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("creating {}", parent.display()))?;
        }
        match render_one(f, &out, ImageFormat::Png, a, view) {
            Ok(ws) => pb.suspend(|| warn(ws)),
            Err(e) => {
                failed += 1;
                pb.suspend(|| eprintln!("prism: error: {e:#}"));
            }
        }
        pb.inc(1);
    }
    pb.finish_and_clear();
    if failed > 0 {
        return Err(UserError::Refused(format!("{failed} of {} files failed", files.len())).into());
    }
    Ok(())
}
