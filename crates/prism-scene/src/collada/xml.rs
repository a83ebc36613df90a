//! Reading values out of the XML tree: located errors ([`Cx`]), child lookup, `#id`
//! references, and the numbers and indices in an element's text.

use prism_math::Loc;
use roxmltree::Node as XmlNode;

use crate::error::SceneError;

/// The file being read: its name and line numbers, for located errors.
pub(super) struct Cx<'a, 'input> {
    /// Line numbers of the text's byte offsets, for locating elements.
    pub(super) lines: prism_math::LineIndex<'input>,
    /// The file's name in errors.
    pub(super) file: &'a str,
}

impl Cx<'_, '_> {
    /// The 1-based line of `n`'s start tag.
    pub(super) fn line(&self, n: XmlNode) -> u32 {
        self.lines.line(n.range().start)
    }

    /// A [`SceneError::Element`] at `n`.
    pub(super) fn err(&self, n: XmlNode, message: impl Into<String>) -> SceneError {
        SceneError::Element {
            at: Loc::line(self.file, self.line(n)),
            element: n.tag_name().name().to_string(),
            message: message.into(),
        }
    }
}

/// The first child element of `n` named `name`.
pub(super) fn child<'a, 'i>(n: XmlNode<'a, 'i>, name: &str) -> Option<XmlNode<'a, 'i>> {
    n.children().find(|c| c.has_tag_name(name))
}

/// The child elements of `n` named `name`.
pub(super) fn children<'a, 'i: 'a>(
    n: XmlNode<'a, 'i>,
    name: &'a str,
) -> impl Iterator<Item = XmlNode<'a, 'i>> + 'a {
    n.children().filter(move |c| c.has_tag_name(name))
}

/// A `#id` attribute, without the `#`.
pub(super) fn reference<'a>(
    cx: &Cx,
    n: XmlNode<'a, '_>,
    attr: &str,
) -> Result<&'a str, SceneError> {
    let v = n
        .attribute(attr)
        .ok_or_else(|| cx.err(n, format!("expected a {attr} attribute")))?;
    v.strip_prefix('#').ok_or_else(|| {
        cx.err(
            n,
            format!("{attr}: expected a local reference \"#id\", found {v:?}"),
        )
    })
}

/// The finite numbers in an element's text.
pub(super) fn floats(cx: &Cx, n: XmlNode) -> Result<Vec<f64>, SceneError> {
    let text = n.text().unwrap_or("");
    let mut out = Vec::with_capacity(text.len() / 8);
    for (i, t) in text.split_ascii_whitespace().enumerate() {
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => out.push(v),
            Ok(_) => {
                return Err(cx.err(n, format!("number {i}: expected a finite value, found {t}")))
            }
            Err(_) => return Err(cx.err(n, format!("number {i}: expected a number, found {t:?}"))),
        }
    }
    Ok(out)
}

/// Exactly `count` finite numbers from an element's text.
pub(super) fn floats_n(cx: &Cx, n: XmlNode, count: usize) -> Result<Vec<f64>, SceneError> {
    let v = floats(cx, n)?;
    if v.len() != count {
        return Err(cx.err(n, format!("expected {count} numbers, found {}", v.len())));
    }
    Ok(v)
}

/// The non-negative integers in an element's text.
pub(super) fn indices(cx: &Cx, n: XmlNode) -> Result<Vec<u32>, SceneError> {
    let text = n.text().unwrap_or("");
    let mut out = Vec::with_capacity(text.len() / 3);
    for (i, t) in text.split_ascii_whitespace().enumerate() {
        out.push(t.parse::<u32>().map_err(|_| {
            cx.err(
                n,
                format!("index {i}: expected a non-negative integer, found {t:?}"),
            )
        })?);
    }
    Ok(out)
}

/// A non-negative integer attribute, if present.
pub(super) fn count_attr(cx: &Cx, n: XmlNode, attr: &str) -> Result<Option<usize>, SceneError> {
    n.attribute(attr)
        .map(|v| {
            v.trim().parse::<usize>().map_err(|_| {
                cx.err(
                    n,
                    format!("{attr}: expected a non-negative integer, found {v:?}"),
                )
            })
        })
        .transpose()
}
