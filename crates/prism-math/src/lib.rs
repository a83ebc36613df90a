//! Floor-0 maths shared by every prism crate: a glam re-export, linear RGB colours, rays,
//! boxes and frames, warps with their densities, and deterministic random numbers.
#![warn(missing_docs)]

mod color;
mod geometry;
mod random;
pub mod warp;

pub use color::Rgb;
pub use geometry::{Aabb, Frame, Ray};
pub use glam;
pub use glam::{DAffine2, DMat2, DVec2, Vec2, Vec3};
pub use random::{hash_words, mix64, unit_f32, Pcg32};
