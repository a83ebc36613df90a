//! [`SceneError`], what can go wrong reading a scene, each with its file and location.

use prism_math::Loc;

use std::sync::Arc;

/// Everything that can go wrong reading a scene.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// What the operating system said.
        #[source]
        source: Arc<std::io::Error>,
    },
    /// The file's extension names no scene format prism reads.
    #[error("{path}: expected a scene file (.dae, .obj, .toml, .xml)")]
    UnknownFormat {
        /// The file.
        path: String,
    },
    /// The path is not a regular file (a directory, say).
    #[error("{path}: expected a regular file")]
    NotAFile {
        /// The path.
        path: String,
    },
    /// The file is larger than the reader's limit.
    #[error("{path}: {bytes} bytes is over the {limit}-byte limit")]
    TooLarge {
        /// The file.
        path: String,
        /// Its size.
        bytes: u64,
        /// The limit.
        limit: u64,
    },
    /// An image the decoder refused (its message names the file).
    #[error(transparent)]
    Decode(Arc<prism_image::ImageError>),
    /// An image file (an environment map) that cannot be used.
    #[error("{path}: {message}")]
    Image {
        /// The file.
        path: String,
        /// What is wrong with it.
        message: String,
    },
    /// The file is not well-formed XML.
    #[error("{file}: {source}")]
    Xml {
        /// The file (or `<memory>`).
        file: String,
        /// The XML parser's error, which carries the line and column.
        #[source]
        source: roxmltree::Error,
    },
    /// A line of a text format (OBJ, MTL, TOML) is missing something or malformed.
    #[error("{at}: {message}")]
    Line {
        /// Where: the file (or `<memory>`) and the line.
        at: Loc,
        /// What was expected and what was found.
        message: String,
    },
    /// No data folder holds a preset's file and prism has no copy built in.
    #[error("preset {preset}: {file} is in none of the data folders ({searched}); give one with --data DIR, data_path or PRISM_DATA (the course's shared/assets)", searched = if searched.is_empty() { "none found".to_string() } else { searched.join(", ") })]
    PresetFileMissing {
        /// The preset.
        preset: &'static str,
        /// The file it loads.
        file: &'static str,
        /// The folders searched.
        searched: Vec<String>,
    },
    /// An element asks for something prism does not render (a plugin or a property).
    #[error("{at}: <{element}>: {message}")]
    Unsupported {
        /// Where: the file and the line of the element's start tag.
        at: Loc,
        /// The element's tag name.
        element: String,
        /// What is not supported.
        message: String,
    },
    /// An element is missing, malformed or refers to something that does not exist.
    #[error("{at}: <{element}>: {message}")]
    Element {
        /// Where: the file (or `<memory>`) and the line of the element's start tag.
        at: Loc,
        /// The element's tag name.
        element: String,
        /// What was expected and what was found.
        message: String,
    },
}

impl From<prism_mesh::obj::ObjError> for SceneError {
    fn from(e: prism_mesh::obj::ObjError) -> SceneError {
        SceneError::Line {
            at: Loc::line(&e.at.file, e.at.line),
            message: e.message,
        }
    }
}

/// Errors are equal when they say the same thing about the same place; OS errors compare
/// by kind.
impl PartialEq for SceneError {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (SceneError::Io { path, source }, SceneError::Io { path: p, source: s }) => {
                path == p && source.kind() == s.kind()
            }
            (SceneError::Xml { file, source }, SceneError::Xml { file: f, source: s }) => {
                file == f && source == s
            }
            _ => self.to_string() == other.to_string() && !matches!(self, SceneError::Io { .. }),
        }
    }
}
