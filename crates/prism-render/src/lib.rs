//! Floor-3 rendering for prism: a pinhole camera, a deterministic sampler, BSDFs, lights and
//! the integrators (`normals`, `direct`, `path`) over a scene from prism-scene.
#![warn(missing_docs)]

pub mod bsdf;
mod camera;
mod render;
mod render_scene;
mod sampler;

pub use bsdf::{Bsdf, BsdfSample};
pub use camera::Perspective;
pub use render::{radiance, render, Integrator, RenderOptions, Rendered};
pub use render_scene::{Interaction, LightSample, RenderLight, RenderScene};
pub use sampler::Sampler;
