//! The logic of `prism view` without a window: a [`Viewer`] takes [`Input`] events (keys,
//! cursor, buttons, wheel, resizes) and produces frames, so that every control is tested
//! headlessly and the window around it stays a thin shell. Each kind of file has its mode
//! (`svg`: the course rasterizer's viewer; `mesh`: MeshEdit's edits on a halfedge mesh; `path`: progressive path tracing; `cloth`: the simulation played and shaded; `whitted`: the Delft ray tracer with its ray trees and BVH views); the help overlay and status line are drawn with
//! an 8x8 bitmap font (`text`).
#![warn(missing_docs)]

mod cloth;
mod input;
mod mesh;
mod orbit;
mod path;
mod svg;
mod text;
mod viewer;
mod whitted;

pub use cloth::ClothMode;
pub use input::{Input, Key};
pub use mesh::{Hover, MeshMode};
pub use orbit::Orbit;
pub use path::{PathMode, MAX_PASSES};
pub use svg::SvgMode;
pub use text::{draw_text, text_width, GLYPH};
pub use viewer::{Frame, Mode, Response, Viewer};
pub use whitted::WhittedMode;
