//! Split renders: the `--tile I/N` argument, writing a part file, and `prism merge`, which
//! checks a set of parts and assembles the picture the single render would have written.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use prism_image::{AtomicFile, ExrRowWriter, Image, ImageError, PngColor, PngRowWriter};
use prism_math::Rgb;
use prism_render::film::{PixelSum, Share};
use prism_render::parts::{merge, merge_rows, Encoding, Part, PartError, PartFile, PartIdentity};

use crate::error::UserError;
use crate::output::ImageFormat;

/// The colour merged pictures give pixels that no part held (with `--allow-missing`).
const HOLE: Rgb = Rgb {
    r: 1.0,
    g: 0.0,
    b: 1.0,
};

/// Parses `I/N` (0 <= I < N): share I of N.
pub fn parse_tile(s: &str) -> std::result::Result<(u32, u32), String> {
    let parsed = s
        .split_once('/')
        .and_then(|(i, n)| Some((i.trim().parse::<u32>().ok()?, n.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((i, n)) if n >= 1 && i < n => Ok((i, n)),
        _ => Err(format!(
            "expected I/N, share I (counted from 0) of N, with 0 <= I < N; found `{s}`"
        )),
    }
}

/// Checks that a `width x height` image has at least `parts` tiles to share out.
pub fn check_tile_count(parts: u32, width: u32, height: u32) -> Result<()> {
    let tiles = prism_render::film::tile_count(width, height);
    if parts as usize > tiles {
        return Err(UserError::Refused(format!(
            "--tile I/{parts}: a {width}x{height} image has only {tiles} tiles of 32x32 to share \
             out; use at most {tiles} shares"
        ))
        .into());
    }
    Ok(())
}

/// Checks that a part is written to an OpenEXR file and that no picture-only output is
/// asked for with it; `flags` names the picture outputs given.
pub fn check_part_output(output: &Path, flags: &[&str]) -> Result<()> {
    if crate::output::extension(output) != "exr" {
        return Err(UserError::Refused(format!(
            "--output {}: a split render writes a part file, an OpenEXR file (.exr); merge \
             the parts with `prism merge` for the picture",
            output.display()
        ))
        .into());
    }
    if let Some(flag) = flags.first() {
        return Err(UserError::Refused(format!(
            "{flag}: a split render writes only its part file; give {flag} to `prism merge`"
        ))
        .into());
    }
    crate::output::check_folder(output, "--output")?;
    Ok(())
}

/// Writes `part` to `output` atomically and prints the summary line when not quiet on a
/// terminal.
pub fn write_part(part: &Part, output: &Path, quiet: bool, started: Instant) -> Result<()> {
    part.write(output)?;
    let samples: u64 = part.sums.pixels().iter().map(|p| u64::from(p.n)).sum();
    part_summary(&part.header.share, samples, output, quiet, started);
    Ok(())
}

/// The summary line of a written part, when not quiet on a terminal.
pub fn part_summary(share: &Share, samples: u64, output: &Path, quiet: bool, started: Instant) {
    if !quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        eprintln!(
            "prism: part {}/{} (samples {}..{}), {:.2} M samples in {:.1} s -> {}",
            share.part,
            share.parts,
            share.samples.start,
            share.samples.end,
            samples as f64 / 1e6,
            started.elapsed().as_secs_f64(),
            output.display()
        );
    }
}

/// Arguments of `prism merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Part files written by `prism render --tile I/N` / `--samples-from A --samples-to B`
    /// or `prism raytrace --tile I/N`, in any order.
    #[arg(required = true, value_name = "PART.exr")]
    parts: Vec<PathBuf>,
    /// The picture: .png or .jpg (encoded as the command that made the parts encodes), or
    /// .exr (linear). The folder must exist.
    #[arg(short, long)]
    output: PathBuf,
    /// Also write the linear picture to this OpenEXR file.
    #[arg(long, value_name = "FILE")]
    exr: Option<PathBuf>,
    /// Write the sample-count heat map (blue: few, red: the most) to this .png or .jpg.
    #[arg(long, value_name = "FILE")]
    heatmap: Option<PathBuf>,
    /// Merge even if some tiles or sample ranges are in no part: those pixels are painted
    /// magenta (a missing sample range only lowers its pixels' sample counts), and each
    /// missing share is listed.
    #[arg(long)]
    allow_missing: bool,
    /// No summary line.
    #[arg(short, long)]
    quiet: bool,
    /// Print per-stage times on stderr: read (opening and checking the parts), then merge
    /// and write (one pass, a row of tiles at a time).
    #[arg(long)]
    stats: bool,
}

