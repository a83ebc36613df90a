//! Split renders: the `--tile I/N` argument, writing a part file, and `prism merge`, which
//! checks a set of parts and assembles the picture the single render would have written.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use prism_image::Image;
use prism_math::Rgb;
use prism_render::film::PixelSum;
use prism_render::parts::{merge, Encoding, Part, PartFile, PartIdentity};

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
    if !quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        let samples: u64 = part.sums.pixels().iter().map(|p| u64::from(p.n)).sum();
        eprintln!(
            "prism: part {}/{} (samples {}..{}), {:.2} M samples in {:.1} s -> {}",
            part.header.share.part,
            part.header.share.parts,
            part.header.share.samples.start,
            part.header.share.samples.end,
            samples as f64 / 1e6,
            started.elapsed().as_secs_f64(),
            output.display()
        );
    }
    Ok(())
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
    /// Print per-stage times on stderr: read (opening and checking the parts), merge, write.
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
    let t1 = Instant::now();
    let merged = merge(&parts, a.allow_missing).map_err(UserError::input)?;
    drop(parts);
    for hole in &merged.holes {
        eprintln!("prism: warning: missing {hole}");
    }
    // Parts prism wrote always have an identity it reads (merge has checked that every part
    // holds the same one); a part that does not is refused, not merged on guesses.
    let identity = PartIdentity::from_attributes(&merged.identity).map_err(|e| {
        UserError::Refused(format!(
            "{}: the part's identity: {e}",
            a.parts[0].display()
        ))
    })?;
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
    let merge_time = t1.elapsed();
    let t2 = Instant::now();
    let truncated = identity.encoding() == Encoding::Truncated;
    match format {
        ImageFormat::Exr => prism_image::write_exr(&a.output, &image)?,
        _ if truncated => {
            crate::output::write_rgb8(&a.output, format, &image.to_rgb8_truncated())?;
        }
        _ => crate::output::write_rgb8(&a.output, format, &image.linear_to_srgb8())?,
    }
    let mut written = vec![a.output.display().to_string()];
    if let Some(exr) = &a.exr {
        prism_image::write_exr(exr, &image)?;
        written.push(exr.display().to_string());
    }
    if let (Some(path), Some(f)) = (&a.heatmap, heatmap_format) {
        let samples = merged.sums.map(|p| p.n);
        crate::output::write_rgb8(path, f, &prism_image::heatmap(&samples))?;
        written.push(path.display().to_string());
    }
    if a.stats {
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        eprintln!("read: {:.1} ms", ms(read_time));
        eprintln!("merge: {:.1} ms", ms(merge_time));
        eprintln!("write: {:.1} ms", ms(t2.elapsed()));
    }
    if !a.quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        let (w, h) = (merged.sums.width(), merged.sums.height());
        eprintln!(
            "prism: merged {} parts, {w}x{h}{} in {:.2} s -> {}",
            a.parts.len(),
            if holes > 0 {
                format!(", {holes} pixels missing (magenta)")
            } else {
                String::new()
            },
            t0.elapsed().as_secs_f64(),
            written.join(", ")
        );
    }
    Ok(())
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
