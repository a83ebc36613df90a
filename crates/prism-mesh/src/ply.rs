//! Stanford PLY: ascii, binary little-endian and binary big-endian in; ascii and binary
//! little-endian out. Vertices take `x y z` and, when present, `nx ny nz` and `u v` (or
//! `s t`); faces take `vertex_indices` (or `vertex_index`). Other elements and properties
//! are read past and dropped.

use prism_math::Loc;
use std::io::Write;
use std::path::Path;

use prism_math::glam::{DVec2, DVec3};

use crate::{MeshError, PolyMesh};

/// How a PLY body is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlyFormat {
    /// Text.
    Ascii,
    /// Binary, little-endian.
    BinaryLittleEndian,
    /// Binary, big-endian (read only).
    BinaryBigEndian,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list.
    list: Option<Scalar>,
    ty: Scalar,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

/// Reads values from the body, ascii or binary.
struct Body<'a> {
    bytes: &'a [u8],
    pos: usize,
    format: PlyFormat,
    /// For ascii: the current line number (1-based, in the whole file).
    line: usize,
    words: std::vec::IntoIter<String>,
    file: &'a str,
}

impl Body<'_> {
    fn err(&self, message: String) -> MeshError {
        let line = if self.format == PlyFormat::Ascii {
            self.line
        } else {
            0
        };
        let message = if self.format == PlyFormat::Ascii {
            message
        } else {
            format!("at byte {}: {message}", self.pos)
        };
        MeshError::Parse {
            at: Loc::line(self.file, line as u32),
            message,
        }
    }

    fn next_word(&mut self) -> Result<String, MeshError> {
        loop {
            if let Some(w) = self.words.next() {
                return Ok(w);
            }
            if self.pos >= self.bytes.len() {
                return Err(self.err("unexpected end of data".into()));
            }
            let end = self.bytes[self.pos..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(self.bytes.len(), |k| self.pos + k);
            let line = String::from_utf8_lossy(&self.bytes[self.pos..end]).into_owned();
            self.pos = (end + 1).min(self.bytes.len());
            self.line += 1;
            self.words = line
                .split_whitespace()
                .map(str::to_string)
                .collect::<Vec<_>>()
                .into_iter();
        }
    }

    fn read(&mut self, ty: Scalar) -> Result<f64, MeshError> {
        if self.format == PlyFormat::Ascii {
            let w = self.next_word()?;
            return w
                .parse::<f64>()
                .map_err(|_| self.err(format!("expected a number, found {w:?}")));
        }
        let n = ty.size();
        if self.pos + n > self.bytes.len() {
            return Err(self.err(format!("expected {n} more bytes, the file ends")));
        }
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(&self.bytes[self.pos..self.pos + n]);
        self.pos += n;
        if self.format == PlyFormat::BinaryBigEndian {
            b[..n].reverse();
        }
        Ok(match ty {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F64 => f64::from_le_bytes(b),
        })
    }
}

