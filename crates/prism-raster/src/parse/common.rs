//! Errors with locations and the readers' limits; number lists, numbers with units and
//! transforms for the course dialect.

use std::sync::Arc;

use prism_math::Loc;

use super::number::{number_prefix_len, to_num, Precision};
use crate::document::Mat3;

/// Deepest element nesting a document may have, counting references (`use`, `url(#id)`).
pub const MAX_DEPTH: usize = 256;
/// Largest SVG file accepted, in bytes.
pub const MAX_SVG_BYTES: u64 = 256 << 20;
/// Most drawables (after expanding points and triangles) a document may produce.
pub const MAX_ITEMS: usize = 20_000_000;
/// Most elements that `use` references may create when expanded (each reference copies
/// its target's whole subtree, references inside it included), as usvg limits them.
pub const MAX_USE_ELEMENTS: usize = 1_000_000;

/// A reader error with its location, shown as `file:line: element: message` (or `file: message`
/// for the whole file).
#[derive(Clone, Debug, thiserror::Error)]
pub enum SvgError {
    /// The file cannot be read.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// What the operating system said.
        #[source]
        source: Arc<std::io::Error>,
    },
    /// The file is not UTF-8 text.
    #[error("{file}: expected UTF-8 text: {source}")]
    Encoding {
        /// The file.
        file: String,
        /// Where the first invalid byte is.
        #[source]
        source: std::str::Utf8Error,
    },
    /// The file is larger than [`MAX_SVG_BYTES`].
    #[error("{file}: the file is larger than the limit of {limit} bytes")]
    FileTooLarge {
        /// The file.
        file: String,
        /// The limit, in bytes.
        limit: u64,
    },
    /// The text is not well-formed XML.
    #[error("{at}: xml: malformed XML: {source}")]
    Xml {
        /// Where: the file (or `<memory>`) and the line of the syntax error.
        at: Loc,
        /// The XML parser's error.
        #[source]
        source: roxmltree::Error,
    },
    /// An element or attribute is missing, malformed or refers to nothing.
    #[error("{at}: {element}: {message}")]
    Element {
        /// Where: the file (or `<memory>`) and the line of the element's start tag.
        at: Loc,
        /// The element's name.
        element: String,
        /// What was expected and what was found.
        message: String,
    },
    /// Elements nest deeper than [`MAX_DEPTH`] (counting `use` references).
    #[error("{at}: {element}: elements nest deeper than the limit of {limit}")]
    NestingLimit {
        /// Where: the file (or `<memory>`) and the line of the first element past the limit.
        at: Loc,
        /// Its name.
        element: String,
        /// The limit.
        limit: usize,
    },
    /// The document produces more than [`MAX_ITEMS`] drawables.
    #[error("{at}: {element}: more than {limit} drawables")]
    ItemsLimit {
        /// Where: the file (or `<memory>`) and the line of the element that passed the limit.
        at: Loc,
        /// Its name.
        element: String,
        /// The limit.
        limit: usize,
    },
    /// Expanding `use` references would create more than [`MAX_USE_ELEMENTS`] elements.
    #[error("{at}: {element}: use references would expand to more than {limit} elements")]
    UseLimit {
        /// Where: the file and the line of the element whose expansion passes the limit.
        at: Loc,
        /// Its name.
        element: String,
        /// The limit.
        limit: usize,
    },
    /// An image the document holds is larger than the image budget allows.
    #[error("{file}: image: {source}")]
    Image {
        /// The SVG file.
        file: String,
        /// The refusal, with the image's size and the budget.
        #[source]
        source: Arc<prism_image::ImageError>,
    },
    /// A font directory given for text cannot be read.
    #[error("{dir}: font directory: {source}")]
    FontDir {
        /// The directory.
        dir: String,
        /// What the operating system said.
        #[source]
        source: Arc<std::io::Error>,
    },
    /// usvg refused the document as a whole (no valid size, too many elements).
    #[error("{file}: {source}")]
    Usvg {
        /// The file.
        file: String,
        /// usvg's error.
        #[source]
        source: Arc<usvg::Error>,
    },
}

