//! Floor-2 scene descriptions for prism: plain data read from files, from which runtime
//! structures (halfedge meshes, BVHs) are built.
//!
//! The reader here is COLLADA 1.4.1 ([`read_collada`], [`parse_collada`]): geometry
//! (`<polylist>`, `<triangles>`, `<polygons>`, the course's CGL spheres), the node hierarchy
//! with its transforms (`matrix`, `translate`, `rotate`, `scale`, `lookat`) and the up axis.
//! [`write_collada`] writes a polygon mesh back as a one-node COLLADA document.
#![warn(missing_docs)]

mod collada;
mod error;

pub use collada::{
    parse_collada, read_collada, write_collada, Collada, Geometry, Instance, MeshData, Node, Part,
    Shape, UpAxis, MAX_FILE_BYTES, MAX_NODE_DEPTH,
};
pub use error::SceneError;