/// Parses a PLY file's bytes; `file` names the source in errors.
///
/// # Errors
/// [`MeshError::Parse`] naming the header line (or, in binary bodies, the byte offset) of a
/// malformed header, an unknown type, missing coordinates, a truncated body, a non-finite
/// coordinate, or a face index out of range.
pub fn parse_ply(bytes: &[u8], file: &str) -> Result<PolyMesh, MeshError> {
    let perr = |line: usize, message: String| MeshError::Parse {
        at: Loc::line(file, line as u32),
        message,
    };
    // Header
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map(|k| pos + k)
            .ok_or_else(|| {
                perr(
                    line_no + 1,
                    "expected end_header before the end of the file".into(),
                )
            })?;
        let line = std::str::from_utf8(&bytes[pos..end])
            .map_err(|_| perr(line_no + 1, "header is not text".into()))?
            .trim_end_matches('\r')
            .to_string();
        pos = end + 1;
        line_no += 1;
        let w: Vec<&str> = line.split_whitespace().collect();
        if line_no == 1 {
            if w != ["ply"] {
                return Err(perr(1, format!("expected \"ply\", found {line:?}")));
            }
            continue;
        }
        match w.first().copied() {
            Some("format") => {
                format = Some(match w.get(1).copied() {
                    Some("ascii") => PlyFormat::Ascii,
                    Some("binary_little_endian") => PlyFormat::BinaryLittleEndian,
                    Some("binary_big_endian") => PlyFormat::BinaryBigEndian,
                    other => return Err(perr(line_no, format!("unknown format {other:?}"))),
                });
            }
            Some("element") => {
                let (Some(name), Some(count)) =
                    (w.get(1), w.get(2).and_then(|c| c.parse::<usize>().ok()))
                else {
                    return Err(perr(
                        line_no,
                        format!("expected \"element NAME COUNT\", found {line:?}"),
                    ));
                };
                elements.push(Element {
                    name: (*name).to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            Some("property") => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| perr(line_no, "property before any element".into()))?;
                let prop = if w.get(1) == Some(&"list") {
                    let (Some(ct), Some(it), Some(name)) = (
                        w.get(2).and_then(|t| Scalar::parse(t)),
                        w.get(3).and_then(|t| Scalar::parse(t)),
                        w.get(4),
                    ) else {
                        return Err(perr(
                            line_no,
                            format!("expected \"property list TYPE TYPE NAME\", found {line:?}"),
                        ));
                    };
                    Property {
                        name: (*name).to_string(),
                        list: Some(ct),
                        ty: it,
                    }
                } else {
                    let (Some(ty), Some(name)) =
                        (w.get(1).and_then(|t| Scalar::parse(t)), w.get(2))
                    else {
                        return Err(perr(
                            line_no,
                            format!("expected \"property TYPE NAME\", found {line:?}"),
                        ));
                    };
                    Property {
                        name: (*name).to_string(),
                        list: None,
                        ty,
                    }
                };
                el.props.push(prop);
            }
            Some("end_header") => break,
            Some("comment") | Some("obj_info") | None => {}
            Some(other) => return Err(perr(line_no, format!("unknown header keyword {other:?}"))),
        }
    }
    let format = format.ok_or_else(|| perr(line_no, "no format line in the header".into()))?;
    let mut body = Body {
        bytes,
        pos,
        format,
        line: line_no,
        words: Vec::new().into_iter(),
        file,
    };
    // Every instance of an element with properties takes at least a few bytes: a count the
    // rest of the file cannot hold is refused before any work is done.
    let remaining = bytes.len().saturating_sub(pos);
    for el in &elements {
        let min_bytes: usize = el
            .props
            .iter()
            .map(|p| match (format, p.list) {
                (PlyFormat::Ascii, _) => 2,
                (_, Some(ct)) => ct.size(),
                (_, None) => p.ty.size(),
            })
            .sum();
        let needed = el.count.saturating_mul(min_bytes);
        if needed > remaining {
            return Err(perr(
                line_no,
                format!(
                    "element {} declares {} instances, more than the {remaining} bytes after the header can hold",
                    el.name, el.count
                ),
            ));
        }
    }
    let mut mesh = PolyMesh::default();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut vertex_count = 0usize;
    let mut face = Vec::new();
    for el in &elements {
        let find = |n: &str| el.props.iter().position(|p| p.name == n);
        let (ix, iy, iz) = (find("x"), find("y"), find("z"));
        let normal_idx = (find("nx"), find("ny"), find("nz"));
        let uv_idx = (find("u").or(find("s")), find("v").or(find("t")));
        let fi = find("vertex_indices").or(find("vertex_index"));
        if el.name == "vertex" && (ix.is_none() || iy.is_none() || iz.is_none()) {
            return Err(perr(line_no, "element vertex lacks x, y or z".into()));
        }
        let mut values = vec![0.0f64; el.props.len()];
        // An element without properties holds nothing to read, whatever its count.
        let count = if el.props.is_empty() { 0 } else { el.count };
        for _ in 0..count {
            for (k, p) in el.props.iter().enumerate() {
                if let Some(ct) = p.list {
                    let n = body.read(ct)?;
                    if !(0.0..=1e6).contains(&n) || n.fract() != 0.0 {
                        return Err(body.err(format!("list length {n} is not a count")));
                    }
                    let is_face = el.name == "face" && Some(k) == fi;
                    if is_face {
                        face.clear();
                    }
                    for _ in 0..n as usize {
                        let v = body.read(p.ty)?;
                        if is_face {
                            if v < 0.0 || v.fract() != 0.0 || v as usize >= vertex_count {
                                return Err(body.err(format!(
                                    "face index {v} is out of range ({vertex_count} vertices)"
                                )));
                            }
                            face.push(v as u32);
                        }
                    }
                } else {
                    values[k] = body.read(p.ty)?;
                }
            }
            if el.name == "vertex" {
                let p = DVec3::new(
                    values[ix.unwrap_or(0)],
                    values[iy.unwrap_or(0)],
                    values[iz.unwrap_or(0)],
                );
                if !p.is_finite() {
                    return Err(body.err("vertex coordinates must be finite".into()));
                }
                mesh.positions.push(p);
                if let (Some(a), Some(b), Some(c)) = normal_idx {
                    normals.push(DVec3::new(values[a], values[b], values[c]));
                }
                if let (Some(a), Some(b)) = uv_idx {
                    uvs.push(DVec2::new(values[a], values[b]));
                }
            } else if el.name == "face" && fi.is_some() {
                if face.len() < 3 {
                    return Err(body.err(format!(
                        "a face needs at least 3 vertices, found {}",
                        face.len()
                    )));
                }
                mesh.push_face(&face);
            }
        }
        if el.name == "vertex" {
            vertex_count = mesh.positions.len();
        }
    }
    if !normals.is_empty() {
        mesh.normals = Some(normals);
    }
    if !uvs.is_empty() {
        mesh.uvs = Some(uvs);
    }
    Ok(mesh)
}