impl SvgError {
    /// Where the error is: the file, and its line (0 for errors about the whole file).
    #[must_use]
    pub fn at(&self) -> Loc {
        match self {
            SvgError::Io { file, .. }
            | SvgError::Encoding { file, .. }
            | SvgError::FileTooLarge { file, .. }
            | SvgError::Usvg { file, .. }
            | SvgError::Image { file, .. } => Loc::line(file, 0),
            SvgError::FontDir { dir, .. } => Loc::line(dir, 0),
            SvgError::Xml { at, .. }
            | SvgError::Element { at, .. }
            | SvgError::NestingLimit { at, .. }
            | SvgError::ItemsLimit { at, .. }
            | SvgError::UseLimit { at, .. } => at.clone(),
        }
    }
}

/// Attribute lookup by plain name, as SVG's own attributes carry no namespace: an editor's
/// `sodipodi:cx` is not `cx`.
pub(crate) trait PlainAttribute<'a> {
    /// The value of the attribute named `name` that has no namespace.
    fn attr(&self, name: &str) -> Option<&'a str>;
}

impl<'a, 'i> PlainAttribute<'a> for roxmltree::Node<'a, 'i> {
    fn attr(&self, name: &str) -> Option<&'a str> {
        self.attributes()
            .find(|a| a.namespace().is_none() && a.name() == name)
            .map(|a| a.value())
    }
}

/// Where the element being read sits, for error messages.
#[derive(Clone, Copy)]
pub(crate) struct ElementAt<'a> {
    pub file: &'a str,
    pub line: u32,
    pub element: &'a str,
}

impl ElementAt<'_> {
    /// The file and line.
    fn at(&self) -> Loc {
        Loc::line(self.file, self.line)
    }

    pub fn err(&self, message: impl Into<String>) -> SvgError {
        SvgError::Element {
            at: self.at(),
            element: self.element.to_string(),
            message: message.into(),
        }
    }

    pub fn nesting_limit(&self) -> SvgError {
        SvgError::NestingLimit {
            at: self.at(),
            element: self.element.to_string(),
            limit: MAX_DEPTH,
        }
    }

    pub fn items_limit(&self) -> SvgError {
        SvgError::ItemsLimit {
            at: self.at(),
            element: self.element.to_string(),
            limit: MAX_ITEMS,
        }
    }
}

/// Reads a whole list of numbers separated by whitespace and/or single commas.
pub(crate) fn number_list(
    s: &str,
    p: Precision,
    loc: &ElementAt,
    attr: &str,
) -> Result<Vec<f64>, SvgError> {
    let mut out = Vec::new();
    let mut rest = s.trim_start();
    while !rest.is_empty() {
        let n = number_prefix_len(rest);
        if n == 0 {
            return Err(loc.err(format!(
                "{attr}: expected a number, found {:?}",
                rest.chars().take(12).collect::<String>()
            )));
        }
        let v = to_num(&rest[..n], p)
            .ok_or_else(|| loc.err(format!("{attr}: number {:?} is not finite", &rest[..n])))?;
        out.push(v);
        rest = rest[n..].trim_start();
        if let Some(r) = rest.strip_prefix(',') {
            rest = r.trim_start();
        }
    }
    Ok(out)
}

/// Reads one number, allowing a trailing unit of letters or `%` (returned alongside).
pub(crate) fn number_with_unit<'s>(
    s: &'s str,
    p: Precision,
    loc: &ElementAt,
    attr: &str,
) -> Result<(f64, &'s str), SvgError> {
    let t = s.trim();
    let n = number_prefix_len(t);
    let bad = || loc.err(format!("{attr}: expected a number, found {t:?}"));
    if n == 0 {
        return Err(bad());
    }
    let v = to_num(&t[..n], p).ok_or_else(bad)?;
    let unit = t[n..].trim();
    if !unit.chars().all(|c| c.is_ascii_alphabetic() || c == '%') {
        return Err(bad());
    }
    Ok((v, unit))
}

