//! The `prism` Python package's native module, `prism._prism`: each system's library
//! function behind a Python function or class, with NumPy arrays in and out.
//!
//! - `svg`: the 2D rasterizer.
//! - `mesh`: the halfedge mesh, Loop subdivision and Bezier patches.
//! - `render`: the path tracer and its scenes.
//! - `raytrace`: the Whitted ray tracer and its ray trees.
//! - `shade`: the course's shaders.
//! - `cloth`: the mass-spring cloth.
//! - `images`: pictures to and from files; `budget`: the memory budget.
//! - `work`: long calls off the GIL, with progress and Ctrl-C; `errors`: exceptions;
//!   `arrays`: pictures as NumPy arrays.

mod arrays;
mod budget;
mod cloth;
mod errors;
mod images;
mod mesh;
mod raytrace;
mod render;
mod shade;
mod svg;
mod work;

use pyo3::prelude::*;

/// The native module.
#[pymodule]
fn _prism(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(svg::svg, m)?)?;
    m.add_class::<mesh::Mesh>()?;
    m.add_function(wrap_pyfunction!(mesh::bezier_patch, m)?)?;
    m.add_class::<render::Scene>()?;
    m.add_function(wrap_pyfunction!(render::load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(raytrace::raytrace, m)?)?;
    m.add_function(wrap_pyfunction!(raytrace::trace_pixel, m)?)?;
    m.add_class::<cloth::Cloth>()?;
    m.add_function(wrap_pyfunction!(shade::shade, m)?)?;
    m.add_function(wrap_pyfunction!(images::write_image, m)?)?;
    m.add_function(wrap_pyfunction!(budget::set_memory_budget, m)?)?;
    m.add_function(wrap_pyfunction!(budget::memory_budget, m)?)?;
    m.add_function(wrap_pyfunction!(images::read_image, m)?)?;
    m.add_function(wrap_pyfunction!(images::encode_png, m)?)?;
    Ok(())
}
