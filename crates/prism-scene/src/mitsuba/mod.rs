//! Mitsuba 3 scene files (`<scene version="3.0.0">`): the document ([`read_document`]:
//! includes, defaults, `$` substitution, properties, transforms, references) and the prism
//! scene it describes ([`to_scene`]), with the film, sampler and integrator settings.

mod bsdfs;
mod conductors;
mod document;
mod limits;
mod meshes;
mod props;
mod sensor;
mod serialized;
mod textures;
mod to_scene;
mod transform;
mod values;

#[cfg(test)]
mod tests;

use std::path::Path;

use crate::error::SceneError;

pub use conductors::{conductor, CONDUCTORS};
pub use document::{read_document, Document, Object, Property, Value};
pub use limits::{MAX_INCLUDE_DEPTH, MAX_MITSUBA_BYTES, MAX_OBJECTS, MAX_SCENE_FILES};
pub use to_scene::{to_scene, Filter, MitsubaOptions, MitsubaScene, MitsubaSettings};
pub use transform::{look_at, rotation};

/// Reads a Mitsuba scene file and the scene it describes; `defines` are `-D name=value`
/// settings for its `$name`s.
///
/// # Errors
/// As [`read_document`] and [`to_scene`].
pub fn read_mitsuba(path: &Path, defines: &[(String, String)]) -> Result<MitsubaScene, SceneError> {
    to_scene(&read_document(path, defines)?, MitsubaOptions::default())
}

/// [`read_mitsuba`] with `options`: leniently, or with another sensor as the camera.
///
/// # Errors
/// As [`read_mitsuba`], but for [`SceneError::Unsupported`] when lenient.
pub fn read_mitsuba_with(
    path: &Path,
    defines: &[(String, String)],
    options: MitsubaOptions,
) -> Result<MitsubaScene, SceneError> {
    to_scene(&read_document(path, defines)?, options)
}
