//! `prism.write_image`, `prism.read_image` and `prism.encode_png`: pictures to and from
//! files, the format chosen by the extension as on the command line.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::arrays::{picture, rgb_f32, rgba8, Picture};
use crate::errors::{argument, from_error};

/// The lower-case extension of `path`.
fn extension(path: &std::path::Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Writes `image` to `path`, the format by its extension: `.png` (8-bit arrays as they
/// are, with alpha if they have it; linear arrays sRGB-encoded and clamped, as `prism
/// render -o x.png` writes them), `.jpg`/`.jpeg` (alpha over white) or `.exr` (linear
/// float arrays only). The file is written whole or not at all.
#[pyfunction]
pub fn write_image(py: Python<'_>, path: PathBuf, image: &Bound<'_, PyAny>) -> PyResult<()> {
    let pic = picture(image)?;
    let ext = extension(&path);
    let name = path.display().to_string();
    let result = py.detach(|| match (ext.as_str(), &pic) {
        ("png", Picture::Rgb8(i)) => Ok(prism_image::write_png(&path, i)),
        ("png", Picture::Rgba8(i)) => Ok(prism_image::write_png_rgba(&path, i)),
        ("png", Picture::Linear(i)) => Ok(prism_image::write_png(&path, &i.linear_to_srgb8())),
        ("jpg" | "jpeg", Picture::Rgb8(i)) => Ok(prism_image::write_jpeg(&path, i)),
        ("jpg" | "jpeg", Picture::Rgba8(i)) => Ok(prism_image::write_jpeg(
            &path,
            &i.over_background([255, 255, 255]),
        )),
        ("jpg" | "jpeg", Picture::Linear(i)) => {
            Ok(prism_image::write_jpeg(&path, &i.linear_to_srgb8()))
        }
        ("exr", Picture::Linear(i)) => Ok(prism_image::write_exr(&path, i)),
        ("exr", _) => {
            Err("an .exr file holds linear radiance: give a float32 or float64 [H, W, 3] array")
        }
        _ => Err("expected a .png, .jpg or .exr file name"),
    });
    match result {
        Ok(written) => written.map_err(|e| from_error(&e, Some(&name))),
        Err(why) => Err(argument(format!("{name}: {why}"))),
    }
}

/// Reads a picture: `.exr` and `.hdr` files as linear `float32[H, W, 3]`, PNG and JPEG
/// files as `uint8[H, W, 4]`.
#[pyfunction]
pub fn read_image<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let name = path.display().to_string();
    if matches!(extension(&path).as_str(), "exr" | "hdr") {
        let image = py
            .detach(|| prism_image::read_radiance(&path))
            .map_err(|e| from_error(&e, Some(&name)))?;
        return Ok(rgb_f32(py, image).into_any());
    }
    let image = py
        .detach(|| prism_image::read_image(&path))
        .map_err(|e| from_error(&e, Some(&name)))?;
    Ok(rgba8(py, image).into_any())
}

/// PNG bytes of a picture (as [`write_image`] writes a `.png`), for notebooks' display.
#[pyfunction]
pub fn encode_png<'py>(py: Python<'py>, image: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyBytes>> {
    let bytes = match picture(image)? {
        Picture::Rgb8(i) => prism_image::encode_png(&i),
        Picture::Rgba8(i) => prism_image::encode_png_rgba(&i),
        Picture::Linear(i) => prism_image::encode_png(&i.linear_to_srgb8()),
    }
    .map_err(|e| from_error(&e, None))?;
    Ok(PyBytes::new(py, &bytes))
}
