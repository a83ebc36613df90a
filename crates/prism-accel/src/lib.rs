//! Floor-2 acceleration for prism's ray tracers: triangles and spheres with robust
//! intersection tests, and one bounding volume hierarchy over both.
//!
//! - Triangles use the watertight test of Woop, Benthin and Wald (JCGT 2013): a ray through
//!   a shared edge or vertex of a closed mesh hits at least one of the triangles.
//! - The BVH is built top-down with a binned surface area heuristic (16 bins on each axis,
//!   leaves costed in packs of four triangles), in parallel above a size threshold, then
//!   collapsed into 8-wide nodes whose eight child boxes are tested at once with SIMD: AVX
//!   when the processor has it (detected at run time), else two SSE halves, with identical
//!   results. Leaf triangles are stored in packs of four, also tested at once. The layout is
//!   a pure function of the input, whatever the thread count.
//! - [`Bvh::intersect`] finds the closest hit, going on to the nearest child entered and
//!   stacking the others; [`Bvh::occluded`] stops at the first hit, for shadow rays.
//! - [`Bvh::intersect_batch`] and [`Bvh::occluded_batch`] answer many rays in one call. On
//!   hierarchies of a few primitives (a Cornell box with two spheres) and processors with
//!   AVX-512, they test sixteen rays at once against every primitive, with the one-ray
//!   tests' operations on each lane, and so return the same hits.
//! - [`Bvh::levels`], [`Bvh::level_boxes`] and [`Bvh::leaf_views`] show the 8-wide tree
//!   level by level and leaf by leaf, for drawing and checking it.
#![warn(missing_docs)]

mod bvh;
mod flat;
mod inspect;
mod node8;
mod shapes;
mod tri4;

pub use bvh::{BuildOptions, Bvh, BvhStats, Hit};
pub use inspect::LeafView;
pub use shapes::{intersect_sphere, intersect_triangle, RayPre, Sphere};
