//! The size limits the mesh readers check before they read.

/// The largest mesh file (OBJ or PLY) the readers open: 1 GiB.
pub const MAX_MESH_FILE_BYTES: u64 = 1 << 30;
