//! Wavefront OBJ, read by one set of rules and written by one writer: the lexer (`lexer`:
//! statements and numbers, shared with MTL), the document (`document`: vertex data, faces
//! as corners, the grouping statements, checked against the memory budget) that every
//! builder starts from (the polygon mesh here, the shading mesh in prism-shade, the Delft
//! scene in prism-scene, each taking what it needs by [`ObjOptions`]), and the writer
//! (`writer`).

mod document;
mod lexer;
mod writer;

use std::path::Path;

use prism_math::glam::DVec3;

use crate::limits::MAX_MESH_FILE_BYTES;
use crate::{MeshError, PolyMesh};

pub use document::{
    Corner, Face, Marker, MarkerKind, ObjDocument, ObjError, ObjOptions, MAX_FACE_CORNERS,
};
pub use lexer::{statements, ObjFloat, Statement};
pub use writer::{write_obj, NumberStyle, ObjWriter};

/// Parses OBJ text into a polygon mesh (positions in `f64`, every face kept as a polygon;
/// texture coordinates and normals are checked and dropped); `file` names the source in
/// errors.
///
/// # Errors
/// [`MeshError::Obj`] at the first malformed statement ([`ObjDocument::parse`]).
pub fn parse_obj(text: &str, file: &str) -> Result<PolyMesh, MeshError> {
    let doc = ObjDocument::<f64>::parse(text, file, ObjOptions::default())?;
    let mut mesh = PolyMesh::default();
    mesh.positions = doc
        .positions
        .iter()
        .map(|p| DVec3::from_array(*p))
        .collect();
    let mut face = Vec::new();
    for f in &doc.faces {
        face.clear();
        face.extend(doc.face_corners(f).iter().map(|c| c.v));
        mesh.push_face(&face);
    }
    Ok(mesh)
}

/// Reads an OBJ file.
///
/// # Errors
/// [`MeshError::Io`] if unreadable, else as [`parse_obj`].
pub fn read_obj(path: &Path) -> Result<PolyMesh, MeshError> {
    let name = path.display().to_string();
    let text =
        prism_math::limits::read_input_text(path, MAX_MESH_FILE_BYTES).map_err(|source| {
            MeshError::Io {
                path: name.clone(),
                source,
            }
        })?;
    parse_obj(&text, &name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{icosahedron, HalfedgeMesh};

    #[test]
    fn write_then_parse_is_lossless() {
        let m = icosahedron();
        let mut buf = Vec::new();
        write_obj(&m, &mut buf).unwrap();
        let back = parse_obj(std::str::from_utf8(&buf).unwrap(), "mem").unwrap();
        assert_eq!(back, m);
    }

    #[test]
    fn normals_are_written_as_vn() {
        let mut m = icosahedron();
        m.normals = Some(crate::vertex_normals_area_weighted(&m));
        let mut buf = Vec::new();
        write_obj(&m, &mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        assert_eq!(text.lines().filter(|l| l.starts_with("vn ")).count(), 12);
        assert!(text.contains("f 1//1 12//12 6//6"));
        let back = parse_obj(&text, "mem").unwrap();
        assert_eq!(back.positions, m.positions);
    }

    #[test]
    fn corner_forms_and_negative_indices() {
        let t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2//1 -1\n";
        let m = parse_obj(t, "mem").unwrap();
        assert_eq!(m.face(0), &[0, 1, 2]);
    }

    #[test]
    fn errors_are_located() {
        let e = parse_obj("v 0 0 0\nv 1 0 nan\n", "a.obj").unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.obj:2: v: expected a finite number, found \"nan\""
        );
        let e = parse_obj("v 0 0 0\nf 1 2 3\n", "a.obj").unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.obj:2: f: vertex index 2 is out of range (1 defined so far)"
        );
        assert!(parse_obj("v 0 0\n", "a.obj").is_err());
        assert!(parse_obj("v 0 0 0\nv 1 1 1\nf 1 2\n", "a.obj").is_err());
    }

    /// Every staged OBJ loads and builds a valid halfedge mesh (or a located refusal).
    #[test]
    fn staged_objs_load() {
        let dir = prism_testkit::shared_asset("delft-raytracer/data");
        for name in ["cube.obj", "monkey.obj", "teapot.obj", "triangle.obj"] {
            let m = read_obj(&dir.join(name)).unwrap();
            assert!(m.face_count() > 0, "{name}");
            match HalfedgeMesh::from_polymesh(&m) {
                Ok(h) => h.validate().unwrap(),
                Err(e) => assert!(!e.to_string().is_empty(), "{name}"),
            }
        }
    }
}
