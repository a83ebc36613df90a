//! Floor-3 simulation for prism: the CS184 ClothSim homework's cloth.
//!
//! - `scene`: [`ClothScene`], the course's scene JSON read as the course reads it, every key
//!   checked, with `--set` overrides; `json` is its small reader with line numbers.
//! - `sim`: [`Cloth`], the mass-spring simulation stepped exactly as the course's algorithm
//!   (`FORMATS.md` §4), in f64.
//! - `springs`: [`Spring`]s, their forces by family on the grid, and each mass's sum of them.
//! - `random`: [`GlibcRand`], the C library's `rand()` that jitters the vertical cloth.
//! - `draw`: the cloth and its obstacles as prism-shade meshes, and the course app's camera.
#![warn(missing_docs)]

mod draw;
mod error;
mod json;
mod random;
mod scene;
mod sim;
mod springs;

pub use draw::{cloth_mesh, course_view, obstacles};
pub use error::ClothError;
pub use json::{parse_json, Json, JsonValue, MAX_JSON_DEPTH};
pub use random::{GlibcRand, RAND_MAX};
pub use scene::{
    parse_scene, read_scene, ClothParams, ClothScene, Orientation, PlaneParams, SphereParams,
    MAX_DENSITY, MAX_GRID_SIDE, MAX_KS, MAX_MASSES, MAX_SCENE_BYTES, MAX_SIZE,
};
pub use sim::{Cloth, StepTimes, FRAMES_PER_SECOND, GRAVITY, STEPS_PER_FRAME};
pub use springs::{Spring, SpringKind};