/// Reads a PLY file.
///
/// # Errors
/// [`MeshError::Io`] if unreadable, else as [`parse_ply`].
pub fn read_ply(path: &Path) -> Result<PolyMesh, MeshError> {
    let name = path.display().to_string();
    let bytes = prism_math::limits::read_input(path, crate::limits::MAX_MESH_FILE_BYTES).map_err(
        |source| MeshError::Io {
            path: name.clone(),
            source,
        },
    )?;
    parse_ply(&bytes, &name)
}

/// Writes positions (as doubles) and faces as PLY, ascii or binary little-endian.
///
/// # Errors
/// Whatever the writer returns; [`PlyFormat::BinaryBigEndian`] is refused as unsupported.
pub fn write_ply(mesh: &PolyMesh, format: PlyFormat, out: &mut impl Write) -> std::io::Result<()> {
    let fmt = match format {
        PlyFormat::Ascii => "ascii",
        PlyFormat::BinaryLittleEndian => "binary_little_endian",
        PlyFormat::BinaryBigEndian => {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Unsupported,
                "big-endian PLY output",
            ))
        }
    };
    writeln!(
        out,
        "ply\nformat {fmt} 1.0\nelement vertex {}",
        mesh.vertex_count()
    )?;
    writeln!(
        out,
        "property double x\nproperty double y\nproperty double z"
    )?;
    writeln!(
        out,
        "element face {}\nproperty list uint int vertex_indices\nend_header",
        mesh.face_count()
    )?;
    match format {
        PlyFormat::Ascii => {
            for p in &mesh.positions {
                writeln!(out, "{} {} {}", p.x, p.y, p.z)?;
            }
            for f in mesh.faces() {
                write!(out, "{}", f.len())?;
                for v in f {
                    write!(out, " {v}")?;
                }
                writeln!(out)?;
            }
        }
        _ => {
            for p in &mesh.positions {
                for c in p.to_array() {
                    out.write_all(&c.to_le_bytes())?;
                }
            }
            for f in mesh.faces() {
                out.write_all(&(f.len() as u32).to_le_bytes())?;
                for &v in f {
                    out.write_all(&(v as i32).to_le_bytes())?;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::icosahedron;

    #[test]
    fn ascii_and_binary_round_trip_losslessly() {
        let m = icosahedron();
        for format in [PlyFormat::Ascii, PlyFormat::BinaryLittleEndian] {
            let mut buf = Vec::new();
            write_ply(&m, format, &mut buf).unwrap();
            assert_eq!(parse_ply(&buf, "mem").unwrap(), m, "{format:?}");
        }
    }

    /// A hand-written big-endian file with floats, a uchar list and an extra element.
    #[test]
    fn big_endian_with_extra_properties() {
        let mut b = b"ply\nformat binary_big_endian 1.0\ncomment x\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\nelement edge 1\nproperty int a\nend_header\n".to_vec();
        for (x, y) in [(0.0f32, 0.0f32), (1.0, 0.0), (0.0, 1.0)] {
            for c in [x, y, 0.5] {
                b.extend_from_slice(&c.to_be_bytes());
            }
            b.push(200);
        }
        b.push(3);
        for i in [0i32, 1, 2] {
            b.extend_from_slice(&i.to_be_bytes());
        }
        b.extend_from_slice(&7i32.to_be_bytes());
        let m = parse_ply(&b, "mem").unwrap();
        assert_eq!(m.positions[1], DVec3::new(1.0, 0.0, 0.5));
        assert_eq!(m.face(0), &[0, 1, 2]);
    }

    #[test]
    fn broken_files_are_located_errors() {
        let e = parse_ply(
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty flaot x\nend_header\n",
            "a.ply",
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("a.ply:4: expected \"property TYPE NAME\""),
            "{e}"
        );
        let e = parse_ply(b"plx\n", "a.ply").unwrap_err();
        assert!(e.to_string().starts_with("a.ply:1:"), "{e}");
        let e = parse_ply(b"ply\nformat ascii 1.0\nelement vertex 1\n", "a.ply").unwrap_err();
        assert!(e.to_string().contains("end_header"), "{e}");
        let ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
        let e = parse_ply(ascii, "a.ply").unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.ply:13: face index 7 is out of range (3 vertices)"
        );
        let mut bin = Vec::new();
        write_ply(&icosahedron(), PlyFormat::BinaryLittleEndian, &mut bin).unwrap();
        let e = parse_ply(&bin[..bin.len() - 3], "b.ply").unwrap_err();
        assert!(e.to_string().contains("the file ends"), "{e}");
        let nan = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 nan 0\n";
        assert!(parse_ply(nan, "a.ply").is_err());
        // Counts the file cannot hold are refused up front; property-less elements are
        // skipped whatever their count.
        let huge = b"ply\nformat ascii 1.0\nelement vertex 3000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n";
        let e = parse_ply(huge, "h.ply").unwrap_err();
        assert!(
            e.to_string().contains("declares 3000000000 instances"),
            "{e}"
        );
        let empty = b"ply\nformat ascii 1.0\nelement junk 18446744073709551615\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        assert_eq!(parse_ply(empty, "e.ply").unwrap().vertex_count(), 0);
    }
}