/// Runs `prism merge`.
pub fn run(a: &MergeArgs) -> Result<()> {
    let t0 = Instant::now();
    let inputs: Vec<(&str, &Path)> = a.parts.iter().map(|p| ("the part", p.as_path())).collect();
    let (format, heatmap_format) =
        crate::output::picture_outputs(&a.output, a.exr.as_deref(), a.heatmap.as_deref(), &inputs)?;
    for path in &a.parts {
        crate::error::check_input(path, None)?;
    }
    let mut parts = Vec::with_capacity(a.parts.len());
    for path in &a.parts {
        parts.push(PartFile::open(path).map_err(UserError::input)?);
    }
    let read_time = t0.elapsed();
    // Parts prism wrote always have an identity it reads (the merge checks that every part
    // holds the same one); a part that does not is refused, not merged on guesses.
    let identity = PartIdentity::from_attributes(&parts[0].header.identity).map_err(|e| {
        UserError::Refused(format!(
            "{}: the part's identity: {e}",
            a.parts[0].display()
        ))
    })?;
    let t1 = Instant::now();
    let merged = if identity.bloom().is_some() {
        merge_whole(a, &mut parts, &identity, format, heatmap_format)?
    } else {
        merge_streaming(a, &mut parts, &identity, format, heatmap_format)?
    };
    let merge_time = t1.elapsed();
    for hole in &merged.missing {
        eprintln!("prism: warning: missing {hole}");
    }
    if a.stats {
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        eprintln!("read: {:.1} ms", ms(read_time));
        eprintln!("merge and write: {:.1} ms", ms(merge_time));
    }
    if !a.quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        let (w, h) = merged.size;
        let mut written = vec![a.output.display().to_string()];
        written.extend(a.exr.iter().map(|p| p.display().to_string()));
        if heatmap_format.is_some() {
            written.extend(a.heatmap.iter().map(|p| p.display().to_string()));
        }
        eprintln!(
            "prism: merged {} parts, {w}x{h}{} in {:.2} s -> {}",
            a.parts.len(),
            if merged.holes > 0 {
                format!(", {} pixels missing (magenta)", merged.holes)
            } else {
                String::new()
            },
            t0.elapsed().as_secs_f64(),
            written.join(", ")
        );
    }
    Ok(())
}

/// What a merge made, for the summary.
struct MergeSummary {
    size: (u32, u32),
    /// Pixels no part held.
    holes: usize,
    /// The shares no part held.
    missing: Vec<String>,
}

/// Why a streaming merge stopped: a part, or an output.
enum MergeFail {
    Part(PartError),
    Write(ImageError),
}

impl From<PartError> for MergeFail {
    fn from(e: PartError) -> Self {
        MergeFail::Part(e)
    }
}

impl From<ImageError> for MergeFail {
    fn from(e: ImageError) -> Self {
        MergeFail::Write(e)
    }
}

impl From<MergeFail> for anyhow::Error {
    fn from(e: MergeFail) -> Self {
        match e {
            MergeFail::Part(e) => UserError::input(e).into(),
            MergeFail::Write(e) => e.into(),
        }
    }
}

/// Where a streamed merge's rows go.
enum Rows<W: std::io::Write> {
    Png(PngRowWriter<W>),
    Exr(ExrRowWriter<W>),
    /// Gathered, for an encoder that takes the picture whole (JPEG).
    Whole(Vec<[u8; 3]>),
}

/// Checks that `memory` more bytes fit the budget, naming the output that needs them.
fn fits(memory: u64, what: &Path) -> Result<()> {
    prism_math::limits::check_memory(memory)
        .map_err(|e| UserError::Refused(format!("{}: {e}", what.display())).into())
}

