//! Floor-3 rendering for prism, split by noun: a perspective camera (pinhole or thin lens,
//! `camera`), a deterministic sampler (`sampler`), BSDFs (`bsdf`), lights (`lights`, the
//! environment map's data in `envmap`), the render scene with its BVH (`render_scene`) and the
//! hit records it returns (`interaction`), the integrators (`integrators`: `normals`,
//! `direct`, `path`, and `wavefront`, which runs a tile's paths together and sixteen at a time
//! where it can) and the film that loops over pixels with adaptive sampling (`film`),
//! over a scene from prism-scene; a split render's part files and their merge (`parts`). The Whitted ray tracer of the Delft project has its scene
//! (`whitted_scene`), integrator (`integrators::whitted`), orbit camera (`camera`) and film
//! with per-pixel ray recording (`raytrace`).
#![warn(missing_docs)]

pub mod bsdf;
mod camera;
mod film;
mod integrators;
mod interaction;
mod lights;
mod parts;
mod profile;
mod render_scene;
mod sampler;
pub mod whitted;

pub use bsdf::{Bsdf, BsdfSample};
pub use camera::Perspective;
pub use film::{
    film_bytes, render, render_share, render_share_except, render_share_profiled, tile_count,
    tile_of, tiles, PixelSum, RenderOptions, Rendered, Share, TILE,
};
pub use integrators::{radiance, Integrator};
pub use interaction::Interaction;
pub use lights::envmap::{direction_to_uv, uv_to_direction, EnvMap};
pub use lights::{LightSample, MeshLight, RenderLight};
pub use parts::{merge, merge_order, Merged, Part, PartError, PartFile, PartHeader};
pub use profile::{Profile, Stage};
pub use render_scene::RenderScene;
pub use sampler::Sampler;
pub use whitted::camera::OrbitView;
pub use whitted::film::{
    raytrace, raytrace_bytes, raytrace_share, trace_pixel, with_bloom, PixelTrace, RaytraceOptions,
    Raytraced,
};
pub use whitted::overlay::{palette, Overlay};
pub use whitted::scene::{PhongMaterial, Surface, WhittedHit, WhittedScene};
pub use whitted::shading::{parallelogram_color, parallelogram_grid, phong};
pub use whitted::tracer::{
    DebugRay, PixelSampler, RayCounts, RayKind, WhittedSettings, WhittedTracer, MISS_LENGTH,
    RAY_EPSILON,
};
