//! `prism bezier`: draw a `.bzc` curve with its de Casteljau construction, or tessellate a
//! `.bez` patch file into a mesh.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use prism_math::DVec2;
use prism_mesh::{parse_bez, parse_bzc, tessellate};
use prism_raster::de_casteljau_construction;

use crate::error::UserError;
use crate::output::ImageFormat;

/// Arguments of `prism bezier`.
#[derive(Args, Debug)]
pub struct BezierArgs {
    /// A `.bzc` curve (drawn to PNG) or a `.bez` patch file (tessellated to .obj or .ply).
    pub input: PathBuf,
    /// Output, by its extension: a .png or .jpg for curves; an .obj, .ply or .dae for
    /// patches. The folder must exist.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Curve parameter, in [0, 1], at which the de Casteljau levels are drawn (`-t` is the
    /// course's flag here, not threads: the work is one thread's).
    #[arg(
        short = 't',
        long = "parameter",
        visible_alias = "t",
        default_value_t = 0.5
    )]
    pub t: f64,
    /// Grid cells per patch side when tessellating.
    #[arg(long, default_value_t = 16)]
    pub resolution: usize,
    /// Picture size in pixels for curves.
    #[arg(long, default_value_t = 800)]
    pub size: u32,
    /// Quiet, as on every subcommand (`prism bezier` prints nothing but errors anyway).
    #[arg(short, long)]
    pub quiet: bool,
    /// Print per-stage times on stderr: read, then draw or tessellate, then write.
    #[arg(long)]
    pub stats: bool,
}

/// Runs `prism bezier`.
pub fn run(a: &BezierArgs) -> Result<()> {
    let name = a.input.display().to_string();
    let kind = crate::output::extension(&a.input);
    // The output is checked before the input is read.
    let curve_format = match kind.as_str() {
        "bzc" => Some(crate::output::image_output(
            &a.output,
            "--output",
            &[ImageFormat::Png, ImageFormat::Jpeg],
        )?),
        "bez" => {
            crate::output::mesh_output(&a.output, "--output")?;
            None
        }
        _ => {
            return Err(UserError::WrongKind {
                flag: None,
                path: a.input.clone(),
                expected: "a .bzc or .bez file".into(),
            }
            .into())
        }
    };
    crate::output::check_distinct(&[("the input", &a.input)], &[("--output", &a.output)])?;
    crate::error::check_input(&a.input, None)?;
    let t0 = std::time::Instant::now();
    let text = prism_math::limits::read_input_text(&a.input, prism_mesh::MAX_MESH_FILE_BYTES)
        .map_err(|e| UserError::Refused(format!("{name}: {e}")))?;
    let stage = |what: &str, t: std::time::Instant| {
        if a.stats {
            eprintln!("{what}: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
        }
    };
    stage("read", t0);
    let t1 = std::time::Instant::now();
    match curve_format {
        Some(format) => {
            if !(0.0..=1.0).contains(&a.t) {
                return Err(UserError::Refused(format!(
                    "--parameter: expected a value in [0, 1], found {}",
                    a.t
                ))
                .into());
            }
            let pts = parse_bzc(&text, &name).map_err(UserError::input)?;
            write_curve(&pts, a.t, a.size, &a.output, format)?;
            stage("draw and write", t1);
            Ok(())
        }
        None => {
            if a.resolution == 0 || a.resolution > 1024 {
                return Err(UserError::Refused(format!(
                    "--resolution: expected 1..=1024, found {}",
                    a.resolution
                ))
                .into());
            }
            let patches = parse_bez(&text, &name).map_err(UserError::input)?;
            let mesh = tessellate(&patches, a.resolution);
            stage("tessellate", t1);
            let t2 = std::time::Instant::now();
            crate::mesh::write(&a.output, &mesh)?;
            stage("write", t2);
            Ok(())
        }
    }
}

/// Draws the curve with its de Casteljau construction at `t` and writes it as `format`.
pub(crate) fn write_curve(
    pts: &[DVec2],
    t: f64,
    size: u32,
    output: &std::path::Path,
    format: ImageFormat,
) -> Result<()> {
    let img = de_casteljau_construction(pts, t, size).map_err(UserError::input)?;
    crate::output::write_rgb8(output, format, &img)
}
