//! Floor-2 acceleration for prism's ray tracers: triangles and spheres with robust
//! intersection tests, and one bounding volume hierarchy over both.
//!
//! - Triangles use the watertight test of Woop, Benthin and Wald (JCGT 2013): a ray through
//!   a shared edge or vertex of a closed mesh hits at least one of the triangles.
//! - The BVH is built top-down with a binned surface area heuristic (16 bins on each axis,
//!   leaves costed in packs of four triangles; every subtree of at most sixteen primitives
//!   one leaf, two in hierarchies of 64 or fewer), in parallel above a size threshold. It
//!   is then collapsed into 8-wide nodes, the descendants each node's slots hold chosen by
//!   dynamic programming for the least total node surface area (to which a random ray's
//!   expected node visits are proportional). A node's eight child boxes are tested at
//!   once with SIMD: AVX when the processor has it (detected at run time), else two SSE
//!   halves, with identical results. Leaf triangles are stored in packs of four, also
//!   tested at once. The layout is a pure function of the input, whatever the thread
//!   count. In scenes of more than 24 primitives, up to 12 large ones (a box of at least
//!   1/16 of the scene's surface area: a room's walls and floor) are built apart under one
//!   child of the root, whose leaves the collapse then usually lifts into the root.
//! - [`Bvh::intersect`] finds the closest hit, going on to the nearest child entered and
//!   stacking the others; [`Bvh::occluded`] stops at the first hit, for shadow rays. A child
//!   is entered when its entry is no farther than the nearest hit found so far, moved up
//!   past the tests' rounding, so walks in any order find the same nearest hit; of two
//!   primitives at one distance the lower-numbered is taken. The hit is therefore a pure
//!   function of the ray and the primitives, whatever the hierarchy's shape.
//! - [`Bvh::intersect_batch`] and [`Bvh::occluded_batch`] answer many rays in one call. On
//!   processors with AVX-512 (AVX2), when the root's leaves hold at most 24 primitives (a
//!   Cornell box's walls, or all of a small scene), they test sixteen (eight) rays at once
//!   against those primitives, with the one-ray tests' operations on each lane, and
//!   against the boxes of the root's other children; only rays that enter one of those
//!   before their nearest hit traverse the rest. Otherwise [`Bvh::intersect_batch`] walks
//!   each group of sixteen (eight) coherent rays, one origin and one direction octant (a
//!   camera's), through the tree together, each node's children and each leaf's triangles
//!   tested on lanes; other rays are walked two at a time. They return the one-ray calls'
//!   hits, bit for bit.
//! - [`Bvh::levels`], [`Bvh::level_boxes`] and [`Bvh::leaf_views`] show the 8-wide tree
//!   level by level and leaf by leaf, for drawing and checking it.
#![warn(missing_docs)]
//!
//! The rooms: `hit` (what a query returns), `shapes` (spheres, the one-triangle and
//! one-sphere tests), `layout` (the hierarchy's data: 8-wide nodes, triangle packs, the
//! root's list), `build` (SAH, collapse, leaves), `traverse` (the queries and their walks),
//! `simd` (the only room that touches `std::arch`: the instruction-set kernels) and
//! `inspect` (the tree level by level, for drawing). Imports go one way: `traverse` and
//! `build` use `simd`, `layout`, `shapes` and `hit`; `simd` uses `layout`, `shapes` and
//! `hit`.

mod build;
mod hit;
mod inspect;
mod layout;
mod shapes;
mod simd;
mod traverse;

pub use build::{BuildOptions, Split};
pub use hit::Hit;
pub use inspect::LeafView;
pub use layout::{Bvh, BvhStats};
pub use shapes::{intersect_sphere, intersect_triangle, RayPre, Sphere};
