//! `prism.svg`: an SVG drawing (a file, or its text) rasterized to `uint8[H, W, 4]`.

use std::path::PathBuf;

use numpy::PyArray3;
use prism_raster::{parse_svg, read_svg_with, render, Dialect, Fonts, RasterOptions, Source};
use pyo3::prelude::*;

use crate::errors::{argument, from_error};

/// Size of the picture with `--compat cs184` when none is given, as on the command line.
const COURSE_SIDE: u32 = 1024;

/// Rasterizes an SVG drawing: `path_or_text` is a file path, or the SVG text itself (a
/// string that starts with `<`, whose relative references resolve against the working
/// folder). Returns straight-alpha RGBA, the pixels `prism svg -o x.png` writes.
///
/// The size is the document's own (`zoom` times it); with only `width` or `height` the
/// other follows the aspect ratio; with both the drawing is fitted into that box.
/// `samples` is a perfect square (1, 4, 9, ... 256). `compat="cs184"` reads the CS184
/// course's dialect, 1024x1024 unless a size is given.
#[pyfunction]
#[pyo3(signature = (path_or_text, *, width=None, height=None, samples=16, compat=None, zoom=None,
    font_dirs=Vec::new(), skip_system_fonts=false, font_family=None, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn svg<'py>(
    py: Python<'py>,
    path_or_text: &Bound<'py, PyAny>,
    width: Option<u32>,
    height: Option<u32>,
    samples: u32,
    compat: Option<&str>,
    zoom: Option<f64>,
    font_dirs: Vec<PathBuf>,
    skip_system_fonts: bool,
    font_family: Option<String>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let dialect = match compat {
        None => Dialect::Svg,
        Some("cs184") => Dialect::Cs184,
        Some(c) => {
            return Err(argument(format!(
                "compat: expected None or 'cs184', found {c:?}"
            )))
        }
    };
    if prism_raster::sample_rate(samples).is_none() {
        return Err(argument(format!(
            "samples: expected a perfect square from 1 to {} (1, 4, 9, 16, ...), found {samples}",
            prism_raster::MAX_SAMPLES
        )));
    }
    let zoom = zoom.unwrap_or(1.0);
    if !(zoom.is_finite() && zoom > 0.0) {
        return Err(argument(format!(
            "zoom: expected a positive number, found {zoom}"
        )));
    }
    if width == Some(0) || height == Some(0) {
        return Err(argument("width, height: expected 1 or more pixels"));
    }
    let fonts = Fonts {
        dirs: font_dirs,
        skip_system: skip_system_fonts,
        family: font_family,
        ..Fonts::default()
    };
    let text = path_or_text
        .extract::<String>()
        .ok()
        .filter(|s| s.trim_start().starts_with('<'));
    let path = match &text {
        Some(_) => None,
        None => Some(path_or_text.extract::<PathBuf>().map_err(|_| {
            argument("path_or_text: expected a file path or SVG text starting with '<'")
        })?),
    };
    let name = path
        .as_ref()
        .map_or_else(|| "<string>".to_string(), |p| p.display().to_string());
    let image = crate::work::run(py, threads, None, 1, |_| {
        let doc = match (&text, &path) {
            (Some(t), _) => {
                let source = Source {
                    name: name.clone(),
                    base_dir: std::env::current_dir().unwrap_or_default(),
                    fonts,
                };
                parse_svg(t, dialect, &source)
            }
            (None, Some(p)) => read_svg_with(p, dialect, &fonts),
            (None, None) => unreachable!("a path when there is no text"),
        }
        .map_err(|e| from_error(&e, Some(&name)))?;
        let (w, h) = if dialect == Dialect::Cs184 {
            (width.unwrap_or(COURSE_SIDE), height.unwrap_or(COURSE_SIDE))
        } else {
            doc.output_size(width, height, zoom)
        };
        let opts = RasterOptions {
            width: w,
            height: h,
            samples,
            compat: dialect == Dialect::Cs184,
            ..RasterOptions::default()
        };
        render(&doc, &opts)
            .map(|(image, _)| image)
            .map_err(|e| from_error(&e, Some(&name)))
    })??;
    Ok(crate::arrays::rgba8(py, image))
}
