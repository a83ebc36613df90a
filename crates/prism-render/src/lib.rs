//! Floor-3 rendering for prism, split by noun: a perspective camera (pinhole or thin lens,
//! `camera`), a deterministic sampler (`sampler`), BSDFs (`bsdf`), lights (`lights`, the
//! environment map's data in `envmap`), the render scene with its BVH (`render_scene`) and the
//! hit records it returns (`interaction`), the integrators (`integrators`: `normals`,
//! `direct`, `path`) and the film that loops over pixels with adaptive sampling (`film`),
//! over a scene from prism-scene.
#![warn(missing_docs)]

pub mod bsdf;
mod camera;
mod envmap;
mod film;
mod integrators;
mod interaction;
mod lights;
mod render_scene;
mod sampler;

pub use bsdf::{Bsdf, BsdfSample};
pub use camera::Perspective;
pub use envmap::{direction_to_uv, uv_to_direction, EnvMap};
pub use film::{render, RenderOptions, Rendered};
pub use integrators::{radiance, Integrator};
pub use interaction::Interaction;
pub use lights::{LightSample, RenderLight};
pub use render_scene::RenderScene;
pub use sampler::Sampler;
