//! Wavefront OBJ: `v`, `f` (with `v`, `v/vt`, `v//vn`, `v/vt/vn` corners and negative
//! relative indices); other statements (`vt`, `vn`, `o`, `g`, `s`, `usemtl`, `mtllib`, `l`)
//! are accepted and ignored.

use std::io::Write;
use std::path::Path;

use prism_math::glam::DVec3;

use crate::limits::MAX_MESH_FILE_BYTES;
use crate::{MeshError, PolyMesh};

/// Parses OBJ text; `file` names the source in errors.
///
/// # Errors
/// [`MeshError::Parse`] with the line of a malformed number, a non-finite coordinate, an
/// index of zero or out of range, or a face with fewer than three corners.
pub fn parse_obj(text: &str, file: &str) -> Result<PolyMesh, MeshError> {
    let mut mesh = PolyMesh::default();
    let mut face = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let err = |message: String| MeshError::Parse {
            file: file.to_string(),
            line: ln + 1,
            message,
        };
        let line = line.split('#').next().unwrap_or("");
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let mut c = [0.0f64; 3];
                for (k, slot) in c.iter_mut().enumerate() {
                    let w = words
                        .next()
                        .ok_or_else(|| err(format!("v: expected 3 coordinates, found {k}")))?;
                    *slot = w
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| err(format!("v: expected a finite number, found {w:?}")))?;
                }
                mesh.positions.push(DVec3::from_array(c));
            }
            Some("f") => {
                face.clear();
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let i: i64 = first
                        .parse()
                        .map_err(|_| err(format!("f: expected a vertex index, found {w:?}")))?;
                    let n = mesh.positions.len() as i64;
                    let idx = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || idx < 0 || idx >= n {
                        return Err(err(format!(
                            "f: vertex index {i} is out of range ({n} vertices so far)"
                        )));
                    }
                    face.push(idx as u32);
                }
                if face.len() < 3 {
                    return Err(err(format!(
                        "f: expected at least 3 corners, found {}",
                        face.len()
                    )));
                }
                mesh.push_face(&face);
            }
            _ => {}
        }
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

/// Writes positions, per-vertex normals (when present for every vertex, as `vn` lines with
/// `v//vn` corners) and faces as OBJ, with the shortest round-trip decimal for every number.
///
/// # Errors
/// Whatever the writer returns.
pub fn write_obj(mesh: &PolyMesh, out: &mut impl Write) -> std::io::Result<()> {
    let mut line = Vec::with_capacity(96);
    let mut num = NumberWriter::default();
    let normals = mesh
        .normals
        .as_ref()
        .filter(|n| n.len() == mesh.vertex_count());
    let vectors = mesh
        .positions
        .iter()
        .map(|p| (b"v" as &[u8], p))
        .chain(normals.into_iter().flatten().map(|n| (b"vn" as &[u8], n)));
    for (tag, p) in vectors {
        line.clear();
        line.extend_from_slice(tag);
        for c in [p.x, p.y, p.z] {
            line.push(b' ');
            num.float(&mut line, c);
        }
        line.push(b'\n');
        out.write_all(&line)?;
    }
    for f in mesh.faces() {
        line.clear();
        line.push(b'f');
        for &v in f {
            line.push(b' ');
            num.int(&mut line, u64::from(v) + 1);
            if normals.is_some() {
                line.extend_from_slice(b"//");
                num.int(&mut line, u64::from(v) + 1);
            }
        }
        line.push(b'\n');
        out.write_all(&line)?;
    }
    Ok(())
}

/// Shortest round-trip decimals for floats (integers print as `1.0`, tiny and huge values in
/// exponent form) and plain decimal integers, appended to a byte buffer.
#[derive(Default)]
pub(crate) struct NumberWriter {
    float: ryu::Buffer,
    int: itoa::Buffer,
}

impl NumberWriter {
    /// Appends the shortest decimal that reads back as `v`.
    pub(crate) fn float(&mut self, out: &mut Vec<u8>, v: f64) {
        out.extend_from_slice(self.float.format(v).as_bytes());
    }

    /// Appends `v` in decimal.
    pub(crate) fn int(&mut self, out: &mut Vec<u8>, v: u64) {
        out.extend_from_slice(self.int.format(v).as_bytes());
    }
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
            "a.obj:2: f: vertex index 2 is out of range (1 vertices so far)"
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
