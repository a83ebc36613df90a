//! What a reader carries while it walks one document: where the document came from
//! ([`Source`]), the XML tree, line numbers for locating elements, the warnings already
//! given and the textures already decoded.

use std::path::PathBuf;

use prism_image::UvConvention;
use roxmltree::Node;

use super::common::ElementAt;

/// Where a document came from, for resolving relative files and naming errors.
#[derive(Clone, Debug, Default)]
pub struct Source {
    /// The name used in error messages (usually the file path).
    pub name: String,
    /// The directory relative file references are resolved against.
    pub base_dir: PathBuf,
    /// The fonts text is set in (standard dialect).
    pub fonts: Fonts,
}

/// Where text finds its fonts, as resvg's command line sets them.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Fonts {
    /// Directories of font files loaded in addition to the system's.
    pub dirs: Vec<PathBuf>,
    /// Leave out the system's fonts.
    pub skip_system: bool,
    /// The family used when an element names none (default Times New Roman).
    pub family: Option<String>,
    /// The family `serif` stands for.
    pub serif: Option<String>,
    /// The family `sans-serif` stands for.
    pub sans_serif: Option<String>,
    /// The family `monospace` stands for.
    pub monospace: Option<String>,
    /// The family `cursive` stands for.
    pub cursive: Option<String>,
    /// The family `fantasy` stands for.
    pub fantasy: Option<String>,
}

/// The state of one reading of a course-dialect document.
pub(crate) struct Ctx<'a> {
    pub source: &'a Source,
    /// Line numbers of the text's byte offsets, for locating elements.
    pub lines: prism_math::LineIndex<'a>,
    /// Textures already decoded, by reference and uv convention: each file or data URI is
    /// decoded once however often it is used.
    pub textures: std::cell::RefCell<std::collections::HashMap<(String, UvConvention), usize>>,
}

/// Where `node` sits in the document, for error messages.
pub(crate) fn element_loc<'a>(ctx: &Ctx<'a>, node: &Node<'a, 'a>) -> ElementAt<'a> {
    let source: &'a Source = ctx.source;
    ElementAt {
        file: &source.name,
        line: ctx.lines.line(node.range().start),
        element: node.tag_name().name(),
    }
}
