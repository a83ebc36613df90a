//! Floor-2 2D rasterization for prism: an SVG reader (the CS184 subset and standard SVG
//! shapes, paths, strokes, gradients and images) producing a plain [`Document`], and a
//! supersampling rasterizer that renders it to an image; and figures, pictures of geometry
//! (mesh wireframes, de Casteljau constructions) drawn with that rasterizer.
//!
//! ```
//! use prism_raster::{parse_svg, render, Dialect, RasterOptions, Source};
//! let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">
//!   <rect width="10" height="10" fill="red"/></svg>"#;
//! let doc = parse_svg(svg, Dialect::Svg, &Source::default()).unwrap();
//! let opts = RasterOptions { width: 10, height: 10, ..Default::default() };
//! let (image, _) = render(&doc, &opts).unwrap();
//! assert_eq!(image.get(5, 5), [255, 0, 0, 255]);
//! ```
#![warn(missing_docs)]

mod blend;
mod document;
mod figures;
pub mod filter;
mod parse;
pub mod path;
mod raster;
mod triangulate;

pub use document::{
    BlendMode, Document, FillRule, Gradient, GradientKind, Item, MaskKind, Mat3, Paint, Pattern,
    Spread, Stop,
};
pub use figures::{de_casteljau_construction, wireframe};
pub use parse::{
    parse_path_data, parse_path_data_prefix, parse_svg, read_svg, read_svg_with, Dialect, Fonts,
    PathDataError, Source, SvgError, MAX_DEPTH, MAX_IMAGE_BYTES, MAX_ITEMS, MAX_SVG_BYTES,
    MAX_TEXT_PATH, MAX_USE_ELEMENTS,
};
pub use raster::{
    render, render_rows, sample_rate, view_transform, Prepared, RasterError, RasterOptions,
    RasterStats, View, MAX_DIMENSION, MAX_SAMPLES,
};
pub use triangulate::ear_clip;
