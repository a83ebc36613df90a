//! Floor-0 maths shared by every prism crate: a glam re-export, linear RGB colours, rays,
//! boxes and frames, exact (order-independent) sums of floats, 4x4 transforms named destination-from-source, sixteen-lane numbers for
//! SIMD kernels, warps with their densities, deterministic random numbers, and line numbers
//! of byte offsets for the readers' error messages, a cache prefetch hint, the
//! instruction sets the kernels may use, and the resource limits every reader shares.
#![warn(missing_docs)]

mod color;
mod elementary;
mod exact;
mod geometry;
pub mod lanes;
pub mod limits;
mod names;
mod random;
mod simd;
mod text;
mod transform;
pub mod warp;

pub use color::Rgb;
pub use elementary::{acos, atan2, exp, ln};
pub use exact::ExactSum;
pub use geometry::{Aabb, Frame, Ray};
pub use glam;
pub use glam::{DAffine2, DMat2, DVec2, Vec2, Vec3};
pub use names::edit_distance;
pub use random::{hash_extend, hash_words, mix64, unit_f32, word_mix, Pcg32};
pub use simd::{prefetch, Isa};
pub use text::{LineIndex, Loc, Warning};
pub use transform::Transform;
