//! prism-view's integration tests, one module per mode of the window, each driven
//! headlessly through the library (events in, frames out).

mod cloth_mode;
mod mesh_mode;
mod path_mode;
mod svg_mode;
mod whitted_mode;
