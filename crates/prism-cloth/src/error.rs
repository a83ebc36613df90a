//! [`ClothError`], what can go wrong reading a cloth scene, each with its file and line.

use prism_math::Loc;

/// Everything that can go wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ClothError {
    /// The file could not be read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What the operating system said.
        message: String,
    },
    /// The text is not JSON, or a value is missing, of the wrong type or out of range.
    #[error("{at}: {message}")]
    Parse {
        /// Where: the file (or `<memory>`) and the line.
        at: Loc,
        /// What was expected and what was found.
        message: String,
    },
    /// A `--set KEY=VALUE` override is malformed or names no key.
    #[error("--set {setting}: {message}")]
    Override {
        /// The override as given.
        setting: String,
        /// What was expected.
        message: String,
    },
}
