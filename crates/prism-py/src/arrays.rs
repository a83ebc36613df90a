//! prism's images as NumPy arrays and back: pictures move into NumPy without a copy.

use numpy::ndarray::{Array2, Array3};
use numpy::{PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods};
use prism_image::{Image, Rgb8Image, RgbImage, Rgba8Image};
use prism_math::Rgb;
use pyo3::prelude::*;

use crate::errors::argument;

/// An RGBA8 picture as `uint8[H, W, 4]`, its pixels moved, not copied.
pub fn rgba8<'py>(py: Python<'py>, image: Rgba8Image) -> Bound<'py, PyArray3<u8>> {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let data = image.into_vec().into_flattened();
    let array = Array3::from_shape_vec((h, w, 4), data).expect("4 bytes a pixel");
    PyArray3::from_owned_array(py, array)
}

/// An RGB8 picture as `uint8[H, W, 3]`, its pixels moved, not copied.
pub fn rgb8<'py>(py: Python<'py>, image: Rgb8Image) -> Bound<'py, PyArray3<u8>> {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let data = image.into_vec().into_flattened();
    let array = Array3::from_shape_vec((h, w, 3), data).expect("3 bytes a pixel");
    PyArray3::from_owned_array(py, array)
}

/// A linear RGB picture as `float32[H, W, 3]`, its pixels moved, not copied.
pub fn rgb_f32<'py>(py: Python<'py>, image: RgbImage) -> Bound<'py, PyArray3<f32>> {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let pixels = std::mem::ManuallyDrop::new(image.into_vec());
    // SAFETY: `Rgb` is `repr(C)` of three `f32` (size 12, alignment 4), so the allocation of
    // `len` pixels holds exactly `3 * len` floats with the same alignment and capacity.
    let data = unsafe {
        Vec::from_raw_parts(
            pixels.as_ptr().cast_mut().cast::<f32>(),
            pixels.len() * 3,
            pixels.capacity() * 3,
        )
    };
    let array = Array3::from_shape_vec((h, w, 3), data).expect("3 floats a pixel");
    PyArray3::from_owned_array(py, array)
}

/// Rows of `N` numbers as `T[rows, N]`.
pub fn rows<'py, T: numpy::Element, const N: usize>(
    py: Python<'py>,
    rows: Vec<[T; N]>,
) -> Bound<'py, PyArray2<T>> {
    let n = rows.len();
    let array = Array2::from_shape_vec((n, N), rows.into_flattened()).expect("N a row");
    PyArray2::from_owned_array(py, array)
}

/// A picture given to prism: 8-bit with or without alpha, or linear floats.
pub enum Picture {
    /// `uint8[H, W, 3]`.
    Rgb8(Rgb8Image),
    /// `uint8[H, W, 4]`, straight alpha.
    Rgba8(Rgba8Image),
    /// `float32` or `float64[H, W, 3]`, linear.
    Linear(RgbImage),
}

fn size(shape: &[usize]) -> PyResult<(u32, u32)> {
    let w = u32::try_from(shape[1]).map_err(|_| argument("image: too wide"))?;
    let h = u32::try_from(shape[0]).map_err(|_| argument("image: too tall"))?;
    if w == 0 || h == 0 {
        return Err(argument(format!("image: {w}x{h} is empty")));
    }
    Ok((w, h))
}

/// Reads a NumPy array as a picture.
///
/// # Errors
/// `ArgumentError` for any other shape or type.
pub fn picture(array: &Bound<'_, PyAny>) -> PyResult<Picture> {
    if let Ok(a) = array.extract::<PyReadonlyArray3<'_, u8>>() {
        let (w, h) = size(a.shape())?;
        let v = a.as_array();
        return match a.shape()[2] {
            3 => Ok(Picture::Rgb8(Image::from_fn(w, h, |x, y| {
                let (x, y) = (x as usize, y as usize);
                [v[[y, x, 0]], v[[y, x, 1]], v[[y, x, 2]]]
            }))),
            4 => Ok(Picture::Rgba8(Image::from_fn(w, h, |x, y| {
                let (x, y) = (x as usize, y as usize);
                [v[[y, x, 0]], v[[y, x, 1]], v[[y, x, 2]], v[[y, x, 3]]]
            }))),
            c => Err(argument(format!(
                "image: expected 3 or 4 channels, found {c}"
            ))),
        };
    }
    let linear = |shape: &[usize], at: &dyn Fn(usize, usize, usize) -> f32| -> PyResult<Picture> {
        if shape[2] != 3 {
            return Err(argument(format!(
                "image: expected 3 channels of linear radiance, found {}",
                shape[2]
            )));
        }
        let (w, h) = size(shape)?;
        Ok(Picture::Linear(Image::from_fn(w, h, |x, y| {
            let (x, y) = (x as usize, y as usize);
            Rgb::new(at(y, x, 0), at(y, x, 1), at(y, x, 2))
        })))
    };
    if let Ok(a) = array.extract::<PyReadonlyArray3<'_, f32>>() {
        let v = a.as_array();
        return linear(a.shape(), &|y, x, c| v[[y, x, c]]);
    }
    if let Ok(a) = array.extract::<PyReadonlyArray3<'_, f64>>() {
        let v = a.as_array();
        return linear(a.shape(), &|y, x, c| v[[y, x, c]] as f32);
    }
    Err(argument(
        "image: expected a NumPy array uint8[H, W, 3 or 4] or float32/float64[H, W, 3]",
    ))
}

/// Reads `[x, y, z]` rows (`float64[N, 3]`, or anything NumPy turns into one).
///
/// # Errors
/// `ArgumentError` for another shape.
pub fn points(array: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<prism_math::glam::DVec3>> {
    let np = array.py().import("numpy")?;
    let a = np.call_method1("ascontiguousarray", (array, "float64"))?;
    let a = a
        .cast_into::<numpy::PyArray2<f64>>()
        .map_err(|_| argument(format!("{what}: expected float rows [N, 3]")))?;
    let r = a.readonly();
    if r.shape()[1] != 3 {
        return Err(argument(format!(
            "{what}: expected rows of 3 coordinates, found {}",
            r.shape()[1]
        )));
    }
    Ok(r.as_array()
        .rows()
        .into_iter()
        .map(|p| prism_math::glam::DVec3::new(p[0], p[1], p[2]))
        .collect())
}
