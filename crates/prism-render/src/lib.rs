//! Floor-3 rendering for prism, one module a room. The path tracer: a perspective camera
//! (pinhole or thin lens, [`camera`]), a deterministic sampler ([`sampler`]), BSDFs
//! ([`bsdf`]), lights with the environment map ([`lights`]), the render scene with its BVH
//! ([`render_scene`]) and the hit records it returns ([`interaction`]), the integrators and
//! their settings ([`integrators`]: normals, direct, path, and the wavefront, which runs a
//! tile's paths together, stage by stage), the film with its pixel sums and adaptive sampling
//! ([`film`]), the tile loop ([`render`]), a split render's part files and their merge
//! ([`parts`]) and where a render's time goes ([`profile`]), over a scene from prism-scene.
//! The Whitted ray tracer of the Delft project is one module, [`whitted`].
#![warn(missing_docs)]

pub mod bsdf;
pub mod camera;
pub mod film;
pub mod integrators;
pub mod interaction;
pub mod lights;
mod materials;
pub mod parts;
pub mod pixel_filter;
pub mod profile;
pub mod render;
pub mod render_scene;
pub mod sampler;
pub mod whitted;
