//! [`ImageError`], what can go wrong reading or writing an image.

use std::path::PathBuf;

/// Everything that can go wrong reading or writing an image.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file involved.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The bytes are not a valid image of the expected format.
    #[error("{what}: {message}")]
    Decode {
        /// The file name, or a description of the in-memory source.
        what: String,
        /// What the decoder expected and found.
        message: String,
    },
    /// The image has a zero dimension.
    #[error("{what}: image size {width}x{height} is empty")]
    BadSize {
        /// The file name, or a description of the in-memory source.
        what: String,
        /// Width in pixels.
        width: u64,
        /// Height in pixels.
        height: u64,
    },
    /// The decoded image would be larger than one image's memory budget
    /// ([`prism_math::limits::image_budget`]); nothing was allocated for it.
    #[error("{what}: a {width}x{height} image {source}")]
    OverBudget {
        /// The file name, or a description of the in-memory source.
        what: String,
        /// Width in pixels.
        width: u64,
        /// Height in pixels.
        height: u64,
        /// What it needs and the budget.
        #[source]
        source: prism_math::limits::OverBudget,
    },
    /// Encoding failed.
    #[error("encoding {format}: {message}")]
    Encode {
        /// The target format.
        format: &'static str,
        /// What went wrong.
        message: String,
    },
}
