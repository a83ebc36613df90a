//! The limits the COLLADA reader checks before it reads or expands: file size, node depth,
//! node count and placed polygons.

/// Largest COLLADA file read, in bytes.
pub const MAX_COLLADA_BYTES: u64 = 1 << 30;

/// Deepest node nesting followed, `instance_node` references included.
pub const MAX_NODE_DEPTH: usize = 64;

/// Most nodes the visual scene may expand to, each `instance_node` copying its target's
/// whole subtree.
pub const MAX_NODES: usize = 1_000_000;

/// Most polygons the instanced geometries may place in the world, counted over every
/// instance.
pub const MAX_PLACED_FACES: usize = 50_000_000;
