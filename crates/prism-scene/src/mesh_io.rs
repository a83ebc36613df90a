//! Mesh files by extension, in one table (as pmp's `io`): Wavefront OBJ and Stanford PLY
//! through prism-mesh, COLLADA flattened to one Y-up world-space mesh.

use std::io::Write;
use std::path::Path;

use prism_mesh::{MeshError, PolyMesh};

use crate::collada::{read_collada, write_collada};
use crate::error::SceneError;

/// A mesh file format, named by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// Wavefront `.obj`.
    Obj,
    /// Stanford `.ply` (read in every encoding, written binary little-endian).
    Ply,
    /// COLLADA `.dae` (read flattened to one Y-up world mesh, written as one node).
    Dae,
}

impl MeshFormat {
    /// Every format, in the order errors list them.
    pub const ALL: [MeshFormat; 3] = [MeshFormat::Obj, MeshFormat::Ply, MeshFormat::Dae];

    /// The extension, without the dot.
    #[must_use]
    pub fn extension(self) -> &'static str {
        match self {
            MeshFormat::Obj => "obj",
            MeshFormat::Ply => "ply",
            MeshFormat::Dae => "dae",
        }
    }

    /// The format `path`'s extension names (in any letter case), if any.
    #[must_use]
    pub fn from_path(path: &Path) -> Option<MeshFormat> {
        let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
        MeshFormat::ALL.into_iter().find(|f| f.extension() == ext)
    }
}

/// What can go wrong reading or writing a mesh file.
#[derive(Debug, thiserror::Error)]
pub enum MeshIoError {
    /// The extension names no mesh format.
    #[error("{path}: expected an .obj, .ply or .dae file")]
    UnknownFormat {
        /// The file.
        path: String,
    },
    /// An OBJ or PLY error (with its location), or a write error.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A COLLADA error (with its location).
    #[error(transparent)]
    Scene(#[from] SceneError),
}

/// Reads the mesh in `path`, in the format its extension names; returns it with the
/// reader's warnings (COLLADA features read past, each naming file and line).
///
/// # Errors
/// [`MeshIoError::UnknownFormat`], or the reader's located error.
pub fn read_mesh(path: &Path) -> Result<(PolyMesh, Vec<prism_math::Warning>), MeshIoError> {
    match MeshFormat::from_path(path) {
        Some(MeshFormat::Obj) => Ok((prism_mesh::read_obj(path)?, Vec::new())),
        Some(MeshFormat::Ply) => Ok((prism_mesh::read_ply(path)?, Vec::new())),
        Some(MeshFormat::Dae) => {
            let doc = read_collada(path)?;
            let mesh = doc.world_mesh(true)?;
            Ok((mesh, doc.warnings))
        }
        None => Err(MeshIoError::UnknownFormat {
            path: path.display().to_string(),
        }),
    }
}

/// Most repairs of one kind named one by one in [`read_mesh_repaired`]'s warnings.
const REPAIR_WARNINGS: usize = 10;

/// [`read_mesh`], then (unless `strict`) the mesh repaired as OpenMesh repairs it on load,
/// with a warning naming each repair: a face on an edge already used in its direction gets
/// its own vertices, and a vertex where fans of faces touch becomes one vertex per fan
/// (vertices numbered from 1, as in OBJ files; faces from 0).
///
/// # Errors
/// As [`read_mesh`].
pub fn read_mesh_repaired(
    path: &Path,
    strict: bool,
) -> Result<(PolyMesh, Vec<prism_math::Warning>), MeshIoError> {
    use prism_math::Warning;
    let (mut p, mut warnings) = read_mesh(path)?;
    if strict {
        return Ok((p, warnings));
    }
    let name = path.display();
    let detached = p.detach_faces_on_used_edges();
    warnings.extend(detached.iter().take(REPAIR_WARNINGS).map(|f| {
        Warning::new(format!(
            "{name}: face {f} uses an edge an earlier face already uses in that direction \
             (a non-manifold edge or a face turned over); it gets vertices of its own \
             (--strict refuses such a mesh)"
        ))
    }));
    if detached.len() > REPAIR_WARNINGS {
        warnings.push(Warning::new(format!(
            "{name}: {} more faces detached the same way",
            detached.len() - REPAIR_WARNINGS
        )));
    }
    let split = p.split_nonmanifold_vertices();
    warnings.extend(split.iter().take(REPAIR_WARNINGS).map(|s| {
        Warning::new(format!(
            "{name}: vertex {} joins {} fans of faces that touch only there; split into \
             {} vertices (--strict refuses such a mesh)",
            s.vertex + 1,
            s.copies.len() + 1,
            s.copies.len() + 1
        ))
    }));
    if split.len() > REPAIR_WARNINGS {
        warnings.push(Warning::new(format!(
            "{name}: {} more vertices split the same way",
            split.len() - REPAIR_WARNINGS
        )));
    }
    Ok((p, warnings))
}

/// Writes `mesh` in `format` to `w`.
///
/// # Errors
/// The writer's I/O error.
pub fn write_mesh(mesh: &PolyMesh, format: MeshFormat, w: &mut impl Write) -> std::io::Result<()> {
    match format {
        MeshFormat::Obj => prism_mesh::write_obj(mesh, w),
        MeshFormat::Ply => {
            prism_mesh::write_ply(mesh, prism_mesh::PlyFormat::BinaryLittleEndian, w)
        }
        MeshFormat::Dae => write_collada(mesh, w),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::glam::DVec3;

    /// Oracle: a round trip through every format gives back the same faces and positions.
    #[test]
    fn every_format_round_trips() {
        let m = PolyMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.5, 0.5, 1.0)],
            &[vec![0, 1, 2], vec![0, 1, 3], vec![1, 2, 3], vec![2, 0, 3]],
        );
        let dir = std::env::temp_dir().join(format!("prism-mesh-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for format in MeshFormat::ALL {
            let path = dir.join(format!("m.{}", format.extension().to_uppercase()));
            assert_eq!(MeshFormat::from_path(&path), Some(format));
            let mut bytes = Vec::new();
            write_mesh(&m, format, &mut bytes).unwrap();
            std::fs::write(&path, bytes).unwrap();
            let (back, warnings) = read_mesh(&path).unwrap();
            assert!(warnings.is_empty(), "{warnings:?}");
            assert_eq!(back.positions, m.positions, "{format:?}");
            assert_eq!(
                back.faces().collect::<Vec<_>>(),
                m.faces().collect::<Vec<_>>()
            );
        }
        let e = read_mesh(&dir.join("m.stl")).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("m.stl: expected an .obj, .ply or .dae file"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