/// Parses an SVG `transform` list into one matrix, functions applied in document order
/// (`M = M1 * M2 * ...`). With `scale_y_defaults_to_one`, `scale(s)` means `scale(s, 1)`
/// as in the course renderer; otherwise `scale(s, s)` as in the SVG spec.
pub(crate) fn parse_transform(
    s: &str,
    p: Precision,
    loc: &ElementAt,
    scale_y_defaults_to_one: bool,
) -> Result<Mat3, SvgError> {
    let mut m = Mat3::IDENTITY;
    let mut rest = s.trim();
    while !rest.is_empty() {
        let open = rest
            .find('(')
            .ok_or_else(|| loc.err(format!("transform: expected '(' in {rest:?}")))?;
        let name = rest[..open].trim();
        let close = rest[open..]
            .find(')')
            .ok_or_else(|| loc.err(format!("transform: expected ')' after {name}(")))?
            + open;
        let args = number_list(&rest[open + 1..close], p, loc, "transform")?;
        let arity = |ok: &[usize]| {
            if ok.contains(&args.len()) {
                Ok(())
            } else {
                Err(loc.err(format!(
                    "transform: {name}() takes {ok:?} arguments, found {}",
                    args.len()
                )))
            }
        };
        let f = match name {
            "matrix" => {
                arity(&[6])?;
                Mat3::affine(args[0], args[1], args[2], args[3], args[4], args[5])
            }
            "translate" => {
                arity(&[1, 2])?;
                Mat3::translate(args[0], args.get(1).copied().unwrap_or(0.0))
            }
            "scale" => {
                arity(&[1, 2])?;
                let y = args
                    .get(1)
                    .copied()
                    .unwrap_or(if scale_y_defaults_to_one { 1.0 } else { args[0] });
                Mat3::scale(args[0], y)
            }
            "rotate" => {
                arity(&[1, 3])?;
                let r = Mat3::rotate(args[0]);
                if args.len() == 3 {
                    Mat3::translate(args[1], args[2])
                        .mul(&r)
                        .mul(&Mat3::translate(-args[1], -args[2]))
                } else {
                    r
                }
            }
            "skewX" => {
                arity(&[1])?;
                Mat3::skew_x(args[0])
            }
            "skewY" => {
                arity(&[1])?;
                Mat3::skew_y(args[0])
            }
            other => {
                return Err(loc.err(format!(
                    "transform: expected matrix, translate, scale, rotate, skewX or skewY, found {other:?}"
                )))
            }
        };
        m = m.mul(&f);
        rest = rest[close + 1..].trim_start();
        if let Some(r) = rest.strip_prefix(',') {
            rest = r.trim_start();
        }
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::DVec2;

    fn loc() -> ElementAt<'static> {
        ElementAt {
            file: "t.svg",
            line: 3,
            element: "rect",
        }
    }

    #[test]
    fn lists_accept_commas_and_compact_signs() {
        let l = number_list("10,20 30-40 .5.5", Precision::F64, &loc(), "points").unwrap();
        assert_eq!(l, vec![10.0, 20.0, 30.0, -40.0, 0.5, 0.5]);
        let e = number_list("1 2 x", Precision::F64, &loc(), "points").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.svg:3: rect: points: expected a number, found \"x\""
        );
        assert!(number_list("1e999", Precision::F64, &loc(), "points").is_err());
    }

    /// Closed form: composite transforms apply right to left to points.
    #[test]
    fn transform_lists_compose_in_document_order() {
        let m =
            parse_transform("translate(10 20) scale(2)", Precision::F64, &loc(), false).unwrap();
        assert_eq!(m.apply(DVec2::new(1.0, 1.0)), DVec2::new(12.0, 22.0));
        let m = parse_transform("scale(2)", Precision::F64, &loc(), true).unwrap();
        assert_eq!(m.apply(DVec2::new(1.0, 1.0)), DVec2::new(2.0, 1.0));
        let m = parse_transform("rotate(90 10 10)", Precision::F64, &loc(), false).unwrap();
        let p = m.apply(DVec2::new(20.0, 10.0));
        assert!((p - DVec2::new(10.0, 20.0)).length() < 1e-12);
        let m = parse_transform("matrix(1,0,0,1,5,6)", Precision::F64, &loc(), false).unwrap();
        assert_eq!(m.apply(DVec2::ZERO), DVec2::new(5.0, 6.0));
        assert!(parse_transform("spin(3)", Precision::F64, &loc(), false).is_err());
        assert!(parse_transform("translate(1", Precision::F64, &loc(), false).is_err());
    }
}