/// The merge a row of tiles at a time, each band of rows encoded as it is made: PNG and
/// OpenEXR outputs are written row by row (the same bytes as written whole), a JPEG or the
/// heat map is gathered (3 or 4 bytes a pixel).
fn merge_streaming(
    a: &MergeArgs,
    parts: &mut [PartFile],
    identity: &PartIdentity,
    format: ImageFormat,
    heatmap_format: Option<ImageFormat>,
) -> Result<MergeSummary> {
    let (w, h) = prism_render::parts::merged_size(parts);
    let pixels = u64::from(w) * u64::from(h);
    if format == ImageFormat::Jpeg {
        fits(3 * pixels, &a.output)?;
    }
    if let Some(path) = &a.heatmap {
        fits(4 * pixels, path)?;
    }
    let truncated = identity.encoding() == Encoding::Truncated;
    let to8 = if truncated {
        prism_image::truncated8
    } else {
        prism_image::srgb8
    };
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ImageError::Io { path, source }
    };
    let mut main_file = AtomicFile::create(&a.output).map_err(io(&a.output))?;
    let mut exr_file = match &a.exr {
        Some(p) => Some(AtomicFile::create(p).map_err(io(p))?),
        None => None,
    };
    let mut samples: Vec<u32> = Vec::new();
    let mut holes = 0usize;
    let missing;
    {
        let mut main = match format {
            ImageFormat::Exr => Rows::Exr(ExrRowWriter::new(main_file.writer(), w, h)?),
            ImageFormat::Jpeg => Rows::Whole(Vec::with_capacity(pixels as usize)),
            _ => Rows::Png(PngRowWriter::new(main_file.writer(), w, h, PngColor::Rgb)?),
        };
        let mut extra = match exr_file.as_mut() {
            Some(f) => Some(ExrRowWriter::new(f.writer(), w, h)?),
            None => None,
        };
        let mut row8 = Vec::with_capacity(3 * w as usize);
        missing = merge_rows(parts, a.allow_missing, |_, band: &[PixelSum]| {
            for sums in band.chunks(w as usize) {
                let row: Vec<Rgb> = sums
                    .iter()
                    .map(|s| if s.n == 0 { HOLE } else { s.mean() })
                    .collect();
                holes += sums.iter().filter(|s| s.n == 0).count();
                if heatmap_format.is_some() {
                    samples.extend(sums.iter().map(|s| s.n));
                }
                match &mut main {
                    Rows::Exr(e) => e.write_row(&row)?,
                    Rows::Png(p) => {
                        row8.clear();
                        row8.extend(row.iter().flat_map(|&p| to8(p)));
                        p.write_row(&row8)?;
                    }
                    Rows::Whole(all) => all.extend(row.iter().map(|&p| to8(p))),
                }
                if let Some(e) = &mut extra {
                    e.write_row(&row)?;
                }
            }
            Ok::<(), MergeFail>(())
        })?;
        match main {
            Rows::Exr(e) => {
                e.finish();
            }
            Rows::Png(p) => {
                p.finish()?;
            }
            Rows::Whole(all) => {
                let image = Image::from_vec(w, h, all);
                let bytes = prism_image::encode_jpeg(&image)?;
                std::io::Write::write_all(main_file.writer(), &bytes).map_err(io(&a.output))?;
            }
        }
        if let Some(e) = extra {
            e.finish();
        }
    }
    main_file.commit().map_err(io(&a.output))?;
    if let (Some(f), Some(path)) = (exr_file, &a.exr) {
        f.commit().map_err(io(path))?;
    }
    if let (Some(path), Some(f)) = (&a.heatmap, heatmap_format) {
        let samples = Image::from_vec(w, h, samples);
        crate::output::write_rgb8(path, f, &prism_image::heatmap(&samples))?;
    }
    Ok(MergeSummary {
        size: (w, h),
        holes,
        missing,
    })
}

/// The merge gathered whole, for a picture with bloom (a filter over the whole picture).
fn merge_whole(
    a: &MergeArgs,
    parts: &mut [PartFile],
    identity: &PartIdentity,
    format: ImageFormat,
    heatmap_format: Option<ImageFormat>,
) -> Result<MergeSummary> {
    let merged = merge(parts, a.allow_missing).map_err(UserError::input)?;
    let mut image: Image<Rgb> = merged.sums.map(PixelSum::mean);
    if let Some(bloom) = identity.bloom() {
        let layer = bloom.layer(&image);
        for (p, l) in image.pixels_mut().iter_mut().zip(layer.pixels()) {
            *p += *l;
        }
    }
    let holes = merged.sums.pixels().iter().filter(|p| p.n == 0).count();
    for (p, s) in image.pixels_mut().iter_mut().zip(merged.sums.pixels()) {
        if s.n == 0 {
            *p = HOLE;
        }
    }
    let truncated = identity.encoding() == Encoding::Truncated;
    match format {
        ImageFormat::Exr => prism_image::write_exr(&a.output, &image)?,
        _ if truncated => {
            crate::output::write_rgb8(&a.output, format, &image.to_rgb8_truncated())?;
        }
        _ => crate::output::write_rgb8(&a.output, format, &image.linear_to_srgb8())?,
    }
    if let Some(exr) = &a.exr {
        prism_image::write_exr(exr, &image)?;
    }
    if let (Some(path), Some(f)) = (&a.heatmap, heatmap_format) {
        let samples = merged.sums.map(|p| p.n);
        crate::output::write_rgb8(path, f, &prism_image::heatmap(&samples))?;
    }
    Ok(MergeSummary {
        size: (merged.sums.width(), merged.sums.height()),
        holes,
        missing: merged.holes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Property: every I/N with 0 <= I < N parses; out-of-range and malformed shares do not.
    #[test]
    fn tiles_parse_only_in_range() {
        assert_eq!(parse_tile("0/1"), Ok((0, 1)));
        assert_eq!(parse_tile("6/7"), Ok((6, 7)));
        for bad in ["7/7", "1/0", "-1/3", "a/b", "3", "1/2/3", ""] {
            assert!(parse_tile(bad).is_err(), "{bad}");
        }
    }
}
