//! The `[extras]` table of a Delft render config and its `[[motion]]` entries: the settings
//! of the template's extras (depth of field, motion blur, glossy reflection, environment
//! mapping), each checked and located.

use std::path::{Path, PathBuf};

use prism_math::{Loc, Vec3};
use toml::de::{DeTable, DeValue};

use super::{Cx, Val};
use crate::error::SceneError;

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

impl Cx<'_> {
    /// A whole number of samples from 1 to [`MAX_EXTRA_SAMPLES`].
    fn samples(&self, v: &Val<'_>, key: &str) -> Result<u32, SceneError> {
        let n = self.integer(v, key)?;
        if !(1..=i64::from(MAX_EXTRA_SAMPLES)).contains(&n) {
            return Err(self.err(
                v,
                format!("{key}: expected 1 to {MAX_EXTRA_SAMPLES} samples, found {n}"),
            ));
        }
        Ok(n as u32)
    }

    /// A number in `[lo, MAX_EXTENT]` (above `lo` if `open`).
    fn bounded(&self, v: &Val<'_>, key: &str, lo: f32, open: bool) -> Result<f32, SceneError> {
        let x = self.number(v, key)?;
        let low_ok = if open { x > lo } else { x >= lo };
        if !low_ok || x > MAX_EXTENT {
            let from = if open { "above" } else { "from" };
            return Err(self.err(
                v,
                format!("{key}: expected a number {from} {lo} up to {MAX_EXTENT}, found {x}"),
            ));
        }
        Ok(x)
    }

    /// The `[extras]` table into `out` (its `motion` entries appended).
    pub(super) fn extras(
        &self,
        v: &Val<'_>,
        base: &Path,
        out: &mut ExtrasTable,
    ) -> Result<(), SceneError> {
        let t = v.get_ref().as_table().ok_or_else(|| {
            self.err(
                v,
                format!("extras: expected a table, found {}", v.get_ref().type_str()),
            )
        })?;
        self.known_keys(
            t,
            &[
                "dof_aperture",
                "dof_focal_distance",
                "dof_samples",
                "motion_samples",
                "glossy_samples",
                "environment_map",
                "environment_strength",
                "motion",
            ],
            "[extras]",
        )?;
        let e = &mut out.extras;
        if let Some(x) = t.get("dof_aperture") {
            e.dof_aperture = self.bounded(x, "dof_aperture", 0.0, false)?;
        }
        if let Some(x) = t.get("dof_focal_distance") {
            e.dof_focal_distance = Some(self.bounded(x, "dof_focal_distance", 0.0, true)?);
        }
        if let Some(x) = t.get("dof_samples") {
            e.dof_samples = self.samples(x, "dof_samples")?;
        }
        if let Some(x) = t.get("motion_samples") {
            e.motion_samples = self.samples(x, "motion_samples")?;
        }
        if let Some(x) = t.get("glossy_samples") {
            e.glossy_samples = self.samples(x, "glossy_samples")?;
        }
        if let Some(x) = t.get("environment_strength") {
            e.environment_strength = self.bounded(x, "environment_strength", 0.0, false)?;
        }
        if let Some(x) = t.get("environment_map") {
            let s = self.string(x, "environment_map")?;
            out.environment_map = Some(EnvironmentMapFile {
                path: base.join(s),
                at: self.loc(x),
            });
        }
        if let Some(x) = t.get("motion") {
            self.motions(x, out)?;
        }
        Ok(())
    }

    /// `[[motion]]` tables into `out`.
    pub(super) fn motions(&self, v: &Val<'_>, out: &mut ExtrasTable) -> Result<(), SceneError> {
        for m in self.tables(v, "motion")? {
            out.motion.push(self.motion(m)?);
        }
        Ok(())
    }

    fn motion(&self, v: &Val<'_>) -> Result<Motion, SceneError> {
        let t: &DeTable<'_> = v.get_ref().as_table().expect("tables() checked");
        self.known_keys(t, &["mesh", "velocity"], "[[motion]]")?;
        let m = self.required(t, v, "mesh", "[[motion]]")?;
        let mesh = match m.get_ref() {
            DeValue::Integer(_) => {
                let i = self.integer(m, "mesh")?;
                MeshRef::Index(usize::try_from(i).map_err(|_| {
                    self.err(
                        m,
                        format!("mesh: expected an index of 0 or more, found {i}"),
                    )
                })?)
            }
            DeValue::String(s) => MeshRef::Name(s.to_string()),
            other => {
                return Err(self.err(
                    m,
                    format!(
                        "mesh: expected a mesh's name or index, found {}",
                        other.type_str()
                    ),
                ))
            }
        };
        let vel = self.required(t, v, "velocity", "[[motion]]")?;
        let velocity = self.vec3(vel, "velocity")?;
        if velocity.abs().max_element() > MAX_EXTENT {
            return Err(self.err(
                vel,
                format!(
                    "velocity: expected components up to {MAX_EXTENT} in size, found {velocity}"
                ),
            ));
        }
        Ok(Motion {
            mesh,
            velocity,
            at: self.loc(v),
        })
    }
}
