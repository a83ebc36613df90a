//! [`ShadeError`], what can go wrong preparing a shaded picture.

/// Everything that can go wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShadeError {
    /// A malformed or too large OBJ file, with its location.
    #[error(transparent)]
    Obj(#[from] prism_mesh::obj::ObjError),
    /// The camera cannot form a picture.
    #[error("camera: {0}")]
    Camera(String),
    /// The sample count is not a square.
    #[error(
        "samples: expected a square number of samples per pixel (1, 4, 9, ..., 256), found {0}"
    )]
    Samples(u32),
}
