//! [`MeshError`], what can go wrong reading a mesh file or building its connectivity.

use prism_math::Loc;

/// Everything that can go wrong reading a mesh or building its connectivity. Face and
/// vertex numbers in topology errors count from 0, in file order.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A syntax or value error in a mesh file, with its location.
    #[error("{at}: {message}")]
    Parse {
        /// Where: the file (or `<memory>`) and the line.
        at: Loc,
        /// What was expected and what was found.
        message: String,
    },
    /// A malformed or too large OBJ file, with its location.
    #[error(transparent)]
    Obj(#[from] crate::obj::ObjError),
    /// The polygon soup cannot be a manifold halfedge mesh.
    #[error("face {face}: {message}")]
    Topology {
        /// The offending face index.
        face: usize,
        /// What is wrong (non-manifold edge or vertex, degenerate face, index out of range).
        message: String,
    },
    /// A vertex makes the mesh non-manifold (its faces do not form one fan).
    #[error("vertex {vertex}: {message}")]
    NonManifoldVertex {
        /// The offending vertex index.
        vertex: usize,
        /// What is wrong.
        message: String,
    },
    /// The result would be larger than the memory budget.
    #[error("making {faces} faces {source}")]
    OverBudget {
        /// Faces the result would have.
        faces: u64,
        /// What they need and the budget.
        #[source]
        source: prism_math::limits::OverBudget,
    },
    /// An operation needs triangles.
    #[error("face {face} has {sides} sides; this operation needs triangles")]
    NotTriangles {
        /// The first non-triangle face.
        face: usize,
        /// Its side count.
        sides: usize,
    },
}
