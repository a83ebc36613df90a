//! SVG readers: the standard dialect ([`Dialect::Svg`], in `svg` with its `style` and
//! `viewport`) and the course's ([`Dialect::Cs184`], in `cs184`), both producing a
//! [`Document`]. Below them: `common` (errors, limits, number lists, transforms), `number`
//! (the number lexer), `pathdata`, `color`, `context` (the reading state), `images` and
//! `course` (the course's own elements, read in both dialects).

mod caught;
pub(crate) mod common;
mod context;
mod course;
pub(crate) mod cs184;
mod fonts;
mod guard;
mod images;
mod number;
mod pathdata;
mod resources;
mod standard;

use prism_math::Loc;
use std::path::Path as FsPath;
use std::sync::Arc;

pub use common::{SvgError, MAX_DEPTH, MAX_ITEMS, MAX_SVG_BYTES, MAX_USE_ELEMENTS};
use context::{element_loc, Ctx};
pub use context::{Fonts, Source};
pub use guard::MAX_TEXT_PATH;
pub use pathdata::{parse_path_data, parse_path_data_prefix, PathDataError};
pub use resources::MAX_IMAGE_BYTES;

use crate::document::Document;

/// Which reading of SVG to apply.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Dialect {
    /// The SVG 1.1/2 specification's reading (what resvg and browsers do).
    #[default]
    Svg,
    /// The CS184 course renderer's reading, quirks included (see `FORMATS.md` section 1).
    Cs184,
}

/// Parses SVG text in the given dialect.
///
/// # Errors
/// [`SvgError`] naming the file, line and element: malformed XML, a root that is not
/// `<svg>`, a document beyond the documented limits ([`MAX_DEPTH`], [`MAX_SVG_BYTES`],
/// [`MAX_ITEMS`], [`MAX_USE_ELEMENTS`]) or one usvg refuses as a whole; in the course
/// dialect also bad numbers, colours or coordinates and a missing or corrupt texture. The
/// standard dialect reads past bad attribute values as browsers and resvg do, with a
/// warning.
pub fn parse_svg(text: &str, dialect: Dialect, source: &Source) -> Result<Document, SvgError> {
    if text.len() as u64 > MAX_SVG_BYTES {
        return Err(SvgError::FileTooLarge {
            file: source.name.clone(),
            limit: MAX_SVG_BYTES,
        });
    }
    if dialect == Dialect::Svg {
        return standard::parse(text, source);
    }
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        nodes_limit: 50_000_000,
        ..Default::default()
    };
    let xml = roxmltree::Document::parse_with_options(text, opts).map_err(|e| SvgError::Xml {
        at: Loc::line(&source.name, e.pos().row),
        source: e,
    })?;
    let root = xml.root_element();
    let mut ctx = Ctx {
        source,
        lines: prism_math::LineIndex::new(text),
        textures: Default::default(),
    };
    if root.tag_name().name() != "svg" {
        let loc = element_loc(&ctx, &root);
        return Err(loc.err("expected the root element to be <svg>"));
    }
    cs184::parse(root, &mut ctx)
}

/// Reads and parses an SVG file; relative references resolve against its directory, and
/// text uses the system's fonts.
///
/// # Errors
/// As [`parse_svg`], plus an unreadable or non-UTF-8 file.
pub fn read_svg(path: &FsPath, dialect: Dialect) -> Result<Document, SvgError> {
    read_svg_with(path, dialect, &Fonts::default())
}

/// [`read_svg`] with text set in the given fonts.
///
/// # Errors
/// As [`read_svg`], plus a font directory that cannot be read.
pub fn read_svg_with(path: &FsPath, dialect: Dialect, fonts: &Fonts) -> Result<Document, SvgError> {
    let name = path.display().to_string();
    let io = |e: std::io::Error| SvgError::Io {
        file: name.clone(),
        source: Arc::new(e),
    };
    let bytes = prism_math::limits::read_input(path, MAX_SVG_BYTES).map_err(io)?;
    let text = String::from_utf8(bytes).map_err(|e| SvgError::Encoding {
        file: name.clone(),
        source: e.utf8_error(),
    })?;
    let base_dir = path.parent().map(FsPath::to_path_buf).unwrap_or_default();
    let source = Source {
        name,
        base_dir,
        fonts: fonts.clone(),
    };
    parse_svg(&text, dialect, &source)
}

#[cfg(test)]
mod tests;
