//! Floor-0 maths shared by every prism crate: a glam re-export, linear RGB colours and the
//! 2D affine transforms used by the rasterizer.
#![warn(missing_docs)]

mod color;

pub use color::Rgb;
pub use glam;
pub use glam::{DAffine2, DMat2, DVec2, Vec2, Vec3};
