/// Everything that can go wrong reading a scene.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// The file is not well-formed XML.
    #[error("{file}: {message}")]
    Xml {
        /// The file (or `<memory>`).
        file: String,
        /// The XML parser's message, which carries the line and column.
        message: String,
    },
    /// An element is missing, malformed or refers to something that does not exist.
    #[error("{file}:{line}: <{element}>: {message}")]
    Element {
        /// The file (or `<memory>`).
        file: String,
        /// 1-based line of the element's start tag.
        line: u32,
        /// The element's tag name.
        element: String,
        /// What was expected and what was found.
        message: String,
    },
}
