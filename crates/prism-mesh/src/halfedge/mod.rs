//! The halfedge mesh: its type, handles and traversal live in `mesh`, building from polygon
//! soups in `build`, flips, splits and collapses in `operations`, and the invariant check in
//! `validation`. Each of those files imports only `mesh`; this file only re-exports.

mod build;
mod mesh;
mod operations;
mod validation;

pub use mesh::{EdgeId, FaceId, HalfedgeId, HalfedgeMesh, VertexId};
pub use operations::TopologyError;
pub use validation::ValidationError;
