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
    /// The image is larger than [`crate::MAX_IMAGE_PIXELS`] or has a zero dimension.
    #[error("{what}: image size {width}x{height} is outside 1..={max} pixels")]
    BadSize {
        /// The file name, or a description of the in-memory source.
        what: String,
        /// Width in pixels.
        width: u64,
        /// Height in pixels.
        height: u64,
        /// The limit that was exceeded.
        max: u64,
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
