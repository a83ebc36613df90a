//! Floor-3 shading for prism: a software 3D pipeline that draws what the CS184 course app's
//! OpenGL set-up draws, on the CPU.
//!
//! - `mesh`: [`ShadeMesh`], one vertex per distinct corner with normals, uvs and tangents, as
//!   the course app builds its buffers (from OBJ text, or any polygon mesh).
//! - `shaders`: [`Shader`], the course's shaders with their [`Uniforms`] and formulas.
//! - `pipeline`: [`shade`], vertex stage, clipping, bands of rows on rayon,
//!   perspective-correct varyings into the shaders, and the supersampling resolve.
//! - `raster`: depth-tested rasterization of a triangle into a band's samples, and the
//!   optional wireframe on top.
//! - `framing`: [`View::fit`], a view that frames a bounding sphere ([`Framing`]).
#![warn(missing_docs)]

mod error;
mod framing;
mod mesh;
mod pipeline;
mod raster;
mod shaders;

pub use error::ShadeError;
pub use framing::{Framing, MIN_FIT_RADIUS};
pub use mesh::ShadeMesh;
pub use pipeline::{frame_bytes, shade, shade_rgb8, to_bytes, ShadeOptions, View, FAR, NEAR};
pub use prism_mesh::obj::MAX_FACE_CORNERS;
pub use shaders::{
    blinn_phong, bumped_normal, course_texture, fragment, height, Needs, Shader, Uniforms, Varyings,
};
