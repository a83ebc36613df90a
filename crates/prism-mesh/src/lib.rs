//! Floor-1 meshes for prism: an indexed polygon mesh ([`PolyMesh`]), a halfedge mesh with
//! typed index handles ([`HalfedgeMesh`]) built from polygon soups with boundary loops,
//! edge flips, splits and collapses that check first and refuse with a [`TopologyError`],
//! Bezier curves and patches (de Casteljau), Wavefront OBJ and Stanford PLY reading and
//! writing, area-weighted vertex normals, Loop subdivision, procedural shapes
//! ([`icosahedron`]), and the repair made on load of vertices where fans touch
//! ([`PolyMesh::split_nonmanifold_vertices`]).
#![warn(missing_docs)]

mod bezier;
mod error;
mod halfedge;
mod limits;
mod loop_subdivision;
mod normals;
pub mod obj;
mod ply;
mod polymesh;
mod repair;
mod shapes;

pub use bezier::{
    bezier_point, de_casteljau_levels, de_casteljau_step, parse_bez, parse_bzc, tessellate,
    BezierPatch,
};
pub use error::MeshError;
pub use halfedge::{
    EdgeId, FaceId, HalfedgeId, HalfedgeMesh, TopologyError, ValidationError, VertexId,
};
pub use limits::MAX_MESH_FILE_BYTES;
pub use loop_subdivision::{
    check_subdivision, loop_subdivide, subdivided_size, LoopWeights, BYTES_PER_FACE,
};
pub use normals::vertex_normals_area_weighted;
pub use obj::{parse_obj, read_obj, write_obj};
pub use ply::{parse_ply, read_ply, write_ply, PlyFormat};
pub use polymesh::PolyMesh;
pub use repair::SplitVertex;
pub use shapes::icosahedron;
