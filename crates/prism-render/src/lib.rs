//! Floor-3 rendering for prism: a perspective camera (pinhole or thin lens), a
//! deterministic sampler, BSDFs, lights (the environment map among them) and the integrators
//! (`normals`, `direct`, `path`) over a scene from prism-scene.
#![warn(missing_docs)]

pub mod bsdf;
mod camera;
mod envmap;
mod render;
mod render_scene;
mod sampler;

pub use bsdf::{Bsdf, BsdfSample};
pub use camera::Perspective;
pub use envmap::{direction_to_uv, uv_to_direction, EnvMap};
pub use render::{radiance, render, Integrator, RenderOptions, Rendered};
pub use render_scene::{Interaction, LightSample, RenderLight, RenderScene};
pub use sampler::Sampler;
