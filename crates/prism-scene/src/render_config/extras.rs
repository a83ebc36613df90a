//! What the `[extras]` table of a Delft render config and its `[[motion]]` entries hold:
//! the settings of the template's extras (depth of field, motion blur, glossy reflection,
//! environment mapping), with their defaults and limits.

use std::path::PathBuf;

use prism_math::{Loc, Vec3};

/// Most samples an extra may take per pixel (or per reflection).
pub const MAX_EXTRA_SAMPLES: u32 = 4096;

/// Largest lens radius, focal distance or velocity a config may give.
pub const MAX_EXTENT: f32 = 1e6;

/// The extras' settings, with the template's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extras {
    /// Depth of field: the lens radius.
    pub dof_aperture: f32,
    /// Depth of field: the distance along the view axis of the plane in focus (`None`: the
    /// camera's distance from its look-at point).
    pub dof_focal_distance: Option<f32>,
    /// Depth of field: lens samples per pixel.
    pub dof_samples: u32,
    /// Motion blur: shutter times per pixel.
    pub motion_samples: u32,
    /// Glossy reflection: rays per reflection.
    pub glossy_samples: u32,
    /// Environment mapping: the map's radiance scale.
    pub environment_strength: f32,
}

impl Default for Extras {
    fn default() -> Extras {
        Extras {
            dof_aperture: 0.05,
            dof_focal_distance: None,
            dof_samples: 16,
            motion_samples: 16,
            glossy_samples: 16,
            environment_strength: 1.0,
        }
    }
}

/// Which meshes a motion entry moves.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshRef {
    /// The scene's mesh of this index (meshes in file order, one per material run; a
    /// preset's single mesh is 0).
    Index(usize),
    /// Every mesh of this name (a mesh is named after its material).
    Name(String),
}

/// A `[[motion]]` entry: meshes that move by `velocity` over the shutter interval [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// The meshes moved.
    pub mesh: MeshRef,
    /// The translation over the whole interval.
    pub velocity: Vec3,
    /// Where the entry is, for errors found when the scene is loaded.
    pub at: Loc,
}

/// An environment map named by a config.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMapFile {
    /// The file, relative paths resolved against the config's folder.
    pub path: PathBuf,
    /// Where it is named.
    pub at: Loc,
}

/// What the `[extras]` table and `[[motion]]` entries say.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExtrasTable {
    /// The settings.
    pub extras: Extras,
    /// `environment_map`.
    pub environment_map: Option<EnvironmentMapFile>,
    /// The motion entries, `[[motion]]` first, then `[extras]`'s `motion` array.
    pub motion: Vec<Motion>,
}
